"""Draft a format declaration for an export: :func:`suggest_declaration`.

When detection reads the file's layout, the draft is filled in with what it found (encoding,
delimiter, decimal mark, names row, first line of numbers, the time, stroke and force columns
and their units); reading the file with the draft gives the same numbers.  When detection fails,
the draft holds the best guesses from the file's head: the sniffed encoding, delimiter and
decimal mark, the line with the most rows of numbers below it as the first data line, a names
row above it, and columns by position with a comment listing the names row's cells; the values
to check are marked ``# CHECK``.
"""

from __future__ import annotations

import ast
import json
import os
import re
from itertools import pairwise
from pathlib import Path
from typing import Any

from bendpam.lab.channels import (
    DEFAULT_UNIT,
    ROLES,
    ColumnInfo,
    choose_channels,
    is_unit_token,
    split_name_unit,
    unit_cell,
    unit_factor,
)
from bendpam.lab.declaration import parse_declaration
from bendpam.lab.layout import DELIMITERS, infer_decimal, is_blank, numeric_cells, split_cells
from bendpam.lab.read_error import ReadError

__all__ = ["suggest_declaration"]

_HEAD_LINES = 3000  # lines of the head used for guesses
_DELIM_WORDS = {"\t": "tab", ";": ";", ",": ",", " ": "whitespace", "whitespace": "whitespace"}


def _q(value: Any) -> str:
    """A TOML value."""
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, float):
        return repr(value)
    return str(value)


def _render(path: Path, how: str, keys: list[tuple[str, Any, str]], columns: dict[str, tuple[Any, str, str]],
            notes: list[str], clocks: dict[str, Any] | None = None) -> str:
    out = [f"# bendpam format declaration for {path.name}", f"# {how}"]
    out += [f"# {n}" for n in notes]
    for key, value, comment in keys:
        out.append(f"{key} = {_q(value)}" + (f"  # {comment}" if comment else ""))
    for role in ROLES:
        if role not in columns:
            continue
        column, unit, comment = columns[role]
        out += ["", f"[{role}]", f"column = {_q(column)}" + (f"  # {comment}" if comment else ""),
                f"unit = {_q(unit)}"]
        if clocks and role in clocks:
            out.append(f"clock = {_q(clocks[role])}  # sampled on its own time column")
    return "\n".join(out) + "\n"


def _head(path: Path) -> tuple[list[str], str | None, str | None, bool]:
    """``(lines, encoding, sheet, whole)`` of the file's head (the sheet with most rows of numbers)."""
    from bendpam.infra.budgets import input_file_problem
    from bendpam.lab.encoding import container_kind, detect_encoding
    from bendpam.lab.source import open_source

    problem = input_file_problem(path, "raw test file")
    if problem is not None:
        raise ReadError(problem, path)
    with open(path, "rb") as fh:
        head = fh.read(1 << 20)
        whole = not fh.read(1)
    if container_kind(head) in ("zip", "ole2"):
        sources, _ = open_source(path)
        best = max(sources, key=lambda s: sum(1 for ln in list(s.lines)[:_HEAD_LINES]
                                              if numeric_cells(ln.split("\t"))[0] >= 2))
        lines = list(best.lines)
        return lines[:_HEAD_LINES], None, best.sheet, len(lines) <= _HEAD_LINES
    encoding = detect_encoding(head, complete=whole)
    text = head.decode(encoding, errors="replace").lstrip("\ufeff")
    lines = text.splitlines()
    if not whole:
        lines = lines[:-1]
    return lines[:_HEAD_LINES], encoding, None, whole and len(lines) <= _HEAD_LINES


def _cells(line: str, sep: str) -> list[str]:
    return line.split() if sep == " " else split_cells(line, sep)


def _is_data(cells: list[str]) -> bool:
    num, nonempty = numeric_cells(cells)
    return num >= 2 and 2 * num >= nonempty


def _thousands(rows: list[list[str]], decimal: str) -> str | None:
    """The thousands separator shown by digit groups in the rows (``"1,004.8"``), or None."""
    t = "," if decimal == "." else "."
    rx = re.compile(rf"[+-]?\d{{1,3}}(?:{re.escape(t)}\d{{3}})+(?:{re.escape(decimal)}\d*)?")
    return t if any(rx.fullmatch(c) and decimal in c for r in rows for c in r) else None


