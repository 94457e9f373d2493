"""Readers of raw four-point-bending exports from testing machines.

A raw test at one pressure is a time series of time (s), crosshead stroke (mm) and force (N).
:func:`read_test` reads it from what a testing machine writes and returns a :class:`RawTest`;
:func:`inspect_file` says how a file was read, as a JSON-ready dict.

The reader is layered, not a list of dialects:

1. **Bytes to text** (:mod:`bendpam.lab.encoding`): BOM, strict UTF-8, then the legacy code
   pages of these machines (cp1252, cp1250, GB18030, Shift-JIS, latin-1), keeping the one under
   which the header makes sense.  Workbooks (``.xlsx``/``.xls``) are read with
   ``python-calamine`` (extra ``excel``).  Zwick ``.zs2`` files are refused: export ASCII.
2. **Layout** (:mod:`bendpam.lab.layout`): delimiter (tab, ``;``, ``,``) and decimal mark
   inferred per data block and checked cell by cell; MTS 793's first line
   (``MTS793|MPT|DEU|1|2|,|.|...``) is honoured; quoted or unquoted cells, empty first fields,
   specimen-index columns, trailing empty columns, exponents like ``e-005``.
3. **Structure**: metadata lines in several grammars, a names row, an optional units row
   (``(s)``, ``[s]``, ``s``, ``in s``), several data blocks in one file (the one with time,
   stroke and force is read, the others are listed).
4. **Channels** (:mod:`bendpam.lab.channels`): names in English, German, French, Italian,
   Spanish, Polish, Chinese and Japanese; units s/ms/min, N/kN/lbf, mm/m/in converted.  Where
   several displacement channels exist, the relative crosshead travel is chosen (eq 6 wants the
   stroke from the blocked state); the choice and its reason are recorded, ``columns=``
   overrides it.  A file without time but with a sampling rate (metadata or ``rate_hz=``)
   reads.  A per-cycle summary or a results table is refused with the reason.
5. **Values** (:mod:`bendpam.lab.checks`): non-finite cells, isolated spikes, time that does
   not increase and gaps are found and refused (default) or, with ``repair=True``, removed
   and reported in :attr:`RawTest.warnings`.

The numeric block is read in chunks of lines by the C parser of :func:`pandas.read_csv`, so
a 500 MB export is read in bounded memory and linear time; a chunk the C parser cannot read is
re-scanned line by line to find the offending line.  Every failure is a :class:`ReadError`
whose message is one line ``FILE:LINE: what was wrong, what was expected``.
"""

from __future__ import annotations

import io
import math
import os
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from bendpam.lab.channels import (
    ACCEPTED_NAMES,
    DEFAULT_UNIT,
    FORCE_UNITS,
    LENGTH_UNITS,
    ROLES,
    TIME_UNITS,
    UNIT_HINT,
    ChannelChoice,
    ColumnInfo,
    canonical_unit,
    choose_channels,
    classify_column,
    is_unit_token,
    looks_like_summary,
    normalize_name,
    split_name_unit,
    unit_cell,
    unit_factor,
)
from bendpam.lab.checks import find_spikes, time_problems
from bendpam.lab.encoding import container_kind, detect_encoding
from bendpam.lab.layout import (
    DELIMITERS,
    LineReader,
    MetaItem,
    Mts793Header,
    has_control_chars,
    infer_decimal,
    is_blank,
    numeric_cells,
    parse_metadata_line,
    parse_mts793,
    parse_number,
    split_cells,
)
from bendpam.lab.read_error import ReadError, show

__all__ = [
    "COLUMNS",
    "DIALECTS",
    "FORCE_UNITS",
    "FORMATS",
    "LENGTH_UNITS",
    "PRESSURE_KEYS",
    "PRESSURE_RANGE_KPA",
    "PRESSURE_UNITS",
    "TIME_UNITS",
    "RawTest",
    "ReadError",
    "check_cycle_count",
    "detect_dialect",
    "format_inspection",
    "inspect_file",
    "is_pressure_key",
    "parse_columns",
    "parse_pressure",
    "pressure_from_filename",
    "read_test",
]

#: Column names of :attr:`RawTest.data`, in order: time in s, stroke in mm, force in N.
COLUMNS: tuple[str, str, str] = ("time_s", "stroke_mm", "force_n")
#: Dialects :func:`bendpam.lab.write_test` writes (and :func:`read_test` reads back).
DIALECTS: tuple[str, ...] = ("csv", "testxpert", "bluehill", "mts")
#: Formats :func:`read_test` reports in :attr:`RawTest.dialect` (alias :attr:`RawTest.format`).
FORMATS: tuple[str, ...] = (
    "csv", "testxpert", "bluehill", "mts", "mts793", "wavematrix", "instron", "trapezium", "excel",
)  # fmt: skip

_ROLE_COLUMN = dict(zip(ROLES, COLUMNS, strict=True))

# Pressure unit -> factor to kPa.
PRESSURE_UNITS: dict[str, float] = {
    "kpa": 1.0, "mpa": 1000.0, "hpa": 0.1, "pa": 1e-3,
    "bar": 100.0, "mbar": 0.1, "psi": 6.894757293168361,
    "n/mm2": 1000.0, "n/mm²": 1000.0,
}  # fmt: skip
#: Metadata names (lower case) that carry the inflation pressure.
PRESSURE_KEYS: frozenset[str] = frozenset(
    {
        "pressure", "druck", "inflation pressure", "supply pressure", "test pressure",
        "fülldruck", "versorgungsdruck", "prüfdruck", "luftdruck", "pression", "pressione",
        "presión", "ciśnienie", "压力", "気圧", "空気圧",
    }
)  # fmt: skip
#: Allowed inflation pressures (kPa), inclusive.
PRESSURE_RANGE_KPA: tuple[float, float] = (0.0, 10_000.0)

_CHUNK_LINES = 100_000  # lines handed to the C parser at a time
_PEEK_LINES = 200  # data rows inspected for the decimal mark
_HEAD_BYTES = 1 << 20  # bytes used to choose the encoding
_MAX_WARN_LINES = 5  # line numbers quoted in a message
_MAX_TIME_S = 1e9  # absurd beyond (about 30 years)
_MAX_STROKE_MM = 1e6
_MAX_FORCE_N = 1e9

_FILE_PRESSURE = re.compile(
    r"(?<![\d.,])((?:(?:^|(?<=[\s_=(\[]))-)?\d+(?:[.,]\d+)?)\s?"
    r"(kpa|mpa|hpa|mbar|bar|psi|pa)(?![a-z])",
    re.IGNORECASE,
)
_PRESSURE_VALUE = re.compile(
    r"\s*([+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][+-]?\d+)?)\s*([^\d\s].*?)?\s*"
)
_BRACKET_UNIT = re.compile(r"(.*?)\s*[(\[]\s*(.*?)\s*[)\]]")
_SUFFIX_UNIT = re.compile(r"(.+?)_([^\W\d_]+)")
_RATE_KEY = re.compile(
    r"sampl|abtast|mess ?rate|data rate|acquisition rate|recording rate|aufzeichnungsrate|"
    r"frequen|taux d.acquisition|échantillon|campionamento|muestreo|próbkowani|採樣|采样|"
    r"サンプリング|データ取込|rate"
)
_INTERVAL_KEY = re.compile(r"interval|intervall|period|periode|abtastzeit|time step|zeitschritt")
_RATE_UNITS = {"hz": 1.0, "khz": 1000.0, "1/s": 1.0, "/s": 1.0, "s-1": 1.0, "samples/s": 1.0,
               "pts/s": 1.0, "points/s": 1.0, "punkte/s": 1.0}  # fmt: skip


# ------------------------------------------------------------------------------------------------
# public types
# ------------------------------------------------------------------------------------------------
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

    Examples
    --------
    :func:`read_test` makes one; so can a script, from data already in library units:

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


# ------------------------------------------------------------------------------------------------
# pressures
# ------------------------------------------------------------------------------------------------
def _pressure_factor(unit: str) -> float | None:
    return PRESSURE_UNITS.get(unit.strip().strip("()[]").strip().lower())


