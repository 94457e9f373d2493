"""Read an export by its format declaration: no detection at all.

:func:`read_declared` reads a file the way a :class:`~bendpam.lab.declaration.Declaration` says
(names row, units, delimiter, decimal mark, encoding or sheet, the lines of numbers, the columns
of time, stroke and force, blocks, specimens side by side) into one
:class:`~bendpam.lab.rawtest.RawTest` per test.  Nothing is guessed: a line of numbers that does
not match the declaration is refused in one line naming the file and the line (the sheet and the
cell for a workbook).  The values then go through the same checks as detected files
(:func:`bendpam.lab.assemble.check_values`: spikes, time order, gaps).

Cells are split line by line; the numbers of each column are converted a chunk of lines at a
time with vectorised string operations (a strict number grammar, the declared decimal mark and
thousands separator), so memory stays bounded for long files.
"""

from __future__ import annotations

import dataclasses
import os
import re
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from itertools import pairwise
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from bendpam.lab.assemble import check_values
from bendpam.lab.cblock import c_numbers
from bendpam.lab.channels import ROLES, canonical_unit, is_unit_token, split_name_unit, unit_cell, unit_factor
from bendpam.lab.declaration import TEXT_KEYS, Declaration, load_declaration
from bendpam.lab.layout import is_number, parse_metadata_line, split_cells
from bendpam.lab.pressure import (
    PRESSURE_RANGE_TEXT,
    is_pressure_key,
    parse_pressure,
    pressure_from_filename,
    pressure_out_of_range,
)
from bendpam.lab.rates import resample_to_time
from bendpam.lab.rawtest import COLUMNS, RawTest
from bendpam.lab.read_error import ReadError, show

__all__ = ["read_declared"]
_CHUNK = 50_000  # lines converted at a time
_NUMBER = r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?"
_OK, _EMPTY, _BAD = 0, 1, 2


@dataclass
class _Input:
    """The lines of the file (or sheet) and how to split them."""

    label: Path
    lines: Iterable[str]
    encoding: str
    sheet: str | None
    split: Callable[[str], list[str]]
    delimiter: str
    decimal: str
    thousands: str
    close: Callable[[], Any] | None = None


@dataclass
class _Layout:
    """What the lines above the numbers say: names, units, the columns of each role."""

    names: list[str]
    head: list[tuple[int, str]]
    pos: dict[str, int]
    units: dict[str, str]
    sources: dict[str, str | None]
    width: int | None
    groups: int = 1
    specimen_names: list[str] = field(default_factory=list)
    clocks: dict[str, tuple[int, str, str]] = field(default_factory=dict)  # role -> its own time column, name, unit

    @property
    def roles(self) -> tuple[str, ...]:
        """The roles read from the file's columns, in the order of :data:`ROLES`."""
        return tuple(r for r in ROLES if r in self.pos)


def _cell_ref(index: int, row: int) -> str:
    """Spreadsheet reference of a 0-based column and a 1-based row: ``(2, 51) -> 'C51'``."""
    letters = ""
    n = index + 1
    while n:
        n, r = divmod(n - 1, 26)
        letters = chr(65 + r) + letters
    return f"{letters}{row}"


def _where(inp: _Input, index: int, line: int) -> str:
    """How a message names a cell: ``"sheet 'S', cell C51: "`` for a workbook, nothing for text (the line does)."""
    return f"sheet {inp.sheet!r}, cell {_cell_ref(index, line)}: " if inp.sheet is not None else ""


def _splitter(delimiter: str, widths: tuple[int, ...] | None) -> Callable[[str], list[str]]:
    if delimiter == "whitespace":
        return lambda line: [c.strip('"') for c in line.split()]
    if delimiter == "fixed":
        assert widths is not None
        edges = np.concatenate([[0], np.cumsum(widths)]).tolist()
        spans = list(pairwise(edges))
        return lambda line: [line[a:b].strip().strip('"').strip() for a, b in spans]
    return lambda line: split_cells(line, delimiter)


