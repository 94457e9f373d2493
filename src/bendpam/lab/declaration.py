"""The format declaration: a small TOML file that says how to read an export, with no detection.

When the reader's detection fails on a file, or chooses wrong, a **format declaration** says
where the names, units and numbers are and which columns hold time, stroke and force.
:func:`load_declaration` reads and validates one strictly (an unknown key or a bad value is one
line naming the declaration file, the key and the allowed values);
:func:`bendpam.lab.declared.read_declared` reads an export by it.  The format is documented in
``docs/formats.md`` ("Format declarations").

A declaration (every key is optional unless marked)::

    header_line = 4            # 1-based line of the names row, or "none"
    units_line = 5             # line of the units row, or "none" (then units per column)
    first_data_line = 6        # required: the first line of numbers
    last_data_line = -1        # last line of numbers; negative counts from the end (-1 = last)
    delimiter = ","            # required for text: "tab", ";", ",", "whitespace" or "fixed"
    widths = [10, 12, 12]      # with delimiter = "fixed": the width of each column (characters)
    decimal = "."              # "." or ","
    thousands = ""             # "", ",", ".", " " or "'"
    encoding = "utf-8"         # a Python codec name (cp1252, shift_jis, utf-16, ...)
    sheet = "Values FBLC"      # workbooks only: the sheet's name or 1-based number
    blocks = "one"             # "one", "concatenate" or "split" (one test per block)
    specimen_width = 4         # several specimens side by side: columns per specimen
    specimen_names_line = 3    # with specimen_width: the line naming each specimen
    rate_hz = 100.0            # sampling rate (Hz) when there is no time column
    pressure_kpa = 150.0       # the test's inflation pressure (kPa)

    [time]                     # column: name in the names row, or 1-based position
    column = "Time"
    unit = "s"                 # s, ms, min, h
    [stroke]
    column = "Extension"
    unit = "mm"                # mm, um, m, cm, in
    [force]
    column = 3
    unit = "N"                 # N, kN, mN, uN, daN, kgf, lbf
"""

from __future__ import annotations

import codecs
import math
import os
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from bendpam.lab.channels import ROLES, UNIT_HINT, unit_factor
from bendpam.lab.pressure import PRESSURE_RANGE_TEXT, pressure_out_of_range
from bendpam.lab.read_error import ReadError

__all__ = [
    "BLOCK_MODES",
    "DECLARATION_HINT",
    "DECLARATION_KEYS",
    "DELIMITER_NAMES",
    "TEXT_KEYS",
    "ColumnSpec",
    "Declaration",
    "load_declaration",
    "parse_declaration",
]

#: Values of ``blocks``: one test (blocks are refused), blocks concatenated, one test per block.
BLOCK_MODES: tuple[str, ...] = ("one", "concatenate", "split")
#: Values of ``delimiter`` -> the delimiter used (``"whitespace"`` and ``"fixed"`` stay words).
DELIMITER_NAMES: dict[str, str] = {
    "tab": "\t", "\t": "\t", ";": ";", ",": ",", "whitespace": "whitespace", "fixed": "fixed",
}  # fmt: skip
#: What a refusal of detection adds, in library words (the command line names its options instead).
DECLARATION_HINT = (
    "describe the file's layout in a format declaration (bendpam.lab.suggest_declaration(path) drafts one)"
)
_DELIMITERS_SHOWN = '"tab", ";", ",", "whitespace" or "fixed"'
_THOUSANDS = ("", ",", ".", " ", "'")
_ROLE_KEYS = ("column", "unit", "clock")
#: Every top-level key of a declaration.
DECLARATION_KEYS: tuple[str, ...] = (
    "version", "header_line", "units_line", "first_data_line", "last_data_line", "delimiter", "widths",
    "decimal", "thousands", "encoding", "sheet", "blocks", "specimen_width", "specimen_names_line", "rate_hz",
    "pressure_kpa", *ROLES,
)  # fmt: skip
#: Keys that describe text only (a workbook is read by sheet and cell).
TEXT_KEYS = ("delimiter", "widths", "decimal", "thousands", "encoding")
_MAX_LINE = 10**9


