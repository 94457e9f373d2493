"""Checks of the values read from an export: spikes, time order and gaps.

Nothing read from a file reaches a result unchecked.  :func:`find_spikes` finds isolated
samples that lie orders of magnitude off their neighbours (a glitch such as ``2,451502E9`` in a
column of ``2,45``); :func:`noise_spikes` the smaller ones processing removes, samples many times
the noise (:func:`white_noise`) off both neighbours; :func:`time_structure` finds samples out of
order, clock restarts, repeated stamps and gaps in the sampling; :func:`padding_rows` the padding
after the samples.  They work on whole columns with NumPy (linear time, a few temporary arrays).
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

__all__ = [
    "GAP_FACTOR",
    "GAP_MIN_S",
    "SPIKE_FACTOR",
    "SPIKE_STEPS",
    "TimeStructure",
    "find_spikes",
    "noise_spikes",
    "padding_rows",
    "resent_rows",
    "spread_repeats",
    "time_structure",
    "white_noise",
]

#: A sample is a spike when it lies this many robust column ranges off the median of its
#: neighbourhood (5 samples).
SPIKE_FACTOR = 10.0
#: ... and (:func:`noise_spikes`) this many times the steps between the samples beside it: a sharp
#: reversal sampled coarsely rises one step above its neighbours, a glitch many.
SPIKE_STEPS = 4.0
#: Samples on each side whose differences give a spike's local noise (:func:`noise_spikes`).
_NEAR = 64
#: A time step is a gap when it exceeds this many median steps and :data:`GAP_MIN_S`.
GAP_FACTOR = 50.0
#: Shortest gap reported (s).
GAP_MIN_S = 2.0


def find_spikes(x: np.ndarray, scratch: np.ndarray | None = None) -> np.ndarray:
    """Indices of isolated spikes in one column.

    A sample is a spike when its distance to the median of the 5 samples around it exceeds
    :data:`SPIKE_FACTOR` times the column's robust range (its values without the 0.5 % most
    extreme on each side, at least two), i.e. it lies
    an order of magnitude or more outside the values the column otherwise takes.  Up to two
    adjacent bad samples are found.

    Parameters
    ----------
    x : numpy.ndarray
        The column (finite values).
    scratch : numpy.ndarray, optional
        A float array at least as long as ``x`` to work in (its contents are overwritten): the
        checks of several columns of one length then share one temporary.

    Returns
    -------
    numpy.ndarray
        Sorted indices (int64) of the spikes.

    Examples
    --------
    A glitch such as ``2,451502E9`` in a force column of about 2.45 N:

    >>> import numpy as np
    >>> force_n = np.linspace(2.40, 2.50, 50)
    >>> force_n[20] = 2.451502e9
    >>> find_spikes(force_n).tolist()
    [20]
    """
    n = x.size
    if n < 5:
        return np.empty(0, dtype=np.int64)
    k = max(2, int(np.ceil(0.005 * n)))  # leave out the k most extreme values on each side
    part = np.empty_like(x) if scratch is None else scratch[:n]
    np.copyto(part, x)
    part.partition([k, n - 1 - k])
    scale = float(part[n - 1 - k] - part[k])
    # the floor, from the median magnitude, matters only for a column that is nearly constant
    biggest = max(float(x.max()), -float(x.min()))
    if scale < max(1e-9 * max(biggest, 1.0), 1e-12):
        mag = float(np.median(np.abs(x)))
        scale = max(scale, max(1e-9 * max(mag, 1.0), 1e-12))
    return _off_median5(x, SPIKE_FACTOR * scale, part)


def _off_median5(x: np.ndarray, limit: float, scratch: np.ndarray | None = None) -> np.ndarray:
    """Indices ``i`` where ``|x[i] - median(x[i-2:i+3])| > limit`` (edges repeated), sorted.

    Such a sample differs by more than ``limit`` from at least 3 of its 4 neighbours, so from
    ``x[i-1]`` or ``x[i+1]``: the medians are taken only there (the same numbers as
    ``scipy.ndimage.median_filter(x, 5, mode="nearest")``, without filtering the whole column).

    >>> import numpy as np
    >>> x = np.array([1.0, 1.1, 9.0, 1.2, 1.0, 1.1, 1.0, 8.0, 8.0, 8.0, 1.1, 1.0, 1.2])  # a spike, a plateau
    >>> _off_median5(x, 1.0).tolist()
    [2]
    """
    n = x.size
    d = np.empty(n - 1) if scratch is None else scratch[:n - 1]
    np.subtract(x[1:], x[:-1], out=d)  # np.diff(x), in the scratch array
    np.abs(d, out=d)
    j = np.flatnonzero(d > limit)  # steps x[j] -> x[j + 1] larger than the limit
    del d
    cand = np.union1d(j, j + 1)
    if cand.size == 0:
        return np.empty(0, dtype=np.int64)
    if cand.size > n // 4:  # a column of steps: filter it whole
        from scipy import ndimage

        dev = ndimage.median_filter(x, size=5, mode="nearest")
        np.subtract(x, dev, out=dev)
        np.abs(dev, out=dev)
        return np.flatnonzero(dev > limit).astype(np.int64)
    window = np.clip(cand[:, None] + np.arange(-2, 3), 0, n - 1)
    med = np.sort(x[window], axis=1)[:, 2]
    return cand[np.abs(x[cand] - med) > limit].astype(np.int64)


def white_noise(x: np.ndarray) -> float:
    """The white noise of one sample of a column, from the median absolute difference of successive samples.

    ``1.4826 MAD(diff(x)) / sqrt(2)``: robust to a few outliers; a signal's own slope (the differences'
    spread about their median) adds to it, so on a moving signal it errs high.  NaN below three samples.

    >>> rng = np.random.default_rng(1)
    >>> round(white_noise(np.linspace(0.0, 10.0, 20000) + rng.normal(0.0, 0.05, 20000)), 2)
    0.05
    """
    d = np.diff(np.asarray(x, dtype=float))
    if d.size < 2:
        return float("nan")
    return float(1.4826 * np.median(np.abs(d - np.median(d))) / np.sqrt(2.0))


def noise_spikes(x: np.ndarray, sigmas: float) -> tuple[np.ndarray, np.ndarray, float]:
    """Isolated spikes of one or two samples many times the noise off the samples on both sides.

    A sample (or two adjacent ones) is a spike when it lies more than ``sigmas`` noise standard deviations
    (:func:`white_noise`; for a coarse column whose samples mostly repeat, the noise its 90th percentile of
    steps gives, at least its quantum, its smallest step) from the median of the five samples around it
    *and* from both samples beside it (beside the pair), on the same side, by more than :data:`SPIKE_STEPS`
    times the steps between those samples and the next ones out, and by ``sigmas`` times the noise of the
    128 samples around it too (noise that grows with the force, as a gain's does, is larger near the blocked
    state than over the column): a glitch of the load cell or the logger, not a step (stick-slip, a dropped
    load, whose samples on one side follow) nor a reversal sampled coarsely (one step above its neighbours).

    Parameters
    ----------
    x : the column (finite values).
    sigmas : the threshold in noise standard deviations (> 0).

    Returns
    -------
    (indices of the spikes, the values to put in their place: the medians of five around them, the noise SD)

    Examples
    --------
    >>> rng = np.random.default_rng(2)
    >>> f = 10.0 * np.sin(np.linspace(0.0, 6.0, 600)) + rng.normal(0.0, 0.05, 600)
    >>> f[100] += 2.0; f[300:302] -= 1.5; f[450:] += 3.0          # two spikes and a step
    >>> idx, fill, noise = noise_spikes(f, 8.0)
    >>> idx.tolist(), round(noise, 2)
    ([100, 300, 301], 0.07)
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    noise = white_noise(x)
    steps = np.abs(np.diff(x))
    quantum = float(steps[steps > 0].min()) if np.any(steps > 0) else 0.0
    # a coarse column has mostly equal samples (no noise by the median difference): its tenth largest steps
    # then say more of its noise (for Gaussian noise the 90th percentile of |N(0, 2 s^2)| is 1.645 sqrt(2) s)
    noise = noise if np.isfinite(noise) else 0.0
    if noise <= quantum and steps.size >= 10:
        noise = max(quantum, float(np.quantile(steps, 0.9)) / (1.645 * np.sqrt(2.0)))
    empty = np.empty(0, dtype=np.int64)
    if n < 5 or noise <= 0.0:
        return empty, np.empty(0), noise
    limit = sigmas * noise
    cand = _off_median5(x, limit)
    if cand.size == 0:
        return empty, np.empty(0), noise
    # runs of one or two candidates, with the samples on both sides of the run off by more than the limit
    first = np.flatnonzero(np.diff(np.concatenate([[-2], cand])) > 1)
    a, b = cand[first], cand[np.concatenate([first[1:], [cand.size]]) - 1]
    ok = (b - a <= 1) & (a > 1) & (b < n - 2)
    a, b = a[ok], b[ok]
    lo, hi = np.minimum(x[a], x[b]), np.maximum(x[a], x[b])
    side_hi, side_lo = np.maximum(x[a - 1], x[b + 1]), np.minimum(x[a - 1], x[b + 1])
    height = np.maximum(lo - side_hi, side_lo - hi)
    local = np.maximum(np.abs(x[a - 1] - x[a - 2]), np.abs(x[b + 2] - x[b + 1]))  # the steps beside it
    spike = (height > limit) & (height > SPIKE_STEPS * local)
    a, b = a[spike], b[spike]
    if a.size:  # the noise around it: a force's noise may grow with the force (a gain's noise)
        near = np.diff(x[np.clip(a[:, None] + np.arange(-_NEAR, _NEAR + 1), 0, n - 1)], axis=1)
        mad = np.median(np.abs(near - np.median(near, axis=1, keepdims=True)), axis=1)
        keep = height[spike] > sigmas * 1.4826 * mad / np.sqrt(2.0)
        a, b = a[keep], b[keep]
    idx = np.unique(np.concatenate([a, b])).astype(np.int64)
    window = np.clip(idx[:, None] + np.arange(-2, 3), 0, n - 1)
    return idx, np.sort(x[window], axis=1)[:, 2], noise