def _open_workbook(path: Path, decl: Declaration) -> _Input:
    from bendpam.lab.source import open_source

    given = [k for k in TEXT_KEYS if k in decl.given]
    if given:
        raise decl.error(given[0], f"applies to text files; {path.name} is a workbook, read by sheet and cell: "
                                   "leave it out")
    sources, _size = open_source(path)
    names = [s.sheet or "" for s in sources]
    shown = ", ".join(repr(n) for n in names)
    if decl.sheet is None:
        if len(sources) > 1:
            raise decl.error("sheet", f"missing: the workbook {path.name} has {len(sources)} sheets ({shown}); "
                                      "expected the name or 1-based number of the one to read")
        src = sources[0]
    elif isinstance(decl.sheet, int):
        if decl.sheet > len(sources):
            raise decl.error("sheet", f"{decl.sheet} is beyond the {len(sources)} sheet(s) of {path.name} ({shown})")
        src = sources[decl.sheet - 1]
    else:
        found = [s for s in sources if s.sheet == decl.sheet]
        if not found:
            raise decl.error("sheet", f"{decl.sheet!r} is not a sheet of {path.name}; expected one of {shown}")
        src = found[0]
    return _Input(path, src.lines, src.encoding, src.sheet, lambda line: line.split("\t"), "\t", ".", "")


def _open(path: Path, decl: Declaration) -> _Input:
    """The lines of the file as the declaration says (a workbook's sheet, or text in its encoding)."""
    from bendpam.infra.budgets import input_file_problem
    from bendpam.lab.encoding import container_kind

    problem = input_file_problem(path, "raw test file")
    if problem is not None:
        raise ReadError(problem, path)
    try:
        with open(path, "rb") as raw:
            head = raw.read(8)
    except OSError as exc:
        raise ReadError(f"cannot read the file ({exc.strerror or exc})", path) from None
    kind = container_kind(head)
    if kind == "gzip":
        raise ReadError("native Zwick .zs2 (or gzip) file; a format declaration reads text exports and "
                        "workbooks: export the test as ASCII from testXpert", path)
    if kind in ("zip", "ole2"):
        return _open_workbook(path, decl)
    if decl.sheet is not None:
        raise decl.error("sheet", f"applies to .xlsx/.xls workbooks; {path.name} is a text file: leave it out")
    if decl.delimiter is None:
        raise decl.error("delimiter", 'missing; expected "tab", ";", ",", "whitespace" or "fixed"')
    encoding = decl.encoding or "utf-8"
    try:
        fh = open(path, encoding=encoding, errors="replace", newline=None)
    except OSError as exc:
        raise ReadError(f"cannot read the file ({exc.strerror or exc})", path) from None
    return _Input(path, fh, encoding, None, _splitter(decl.delimiter, decl.widths), decl.delimiter,
                  decl.decimal or ".", decl.thousands, fh.close)


# ------------------------------------------------------------------------------------------------
# the lines above the numbers
# ------------------------------------------------------------------------------------------------
def _resolve(role: str, decl: Declaration, names: list[str], inp: _Input, key: str = "column") -> int:
    """0-based position of a role's column (``key="clock"``: of its own time column)."""
    spec = decl.columns[role]
    ref = spec.clock if key == "clock" else spec.column
    assert ref is not None
    width = decl.specimen_width
    if isinstance(ref, int):
        return ref - 1
    hits = [i for i, n in enumerate(names) if n.strip() == ref]
    if width is not None:
        hits = [i for i in hits if i < width]
    if not hits:
        cells = ", ".join(repr(n) for n in names if n.strip())
        raise decl.error(f"{role}.{key}", f"{ref!r} is not in the names row (line {decl.header_line} of "
                                           f"{inp.label.name}: {cells}); expected one of its cells or a 1-based "
                                           "position")
    if len(hits) > 1:
        raise decl.error(f"{role}.{key}", f"{ref!r} appears {len(hits)} times in the names row (positions "
                                           f"{', '.join(str(i + 1) for i in hits)}); expected its 1-based position")
    return hits[0]


def _unit(role: str, decl: Declaration, index: int, names: list[str], units_row: list[str] | None) -> str:
    spec = decl.columns[role]
    if spec.unit:
        return spec.unit
    if units_row is not None and index < len(units_row) and units_row[index].strip():
        u = unit_cell(units_row[index]).strip()
        if unit_factor(role, u) is None:
            raise decl.error(f"{role}.unit", f"missing, and the units row (line {decl.units_line}) gives "
                                             f"{show(u)} for {spec.shown}, not a {role} unit; expected {role}.unit")
        return u
    if index < len(names):
        u2 = split_name_unit(names[index])[1]
        if u2 and unit_factor(role, u2) is not None:
            return u2
    raise decl.error(f"{role}.unit", f"missing, and the file gives no unit for {spec.shown}; expected the unit, "
                                     "e.g. unit = \"s\" (time), \"mm\" (stroke), \"N\" (force)")


