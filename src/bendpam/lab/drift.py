"""Load-cell offset drift and zero checks of a cyclic bending test.

A four-point-bending test repeats the same stroke path cycle after cycle, so, apart from noise, the
force at a given place of a cycle (the free end, where the fixture reads about the detection load;
the blocked end, where the force is largest) is the same in every cycle.  A load-cell offset that
drifts adds the same ``a * t`` to every sample, and shows as a trend of those forces across cycles.

:func:`estimate_drift` reads the force near the four ends of every cycle (the end of the unloading
and the start of the loading at the free state; the end of the loading and the start of the
unloading at the blocked state).  Each end is a band of stroke common to all cycles, from 1 % to
10 % of the stroke range (``band_fraction``) away from the median turning stroke (the very tips,
where the cycles turn at slightly different strokes or dwell, are left out).  Each cycle's force
and time are interpolated on one stroke grid over the band and averaged, so every cycle is read at
the same strokes whatever the phase of its sampling.  With three cycles or more the first cycle's
unloading is left out: it starts from the state before any cycling, and a hysteresis loop (or the
Mullins softening of a rubber) settles during it.  Then ``F = c_end + a t`` is fitted by least
squares with one intercept per end and one common slope ``a`` (N/s).  Its standard error is the
larger of the residual one and the one the force noise alone gives (the noise from the differences
of successive samples), so a few cycles do not make it small by chance.  The free ends alone and
the blocked ends alone give their own slopes: an offset drift moves both alike, creep or a loop
that settles moves the blocked ends more.

The drift is *flagged* (:attr:`DriftEstimate.flagged`) when it is both significant (``|a| >= 3``
standard errors) and large enough to bias a fit: over the test it reaches ``0.1 %`` of the blocked
force (:data:`FLAG_FRACTION`).  On independent test data a drift of 1 % of the blocked force over
a test moved a fitted ``alpha0`` by about 20 of its standard errors, so 0.1 % is about 2.

A load cell that drifts does so in every test of a set, so the tests' slopes are also pooled
(:func:`set_drift`, the inverse-variance mean in N/s): a set whose pooled slope reaches
:data:`SET_FLAG_SIGMAS` of its standard error drifts, even when no single test is long or
quiet enough to show it (:func:`set_drift_findings`).  Then every test's drift is real to the fit:
left uncorrected, each adds its doubt (:func:`bendpam.identify.data.drift_offsets`).

When the offset was zeroed the data do not say.  A log that starts at ``t = 0`` was zeroed there (the
machine is zeroed before the test).  A log whose clock starts later, ``0 < t_0 <= duration`` (a testing
machine's test time counts from the start of the test, and the log often begins at a pre-load, after a
pre-cycle or a step before: 43 of the 88 real exports of ``tests/data/real`` that are read start at a
time ``0 < t_0 <= duration``, 43 at 0 and 2 later),
was zeroed at some instant between the clock's zero and its first sample: the offset is taken as zero
halfway (:attr:`DriftEstimate.zero_s`, ``t_0 / 2``), and the two ends being equally likely, the rest of
the offset at the first sample is doubt: a rectangular distribution of half-width ``|a| t_0 / 2``,
standard deviation ``|a| t_0 / (2 sqrt 3)`` (:attr:`DriftEstimate.zero_sd_n`, GUM 4.3.7), which the fit
counts with a corrected drift.  A clock that starts later still (a time of day) is taken as zeroed at the
first sample.  :meth:`DriftEstimate.offset_n` is the fitted offset ``a (t - zero_s)`` that a correction
subtracts.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, fields

import numpy as np

from bendpam.lab.checks import white_noise

__all__ = ["DRIFT_METHODS", "FLAG_FRACTION", "FLAG_SIGMAS", "SET_FLAG_SIGMAS", "DriftEstimate", "check_drift",
           "drift_findings", "estimate_drift", "moment_shift_nmm", "set_drift", "set_drift_findings", "set_drifts"]

#: The drift corrections processing knows: ``"none"`` (estimate and report only) and ``"linear"``.
DRIFT_METHODS = ("none", "linear")
#: A drift is flagged when over the test it reaches this fraction of the blocked force ...
FLAG_FRACTION = 0.001
#: ... and this many of its standard errors.
FLAG_SIGMAS = 3.0
#: A set drifts when its tests' pooled slope reaches this many standard errors.  On the calibration study's tests
#: without a drift (six cases, eight seeds) the pooled slope stayed within 2.2 standard errors; with a drift of
#: 0.8 % of the blocked force over each test that no single test showed, it reached 2.5-3.9 in seven of eight sets.
SET_FLAG_SIGMAS = 2.5
#: Use the first cycle's unloading when there are three cycles or more?  No: it starts from the state
#: before any cycling (a transient of the loop).
FIRST_UNLOADING = False
#: Points of the stroke grid of an end band (dense: its mean is close to the mean of every sample there).
_GRID = 256
#: The four ends of a cycle, in the order of :attr:`DriftEstimate.ends`.
_ENDS = ("blocked, start of unloading", "free, end of unloading", "free, start of loading",
         "blocked, end of loading")


@dataclass
class DriftEstimate:
    """A linear load-cell offset drift fitted to one test (force positive toward the blocked state).

    rate_n_per_s, rate_se_n_per_s : the drift ``a`` (N/s) and its standard error.
    duration_s, t0_s : the test's duration and first time (s).  drift_n : ``a * duration_s`` (N).
    zero_s : the time at which the offset is taken as zero (s; NaN: ``t0_s``, the first sample; see the module).
    noise_n : the force noise (standard deviation of one sample, N).
    blocked_force_n : the mean force at the blocked ends (N).  points : the end windows used.
    free_rate_n_per_s, blocked_rate_n_per_s : the slopes of the free ends alone and of the blocked ends alone.
    difference_se_n_per_s : the standard error of their difference.
    blocked_moment_shift_nmm : how much correcting the drift moves the blocked moment (N*mm; set by processing).
    corrected : whether processing subtracted the offset.  flagged : see the module docstring.

    Examples
    --------
    >>> est = DriftEstimate(rate_n_per_s=1e-4, rate_se_n_per_s=1e-5, duration_s=300.0, t0_s=0.0, noise_n=0.05,
    ...                     blocked_force_n=10.0, points=12)
    >>> round(est.drift_n, 6), est.flagged            # N: 1e-4 N/s over 300 s is 0.3 % of 10 N, 10 SE
    (0.03, True)
    >>> est.offset_n(np.array([0.0, 150.0])).tolist()  # N
    [0.0, 0.015]
    """

    rate_n_per_s: float
    rate_se_n_per_s: float
    duration_s: float
    t0_s: float
    noise_n: float
    blocked_force_n: float
    points: int
    free_rate_n_per_s: float = math.nan
    blocked_rate_n_per_s: float = math.nan
    difference_se_n_per_s: float = math.nan
    blocked_moment_shift_nmm: float = math.nan
    blocked_moment_nmm: float = math.nan
    corrected: bool = False
    zero_s: float = math.nan

    @property
    def drift_n(self) -> float:
        """The drift over the test (N)."""
        return self.rate_n_per_s * self.duration_s

    @property
    def sigmas(self) -> float:
        """``|a|`` in standard errors (NaN when the standard error is not known)."""
        se = self.rate_se_n_per_s
        return abs(self.rate_n_per_s) / se if math.isfinite(se) and se > 0 else math.nan

    @property
    def threshold_n(self) -> float:
        """The drift over the test from which it biases a fit (N): :data:`FLAG_FRACTION` of the blocked force."""
        return FLAG_FRACTION * abs(self.blocked_force_n)

    @property
    def flagged(self) -> bool:
        """Significant (:data:`FLAG_SIGMAS`) and at least :attr:`threshold_n` over the test."""
        s = self.sigmas
        return bool(math.isfinite(s) and s >= FLAG_SIGMAS and abs(self.drift_n) >= self.threshold_n)

    @property
    def differs(self) -> bool:
        """The free and the blocked ends drift differently (by more than 3 standard errors of the difference)."""
        d = self.free_rate_n_per_s - self.blocked_rate_n_per_s
        return bool(math.isfinite(d) and abs(d) > 3.0 * self.difference_se_n_per_s)

    @classmethod
    def from_dict(cls, data) -> DriftEstimate | None:
        """An estimate from :meth:`to_dict` (the derived keys are ignored); ``None`` for anything else.

        >>> est = DriftEstimate(1e-4, 1e-5, 300.0, 0.0, 0.05, 10.0, 12, corrected=True)
        >>> DriftEstimate.from_dict(est.to_dict()) == est, DriftEstimate.from_dict(None)
        (True, None)
        """
        if not isinstance(data, dict):
            return None
        names = {f.name for f in fields(cls)}
        try:
            return cls(**{k: v for k, v in data.items() if k in names})
        except TypeError:
            return None

    @property
    def zero_time_s(self) -> float:
        """The time at which the offset is taken as zero (s): :attr:`zero_s`, or the first sample's."""
        return self.zero_s if math.isfinite(self.zero_s) else self.t0_s

    @property
    def zero_sd_n(self) -> float:
        """The offset's doubt at the first sample from not knowing when the load cell was zeroed (N).

        ``|a| (t_0 - zero_s) / sqrt 3``: zero when the offset is taken as zero at the first sample.

        >>> e = DriftEstimate(1e-3, 1e-4, 300.0, 100.0, 0.05, 10.0, 12, zero_s=50.0)
        >>> round(e.zero_sd_n, 4), round(float(e.offset_n(np.array([100.0]))[0]), 3)   # N
        (0.0289, 0.05)
        """
        return abs(self.rate_n_per_s) * max(self.t0_s - self.zero_time_s, 0.0) / math.sqrt(3.0)

    def offset_n(self, time_s) -> np.ndarray:
        """The fitted offset ``a (t - zero_s)`` at ``time_s`` (N), zero at :attr:`zero_time_s`."""
        return self.rate_n_per_s * (np.asarray(time_s, dtype=float) - self.zero_time_s)

    def message(self) -> str:
        """The drift in words: its size against the noise and the blocked force, and what correcting it does."""
        pct = 100.0 * self.drift_n / self.blocked_force_n if self.blocked_force_n else math.nan
        text = (f"the load-cell offset drifts by {self.drift_n:+.3g} N over the test ({self.duration_s:.4g} s; "
                f"{self.rate_n_per_s:+.3g} ± {self.rate_se_n_per_s:.2g} N/s, {self.sigmas:.1f} standard errors): "
                f"{abs(self.drift_n) / self.noise_n if self.noise_n > 0 else math.inf:.2g} times the force noise "
                f"({self.noise_n:.2g} N) and {pct:+.2g} % of the blocked force ({self.blocked_force_n:.4g} N)")
        shift = self.blocked_moment_shift_nmm
        if math.isfinite(shift):
            rel = 100.0 * shift / self.blocked_moment_nmm if self.blocked_moment_nmm else math.nan
            verb = "moved" if self.corrected else "would move"
            text += f"; correcting it {verb} the blocked moment by {shift:+.3g} N*mm ({rel:+.2g} %)"
        if self.zero_time_s < self.t0_s:
            text += (f"; the log starts at {self.t0_s:.4g} s, so the offset is taken as zero at {self.zero_time_s:.4g} "
                     f"s, halfway to the clock's start (± {self.zero_sd_n:.2g} N at the first sample)")
        if self.differs:
            text += (f"; the free ends ({self.free_rate_n_per_s:+.3g} N/s) and the blocked ends "
                     f"({self.blocked_rate_n_per_s:+.3g} N/s) drift differently, so part of it is creep or a "
                     "settling loop rather than an offset")
        return text

    def to_dict(self) -> dict:
        """The estimate as a JSON-ready dict (with ``drift_n``, ``sigmas``, ``flagged`` and ``message``).

        >>> sorted(DriftEstimate(0.0, 1e-5, 300.0, 0.0, 0.05, 10.0, 12).to_dict())[:3]
        ['blocked_force_n', 'blocked_moment_nmm', 'blocked_moment_shift_nmm']
        """
        out = asdict(self)
        out.update(drift_n=self.drift_n, sigmas=self.sigmas, threshold_n=self.threshold_n, flagged=self.flagged,
                   message=self.message())
        return out


