"""A raw four-point-bending test in library units: :class:`RawTest` and its parts.

A raw test at one pressure is a time series of time (s), crosshead stroke (mm) and force (N)
(:data:`COLUMNS`), with a record of how its file was read.  :func:`bendpam.lab.read_test` makes
one from a testing machine's export; :func:`check_cycle_count` compares a segmentation with the
machine's own cycle counter.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pandas is imported by the readers; a RawTest only holds a frame
    from pathlib import Path

    import pandas as pd

__all__ = ["COLUMNS", "DIALECTS", "FORMATS", "RawTest", "check_cycle_count"]

#: Column names of :attr:`RawTest.data`, in order: time in s, stroke in mm, force in N.
COLUMNS: tuple[str, str, str] = ("time_s", "stroke_mm", "force_n")
#: Dialects :func:`bendpam.lab.write_test` writes (and :func:`~bendpam.lab.readers.read_test` reads back).
DIALECTS: tuple[str, ...] = ("csv", "testxpert", "bluehill", "mts")
#: Formats :func:`~bendpam.lab.readers.read_test` reports in :attr:`RawTest.dialect` (alias :attr:`RawTest.format`).
FORMATS: tuple[str, ...] = (
    "csv", "testxpert", "bluehill", "mts", "mts793", "wavematrix", "instron", "trapezium", "excel", "zs2",
    "declared",
)  # fmt: skip


@dataclass(frozen=True, eq=False)
class RawTest:
    """One raw four-point-bending test at one pressure, in library units.

    Attributes
    ----------
    data : pandas.DataFrame
        Columns exactly ``["time_s", "stroke_mm", "force_n"]`` (time in s, crosshead stroke in
        mm, force in N), float64, finite, in file order, index ``0..n-1``.
    path : pathlib.Path
        The file read.
    dialect : str
        Format of the export, one of :data:`FORMATS` (also as :attr:`format`).
    metadata : dict of str to str
        Metadata name -> raw value string as written in the file (with the unit appended after
        a space when the file gave one in its own field), in file order.
    pressure_kpa : float or None
        Inflation pressure in kPa, if known.
    pressure_source : str or None
        ``"option"`` (the ``pressure_kpa`` argument), ``"metadata"`` (a Pressure/Druck line),
        ``"filename"`` (a token like ``200kPa``) or None.
    source_units : dict of str to str
        Unit of each column in the file, e.g. ``{"time_s": "s", "stroke_mm": "mm",
        "force_n": "kN"}`` (the assumed default s, mm, N when the file gave none).
    encoding : str or None
        Codec the text was decoded with (``"utf-8"``, ``"cp1250"``, ...; ``"xlsx"`` for a
        workbook).
    delimiter : str or None
        Cell delimiter of the data block (``"\\t"``, ``";"`` or ``","``).
    decimal : str or None
        Decimal mark of the data block (``"."`` or ``","``).
    header_line : int or None
        1-based line of the names row of the data block read.
    channels : dict
        role (``"time"``, ``"stroke"``, ``"force"``) -> ``{"source": column name as written
        (None for a time made from a sampling rate), "unit": unit as written, "why": reason}``.
    other_columns : list of str
        The block's other columns (not used), as written.
    warnings : list of str
        What was repaired, assumed or left unread (one sentence each).
    cycle_counter : numpy.ndarray or None
        The machine's cycle counter, one value per sample (float64), if the file has one.
    cycle_counter_source : str or None
        Its column name.
    blocks : list of dict
        Every data block of the file: ``{"line", "columns", "rows", "read"}``.
    sample_rate_hz : float or None
        The rate time was made from, when the file has no time column.
    data_lines : tuple of int or None
        First and last line (1-based; rows of a worksheet) of the samples read, for messages
        about the data as a whole; None for a test not read from a file.
    specimen : str or None
        Name of the specimen when the file holds several side by side (column groups), e.g.
        ``"Sample 2"``; None for a file of one specimen.
    block : int or None
        1-based number of the data block when the file holds several tests one after the other
        (each with its own header); None when the test is the whole file (blocks that continue
        one test are concatenated and listed in :attr:`blocks`).
    segments : list of tuple of int
        ``(start, stop)`` sample indices (``stop`` exclusive) of the stretches of continuous
        sampling; a gap in the sampling or a reset of time starts a new one.  One segment
        ``(0, n)`` for a test read without either; empty (one segment) for a test a script made.

    Examples
    --------
    :func:`~bendpam.lab.readers.read_test` makes one; so can a script, from data already in library units:

    >>> import pandas as pd
    >>> from pathlib import Path
    >>> data = pd.DataFrame({"time_s": [0.0, 0.05], "stroke_mm": [0.0, 0.027], "force_n": [11.8, 11.71]})
    >>> raw = RawTest(data, Path("be_150kPa.csv"), "csv", pressure_kpa=150.0, pressure_source="option")
    >>> raw
    RawTest(path='be_150kPa.csv', dialect='csv', rows=2, pressure=150 kPa (option), source_units={})
    """

    data: pd.DataFrame
    path: Path
    dialect: str
    metadata: dict[str, str] = field(default_factory=dict)
    pressure_kpa: float | None = None
    pressure_source: str | None = None
    source_units: dict[str, str] = field(default_factory=dict)
    encoding: str | None = None
    delimiter: str | None = None
    decimal: str | None = None
    header_line: int | None = None
    channels: dict[str, dict[str, str | None]] = field(default_factory=dict)
    other_columns: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    cycle_counter: np.ndarray | None = None
    cycle_counter_source: str | None = None
    blocks: list[dict[str, Any]] = field(default_factory=list)
    sample_rate_hz: float | None = None
    data_lines: tuple[int, int] | None = None
    specimen: str | None = None
    block: int | None = None
    segments: list[tuple[int, int]] = field(default_factory=list)

    @property
    def format(self) -> str:
        """Format of the export (same as :attr:`dialect`)."""
        return self.dialect

    def __len__(self) -> int:
        """Number of samples (rows)."""
        return len(self.data)

    def __repr__(self) -> str:
        p = "None"
        if self.pressure_kpa is not None:
            p = f"{self.pressure_kpa:g} kPa ({self.pressure_source})"
        return (
            f"RawTest(path={str(self.path)!r}, dialect={self.dialect!r}, rows={len(self.data)}, "
            f"pressure={p}, source_units={self.source_units})"
        )


def _machine_cycles(counter: np.ndarray) -> int | None:
    c = counter[np.isfinite(counter)]
    if c.size == 0:
        return None
    return round(float(np.max(c)) - float(np.min(c)))


def check_cycle_count(raw: RawTest, n_cycles_found: int) -> str | None:
    """Compare a segmentation's cycle count with the machine's cycle counter.

    The machine's count is the number of counter increments in the record (``max - min`` of
    the counter: a counter that starts at 0 and one that numbers cycles from 1 both give the
    cycles completed).

    Parameters
    ----------
    raw : RawTest
        A test read by :func:`~bendpam.lab.readers.read_test`.
    n_cycles_found : int
        Complete cycles found by the segmentation.

    Returns
    -------
    str or None
        A warning sentence when the counts disagree, None when they agree or the file has no
        cycle counter.

    Examples
    --------
    >>> import numpy as np, pandas as pd
    >>> from pathlib import Path
    >>> data = pd.DataFrame({"time_s": np.arange(7.0), "stroke_mm": np.zeros(7), "force_n": np.ones(7)})
    >>> raw = RawTest(data, Path("t.csv"), "csv", cycle_counter=np.array([0, 0, 1, 1, 2, 2, 3.0]),
    ...               cycle_counter_source="Total Cycle Count")
    >>> check_cycle_count(raw, 3) is None
    True
    >>> print(check_cycle_count(raw, 2))
    t.csv: the machine's cycle counter 'Total Cycle Count' counts 3 cycle(s) (from 0 to 3) but the segmentation ...
    """
    if raw.cycle_counter is None or raw.cycle_counter.size == 0:
        return None
    machine = _machine_cycles(np.asarray(raw.cycle_counter, dtype=np.float64))
    if machine is None or machine == int(n_cycles_found):
        return None
    c = raw.cycle_counter[np.isfinite(raw.cycle_counter)]
    return (
        f"{raw.path}: the machine's cycle counter {raw.cycle_counter_source!r} counts {machine} "
        f"cycle(s) (from {float(c.min()):.6g} to {float(c.max()):.6g}) but the segmentation "
        f"found {int(n_cycles_found)}; check the reversal threshold or the record"
    )