def parse_pressure(value: str | float, unit: str | None = None) -> float:
    """Parse a pressure such as ``'200 kPa'``, ``'0,2 MPa'``, ``'2 bar'`` or ``'29 psi'``.

    Parameters
    ----------
    value : str or float
        A number, optionally followed by its unit.  A decimal comma is accepted.
    unit : str, optional
        Unit of ``value`` when ``value`` carries none (kPa, MPa, bar, mbar, hPa, Pa, psi).

    Returns
    -------
    float
        The pressure in kPa (not range-checked; see :data:`PRESSURE_RANGE_KPA`).

    Raises
    ------
    ReadError
        (a ``ValueError``) if the value is not a finite number, has no unit, or the unit is
        unknown, or ``value`` and ``unit`` name different units.

    Examples
    --------
    >>> parse_pressure("0,2 MPa"), parse_pressure("2 bar"), round(parse_pressure(29, "psi"), 2)
    (200.0, 200.0, 199.95)
    """
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
        number, text_unit, shown = float(value), "", repr(value)
    else:
        shown = show(str(value))
        m = _PRESSURE_VALUE.fullmatch(str(value))
        if m is None:
            raise ReadError(
                f"pressure {shown} is not a number with a unit; expected e.g. '200 kPa', "
                "'0,2 MPa' or '2 bar'"
            )
        number = float(m.group(1).replace(",", "."))
        text_unit = (m.group(2) or "").strip()
    given = (unit or "").strip()
    if text_unit and given and _pressure_factor(text_unit) != _pressure_factor(given):
        raise ReadError(f"pressure {shown} contradicts its unit {given!r}")
    u = text_unit or given
    if not u:
        raise ReadError(
            f"pressure {shown} has no unit; expected one of kPa, MPa, bar, Pa or psi"
        )
    factor = _pressure_factor(u)
    if factor is None:
        raise ReadError(
            f"unknown pressure unit {show(u)} in {shown}; expected kPa, MPa, bar, mbar, Pa or psi"
        )
    kpa = number * factor
    if not math.isfinite(kpa):
        raise ReadError(f"pressure {shown} is not finite; expected a finite number")
    return kpa


def _pressure_out_of_range(kpa: float) -> bool:
    lo, hi = PRESSURE_RANGE_KPA
    return not (lo <= kpa <= hi)


_RANGE_TEXT = "expected 0 to 10 000 kPa (an inflation pressure)"


def pressure_from_filename(name: str | os.PathLike) -> float | None:
    """Pressure in kPa encoded as a token in a file name, or None.

    Recognises ``200kPa``, ``0.2MPa``, ``2bar``, ``2,5bar``, ``200000Pa``, ``29psi`` (any
    case), also inside other text (``x200kPa_y``); the number must not be glued to a preceding
    digit or decimal mark and the unit must not run on into further letters (``2bars`` is not a
    token).  A minus sign counts only after ``_``, a blank, ``=`` or at the start
    (``be_-50kPa``); ``BE-200kPa`` is 200 kPa.  Only the last path component is looked at; the
    first token wins.  The value is not range-checked (:func:`read_test` refuses a pressure
    outside :data:`PRESSURE_RANGE_KPA`).

    Parameters
    ----------
    name : str or os.PathLike
        File name or path.

    Returns
    -------
    float or None
        Pressure in kPa.

    Examples
    --------
    >>> pressure_from_filename("be-pam_200kPa.csv"), pressure_from_filename("run_2,5bar.txt")
    (200.0, 250.0)
    >>> pressure_from_filename("run.csv") is None
    True
    """
    base = Path(os.fspath(name)).name if str(name) else ""
    for m in _FILE_PRESSURE.finditer(base):
        kpa = float(m.group(1).replace(",", ".")) * PRESSURE_UNITS[m.group(2).lower()]
        if math.isfinite(kpa):
            return kpa
    return None


def is_pressure_key(key: str) -> tuple[bool, str | None]:
    """Is ``key`` a metadata name of the inflation pressure?  Also return its unit.

    ``'Pressure (kPa)'`` -> ``(True, 'kPa')``, ``'Druck'`` -> ``(True, None)``,
    ``'Max pressure'`` -> ``(False, None)``.
    """
    k = key.strip().rstrip(":").strip()
    unit = None
    m = _BRACKET_UNIT.fullmatch(k)
    if m and m.group(2):
        k, unit = m.group(1), m.group(2)
    else:
        m = _SUFFIX_UNIT.fullmatch(k)
        if m and m.group(2).lower() in PRESSURE_UNITS:
            k, unit = m.group(1), m.group(2)
    k = " ".join(k.replace("_", " ").split()).lower()
    return k in PRESSURE_KEYS, unit


# ------------------------------------------------------------------------------------------------
# columns option
# ------------------------------------------------------------------------------------------------
def parse_columns(columns: Mapping[str, str] | str | None) -> dict[str, str]:
    """Normalise the ``columns=`` option to ``{role: column name}``.

    Parameters
    ----------
    columns : mapping, str or None
        ``{"time": NAME, "stroke": NAME, "force": NAME}`` (any subset) or the string form
        ``"time=NAME,stroke=NAME,force=NAME"``.

    Returns
    -------
    dict of str to str

    Raises
    ------
    bendpam.errors.InputError
        For an unknown role, an empty name or a malformed string.

    Examples
    --------
    >>> parse_columns("time=Zeit,force=Kraft"), parse_columns({"Stroke": "Weg"})
    ({'time': 'Zeit', 'force': 'Kraft'}, {'stroke': 'Weg'})
    """
    from bendpam.errors import InputError

    if columns is None:
        return {}
    if isinstance(columns, str):
        out: dict[str, str] = {}
        for part in re.split(r",(?=\s*(?:time|stroke|force)\s*=)", columns.strip()):
            if not part.strip():
                continue
            if "=" not in part:
                raise InputError(
                    f"columns {columns!r}: {part.strip()!r} has no '='; expected "
                    "'time=NAME,stroke=NAME,force=NAME'"
                )
            role, name = part.split("=", 1)
            out[role.strip().lower()] = name.strip()
        columns = out
    if not isinstance(columns, Mapping):
        raise InputError(f"columns must be a mapping or a string, got {type(columns).__name__}")
    result: dict[str, str] = {}
    for role, name in columns.items():
        r = str(role).strip().lower()
        if r not in ROLES:
            raise InputError(f"columns: unknown role {role!r}; expected time, stroke or force")
        if not str(name).strip():
            raise InputError(f"columns: the {r} column name is empty")
        result[r] = str(name).strip()
    if len(set(result.values())) < len(result):
        raise InputError(f"columns: one column named for two roles ({result})")
    return result


# ------------------------------------------------------------------------------------------------
# the source: bytes or workbook -> lines
# ------------------------------------------------------------------------------------------------
@dataclass
class _Source:
    label: Path | str
    encoding: str
    lines: Iterable[str]
    first_line: str
    is_excel: bool = False
    sheet: str | None = None
    close: Any = None


def _read_head(path: Path) -> tuple[bytes, int]:
    try:
        size = path.stat().st_size
        if path.is_dir():
            raise IsADirectoryError
        with open(path, "rb") as fh:
            head = fh.read(_HEAD_BYTES)
    except FileNotFoundError:
        raise ReadError("file not found; expected an existing raw test export", path) from None
    except IsADirectoryError:
        raise ReadError("is a directory; expected a raw test export file", path) from None
    except PermissionError:
        raise ReadError("permission denied; cannot read the file", path) from None
    except OSError as exc:
        raise ReadError(f"cannot read the file ({exc.strerror or exc})", path) from None
    return head, size


def _binary_error(path: Path, head: bytes) -> None:
    nul = head.find(b"\x00")
    if nul >= 0:
        raise ReadError(
            "binary data (NUL byte); expected a text export (CSV/TXT) or an .xlsx/.xls "
            "workbook, not a proprietary test file",
            path,
            head.count(b"\n", 0, nul) + 1,
        )


