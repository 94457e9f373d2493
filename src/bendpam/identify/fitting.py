"""Parameter identification from processed cyclic tests (paper section 3.4, eq 53-55, Table 3).

:func:`fit` identifies any subset of alpha0, C10, C01, P_start, E_f and R0_start for either model
from all pressures at once, by default together with the actuator's friction loop.

Data and model (hysteresis-aware by default)
    When the tests show a loop (median energy-loss ratio above 1 %,
    :func:`~bendpam.identify.diagnose.has_loop`), both mean branches of every pressure are fitted
    with the loop model of :mod:`bendpam.physics.hysteresis`::

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

Uncertainty (both parts are reported separately: ``FitResult.uncertainty``)
    1. Statistical: a sandwich covariance ``B^-1 (sum meat) B^-1`` (:mod:`bendpam.identify.uncertainty`),
       ``B = J^T J``.  The meat of a test with two cycles or more is the exact covariance of
       resampling its cycles (a block bootstrap over cycles through the linearised fit, scaled for
       few cycles), plus, where a curve's residuals exceed the cycles' scatter (lack of fit against the
       cycles as replicates), that excess share of the sandwich's meat below (the misfit as correlated
       noise); that of a single-cycle test or a tension test is its residual variance ``s_g^2``
       inflated by ``f_g = (1 + rho_g) / (1 - rho_g)`` for the lag-1 autocorrelation of its
       residuals; a drift correction adds its own doubt as an offset.
    2. Systematic (the loop law): no law is known to be the actuator's.  The fit is repeated with
       every law of :data:`bendpam.physics.hysteresis.ENSEMBLE` (warm-started, the quasi-static
       parameters free as in the fit, some laws with parameters of their own), and once more the law of
       most weight with a load-cell zero offset (N) fitted too (every law, when that member takes most
       of the weight; not where its shape sits on a bound); the reported model parameters are the
       average over the members with Akaike weights (AICc on the residuals' effective number of points,
       bootstrapped over the residual groups), their covariance the unconditional one: the members' own
       covariances (statistical) and their spread about the average (systematic)
       (:mod:`bendpam.identify.ensemble`).
    3. Instrument (when declared, :class:`~bendpam.identify.uncertainty.Instrument`): a load cell's and a
       pressure gauge's calibration, each the linearised refit its error would make; a third part.
    4. The profile of alpha0 (the objective minimised over everything else, against alpha0) is
       kept in ``FitResult.alpha0_profile``.
    Pairs with ``|corr| > corr_flag`` are flagged, with the combination the data determine and
    their joint 95 % region (``FitResult.joint_intervals``); this and every other judgement of the
    fit (its flags and identifiability notes) are :mod:`bendpam.identify.diagnose`'s.

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

import copy
import dataclasses
import math
import time
from dataclasses import dataclass, field
from datetime import UTC, datetime

import numpy as np

from bendpam.errors import FitError, InputError
from bendpam.identify.data import (
    FitData,
    bladder_stretch_range,
    branch_data,
    cycle_deviations,
    drift_note,
    drift_offsets,
    fit_data,
    offset_modes,
)
from bendpam.identify.diagnose import (
    LIMITS,
    at_bounds,
    bound_flags,
    correlated_pairs,
    fit_flags,
    has_loop,
    identifiability,
)
from bendpam.identify.ensemble import (
    MEMBER_EXTRA,
    OFFSET_NOTE_WEIGHT,
    OFFSET_PARAMETERS,
    OFFSETS,
    SPAN_SCALED,
    MemberFit,
    group_ssr,
    member_weights,
    offset_average,
    offset_note,
    offset_widening,
    part_sds,
    spans_differ,
    uncertainty_budget,
    widening_note,
)
from bendpam.identify.metrics import score
from bendpam.identify.problem import Problem, Tension
from bendpam.identify.result import (
    HYST_PARAMETERS,
    PARAMETER_ORDER,
    PARAMETERS,
    FitResult,
    HysteresisFit,
    LossRatio,
    Parameter,
    Profile,
    UncertaintyBudget,
    parse_free,
)
from bendpam.identify.uncertainty import (
    Instrument,
    Uncertainty,
    instrument_covariance,
    lack_of_fit,
    material_fit,
    offset_shift,
    sandwich_covariance,
)
from bendpam.lab.processed import as_processed
from bendpam.physics.actuator import NEUTRAL_ANGLE_DEG, Actuator, FitIdentity
from bendpam.physics.braid import DEFAULT_ORDER
from bendpam.physics.law import MomentLaw
from bendpam.physics.material import admissible_shape_range
from bendpam.physics.models import resolve_model
from bendpam.validate import PLAUSIBLE
from bendpam.version import __version__

__all__ = ["PAPER_START", "fit"]

#: The paper's starting values of the identification (section 3.4, from its tension test), kPa.
PAPER_START = {"C10": 114.0, "C01": 300.0}
#: Loop angles (deg) of the global grid.
_THETA_GRID = np.geomspace(0.5, 40.0, 9)
#: Stretch margin over the tested curvatures for the admissible shapes.
_STRETCH_MARGIN = 1.1


def _default_bounds(actuator: Actuator, P_min_kpa: float) -> dict[str, tuple[float, float]]:
    a0 = actuator.alpha0_deg
    angles, moduli = PLAUSIBLE["alpha0_deg"], PLAUSIBLE["frame_modulus_mpa"]  # within the plausible ranges
    lo, hi = max(0.9 * a0, angles.lo), min(1.1 * a0, angles.hi)
    if actuator.bend_sign > 0:
        lo = max(lo, NEUTRAL_ANGLE_DEG + 0.05)
    elif actuator.bend_sign < 0:
        hi = min(hi, NEUTRAL_ANGLE_DEG - 0.05)
    return {
        "alpha0": (lo, hi),
        "C10": (-5000.0, 5000.0),
        "C01": (-5000.0, 5000.0),
        "P_start": (0.0, 0.98 * P_min_kpa),
        "E_f": (max(0.1 * actuator.frame_modulus_mpa, moduli.lo), min(10.0 * actuator.frame_modulus_mpa, moduli.hi)),
        "R0_start": (actuator.R0_mm, 1.5 * actuator.R0_mm),
    }



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


def fit(processed, actuator: Actuator, model: str | None = None, free=("alpha0", "C10", "C01"), *,
        bounds: dict[str, tuple[float, float]] | None = None, tension=None, tension_data=None,
        order: int = DEFAULT_ORDER, eq19_factor: bool = True, grid_alpha: int = 41, grid_r0: int = 9,
        corr_flag: float = LIMITS.correlation,
        fit_range: str = "developed", hysteresis: str | None = "auto", hysteresis_law: str = "pi",
        law_uncertainty: bool = True, admissible_range: tuple[float, float] | None = (0.6, 1.6),
        profile_points: int = 13, instrument: Instrument | None = None) -> FitResult:
    """Identify ``free`` parameters of ``actuator`` for ``model`` from a processed test set.

    The stages (module notes): the data and the admissible shapes, a global grid and a local search
    on the projected problem, the fold rule, the joint fit with a tension test, the uncertainty
    (statistical and the loop law's systematic part), the profile of alpha0, and the result.

    Parameters
    ----------
    processed : :class:`bendpam.lab.processing.ProcessedSet`, or the folder it was written to (str or Path).
    actuator : the nominal actuator (geometry, and the values of the parameters held fixed).
    model : ``"energy"``, ``"force_balance"`` or None (default): the start actuator's own model (energy when
        unknown).  Fitting the other model from its constants is deliberate and does not warn.
    free : names among alpha0, C10, C01, P_start, E_f, R0_start (aliases such as ``alpha0_deg`` work).
    bounds : overrides of the default bounds, ``{name: (lo, hi)}`` in the parameter's unit;
        ``"shape"`` narrows the admissible shapes C01/(C10 + C01).
    tension : a :class:`~bendpam.identify.tension.TensionFit`; its ``C10_kpa`` and ``C01_kpa`` replace the
        actuator's before fitting (the values of constants held fixed).
    tension_data : a :class:`~bendpam.identify.tension.TensionData` (the bladder's tension test): fitted
        together with the bending curves (module notes) when C10 or C01 is free.
    fit_range : without a loop model, ``"developed"`` (default) fits each mean curve where the loop
        is developed (:func:`~bendpam.identify.data.developed_range`), ``"all"`` every point (the paper).
    hysteresis : ``"auto"`` (default): both branches with the loop model when the tests show a loop
        (:func:`~bendpam.identify.diagnose.has_loop`), else the mean curves; a law name (``"pi"``,
        ``"dahl"``) forces the loop model; ``None`` fits the mean curves (the paper's way).
    hysteresis_law : the law of ``"auto"`` (``"pi"``: Prandtl-Ishlinskii, or ``"dahl"``).  With a
        free P_start the loop's amplitude ``a0 + a1 (P - P_start)`` uses the nominal P_start (the
        amplitude stays linear in a0, a1); the fitted loop is saved with the fitted one.
    law_uncertainty : with a loop, the ensemble of loop laws' systematic part (:mod:`bendpam.identify.ensemble`).
    admissible_range : stretches (lo, hi) the material must be physical over besides the tested ones (or None).
    profile_points : points of the profile of alpha0 (0: none).
    instrument : a declared calibration of the rig (:class:`~bendpam.identify.uncertainty.Instrument`), or None.

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
    Virtual tests of the paper's BE-PAM (alpha0 = 69.7 deg; coarse, without a loop), processed and fitted:

    >>> from pathlib import Path
    >>> import bendpam
    >>> from bendpam.lab import RawTest, processing, simulate
    >>> be, settings = bendpam.physics.presets.be_pam(), simulate.SimulationSettings(cycles=1, rate_hz=2.0,
    ...                                                                              hysteresis=0.0, seed=1)
    >>> raws = [RawTest(simulate.simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv",
    ...                 pressure_kpa=p) for p in (100.0, 200.0)]
    >>> processed = processing.process_tests(raws, keep_series=False, options=processing.ProcessingOptions(
    ...                                                                                    grid_points=21))
    >>> result = fit(processed, be)
    >>> result.converged, abs(result.actuator.alpha0_deg - 69.7) < 0.5
    (True, True)
    """
    t0 = time.perf_counter()
    model = resolve_model(actuator, model, warn=False)  # fitting another model from these constants is deliberate
    free = parse_free(free)
    if tension is not None:
        actuator = actuator.replace(C10_kpa=tension.C10_kpa, C01_kpa=tension.C01_kpa)
    processed = as_processed(processed)  # a ProcessedSet, or the folder it was written to
    run = _prepare(processed, actuator, model, free, bounds, tension_data, fit_range, hysteresis, hysteresis_law,
                   admissible_range, order, eq19_factor)
    _search_stages(run, grid_alpha, grid_r0, tension_data)
    unc, budget = _uncertainty_stages(run, corr_flag, law_uncertainty, instrument)
    profile, n = _profile(run.prob, run.bnd, run.nl, unc, profile_points)
    run.nfev += n
    return _result(processed, actuator, run, unc, tension, t0, budget, profile, hysteresis)


@dataclass
class _Run:
    """One identification as its stages go (:func:`fit`): the problem, the solution so far, the notes."""

    args: tuple  # Problem's: actuator, data, model, free, bounds, order, eq19_factor, law, shape bounds
    stretch: tuple[float, float]  # the stretches the admissible shapes hold over
    prob: Problem
    nl: dict[str, float] = field(default_factory=dict)  # the nonlinear parameters
    lin: np.ndarray = field(default_factory=lambda: np.zeros(0))  # the linear ones (internal coordinates)
    converged: bool = True
    message: str = ""
    nfev: int = 0
    notes: list[str] = field(default_factory=list)
    shape_held: str = ""
    cycles: list = field(default_factory=list)  # the tests whose cycles are resampled (data.cycle_deviations)
    offsets: list = field(default_factory=list)  # the drift corrections' doubt (data.drift_offsets)

    @property
    def bnd(self) -> dict[str, tuple[float, float]]:
        return self.args[4]

    @property
    def law(self) -> str | None:
        return self.args[7]


def _prepare(processed, actuator: Actuator, model: str, free: list[str], bounds, tension_data, fit_range: str,
             hysteresis, hysteresis_law: str, admissible_range, order: int, eq19_factor: bool) -> _Run:
    """The data, the bounds and the admissible shapes: the problem to solve."""
    law = _loop_law(hysteresis, hysteresis_law, processed)
    d = branch_data(processed, actuator.L0_mm) if law else fit_data(processed, fit_range)
    bnd = _bounds(actuator, d, bounds)
    if "P_start" not in free and actuator.P_start_kpa >= d.P.min():
        raise InputError(
            f"P_start = {actuator.P_start_kpa:g} kPa is not below the lowest test pressure {d.P.min():g} kPa")
    stretch = _stretch_range(actuator, d, admissible_range, tension_data)
    shape_bounds = _shape_bounds(stretch, bounds)
    args = (actuator, d, model, free, bnd, order, eq19_factor, law, shape_bounds)
    return _Run(args, stretch, Problem(*args), cycles=cycle_deviations(processed, d),
                offsets=drift_offsets(processed, d))


def _search_stages(run: _Run, grid_alpha: int, grid_r0: int, tension_data) -> None:
    """The global grid, the local search, the fold rule and the joint fit with a tension test."""
    prob, d, bnd = run.prob, run.args[1], run.bnd
    step = max(1, d.kc.size // 400)  # the grid only has to find the basin: about 400 points suffice
    coarse = Problem(run.args[0], d.thin(step), *run.args[2:]) if step > 1 else prob
    best, nfev = _start(coarse, bnd, grid_alpha, grid_r0)
    nl, lin, run.converged, run.message, n = _solve(prob, bnd, 0, 0, start=best[1])
    run.nfev += nfev + n
    prob, nl, lin, n, fold_note, run.shape_held = _fold_rule(prob, run.args, bnd, nl, lin, float(d.P.max()))
    run.nfev += n
    if fold_note:
        run.notes.append(fold_note)
    if tension_data is not None and {"C10", "C01"} & set(run.args[3]):
        prob, nl, lin, n, note = _joint_tension(prob, run.args, bnd, nl, lin, tension_data)
        run.nfev += n
        run.notes.append(note)
    run.prob, run.nl, run.lin = prob, nl, lin


def _uncertainty_stages(run: _Run, corr_flag: float, law_uncertainty: bool, instrument: Instrument | None = None):
    """The statistical covariance, the loop laws' systematic part and a declared instrument's: ``(unc, budget)``."""
    from bendpam.physics.hysteresis import ENSEMBLE

    unc = _uncertainty(run.prob, run.bnd, run.nl, run.lin, corr_flag, run.cycles, run.offsets, instrument)
    run.nfev += unc.nfev
    fits: dict[str, MemberFit] = {}
    r = run.prob.residual_full(np.concatenate([[run.nl[p] for p in run.prob.nonlin], run.lin]))
    misfit_ratio = lack_of_fit(r, [(rows, run.prob.w[rows][None, :] * E) for rows, E in run.cycles])
    run.notes += misfit_note(misfit_ratio, run.law)
    if run.law and law_uncertainty:
        fits[run.law] = MemberFit(dict(unc.values), float(r @ r), tuple(unc.names), unc.cov_stat.copy(),
                                  len(run.prob.free), group_ssr(r, run.prob.groups))
        solved = {}
        for alt in (a for a in ENSEMBLE if a != run.law and (a not in SPAN_SCALED or spans_differ(run.prob.d))):
            try:
                fits[alt], n, solved[alt] = _law_refit(run.prob, run.bnd, run.nl, alt)
            except FitError:  # this law cannot describe the curves at all: it has no weight
                continue
            run.nfev += n
        if "F_off" in run.bnd:
            _offset_members(run, fits, solved, r, instrument.offsets_declared if instrument is not None else ())
    if fits:  # each member's own statistical covariance, where it has weight (the others add nothing)
        w, _ = member_weights(fits, r, run.prob.groups)
        offsets: dict[str, list] = {n: [] for n in OFFSET_PARAMETERS}  # each offset's (weight, value, SE)
        for (alt, f), wk in zip(list(fits.items()), w, strict=True):
            if alt in solved and wk > 1e-4:
                p2, nl2, lin2 = solved[alt]
                u2 = _uncertainty(p2, run.bnd, nl2, lin2, corr_flag, run.cycles, run.offsets)
                fits[alt] = f._replace(names=tuple(u2.names), cov=u2.cov_stat)
                run.nfev += u2.nfev
                for name in (n for n in OFFSET_PARAMETERS if n in u2.names):
                    offsets[name].append((float(wk), u2.values[name], float(u2.sd[u2.names.index(name)])))
        evident = False
        for name, found in offsets.items():
            if found and sum(o[0] for o in found) >= OFFSET_NOTE_WEIGHT:
                mean, sd, weight = offset_average(found)
                if abs(mean) >= 3.0 * sd:  # an offset the curves show, not the members' share of a misfit
                    run.notes.append(offset_note(mean, sd, weight, name))
                    evident = True
        if not evident:
            run.notes += _widening_notes(fits, w, misfit_ratio >= MISFIT_NOTE_RATIO)
    shape_bound = unc.at_bound.get("S_lo", False) or unc.at_bound.get("S_hi", False)
    budget = uncertainty_budget(unc, run.prob.actuator(unc.values), fits, r, run.prob.groups, run.law,
                                0 if shape_bound else len(run.cycles))
    if "viscous" in fits:
        timed = getattr(run.prob.d, "time_s", None) is not None
        budget.weighting += ("; the viscous loop driven at the test's own times" if timed else
                             "; the viscous loop's rate approximated at a constant crosshead speed (the processed "
                             "set keeps no time: saved before 0.4)")
    run.notes += drift_note(unc.drift_shift, budget.total, sum(o.shift != 0 for o in run.offsets))
    if instrument is not None and instrument.declared:
        budget.instrument = part_sds(unc.cov_inst, unc.names, run.prob.actuator(unc.values))
        budget.declared = instrument.describe()
        if instrument.offsets_declared and run.prob.d.lever is None:
            run.notes.append("the declared offsets are not counted: the processed set keeps no fixture (its lever "
                             "turns a force into a moment)")
    return unc, budget


#: The ratio of the residuals' sum of squares to the cycles' pure error (:func:`~bendpam.identify.uncertainty.
#: lack_of_fit`) from which the fit says its model misfits the curves: three quarters of the sum of squares is misfit.
#: On the calibration study's main set the ratio is 1-3; on the tenth held-out set's braid friction 15-36.
MISFIT_NOTE_RATIO = 4.0


def misfit_note(ratio: float, law: str | None) -> list[str]:
    """The fit's words when the curves' misfit is well beyond what the cycles' scatter explains (``ratio`` at least
    :data:`MISFIT_NOTE_RATIO`).

    >>> misfit_note(23.4, "pi")[0].split(":")[0]
    "the curves' residuals are 23 times what the scatter of their cycles explains (lack of fit against the cycles)"
    >>> misfit_note(1.4, "pi")
    []
    """
    if not (ratio >= MISFIT_NOTE_RATIO):
        return []
    model, shared = ((f"the model with its {law} loop", "a bias that every loop law shares") if law else
                     ("the model of the mean curves", "a bias"))
    return [f"the curves' residuals are {ratio:.0f} times what the scatter of their cycles explains (lack of fit "
            f"against the cycles): {model} does not follow them to their noise; the error bars count the excess "
            f"misfit as correlated noise (docs/calibration.md), but {shared} may remain"]


def _widening_notes(fits: dict, w: np.ndarray, misfit: bool = False) -> list[str]:
    """The fit's words when offset members the curves do not call for widen alpha0's error bar by half or more
    (:func:`~bendpam.identify.ensemble.offset_widening`): a declared zero replaces them (``misfit``: the curves'
    misfit is well beyond their cycles' scatter, and the wider bar may be covering it)."""
    members = []
    for (law, f), wk in zip(fits.items(), w, strict=True):
        names = tuple(getattr(f, "names", ()))
        if getattr(f, "cov", None) is not None and "alpha0" in names and wk > 1e-4:
            j = names.index("alpha0")
            members.append((law, float(wk), float(f[0]["alpha0"]), math.sqrt(max(float(f.cov[j, j]), 0.0))))
    weight, with_, without = offset_widening(members) if members else (0.0, math.nan, math.nan)
    return [widening_note(weight, with_, without, misfit)] if weight >= 0.05 and with_ >= 1.5 * without else []


def _bounds(actuator: Actuator, d: FitData, bounds) -> dict[str, tuple[float, float]]:
    bnd = _default_bounds(actuator, float(d.P.min()))
    bnd.update({"theta_h": (0.2, 90.0), "a0": (0.0, 10.0 * float(d.BM.max())), "a1": (0.0, 100.0), "gap": (0.0, 5.0)})
    if d.lever is not None:  # a load-cell zero offset (N), the ensemble's offset member: up to half the blocked force
        f_b = 0.5 * float(np.max(d.BM / d.lever.min()))
        bnd["F_off"] = (-f_b, f_b)
        bnd["F_P"] = (-f_b / float(d.P.max()), f_b / float(d.P.max()))  # N/kPa: as much at the highest pressure
    bnd.update({"a0_2": bnd["a0"], "a1_2": bnd["a1"], "ratio": (1.0, 3.0), "theta_2": bnd["theta_h"]})  # members' own
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


def _stretch_range(actuator: Actuator, d: FitData, admissible_range, tension_data) -> tuple[float, float]:
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


def _solve(prob: Problem, bnd, grid_alpha: int, grid_r0: int, start: dict[str, float] | None = None):
    """Global grid (unless ``start`` is given) and local search; returns (nl, lin, converged, message, nfev)."""
    nfev = 0
    if start is None:
        best, nfev = _start(prob, bnd, grid_alpha, grid_r0)
    else:
        best = (math.nan, dict(start))
    nl, lin, converged, message, n = _search(prob, bnd, best)
    return nl, lin, converged, message, nfev + n


def _start(prob: Problem, bnd, grid_alpha: int, grid_r0: int):
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


def _search(prob: Problem, bnd, best, tol: float = 1e-10):
    """A bounded trust-region search on the projected problem (``xtol = tol``); the final linear solve."""
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
                            diff_step=1e-6, xtol=tol, ftol=1e-2 * tol, gtol=1e-2 * tol)
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


