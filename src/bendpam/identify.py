"""Parameter identification from processed cyclic tests (paper section 3.4, eq 53-55, Table 3).

:func:`fit` identifies any subset of alpha0, C10, C01, P_start, E_f and R0_start for either model
from the hysteresis-free mean curves of all pressures at once.

Objective
    Weighted least squares whose sum of squares *is* the paper's cycle metric (eq 53)::

        r_ij = sqrt(K_i / sum K) / (M_max,i sqrt(n_i)) * (M_model(P_i, k_ij) - M_data,ij)
        sum r^2 = NRMSE_cycles^2

    with ``K_i`` the test's maximum curvature (its free curvature) and ``M_max,i`` its maximum
    moment (its blocked moment).  Data are magnitudes; the model is evaluated on the actuator's
    bending side (``k' = bend_sign * |k|``).

Method (variable projection)
    Both models are linear in C10, C01, E_f and P_start for fixed kinematics
    (``M = (P - P_start) A(k') - E_f I_f k' - C10 b10(k') - C01 b01(k')``, see
    ``bendpam.models.*.basis``), and the kinematics depend only on alpha0 and R0_start.  For every
    trial (alpha0, R0_start) the linear parameters are therefore solved exactly by bounded linear
    least squares (``scipy.optimize.lsq_linear``).

    1. Global stage: a grid scan over the nonlinear parameters (41 alpha0 values across their
       bounds, 9 R0_start values), so the answer does not depend on a lucky start.
    2. Local stage: ``scipy.optimize.least_squares`` (trust-region reflective, bounds) on the
       projected problem from the best grid point; the linear parameters stay exact at every step.
    3. Uncertainty: a sandwich covariance ``(J^T J)^-1 (sum_i s_i^2 f_i J_i^T J_i) (J^T J)^-1``
       from the Jacobian at the optimum.  The eq-53 weights normalise the curves but are not
       inverse noise variances, so each pressure's curve ``i`` gets its own residual variance
       ``s_i^2`` and an inflation ``f_i = (1 + rho_i) / (1 - rho_i)`` for the lag-1 autocorrelation
       of its residuals (serially correlated residuals carry less information than their count
       suggests).  Standard errors and the correlation matrix follow; pairs with
       ``|corr| > 0.95`` are flagged as poorly identifiable (C10 and C01 often are).

    When both C10 and C01 are free the solver works with ``S = C10 + C01`` (bounded > 0, the
    initial shear modulus must be positive) and C01, and maps the covariance back.

Bounds: alpha0 within +-10 % of its nominal value (as in the paper) and on the actuator's side of
54.74 deg; C10, C01 in [-5000, 5000] kPa with C10 + C01 >= 1 kPa; P_start in [0, 0.98 min(P_i)];
E_f in [0.1, 10] x nominal; R0_start in [R0, 1.5 R0].  Any bound can be overridden.

Starting values: the linear parameters need none (they are solved exactly for every trial of the
nonlinear ones), and the grid scan makes alpha0's start irrelevant.  Parameters held fixed keep the
actuator's values, or the tension-test values of C10 and C01 when ``tension`` is given
(``bendpam fit-material``).  Each parameter's ``initial`` records the conventional start: the
tension-test values, or else the paper's C10 = 114 kPa and C01 = 300 kPa (section 3.4).

The fold of the BC-PAM does not affect the fit (it compares moments at measured curvatures, no
root finding); it only makes the free-curvature metric skip pressures without an equilibrium,
which are counted and reported.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares, lsq_linear

from .actuator import NEUTRAL_ANGLE_DEG, Actuator
from .atomic import atomic_write_text, json_safe
from .errors import FileFormatError, FitError, InputError
from .law import MomentLaw
from .models import normalise_model

__all__ = [
    "HYST_PARAMETERS",
    "PARAMETERS",
    "FitResult",
    "HysteresisFit",
    "LossRatio",
    "Metrics",
    "Parameter",
    "branch_nrmse",
    "developed_range",
    "fit",
    "parse_free",
    "predicted_loss_ratios",
    "score",
]

#: Identifiable parameters: short name -> (Actuator field, unit).
PARAMETERS = {
    "alpha0": ("alpha0_deg", "deg"),
    "C10": ("C10_kpa", "kPa"),
    "C01": ("C01_kpa", "kPa"),
    "P_start": ("P_start_kpa", "kPa"),
    "E_f": ("frame_modulus_mpa", "MPa"),
    "R0_start": ("R0_start_mm", "mm"),
}
_ALIASES = {
    "alpha0": "alpha0", "alpha0_deg": "alpha0", "a0": "alpha0", "alpha": "alpha0",
    "c10": "C10", "c10_kpa": "C10", "c1": "C10",
    "c01": "C01", "c01_kpa": "C01", "c2": "C01",
    "p_start": "P_start", "pstart": "P_start", "p_start_kpa": "P_start",
    "e_f": "E_f", "ef": "E_f", "frame_modulus_mpa": "E_f", "frame_modulus": "E_f",
    "r0_start": "R0_start", "r0start": "R0_start", "r0_start_mm": "R0_start",
}
_NONLINEAR = ("alpha0", "R0_start")
#: The paper's starting values of the identification (section 3.4, from its tension test), kPa.
PAPER_START = {"C10": 114.0, "C01": 300.0}
_ORDER = ("alpha0", "C10", "C01", "P_start", "E_f", "R0_start")


def parse_free(free) -> list[str]:
    """Normalise a list (or comma string) of parameter names; unknown names raise ValueError."""
    if isinstance(free, str):
        free = [f for f in free.replace(" ", ",").split(",") if f]
    out = []
    for f in free:
        key = _ALIASES.get(str(f).strip().lower())
        if key is None:
            raise InputError(f"unknown parameter {f!r} to fit; choose from {', '.join(PARAMETERS)}")
        if key not in out:
            out.append(key)
    if not out:
        raise InputError(f"no parameter to fit; choose from {', '.join(PARAMETERS)}")
    return sorted(out, key=_ORDER.index)


@dataclass
class Parameter:
    """One identified parameter (lmfit-style): value, standard error, bounds, vary flag, unit."""

    name: str
    field: str
    unit: str
    value: float
    stderr: float | None
    min: float
    max: float
    vary: bool
    initial: float

    def to_dict(self) -> dict:
        return {"value": self.value, "stderr": self.stderr, "min": self.min, "max": self.max, "vary": self.vary,
                "initial": self.initial, "unit": self.unit}

    @classmethod
    def from_dict(cls, name: str, field_name: str, d: dict) -> Parameter:
        return cls(name, field_name, d["unit"], float(d["value"]), None if d["stderr"] is None else float(d["stderr"]),
                   _num(d["min"]), _num(d["max"]), bool(d["vary"]), _num(d["initial"]))


@dataclass
class Metrics:
    """Paper metrics (eq 53-55) and plain RMSEs of a model against processed data."""

    nrmse_cycles: float
    nrmse_blocked_moment: float
    nrmse_free_curvature: float
    rmse_cycles: float
    rmse_blocked_moment: float
    rmse_free_curvature: float
    per_pressure: list[dict]
    no_equilibrium_kpa: list[float]

    def to_dict(self) -> dict:
        return {
            "nrmse": {"cycles": self.nrmse_cycles, "blocked_moment": self.nrmse_blocked_moment,
                      "free_curvature": self.nrmse_free_curvature},
            "rmse": {"cycles_nmm": self.rmse_cycles, "blocked_moment_nmm": self.rmse_blocked_moment,
                     "free_curvature_per_mm": self.rmse_free_curvature},
            "per_pressure": self.per_pressure,
            "no_equilibrium_kpa": self.no_equilibrium_kpa,
        }


HYST_PARAMETERS = {"theta_h": ("theta_h_deg", "deg"), "a0": ("a0_nmm", "N*mm"), "a1": ("a1_nmm_per_kpa", "N*mm/kPa")}


def _label(name: str) -> str:
    return (PARAMETERS.get(name) or HYST_PARAMETERS[name])[0]


@dataclass
class _Data:
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


def developed_range(result, threshold: float = 0.8, negligible: float = 0.01) -> np.ndarray:
    """Mask of the grid points where the hysteresis loop is developed.

    Near each reversal a rounded loop closes: there both branches lie on the same side of the
    hysteresis-free curve, and their average is biased by up to the loop's half-width.  Where the
    half-width ``(loading - unloading) / 2`` is at least ``threshold`` times its median, the average
    of the branches is a fair estimate of the quasi-static curve.  If the loop is negligible
    (median half-width below ``negligible`` of the blocked moment) every point is kept.
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


