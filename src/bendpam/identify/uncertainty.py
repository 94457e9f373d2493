"""Uncertainty of an identification: the sandwich covariance and what follows from it.

The weights of the fit normalise each curve (eq 53); they are not inverse noise variances.  So
:func:`sandwich_covariance` gives each residual group (a curve, a branch, the tension test) its own
variance, inflated for the lag-1 autocorrelation of its residuals
(:func:`lag1_autocorrelation`).  Where a test has two cycles or more, its groups' part comes from
resampling its cycles instead (a block bootstrap over cycles, through the linearised fit; its
covariance is computed exactly rather than from random resamples): noise that is not white,
slow drifts and creep from cycle to cycle widen it as they widen the seed-to-seed spread, while
the model's own misfit, the same in every cycle, does not.  That misfit is answered twice: by the
ensemble of loop laws (:mod:`bendpam.identify.ensemble`), and, where a curve's residuals exceed what
the cycles' scatter explains (a lack-of-fit test against the cycles as replicates), by treating that
excess as correlated noise (:func:`sandwich_covariance`).  :class:`Uncertainty` holds the covariance of
the varied parameters in their units, statistical and systematic; :func:`material_fit` propagates
it to the bladder's shear modulus and shape.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from bendpam.errors import FitError
from bendpam.identify.diagnose import shape_identified, study_coverage
from bendpam.identify.result import MaterialFit
from bendpam.physics.actuator import Actuator

__all__ = ["Instrument", "Uncertainty", "instrument_covariance", "lack_of_fit", "lag1_autocorrelation",
           "material_fit", "material_gradients", "offset_shift", "sandwich_covariance"]


class Uncertainty:
    """Covariance of the varied parameters (user units) with flags; a systematic term can be added.

    Parameters
    ----------
    values : every fitted value, by short name.
    names : the varied parameters, in the order of ``cov``.
    cov : their statistical covariance.
    rho : mean lag-1 autocorrelation of the residuals.
    nfev : model evaluations spent on it.
    at_bound : the search's variables at a bound (:func:`bendpam.identify.diagnose.at_bounds`), by name.
    ssr, m : weighted sum of squares and number of residuals.
    corr_flag : |correlation| above which a pair is flagged.

    Examples
    --------
    >>> unc = Uncertainty({"C10": 100.0, "C01": 300.0}, ["C10", "C01"], np.array([[4.0, -5.0], [-5.0, 9.0]]),
    ...                   0.1, 0, {}, 1e-3, 40, 0.95)
    >>> unc.sd.tolist(), round(float(unc.corr[0, 1]), 3)
    ([2.0, 3.0], -0.833)
    >>> unc.set_systematic(np.diag([12.0, 0.0]))   # 12 kPa^2 more variance of C10
    >>> unc.sd.tolist(), unc.sd_stat.tolist()
    ([4.0, 3.0], [2.0, 3.0])
    """

    def __init__(self, values, names, cov, rho, nfev, at_bound, ssr, m, corr_flag):
        self.corr_flag = corr_flag
        self.values = values
        self.names = names
        self.cov_stat = cov
        self.cov_sys = np.zeros_like(cov)
        self.cov_inst = np.zeros_like(cov)
        self.rho = rho
        self.nfev = nfev
        self.at_bound = at_bound
        self.ssr = ssr
        self.m = m
        self.drift_shift: dict[str, float] = {}

    def set_drift_shift(self, shift: np.ndarray) -> None:
        """Keep how far correcting an uncorrected drift would move the parameters (``shift`` in the order of
        ``names``, :func:`offset_shift`): ``alpha0_deg`` and ``shear_modulus_kpa`` (``2 (C10 + C01)``), by field.

        >>> unc = Uncertainty({}, ["alpha0", "C10", "C01"], np.eye(3), 0.0, 0, {}, 0.0, 40, 0.95)
        >>> unc.set_drift_shift(np.array([0.1, 2.0, -0.5]))
        >>> unc.drift_shift
        {'alpha0_deg': 0.1, 'shear_modulus_kpa': 3.0}
        """
        by = dict(zip(self.names, (float(x) for x in shift), strict=True))
        if not any(by.values()):
            self.drift_shift = {}
            return
        out = {"alpha0_deg": by["alpha0"]} if "alpha0" in by else {}
        if "C10" in by or "C01" in by:
            out["shear_modulus_kpa"] = 2.0 * (by.get("C10", 0.0) + by.get("C01", 0.0))
        self.drift_shift = out

    @property
    def cov(self) -> np.ndarray:
        """The covariance of the varied parameters: the statistical, systematic and instrument parts summed."""
        return self.cov_stat + self.cov_sys + self.cov_inst

    @property
    def sd(self) -> np.ndarray:
        """Standard errors of the varied parameters."""
        return np.sqrt(np.clip(np.diag(self.cov), 0.0, None))

    @property
    def sd_stat(self) -> np.ndarray:
        """The statistical part of the standard errors."""
        return np.sqrt(np.clip(np.diag(self.cov_stat), 0.0, None))

    @property
    def sd_sys(self) -> np.ndarray:
        """The systematic part of the standard errors."""
        return np.sqrt(np.clip(np.diag(self.cov_sys), 0.0, None))

    @property
    def corr(self) -> np.ndarray:
        """Their correlation matrix."""
        sd = self.sd
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.cov / np.outer(sd, sd)

    def average(self, idx, values, cov_stat, cov_sys) -> None:
        """Replace the values and the covariance of the parameters ``idx`` (positions in ``names``) by a model
        average's (:func:`bendpam.identify.ensemble.model_average`); the other parameters keep theirs.

        >>> unc = Uncertainty({"a": 1.0, "b": 2.0}, ["a", "b"], np.diag([1.0, 4.0]), 0.0, 0, {}, 0.0, 9, 0.95)
        >>> unc.average([0], np.array([1.5]), np.array([[2.0]]), np.array([[0.25]]))
        >>> unc.values, unc.sd.tolist(), unc.sd_sys.tolist()
        ({'a': 1.5, 'b': 2.0}, [1.5, 2.0], [0.5, 0.0])
        """
        ix = np.ix_(idx, idx)
        for j, v in zip(idx, values, strict=True):
            self.values[self.names[j]] = float(v)
        self.cov_stat = self.cov_stat.copy()
        self.cov_stat[ix] = cov_stat
        cov_s = np.zeros_like(self.cov_stat)
        cov_s[ix] = cov_sys
        self.set_systematic(cov_s)

    def set_systematic(self, cov_sys: np.ndarray) -> None:
        """The systematic covariance (the loop laws' spread, :mod:`bendpam.identify.ensemble`); ``cov`` is the sum."""
        self.cov_sys = np.asarray(cov_sys, dtype=float)

    def set_instrument(self, cov_inst: np.ndarray) -> None:
        """The instrument's declared calibration (:class:`Instrument`, :func:`instrument_covariance`); ``cov`` is
        the sum of the three parts.

        >>> unc = Uncertainty({"a": 1.0}, ["a"], np.array([[9.0]]), 0.0, 0, {}, 0.0, 9, 0.95)
        >>> unc.set_instrument(np.array([[16.0]]))
        >>> unc.sd.tolist(), unc.sd_stat.tolist()
        ([5.0], [3.0])
        """
        self.cov_inst = np.asarray(cov_inst, dtype=float)


@dataclass(frozen=True)
class Instrument:
    """The test rig's calibration, as standard uncertainties common to every test of a set (GUM type B).

    The curves cannot show a load cell that reads a fixed fraction high, or a gauge that reads every
    pressure a few kPa off: every test moves alike, and a fit takes it for the actuator.  Declared, each
    adds to the error bars what it would move the fitted parameters by (:func:`instrument_covariance`).

    force_uncertainty_pct : relative standard uncertainty of the force reading (%); a load cell of ISO
        7500-1 class 1 (within 1 % of the reading) has ``1 / sqrt(3) = 0.58`` %.
    pressure_uncertainty_kpa : standard uncertainty of the pressure the actuator was held at (kPa); a
        gauge within 0.5 % of a 600 kPa span has ``3 / sqrt(3) = 1.7`` kPa.
    zero_uncertainty_n : the load cell's zero is known (a tare with the fixture as tested, or its reading
        with the actuator unloaded): the standard uncertainty (N) of the force it reads with no load, 0 for
        exactly.  None (default): not known.  Declared, the fit's offset members that fit a zero offset are
        left out (:mod:`bendpam.identify.ensemble`) and this doubt takes their place.
    pressure_force_uncertainty_n_per_kpa : no force in proportion to the pressure reaches the load cell (a
        supply hose, a fitting's thrust) beyond this standard uncertainty (N/kPa), 0 for none.  None
        (default): not known.  Declared, the members that fit such a force are left out.

    >>> Instrument(force_uncertainty_pct=0.58).declared, Instrument().declared
    (True, False)
    >>> Instrument(0.58, 1.7).describe()
    'the force reading to 0.58 % and the pressure to 1.7 kPa (standard uncertainties, common to every test)'
    >>> Instrument(zero_uncertainty_n=0.01, pressure_force_uncertainty_n_per_kpa=0.0).offsets_declared
    ('F_off', 'F_P')
    """

    force_uncertainty_pct: float = 0.0
    pressure_uncertainty_kpa: float = 0.0
    zero_uncertainty_n: float | None = None
    pressure_force_uncertainty_n_per_kpa: float | None = None

    def __post_init__(self) -> None:
        from bendpam.validate import number

        object.__setattr__(self, "force_uncertainty_pct",
                           number("force_uncertainty_pct", self.force_uncertainty_pct, 0.0, 20.0, unit="%"))
        object.__setattr__(self, "pressure_uncertainty_kpa",
                           number("pressure_uncertainty_kpa", self.pressure_uncertainty_kpa, 0.0, 100.0, unit="kPa"))
        for name, hi, unit in (("zero_uncertainty_n", 1e4, "N"),
                               ("pressure_force_uncertainty_n_per_kpa", 10.0, "N/kPa")):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, number(name, getattr(self, name), 0.0, hi, unit=unit))

    @property
    def declared(self) -> bool:
        """Is any part declared (a calibration non-zero, or an offset known)?"""
        return self.force_uncertainty_pct > 0.0 or self.pressure_uncertainty_kpa > 0.0 or bool(self.offsets_declared)

    @property
    def offsets_declared(self) -> tuple[str, ...]:
        """The offset forces declared known, by their names in the fit (``"F_off"``, ``"F_P"``)."""
        return tuple(self.offset_uncertainties())

    def offset_uncertainties(self) -> dict[str, float]:
        """The declared offsets' standard uncertainties, by name (N for ``"F_off"``, N/kPa for ``"F_P"``)."""
        return {n: float(u) for n, u in (("F_off", self.zero_uncertainty_n),
                                         ("F_P", self.pressure_force_uncertainty_n_per_kpa)) if u is not None}

    def describe(self) -> str:
        """The declaration in words.

        >>> Instrument(zero_uncertainty_n=0.01, pressure_force_uncertainty_n_per_kpa=0.0).describe().split(" (")[0]
        "the load cell's zero to 0.01 N and no force in proportion to the pressure"
        """
        parts = ([f"the force reading to {self.force_uncertainty_pct:.3g} %"] if self.force_uncertainty_pct else []) + \
                ([f"the pressure to {self.pressure_uncertainty_kpa:.3g} kPa"] if self.pressure_uncertainty_kpa else [])
        if self.zero_uncertainty_n is not None:
            parts.append(f"the load cell's zero to {self.zero_uncertainty_n:.3g} N" if self.zero_uncertainty_n
                         else "the load cell's zero exactly")
        if self.pressure_force_uncertainty_n_per_kpa is not None:
            parts.append(f"a force in proportion to the pressure to {self.pressure_force_uncertainty_n_per_kpa:.3g} "
                         "N/kPa" if self.pressure_force_uncertainty_n_per_kpa
                         else "no force in proportion to the pressure")
        return " and ".join(parts) + " (standard uncertainties, common to every test)" if parts else "nothing"


