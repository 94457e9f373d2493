"""The processed tests as the identification sees them: curves, weights and the stretches they reach.

:func:`fit_data` takes the mean curve of every pressure (where the loop is developed,
:func:`developed_range`), :func:`branch_data` both mean branches (for fits with a loop model); both
give a :class:`FitData` whose weights make the sum of squares the paper's cycle metric (eq 53).
Replicates (several tests at one pressure, :meth:`bendpam.lab.processed.ProcessedSet.replicates`)
are curves of their own: each test's curve is data, weighted as a test of its own, not their mean.
:func:`bladder_stretch_range` gives the bladder's stretches at the tested curvatures (eq 17).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import NamedTuple

import numpy as np

from bendpam.errors import InputError
from bendpam.lab.drift import set_drifts
from bendpam.physics.actuator import Actuator
from bendpam.physics.braid import radius_terms

__all__ = [
    "DriftOffset",
    "FitData",
    "bladder_stretch_range",
    "branch_data",
    "cycle_deviations",
    "cycle_period_s",
    "developed_range",
    "drift_note",
    "drift_offsets",
    "fit_data",
    "offset_modes",
    "relative_rate",
]


@dataclass
class FitData:
    """The curves a fit uses, concatenated, with the weights of eq 53 (magnitudes; kPa, 1/mm, N*mm).

    Per test ``P``, ``k``, ``M`` (pressure, curvatures, mean curve), ``BM``/``BM_se`` and ``K``/``K_se``
    (blocked moment, free curvature and their standard errors); per point ``kc``, ``Mc``, ``Pc``,
    the weight ``w`` and the test ``seg``; with a loop ``branch`` (+1 loading, -1 unloading),
    ``delta`` (bending angle from the branch's start, rad) and ``span`` (between the loop's ends); ``lever``
    the moment per newton of machine force at each point (eq 7, mm: a load-cell offset's moment).

    Examples
    --------
    One virtual test of five points (a straight mean curve from the blocked to the free state):

    >>> from types import SimpleNamespace as NS
    >>> k = np.linspace(0.0, 0.008, 5)
    >>> test = NS(pressure_kpa=150.0, curvature_grid=k, mean_curve=200.0 * (1 - k / 0.008),
    ...           mean_loading=210.0 * (1 - k / 0.008), mean_unloading=190.0 * (1 - k / 0.008),
    ...           blocked_moment=(200.0, 1.0), free_curvature=(0.008, 1e-4))
    >>> d = fit_data(NS(results=[test]), "all")
    >>> d.kc.size, float(d.w[0]), d.thin(2).kc.size
    (5, 0.002236..., 3)
    """

    P: np.ndarray  # (n,) kPa
    k: list[np.ndarray]  # magnitudes, 1/mm
    M: list[np.ndarray]  # mean curves, N*mm
    BM: np.ndarray  # blocked moments (data), N*mm
    BM_se: np.ndarray
    K: np.ndarray  # free curvatures (data), 1/mm
    K_se: np.ndarray
    w: np.ndarray  # per-point weights (concatenated)
    kc: np.ndarray  # concatenated curvature magnitudes
    Mc: np.ndarray  # concatenated data
    Pc: np.ndarray  # concatenated pressures (kPa)
    seg: np.ndarray  # curve index per point
    branch: np.ndarray | None = None  # +1 loading (free -> blocked), -1 unloading (hysteresis fits)
    delta: np.ndarray | None = None  # bending angle from the branch's starting end point (rad)
    span: np.ndarray | None = None  # bending angle between the loop's end points (rad)
    grid_index: np.ndarray | None = None  # each point's index on its test's curvature grid
    period_s: np.ndarray | None = None  # (n,) each test's mean cycle period, s (NaN: not known)
    rate: np.ndarray | None = None  # each point's bending rate at a constant crosshead speed, relative to k' = 0
    time_s: np.ndarray | None = None  # each point's time since its branch began (cycle mean, s); None: not kept
    lever: np.ndarray | None = None  # each point's moment per newton of machine force (eq 7, mm); None: no fixture

    @cached_property
    def branch_rows(self) -> dict[int, np.ndarray]:
        """The rows of each branch of each test in time order, keyed ``2 seg + (branch < 0)`` (needs ``branch``
        and ``time_s``; computed once: the fit's loop laws evaluate it at every step)."""
        assert self.branch is not None and self.time_s is not None
        key = 2 * self.seg + (self.branch < 0)
        rows = {}
        for k in np.unique(key):
            r = np.flatnonzero(key == k)
            rows[int(k)] = r[np.argsort(self.time_s[r], kind="stable")]
        return rows

    def thin(self, step: int) -> FitData:
        """Every ``step``-th point (weights scaled so the objective keeps its scale): for the grid stage."""
        keep = np.arange(self.kc.size) % step == 0
        opt = {n: None if getattr(self, n) is None else getattr(self, n)[keep]
               for n in ("branch", "delta", "span", "grid_index", "rate", "time_s", "lever")}
        return FitData(self.P, self.k, self.M, self.BM, self.BM_se, self.K, self.K_se,
                     self.w[keep] * math.sqrt(self.kc.size / keep.sum()), self.kc[keep], self.Mc[keep], self.Pc[keep],
                     self.seg[keep], **opt, period_s=self.period_s)

    @property
    def group(self) -> np.ndarray:
        """Residual groups of the uncertainty: one per curve (per branch with a loop)."""
        return self.seg if self.branch is None else 2 * self.seg + (self.branch < 0)


def developed_range(result, threshold: float = 0.8, negligible: float = 0.01) -> np.ndarray:
    """Mask of the grid points where the hysteresis loop is developed.

    Near each reversal a rounded loop closes: there both branches lie on the same side of the
    hysteresis-free curve, and their average is biased by up to the loop's half-width.  Where the
    half-width ``(loading - unloading) / 2`` is at least ``threshold`` times its median, the average
    of the branches is a fair estimate of the quasi-static curve.  If the loop is negligible
    (median half-width below ``negligible`` of the blocked moment) every point is kept.

    >>> from types import SimpleNamespace as NS
    >>> k = np.linspace(0.0, 0.008, 9)
    >>> half_width = np.minimum(k, 0.008 - k) / 0.002      # a loop that closes at both reversals
    >>> test = NS(mean_loading=50.0 + half_width, mean_unloading=50.0 - half_width, blocked_moment=(50.0, 1.0))
    >>> developed_range(test).astype(int).tolist()
    [0, 0, 1, 1, 1, 1, 1, 0, 0]
    """
    hw = 0.5 * (np.asarray(result.mean_loading) - np.asarray(result.mean_unloading))
    med = float(np.median(hw))
    if not np.isfinite(med) or med <= negligible * float(result.blocked_moment[0]):
        return np.ones(hw.size, dtype=bool)
    keep = hw >= threshold * med
    if keep.sum() < max(5, hw.size // 5):
        return np.ones(hw.size, dtype=bool)
    # one contiguous range: from the first to the last developed point
    idx = np.flatnonzero(keep)
    mask = np.zeros(hw.size, dtype=bool)
    mask[idx[0]: idx[-1] + 1] = True
    return mask


def branch_data(processed, L0: float) -> FitData:
    """Both mean branches of every pressure (for fits with a hysteresis loop); ``L0`` the active length, mm.

    >>> from types import SimpleNamespace as NS
    >>> k = np.linspace(0.0, 0.008, 5)
    >>> test = NS(pressure_kpa=150.0, curvature_grid=k, mean_curve=200.0 * (1 - k / 0.008),
    ...           mean_loading=210.0 * (1 - k / 0.008), mean_unloading=190.0 * (1 - k / 0.008),
    ...           blocked_moment=(200.0, 1.0), free_curvature=(0.008, 1e-4))
    >>> d = branch_data(NS(results=[test]), 145.0)
    >>> d.kc.size, d.branch.tolist()
    (10, [1, 1, 1, 1, 1, -1, -1, -1, -1, -1])
    """
    res = processed.results
    if not res:
        raise InputError("no processed pressures to fit")
    d = fit_data(processed, "all")
    k, M, w, Pc, seg, br, delta, span, times = [], [], [], [], [], [], [], [], []
    wK = d.K / d.K.sum()
    for i, r in enumerate(res):
        g = np.asarray(r.curvature_grid, float)
        n = g.size
        Kf = d.K[i]
        tb = getattr(r, "branch_times_s", None)
        for bi, (sign, curve, dist) in enumerate(((1, r.mean_loading, (Kf - g) * L0),
                                                   (-1, r.mean_unloading, g * L0))):
            times.append(np.full(n, np.nan) if tb is None else np.nanmean(np.asarray(tb, float)[:, bi], axis=0))
            k.append(g)
            M.append(np.asarray(curve, float))
            w.append(np.full(n, math.sqrt(wK[i]) / (d.BM[i] * math.sqrt(2 * n))))
            Pc.append(np.full(n, d.P[i]))
            seg.append(np.full(n, i))
            br.append(np.full(n, sign))
            delta.append(np.maximum(dist, 0.0))
            span.append(np.full(n, Kf * L0))
    cat = np.concatenate
    gi = cat([np.tile(np.arange(np.asarray(r.curvature_grid).size), 2) for r in res])
    fixture = getattr(processed, "fixture", None)
    t = cat(times)
    kk = cat(k)
    return FitData(d.P, d.k, d.M, d.BM, d.BM_se, d.K, d.K_se, cat(w), kk, cat(M), cat(Pc), cat(seg), cat(br),
                 cat(delta), cat(span), gi, d.period_s, None if fixture is None else relative_rate(fixture, kk),
                 t if np.all(np.isfinite(t)) else None,
                 None if fixture is None else np.asarray(fixture.lever(fixture.curvature_to_beta(kk)), dtype=float))


def relative_rate(fixture, curvature_per_mm) -> np.ndarray:
    """The bending rate at a constant crosshead speed, relative to the straight state (eq 6 and 8).

    ``theta = 2 beta`` and ``ds/dbeta = d sec^2 beta + c sec beta tan beta`` (``c = 2 r + t``), so the rate
    ``dtheta/dt = 2 v / (ds/dbeta)`` falls as the plates pitch: ``d / (ds/dbeta)`` relative to ``beta = 0``.

    >>> from bendpam.physics.fixture import PAPER_FIXTURE
    >>> relative_rate(PAPER_FIXTURE, np.array([0.0, 0.01])).round(3).tolist()   # beta = 0.725 rad: 35 / 73.1
    [1.0, 0.479]
    """
    b = np.abs(fixture.curvature_to_beta(np.asarray(curvature_per_mm, dtype=float)))
    sec = 1.0 / np.cos(b)
    return fixture.d_mm / (fixture.d_mm * sec**2 + fixture.c * sec * np.tan(b))


def fit_data(processed, fit_range: str = "developed") -> FitData:
    """The mean curve of every pressure, where the loop is developed (``"developed"``) or whole (``"all"``).

    Weights ``sqrt(K_i / sum K) / (M_max,i sqrt(n_i))`` make the sum of squares eq 53.

    >>> from types import SimpleNamespace as NS
    >>> k = np.linspace(0.0, 0.008, 5)
    >>> test = NS(pressure_kpa=150.0, curvature_grid=k, mean_curve=200.0 * (1 - k / 0.008),
    ...           blocked_moment=(200.0, 1.0), free_curvature=(0.008, 1e-4))
    >>> d = fit_data(NS(results=[test]), "all")
    >>> d.P.tolist(), d.Mc.tolist()
    ([150.0], [200.0, 150.0, 100.0, 50.0, 0.0])
    """
    res = processed.results
    if not res:
        raise InputError("no processed pressures to fit")
    if fit_range not in ("developed", "all"):
        raise InputError(f"fit_range = {fit_range!r}; choose 'developed' or 'all'")
    P = np.array([r.pressure_kpa for r in res], dtype=float)
    masks = [developed_range(r) if fit_range == "developed" else np.ones(r.curvature_grid.size, bool) for r in res]
    k = [np.asarray(r.curvature_grid, float)[m] for r, m in zip(res, masks, strict=True)]
    M = [np.asarray(r.mean_curve, float)[m] for r, m in zip(res, masks, strict=True)]
    BM = np.array([r.blocked_moment[0] for r in res])
    BMse = np.array([r.blocked_moment[1] for r in res])
    K = np.array([r.free_curvature[0] for r in res])
    Kse = np.array([r.free_curvature[1] for r in res])
    if np.any(~np.isfinite(BM)) or np.any(BM <= 0) or np.any(~np.isfinite(K)) or np.any(K <= 0):
        raise InputError("processed data need a positive blocked moment and free curvature at every pressure")
    wK = K / K.sum()
    w = np.concatenate([np.full(kk.size, math.sqrt(wK[i]) / (BM[i] * math.sqrt(kk.size))) for i, kk in enumerate(k)])
    seg = np.concatenate([np.full(kk.size, i) for i, kk in enumerate(k)])
    gi = np.concatenate([np.flatnonzero(m) for m in masks])
    return FitData(P, k, M, BM, BMse, K, Kse, w, np.concatenate(k), np.concatenate(M),
                 np.concatenate([np.full(kk.size, P[i]) for i, kk in enumerate(k)]), seg,
                 grid_index=gi, period_s=np.array([cycle_period_s(r) for r in res]))


def cycle_period_s(result) -> float:
    """A test's mean cycle period (s) from its kept samples (their ``time_s`` and ``cycle`` labels); NaN without.

    >>> import pandas as pd
    >>> from types import SimpleNamespace as NS
    >>> series = pd.DataFrame({"time_s": np.arange(9.0), "cycle": [0, 1, 1, 1, 1, 2, 2, 2, 2]})
    >>> cycle_period_s(NS(series=series)), cycle_period_s(NS(series=None))
    (3.0, nan)
    """
    series = getattr(result, "series", None)
    if series is None or "cycle" not in series or "time_s" not in series:
        return math.nan
    t = series["time_s"].to_numpy(dtype=float)
    c = series["cycle"].to_numpy()
    ids = np.unique(c[c > 0])
    if ids.size == 0:
        return math.nan
    first = np.array([t[c == i][0] for i in ids])
    last = np.array([t[c == i][-1] for i in ids])
    return float(np.mean(last - first))


def cycle_deviations(processed, d: FitData) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each cycle's deviation from the mean of its test at the fit's points: ``[(rows, E)]``.

    One entry per test with two cycles or more: ``rows`` index ``d``'s points of that test and
    ``E`` (cycles x rows, N*mm) is each cycle's branch (loading, unloading, or their average for the
    mean curves) minus the mean over the cycles, at those points.  This is what resampling the cycles
    (a block bootstrap over cycles) perturbs the fitted data by.

    >>> from types import SimpleNamespace as NS
    >>> k = np.linspace(0.0, 0.008, 3)
    >>> br = np.array([[[3.0, 2.0, 1.0], [1.0, 0.0, -1.0]], [[5.0, 4.0, 3.0], [3.0, 2.0, 1.0]]])
    >>> d = FitData(np.array([150.0]), [k], [br.mean(axis=(0, 1))], np.ones(1), np.zeros(1), np.ones(1), np.zeros(1),
    ...             np.ones(3), k, br.mean(axis=(0, 1)), np.full(3, 150.0), np.zeros(3, int), grid_index=np.arange(3))
    >>> [(rows.tolist(), E.tolist()) for rows, E in cycle_deviations(NS(results=[NS(branches=br)]), d)]
    [([0, 1, 2], [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]])]
    """
    out: list[tuple[np.ndarray, np.ndarray]] = []
    if d.grid_index is None:
        return out
    for i, r in enumerate(processed.results):
        br = getattr(r, "branches", None)
        if br is None or np.asarray(br).ndim != 3 or np.asarray(br).shape[0] < 2:
            continue
        br = np.asarray(br, dtype=float)
        rows = np.flatnonzero(d.seg == i)
        gi = d.grid_index[rows]
        if d.branch is None:
            Y = 0.5 * (br[:, 0, gi] + br[:, 1, gi])
        else:
            Y = np.where(d.branch[rows] > 0, br[:, 0, gi], br[:, 1, gi])
        out.append((rows, Y - Y.mean(axis=0)))
    return out


def bladder_stretch_range(actuator: Actuator, curvature_per_mm) -> tuple[float, float]:
    """Smallest and largest principal in-plane stretch of the bladder at curvatures (eq 17).

    The axial stretch ``lambda1 = 1 + u (1 - cos Phi)`` (``u = k' R``) spans ``[1, 1 + 2u]`` around
    the section, the hoop stretch is ``lambda2 = R / R0_start``; the range always contains 1.

    Parameters
    ----------
    actuator : the actuator (its alpha0 and R0_start set the kinematics).
    curvature_per_mm : curvature magnitudes along the bending direction, 1/mm.

    Returns
    -------
    (float, float)

    Examples
    --------
    >>> import bendpam
    >>> lo, hi = bladder_stretch_range(bendpam.physics.presets.be_pam(), [0.0, 0.0135])
    >>> round(lo, 3), round(hi, 3)
    (0.979, 1.267)
    """
    p = actuator.params
    k = (actuator.bend_sign or 1) * np.abs(np.atleast_1d(np.asarray(curvature_per_mm, dtype=float)))
    u, R, _ = radius_terms(k, float(p.alpha0), float(p.R0_start))
    lam1 = 1.0 + 2.0 * u
    lam2 = R / float(p.R0_start)
    allv = np.concatenate([lam1, lam2, [1.0]])
    return float(np.min(allv)), float(np.max(allv))




class DriftOffset(NamedTuple):
    """One test's load-cell drift doubt as a moment offset of its rows (N*mm): see :func:`drift_offsets`.

    rows : the test's rows of the fit's data.  sd : the doubt of the test's own (independent of the others').
    shift : what correcting a drift left uncorrected would move its moments (0 for a corrected test).
    common : a doubt shared by every test, with its sign (one load cell: when it was zeroed).

    >>> DriftOffset(np.array([0, 1]), 0.3, 0.0).common
    0.0
    """

    rows: np.ndarray
    sd: float
    shift: float
    common: float = 0.0


def drift_offsets(processed, d: FitData) -> list[DriftOffset]:
    """The load-cell drift's doubt as a moment offset per test (:class:`DriftOffset`, N*mm).

    ``shift`` is how much correcting a drift left uncorrected would move the test's moments (its
    blocked-moment shift, as a constant offset of its rows; 0 for a corrected test), for the fit to say how
    far its values would move.

    A test whose drift was corrected keeps the error of the estimated rate: an offset growing from the
    test's start, ``rate_se (t - t0)``, common to its cycles on average (``rate_se x duration / 2``;
    resampling the cycles sees only its growth), converted to moment by the blocked state's lever
    ``M_b / F_b``; and, for a log that starts after its clock, the doubt of when the load cell was zeroed
    (:attr:`bendpam.lab.drift.DriftEstimate.zero_sd_n`, with the drift's sign), which is the same
    procedure's for every test: ``common``.  A drift left uncorrected, when it is flagged or the set drifts
    as a whole (:func:`bendpam.lab.drift.set_drifts`), is an offset of the root mean square size of what
    correcting it would move the blocked moment by: that shift ``s`` is known to its standard error
    ``s / z`` (``z`` the drift's size in standard errors), so ``sqrt(s^2 + (s / z)^2)``.  Other tests add
    nothing.

    >>> from types import SimpleNamespace as NS
    >>> drift = NS(corrected=True, flagged=True, rate_n_per_s=1e-3, rate_se_n_per_s=1e-4, duration_s=200.0,
    ...            blocked_moment_nmm=300.0, blocked_force_n=10.0, blocked_moment_shift_nmm=-3.0,
    ...            free_rate_n_per_s=1e-3, blocked_rate_n_per_s=1e-3, zero_sd_n=0.02)   # both ends alike
    >>> d = NS(seg=np.array([0, 0, 0]))
    >>> [(o.rows.tolist(), round(o.sd, 6), o.shift, round(o.common, 6))
    ...  for o in drift_offsets(NS(results=[NS(drift=drift)]), d)]  # N*mm
    [([0, 1, 2], 0.3, 0.0, 0.6)]

    Two tests that drift by 2 standard errors each, left uncorrected: not flagged alone, but the set drifts
    (2.8 standard errors pooled), so each adds ``sqrt(s^2 + (s / 2)^2)``:

    >>> from bendpam.lab.drift import DriftEstimate
    >>> e = DriftEstimate(2e-4, 1e-4, 200.0, 0.0, 0.05, 10.0, 12, blocked_moment_shift_nmm=-2.0)
    >>> d = NS(seg=np.array([0, 0, 1, 1]))
    >>> [(o.rows.tolist(), round(o.sd, 3), o.shift) for o in drift_offsets(NS(results=[NS(drift=e)] * 2), d)]
    [([0, 1], 2.236, -2.0), ([2, 3], 2.236, -2.0)]
    """
    out: list[DriftOffset] = []
    drifts = set_drifts([getattr(r, "drift", None) for r in processed.results])
    for i, r in enumerate(processed.results):
        e = getattr(r, "drift", None)
        if e is None:
            continue
        shift, common = 0.0, 0.0
        if e.corrected:
            lever = abs(e.blocked_moment_nmm / e.blocked_force_n) if e.blocked_force_n else math.nan
            ends = abs(e.free_rate_n_per_s - e.blocked_rate_n_per_s) / 2.0
            rate_sd = math.hypot(e.rate_se_n_per_s, ends) if math.isfinite(ends) else e.rate_se_n_per_s
            sd = abs(rate_sd * e.duration_s / 2.0 * lever)
            common = math.copysign(getattr(e, "zero_sd_n", 0.0) * lever, e.rate_n_per_s)
        elif e.flagged or drifts:  # its own estimate of the shift, known to its standard error shift / sigmas
            shift, sig = float(e.blocked_moment_shift_nmm), e.sigmas
            sd = math.hypot(shift, shift / sig) if math.isfinite(sig) and sig > 0 else abs(shift)
        else:
            sd = 0.0
        sd, common = (x if math.isfinite(x) else 0.0 for x in (sd, common))
        if sd > 0 or common:
            out.append(DriftOffset(np.flatnonzero(d.seg == i), float(sd), shift if math.isfinite(shift) else 0.0,
                                   float(common)))
    return out


def offset_modes(offsets, w: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """The drift's doubt as offsets of the weighted data (:func:`sandwich_covariance`'s ``offsets``).

    A corrected drift's error is its own test's (independent of the others').  Drifts left uncorrected are
    one load cell's: what correcting them would move, every test's shift with its sign, is one mode (its
    effect on the parameters is the shift the fit's note reports), and only each shift's own error
    ``s / z`` is independent.  Taken one test at a time, shifts of one sign could add up as though they had
    any sign, and excite directions the data barely fix (a shape on its bound) far beyond what correcting
    the drift does.

    The doubt of when a corrected drift was zeroed (``common``) is one mode too: the same procedure zeroed
    every test.

    >>> rows = [np.array([0, 1]), np.array([2])]
    >>> modes = offset_modes([DriftOffset(rows[0], 1.25, -1.0), DriftOffset(rows[1], 0.5, 0.0)], np.ones(3))
    >>> [(r.tolist(), u.tolist()) for r, u in modes]       # 1.25 = hypot(1, 0.75): 0.75 alone, the shift as a mode
    [([0, 1], [0.75, 0.75]), ([2], [0.5]), ([0, 1], [-1.0, -1.0])]
    """
    modes = []
    shared: dict[str, tuple[list, list]] = {"shift": ([], []), "common": ([], [])}
    for o in offsets:
        own = math.sqrt(max(o.sd * o.sd - o.shift * o.shift, 0.0)) if o.shift else o.sd
        if own > 0:
            modes.append((o.rows, own * w[o.rows]))
        for key, value in (("shift", o.shift), ("common", o.common)):
            if value:
                shared[key][0].append(o.rows)
                shared[key][1].append(value * w[o.rows])
    modes += [(np.concatenate(r), np.concatenate(u)) for r, u in shared.values() if r]
    return modes


def drift_note(shift: dict[str, float], sd: dict[str, float], tests: int) -> list[str]:
    """The fit's words for a drift left uncorrected: how far correcting it would move alpha0 (and mu), in degrees,
    kPa and standard errors.  ``shift``, ``sd``: by field name (``alpha0_deg``, ``shear_modulus_kpa``).

    >>> shift, sd = {"alpha0_deg": 0.14, "shear_modulus_kpa": 1.2}, {"alpha0_deg": 0.07, "shear_modulus_kpa": 3.0}
    >>> drift_note(shift, sd, 2)[0].split("would move ")[1].split(";")[0]
    'alpha0 by about +0.14 deg (2 SE) and mu by +1.2 kPa (0.4 SE)'
    """
    a = shift.get("alpha0_deg")
    if not tests or a is None or not math.isfinite(a):
        return []
    words = [f"alpha0 by about {a:+.2g} deg ({abs(a) / sd['alpha0_deg']:.2g} SE)" if sd.get("alpha0_deg") else
             f"alpha0 by about {a:+.2g} deg"]
    mu, mu_sd = shift.get("shear_modulus_kpa"), sd.get("shear_modulus_kpa")
    if mu is not None and math.isfinite(mu):
        words.append(f"mu by {mu:+.2g} kPa" + (f" ({abs(mu) / mu_sd:.2g} SE)" if mu_sd else ""))
    return [f"the load-cell drift of {tests} test(s) was left uncorrected (flagged, or shared by the set): correcting "
            f"it (--drift linear) would move {' and '.join(words)}; its doubt is in the standard errors"]
