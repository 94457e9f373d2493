"""Readers of raw four-point-bending exports from testing machines.

A raw test at one pressure is a time series of time (s), crosshead stroke (mm) and force (N).
:func:`read_test` reads it from the text export of a testing machine, detects the export
*dialect* from the content (never from the extension), converts the units and returns a
:class:`RawTest`.

Dialects
--------
``"csv"``
    Plain CSV: an optional block of ``# key: value`` comment lines, then a header row naming
    time, stroke and force (``time_s,stroke_mm,force_n`` or ``Time (s);Stroke [mm];Load (kN)``),
    then the numbers.  ``,``, ``;`` or tab separated, decimal point.
``"testxpert"``
    Zwick testXpert ASCII export: ``;``-separated, decimal comma, cp1252/latin-1 or UTF-8;
    ``$`` comment lines and ``Name;value;unit`` metadata lines, a names row (English or German:
    ``Prüfzeit;Standardweg;Standardkraft``) and a units row (``s;mm;N``).
``"bluehill"``
    Instron Bluehill CSV: every value quoted; ``"Name : value"`` metadata lines; a names row and
    a units row ``"(s)","(mm)","(kN)"`` or one header row ``"Time (s)","Extension (mm)",...``.
``"mts"``
    MTS TestSuite CSV/TXT: ``Key,Value`` / ``Key: Value`` / tab-separated metadata lines, a
    names row (``Time,Crosshead,Force``) and usually a units row (``sec,mm,kN``).

Every failure is a :class:`ReadError` whose message is one line ``FILE:LINE: what was wrong,
what was expected``.  The numeric block is read by the C parser of :func:`pandas.read_csv`;
only when that fails is the text re-scanned line by line to find the offending line and column.
"""

from __future__ import annotations

from ..errors import FileFormatError

import csv
import io
import math
import os
import re
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

__all__ = [
    "COLUMNS",
    "DIALECTS",
    "RawTest",
    "ReadError",
    "detect_dialect",
    "parse_pressure",
    "pressure_from_filename",
    "read_test",
]

#: Column names of :attr:`RawTest.data`, in order: time in s, stroke in mm, force in N.
COLUMNS: tuple[str, str, str] = ("time_s", "stroke_mm", "force_n")
#: Names of the dialects :func:`read_test` understands (and :func:`write_test` writes).
DIALECTS: tuple[str, ...] = ("csv", "testxpert", "bluehill", "mts")

_ROLES = ("time", "stroke", "force")
_ROLE_COLUMN = dict(zip(_ROLES, COLUMNS))
_DEFAULT_UNIT = {"time": "s", "stroke": "mm", "force": "N"}

# Unit -> factor to s, mm, N.  Keys are lower case; "mn" is milli-newton (never mega-newton).
TIME_UNITS: dict[str, float] = {
    "s": 1.0, "sec": 1.0, "secs": 1.0, "second": 1.0, "seconds": 1.0,
    "ms": 1e-3, "msec": 1e-3,
    "min": 60.0, "mins": 60.0, "minute": 60.0, "minutes": 60.0,
    "h": 3600.0, "hr": 3600.0, "hrs": 3600.0, "hour": 3600.0, "hours": 3600.0,
}  # fmt: skip
LENGTH_UNITS: dict[str, float] = {
    "m": 1000.0, "cm": 10.0, "mm": 1.0,
    "µm": 1e-3, "μm": 1e-3, "um": 1e-3, "micron": 1e-3, "microns": 1e-3,
    "in": 25.4, "inch": 25.4, "inches": 25.4,
}  # fmt: skip
FORCE_UNITS: dict[str, float] = {
    "n": 1.0, "newton": 1.0, "newtons": 1.0,
    "kn": 1000.0, "mn": 1e-3, "dan": 10.0,
    "lbf": 4.4482216152605, "kgf": 9.80665,
}  # fmt: skip
_UNIT_TABLES = {"time": TIME_UNITS, "stroke": LENGTH_UNITS, "force": FORCE_UNITS}
_UNIT_HINT = {
    "time": "s, sec, ms, min or h",
    "stroke": "m, cm, mm, µm/um or in",
    "force": "N, kN, mN or lbf",
}
_ALL_UNITS = set(TIME_UNITS) | set(LENGTH_UNITS) | set(FORCE_UNITS)

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
        "fülldruck", "versorgungsdruck", "prüfdruck", "luftdruck",
    }
)  # fmt: skip