def _split_names(line: str) -> list[str]:
    """A names or units row with ``delimiter = "whitespace"``: at runs of two or more blanks (or tabs)
    when there are several, so that names holding single spaces (``Ch 1 Force  Time``) stay whole."""
    cells = [c.strip('"') for c in re.split(r"\t|\s{2,}", line.strip()) if c.strip()]
    return cells if len(cells) >= 2 else [c.strip('"') for c in line.split()]


def _read_head(inp: _Input, decl: Declaration, lines: Iterator[tuple[int, str]]) -> _Layout:
    """Read the lines before ``first_data_line``: names, units, specimen names, metadata."""
    head: list[tuple[int, str]] = []
    for ln, line in lines:
        head.append((ln, line))
        if ln == decl.first_data_line - 1:
            break
    if len(head) < decl.first_data_line - 1:
        raise decl.error("first_data_line", f"line {decl.first_data_line} is past the end of {inp.label.name} "
                                            f"({len(head)} line(s){' in its sheet' if inp.sheet else ''})")
    text = dict(head)
    split = _split_names if inp.delimiter == "whitespace" else inp.split
    names = split(text[decl.header_line]) if decl.header_line else []
    units_row = split(text[decl.units_line]) if decl.units_line else None
    pos: dict[str, int] = {}
    units: dict[str, str] = {}
    sources: dict[str, str | None] = {}
    for role in ROLES:
        if role not in decl.columns:
            sources[role] = None
            continue
        i = _resolve(role, decl, names, inp)
        pos[role] = i
        units[role] = _unit(role, decl, i, names, units_row)
        cell = names[i].strip() if i < len(names) else ""
        sources[role] = cell or f"column {i + 1}"
    layout = _Layout(names, head, pos, units, sources, decl.specimen_width)
    for role in layout.roles:
        if decl.columns[role].clock is not None:
            i = _resolve(role, decl, names, inp, "clock")
            cell = units_row[i].strip() if units_row is not None and i < len(units_row) else ""
            unit = cell if cell and unit_factor("time", cell) is not None else units["time"]
            layout.clocks[role] = (i, names[i].strip() if i < len(names) and names[i].strip() else f"column {i + 1}",
                                   unit)
    if decl.specimen_names_line:
        layout.specimen_names = inp.split(text[decl.specimen_names_line])
    return layout


# ------------------------------------------------------------------------------------------------
# the numbers
# ------------------------------------------------------------------------------------------------
def _to_numbers(cells: list[str], decimal: str, thousands: str) -> tuple[np.ndarray, np.ndarray]:
    """Values (NaN where none) and status (0 number, 1 empty, 2 not a number) of a column's cells."""
    s = pd.Series(cells, dtype=object)
    n = len(cells)
    empty = (s == "").to_numpy()
    bad = np.zeros(n, dtype=bool)
    if thousands:
        has = s.str.contains(thousands, regex=False).to_numpy(dtype=bool)
        if has.any():
            t, d = re.escape(thousands), re.escape(decimal)
            group = rf"[+-]?\d{{1,3}}(?:{t}\d{{3}})+(?:{d}\d*)?(?:[eE][+-]?\d+)?"
            bad |= has & ~s.str.fullmatch(group).to_numpy(dtype=bool)
            s = s.str.replace(thousands, "", regex=False)
    if decimal == ",":
        bad |= s.str.contains(".", regex=False).to_numpy(dtype=bool)
        s = s.str.replace(",", ".", regex=False)
    valid = s.str.fullmatch(_NUMBER).to_numpy(dtype=bool) & ~bad
    values = np.full(n, np.nan)
    if valid.any():
        values[valid] = s[valid].astype(np.float64).to_numpy()
    ok = valid & np.isfinite(values)
    return values, np.where(ok, _OK, np.where(empty, _EMPTY, _BAD)).astype(np.int8)


def _data_lines(decl: Declaration, lines: Iterator[tuple[int, str]]) -> Iterator[tuple[int, str]]:
    """The lines from ``first_data_line`` to ``last_data_line`` (negative: from the end, blank lines not counted)."""
    last = decl.last_data_line
    if last is None or last > 0:
        for ln, line in lines:
            if last is not None and ln > last:
                return
            yield ln, line
        return
    keep = -last  # non-blank lines left out at the end, -1 = up to the last one included
    held: deque[tuple[int, str]] = deque()
    nonblank = 0
    for ln, line in lines:
        held.append((ln, line))
        if line.strip():
            nonblank += 1
        while nonblank > keep - 1:
            item = held.popleft()
            if item[1].strip():
                nonblank -= 1
            yield item