def _branch_data(processed, L0: float) -> _Data:
    """Both mean branches of every pressure (for fits with a hysteresis loop)."""
    res = processed.results
    if not res:
        raise InputError("no processed pressures to fit")
    d = _data(processed, "all")
    k, M, w, Pc, seg, br, delta, span = [], [], [], [], [], [], [], []
    wK = d.K / d.K.sum()
    for i, r in enumerate(res):
        g = np.asarray(r.curvature_grid, float)
        n = g.size
        Kf = d.K[i]
        for sign, curve, dist in ((1, r.mean_loading, (Kf - g) * L0), (-1, r.mean_unloading, g * L0)):
            k.append(g)
            M.append(np.asarray(curve, float))
            w.append(np.full(n, math.sqrt(wK[i]) / (d.BM[i] * math.sqrt(2 * n))))
            Pc.append(np.full(n, d.P[i]))
            seg.append(np.full(n, i))
            br.append(np.full(n, sign))
            delta.append(np.maximum(dist, 0.0))
            span.append(np.full(n, Kf * L0))
    cat = np.concatenate
    return _Data(d.P, d.k, d.M, d.BM, d.BM_se, d.K, d.K_se, cat(w), cat(k), cat(M), cat(Pc), cat(seg), cat(br),
                 cat(delta), cat(span))


def _data(processed, fit_range: str = "developed") -> _Data:
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
    return _Data(P, k, M, BM, BMse, K, Kse, w, np.concatenate(k), np.concatenate(M),
                 np.concatenate([np.full(kk.size, P[i]) for i, kk in enumerate(k)]), seg)


def _default_bounds(actuator: Actuator, P_min_kpa: float) -> dict[str, tuple[float, float]]:
    a0 = actuator.alpha0_deg
    lo, hi = 0.9 * a0, min(1.1 * a0, 89.9)
    if actuator.bend_sign > 0:
        lo = max(lo, NEUTRAL_ANGLE_DEG + 0.05)
    elif actuator.bend_sign < 0:
        hi = min(hi, NEUTRAL_ANGLE_DEG - 0.05)
    return {
        "alpha0": (lo, hi),
        "C10": (-5000.0, 5000.0),
        "C01": (-5000.0, 5000.0),
        "P_start": (0.0, 0.98 * P_min_kpa),
        "E_f": (0.1 * actuator.frame_modulus_mpa, 10.0 * actuator.frame_modulus_mpa),
        "R0_start": (actuator.R0_mm, 1.5 * actuator.R0_mm),
    }


