"""Processing of four-point-bending cyclic tests (paper section 2.2, Figure 4, Table 2).

One raw test (time, stroke, force) at one pressure becomes:

1. **Orientation.**  Force is made positive at the blocked state (compression exports are often
   negative) and stroke is oriented so that it grows toward the free state (force falls as the
   actuator is released); both flips are recorded.
2. **Filtering.**  A zero-phase low-pass filter, ``scipy.signal.sosfiltfilt`` with a 4th-order
   Butterworth design.  The default cutoff is 1 Hz, limited to 40 % of the Nyquist frequency;
   the paper's tests run at about 30 mm/min, so a cycle lasts minutes and the filter only
   removes measurement noise.  Set ``cutoff_hz`` to change it, or ``cutoff_hz=0`` to switch it off.
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
"""

from __future__ import annotations

import itertools
import math
import warnings
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from bendpam.errors import InputError, ProcessingError
from bendpam.physics.fixture import PAPER_FIXTURE, Fixture

if TYPE_CHECKING:  # pandas and xarray are imported by the functions that use them (fast start-up of `fit`)
    import pandas as pd
    import xarray as xr

__all__ = [
    "PressureResult",
    "ProcessedSet",
    "ProcessingError",
    "ProcessingOptions",
    "deadband_fit",
    "find_turning_points",
    "load_processed",
    "process_series",
    "process_tests",
    "write_processed",
]

BRANCHES = ("loading", "unloading")




@dataclass(frozen=True)
class ProcessingOptions:
    """Settings of :func:`process_series` (units in the names).

    cutoff_hz : low-pass cutoff (Hz); ``None`` = 1 Hz limited to 40 % of Nyquist; 0 = no filter.
    filter_order : Butterworth order (applied forward and backward, so the effective order doubles).
    reversal_fraction : zig-zag threshold for stroke reversals, as a fraction of the stroke range.
    grid_points : points of the common curvature grid of the branches.
    tare_n : force subtracted before eq 7 (N), e.g. the self-weight read unpressurised.
    zero_stroke : count the stroke from the blocked turning points (True) or use it as recorded.
    """

    cutoff_hz: float | None = None
    filter_order: int = 4
    reversal_fraction: float = 0.05
    grid_points: int = 101
    tare_n: float = 0.0
    zero_stroke: bool = True

    def __post_init__(self) -> None:
        if self.cutoff_hz is not None and (not math.isfinite(self.cutoff_hz) or self.cutoff_hz < 0):
            raise InputError(f"cutoff_hz = {self.cutoff_hz!r} must be >= 0 Hz (0 switches the filter off)")
        if not 1 <= int(self.filter_order) <= 10:
            raise InputError(f"filter_order = {self.filter_order!r} is outside the allowed range [1, 10]")
        if not 0.0 < self.reversal_fraction < 0.5:
            raise InputError(f"reversal_fraction = {self.reversal_fraction!r} is outside the allowed range (0, 0.5)")
        if not 5 <= int(self.grid_points) <= 100000:
            raise InputError(f"grid_points = {self.grid_points!r} is outside the allowed range [5, 100000]")
        if not math.isfinite(self.tare_n):
            raise InputError(f"tare_n = {self.tare_n!r} N is not finite")