def instrument_covariance(J: np.ndarray, force_rows: np.ndarray, pressure_rows: np.ndarray,
                          instrument: Instrument, offset_rows: dict[str, np.ndarray] | None = None) -> np.ndarray:
    """The covariance a declared calibration (:class:`Instrument`) adds to the parameters (linearised refits).

    A force reading high by a fraction ``e`` moves the weighted data by ``e * force_rows`` (``w M``, the
    weighted moments; zero on rows the load cell did not measure), a pressure off by ``p`` kPa moves the
    weighted residuals by ``p * pressure_rows`` (their change per kPa), a declared offset ``F`` (a zero, N; a
    force in proportion to the pressure, N/kPa) moves them by ``F * offset_rows[name]`` (its weighted moment per
    unit: eq 7's lever, times the pressure for ``"F_P"``); each moves the parameters by :func:`offset_shift`'s
    linearised refit, ``dx``, and adds ``u^2 dx dx^T`` (``u`` its standard uncertainty).

    >>> J = np.column_stack([np.ones(4), np.arange(4.0)])          # a line: offset and slope
    >>> y = np.array([1.0, 2.0, 3.0, 4.0])                          # data on y = 1 + x
    >>> cov = instrument_covariance(J, y, np.zeros(4), Instrument(force_uncertainty_pct=1.0))
    >>> np.sqrt(np.diag(cov)).round(6).tolist()                    # 1 % of the offset 1 and of the slope 1
    [0.01, 0.01]
    >>> zero = Instrument(zero_uncertainty_n=0.2)                   # a zero known to 0.2 N, on a lever of 3 mm
    >>> cov = instrument_covariance(J, y, np.zeros(4), zero, {"F_off": np.full(4, 3.0)})
    >>> np.sqrt(np.diag(cov)).round(6).tolist()                    # the offset by 0.6, the slope not at all
    [0.6, 0.0]
    """
    every = np.arange(J.shape[0])
    rows_of = offset_rows or {}
    parts = [(force_rows, instrument.force_uncertainty_pct / 100.0),
             (pressure_rows, instrument.pressure_uncertainty_kpa)]
    parts += [(rows_of[n], u) for n, u in instrument.offset_uncertainties().items() if n in rows_of]
    dxs = [offset_shift(J, [(every, u * np.asarray(rows, dtype=float))]) for rows, u in parts if u > 0.0]
    return sum((np.outer(dx, dx) for dx in dxs), np.zeros((J.shape[1], J.shape[1])))