@dataclass(frozen=True)
class TimeStructure:
    """How a time column runs: out-of-order samples, resets, repeats and gaps.

    Attributes
    ----------
    glitches : numpy.ndarray
        Indices of isolated samples out of order (time goes back at ``i`` and the next sample
        is past ``t[i-1]`` again): a wrong number, not a lab habit.
    resets : numpy.ndarray
        Indices where time goes back and runs on from there (a restart of the clock).
    repeats : numpy.ndarray
        Indices ``i`` with ``t[i] == t[i-1]`` (a repeated time stamp).
    gaps : numpy.ndarray
        Indices ``i`` where ``t[i] - t[i-1]`` is a gap (a pause: see :data:`GAP_FACTOR`).
    median_step_s : float
        Median positive time step (s), NaN if none.

    Examples
    --------
    >>> import numpy as np
    >>> ts = time_structure(np.array([0.0, 0.1, 0.2, 0.2, 30.0, 30.1, 0.0, 0.1, 0.2]))   # s
    >>> ts.repeats.tolist(), ts.gaps.tolist(), ts.resets.tolist(), ts.glitches.tolist()
    ([3], [4], [6], [])
    >>> ts.segments(9)
    [(0, 4), (4, 6), (6, 9)]
    """

    glitches: np.ndarray
    resets: np.ndarray
    repeats: np.ndarray
    gaps: np.ndarray
    median_step_s: float

    def segments(self, n: int) -> list[tuple[int, int]]:
        """``(start, stop)`` sample ranges of continuous sampling (split at resets and gaps)."""
        cuts = np.union1d(self.resets, self.gaps).astype(np.int64).tolist()
        edges = [0, *[c for c in cuts if 0 < c < n], n]
        return [(int(a), int(b)) for a, b in itertools.pairwise(edges) if b > a]