def _end_windows(time: np.ndarray, stroke: np.ndarray, force: np.ndarray, cycles, band_mm: float,
                 first_unloading: bool) -> tuple[np.ndarray, ...]:
    """The end windows of every cycle ``(blocked, free, blocked)``: ``(end, mean time, mean force, samples)``.

    The bands are common to all cycles: from 10 % to 100 % of ``band_mm`` away from the median
    blocked and free turning strokes (the very tips, where the cycles' turning points differ, are
    left out).  Each window's force and time are interpolated on one stroke grid over its band and
    averaged there, so every cycle is read at the same strokes whatever the phase of its sampling.
    """
    idx = np.asarray(cycles, dtype=int).reshape(-1, 3)
    s0 = float(np.median(stroke[np.concatenate([idx[:, 0], idx[:, 2]])]))
    s1 = float(np.median(stroke[idx[:, 1]]))
    blocked = np.linspace(s0 + 0.1 * band_mm, s0 + band_mm, _GRID)
    free = np.linspace(s1 - band_mm, s1 - 0.1 * band_mm, _GRID)
    grids = {0: blocked, 1: free, 2: free, 3: blocked}
    rows = []
    for j, (a, b, c) in enumerate(idx):
        for end, i0, i1 in ((0, a, b), (1, a, b), (2, b, c), (3, b, c)):
            if end < 2 and j == 0 and not first_unloading and len(idx) >= 3:
                continue
            g = grids[end]
            seg = np.arange(i0, i1 + 1)
            inside = seg[(stroke[seg] >= g[0]) & (stroke[seg] <= g[-1])]
            if inside.size < 2 or stroke[seg].min() > g[0] or stroke[seg].max() < g[-1]:
                continue  # this cycle does not cover the band
            o = np.argsort(stroke[inside], kind="stable")
            xs = stroke[inside][o]
            rows.append((end, float(np.interp(g, xs, time[inside][o]).mean()),
                         float(np.interp(g, xs, force[inside][o]).mean()), inside.size))
    arr = np.array(rows, dtype=float).reshape(-1, 4)
    return arr[:, 0].astype(int), arr[:, 1], arr[:, 2], arr[:, 3]