class _Problem:
    """Residuals of the weighted problem for a given set of free parameters."""

    def __init__(self, actuator: Actuator, data: _Data, model: str, free: list[str], bounds, order: int,
                 eq19_factor: bool, hysteresis: str | None = None):
        self.hyst = hysteresis
        if hysteresis:
            free = [*free, "theta_h", "a0", "a1"]
        self._qs_cache: dict = {}
        self.base = actuator
        self.d = data
        self.model = model
        self.free = free
        self.bounds = bounds
        self.order = order
        self.eq19 = eq19_factor
        self.sign = actuator.bend_sign or 1
        self.nonlin = [p for p in free if p in _NONLINEAR or p == "theta_h"]
        self.lin = [p for p in free if p not in _NONLINEAR and p != "theta_h"]
        # both C10 and C01 free: solve for S = C10 + C01 and C01 (S > 0)
        self.sum_param = "C10" in self.lin and "C01" in self.lin

    # -- linear parameters in internal coordinates ---------------------------------------------
    def lin_names(self) -> list[str]:
        return ["S" if (p == "C10" and self.sum_param) else p for p in self.lin]

    def lin_bounds(self):
        lo, hi = [], []
        for p in self.lin_names():
            if p == "S":
                lo.append(1.0)
                hi.append(self.bounds["C10"][1] + self.bounds["C01"][1])
            elif p == "C10" and "C01" not in self.lin:  # C10 + C01_fixed >= 1
                lo.append(max(self.bounds["C10"][0], 1.0 - self.base.C01_kpa))
                hi.append(self.bounds["C10"][1])
            elif p == "C01" and "C10" not in self.lin:
                lo.append(max(self.bounds["C01"][0], 1.0 - self.base.C10_kpa))
                hi.append(self.bounds["C01"][1])
            else:
                lo.append(self.bounds[p][0])
                hi.append(self.bounds[p][1])
        return np.array(lo), np.array(hi)

    def actuator(self, values: dict[str, float]) -> Actuator:
        ch = {PARAMETERS[p][0]: v for p, v in values.items() if p in PARAMETERS}
        return self.base.replace(**ch)

    def design(self, nl: dict[str, float]):
        """Fixed part ``c0`` and columns ``X`` (per internal linear unit) of the model magnitude."""
        key = tuple(sorted((p, v) for p, v in nl.items() if p in PARAMETERS))
        if key not in self._qs_cache:
            if len(self._qs_cache) > 64:
                self._qs_cache.clear()
            self._qs_cache[key] = self._design_qs(dict(key))
        c0, cols = self._qs_cache[key]
        if self.hyst:
            from .hysteresis import make_law

            z_away, z_back = make_law(self.hyst, nl["theta_h"]).steady_branches(self.d.delta, self.d.span)
            assert self.d.branch is not None, "a hysteresis fit is built on branch-resolved data"
            z = np.where(self.d.branch < 0, z_away, z_back)  # unloading leaves the blocked state
            pa = np.maximum(self.d.Pc - self.base.P_start_kpa, 0.0)
            cols = {**cols, "a0": -z, "a1": -z * pa}
        xcols = []
        for p in self.lin_names():
            if p == "S":
                xcols.append(cols["C10"])
            elif p == "C01" and self.sum_param:
                xcols.append(cols["C01"] - cols["C10"])
            else:
                xcols.append(cols[p])
        X = np.column_stack(xcols) if xcols else np.zeros((c0.size, 0))
        return c0, X

    def _design_qs(self, nl: dict[str, float]):
        a = self.base.replace(**{PARAMETERS[p][0]: v for p, v in nl.items()})
        s = self.sign
        ks = s * self.d.kc
        A, b10, b01 = MomentLaw(a, self.model, eq19_factor=self.eq19, order=self.order).basis(ks)
        P = self.d.Pc
        If = a.frame_inertia_mm4
        cols = {
            "C10": -s * b10,  # per kPa
            "C01": -s * b01,
            "P_start": -s * A,  # per kPa
            "E_f": -If * self.d.kc,  # per MPa (magnitude: -E I |k|)
        }
        c0 = s * (P * A)
        for p in ("C10", "C01", "P_start", "E_f"):
            if p not in self.lin:
                c0 = c0 + cols[p] * {"C10": a.C10_kpa, "C01": a.C01_kpa, "P_start": a.P_start_kpa,
                                     "E_f": a.frame_modulus_mpa}[p]
        return c0, cols

    def to_user(self, nl: dict[str, float], lin_int: np.ndarray) -> dict[str, float]:
        out = dict(nl)
        names = self.lin_names()
        vals = dict(zip(names, lin_int, strict=True))
        for p in self.lin:
            if p == "C10" and self.sum_param:
                out["C10"] = vals["S"] - vals["C01"]
            else:
                out[p] = vals[p]
        return out

    def project(self, nl: dict[str, float]):
        """Best linear parameters for the nonlinear ones; returns (residuals, lin_int)."""
        c0, X = self.design(nl)
        w = self.d.w
        y = w * (self.d.Mc - c0)
        if X.shape[1] == 0:
            return -y, np.zeros(0)
        lo, hi = self.lin_bounds()
        sol = lsq_linear(w[:, None] * X, y, bounds=(lo, hi), method="bvls", lsmr_tol=None)
        return w * (c0 + X @ sol.x - self.d.Mc), sol.x

    def residual_full(self, x_int: np.ndarray) -> np.ndarray:
        nl = dict(zip(self.nonlin, x_int[: len(self.nonlin)], strict=True))
        c0, X = self.design(nl)
        return self.d.w * (c0 + X @ x_int[len(self.nonlin):] - self.d.Mc)