def lack_of_fit(r: np.ndarray, cycles) -> float:
    """The residuals' sum of squares over their pure error, on the rows whose cycles are resampled.

    ``r``: weighted residuals; ``cycles``: ``(rows, U)`` with ``U`` the weighted deviation of each of a test's ``n``
    cycles from their mean (:func:`sandwich_covariance`).  The pure error, ``sum U^2 / (n (n - 1))``, is what the
    sum of squares of a model that fits to the noise would be; their ratio is about 1 then, and the misfit's
    share of the residuals is ``1 - 1 / ratio``.  NaN without cycles.

    >>> U = np.array([[0.1, -0.1], [-0.1, 0.1]])              # two cycles: pure error 2 * 0.02 / 2 = 0.02
    >>> round(lack_of_fit(np.array([0.1, 0.1]), [(np.arange(2), U)]), 9)   # a sum of squares of 0.02: all noise
    1.0
    >>> round(lack_of_fit(np.array([0.4, 0.2]), [(np.arange(2), U)]), 9)   # 0.2: ten times, 90 % misfit
    10.0
    """
    ssr = pe = 0.0
    for rows, U in cycles:
        ssr += float(np.sum(np.asarray(r)[rows] ** 2))
        pe += float(_pure_error(U).sum())
    return ssr / pe if pe > 0.0 else math.nan


