"""Admissible Mooney-Rivlin constants of the bladder from a uniaxial tension test.

The uniaxial nominal stress of an incompressible Mooney-Rivlin solid is linear in its
constants.  Written with the initial shear modulus ``mu = 2 (C10 + C01)`` and the shape
``beta = C01 / (C10 + C01)`` (:mod:`bendpam.physics.material`)::

    P(l) = mu (l - l^-2) + (mu beta) (l - l^-2)(1/l - 1)

it is linear in ``x = (mu, mu beta)``.  The shape is confined to the admissible interval
``[beta_lo, beta_hi]`` of :func:`~bendpam.physics.material.admissible_shape_range` over the
stretches the material must serve: those of the data used and ``admissible_range``, the
range the constants will be asked to predict (by default the bladder's, 0.6 to 1.6).
For ``mu > 0`` that is two linear inequalities, ``mu beta - beta_lo mu >= 0`` and
``beta_hi mu - mu beta >= 0``: a cone whose edges are the two bounding shapes.

Method
    Exact bounded linear least squares on the nominal stress (unweighted, kPa).  The
    optimum of a convex quadratic over the cone is the unconstrained optimum if that
    lies in the cone, else the best point of one of its two edges (``beta`` fixed at a
    bound, ``mu >= 0`` in closed form).  All candidates are enumerated, so the result is
    the global constrained optimum, with no iteration and no start value.

Uncertainty
    Standard errors and the C10-C01 correlation come from the unconstrained problem's
    covariance at the solution, ``s^2 (X^T X)^-1`` with ``s^2 = RSS/(n - 2)``; at a
    bound they tell how well the data alone fix the constants.  ``se_shape`` follows by
    the delta method.  The shape counts as identified when its 95 % interval
    (``+-1.96 se_shape``) covers at most half of the admissible width
    ``beta_hi - beta_lo`` (:data:`SHAPE_RESOLVED_FRACTION`); the shear modulus nearly
    always is.  :attr:`TensionFit.identifiable` says which, in words.

Units: stresses in kPa at every public edge (MPa only inside, for
:class:`~bendpam.physics.material.MooneyRivlin`).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from bendpam.errors import FitError, InputError, ProcessingError
from bendpam.identify.diagnose import LIMITS, tension_identifiability
from bendpam.infra.atomic import json_safe
from bendpam.physics.material import MooneyRivlin, admissible_shape_range, within
from bendpam.validate import PLAUSIBLE, number, plausible

__all__ = [
    "DEFAULT_ADMISSIBLE_RANGE",
    "SHAPE_RESOLVED_FRACTION",
    "TensionData",
    "TensionFit",
    "fit_tension",
    "tension_data",
    "tension_from_test",
]

#: Principal stretches the bladder reaches in bending (a generous envelope).
DEFAULT_ADMISSIBLE_RANGE: tuple[float, float] = (0.6, 1.6)

#: The shape is identified when its 95 % interval spans at most this fraction of the
#: admissible width (``LIMITS.shape_resolved`` of :mod:`bendpam.identify.diagnose`).
SHAPE_RESOLVED_FRACTION = LIMITS.shape_resolved

_MIN_POINTS = 3  # informative points (stretch != 1) for two constants and a residual
_MIN_TEST_POINTS = 5
_MIN_TEST_STRETCH = 1.01


@dataclass(frozen=True)
class TensionFit:
    """Admissible Mooney-Rivlin constants fitted to uniaxial tension data (kPa).

    Attributes
    ----------
    C10_kpa, C01_kpa : float
        The constants, kPa.
    shear_modulus_kpa : float
        Initial shear modulus ``mu = 2 (C10 + C01)``, kPa (> 0).
    shape : float
        ``beta = C01 / (C10 + C01)``.
    shape_bounds : (float, float)
        The admissible shapes ``(beta_lo, beta_hi)`` the fit was confined to.
    shape_at_bound : bool
        True when the unconstrained fit lies outside ``shape_bounds`` (or has
        ``mu <= 0``) and the result sits on a bound: the constraint, not the data, then
        sets the shape.
    se_C10_kpa, se_C01_kpa, se_shear_modulus_kpa, se_shape : float
        Standard errors (module notes).
    correlation : float
        Correlation of the C10 and C01 estimates (near -1: only their sum is known).
    rmse_kpa : float
        Root-mean-square residual on the points used, kPa.
    nrmse : float
        ``rmse_kpa`` divided by the largest absolute stress used.
    n_points : int
        Points used (inside ``stretch_range``).
    stretch_min, stretch_max : float
        Smallest and largest stretch used.
    bounds_stretch_range : (float, float)
        The stretches ``shape_bounds`` hold over: the data's and ``admissible_range``,
        widened to contain 1.
    identifiable : str
        One sentence: the shear modulus is determined; the shape only when the curve can
        tell (or: it sits at a bound).
    source : str
        Where the data came from (file name), may be empty.

    Examples
    --------
    >>> lam = np.linspace(1.0, 2.0, 11)
    >>> fit = fit_tension(lam, MooneyRivlin(0.2, 0.1).uniaxial_nominal_stress(lam) * 1e3)
    >>> round(fit.shear_modulus_kpa, 6), round(fit.shape, 6), fit.n_points
    (600.0, 0.333333, 11)
    """

    C10_kpa: float
    C01_kpa: float
    shear_modulus_kpa: float
    shape: float
    shape_bounds: tuple[float, float]
    shape_at_bound: bool
    se_C10_kpa: float
    se_C01_kpa: float
    se_shear_modulus_kpa: float
    se_shape: float
    correlation: float
    rmse_kpa: float
    nrmse: float
    n_points: int
    stretch_min: float
    stretch_max: float
    bounds_stretch_range: tuple[float, float]
    identifiable: str
    source: str = ""

    def to_dict(self) -> dict[str, Any]:
        """The fields as plain JSON types (non-finite numbers become ``None``).

        Examples
        --------
        >>> import json
        >>> lam = np.linspace(1.0, 2.0, 11)
        >>> p_kpa = MooneyRivlin(0.2, 0.1).uniaxial_nominal_stress(lam) * 1e3
        >>> fit = fit_tension(lam, p_kpa)
        >>> d = json.loads(json.dumps(fit.to_dict(), allow_nan=False))
        >>> [round(b, 4) for b in d["shape_bounds"]], d["shape_at_bound"]
        ([-0.1489, 1.0667], False)
        """
        return json_safe(asdict(self))

    def material(self) -> MooneyRivlin:
        """The fitted law as a :class:`~bendpam.physics.material.MooneyRivlin` (MPa).

        Examples
        --------
        >>> lam = np.linspace(1.0, 2.0, 11)
        >>> p_kpa = MooneyRivlin(0.2, 0.1).uniaxial_nominal_stress(lam) * 1e3
        >>> fit = fit_tension(lam, p_kpa)
        >>> m = fit.material()
        >>> round(m.C10, 9), round(m.C01, 9)
        (0.2, 0.1)
        """
        return MooneyRivlin(self.C10_kpa * 1e-3, self.C01_kpa * 1e-3)

    def predict(self, stretch: ArrayLike) -> np.ndarray:
        """Uniaxial nominal stress at ``stretch``, kPa.

        Examples
        --------
        >>> lam = np.linspace(1.0, 2.0, 11)
        >>> p_kpa = MooneyRivlin(0.2, 0.1).uniaxial_nominal_stress(lam) * 1e3
        >>> fit = fit_tension(lam, p_kpa)
        >>> round(float(fit.predict(1.5)), 6)  # 2 (1.5 - 1/2.25)(200 + 100/1.5) kPa
        562.962963
        """
        return np.asarray(self.material().uniaxial_nominal_stress(stretch)) * 1e3


def _pair(name: str, value: Any) -> tuple[float, float]:
    """A validated ``(lo, hi)`` stretch pair with ``0 < lo < hi``."""
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise InputError(
            f"{name} = {value!r} is not a pair (lo, hi) of stretches"
        ) from None
    if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 < lo < hi):
        raise InputError(
            f"{name} = ({lo:g}, {hi:g}) is not a valid stretch range; "
            "expected finite 0 < lo < hi"
        )
    return lo, hi


def _column(name: str, value: Any, unit: str) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name} is not numeric ({unit} expected)") from None
    if arr.ndim != 1:
        raise InputError(f"{name} must be one-dimensional, got shape {arr.shape}")
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        i = int(bad[0])
        v = float(arr[i])
        raise InputError(f"{name} has a non-finite value {v!r} at index {i}")
    return arr


def fit_tension(
    stretch: ArrayLike,
    nominal_stress_kpa: ArrayLike,
    *,
    stretch_range: tuple[float, float] | None = None,
    admissible_range: tuple[float, float] | None = DEFAULT_ADMISSIBLE_RANGE,
    source: str = "",
) -> TensionFit:
    """Fit admissible Mooney-Rivlin constants to uniaxial nominal stress data.

    Parameters
    ----------
    stretch : array_like
        Stretches ``l = L / L0`` (> 0), one-dimensional.
    nominal_stress_kpa : array_like
        Nominal stresses ``F / A0`` in kPa, same length.
    stretch_range : (float, float), optional
        Use only points with ``lo <= stretch <= hi`` (default: all).
    admissible_range : (float, float) or None
        Principal stretches the constants must be physical for besides the data's
        (default the bladder's 0.6 to 1.6); ``None``: the data's alone.
    source : str
        Recorded in the result (a file name, say).

    Returns
    -------
    TensionFit
        The constrained least-squares constants with standard errors (module notes).

    Raises
    ------
    InputError
        Non-numeric, non-finite or mismatched arrays, a stretch <= 0 or > 20, a stress beyond
        100 MPa (a unit mistake), a bad range, or fewer than 3 points with stretch != 1.
    FitError
        No positive shear modulus fits, or the constants are beyond a rubber's (|C10|, |C01| <= 100 MPa).

    Examples
    --------
    >>> lam = np.linspace(1.0, 2.0, 11)
    >>> p_kpa = MooneyRivlin(0.2, 0.1).uniaxial_nominal_stress(lam) * 1e3
    >>> fit = fit_tension(lam, p_kpa)
    >>> round(fit.C10_kpa, 6), round(fit.C01_kpa, 6), fit.shape_at_bound
    (200.0, 100.0, False)
    """
    lam, p_kpa = _points(stretch, nominal_stress_kpa, stretch_range, source)
    span = _bounds_span(lam, admissible_range)
    b_lo, b_hi = admissible_shape_range(*span)

    # basis for x = (mu, mu*beta) in kPa: P = x0 g1 + x1 g2
    g1 = lam - lam**-2
    g2 = g1 * (1.0 / lam - 1.0)
    x, at_bound, x_free = _cone_lstsq(g1, g2, p_kpa, b_lo, b_hi)
    mu = float(x[0])
    if not mu > 0.0:
        raise FitError(
            f"{source or 'tension data'}: no positive shear modulus fits: the nominal "
            f"stress does not rise with stretch on the {lam.size} points used"
        )
    beta = float(x[1]) / mu
    c10, c01 = 0.5 * mu * (1.0 - beta), 0.5 * mu * beta
    _plausible_constants(c10, c01, source or "tension data")
    resid = p_kpa - (c10 * 2.0 * g1 + c01 * 2.0 * g1 / lam)
    rss = float(resid @ resid)
    rmse = math.sqrt(rss / lam.size)
    pmax = float(np.max(np.abs(p_kpa)))
    se10, se01, corr, se_mu, se_beta = _uncertainty(lam, g1, rss, c10, c01)
    mu_free = float(x_free[0])
    beta_free = float(x_free[1]) / mu_free if mu_free != 0.0 else math.nan
    sentence = tension_identifiability(mu, se_mu, beta, se_beta, corr, (b_lo, b_hi), span,
                                       at_bound, mu_free, beta_free)
    return TensionFit(
        C10_kpa=c10, C01_kpa=c01, shear_modulus_kpa=mu, shape=beta,
        shape_bounds=(float(b_lo), float(b_hi)), shape_at_bound=at_bound,
        se_C10_kpa=se10, se_C01_kpa=se01, se_shear_modulus_kpa=se_mu, se_shape=se_beta,
        correlation=corr, rmse_kpa=rmse, nrmse=rmse / pmax if pmax > 0 else math.nan,
        n_points=int(lam.size), stretch_min=float(lam.min()),
        stretch_max=float(lam.max()),
        bounds_stretch_range=span, identifiable=sentence, source=source,
    )


def _points(stretch: ArrayLike, nominal_stress_kpa: ArrayLike, stretch_range, source: str
            ) -> tuple[np.ndarray, np.ndarray]:
    """The validated points of :func:`fit_tension` inside ``stretch_range``: ``(stretch, stress in kPa)``."""
    lam = _column("stretch", stretch, "a stretch")
    p_kpa = _column("nominal_stress_kpa", nominal_stress_kpa, "kPa")
    if lam.size != p_kpa.size:
        raise InputError(
            f"stretch has {lam.size} values but nominal_stress_kpa has {p_kpa.size}"
        )
    if lam.size and float(lam.min()) <= 0.0:
        i = int(np.argmin(lam))
        raise InputError(f"stretch = {lam[i]:g} at index {i} is not > 0")
    plausible("stretch", lam, indexed=True)
    plausible("nominal_stress_kpa", p_kpa, indexed=True)
    if stretch_range is not None:
        lo, hi = _pair("stretch_range", stretch_range)
        keep = (lam >= lo) & (lam <= hi)
        lam, p_kpa = lam[keep], p_kpa[keep]
    where = f" inside stretch_range {tuple(stretch_range)}" if stretch_range else ""
    n_info = int(np.count_nonzero(np.abs(lam - 1.0) > 1e-6))
    if n_info < _MIN_POINTS:
        raise InputError(
            f"{source or 'tension data'}: {n_info} point(s) with stretch != 1{where}; "
            f"a fit of C10 and C01 needs at least {_MIN_POINTS}"
        )
    return lam, p_kpa


def _plausible_constants(c10: float, c01: float, source: str) -> None:
    """A :class:`FitError` when the fitted constants are beyond a rubber's (:data:`bendpam.validate.PLAUSIBLE`)."""
    for name, value in (("C10_kpa", c10), ("C01_kpa", c01)):
        b = PLAUSIBLE[name]
        if not b.lo <= value <= b.hi:
            raise FitError(f"{source}: the fitted {name} = {value:.4g} kPa is beyond the plausible range "
                           f"[{b.lo:g}, {b.hi:g}] kPa ({b.reason}); are the stresses in kPa and the stretches "
                           "L/L0 (not strains)?")


def _bounds_span(lam: np.ndarray, admissible_range) -> tuple[float, float]:
    """The stretches the admissible shapes must hold over: the data's, ``admissible_range`` and 1."""
    span = (float(lam.min()), float(lam.max()))
    if admissible_range is not None:
        a_lo, a_hi = _pair("admissible_range", admissible_range)
        span = (min(span[0], a_lo), max(span[1], a_hi))
    return (min(span[0], 1.0), max(span[1], 1.0))


def _cone_lstsq(
    g1: np.ndarray, g2: np.ndarray, p: np.ndarray, b_lo: float, b_hi: float
) -> tuple[np.ndarray, bool, np.ndarray]:
    """``min |x0 g1 + x1 g2 - p|`` over ``b_lo x0 <= x1 <= b_hi x0`` (so ``x0 >= 0``).

    Returns the optimum, whether it lies on an edge of the cone, and the unconstrained
    optimum.
    """
    X = np.column_stack([g1, g2])
    x_free = np.linalg.lstsq(X, p, rcond=None)[0]
    if x_free[0] > 0.0 and within(float(x_free[1] / x_free[0]), b_lo, b_hi):
        return x_free, False, x_free
    best = np.zeros(2)
    best_rss = float(p @ p)  # the apex x = 0
    for b in (b_lo, b_hi):
        h = g1 + b * g2
        hh = float(h @ h)
        mu = max(0.0, float(h @ p) / hh) if hh > 0.0 else 0.0
        r = p - mu * h
        rss = float(r @ r)
        if rss < best_rss:
            best, best_rss = np.array([mu, mu * b]), rss
    return best, True, x_free


def _uncertainty(
    lam: np.ndarray, g1: np.ndarray, rss: float, c10: float, c01: float
) -> tuple[float, float, float, float, float]:
    """Standard errors of C10, C01 (kPa), their correlation, and those of mu, beta."""
    X = np.column_stack([2.0 * g1, 2.0 * g1 / lam])  # P = C10 X0 + C01 X1
    dof = lam.size - 2
    try:
        cov = np.linalg.inv(X.T @ X) * (rss / dof)
    except np.linalg.LinAlgError:
        nan = math.nan
        return nan, nan, nan, nan, nan
    v10, v01, c = float(cov[0, 0]), float(cov[1, 1]), float(cov[0, 1])
    se10, se01 = math.sqrt(max(v10, 0.0)), math.sqrt(max(v01, 0.0))
    corr = c / (se10 * se01) if se10 > 0 and se01 > 0 else math.nan
    se_mu = 2.0 * math.sqrt(max(v10 + v01 + 2.0 * c, 0.0))
    s = c10 + c01
    grad = np.array([-c01 / s**2, c10 / s**2])  # d beta / d(C10, C01)
    se_beta = math.sqrt(max(float(grad @ cov @ grad), 0.0))
    return se10, se01, corr, se_mu, se_beta


@dataclass(frozen=True)
class TensionData:
    """The points of a uniaxial tension test the fits use (the loading branch, in the stretch range).

    Attributes
    ----------
    stretch : np.ndarray
        Stretches ``l = L / L0``.
    nominal_stress_kpa : np.ndarray
        Nominal stresses, kPa.
    source : str
        Where they came from (file name), may be empty.

    Examples
    --------
    >>> td = TensionData(np.array([1.0, 1.5, 2.0]), np.array([0.0, 350.0, 600.0]), "t.csv")
    >>> td.stretch.size, td.source
    (3, 't.csv')
    """

    stretch: np.ndarray
    nominal_stress_kpa: np.ndarray
    source: str = ""


def tension_data(
    raw: Any,
    *,
    gauge_length_mm: float,
    area_mm2: float,
    stretch_range: tuple[float, float] | None = None,
) -> TensionData:
    """The loading branch of a raw tension-test export as stretches and nominal stresses.

    Stretch ``1 + stroke / gauge_length_mm`` (stroke relative to the first sample) and nominal
    stress ``force / area_mm2`` (N/mm^2, reported in kPa).  A machine that records tension as
    negative force or stroke is handled by flipping the sign of a column whose median is negative.

    Only the first loading branch, from the start to the maximum stretch, is used: that is the
    elastic response the Mooney-Rivlin law stands for.  The unloading branch lies below it
    (hysteresis, Mullins softening, relaxation during a hold), so fitting both would average two
    different curves, and anything after the maximum (unloading, further cycles) is dropped.

    Parameters
    ----------
    raw : bendpam.lab.RawTest
        The test; ``raw.data`` has columns ``time_s``, ``stroke_mm``, ``force_n``.
    gauge_length_mm : float
        Initial gauge length, mm (> 0).
    area_mm2 : float
        Initial cross-section of the specimen, mm^2 (> 0).
    stretch_range : (float, float), optional
        Keep only points with ``lo <= stretch <= hi``.

    Returns
    -------
    TensionData
        With ``source`` the file name.

    Raises
    ------
    InputError
        A non-positive or non-finite ``gauge_length_mm`` or ``area_mm2``, a bad ``stretch_range``.
    ProcessingError
        Fewer than 5 samples on the loading branch, or no stretch above 1.01.

    Examples
    --------
    >>> import pandas as pd
    >>> from pathlib import Path
    >>> from bendpam.lab import RawTest
    >>> df = pd.DataFrame({"time_s": [0, 1, 2, 3, 4, 5], "stroke_mm": [0, 2, 4, 6, 8, 4],
    ...                    "force_n": [0, 1, 2, 3, 4, 1]})
    >>> td = tension_data(RawTest(df, Path("t.csv"), "csv"), gauge_length_mm=20, area_mm2=2)
    >>> td.stretch.tolist(), td.nominal_stress_kpa.tolist()
    ([1.0, 1.1, 1.2, 1.3, 1.4], [0.0, 500.0, 1000.0, 1500.0, 2000.0])
    """
    gauge = _positive("gauge_length_mm", gauge_length_mm, "mm")
    area = _positive("area_mm2", area_mm2, "mm^2")
    name = str(getattr(raw, "path", "") or "tension test")
    ext, force = _loading_branch(raw, name)
    lam = 1.0 + ext / gauge
    if float(lam.max()) <= _MIN_TEST_STRETCH:
        raise ProcessingError(
            f"{name}: the largest stretch is {float(lam.max()):.5g} (stroke "
            f"{float(ext.max()):.4g} mm on a {gauge:g} mm gauge); a tension fit needs "
            f"a stretch above {_MIN_TEST_STRETCH:g}"
        )
    stress = force / area * 1e3
    if stretch_range is not None:
        lo, hi = _pair("stretch_range", stretch_range)
        keep = (lam >= lo) & (lam <= hi)
        lam, stress = lam[keep], stress[keep]
    return TensionData(lam, stress, name)


def _loading_branch(raw: Any, name: str) -> tuple[np.ndarray, np.ndarray]:
    """Extension (mm, from the first sample) and force (N) up to the maximum extension, tension positive."""
    stroke = np.asarray(raw.data["stroke_mm"], dtype=float)
    force = np.asarray(raw.data["force_n"], dtype=float)
    if stroke.size == 0:
        raise ProcessingError(f"{name}: no samples; a tension fit needs at least "
                              f"{_MIN_TEST_POINTS} on the loading branch")
    ext = stroke - stroke[0]
    if np.median(ext) < 0:
        ext = -ext
    if np.median(force) < 0:
        force = -force
    i = int(np.argmax(ext))
    ext, force = ext[: i + 1], force[: i + 1]
    if ext.size < _MIN_TEST_POINTS:
        raise ProcessingError(
            f"{name}: {ext.size} sample(s) up to the maximum stretch; a tension fit "
            f"needs at least {_MIN_TEST_POINTS} on the loading branch"
        )
    return ext, force


def tension_from_test(
    raw: Any,
    *,
    gauge_length_mm: float,
    area_mm2: float,
    stretch_range: tuple[float, float] | None = None,
    admissible_range: tuple[float, float] | None = DEFAULT_ADMISSIBLE_RANGE,
) -> TensionFit:
    """Fit a raw tension-test export (:class:`~bendpam.lab.RawTest`).

    The loading branch of :func:`tension_data` through :func:`fit_tension`.

    Parameters
    ----------
    raw : bendpam.lab.RawTest
        The test; ``raw.data`` has columns ``time_s``, ``stroke_mm``, ``force_n``.
    gauge_length_mm : float
        Initial gauge length, mm (> 0).
    area_mm2 : float
        Initial cross-section of the specimen, mm^2 (> 0).
    stretch_range, admissible_range : optional
        Passed to :func:`fit_tension`.

    Returns
    -------
    TensionFit
        With ``source`` the file name.

    Raises
    ------
    InputError
        A non-positive or non-finite ``gauge_length_mm`` or ``area_mm2``.
    ProcessingError
        Fewer than 5 samples on the loading branch, or no stretch above 1.01.

    Examples
    --------
    >>> import pandas as pd
    >>> from pathlib import Path
    >>> from bendpam.lab import RawTest
    >>> lam = np.linspace(1.0, 2.0, 21)
    >>> force = MooneyRivlin(0.2, 0.1).uniaxial_nominal_stress(lam) * 2.0   # N, 2 mm^2
    >>> df = pd.DataFrame({"time_s": lam, "stroke_mm": (lam - 1) * 20,
    ...                    "force_n": force})
    >>> fit = tension_from_test(RawTest(df, Path("t.csv"), "csv"), gauge_length_mm=20,
    ...                         area_mm2=2)
    >>> round(fit.C10_kpa, 6), round(fit.C01_kpa, 6), fit.n_points
    (200.0, 100.0, 21)
    """
    td = tension_data(raw, gauge_length_mm=gauge_length_mm, area_mm2=area_mm2)
    return fit_tension(td.stretch, td.nominal_stress_kpa, stretch_range=stretch_range,
                       admissible_range=admissible_range, source=td.source)


def _positive(name: str, value: Any, unit: str) -> float:
    return number(name, value, 0.0, lo_open=True, unit=unit)
