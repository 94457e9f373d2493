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

The numeric block is read in blocks of text (about 2 MB, no string per line) by the C parser of
:func:`pandas.read_csv`, into buffers sized from the bytes left in the file, so a 450 MB export
is read in bounded memory and linear time, in about 2x the time of :func:`pandas.read_csv`; a block
the C parser cannot read is read in pieces of 2000 lines, and only the odd piece line by line,
which finds the offending line.  Every failure is a :class:`ReadError`
whose message is one line ``FILE:LINE: what was wrong, what was expected``.

The steps live in their own modules: :mod:`bendpam.lab.source` (file to lines),
:mod:`bendpam.lab.parser` (lines to blocks, metadata and numbers), :mod:`bendpam.lab.assemble`
(numbers to a :class:`~bendpam.lab.rawtest.RawTest`, units and values checked),
:mod:`bendpam.lab.pressure` (the pressure from a value, a metadata line or a file name).  This
module holds the entry points and the naming of the format.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.infra.manifest import verify_input
from bendpam.lab.assemble import assemble
from bendpam.lab.channels import FORCE_UNITS, LENGTH_UNITS, ROLES, TIME_UNITS
from bendpam.lab.parser import Parsed, parse_path, parse_source
from bendpam.lab.pressure import (
    PRESSURE_KEYS,
    PRESSURE_RANGE_KPA,
    PRESSURE_RANGE_TEXT,
    PRESSURE_UNITS,
    is_pressure_key,
    parse_pressure,
    pressure_from_filename,
    pressure_out_of_range,
)
from bendpam.lab.rawtest import COLUMNS, DIALECTS, FORMATS, RawTest, check_cycle_count
from bendpam.lab.read_error import ReadError
from bendpam.lab.source import text_source

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
# format names
# ------------------------------------------------------------------------------------------------
_ZWICK = re.compile(r"prüfzeit|pruefzeit|standardweg|standardkraft|standard travel|standard force|"
                    r"traverse abs|testxpert|zwick")  # fmt: skip
_GERMAN = re.compile(r"zeit|kraft|weg\b")
_WAVEMATRIX = re.compile(r"total cycles|elapsed cycles|cycle elapsed time|digital position|"
                         r"wavematrix")  # fmt: skip
_TRAPEZIUM = re.compile(r"試験力|ストローク|trapezium|shimadzu")


def _classify_format(parsed: Parsed) -> str:
    p, blk, source = parsed.parser, parsed.block, parsed.source
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
        if pressure_out_of_range(pressure_kpa):
            raise InputError(f"pressure_kpa = {pressure_kpa:g} is out of range; {PRESSURE_RANGE_TEXT}")
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
    verify_input(p)  # raw files of a bendpam set (simulate-test) are read only as bendpam wrote them
    parsed = parse_path(p, dialect=dialect, overrides=overrides, rate_hz=rate_hz, repair=repair)
    fmt = dialect or _classify_format(parsed)
    return assemble(parsed, fmt=fmt, pressure_kpa=pressure_kpa, rate_hz=rate_hz, repair=repair)



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
    sources, path = text_source(path_or_text_lines)
    kw: dict[str, Any] = {"dialect": None, "overrides": {}, "rate_hz": None, "repair": False,
                          "want_data": False}  # fmt: skip
    if sources is None:
        assert path is not None
        parsed = parse_path(path, **kw)
    else:
        parsed = parse_source(sources[0], **kw)
    return _classify_format(parsed)



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