def _blocked_force_n(stroke: np.ndarray, force: np.ndarray, cycles, band_fraction: float) -> float:
    """The force at the blocked state (N): the mean of the samples within a tenth of the band of its stroke."""
    idx = np.asarray(cycles, dtype=int).reshape(-1, 3)
    s0 = float(np.median(stroke[np.concatenate([idx[:, 0], idx[:, 2]])]))
    tip = stroke <= s0 + 0.1 * band_fraction * float(np.ptp(stroke))
    return float(force[tip].mean()) if tip.any() else float(np.max(force))


def _slope(t: np.ndarray, f: np.ndarray, n: np.ndarray, end: np.ndarray, noise: float,
           keep: np.ndarray) -> tuple[float, float]:
    """Least squares ``f = c_end + a t`` over the window means ``keep``: ``(a, its standard error)``.

    The standard error is the larger of the residual one (when there are degrees of freedom) and the
    one the noise alone gives (each window mean of ``n`` samples has ``noise / sqrt(n)``).
    """
    t, f, n, end = t[keep], f[keep], n[keep], end[keep]
    dt = t.copy()
    df = f.copy()
    for e in np.unique(end):  # within-end centring: one intercept per end
        m = end == e
        dt[m] -= dt[m].mean()
        df[m] -= df[m].mean()
    sxx = float(dt @ dt)
    if sxx <= 0.0:
        return math.nan, math.nan
    a = float(dt @ df) / sxx
    dof = t.size - np.unique(end).size - 1
    resid = df - a * dt
    se_resid = math.sqrt(float(resid @ resid) / dof / sxx) if dof >= 1 else math.nan
    se_noise = math.sqrt(float(np.sum(dt**2 * noise**2 / n))) / sxx
    return a, max((x for x in (se_resid, se_noise) if math.isfinite(x)), default=math.nan)


