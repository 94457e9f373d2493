"""What processing produces: per-pressure results, the set across pressures, and its files.

:func:`bendpam.lab.processing.process_tests` turns raw tests into a :class:`ProcessedSet`: one
:class:`PressureResult` per pressure (the branches on a common curvature grid, the blocked moment,
the free-bending curvature and the energy-loss ratio of every cycle) and, across pressures, the
deadband (:func:`deadband_fit`).  The set is saved as ``curves.nc`` (NetCDF), ``curves.npz`` (the
same variables and attributes as plain NumPy arrays), ``curves.csv``, ``summary.json`` and
``figure4.png`` (:meth:`ProcessedSet.save`, :func:`write_processed`) and read back by
:func:`load_processed`: from ``curves.npz`` when it was written with the ``curves.nc`` beside it
(no NetCDF library to import), else from ``curves.nc``.  :class:`ProcessingOptions` records the
settings of the processing.

Values are magnitudes, as in the paper (N*mm, 1/mm, kPa).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from bendpam.errors import InputError, ProcessingError
from bendpam.infra.accessors import figure as figure_by_name
from bendpam.infra.budgets import check_input_file
from bendpam.infra.display import summary_html, summary_text
from bendpam.infra.manifest import verify_input
from bendpam.lab.drift import DRIFT_METHODS, DriftEstimate, set_drift_findings
from bendpam.physics.fixture import Fixture

if TYPE_CHECKING:  # pandas and xarray are imported by the functions that use them (fast start-up of `fit`)
    from pathlib import Path

    import pandas as pd
    import xarray as xr

__all__ = [
    "BRANCHES",
    "PressureResult",
    "ProcessedSet",
    "ProcessingOptions",
    "as_processed",
    "deadband_fit",
    "load_processed",
    "write_processed",
]

#: Branches of a cycle, in the order of :attr:`PressureResult.branches`: loading (free -> blocked,
#: the upper curve) and unloading (blocked -> free, the lower curve).
BRANCHES = ("loading", "unloading")


@dataclass(frozen=True)
class ProcessingOptions:
    """Settings of :func:`~bendpam.lab.processing.process_series` (units in the names).

    cutoff_hz : low-pass cutoff (Hz); ``None`` = 1 Hz limited to 40 % of Nyquist; 0 = no filter.
    filter_order : Butterworth order (applied forward and backward, so the effective order doubles).
    reversal_fraction : zig-zag threshold for stroke reversals, as a fraction of the stroke range.
    grid_points : points of the common curvature grid of the branches.
    tare_n : force subtracted before eq 7 (N), e.g. the self-weight read unpressurised.
    zero_stroke : count the stroke from the blocked turning points (True) or use it as recorded.
    drift : the load-cell offset drift (:mod:`bendpam.lab.drift`): ``"none"`` estimates and reports it,
    ``"linear"`` also subtracts the fitted linear offset before the conversion.
    despike_sigmas : isolated spikes of one or two samples, this many noise standard deviations off the
    samples on both sides (:func:`bendpam.lab.checks.noise_spikes`), are replaced by the median of the five
    samples around them before filtering, and the test's notes say so; 0 keeps them (allowed: 0, or 4 to 1e6).

    Examples
    --------
    >>> ProcessingOptions(cutoff_hz=0.5).grid_points
    101
    >>> ProcessingOptions(reversal_fraction=0.6)
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: reversal_fraction = 0.6 is outside the allowed range (0, 0.5)
    """

    cutoff_hz: float | None = None
    filter_order: int = 4
    reversal_fraction: float = 0.05
    grid_points: int = 101
    tare_n: float = 0.0
    zero_stroke: bool = True
    drift: str = "none"
    despike_sigmas: float = 8.0

    def __post_init__(self) -> None:
        if self.drift not in DRIFT_METHODS:
            raise InputError(f"drift = {self.drift!r}; choose one of: {', '.join(DRIFT_METHODS)}")
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
        if not (self.despike_sigmas == 0 or 4.0 <= self.despike_sigmas <= 1e6):
            raise InputError(f"despike_sigmas = {self.despike_sigmas!r} is outside the allowed values: 0 (off) or "
                             "4 to 1e6 noise standard deviations")


@dataclass
class PressureResult:
    """Processed cyclic test at one pressure (magnitudes; N*mm, 1/mm, kPa).

    Made by :func:`~bendpam.lab.processing.process_series`.  The arrays hold one entry per
    complete cycle; :attr:`branches` are the cycles' branches resampled on :attr:`curvature_grid`
    (``[:, 0]`` loading, the upper curve; ``[:, 1]`` unloading, the lower curve).

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.lab.processing import process_series
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> data, _ = simulate_test(bendpam.physics.presets.be_pam(), 150.0,
    ...                         settings=SimulationSettings(cycles=2, rate_hz=5.0, seed=1))
    >>> result = process_series(data["time_s"], data["stroke_mm"], data["force_n"], 150.0, keep_series=False)
    >>> result.branches.shape                     # cycles, (loading, unloading), grid points
    (2, 2, 101)
    >>> round(result.blocked_moment[0]), round(result.free_curvature[0], 5)       # N*mm, 1/mm
    (205, 0.00729)
    """

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
    specimen: str | None = None  # the specimen's name when a file holds several
    replicate: int = 1  # 1, 2, ... among the tests at this pressure
    findings: list[dict] = field(default_factory=list)  # plausibility findings (bendpam.lab.plausibility)
    drift: DriftEstimate | None = None  # the load-cell offset drift (bendpam.lab.drift)
    #: (n_cycles, 2, n_grid) s: each branch point's time since its branch began (None: a set saved before 0.4)
    branch_times_s: np.ndarray | None = None

    @property
    def mean_loading(self) -> np.ndarray:
        """Loading branch (free -> blocked), mean over the cycles (N*mm on :attr:`curvature_grid`)."""
        return self.branches[:, 0].mean(axis=0)

    @property
    def mean_unloading(self) -> np.ndarray:
        """Unloading branch (blocked -> free), mean over the cycles (N*mm on :attr:`curvature_grid`)."""
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
        """Mean over the cycles of loop area / area under the cycle's mean curve (Table 2)."""
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
        """The pressure's Table 2 values (and its source and notes) as a JSON-ready dict."""
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
            "specimen": self.specimen,
            "replicate": self.replicate,
            "notes": list(self.notes),
            "warnings": [f["message"] for f in self.findings],
            "drift": self.drift.to_dict() if self.drift is not None else None,
        }