@dataclass(frozen=True)
class ColumnSpec:
    """Where one channel is: a column name (as in the names row) or a 1-based position, and its unit.

    >>> ColumnSpec("Load", "kN").shown, ColumnSpec(3, None).shown
    ("'Load'", 'column 3')
    """

    column: str | int
    unit: str | None = None
    #: The time column this channel is sampled on, when not the one of ``[time]`` (a slower rate group).
    clock: str | int | None = field(default=None, repr=False)

    @property
    def shown(self) -> str:
        """The column as named in messages."""
        return f"column {self.column}" if isinstance(self.column, int) else repr(self.column)


@dataclass(frozen=True)
class Declaration:
    """A validated format declaration (see the module's documentation for each key).

    Lines are 1-based (rows of the sheet for a workbook); ``None`` means "not given".

    Examples
    --------
    >>> decl = parse_declaration('header_line = 1\\nfirst_data_line = 2\\ndelimiter = ","\\n'
    ...                          'time = {column = "t", unit = "s"}\\nstroke = {column = 2, unit = "mm"}\\n'
    ...                          'force = {column = 3, unit = "kN"}\\n', "be.toml")
    >>> decl.delimiter, decl.first_data_line, decl.columns["force"]
    (',', 2, ColumnSpec(column=3, unit='kN'))
    """

    source: Path | str
    first_data_line: int
    columns: dict[str, ColumnSpec]
    header_line: int | None = None
    units_line: int | None = None
    last_data_line: int | None = None
    delimiter: str | None = None
    widths: tuple[int, ...] | None = None
    decimal: str | None = None
    thousands: str = ""
    encoding: str | None = None
    sheet: str | int | None = None
    blocks: str = "one"
    specimen_width: int | None = None
    specimen_names_line: int | None = None
    rate_hz: float | None = None
    pressure_kpa: float | None = None
    given: frozenset[str] = field(default_factory=frozenset)

    def error(self, key: str, message: str) -> ReadError:
        """A one-line error about ``key`` of this declaration (raised by the reader)."""
        return ReadError(f"{key}: {message}", self.source, None, key)