def estimate_drift(time_s, stroke_mm, force_n, cycles, *, band_fraction: float = 0.1) -> DriftEstimate | None:
    """Fit a linear load-cell offset drift to one test from the force at the ends of its cycles.

    Parameters
    ----------
    time_s, stroke_mm, force_n : array_like
        The samples (s, mm, N), the stroke growing toward the free state and the force positive at the
        blocked state (as processing orients them); the raw force, not filtered, so its noise is known.
    cycles : list of (int, int, int)
        Each cycle's sample indices ``(blocked, free, blocked)``, as processing finds them.
    band_fraction : float
        The end bands: from a tenth of this fraction to this fraction of the stroke range away from
        the median turning strokes.

    Returns
    -------
    DriftEstimate, or None with fewer than two cycles (nothing to compare).

    Examples
    --------
    Three triangular cycles of 100 s with a force of 10 N at the blocked state, 0.2 N at the free
    state, and a drift of 1e-4 N/s (0.03 N over the test, 0.3 % of the blocked force):

    >>> t = np.arange(0.0, 300.0, 0.05)
    >>> s = 10.0 * (1.0 - np.abs(((t / 100.0) % 1.0) * 2.0 - 1.0))        # mm: 0 -> 10 -> 0 per cycle
    >>> f = 10.0 - 0.98 * s + 1e-4 * t + np.random.default_rng(1).normal(0.0, 0.02, t.size)
    >>> cycles = [(2000 * i, 2000 * i + 1000, 2000 * (i + 1)) for i in range(2)] + [(4000, 5000, 5999)]
    >>> est = estimate_drift(t, s, f, cycles)
    >>> abs(est.rate_n_per_s - 1e-4) < 2 * est.rate_se_n_per_s, est.flagged
    (True, True)
    """
    t = np.asarray(time_s, dtype=float)
    s = np.asarray(stroke_mm, dtype=float)
    f = np.asarray(force_n, dtype=float)
    if not cycles or t.size < 2:
        return None
    end, tw, fw, nw = _end_windows(t, s, f, cycles, band_fraction * float(np.ptp(s)), FIRST_UNLOADING)
    if end.size == 0:
        return None
    noise = white_noise(f)
    a, se = _slope(tw, fw, nw, end, noise, np.ones(end.size, dtype=bool))
    if not math.isfinite(a):
        return None
    free = (end == 1) | (end == 2)
    blocked = ~free
    a_free, se_free = _slope(tw, fw, nw, end, noise, free)
    a_blocked, se_blocked = _slope(tw, fw, nw, end, noise, blocked)
    duration = float(t[-1] - t[0])
    zero = 0.5 * float(t[0]) if 0.0 < float(t[0]) <= duration else float(t[0])  # zeroed between 0 and t0
    return DriftEstimate(
        rate_n_per_s=a, rate_se_n_per_s=se, duration_s=duration, t0_s=float(t[0]), noise_n=noise, zero_s=zero,
        blocked_force_n=_blocked_force_n(s, f, cycles, band_fraction), points=int(end.size),
        free_rate_n_per_s=a_free, blocked_rate_n_per_s=a_blocked,
        difference_se_n_per_s=math.hypot(se_free, se_blocked),
    )