def deadband_fit(pressure_kpa, blocked_moment_nmm) -> tuple[float, float, float, float]:
    """x-intercept of the least-squares line ``M = a (P - P0)`` and its standard error.

    Returns ``(P0_kpa, P0_se_kpa, slope_nmm_per_kpa, intercept_nmm)``; the standard error uses the
    delta method on the fit's covariance (NaN with fewer than three pressures).

    Examples
    --------
    >>> p0, se, slope, intercept = deadband_fit([100.0, 150.0, 200.0], [80.0, 205.0, 330.0])
    >>> round(p0, 6), round(slope, 6), round(intercept, 6)        # kPa, N*mm/kPa, N*mm
    (68.0, 2.5, -170.0)
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
    """Processed tests at several pressures (sorted by pressure).

    Attributes
    ----------
    results : list of PressureResult
        One per pressure, by increasing pressure.
    fixture : Fixture
        The four-point fixture the tests were converted with.
    options : ProcessingOptions
        The processing settings.

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.lab.processing import process_series
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> from bendpam.physics.fixture import PAPER_FIXTURE
    >>> be, settings = bendpam.physics.presets.be_pam(), SimulationSettings(cycles=2, rate_hz=5.0, seed=1)
    >>> results = []
    >>> for p in (100.0, 150.0, 200.0):
    ...     data, _ = simulate_test(be, p, settings=settings)
    ...     results.append(process_series(data["time_s"], data["stroke_mm"], data["force_n"], p))
    >>> processed = ProcessedSet(results, PAPER_FIXTURE, ProcessingOptions())
    >>> [round(r.blocked_moment[0]) for r in processed.results]                # N*mm
    [80, 205, 330]
    >>> p0, se = processed.deadband()                                          # kPa
    >>> round(p0), round(se, 1)
    (68, 0.1)
    >>> processed.to_frame().columns.tolist()
    ['pressure_kpa', 'cycle', 'branch', 'curvature_per_mm', 'moment_nmm', 'replicate', 'time_s']
    """

    results: list[PressureResult]
    fixture: Fixture
    options: ProcessingOptions
    files: list[dict] = field(default_factory=list)  # what became of each input file (bendpam.lab.batch)

    def _summary(self) -> tuple[str, list[tuple[str, object]], list[str], list[list[Any]]]:
        rows = [[r.pressure_kpa, r.n_cycles, float(np.mean(r.blocked_moments)) if r.n_cycles else None,
                 float(np.mean(r.free_curvatures)) if r.n_cycles else None,
                 100 * float(np.mean(r.energy_loss_ratios)) if r.n_cycles else None] for r in self.results]
        try:
            p0, se = self.deadband()
            deadband = f"{p0:.4g} ± {se:.2g} kPa"
        except (ProcessingError, InputError, ValueError):
            deadband = "not defined"
        fx = self.fixture
        return (f"ProcessedSet: {len(self.results)} pressure(s), fixture d, r, t = {fx.d_mm:g}, {fx.r_mm:g}, "
                f"{fx.t_mm:g} mm", [("deadband", deadband)],
                ["P (kPa)", "cycles", "M_blocked (N·mm)", "k_free (1/mm)", "loss (%)"], rows)

    def __repr__(self) -> str:
        """Table 2 in a few lines (one per pressure; the arrays stay in :attr:`results`)."""
        return summary_text(*self._summary())

    def _repr_html_(self) -> str:
        """Table 2 as a small HTML table for a notebook."""
        return summary_html(*self._summary())

    @property
    def pressures_kpa(self) -> np.ndarray:
        """The pressures of the results (kPa)."""
        return np.array([r.pressure_kpa for r in self.results])

    def deadband_fit(self) -> tuple[float, float, float, float]:
        """The deadband and the line it comes from: ``(P0_kpa, P0_se_kpa, slope_nmm_per_kpa, intercept_nmm)``.

        :func:`deadband_fit` of the blocked moments (each pressure's mean over its cycles of the
        maximum moment) against the pressures; the line ``M = slope * P + intercept`` is what a
        figure draws.
        """
        bm = [r.blocked_moment[0] for r in self.results]
        return deadband_fit(self.pressures_kpa, bm)

    def deadband(self) -> tuple[float, float]:
        """The deadband pressure and its standard error (kPa): where the blocked moment reaches zero.

        The x-intercept of the least-squares line of blocked moment against pressure
        (:meth:`deadband_fit`); NaN with fewer than two pressures, the standard error NaN with fewer
        than three.
        """
        p0, se, _, _ = self.deadband_fit()
        return p0, se

    @property
    def findings(self) -> list[dict]:
        """Every plausibility finding: of the processed tests, of the set (a drift the tests share,
        :func:`bendpam.lab.drift.set_drift_findings`), then of the files that were skipped."""
        out = [f for r in self.results for f in r.findings] + set_drift_findings(self.results)
        return out + [f for info in self.files for f in info.get("findings", [])]

    def replicates(self) -> list[dict]:
        """Per pressure: the tests there (replicates), their mean and spread (std over the tests, n).

        The spread is the sample standard deviation (ddof 1) of the tests' own values (each test's
        mean over its cycles); NaN with one test.

        Examples
        --------
        >>> from types import SimpleNamespace as NS
        >>> tests = [NS(pressure_kpa=150.0, source=name, blocked_moment=(bm, 1.0), free_curvature=(0.007, 1e-5),
        ...             energy_loss_ratio=0.1) for name, bm in (("a.csv", 200.0), ("b.csv", 210.0))]
        >>> row = ProcessedSet.replicates(NS(results=tests))[0]
        >>> row["n"], row["blocked_moment_nmm"], round(row["blocked_moment_std_nmm"], 3), row["tests"]
        (2, 205.0, 7.071, ['a.csv', 'b.csv'])
        """
        rows = []
        pressures = sorted({float(r.pressure_kpa) for r in self.results})
        for p in pressures:
            group = [r for r in self.results if float(r.pressure_kpa) == p]
            row: dict = {"pressure_kpa": p, "n": len(group), "tests": [r.source for r in group]}
            for key, vals in (("blocked_moment", [r.blocked_moment[0] for r in group]),
                              ("free_curvature", [r.free_curvature[0] for r in group]),
                              ("energy_loss_ratio", [r.energy_loss_ratio for r in group])):
                unit = {"blocked_moment": "_nmm", "free_curvature": "_per_mm"}.get(key, "")
                v = np.asarray(vals, dtype=float)
                row[f"{key}{unit}"] = float(np.mean(v))
                row[f"{key}_std{unit}"] = float(np.std(v, ddof=1)) if v.size > 1 else math.nan
            rows.append(row)
        return rows

    def summary(self) -> dict:
        """Table 2 as a JSON-ready dict: every test's summary, the replicates' means, the deadband, units, fixture.

        ``pressures`` holds one entry per test (several at one pressure are replicates, numbered
        by ``replicate``); ``replicates`` one per pressure with the mean and spread of its tests;
        ``warnings`` every plausibility finding; ``files`` what became of each input file.
        """
        p0, se = self.deadband()
        return {
            "pressures": [r.summary() for r in self.results],
            "replicates": self.replicates(),
            "warnings": self.findings,
            "files": list(self.files),
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
        import json

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
                "replicate": ("pressure_kpa", np.array([r.replicate for r in self.results]),
                              {"long_name": "replicate number among the tests at this pressure"}),
            },
        )
        if all(r.branch_times_s is not None for r in self.results):
            tb = np.full((npres, ncyc, 2, npt), np.nan)
            for i, r in enumerate(self.results):
                tb[i, : r.n_cycles] = r.branch_times_s
            ds["time_s"] = (("pressure_kpa", "cycle", "branch", "point"), tb,
                            {"units": "s", "long_name": "time of each branch point since its branch began (reversal)"})
        ds["mean_curve_nmm"] = 0.5 * (ds["mean_loading_nmm"] + ds["mean_unloading_nmm"])
        ds["mean_curve_nmm"].attrs.update(units="N*mm", long_name="hysteresis-free mean curve (average of branches)")
        p0, se = self.deadband()
        ds.attrs.update(
            deadband_kpa=p0, deadband_se_kpa=se, fixture_d_mm=self.fixture.d_mm, fixture_r_mm=self.fixture.r_mm,
            fixture_t_mm=self.fixture.t_mm, L0_mm=self.fixture.L0_mm, sign_convention="magnitudes",
            sources="; ".join(r.source for r in self.results),
            specimens="; ".join(r.specimen or "" for r in self.results),
            plausibility_json=json.dumps([r.findings for r in self.results], allow_nan=True),
            drift_json=json.dumps([r.drift.to_dict() if r.drift is not None else None for r in self.results],
                                  allow_nan=True),
        )
        return ds

    def plot(self, title: str = ""):
        """Figure 4 of the paper for this set (a matplotlib Figure; see :func:`bendpam.present.figures.figure4`).

        The figure function is looked up by name (:func:`bendpam.infra.accessors.figure`), so
        processing does not import the presentation layer.
        """
        return figure_by_name("figure4")(self, title)

    def save(self, out_dir, *, figure: bool = True) -> dict[str, str]:
        """Write ``curves.nc`` (xarray/NetCDF), ``curves.npz``, ``curves.csv``, ``summary.json`` and ``figure4.png``.

        ``curves.npz`` holds the variables and attributes of ``curves.nc`` as plain arrays (no
        pickles) and the sha256 of the ``curves.nc`` it was written with, so that
        :func:`load_processed` reads it only beside that very file.  Every file is written atomically.
        Returns ``{name: path}`` of the files written.
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
        written["curves.npz"] = str(_write_npz(ds, out / "curves.nc"))
        atomic_write_text(out / "curves.csv", self.to_frame().to_csv(index=False, float_format="%.10g"))
        written["curves.csv"] = str(out / "curves.csv")
        atomic_write_text(out / "summary.json", json.dumps(json_safe(self.summary()), indent=2, allow_nan=False))
        written["summary.json"] = str(out / "summary.json")
        if figure:
            figure_by_name("save_figure")(self.plot(), out / "figure4.png")
            written["figure4.png"] = str(out / "figure4.png")
        return written

    @classmethod
    def load(cls, path) -> ProcessedSet:
        """Read what :meth:`save` wrote (the folder or its ``curves.nc``)."""
        return load_processed(path)

    def to_frame(self) -> pd.DataFrame:
        """Tidy table of the resampled branches: pressure, cycle, branch, curvature, moment, replicate, and
        ``time_s``, the test's time at each point of a cycle's branch (empty for the mean curves, and for
        sets processed before branch times were kept)."""
        import pandas as pd

        rows = []
        for r in self.results:
            times = r.branch_times_s
            for ci in range(r.n_cycles):
                for bi, name in enumerate(BRANCHES):
                    rows.append(pd.DataFrame({
                        "pressure_kpa": r.pressure_kpa, "cycle": ci + 1, "branch": name,
                        "curvature_per_mm": r.curvature_grid, "moment_nmm": r.branches[ci, bi],
                        "replicate": r.replicate, "time_s": times[ci, bi] if times is not None else np.nan,
                    }))
            for name, arr in (("mean_loading", r.mean_loading), ("mean_unloading", r.mean_unloading),
                              ("mean", r.mean_curve)):
                rows.append(pd.DataFrame({
                    "pressure_kpa": r.pressure_kpa, "cycle": 0, "branch": name,
                    "curvature_per_mm": r.curvature_grid, "moment_nmm": arr, "replicate": r.replicate,
                    "time_s": np.nan,
                }))
        return pd.concat(rows, ignore_index=True)


