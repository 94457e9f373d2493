"""Empty cells in the columns read: channels sampled at other rates, channels that end first.

Testing-machine software writes channels sampled at different rates into one table.  What the
empty cells of a column mean is decided from their pattern, never from the file's name:

* **its own clock**: the column is shorter than the others and another time column of the block
  ends on the same row (HBM catman writes one time column per rate group, ``Time 1 - default
  sample rate`` and ``Time 1 - slow sample rate``): the column's values belong to that clock and
  are interpolated linearly to the times of the time column read;
* **a value every m rows** (m >= 1.2, evenly spread: steps of floor(m) or ceil(m) rows): a
  channel sampled slower on the same clock; the empty cells between its values are interpolated
  linearly in time;
* **empty after its last value** (or before its first), with no clock of its own: the rows are
  dropped (a channel that ended first, an end record with fewer numbers), as long as they are few
  (at most :data:`MAX_TAIL_FRACTION` of the rows, or 3): more would mean a slower channel whose
  times are unknown, which is refused;
* anything else (an empty cell here and there) is refused, as before, or with ``repair`` its
  rows are dropped.

Rows within one sampling period of a slower channel's first or last value take that value (its
sample holds until the next); rows further out are dropped.  Every decision is one warning line.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from bendpam.lab.channels import ColumnInfo, classify_column, normalize_name
from bendpam.lab.layout import MetaItem
from bendpam.lab.read_error import ReadError

__all__ = ["MAX_END_RECORDS", "MAX_TAIL_FRACTION", "MIN_RATE_VALUES", "counted_samples", "fill_empty_cells",
           "other_clocks", "resample_to_time"]

#: Rows after a column's last value (without a clock of its own) dropped at most, as a fraction of the rows.
MAX_TAIL_FRACTION = 0.05
#: Metadata keys that count the samples written (``Number of points``, ``Samples``, ``Anzahl Messpunkte``, ...).
_COUNT_KEY = re.compile(
    r"(?:(?:total )?number of|no|nb|nbr|num|anzahl(?: der)?|nombre de|numero di|numero de|liczba)?\s*"
    r"(?:data |measured |measurement |recorded )?(?:points|samples|pts|records|scans|messpunkte|punkte|"
    r"datenpunkte|messwerte|points de mesure|punti|puntos|punktow|punktów|próbek)"
)
#: Rows after the counted ones read as end records at most.
MAX_END_RECORDS = 3
#: Values a column sampled slower must have (evenly spread) for its empty cells to be interpolated.
MIN_RATE_VALUES = 5


def other_clocks(columns: Sequence[ColumnInfo], time: ColumnInfo) -> list[tuple[str, ColumnInfo]]:
    """The block's time columns other than ``time``, named ``clock1``, ``clock2``, ...

    Parameters
    ----------
    columns : sequence of ColumnInfo
        The block's columns.
    time : ColumnInfo
        The time column read.

    Returns
    -------
    list of (str, ColumnInfo)

    Examples
    --------
    >>> cols = [ColumnInfo(0, "Time 1 - default sample rate", "Time 1 - default sample rate", "s"),
    ...         ColumnInfo(1, "Time 1 - slow sample rate", "Time 1 - slow sample rate", "s"),
    ...         ColumnInfo(2, "Load", "Load", "kN")]
    >>> [(name, col.source) for name, col in other_clocks(cols, cols[0])]
    [('clock1', 'Time 1 - slow sample rate')]
    """
    out: list[tuple[str, ColumnInfo]] = []
    for col in columns:
        if col.index == time.index:
            continue
        if any(c.role == "time" and c.unit_ok for c in classify_column(col)):
            out.append((f"clock{len(out) + 1}", col))
    return out


def _span(lines: np.ndarray, rows: np.ndarray) -> str:
    a, b = int(lines[rows[0]]), int(lines[rows[-1]])
    return f"line {a}" if a == b else f"lines {a}-{b}"


def _regular(idx: np.ndarray) -> float | None:
    """Rows per value when the values sit evenly every m >= 1.2 rows (steps of floor(m) or ceil(m) rows), else None.

    At least :data:`MIN_RATE_VALUES` values: one empty cell between two values is no pattern.
    """
    if idx.size < MIN_RATE_VALUES:
        return None
    r = (idx[-1] - idx[0]) / (idx.size - 1)
    steps = np.diff(idx)
    if r < 1.2 or steps.min() < np.floor(r) or steps.max() > np.ceil(r) or \
            np.max(np.abs(idx - (idx[0] + r * np.arange(idx.size)))) > 1.0:
        return None  # a step of another length: a missing value, not a rate
    return float(r)


def _own_clock(ok: np.ndarray, clocks: dict[str, tuple[np.ndarray, str]]) -> tuple[np.ndarray, str] | None:
    """A time column with values on exactly the rows of ``ok`` and rising: the column's own clock."""
    for c, name in clocks.values():
        if np.array_equal(np.isfinite(c), ok) and np.all(np.diff(c[ok]) > 0):
            return c, name
    return None