class _Checker:
    """Validates the keys of one declaration, naming the file, the key and its line."""

    def __init__(self, text: str, source: Path | str) -> None:
        self.text = text
        self.source = source

    def line_of(self, key: str) -> int | None:
        m = re.search(rf"(?m)^[ \t]*\[?[ \t]*{re.escape(key)}[ \t]*[\]=]", self.text)
        return self.text.count("\n", 0, m.start()) + 1 if m else None

    def fail(self, key: str, message: str) -> ReadError:
        return ReadError(f"{key}: {message}", self.source, self.line_of(key.split(".")[0]), key)

    def line(self, data: dict[str, Any], key: str, *, none_ok: bool = False, negative: bool = False) -> int | None:
        if key not in data:
            return None
        v = data[key]
        if none_ok and v == "none":
            return None
        expected = "a 1-based line number" + (" or \"none\"" if none_ok else "") + (
            " (negative: counted from the end, -1 = the last line)" if negative else "")
        if isinstance(v, bool) or not isinstance(v, int):
            raise self.fail(key, f"{v!r} is not a line number; expected {expected}")
        if v == 0 or (v < 0 and not negative) or abs(v) > _MAX_LINE:
            raise self.fail(key, f"{v} is out of range; expected {expected}")
        return v

    def choice(self, data: dict[str, Any], key: str, allowed: tuple[str, ...], shown: str) -> str | None:
        if key not in data:
            return None
        v = data[key]
        if not isinstance(v, str) or v not in allowed:
            raise self.fail(key, f"{v!r} is not allowed; expected {shown}")
        return v

    def number(self, data: dict[str, Any], key: str, low: float, high: float, unit: str) -> float | None:
        if key not in data:
            return None
        v = data[key]
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v) or not low < v <= high:
            raise self.fail(key, f"{v!r} is not allowed; expected a number above {low:g} and at most {high:g} {unit}")
        return float(v)

    def column(self, data: dict[str, Any], role: str) -> ColumnSpec | None:
        if role not in data:
            return None
        spec = data[role]
        if not isinstance(spec, dict):
            raise self.fail(role, f"{spec!r} is not a table; expected {role} = {{column = NAME or POSITION, "
                                  "unit = UNIT}")
        unknown = sorted(set(spec) - set(_ROLE_KEYS))
        if unknown:
            raise self.fail(f"{role}.{unknown[0]}", f"unknown key; expected {' or '.join(_ROLE_KEYS)}")
        if "column" not in spec:
            raise self.fail(f"{role}.column", "missing; expected the column's name in the names row or its "
                                              "1-based position")
        col = spec["column"]
        if isinstance(col, bool) or not isinstance(col, (str, int)) or (isinstance(col, str) and not col.strip()) \
                or (isinstance(col, int) and not 1 <= col <= 100_000):
            raise self.fail(f"{role}.column", f"{col!r} is not allowed; expected a non-empty column name or a "
                                              "1-based position (1 to 100000)")
        unit = spec.get("unit")
        if unit is not None and (not isinstance(unit, str) or unit_factor(role, unit) is None):
            raise self.fail(f"{role}.unit", f"{unit!r} is not allowed; expected {UNIT_HINT[role]}")
        clock = spec.get("clock")
        if clock is not None and (role == "time" or isinstance(clock, bool) or not isinstance(clock, (str, int))
                                  or (isinstance(clock, str) and not clock.strip())
                                  or (isinstance(clock, int) and not 1 <= clock <= 100_000)):
            raise self.fail(f"{role}.clock", f"{clock!r} is not allowed; expected the name or 1-based position of "
                                             "the time column this channel is sampled on (stroke and force only)")
        return ColumnSpec(col.strip() if isinstance(col, str) else col, unit.strip() if unit else None,
                          clock.strip() if isinstance(clock, str) else clock)


def _text_keys(c: _Checker, data: dict[str, Any]) -> dict[str, Any]:
    """delimiter, widths, decimal, thousands and encoding, checked together."""
    out: dict[str, Any] = {}
    d = c.choice(data, "delimiter", tuple(DELIMITER_NAMES), _DELIMITERS_SHOWN)
    out["delimiter"] = DELIMITER_NAMES[d] if d is not None else None
    if "widths" in data:
        w = data["widths"]
        if out["delimiter"] != "fixed":
            raise c.fail("widths", 'only with delimiter = "fixed"')
        if not isinstance(w, list) or not w or not all(isinstance(x, int) and not isinstance(x, bool)
                                                       and 1 <= x <= 10_000 for x in w):
            raise c.fail("widths", f"{w!r} is not allowed; expected a list of column widths in characters "
                                   "(integers 1 to 10000), e.g. [10, 12, 12]")
        out["widths"] = tuple(w)
    elif out["delimiter"] == "fixed":
        raise c.fail("delimiter", 'delimiter = "fixed" needs widths = [..] (the width of each column)')
    out["decimal"] = c.choice(data, "decimal", (".", ","), '"." or ","')
    t = c.choice(data, "thousands", _THOUSANDS, '"" (none), ",", ".", " " or "\'"')
    out["thousands"] = t or ""
    if out["thousands"] and out["thousands"] == (out["decimal"] or "."):
        raise c.fail("thousands", f"{t!r} is also the decimal mark; expected another separator or \"\"")
    if out["decimal"] and out["decimal"] == out["delimiter"]:
        raise c.fail("decimal", f"{out['decimal']!r} is also the delimiter; expected the other decimal mark")
    if "encoding" in data:
        e = data["encoding"]
        try:
            ok = isinstance(e, str) and bool(codecs.lookup(e))
        except LookupError:
            ok = False
        if not ok:
            raise c.fail("encoding", f"{e!r} is not a known text encoding; expected a codec name such as "
                                     "utf-8, utf-8-sig, cp1252, cp1250, latin-1, shift_jis, gb18030 or utf-16")
        out["encoding"] = e
    return out