def _pure_error(U: np.ndarray) -> np.ndarray:
    """Each row's pure error: the variance of its mean over the ``n`` cycles, ``sum_cycles U^2 / (n (n - 1))``
    (``U``: cycles x rows, each cycle's deviation from their mean)."""
    U = np.asarray(U, dtype=float)
    n = U.shape[0]
    return np.sum(U**2, axis=0) / (n * (n - 1))


def lag1_autocorrelation(resid: np.ndarray, seg: np.ndarray) -> float:
    """Lag-1 autocorrelation of residuals, pooled over the segments ``seg`` (each about its own mean).

    >>> lag1_autocorrelation(np.array([1.0, -1.0, 1.0, -1.0]), np.zeros(4, int))
    -0.75
    """
    num = den = 0.0
    for i in np.unique(seg):
        r = resid[seg == i]
        r = r - r.mean()
        num += float(r[1:] @ r[:-1])
        den += float(r @ r)
    return num / den if den > 0 else 0.0


def offset_shift(J: np.ndarray, shifts: Sequence[tuple[np.ndarray, float | np.ndarray]]) -> np.ndarray:
    """How far the parameters move when each group of rows of the data moves by a constant (linearised refit).

    With weighted residuals ``r = w (model - y)`` at the optimum (``J^T r = 0``), moving the data by ``dy``
    moves the optimum by ``dx = (J^T J)^-1 J^T (w dy)``.  ``shifts``: ``(rows, w dy)`` with ``w dy`` the
    weighted shift of those rows (a scalar times their weights, or an array); zero without any.

    >>> J = np.column_stack([np.ones(4), np.arange(4.0)])   # a line: offset and slope
    >>> offset_shift(J, [(np.arange(4), np.full(4, 0.5))]).round(12).tolist()   # all rows up by 0.5: offset only
    [0.5, 0.0]
    """
    b = np.zeros(J.shape[0])
    for rows, dy in shifts:
        b[rows] += dy
    if not np.any(b):
        return np.zeros(J.shape[1])
    return np.linalg.lstsq(J, b, rcond=None)[0]