@dataclass
class _Part:
    """The samples of one block and one specimen, in the file's units."""

    values: dict[str, list[np.ndarray]] = field(default_factory=dict)
    lines: list[np.ndarray] = field(default_factory=list)
    skipped: int = 0
    dropped: list[int] = field(default_factory=list)


@dataclass
class _State:
    """What the chunks carry to the next: the current block, the separator lines since the last numbers."""

    block: int = -1
    after_sep: bool = True
    sep_texts: list[tuple[int, str]] = field(default_factory=list)
    skip: bool = False
    parts: dict[tuple[int, int], _Part] = field(default_factory=dict)
    blocks: list[dict[str, Any]] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)


def _same_layout(texts: list[tuple[int, str]], inp: _Input, names: list[str]) -> bool:
    """Do the lines before a block keep the declared columns (a repeated names row, or no names row)?"""
    if not names:
        return True
    want = [n.strip() for n in names]
    while want and not want[-1]:
        want.pop()
    other = False
    for _ln, text in texts:
        cells = [c.strip() for c in inp.split(text)]
        if cells[: len(want)] == want:
            return True
        words = [c for c in cells if c and not is_number(c)]
        other = other or len(words) >= 2
    return not other


def _block_names(texts: list[tuple[int, str]], inp: _Input, names: list[str]) -> list[str]:
    """The names row above a block: the declared one when it is repeated (or there is none), else the other one."""
    declared = [n.strip() for n in names if n.strip()]
    found: list[str] | None = None
    for _ln, text in texts:
        cells = [c.strip() for c in inp.split(text) if c.strip()]
        if cells == declared:
            return declared
        if len([c for c in cells if not is_number(c)]) >= 2 and not all(is_unit_token(c) for c in cells):
            found = cells  # the last such line: the names row is the nearest above the numbers
    if found is None and texts:  # only a units row (or other short cells) above the block
        found = [c.strip() for c in inp.split(texts[0][1]) if c.strip()]
    return found if found is not None else declared


def _refuse_cell(inp: _Input, layout: _Layout, k: int, line: int, cell: str, what: str) -> ReadError:
    role = layout.roles[k % len(layout.pos)]
    g = k // len(layout.pos)
    index = layout.pos[role] + g * (layout.width or 0)
    spec = f"{layout.sources[role]!r}" + (f" of specimen {g + 1}" if layout.groups > 1 else "")
    return ReadError(f"{_where(inp, index, line)}{what}: {show(cell)} in the {role} column {spec}; expected a "
                     f"number with decimal {inp.decimal!r} as declared", inp.label, line, layout.sources[role])


def _blocks_of(ok_rows: np.ndarray, sep: np.ndarray, state: _State, lines: np.ndarray, texts: list[str],
               inp: _Input, layout: _Layout, decl: Declaration) -> np.ndarray:
    """Block number of every row (-1 for separators and rows of blocks not read)."""
    prev_sep = np.concatenate([[state.after_sep], sep[:-1]])
    starts = ok_rows & prev_sep
    block = np.full(sep.size, -1, dtype=np.int64)
    idx = np.flatnonzero(sep | starts)
    cur, skip = state.block, state.skip
    last = 0
    for i in idx.tolist():
        block[last:i] = -1 if skip else cur
        if sep[i]:
            if texts[i].strip():
                state.sep_texts.append((int(lines[i]), texts[i]))
            last = i + 1
            block[i] = -1
            continue
        cur += 1
        same = cur == 0 or _same_layout(state.sep_texts, inp, layout.names)
        skip = not same
        names = _block_names(state.sep_texts, inp, layout.names)
        state.blocks.append({"line": int(lines[i]), "columns": names, "rows": 0, "read": same})
        if not same:
            shown = ", ".join(names[:6]) + (", ..." if len(names) > 6 else "")
            state.warnings.append(f"block at line {int(lines[i])} has other columns ({shown}); not read")
        state.sep_texts = []
        last = i
    block[last:] = -1 if skip else cur
    block[sep] = -1
    state.block, state.skip = cur, skip
    state.after_sep = bool(sep[-1]) if sep.size else state.after_sep
    return block