def time_structure(t: np.ndarray) -> TimeStructure:
    """Find out-of-order samples, resets, repeated stamps and gaps in a time column (s).

    Parameters
    ----------
    t : numpy.ndarray
        Time in s, finite.

    Returns
    -------
    TimeStructure

    Examples
    --------
    >>> import numpy as np
    >>> ts = time_structure(np.array([0.0, 0.05, 0.1, 0.08, 0.15]))     # s: one sample out of order
    >>> ts.glitches.tolist(), ts.resets.tolist()
    ([3], [])
    """
    e = np.empty(0, dtype=np.int64)
    if t.size < 2:
        return TimeStructure(e, e, e, e, float("nan"))
    dt = np.diff(t)
    back = np.flatnonzero(dt < 0) + 1
    nxt = np.minimum(back + 1, t.size - 1)
    # out of order: the next sample is past the one before the step back again (or it is the last sample)
    glitch = (t[nxt] > t[back - 1]) | (back == t.size - 1)
    pos = dt[dt > 0]
    med = float(np.median(pos)) if pos.size else float("nan")
    gaps = np.flatnonzero(dt > max(GAP_FACTOR * med, GAP_MIN_S)) + 1 if pos.size else e
    repeats = np.flatnonzero(dt == 0) + 1
    return TimeStructure(back[glitch].astype(np.int64), back[~glitch].astype(np.int64),
                         repeats.astype(np.int64), gaps.astype(np.int64), med)  # fmt: skip


