"""The structure of an export, found in one pass over its lines: data blocks, metadata, numbers.

:class:`Parser` reads the lines of a :class:`~bendpam.lab.source.Source` once.  Text lines are
kept as metadata candidates; a line of numbers after text starts a data :class:`Block` (its
names row, an optional units row, the delimiter, the channels chosen by
:func:`bendpam.lab.channels.choose_channels`); the best block (time, stroke and force, or
stroke and force with a sampling rate) is read into :class:`ColumnData`, in blocks of text by
the C parser of :func:`pandas.read_csv`; a block it cannot read is read in pieces, the odd piece
line by line to find the offending line or the end of the block.  :func:`parse_source` and
:func:`parse_path` run the pass and return the :class:`Parsed` result, or raise the
:class:`~bendpam.lab.read_error.ReadError` that says why no block could be read.
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.lab.cblock import c_numbers
from bendpam.lab.channels import (
    ROLES,
    ChannelChoice,
    ColumnInfo,
    choose_channels,
    is_unit_token,
    looks_like_summary,
    normalize_name,
    split_name_unit,
    unit_cell,
    unit_factor,
)
from bendpam.lab.header import find_header, group_period
from bendpam.lab.header_refusal import no_header_error, role_hits
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
from bendpam.lab.rates import other_clocks
from bendpam.lab.read_error import ReadError, show
from bendpam.lab.source import Source, open_source

__all__ = ["Block", "ColumnData", "Parsed", "Parser", "parse_path", "parse_source"]

_CHUNK_LINES = 100_000  # lines looked at at a time when a block is only skipped
_CHUNK_CHARS = 1 << 21  # characters of data lines handed to the C parser at a time
_PIECE_LINES = 2_000  # lines per piece of a chunk that has odd lines (the odd piece is read line by line)
_PEEK_LINES = 200  # data rows inspected for the decimal mark
_TAIL_PEEK = 50  # lines after an odd row looked at: an end or summary record only if the file ends within them
_RATE_KEY = re.compile(
    r"sampl|abtast|mess ?rate|data rate|acquisition rate|recording rate|aufzeichnungsrate|"
    r"frequen|taux d.acquisition|échantillon|campionamento|muestreo|próbkowani|採樣|采样|"
    r"サンプリング|データ取込|rate"
)
_INTERVAL_KEY = re.compile(r"interval|intervall|period|periode|abtastzeit|time step|zeitschritt")
_RATE_UNITS = {"hz": 1.0, "khz": 1000.0, "1/s": 1.0, "/s": 1.0, "s-1": 1.0, "samples/s": 1.0,
               "pts/s": 1.0, "points/s": 1.0, "punkte/s": 1.0}  # fmt: skip


@dataclass
class Block:
    """One data block of an export: its names row, units row, delimiter, columns and rows.

    Attributes
    ----------
    index : int
        1-based number of the block in the file.
    header_line : int
        1-based line of the names row.
    names : list of str
        The names row's cells, as written.
    units_line : int or None
        Line of the units row, if there is one.
    units : list of str or None
        The units row's cells.
    sep : str
        Cell delimiter of the block.
    first_line, first_row : int, str
        The first data line and its text.
    columns : list of ColumnInfo
        The block's columns with their units.
    choice : ChannelChoice or None
        The columns chosen for time, stroke and force (None when a ``columns=`` name is missing).
    override_missing : str or None
        A column named in the ``columns=`` option that the block lacks.
    summary : list of str
        Columns that mark the block as a per-cycle or per-specimen summary.
    n_rows, last_line : int
        Data rows found and the last one's line.
    read : bool
        The block whose numbers were read.
    decimal : str or None
        Decimal mark of the block's numbers.
    specimen_line, specimens : int or None, list of str or None
        A row naming specimens side by side (column groups), if any.
    header_candidates : list of dict
        The rows scored as the names row (:func:`bendpam.lab.header.find_header`), best first.
    groups, group_labels, group : int, list of str, int
        Specimens side by side: the number of column groups, their names, and the 0-based group
        whose columns :attr:`columns` are (1, [], 0 for one specimen).

    Examples
    --------
    >>> from bendpam.lab.channels import ColumnInfo
    >>> cols = [ColumnInfo(0, "time_s", "time", "s"), ColumnInfo(1, "force_n", "force", "n")]
    >>> block = Block(1, 3, ["time_s", "force_n"], None, None, ",", 4, "0,11.8", cols, n_rows=2)
    >>> block.describe()
    'line 3 (time_s, force_n; 2 rows)'
    """

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
    specimen_line: int | None = None
    specimens: list[str] | None = None
    header_candidates: list[dict] = field(default_factory=list)
    groups: int = 1
    group_labels: list[str] = field(default_factory=list)
    group: int = 0

    def describe(self) -> str:
        """Where the block is and what it holds, for a message."""
        names = [n for n in self.names if n]
        shown = ", ".join(names[:6]) + (", ..." if len(names) > 6 else "")
        return f"line {self.header_line} ({shown}; {self.n_rows} rows)"


@dataclass
class ColumnData:
    """The numbers read from the chosen block, in chunks, with their line numbers.

    Attributes
    ----------
    cols : dict of str to list of numpy.ndarray
        role (``"time"``, ``"stroke"``, ``"force"``, ``"counter"``) -> chunks of values in the
        file's units.
    lines : list of numpy.ndarray
        1-based line number of every value, chunk by chunk.
    dropped_nonfinite : list of int
        Lines dropped for a non-finite or empty cell (``repair=True``).
    counter_bad_line : int or None
        First line whose cycle-counter cell is not a number.
    empty_first : dict of str to (int, str)
        role -> ``(line, message)`` of the first empty cell of that column (its values are NaN
        there; :mod:`bendpam.lab.rates` decides whether the pattern is a channel sampled slower).
    clocks : dict of str to ColumnInfo
        ``"clock1"``, ... -> the block's other time columns, read alongside (NaN where not a number).

    Examples
    --------
    >>> import numpy as np
    >>> data = ColumnData()
    >>> data.cols["force"] = [np.array([11.8, 11.71])]
    >>> data.lines.append(np.array([2, 3]))
    >>> np.concatenate(data.cols["force"]).tolist(), data.dropped_nonfinite
    ([11.8, 11.71], [])
    """

    cols: dict[str, list[np.ndarray]] = field(default_factory=dict)
    lines: list[np.ndarray] = field(default_factory=list)
    dropped_nonfinite: list[int] = field(default_factory=list)
    counter_bad_line: int | None = None
    empty_first: dict[str, tuple[int, str]] = field(default_factory=dict)
    clocks: dict[str, ColumnInfo] = field(default_factory=dict)


def _is_units_row(cells: list[str], names: list[str]) -> bool:
    nonempty = [c for c in cells if c]
    if not nonempty or role_hits(cells) > 0 or role_hits(names) == 0:
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
    if not out and " " in line.strip():  # a space-aligned table (MTS BasicTestWare, fixed-width exports)
        num, nonempty = numeric_cells(split_cells(line, " "))
        if num >= 2 and num == nonempty:
            out.append(" ")
    return out


class _Sink:
    """Growing buffers for the numbers of the block read, one per role and one of line numbers.

    The rows of every chunk are copied in place (no list of chunks to join at the end, which would
    hold the numbers twice); the buffers are sized from an estimate of the rows left (the bytes
    left in the file at the bytes per line seen so far), which untouched pages of memory do not
    cost, and grow by half when the estimate was short.
    """

    def __init__(self, roles: list[str]) -> None:
        self.roles = roles
        self.n = 0
        self.bufs = {role: np.empty(0) for role in roles}
        self.lines = np.empty(0, dtype=np.int32)

    def reserve(self, rows: int) -> None:
        """Room for at least ``rows`` rows in all."""
        if rows <= self.lines.size:
            return
        for role in self.roles:
            buf = np.empty(rows)
            buf[:self.n] = self.bufs[role][:self.n]
            self.bufs[role] = buf
        lines = np.empty(rows, dtype=np.int32)
        lines[:self.n] = self.lines[:self.n]
        self.lines = lines

    def add(self, arrs: list[np.ndarray], lnos: np.ndarray) -> None:
        k = len(lnos)
        if self.n + k > self.lines.size:
            self.reserve(max(self.n + k, self.lines.size + self.lines.size // 2 + 4096))
        for role, arr in zip(self.roles, arrs, strict=True):
            self.bufs[role][self.n:self.n + k] = arr
        self.lines[self.n:self.n + k] = lnos
        self.n += k

    def into(self, data: ColumnData) -> None:
        """Hand the rows to ``data``: one more chunk per role (none when no row was read)."""
        for role in self.roles:  # appended: the blocks that continue one test join its rows
            chunks = data.cols.setdefault(role, [])
            if self.n:
                chunks.append(self.bufs[role][:self.n])
        if self.n:
            data.lines.append(self.lines[:self.n])


class Parser:
    """One pass over the lines of an export: blocks, metadata and the chosen block's numbers.

    Parameters
    ----------
    reader : LineReader
        The lines.
    label : pathlib.Path or str
        The file, as named in messages.
    mts : Mts793Header or None
        The first line of an MTS 793 export (its delimiter and decimal mark are honoured).
    default_decimal : str or None
        Decimal mark when the numbers do not show one.
    overrides : dict of str to str
        role -> column name (the ``columns=`` option).
    rate_hz : float or None
        Sampling rate for a block without a time column.
    repair : bool
        Drop rows with a non-finite or empty cell instead of refusing them.
    want_data : bool
        Read the chosen block's numbers (False: only find the blocks, as
        :func:`~bendpam.lab.readers.detect_dialect` does).
    specimen : int or None
        For several specimens side by side (column groups), the 0-based group to read (default
        the first).

    Examples
    --------
    >>> from bendpam.lab.layout import LineReader
    >>> lines = ["# Pressure: 150 kPa", "time_s,stroke_mm,force_n", "0,0,11.8", "0.05,0.027,11.71"]
    >>> parser = Parser(LineReader(lines), "<text>", mts=None, default_decimal=None, overrides={},
    ...                 rate_hz=None, repair=False)
    >>> parser.run()
    >>> parser.chosen.header_line, parser.chosen.n_rows, parser.chosen.decimal
    (2, 2, '.')
    >>> [(line, item.key, item.shown) for line, item in parser.meta_items()]
    [(1, 'Pressure', '150 kPa')]
    """

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
        specimen: int | None = None,
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
        self.blocks: list[Block] = []
        self.chosen: Block | None = None
        self.data: ColumnData | None = None
        self.first_orphan: int | None = None
        self.dollar = False
        self.warnings: list[str] = []
        self.joined: list[Block] = []  # blocks after the chosen one that repeat its header, read with it
        self.specimen = specimen
        self.trailing: list[tuple[int, str]] = []
        self._pending: tuple[int, str, str] | None = None  # a odd row that ends the block unless samples follow
        self._blank_carry = False  # the last chunk of data lines read ended in blank lines
        self._sink = _Sink([])  # the numbers of the block being read

    # -- metadata ----------------------------------------------------------------------------
    def meta_items(self, before: int | None = None) -> list[tuple[int, MetaItem]]:
        """``(line, item)`` of the metadata lines (before line ``before``, if given)."""
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
        """``(rate in Hz, where it was found)`` from a sampling-rate or interval metadata line, or None."""
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
        """Read the lines: find the blocks, keep the text lines, read the best block's numbers."""
        reader = self.reader
        pre: list[tuple[int, str]] = []
        while True:
            line = reader.next()
            if line is None:
                break
            ln = reader.lineno
            if is_blank(line):
                continue
            if line.endswith("\x00") and not self.blocks and "\x00" not in line.rstrip("\x00"):
                line = line.rstrip("\x00")  # a stray NUL at the end of a text line before the data
                self.warnings.append(f"line {ln}: a NUL byte at the end of the line was ignored")
            if has_control_chars(line):
                self._binary_line(ln)
            if line.lstrip().startswith("$"):
                self.dollar = True
            seps = _data_seps(line)
            if seps and pre:
                blk = self._start_block(pre, line, ln, seps)
                reader.push_back([line])
                before = (self.chosen, self.data, list(self.joined), [b.read for b in self.blocks])
                self._consume_block(blk)
                if blk.n_rows < 2 and blk not in self.joined and self._more_lines():
                    # one numeric row among text rows (a channel-metadata row of zeros): not a block;
                    # the rows above stay candidates for the names row of the next block
                    self._dissolve(blk, before)
                    pre.append((ln, line))
                    continue
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

    def _more_lines(self) -> bool:
        """Are there lines left to read?"""
        nxt = self.reader.next()
        if nxt is None:
            return False
        self.reader.push_back([nxt])
        return True

    def _dissolve(self, blk: Block, before: tuple[Any, ...]) -> None:
        """Undo a block of fewer than 2 rows: the parser's state as it was before it."""
        self.chosen, self.data, self.joined, reads = before
        self.blocks.remove(blk)
        for b, r in zip(self.blocks, reads, strict=False):
            b.read = r
        self.block_lines.discard(blk.header_line)
        if blk.units_line is not None:
            self.block_lines.discard(blk.units_line)

    def _binary_line(self, ln: int) -> None:
        raise ReadError(
            "binary data (control characters); expected a text export (CSV/TXT)", self.label, ln
        )

    def _start_block(self, pre: list[tuple[int, str]], line: str, ln: int, seps: list[str]) -> Block:
        order = list(seps)
        if self.mts is not None and self.mts.delimiter in order:
            order.remove(self.mts.delimiter)
            order.insert(0, self.mts.delimiter)
        guess = find_header(pre, line, order, role_hits=role_hits, is_units_row=_is_units_row)
        best: tuple[tuple[int, int, int, int], Block] | None = None
        if guess is not None:
            cols = _make_columns(guess.names, guess.units, guess.names_line, guess.units_line)
            blk = Block(len(self.blocks) + 1, guess.names_line, guess.names, guess.units_line, guess.units,
                        guess.sep, ln, line, cols, specimen_line=guess.specimen_line, specimens=guess.specimens,
                        header_candidates=guess.candidates)  # fmt: skip
            self._split_groups(blk, pre)
            best = ((0, 0, 0, 0), blk)
        p1 = pre[-1]
        p2 = pre[-2] if len(pre) >= 2 else None
        for k, sep in enumerate(order if best is None else []):
            data_cells = split_cells(line, sep)
            c1 = split_cells(p1[1], sep)
            names_ln, names, units_ln, units = p1[0], c1, None, None
            if p2 is not None:
                c2 = split_cells(p2[1], sep)
                if len(c2) >= 2 and _is_units_row(c1, c2):
                    names_ln, names, units_ln, units = p2[0], c2, p1[0], c1
            fit = int(len(_trim(names)) >= 2 and abs(len(_trim(names)) - len(_trim(data_cells))) <= 1)
            score = (role_hits(names), fit, len(names) >= 2, -k)
            cols = _make_columns(names, units, names_ln, units_ln)
            blk = Block(len(self.blocks) + 1, names_ln, names, units_ln, units, sep, ln, line, cols)
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

    def _split_groups(self, blk: Block, pre: list[tuple[int, str]]) -> None:
        """Several specimens side by side: keep the columns of the asked group, name the groups."""
        width = len(_trim(split_cells(blk.first_row, blk.sep)))
        g = group_period(blk.names, width)
        if g is None:
            return
        n = -(-max(len(_trim(blk.names)), width) // g)
        k = min(self.specimen or 0, n - 1)
        repeated = len(_trim(blk.names)) >= 2 * g
        lo = k * g if repeated else 0
        names = blk.names[lo:lo + g]
        units = blk.units[lo:lo + g] if blk.units is not None else None
        cols = _make_columns(names, units, blk.header_line, blk.units_line)
        blk.columns = [dataclasses.replace(c, index=c.index + k * g) for c in cols]
        label_rows = [split_cells(line, blk.sep) for ln, line in pre if ln in (blk.header_line - 1, blk.specimen_line)]
        labels = []
        for j in range(n):
            found = [c for row in label_rows for c in row[j * g:(j + 1) * g] if c]
            labels.append(found[0] if found else f"specimen {j + 1}")
        blk.groups, blk.group_labels, blk.group = n, labels, k

    def _usable(self, blk: Block) -> int:
        """2 = time, stroke and force; 1 = stroke and force (time from a rate, or the sample number); 0 = not usable."""
        ch = blk.choice
        if ch is None or ch.bad_unit:
            return 0
        if {"time", "stroke", "force"} <= set(ch.chosen):
            return 2
        if {"stroke", "force"} <= set(ch.chosen):
            return 1
        return 0

    def _continues(self, blk: Block, level: int) -> bool:
        """Does ``blk`` repeat the chosen block's header (same delimiter and names): one more block of its test?"""
        ch = self.chosen
        if ch is None or level == 0 or self._usable(ch) != level or blk.sep != ch.sep or not self.want_data:
            return False
        return [normalize_name(n) for n in _trim(blk.names)] == [normalize_name(n) for n in _trim(ch.names)]

    def _consume_block(self, blk: Block) -> None:
        self.trailing = []
        level = self._usable(blk)
        current = 0 if self.chosen is None else self._usable(self.chosen)
        if self._continues(blk, level):
            assert self.chosen is not None and self.data is not None
            blk.read = True
            blk.decimal = self.chosen.decimal
            blk.choice = self.chosen.choice
            blk.columns = self.chosen.columns
            self.joined.append(blk)
            self._read_rows(blk, self.data)
            return
        if level > current:
            self.chosen = blk
            blk.read = True
            self.joined = []
            self.trailing = []
            if self.want_data:
                self.data = ColumnData()
                self._read_rows(blk, self.data)
            else:
                self._read_rows(blk, None)
            for other in self.blocks:
                if other is not blk:
                    other.read = False
        else:
            self._read_rows(blk, None)

    # -- rows --------------------------------------------------------------------------------
    def _decimal_for(self, blk: Block) -> str:
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

    def _needed(self, blk: Block) -> list[tuple[str, ColumnInfo]]:
        ch = blk.choice
        assert ch is not None
        out = [(role, ch.chosen[role]) for role in ROLES if role in ch.chosen]
        if "time" in ch.chosen and self.data is not None:
            out += [(name, col) for name, col in other_clocks(blk.columns, ch.chosen["time"])]
            self.data.clocks.update(dict(out[len(ch.chosen):]))
        if ch.counter is not None:
            out.append(("counter", ch.counter))
        return out

    def _read_rows(self, blk: Block, data: ColumnData | None) -> None:
        reader = self.reader
        dec = self._decimal_for(blk)
        blk.decimal = dec
        if data is None:
            self._skip_rows(blk)
            return
        needed = self._needed(blk)
        self._sink = _Sink([role for role, _col in needed])
        self._blank_carry = False
        sized = False
        while True:
            got = reader.take_text(_CHUNK_CHARS)
            if got is None:
                break
            text, n = got
            start = reader.lineno - n + 1
            if not sized and n >= 1000:  # room for the rows the rest of the file will likely hold
                left = reader.bytes_left()
                if left is not None:
                    self._sink.reserve(self._sink.n + n + int(1.02 * left * n / max(len(text), 1)) + 4096)
                sized = True
            arrs = self._fast(text, n, blk, needed, dec, data, start)
            if arrs is not None:
                self._keep_rows(blk, arrs, np.arange(start, start + n, dtype=np.int32))
                continue
            lines = text.split("\n")
            del text
            if self._rows_of_lines(lines, start, blk, needed, dec, data):
                break
        self._sink.into(data)
        self._end_records(blk)

    def _keep_rows(self, blk: Block, arrs: list[np.ndarray], lnos: np.ndarray) -> None:
        self._sink.add(arrs, lnos)
        blk.n_rows += len(lnos)
        blk.last_line = int(lnos[-1])
        self._blank_carry = False

    def _rows_of_lines(self, lines: list[str], start: int, blk: Block, needed, dec: str, data: ColumnData) -> bool:
        """Read a chunk that has odd lines in pieces; True if the block ends in it (the rest pushed back)."""
        for off in range(0, len(lines), _PIECE_LINES):
            piece = lines[off:off + _PIECE_LINES]
            first = start + off
            arrs = self._fast("\n".join(piece), len(piece), blk, needed, dec, data, first)
            if arrs is not None:
                self._keep_rows(blk, arrs, np.arange(first, first + len(piece), dtype=np.int32))
                continue
            end = self._slow(piece, first, blk, needed, dec, data)
            if end is not None:
                self.reader.push_back(lines[off + end:])
                return True
        return False

    def _fast(self, text: str, n: int, blk: Block, needed, dec: str, data: ColumnData,
              start: int = 0) -> list[np.ndarray] | None:  # fmt: skip
        """The needed columns of ``n`` lines of numbers by the C parser, or None if any line is odd.

        Once the optional cycle counter is known to hold a non-number, it is no longer parsed
        (NaN: the counter is left out anyway).
        """
        counter_off = needed[-1][0] == "counter" and data.counter_bad_line is not None
        idx = [col.index for _role, col in (needed[:-1] if counter_off else needed)]
        arrs = c_numbers(text, sep=blk.sep, decimal=dec, columns=idx, n_rows=n)
        if arrs is None and data.empty_first:  # empty cells seen already (a slower channel): keep them as NaN
            arrs = self._fast_empty(text, n, blk, needed[:len(idx)], dec, data, start)
        if arrs is None:
            return None
        if counter_off:
            arrs.append(np.full(n, np.nan))
        return arrs

    def _fast_empty(self, text: str, n: int, blk: Block, needed, dec: str, data: ColumnData,
                    start: int) -> list[np.ndarray] | None:  # fmt: skip
        """The C parser with empty cells as NaN (lines from ``start``), when every row has a time, stroke or force."""
        arrs = c_numbers(text, sep=blk.sep, decimal=dec, columns=[col.index for _r, col in needed], n_rows=n,
                         empty_nan=True)  # fmt: skip
        if arrs is None:
            return None
        core = [(k, role, col) for k, (role, col) in enumerate(needed) if role in ROLES]
        if not np.logical_or.reduce([np.isfinite(arrs[k]) for k, _r, _c in core]).all():
            return None  # a row without any (a blank line): the line-by-line path sees where the block ends
        for k, role, col in core:
            bad = np.flatnonzero(np.isnan(arrs[k]))
            if bad.size and role not in data.empty_first:
                line = text.split("\n", int(bad[0]) + 1)[int(bad[0])]
                data.empty_first[role] = (start + int(bad[0]),
                                          self._row_problem(role, col, "", dec, blk, line))
        if needed[-1][0] == "counter" and data.counter_bad_line is None and np.isnan(arrs[-1]).any():
            data.counter_bad_line = start + int(np.flatnonzero(np.isnan(arrs[-1]))[0])
        return arrs

    def _row_problem(self, role: str, col: ColumnInfo, cell: str | None, dec: str, blk: Block,
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

    def _slow(self, lines: list[str], start: int, blk: Block, needed, dec: str,
              data: ColumnData) -> int | None:  # fmt: skip
        """Parse line by line; the index in ``lines`` where the block ends, or None."""
        sep = blk.sep
        rows: list[list[float]] = []
        lnos: list[int] = []
        blank_run: int | None = 0 if self._blank_carry else None  # blank lines ended the previous chunk
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
            vals, problem, empty = self._cells(cells, ln, needed, dec, data)
            if blk.groups > 1 and (problem is not None or empty) and all(
                    col.index >= len(cells) or not cells[col.index] for _r, col in needed):
                if blank_run is None:  # this specimen's columns have ended (a shorter one side by side)
                    blank_run = k
                continue
            num, nonempty = numeric_cells(cells)
            datalike = num >= 2 and 2 * num >= nonempty
            numbers = datalike or 0 < num == nonempty  # a row of numbers, some cells empty
            if problem is None and (not empty or (numbers and blank_run is None)):
                for role, col, cell in empty:  # NaN: a channel sampled slower, or an end record (rates.py)
                    data.empty_first.setdefault(role, (ln, self._row_problem(role, col, cell, dec, blk, line)))
                rows.append(vals)
                lnos.append(ln)
                blank_run = None
                continue
            if problem is None:
                problem = empty[0]
            if not datalike:
                repeated = [normalize_name(c) for c in cells] == names_norm or any(
                    [normalize_name(c) for c in split_cells(nxt, sep)] == names_norm for nxt in lines[k + 1:k + 3])
                if blank_run is not None or repeated or role_hits(cells) >= 2 or blk.n_rows + len(rows) < 2:
                    end = blank_run if blank_run is not None else k
                    break
            role, col, cell = problem
            if datalike and cell is not None and parse_number(cell, dec).problem not in ("nonfinite", "thousands") and (
                    self._pending is None):  # a row of numbers with text: an end or summary record if no sample follows
                self._pending = (ln, self._row_problem(role, col, cell, dec, blk, line), col.source)
                end = k
                break
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
            self._sink.add([arr[:, j] for j in range(len(needed))], np.asarray(lnos, dtype=np.int32))
            blk.n_rows += len(rows)
            blk.last_line = lnos[-1]
        self._blank_carry = end is None and blank_run is not None  # trailing blank lines: the next chunk decides
        return end

    def _cells(self, cells: list[str], ln: int, needed: list[tuple[str, ColumnInfo]], dec: str, data: ColumnData
               ) -> tuple[list[float], tuple[str, ColumnInfo, str | None] | None,
                          list[tuple[str, ColumnInfo, str | None]]]:  # fmt: skip
        """The needed cells of one row as numbers: ``(values, first bad cell, empty cells)``.

        The counter and the other time columns are NaN where they are not numbers; an empty or
        missing cell of time, stroke or force is NaN and listed; any other bad cell stops the row.
        """
        vals: list[float] = []
        empty: list[tuple[str, ColumnInfo, str | None]] = []
        for role, col in needed:
            cell = cells[col.index] if col.index < len(cells) else None
            res = parse_number(cell, dec) if cell is not None else None
            if res is not None and res.value is not None:
                vals.append(res.value)
                continue
            if role == "counter" or role.startswith("clock"):
                vals.append(math.nan)
                if role == "counter" and cell is not None and data.counter_bad_line is None:
                    data.counter_bad_line = ln
                continue
            if res is None or res.problem == "empty":
                empty.append((role, col, cell))
                vals.append(math.nan)
                continue
            return vals, (role, col, cell), empty
        return vals, None, empty

    def _end_records(self, blk: Block) -> None:
        """After a block ended at an odd row: refuse it if samples follow, else note it as an end record."""
        if self._pending is None:
            return
        ln, message, column = self._pending
        self._pending = None
        ahead = self.reader.take(_TAIL_PEEK)
        self.reader.push_back(ahead)
        needed = self._needed(blk)[:3] if blk.choice is not None else []
        dec = blk.decimal or "."

        def sample(line: str) -> bool:
            cells = split_cells(line, blk.sep)
            return bool(needed) and all(c.index < len(cells) and parse_number(cells[c.index], dec).value is not None
                                        for _r, c in needed)

        if len(ahead) >= _TAIL_PEEK or any(sample(x) for x in ahead[1:]):
            raise ReadError(message, self.label, ln, column)
        rest = [x for x in ahead if not is_blank(x, blk.sep)]
        if _data_seps(rest[0]):  # a text line without delimiters is listed with the text after the data
            self.warnings.append(f"line {ln}: {len(rest)} end or summary record(s) after the samples not read "
                                 f"(no number in column {column!r}: {show(rest[0].strip())})")

    def _skip_rows(self, blk: Block) -> None:
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


@dataclass
class Parsed:
    """What :func:`parse_source` found: the parser (metadata, blocks, numbers), its source and the block read.

    Examples
    --------
    >>> from bendpam.lab.source import text_source
    >>> (source,), _ = text_source(["time_s,stroke_mm,force_n", "0,0,11.8", "0.05,0.027,11.71"])
    >>> parsed = parse_source(source, dialect=None, overrides={}, rate_hz=None, repair=False)
    >>> parsed.block is parsed.parser.chosen, parsed.source.label
    (True, '<text>')
    """

    parser: Parser
    source: Source
    block: Block


def parse_source(source: Source, *, dialect: str | None, overrides: dict[str, str],
                 rate_hz: float | None, repair: bool, want_data: bool = True,
                 specimen: int | None = None) -> Parsed:  # fmt: skip
    """Parse one source: its blocks and metadata, and the numbers of the block to read.

    Parameters
    ----------
    source : Source
        The lines (closed when read).
    dialect : str or None
        The format asked for; ``"testxpert"`` makes the decimal comma the default.
    overrides, rate_hz, repair, want_data, specimen
        As for :class:`Parser`.

    Returns
    -------
    Parsed

    Raises
    ------
    ReadError
        If no block has time (or a rate), stroke and force, saying what was found instead.

    Examples
    --------
    >>> from bendpam.lab.source import text_source
    >>> (source,), _ = text_source("Zeit;Weg;Kraft\\ns;mm;kN\\n0;0,000;0,0118\\n0,05;0,027;0,01171\\n")
    >>> parsed = parse_source(source, dialect=None, overrides={}, rate_hz=None, repair=False)
    >>> block = parsed.block
    >>> block.sep, block.decimal, block.units, block.n_rows
    (';', ',', ['s', 'mm', 'kN'], 2)
    >>> parsed.parser.data.cols["force"][0].tolist()          # kN, as written
    [0.0118, 0.01171]
    """
    mts = parse_mts793(source.first_line)
    default_decimal = "," if dialect == "testxpert" else None
    reader = LineReader(source.lines)
    p = Parser(reader, source.label, mts=mts, default_decimal=default_decimal,
               overrides=overrides, rate_hz=rate_hz, repair=repair, want_data=want_data,
               specimen=specimen)  # fmt: skip
    try:
        p.run()
    finally:
        if source.close is not None:
            source.close()
    if p.chosen is None:
        raise no_header_error(p)
    return Parsed(p, source, p.chosen)


def parse_path(path: Path, *, sheet: str | None = None, **kw: Any) -> Parsed:
    """Parse a file (the first readable sheet of a workbook, or the sheet named); ``kw`` as for :func:`parse_source`.

    Examples
    --------
    >>> import tempfile
    >>> from pathlib import Path
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = Path(folder) / "be_150kPa.csv"
    ...     _ = path.write_text("time_s,stroke_mm,force_n\\n0,0,11.8\\n0.05,0.027,11.71\\n")
    ...     parsed = parse_path(path, dialect=None, overrides={}, rate_hz=None, repair=False)
    >>> parsed.block.header_line, parsed.block.n_rows, parsed.source.encoding
    (1, 2, 'utf-8')
    """
    sources, _size = open_source(path)
    if sheet is not None:
        sources = [s for s in sources if s.sheet == sheet]
        if not sources:
            raise ReadError(f"no sheet {sheet!r} in the workbook", path)
    first_error: ReadError | None = None
    for src in sources:
        try:
            return parse_source(src, **kw)
        except ReadError as exc:
            if not src.is_excel:
                raise
            if first_error is None:
                first_error = ReadError(f"sheet {src.sheet!r}: {exc.message}", path, exc.line,
                                        exc.column)  # fmt: skip
    assert first_error is not None
    raise first_error