def _convert_chunk(lines: np.ndarray, vals: np.ndarray, status: np.ndarray, cells: list[list[str]] | None,
                   texts: list[str], inp: _Input, layout: _Layout, decl: Declaration, state: _State,
                   repair: bool) -> None:  # fmt: skip
    """Add the samples of one chunk of lines (numbers already converted) to the parts."""
    any_num = (status == _OK).any(axis=0)
    text_row = ~any_num & (status == _BAD).any(axis=0)
    if decl.blocks == "one" and text_row.any():
        assert cells is not None  # the fast path converts numbers only
        i = int(np.flatnonzero(text_row)[0])
        k = int(np.flatnonzero(status[:, i] == _BAD)[0])
        raise _refuse_cell(inp, layout, k, int(lines[i]), cells[i][k], "a line that is not numbers (set "
                           "last_data_line to stop before it, or blocks to read several blocks)")
    if decl.blocks != "one":
        any_num = _names_rows_as_separators(any_num, status, len(layout.roles), state.after_sep)
    if decl.blocks == "one":
        block = np.where(any_num, 0, -1)
        if not state.blocks and any_num.any():
            state.blocks.append({"line": int(lines[any_num][0]), "columns": [n.strip() for n in layout.names
                                                                              if n.strip()], "rows": 0, "read": True})
    else:
        block = _blocks_of(any_num, ~any_num, state, lines, texts, inp, layout, decl)
    nr = len(layout.roles)
    for g in range(layout.groups):
        st = status[g * nr:(g + 1) * nr].copy()
        for k, role in enumerate(layout.clocks):  # a channel on its own clock: empty where its clock is empty
            j = layout.roles.index(role)
            st[j][(st[j] == _EMPTY) & (status[layout.groups * nr + k] == _EMPTY)] = _OK
        good = (st == _OK).all(axis=0) & (block >= 0)
        damaged = any_num & (block >= 0) & ~good & ~(st == _EMPTY).all(axis=0)
        if damaged.any() and not repair:
            assert cells is not None
            i = int(np.flatnonzero(damaged)[0])
            k = g * nr + int(np.flatnonzero(st[:, i] != _OK)[0])
            what = "an empty cell" if status[k, i] == _EMPTY else "not a number"
            raise _refuse_cell(inp, layout, k, int(lines[i]), cells[i][k], what)
        for b in np.unique(block[good]).tolist():
            sel = good & (block == b)
            part = state.parts.setdefault((b, g), _Part())
            for j, role in enumerate(layout.roles):
                part.values.setdefault(role, []).append(vals[g * nr + j][sel])
            for k, role in enumerate(layout.clocks):
                part.values.setdefault(f"clock:{role}", []).append(vals[layout.groups * nr + k][sel])
            part.lines.append(lines[sel])
            part.dropped.extend(lines[damaged & (block == b)].tolist())
            if g == 0:
                state.blocks[b]["rows"] += int(sel.sum())