def _lag1(resid: np.ndarray, seg: np.ndarray) -> float:
    num = den = 0.0
    for i in np.unique(seg):
        r = resid[seg == i]
        r = r - r.mean()
        num += float(r[1:] @ r[:-1])
        den += float(r @ r)
    return num / den if den > 0 else 0.0


@dataclass(frozen=True)
class LossRatio:
    """Energy-loss ratio of one test: measured (processing) and predicted (the fitted loop)."""

    pressure_kpa: float
    measured: float
    predicted: float


@dataclass
class HysteresisFit:
    """The loop part of a fit (``fit(..., hysteresis="pi")``): parameters, loss ratios, branch NRMSE."""

    law: str
    amplitude: str
    parameters: dict[str, Parameter]
    energy_loss_ratio: list[LossRatio]
    nrmse_branches: float

    def loop(self):
        """The fitted :class:`bendpam.hysteresis.LoopModel`."""
        from .hysteresis import LoopModel

        return LoopModel(law=self.law, amplitude=self.amplitude,
                         **{p.field: p.value for p in self.parameters.values()})

    def to_dict(self) -> dict:
        return {"law": self.law, "amplitude": self.amplitude,
                "parameters": {p.field: p.to_dict() for p in self.parameters.values()},
                "energy_loss_ratio": [asdict(e) for e in self.energy_loss_ratio],
                "nrmse_branches": self.nrmse_branches}

    @classmethod
    def from_dict(cls, d: dict) -> HysteresisFit:
        names = {v[0]: k for k, v in HYST_PARAMETERS.items()}
        params = {names[f]: Parameter.from_dict(names[f], f, v) for f, v in d["parameters"].items()}
        return cls(d["law"], d.get("amplitude", "linear"), params,
                   [LossRatio(**e) for e in d.get("energy_loss_ratio", [])], d.get("nrmse_branches", math.nan))