_ACCEPTED_NAMES = (
    "time: 'time', 'zeit' (e.g. 'time_s', 'Time (s)', 'Test time', 'Prüfzeit'); "
    "stroke: 'stroke', 'travel', 'displacement', 'extension', 'position', 'crosshead', "
    "'deflection', 'weg' (e.g. 'stroke [mm]', 'Standard travel', 'Standardweg'); "
    "force: 'force', 'load', 'kraft' (e.g. 'force_n', 'Load (kN)', 'Standardkraft')"
)

_MAX_PREAMBLE_LINES = 5000  # non-data lines scanned for a header before giving up
_N_SAMPLE_ROWS = 50  # data rows inspected for the decimal separator and quoting
_NL = re.compile(r"\r\n|\r|\n")
_NUM = re.compile(r"[+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][+-]?\d+)?")
_NUM_DOT = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_NUM_COMMA = re.compile(r"[+-]?(?:\d+,?\d*|,\d+)(?:[eE][+-]?\d+)?")
_COMMA_DECIMAL = re.compile(r"\d,\d")
_DOT_DECIMAL = re.compile(r"\d\.\d")
_BRACKET_UNIT = re.compile(r"(.*?)\s*[(\[]\s*(.*?)\s*[)\]]")
_SUFFIX_UNIT = re.compile(r"(.+?)_([^\W\d_]+)")
_CONTROL = re.compile(r"[\x00-\x08\x0e-\x19\x1b-\x1f\x7f]")
_STROKE_WORDS = (
    "stroke", "travel", "displacement", "extension", "position", "crosshead", "cross-head",
    "deflection", "traverse", "elongation",
)  # fmt: skip
_FORCE_WORDS = ("force", "load", "kraft")
_WEG = re.compile(r"weg\b")
_FILE_PRESSURE = re.compile(
    r"(?<![\d.,])(\d+(?:[.,]\d+)?)\s?(kpa|mpa|hpa|mbar|bar|psi|pa)(?![a-z])", re.IGNORECASE
)
_PRESSURE_VALUE = re.compile(
    r"\s*([+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][+-]?\d+)?)\s*([^\d\s].*?)?\s*"
)


# ------------------------------------------------------------------------------------------------
# public types
# ------------------------------------------------------------------------------------------------
def _one_line(text: str) -> str:
    """Collapse any line break in ``text`` to a space."""
    return " ".join(str(text).splitlines()) if text else ""


def _show(value: str, limit: int = 40) -> str:
    """``repr`` of a cell value for a message, shortened to about ``limit`` characters."""
    if len(value) > limit:
        value = value[:limit] + "..."
    return repr(value)


class ReadError(FileFormatError):
    """A raw test file that cannot be read.

    ``str(err)`` is one line ``FILE:LINE: what was wrong, what was expected`` (``LINE`` is
    1-based and left out when it does not apply; ``FILE:`` is left out when there is no file).

    Parameters
    ----------
    message : str
        What was wrong and what was expected.
    path : str or os.PathLike, optional
        The file.
    line : int, optional
        1-based line number in the file.
    column : str, optional
        Name of the column (as written in the file) the error is about.

    Attributes
    ----------
    path : pathlib.Path or None
    line : int or None
    column : str or None
    message : str
        The message without the ``FILE:LINE:`` prefix.
    """

    def __init__(
        self,
        message: str,
        path: str | os.PathLike | None = None,
        line: int | None = None,
        column: str | None = None,
    ) -> None:
        self.message = _one_line(message)
        self.path = Path(path) if path is not None else None
        self.line = int(line) if line is not None else None
        self.column = column
        super().__init__(self._format())

    def _format(self) -> str:
        if self.path is None:
            prefix = f"line {self.line}: " if self.line is not None else ""
        else:
            loc = _one_line(os.fspath(self.path))
            prefix = f"{loc}:{self.line}: " if self.line is not None else f"{loc}: "
        return prefix + self.message

    def __str__(self) -> str:
        return self._format()

    def __reduce__(self):
        return (type(self), (self.message, self.path, self.line, self.column))