def _sniff_delimiter(lines: list[str]) -> str:
    scores = {}
    for sep in (*DELIMITERS, " "):
        scores[sep] = sum(numeric_cells(c)[0] for c in (_cells(ln, sep) for ln in lines) if _is_data(c))
    return max(scores, key=lambda s: scores[s])  # ties: the order of DELIMITERS, whitespace last


def _first_data(lines: list[str], sep: str) -> tuple[int, int]:
    """0-based ``(start, end)`` of the longest run of rows of numbers (blank lines inside allowed)."""
    best, start, count, best_count = (0, 0), None, 0, -1
    end = 0
    for i, line in enumerate([*lines, "x x"]):
        if is_blank(line, sep if sep != " " else None) and start is not None:
            continue
        if _is_data(_cells(line, sep)):
            if start is None:
                start, count = i, 0
            count += 1
            end = i
            continue
        if start is not None and count > best_count:
            best, best_count = (start, end), count
        start = None
    return best


def _header(lines: list[str], sep: str, first: int, n_cols: int) -> tuple[int | None, int | None]:
    """0-based names row and units row above the numbers (None when there is none)."""
    best, best_score = None, None
    for i in range(first - 1, max(-1, first - 120), -1):
        cells = _cells(lines[i], sep)
        words = [c for c in cells if c]
        if len(words) < 2 or numeric_cells(cells)[0] * 5 > len(words):
            continue
        cols = [ColumnInfo(j, c, *split_name_unit(c)) for j, c in enumerate(cells) if c]
        hits = len(choose_channels(cols).chosen) + _units_like(lines, sep, i + 1, first)
        score = (hits, -abs(len(cells) - n_cols), i)
        if best_score is None or score > best_score:
            best, best_score = i, score
    if best is None:
        return None, None
    return best, best + 1 if _units_like(lines, sep, best + 1, first) else None


def _units_like(lines: list[str], sep: str, i: int, first: int) -> bool:
    """Is line ``i`` (0-based, above the numbers) a units row?"""
    if i >= first:
        return False
    cells = [c for c in _cells(lines[i], sep) if c]
    return bool(cells) and all(is_unit_token(c) for c in cells)


def _guess_columns(names: list[str], units: list[str] | None, rows: list[list[str]]
                   ) -> dict[str, tuple[Any, str, str]]:  # fmt: skip
    """Columns by position (1-based), from the names where they tell, else the first increasing column as time."""
    cols = []
    for j, cell in enumerate(names):
        name, unit = split_name_unit(cell)
        if units is not None and j < len(units) and units[j].strip():
            unit = unit_cell(units[j])
        cols.append(ColumnInfo(j, cell, name, unit))
    chosen = {r: c for r, c in choose_channels(cols).chosen.items()} if cols else {}
    out: dict[str, tuple[Any, str, str]] = {}
    used = {c.index for c in chosen.values()}
    if "time" not in chosen and rows:
        for j in range(min(len(r) for r in rows)):
            try:
                v = [float(r[j].replace(",", ".")) for r in rows[:50]]
            except ValueError:
                continue
            if j not in used and len(v) > 2 and all(b > a for a, b in pairwise(v)):
                chosen["time"] = cols[j] if j < len(cols) else ColumnInfo(j, "", "", None)
                used.add(j)
                break
    free = iter(j for j in range(max(len(names), max((len(r) for r in rows), default=0))) if j not in used)
    for role in ROLES:
        c = chosen.get(role)
        if c is not None:
            unit = c.unit if c.unit and unit_factor(role, c.unit) is not None else None
            label = f"'{c.source}'" if c.source else "no name"
            out[role] = (c.index + 1, unit or DEFAULT_UNIT[role],
                         f"{label}{'' if unit else '; unit assumed: CHECK'}")
        else:
            j = next(free, len(names))
            out[role] = (j + 1, DEFAULT_UNIT[role], "CHECK: a guess")
    return out


