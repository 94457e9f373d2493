"""Parameter identification from processed cyclic tests (paper section 3.4, eq 53-55, Table 3).

:func:`fit` identifies any subset of alpha0, C10, C01, P_start, E_f and R0_start for either model
from all pressures at once, by default together with the actuator's friction loop.

Data and model (hysteresis-aware by default)
    When the tests show a loop (median energy-loss ratio above :data:`LOOP_THRESHOLD`,
    :func:`has_loop`), both mean branches of every pressure are fitted with the loop model of
    :mod:`bendpam.physics.hysteresis`::

        M = M_qs(P, k') - (a0 + a1 P_active) z                                   (N*mm)

    on the steady cycle between the blocked state and the test's measured free curvature (the path
    the machine drove).  Fitting the average of the two branches instead (``hysteresis=None``, the
    paper's way) lets the loop bias alpha0: near each reversal a rounded loop closes and the
    average of its branches leans to one side.  Without a loop the hysteresis-free mean curves are
    fitted (where the loop is developed, ``fit_range``).

Objective
    Weighted least squares whose sum of squares *is* the paper's cycle metric (eq 53)::

        r_ij = sqrt(K_i / sum K) / (M_max,i sqrt(n_i)) * (M_model(P_i, k_ij) - M_data,ij)

    with ``K_i`` the test's free curvature, ``M_max,i`` its blocked moment and ``n_i`` its points
    (both branches count with a loop).  Data are magnitudes; the model is evaluated on the
    actuator's bending side (``k' = bend_sign * |k|``).

Admissible material by construction
    The bladder is parametrised by its initial shear modulus ``mu = 2 (C10 + C01) > 0`` and its
    shape ``beta = C01 / (C10 + C01)`` (:mod:`bendpam.physics.material`), confined to the admissible
    interval ``[beta_lo, beta_hi]`` of :func:`~bendpam.physics.material.admissible_shape_range`: strain
    energy >= 0, monotone uniaxial stress and Baker-Ericksen over the bladder's stretches at the
    tested curvatures (eq 17, with a 10 % margin), the tension test's if one is given, and
    ``admissible_range`` (the range it will be asked to predict; default 0.6 to 1.6).  With both
    constants free the solver works with the weights ``(S_lo, S_hi) >= 0`` of the two bounding
    shapes, ``C10 + C01 = S_lo + S_hi`` and ``C01 = beta_lo S_lo + beta_hi S_hi``: box bounds, so
    the linear solve stays exact.  The fit says in words which combinations the data determine
    (``FitResult.identifiability``): ``mu`` nearly always, the shape only when its 95 % interval
    covers at most half of the admissible width (as ``bendpam fit-material``).

Method (variable projection)
    Both models are linear in C10, C01, E_f, P_start and the loop's a0, a1 for fixed kinematics
    (``M = (P - P_start) A(k') - E_f I_f k' - C10 b10(k') - C01 b01(k')``), and the kinematics
    depend only on alpha0 and R0_start (the loop's shape only on its angle ``theta_h``).  For every
    trial of those the linear parameters are solved exactly by bounded linear least squares.  The
    kinematics are sampled on 32 Chebyshev nodes of the tested curvature range and interpolated
    (checked against direct evaluation; exact to round-off on these smooth functions).

    1. Global stage: a grid over the nonlinear parameters (alpha0 across its bounds, R0_start,
       the loop angle on a geometric grid), so the answer does not depend on a lucky start.
    2. Local stage: ``scipy.optimize.least_squares`` (trust-region reflective, bounds) on the
       projected problem from the best grid point.

Folds
    A fitted model whose free-bending branch ends (fold) below the highest tested pressure is
    rejected: the shape is scanned over the admissible interval and the best fold-free material
    kept, with a note; if none exists the fit is flagged as unable to describe the data.

Uncertainty
    1. Statistical: a sandwich covariance ``B^-1 (sum_g s_g^2 f_g J_g^T J_g) B^-1``,
       ``B = J^T J``, with each curve (each branch with a loop) ``g`` its own residual variance
       ``s_g^2`` and an inflation ``f_g = (1 + rho_g) / (1 - rho_g)`` for the lag-1
       autocorrelation of its residuals.
    2. Systematic (the loop law): no law is known to be the actuator's.  The fit is repeated with
       the other law bendpam offers (Prandtl-Ishlinskii <-> Dahl, warm-started); the shift
       ``delta`` of the model parameters between the two is a model-form error, taken as
       uniformly distributed over ``[0, delta]``: ``delta delta^T / 3`` is added to the covariance
       (standard error ``|delta| / sqrt 3`` per parameter, fully correlated).  On data made with
       an independent (Bouc-Wen) loop law this makes the 2-SE intervals cover the truth
       (tests/test_identify_loops.py).
    3. The profile of alpha0 (the objective minimised over everything else, against alpha0) is
       kept in ``FitResult.alpha0_profile``.
    Pairs with ``|corr| > corr_flag`` are flagged, with the combination the data determine and
    their joint 95 % region (``FitResult.joint_intervals``).

Joint fit with a tension test (``tension_data``)
    The bladder's uniaxial nominal stress ``2 C10 (l - l^-2) + 2 C01 (l - l^-2)/l`` is linear in
    the constants, so its points join the linear solve as more rows.  The two data sets are
    weighted by their own noise: each is first fitted alone (the bending curves by the stages
    above, the tension test by :func:`bendpam.identify.tension.fit_tension`), and the tension rows are
    scaled by ``s_bend / s_tension`` (the residual standard deviations), so the objective is
    ``SSR_bend / s_bend^2 + SSR_tension / s_tension^2``: one Gaussian likelihood.

Bounds: alpha0 within +-10 % of its nominal value (as in the paper) and on the actuator's side of
54.74 deg; C10 and C01 by the admissible cone (a single free constant within [-5000, 5000] kPa and
the cone); P_start in [0, 0.98 min(P_i)]; E_f in [0.1, 10] x nominal; R0_start in [R0, 1.5 R0];
the loop's a0 in [0, 10 max BM] N*mm, a1 in [0, 100] N*mm/kPa, theta_h in [0.2, 90] deg.  Any
bound can be overridden (``bounds={"shape": (lo, hi)}`` narrows the admissible shapes).
"""

from __future__ import annotations

import json
import math
import time
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from bendpam.errors import FileFormatError, FitError, InputError
from bendpam.infra.atomic import atomic_write_text, json_safe
from bendpam.physics.actuator import NEUTRAL_ANGLE_DEG, Actuator
from bendpam.physics.braid import DEFAULT_ORDER
from bendpam.physics.law import MomentLaw
from bendpam.physics.material import admissible_shape_range
from bendpam.physics.models import normalise_model

