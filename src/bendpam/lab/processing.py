"""Processing of four-point-bending cyclic tests (paper section 2.2, Figure 4, Table 2).

One raw test (time, stroke, force) at one pressure becomes:

1. **Orientation.**  Force is made positive at the blocked state (compression exports are often
   negative) and stroke is oriented so that it grows toward the free state (force falls as the
   actuator is released); both flips are recorded.
2. **Filtering.**  Isolated spikes of one or two samples, ``despike_sigmas`` (8) noise standard
   deviations off the samples on both sides, are first replaced by the median of the five samples
   around them and noted (:func:`bendpam.lab.checks.noise_spikes`).  Then a zero-phase low-pass
   filter, ``scipy.signal.sosfiltfilt`` with a 4th-order Butterworth design.  The default cutoff is
   1 Hz, limited to 40 % of the Nyquist frequency; the paper's tests run at about 30 mm/min, so a
   cycle lasts minutes and the filter only removes measurement noise.  Set ``cutoff_hz`` to change
   it, or ``cutoff_hz=0`` to switch it off.
3. **Segmentation.**  Turning points of the filtered stroke, found with a hysteresis (zig-zag)
   threshold of ``reversal_fraction`` of the stroke range, so noise, dwell at the ends and small
   back-steps do not create false reversals.  A cycle is blocked -> free -> blocked; a partial
   last cycle (one that does not come back to the blocked state) is dropped and reported.
4. **Zero and conversion.**  The stroke is counted from the blocked state (the median stroke at
   the blocked turning points), then converted to beta, k' and M by eq 6-8
   (:class:`bendpam.physics.fixture.Fixture`), after an optional force tare for self-weight.
5. **Branches.**  Each cycle has an *unloading* branch (blocked -> free, the lower curve) and a
   *loading* branch (free -> blocked, the upper curve).  Each is resampled onto a common curvature
   grid (the range that every branch covers) and averaged over the cycles.  The hysteresis-free
   mean curve is the average of the two mean branches, as in the paper.
6. **Results.**
   * blocked moment: each cycle's maximum moment (the paper's definition), mean and standard error
     over the cycles; also the mean curve extrapolated linearly to k' = 0;
   * free-bending curvature: the curvature at each cycle's turning point toward the free state
     (where the machine found the 0.2 N detection load), mean and standard error;
   * energy-loss ratio (Table 2): loop area / area under that cycle's mean curve from blocked to
     free, both in M-theta (the ratio does not depend on the x-variable's scale), mean over cycles.
7. **Across pressures.**  The deadband pressure is the x-intercept of a least-squares line of
   blocked moment against pressure, with its standard error by the delta method.

Values are magnitudes, as in the paper; a BC-PAM's moment and curvature are negative in bendpam's
model sign convention (multiply by ``actuator.bend_sign`` to compare).

This module holds the algorithms (:func:`process_series` for one test, :func:`process_tests` for
a set); what they produce, :class:`~bendpam.lab.processed.PressureResult` and
:class:`~bendpam.lab.processed.ProcessedSet` with their files, lives in :mod:`bendpam.lab.processed`
(its names are importable from here too).
"""

from __future__ import annotations

import dataclasses
import itertools
import warnings
from typing import TYPE_CHECKING

import numpy as np

from bendpam.errors import InputError, PlausibilityWarning, ProcessingError
from bendpam.lab.checks import noise_spikes
from bendpam.lab.drift import check_drift, drift_findings, moment_shift_nmm, set_drift_findings
from bendpam.lab.plausibility import check_result, compression_like
from bendpam.lab.processed import (
    PressureResult,
    ProcessedSet,
    ProcessingOptions,
    deadband_fit,
    load_processed,
    write_processed,
)
from bendpam.lab.rawtest import check_cycle_count
from bendpam.physics.fixture import PAPER_FIXTURE, Fixture

if TYPE_CHECKING:  # pandas is imported by the functions that use it (fast start-up of `fit`)
    import pandas as pd

__all__ = [
    "NotABendingTest",
    "PressureResult",
    "ProcessedSet",
    "ProcessingError",
    "ProcessingOptions",
    "continuous_time",
    "deadband_fit",
    "find_turning_points",
    "load_processed",
    "number_replicates",
    "process_one",
    "process_series",
    "process_tests",
    "raw_test_name",
    "warn_set",
    "write_processed",
]