@dataclass
class FitResult:
    """Result of :func:`fit`: a value you can print, predict with, plot, save and load.

    Attributes
    ----------
    model : the model fitted (``"energy"`` or ``"force_balance"``).
    actuator : the fitted :class:`~bendpam.Actuator` (usable by every command).
    parameters : short name -> :class:`Parameter` (value, standard error, bounds, vary flag, unit).
    correlation, correlation_names : correlation matrix of the varied parameters.
    metrics : :class:`Metrics` (eq 53-55).
    converged, message, nfev, time_s : about the search.
    flags : plain-language warnings (poorly identifiable pairs, parameters at a bound, folds).
    autocorrelation : mean lag-1 autocorrelation of the residuals (used in the standard errors).
    hysteresis : :class:`HysteresisFit` or None.
    """

    model: str
    actuator: Actuator
    parameters: dict[str, Parameter]
    correlation: np.ndarray
    correlation_names: list[str]
    metrics: Metrics
    converged: bool
    message: str
    nfev: int
    time_s: float
    flags: list[str] = field(default_factory=list)
    autocorrelation: float = 0.0
    hysteresis: HysteresisFit | None = None

    @property
    def loop(self):
        """The fitted loop (:class:`bendpam.hysteresis.LoopModel`) or None."""
        return None if self.hysteresis is None else self.hysteresis.loop()

    def predict(self, pressure_kpa, curvature_per_mm) -> np.ndarray:
        """The fitted model's quasi-static moment ``M(P, k')`` (N*mm), broadcasting (signed as the paper)."""
        return MomentLaw.of(self.actuator, self.model).moment(pressure_kpa, curvature_per_mm)

    def plot(self, processed, title: str = ""):
        """Figure 7 (a matplotlib Figure): the fitted model against ``processed``."""
        from .plots import figure7

        return figure7(processed, self, title)

    def to_dict(self) -> dict:
        m = self.metrics.to_dict()
        return {
            "model": self.model,
            "parameters": {PARAMETERS[n][0]: p.to_dict() for n, p in self.parameters.items()},
            "correlation": {"names": [_label(n) for n in self.correlation_names],
                            "matrix": self.correlation.tolist()},
            "nrmse": m["nrmse"],
            "rmse": m["rmse"],
            "per_pressure": m["per_pressure"],
            "no_equilibrium_kpa": m["no_equilibrium_kpa"],
            "flags": self.flags,
            "converged": self.converged,
            "message": self.message,
            "nfev": self.nfev,
            "time_s": self.time_s,
            "residual_autocorrelation": self.autocorrelation,
            "actuator": self.actuator.to_dict(),
            **({"hysteresis": self.hysteresis.to_dict()} if self.hysteresis is not None else {}),
        }

    def to_json(self) -> str:
        return json.dumps(json_safe(self.to_dict()), indent=2, allow_nan=False)

    def save(self, out_dir) -> dict[str, str]:
        """Write ``fit.json`` and ``fitted_actuator.toml`` atomically into the folder ``out_dir``."""
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        atomic_write_text(out / "fit.json", self.to_json())
        text = self.actuator.to_toml()
        loop = self.loop
        if loop is not None:
            import tomli_w

            text += "\n" + tomli_w.dumps({"hysteresis": loop.to_dict()})
        atomic_write_text(out / "fitted_actuator.toml", text)
        return {"fit.json": str(out / "fit.json"), "fitted_actuator.toml": str(out / "fitted_actuator.toml")}

    @classmethod
    def load(cls, path) -> FitResult:
        """Read a fit written by :meth:`save` (the folder or its ``fit.json``)."""
        p = Path(path)
        fj = p / "fit.json" if p.is_dir() else p
        try:
            d = json.loads(fj.read_text(encoding="utf-8"))
            act = Actuator.from_dict(d["actuator"], source=str(fj))
            short = {v[0]: k for k, v in PARAMETERS.items()}
            params = {short[f]: Parameter.from_dict(short[f], f, v) for f, v in d["parameters"].items()}
            rev = {v[0]: k for k, v in {**PARAMETERS, **HYST_PARAMETERS}.items()}
            metrics = Metrics(
                nrmse_cycles=_num(d["nrmse"]["cycles"]), nrmse_blocked_moment=_num(d["nrmse"]["blocked_moment"]),
                nrmse_free_curvature=_num(d["nrmse"]["free_curvature"]), rmse_cycles=_num(d["rmse"]["cycles_nmm"]),
                rmse_blocked_moment=_num(d["rmse"]["blocked_moment_nmm"]),
                rmse_free_curvature=_num(d["rmse"]["free_curvature_per_mm"]), per_pressure=d["per_pressure"],
                no_equilibrium_kpa=d["no_equilibrium_kpa"])
            return cls(
                model=d["model"], actuator=act, parameters=params,
                correlation=np.array(d["correlation"]["matrix"], dtype=float).reshape(
                    len(d["correlation"]["names"]), len(d["correlation"]["names"])),
                correlation_names=[rev[n] for n in d["correlation"]["names"]], metrics=metrics,
                converged=bool(d["converged"]), message=str(d["message"]), nfev=int(d["nfev"]),
                time_s=float(d["time_s"]), flags=list(d["flags"]),
                autocorrelation=float(d.get("residual_autocorrelation", 0.0)),
                hysteresis=HysteresisFit.from_dict(d["hysteresis"]) if d.get("hysteresis") else None,
            )
        except FileNotFoundError:
            raise FileFormatError(f"{fj}: no such fit file; give the output folder of 'bendpam fit'") from None
        except (OSError, UnicodeDecodeError, json.JSONDecodeError, KeyError, TypeError, ValueError) as exc:
            raise FileFormatError(f"{fj}: not a bendpam fit.json ({type(exc).__name__}: {exc})") from None

    def __str__(self) -> str:
        lines = [f"{self.model.replace('_', '-')} model fit ({'converged' if self.converged else 'NOT converged'}, "
                 f"{self.nfev} evaluations, {self.time_s:.2f} s)"]
        for n, p in self.parameters.items():
            se = "fixed" if not p.vary else (f"± {p.stderr:.3g}" if p.stderr is not None else "± n/a")
            lines.append(f"  {PARAMETERS[n][0]:>18} = {p.value:10.4g} {se:>12}  [{p.min:g}, {p.max:g}]")
        m = self.metrics
        lines.append(f"  NRMSE cycles {100 * m.nrmse_cycles:.2f} %, "
                     f"blocked moment {100 * m.nrmse_blocked_moment:.2f} %, "
                     f"free curvature {_pct(m.nrmse_free_curvature)}")
        h = self.hysteresis
        if h is not None:
            lines.append("  loop (" + h.law + "): " + ", ".join(
                f"{p.field} = {p.value:.4g}" + (f" ± {p.stderr:.2g}" if p.stderr is not None else "")
                for p in h.parameters.values()) + f"; NRMSE of the branches {100 * h.nrmse_branches:.2f} %")
            lines.append("  energy-loss ratio measured/predicted: " + ", ".join(
                f"{e.pressure_kpa:g} kPa {100 * e.measured:.1f}/{100 * e.predicted:.1f} %"
                for e in h.energy_loss_ratio))
        lines += [f"  note: {f}" for f in self.flags]
        return "\n".join(lines)


def _num(x) -> float:
    return math.nan if x is None else float(x)


def _pct(x):
    return "n/a" if x is None or not np.isfinite(x) else f"{100 * x:.2f} %"