def resent_rows(t: np.ndarray, columns: Iterable[np.ndarray], resets: np.ndarray) -> np.ndarray:
    """Rows sent twice: where time goes back (``resets``) into the stretch before and the rows from there repeat
    that stretch's last rows exactly, in every column (a logger's buffer sent again after a lost acknowledgement).

    Parameters
    ----------
    t : numpy.ndarray
        Time in s.
    columns : iterable of numpy.ndarray
        Every column read (time included or not), each as long as ``t``.
    resets : numpy.ndarray
        Where time goes back and runs on (:attr:`TimeStructure.resets`).

    Returns
    -------
    numpy.ndarray
        A mask, True on the rows that repeat earlier ones (to be dropped); a restart of the clock (time back to
        its start, or rows that differ) is not one.

    Examples
    --------
    >>> import numpy as np
    >>> t = np.array([0.0, 0.1, 0.2, 0.3, 0.2, 0.3, 0.4])     # s: the rows at 0.2 and 0.3 sent again
    >>> f = np.array([1.0, 2.0, 3.0, 4.0, 3.0, 4.0, 5.0])     # N
    >>> resent_rows(t, [t, f], np.array([4])).nonzero()[0].tolist()
    [4, 5]
    >>> resent_rows(t, [t, f + (np.arange(7) == 5)], np.array([4])).any()   # one cell differs: a restart
    np.False_
    """
    t = np.asarray(t, dtype=float)
    cols = [np.asarray(c) for c in columns]
    drop = np.zeros(t.size, dtype=bool)
    starts = np.r_[0, np.asarray(resets, dtype=np.int64)]
    for k, i in enumerate(starts[1:], start=1):  # one per reset (few), not per sample
        a = int(starts[k - 1])
        j = a + int(np.searchsorted(t[a:i], t[i], side="left"))  # the earlier row at the time gone back to
        m = int(i) - j
        if m <= 0 or j <= a or i + m > t.size or t[j] != t[i]:
            continue
        if all(np.array_equal(c[j:i], c[i:i + m]) for c in cols):
            drop[i:i + m] = True
    return drop