def _check_text_head(text: str, label: Path | str) -> None:
    if "\x00" in text:
        raise ReadError(
            "binary data (NUL character); expected a text export (CSV/TXT)",
            label,
            text.count("\n", 0, text.index("\x00")) + 1,
        )
    head = text[:65536]
    bad = re.findall(r"[\x00-\x08\x0e-\x19\x1b-\x1f\x7f]", head)
    if len(bad) > max(2, len(head) // 100):
        first = re.search(r"[\x00-\x08\x0e-\x19\x1b-\x1f\x7f]", head)
        assert first is not None
        raise ReadError(
            "binary data (control characters); expected a text export (CSV/TXT)",
            label,
            head.count("\n", 0, first.start()) + 1,
        )
    if not text.strip():
        raise ReadError("file contains only whitespace; expected a header row and data rows", label)


def _open_excel(path: Path, kind: str) -> list[tuple[str, list[str]]]:
    from bendpam.lab.excel import EXCEL_EXTRA_HINT, ExcelUnavailable, workbook_sheets

    what = "an .xlsx workbook (ZIP container)" if kind == "zip" else "an .xls workbook (OLE2)"
    try:
        sheets = workbook_sheets(path)
    except ExcelUnavailable:
        raise ReadError(
            f"binary file, {what}: reading workbooks needs python-calamine; "
            f"{EXCEL_EXTRA_HINT}, or export CSV/TXT from the testing software",
            path,
            1,
        ) from None
    except ValueError as exc:
        raise ReadError(
            f"binary data that is not a readable workbook ({exc}); expected a text export "
            "(CSV/TXT) or an .xlsx/.xls workbook",
            path,
            1,
        ) from None
    return [(s.name, s.lines) for s in sheets]


def _open_source(path: Path) -> tuple[list[_Source], int]:
    head, size = _read_head(path)
    if size == 0 or not head:
        raise ReadError("file is empty; expected a header row and data rows", path)
    kind = container_kind(head)
    if path.suffix.lower() in (".zs2", ".zp2") or (kind == "gzip"):
        raise ReadError(
            "native Zwick .zs2 (or gzip) file; export the test as ASCII (TXT/TRA) from "
            "testXpert and read that",
            path,
        )
    if kind in ("zip", "ole2"):
        sheets = _open_excel(path, kind)
        sources = []
        for name, lines in sheets:
            first = next((ln for ln in lines if ln.strip()), "")
            sources.append(_Source(path, "xlsx" if kind == "zip" else "xls", lines, first,
                                   is_excel=True, sheet=name))  # fmt: skip
        if not sources:
            raise ReadError("workbook without sheets; expected a sheet of test data", path, 1)
        return sources, size
    encoding = detect_encoding(head, complete=size <= len(head))
    if not encoding.startswith(("utf-16", "utf-32")):
        _binary_error(path, head)
    try:
        head_text = head.decode(encoding, errors="replace")
    except LookupError:  # pragma: no cover - codecs are fixed
        head_text = head.decode("latin-1")
    _check_text_head(head_text, path)
    fh = open(path, encoding=encoding, errors="replace", newline=None)
    first = head_text.lstrip("\ufeff").splitlines()[0] if head_text.strip() else ""
    return [_Source(path, encoding, fh, first, close=fh.close)], size


# ------------------------------------------------------------------------------------------------
# the structure: blocks of data rows, names rows, units rows, metadata
# ------------------------------------------------------------------------------------------------
@dataclass
class _Block:
    index: int
    header_line: int
    names: list[str]
    units_line: int | None
    units: list[str] | None
    sep: str
    first_line: int
    first_row: str
    columns: list[ColumnInfo]
    choice: ChannelChoice | None = None
    override_missing: str | None = None
    summary: list[str] = field(default_factory=list)
    n_rows: int = 0
    last_line: int = 0
    read: bool = False
    decimal: str | None = None

    def describe(self) -> str:
        names = [n for n in self.names if n]
        shown = ", ".join(names[:6]) + (", ..." if len(names) > 6 else "")
        return f"line {self.header_line} ({shown}; {self.n_rows} rows)"


@dataclass
class _Data:
    cols: dict[str, list[np.ndarray]] = field(default_factory=dict)
    lines: list[np.ndarray] = field(default_factory=list)
    dropped_nonfinite: list[int] = field(default_factory=list)
    counter_bad_line: int | None = None


def _role_hits(cells: list[str]) -> int:
    roles = set()
    for i, cell in enumerate(cells):
        if not cell or len(cell) > 80:
            continue
        name, unit = split_name_unit(cell)
        for c in classify_column(ColumnInfo(i, cell, name, unit)):
            if c.role in ROLES:
                roles.add(c.role)
    return len(roles)


def _is_units_row(cells: list[str], names: list[str]) -> bool:
    nonempty = [c for c in cells if c]
    if not nonempty or _role_hits(cells) > 0 or _role_hits(names) == 0:
        return False
    if numeric_cells(cells)[0] > 0:
        return False
    for c in nonempty:
        u = unit_cell(c)
        if not (is_unit_token(c) or (len(u) <= 12 and " " not in u.strip())):
            return False
    return len(nonempty) <= max(len(names), 1) + 1


def _trim(cells: list[str]) -> list[str]:
    out = list(cells)
    while out and not out[-1]:
        out.pop()
    return out


def _make_columns(
    names: list[str], units: list[str] | None, header_line: int, units_line: int | None
) -> list[ColumnInfo]:
    cols = []
    for i, cell in enumerate(names):
        name, unit = split_name_unit(cell)
        unit_line: int | None = header_line if unit else None
        if units is not None and i < len(units) and units[i].strip():
            unit, unit_line = unit_cell(units[i]).strip(), units_line
        cols.append(ColumnInfo(i, cell, name, unit or None, unit_line))
    return cols


def _data_seps(line: str) -> list[str]:
    out = []
    for sep in DELIMITERS:
        if sep in line:
            num, nonempty = numeric_cells(split_cells(line, sep))
            if num >= 2 and 2 * num >= nonempty:
                out.append(sep)
    return out


class _Parser:
    """One pass over the lines of an export: blocks, metadata and the chosen block's numbers."""

    def __init__(
        self,
        reader: LineReader,
        label: Path | str,
        *,
        mts: Mts793Header | None,
        default_decimal: str | None,
        overrides: dict[str, str],
        rate_hz: float | None,
        repair: bool,
        want_data: bool = True,
    ) -> None:
        self.reader = reader
        self.label = label
        self.mts = mts
        self.default_decimal = default_decimal
        self.overrides = overrides
        self.rate_hz = rate_hz
        self.repair = repair
        self.want_data = want_data
        self.text: list[tuple[int, str]] = []  # text lines outside blocks
        self.block_lines: set[int] = set()  # names and units rows
        self.blocks: list[_Block] = []
        self.chosen: _Block | None = None
        self.data: _Data | None = None
        self.first_orphan: int | None = None
        self.dollar = False
        self.warnings: list[str] = []
        self.trailing: list[tuple[int, str]] = []

    # -- metadata ----------------------------------------------------------------------------
    def meta_items(self, before: int | None = None) -> list[tuple[int, MetaItem]]:
        out = []
        for ln, line in self.text:
            if before is not None and ln >= before:
                break
            if ln in self.block_lines:
                continue
            if line.lstrip().startswith("$"):
                continue
            item = parse_metadata_line(line)
            if item is not None:
                out.append((ln, item))
        return out

    def rate_from_metadata(self, before: int | None = None) -> tuple[float, str] | None:
        for _ln, item in self.meta_items(before):
            key = normalize_name(item.key)
            unit = item.unit.strip().lower()
            value = item.value
            m = re.fullmatch(r"\s*([+-]?\d+(?:[.,]\d+)?(?:[eE][+-]?\d+)?)\s*(\S*)\s*", value)
            if m is None:
                continue
            number = float(m.group(1).replace(",", "."))
            unit = unit or m.group(2).lower()
            _kname, kunit = split_name_unit(item.key)
            unit = unit or (kunit or "").lower()
            if not (math.isfinite(number) and number > 0):
                continue
            if _RATE_KEY.search(key) and unit in _RATE_UNITS:
                return number * _RATE_UNITS[unit], f"metadata {item.key!r}"
            if _INTERVAL_KEY.search(key) and unit_factor("time", unit or "x") is not None:
                dt = number * (unit_factor("time", unit) or 1.0)
                return 1.0 / dt, f"metadata {item.key!r}"
        return None

    # -- main loop ---------------------------------------------------------------------------
    def run(self) -> None:
        reader = self.reader
        pre: list[tuple[int, str]] = []
        while True:
            line = reader.next()
            if line is None:
                break
            ln = reader.lineno
            if is_blank(line):
                continue
            if has_control_chars(line):
                self._binary_line(ln)
            if line.lstrip().startswith("$"):
                self.dollar = True
            seps = _data_seps(line)
            if seps and pre:
                blk = self._start_block(pre, line, ln, seps)
                reader.push_back([line])
                self._consume_block(blk)
                pre = []
                if self.chosen is not None and self.chosen.choice is not None and (
                    "time" in self.chosen.choice.chosen and not self.want_data
                ):
                    return
                continue
            if seps:
                if self.first_orphan is None:
                    self.first_orphan = ln
                continue
            pre.append((ln, line))
            self.text.append((ln, line))
            if self.chosen is not None and self.chosen.read:
                self.trailing.append((ln, line))

    def _binary_line(self, ln: int) -> None:
        raise ReadError(
            "binary data (control characters); expected a text export (CSV/TXT)", self.label, ln
        )

    def _start_block(self, pre: list[tuple[int, str]], line: str, ln: int, seps: list[str]) -> _Block:
        order = list(seps)
        if self.mts is not None and self.mts.delimiter in order:
            order.remove(self.mts.delimiter)
            order.insert(0, self.mts.delimiter)
        best: tuple[tuple[int, int, int, int], _Block] | None = None
        p1 = pre[-1]
        p2 = pre[-2] if len(pre) >= 2 else None
        for k, sep in enumerate(order):
            data_cells = split_cells(line, sep)
            c1 = split_cells(p1[1], sep)
            names_ln, names, units_ln, units = p1[0], c1, None, None
            if p2 is not None:
                c2 = split_cells(p2[1], sep)
                if len(c2) >= 2 and _is_units_row(c1, c2):
                    names_ln, names, units_ln, units = p2[0], c2, p1[0], c1
            fit = int(len(_trim(names)) >= 2 and abs(len(_trim(names)) - len(_trim(data_cells))) <= 1)
            score = (_role_hits(names), fit, len(names) >= 2, -k)
            cols = _make_columns(names, units, names_ln, units_ln)
            blk = _Block(len(self.blocks) + 1, names_ln, names, units_ln, units, sep, ln, line, cols)
            if best is None or score > best[0]:
                best = (score, blk)
        assert best is not None
        blk = best[1]
        self.blocks.append(blk)
        self.block_lines.add(blk.header_line)
        if blk.units_line is not None:
            self.block_lines.add(blk.units_line)
        try:
            blk.choice = choose_channels(blk.columns, self.overrides)
        except KeyError as exc:
            blk.override_missing = str(exc.args[0])
            blk.choice = None
        blk.summary = looks_like_summary(blk.columns)
        return blk

    def _usable(self, blk: _Block) -> int:
        """2 = time, stroke and force; 1 = stroke and force with a rate; 0 = not usable."""
        ch = blk.choice
        if ch is None or ch.bad_unit:
            return 0
        if {"time", "stroke", "force"} <= set(ch.chosen):
            return 2
        if {"stroke", "force"} <= set(ch.chosen) and (
            self.rate_hz is not None or self.rate_from_metadata(blk.header_line) is not None
        ):
            return 1
        return 0

    def _consume_block(self, blk: _Block) -> None:
        self.trailing = []
        level = self._usable(blk)
        current = 0 if self.chosen is None else self._usable(self.chosen)
        if level > current:
            self.chosen = blk
            blk.read = True
            self.trailing = []
            if self.want_data:
                self.data = _Data()
                self._read_rows(blk, self.data)
            else:
                self._read_rows(blk, None)
            for other in self.blocks:
                if other is not blk:
                    other.read = False
        else:
            self._read_rows(blk, None)

    # -- rows --------------------------------------------------------------------------------
    def _decimal_for(self, blk: _Block) -> str:
        reader = self.reader
        peek = reader.take(_PEEK_LINES)
        rows = []
        for ln_text in peek:
            if is_blank(ln_text):
                continue
            cells = split_cells(ln_text, blk.sep)
            num, nonempty = numeric_cells(cells)
            if num == 0 and nonempty:
                break
            rows.append(cells)
        reader.push_back(peek)
        mark, _comma, _dot = infer_decimal(rows, blk.sep)
        if self.mts is not None and self.mts.decimal is not None:
            return self.mts.decimal
        if mark is not None:
            return mark
        return self.default_decimal or "."

    def _needed(self, blk: _Block) -> list[tuple[str, ColumnInfo]]:
        ch = blk.choice
        assert ch is not None
        out = [(role, ch.chosen[role]) for role in ROLES if role in ch.chosen]
        if ch.counter is not None:
            out.append(("counter", ch.counter))
        return out

    def _read_rows(self, blk: _Block, data: _Data | None) -> None:
        reader = self.reader
        dec = self._decimal_for(blk)
        blk.decimal = dec
        if data is None:
            self._skip_rows(blk)
            return
        needed = self._needed(blk)
        for role, _col in needed:
            data.cols[role] = []
        while True:
            lines = reader.take(_CHUNK_LINES)
            if not lines:
                break
            start = reader.lineno - len(lines) + 1
            arrs = self._fast(lines, blk, needed, dec)
            if arrs is None and needed[-1][0] == "counter":
                # the optional counter alone may be what the C parser cannot read
                arrs = self._fast(lines, blk, needed[:-1], dec)
                if arrs is not None:
                    arrs.append(np.full(len(lines), np.nan))
                    if data.counter_bad_line is None:
                        data.counter_bad_line = start
            if arrs is not None:
                for (role, _col), arr in zip(needed, arrs, strict=True):
                    data.cols[role].append(arr)
                data.lines.append(np.arange(start, start + len(lines), dtype=np.int32))
                blk.n_rows += len(lines)
                blk.last_line = start + len(lines) - 1
                continue
            end = self._slow(lines, start, blk, needed, dec, data)
            if end is not None:
                reader.push_back(lines[end:])
                break

    def _fast(self, lines: list[str], blk: _Block, needed, dec: str) -> list[np.ndarray] | None:
        if blk.sep == dec:
            return None
        idx = [col.index for _role, col in needed]
        try:
            df = pd.read_csv(
                io.BytesIO("\n".join(lines).encode("utf-8", "surrogatepass")),
                sep=blk.sep,
                decimal=dec,
                header=None,
                usecols=sorted(set(idx)),
                dtype=np.float64,
                engine="c",
                skip_blank_lines=False,
                quotechar='"',
                na_filter=False,
                index_col=False,
            )
            arrs = [np.array(df[i].to_numpy(dtype=np.float64), copy=True) for i in idx]
        except Exception:  # any parser trouble -> the slow path finds the line
            return None
        del df
        if any(len(a) != len(lines) or not np.isfinite(a).all() for a in arrs):
            return None
        return arrs

    def _row_problem(self, role: str, col: ColumnInfo, cell: str | None, dec: str, blk: _Block,
                     line: str) -> str:  # fmt: skip
        roles = [r for r in ROLES if blk.choice is not None and r in blk.choice.chosen]
        what = f"{len(roles)} numeric columns ({', '.join(roles)})"
        name = col.source
        if cell is None:
            return (
                f"expected {what}, got {show(line.strip())} with only "
                f"{len(split_cells(line, blk.sep))} field(s) (column {name!r} missing)"
            )
        res = parse_number(cell, dec)
        mark = "decimal comma" if dec == "," else "decimal point"
        if res.problem == "empty":
            return f"expected {what} with a {mark}, got an empty cell in column {name!r}"
        if res.problem == "nonfinite":
            return f"non-finite value {show(cell)} in column {name!r}; expected a finite number"
        if res.problem == "thousands":
            return (
                f"number {show(cell)} in column {name!r} has a thousands separator that collides "
                f"with the {mark}; expected numbers without digit grouping (export them plain)"
            )
        return f"expected {what} with a {mark}, got {show(cell)} in column {name!r}"

    def _slow(self, lines: list[str], start: int, blk: _Block, needed, dec: str,
              data: _Data) -> int | None:  # fmt: skip
        """Parse line by line; the index in ``lines`` where the block ends, or None."""
        sep = blk.sep
        rows: list[list[float]] = []
        lnos: list[int] = []
        blank_run: int | None = None
        names_norm = [normalize_name(n) for n in blk.names]
        end: int | None = None
        for k, line in enumerate(lines):
            ln = start + k
            if is_blank(line, sep):
                if blank_run is None:
                    blank_run = k
                continue
            if has_control_chars(line):
                self._binary_line(ln)
            cells = split_cells(line, sep)
            vals: list[float] = []
            problem: tuple[str, ColumnInfo, str | None] | None = None
            for role, col in needed:
                cell = cells[col.index] if col.index < len(cells) else None
                if cell is None:
                    if role == "counter":
                        vals.append(math.nan)
                        continue
                    problem = (role, col, None)
                    break
                res = parse_number(cell, dec)
                if res.value is None:
                    if role == "counter":
                        vals.append(math.nan)
                        if data.counter_bad_line is None:
                            data.counter_bad_line = ln
                        continue
                    problem = (role, col, cell)
                    break
                vals.append(res.value)
            if problem is None:
                rows.append(vals)
                lnos.append(ln)
                blank_run = None
                continue
            num, nonempty = numeric_cells(cells)
            datalike = num >= 2 and 2 * num >= nonempty
            if not datalike:
                repeated = [normalize_name(c) for c in cells] == names_norm
                if blank_run is not None or repeated or _role_hits(cells) >= 2:
                    end = blank_run if blank_run is not None else k
                    break
            role, col, cell = problem
            if (
                self.repair
                and cell is not None
                and parse_number(cell, dec).problem in ("nonfinite", "empty")
                and datalike
            ):
                data.dropped_nonfinite.append(ln)
                blank_run = None
                continue
            raise ReadError(self._row_problem(role, col, cell, dec, blk, line), self.label, ln,
                            col.source)  # fmt: skip
        if rows:
            arr = np.asarray(rows, dtype=np.float64).reshape(-1, len(needed))
            for j, (role, _col) in enumerate(needed):
                data.cols[role].append(arr[:, j].copy())
            data.lines.append(np.asarray(lnos, dtype=np.int32))
            blk.n_rows += len(rows)
            blk.last_line = lnos[-1]
        if end is None and blank_run is not None:
            return None  # trailing blank lines: the next chunk decides
        return end

    def _skip_rows(self, blk: _Block) -> None:
        reader = self.reader
        sep = blk.sep
        while True:
            lines = reader.take(_CHUNK_LINES)
            if not lines:
                return
            start = reader.lineno - len(lines) + 1
            blank_run: int | None = None
            for k, line in enumerate(lines):
                if is_blank(line, sep):
                    if blank_run is None:
                        blank_run = k
                    continue
                cells = split_cells(line, sep)
                num, nonempty = numeric_cells(cells)
                if num >= 1 and 2 * num >= nonempty:
                    blk.n_rows += 1
                    blk.last_line = start + k
                    blank_run = None
                    continue
                if has_control_chars(line):
                    self._binary_line(start + k)
                end = blank_run if blank_run is not None else k
                reader.push_back(lines[end:])
                return


# ------------------------------------------------------------------------------------------------
# format names
# ------------------------------------------------------------------------------------------------
_ZWICK = re.compile(r"prüfzeit|pruefzeit|standardweg|standardkraft|standard travel|standard force|"
                    r"traverse abs|testxpert|zwick")  # fmt: skip
_GERMAN = re.compile(r"zeit|kraft|weg\b")
_WAVEMATRIX = re.compile(r"total cycles|elapsed cycles|cycle elapsed time|digital position|"
                         r"wavematrix")  # fmt: skip
_TRAPEZIUM = re.compile(r"試験力|ストローク|trapezium|shimadzu")


def _classify_format(p: _Parser, blk: _Block, source: _Source) -> str:
    if source.is_excel:
        return "excel"
    if p.mts is not None:
        return "mts793"
    names = " ".join(c.casefold() for c in blk.names)
    meta = [(ln, line) for ln, line in p.text if ln < blk.header_line]
    meta_text = " ".join(line.casefold() for _ln, line in meta)
    other_meta = any(not line.lstrip().startswith(("#", "$")) for ln, line in meta
                     if ln not in p.block_lines)  # fmt: skip
    units_row = blk.units_line is not None
    paren_units = units_row and blk.units is not None and any(
        re.fullmatch(r"\(.*\)", u.strip()) for u in blk.units if u.strip()
    )
    if p.dollar or _ZWICK.search(names) or _ZWICK.search(meta_text):
        return "testxpert"
    if _TRAPEZIUM.search(names) or _TRAPEZIUM.search(meta_text):
        return "trapezium"
    if _WAVEMATRIX.search(names) or _WAVEMATRIX.search(meta_text):
        return "wavematrix"
    if blk.first_row.lstrip().startswith('"') or paren_units:
        return "bluehill"
    if re.search(r"text inputs :|general :|bluehill", meta_text):
        return "bluehill"
    german = _GERMAN.search(names) is not None
    if blk.sep == ";" and (german or blk.decimal == "," or other_meta or units_row):
        return "testxpert"
    if "instron" in meta_text:
        return "instron"
    if other_meta or units_row or re.search(r"(^|\s)_\w", names):
        return "mts"
    return "csv"


# ------------------------------------------------------------------------------------------------
# reading
# ------------------------------------------------------------------------------------------------
def _no_header_error(p: _Parser) -> ReadError:
    label = p.label
    partial = [b for b in p.blocks if b.choice is not None and b.choice.n_roles >= 2]
    summaries = [b for b in p.blocks if b.summary and (b.choice is None or b.choice.n_roles < 2)]
    missing_override = [b for b in p.blocks if b.override_missing is not None]
    if missing_override and p.overrides:
        b = missing_override[0]
        wanted = b.override_missing
        cols = ", ".join(repr(n) for n in b.names if n)
        return ReadError(
            f"column {wanted!r} named in the columns option is not in the file; its columns "
            f"are {cols}",
            label,
            b.header_line,
        )
    for b in partial:
        assert b.choice is not None
        for role, col in b.choice.bad_unit.items():
            return ReadError(
                f"unknown {role} unit {show(col.unit or '')} for column {col.source!r}; expected "
                f"{UNIT_HINT[role]}",
                label,
                col.unit_line or b.header_line,
                col.source,
            )
    if summaries and not partial:
        b = summaries[0]
        cols = ", ".join(repr(c) for c in b.summary[:4])
        return ReadError(
            f"a per-cycle or per-specimen summary, not a time series: columns such as {cols} "
            "hold one value per cycle or specimen and no column is a time, stroke or force "
            "sample; expected the raw data export (time, stroke and force samples)",
            label,
            b.header_line,
        )
    if partial:
        b = partial[0]
        assert b.choice is not None
        ch = b.choice
        found = ", ".join(f"{r} {ch.chosen[r].source!r}" for r in ROLES if r in ch.chosen)
        missing = [r for r in ROLES if r not in ch.chosen]
        if missing == ["time"]:
            return ReadError(
                f"header row has no time column (found {found}) and no sampling rate is known; "
                "expected a time column, a sampling rate in the metadata (e.g. 'Sample rate: "
                "100 Hz') or the rate_hz option",
                label,
                b.header_line,
            )
        return ReadError(
            f"header row has no {' or '.join(missing)} column (found {found}); expected a "
            f"column named after {' and '.join(missing)} (accepted names: {ACCEPTED_NAMES})",
            label,
            b.header_line,
        )
    # a header without data rows?
    for ln, line in p.text:
        for sep in DELIMITERS:
            if sep in line and _role_hits(split_cells(line, sep)) >= 3:
                return ReadError(
                    "header row is followed by no data rows; expected at least 2", label, ln
                )
    first_data = p.blocks[0].first_line if p.blocks else p.first_orphan
    if first_data is not None:
        return ReadError(
            "no header row naming time, stroke and force columns before the first data row; "
            f"expected e.g. 'time_s,stroke_mm,force_n' (accepted names: {ACCEPTED_NAMES})",
            label,
            first_data,
        )
    return ReadError(
        "no header row naming time, stroke and force columns; expected e.g. "
        f"'time_s,stroke_mm,force_n' (accepted names: {ACCEPTED_NAMES})",
        label,
    )


@dataclass
class _Parsed:
    parser: _Parser
    source: _Source
    block: _Block


def _parse_source(source: _Source, *, dialect: str | None, overrides: dict[str, str],
                  rate_hz: float | None, repair: bool, want_data: bool = True) -> _Parsed:  # fmt: skip
    mts = parse_mts793(source.first_line)
    default_decimal = "," if dialect == "testxpert" else None
    reader = LineReader(source.lines)
    p = _Parser(reader, source.label, mts=mts, default_decimal=default_decimal,
                overrides=overrides, rate_hz=rate_hz, repair=repair, want_data=want_data)  # fmt: skip
    try:
        p.run()
    finally:
        if source.close is not None:
            source.close()
    if p.chosen is None:
        raise _no_header_error(p)
    return _Parsed(p, source, p.chosen)


def _parse_path(path: Path, **kw: Any) -> _Parsed:
    sources, _size = _open_source(path)
    first_error: ReadError | None = None
    for src in sources:
        try:
            return _parse_source(src, **kw)
        except ReadError as exc:
            if not src.is_excel:
                raise
            if first_error is None:
                first_error = ReadError(f"sheet {src.sheet!r}: {exc.message}", path, exc.line,
                                        exc.column)  # fmt: skip
    assert first_error is not None
    raise first_error


def _lines_text(lines: Iterable[int]) -> str:
    ls = list(lines)
    shown = ", ".join(str(v) for v in ls[:_MAX_WARN_LINES])
    return shown + (f" (and {len(ls) - _MAX_WARN_LINES} more)" if len(ls) > _MAX_WARN_LINES else "")


def _fmt(v: float) -> str:
    return f"{v:.6g}"


def _assemble(parsed: _Parsed, *, pressure_kpa: float | None, dialect: str | None,
              rate_hz: float | None, repair: bool) -> RawTest:  # fmt: skip
    p, blk = parsed.parser, parsed.block
    label = p.label
    path = Path(label) if isinstance(label, (str, Path)) else Path(str(label))
    data = p.data
    assert data is not None and blk.choice is not None
    ch = blk.choice
    warnings = list(p.warnings)
    if blk.n_rows < 2:
        raise ReadError(
            f"header row is followed by {blk.n_rows} data row(s); expected at least 2",
            label,
            blk.header_line,
        )

    def column(role: str) -> np.ndarray:
        parts = data.cols.pop(role)
        arr = np.concatenate(parts) if len(parts) != 1 else parts[0]
        parts.clear()
        return arr

    lines = np.concatenate(data.lines) if len(data.lines) != 1 else data.lines[0]
    data.lines.clear()
    if data.dropped_nonfinite:
        warnings.append(
            f"dropped {len(data.dropped_nonfinite)} row(s) with a non-finite or empty value at "
            f"line(s) {_lines_text(data.dropped_nonfinite)}"
        )

    # units
    source_units: dict[str, str] = {}
    channels: dict[str, dict[str, str | None]] = {}
    values: dict[str, np.ndarray] = {}
    for role in ROLES:
        if role not in ch.chosen:
            continue
        col = ch.chosen[role]
        unit = col.unit
        if not unit:
            unit = DEFAULT_UNIT[role]
            warnings.append(f"no unit for the {role} column {col.source!r}; assumed {unit}")
        f = unit_factor(role, unit)
        if f is None:
            raise ReadError(
                f"unknown {role} unit {show(unit)} for column {col.source!r}; expected "
                f"{UNIT_HINT[role]}",
                label,
                col.unit_line or blk.header_line,
                col.source,
            )
        arr = column(role)
        if f != 1.0:
            arr *= f
        values[role] = arr
        source_units[_ROLE_COLUMN[role]] = canonical_unit(role, unit)
        channels[role] = {"source": col.source, "unit": canonical_unit(role, unit),
                          "why": ch.why.get(role, "")}  # fmt: skip
    counter = column("counter") if ch.counter is not None else None

    sample_rate: float | None = None
    if "time" not in values:
        if rate_hz is not None:
            sample_rate, rate_src = float(rate_hz), "the rate_hz option"
        else:
            got = p.rate_from_metadata(blk.header_line)
            assert got is not None
            sample_rate, rate_src = got
        n = values["stroke"].size
        values["time"] = np.arange(n, dtype=np.float64) / sample_rate
        source_units["time_s"] = "s"
        channels["time"] = {
            "source": None,
            "unit": "s",
            "why": f"no time column; made from the sampling rate {sample_rate:g} Hz ({rate_src})",
        }
        warnings.append(f"no time column: time made from {sample_rate:g} Hz ({rate_src})")
    elif rate_hz is not None:
        warnings.append(f"rate_hz={rate_hz:g} ignored: the file has a time column")

    # values: spikes, absurd magnitudes, time order, gaps
    keep = np.ones(lines.size, dtype=bool)
    limits = {"time": _MAX_TIME_S, "stroke": _MAX_STROKE_MM, "force": _MAX_FORCE_N}
    units_shown = {"time": "s", "stroke": "mm", "force": "N"}
    for role in ("time", "stroke", "force"):
        if channels[role]["source"] is None:
            continue
        x = values[role]
        name = channels[role]["source"]
        spikes = find_spikes(x)
        absurd = np.flatnonzero(np.abs(x) > limits[role])
        bad = np.union1d(spikes, absurd)
        if bad.size:
            i = int(bad[0])
            nb = [x[j] for j in (i - 1, i + 1) if 0 <= j < x.size and j not in set(bad[:20].tolist())]
            around = f" where the neighbours read {', '.join(_fmt(v) for v in nb)} {units_shown[role]}" if nb else ""
            where = _lines_text(lines[bad].tolist())
            if not repair:
                raise ReadError(
                    f"isolated spike in column {name!r}: {_fmt(x[i])} {units_shown[role]}{around} "
                    f"({bad.size} such sample(s), at line(s) {where}); expected values in the "
                    "column's range (read with repair=True to drop them)",
                    label,
                    int(lines[i]),
                    name,
                )
            keep[bad] = False
            warnings.append(
                f"dropped {bad.size} spike sample(s) in column {name!r} at line(s) {where}"
            )
    if not keep.all():
        for role in values:
            values[role] = values[role][keep]
        lines = lines[keep]
        if counter is not None:
            counter = counter[keep]
    t = values["time"]
    if channels["time"]["source"] is not None:
        tp = time_problems(t)
        tname = channels["time"]["source"]
        if tp.backwards.size:
            i = int(tp.backwards[0])
            if not repair:
                raise ReadError(
                    f"time does not increase in column {tname!r}: {_fmt(t[i - 1])} s then "
                    f"{_fmt(t[i])} s ({tp.backwards.size} sample(s), at line(s) "
                    f"{_lines_text(lines[tp.backwards].tolist())}); expected increasing time "
                    "(read with repair=True to drop such samples)",
                    label,
                    int(lines[i]),
                    tname,
                )
            warnings.append(
                f"dropped {tp.backwards.size} sample(s) where time does not increase, at line(s) "
                f"{_lines_text(lines[tp.backwards].tolist())}"
            )
            k2 = np.ones(t.size, dtype=bool)
            k2[tp.backwards] = False
            for role in values:
                values[role] = values[role][k2]
            lines = lines[k2]
            if counter is not None:
                counter = counter[k2]
            t = values["time"]
            tp = time_problems(t)
        if tp.gaps.size:
            i = int(tp.gaps[0])
            gap = t[i] - t[i - 1]
            msg = (
                f"gap in the sampling: {_fmt(gap)} s between line {int(lines[i - 1])} and line "
                f"{int(lines[i])} against a median step of {_fmt(tp.median_step_s)} s "
                f"({tp.gaps.size} gap(s), at line(s) {_lines_text(lines[tp.gaps].tolist())})"
            )
            if not repair:
                raise ReadError(
                    msg + "; expected regular sampling (read with repair=True to accept the gaps)",
                    label,
                    int(lines[i]),
                    tname,
                )
            warnings.append(msg + "; kept (no samples to restore)")
    if values["time"].size < 2:
        raise ReadError(
            f"only {values['time'].size} sample(s) left after the checks; expected at least 2",
            label,
            blk.header_line,
        )

    if counter is not None and not np.isfinite(counter).all():
        bad_line = data.counter_bad_line
        warnings.append(
            f"cycle counter {ch.counter.source!r} has non-numeric cells"  # type: ignore[union-attr]
            + (f" (line {bad_line})" if bad_line else "")
            + "; not used"
        )
        counter = None
    counter_source = ch.counter.source if (counter is not None and ch.counter) else None

    frame = pd.DataFrame(
        {"time_s": values.pop("time"), "stroke_mm": values.pop("stroke"),
         "force_n": values.pop("force")},
        copy=False,
    )  # fmt: skip

    # metadata and pressure
    metadata: dict[str, str] = {}
    meta_pressure: float | None = None
    for ln, item in p.meta_items(blk.header_line):
        shown_value = item.shown
        metadata.setdefault(item.key, shown_value)
        if pressure_kpa is None and meta_pressure is None and shown_value:
            is_p, key_unit = is_pressure_key(item.key)
            if is_p:
                try:
                    meta_pressure = parse_pressure(shown_value, key_unit)
                except ReadError as exc:
                    raise ReadError(
                        f"metadata {item.key!r}: {exc.message}", label, ln, item.key
                    ) from None
                if _pressure_out_of_range(meta_pressure):
                    raise ReadError(
                        f"metadata {item.key!r}: pressure {_fmt(meta_pressure)} kPa is out of "
                        f"range; {_RANGE_TEXT}",
                        label,
                        ln,
                        item.key,
                    )
    pressure: float | None
    psource: str | None
    if pressure_kpa is not None:
        pressure, psource = pressure_kpa, "option"
    elif meta_pressure is not None:
        pressure, psource = meta_pressure, "metadata"
    else:
        pressure = pressure_from_filename(path.name)
        psource = "filename" if pressure is not None else None
        if pressure is not None and _pressure_out_of_range(pressure):
            raise ReadError(
                f"pressure {_fmt(pressure)} kPa in the file name is out of range; {_RANGE_TEXT}",
                label,
            )

    # what else the file holds
    if len(p.blocks) > 1:
        others = [b for b in p.blocks if b is not blk]
        warnings.append(
            f"the file holds {len(p.blocks)} data blocks; read the one at {blk.describe()}; "
            f"not read: {'; '.join(b.describe() for b in others)}"
        )
    if p.trailing:
        ln, line = p.trailing[0]
        warnings.append(
            f"{len(p.trailing)} text line(s) after the data were not read (line {ln}: "
            f"{show(line.strip())})"
        )
    if any("\ufffd" in line for _ln, line in p.text[:200]) or any("\ufffd" in n for n in blk.names):
        warnings.append(
            f"undecodable bytes in the text (decoded as {parsed.source.encoding}, shown as "
            "U+FFFD); names were matched without them"
        )
    used = {id(c) for c in ch.chosen.values()}
    # a bare number without a unit as a column name is a specimen index (Bluehill Universal)
    other_columns = [c.source for c in blk.columns if c.source and id(c) not in used
                     and not (c.source.isdigit() and not c.unit)]  # fmt: skip
    fmt = dialect or _classify_format(p, blk, parsed.source)
    blocks = [
        {"line": b.header_line, "columns": [n for n in b.names if n], "rows": b.n_rows,
         "read": b is blk}
        for b in p.blocks
    ]  # fmt: skip
    if parsed.source.is_excel:
        metadata.setdefault("sheet", parsed.source.sheet or "")
    return RawTest(
        data=frame,
        path=path,
        dialect=fmt,
        metadata=metadata,
        pressure_kpa=pressure,
        pressure_source=psource,
        source_units=source_units,
        encoding=parsed.source.encoding,
        delimiter=blk.sep,
        decimal=blk.decimal,
        header_line=blk.header_line,
        channels={r: channels[r] for r in ROLES},
        other_columns=other_columns,
        warnings=warnings,
        cycle_counter=counter,
        cycle_counter_source=counter_source,
        blocks=blocks,
        sample_rate_hz=sample_rate,
    )


def _check_options(pressure_kpa: float | None, dialect: str | None, rate_hz: float | None
                   ) -> tuple[float | None, float | None]:  # fmt: skip
    from bendpam.errors import InputError

    if dialect is not None and dialect not in FORMATS:
        raise InputError(f"unknown dialect {dialect!r}; expected one of {', '.join(FORMATS)}")
    if pressure_kpa is not None:
        try:
            pressure_kpa = float(pressure_kpa)
        except (TypeError, ValueError):
            raise InputError(f"pressure_kpa must be a number in kPa, got {pressure_kpa!r}") from None
        if not math.isfinite(pressure_kpa):
            raise InputError(f"pressure_kpa must be finite, got {pressure_kpa!r}")
        if _pressure_out_of_range(pressure_kpa):
            raise InputError(f"pressure_kpa = {pressure_kpa:g} is out of range; {_RANGE_TEXT}")
    if rate_hz is not None:
        try:
            rate_hz = float(rate_hz)
        except (TypeError, ValueError):
            raise InputError(f"rate_hz must be a number in Hz, got {rate_hz!r}") from None
        if not (math.isfinite(rate_hz) and 0 < rate_hz <= 1e7):
            raise InputError(f"rate_hz = {rate_hz!r} is out of range; expected 0 < rate <= 1e7 Hz")
    return pressure_kpa, rate_hz


def read_test(
    path: str | os.PathLike,
    *,
    pressure_kpa: float | None = None,
    dialect: str | None = None,
    columns: Mapping[str, str] | str | None = None,
    rate_hz: float | None = None,
    repair: bool = False,
) -> RawTest:
    """Read one raw four-point-bending test export.

    Parameters
    ----------
    path : str or os.PathLike
        The export: text (CSV/TXT/DAT/TRA from Zwick testXpert, Instron Bluehill, WaveMatrix
        or console, MTS 793 or TestSuite, Shimadzu Trapezium, plain CSV) or an ``.xlsx``/
        ``.xls`` workbook (extra ``excel``).
    pressure_kpa : float, optional
        Inflation pressure in kPa (0 to 10 000).  Overrides a pressure in the metadata or the
        file name.
    dialect : str, optional
        Force the reported format (one of :data:`FORMATS`).  ``"testxpert"`` also makes the
        decimal comma the default when the data do not show the decimal mark.
    columns : mapping or str, optional
        Columns to use, overriding the automatic choice: ``{"time": NAME, "stroke": NAME,
        "force": NAME}`` (any subset) or ``"time=NAME,stroke=NAME,force=NAME"``.
    rate_hz : float, optional
        Sampling rate (Hz) for a file without a time column.
    repair : bool
        Drop spikes, samples where time does not increase and rows with non-finite values,
        and accept gaps, reporting each in :attr:`RawTest.warnings` (default: refuse them).

    Returns
    -------
    RawTest
        Time in s, stroke in mm and force in N, with the metadata, the pressure in kPa and a
        record of how the file was read.

    Raises
    ------
    ReadError
        For anything that makes the file unreadable, with a one-line ``FILE:LINE: ...`` message.
    bendpam.errors.InputError
        (a ``ValueError``) for a bad option: unknown ``dialect``, a non-finite or out-of-range
        ``pressure_kpa`` or ``rate_hz``, a malformed ``columns``.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "be_150kPa.csv"
    ...     _ = path.write_text("time_s,stroke_mm,force_n\\n0,0.000,11.80\\n0.05,0.027,11.71\\n0.1,0.051,11.54\\n")
    ...     raw = read_test(path)
    >>> raw.dialect, len(raw), raw.pressure_kpa, raw.pressure_source
    ('csv', 3, 150.0, 'filename')
    >>> raw.data["force_n"].tolist()                     # N
    [11.8, 11.71, 11.54]
    """
    pressure_kpa, rate_hz = _check_options(pressure_kpa, dialect, rate_hz)
    overrides = parse_columns(columns)
    p = Path(path)
    parsed = _parse_path(p, dialect=dialect, overrides=overrides, rate_hz=rate_hz, repair=repair)
    return _assemble(parsed, pressure_kpa=pressure_kpa, dialect=dialect, rate_hz=rate_hz,
                     repair=repair)  # fmt: skip


def _text_source(path_or_text_lines: Any) -> tuple[list[_Source] | None, Path | None]:
    if isinstance(path_or_text_lines, os.PathLike) or (
        isinstance(path_or_text_lines, str) and not re.search(r"[\r\n]", path_or_text_lines)
    ):
        return None, Path(path_or_text_lines)
    if isinstance(path_or_text_lines, str):
        text = path_or_text_lines
    elif isinstance(path_or_text_lines, Iterable):
        text = "\n".join(str(s).rstrip("\r\n") for s in path_or_text_lines)
    else:
        raise TypeError(
            f"expected a path or an iterable of text lines, got {type(path_or_text_lines).__name__}"
        )
    label = "<text>"
    if not text.strip():
        raise ReadError("no text; expected a header row and data rows", label)
    _check_text_head(text, label)
    lines = io.StringIO(text, newline=None)
    first = text.lstrip("\ufeff").splitlines()[0] if text.strip() else ""
    return [_Source(label, "str", lines, first)], None


def detect_dialect(path_or_text_lines: str | os.PathLike | Iterable[str]) -> str:
    """Format of a raw test export, from its content (never from the extension).

    Parameters
    ----------
    path_or_text_lines : str, os.PathLike or iterable of str
        A file path, or the file's lines (a single string containing line breaks is taken as
        the text itself).

    Returns
    -------
    str
        One of :data:`FORMATS`.

    Raises
    ------
    ReadError
        If no data block with time (or a rate), stroke and force is found.

    Examples
    --------
    >>> detect_dialect("Test time;Standard travel;Standard force\\ns;mm;N\\n0;0,000;11,80\\n0,05;0,027;11,71\\n")
    'testxpert'
    """
    sources, path = _text_source(path_or_text_lines)
    kw: dict[str, Any] = {"dialect": None, "overrides": {}, "rate_hz": None, "repair": False,
                          "want_data": False}  # fmt: skip
    if sources is None:
        assert path is not None
        parsed = _parse_path(path, **kw)
    else:
        parsed = _parse_source(sources[0], **kw)
    return _classify_format(parsed.parser, parsed.block, parsed.source)


# ------------------------------------------------------------------------------------------------
# cycle counters
# ------------------------------------------------------------------------------------------------
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
        A test read by :func:`read_test`.
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
        f"cycle(s) (from {_fmt(float(c.min()))} to {_fmt(float(c.max()))}) but the segmentation "
        f"found {int(n_cycles_found)}; check the reversal threshold or the record"
    )