def score(
    processed, actuator: Actuator, model: str = "energy", *, order: int = 32, eq19_factor: bool = True
) -> Metrics:
    """Metrics of eq 53-55 (and plain RMSEs) of ``actuator`` against processed data, without fitting.

    * eq 53: ``NRMSE_cycles = sqrt(sum_i (RMSE_i / M_max,i)^2 K_max,i / sum_i K_max,i)`` over the
      mean curves, with ``M_max,i`` the test's blocked moment and ``K_max,i`` its free curvature;
    * eq 54: ``NRMSE_BM = RMSE_BM / max_i BM_i``;
    * eq 55: ``NRMSE_FBC = RMSE_FBC / max_i FBC_i``, over the pressures where the model has a
      free-bending equilibrium (the others are listed in ``no_equilibrium_kpa``).
    """
    model = normalise_model(model)
    d = _data(processed, "all")
    law = MomentLaw(actuator, model, order=order, eq19_factor=eq19_factor)
    s = actuator.bend_sign or 1
    A, B = law.coefficients(s * d.kc)
    pa = np.maximum(d.Pc - actuator.P_start_kpa, 0.0)
    Mm = s * (pa * A - B)
    per = []
    rm_list = []
    for i in range(d.P.size):
        sel = d.seg == i
        rm_list.append(math.sqrt(float(np.mean((Mm[sel] - d.Mc[sel]) ** 2))))
    rm = np.array(rm_list)
    nrmse_c = math.sqrt(float(np.sum((rm / d.BM) ** 2 * d.K) / np.sum(d.K)))
    bm_model = np.abs(law.blocked_moment(d.P))
    rmse_bm = math.sqrt(float(np.mean((bm_model - d.BM) ** 2)))
    kf_model = np.abs(law.free_curvature_array(d.P))
    ok = np.isfinite(kf_model)
    rmse_fbc = math.sqrt(float(np.mean((kf_model[ok] - d.K[ok]) ** 2))) if ok.any() else math.nan
    for i in range(d.P.size):
        per.append({
            "pressure_kpa": float(d.P[i]), "rmse_cycle_nmm": float(rm[i]), "M_max_nmm": float(d.BM[i]),
            "K_max_per_mm": float(d.K[i]), "blocked_moment_model_nmm": float(bm_model[i]),
            "free_curvature_model_per_mm": float(kf_model[i]) if ok[i] else None,
        })
    sq = (Mm - d.Mc) ** 2
    return Metrics(
        nrmse_cycles=nrmse_c,
        nrmse_blocked_moment=rmse_bm / float(d.BM.max()),
        nrmse_free_curvature=rmse_fbc / float(d.K.max()) if ok.any() else math.nan,
        rmse_cycles=math.sqrt(float(np.mean(sq))),
        rmse_blocked_moment=rmse_bm,
        rmse_free_curvature=rmse_fbc,
        per_pressure=per,
        no_equilibrium_kpa=[float(p) for p in d.P[~ok]],
    )


def fit(processed, actuator: Actuator, model: str = "energy", free=("alpha0", "C10", "C01"), *,
        bounds: dict[str, tuple[float, float]] | None = None, tension=None, order: int = 32,
        eq19_factor: bool = True, grid_alpha: int = 41, grid_r0: int = 9, corr_flag: float = 0.95,
        fit_range: str = "developed", hysteresis: str | None = None) -> FitResult:
    """Identify ``free`` parameters of ``actuator`` for ``model`` from a processed test set.

    The stages: :func:`_setup` (data, bounds, the problem), :func:`_start` (a global grid over the
    nonlinear parameters with the linear ones projected), :func:`_search` (a trust-region search
    on the projected problem), :func:`_uncertainty` (sandwich covariance) and :func:`_result`.

    Parameters
    ----------
    processed : :class:`bendpam.lab.processing.ProcessedSet` (or ``load_processed(dir)``).
    actuator : the nominal actuator (geometry, and the values of the parameters held fixed).
    model : ``"energy"`` or ``"force_balance"``.
    free : names among alpha0, C10, C01, P_start, E_f, R0_start (aliases such as ``alpha0_deg`` work).
    bounds : overrides of the default bounds, ``{name: (lo, hi)}`` in the parameter's unit.
    tension : a tension-test fit with ``C10_kpa`` and ``C01_kpa``; they replace the actuator's
        before fitting.
    fit_range : ``"developed"`` (default) fits each mean curve where the hysteresis loop is
        developed (see :func:`developed_range`): near the reversals a rounded loop biases the
        average of the branches.  ``"all"`` fits every point, as the paper did.  The metrics are
        always computed on every point (eq 53).
    hysteresis : ``None`` (fit the mean curves), or a loop law (``"pi"`` or ``"dahl"``, see
        :mod:`bendpam.hysteresis`): fit both branches of every pressure with
        ``M = M_load - (a0 + a1 P_active) z`` on a steady cycle between the blocked state and each
        test's free curvature.  ``a0`` (N*mm) and ``a1`` (N*mm/kPa) are linear parameters, the law's
        angle ``theta_h`` a nonlinear one (scanned and searched with alpha0).

    Returns
    -------
    FitResult
    """
    t0 = time.perf_counter()
    model = normalise_model(model)
    prob, d, bnd, actuator, hysteresis = _setup(processed, actuator, model, free, bounds, tension, order,
                                                eq19_factor, fit_range, hysteresis)
    best, nfev = _start(prob, bnd, grid_alpha, grid_r0)
    nl, lin, converged, message, n = _search(prob, bnd, best)
    nfev += n
    unc = _uncertainty(prob, d, bnd, nl, lin, corr_flag)
    nfev += unc.nfev
    return _result(processed, actuator, model, prob, bnd, unc, tension, hysteresis, converged, message, nfev,
                   time.perf_counter() - t0, order, eq19_factor)


def _setup(processed, actuator, model, free, bounds, tension, order, eq19_factor, fit_range, hysteresis):
    """Stage 1: the data, the bounds and the projected least-squares problem."""
    free = parse_free(free)
    if tension is not None:
        actuator = actuator.replace(C10_kpa=tension.C10_kpa, C01_kpa=tension.C01_kpa)
    if hysteresis is not None:
        from .hysteresis import LAWS

        hysteresis = str(hysteresis).lower()
        if hysteresis not in LAWS:
            raise InputError(f"hysteresis law {hysteresis!r} is not known; choose one of {', '.join(LAWS)}")
        d = _branch_data(processed, actuator.L0_mm)
    else:
        d = _data(processed, fit_range)
    bnd = _default_bounds(actuator, float(d.P.min()))
    bnd.update({"theta_h": (0.2, 90.0), "a0": (0.0, 10.0 * float(d.BM.max())), "a1": (0.0, 100.0)})
    for k, v in (bounds or {}).items():
        key = parse_free([k])[0]
        lo, hi = float(v[0]), float(v[1])
        if not lo < hi:
            raise InputError(f"bounds for {k}: lower {lo:g} must be below upper {hi:g}")
        bnd[key] = (lo, hi)
    if "P_start" not in free and actuator.P_start_kpa >= d.P.min():
        raise InputError(
            f"P_start = {actuator.P_start_kpa:g} kPa is not below the lowest test pressure {d.P.min():g} kPa"
        )
    return _Problem(actuator, d, model, free, bnd, order, eq19_factor, hysteresis), d, bnd, actuator, hysteresis