def spread_repeats(t: np.ndarray) -> tuple[np.ndarray, int]:
    """Times with every run of repeated stamps spread evenly: ``(times, longest run)``.

    A clock coarser than the sampling (time logged to 0.1 s at 50 Hz), or samples sent in packets that
    each carry one arrival time, writes runs of equal stamps.  The samples were taken evenly, so each
    sample's time is interpolated over its index between the runs' centres (a run of ``m`` equal stamps
    becomes ``m`` times one step apart) and extrapolated at the ends with the nearest runs' step.  The
    times move by at most half a run, and as all channels share the clock the curves do not change;
    a run at a reset of the clock (time going back) or at a gap (:data:`GAP_FACTOR`) keeps to its own side.

    Parameters
    ----------
    t : numpy.ndarray
        Time in s, finite, with no sample out of order (resets allowed).

    Returns
    -------
    times : numpy.ndarray
        Strictly increasing within each run between resets (a copy).
    longest : int
        The longest run of equal stamps (1: none repeated, ``t`` returned as it is).

    Examples
    --------
    >>> import numpy as np
    >>> spread_repeats(np.array([0.0, 0.0, 0.2, 0.2, 0.4, 0.4]))     # s: packets of two
    (array([-0.05,  0.05,  0.15,  0.25,  0.35,  0.45]), 2)
    """
    t = np.asarray(t, dtype=float)
    first = np.flatnonzero(np.r_[True, np.diff(t) != 0])
    longest = int(np.diff(np.r_[first, t.size]).max()) if t.size else 0
    if longest <= 1:
        return t, 1
    out = t.copy()
    back = first[1:][np.diff(t[first]) < 0]  # the clock's resets and the gaps split the record
    cuts = np.union1d(np.r_[0, back, t.size], time_structure(t).gaps).astype(np.int64)
    for a, b in itertools.pairwise(cuts):  # one per reset or gap (few), not per sample
        out[a:b] = _spread(t[a:b])
    return out, longest


def _spread(t: np.ndarray) -> np.ndarray:
    """:func:`spread_repeats` on a stretch whose stamps do not go back (a copy; as it is with one stamp only)."""
    first = np.flatnonzero(np.r_[True, np.diff(t) != 0])
    if first.size < 2 or first.size == t.size:
        return t.copy()
    size = np.diff(np.r_[first, t.size])
    centre = first + (size - 1) / 2.0
    value = t[first]
    idx = np.arange(t.size, dtype=float)
    out = np.interp(idx, centre, value)
    for end, near, rows in ((0, 1, idx < centre[0]), (-1, -2, idx > centre[-1])):
        step = (value[end] - value[near]) / (centre[end] - centre[near])
        out[rows] = value[end] + (idx[rows] - centre[end]) * step
    return out


def padding_rows(t: np.ndarray, stroke: np.ndarray, force: np.ndarray) -> int:
    """Number of padding rows at the end: rows of zeros, or a last row whose time goes back to the start.

    Parameters
    ----------
    t, stroke, force : numpy.ndarray
        Time (s), stroke (mm) and force (N), one length.

    Returns
    -------
    int
        How many rows at the end are padding (never all of them).

    Examples
    --------
    >>> import numpy as np
    >>> t = np.array([0.1, 0.2, 0.3, 0.0, 0.0])       # s
    >>> s = np.array([0.0, 0.1, 0.2, 0.0, 0.0])       # mm
    >>> f = np.array([1.0, 2.0, 3.0, 0.0, 0.0])       # N
    >>> padding_rows(t, s, f), padding_rows(t[:4], s[:4], np.r_[f[:3], 0.5])
    (2, 1)
    """
    n = t.size
    zero = (t == 0) & (stroke == 0) & (force == 0)
    k = int(np.argmin(zero[::-1])) if not zero.all() else 0
    m = n - k
    back = t[:m] <= t[0]  # end records whose time goes back to the start (or to 0)
    r = int(np.argmin(back[::-1])) if m and not back.all() else 0
    if r and m - r >= 2 and t[m - r - 1] > t[0] and r <= max(1, min(5, m // 10)):
        k += r
    return k if k <= n // 2 and n - k >= 2 else 0