# ------------------------------------------------------------------------------------------------
# inspection
# ------------------------------------------------------------------------------------------------
def _finite_or_none(v: Any) -> float | None:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


def inspect_file(
    path: str | os.PathLike,
    *,
    pressure_kpa: float | None = None,
    columns: Mapping[str, str] | str | None = None,
    rate_hz: float | None = None,
    repair: bool = False,
) -> dict[str, Any]:
    """How a raw test export reads, as a JSON-ready dict (never raises for a bad file).

    Parameters
    ----------
    path : str or os.PathLike
        The export.
    pressure_kpa, columns, rate_hz, repair
        As for :func:`read_test`.

    Returns
    -------
    dict
        ``{"file", "format", "encoding", "delimiter", "decimal", "header_line", "n_samples",
        "columns": {"time": {"source", "unit"}, "stroke": {...}, "force": {...}},
        "other_columns", "first": {"time_s", "stroke_mm", "force_n"}, "last": {...},
        "metadata", "pressure_kpa", "cycle_counter": {"source", "max"} or None, "warnings"}``;
        for a file that cannot be read ``{"file", "error"}``.  No NaN or infinity anywhere
        (None instead).  Values are in s, mm, N and kPa.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "be_150kPa.csv"
    ...     _ = path.write_text("time_s,stroke_mm,force_n\\n0,0.000,11.80\\n0.05,0.027,11.71\\n")
    ...     info = inspect_file(path)
    ...     bad = inspect_file(Path(folder) / "missing.csv")
    >>> info["format"], info["n_samples"], info["columns"]["force"], info["pressure_kpa"]
    ('csv', 2, {'source': 'force_n', 'unit': 'N'}, 150.0)
    >>> sorted(bad)
    ['error', 'file']
    """
    from bendpam.errors import BendpamError

    name = os.fspath(path)
    try:
        raw = read_test(path, pressure_kpa=pressure_kpa, columns=columns, rate_hz=rate_hz,
                        repair=repair)  # fmt: skip
    except (BendpamError, ValueError, OSError) as exc:
        return {"file": name, "error": str(exc)}
    d = raw.data

    def row(i: int) -> dict[str, float | None]:
        return {c: _finite_or_none(d[c].iat[i]) for c in COLUMNS}

    counter = None
    if raw.cycle_counter is not None:
        c = raw.cycle_counter[np.isfinite(raw.cycle_counter)]
        counter = {"source": raw.cycle_counter_source,
                   "max": _finite_or_none(c.max()) if c.size else None}  # fmt: skip
    return {
        "file": name,
        "format": raw.dialect,
        "encoding": raw.encoding,
        "delimiter": raw.delimiter,
        "decimal": raw.decimal,
        "header_line": raw.header_line,
        "n_samples": len(d),
        "columns": {
            r: {"source": raw.channels[r]["source"], "unit": raw.channels[r]["unit"]} for r in ROLES
        },
        "other_columns": list(raw.other_columns),
        "first": row(0),
        "last": row(len(d) - 1),
        "metadata": dict(raw.metadata),
        "pressure_kpa": _finite_or_none(raw.pressure_kpa) if raw.pressure_kpa is not None else None,
        "cycle_counter": counter,
        "warnings": list(raw.warnings),
    }