def resample_to_time(x: np.ndarray, clock_s: np.ndarray, t: np.ndarray, lines: np.ndarray, *, source: str,
                     clock: str, time: str) -> tuple[np.ndarray, np.ndarray, str]:  # fmt: skip
    """A channel sampled on its own clock, interpolated linearly to the times ``t`` of the time column read.

    Rows within one of its sampling periods before its first or after its last value take that
    value (a sample holds until the next); rows further out are to be dropped.

    Parameters
    ----------
    x, clock_s : numpy.ndarray
        The channel's values and its clock (s), NaN where a row has none; the rows where both
        are numbers are its samples (its clock must rise over them).
    t : numpy.ndarray
        The time (s) of every row.
    lines : numpy.ndarray
        The line of every row (for the note).
    source, clock, time : str
        The names of the channel's column, of its clock and of the time column read.

    Returns
    -------
    values : numpy.ndarray
        The channel at the times ``t``.
    keep : numpy.ndarray
        The rows within its samples' span (and one period beyond).
    note : str
        One line saying what was done.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.arange(6) * 0.05                               # s, the fast clock
    >>> slow = np.array([0.0, 0.1, 0.2, np.nan, np.nan, np.nan])
    >>> load = np.array([0.0, 1.0, 2.0, np.nan, np.nan, np.nan])
    >>> v, keep, note = resample_to_time(load, slow, t, np.arange(3, 9), source="Load", clock="Time slow",
    ...                                  time="Time")
    >>> v.tolist(), keep.tolist()
    ([0.0, 0.5, 1.0, 1.5, 2.0, 2.0], [True, True, True, True, True, True])
    >>> import textwrap
    >>> print(textwrap.fill(note, 100))
    column 'Load' is sampled on its own clock 'Time slow' (every 0.1 s, 3 values for 6 rows): its
    values interpolated linearly to the times of 'Time'; line 8 within one period past its first or
    last value hold that value
    """
    ok = np.isfinite(x) & np.isfinite(clock_s)
    ct, xs = clock_s[ok], x[ok]
    period = float(np.median(np.diff(ct)))
    keep = (t >= ct[0] - period) & (t <= ct[-1] + period)
    held = np.flatnonzero(keep & ((t < ct[0]) | (t > ct[-1])))
    note = (f"column {source!r} is sampled on its own clock {clock!r} (every {period:.4g} s, {xs.size} values for "
            f"{x.size} rows): its values interpolated linearly to the times of {time!r}"
            + (f"; {_span(lines, held)} within one period past its first or last value hold that value"
               if held.size else "")
            + (f"; {_span(lines, np.flatnonzero(~keep))} further out dropped" if not keep.all() else ""))
    return np.interp(t, ct, xs), keep, note