# ------------------------------------------------------------------------------------------------
# outputs
# ------------------------------------------------------------------------------------------------
def write_processed(processed: ProcessedSet, out_dir, *, figure: bool = True) -> dict[str, str]:
    """Write ``curves.nc``, ``curves.npz``, ``curves.csv``, ``summary.json`` (and ``figure4.png``): ``save``.

    Examples
    --------
    >>> import tempfile
    >>> import bendpam
    >>> from pathlib import Path
    >>> from bendpam.lab import RawTest
    >>> from bendpam.lab.processing import process_tests
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> be, settings = bendpam.physics.presets.be_pam(), SimulationSettings(cycles=2, rate_hz=5.0, seed=1)
    >>> raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv", pressure_kpa=p)
    ...         for p in (100.0, 200.0)]
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     written = write_processed(process_tests(raws), folder, figure=False)
    ...     names = sorted(Path(path).name for path in written.values())
    >>> names
    ['curves.csv', 'curves.nc', 'curves.npz', 'summary.json']
    """
    return processed.save(out_dir, figure=figure)


#: The entries of ``curves.npz`` besides the variables of ``curves.nc``: its attributes (JSON text) and the
#: sha256 of the ``curves.nc`` written with it.
_NPZ_ATTRS, _NPZ_NC_SHA256 = "_attrs_json", "_curves_nc_sha256"