def _ssr(prob: Problem, nl, lin) -> float:
    r = prob.residual_full(np.concatenate([[nl[p] for p in prob.nonlin], lin]))
    return float(r @ r)


def _fold_kpa(prob: Problem, nl, lin, p_max: float) -> float | None:
    """The fold pressure of the fitted quasi-static model if its free-bending branch ends below ``p_max``."""
    act = prob.actuator(prob.to_user(nl, lin))
    br = MomentLaw.of(act, prob.model, order=prob.order, eq19_factor=prob.eq19).free_branch()
    return float(br.max_pressure_kpa) if br.max_pressure_kpa < p_max else None


def _fold_rule(prob: Problem, args, bnd, nl, lin, p_max: float):
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
        p2 = Problem(*args, shape_fixed=float(beta))
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


def _joint_tension(prob: Problem, args, bnd, nl, lin, tension_data):
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
    ten = Tension(lam, stress, s_b / s_t)
    p2 = Problem(*args, shape_fixed=prob.shape_fixed, tension=ten)
    nl2, lin2, _, _, n = _solve(p2, bnd, 0, 0, start=nl)
    note = (f"joint fit with the tension test{' ' + tf.source if tf.source else ''} ({lam.size} points, stretch "
            f"{lam.min():.3g} to {lam.max():.3g}): each data set weighted by its own residual noise (bending "
            f"{s_b:.3g} in eq-53 units, tension {s_t:.3g} kPa)")
    return p2, nl2, lin2, n, note