def _start(prob: _Problem, bnd, grid_alpha: int, grid_r0: int):
    """Stage 2: a global grid over the nonlinear parameters, the linear ones projected exactly."""
    nfev = 0
    grids = []
    for p in prob.nonlin:
        lo, hi = bnd[p]
        if p == "theta_h":  # the loop's angle spans decades: a geometric grid
            grids.append(np.geomspace(0.5, 40.0, 14))
        else:
            grids.append(np.linspace(lo, hi, grid_alpha if p == "alpha0" else grid_r0))
    best: tuple[float, dict[str, float]] = (math.inf, {})
    if not grids:
        return best, nfev
    mesh = np.meshgrid(*grids, indexing="ij")
    for idx in np.ndindex(mesh[0].shape):
        nl = {p: float(m[idx]) for p, m in zip(prob.nonlin, mesh, strict=True)}
        r, _ = prob.project(nl)
        nfev += 1
        ssr = float(r @ r)
        if ssr < best[0]:
            best = (ssr, nl)
    return best, nfev


def _search(prob: _Problem, bnd, best):
    """Stage 3: a bounded trust-region search on the projected problem; the final linear solve."""
    nfev = 0
    converged, message = True, "linear least squares (exact)"
    nl_best = best[1]
    if prob.nonlin:
        x0 = np.array([nl_best[p] for p in prob.nonlin])
        lo = np.array([bnd[p][0] for p in prob.nonlin])
        hi = np.array([bnd[p][1] for p in prob.nonlin])

        def fun(x):
            return prob.project(dict(zip(prob.nonlin, x, strict=True)))[0]

        sol = least_squares(fun, x0, bounds=(lo, hi), method="trf", x_scale=np.maximum(hi - lo, 1e-9) * 0.05,
                            diff_step=1e-6, xtol=1e-12, ftol=1e-12, gtol=1e-12)
        nfev += sol.nfev * (1 + len(prob.nonlin))
        converged = bool(sol.status > 0)
        message = "converged" if converged else "the search stopped before converging (iteration limit)"
        nl_best = dict(zip(prob.nonlin, sol.x, strict=True))
    _, lin = prob.project(nl_best)
    return nl_best, lin, converged, message, nfev + 1


@dataclass
class _Uncertainty:
    values: dict[str, float]
    names: list[str]
    sd: np.ndarray
    corr: np.ndarray
    flags: list[str]
    rho: float
    nfev: int


def _uncertainty(prob: _Problem, d, bnd, nl_best, lin, corr_flag: float) -> _Uncertainty:
    """Stage 4: sandwich covariance from the joint Jacobian (nonlinear columns by central differences).

    The weights normalise each curve (eq 53), they are not inverse noise variances, so each curve
    gets its own residual variance (with its AR(1) inflation).
    """
    nfev = 0
    x_int = np.concatenate([[nl_best[p] for p in prob.nonlin], lin])
    r = prob.residual_full(x_int)
    m = r.size
    J = np.empty((m, x_int.size))
    nn = len(prob.nonlin)
    for j in range(nn):
        h = 1e-5 * max(abs(x_int[j]), 1.0)
        e = np.zeros_like(x_int)
        e[j] = h
        J[:, j] = (prob.residual_full(x_int + e) - prob.residual_full(x_int - e)) / (2 * h)
        nfev += 2
    _, X = prob.design(nl_best)
    J[:, nn:] = prob.d.w[:, None] * X
    B = J.T @ J
    meat = np.zeros_like(B)
    share = 1.0 - x_int.size / max(m, 1)
    rhos = []
    for i in np.unique(d.seg):
        sel = d.seg == i
        ri = r[sel]
        var_i = float(ri @ ri) / max(share * ri.size, 1.0)
        rho_i = min(max(_lag1(ri, np.zeros(ri.size, int)), 0.0), 0.95)
        rhos.append(rho_i)
        meat += (J[sel].T @ J[sel]) * var_i * (1.0 + rho_i) / (1.0 - rho_i)
    rho = float(np.mean(rhos)) if rhos else 0.0
    names_int = prob.nonlin + prob.lin_names()
    lo_all = np.concatenate([[bnd[p][0] for p in prob.nonlin], prob.lin_bounds()[0]])
    hi_all = np.concatenate([[bnd[p][1] for p in prob.nonlin], prob.lin_bounds()[1]])
    at_bound = (np.abs(x_int - lo_all) <= 1e-9 * np.maximum(1, np.abs(lo_all))) | (
        np.abs(x_int - hi_all) <= 1e-9 * np.maximum(1, np.abs(hi_all)))
    try:
        Binv = np.linalg.pinv(B, rcond=1e-13)
    except np.linalg.LinAlgError:
        raise FitError("the data do not determine the parameters (the Jacobian is degenerate: the curves at "
                       "the tested pressures cannot separate them); fix some with a narrower --free") from None
    cov_int = Binv @ meat @ Binv
    G = np.eye(x_int.size)  # internal (S, C01) -> user (C10, C01)
    if prob.sum_param:
        G[names_int.index("S"), names_int.index("C01")] = -1.0  # C10 = S - C01
    cov = G @ cov_int @ G.T
    user_names = prob.nonlin + prob.lin
    values = prob.to_user(nl_best, lin)
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(sd, sd)
    flags = []
    for i in range(len(user_names)):
        for j in range(i + 1, len(user_names)):
            if np.isfinite(corr[i, j]) and abs(corr[i, j]) > corr_flag:
                flags.append(f"{_label(user_names[i])} and {_label(user_names[j])} are poorly identifiable together "
                             f"(correlation {corr[i, j]:+.3f}): their combination is determined, not each one")
    for i, p in enumerate(names_int):
        if at_bound[i]:
            flags.append(f"{'C10 + C01' if p == 'S' else p} is at a bound of its range; its standard error is not "
                         "meaningful")
    return _Uncertainty(values, user_names, sd, corr, flags, rho, nfev)