def _write_npz(ds: xr.Dataset, nc) -> Path:
    """Write ``curves.npz`` beside the ``curves.nc`` just written from ``ds``: its variables, attributes and sha256."""
    import json

    from bendpam.infra.atomic import atomic_path
    from bendpam.infra.fsops import hash_file

    arrays: dict[str, Any] = {str(k): np.asarray(ds[k].values) for k in ds.variables}
    if any(a.dtype.hasobject for a in arrays.values()):  # np.load(allow_pickle=False) could not read them back
        raise ProcessingError(f"{nc}: a variable of the processed set holds Python objects, not numbers or text")
    attrs = {k: v.item() if isinstance(v, np.generic) else v for k, v in ds.attrs.items()}
    arrays[_NPZ_ATTRS] = np.array(json.dumps(attrs, allow_nan=True))
    arrays[_NPZ_NC_SHA256] = np.array(hash_file(nc)[1])
    npz = nc.with_suffix(".npz")
    with atomic_path(npz) as tmp, open(tmp, "wb") as fh:
        np.savez(fh, **arrays)
    return npz


def _trusted_npz(nc, nc_sha256: str | None = None) -> Path | None:
    """The ``curves.npz`` beside ``nc`` when it was written with this very ``nc`` (the sha256 it records), else None.

    ``nc_sha256``: the sha256 of ``nc`` when the set's manifest has just checked it (not hashed again).

    A set written before 0.4 has none (``nc`` is read, silently).  One that was written with
    another ``curves.nc`` (the set was edited since, e.g. with xarray) or cannot be read is not
    used, and a warning says why.
    """
    import warnings
    import zipfile

    from bendpam.infra.fsops import hash_file

    npz = nc.with_suffix(".npz")
    if not npz.is_file():
        return None
    check_input_file(npz, "processed curves file")
    verify_input(npz)  # as curves.nc: a set with a manifest is read only as bendpam wrote it
    try:
        with np.load(npz, allow_pickle=False) as z:
            recorded = str(z[_NPZ_NC_SHA256])
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
        why = f"it cannot be read ({type(exc).__name__})"
    else:
        if recorded == (nc_sha256 or hash_file(nc)[1]):
            return npz
        why = f"it was written with another {nc.name} (that file was changed or replaced since)"
    warnings.warn(f"{npz}: not used, {why}; reading {nc} instead", UserWarning, stacklevel=3)
    return None