def sandwich_covariance(J: np.ndarray, r: np.ndarray, groups: np.ndarray,
                        cycles: Sequence[tuple[np.ndarray, np.ndarray]] = (),
                        offsets: Sequence[tuple[np.ndarray, np.ndarray]] = ()) -> tuple[np.ndarray, float]:
    """``B^-1 (sum_g meat_g) B^-1`` with ``B = J^T J``, and the mean autocorrelation of the groups.

    A residual group ``g`` not covered by ``cycles`` contributes ``s_g^2 f_g J_g^T J_g``: its own
    variance ``s_g^2`` (its residuals' mean square, for the degrees of freedom left) and the inflation
    ``f_g = (1 + rho_g) / (1 - rho_g)`` for the lag-1 autocorrelation ``rho_g`` of its residuals
    (clipped to [0, 0.95]).  Each entry ``(rows, U)`` of ``cycles`` is one test: ``U`` (cycles x rows)
    the weighted deviation of each of its ``n`` cycles from their mean at the residual rows ``rows``.
    Resampling its cycles with replacement moves the weighted data by the mean of ``n`` resampled
    rows of ``U``, whose covariance (times ``n / (n - 1)`` for the resampling's bias) is
    ``U^T U / (n (n - 1))``: its meat is ``G^T G / (n (n - 1))``, ``G = U J_rows``, the exact
    covariance of the cycle bootstrap through the linearised fit, and it replaces the sandwich's
    meat for the groups it covers.  With few cycles that estimate is itself uncertain: it is scaled
    by ``(t_0.975(nu) / 1.96)^2``, ``nu = sum (n - 1)``, so that +-2 SE keep about 95 %.  The bootstrap
    sees the noise, not a misfit that repeats in every cycle: a covered group whose residuals' sum of
    squares ``SSR_g`` exceeds their pure error ``PE_g`` (the variance of its mean over the cycles,
    ``sum U^2 / (n (n - 1))`` over its rows; a lack-of-fit test against replicates) also contributes
    the sandwich's meat above times the misfit's share, ``1 - PE_g / SSR_g`` (0 where the model fits
    to the noise): the misfit beyond the cycles' scatter is treated as correlated noise.  Each entry
    ``(rows, u)`` of ``offsets`` is an offset common to the rows ``rows`` with weighted standard
    deviations ``u`` (the drift correction's doubt): meat ``g^T g``, ``g = u J_rows``.

    Parameters
    ----------
    J : Jacobian of the weighted residuals (rows: residuals, columns: parameters).
    r : the weighted residuals at the optimum.
    groups : the residual group of each row.
    cycles : the tests whose cycles are resampled (:func:`bendpam.identify.data.cycle_deviations`, weighted).
    offsets : offsets common to a test's rows (:func:`bendpam.identify.data.drift_offsets`, weighted).

    Returns
    -------
    (covariance, mean autocorrelation of the groups)

    Raises
    ------
    FitError
        The Jacobian is not finite: the data do not determine the parameters.

    Examples
    --------
    A straight line through four points, one group:

    >>> J = np.column_stack([np.ones(4), np.arange(4.0)])
    >>> cov, rho = sandwich_covariance(J, np.array([0.1, -0.1, -0.1, 0.1]), np.zeros(4, int))
    >>> cov.shape, rho
    ((2, 2), 0.0)

    A mean of two cycles that differ by +-1 at one point: the bootstrap's variance of the mean, 1, times
    ``(t_0.975(1) / 1.96)^2 = (12.71 / 1.96)^2 = 42.0`` for a single degree of freedom

    >>> one = np.ones((1, 1))
    >>> cov, _ = sandwich_covariance(one, np.zeros(1), np.zeros(1, int), [(np.array([0]), np.array([[-1.0], [1.0]]))])
    >>> cov.round(2)
    array([[42.03]])

    A line fitted to two cycles that agree (no pure error) but miss the data by a misfit the same in each:
    the bootstrap sees nothing, the misfit counts as noise

    >>> same = [(np.arange(4), np.zeros((2, 4)))]
    >>> r = np.array([0.1, -0.1, -0.1, 0.1])
    >>> cov, _ = sandwich_covariance(J, r, np.zeros(4, int), same)
    >>> bool(np.all(np.diag(cov) > 0)), np.allclose(cov, sandwich_covariance(J, r, np.zeros(4, int))[0])
    (True, True)
    """
    if not np.all(np.isfinite(J)):
        raise FitError("the data do not determine the parameters (the Jacobian is not finite at the optimum); "
                       "hold some of them fixed")
    meat, covered, pure = _cycle_meat(J, cycles)
    for rows, u in offsets:
        g = u @ J[rows]
        meat += np.outer(g, g)
    group_meat, rho = _group_meat(J, r, groups, covered, pure, 1.0 - J.shape[1] / max(r.size, 1))
    Binv = np.linalg.pinv(J.T @ J, rcond=1e-13)
    return Binv @ (meat + group_meat) @ Binv, rho