def moment_shift_nmm(convert, stroke_mm, force_n, moment_nmm, time_s, cycles, estimate: DriftEstimate,
                     *, corrected: bool) -> float:
    """How much correcting the drift moves the blocked moment (N*mm): the mean over the cycles at their maxima.

    ``convert(stroke, force) -> moment`` is the fixture's conversion; ``force_n`` and ``moment_nmm``
    are what processing used (corrected already when ``corrected``).  The shift is corrected minus
    uncorrected, at each cycle's sample of largest moment.

    >>> est = DriftEstimate(1e-3, 1e-4, 100.0, 0.0, 0.01, 10.0, 12)
    >>> m = np.array([300.0, 200.0, 310.0])
    >>> round(moment_shift_nmm(lambda s, f: 30.0 * f, np.zeros(3), m / 30.0, m, np.array([0.0, 50.0, 100.0]),
    ...                        [(0, 1, 2)], est, corrected=False), 6)   # N*mm: -0.1 N at t = 100 s times 30 mm
    -3.0
    """
    m = np.asarray(moment_nmm, dtype=float)
    idx = np.array([a + int(np.argmax(m[a:c + 1])) for a, _b, c in cycles], dtype=int)
    off = estimate.offset_n(np.asarray(time_s, dtype=float)[idx])
    f = np.asarray(force_n, dtype=float)[idx]
    s = np.asarray(stroke_mm, dtype=float)[idx]
    other = np.asarray(convert(s, f + off if corrected else f - off), dtype=float)
    shift = m[idx] - other if corrected else other - m[idx]
    return float(np.mean(shift))