def _lines(c: _Checker, data: dict[str, Any]) -> dict[str, Any]:
    """The line keys, checked against each other."""
    out = {
        "header_line": c.line(data, "header_line", none_ok=True),
        "units_line": c.line(data, "units_line", none_ok=True),
        "first_data_line": c.line(data, "first_data_line"),
        "last_data_line": c.line(data, "last_data_line", negative=True),
        "specimen_names_line": c.line(data, "specimen_names_line"),
    }
    first = out["first_data_line"]
    if first is None:
        raise c.fail("first_data_line", "missing; expected the 1-based line of the first row of numbers")
    for key in ("header_line", "units_line", "specimen_names_line"):
        v = out[key]
        if v is not None and v >= first:
            raise c.fail(key, f"line {v} is not above first_data_line = {first}; expected a line before "
                              "the numbers")
    if out["units_line"] is not None and out["units_line"] == out["header_line"]:
        raise c.fail("units_line", "is the header_line; expected the line of the units row, or leave it out")
    last = out["last_data_line"]
    if last is not None and 0 < last < first:
        raise c.fail("last_data_line", f"{last} is before first_data_line = {first}; expected a line at or after "
                                       "it, or a negative line counted from the end")
    return out


def parse_declaration(text: str, source: str | os.PathLike = "<declaration>") -> Declaration:
    """Validate the TOML text of a format declaration.

    Parameters
    ----------
    text : str
        The declaration (TOML).
    source : str or os.PathLike
        Its file, as named in messages.

    Returns
    -------
    Declaration

    Raises
    ------
    ReadError
        One line ``DECLARATION:LINE: key: what is wrong; expected ...`` for invalid TOML, an
        unknown key, a missing key or a bad value.

    Examples
    --------
    >>> text = 'first_data_line = 2\\ndelimiter = "pipe"\\n'
    >>> try:
    ...     parse_declaration(text, "be.toml")
    ... except ReadError as exc:
    ...     print(exc)
    be.toml:2: delimiter: 'pipe' is not allowed; expected "tab", ";", ",", "whitespace" or "fixed"
    """
    from bendpam.errors import FileFormatError
    from bendpam.infra.budgets import loads_toml

    label: Path | str = Path(source) if isinstance(source, os.PathLike) else source
    try:
        data = loads_toml(text, str(label), kind="format declaration")
    except FileFormatError as exc:
        raise ReadError(str(exc).split(": ", 1)[-1], label) from None
    c = _Checker(text, label)
    unknown = [k for k in data if k not in DECLARATION_KEYS]
    if unknown:
        raise c.fail(unknown[0], f"unknown key; expected one of {', '.join(DECLARATION_KEYS)}")
    if "version" in data and data["version"] != 1:
        raise c.fail("version", f"{data['version']!r} is not allowed; expected 1")
    kw: dict[str, Any] = {**_lines(c, data), **_text_keys(c, data)}
    sheet = data.get("sheet")
    if sheet is not None and (isinstance(sheet, bool) or not isinstance(sheet, (str, int))
                              or (isinstance(sheet, int) and sheet < 1) or (isinstance(sheet, str) and not sheet)):
        raise c.fail("sheet", f"{sheet!r} is not allowed; expected the sheet's name or its 1-based number")
    kw["sheet"] = sheet
    kw["blocks"] = c.choice(data, "blocks", BLOCK_MODES, '"one", "concatenate" or "split"') or "one"
    width = data.get("specimen_width")
    if width is not None and (isinstance(width, bool) or not isinstance(width, int) or not 1 <= width <= 10_000):
        raise c.fail("specimen_width", f"{width!r} is not allowed; expected the number of columns of one specimen "
                                       "(1 to 10000)")
    kw["specimen_width"] = width
    if kw["specimen_names_line"] is not None and width is None:
        raise c.fail("specimen_names_line", "only with specimen_width (several specimens side by side)")
    kw["rate_hz"] = c.number(data, "rate_hz", 0.0, 1e7, "Hz")
    p = data.get("pressure_kpa")
    if p is not None and (isinstance(p, bool) or not isinstance(p, (int, float)) or not math.isfinite(p)
                          or pressure_out_of_range(float(p))):
        raise c.fail("pressure_kpa", f"{p!r} is not allowed; {PRESSURE_RANGE_TEXT}")
    kw["pressure_kpa"] = float(p) if p is not None else None
    columns = {r: s for r in ROLES if (s := c.column(data, r)) is not None}
    _check_columns(c, columns, kw)
    return Declaration(source=label, columns=columns, given=frozenset(data), **kw)