# ------------------------------------------------------------------------------------------------
def _lowpass(x: np.ndarray, fs: float, cutoff: float, order: int) -> np.ndarray:
    if cutoff <= 0.0:
        return x.copy()
    from scipy import signal

    sos = signal.butter(order, cutoff, btype="low", fs=fs, output="sos")
    padlen = min(3 * (2 * sos.shape[0] + 1), x.size - 1)
    return signal.sosfiltfilt(sos, x, padlen=padlen)


def _segment_lowpass(x: np.ndarray, tp: np.ndarray, fs: float, cutoff: float, order: int,
                     fallback: np.ndarray) -> np.ndarray:
    """Zero-phase low-pass of each segment ``[tp[j], tp[j+1]]`` separately; shared end points averaged.

    Segments too short for the filter keep the values of ``fallback`` (the whole-record filter).
    """
    if cutoff <= 0.0:
        return x.copy()
    from scipy import signal

    sos = signal.butter(order, cutoff, btype="low", fs=fs, output="sos")
    edges = np.unique(np.concatenate([tp, [x.size - 1]]))
    out = fallback.copy()
    need = 3 * (2 * sos.shape[0] + 1)
    last_end, last_val = -1, 0.0
    for a, b in itertools.pairwise(edges):
        seg = x[a: b + 1]
        if seg.size <= need:
            continue
        y = signal.sosfiltfilt(sos, seg, padtype="odd", padlen=min(seg.size - 1, max(need, int(3 * fs / cutoff))))
        np.add(y, 0.0, out=out[a: b + 1])  # the sum of the one segment, as (0 + y) / 1 was
        if a == last_end:  # the end point shared with the previous filtered segment: their mean
            out[a] = ((0.0 + last_val) + y[0]) / 2.0
        last_end, last_val = int(b), float(y[-1])
    return out


def find_turning_points(stroke: np.ndarray, threshold: float) -> tuple[np.ndarray, np.ndarray]:
    """Alternating extrema of ``stroke`` by a zig-zag rule with a ``threshold`` hysteresis.

    Candidate extrema are the sign changes of the first difference (plateaus collapsed), so the
    Python loop runs over candidates, not samples.  A reversal is confirmed only once the signal
    has moved more than ``threshold`` back from the running extremum, which makes the rule robust
    to noise, dwell and small back-steps.  The first sample is the first turning point.

    Returns
    -------
    idx : int array of sample indices, increasing.
    is_max : bool array, True where the turning point is a maximum.

    Examples
    --------
    Two triangles of stroke (mm), 0 -> 10 -> 0, with a threshold of 0.5 mm:

    >>> import numpy as np
    >>> one = np.concatenate([np.linspace(0.0, 10.0, 11), np.linspace(10.0, 0.0, 11)[1:]])
    >>> idx, is_max = find_turning_points(np.tile(one, 2), 0.5)
    >>> idx.tolist(), is_max.tolist()
    ([0, 10, 20, 31, 41], [False, True, False, True, False])
    """
    s = np.asarray(stroke, dtype=float)
    n = s.size
    d = np.diff(s)
    nz = np.flatnonzero(d != 0.0)
    if nz.size == 0:
        return np.array([0]), np.array([False])
    sg = d[nz] > 0.0  # the sign of each nonzero step, one byte each
    del d
    change = np.flatnonzero(sg[1:] != sg[:-1])
    cand = np.concatenate([[0], nz[change] + 1, [n - 1]])
    vals = s[cand]
    out: list[int] = [0]
    direction = 0
    ext = 0
    first_dir = 0
    for i in range(1, cand.size):
        v = vals[i]
        if direction == 0:
            if abs(v - vals[0]) > threshold:
                direction = first_dir = 1 if v > vals[0] else -1
                ext = i
            continue
        if direction == 1:
            if v >= vals[ext]:
                ext = i
            elif vals[ext] - v > threshold:
                out.append(ext)
                direction, ext = -1, i
        else:
            if v <= vals[ext]:
                ext = i
            elif v - vals[ext] > threshold:
                out.append(ext)
                direction, ext = 1, i
    if direction != 0 and ext != out[-1]:
        out.append(ext)
    idx = cand[np.array(out)]
    # the first point is a minimum if the signal first rises, and the types alternate
    is_max = (np.arange(idx.size) % 2 == 1) if first_dir >= 0 else (np.arange(idx.size) % 2 == 0)
    return idx, is_max