def _fill_one(x: np.ndarray, t: np.ndarray, source: str, time_source: str, lines: np.ndarray,
              clocks: dict[str, tuple[np.ndarray, str]], notes: list[str]) -> np.ndarray | None:  # fmt: skip
    """Fill one column's empty cells in place; the rows to keep, or None if the pattern is not one of a rate."""
    n = x.size
    ok = np.isfinite(x)
    idx = np.flatnonzero(ok)
    if idx.size < 2:
        return None
    keep = np.ones(n, dtype=bool)
    own = _own_clock(ok, clocks)
    if own is not None:  # values on their own clock: to the times of the time column read
        new, keep, note = resample_to_time(x, own[0], t, lines, source=source, clock=own[1], time=time_source)
        x[:] = new
        notes.append(note)
        return keep
    inner = idx[-1] - idx[0] + 1 > idx.size
    r = _regular(idx) if inner else 1.0
    if r is None:
        return None
    if inner:
        gap = np.flatnonzero(~ok[idx[0]:idx[-1]]) + idx[0]
        rows = np.arange(n, dtype=np.float64)
        base = t if np.all(np.diff(t[idx[0]:idx[-1] + 1]) > 0) else rows
        x[gap] = np.interp(base[gap], base[idx], x[idx])
        notes.append(f"{_span(lines, idx)}: column {source!r} has a value every {r:.3g} rows (sampled "
                     f"slower): its {gap.size} empty cells interpolated linearly in time")
    rows_i = np.arange(n)
    head, tail = rows_i < idx[0], rows_i > idx[-1]
    hold = (head & (idx[0] - rows_i < r)) | (tail & (rows_i - idx[-1] < r))
    x[head & hold], x[tail & hold] = x[idx[0]], x[idx[-1]]
    keep = ~((head | tail) & ~hold)
    if not keep.all():
        if inner or (~keep).sum() > max(3, MAX_TAIL_FRACTION * n):
            return None
        notes.append(f"{_span(lines, np.flatnonzero(~keep))}: column {source!r} is empty (its channel ended "
                     f"first, or an end record with fewer numbers): {(~keep).sum()} row(s) dropped")
    return keep


def fill_empty_cells(values: dict[str, np.ndarray], lines: np.ndarray, sources: dict[str, str],
                     clocks: dict[str, tuple[np.ndarray, str]], empty_first: dict[str, tuple[int, str]],
                     label: Path | str, repair: bool, warnings: list[str]) -> np.ndarray:  # fmt: skip
    """Fill or drop the empty cells (NaN) of time, stroke and force by their pattern (module docstring).

    Parameters
    ----------
    values : dict of str to numpy.ndarray
        role -> values in s, mm, N, NaN where the cell was empty; filled in place.
    lines : numpy.ndarray
        The line of each row.
    sources : dict of str to str
        role -> the column's name as written.
    clocks : dict of str to (numpy.ndarray, str)
        The block's other time columns: values in s (NaN where empty) and name.
    empty_first : dict of str to (int, str)
        role -> line and refusal message of its first empty cell.
    label : pathlib.Path or str
        The file, as named in messages.
    repair : bool
        Drop the rows of an empty cell that fits no pattern instead of refusing it.
    warnings : list of str
        One line per decision is appended.

    Returns
    -------
    numpy.ndarray
        The rows to keep (bool).

    Raises
    ------
    ReadError
        An empty cell that fits no pattern, without ``repair`` (the message of the first one).

    Examples
    --------
    Force sampled at a third of the rate of time and stroke, one row past its last value:

    >>> import textwrap
    >>> import numpy as np
    >>> force = np.full(14, np.nan)
    >>> force[::3] = [0.0, 3.0, 6.0, 9.0, 12.0]                 # N, every third row
    >>> v = {"time": np.arange(14) * 0.1, "stroke": np.arange(14.0), "force": force}
    >>> notes = []
    >>> keep = fill_empty_cells(v, np.arange(2, 16), {"time": "t", "stroke": "s", "force": "F"}, {},
    ...                         {}, "x.csv", False, notes)
    >>> np.round(v["force"], 6).tolist()[9:], bool(keep.all())
    ([9.0, 10.0, 11.0, 12.0, 12.0], True)
    >>> print(textwrap.fill(notes[0], 100))
    lines 2-14: column 'F' has a value every 3 rows (sampled slower): its 8 empty cells interpolated
    linearly in time

    An empty cell here and there is no pattern: refused (or, with ``repair``, its row dropped):

    >>> v["force"][5] = np.nan
    >>> fill_empty_cells(v, np.arange(2, 16), {"time": "t", "stroke": "s", "force": "F"}, {},
    ...                  {"force": (7, "empty cell in column 'F'")}, "x.csv", False, notes)
    Traceback (most recent call last):
    ...
    bendpam.lab.read_error.ReadError: x.csv:7: empty cell in column 'F'
    """
    keep = np.ones(lines.size, dtype=bool)
    roles = [r for r in ("time", "stroke", "force") if r in values and not np.isfinite(values[r]).all()]
    if "time" in roles:  # the time column read: only rows before its first or after its last value go
        keep &= _time_rows(values["time"], lines, sources["time"], warnings)
        if not keep.any():
            keep = _irregular("time", sources["time"], values, lines, empty_first, label, repair, warnings)
        roles.remove("time")
    t = values.get("time", np.arange(lines.size, dtype=np.float64))
    for role in roles:
        got = _fill_one(values[role], t, sources[role], sources.get("time", "time"), lines, clocks, warnings)
        if got is None:
            got = _irregular(role, sources[role], values, lines, empty_first, label, repair, warnings)
        keep &= got
    return keep