def _group_meat(J: np.ndarray, r: np.ndarray, groups: np.ndarray, covered: np.ndarray, pure: np.ndarray,
                share: float) -> tuple[np.ndarray, float]:
    """The residual groups' sandwich meat (:func:`sandwich_covariance`): each group's variance with its AR(1)
    inflation, times the misfit's share ``1 - PE_g / SSR_g`` where the cycle bootstrap covers it (1 where not);
    and the groups' mean lag-1 autocorrelation."""
    meat = np.zeros((J.shape[1], J.shape[1]))
    rhos = []
    for g in np.unique(groups):
        sel = groups == g
        ri = r[sel]
        rho_i = min(max(lag1_autocorrelation(ri, np.zeros(ri.size, int)), 0.0), 0.95)
        rhos.append(rho_i)
        ssr = float(ri @ ri)
        misfit = (max(0.0, 1.0 - float(pure[sel].sum()) / ssr) if ssr > 0.0 else 0.0) if covered[sel].all() else 1.0
        if misfit > 0.0:  # the residuals beyond the cycles' scatter (all of them where no cycles are resampled)
            var_i = ssr / max(share * ri.size, 1.0)
            meat += (J[sel].T @ J[sel]) * var_i * (1.0 + rho_i) / (1.0 - rho_i) * misfit
    return meat, (float(np.mean(rhos)) if rhos else 0.0)