def _names_rows_as_separators(any_num: np.ndarray, status: np.ndarray, n_roles: int, after_sep: bool
                              ) -> np.ndarray:  # fmt: skip
    """Rows of numbers, leaving out rows with some numbers but no complete sample between two rows of
    text: a names row holding a number (a sensor's serial number ``1281068``) above a block, or a block's
    heading of several such rows (MTS MPT: ``Parado en: 100 cycle`` then ``Puntos: 51``)."""
    complete = np.zeros(any_num.size, dtype=bool)
    for g in range(status.shape[0] // n_roles):
        complete |= (status[g * n_roles:(g + 1) * n_roles] == _OK).all(axis=0)
    sep = ~any_num
    partial = any_num & ~complete
    edges = np.flatnonzero(np.diff(np.concatenate([[0], partial.astype(np.int8), [0]])))
    a, b = edges[::2], edges[1::2]  # the runs [a, b) of partial rows
    before = np.where(a > 0, sep[np.maximum(a - 1, 0)], after_sep)
    after = (b < sep.size) & sep[np.minimum(b, sep.size - 1)]
    marks = np.zeros(sep.size + 1, dtype=np.int64)
    np.add.at(marks, a[before & after], 1)
    np.add.at(marks, b[before & after], -1)
    return any_num & ~(np.cumsum(marks[:-1]) > 0)


def _fast_numbers(texts: list[str], needed: list[int], inp: _Input) -> np.ndarray | None:
    """The chunk's numbers by pandas' C parser (:func:`~bendpam.lab.cblock.c_numbers`, the detected
    reader's path too) when every line is a regular row of finite numbers, else None.

    Only for a one-character delimiter without a thousands separator (whose digit groups the C
    parser would not check); anything irregular (a blank or text line, an empty cell, a line with
    another number of cells) is left to the exact line-by-line path.
    """
    if inp.delimiter not in ("\t", ";", ",", "whitespace") or inp.thousands or not texts:
        return None
    sep = " " if inp.delimiter == "whitespace" else inp.delimiter
    arrs = c_numbers("\n".join(texts), sep=sep, decimal=inp.decimal, columns=needed, n_rows=len(texts),
                     skipinitialspace=True)  # fmt: skip
    return None if arrs is None else np.ascontiguousarray(np.vstack(arrs))


def _groups(cells: list[str], layout: _Layout) -> int:
    """Specimens side by side in the first line of numbers: the column groups with a number in a declared column."""
    w = layout.width
    if not w:
        return 1
    return max(1, sum(1 for g in range(len(cells) // w + 1)
                      if any(layout.pos[r] + g * w < len(cells) and cells[layout.pos[r] + g * w]
                             for r in layout.roles)))


def _read_data(inp: _Input, decl: Declaration, layout: _Layout, lines: Iterator[tuple[int, str]],
               repair: bool) -> _State:
    state = _State()
    needed: list[int] = []
    first_ln = 0
    texts: list[str] = []
    for ln, line in _data_lines(decl, lines):
        if not needed:
            if not line.strip():
                state.after_sep = True
                continue
            layout.groups = _groups(inp.split(line), layout)
            needed = [layout.pos[r] + g * (layout.width or 0) for g in range(layout.groups) for r in layout.roles]
            needed += [c[0] for c in layout.clocks.values()]
            first_ln = ln
        texts.append(line)
        if len(texts) >= _CHUNK:
            _flush(first_ln, texts, needed, inp, layout, decl, state, repair)
            first_ln, texts = ln + 1, []
    if texts:
        _flush(first_ln, texts, needed, inp, layout, decl, state, repair)
    return state


def _flush(first_ln: int, texts: list[str], needed: list[int], inp: _Input, layout: _Layout,
           decl: Declaration, state: _State, repair: bool) -> None:
    """Convert a chunk of consecutive lines (the first is line ``first_ln``)."""
    lines = np.arange(first_ln, first_ln + len(texts), dtype=np.int64)
    vals = _fast_numbers(texts, needed, inp)
    if vals is not None:
        _convert_chunk(lines, vals, np.zeros(vals.shape, dtype=np.int8), None, texts, inp, layout, decl, state,
                       repair)
        return
    cells = []
    for line in texts:
        row = inp.split(line) if line.strip() else []
        cells.append([row[i] if i < len(row) else "" for i in needed])
    vals = np.empty((len(needed), len(texts)))
    status = np.empty((len(needed), len(texts)), dtype=np.int8)
    for k in range(len(needed)):
        vals[k], status[k] = _to_numbers([c[k] for c in cells], inp.decimal, inp.thousands)
    _convert_chunk(lines, vals, status, cells, texts, inp, layout, decl, state, repair)


# ------------------------------------------------------------------------------------------------
# the tests
# ------------------------------------------------------------------------------------------------
def _metadata(layout: _Layout, decl: Declaration, label: Path, pressure_kpa: float | None
              ) -> tuple[dict[str, str], float | None, str | None]:  # fmt: skip
    """The metadata lines above the numbers, and the pressure: option, declaration, metadata or file name."""
    skip = {decl.header_line, decl.units_line, decl.specimen_names_line}
    metadata: dict[str, str] = {}
    meta_p: float | None = None
    for ln, line in layout.head:
        if ln in skip:
            continue
        item = parse_metadata_line(line.replace("\x00", ""))
        if item is None:
            continue
        metadata.setdefault(item.key, item.shown)
        is_p, key_unit = is_pressure_key(item.key)
        if is_p and meta_p is None and item.shown:
            try:
                meta_p = parse_pressure(item.shown, key_unit)
            except ReadError as exc:
                raise ReadError(f"metadata {item.key!r}: {exc.message}", label, ln, item.key) from None
            if pressure_out_of_range(meta_p):
                raise ReadError(f"metadata {item.key!r}: pressure {meta_p:g} kPa is out of range; "
                                f"{PRESSURE_RANGE_TEXT}", label, ln, item.key)
    if pressure_kpa is not None:
        return metadata, pressure_kpa, "option"
    if decl.pressure_kpa is not None:
        return metadata, decl.pressure_kpa, "declaration"
    if meta_p is not None:
        return metadata, meta_p, "metadata"
    p = pressure_from_filename(label.name)
    if p is not None and pressure_out_of_range(p):
        raise ReadError(f"pressure {p:g} kPa in the file name is out of range; {PRESSURE_RANGE_TEXT}", label)
    return metadata, p, "filename" if p is not None else None


def _specimen_name(layout: _Layout, g: int) -> str:
    w = layout.width or 0
    cells = [c.strip() for c in layout.specimen_names[g * w:(g + 1) * w] if c.strip()]
    return cells[0] if cells else f"specimen {g + 1}"


def _make_test(inp: _Input, decl: Declaration, layout: _Layout, state: _State, key: tuple[int | None, int],
               parts: list[_Part], common: dict[str, Any], repair: bool, rate_hz: float | None) -> RawTest:
    """One RawTest from the parts (blocks) of one specimen: units converted, time made or checked."""
    b, g = key
    label = inp.label
    warnings = list(state.warnings)
    which = (f"specimen {_specimen_name(layout, g)!r}" if layout.groups > 1 else "") + (
        f"{' ' if layout.groups > 1 else ''}block {b + 1}" if b is not None else "")
    lines = np.concatenate([ln for p in parts for ln in p.lines]) if parts else np.empty(0, dtype=np.int64)
    if lines.size < 2:
        raise ReadError(f"the declared columns hold {lines.size} row(s) of numbers{' for ' + which if which else ''};"
                        " expected at least 2", label, decl.first_data_line)
    dropped = [ln for p in parts for ln in p.dropped]
    if dropped:
        warnings.append(f"dropped {len(dropped)} row(s) with an empty or non-number cell at line(s) "
                        f"{', '.join(str(v) for v in dropped[:5])}{' (and more)' if len(dropped) > 5 else ''}")
    values: dict[str, np.ndarray] = {}
    channels: dict[str, dict[str, str | None]] = {}
    source_units: dict[str, str] = {}
    why = f"declared in {Path(str(decl.source)).name}"
    for role in layout.roles:
        arr = np.concatenate([v for p in parts for v in p.values[role]])
        f = unit_factor(role, layout.units[role])
        assert f is not None  # checked when the declaration was read
        values[role] = arr * f if f != 1.0 else arr
        unit = canonical_unit(role, layout.units[role])
        channels[role] = {"source": layout.sources[role], "unit": unit, "why": why}
        source_units[COLUMNS[ROLES.index(role)]] = unit
    rate = None
    if "time" not in values:
        rate = rate_hz if rate_hz is not None else decl.rate_hz
        assert rate is not None
        values["time"] = np.arange(lines.size, dtype=np.float64) / rate
        channels["time"] = {"source": None, "unit": "s", "why": f"no time column; made from the sampling rate "
                                                                 f"{rate:g} Hz ({why})"}
        source_units["time_s"] = "s"
        warnings.append(f"no time column: time made from {rate:g} Hz ({why})")
    for role, (_i, clock, unit) in layout.clocks.items():
        ct = np.concatenate([v for p in parts for v in p.values[f"clock:{role}"]]) * (unit_factor("time", unit) or 1.0)
        values[role], keep, note = resample_to_time(values[role], ct, values["time"], lines,
                                                    source=str(layout.sources[role]), clock=clock,
                                                    time=str(layout.sources["time"]))  # fmt: skip
        warnings.append(note)
        values = {r: v[keep] for r, v in values.items()}
        lines = lines[keep]
    values, lines = check_values(values, lines, {r: channels[r] for r in ROLES}, label, repair, warnings)
    if lines.size < 2:
        raise ReadError(f"only {lines.size} sample(s) left after the checks; expected at least 2", label,
                        decl.first_data_line)
    frame = pd.DataFrame({c: values[r] for r, c in zip(ROLES, COLUMNS, strict=True)}, copy=False)
    metadata = dict(common["metadata"])
    extra: dict[str, Any] = {}
    if layout.groups > 1:
        metadata["specimen"] = _specimen_name(layout, g)
        extra["specimen"] = metadata["specimen"]
    if b is not None:
        metadata["block"] = str(b + 1)
        extra["block"] = b + 1
    if inp.sheet is not None:
        metadata.setdefault("sheet", inp.sheet)
    fields = RawTest.__dataclass_fields__
    raw = RawTest(
        data=frame, path=label, dialect="declared", metadata=metadata, pressure_kpa=common["pressure"],
        pressure_source=common["psource"], source_units=source_units, encoding=inp.encoding,
        delimiter=inp.delimiter, decimal=inp.decimal, header_line=decl.header_line,
        channels={r: channels[r] for r in ROLES},
        other_columns=[n.strip() for i, n in enumerate(layout.names) if n.strip() and i not in layout.pos.values()],
        warnings=warnings, blocks=common["blocks"], sample_rate_hz=rate,
        data_lines=(int(lines[0]), int(lines[-1])),
    )
    extra = {k: v for k, v in extra.items() if k in fields}
    return dataclasses.replace(raw, **extra) if extra else raw


def read_declared(
    path: str | os.PathLike,
    declaration: Declaration | str | os.PathLike,
    *,
    pressure_kpa: float | None = None,
    rate_hz: float | None = None,
    repair: bool = False,
) -> list[RawTest]:
    """Read an export by its format declaration, with no detection: one test per block and specimen.

    Parameters
    ----------
    path : str or os.PathLike
        The export (text, or an ``.xlsx``/``.xls`` workbook).
    declaration : Declaration, str or os.PathLike
        The declaration, or its TOML file (:func:`~bendpam.lab.declaration.load_declaration`).
    pressure_kpa : float, optional
        Inflation pressure in kPa; overrides the declaration's, the metadata's and the file name's.
    rate_hz : float, optional
        Sampling rate (Hz) for a declaration without a time column (overrides its ``rate_hz``).
    repair : bool
        Drop rows with an empty or non-number cell, spikes and samples where time does not
        increase, accept gaps, each reported in :attr:`RawTest.warnings` (default: refuse).

    Returns
    -------
    list of RawTest
        One test, or one per specimen (``specimen_width``) and per block (``blocks = "split"``),
        in file order; :attr:`RawTest.dialect` is ``"declared"``.

    Raises
    ------
    ReadError
        One line naming the file and line (the sheet and cell of a workbook) for a line of
        numbers that does not match the declaration, or naming the declaration and its key.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> from bendpam.lab.declaration import parse_declaration
    >>> decl = parse_declaration('header_line = 2\\nfirst_data_line = 4\\ndelimiter = ";"\\ndecimal = ","\\n'
    ...                          'time = {column = "Zeit", unit = "s"}\\nstroke = {column = "Weg", unit = "mm"}\\n'
    ...                          'force = {column = 3, unit = "kN"}\\n', "zwick.toml")
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "be_150kPa.txt"
    ...     _ = path.write_text("Probe 1\\nZeit;Weg;Kraft\\ns;mm;kN\\n0;0,000;0,0118\\n0,05;0,027;0,01171\\n")
    ...     (raw,) = read_declared(path, decl)
    >>> raw.data["force_n"].tolist(), raw.pressure_kpa, raw.channels["force"]["source"]
    ([11.8, 11.71], 150.0, 'Kraft')
    """
    decl = declaration if isinstance(declaration, Declaration) else load_declaration(declaration)
    if rate_hz is not None and "time" in decl.columns:
        raise decl.error("rate_hz", "a sampling rate was given but the declaration has a time column; expected "
                                    "no rate (it is for files without a time column)")
    inp = _open(Path(path), decl)
    try:
        numbered = ((i, line.rstrip("\r\n").lstrip("\ufeff") if i == 1 else line.rstrip("\r\n"))
                    for i, line in enumerate(inp.lines, start=1))
        layout = _read_head(inp, decl, numbered)
        state = _read_data(inp, decl, layout, numbered, repair)
    finally:
        if inp.close is not None:
            inp.close()
    if any("\ufffd" in n for n in layout.names):
        state.warnings.append(f"undecodable bytes in the names row (decoded as {inp.encoding}); check encoding")
    return _tests(inp, decl, layout, state, pressure_kpa, rate_hz, repair)


def _tests(inp: _Input, decl: Declaration, layout: _Layout, state: _State, pressure_kpa: float | None,
           rate_hz: float | None, repair: bool) -> list[RawTest]:
    """One test per block read (``split``) or for all of them, and per specimen."""
    metadata, pressure, psource = _metadata(layout, decl, inp.label, pressure_kpa)
    if len(state.blocks) > 1:
        state.warnings.append(f"{len(state.blocks)} blocks of numbers (at lines "
                              f"{', '.join(str(b['line']) for b in state.blocks)}); "
                              + ("each read as one test" if decl.blocks == "split" else "read one after the other"))
    common = {"metadata": metadata, "pressure": pressure, "psource": psource, "blocks": state.blocks}
    read_blocks = [i for i, b in enumerate(state.blocks) if b["read"]]
    if not read_blocks:
        raise ReadError("no line of numbers in the declared columns; expected numbers from first_data_line = "
                        f"{decl.first_data_line}", inp.label, decl.first_data_line)
    tests = []
    keys: list[tuple[int | None, list[int]]] = (
        [(b, [b]) for b in read_blocks] if decl.blocks == "split" else [(None, read_blocks)])
    for b, blocks in keys:
        for g in range(layout.groups):
            parts = [state.parts[(i, g)] for i in blocks if (i, g) in state.parts]
            tests.append(_make_test(inp, decl, layout, state, (b, g), parts, common, repair, rate_hz))
    return tests