def _uncertainty(prob: Problem, bnd, nl_best, lin, corr_flag: float, cycles=(), offsets=(),
                 instrument: Instrument | None = None) -> Uncertainty:
    """Sandwich covariance from the joint Jacobian (nonlinear columns by central differences).

    The weights normalise each curve (eq 53), they are not inverse noise variances, so each residual
    group (a curve, a branch, the tension test) gets its own variance with its AR(1) inflation, or,
    for the tests in ``cycles`` (:func:`~bendpam.identify.data.cycle_deviations`), the covariance of
    resampling their cycles, and the drift corrections' doubt (``offsets``,
    :func:`~bendpam.identify.data.drift_offsets`).  Where the shape sits on an admissibility bound the
    model cannot follow the curves; their misfit, the same in every cycle, is then treated as
    correlated noise (the sandwich with its AR(1) inflation for every curve) instead of resampling
    the cycles, which would not see it.
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
    lo_all = np.concatenate([[bnd[p][0] for p in prob.nonlin], prob.lo])
    hi_all = np.concatenate([[bnd[p][1] for p in prob.nonlin], prob.hi])
    at_bound = at_bounds(x_int, lo_all, hi_all)
    bound_names = {n: bool(b) for n, b in zip(prob.nonlin + prob.int_names, at_bound, strict=True)}
    if bound_names.get("S_lo", False) or bound_names.get("S_hi", False):
        cycles = ()  # the model cannot follow the curves (shape at an admissibility bound): misfit as noise
    weighted = [(rows, prob.w[rows][None, :] * E) for rows, E in cycles]
    cov_int, rho = sandwich_covariance(J, r, prob.groups, weighted, offset_modes(offsets, prob.w))
    G = np.zeros((nn + len(prob.lin), x_int.size))
    G[:nn, :nn] = np.eye(nn)
    G[nn:, nn:] = prob.T
    unc = Uncertainty(prob.to_user(nl_best, lin), prob.nonlin + prob.lin, G @ cov_int @ G.T, rho, nfev, bound_names,
                      float(r @ r), m, corr_flag)
    moved = [(o.rows, o.shift * prob.w[o.rows]) for o in offsets]
    unc.set_drift_shift(G @ offset_shift(J, moved))  # an uncorrected drift's
    if instrument is not None and instrument.declared:  # the load cell's moments; the residuals' change per kPa
        p2 = copy.copy(prob)
        p2.d = dataclasses.replace(prob.d, Pc=prob.d.Pc + 1.0)
        bending = np.arange(m) < prob.d.kc.size
        force = np.where(bending, prob.w * prob.y, 0.0)
        Jf = np.where(np.asarray(at_bound, dtype=bool)[None, :], 0.0, J)  # a bound held moves nothing (refit)
        offset_rows = {}
        if prob.d.lever is not None:  # a declared offset's weighted moment per unit: eq 7's lever (times P)
            n_b = prob.d.kc.size
            offset_rows = {"F_off": np.zeros(m), "F_P": np.zeros(m)}
            offset_rows["F_off"][:n_b] = prob.w[:n_b] * prob.d.lever
            offset_rows["F_P"][:n_b] = offset_rows["F_off"][:n_b] * prob.d.Pc
        unc.set_instrument(G @ instrument_covariance(Jf, force, p2.residual_full(x_int) - r, instrument,
                                                     offset_rows) @ G.T)
    return unc


def _law_refit(prob: Problem, bnd, nl, alt: str):
    """The fit with another loop law ``alt`` (warm start, angle grid; a member's own parameters from short grids):
    ``(MemberFit without its covariance, nfev, (problem, nonlinear, linear values))``.  The search stops at
    ``xtol = 1e-5`` (alpha0 to about 1e-3 deg): well within the standard errors the values serve."""
    p2 = copy.copy(prob)  # the same data and kinematics (their caches are shared), another loop law
    p2.law = alt
    extra = MEMBER_EXTRA.get(alt, ())
    if extra:
        p2.set_free([*prob.free, *extra])
    nfev = 0
    best = (math.inf, dict(nl))
    own = {"gap": (0.25, 0.5, 1.0, 2.0), "ratio": (1.25, 1.75), "theta_2": (2.0, 8.0, 30.0)}  # members' own grids
    grid: list[dict[str, float]] = [{}]
    for p in extra:
        grid = [{**g, p: v} for g in grid for v in own[p]] if p in own else grid
    for th in _THETA_GRID:
        for g in grid:
            trial = {**nl, "theta_h": float(th), **g}
            r, _ = p2.project(trial)
            nfev += 1
            if float(r @ r) < best[0]:
                best = (float(r @ r), trial)
    nl2, lin2, _, _, n = _search(p2, bnd, best, tol=1e-5)
    r2 = p2.residual_full(np.concatenate([[nl2[p] for p in p2.nonlin], lin2]))
    member = MemberFit(p2.to_user(nl2, lin2), float(r2 @ r2), n_params=len(p2.free),
                       group_ssr=group_ssr(r2, p2.groups))
    return member, nfev + n, (p2, nl2, lin2)


def _offset_members(run: _Run, fits: dict, solved: dict, r: np.ndarray, declared: tuple[str, ...] = ()) -> None:
    """Add the offset members to ``fits`` (and their problems to ``solved``): the law of most weight refitted with
    each offset of :data:`~bendpam.identify.ensemble.OFFSETS` (:func:`_offset_refit`); when those members take most
    of the weight, every other law too, so that the offsets are part of every member and the laws' spread is the
    systematic part again.  A member that fits an offset the instrument declares known (``declared``,
    :attr:`~bendpam.identify.uncertainty.Instrument.offsets_declared`) is left out: the declared doubt replaces it."""
    kinds = {suffix: names for suffix, names in OFFSETS.items() if not set(names) & set(declared)}
    if not kinds:
        return

    def add(law: str) -> None:
        prob, nl = solved[law][:2] if law in solved else (run.prob, run.nl)
        for suffix, names in kinds.items():
            try:
                fits[law + suffix], n, solved[law + suffix] = _offset_refit(prob, run.bnd, nl, names)
                run.nfev += n
            except FitError:  # no such offset describes the curves with this law: the member has no weight
                pass

    laws = list(fits)
    top = laws[int(np.argmax(member_weights(fits, r, run.prob.groups)[0]))]
    add(top)
    w = dict(zip(fits, member_weights(fits, r, run.prob.groups)[0], strict=True))
    if sum(w.get(top + suffix, 0.0) for suffix in kinds) >= 0.5:
        for law in laws:
            if law != top:
                add(law)


def _offset_refit(prob: Problem, bnd, nl, names: tuple[str, ...] = ("F_off",)):
    """A member's fit (``prob`` at ``nl``) with offset forces as well: ``names`` among ``"F_off"``, a load-cell zero
    offset (N), and ``"F_P"``, a force in proportion to the pressure (N/kPa): the ensemble's offset members
    (:data:`~bendpam.identify.ensemble.OFFSETS`).  The offsets are linear (their moment at each point is eq 7's lever
    times them), so the search only refines the kinematics from the member's.  Where its shape still sits on an
    admissibility bound the model cannot follow the curves even so, and the offsets would only absorb their misfit:
    FitError (the member is left out)."""
    p2 = copy.copy(prob)
    p2.set_free([*prob.free, *names])
    r0, _ = p2.project(nl)
    nl2, lin2, _, _, n = _search(p2, bnd, (float(r0 @ r0), dict(nl)), tol=1e-5)
    held = dict(zip(p2.int_names, at_bounds(lin2, p2.lo, p2.hi), strict=True))
    if held.get("S_lo", False) or held.get("S_hi", False):
        raise FitError("with the offset too the shape sits on its bound: the offset would absorb the model's misfit")
    r2 = p2.residual_full(np.concatenate([[nl2[p] for p in p2.nonlin], lin2]))
    member = MemberFit(p2.to_user(nl2, lin2), float(r2 @ r2), n_params=len(p2.free),
                       group_ssr=group_ssr(r2, p2.groups))
    return member, n + 1, (p2, nl2, lin2)


def _profile(prob: Problem, bnd, nl, unc: Uncertainty, n_points: int):
    """The reported loop law's objective minimised over everything else against alpha0, around its optimum."""
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
    sd, mid = float(unc.sd[i]), float(unc.values["alpha0"])  # the reported value: the ensemble's average
    return Profile([float(x) for x in alphas], [float(x) for x in obj], (mid - 2 * sd, mid + 2 * sd)), nfev


def _result(processed, actuator: Actuator, run: _Run, unc: Uncertainty, tension, t0: float,
            budget: UncertaintyBudget, profile: Profile | None, hysteresis) -> FitResult:
    """The fitted actuator, its parameters, material, metrics, loop and notes."""
    prob, bnd, model, law = run.prob, run.bnd, run.args[2], run.law
    order, eq19_factor = run.args[5], run.args[6]
    fitted = prob.actuator(unc.values)
    fitted = fitted.replace(name=f"{actuator.name or actuator.kind} [fitted, {model.replace('_', '-')} model]",
                            model=model)
    params = _parameters(prob, bnd, unc, fitted, actuator, tension)
    shape_at_bound = prob.cone and prob.shape_fixed is None and (unc.at_bound.get("S_lo", False)
                                                                 or unc.at_bound.get("S_hi", False))
    free_user = [p for p in prob.free if p in PARAMETERS]
    mat = material_fit(fitted, unc, prob.shape_bounds, run.stretch, shape_at_bound, run.shape_held, free_user,
                       joint=prob.tension is not None)
    joint, jflags = correlated_pairs(unc.names, unc.values, unc.cov, unc.corr, unc.corr_flag)
    ident = identifiability(mat, free_user, unc, fitted, budget, law)
    hyst = _hysteresis_fit(processed, fitted, model, unc, bnd, law, budget, order, eq19_factor)
    loop = None if hyst is None else hyst.loop()
    metrics = score(processed, fitted, model, loop=loop, order=order, eq19_factor=eq19_factor)
    if hyst is not None:
        hyst.nrmse_branches = metrics.nrmse_cycles
    flags = [*jflags, *bound_flags(unc.at_bound), *run.notes, *fit_flags(processed, law, metrics)]
    message = run.message
    if law is not None and str(hysteresis).strip().lower() == "auto":
        ratio = float(np.median([r.energy_loss_ratio for r in processed.results]))
        message += (f"; fitted with the {law} loop model on both branches (the tests show a loop, median "
                    f"energy-loss ratio {100 * ratio:.1f} %)")
    P = np.array([r.pressure_kpa for r in processed.results], dtype=float)
    # the fitted actuator remembers where it was tested and which fit made it (save() adds fit.json's hash)
    fitted = fitted.replace(tested_pressure_kpa=(float(P.min()), float(P.max())), fit_identity=FitIdentity(
        date=datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ"), version=__version__))
    return FitResult(
        model=model, actuator=fitted, parameters=params, correlation=unc.corr, correlation_names=unc.names,
        metrics=metrics, converged=run.converged, message=message, nfev=run.nfev, time_s=time.perf_counter() - t0,
        flags=flags, autocorrelation=unc.rho, hysteresis=hyst, material=mat, identifiability=ident,
        alpha0_profile=profile, joint_intervals=joint, covariance=unc.cov,
        pressure_range_kpa=(float(P.min()), float(P.max())), uncertainty=budget,
    )


def _parameters(prob: Problem, bnd, unc: Uncertainty, fitted: Actuator, actuator: Actuator,
                tension) -> dict[str, Parameter]:
    """Every parameter of the model: the varied ones with their standard errors and start values."""
    sd = unc.sd
    params = {}
    for n in PARAMETER_ORDER:
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
    return params


def _hysteresis_fit(processed, fitted: Actuator, model: str, unc: Uncertainty, bnd, law: str | None,
                    budget: UncertaintyBudget, order: int, eq19_factor: bool) -> HysteresisFit | None:
    """The fitted loop with its parameters and the energy-loss ratio it predicts per test (None without a loop)."""
    if law is None:
        return None
    from bendpam.physics.hysteresis import predict_cycles

    sd = unc.sd
    hp = {}
    for n in ("a0", "a1", "theta_h"):
        i = unc.names.index(n)
        field_, unit = HYST_PARAMETERS[n]
        hp[n] = Parameter(n, field_, unit, float(unc.values[n]), float(sd[i]) if np.isfinite(sd[i]) else None,
                          bnd[n][0], bnd[n][1], True, math.nan)
    alt = {"pi": "dahl", "dahl": "pi"}.get(law, "")
    other = next((m for m in budget.ensemble if m.law == alt), None)  # the shift of 0.3's systematic term
    shift = {} if other is None else {f: v - float(getattr(fitted, f)) for f, v in other.values.items()
                                      if f in {PARAMETERS[p][0] for p in PARAMETERS}}
    hyst = HysteresisFit(law, "linear", hp, [], math.nan, alt if shift else "", shift)
    cycles = predict_cycles(fitted, hyst.loop(), [r.pressure_kpa for r in processed.results], model,
                            order=order, eq19_factor=eq19_factor)
    hyst.energy_loss_ratio = [LossRatio(float(r.pressure_kpa), float(r.energy_loss_ratio), c.energy_loss_ratio)
                              for r, c in zip(processed.results, cycles, strict=True)]
    return hyst