def check_drift(time_s, stroke_mm, force_raw_n, force_n, cycles, method: str = "none"
                ) -> tuple[DriftEstimate | None, np.ndarray]:  # fmt: skip
    """Processing's drift step: the estimate from the raw force, and the force to go on with.

    ``method`` is one of :data:`DRIFT_METHODS`: ``"none"`` returns ``force_n`` as it is,
    ``"linear"`` subtracts the fitted offset from it (and marks the estimate corrected).

    >>> t = np.arange(0.0, 300.0, 0.05)
    >>> s = 10.0 * (1.0 - np.abs(((t / 100.0) % 1.0) * 2.0 - 1.0))
    >>> f = 10.0 - 0.98 * s + 1e-3 * t
    >>> cycles = [(2000 * i, 2000 * i + 1000, 2000 * (i + 1)) for i in range(2)] + [(4000, 5000, 5999)]
    >>> est, fixed = check_drift(t, s, f, f, cycles, "linear")
    >>> est.corrected, round(float(np.ptp(fixed - (10.0 - 0.98 * s))), 9)       # N: the drift is gone
    (True, 0.0)
    """
    est = estimate_drift(time_s, stroke_mm, force_raw_n, cycles)
    if est is None or method == "none":
        return est, force_n
    est.corrected = True
    return est, np.asarray(force_n, dtype=float) - est.offset_n(time_s)


def drift_findings(result) -> list[dict]:
    """A finding (as :func:`bendpam.lab.plausibility.check_result` makes them) when the test's drift is flagged.

    >>> from types import SimpleNamespace as NS
    >>> est = DriftEstimate(1e-4, 1e-5, 300.0, 0.0, 0.05, 10.0, 12)
    >>> [f["check"] for f in drift_findings(NS(source="a.csv", pressure_kpa=150.0, drift=est))]
    ['drift']
    """
    est = getattr(result, "drift", None)
    if est is None or not est.flagged:
        return []
    what = "corrected" if est.corrected else "not corrected"
    return [{"test": result.source, "pressure_kpa": float(result.pressure_kpa), "check": "drift",
             "value": float(est.drift_n), "bound": float(est.threshold_n), "unit": "N",
             "message": f"{result.source} ({result.pressure_kpa:g} kPa): {est.message()} ({what})"}]