def _from_head(path: Path, reason: str) -> str:
    """A draft from the file's head alone (detection failed)."""
    lines, encoding, sheet, whole = _head(path)
    sep = "\t" if sheet is not None else _sniff_delimiter(lines)
    start, end = _first_data(lines, sep)
    rows = [_cells(ln, sep) for ln in lines[start:end + 1] if not is_blank(ln)]
    n_cols = max((len(r) for r in rows[:50]), default=0)
    hi, ui = _header(lines, sep, start, n_cols)
    names = _cells(lines[hi], sep) if hi is not None else []
    units = _cells(lines[ui], sep) if ui is not None else None
    keys: list[tuple[str, Any, str]] = []
    if sheet is not None:
        keys.append(("sheet", sheet, "the sheet with the most rows of numbers"))
    keys.append(("header_line", hi + 1 if hi is not None else "none", "CHECK: the names row"))
    if ui is not None:
        keys.append(("units_line", ui + 1, ""))
    keys.append(("first_data_line", start + 1, "the first of the most rows of numbers"))
    tail = [ln for ln in lines[end + 1:] if ln.strip()]
    if whole and tail:
        keys.append(("last_data_line", end + 1, "text follows the numbers"))
    if sheet is None:
        keys.append(("delimiter", _DELIM_WORDS[sep], ""))
        decimal = infer_decimal(rows[:200], sep if sep != " " else "\t")[0] or "."
        keys.append(("decimal", decimal, ""))
        mark = _thousands(rows, decimal)
        if mark:
            keys.append(("thousands", mark, "digit groups seen in the numbers"))
        keys.append(("encoding", encoding, ""))
    width = len([c for c in names if c.strip()])
    if names and width >= 2 and n_cols >= 2 * width and not any(c.strip() for c in names[width:]):
        keys.append(("specimen_width", width, "CHECK: the numbers are several column groups wide"))
    columns = _guess_columns(names[:width] if width else names, units, rows[:60])
    if "time" in columns and columns["time"][2] == "CHECK: a guess":
        keys.append(("rate_hz", 1.0, "CHECK: no time column found; the sampling rate in Hz"))
        del columns["time"]
    elif "time" in columns and sheet is None and not (whole and tail) and _end_record(path, encoding, sep,
                                                                                      columns["time"][0]):
        keys.append(("last_data_line", -2, "CHECK: the last line goes back in time (an end record, not a sample?)"))
    shown = ", ".join(f"{j + 1}: {c!r}" for j, c in enumerate(names) if c.strip())
    notes = [f"detection failed ({reason[:160]})", "the values marked CHECK are guesses: edit them",
             f"names row cells (position: name): {shown}" if shown else "no names row found: columns are positions"]
    return _render(path, "drafted from the file's head", keys, columns, notes)


def _last_text_line(path: Path, source: Any) -> int:
    """1-based number of the last non-blank line of the file (of the sheet read)."""
    from bendpam.lab.source import open_source

    last = 0
    if source.is_excel:
        sheet = next(s for s in open_source(path)[0] if s.sheet == source.sheet)
        lines: Any = sheet.lines
    else:
        lines = open(path, encoding=source.encoding, errors="replace", newline=None)
    try:
        for i, line in enumerate(lines, start=1):
            if not is_blank(line.rstrip("\r\n")):
                last = i
    finally:
        if not source.is_excel:
            lines.close()
    return last


def _end_record(path: Path, encoding: str | None, sep: str, column: int) -> bool:
    """Does the file's last line go back in the time column (an end record rather than a sample)?"""
    if encoding is None:
        return False
    with open(path, "rb") as fh:
        fh.seek(0, os.SEEK_END)
        fh.seek(max(0, fh.tell() - 65536))
        tail = fh.read().decode(encoding, errors="replace").splitlines()[1:]
    rows = [_cells(ln, sep) for ln in tail if ln.strip()][-2:]
    try:
        a, b = (float(r[column - 1].replace(",", ".")) for r in rows)
    except (ValueError, IndexError):
        return False
    return b < a