def _cycle_meat(J: np.ndarray, cycles) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cycle bootstrap's meat, t-scaled (:func:`sandwich_covariance`), which rows it covers, and each row's pure
    error (the variance of its mean over the cycles, weighted)."""
    meat = np.zeros((J.shape[1], J.shape[1]))
    covered = np.zeros(J.shape[0], dtype=bool)
    pure = np.zeros(J.shape[0])
    dof = 0
    for rows, U in cycles:
        n = U.shape[0]
        G = U @ J[rows]
        meat += G.T @ G / (n * (n - 1))
        covered[rows] = True
        pure[rows] = _pure_error(U)
        dof += n - 1
    if dof:
        from scipy.special import stdtrit  # Student's t quantile (scipy.stats would cost 0.3 s to import)

        meat *= (float(stdtrit(dof, 0.975)) / 1.96) ** 2
    return meat, covered, pure


def material_fit(fitted: Actuator, unc: Uncertainty, shape_bounds, stretch, at_bound: bool, held: str,
                 free: list[str], *, joint: bool = False) -> MaterialFit | None:
    """The bladder's shear modulus ``2 (C10 + C01)`` and shape ``C01 / (C10 + C01)`` with their standard errors.

    By the delta method from ``unc``; None when neither constant is in ``free``.  ``shape_bounds``
    and ``stretch`` are the admissible shapes and the stretches they hold over, ``at_bound`` whether
    the shape sits on one of them, ``held`` why it was held fixed ("" if not).  A narrow interval
    of the shape is called determined only where the calibration study's coverage for it holds
    (:func:`~bendpam.identify.diagnose.study_coverage`), unless a tension test was fitted with the
    curves (``joint``), which the study does not cover.

    >>> import bendpam
    >>> act = bendpam.physics.presets.be_pam().replace(C10_kpa=100.0, C01_kpa=300.0)
    >>> unc = Uncertainty({}, ["C10", "C01"], np.array([[4.0, -5.0], [-5.0, 9.0]]), 0.0, 0, {}, 0.0, 40, 0.95)
    >>> mat = material_fit(act, unc, (-0.15, 1.07), (0.6, 1.6), False, "", ["C10", "C01"])
    >>> mat.shear_modulus_kpa, round(mat.se_shear_modulus_kpa, 3), mat.shape, mat.shape_narrow
    (800.0, 3.464, 0.75, True)
    """
    if "C10" not in free and "C01" not in free:
        return None
    c10, c01 = fitted.C10_kpa, fitted.C01_kpa
    S = c10 + c01
    g_mu, g_b = material_gradients(fitted, unc.names)
    se_mu = math.sqrt(max(float(g_mu @ unc.cov @ g_mu), 0.0))
    se_b = math.sqrt(max(float(g_b @ unc.cov @ g_b), 0.0))
    identified = shape_identified(se_b, shape_bounds, at_bound, held)
    why = ""
    if identified and not joint:
        identified, why = study_coverage()
    return MaterialFit(2.0 * S, se_mu, c01 / S, se_b, (float(shape_bounds[0]), float(shape_bounds[1])),
                       (float(stretch[0]), float(stretch[1])), bool(at_bound), identified, held, why)


def material_gradients(fitted: Actuator, names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """Gradients of the shear modulus ``2 (C10 + C01)`` and the shape ``C01 / (C10 + C01)`` in the varied ``names``.

    >>> import bendpam
    >>> act = bendpam.physics.presets.be_pam().replace(C10_kpa=100.0, C01_kpa=300.0)
    >>> [g.tolist() for g in material_gradients(act, ["alpha0", "C10", "C01"])]
    [[0.0, 2.0, 2.0], [0.0, -0.001875, 0.000625]]
    """
    c10, c01 = fitted.C10_kpa, fitted.C01_kpa
    S = c10 + c01
    g_mu = np.zeros(len(names))
    g_b = np.zeros(len(names))
    if "C10" in names:
        g_mu[names.index("C10")] = 2.0
        g_b[names.index("C10")] = -c01 / S**2
    if "C01" in names:
        g_mu[names.index("C01")] = 2.0
        g_b[names.index("C01")] = c10 / S**2
    return g_mu, g_b