def _time_rows(t: np.ndarray, lines: np.ndarray, source: str, warnings: list[str]) -> np.ndarray:
    """Rows to keep when the time column has empty cells: only a few at its ends go (all False: no pattern)."""
    idx = np.flatnonzero(np.isfinite(t))
    contiguous = idx.size >= 2 and idx[-1] - idx[0] + 1 == idx.size
    if not (contiguous and lines.size - idx.size <= max(3, MAX_TAIL_FRACTION * lines.size)):
        return np.zeros(t.size, dtype=bool)
    drop = ~np.isfinite(t)
    warnings.append(f"{_span(lines, np.flatnonzero(drop))}: the time column {source!r} is empty "
                    f"(an end record with fewer numbers?): {drop.sum()} row(s) dropped")
    return ~drop


def _irregular(role: str, column: str, values: dict[str, np.ndarray], lines: np.ndarray,
               empty_first: dict[str, tuple[int, str]], label: Path | str, repair: bool,
               warnings: list[str]) -> np.ndarray:  # fmt: skip
    """Empty cells that fit no pattern: refused (the first one's message) or, with ``repair``, their rows dropped."""
    bad = ~np.isfinite(values[role])
    if not repair:
        line, message = empty_first.get(role, (int(lines[np.argmax(bad)]), f"empty cell in the {role} column"))
        idx = np.flatnonzero(~bad)
        steps = np.diff(idx)
        med = float(np.median(steps)) if steps.size else 1.0
        if med >= 1.2 and (steps > np.ceil(med)).any():  # a slower channel's pattern, broken further down
            j = int(np.flatnonzero(steps > np.ceil(med))[0])
            line = int(lines[idx[j] + int(np.ceil(med))])
            message = (f"an empty cell in column {column!r} breaks its pattern (a value every {med:g} rows up to "
                       f"line {int(lines[idx[j]])}); expected a value every {med:g} rows, as sampled at one rate")
        raise ReadError(message, label, line, column)
    shown = ", ".join(str(int(v)) for v in lines[bad][:5]) + (f" (and {bad.sum() - 5} more)" if bad.sum() > 5 else "")
    warnings.append(f"dropped {bad.sum()} row(s) with a non-finite or empty value at line(s) {shown}")
    return ~bad



def counted_samples(items: Sequence[tuple[int, MetaItem]]) -> tuple[int, str] | None:
    """The number of samples the metadata declare (``Number of points : 2701``), and the line saying it.

    Parameters
    ----------
    items : sequence of (int, MetaItem)
        ``(line, item)`` of the metadata lines above the data.

    Returns
    -------
    (int, str) or None
        The count and ``"line N: 'key : value'"``, or None when no line counts the samples.

    Examples
    --------
    >>> counted_samples([(3, MetaItem("Span", "10,0")), (11, MetaItem("Number of points", "2701"))])
    (2701, "line 11: 'Number of points : 2701'")
    >>> counted_samples([(2, MetaItem("Points per cycle", "200"))]) is None
    True
    """
    for line, item in items:
        if _COUNT_KEY.fullmatch(normalize_name(item.key)) and re.fullmatch(r"\s*\d+\s*", item.value):
            return int(item.value), f"line {line}: '{item.key} : {item.value.strip()}'"
    return None