def _from_detection(path: Path, parsed: Any, raw: Any) -> str:
    """A draft from what detection found (reads the file to the same numbers as ``raw``, its first test)."""
    p, blk, source = parsed.parser, parsed.block, parsed.source
    last_line = blk.last_line
    if raw.data_lines is not None and blk.first_line <= raw.data_lines[1] < blk.last_line:
        last_line = raw.data_lines[1]  # padding rows or end records after the samples were dropped
    keys: list[tuple[str, Any, str]] = []
    if source.is_excel:
        keys.append(("sheet", source.sheet, ""))
    keys.append(("header_line", blk.header_line, ""))
    if blk.units_line is not None:
        keys.append(("units_line", blk.units_line, ""))
    keys.append(("first_data_line", blk.first_line, ""))
    if raw.data_lines is not None and raw.data_lines[1] > blk.last_line:
        keys.append(("blocks", "concatenate", "the blocks continue one test"))
    elif last_line < blk.last_line:
        keys.append(("last_data_line", last_line, "padding or end records follow the samples"))
    elif len(p.blocks) > 1 or p.trailing or _last_text_line(path, source) > blk.last_line:
        keys.append(("last_data_line", blk.last_line, "other lines follow the numbers"))
    if not source.is_excel:
        keys.append(("delimiter", _DELIM_WORDS.get(blk.sep, blk.sep), ""))
        keys.append(("decimal", blk.decimal or ".", ""))
        lines = _head(path)[0]
        mark = _thousands([split_cells(ln, blk.sep) for ln in lines[blk.first_line - 1:]], blk.decimal or ".")
        if mark:
            keys.append(("thousands", mark, "digit groups seen in the numbers"))
        keys.append(("encoding", source.encoding, ""))
    ch = blk.choice
    assert ch is not None
    if "time" not in ch.chosen:
        got = p.rate_from_metadata(blk.header_line)
        if got is not None:
            keys.append(("rate_hz", float(got[0]), f"from {got[1]}"))
        else:
            keys.append(("rate_hz", 1.0, "CHECK: no time column and no rate known; 1 Hz makes time the sample number"))
    names = [c.source for c in blk.columns]
    columns: dict[str, tuple[Any, str, str]] = {}
    by_name = {c.source: c for c in blk.columns}
    for role, col in ch.chosen.items():
        final = raw.channels.get(role, {}).get("source")
        col = by_name.get(final, col)  # detection may have replaced a dead or unreadable channel
        unit = col.unit or DEFAULT_UNIT[role]
        comment = "" if col.unit else "no unit in the file: assumed"
        column: Any = col.source if col.source and names.count(col.source) == 1 else col.index + 1
        columns[role] = (column, unit, comment)
    clocks = {}
    for role in ("stroke", "force"):  # a channel detection resampled from its own clock (bendpam.lab.rates)
        src = raw.channels.get(role, {}).get("source")
        m = next((re.match(r"column (.+?) is sampled on its own clock (.+?) \(every", w) for w in raw.warnings
                  if w.startswith(f"column {src!r} is sampled on its own clock ")), None)
        name = ast.literal_eval(m.group(2)) if m else None
        if name is not None:
            clocks[role] = name if names.count(name) == 1 else names.index(name) + 1
    notes = ["CHECK: detection interpolated the empty cells of a channel sampled slower on the same clock; "
             "a declaration refuses empty cells (except on a channel's own clock)"] if any(
        "(sampled slower)" in w for w in raw.warnings) else []
    return _render(path, "filled in with what detection found", keys, columns, notes, clocks)


def suggest_declaration(path: str | os.PathLike) -> str:
    """A format declaration (TOML text) that reads ``path``, to save and edit.

    Parameters
    ----------
    path : str or os.PathLike
        The export.

    Returns
    -------
    str
        The declaration: what detection found, or (when it fails) the best guesses from the
        file's head with the values to check marked ``# CHECK``.

    Raises
    ------
    ReadError
        A file that cannot be opened (missing, empty, not a regular file).

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "be_150kPa.csv"
    ...     _ = path.write_text("Zeit;Weg;Kraft\\ns;mm;kN\\n0;0,000;0,0118\\n0,05;0,027;0,01171\\n")
    ...     text = suggest_declaration(path)
    >>> print(text)  # doctest: +ELLIPSIS
    # bendpam format declaration for be_150kPa.csv
    # filled in with what detection found
    header_line = 1
    units_line = 2
    first_data_line = 3
    delimiter = ";"
    decimal = ","
    encoding = "utf-8"
    <BLANKLINE>
    [time]
    column = "Zeit"
    unit = "s"
    ...
    """
    from bendpam.lab.parser import parse_path
    from bendpam.lab.readers import read_tests

    p = Path(path)
    try:
        parsed = parse_path(p, dialect=None, overrides={}, rate_hz=None, repair=False, want_data=False)
        first = read_tests(p)[0]  # what detection reads in the end (padding dropped, dead channels replaced)
    except ReadError as exc:
        text = _from_head(p, exc.message)
    else:
        text = _from_detection(p, parsed, first)
    parse_declaration(text, f"<draft for {p.name}>")  # a draft is always a valid declaration
    return text