@dataclass(frozen=True, eq=False)
class RawTest:
    """One raw four-point-bending test at one pressure, in SI-ish library units.

    Attributes
    ----------
    data : pandas.DataFrame
        Columns exactly ``["time_s", "stroke_mm", "force_n"]`` (time in s, crosshead stroke in
        mm, force in N), float64, finite, in file order, index ``0..n-1``.
    path : pathlib.Path
        The file read.
    dialect : str
        ``"csv"``, ``"testxpert"``, ``"bluehill"`` or ``"mts"``.
    metadata : dict of str to str
        Metadata name -> raw value string as written in the file (with the unit appended after
        a space when the file gave one in its own field), in file order.
    pressure_kpa : float or None
        Inflation pressure in kPa, if known.
    pressure_source : str or None
        Where ``pressure_kpa`` came from: ``"option"`` (the ``pressure_kpa`` argument),
        ``"metadata"`` (a Pressure/Druck line), ``"filename"`` (a token like ``200kPa``) or None.
    source_units : dict of str to str
        Unit of each column in the file, e.g. ``{"time_s": "s", "stroke_mm": "mm",
        "force_n": "kN"}`` (the assumed default s, mm, N when the file gave none).

    Notes
    -----
    The class is frozen but compares by identity (``eq=False``): DataFrames have no single
    truth value, so a field-wise ``==`` would be meaningless.
    """

    data: pd.DataFrame
    path: Path
    dialect: str
    metadata: dict[str, str] = field(default_factory=dict)
    pressure_kpa: float | None = None
    pressure_source: str | None = None
    source_units: dict[str, str] = field(default_factory=dict)

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
        The pressure in kPa.

    Raises
    ------
    ReadError
        (a ``ValueError``) if the value is not a finite number, has no unit, or the unit is
        unknown, or ``value`` and ``unit`` name different units.
    """
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
        number, text_unit, shown = float(value), "", repr(value)
    else:
        shown = _show(str(value))
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
            f"unknown pressure unit {_show(u)} in {shown}; expected kPa, MPa, bar, mbar, Pa or psi"
        )
    kpa = number * factor
    if not math.isfinite(kpa):
        raise ReadError(f"pressure {shown} is not finite; expected a finite number")
    return kpa


def pressure_from_filename(name: str | os.PathLike) -> float | None:
    """Pressure in kPa encoded as a token in a file name, or None.

    Recognises ``200kPa``, ``0.2MPa``, ``2bar``, ``2,5bar``, ``200000Pa``, ``29psi`` (any
    case), also inside other text (``x200kPa_y``); the number must not be glued to a preceding
    digit or decimal mark and the unit must not run on into further letters (``2bars`` is not a
    token).  Only the last path component is looked at; the first token wins.

    Parameters
    ----------
    name : str or os.PathLike
        File name or path.

    Returns
    -------
    float or None
        Pressure in kPa.
    """
    base = Path(os.fspath(name)).name if str(name) else ""
    for m in _FILE_PRESSURE.finditer(base):
        kpa = float(m.group(1).replace(",", ".")) * PRESSURE_UNITS[m.group(2).lower()]
        if math.isfinite(kpa):
            return kpa
    return None


def _pressure_key(key: str) -> tuple[bool, str | None]:
    """Is ``key`` a pressure metadata name?  Also return its unit (``Pressure (kPa)``)."""
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
# text level helpers
# ------------------------------------------------------------------------------------------------
def _iter_lines(text: str, pos: int = 0, lineno: int = 1) -> Iterator[tuple[int, int, str]]:
    """Yield ``(lineno, start, line)``; lines end at ``\\r\\n``, ``\\r`` or ``\\n`` like pandas."""
    n = len(text)
    search = _NL.search
    while pos < n:
        m = search(text, pos)
        if m is None:
            yield lineno, pos, text[pos:]
            return
        yield lineno, pos, text[pos : m.start()]
        pos = m.end()
        lineno += 1


def _split(line: str, sep: str | None) -> list[str]:
    """Split one line at ``sep`` honouring double quotes; cells are stripped and unquoted."""
    if sep is None:
        return [line.strip().strip('"').strip()]
    if '"' not in line:
        return [c.strip() for c in line.split(sep)]
    try:
        cells = next(csv.reader([line], delimiter=sep, quotechar='"', skipinitialspace=True), [])
    except csv.Error:
        return [c.strip().strip('"').strip() for c in line.split(sep)]
    return [c.strip() for c in cells]


def _guess_sep(line: str, prefer: str | None = None) -> str | None:
    for cand in ("\t", prefer, ";", ","):
        if cand and cand in line:
            return cand
    return None


def _is_number(cell: str) -> bool:
    return _NUM.fullmatch(cell) is not None


def _is_numeric_row(line: str) -> bool:
    """At least two cells, all non-empty cells numbers (decimal point or comma)."""
    sep = _guess_sep(line)
    if sep is None:
        return False
    cells = [c for c in _split(line, sep) if c]
    return len(cells) >= 2 and all(_is_number(c) for c in cells)


def _is_blank(line: str, sep: str) -> bool:
    """Empty, or only separators, quotes and whitespace (e.g. ``;;;`` rows from spreadsheets)."""
    return not line.strip(' \t"\x1a\x0c\x0b' + sep)


def _split_name_unit(cell: str) -> tuple[str, str | None]:
    """``'Time (s)'`` -> ``('Time', 's')``; ``'force_kN'`` -> ``('force', 'kN')``."""
    s = cell.strip().strip('"').strip()
    m = _BRACKET_UNIT.fullmatch(s)
    if m:
        return m.group(1).strip(), m.group(2).strip()
    m = _SUFFIX_UNIT.fullmatch(s)
    if m and m.group(2).lower() in _ALL_UNITS:
        return m.group(1).strip(), m.group(2)
    return s, None


def _unit_cell(cell: str) -> str:
    """Unit text of a units-row cell: ``'(kN)'`` -> ``'kN'``."""
    s = cell.strip().strip('"').strip()
    m = re.fullmatch(r"[(\[]\s*(.*?)\s*[)\]]", s)
    return m.group(1) if m else s


def _role_of(name: str) -> str | None:
    n = " ".join(name.lower().split())
    if not n or _is_number(n):
        return None
    if n == "t" or "time" in n or "zeit" in n:
        return "time"
    if any(w in n for w in _STROKE_WORDS) or _WEG.search(n):
        return "stroke"
    if any(w in n for w in _FORCE_WORDS):
        return "force"
    return None


_FORCE_SPELLING = {"n": "N", "kn": "kN", "mn": "mN", "dan": "daN", "newton": "N", "newtons": "N"}


def _canonical_unit(role: str, unit: str) -> str:
    """Unit as written, with the case fixed: ``'n'`` -> ``'N'``, ``'MM'`` -> ``'mm'``."""
    u = unit.strip()
    if role == "force":
        return _FORCE_SPELLING.get(u.lower(), u)
    return u.lower()


def _unit_factor(role: str, unit: str) -> float | None:
    table = _UNIT_TABLES[role]
    u = unit.strip()
    f = table.get(u.lower())
    if f is None and u.endswith("."):  # 'sec.'
        f = table.get(u[:-1].lower())
    return f


# ------------------------------------------------------------------------------------------------
# reading the file
# ------------------------------------------------------------------------------------------------
def _load_text(path: Path) -> str:
    """Read and decode ``path``: UTF-8 (BOM optional), UTF-16 with BOM, else cp1252/latin-1."""
    try:
        raw = path.read_bytes()
    except FileNotFoundError:
        raise ReadError("file not found; expected an existing raw test export", path) from None
    except IsADirectoryError:
        raise ReadError("is a directory; expected a raw test export file", path) from None
    except PermissionError:
        raise ReadError("permission denied; cannot read the file", path) from None
    except OSError as exc:
        raise ReadError(f"cannot read the file ({exc.strerror or exc})", path) from None
    if not raw:
        raise ReadError("file is empty; expected a header row and data rows", path)
    if raw[:2] in (b"\xff\xfe", b"\xfe\xff"):
        try:
            text = raw.decode("utf-16")
        except UnicodeDecodeError as exc:
            line = raw.count(b"\n", 0, exc.start) // 2 + 1
            raise ReadError("undecodable UTF-16 text; expected a text export", path, line) from None
    else:
        nul = raw.find(b"\x00")
        if nul >= 0:
            raise ReadError(
                "binary data (NUL byte); expected a text export (CSV/TXT), not e.g. an .xlsx or "
                "a proprietary test file",
                path,
                raw.count(b"\n", 0, nul) + 1,
            )
        try:
            text = raw.decode("utf-8-sig")
        except UnicodeDecodeError:
            try:
                text = raw.decode("cp1252")
            except UnicodeDecodeError:
                text = raw.decode("latin-1")
    return _check_text(text, path)


def _check_text(text: str, path: Path | str) -> str:
    if "\x00" in text:
        raise ReadError(
            "binary data (NUL character); expected a text export (CSV/TXT)",
            path,
            text.count("\n", 0, text.index("\x00")) + 1,
        )
    head = text[:65536]
    bad = _CONTROL.findall(head)
    if len(bad) > max(2, len(head) // 100):
        first = _CONTROL.search(head).start()  # type: ignore[union-attr]
        raise ReadError(
            "binary data (control characters); expected a text export (CSV/TXT)",
            path,
            head.count("\n", 0, first) + 1,
        )
    if not text.strip():
        raise ReadError("file contains only whitespace; expected a header row and data rows", path)
    return text


@dataclass
class _Header:
    sep: str
    cells: list[str]
    roles: dict[str, int]
    units: dict[str, str | None]
    line: int = 0
    raw: str = ""

    def column(self, role: str) -> str:
        return self.cells[self.roles[role]]


@dataclass
class _Layout:
    """Where things are in a file: found by :func:`_scan` without reading the numeric block."""

    header: _Header
    meta_lines: list[tuple[int, str, bool]]  # (lineno, text, from '#' comment)
    dollar: bool
    units_line: int | None
    units_cells: list[str] | None
    data_line: int | None  # first line of the numeric block
    data_offset: int | None
    samples: list[tuple[int, str, list[str]]]  # first data rows (lineno, raw, cells)
    decimal_evidence: str | None

    def dialect(self) -> str:
        h = self.header
        names = " ".join(h.column(r).lower() for r in _ROLES)
        german = any(w in names for w in ("zeit", "kraft")) or _WEG.search(names) is not None
        other_meta = any(not is_hash for _, _, is_hash in self.meta_lines)
        units_row = self.units_line is not None
        if self.dollar or (german and h.sep == ";"):
            return "testxpert"
        if h.sep == ";" and (self.decimal_evidence == "," or other_meta or units_row):
            return "testxpert"
        if self.samples and self.samples[0][1].lstrip().startswith('"'):
            return "bluehill"
        if (
            units_row
            and h.raw.lstrip().startswith('"')
            and self.units_cells
            and all(_unit_cell(c) != c.strip().strip('"') for c in self.units_cells if c.strip())
        ):
            return "bluehill"  # '"(s)","(mm)","(kN)"' units row
        if other_meta or units_row:
            return "mts"
        return "csv"

    def decimal(self, dialect: str) -> str:
        if self.decimal_evidence is not None:
            return self.decimal_evidence
        return "," if dialect == "testxpert" else "."


def _match_header(line: str) -> _Header | None:
    """Best reading of ``line`` as a header row (most roles found), or None."""
    best: _Header | None = None
    for sep in ("\t", ";", ","):
        if sep not in line:
            continue
        cells = _split(line, sep)
        roles: dict[str, int] = {}
        units: dict[str, str | None] = {}
        for i, cell in enumerate(cells):
            name, unit = _split_name_unit(cell)
            role = _role_of(name)
            if role is not None and role not in roles:
                roles[role] = i
                units[role] = unit
        if best is None or len(roles) > len(best.roles):
            best = _Header(sep, [c.strip().strip('"').strip() for c in cells], roles, units)
        if len(roles) == 3:
            break
    return best if best is not None and best.roles else None


def _scan(text: str, path: Path | str) -> _Layout:
    """Find metadata, header, units row and the start of the numeric block."""
    meta: list[tuple[int, str, bool]] = []
    dollar = False
    partial: _Header | None = None
    header: _Header | None = None
    lines = _iter_lines(text)
    n_pre = 0
    for lineno, _start, line in lines:
        s = line.strip()
        if not s:
            continue
        if s.startswith("$"):
            dollar = True
            continue
        if s.startswith("#"):
            meta.append((lineno, s.lstrip("#").strip(), True))
            continue
        h = _match_header(line)
        if h is not None:
            h.line, h.raw = lineno, line
            if len(h.roles) == 3:
                header = h
                break
            if len(h.roles) >= 2 and partial is None:
                partial = h
        if _is_numeric_row(line):
            _no_header(path, partial, lineno)
        meta.append((lineno, s, False))
        n_pre += 1
        if n_pre > _MAX_PREAMBLE_LINES:
            _no_header(path, partial, None, more=f" in the first {_MAX_PREAMBLE_LINES} lines")
    if header is None:
        _no_header(path, partial, None)
    assert header is not None

    sep = header.sep
    role_idx = [header.roles[r] for r in _ROLES]
    units_line = units_cells = data_line = data_offset = None
    samples: list[tuple[int, str, list[str]]] = []
    for lineno, start, line in lines:
        if _is_blank(line, sep):
            continue
        cells = _split(line, sep)
        if data_line is None:
            if units_line is None and not samples:
                role_cells = [cells[i] if i < len(cells) else "" for i in role_idx]
                if not any(_is_number(c.strip('"').strip()) for c in role_cells):
                    units_line, units_cells = lineno, cells
                    continue
            data_line, data_offset = lineno, start
        samples.append((lineno, line, cells))
        if len(samples) >= _N_SAMPLE_ROWS:
            break

    comma = dot = 0
    for _, _, cells in samples:
        for i in role_idx:
            if i < len(cells):
                c = cells[i]
                comma += _COMMA_DECIMAL.search(c) is not None
                dot += _DOT_DECIMAL.search(c) is not None
    evidence = "," if comma and not dot else "." if dot and not comma else None
    return _Layout(
        header, meta, dollar, units_line, units_cells, data_line, data_offset, samples, evidence
    )


def _no_header(path, partial: _Header | None, data_line: int | None, more: str = "") -> None:
    if partial is not None:
        found = ", ".join(f"{r} {partial.column(r)!r}" for r in _ROLES if r in partial.roles)
        missing = [r for r in _ROLES if r not in partial.roles]
        raise ReadError(
            f"header row has no {' or '.join(missing)} column (found {found}); expected a "
            f"column named after {' and '.join(missing)} (accepted names: {_ACCEPTED_NAMES})",
            path,
            partial.line,
            column=None,
        )
    where = " before the first data row" if data_line is not None else more
    raise ReadError(
        f"no header row naming time, stroke and force columns{where}; expected e.g. "
        f"'time_s,stroke_mm,force_n' (accepted names: {_ACCEPTED_NAMES})",
        path,
        data_line,
    )


def _parse_meta(text: str, sep: str) -> tuple[str, str, str] | None:
    """``(name, value, unit)`` of a metadata line, or None for a line without a value."""
    s = text.strip()
    cand = _guess_sep(s, sep)
    cells = _split(s, cand)
    while cells and not cells[-1]:
        cells.pop()
    if not cells:
        return None
    first = cells[0]
    if ":" in first and first.split(":", 1)[1].strip():
        whole = first if len(cells) == 1 else s  # one (unquoted) cell, or 'Key: a, b' split at ','
        key, value = whole.split(":", 1)
        key, value, unit = key.strip().strip('"'), value.strip(), ""
    elif len(cells) >= 2:
        key, value = first, cells[1]
        unit = cells[2] if len(cells) >= 3 else ""
    elif "=" in first:
        key, value = first.split("=", 1)
        unit = ""
    else:
        return None
    key = key.strip().rstrip(":=").strip()
    if not key:
        return None
    return key, value.strip(), unit.strip()


def _resolve_units(layout: _Layout, path) -> tuple[dict[str, str], dict[str, float]]:
    h = layout.header
    source: dict[str, str] = {}
    factors: dict[str, float] = {}
    for role in _ROLES:
        unit, line = h.units.get(role), h.line
        if layout.units_cells is not None:
            idx = h.roles[role]
            cell = _unit_cell(layout.units_cells[idx]) if idx < len(layout.units_cells) else ""
            if cell:
                unit, line = cell, layout.units_line
        if not unit:
            unit = _DEFAULT_UNIT[role]
        f = _unit_factor(role, unit)
        if f is None:
            raise ReadError(
                f"unknown {role} unit {_show(unit)} for column {h.column(role)!r}; expected "
                f"{_UNIT_HINT[role]}",
                path,
                line,
                h.column(role),
            )
        source[_ROLE_COLUMN[role]] = _canonical_unit(role, unit)
        factors[role] = f
    return source, factors


def _strip_trailing_blank(block: str, sep: str) -> str:
    """Drop trailing lines of only whitespace, separators or quotes, and the final newline."""
    end = len(block)
    while end > 0:
        e = end
        while e > 0 and block[e - 1] in "\r\n":
            e -= 1
        start = max(block.rfind("\n", 0, e), block.rfind("\r", 0, e)) + 1
        if start < e and not _is_blank(block[start:e], sep):
            return block[:e]
        end = start
    return ""


def _count_lines(block: str) -> int:
    if not block:
        return 0
    crlf = block.count("\r\n")
    return block.count("\n") + block.count("\r") - crlf + 1


def _parse_fast(block: str, layout: _Layout, decimal: str) -> np.ndarray | None:
    """The numeric block via ``pandas.read_csv(engine="c")``; None if anything looks wrong."""
    h = layout.header
    if h.sep == decimal:
        return None
    cols = [h.roles[r] for r in _ROLES]
    try:
        df = pd.read_csv(
            io.StringIO(block),
            sep=h.sep,
            decimal=decimal,
            header=None,
            usecols=sorted(set(cols)),
            dtype=np.float64,
            engine="c",
            skip_blank_lines=False,
            quotechar='"',
        )
        arr = np.column_stack([df[c].to_numpy(dtype=np.float64) for c in cols])
    except Exception:  # noqa: BLE001 - any parser trouble -> slow path finds the line
        return None
    if len(arr) != _count_lines(block) or not np.isfinite(arr).all():
        return None
    return arr


def _to_float(cell: str, decimal: str) -> float | None:
    c = cell.strip().strip('"').strip()
    if decimal == ",":
        if _NUM_COMMA.fullmatch(c) is None:
            return None
        c = c.replace(",", ".")
    elif _NUM_DOT.fullmatch(c) is None:
        return None
    return float(c)


def _parse_slow(block: str, first_line: int, layout: _Layout, decimal: str, path) -> np.ndarray:
    """Line-by-line parse of the numeric block; raises :class:`ReadError` at the first bad cell."""
    h = layout.header
    sep = h.sep
    idx = [h.roles[r] for r in _ROLES]
    names = [h.column(r) for r in _ROLES]
    need = max(idx) + 1
    rows: list[tuple[float, float, float]] = []
    for lineno, _start, line in _iter_lines(block, 0, first_line):
        if _is_blank(line, sep):
            continue
        cells = _split(line, sep)
        if len(cells) < need:
            missing = names[next(k for k, i in enumerate(idx) if i >= len(cells))]
            raise ReadError(
                f"expected 3 numeric columns (time, stroke, force), got {_show(line.strip())} "
                f"with only {len(cells)} field(s) (column {missing!r} missing)",
                path,
                lineno,
                missing,
            )
        vals = []
        for i, name in zip(idx, names):
            cell = cells[i]
            v = _to_float(cell, decimal)
            if v is None:
                what = "an empty cell" if not cell.strip() else _show(cell)
                mark = "decimal comma" if decimal == "," else "decimal point"
                raise ReadError(
                    f"expected 3 numeric columns (time, stroke, force) with a {mark}, got {what} "
                    f"in column {name!r}",
                    path,
                    lineno,
                    name,
                )
            if not math.isfinite(v):
                raise ReadError(
                    f"non-finite value {_show(cell)} in column {name!r}; expected a finite number",
                    path,
                    lineno,
                    name,
                )
            vals.append(v)
        rows.append((vals[0], vals[1], vals[2]))
    return np.asarray(rows, dtype=np.float64).reshape(-1, 3)


def _text_of(path_or_text_lines) -> tuple[str, Path | str]:
    if isinstance(path_or_text_lines, os.PathLike) or (
        isinstance(path_or_text_lines, str) and not _NL.search(path_or_text_lines)
    ):
        p = Path(path_or_text_lines)
        return _load_text(p), p
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
    return _check_text(text, label), label


def detect_dialect(path_or_text_lines) -> str:
    """Dialect of a raw test export, from its content.

    Parameters
    ----------
    path_or_text_lines : str, os.PathLike or iterable of str
        A file path, or the file's lines (a single string containing line breaks is taken as the
        text itself).

    Returns
    -------
    str
        ``"csv"``, ``"testxpert"``, ``"bluehill"`` or ``"mts"``.

    Raises
    ------
    ReadError
        If no header row naming time, stroke and force is found.
    """
    text, label = _text_of(path_or_text_lines)
    return _scan(text, label).dialect()


def read_test(
    path: str | os.PathLike,
    *,
    pressure_kpa: float | None = None,
    dialect: str | None = None,
) -> RawTest:
    """Read one raw four-point-bending test export.

    Parameters
    ----------
    path : str or os.PathLike
        The export file (plain CSV, Zwick testXpert, Instron Bluehill or MTS TestSuite).
    pressure_kpa : float, optional
        Inflation pressure in kPa.  Overrides a pressure in the metadata or the file name.
    dialect : str, optional
        Force a dialect instead of detecting it.  It chooses the decimal separator when the data
        do not show one (``","`` for testxpert, ``"."`` otherwise).

    Returns
    -------
    RawTest
        Time in s, stroke in mm and force in N, with the metadata and the pressure in kPa.

    Raises
    ------
    ReadError
        For anything that makes the file unreadable, with a one-line ``FILE:LINE: ...`` message.
    ValueError
        For a bad ``dialect`` name or a non-finite ``pressure_kpa``.
    """
    if dialect is not None and dialect not in DIALECTS:
        raise ValueError(f"unknown dialect {dialect!r}; expected one of {', '.join(DIALECTS)}")
    if pressure_kpa is not None:
        try:
            pressure_kpa = float(pressure_kpa)
        except (TypeError, ValueError):
            msg = f"pressure_kpa must be a number in kPa, got {pressure_kpa!r}"
            raise ValueError(msg) from None
        if not math.isfinite(pressure_kpa):
            raise ValueError(f"pressure_kpa must be finite, got {pressure_kpa!r}")
    p = Path(path)
    text = _load_text(p)
    layout = _scan(text, path)
    found = layout.dialect()
    used = dialect or found
    h = layout.header

    source_units, factors = _resolve_units(layout, path)

    metadata: dict[str, str] = {}
    meta_pressure: float | None = None
    for lineno, line, _is_hash in layout.meta_lines:
        parsed = _parse_meta(line, h.sep)
        if parsed is None:
            continue
        key, value, unit = parsed
        shown = f"{value} {unit}" if unit and value else (value or unit)
        metadata.setdefault(key, shown)
        if pressure_kpa is None and meta_pressure is None and shown:
            is_p, key_unit = _pressure_key(key)
            if is_p:
                try:
                    meta_pressure = parse_pressure(shown, key_unit)
                except ReadError as exc:
                    raise ReadError(
                        f"metadata {key!r}: {exc.message}", path, lineno, key
                    ) from None

    if layout.data_line is None or layout.data_offset is None:
        raise ReadError(
            "header row is followed by no data rows; expected at least 2", path, h.line
        )
    decimal = layout.decimal(used)
    block = _strip_trailing_blank(text[layout.data_offset :], h.sep)
    arr = _parse_fast(block, layout, decimal)
    if arr is None:
        arr = _parse_slow(block, layout.data_line, layout, decimal, path)
    if len(arr) < 2:
        raise ReadError(
            f"header row is followed by {len(arr)} data row(s); expected at least 2",
            path,
            h.line,
        )
    for k, role in enumerate(_ROLES):
        if factors[role] != 1.0:
            arr[:, k] *= factors[role]
    if not np.isfinite(arr).all():  # unit conversion overflow
        bad = int(np.argwhere(~np.isfinite(arr))[0][0])
        raise ReadError(
            f"value out of range after unit conversion in data row {bad + 1}; expected finite "
            "numbers",
            path,
            layout.data_line,
        )
    data = pd.DataFrame(arr, columns=list(COLUMNS), dtype=np.float64)

    if pressure_kpa is not None:
        pressure, source = pressure_kpa, "option"
    elif meta_pressure is not None:
        pressure, source = meta_pressure, "metadata"
    else:
        pressure = pressure_from_filename(p.name)
        source = "filename" if pressure is not None else None
    return RawTest(
        data=data,
        path=p,
        dialect=used,
        metadata=metadata,
        pressure_kpa=pressure,
        pressure_source=source,
        source_units=source_units,
    )