def set_drift(estimates) -> tuple[float, float]:
    """The tests' drift slopes pooled: their inverse-variance mean (N/s) and its size in standard errors.

    ``estimates``: the tests' :class:`DriftEstimate` (None for a test without one; NaN, NaN when none has a
    standard error).

    >>> e = [DriftEstimate(1e-4, 5e-5, 300.0, 0.0, 0.05, 10.0, 12),
    ...      DriftEstimate(2e-4, 1e-4, 300.0, 0.0, 0.05, 10.0, 12)]
    >>> rate, z = set_drift(e)          # each test 2 SE alone; together 2.68 SE
    >>> round(rate * 1e4, 3), round(z, 2)
    (1.2, 2.68)
    """
    rates = [(e.rate_n_per_s, e.rate_se_n_per_s) for e in estimates if e is not None]
    ok = [(a, se) for a, se in rates if math.isfinite(a) and math.isfinite(se) and se > 0]
    if not ok:
        return math.nan, math.nan
    a, se = np.array(ok).T
    w = 1.0 / se**2
    rate = float(np.sum(w * a) / np.sum(w))
    return rate, abs(rate) * math.sqrt(float(np.sum(w)))


def set_drifts(estimates) -> bool:
    """Does the set drift (:func:`set_drift` at :data:`SET_FLAG_SIGMAS` or more, with two tests or more)?

    >>> e = DriftEstimate(2e-4, 1e-4, 300.0, 0.0, 0.05, 10.0, 12)        # 2 SE: not flagged alone
    >>> set_drifts([e]), set_drifts([e, e]), set_drifts([e, None])      # two alike: 2.8 SE pooled
    (False, True, False)
    """
    return _drifts(sum(e is not None for e in estimates), set_drift(estimates)[1])


def _drifts(n: int, z: float) -> bool:
    """``n`` tests whose pooled drift is ``z`` standard errors: does the set drift?"""
    return bool(n >= 2 and math.isfinite(z) and z >= SET_FLAG_SIGMAS)


def set_drift_findings(results) -> list[dict]:
    """A finding for the set when its tests drift together (:func:`set_drifts`) and some tests are not flagged
    on their own (those have their findings already).

    >>> from types import SimpleNamespace as NS
    >>> e = [DriftEstimate(1e-4, 5e-5, 300.0, 0.0, 0.05, 10.0, 12),
    ...      DriftEstimate(2e-4, 1e-4, 300.0, 0.0, 0.05, 10.0, 12)]
    >>> [f["check"] for f in set_drift_findings([NS(drift=x, source="a.csv") for x in e])]
    ['set drift']
    """
    ests = [getattr(r, "drift", None) for r in results]
    rate, z = set_drift(ests)
    n, alone = sum(e is not None for e in ests), sum(e is not None and not e.flagged for e in ests)
    if not _drifts(n, z) or not alone:
        return []
    fixed = all(e is None or e.corrected for e in ests)
    what = ("corrected (--drift linear)" if fixed else
            "not corrected: each test's drift is counted in the fit's error bars; --drift linear corrects it")
    return [{"test": "(the set)", "pressure_kpa": math.nan, "check": "set drift", "value": rate, "bound": z,
             "unit": "N/s",
             "message": (f"the load-cell offset drifts in the set as a whole: the {n} tests' slopes pooled are "
                         f"{rate:+.3g} N/s, {z:.1f} standard errors (a set drifts from {SET_FLAG_SIGMAS:g}), though "
                         f"{alone} of them are not flagged alone; {what}")}]