__all__ = [
    "HYST_PARAMETERS",
    "LOOP_THRESHOLD",
    "PARAMETERS",
    "Band",
    "ExtrapolationWarning",
    "FitResult",
    "HysteresisFit",
    "JointInterval",
    "LossRatio",
    "MaterialFit",
    "Metrics",
    "Parameter",
    "Profile",
    "bladder_stretch_range",
    "branch_nrmse",
    "developed_range",
    "fit",
    "has_loop",
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
#: The tests "show a loop" when their median energy-loss ratio exceeds this (1 %).
LOOP_THRESHOLD = 0.01
#: Loop angles (deg) of the global grid.
_THETA_GRID = np.geomspace(0.5, 40.0, 9)
#: Chebyshev nodes on which the kinematics are sampled (then interpolated to the data).
_CHEB_NODES = 32
#: The 95 % quantile of chi-square with 2 degrees of freedom (joint regions of pairs).
_CHI2_2_95 = 5.991464547107979
_Z95 = 1.959963984540054
#: The shape counts as identified when its 95 % interval spans at most this fraction of the admissible width.
_SHAPE_RESOLVED = 0.5
#: Stretch margin over the tested curvatures for the admissible shapes.
_STRETCH_MARGIN = 1.1


class ExtrapolationWarning(UserWarning):
    """A prediction outside the pressures the fit was identified on."""


def parse_free(free) -> list[str]:
    """Normalise a list (or comma string) of parameter names; unknown names raise InputError.

    >>> parse_free("c01, alpha0_deg")
    ['alpha0', 'C01']
    """
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
    """Paper metrics (eq 53-55) and plain RMSEs of a model against processed data.

    ``curves`` says what the model curves were: ``"mean curves"`` (the quasi-static model against
    the average of the branches, as the paper) or ``"loop"`` (the model with its loop against both
    branches; blocked moment and free curvature of the predicted cycle).
    """

    nrmse_cycles: float
    nrmse_blocked_moment: float
    nrmse_free_curvature: float
    rmse_cycles: float
    rmse_blocked_moment: float
    rmse_free_curvature: float
    per_pressure: list[dict]
    no_equilibrium_kpa: list[float]
    curves: str = "mean curves"

    def to_dict(self) -> dict:
        return {
            "nrmse": {"cycles": self.nrmse_cycles, "blocked_moment": self.nrmse_blocked_moment,
                      "free_curvature": self.nrmse_free_curvature},
            "rmse": {"cycles_nmm": self.rmse_cycles, "blocked_moment_nmm": self.rmse_blocked_moment,
                     "free_curvature_per_mm": self.rmse_free_curvature},
            "per_pressure": self.per_pressure,
            "no_equilibrium_kpa": self.no_equilibrium_kpa,
            "metrics_curves": self.curves,
        }


HYST_PARAMETERS = {"theta_h": ("theta_h_deg", "deg"), "a0": ("a0_nmm", "N*mm"), "a1": ("a1_nmm_per_kpa", "N*mm/kPa")}


def _label(name: str) -> str:
    return (PARAMETERS.get(name) or HYST_PARAMETERS[name])[0]


def _unit(name: str) -> str:
    return (PARAMETERS.get(name) or HYST_PARAMETERS[name])[1]


@dataclass
class MaterialFit:
    """The bladder as identified: initial shear modulus and shape (kPa; see :mod:`bendpam.physics.material`).

    Attributes
    ----------
    shear_modulus_kpa, se_shear_modulus_kpa : ``mu = 2 (C10 + C01)`` and its standard error, kPa.
    shape, se_shape : ``beta = C01 / (C10 + C01)`` and its standard error.
    shape_bounds : the admissible shapes the fit was confined to.
    stretch_range : the principal stretches they hold over (data, tension test, prediction range).
    shape_at_bound : True when the shape sits on an admissibility bound (set by the rule, not the data).
    shape_identified : True when the data determine the shape (95 % interval within half the width).
    shape_held : the reason the shape was held fixed (a fold, the free list), or "".
    """

    shear_modulus_kpa: float
    se_shear_modulus_kpa: float | None
    shape: float
    se_shape: float | None
    shape_bounds: tuple[float, float]
    stretch_range: tuple[float, float]
    shape_at_bound: bool
    shape_identified: bool
    shape_held: str = ""

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> MaterialFit:
        return cls(_num(d["shear_modulus_kpa"]), _opt(d.get("se_shear_modulus_kpa")), _num(d["shape"]),
                   _opt(d.get("se_shape")), _pair(d["shape_bounds"]), _pair(d["stretch_range"]),
                   bool(d["shape_at_bound"]), bool(d["shape_identified"]), str(d.get("shape_held", "")))


@dataclass
class Profile:
    """The profile of alpha0: the fit objective minimised over every other parameter, against alpha0.

    ``objective`` is the weighted sum of squares (eq 53 scale: NRMSE^2 of the fitted curves);
    ``interval_deg`` the reported alpha0 +- 2 standard errors (statistical and systematic).
    """

    alpha0_deg: list[float]
    objective: list[float]
    interval_deg: tuple[float, float]

    def to_dict(self) -> dict:
        return {"alpha0_deg": self.alpha0_deg, "objective": self.objective, "interval_deg": self.interval_deg}

    @classmethod
    def from_dict(cls, d: dict) -> Profile:
        return cls([float(x) for x in d["alpha0_deg"]], [_num(x) for x in d["objective"]], _pair(d["interval_deg"]))


@dataclass
class JointInterval:
    """Two strongly correlated parameters: what the data determine of them.

    ``first + coefficient * second = value +- stderr`` is their best-determined combination;
    ``box`` the extent of their joint 95 % region (``{field: (lo, hi)}``); ``text`` a sentence.
    """

    names: tuple[str, str]
    correlation: float
    coefficient: float
    value: float
    stderr: float
    box: dict[str, tuple[float, float]]
    text: str

    def to_dict(self) -> dict:
        return {"names": list(self.names), "correlation": self.correlation, "coefficient": self.coefficient,
                "value": self.value, "stderr": self.stderr, "box": {k: list(v) for k, v in self.box.items()},
                "text": self.text}

    @classmethod
    def from_dict(cls, d: dict) -> JointInterval:
        return cls((str(d["names"][0]), str(d["names"][1])), _num(d["correlation"]), _num(d["coefficient"]),
                   _num(d["value"]), _num(d["stderr"]), {k: _pair(v) for k, v in d["box"].items()}, str(d["text"]))


@dataclass(frozen=True)
class Band:
    """A prediction with its uncertainty band (``value -+ level * SE``; NaN where none exists)."""

    quantity: str
    unit: str
    pressure_kpa: np.ndarray
    value: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    extrapolated: np.ndarray  # bool: outside the tested pressures


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

    def thin(self, step: int) -> _Data:
        """Every ``step``-th point (weights scaled so the objective keeps its scale): for the grid stage."""
        keep = np.arange(self.kc.size) % step == 0
        opt = {n: None if getattr(self, n) is None else getattr(self, n)[keep] for n in ("branch", "delta", "span")}
        return _Data(self.P, self.k, self.M, self.BM, self.BM_se, self.K, self.K_se,
                     self.w[keep] * math.sqrt(self.kc.size / keep.sum()), self.kc[keep], self.Mc[keep], self.Pc[keep],
                     self.seg[keep], **opt)

    @property
    def group(self) -> np.ndarray:
        """Residual groups of the uncertainty: one per curve (per branch with a loop)."""
        return self.seg if self.branch is None else 2 * self.seg + (self.branch < 0)


def has_loop(processed, threshold: float = LOOP_THRESHOLD) -> bool:
    """Whether the processed tests show a hysteresis loop: median energy-loss ratio above ``threshold``.

    >>> from types import SimpleNamespace as NS
    >>> has_loop(NS(results=[NS(energy_loss_ratio=0.2), NS(energy_loss_ratio=0.18)]))
    True
    """
    ratios = np.array([float(r.energy_loss_ratio) for r in processed.results], dtype=float)
    ratios = ratios[np.isfinite(ratios)]
    return bool(ratios.size and float(np.median(ratios)) > threshold)


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
    from bendpam.physics.braid import radius_terms

    p = actuator.params
    k = (actuator.bend_sign or 1) * np.abs(np.atleast_1d(np.asarray(curvature_per_mm, dtype=float)))
    u, R, _ = radius_terms(k, float(p.alpha0), float(p.R0_start))
    lam1 = 1.0 + 2.0 * u
    lam2 = R / float(p.R0_start)
    allv = np.concatenate([lam1, lam2, [1.0]])
    return float(np.min(allv)), float(np.max(allv))


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


def _cheb(x: np.ndarray, hi: float, n: int = _CHEB_NODES) -> tuple[np.ndarray, np.ndarray]:
    """Chebyshev nodes on ``[0, hi]`` and the barycentric matrix interpolating from them to ``x``."""
    j = np.arange(n)
    t = np.cos(np.pi * (j + 0.5) / n)
    nodes = 0.5 * hi * (t + 1.0)
    wts = (-1.0) ** j * np.sin(np.pi * (j + 0.5) / n)
    diff = x[:, None] - nodes[None, :]
    hit = diff == 0.0
    diff[hit] = 1.0
    W = wts / diff
    W /= W.sum(axis=1, keepdims=True)
    rows = hit.any(axis=1)
    if rows.any():
        W[rows] = hit[rows].astype(float)
    return nodes, W


def _halfline(a: float, b: float) -> tuple[float, float]:
    """The ``x`` with ``a x >= b``."""
    if a > 0:
        return b / a, math.inf
    if a < 0:
        return -math.inf, b / a
    return (-math.inf, math.inf) if b <= 0 else (math.inf, -math.inf)


def _small_lstsq(R: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.linalg.lstsq(R, b, rcond=None)[0] if R.shape[1] else np.zeros(0)


def _bounded_lstsq(A: np.ndarray, y: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``min |A x - y|`` with ``lo <= x <= hi`` (A tall, few columns).

    One QR of ``[A | y]`` reduces the problem to ``min |R x - b|`` with ``R`` square; that is solved
    exactly by a primal active-set method (variables at a bound are fixed, released when their
    multiplier has the wrong sign; a step that leaves the box stops at the first bound), the
    method of Stark and Parker's BVLS on the small system.  ``scipy.optimize.lsq_linear`` is the
    fallback should the iteration not settle.
    """
    p = A.shape[1]
    if p == 0:
        return np.zeros(0)
    sc = np.sqrt(np.einsum("ij,ij->j", A, A))
    sc[~(sc > 0)] = 1.0
    H = (A.T @ A) / np.outer(sc, sc)
    try:
        L = np.linalg.cholesky(H)
    except np.linalg.LinAlgError:
        L = None
    if L is not None and np.all(np.abs(np.diag(L)) > 1e-7):
        # columns scaled to unit norm: H = L L^T is well conditioned enough for the normal equations
        R, b = L.T, np.linalg.solve(L, (A.T @ y) / sc)
    else:
        Rb = np.asarray(np.linalg.qr(np.column_stack([A / sc, y]), mode="r"))
        R, b = Rb[:p, :p], Rb[:p, p]
    lo, hi = lo * sc, hi * sc
    x = _small_lstsq(R, b)
    if np.all(x >= lo) and np.all(x <= hi):
        return x / sc
    x = np.clip(x, lo, hi)
    fixed = (x <= lo) | (x >= hi)
    for _ in range(8 * p + 10):
        f = ~fixed
        z = x.copy()
        z[f] = _small_lstsq(R[:, f], b - R[:, ~f] @ x[~f])
        if np.all(z[f] >= lo[f]) and np.all(z[f] <= hi[f]):
            x = z
            g = R.T @ (R @ x - b)  # gradient of |R x - b|^2 / 2
            tol = 1e-12 * float(np.abs(R.T @ b).max() + 1e-300)
            bad = fixed & (((x <= lo) & (g < -tol)) | ((x >= hi) & (g > tol)))
            if not bad.any():
                return x / sc
            i = int(np.argmax(np.where(bad, np.abs(g), -1.0)))
            fixed[i] = False
            continue
        # step toward z until the first free variable meets a bound
        dz = z - x
        with np.errstate(divide="ignore", invalid="ignore"):
            t_lo = np.where(f & (z < lo), (lo - x) / dz, np.inf)
            t_hi = np.where(f & (z > hi), (hi - x) / dz, np.inf)
        t = np.minimum(t_lo, t_hi)
        i = int(np.argmin(t))
        step = float(np.clip(t[i], 0.0, 1.0))
        x = np.clip(x + step * dz, lo, hi)
        x[i] = lo[i] if t_lo[i] <= t_hi[i] else hi[i]
        fixed[i] = True
    from scipy.optimize import lsq_linear

    return lsq_linear(A, y, bounds=(lo, hi), method="bvls").x


@dataclass
class _Tension:
    """Tension-test rows of a joint fit: stretches, nominal stresses (kPa) and their weight."""

    stretch: np.ndarray
    stress_kpa: np.ndarray
    weight: float


class _Problem:
    """Residuals of the weighted problem for a given set of free parameters (variable projection)."""

    def __init__(self, actuator: Actuator, data: _Data, model: str, free: list[str], bounds, order: int,
                 eq19_factor: bool, law: str | None, shape_bounds: tuple[float, float], *,
                 shape_fixed: float | None = None, tension: _Tension | None = None):
        self.base = actuator
        self.d = data
        self.model = model
        self.order = order
        self.eq19 = eq19_factor
        self.law = law
        self.bounds = bounds
        self.shape_bounds = shape_bounds
        self.shape_fixed = shape_fixed
        self.tension = tension
        self.sign = actuator.bend_sign or 1
        self.free = [*free, "theta_h", "a0", "a1"] if law else list(free)
        self.nonlin = [p for p in self.free if p in _NONLINEAR or p == "theta_h"]
        self.lin = [p for p in self.free if p not in self.nonlin]
        self.cone = "C10" in self.lin and "C01" in self.lin
        self.int_names, self.T, self.lo, self.hi = self._internal()
        w, y, grp = data.w, data.Mc, data.group
        if tension is not None:
            n = tension.stretch.size
            w = np.concatenate([w, np.full(n, tension.weight)])
            y = np.concatenate([y, tension.stress_kpa])
            grp = np.concatenate([grp, np.full(n, int(grp.max()) + 1)])
        self.w, self.y, self.groups = w, y, grp
        self.W: np.ndarray | None
        self.nodes, self.W = _cheb(data.kc, float(data.kc.max()) or 1e-9)
        self._qs_cache: dict = {}
        self._z_cache: dict = {}
        if not self._interpolation_ok():
            self.W = None

    # -- linear parameters: internal coordinates -> user values (user = T @ internal) ---------
    def _internal(self):
        blocks = []  # (internal name, {user name: coefficient}, lo, hi)
        hiS = max(self.bounds["C10"][1] + self.bounds["C01"][1], 1.0)
        for p in self.lin:
            if p == "C01" and self.cone:
                continue
            if p == "C10" and self.cone:
                if self.shape_fixed is not None:
                    b = self.shape_fixed
                    blocks.append(("S", {"C10": 1.0 - b, "C01": b}, 0.0, hiS))
                else:
                    b_lo, b_hi = self.shape_bounds
                    blocks.append(("S_lo", {"C10": 1.0 - b_lo, "C01": b_lo}, 0.0, hiS))
                    blocks.append(("S_hi", {"C10": 1.0 - b_hi, "C01": b_hi}, 0.0, hiS))
            elif p in ("C10", "C01"):
                blocks.append((p, {p: 1.0}, *self._single_constant_bounds(p)))
            else:
                blocks.append((p, {p: 1.0}, *self.bounds[p]))
        T = np.zeros((len(self.lin), len(blocks)))
        for j, (_, coef, _, _) in enumerate(blocks):
            for name, c in coef.items():
                T[self.lin.index(name), j] = c
        return [b[0] for b in blocks], T, np.array([b[2] for b in blocks]), np.array([b[3] for b in blocks])

    def _single_constant_bounds(self, p: str) -> tuple[float, float]:
        """Bounds of one free constant with the other fixed: its box, C10 + C01 >= 1 kPa, the cone."""
        b_lo, b_hi = self.shape_bounds if self.shape_fixed is None else (self.shape_fixed, self.shape_fixed)
        other = "C01" if p == "C10" else "C10"
        c = float(getattr(self.base, PARAMETERS[other][0]))
        if p == "C10":  # x = C10: C01 - b_lo S >= 0, b_hi S - C01 >= 0
            conds = [(-b_lo, -(1.0 - b_lo) * c), (b_hi, -(b_hi - 1.0) * c), (1.0, 1.0 - c)]
        else:  # x = C01
            conds = [(1.0 - b_lo, b_lo * c), (b_hi - 1.0, -b_hi * c), (1.0, 1.0 - c)]
        lo, hi = self.bounds[p]
        for a, b in conds:
            l_, h_ = _halfline(a, b)
            lo, hi = max(lo, l_), min(hi, h_)
        if not lo <= hi:
            raise InputError(
                f"with {PARAMETERS[other][0]} = {c:g} kPa held fixed no {PARAMETERS[p][0]} gives an admissible "
                f"material (shape C01/(C10 + C01) in [{b_lo:.4g}, {b_hi:.4g}]); free both constants")
        return lo, hi

    def actuator(self, values: dict[str, float]) -> Actuator:
        ch = {PARAMETERS[p][0]: v for p, v in values.items() if p in PARAMETERS}
        return self.base.replace(**ch)

    # -- the model's columns --------------------------------------------------------------------
    def _interpolation_ok(self) -> bool:
        if self.W is None or self.d.kc.size <= 3 * _CHEB_NODES:
            return False
        law = MomentLaw(self.base, self.model, eq19_factor=self.eq19, order=self.order)
        k = float(self.d.kc.max()) * np.array([1.0, 0.37, 0.81])
        idx = [int(np.argmin(np.abs(self.d.kc - x))) for x in k]
        nodes = np.column_stack(law.basis(self.sign * self.nodes))
        approx = self.W[idx] @ nodes
        exact = np.column_stack(law.basis(self.sign * self.d.kc[idx]))
        scale = np.maximum(np.abs(exact).max(axis=0), 1e-300)
        return bool(np.all(np.abs(approx - exact) <= 1e-9 * scale))

    def _qs(self, nl: dict[str, float]):
        """The actuator and ``(A, b10, b01)`` (per kPa) at the data's curvatures for the kinematics in ``nl``."""
        key = tuple(sorted((p, float(v)) for p, v in nl.items() if p in PARAMETERS))
        hit = self._qs_cache.get(key)
        if hit is None:
            if len(self._qs_cache) > 256:
                self._qs_cache.clear()
            a = self.base.replace(**{PARAMETERS[p][0]: v for p, v in key})
            law = MomentLaw(a, self.model, eq19_factor=self.eq19, order=self.order)
            if self.W is not None:
                cols = self.W @ np.column_stack(law.basis(self.sign * self.nodes))
                hit = (a, cols[:, 0], cols[:, 1], cols[:, 2])
            else:
                hit = (a, *law.basis(self.sign * self.d.kc))
            self._qs_cache[key] = hit
        return hit

    def _z(self, theta_deg: float) -> np.ndarray:
        z = self._z_cache.get(theta_deg)
        if z is None:
            from bendpam.physics.hysteresis import make_law

            if len(self._z_cache) > 256:
                self._z_cache.clear()
            assert self.law is not None and self.d.branch is not None, "a loop fit is built on branch data"
            z_away, z_back = make_law(self.law, theta_deg).steady_branches(self.d.delta, self.d.span)
            z = np.where(self.d.branch < 0, z_away, z_back)  # unloading leaves the blocked state
            self._z_cache[theta_deg] = z
        return z

    def design(self, nl: dict[str, float]):
        """Fixed part ``c0`` and columns ``X`` (per internal linear unit) of every row of the model."""
        a, A, b10, b01 = self._qs(nl)
        s, d = self.sign, self.d
        cols = {"C10": -s * b10, "C01": -s * b01, "P_start": -s * A, "E_f": -a.frame_inertia_mm4 * d.kc}
        c0 = s * d.Pc * A
        fixed = {"C10": a.C10_kpa, "C01": a.C01_kpa, "P_start": a.P_start_kpa, "E_f": a.frame_modulus_mpa}
        for p, col in cols.items():
            if p not in self.lin:
                c0 = c0 + col * fixed[p]
        if self.law:
            z = self._z(float(nl["theta_h"]))
            cols["a0"] = -z
            cols["a1"] = -z * np.maximum(d.Pc - a.P_start_kpa, 0.0)
        X = np.column_stack([cols[p] for p in self.lin]) if self.lin else np.zeros((c0.size, 0))
        if self.tension is not None:
            lam = self.tension.stretch
            g1 = lam - lam**-2
            tcols = {"C10": 2.0 * g1, "C01": 2.0 * g1 / lam}
            ct = np.zeros(lam.size)
            for p, col in tcols.items():
                if p not in self.lin:
                    ct = ct + col * fixed[p]
            Xt = np.column_stack([tcols.get(p, np.zeros(lam.size)) for p in self.lin])
            c0 = np.concatenate([c0, ct])
            X = np.vstack([X, Xt])
        return c0, X @ self.T

    def to_user(self, nl: dict[str, float], lin_int: np.ndarray) -> dict[str, float]:
        out = {p: float(v) for p, v in nl.items()}
        out.update({p: float(v) for p, v in zip(self.lin, self.T @ lin_int, strict=True)})
        return out

    def project(self, nl: dict[str, float]):
        """Best linear parameters for the nonlinear ones; returns (weighted residuals, internal linear values)."""
        c0, X = self.design(nl)
        Aw = self.w[:, None] * X
        yw = self.w * (self.y - c0)
        x = _bounded_lstsq(Aw, yw, self.lo, self.hi)
        return Aw @ x - yw, x

    def residual_full(self, x_int: np.ndarray) -> np.ndarray:
        nl = dict(zip(self.nonlin, x_int[: len(self.nonlin)], strict=True))
        c0, X = self.design(nl)
        return self.w * (c0 + X @ x_int[len(self.nonlin):] - self.y)


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
    """Energy-loss ratio of one test: measured (processing) and predicted (the fitted loop's free cycle)."""

    pressure_kpa: float
    measured: float
    predicted: float


@dataclass
class HysteresisFit:
    """The loop part of a fit: parameters, loss ratios, branch NRMSE, and the law's systematic shift.

    ``energy_loss_ratio`` holds, per test, the measured ratio and the one of the predicted free cycle
    (:func:`bendpam.physics.hysteresis.predict_cycles`, the computation of ``bendpam predict --cycle``).
    ``law_shift`` is the change of each model parameter when the other law is fitted instead
    (``{field: shift}``, empty when not computed), ``alternative_law`` that law.
    """

    law: str
    amplitude: str
    parameters: dict[str, Parameter]
    energy_loss_ratio: list[LossRatio]
    nrmse_branches: float
    alternative_law: str = ""
    law_shift: dict[str, float] = field(default_factory=dict)

    def loop(self):
        """The fitted :class:`bendpam.physics.hysteresis.LoopModel`."""
        from bendpam.physics.hysteresis import LoopModel

        return LoopModel(law=self.law, amplitude=self.amplitude,
                         **{p.field: p.value for p in self.parameters.values()})

    def to_dict(self) -> dict:
        return {"law": self.law, "amplitude": self.amplitude,
                "parameters": {p.field: p.to_dict() for p in self.parameters.values()},
                "energy_loss_ratio": [asdict(e) for e in self.energy_loss_ratio],
                "nrmse_branches": self.nrmse_branches,
                "alternative_law": self.alternative_law, "law_shift": self.law_shift}

    @classmethod
    def from_dict(cls, d: dict) -> HysteresisFit:
        names = {v[0]: k for k, v in HYST_PARAMETERS.items()}
        params = {names[f]: Parameter.from_dict(names[f], f, v) for f, v in d["parameters"].items()}
        return cls(d["law"], d.get("amplitude", "linear"), params,
                   [LossRatio(**e) for e in d.get("energy_loss_ratio", [])], _num(d.get("nrmse_branches")),
                   str(d.get("alternative_law", "")), {k: _num(v) for k, v in d.get("law_shift", {}).items()})


@dataclass
class FitResult:
    """Result of :func:`fit`: a value you can print, predict with, plot, save and load.

    Attributes
    ----------
    model : the model fitted (``"energy"`` or ``"force_balance"``).
    actuator : the fitted :class:`~bendpam.Actuator` (usable by every command).
    parameters : short name -> :class:`Parameter` (value, standard error, bounds, vary flag, unit).
    correlation, correlation_names : correlation matrix of the varied parameters.
    metrics : :class:`Metrics` (eq 53-55), against the model the fit used (with its loop if any).
    converged, message, nfev, time_s : about the search.
    flags : plain-language warnings (poorly identifiable pairs, parameters at a bound, folds).
    autocorrelation : mean lag-1 autocorrelation of the residuals (used in the standard errors).
    hysteresis : :class:`HysteresisFit` or None.
    material : :class:`MaterialFit` (shear modulus and shape) or None when neither constant varied.
    identifiability : sentences: which parameters and combinations the data determine.
    alpha0_profile : :class:`Profile` of alpha0 or None.
    joint_intervals : :class:`JointInterval` of each strongly correlated pair.
    covariance : covariance matrix of the varied parameters (``correlation_names`` order; statistical
        plus systematic), in their units.
    pressure_range_kpa : the tested pressures' range (predictions outside it are extrapolations).
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
    material: MaterialFit | None = None
    identifiability: list[str] = field(default_factory=list)
    alpha0_profile: Profile | None = None
    joint_intervals: list[JointInterval] = field(default_factory=list)
    covariance: np.ndarray | None = None
    pressure_range_kpa: tuple[float, float] = (math.nan, math.nan)

    @property
    def loop(self):
        """The fitted loop (:class:`bendpam.physics.hysteresis.LoopModel`) or None."""
        return None if self.hysteresis is None else self.hysteresis.loop()

    def _warn_outside(self, pressure_kpa) -> np.ndarray:
        P = np.asarray(pressure_kpa, dtype=float)
        lo, hi = self.pressure_range_kpa
        out = np.zeros(P.shape, dtype=bool)
        if math.isfinite(lo) and math.isfinite(hi):
            out = (P < lo) | (P > hi)
            if np.any(out):
                bad = P[out]
                warnings.warn(
                    f"pressure {float(bad.flat[0]):g} kPa is outside the tested range [{lo:g}, {hi:g}] kPa: the "
                    "prediction is an extrapolation (FitResult.band gives its uncertainty)",
                    ExtrapolationWarning, stacklevel=3)
        return out

    def predict(self, pressure_kpa, curvature_per_mm) -> np.ndarray:
        """The fitted model's quasi-static moment ``M(P, k')`` (N*mm), broadcasting (signed as the paper).

        Pressures outside the tested range raise an :class:`ExtrapolationWarning`.
        """
        self._warn_outside(pressure_kpa)
        return MomentLaw.of(self.actuator, self.model).moment(pressure_kpa, curvature_per_mm)

    def band(self, pressure_kpa, quantity: str = "free_curvature", curvature_per_mm: float = 0.0,
             level: float = 2.0) -> Band:
        """A prediction and its band ``value -+ level * SE`` from the parameters' covariance.

        Parameters
        ----------
        pressure_kpa : pressures, kPa (1-D).
        quantity : ``"free_curvature"`` (magnitude, 1/mm), ``"blocked_moment"`` (magnitude, N*mm)
            or ``"moment"`` (magnitude at ``curvature_per_mm`` along the bending direction, N*mm);
            of the quasi-static model (what ``bendpam predict`` gives).
        level : multiples of the standard error (2: the reported intervals).

        Returns
        -------
        :class:`Band`; ``extrapolated`` marks pressures outside the tested range.  The standard error
        is propagated to first order (central differences of the quantity in each varied
        parameter); NaN where the model or a perturbed one has no answer (above a fold).
        """
        from bendpam.validate import pressure_kpa as check_pressure

        P = np.atleast_1d(check_pressure(pressure_kpa)).astype(float).ravel()
        units = {"free_curvature": "1/mm", "blocked_moment": "N*mm", "moment": "N*mm"}
        if quantity not in units:
            raise InputError(f"quantity = {quantity!r}; choose one of {', '.join(units)}")
        lo, hi = self.pressure_range_kpa
        extrap = (P < lo) | (P > hi) if math.isfinite(lo) else np.zeros(P.size, bool)

        def value(act):
            law = MomentLaw.of(act, self.model)
            s = act.bend_sign or 1
            if quantity == "free_curvature":
                return np.abs(law.free_curvature_array(P))
            k = 0.0 if quantity == "blocked_moment" else s * abs(float(curvature_per_mm))
            return np.abs(law.moment(P, k))

        v0 = value(self.actuator)
        names = [n for n in self.correlation_names if n in PARAMETERS]
        var = np.zeros(P.size)
        if names and self.covariance is not None:
            idx = [self.correlation_names.index(n) for n in names]
            cov = np.asarray(self.covariance)[np.ix_(idx, idx)]
            G = np.empty((P.size, len(names)))
            for j, n in enumerate(names):
                f = PARAMETERS[n][0]
                x = float(getattr(self.actuator, f))
                h = max(1e-3 * math.sqrt(max(cov[j, j], 0.0)), 1e-7 * max(abs(x), 1.0))
                try:
                    up = value(self.actuator.replace(**{f: x + h}))
                    dn = value(self.actuator.replace(**{f: x - h}))
                except InputError:
                    up = dn = np.full(P.size, math.nan)
                G[:, j] = (up - dn) / (2 * h)
            var = np.einsum("ij,jk,ik->i", G, cov, G)
        sd = np.sqrt(np.clip(var, 0.0, None))
        return Band(quantity, units[quantity], P, v0, v0 - level * sd, v0 + level * sd, extrap)

    def plot(self, processed, title: str = ""):
        """Figure 7 (a matplotlib Figure): the fitted model against ``processed``."""
        from bendpam.present.figures import figure7

        return figure7(processed, self, title)

    def to_dict(self) -> dict:
        m = self.metrics.to_dict()
        return {
            "model": self.model,
            "parameters": {PARAMETERS[n][0]: p.to_dict() for n, p in self.parameters.items()},
            "correlation": {"names": [_label(n) for n in self.correlation_names],
                            "matrix": self.correlation.tolist()},
            "covariance": None if self.covariance is None else np.asarray(self.covariance).tolist(),
            "nrmse": m["nrmse"],
            "rmse": m["rmse"],
            "metrics_curves": m["metrics_curves"],
            "per_pressure": m["per_pressure"],
            "no_equilibrium_kpa": m["no_equilibrium_kpa"],
            "pressure_range_kpa": list(self.pressure_range_kpa),
            "material": None if self.material is None else self.material.to_dict(),
            "identifiability": self.identifiability,
            "alpha0_profile": None if self.alpha0_profile is None else self.alpha0_profile.to_dict(),
            "joint_intervals": [j.to_dict() for j in self.joint_intervals],
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
                no_equilibrium_kpa=d["no_equilibrium_kpa"], curves=str(d.get("metrics_curves", "mean curves")))
            n = len(d["correlation"]["names"])
            cov = d.get("covariance")
            return cls(
                model=d["model"], actuator=act, parameters=params,
                correlation=np.array(d["correlation"]["matrix"], dtype=float).reshape(n, n),
                correlation_names=[rev[n] for n in d["correlation"]["names"]], metrics=metrics,
                converged=bool(d["converged"]), message=str(d["message"]), nfev=int(d["nfev"]),
                time_s=float(d["time_s"]), flags=list(d["flags"]),
                autocorrelation=float(d.get("residual_autocorrelation", 0.0)),
                hysteresis=HysteresisFit.from_dict(d["hysteresis"]) if d.get("hysteresis") else None,
                material=MaterialFit.from_dict(d["material"]) if d.get("material") else None,
                identifiability=[str(s) for s in d.get("identifiability", [])],
                alpha0_profile=Profile.from_dict(d["alpha0_profile"]) if d.get("alpha0_profile") else None,
                joint_intervals=[JointInterval.from_dict(j) for j in d.get("joint_intervals", [])],
                covariance=None if cov is None else np.array(cov, dtype=float).reshape(n, n),
                pressure_range_kpa=_pair(d.get("pressure_range_kpa", [None, None])),
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
        mat = self.material
        if mat is not None:
            se_mu = f" ± {mat.se_shear_modulus_kpa:.3g}" if mat.se_shear_modulus_kpa is not None else ""
            se_b = f" ± {mat.se_shape:.2g}" if mat.se_shape is not None else ""
            lines.append(f"  shear modulus mu = 2(C10 + C01) = {mat.shear_modulus_kpa:.4g}{se_mu} kPa, shape "
                         f"C01/(C10 + C01) = {mat.shape:.3g}{se_b} (admissible [{mat.shape_bounds[0]:.3g}, "
                         f"{mat.shape_bounds[1]:.3g}])")
        m = self.metrics
        what = " (model with its loop, both branches)" if m.curves == "loop" else ""
        lines.append(f"  NRMSE cycles {100 * m.nrmse_cycles:.2f} %, "
                     f"blocked moment {100 * m.nrmse_blocked_moment:.2f} %, "
                     f"free curvature {_pct(m.nrmse_free_curvature)}{what}")
        h = self.hysteresis
        if h is not None:
            lines.append("  loop (" + h.law + "): " + ", ".join(
                f"{p.field} = {p.value:.4g}" + (f" ± {p.stderr:.2g}" if p.stderr is not None else "")
                for p in h.parameters.values()) + f"; NRMSE of the branches {100 * h.nrmse_branches:.2f} %")
            lines.append("  energy-loss ratio measured/predicted: " + ", ".join(
                f"{e.pressure_kpa:g} kPa {100 * e.measured:.1f}/{_pct(e.predicted, 1)}"
                for e in h.energy_loss_ratio))
        lines += [f"  identifiability: {s}" for s in self.identifiability]
        lines += [f"  note: {f}" for f in self.flags]
        return "\n".join(lines)


def _num(x) -> float:
    return math.nan if x is None else float(x)


def _opt(x) -> float | None:
    return None if x is None else float(x)


def _pair(x) -> tuple[float, float]:
    return _num(x[0]), _num(x[1])


def _pct(x, digits: int = 2):
    return "n/a" if x is None or not np.isfinite(x) else f"{100 * x:.{digits}f} %"


def score(
    processed, actuator: Actuator, model: str = "energy", *, loop=None, order: int = DEFAULT_ORDER,
    eq19_factor: bool = True,
) -> Metrics:
    """Metrics of eq 53-55 (and plain RMSEs) of ``actuator`` against processed data, without fitting.

    * eq 53: ``NRMSE_cycles = sqrt(sum_i (RMSE_i / M_max,i)^2 K_max,i / sum_i K_max,i)`` with
      ``M_max,i`` the test's blocked moment and ``K_max,i`` its free curvature; ``RMSE_i`` over the
      mean curve (no ``loop``), or over both mean branches against the loop model on the test's own
      path, blocked state to its measured free curvature (``loop`` given);
    * eq 54: ``NRMSE_BM = RMSE_BM / max_i BM_i``: the model's blocked moment, with a loop the
      largest moment of the predicted free cycle (:func:`bendpam.physics.hysteresis.predict_cycles`);
    * eq 55: ``NRMSE_FBC = RMSE_FBC / max_i FBC_i``: the model's free curvature, with a loop where
      the predicted cycle's unloading branch reaches zero moment; over the pressures where there is
      one (the others are listed in ``no_equilibrium_kpa``).
    """
    model = normalise_model(model)
    d = _data(processed, "all")
    s = actuator.bend_sign or 1
    if loop is None:
        law = MomentLaw(actuator, model, order=order, eq19_factor=eq19_factor)
        A, B = law.coefficients(s * d.kc)
        pa = np.maximum(d.Pc - actuator.P_start_kpa, 0.0)
        sq = (s * (pa * A - B) - d.Mc) ** 2
        seg = d.seg
        bm_model = np.abs(law.blocked_moment(d.P))
        kf_model = np.abs(law.free_curvature_array(d.P))
    else:
        from bendpam.physics.hysteresis import loop_branches, predict_cycles

        res = processed.results
        k = np.concatenate([np.asarray(r.curvature_grid, float) for r in res])
        n = [np.asarray(r.curvature_grid).size for r in res]
        Pp = np.repeat(d.P, n)
        up, low = loop_branches(actuator, loop, Pp, np.repeat(d.K, n), k, model, order=order,
                                eq19_factor=eq19_factor)
        ld = np.concatenate([np.asarray(r.mean_loading, float) for r in res])
        ul = np.concatenate([np.asarray(r.mean_unloading, float) for r in res])
        sq = np.concatenate([(up - ld) ** 2, (low - ul) ** 2])
        seg = np.tile(np.repeat(np.arange(len(res)), n), 2)
        cycles = predict_cycles(actuator, loop, d.P, model, order=order, eq19_factor=eq19_factor)
        bm_model = np.array([c.blocked_moment_nmm for c in cycles])
        kf_model = np.array([c.free_curvature_per_mm for c in cycles])
    rm = np.sqrt(np.bincount(seg, sq, d.P.size) / np.bincount(seg, None, d.P.size))
    nrmse_c = math.sqrt(float(np.sum((rm / d.BM) ** 2 * d.K) / np.sum(d.K)))
    rmse_bm = math.sqrt(float(np.mean((bm_model - d.BM) ** 2)))
    ok = np.isfinite(kf_model)
    rmse_fbc = math.sqrt(float(np.mean((kf_model[ok] - d.K[ok]) ** 2))) if ok.any() else math.nan
    per = [{"pressure_kpa": float(d.P[i]), "rmse_cycle_nmm": float(rm[i]), "M_max_nmm": float(d.BM[i]),
            "K_max_per_mm": float(d.K[i]), "blocked_moment_model_nmm": float(bm_model[i]),
            "free_curvature_model_per_mm": float(kf_model[i]) if ok[i] else None} for i in range(d.P.size)]
    return Metrics(
        nrmse_cycles=nrmse_c,
        nrmse_blocked_moment=rmse_bm / float(d.BM.max()),
        nrmse_free_curvature=rmse_fbc / float(d.K.max()) if ok.any() else math.nan,
        rmse_cycles=math.sqrt(float(np.mean(sq))),
        rmse_blocked_moment=rmse_bm,
        rmse_free_curvature=rmse_fbc,
        per_pressure=per,
        no_equilibrium_kpa=[float(p) for p in d.P[~ok]],
        curves="mean curves" if loop is None else "loop",
    )


def _loop_law(hysteresis, hysteresis_law: str, processed) -> str | None:
    """The loop law a fit uses: None (mean curves) or a law name."""
    from bendpam.physics.hysteresis import LAWS

    if hysteresis is None or hysteresis is False:
        return None
    key = str(hysteresis).strip().lower()
    if key in ("none", "off", "no", "false"):
        return None
    if key == "auto" or hysteresis is True:
        law = str(hysteresis_law).strip().lower()
        if law not in LAWS:
            raise InputError(f"hysteresis law {hysteresis_law!r} is not known; choose one of {', '.join(LAWS)}")
        return law if has_loop(processed) else None
    if key not in LAWS:
        raise InputError(f"hysteresis = {hysteresis!r}; choose 'auto', None or a loop law ({', '.join(LAWS)})")
    return key


def fit(processed, actuator: Actuator, model: str = "energy", free=("alpha0", "C10", "C01"), *,
        bounds: dict[str, tuple[float, float]] | None = None, tension=None, tension_data=None,
        order: int = DEFAULT_ORDER, eq19_factor: bool = True, grid_alpha: int = 41, grid_r0: int = 9,
        corr_flag: float = 0.95,
        fit_range: str = "developed", hysteresis: str | None = "auto", hysteresis_law: str = "pi",
        law_uncertainty: bool = True, admissible_range: tuple[float, float] | None = (0.6, 1.6),
        profile_points: int = 13) -> FitResult:
    """Identify ``free`` parameters of ``actuator`` for ``model`` from a processed test set.

    The stages (module notes): the data and the admissible shapes, a global grid and a local search
    on the projected problem, the fold rule, the joint fit with a tension test, the uncertainty
    (statistical and the loop law's systematic part), the profile of alpha0, and the result.

    Parameters
    ----------
    processed : :class:`bendpam.lab.processing.ProcessedSet` (or ``load_processed(dir)``).
    actuator : the nominal actuator (geometry, and the values of the parameters held fixed).
    model : ``"energy"`` or ``"force_balance"``.
    free : names among alpha0, C10, C01, P_start, E_f, R0_start (aliases such as ``alpha0_deg`` work).
    bounds : overrides of the default bounds, ``{name: (lo, hi)}`` in the parameter's unit;
        ``"shape"`` narrows the admissible shapes C01/(C10 + C01).
    tension : a :class:`~bendpam.identify.tension.TensionFit`; its ``C10_kpa`` and ``C01_kpa`` replace the
        actuator's before fitting (the values of constants held fixed).
    tension_data : a :class:`~bendpam.identify.tension.TensionData` (the bladder's tension test): fitted
        together with the bending curves (module notes) when C10 or C01 is free.
    fit_range : without a loop model, ``"developed"`` (default) fits each mean curve where the loop
        is developed (:func:`developed_range`), ``"all"`` every point, as the paper did.
    hysteresis : ``"auto"`` (default): fit both branches with the loop model when the tests show a
        loop (:func:`has_loop`), else the mean curves; a law name (``"pi"``, ``"dahl"``) forces the
        loop model; ``None`` fits the mean curves (the paper's way, today's ``--no-hysteresis``).
    hysteresis_law : the law of ``"auto"`` (``"pi"``: Prandtl-Ishlinskii, or ``"dahl"``).  With a
        free P_start the loop's amplitude ``a0 + a1 (P - P_start)`` uses the nominal P_start (the
        amplitude stays linear in a0, a1); the fitted loop is saved with the fitted one.
    law_uncertainty : with a loop, refit with the other law and add the shift as a systematic error.
    admissible_range : principal stretches (lo, hi) the material must be physical over besides the
        tested ones (the range it will predict); None: only the tested ones.
    profile_points : points of the profile of alpha0 (0: none).

    Returns
    -------
    FitResult

    Raises
    ------
    InputError
        Bad arguments (unknown parameter, bounds, law; P_start not below the tested pressures).
    FitError
        The data cannot be described: no positive shear modulus fits, or a degenerate Jacobian.

    Examples
    --------
    Virtual tests of the paper's BE-PAM (alpha0 = 69.7 deg), processed and fitted:

    >>> from pathlib import Path
    >>> import bendpam
    >>> from bendpam.lab import RawTest
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> be, settings = bendpam.physics.presets.be_pam(), SimulationSettings(cycles=2, rate_hz=5.0, seed=1)
    >>> raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv",
    ...                 pressure_kpa=p) for p in (100.0, 150.0, 200.0)]
    >>> result = fit(bendpam.process_tests(raws, keep_series=False), be)
    >>> result.converged, abs(result.actuator.alpha0_deg - 69.7) < 0.5
    (True, True)
    """
    t0 = time.perf_counter()
    model = normalise_model(model)
    free = parse_free(free)
    if tension is not None:
        actuator = actuator.replace(C10_kpa=tension.C10_kpa, C01_kpa=tension.C01_kpa)
    law = _loop_law(hysteresis, hysteresis_law, processed)
    d = _branch_data(processed, actuator.L0_mm) if law else _data(processed, fit_range)
    bnd = _bounds(actuator, d, bounds)
    if "P_start" not in free and actuator.P_start_kpa >= d.P.min():
        raise InputError(
            f"P_start = {actuator.P_start_kpa:g} kPa is not below the lowest test pressure {d.P.min():g} kPa")
    stretch = _stretch_range(actuator, d, admissible_range, tension_data)
    shape_bounds = _shape_bounds(stretch, bounds)
    args = (actuator, d, model, free, bnd, order, eq19_factor, law, shape_bounds)
    prob = _Problem(*args)
    step = max(1, d.kc.size // 400)  # the grid only has to find the basin: about 400 points suffice
    coarse = _Problem(actuator, d.thin(step), *args[2:]) if step > 1 else prob
    best, nfev = _start(coarse, bnd, grid_alpha, grid_r0)
    nl, lin, converged, message, n = _solve(prob, bnd, 0, 0, start=best[1])
    nfev += n
    notes: list[str] = []
    shape_held = ""
    prob, nl, lin, n, fold_note, shape_held = _fold_rule(prob, args, bnd, nl, lin, float(d.P.max()))
    nfev += n
    if fold_note:
        notes.append(fold_note)
    if tension_data is not None and {"C10", "C01"} & set(free):
        prob, nl, lin, n, note = _joint_tension(prob, args, bnd, nl, lin, tension_data)
        nfev += n
        notes.append(note)
    unc = _uncertainty(prob, bnd, nl, lin, corr_flag)
    nfev += unc.nfev
    shift: dict[str, float] = {}
    alt = ""
    if law and law_uncertainty:
        alt = "dahl" if law == "pi" else "pi"
        shift, n = _law_shift(prob, args, bnd, nl, lin, alt)
        nfev += n
        unc.add_systematic(shift)
    profile, n = _profile(prob, bnd, nl, unc, profile_points)
    nfev += n
    return _result(processed, actuator, model, prob, bnd, unc, tension, law, converged, message, nfev, t0,
                   order, eq19_factor, notes, shift, alt, profile, stretch, shape_held, hysteresis)


def _bounds(actuator: Actuator, d: _Data, bounds) -> dict[str, tuple[float, float]]:
    bnd = _default_bounds(actuator, float(d.P.min()))
    bnd.update({"theta_h": (0.2, 90.0), "a0": (0.0, 10.0 * float(d.BM.max())), "a1": (0.0, 100.0)})
    for k, v in (bounds or {}).items():
        key = "shape" if str(k).strip().lower() in ("shape", "beta") else parse_free([k])[0]
        try:
            lo, hi = float(v[0]), float(v[1])
        except (TypeError, ValueError, IndexError):
            raise InputError(f"bounds for {k}: expected a pair (lo, hi), got {v!r}") from None
        if not lo < hi:
            raise InputError(f"bounds for {k}: lower {lo:g} must be below upper {hi:g}")
        bnd[key] = (lo, hi)
    return bnd


def _stretch_range(actuator: Actuator, d: _Data, admissible_range, tension_data) -> tuple[float, float]:
    """Stretches the material must serve: the tested curvatures (+10 %), the tension test, ``admissible_range``."""
    lo, hi = bladder_stretch_range(actuator, np.linspace(0.0, _STRETCH_MARGIN * float(d.K.max()), 41))
    if admissible_range is not None:
        try:
            a, b = (float(x) for x in admissible_range)
        except (TypeError, ValueError):
            raise InputError(f"admissible_range = {admissible_range!r} is not a pair (lo, hi) of stretches") from None
        if not (math.isfinite(a) and math.isfinite(b) and 0.0 < a < b):
            raise InputError(f"admissible_range = ({a:g}, {b:g}) is not a valid stretch range; expected 0 < lo < hi")
        lo, hi = min(lo, a), max(hi, b)
    if tension_data is not None and tension_data.stretch.size:
        lo, hi = min(lo, float(tension_data.stretch.min())), max(hi, float(tension_data.stretch.max()))
    return min(lo, 1.0), max(hi, 1.0)


def _shape_bounds(stretch: tuple[float, float], bounds) -> tuple[float, float]:
    lo, hi = admissible_shape_range(*stretch)
    for k, v in (bounds or {}).items():
        if str(k).strip().lower() in ("shape", "beta"):
            a, b = float(v[0]), float(v[1])
            if b < lo or a > hi:
                raise InputError(f"bounds for shape: ({a:g}, {b:g}) lies outside the admissible shapes "
                                 f"[{lo:.4g}, {hi:.4g}] for stretches [{stretch[0]:.4g}, {stretch[1]:.4g}]")
            lo, hi = max(lo, a), min(hi, b)
    return lo, hi


def _solve(prob: _Problem, bnd, grid_alpha: int, grid_r0: int, start: dict[str, float] | None = None):
    """Global grid (unless ``start`` is given) and local search; returns (nl, lin, converged, message, nfev)."""
    nfev = 0
    if start is None:
        best, nfev = _start(prob, bnd, grid_alpha, grid_r0)
    else:
        best = (math.nan, dict(start))
    nl, lin, converged, message, n = _search(prob, bnd, best)
    return nl, lin, converged, message, nfev + n


def _start(prob: _Problem, bnd, grid_alpha: int, grid_r0: int):
    """A global grid over the nonlinear parameters, the linear ones projected exactly."""
    nfev = 0
    grids = []
    for p in prob.nonlin:
        lo, hi = bnd[p]
        if p == "theta_h":  # the loop's angle spans decades: a geometric grid
            g = _THETA_GRID[(_THETA_GRID >= lo) & (_THETA_GRID <= hi)]
            grids.append(g if g.size else np.array([math.sqrt(lo * hi)]))
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
    """A bounded trust-region search on the projected problem; the final linear solve."""
    from scipy.optimize import least_squares

    nfev = 0
    converged, message = True, "linear least squares (exact)"
    nl_best = best[1]
    if prob.nonlin:
        x0 = np.array([nl_best[p] for p in prob.nonlin])
        lo = np.array([bnd[p][0] for p in prob.nonlin])
        hi = np.array([bnd[p][1] for p in prob.nonlin])
        x0 = np.clip(x0, lo, hi)

        def fun(x):
            return prob.project(dict(zip(prob.nonlin, x, strict=True)))[0]

        sol = least_squares(fun, x0, bounds=(lo, hi), method="trf", x_scale=np.maximum(hi - lo, 1e-9) * 0.05,
                            diff_step=1e-6, xtol=1e-10, ftol=1e-12, gtol=1e-12)
        nfev += sol.nfev * (1 + len(prob.nonlin))
        converged = bool(sol.status > 0)
        message = "converged" if converged else "the search stopped before converging (iteration limit)"
        nl_best = {p: float(v) for p, v in zip(prob.nonlin, sol.x, strict=True)}
    _, lin = prob.project(nl_best)
    if prob.cone or prob.shape_fixed is not None:
        S = sum(float(v) for p, v in zip(prob.int_names, lin, strict=True) if p in ("S", "S_lo", "S_hi"))
        if not S > 0.0:
            raise FitError("no positive shear modulus fits the curves: the moment does not fall with curvature "
                           "as a bladder's would (C10 + C01 came out 0)")
    return nl_best, lin, converged, message, nfev + 1


def _ssr(prob: _Problem, nl, lin) -> float:
    r = prob.residual_full(np.concatenate([[nl[p] for p in prob.nonlin], lin]))
    return float(r @ r)


def _fold_kpa(prob: _Problem, nl, lin, p_max: float) -> float | None:
    """The fold pressure of the fitted quasi-static model if its free-bending branch ends below ``p_max``."""
    act = prob.actuator(prob.to_user(nl, lin))
    br = MomentLaw.of(act, prob.model, order=prob.order, eq19_factor=prob.eq19).free_branch()
    return float(br.max_pressure_kpa) if br.max_pressure_kpa < p_max else None


def _fold_rule(prob: _Problem, args, bnd, nl, lin, p_max: float):
    """Reject a fit whose model has no free-bending equilibrium inside the tested pressures.

    Returns ``(prob, nl, lin, nfev, note, shape_held)``.
    """
    fold = _fold_kpa(prob, nl, lin, p_max)
    if fold is None:
        return prob, nl, lin, 0, "", ""
    if not prob.cone:
        return prob, nl, lin, 0, (
            f"REJECTED: the fitted model has no free-bending equilibrium above {fold:.4g} kPa (a fold), inside the "
            f"tested range (to {p_max:g} kPa); free both C10 and C01 so the shape can avoid it"), ""
    nfev = 0
    best = None
    for beta in np.linspace(*prob.shape_bounds, 9):
        p2 = _Problem(*args, shape_fixed=float(beta))
        nl2, lin2, _, _, n = _solve(p2, bnd, 0, 0, start=nl)
        nfev += n
        if _fold_kpa(p2, nl2, lin2, p_max) is None:
            ssr = _ssr(p2, nl2, lin2)
            if best is None or ssr < best[0]:
                best = (ssr, p2, nl2, lin2, float(beta))
    if best is None:
        return prob, nl, lin, nfev, (
            f"REJECTED: the fitted model has no free-bending equilibrium above {fold:.4g} kPa (a fold), inside the "
            f"tested range (to {p_max:g} kPa), and no admissible shape avoids it: the model cannot describe "
            "these data"), ""
    _, p2, nl2, lin2, beta = best
    why = (f"the best-fitting admissible material folds at {fold:.4g} kPa, inside the tested range (to "
           f"{p_max:g} kPa)")
    return p2, nl2, lin2, nfev, (
        f"fold rejected: {why}; the shape C01/(C10 + C01) is held at {beta:.3g}, the best one without a fold"), \
        f"held at {beta:.4g} because {why}"


def _joint_tension(prob: _Problem, args, bnd, nl, lin, tension_data):
    """Refit with the tension test's rows, each data set weighted by its own residual noise."""
    from bendpam.identify.tension import fit_tension

    lam = np.asarray(tension_data.stretch, dtype=float)
    stress = np.asarray(tension_data.nominal_stress_kpa, dtype=float)
    r, _ = prob.project(nl)
    m, p = r.size, len(prob.nonlin) + len(prob.int_names)
    s_b = math.sqrt(float(r @ r) / max(m - p, 1))
    tf = fit_tension(lam, stress, admissible_range=None, source=getattr(tension_data, "source", ""))
    s_t = tf.rmse_kpa * math.sqrt(tf.n_points / max(tf.n_points - 2, 1))
    if not (s_t > 0 and math.isfinite(s_t)):
        s_t = 1e-6 * max(float(np.max(np.abs(stress))), 1.0)
    ten = _Tension(lam, stress, s_b / s_t)
    p2 = _Problem(*args, shape_fixed=prob.shape_fixed, tension=ten)
    nl2, lin2, _, _, n = _solve(p2, bnd, 0, 0, start=nl)
    note = (f"joint fit with the tension test{' ' + tf.source if tf.source else ''} ({lam.size} points, stretch "
            f"{lam.min():.3g} to {lam.max():.3g}): each data set weighted by its own residual noise (bending "
            f"{s_b:.3g} in eq-53 units, tension {s_t:.3g} kPa)")
    return p2, nl2, lin2, n, note


class _Uncertainty:
    """Covariance of the varied parameters (user units) with flags; a systematic term can be added."""

    def __init__(self, values, names, cov, rho, nfev, at_bound, ssr, m, corr_flag):
        self.corr_flag = corr_flag
        self.values = values
        self.names = names
        self.cov_stat = cov
        self.cov = cov.copy()
        self.rho = rho
        self.nfev = nfev
        self.at_bound = at_bound
        self.ssr = ssr
        self.m = m

    @property
    def sd(self) -> np.ndarray:
        return np.sqrt(np.clip(np.diag(self.cov), 0.0, None))

    @property
    def corr(self) -> np.ndarray:
        sd = self.sd
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.cov / np.outer(sd, sd)

    def add_systematic(self, shift: dict[str, float]) -> None:
        """Add ``delta delta^T / 3`` for the parameter shifts (module notes)."""
        dv = np.array([shift.get(n, 0.0) for n in self.names])
        self.cov = self.cov_stat + np.outer(dv, dv) / 3.0


def _uncertainty(prob: _Problem, bnd, nl_best, lin, corr_flag: float) -> _Uncertainty:
    """Sandwich covariance from the joint Jacobian (nonlinear columns by central differences).

    The weights normalise each curve (eq 53), they are not inverse noise variances, so each residual
    group (a curve, a branch, the tension test) gets its own variance with its AR(1) inflation.
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
    J[:, nn:] = prob.w[:, None] * X
    B = J.T @ J
    meat = np.zeros_like(B)
    share = 1.0 - x_int.size / max(m, 1)
    rhos = []
    for g in np.unique(prob.groups):
        sel = prob.groups == g
        ri = r[sel]
        var_i = float(ri @ ri) / max(share * ri.size, 1.0)
        rho_i = min(max(_lag1(ri, np.zeros(ri.size, int)), 0.0), 0.95)
        rhos.append(rho_i)
        meat += (J[sel].T @ J[sel]) * var_i * (1.0 + rho_i) / (1.0 - rho_i)
    rho = float(np.mean(rhos)) if rhos else 0.0
    lo_all = np.concatenate([[bnd[p][0] for p in prob.nonlin], prob.lo])
    hi_all = np.concatenate([[bnd[p][1] for p in prob.nonlin], prob.hi])
    tol_lo = 1e-9 * np.maximum(1, np.abs(np.where(np.isfinite(lo_all), lo_all, 0.0)))
    tol_hi = 1e-9 * np.maximum(1, np.abs(np.where(np.isfinite(hi_all), hi_all, 0.0)))
    at_bound = (np.abs(x_int - lo_all) <= tol_lo) | (np.abs(x_int - hi_all) <= tol_hi)
    if not np.all(np.isfinite(B)):
        raise FitError("the data do not determine the parameters (the Jacobian is not finite at the optimum); "
                       "fix some with a narrower --free")
    Binv = np.linalg.pinv(B, rcond=1e-13)
    cov_int = Binv @ meat @ Binv
    G = np.zeros((nn + len(prob.lin), x_int.size))
    G[:nn, :nn] = np.eye(nn)
    G[nn:, nn:] = prob.T
    cov = G @ cov_int @ G.T
    names = prob.nonlin + prob.lin
    values = prob.to_user(nl_best, lin)
    bound_names = {n: bool(b) for n, b in zip(prob.nonlin + prob.int_names, at_bound, strict=True)}
    return _Uncertainty(values, names, cov, rho, nfev, bound_names, float(r @ r), m, corr_flag)


def _law_shift(prob: _Problem, args, bnd, nl, lin, alt: str):
    """Shift of the model parameters when the other loop law is fitted (warm start, angle grid)."""
    a2 = list(args)
    a2[7] = alt
    p2 = _Problem(*a2, shape_fixed=prob.shape_fixed, tension=prob.tension)
    nfev = 0
    best = (math.inf, dict(nl))
    for th in _THETA_GRID:
        trial = {**nl, "theta_h": float(th)}
        r, _ = p2.project(trial)
        nfev += 1
        if float(r @ r) < best[0]:
            best = (float(r @ r), trial)
    nl2, lin2, _, _, n = _search(p2, bnd, best)
    nfev += n
    v1 = prob.to_user(nl, lin)
    v2 = p2.to_user(nl2, lin2)
    return {p: v2[p] - v1[p] for p in v1 if p in PARAMETERS}, nfev


def _profile(prob: _Problem, bnd, nl, unc: _Uncertainty, n_points: int):
    """The objective minimised over everything else against alpha0, around the optimum."""
    if "alpha0" not in prob.nonlin or n_points < 3:
        return None, 0
    from scipy.optimize import least_squares

    i = unc.names.index("alpha0")
    a_hat, se = float(nl["alpha0"]), float(unc.sd[i])
    half = max(4.0 * se if math.isfinite(se) else 0.0, 0.05)
    lo, hi = max(a_hat - half, bnd["alpha0"][0]), min(a_hat + half, bnd["alpha0"][1])
    alphas = np.unique(np.concatenate([np.linspace(lo, hi, n_points), [a_hat]]))
    others = [p for p in prob.nonlin if p != "alpha0"]
    nfev = 0
    obj = np.empty(alphas.size)
    centre = int(np.argmin(np.abs(alphas - a_hat)))
    order = list(range(centre, alphas.size)) + list(range(centre - 1, -1, -1))
    x_prev = np.array([nl[p] for p in others])
    for j in order:
        a = float(alphas[j])
        if j == centre - 1:
            x_prev = np.array([nl[p] for p in others])
        if not others:
            r, _ = prob.project({"alpha0": a})
            nfev += 1
        else:
            lo_o = np.array([bnd[p][0] for p in others])
            hi_o = np.array([bnd[p][1] for p in others])

            def fun(x, a=a):
                return prob.project({"alpha0": a, **dict(zip(others, x, strict=True))})[0]

            sol = least_squares(fun, np.clip(x_prev, lo_o, hi_o), bounds=(lo_o, hi_o), method="trf",
                                x_scale=np.maximum(hi_o - lo_o, 1e-9) * 0.05, diff_step=1e-6, xtol=1e-7,
                                ftol=1e-8, max_nfev=20)
            nfev += sol.nfev * (1 + len(others))
            x_prev = sol.x
            r = sol.fun
        obj[j] = float(r @ r)
    sd = float(unc.sd[i])
    return Profile([float(x) for x in alphas], [float(x) for x in obj], (a_hat - 2 * sd, a_hat + 2 * sd)), nfev


def _joint(names, values, cov, corr, corr_flag) -> tuple[list[JointInterval], list[str]]:
    out, flags = [], []
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            c = corr[i, j]
            if not (np.isfinite(c) and abs(c) > corr_flag and sd[j] > 0):
                continue
            li, lj = _label(names[i]), _label(names[j])
            lam = -cov[i, j] / cov[j, j]
            val = values[names[i]] + lam * values[names[j]]
            se = math.sqrt(max(cov[i, i] + 2 * lam * cov[i, j] + lam * lam * cov[j, j], 0.0))
            q = math.sqrt(_CHI2_2_95)
            box = {li: (values[names[i]] - q * sd[i], values[names[i]] + q * sd[i]),
                   lj: (values[names[j]] - q * sd[j], values[names[j]] + q * sd[j])}
            unit = _unit(names[i]) if _unit(names[i]) == _unit(names[j]) or abs(lam) < 1e-300 else ""
            comb = f"{li} {'+' if lam >= 0 else '-'} {abs(lam):.3g} {lj}"
            text = (f"{li} and {lj} are poorly identifiable together (correlation {c:+.4f}): the data determine "
                    f"{comb} = {val:.4g} ± {2 * se:.2g}{' ' + unit if unit else ''} (2 SE), not each one; jointly "
                    f"(95 %) {li} in [{box[li][0]:.4g}, {box[li][1]:.4g}] and {lj} in [{box[lj][0]:.4g}, "
                    f"{box[lj][1]:.4g}] along that line")
            out.append(JointInterval((li, lj), float(c), float(lam), float(val), float(se), box, text))
            flags.append(text)
    return out, flags


def _material(fitted: Actuator, unc: _Uncertainty, shape_bounds, stretch, at_bound: bool, held: str,
              free: list[str]) -> MaterialFit | None:
    if "C10" not in free and "C01" not in free:
        return None
    c10, c01 = fitted.C10_kpa, fitted.C01_kpa
    S = c10 + c01
    names = unc.names
    g_mu = np.zeros(len(names))
    g_b = np.zeros(len(names))
    if "C10" in names:
        g_mu[names.index("C10")] = 2.0
        g_b[names.index("C10")] = -c01 / S**2
    if "C01" in names:
        g_mu[names.index("C01")] = 2.0
        g_b[names.index("C01")] = c10 / S**2
    se_mu = math.sqrt(max(float(g_mu @ unc.cov @ g_mu), 0.0))
    se_b = math.sqrt(max(float(g_b @ unc.cov @ g_b), 0.0))
    width = shape_bounds[1] - shape_bounds[0]
    identified = bool(not at_bound and not held and width > 0 and 2 * _Z95 * se_b <= _SHAPE_RESOLVED * width)
    return MaterialFit(2.0 * S, se_mu, c01 / S, se_b, (float(shape_bounds[0]), float(shape_bounds[1])),
                       (float(stretch[0]), float(stretch[1])), bool(at_bound), identified, held)


def _identifiability(mat: MaterialFit | None, free: list[str], unc: _Uncertainty, fitted: Actuator,
                     shift: dict[str, float], alt: str, law: str | None) -> list[str]:
    out = []
    if "alpha0" in unc.names:
        i = unc.names.index("alpha0")
        se = float(unc.sd[i])
        sys_ = abs(shift.get("alpha0", 0.0)) / math.sqrt(3.0)
        tail = (f"; the loop law alone ({law} vs {alt}, systematic) accounts for ± {2 * sys_:.2g} deg"
                if law and alt and sys_ > 0 else "")
        head = f"alpha0 = {fitted.alpha0_deg:.4g} ± {2 * se:.2g} deg (2 SE{tail})"
        if unc.at_bound.get("alpha0", False):
            out.append(f"{head} sits at a bound of its range: the curves do not determine it there.")
        elif not 2 * se <= 1.0:
            out.append(f"{head} is only loosely determined by the curves.")
        else:
            out.append(f"{head} is determined by the curves.")
    if mat is None:
        return out
    both = "C10" in free and "C01" in free
    rel = (mat.se_shear_modulus_kpa or 0.0) / mat.shear_modulus_kpa
    mu_txt = f"mu = 2(C10 + C01) = {mat.shear_modulus_kpa:.4g} ± {2 * (mat.se_shear_modulus_kpa or 0):.2g} kPa (2 SE)"
    if rel <= 0.05:
        out.append(f"The initial shear modulus {mu_txt} is determined by the data.")
    else:
        out.append(f"The initial shear modulus {mu_txt} is only loosely determined ({100 * rel:.0f} % SE).")
    lo, hi = mat.shape_bounds
    adm = (f"the admissible [{lo:.3g}, {hi:.3g}] (energy >= 0, monotone, Baker-Ericksen for stretches "
           f"{mat.stretch_range[0]:.3g} to {mat.stretch_range[1]:.3g})")
    if not both:
        out.append(f"The shape C01/(C10 + C01) = {mat.shape:.3g} follows from the constant held fixed; it lies in "
                   f"{adm}.")
    elif mat.shape_held:
        out.append(f"The shape C01/(C10 + C01) is not fitted: {mat.shape_held}.")
    elif mat.shape_at_bound:
        out.append(f"The shape C01/(C10 + C01) is not determined: the curves push it to the bound {mat.shape:.3g} of "
                   f"{adm}; it is set by the admissibility rule, not the data, so only mu is reliable.")
    elif mat.shape_identified:
        out.append(f"The shape C01/(C10 + C01) = {mat.shape:.3g} ± {2 * (mat.se_shape or 0):.2g} (2 SE) is "
                   f"determined too: its 95 % interval covers at most half of {adm}.")
    else:
        frac = 2 * _Z95 * (mat.se_shape or 0) / (hi - lo) if hi > lo else math.inf
        out.append(f"The shape C01/(C10 + C01) = {mat.shape:.3g} ± {2 * (mat.se_shape or 0):.2g} (2 SE) is not "
                   f"determined: its 95 % interval covers {min(100 * frac, 999):.0f} % of {adm}; only mu = "
                   "2(C10 + C01) is reliable, not C10 and C01 apart.")
    return out


def _result(processed, actuator, model, prob: _Problem, bnd, unc: _Uncertainty, tension, law, converged, message,
            nfev, t0, order, eq19_factor, notes, shift, alt, profile, stretch, shape_held, hysteresis) -> FitResult:
    """The fitted actuator, its parameters, material, metrics, loop and notes."""
    fitted = prob.actuator(unc.values)
    fitted = fitted.replace(name=f"{actuator.name or actuator.kind} [fitted, {model.replace('_', '-')} model]",
                            model=model)
    sd = unc.sd
    params = {}
    for n in _ORDER:
        field_, unit = PARAMETERS[n]
        val = float(getattr(fitted, field_))
        lo, hi = bnd[n]
        if n in ("C10", "C01") and prob.cone:
            lo, hi = -math.inf, math.inf  # the admissible cone (material.shape_bounds), not a box
        if n in unc.names:
            i = unc.names.index(n)
            se = float(sd[i]) if np.isfinite(sd[i]) else None
            start = PAPER_START.get(n, float(getattr(actuator, field_))) if tension is None else \
                {"C10": tension.C10_kpa, "C01": tension.C01_kpa}.get(n, float(getattr(actuator, field_)))
            params[n] = Parameter(n, field_, unit, val, se, lo, hi, True, start)
        elif n in ("alpha0", "C10", "C01", "P_start"):
            params[n] = Parameter(n, field_, unit, val, None, lo, hi, False, val)
    flags = []
    for p, b in unc.at_bound.items():
        if not b:
            continue
        if p in ("S_lo", "S_hi"):
            continue  # the shape at an admissibility bound: said in the identifiability notes
        flags.append(f"{'C10 + C01' if p == 'S' else _label(p) if p in PARAMETERS or p in HYST_PARAMETERS else p} "
                     "is at a bound of its range; its standard error is not meaningful")
    shape_at_bound = prob.cone and prob.shape_fixed is None and (unc.at_bound.get("S_lo", False)
                                                                 or unc.at_bound.get("S_hi", False))
    mat = _material(fitted, unc, prob.shape_bounds, stretch, shape_at_bound, shape_held,
                       [p for p in prob.free if p in PARAMETERS])
    joint, jflags = _joint(unc.names, unc.values, unc.cov, unc.corr, unc.corr_flag)
    flags = jflags + flags + list(notes)
    free_user = [p for p in prob.free if p in PARAMETERS]
    ident = _identifiability(mat, free_user, unc, fitted, shift, alt, law)
    loop = None
    hyst = None
    if law is not None:
        from bendpam.physics.hysteresis import predict_cycles

        hp = {}
        for n in ("a0", "a1", "theta_h"):
            i = unc.names.index(n)
            field_, unit = HYST_PARAMETERS[n]
            hp[n] = Parameter(n, field_, unit, float(unc.values[n]), float(sd[i]) if np.isfinite(sd[i]) else None,
                              bnd[n][0], bnd[n][1], True, math.nan)
        hyst = HysteresisFit(law, "linear", hp, [], math.nan, alt,
                             {PARAMETERS[k][0]: float(v) for k, v in shift.items()})
        loop = hyst.loop()
        cycles = predict_cycles(fitted, loop, [r.pressure_kpa for r in processed.results], model, order=order,
                                eq19_factor=eq19_factor)
        hyst.energy_loss_ratio = [LossRatio(float(r.pressure_kpa), float(r.energy_loss_ratio), c.energy_loss_ratio)
                                  for r, c in zip(processed.results, cycles, strict=True)]
    elif has_loop(processed):
        ratio = float(np.median([r.energy_loss_ratio for r in processed.results]))
        flags.append(f"fitted to the mean curves although the tests show a loop (median energy-loss ratio "
                     f"{100 * ratio:.1f} %): the loop can bias alpha0 by more than its standard error; the default "
                     "(hysteresis-aware) fit avoids that")
    metrics = score(processed, fitted, model, loop=loop, order=order, eq19_factor=eq19_factor)
    if hyst is not None:
        hyst.nrmse_branches = metrics.nrmse_cycles
    if metrics.no_equilibrium_kpa:
        what = "free-bending cycle (the unloading branch never reaches zero)" if loop is not None else \
            "free-bending equilibrium"
        flags.append(f"no {what} in the fitted model at " + ", ".join(f"{p:g}" for p in metrics.no_equilibrium_kpa)
                     + " kPa; those pressures are left out of the free-curvature metric")
    if law is not None and str(hysteresis).strip().lower() == "auto":
        ratio = float(np.median([r.energy_loss_ratio for r in processed.results]))
        message += (f"; fitted with the {law} loop model on both branches (the tests show a loop, median "
                    f"energy-loss ratio {100 * ratio:.1f} %)")
    P = np.array([r.pressure_kpa for r in processed.results], dtype=float)
    return FitResult(
        model=model, actuator=fitted, parameters=params, correlation=unc.corr, correlation_names=unc.names,
        metrics=metrics, converged=converged, message=message, nfev=nfev, time_s=time.perf_counter() - t0,
        flags=flags, autocorrelation=unc.rho, hysteresis=hyst, material=mat, identifiability=ident,
        alpha0_profile=profile, joint_intervals=joint, covariance=unc.cov,
        pressure_range_kpa=(float(P.min()), float(P.max())),
    )


def predicted_loss_ratios(processed, actuator: Actuator, loop, model: str = "energy", *, order: int = DEFAULT_ORDER,
                          eq19_factor: bool = True) -> list[dict]:
    """Energy-loss ratio of each test, measured (processing) and predicted (the loop's free cycle).

    The prediction is :func:`bendpam.physics.hysteresis.predict_cycles`, exactly what ``bendpam predict
    --cycle`` prints: the cycle between the blocked state and the free state the model reaches on
    unloading.
    """
    from bendpam.physics.hysteresis import predict_cycles

    cycles = predict_cycles(actuator, loop, [r.pressure_kpa for r in processed.results], model, order=order,
                            eq19_factor=eq19_factor)
    return [{"pressure_kpa": float(r.pressure_kpa), "measured": float(r.energy_loss_ratio),
             "predicted": c.energy_loss_ratio} for r, c in zip(processed.results, cycles, strict=True)]


def branch_nrmse(processed, actuator: Actuator, loop, model: str = "energy", *, order: int = DEFAULT_ORDER,
                 eq19_factor: bool = True) -> float:
    """eq-53-style NRMSE of both branches (loading and unloading) against the loop model (:func:`score`)."""
    return score(processed, actuator, model, loop=loop, order=order, eq19_factor=eq19_factor).nrmse_cycles
