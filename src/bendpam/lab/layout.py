"""Text layout of testing-machine exports: lines, cells, numbers, metadata lines.

The helpers here know nothing about channels; they split lines into cells (tab, ``;`` or ``,``,
quoted or not), read numbers with a decimal point or comma (exponents like ``e-005``, a
thousands separator only where it cannot be mistaken for the decimal mark), parse the metadata
grammars seen in real exports and the first line of an MTS 793 export.

Metadata grammars (one per line, all seen in real files)::

    "Key"<TAB>value<TAB>"unit"          Zwick testXpert II
    Key;value;unit  /  Key,value,unit    testXpert (synthetic), MTS TestSuite
    Category : Name,"value",unit        Instron Bluehill 2
    "Key : value"  /  Key : value        Instron Bluehill, MTS 793
    Key:<TAB>value<TAB>unit              Instron console (8852)
    # key: value  /  Key=value           plain CSV
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
from collections import deque
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from itertools import islice

from bendpam.lab.channels import is_unit_token

__all__ = [
    "DELIMITERS",
    "NONFINITE_TOKENS",
    "LineReader",
    "MetaItem",
    "Mts793Header",
    "NumberParse",
    "has_control_chars",
    "infer_decimal",
    "is_blank",
    "is_number",
    "numeric_cells",
    "parse_metadata_line",
    "parse_mts793",
    "parse_number",
    "split_cells",
]

#: Cell delimiters tried, in order of preference.
DELIMITERS: tuple[str, ...] = ("\t", ";", ",")

#: Cell texts that stand for a missing or non-finite number (lower case).
NONFINITE_TOKENS = frozenset(
    {
        "nan", "-nan", "+nan", "inf", "-inf", "+inf", "infinity", "-infinity", "+infinity",
        "na", "n/a", "#n/a", "-1.#ind", "1.#qnan", "-1.#inf", "1.#inf", "#num!", "#value!",
        "#div/0!", "null", "none", "-1,#ind", "1,#qnan", "-1,#inf", "1,#inf",
    }
)  # fmt: skip

_NUM_ANY = re.compile(r"[+-]?(?:\d+(?:[.,]\d*)?|[.,]\d+)(?:[eE][+-]?\d+)?")
_NUM_DOT = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_NUM_COMMA = re.compile(r"[+-]?(?:\d+,?\d*|,\d+)(?:[eE][+-]?\d+)?")
# digit grouping: unambiguous with the other decimal mark, or with two or more groups
_GROUP_COMMA_DOT = re.compile(r"[+-]?\d{1,3}(?:,\d{3})+\.\d*(?:[eE][+-]?\d+)?")
_GROUP_DOT_COMMA = re.compile(r"[+-]?\d{1,3}(?:\.\d{3})+,\d*(?:[eE][+-]?\d+)?")
_GROUP_COMMAS = re.compile(r"[+-]?\d{1,3}(?:,\d{3}){2,}")
_GROUP_DOTS = re.compile(r"[+-]?\d{1,3}(?:\.\d{3}){2,}")
_COLLIDE_COMMA = re.compile(r"[+-]?\d{1,3}(?:,\d{3})+,\d+(?:[eE][+-]?\d+)?")
_COLLIDE_DOT = re.compile(r"[+-]?\d{1,3}(?:\.\d{3})+\.\d+(?:[eE][+-]?\d+)?")
_GROUP_SPACES = re.compile(r"[+-]?\d{1,3}(?:[ \u00a0\u202f\u2009]\d{3})+(?:[.,]\d*)?(?:[eE][+-]?\d+)?")
_CONTROL = re.compile(r"[\x00-\x08\x0e-\x19\x1b-\x1f\x7f]")
_BLANK_CHARS = ' \t"\x1a\x0c\x0b\ufeff'


def split_cells(line: str, sep: str | None) -> list[str]:
    """Split one line at ``sep`` honouring double quotes; cells are stripped and unquoted.

    ``sep=" "`` is a space-aligned table: numbers split at any blanks, names at two or more.

    >>> split_cells('"Time";"Load";0,5', ";")
    ['Time', 'Load', '0,5']
    >>> split_cells("Ch 1 Displacement  Ch 1 Force  Time", " "), split_cells("  0.5 -1.25   3", " ")
    (['Ch 1 Displacement', 'Ch 1 Force', 'Time'], ['0.5', '-1.25', '3'])
    """
    if sep is None:
        return [line.strip().strip('"').strip()]
    if sep == " ":
        return _split_spaces(line)
    if '"' not in line:
        return [c.strip() for c in line.split(sep)]
    try:
        cells = next(csv.reader([line], delimiter=sep, quotechar='"', skipinitialspace=True), [])
    except csv.Error:
        return [c.strip().strip('"').strip() for c in line.split(sep)]
    return [c.strip() for c in cells]


def _split_spaces(line: str) -> list[str]:
    """Cells of a space-aligned line: a row of numbers splits at any run of blanks, a names row
    (names may hold single spaces, ``Ch 1 Force``) at two blanks or more or a tab."""
    tokens = line.split()
    num = sum(_NUM_ANY.fullmatch(t) is not None for t in tokens)
    if tokens and 2 * num >= len(tokens):
        return tokens
    cells = [c.strip('"').strip() for c in re.split(r"\s{2,}|\t", line.strip())]
    return cells if len(cells) > 1 else [c.strip('"') for c in tokens]


def is_blank(line: str, sep: str | None = None) -> bool:
    """Empty, or only separators, quotes and whitespace (``;;;`` rows from spreadsheets).

    >>> is_blank(";;;", ";"), is_blank(' "" '), is_blank("0;1", ";")
    (True, True, False)
    """
    return not line.strip(_BLANK_CHARS + (sep or ""))


def has_control_chars(line: str) -> bool:
    """Does the line hold control characters (binary data)?

    >>> has_control_chars("0,1" + chr(1)), has_control_chars("0\\t1")
    (True, False)
    """
    return _CONTROL.search(line) is not None


def is_number(cell: str) -> bool:
    """A number with a decimal point or comma (or a non-finite token such as ``nan``).

    >>> is_number("1,5e-005"), is_number("nan"), is_number("Load")
    (True, True, False)
    """
    c = cell.strip()
    return _NUM_ANY.fullmatch(c) is not None or c.lower() in NONFINITE_TOKENS


def numeric_cells(cells: list[str]) -> tuple[int, int]:
    """``(numbers, non-empty cells)`` of a split line.

    >>> numeric_cells(["0,5", "11.8", "", "N"])
    (2, 3)
    """
    num = nonempty = 0
    for c in cells:
        if c:
            nonempty += 1
            if _NUM_ANY.fullmatch(c) is not None or _GROUP_SPACES.fullmatch(c) is not None:
                num += 1
    return num, nonempty


@dataclass(frozen=True)
class NumberParse:
    """Result of :func:`parse_number`: ``value`` or, when None, ``problem``.

    ``problem`` is ``"empty"``, ``"nonfinite"``, ``"thousands"`` (a digit grouping that collides
    with the decimal mark) or ``"text"``.

    >>> NumberParse(11.8), NumberParse(None, "text").problem
    (NumberParse(value=11.8, problem=None), 'text')
    """

    value: float | None
    problem: str | None = None


def parse_number(cell: str, decimal: str) -> NumberParse:
    """Read a number written with ``decimal`` (``"."`` or ``","``) as the decimal mark.

    Parameters
    ----------
    cell : str
        The cell text (quotes already removed).
    decimal : {".", ","}
        The decimal mark of the file.

    Returns
    -------
    NumberParse

    Examples
    --------
    >>> parse_number("6.8902e-005", ".").value, parse_number("1.000,5", ",").value
    (6.8902e-05, 1000.5)
    >>> parse_number("1,000,5", ",").problem, parse_number("n/a", ".").problem
    ('thousands', 'nonfinite')
    >>> parse_number("-1\u00a0234,5", ",").value            # digits grouped by a no-break space
    -1234.5
    """
    c = cell.strip().replace("\u2212", "-")
    if not c:
        return NumberParse(None, "empty")
    if _GROUP_SPACES.fullmatch(c):  # digits grouped by (narrow, no-break) spaces: '1 234,5'
        c = re.sub(r"[ \u00a0\u202f\u2009]", "", c)
    if decimal == ",":
        if _NUM_COMMA.fullmatch(c):
            v = float(c.replace(",", "."))
        elif _GROUP_DOT_COMMA.fullmatch(c):
            v = float(c.replace(".", "").replace(",", "."))
        elif _GROUP_DOTS.fullmatch(c):
            v = float(c.replace(".", ""))
        elif _COLLIDE_COMMA.fullmatch(c) or _GROUP_COMMAS.fullmatch(c):
            return NumberParse(None, "thousands")
        elif c.lower() in NONFINITE_TOKENS:
            return NumberParse(None, "nonfinite")
        else:
            return NumberParse(None, "text")
    else:
        if _NUM_DOT.fullmatch(c):
            v = float(c)
        elif _GROUP_COMMA_DOT.fullmatch(c) or _GROUP_COMMAS.fullmatch(c):
            v = float(c.replace(",", ""))
        elif _COLLIDE_DOT.fullmatch(c) or _GROUP_DOTS.fullmatch(c):
            return NumberParse(None, "thousands")
        elif c.lower() in NONFINITE_TOKENS:
            return NumberParse(None, "nonfinite")
        else:
            return NumberParse(None, "text")
    if not math.isfinite(v):
        return NumberParse(None, "nonfinite")
    return NumberParse(v)


def infer_decimal(rows: Iterable[list[str]], sep: str) -> tuple[str | None, int, int]:
    """Decimal mark shown by data cells: ``(mark or None, cells with ',', cells with '.')``.

    A cell like ``1,000.5`` counts for the point, ``1.000,5`` for the comma; ``1,000,292``
    (a grouping that collides with a decimal comma) counts for the comma, so that the reader
    refuses it with its line.  The majority wins; the minority cells fail later with their line.

    >>> infer_decimal([["0,05", "0,027"], ["0,1", "11,54"]], ";")
    (',', 4, 0)
    """
    comma = dot = 0
    for cells in rows:
        for c in cells:
            if not c or (not c[-1:].isdigit() and c[-1:] not in ".,"):
                continue
            if _GROUP_COMMA_DOT.fullmatch(c):
                dot += 1
            elif _GROUP_DOT_COMMA.fullmatch(c):
                comma += 1
            elif "," in c and _NUM_COMMA.fullmatch(c) and re.search(r"\d,\d", c):
                comma += 1
            elif "." in c and _NUM_DOT.fullmatch(c) and re.search(r"\d\.\d", c):
                dot += 1
            elif _COLLIDE_COMMA.fullmatch(c) or _GROUP_COMMAS.fullmatch(c):
                comma += 1
    if comma > dot:
        return ",", comma, dot
    if dot > comma:
        return ".", comma, dot
    return None, comma, dot


@dataclass(frozen=True)
class MetaItem:
    """One metadata line: ``key``, ``value`` and ``unit`` (``""`` when none).

    >>> MetaItem("Pressure", "200", "kPa").shown
    '200 kPa'
    """

    key: str
    value: str
    unit: str = ""

    @property
    def shown(self) -> str:
        """Value with its unit after a space (as stored in ``RawTest.metadata``)."""
        if self.unit and self.value:
            return f"{self.value} {self.unit}"
        return self.value or self.unit


def _line_sep(s: str) -> str | None:
    bare = re.sub(r'"[^"]*"', "", s)  # delimiters inside quotes do not count
    for sep in DELIMITERS:
        if sep in bare:
            return sep
    return None


def parse_metadata_line(line: str) -> MetaItem | None:
    """Key, value and unit of a metadata line in any of the grammars above, or None.

    Lines without a value (section titles such as ``Bediener Information Ende``), ``$``
    comment lines and blank lines give None.

    >>> parse_metadata_line('"Pressure"\\t200\\t"kPa"')
    MetaItem(key='Pressure', value='200', unit='kPa')
    >>> parse_metadata_line('General : Specimen label,"BE-3",')
    MetaItem(key='Specimen label', value='BE-3', unit='')
    >>> parse_metadata_line("# Pressure: 200 kPa"), parse_metadata_line("$testXpert II") is None
    (MetaItem(key='Pressure', value='200 kPa', unit=''), True)
    """
    s = line.strip().lstrip("\ufeff")
    if s.startswith("#"):
        s = s.lstrip("#").strip()
    if not s or s.startswith("$"):
        return None
    sep = _line_sep(s)
    if sep is not None and sep != "\t":
        head = split_cells(s, sep)[0] if s.startswith('"') else s.split(sep, 1)[0]
        if ":" in head:
            after = head.split(":", 1)[1]
            # 'Key: a, b' (a value holding the delimiter) vs 'Category : Name,value'
            if after.strip() and (" : " not in head or re.search(r"\d", after)):
                sep = None
    if sep is not None:
        cells = split_cells(s, sep)
    elif len(s) >= 2 and s[0] == '"' and s[-1] == '"' and s.count('"') % 2 == 0:
        cells = [s[1:-1].replace('""', '"').strip()]
    else:
        cells = [s]
    cells = [c for c in cells if c]
    if not cells:
        return None
    first = cells[0]
    if len(cells) == 1:
        if " : " in first:
            key, value = first.split(" : ", 1)
        elif ":" in first:
            key, value = first.split(":", 1)
        elif "=" in first:
            key, value = first.split("=", 1)
        else:
            return None
        key, value = key.strip().strip('"'), value.strip()
        return MetaItem(key, value) if key else None
    rest = cells[1:]
    if first.endswith(":"):
        key = first[:-1].strip()
    elif " : " in first:
        cat, key = first.split(" : ", 1)
        key = key.strip() or cat.strip()
    elif first.endswith("=") or first.endswith(":"):
        key = first[:-1].strip()
    else:
        key = first
    if rest and rest[0].endswith(":") and len(rest) > 1:  # 'Section<TAB>Zeit:<TAB>33,0<TAB>s'
        key = f"{key} {rest[0][:-1].strip()}"
        rest = rest[1:]
    value = rest[0]
    unit = ""
    more = rest[1:]
    if more and is_unit_token(more[0]) and len(more[0]) <= 12:
        unit, more = more[0], more[1:]
    if more and not unit:
        value = " ".join([value, *more])
    elif more:
        unit = " ".join([unit, *more])
    key = key.strip().strip('"').strip()
    if not key:
        return None
    return MetaItem(key, value.strip(), unit.strip())


@dataclass(frozen=True)
class Mts793Header:
    """First line of an MTS 793 export: ``MTS793|MPT|DEU|1|2|,|.|:|49|1|1|A``.

    Fields: program, application, language, version, delimiter code (2 = tab), decimal mark,
    date separator, time separator, ...

    >>> Mts793Header("MTS793", "MPT", "DEU", "\\t", ",").decimal
    ','
    """

    program: str
    application: str
    language: str
    delimiter: str | None
    decimal: str | None


_MTS_DELIMITERS = {"2": "\t", "0": ",", "1": ";", "3": " "}


def parse_mts793(line: str) -> Mts793Header | None:
    """Parse the first line of an MTS 793 export, or None if ``line`` is not one.

    >>> parse_mts793("MTS793|MPT|DEU|1|2|,|.|:|49|1|1|A")
    Mts793Header(program='MTS793', application='MPT', language='DEU', delimiter='\\t', decimal=',')
    >>> parse_mts793("time_s,stroke_mm,force_n") is None
    True
    """
    s = line.strip().lstrip("\ufeff")
    if not s.upper().startswith("MTS") or s.count("|") < 6:
        return None
    f = s.split("|")
    decimal = f[5] if len(f) > 5 and f[5] in (".", ",") else None
    return Mts793Header(f[0], f[1], f[2], _MTS_DELIMITERS.get(f[4].strip()), decimal)


class LineReader:
    """Lines of a text stream with their 1-based numbers, with look-ahead and push-back.

    Line ends are ``\\r\\n``, ``\\r`` or ``\\n`` (the stream must be opened with universal
    newlines); the returned lines have no line end.

    >>> reader = LineReader(["time_s,force_n\\n", "0,11.8\\n", "0.05,11.71\\n"])
    >>> reader.next(), reader.take(2), reader.lineno
    ('time_s,force_n', ['0,11.8', '0.05,11.71'], 3)
    >>> reader.push_back(["0.05,11.71"])
    >>> reader.lineno, reader.next(), reader.next()
    (2, '0.05,11.71', None)
    """

    def __init__(self, lines: Iterable[str]) -> None:
        self._src = lines
        self._it: Iterator[str] = iter(lines)
        self._pending: deque[str] = deque()
        self.lineno = 0  # number of the last line handed out

    def next(self) -> str | None:
        """The next line, or None at the end."""
        if self._pending:
            line = self._pending.popleft()
        else:
            raw = next(self._it, None)
            if raw is None:
                return None
            line = raw.rstrip("\r\n")
        self.lineno += 1
        return line

    def take(self, n: int) -> list[str]:
        """Up to ``n`` next lines (fewer at the end); ``lineno`` is then the last one's."""
        out: list[str] = []
        while self._pending and len(out) < n:
            out.append(self._pending.popleft())
        if len(out) < n:
            out.extend(raw.rstrip("\r\n") for raw in islice(self._it, n - len(out)))
        self.lineno += len(out)
        return out

    def take_text(self, n_chars: int) -> tuple[str, int] | None:
        """The next whole lines as one text of about ``n_chars`` characters: ``(text, line count)``, or None at the end.

        The lines are joined with ``\\n`` (no line end after the last); ``lineno`` is then the
        last one's.  Pushed-back lines come first, on their own; a text stream (one with
        ``read``, opened with universal newlines) is then read in blocks without making a string
        per line, any other iterable line by line.

        >>> import io
        >>> reader = LineReader(io.StringIO("a\\r\\nb\\rc\\nd", newline=None))
        >>> reader.next(), reader.take_text(3), reader.lineno, reader.take_text(2)
        ('a', ('b\\nc', 2), 3, ('d', 1))
        >>> reader.push_back(["d"]); reader.take_text(100), reader.take_text(100)
        (('d', 1), None)
        """
        if self._pending:
            lines = list(self._pending)
            self._pending.clear()
        elif isinstance(self._src, io.TextIOBase):
            text = self._src.read(n_chars)
            if not text:
                return None
            if not text.endswith("\n"):
                text += self._src.readline()
            if text.endswith("\n"):
                text = text[:-1]
            n = text.count("\n") + 1
            self.lineno += n
            return text, n
        else:
            lines = self.take(max(1, n_chars // 32))
            self.lineno -= len(lines)
        if not lines:
            return None
        self.lineno += len(lines)
        return "\n".join(lines), len(lines)

    def bytes_left(self) -> int | None:
        """Bytes of the file not read yet (about: the stream reads ahead), or None if not a file.

        >>> LineReader(["0,1"]).bytes_left() is None
        True
        """
        try:
            raw = self._src.buffer  # type: ignore[attr-defined]  # a text file's bytes
            return max(0, os.fstat(raw.fileno()).st_size - raw.tell())
        except (AttributeError, OSError, ValueError, io.UnsupportedOperation):
            return None

    def push_back(self, lines: list[str]) -> None:
        """Return ``lines`` (the last ones handed out, in order) to the reader."""
        self._pending.extendleft(reversed(lines))
        self.lineno -= len(lines)