class _Curves:
    """The variables (``ds[name].values``), ``data_vars`` and ``attrs`` of a ``curves.nc``, read without xarray."""

    def __init__(self, values: dict, attrs: dict):
        self._values, self.attrs, self.data_vars = values, attrs, set(values)

    def __getitem__(self, name):
        from types import SimpleNamespace

        return SimpleNamespace(values=self._values[name])


def _read_curves(nc):
    """A ``curves.nc`` or ``curves.npz`` as :class:`_Curves`: NumPy, SciPy's NetCDF-3 reader, else xarray.

    A ``curves.npz`` (:func:`_write_npz`) is read with :func:`numpy.load` (no pickles).  SciPy's
    reader is used for NetCDF-3 files (xarray's own scipy backend reads them the same way; every
    variable is float64 or int with NaN as the fill value, so no CF decoding is needed), which
    spares ``bendpam fit`` importing xarray, pandas and Dask.  Other files (NetCDF-4) go through xarray.
    """
    if str(nc).endswith(".npz"):
        import json

        with np.load(nc, allow_pickle=False) as z:
            values = {k: z[k] for k in z.files if k not in (_NPZ_ATTRS, _NPZ_NC_SHA256)}
            attrs = json.loads(str(z[_NPZ_ATTRS]))
        return _Curves(values, attrs)
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