def _result(processed, actuator, model, prob, bnd, unc: _Uncertainty, tension, hysteresis, converged, message,
            nfev, time_s, order, eq19_factor) -> FitResult:
    """Stage 5: the fitted actuator, its parameters, the metrics and the loop."""
    flags = list(unc.flags)
    fitted = prob.actuator(unc.values)
    fitted = fitted.replace(name=f"{actuator.name or actuator.kind} [fitted, {model.replace('_', '-')} model]",
                            model=model)
    params = {}
    for n in _ORDER:
        field_, unit = PARAMETERS[n]
        val = float(getattr(fitted, field_))
        if n in unc.names:
            i = unc.names.index(n)
            se = float(unc.sd[i]) if np.isfinite(unc.sd[i]) else None
            start = PAPER_START.get(n, float(getattr(actuator, field_))) if tension is None else \
                {"C10": tension.C10_kpa, "C01": tension.C01_kpa}.get(n, float(getattr(actuator, field_)))
            params[n] = Parameter(n, field_, unit, val, se, bnd[n][0], bnd[n][1], True, start)
        elif n in ("alpha0", "C10", "C01", "P_start"):
            params[n] = Parameter(n, field_, unit, val, None, bnd[n][0], bnd[n][1], False, val)
    metrics = score(processed, fitted, model, order=order, eq19_factor=eq19_factor)
    if metrics.no_equilibrium_kpa:
        flags.append("no free-bending equilibrium in the fitted model at " +
                     ", ".join(f"{p:g}" for p in metrics.no_equilibrium_kpa) + " kPa (fold); "
                     "those pressures are left out of the free-curvature metric")
    hyst = None
    if hysteresis is not None:
        hp = {}
        for n in ("a0", "a1", "theta_h"):
            i = unc.names.index(n)
            field_, unit = HYST_PARAMETERS[n]
            hp[n] = Parameter(n, field_, unit, float(unc.values[n]),
                              float(unc.sd[i]) if np.isfinite(unc.sd[i]) else None, bnd[n][0], bnd[n][1], True,
                              math.nan)
        hyst = HysteresisFit(hysteresis, "linear", hp, [], math.nan)
        loop = hyst.loop()
        hyst.energy_loss_ratio = [LossRatio(**e) for e in predicted_loss_ratios(
            processed, fitted, loop, model, order=order, eq19_factor=eq19_factor)]
        hyst.nrmse_branches = branch_nrmse(processed, fitted, loop, model, order=order, eq19_factor=eq19_factor)
    return FitResult(
        model=model, actuator=fitted, parameters=params, correlation=unc.corr, correlation_names=unc.names,
        metrics=metrics, converged=converged, message=message, nfev=nfev, time_s=time_s,
        flags=flags, autocorrelation=unc.rho, hysteresis=hyst,
    )


def predicted_loss_ratios(processed, actuator: Actuator, loop, model: str = "energy", *, order: int = 32,
                          eq19_factor: bool = True) -> list[dict]:
    """Energy-loss ratio of each test, measured (processing) and predicted (loop model on the same range)."""
    from .hysteresis import loop_branches, loss_ratio

    out = []
    for r in processed.results:
        kf = float(r.free_curvature[0])
        k = np.linspace(0.0, kf, 400)
        up, low = loop_branches(actuator, loop, r.pressure_kpa, kf, k, model, order=order, eq19_factor=eq19_factor)
        out.append({"pressure_kpa": float(r.pressure_kpa), "measured": float(r.energy_loss_ratio),
                    "predicted": loss_ratio(k, up, low, actuator.L0_mm)[0]})
    return out


def branch_nrmse(processed, actuator: Actuator, loop, model: str = "energy", *, order: int = 32,
                 eq19_factor: bool = True) -> float:
    """eq-53-style NRMSE of both branches (loading and unloading) against the loop model."""
    from .hysteresis import loop_branches

    num = den = 0.0
    for r in processed.results:
        kf = float(r.free_curvature[0])
        up, low = loop_branches(actuator, loop, r.pressure_kpa, kf, r.curvature_grid, model, order=order,
                                eq19_factor=eq19_factor)
        rm = math.sqrt(float(np.mean(np.concatenate([(up - r.mean_loading) ** 2, (low - r.mean_unloading) ** 2]))))
        num += (rm / float(r.blocked_moment[0])) ** 2 * kf
        den += kf
    return math.sqrt(num / den)