def _check_columns(c: _Checker, columns: dict[str, ColumnSpec], kw: dict[str, Any]) -> None:
    for role in ("stroke", "force"):
        if role not in columns:
            raise c.fail(role, f"missing; expected {role} = {{column = NAME or POSITION, unit = UNIT}}")
    if "time" not in columns and kw["rate_hz"] is None:
        raise c.fail("time", "missing, and no rate_hz; expected time = {column = NAME or POSITION, unit = UNIT} "
                             "or the sampling rate rate_hz (Hz)")
    if "time" in columns and kw["rate_hz"] is not None:
        raise c.fail("rate_hz", "given with a time column; expected one of them (rate_hz only when the file has "
                                "no time column)")
    if kw["specimen_width"] is not None or "time" not in columns:
        clocked = [r for r, s in columns.items() if s.clock is not None]
        if clocked:
            raise c.fail(f"{clocked[0]}.clock", "needs a [time] column and one specimen (no specimen_width)")
    cols = [s.column for s in columns.values()]
    if len(set(cols)) < len(cols):
        raise c.fail("force", f"one column given for two roles ({', '.join(s.shown for s in columns.values())}); "
                              "expected three different columns")
    if kw["header_line"] is None:
        named = [r for r, s in columns.items() if isinstance(s.column, str)]
        if named:
            raise c.fail(f"{named[0]}.column", "a name needs header_line; expected a 1-based position, or give "
                                               "header_line")
    width = kw["specimen_width"]
    if width is not None:
        far = [r for r, s in columns.items() if isinstance(s.column, int) and s.column > width]
        if far:
            raise c.fail(f"{far[0]}.column", f"position {columns[far[0]].column} is beyond specimen_width = "
                                             f"{width}; expected a position within the first specimen's columns")


def load_declaration(path: str | os.PathLike) -> Declaration:
    """Read and validate a format declaration file (TOML, UTF-8).

    Parameters
    ----------
    path : str or os.PathLike
        The declaration.

    Returns
    -------
    Declaration

    Raises
    ------
    ReadError
        A missing or unreadable file, or an invalid declaration (one line naming the file,
        the key and the allowed values).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "bluehill.toml"
    ...     _ = path.write_text('header_line = 1\\nfirst_data_line = 2\\ndelimiter = ","\\nblocks = "all"\\n')
    ...     try:
    ...         load_declaration(path)
    ...     except ReadError as exc:
    ...         print(exc.message)
    blocks: 'all' is not allowed; expected "one", "concatenate" or "split"
    """
    from bendpam.errors import FileFormatError
    from bendpam.infra.budgets import read_input_bytes

    p = Path(path)
    try:
        raw = read_input_bytes(p, "format declaration")
    except FileFormatError as exc:
        raise ReadError(str(exc).split(": ", 1)[-1], p) from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ReadError(f"not UTF-8 text (byte {exc.start}); expected a TOML file in UTF-8", p) from None
    return parse_declaration(text, p)