def as_processed(processed) -> ProcessedSet:
    """``processed`` itself, or the set in a folder (a ``str`` or ``Path``) read by :func:`load_processed`.

    Reading checks the folder's manifest as :func:`load_processed` does; anything else that is not a
    processed set is refused in one line.

    >>> as_processed(3.5)
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: expected a processed test set (bendpam.process_tests) or the folder ...
    """
    import os

    if isinstance(processed, str | os.PathLike):
        return load_processed(processed)
    if not hasattr(processed, "results"):
        raise InputError("expected a processed test set (bendpam.process_tests) or the folder the processing wrote "
                         f"(a str or Path); got {type(processed).__name__}")
    return processed


def load_processed(path) -> ProcessedSet:
    """Read the output of :func:`write_processed` (a folder or its ``curves.nc``) back.

    The arrays come from the ``curves.npz`` beside ``curves.nc`` when it was written with that very
    file (it records its sha256), with :func:`numpy.load`; else from ``curves.nc`` (a set saved
    before 0.4, or one whose ``curves.nc`` was changed since: a warning then says why).  Both
    give the same set.  The curves, per-cycle values, branch times, fixture and sources come back; the options are the
    defaults and the samples (:attr:`PressureResult.series`) are not stored.  A set saved before
    0.4 has no branch times (:attr:`PressureResult.branch_times_s` is None): a fit then
    approximates the bending rate (see :mod:`bendpam.identify.ensemble`) and says so.

    Examples
    --------
    >>> import tempfile
    >>> import bendpam
    >>> from pathlib import Path
    >>> from bendpam.lab import RawTest
    >>> from bendpam.lab.processing import process_tests
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> be, settings = bendpam.physics.presets.be_pam(), SimulationSettings(cycles=2, rate_hz=5.0, seed=1)
    >>> raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv", pressure_kpa=p)
    ...         for p in (100.0, 200.0)]
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     _ = write_processed(process_tests(raws, keep_series=False), folder, figure=False)
    ...     back = load_processed(folder)
    >>> back.pressures_kpa.tolist(), [round(r.blocked_moment[0]) for r in back.results]    # kPa, N*mm
    ([100.0, 200.0], [80, 330])
    """
    from pathlib import Path

    p = Path(path)
    nc = p / "curves.nc" if p.is_dir() else p
    if not nc.exists():
        raise ProcessingError(f"{p}: no curves.nc here; give the output folder of 'bendpam process'")
    check_input_file(nc, "processed curves file")  # a regular file of a sane size (a pipe would hang the read)
    nc_sha = verify_input(nc)  # a set that bendpam wrote is read only as it wrote it (its manifest's hashes)
    source = _trusted_npz(nc, nc_sha) or nc  # the same variables, without a NetCDF reader to import
    try:
        ds = _read_curves(source)
    except Exception as exc:
        raise ProcessingError(f"{source}: cannot read as a bendpam processed-curves file ({type(exc).__name__})") \
            from None
    need = {"moment_nmm", "blocked_moment_cycle_nmm", "free_curvature_cycle_per_mm", "energy_loss_ratio_cycle"}
    if not need <= set(ds.data_vars):
        raise ProcessingError(f"{nc}: not a bendpam processed-curves file (missing {sorted(need - set(ds.data_vars))})")
    missing = [k for k in ("fixture_d_mm", "fixture_r_mm", "fixture_t_mm", "L0_mm") if k not in ds.attrs]
    if missing:
        raise ProcessingError(f"{nc}: not a bendpam processed-curves file (attribute(s) {', '.join(missing)} missing)")
    fx = Fixture(ds.attrs["fixture_d_mm"], ds.attrs["fixture_r_mm"], ds.attrs["fixture_t_mm"], ds.attrs["L0_mm"])
    results = []
    sources = str(ds.attrs.get("sources", "")).split("; ")
    specimens = str(ds.attrs.get("specimens", "")).split("; ")
    findings = _stored_findings(ds.attrs.get("plausibility_json"))
    drifts = _stored_drifts(ds.attrs.get("drift_json"))
    replicate = ds["replicate"].values if "replicate" in ds.data_vars else None
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
            specimen=(specimens[i] or None) if i < len(specimens) else None,
            replicate=int(replicate[i]) if replicate is not None else 1,
            findings=findings[i] if i < len(findings) else [],
            drift=drifts[i] if i < len(drifts) else None,
            branch_times_s=ds["time_s"].values[i, :n] if "time_s" in ds.data_vars else None,
        ))
    return ProcessedSet(results=results, fixture=fx, options=ProcessingOptions())


def _stored_findings(text) -> list[list[dict]]:
    """The per-test plausibility findings stored in a ``curves.nc`` (none in files older than 0.4).

    >>> _stored_findings('[[], [{"check": "loss-ratio"}]]')[1][0]["check"], _stored_findings(None)
    ('loss-ratio', [])
    """
    return [list(v) if isinstance(v, list) else [] for v in _stored_list(text)]


def _stored_drifts(text) -> list[DriftEstimate | None]:
    """The per-test drift estimates stored in a ``curves.nc`` (none in files older than 0.4).

    >>> _stored_drifts('[null, {"rate_n_per_s": 0.001}]'), _stored_drifts("[")
    ([None, None], [])
    """
    return [DriftEstimate.from_dict(v) for v in _stored_list(text)]


def _stored_list(text) -> list:
    """A JSON list stored as a ``curves.nc`` attribute; ``[]`` when absent or unreadable.

    >>> _stored_list("[1, 2]"), _stored_list("{}"), _stored_list(None)
    ([1, 2], [], [])
    """
    import json

    if not text:
        return []
    try:
        value = json.loads(str(text))
    except ValueError:
        return []
    return value if isinstance(value, list) else []
