"""Where a table's header is: candidate names, units and specimen rows, scored.

A data block starts at a line of numbers; the rows above it are metadata, the names row, and
maybe a units row, a row of specimen names, a row of empty cells or rows of per-channel
metadata (one cell per column, as HBM catman writes).  :func:`find_header` does not look for
known first lines: it scores every text row above the data (up to :data:`LOOK_BACK` rows) as the
names row, by the channels its cells name (time, stroke, force), how its cell count fits the
data row's (or a whole number of column groups: several specimens side by side), and how near
the data it is; the rows between it and the data must each be a units row (unit tokens), a
specimen row, a row of empty cells or a row of one cell per column.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from bendpam.lab.layout import numeric_cells, split_cells

__all__ = [
    "LOOK_BACK",
    "HeaderGuess",
    "find_header",
    "grid_cells",
    "group_period",
]

#: Text rows above a data row considered as its names row.
LOOK_BACK = 60


@dataclass
class HeaderGuess:
    """The names row (and units and specimen rows) found for one data row.

    Attributes
    ----------
    sep : str
        The delimiter.
    names_line : int
        1-based line of the names row.
    names : list of str
        Its cells.
    units_line : int or None
        Line of the units row, if any.
    units : list of str or None
        Its cells.
    specimen_line : int or None
        Line of a row naming specimens (``Sample 1,,,,Sample 2,,,``), if any.
    specimens : list of str or None
        Its cells.
    score : tuple
        The score the row won with (channels named, fit, nearness).
    candidates : list of dict
        Every row scored: ``{"line", "score", "reasons"}``, best first.

    Examples
    --------
    >>> pre = [(1, "Operator: A"), (2, "Zeit;Weg;Kraft"), (3, "s;mm;N")]
    >>> g = find_header(pre, "0;0,1;2", [";"], role_hits=lambda cells: sum(c in "ZeitWegKraft" for c in cells),
    ...                 is_units_row=lambda cells, names: cells == ["s", "mm", "N"])
    >>> g.names_line, g.names, g.units_line
    (2, ['Zeit', 'Weg', 'Kraft'], 3)
    """

    sep: str
    names_line: int
    names: list[str]
    units_line: int | None = None
    units: list[str] | None = None
    specimen_line: int | None = None
    specimens: list[str] | None = None
    score: tuple = ()
    candidates: list[dict] = field(default_factory=list)


def _trimmed_len(cells: Sequence[str]) -> int:
    n = len(cells)
    while n and not cells[n - 1]:
        n -= 1
    return n


def group_period(names: Sequence[str], width: int) -> int | None:
    """The width of a column group repeated side by side (several specimens), or None.

    The names either repeat with that period (``Time,Force,Time,Force``) or are written above the
    first group only and the data row is a whole number of groups wide.

    Parameters
    ----------
    names : sequence of str
        The names row's cells.
    width : int
        Cells in the data row (trailing empty cells left out).

    Returns
    -------
    int or None

    Examples
    --------
    >>> group_period(["Time", "Force", "Stroke", "Time", "Force", "Stroke"], 6)
    3
    >>> group_period(["Force", "Distance", "Time", "Event", "", "", "", ""], 8)
    4
    >>> group_period(["Temps", "Force", "Course", "", "Temps", "Force", "Course"], 7)
    4
    >>> group_period(["Time", "Force", "Stroke"], 3) is None, group_period(["Time", "Load", "Time"], 3) is None
    (True, True)
    """
    low = [" ".join(n.split()).casefold() for n in names]
    n = _trimmed_len(low)
    for g in range(2, (max(n, width) + 1) // 2 + 1):
        first = [x for x in low[:g] if x]
        if len(first) < 2 or len(set(first)) < len(first):
            continue
        groups = -(-n // g)
        if (groups >= 2 and all(low[i] == low[i % g] for i in range(n))
                and all(not low[i % g] for i in range(n, groups * g))):  # fmt: skip
            return g  # names repeated per group (an empty separator column may end each group)
        if n <= g and len(first) == n and width >= 2 * g and width % g == 0:
            return g  # names above the first group only
    return None


def _between_ok(cells: list[str], names: list[str], width: int) -> str | None:
    """What an in-between row is (units are checked by the caller): a reason, or None if it cannot be there."""
    nonempty = [c for c in cells if c]
    if not nonempty:
        return "empty cells"
    n_names = _trimmed_len(names)
    n = _trimmed_len(cells)
    num, _ne = numeric_cells(cells)
    if 2 <= len(nonempty) <= max(2, width // 2) and len(nonempty) < n and num == 0 and not cells[1]:
        return "specimen names"
    if n >= 2 and abs(n - n_names) <= 1 and len(nonempty) >= max(2, n_names - 1):
        return "one cell per column (channel metadata)"
    if n >= 2 and abs(n - n_names) <= 1 and num == 0 and len(nonempty) >= max(2, (n_names + 1) // 2):
        return "channel metadata (some channels without)"  # catman: no hardware scaling for its time columns
    return None


def _runs(rows: list[tuple[int, str]]) -> list[str]:
    """``line 5: x`` for each row, runs of one kind shown as ``lines 5-31: x (27 rows)``."""
    out: list[str] = []
    k = 0
    while k < len(rows):
        j = k
        while j + 1 < len(rows) and rows[j + 1][1] == rows[k][1]:
            j += 1
        a, b = rows[k][0], rows[j][0]
        out.append(f"line {a}: {rows[k][1]}" if j == k else f"lines {a}-{b}: {rows[k][1]} ({j - k + 1} rows)")
        k = j + 1
    return out


def _merged(upper: list[str], lower: list[str]) -> list[str]:
    """Names written over two rows (``Ch 1`` above ``Force``): the cells joined, the upper carried right."""
    out, carry = [], ""
    for k, low in enumerate(lower):
        up = upper[k] if k < len(upper) else ""
        carry = up or carry
        out.append(" ".join(x for x in (carry if up or low else "", low) if x))
    return out


def grid_cells(text: str, data_line: str) -> list[str]:
    """A space-aligned names or units row cut at the columns of the data row under it.

    Each piece of ``text`` (split at two or more blanks) belongs to the first data column that
    ends at or after the piece's end (right-aligned columns, as fixed-width exports write them);
    pieces of one column are joined as written, and a column with none is ``""``.  Used only when
    the plain split does not give one cell per data column.

    >>> names = "     No.          Time    Phi  (D)    Force"
    >>> data = "      19      0.002099      0.0316     -0.7"
    >>> grid_cells(names, data), grid_cells("                     s                   N", data)
    (['No.', 'Time', 'Phi  (D)', 'Force'], ['', 's', '', 'N'])
    """
    ends = [m.end() for m in re.finditer(r"\S+", data_line)]
    spans: list[list[tuple[int, int]]] = [[] for _ in ends]
    for m in re.finditer(r"\S+(?: \S+)*", text):
        k = next((i for i, e in enumerate(ends) if e >= m.end()), len(ends) - 1)
        if k >= 0:
            spans[k].append((m.start(), m.end()))
    return [text[sp[0][0]:sp[-1][1]] if sp else "" for sp in spans]


def _score_candidate(pre: Sequence[tuple[int, str]], j: int, sep: str, width: int,
                     role_hits: Callable[[list[str]], int],
                     is_units_row: Callable[[list[str], list[str]], bool],
                     data_line: str = "") -> tuple[tuple, HeaderGuess, str] | None:
    ln, line = pre[j]
    names = split_cells(line, sep)
    gridded = sep == " " and data_line and _trimmed_len(names) != width
    if gridded:  # fixed-width columns whose names hold blanks, or a column without a name
        names = grid_cells(line, data_line)
    hits = role_hits(names)
    two_rows = False
    if 0 < hits < 3 and j > 0:  # a names row over two rows?
        upper = split_cells(pre[j - 1][1], sep)
        if _trimmed_len(upper) >= 2 and abs(_trimmed_len(upper) - _trimmed_len(names)) <= 1:
            merged = _merged(upper, names)
            if role_hits(merged) > hits and role_hits(upper) < role_hits(merged):
                names, hits, two_rows = merged, role_hits(merged), True
    n_names = _trimmed_len(names)
    if n_names < 2 and not (n_names == 1 and width == 1):
        return None
    guess = HeaderGuess(sep, ln, names)
    reasons = [f"names {hits} channel(s)" + (" (over two rows)" if two_rows else "")]
    between: list[tuple[int, str]] = []
    for k in range(j + 1, len(pre)):
        bl, bline = pre[k]
        cells = grid_cells(bline, data_line) if gridded else split_cells(bline, sep)
        if guess.units is None and k == j + 1 and is_units_row(cells, names):
            guess.units_line, guess.units = bl, cells
            reasons.append(f"units row at line {bl}")
            continue
        why = _between_ok(cells, names, width)
        if why is None:
            return None
        if why == "specimen names" and guess.specimens is None:
            guess.specimen_line, guess.specimens = bl, cells
        between.append((bl, why))
    reasons += _runs(between)
    fit = 2 if abs(n_names - width) <= 1 else (1 if group_period(names, width) else 0)
    reasons.append({2: "as many names as data cells", 1: "column groups side by side",
                    0: f"{n_names} names for {width} data cells"}[fit])  # fmt: skip
    score = (hits, fit, -(len(pre) - j))
    return score, guess, "; ".join(reasons)


def find_header(pre: Sequence[tuple[int, str]], data_line: str, seps: Sequence[str], *,
                role_hits: Callable[[list[str]], int],
                is_units_row: Callable[[list[str], list[str]], bool]) -> HeaderGuess | None:
    """Score the text rows above a data row as its names row; the best guess, or None.

    Parameters
    ----------
    pre : sequence of (int, str)
        ``(line, text)`` of the text rows since the previous block, in file order.
    data_line : str
        The first data row.
    seps : sequence of str
        Delimiters the data row splits at, preferred first.
    role_hits : callable
        Number of distinct channels (time, stroke, force) a row's cells name.
    is_units_row : callable
        ``is_units_row(cells, names)``: is a row a units row for these names?

    Returns
    -------
    HeaderGuess or None
        None when no row above names a channel.

    Examples
    --------
    >>> pre = [(1, "Force,Distance,Time,,,"), (2, "N,mm,min,,,"), (3, "Sample 1,,,Sample 2,,")]
    >>> hits = lambda cells: len({"Force", "Distance", "Time"} & set(cells))
    >>> g = find_header(pre, "0.1,0,0,0.2,0,0", [","], role_hits=hits,
    ...                 is_units_row=lambda cells, names: cells[:3] == ["N", "mm", "min"])
    >>> g.names_line, g.units_line, g.specimen_line, [c for c in g.specimens if c]
    (1, 2, 3, ['Sample 1', 'Sample 2'])
    """
    best: tuple[tuple, int, HeaderGuess] | None = None
    scored: list[tuple[tuple, dict]] = []
    lo = max(0, len(pre) - LOOK_BACK)
    for k, sep in enumerate(seps):
        width = _trimmed_len(split_cells(data_line, sep))
        for j in range(len(pre) - 1, lo - 1, -1):
            got = _score_candidate(pre, j, sep, width, role_hits, is_units_row, data_line)
            if got is None:
                continue
            score, guess, reasons = got
            full = (*score, -k)
            scored.append((full, {"line": guess.names_line, "delimiter": sep, "score": list(score),
                                  "reasons": reasons}))  # fmt: skip
            if score[0] > 0 and (best is None or full > best[0]):
                best = (full, k, guess)
    if best is None:
        return None
    guess = best[2]
    guess.score = best[0]
    guess.candidates = [d for _s, d in sorted(scored, key=lambda x: x[0], reverse=True)[:8]]
    return guess