_DELIM_NAMES = {"\t": "tab", ";": "';'", ",": "','", " ": "space"}


def format_inspection(info: Mapping[str, Any]) -> str:
    """A short readable multi-line summary of one :func:`inspect_file` result.

    >>> info = {"file": "be_150kPa.csv", "format": "csv", "encoding": "utf-8", "delimiter": ",",
    ...         "decimal": ".", "header_line": 1, "n_samples": 2,
    ...         "columns": {r: {"source": f"{r}_col", "unit": u} for r, u in (("time", "s"), ("stroke", "mm"),
    ...                                                                       ("force", "N"))},
    ...         "first": {"time_s": 0.0, "stroke_mm": 0.0, "force_n": 11.8},
    ...         "last": {"time_s": 0.05, "stroke_mm": 0.027, "force_n": 11.71}, "pressure_kpa": 150.0}
    >>> print(format_inspection(info))
    be_150kPa.csv
      format csv, encoding utf-8, delimiter ',', decimal '.', header at line 1
      2 samples
      time   <- 'time_col' (s)
      stroke <- 'stroke_col' (mm)
      force  <- 'force_col' (N)
      first: 0 s, 0 mm, 11.8 N
      last:  0.05 s, 0.027 mm, 11.71 N
      pressure: 150 kPa
    """
    name = info.get("file", "?")
    if "error" in info:
        return f"{name}\n  error: {info['error']}"
    out = [str(name)]
    delim = _DELIM_NAMES.get(str(info.get("delimiter")), repr(info.get("delimiter")))
    out.append(
        f"  format {info.get('format')}, encoding {info.get('encoding')}, delimiter {delim}, "
        f"decimal {info.get('decimal')!r}, header at line {info.get('header_line')}"
    )
    out.append(f"  {info.get('n_samples')} samples")
    cols = info.get("columns") or {}
    for role in ROLES:
        c = cols.get(role) or {}
        src = c.get("source")
        out.append(f"  {role:<6} <- {src!r} ({c.get('unit')})" if src is not None
                   else f"  {role:<6} <- made from a sampling rate")  # fmt: skip
    first, last = info.get("first") or {}, info.get("last") or {}

    def triple(r: Mapping[str, Any]) -> str:
        vals = []
        for key, unit in (("time_s", "s"), ("stroke_mm", "mm"), ("force_n", "N")):
            v = r.get(key)
            vals.append(f"{v:.6g} {unit}" if isinstance(v, (int, float)) else f"? {unit}")
        return ", ".join(vals)

    out.append(f"  first: {triple(first)}")
    out.append(f"  last:  {triple(last)}")
    others = info.get("other_columns") or []
    if others:
        shown = ", ".join(others[:8]) + (", ..." if len(others) > 8 else "")
        out.append(f"  other columns: {shown}")
    p = info.get("pressure_kpa")
    out.append(f"  pressure: {p:g} kPa" if isinstance(p, (int, float)) else "  pressure: unknown")
    cc = info.get("cycle_counter")
    if cc:
        out.append(f"  cycle counter: {cc.get('source')!r} (max {cc.get('max')})")
    for w in info.get("warnings") or []:
        out.append(f"  warning: {w}")
    return "\n".join(out)