def _checked_arrays(time_s, stroke_mm, force_n, source: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time, stroke and force as float arrays: 1-D, of one length, at least 20, finite, time increasing."""
    t = np.asarray(time_s, dtype=float)
    s_raw = np.asarray(stroke_mm, dtype=float)
    f_raw = np.asarray(force_n, dtype=float)
    if not (t.shape == s_raw.shape == f_raw.shape) or t.ndim != 1:
        raise ProcessingError(f"{source}: time, stroke and force must be 1-D arrays of one length")
    if t.size < 20:
        raise ProcessingError(f"{source}: only {t.size} samples; a cyclic test needs at least 20")
    for name, arr in (("time", t), ("stroke", s_raw), ("force", f_raw)):
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size:
            raise ProcessingError(f"{source}: {name} sample {int(bad[0])} is not finite")
    dt = np.diff(t)
    if np.any(dt <= 0):
        i = int(np.flatnonzero(dt <= 0)[0])
        raise ProcessingError(f"{source}: time does not increase at sample {i + 1} ({t[i]:g} s -> {t[i + 1]:g} s)")
    return t, s_raw, f_raw


def _sampling(t: np.ndarray, opt: ProcessingOptions, source: str, notes: list[str]) -> tuple[float, float]:
    """Step 2's rates: the median sampling rate and the low-pass cutoff (Hz)."""
    dt = np.diff(t)
    largest = float(np.max(dt))
    fs = 1.0 / float(np.median(dt, overwrite_input=True))  # dt is not used after: no copy
    del dt
    if largest > 5.0 / fs:
        notes.append(f"irregular sampling: largest gap {largest:.3g} s at a median rate of {fs:.3g} Hz")
    nyq = 0.5 * fs
    cutoff = (min(1.0, 0.4 * nyq) if opt.cutoff_hz is None else float(opt.cutoff_hz))
    if cutoff >= nyq:
        raise ProcessingError(f"{source}: cutoff {cutoff:g} Hz is not below the Nyquist frequency {nyq:g} Hz")
    return fs, cutoff


def _orient(s_f: np.ndarray, f_f: np.ndarray, s_raw: np.ndarray, f_raw: np.ndarray, notes: list[str]
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:  # fmt: skip
    """Step 1: force positive at the blocked state, stroke growing toward the free state."""
    if np.median(f_f) < 0:
        f_f, f_raw = -f_f, -f_raw
        notes.append("force sign flipped (compression recorded as negative)")
    if np.ptp(f_f) > 0 and _covariance(s_f, f_f) > 0:
        s_f, s_raw = -s_f, -s_raw
        notes.append("stroke direction flipped (stroke recorded as decreasing toward the free state)")
    return s_f, f_f, s_raw, f_raw


def _covariance(x: np.ndarray, y: np.ndarray, block: int = 1 << 18) -> float:
    """Sum of ``(x - mean x) * (y - mean y)`` (the sign of the correlation), in blocks (bounded memory).

    >>> _covariance(np.array([0.0, 1.0, 2.0]), np.array([5.0, 3.0, 1.0]))
    -4.0
    """
    mx, my = float(np.mean(x)), float(np.mean(y))
    return float(sum(np.dot(x[i:i + block] - mx, y[i:i + block] - my) for i in range(0, x.size, block)))


def _complete_cycles(tp: np.ndarray, is_max: np.ndarray, vals: np.ndarray, s0: float, back_tol: float,
                     opt: ProcessingOptions, source: str, notes: list[str]) -> list[tuple[int, int, int]]:
    """Step 3's cycles: min -> max -> min, the closing minimum back near the blocked state."""
    cycles = []
    for j in range(tp.size - 2):
        if not is_max[j] and is_max[j + 1] and not is_max[j + 2] and abs(vals[j + 2] - s0) <= back_tol:
            cycles.append((int(tp[j]), int(tp[j + 1]), int(tp[j + 2])))
    if tp.size and is_max[-1]:
        notes.append("partial last cycle (it did not return to the blocked state) dropped")
    if tp.size and is_max[0]:
        notes.append("the record starts in the free state; its first half-cycle is not used")
    if not cycles:
        raise ProcessingError(
            f"{source}: no complete cycle (blocked -> free -> blocked) found; "
            f"{tp.size} turning points at a {100 * opt.reversal_fraction:g}% reversal threshold"
        )
    return cycles


def _segment(s_raw: np.ndarray, f_raw: np.ndarray, s_f: np.ndarray, f_f: np.ndarray, rng: float, fs: float,
             cutoff: float, opt: ProcessingOptions, source: str, notes: list[str]
             ) -> tuple[np.ndarray, np.ndarray, list[tuple[int, int, int]]]:  # fmt: skip
    """Steps 3-4: turning points, filtered segments, the stroke from the blocked state, the complete cycles.

    Returns the zeroed stroke (mm), the filtered force (N) and the cycles as sample indices
    ``(blocked, free, blocked)``.
    """
    tp, is_max = find_turning_points(s_f, opt.reversal_fraction * rng)
    # Filter each monotone segment between turning points on its own (odd padding continues a
    # ramp linearly), so the corners of the triangular stroke are not rounded: a filter across a
    # reversal would lift the blocked stroke and lower the free one, shifting every curvature.
    s_f = _segment_lowpass(s_raw, tp, fs, cutoff, int(opt.filter_order), s_f)
    f_f = _segment_lowpass(f_raw, tp, fs, cutoff, int(opt.filter_order), f_f)
    vals = s_f[tp]
    mins = np.flatnonzero(~is_max)
    s0 = float(np.median(vals[mins])) if (opt.zero_stroke and mins.size) else 0.0
    s_z = s_f - s0
    cycles = _complete_cycles(tp, is_max, vals, s0, opt.reversal_fraction * rng, opt, source, notes)
    return s_z, f_f, cycles


def _convert(fixture: Fixture, s_z: np.ndarray, f_f: np.ndarray, tare_n: float,
             block: int = 1 << 20) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Step 4's eq 6-8 (:meth:`Fixture.convert`, element by element) in blocks of samples: bounded temporaries.

    A value the fixture refuses is refused as in one call, naming its index in the whole record.

    >>> beta, k, M = _convert(PAPER_FIXTURE, np.linspace(0.0, 5.0, 7), np.full(7, 10.0), 0.0, block=3)
    >>> np.array_equal(M, PAPER_FIXTURE.convert(np.linspace(0.0, 5.0, 7), np.full(7, 10.0))[2])
    True
    """
    n = s_z.size
    if n <= block:
        return fixture.convert(s_z, f_f, tare_n)
    out = np.empty((3, n))
    try:
        for i in range(0, n, block):
            out[:, i:i + block] = fixture.convert(s_z[i:i + block], f_f[i:i + block], tare_n)
    except InputError:
        return fixture.convert(s_z, f_f, tare_n)
    return out[0], out[1], out[2]


def _common_grid(cycles: list[tuple[int, int, int]], k: np.ndarray, grid_n: int, source: str) -> np.ndarray:
    """Step 5's common curvature grid: the range every branch of every cycle covers (1/mm)."""
    seg = [((b, c), (a, b)) for a, b, c in cycles]  # (loading: free->blocked, unloading: blocked->free)
    lo = max(max(k[i0:i1 + 1].min() for (i0, i1) in pair) for pair in seg)
    hi = min(min(k[i0:i1 + 1].max() for (i0, i1) in pair) for pair in seg)
    lo = max(lo, 0.0)
    if not hi > lo:
        raise ProcessingError(f"{source}: the cycles do not share a curvature range (low {lo:g}, high {hi:g} 1/mm)")
    return np.linspace(lo, hi, grid_n)


def _cycle_results(cycles: list[tuple[int, int, int]], k: np.ndarray, M: np.ndarray, grid: np.ndarray,
                   L0_mm: float, t: np.ndarray) -> tuple[np.ndarray, ...]:
    """Steps 5-6 per cycle: ``(branches, blocked moments, free curvatures, loop energies, stored energies,
    branch times)``; the branch times (s) are each grid point's time since its branch began (its reversal)."""
    n, grid_n = len(cycles), grid.size
    branches = np.empty((n, 2, grid_n))
    times = np.empty((n, 2, grid_n))
    bm = np.empty(n)
    kf = np.empty(n)
    loss = np.empty(n)
    stored = np.empty(n)
    for ci, (a, b, c) in enumerate(cycles):
        for bi, (i0, i1) in enumerate(((b, c), (a, b))):  # loading: free->blocked, unloading: blocked->free
            kk, mm = k[i0:i1 + 1], M[i0:i1 + 1]
            order = np.argsort(kk, kind="stable")
            branches[ci, bi] = np.interp(grid, kk[order], mm[order])
            times[ci, bi] = np.interp(grid, kk[order], t[i0:i1 + 1][order] - t[i0])
        bm[ci] = float(M[a:c + 1].max())
        kf[ci] = float(k[b])
        # energy loss in M-theta over this cycle's own range
        own = np.linspace(max(min(k[a:b + 1].min(), k[b:c + 1].min()), 0.0), kf[ci], grid_n)
        up = np.interp(own, *_sorted(k[b:c + 1], M[b:c + 1]))
        down = np.interp(own, *_sorted(k[a:b + 1], M[a:b + 1]))
        th = own * L0_mm
        loss[ci] = float(np.trapezoid(up - down, th))
        stored[ci] = float(np.trapezoid(0.5 * (up + down), th))
    return branches, bm, kf, loss, stored, times


def _labelled_series(t: np.ndarray, s_z: np.ndarray, f_f: np.ndarray, beta: np.ndarray, k: np.ndarray,
                     M: np.ndarray, cycles: list[tuple[int, int, int]]) -> pd.DataFrame:
    """The filtered, converted samples labelled with their cycle (1, 2, ...; -1: none) and branch.

    The frame holds the arrays given (no copies); the branch is categorical (``""``, ``"unloading"``,
    ``"loading"``: one byte a sample).
    """
    cyc = np.full(t.size, -1)
    br = np.zeros(t.size, dtype=np.int8)  # 0: none, 1: unloading, 2: loading
    for ci, (a, b, c) in enumerate(cycles):
        cyc[a:c + 1] = ci + 1
        br[a:b + 1] = 1
        br[b:c + 1] = 2
    import pandas as pd

    names = pd.Categorical.from_codes(br, categories=["", "unloading", "loading"])
    return pd.DataFrame({
        "time_s": t, "stroke_mm": s_z, "force_n": f_f, "beta_rad": beta, "curvature_per_mm": k,
        "moment_nmm": M, "cycle": cyc, "branch": names,
    }, copy=False)


def process_series(
    time_s, stroke_mm, force_n,
    pressure_kpa: float,
    *,
    fixture: Fixture = PAPER_FIXTURE,
    options: ProcessingOptions | None = None,
    source: str = "<data>",
    keep_series: bool = True,
) -> PressureResult:
    """Process one cyclic test at one pressure.  See the module docstring for the steps.

    Parameters
    ----------
    time_s, stroke_mm, force_n : array_like
        The samples: time (s), crosshead stroke (mm) and force (N), 1-D, of one length (at least 20).
    pressure_kpa : float
        The test's pressure (kPa), recorded in the result.
    fixture : Fixture
        The four-point fixture (eq 6-8).
    options : ProcessingOptions, optional
        Filter, segmentation and grid settings (default: :class:`ProcessingOptions()`).
    source : str
        Name of the test in messages and in the result.
    keep_series : bool
        Keep the filtered, converted samples (:attr:`PressureResult.series`).

    Returns
    -------
    PressureResult

    Raises
    ------
    ProcessingError
        For samples that are not finite, time that does not increase, a stroke that does not move,
        no complete cycle, or cycles without a common curvature range.

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> data, truth = simulate_test(bendpam.physics.presets.be_pam(), 150.0,
    ...                             settings=SimulationSettings(cycles=2, rate_hz=5.0, seed=1))
    >>> result = process_series(data["time_s"], data["stroke_mm"], data["force_n"], 150.0)
    >>> result.n_cycles, round(result.blocked_moment[0]), round(truth["blocked_moment_nmm"])   # N*mm
    (2, 205, 204)
    """
    opt = options or ProcessingOptions()
    t, s_raw, f_raw = _checked_arrays(time_s, stroke_mm, force_n, source)
    notes: list[str] = []
    fs, cutoff = _sampling(t, opt, source, notes)
    s_raw, f_raw = (_despike(x, opt.despike_sigmas, t, what, notes) for x, what in ((s_raw, "stroke (mm)"),
                                                                                   (f_raw, "force (N)")))
    s_f, f_f = (_lowpass(x, fs, cutoff, int(opt.filter_order)) for x in (s_raw, f_raw))
    rng = float(np.ptp(s_f))
    if rng <= 0:
        raise ProcessingError(f"{source}: the stroke does not move; no cycles to process")
    _refuse_compression(s_raw, f_raw, opt.reversal_fraction * rng, source)
    s_f, f_f, s_raw, f_raw = _orient(s_f, f_f, s_raw, f_raw, notes)

    s_z, f_f, cycles = _segment(s_raw, f_raw, s_f, f_f, rng, fs, cutoff, opt, source, notes)
    drift, f_f = check_drift(t, s_z, f_raw, f_f, cycles, opt.drift)  # bendpam.lab.drift
    del s_f, s_raw, f_raw  # the whole-record filter and the raw samples are not needed after segmentation

    beta, k, M = _convert(fixture, s_z, f_f, opt.tare_n)
    grid = _common_grid(cycles, k, int(opt.grid_points), source)
    branches, bm, kf, loss, stored, times = _cycle_results(cycles, k, M, grid, fixture.L0_mm, t)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(stored > 0, loss / stored, np.nan)
    if np.any(~np.isfinite(ratio)):
        notes.append("energy-loss ratio undefined for a cycle with no stored energy")

    series = _labelled_series(t, s_z, f_f, beta, k, M, cycles) if keep_series else None
    result = PressureResult(
        pressure_kpa=float(pressure_kpa), source=source, n_cycles=len(cycles), curvature_grid=grid,
        branches=branches, blocked_moments=bm, free_curvatures=kf, energy_loss_ratios=ratio, loop_energy=loss,
        stored_energy=stored, sample_rate_hz=fs, cutoff_hz=cutoff, notes=notes, series=series, drift=drift,
        branch_times_s=times,
    )
    _judge(result, fixture, cycles, k, (t, s_z, f_f, M), opt.tare_n)
    return result


def _despike(x: np.ndarray, sigmas: float, t: np.ndarray, what: str, notes: list[str]) -> np.ndarray:
    """``x`` with its isolated spikes (:func:`~bendpam.lab.checks.noise_spikes`) replaced, and a note of them.

    >>> x = np.r_[np.zeros(50), 5.0, np.zeros(49)] + 0.01 * np.sin(np.arange(100.0))
    >>> notes = []
    >>> float(_despike(x, 8.0, np.arange(100.0), "force (N)", notes).max()) < 0.1, notes[0][:48]
    (True, '1 isolated spike(s) in the force (N) replaced by')
    """
    if not sigmas:
        return x
    idx, fill, noise = noise_spikes(x, sigmas)
    if idx.size == 0:
        return x
    out = x.copy()
    dev = x[idx] - fill
    j = int(np.argmax(np.abs(dev)))
    out[idx] = fill
    notes.append(f"{idx.size} isolated spike(s) in the {what} replaced by the median of the samples around them "
                 f"(the largest {dev[j]:+.3g} at t = {t[idx[j]]:.6g} s, {abs(dev[j]) / noise:.0f} times the noise "
                 f"{noise:.2g}; a spike is {sigmas:g} times the noise off both neighbours; despike_sigmas = 0 keeps "
                 "them)")
    return out


def _refuse_compression(s_raw: np.ndarray, f_raw: np.ndarray, threshold_mm: float, source: str) -> None:
    """Refuse a compression or tension test (:func:`~bendpam.lab.plausibility.compression_like` on the raw samples:
    a low-pass filter rings at a break)."""
    why = compression_like(s_raw, f_raw, threshold_mm)
    if why is not None:
        raise NotABendingTest(f"{source}: not a cyclic bending test (no complete cycle): {why}")


def _judge(result: PressureResult, fixture: Fixture, cycles: list[tuple[int, int, int]], k: np.ndarray,
           samples: tuple[np.ndarray, ...], tare_n: float) -> None:
    """The plausibility findings of a processed test, kept on it and warned about (PlausibilityWarning).

    With a drift estimate (:mod:`bendpam.lab.drift`), first how much correcting it moves the blocked
    moment, from ``samples`` = (time, stroke, force, moment) as processing used them.
    """
    drift = result.drift
    if drift is not None:
        drift.blocked_moment_nmm = result.blocked_moment[0]
        t, s_z, f_f, M = samples
        drift.blocked_moment_shift_nmm = moment_shift_nmm(lambda s, f: fixture.convert(s, f, tare_n)[2], s_z, f_f, M,
                                                          t, cycles, drift, corrected=drift.corrected)
    result.findings = check_result(result, fixture, _return_gaps(cycles, k)) + drift_findings(result)
    for f in result.findings:
        warnings.warn(f["message"], PlausibilityWarning, stacklevel=3)


def _return_gaps(cycles: list[tuple[int, int, int]], k: np.ndarray) -> np.ndarray:
    """Per cycle ``(blocked, free, blocked)``: how far its end curvature lies from its start, over its range.

    >>> _return_gaps([(0, 2, 4)], np.array([0.0, 0.5, 1.0, 0.6, 0.3])).tolist()
    [0.3]
    """
    idx = np.asarray(cycles, dtype=int).reshape(-1, 3)
    a, b, c = k[idx[:, 0]], k[idx[:, 1]], k[idx[:, 2]]
    span = np.abs(b - a)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(span > 0, np.abs(c - a) / span, np.nan)


class NotABendingTest(ProcessingError):
    """A record that is no cyclic bending test (a monotone compression or tension test): a plausibility refusal.

    >>> isinstance(NotABendingTest("c.csv: not a cyclic bending test"), ProcessingError)
    True
    """


def _sorted(x, y):
    o = np.argsort(x, kind="stable")
    return x[o], y[o]



def _located(exc: ProcessingError, src: str, data_lines: tuple[int, int] | None) -> ProcessingError:
    """``exc`` with the data lines of its test after the file name: ``FILE: lines A-B: ...``.

    >>> str(_located(ProcessingError("a.csv: only 5 samples"), "a.csv", (4, 8)))
    'a.csv: lines 4-8: only 5 samples'
    """
    msg = str(exc)
    if data_lines is None or not msg.startswith(f"{src}: "):
        return exc
    first, last = data_lines
    return ProcessingError(f"{src}: lines {first}-{last}: {msg[len(src) + 2:]}")


def raw_test_name(rt) -> str:
    """How a raw test is named in results and messages: its file, and its specimen or block when it has one.

    >>> from types import SimpleNamespace as NS
    >>> raw_test_name(NS(path="s.csv", specimen="3", block=None))
    's.csv [specimen 3]'
    >>> raw_test_name(NS(path="m.txt", specimen=None, block=2))
    'm.txt [block 2]'
    """
    name = str(rt.path)
    specimen, block = getattr(rt, "specimen", None), getattr(rt, "block", None)
    if specimen is not None:
        return f"{name} [specimen {specimen}]"
    if block is not None:
        return f"{name} [block {block}]"
    return name


def process_one(rt, *, fixture: Fixture = PAPER_FIXTURE, options: ProcessingOptions | None = None,
                keep_series: bool = True) -> PressureResult:
    """Process one raw test (a ``RawTest``); its pressure must be known.

    Raises :class:`~bendpam.errors.ProcessingError` naming the test (and its data lines) when it
    cannot be processed, :class:`NotABendingTest` when it is no cyclic bending test.

    >>> from pathlib import Path
    >>> import bendpam
    >>> from bendpam.lab import RawTest
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> data, _ = simulate_test(bendpam.physics.presets.be_pam(), 150.0,
    ...                         settings=SimulationSettings(cycles=2, rate_hz=5.0, seed=1))
    >>> round(process_one(RawTest(data, Path("be.csv"), "csv", pressure_kpa=150.0)).blocked_moment[0])   # N*mm
    205
    """
    src = raw_test_name(rt)
    d = rt.data
    if rt.pressure_kpa is None:
        s = d["stroke_mm"].to_numpy(dtype=float)
        threshold = (options or ProcessingOptions()).reversal_fraction * float(np.ptp(s)) if s.size else 0.0
        why = compression_like(s, d["force_n"].to_numpy(dtype=float), threshold)
        if why is not None:  # say what the test is rather than ask for its pressure
            raise NotABendingTest(f"{src}: not a cyclic bending test (no complete cycle): {why}")
        raise ProcessingError(
            f"{src}: no pressure: give pressure_kpa when reading it, a 'Pressure' metadata line, "
            "or a filename token like 200kPa"
        )
    t, restarts = continuous_time(d["time_s"].to_numpy(dtype=float), getattr(rt, "segments", None) or [])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        try:
            res = process_series(t, d["stroke_mm"].to_numpy(), d["force_n"].to_numpy(),
                                 float(rt.pressure_kpa), fixture=fixture, options=options, source=src,
                                 keep_series=keep_series)
        except ProcessingError as exc:
            located = _located(exc, src, getattr(rt, "data_lines", None))
            raise (type(exc)(str(located)) if isinstance(exc, NotABendingTest) else located) from None
    res.specimen = getattr(rt, "specimen", None)
    res.notes.extend(getattr(rt, "warnings", []) or [])
    if restarts:
        res.notes.append(f"the clock restarts {restarts} time(s): each later segment was placed after the one "
                         "before it, one median sampling interval on")
    mismatch = check_cycle_count(rt, res.n_cycles)
    if mismatch:
        res.notes.append(mismatch)
    return res


def continuous_time(time_s: np.ndarray, segments: list[tuple[int, int]]) -> tuple[np.ndarray, int]:
    """Time made to run on across clock restarts between ``segments`` (sample ranges of a raw test).

    A segment that starts at or before the end of the one before it (a restart of the machine's
    clock, reported by the reader) is shifted to start one median sampling interval after it;
    gaps (time jumping forward) are kept.  Returns the time (s) and the number of restarts.

    >>> t = np.array([0.0, 0.1, 0.2, 0.0, 0.1, 0.2])
    >>> continuous_time(t, [(0, 3), (3, 6)])
    (array([0. , 0.1, 0.2, 0.3, 0.4, 0.5]), 1)
    """
    t = np.asarray(time_s, dtype=float)
    if len(segments) < 2 or t.size < 2:
        return t, 0
    d = np.diff(t)
    step = float(np.median(d[d > 0])) if np.any(d > 0) else 1.0
    out = t.copy()
    restarts = 0
    for start, _stop in segments[1:]:
        if 0 < start < out.size and out[start] <= out[start - 1]:
            out[start:] += out[start - 1] + step - out[start]
            restarts += 1
    return out, restarts


def number_replicates(results: list[PressureResult]) -> list[PressureResult]:
    """``results`` sorted by pressure (then source), with ``replicate`` = 1, 2, ... at each pressure.

    >>> from types import SimpleNamespace as NS
    >>> rs = number_replicates([NS(pressure_kpa=p, source=s, replicate=0)
    ...                         for p, s in ((200, "b"), (100, "x"), (200, "a"))])
    >>> [(r.pressure_kpa, r.source, r.replicate) for r in rs]
    [(100, 'x', 1), (200, 'a', 1), (200, 'b', 2)]
    """
    results = sorted(results, key=lambda r: (r.pressure_kpa, r.source))
    count: dict[float, int] = {}
    for r in results:
        count[r.pressure_kpa] = count.get(r.pressure_kpa, 0) + 1
        r.replicate = count[r.pressure_kpa]
    return results


def process_tests(tests, *, fixture: Fixture = PAPER_FIXTURE, options: ProcessingOptions | None = None,
                  keep_series: bool = True, drift: str | None = None) -> ProcessedSet:
    """Process several raw tests (``RawTest`` objects from :func:`bendpam.lab.read_test`).

    Every test needs a pressure (from the reader: option, metadata or filename).  Several tests at
    one pressure (specimens, repeats) are replicates: each is kept and numbered
    (:attr:`PressureResult.replicate`), :meth:`ProcessedSet.replicates` gives their mean and spread,
    and a fit uses every one.  The first test that cannot be processed raises; to go on past it,
    see :func:`bendpam.lab.batch.process_files`.  ``drift`` (``"none"`` or ``"linear"``), when given,
    replaces ``options.drift`` (:mod:`bendpam.lab.drift`).

    Examples
    --------
    Three virtual tests (two cycles at 5 Hz each, to be quick), processed without files:

    >>> from pathlib import Path
    >>> import bendpam
    >>> from bendpam.lab import RawTest
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> be, settings = bendpam.physics.presets.be_pam(), SimulationSettings(cycles=2, rate_hz=5.0, seed=1)
    >>> raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv",
    ...                 pressure_kpa=p) for p in (100.0, 150.0, 200.0)]
    >>> processed = process_tests(raws, keep_series=False)
    >>> processed.pressures_kpa.tolist()
    [100.0, 150.0, 200.0]
    >>> [round(p["blocked_moment_nmm"]) for p in processed.summary()["pressures"]]   # N*mm
    [80, 205, 330]
    >>> round(processed.deadband()[0])                  # kPa: the x-intercept (P_start = 68 kPa)
    68
    """
    if drift is not None:
        options = dataclasses.replace(options or ProcessingOptions(), drift=drift)
    results = [process_one(rt, fixture=fixture, options=options, keep_series=keep_series) for rt in tests]
    if not results:
        raise ProcessingError("no tests to process")
    warn_set(results)
    return ProcessedSet(results=number_replicates(results), fixture=fixture, options=options or ProcessingOptions())


def warn_set(results) -> None:
    """Warn (PlausibilityWarning) the findings of the set as a whole: a drift its tests share
    (:func:`bendpam.lab.drift.set_drift_findings`).

    >>> import warnings
    >>> from types import SimpleNamespace as NS
    >>> from bendpam.lab.drift import DriftEstimate
    >>> e = DriftEstimate(2e-4, 1e-4, 300.0, 0.0, 0.05, 10.0, 12)
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warn_set([NS(drift=e, source="a.csv"), NS(drift=e, source="b.csv")])
    >>> [str(w.message)[:50] for w in caught]
    ['the load-cell offset drifts in the set as a whole:']
    """
    for f in set_drift_findings(results):
        warnings.warn(f["message"], PlausibilityWarning, stacklevel=3)