@dataclass
class PressureResult:
    """Processed cyclic test at one pressure (magnitudes; N*mm, 1/mm, kPa)."""

    pressure_kpa: float
    source: str
    n_cycles: int
    curvature_grid: np.ndarray  # (n_grid,) 1/mm
    branches: np.ndarray  # (n_cycles, 2, n_grid) N*mm; [:, 0] loading (upper), [:, 1] unloading (lower)
    blocked_moments: np.ndarray  # (n_cycles,) N*mm: each cycle's maximum
    free_curvatures: np.ndarray  # (n_cycles,) 1/mm: at each cycle's free turning point
    energy_loss_ratios: np.ndarray  # (n_cycles,)
    loop_energy: np.ndarray  # (n_cycles,) N*mm*rad
    stored_energy: np.ndarray  # (n_cycles,) N*mm*rad
    sample_rate_hz: float
    cutoff_hz: float
    notes: list[str] = field(default_factory=list)
    series: pd.DataFrame | None = None  # filtered, converted samples with cycle/branch labels

    @property
    def mean_loading(self) -> np.ndarray:
        return self.branches[:, 0].mean(axis=0)

    @property
    def mean_unloading(self) -> np.ndarray:
        return self.branches[:, 1].mean(axis=0)

    @property
    def mean_curve(self) -> np.ndarray:
        """Hysteresis-free mean curve: the average of the two mean branches (N*mm)."""
        return 0.5 * (self.mean_loading + self.mean_unloading)

    @staticmethod
    def _mean_se(x: np.ndarray) -> tuple[float, float]:
        x = np.asarray(x, dtype=float)
        m = float(np.mean(x))
        se = float(np.std(x, ddof=1) / math.sqrt(x.size)) if x.size > 1 else math.nan
        return m, se

    @property
    def blocked_moment(self) -> tuple[float, float]:
        """Mean and standard error of the cycles' maximum moments (N*mm)."""
        return self._mean_se(self.blocked_moments)

    @property
    def free_curvature(self) -> tuple[float, float]:
        """Mean and standard error of the cycles' free-bending curvatures (1/mm)."""
        return self._mean_se(self.free_curvatures)

    @property
    def energy_loss_ratio(self) -> float:
        return float(np.mean(self.energy_loss_ratios))

    @property
    def blocked_moment_mean_curve(self) -> float:
        """The mean curve at k' = 0 (N*mm), extrapolated linearly over its first 5 % if needed."""
        k, m = self.curvature_grid, self.mean_curve
        if k[0] <= 0.0:
            return float(m[0])
        n = max(3, k.size // 20)
        _slope, icept = np.polyfit(k[:n], m[:n], 1)
        return float(icept)

    def summary(self) -> dict:
        bm, bm_se = self.blocked_moment
        kf, kf_se = self.free_curvature
        return {
            "pressure_kpa": self.pressure_kpa,
            "cycles": self.n_cycles,
            "blocked_moment_nmm": bm,
            "blocked_moment_se_nmm": bm_se,
            "blocked_moment_mean_curve_nmm": self.blocked_moment_mean_curve,
            "free_curvature_per_mm": kf,
            "free_curvature_se_per_mm": kf_se,
            "energy_loss_ratio": self.energy_loss_ratio,
            "source": self.source,
            "notes": list(self.notes),
        }


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
    acc = np.zeros(x.size)
    cnt = np.zeros(x.size)
    need = 3 * (2 * sos.shape[0] + 1)
    for a, b in itertools.pairwise(edges):
        seg = x[a: b + 1]
        if seg.size <= need:
            continue
        y = signal.sosfiltfilt(sos, seg, padtype="odd", padlen=min(seg.size - 1, max(need, int(3 * fs / cutoff))))
        acc[a: b + 1] += y
        cnt[a: b + 1] += 1
    done = cnt > 0
    out[done] = acc[done] / cnt[done]
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
    """
    s = np.asarray(stroke, dtype=float)
    n = s.size
    d = np.diff(s)
    nz = np.flatnonzero(d != 0.0)
    if nz.size == 0:
        return np.array([0]), np.array([False])
    sg = np.sign(d[nz])
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


def process_series(
    time_s,
    stroke_mm,
    force_n,
    pressure_kpa: float,
    *,
    fixture: Fixture = PAPER_FIXTURE,
    options: ProcessingOptions | None = None,
    source: str = "<data>",
    keep_series: bool = True,
) -> PressureResult:
    """Process one cyclic test at one pressure.  See the module docstring for the steps."""
    opt = options or ProcessingOptions()
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
    notes: list[str] = []
    fs = 1.0 / float(np.median(dt))
    if np.max(dt) > 5.0 / fs:
        notes.append(f"irregular sampling: largest gap {np.max(dt):.3g} s at a median rate of {fs:.3g} Hz")
    nyq = 0.5 * fs
    cutoff = (min(1.0, 0.4 * nyq) if opt.cutoff_hz is None else float(opt.cutoff_hz))
    if cutoff >= nyq:
        raise ProcessingError(f"{source}: cutoff {cutoff:g} Hz is not below the Nyquist frequency {nyq:g} Hz")
    s_f = _lowpass(s_raw, fs, cutoff, int(opt.filter_order))
    f_f = _lowpass(f_raw, fs, cutoff, int(opt.filter_order))

    rng = float(np.ptp(s_f))
    if rng <= 0:
        raise ProcessingError(f"{source}: the stroke does not move; no cycles to process")
    # orientation: force positive at the blocked state, stroke growing toward the free state
    if np.median(f_f) < 0:
        f_f, f_raw = -f_f, -f_raw
        notes.append("force sign flipped (compression recorded as negative)")
    if np.ptp(f_f) > 0 and np.corrcoef(s_f, f_f)[0, 1] > 0:
        s_f, s_raw = -s_f, -s_raw
        notes.append("stroke direction flipped (stroke recorded as decreasing toward the free state)")

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
    # complete cycles: min -> max -> min, the closing minimum back near the blocked state
    back_tol = opt.reversal_fraction * rng
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

    beta, k, M = fixture.convert(s_z, f_f, opt.tare_n)

    n = len(cycles)
    grid_n = int(opt.grid_points)
    # per-branch coverage and the common grid
    seg = []
    for a, b, c in cycles:
        seg.append(((b, c), (a, b)))  # (loading: free->blocked, unloading: blocked->free)
    lo = max(max(k[i0:i1 + 1].min() for (i0, i1) in pair) for pair in seg)
    hi = min(min(k[i0:i1 + 1].max() for (i0, i1) in pair) for pair in seg)
    lo = max(lo, 0.0)
    if not hi > lo:
        raise ProcessingError(f"{source}: the cycles do not share a curvature range (low {lo:g}, high {hi:g} 1/mm)")
    grid = np.linspace(lo, hi, grid_n)
    branches = np.empty((n, 2, grid_n))
    bm = np.empty(n)
    kf = np.empty(n)
    loss = np.empty(n)
    stored = np.empty(n)
    for ci, ((a, b, c), pair) in enumerate(zip(cycles, seg, strict=True)):
        for bi, (i0, i1) in enumerate(pair):
            kk, mm = k[i0:i1 + 1], M[i0:i1 + 1]
            order = np.argsort(kk, kind="stable")
            branches[ci, bi] = np.interp(grid, kk[order], mm[order])
        bm[ci] = float(M[a:c + 1].max())
        kf[ci] = float(k[b])
        # energy loss in M-theta over this cycle's own range
        own = np.linspace(max(min(k[a:b + 1].min(), k[b:c + 1].min()), 0.0), kf[ci], grid_n)
        up = np.interp(own, *_sorted(k[b:c + 1], M[b:c + 1]))
        down = np.interp(own, *_sorted(k[a:b + 1], M[a:b + 1]))
        th = own * fixture.L0_mm
        loss[ci] = float(np.trapezoid(up - down, th))
        stored[ci] = float(np.trapezoid(0.5 * (up + down), th))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(stored > 0, loss / stored, np.nan)
    if np.any(~np.isfinite(ratio)):
        notes.append("energy-loss ratio undefined for a cycle with no stored energy")

    series = None
    if keep_series:
        cyc = np.full(t.size, -1)
        br = np.full(t.size, "", dtype=object)
        for ci, (a, b, c) in enumerate(cycles):
            cyc[a:c + 1] = ci + 1
            br[a:b + 1] = "unloading"
            br[b:c + 1] = "loading"
        import pandas as pd

        series = pd.DataFrame({
            "time_s": t, "stroke_mm": s_z, "force_n": f_f, "beta_rad": beta, "curvature_per_mm": k,
            "moment_nmm": M, "cycle": cyc, "branch": br.astype(str),
        })
    return PressureResult(
        pressure_kpa=float(pressure_kpa), source=source, n_cycles=n, curvature_grid=grid, branches=branches,
        blocked_moments=bm, free_curvatures=kf, energy_loss_ratios=ratio, loop_energy=loss, stored_energy=stored,
        sample_rate_hz=fs, cutoff_hz=cutoff, notes=notes, series=series,
    )


def _sorted(x, y):
    o = np.argsort(x, kind="stable")
    return x[o], y[o]


# ------------------------------------------------------------------------------------------------
def deadband_fit(pressure_kpa, blocked_moment_nmm) -> tuple[float, float, float, float]:
    """x-intercept of the least-squares line ``M = a (P - P0)`` and its standard error.

    Returns ``(P0_kpa, P0_se_kpa, slope_nmm_per_kpa, intercept_nmm)``; the standard error uses the
    delta method on the fit's covariance (NaN with fewer than three pressures).
    """
    P = np.asarray(pressure_kpa, dtype=float)
    M = np.asarray(blocked_moment_nmm, dtype=float)
    if P.size < 2 or np.ptp(P) == 0:
        return math.nan, math.nan, math.nan, math.nan
    if P.size >= 3:
        (a, b), cov = np.polyfit(P, M, 1, cov="unscaled")
        resid = M - (a * P + b)
        s2 = float(resid @ resid) / (P.size - 2)
        cov = cov * s2
    else:
        a, b = np.polyfit(P, M, 1)
        cov = None
    if a == 0:
        return math.nan, math.nan, float(a), float(b)
    p0 = -b / a
    if cov is None:
        return float(p0), math.nan, float(a), float(b)
    # P0 = -b/a: grad = (b/a^2, -1/a)
    g = np.array([b / a**2, -1.0 / a])
    var = float(g @ cov @ g)
    return float(p0), math.sqrt(max(var, 0.0)), float(a), float(b)


@dataclass
class ProcessedSet:
    """Processed tests at several pressures (sorted by pressure)."""

    results: list[PressureResult]
    fixture: Fixture
    options: ProcessingOptions

    @property
    def pressures_kpa(self) -> np.ndarray:
        return np.array([r.pressure_kpa for r in self.results])

    def deadband(self) -> tuple[float, float]:
        bm = [r.blocked_moment[0] for r in self.results]
        p0, se, _, _ = deadband_fit(self.pressures_kpa, bm)
        return p0, se

    def summary(self) -> dict:
        p0, se = self.deadband()
        return {
            "pressures": [r.summary() for r in self.results],
            "deadband_kpa": p0,
            "deadband_se_kpa": se,
            "units": {"pressure_kpa": "kPa", "blocked_moment_nmm": "N*mm", "free_curvature_per_mm": "1/mm",
                      "energy_loss_ratio": "1"},
            "fixture": {"d_mm": self.fixture.d_mm, "r_mm": self.fixture.r_mm, "t_mm": self.fixture.t_mm,
                        "L0_mm": self.fixture.L0_mm},
            "sign_convention": "magnitudes, as in the paper",
        }

    def to_dataset(self) -> xr.Dataset:
        """Labelled curves: dims ``pressure_kpa``, ``cycle``, ``branch``, ``point``.

        The curvature grid differs between pressures, so it is a 2-D coordinate
        ``curvature_per_mm(pressure_kpa, point)``.  Pressures with fewer cycles are NaN-padded.
        """
        npres = len(self.results)
        ncyc = max(r.n_cycles for r in self.results)
        npt = self.results[0].curvature_grid.size
        br = np.full((npres, ncyc, 2, npt), np.nan)
        kg = np.empty((npres, npt))
        bmc = np.full((npres, ncyc), np.nan)
        kfc = np.full((npres, ncyc), np.nan)
        elc = np.full((npres, ncyc), np.nan)
        for i, r in enumerate(self.results):
            br[i, : r.n_cycles] = r.branches
            kg[i] = r.curvature_grid
            bmc[i, : r.n_cycles] = r.blocked_moments
            kfc[i, : r.n_cycles] = r.free_curvatures
            elc[i, : r.n_cycles] = r.energy_loss_ratios
        import xarray as xr

        P = self.pressures_kpa
        ds = xr.Dataset(
            {
                "moment_nmm": (("pressure_kpa", "cycle", "branch", "point"), br,
                               {"units": "N*mm", "long_name": "branch moment on the common curvature grid"}),
                "mean_loading_nmm": (("pressure_kpa", "point"), np.nanmean(br[:, :, 0], axis=1),
                                     {"units": "N*mm", "long_name": "loading branch (free -> blocked), cycle mean"}),
                "mean_unloading_nmm": (
                    ("pressure_kpa", "point"), np.nanmean(br[:, :, 1], axis=1),
                    {"units": "N*mm", "long_name": "unloading branch (blocked -> free), cycle mean"}),
                "blocked_moment_cycle_nmm": (("pressure_kpa", "cycle"), bmc, {"units": "N*mm"}),
                "free_curvature_cycle_per_mm": (("pressure_kpa", "cycle"), kfc, {"units": "1/mm"}),
                "energy_loss_ratio_cycle": (("pressure_kpa", "cycle"), elc, {"units": "1"}),
                "blocked_moment_nmm": (
                    "pressure_kpa", [r.blocked_moment[0] for r in self.results], {"units": "N*mm"}),
                "blocked_moment_se_nmm": (
                    "pressure_kpa", [r.blocked_moment[1] for r in self.results], {"units": "N*mm"}),
                "free_curvature_per_mm": (
                    "pressure_kpa", [r.free_curvature[0] for r in self.results], {"units": "1/mm"}),
                "free_curvature_se_per_mm": (
                    "pressure_kpa", [r.free_curvature[1] for r in self.results], {"units": "1/mm"}),
                "energy_loss_ratio": ("pressure_kpa", [r.energy_loss_ratio for r in self.results], {"units": "1"}),
            },
            coords={
                "pressure_kpa": ("pressure_kpa", P, {"units": "kPa"}),
                "cycle": ("cycle", np.arange(1, ncyc + 1)),
                "branch": ("branch", list(BRANCHES)),
                "point": ("point", np.arange(npt)),
                "curvature_per_mm": (("pressure_kpa", "point"), kg, {"units": "1/mm"}),
            },
        )
        ds["mean_curve_nmm"] = 0.5 * (ds["mean_loading_nmm"] + ds["mean_unloading_nmm"])
        ds["mean_curve_nmm"].attrs.update(units="N*mm", long_name="hysteresis-free mean curve (average of branches)")
        p0, se = self.deadband()
        ds.attrs.update(
            deadband_kpa=p0, deadband_se_kpa=se, fixture_d_mm=self.fixture.d_mm, fixture_r_mm=self.fixture.r_mm,
            fixture_t_mm=self.fixture.t_mm, L0_mm=self.fixture.L0_mm, sign_convention="magnitudes",
            sources="; ".join(r.source for r in self.results),
        )
        return ds

    def plot(self, title: str = ""):
        """Figure 4 of the paper for this set (a matplotlib Figure; see :func:`bendpam.present.figures.figure4`)."""
        from bendpam.present.figures import figure4

        return figure4(self, title)

    def save(self, out_dir, *, figure: bool = True) -> dict[str, str]:
        """Write ``curves.nc`` (xarray/NetCDF), ``curves.csv``, ``summary.json`` and ``figure4.png``.

        Every file is written atomically.  Returns ``{name: path}`` of the files written.
        """
        import json
        from pathlib import Path

        from bendpam.infra.atomic import atomic_path, atomic_write_text, json_safe

        out = Path(out_dir)
        if out.exists() and not out.is_dir():
            raise ProcessingError(f"{str(out)!r} exists and is not a folder")
        out.mkdir(parents=True, exist_ok=True)
        written = {}
        ds = self.to_dataset()
        with atomic_path(out / "curves.nc") as tmp:
            ds.to_netcdf(tmp)
        written["curves.nc"] = str(out / "curves.nc")
        atomic_write_text(out / "curves.csv", self.to_frame().to_csv(index=False, float_format="%.10g"))
        written["curves.csv"] = str(out / "curves.csv")
        atomic_write_text(out / "summary.json", json.dumps(json_safe(self.summary()), indent=2, allow_nan=False))
        written["summary.json"] = str(out / "summary.json")
        if figure:
            from bendpam.present.figures import save_figure

            save_figure(self.plot(), out / "figure4.png")
            written["figure4.png"] = str(out / "figure4.png")
        return written

    @classmethod
    def load(cls, path) -> ProcessedSet:
        """Read what :meth:`save` wrote (the folder or its ``curves.nc``)."""
        return load_processed(path)

    def to_frame(self) -> pd.DataFrame:
        """Tidy table of the resampled branches: pressure, cycle, branch, curvature, moment."""
        import pandas as pd

        rows = []
        for r in self.results:
            for ci in range(r.n_cycles):
                for bi, name in enumerate(BRANCHES):
                    rows.append(pd.DataFrame({
                        "pressure_kpa": r.pressure_kpa, "cycle": ci + 1, "branch": name,
                        "curvature_per_mm": r.curvature_grid, "moment_nmm": r.branches[ci, bi],
                    }))
            for name, arr in (("mean_loading", r.mean_loading), ("mean_unloading", r.mean_unloading),
                              ("mean", r.mean_curve)):
                rows.append(pd.DataFrame({
                    "pressure_kpa": r.pressure_kpa, "cycle": 0, "branch": name,
                    "curvature_per_mm": r.curvature_grid, "moment_nmm": arr,
                }))
        return pd.concat(rows, ignore_index=True)


def process_tests(tests, *, fixture: Fixture = PAPER_FIXTURE, options: ProcessingOptions | None = None,
                  keep_series: bool = True) -> ProcessedSet:
    """Process several raw tests (``RawTest`` objects from :func:`bendpam.lab.read_test`).

    Every test needs a pressure (from the reader: option, metadata or filename).  Two tests at one
    pressure are an error.

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
    results = []
    seen: dict[float, str] = {}
    for rt in tests:
        src = str(rt.path)
        if rt.pressure_kpa is None:
            raise ProcessingError(
                f"{src}: no pressure: give --pressure-kpa, a 'Pressure' metadata line, or a filename token like 200kPa"
            )
        p = float(rt.pressure_kpa)
        if p in seen:
            raise ProcessingError(f"{src}: a second test at {p:g} kPa (the first is {seen[p]})")
        seen[p] = src
        d = rt.data
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            res = process_series(d["time_s"].to_numpy(), d["stroke_mm"].to_numpy(), d["force_n"].to_numpy(),
                                 p, fixture=fixture, options=options, source=src, keep_series=keep_series)
        res.notes.extend(getattr(rt, "warnings", []) or [])
        from bendpam.lab.readers import check_cycle_count

        mismatch = check_cycle_count(rt, res.n_cycles)
        if mismatch:
            res.notes.append(mismatch)
        results.append(res)
    if not results:
        raise ProcessingError("no tests to process")
    results.sort(key=lambda r: r.pressure_kpa)
    return ProcessedSet(results=results, fixture=fixture, options=options or ProcessingOptions())


# ------------------------------------------------------------------------------------------------
# outputs
# ------------------------------------------------------------------------------------------------
def write_processed(processed: ProcessedSet, out_dir, *, figure: bool = True) -> dict[str, str]:
    """Write ``curves.nc``, ``curves.csv``, ``summary.json`` (and ``figure4.png``): :meth:`ProcessedSet.save`."""
    return processed.save(out_dir, figure=figure)


class _Curves:
    """The variables (``ds[name].values``), ``data_vars`` and ``attrs`` of a ``curves.nc``, read without xarray."""

    def __init__(self, values: dict, attrs: dict):
        self._values, self.attrs, self.data_vars = values, attrs, set(values)

    def __getitem__(self, name):
        from types import SimpleNamespace

        return SimpleNamespace(values=self._values[name])


def _read_curves(nc):
    """A ``curves.nc`` as :class:`_Curves`: SciPy's NetCDF-3 reader (what bendpam writes), else xarray.

    SciPy's reader is used for NetCDF-3 files (xarray's own scipy backend reads them the same way;
    every variable is float64 or int with NaN as the fill value, so no CF decoding is needed), which
    spares ``bendpam fit`` importing xarray, pandas and Dask.  Other files (NetCDF-4) go through xarray.
    """
    with open(nc, "rb") as fh:
        magic = fh.read(3)
    if magic == b"CDF":
        from scipy.io import netcdf_file

        with netcdf_file(nc, "r", mmap=False) as f:
            values = {k: np.array(v.data) for k, v in f.variables.items()}
            attrs = {k: (v.decode("utf-8") if isinstance(v, bytes) else v) for k, v in f._attributes.items()}
        return _Curves(values, attrs)
    import xarray as xr

    with xr.open_dataset(nc) as ds:
        ds = ds.load()
        return _Curves({k: ds[k].values for k in ds.variables}, dict(ds.attrs))


def load_processed(path) -> ProcessedSet:
    """Read the output of :func:`write_processed` (a folder or its ``curves.nc``) back."""
    from pathlib import Path

    p = Path(path)
    nc = p / "curves.nc" if p.is_dir() else p
    if not nc.exists():
        raise ProcessingError(f"{p}: no curves.nc here; give the output folder of 'bendpam process'")
    try:
        ds = _read_curves(nc)
    except Exception as exc:
        raise ProcessingError(f"{nc}: cannot read as a bendpam processed-curves file ({type(exc).__name__})") from None
    need = {"moment_nmm", "blocked_moment_cycle_nmm", "free_curvature_cycle_per_mm", "energy_loss_ratio_cycle"}
    if not need <= set(ds.data_vars):
        raise ProcessingError(f"{nc}: not a bendpam processed-curves file (missing {sorted(need - set(ds.data_vars))})")
    missing = [k for k in ("fixture_d_mm", "fixture_r_mm", "fixture_t_mm", "L0_mm") if k not in ds.attrs]
    if missing:
        raise ProcessingError(f"{nc}: not a bendpam processed-curves file (attribute(s) {', '.join(missing)} missing)")
    fx = Fixture(ds.attrs["fixture_d_mm"], ds.attrs["fixture_r_mm"], ds.attrs["fixture_t_mm"], ds.attrs["L0_mm"])
    results = []
    sources = str(ds.attrs.get("sources", "")).split("; ")
    for i, P in enumerate(ds["pressure_kpa"].values):
        bmc = ds["blocked_moment_cycle_nmm"].values[i]
        n = int(np.sum(np.isfinite(bmc)))
        if not np.isfinite(P):
            raise ProcessingError(f"{nc}: pressure {i + 1} is not a finite number ({P!r})")
        if n == 0 or not np.isfinite(ds["curvature_per_mm"].values[i]).any() \
                or not np.isfinite(ds["moment_nmm"].values[i, :n]).any():
            raise ProcessingError(f"{nc}: no finite cycle at {float(P):g} kPa (blocked moments, curvatures or "
                                  "moments are all missing); process the raw files again")
        results.append(PressureResult(
            pressure_kpa=float(P), source=sources[i] if i < len(sources) else str(nc), n_cycles=n,
            curvature_grid=ds["curvature_per_mm"].values[i], branches=ds["moment_nmm"].values[i, :n],
            blocked_moments=bmc[:n], free_curvatures=ds["free_curvature_cycle_per_mm"].values[i, :n],
            energy_loss_ratios=ds["energy_loss_ratio_cycle"].values[i, :n], loop_energy=np.full(n, np.nan),
            stored_energy=np.full(n, np.nan), sample_rate_hz=math.nan, cutoff_hz=math.nan,
        ))
    return ProcessedSet(results=results, fixture=fx, options=ProcessingOptions())
