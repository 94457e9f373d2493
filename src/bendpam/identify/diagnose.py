"""Every judgement of a fit, by one table of limits (:data:`LIMITS`).

A fit is judged in two places: by :func:`bendpam.identify.fitting.fit` itself, which writes its
notes into the result (``FitResult.flags`` and ``FitResult.identifiability``), and by whoever
shows it, the report for one (:mod:`bendpam.present.report`), which asks :func:`judge` what is
wrong with the fits and the data and puts the answers into words.  Both use the functions here,
and the functions use the limits of :class:`Limits`, so that no limit is written twice.

The judgements
    * a poor fit (:func:`judge_fit`): NRMSE of the loading cycles above ``nrmse_cycles`` (10 %),
      or of the blocked moment or free-bending curvature above ``nrmse_points`` (20 %); the
      paper's fits reach 3-9 %;
    * a parameter at a bound of its range (:func:`at_bound`, within ``bound_fraction`` of the span;
      :func:`at_bounds` for the search's own variables, within ``solver_bound``), the shear modulus
      at its lower bound;
    * strongly correlated parameters (``|r| > correlation``; :func:`correlated_pairs` gives what the
      data determine of them);
    * a search that did not converge (:func:`search_state` reads the optimiser's message), no
      free-bending equilibrium at a tested pressure (a fold);
    * a measured deadband far from P_start (:func:`judge_data`), data that bend the other way
      than the actuator's type, a model that could not be fitted at all;
    * loops in the tests (:func:`has_loop`), and which parameters and combinations the data
      determine (:func:`identifiability`, :func:`shape_identified`,
      :func:`tension_identifiability`).

A :class:`Finding` carries a judgement's kind, what it concerns and the numbers behind it, not
words: the report words it.

Examples
--------
>>> from types import SimpleNamespace as NS
>>> p = NS(value=76.66, min=62.73, max=76.67, vary=True)
>>> at_bound(p), LIMITS.bound_fraction
('upper', 0.001)
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from bendpam.identify.result import JointInterval, MaterialFit, UncertaintyBudget, parameter_field, parameter_unit

if TYPE_CHECKING:
    from bendpam.identify.uncertainty import Uncertainty
    from bendpam.physics.actuator import Actuator

__all__ = [
    "CORRELATION_LIMIT",
    "KINDS",
    "LIMITS",
    "LOOP_THRESHOLD",
    "NRMSE_CYCLES_LIMIT",
    "Finding",
    "Limits",
    "at_bound",
    "at_bounds",
    "bound_flags",
    "correlated_pairs",
    "fit_flags",
    "has_loop",
    "identifiability",
    "judge",
    "judge_data",
    "judge_fit",
    "needs_type_check",
    "search_state",
    "shape_identified",
    "study_coverage",
    "tension_identifiability",
]


@dataclass(frozen=True)
class Limits:
    """The limits by which fits are judged: the one table (its instance is :data:`LIMITS`).

    Attributes
    ----------
    nrmse_cycles : NRMSE of the loading cycles (eq 53) above which a fit is poor (the paper's: 3.3-5.5 %).
    nrmse_points : NRMSE of the blocked moment or free-bending curvature (eq 54-55) above which a fit
        is poor (the paper's: 2-9 %).
    bound_fraction : a fitted parameter within this fraction of its range's span from a bound is at it.
    solver_bound : the search's variables within this relative distance of a bound are at it (their
        standard errors are not meaningful).
    correlation : pairs of fitted parameters with a larger |correlation| are poorly identifiable together.
    deadband_kpa, deadband_fraction, deadband_se : the measured deadband is far from P_start when they
        differ by more than ``max(deadband_kpa, deadband_fraction * P_start)`` kPa and by more than
        ``deadband_se`` standard errors.
    loop : the tests show a loop when their median energy-loss ratio exceeds this.
    direction_ratio : the other actuator type fits better when its NRMSE of the cycles is below the
        chosen type's divided by this (and within ``nrmse_cycles``).
    autocorrelation : residuals with a larger lag-1 autocorrelation miss the curves' shape systematically.
    alpha0_2se_deg : alpha0 is determined when twice its standard error is at most this, deg.
    mu_se : the shear modulus of a bending fit is determined when its relative standard error is at most this.
    tension_mu_se : the same for a tension-test fit.
    shape_resolved : the shape C01/(C10 + C01) is determined when its 95 % interval covers at most this
        fraction of the admissible width.

    Examples
    --------
    >>> LIMITS.nrmse_cycles, LIMITS.correlation, LIMITS.loop
    (0.1, 0.95, 0.01)
    """

    nrmse_cycles: float = 0.10
    nrmse_points: float = 0.20
    bound_fraction: float = 1e-3
    solver_bound: float = 1e-9
    correlation: float = 0.95
    deadband_kpa: float = 15.0
    deadband_fraction: float = 0.30
    deadband_se: float = 2.0
    loop: float = 0.01
    direction_ratio: float = 1.5
    autocorrelation: float = 0.5
    alpha0_2se_deg: float = 1.0
    mu_se: float = 0.05
    tension_mu_se: float = 0.10
    shape_resolved: float = 0.5


#: The limits in force.
LIMITS = Limits()
#: The tests "show a loop" when their median energy-loss ratio exceeds this (``LIMITS.loop``, 1 %).
LOOP_THRESHOLD = LIMITS.loop
#: NRMSE of the loading cycles above which a fit is poor (``LIMITS.nrmse_cycles``).
NRMSE_CYCLES_LIMIT = LIMITS.nrmse_cycles
#: |correlation| above which a pair of parameters is flagged (``LIMITS.correlation``).
CORRELATION_LIMIT = LIMITS.correlation

#: The kinds of :class:`Finding`, most serious first.
KINDS = ("direction", "deadband", "fit-failed", "poor-fit", "fold", "not-converged", "at-bound", "correlated")

_Z95 = 1.959963984540054  # the 95 % quantile of the standard normal distribution
_CHI2_2_95 = 5.991464547107979  # the 95 % quantile of chi-square with 2 degrees of freedom (joint regions of pairs)


@dataclass(frozen=True)
class Finding:
    """One judgement: something about a fit, or about the data, that its user should know.

    Attributes
    ----------
    kind : one of :data:`KINDS`.
    key : what it concerns within its kind (a parameter's short name, ``"mu"``, the correlated
        pairs ``"C10+C01"``), or ``""``.
    model : the model of the fit it concerns (``""`` for the data).
    severity : ``"warning"`` (the results should not be used as they are) or ``"caution"``.
    facts : the numbers and names behind it, by kind:

        * ``poor-fit``: ``nrmse``, ``{"cycles"/"blocked_moment"/"free_curvature": value}`` of those over their limit;
        * ``at-bound``: ``side`` ("lower"/"upper"), ``value``, ``min``, ``max``; for ``key="mu"`` only ``mu`` (kPa);
        * ``correlated``: ``pairs`` [(name, name, r)], ``C10_C01`` (whether C10 and C01 are one of them);
        * ``fold``: ``pressures_kpa``; ``fit-failed``: ``reason``;
        * ``deadband``: ``deadband_kpa``, ``deadband_se_kpa``, ``P_start_kpa``, ``difference_kpa``,
          ``limit_kpa``, ``fitted_P_start_kpa`` ({model: value} of the fits that freed it);
        * ``direction``: ``kind``, ``other`` (the actuator types), ``evidence``: dicts with ``source``
          ``"metadata"`` (and ``where``), ``"comparison"`` (``nrmse_other``, ``alpha0_other_deg``,
          ``nrmse_same``) or ``"alpha0-bound"``.

    Examples
    --------
    >>> Finding("fold", model="energy", facts={"pressures_kpa": [200.0]}).severity
    'warning'
    """

    kind: str
    key: str = ""
    model: str = ""
    severity: str = "warning"
    facts: Mapping[str, Any] = field(default_factory=dict)


def _finite(x) -> bool:
    try:
        return x is not None and not isinstance(x, bool) and math.isfinite(float(x))
    except (TypeError, ValueError):
        return False


# ------------------------------------------------------------------------------------------------
# the tests
# ------------------------------------------------------------------------------------------------
def has_loop(processed, threshold: float = LIMITS.loop) -> bool:
    """Whether the processed tests show a hysteresis loop: median energy-loss ratio above ``threshold``.

    >>> from types import SimpleNamespace as NS
    >>> has_loop(NS(results=[NS(energy_loss_ratio=0.2), NS(energy_loss_ratio=0.18)]))
    True
    """
    ratios = np.array([float(r.energy_loss_ratio) for r in processed.results], dtype=float)
    ratios = ratios[np.isfinite(ratios)]
    return bool(ratios.size and float(np.median(ratios)) > threshold)


# ------------------------------------------------------------------------------------------------
# parameters and their uncertainty
# ------------------------------------------------------------------------------------------------
def at_bound(p, fraction: float = LIMITS.bound_fraction) -> str | None:
    """``"lower"``/``"upper"`` if a varied parameter is within ``fraction`` of its range's span of a bound, else None.

    ``p`` has ``value``, ``min``, ``max`` and ``vary`` (a :class:`~bendpam.identify.result.Parameter`).

    >>> from types import SimpleNamespace as NS
    >>> near, inside = NS(value=62.74, min=62.73, max=76.67, vary=True), NS(value=69.7, min=62.73, max=76.67, vary=True)
    >>> at_bound(near), at_bound(inside)
    ('lower', None)
    """
    if not p.vary or not (_finite(p.min) and _finite(p.max) and _finite(p.value)) or not p.max > p.min:
        return None
    tol = fraction * (p.max - p.min)
    if p.value - p.min <= tol:
        return "lower"
    if p.max - p.value <= tol:
        return "upper"
    return None


def at_bounds(x: np.ndarray, lo: np.ndarray, hi: np.ndarray, tol: float = LIMITS.solver_bound) -> np.ndarray:
    """Which of the search's variables ``x`` sit at a bound (within ``tol`` relative, at least ``tol`` absolute).

    >>> at_bounds(np.array([0.0, 0.5, 2.0]), np.zeros(3), np.array([1.0, 1.0, np.inf])).tolist()
    [True, False, False]
    """
    tol_lo = tol * np.maximum(1, np.abs(np.where(np.isfinite(lo), lo, 0.0)))
    tol_hi = tol * np.maximum(1, np.abs(np.where(np.isfinite(hi), hi, 0.0)))
    return (np.abs(x - lo) <= tol_lo) | (np.abs(x - hi) <= tol_hi)


def bound_flags(at_bound: Mapping[str, bool]) -> list[str]:
    """The fit's notes on its variables at a bound (:func:`at_bounds`, by name; ``S`` is ``C10 + C01``).

    The weights of the two bounding shapes (``S_lo``, ``S_hi``) are left to :func:`identifiability`.

    >>> bound_flags({"alpha0": True, "S_lo": True, "C10": False})
    ['alpha0_deg is at a bound of its range; its standard error is not meaningful']
    """
    flags = []
    for p, b in at_bound.items():
        if not b:
            continue
        if p in ("S_lo", "S_hi"):
            continue  # the shape at an admissibility bound: said in the identifiability notes
        name = "C10 + C01" if p == "S" else _field(p)
        flags.append(f"{name} is at a bound of its range; its standard error is not meaningful")
    return flags


def _field(p: str) -> str:
    try:
        return parameter_field(p)
    except KeyError:
        return p


def correlated_pairs(names, values, cov, corr, limit: float = LIMITS.correlation
                     ) -> tuple[list[JointInterval], list[str]]:
    """The pairs with ``|correlation| > limit``: what the data determine of each, and a sentence.

    Parameters
    ----------
    names : the varied parameters (short names), in the order of ``cov``.
    values : their values, by short name.
    cov, corr : their covariance and correlation.
    limit : the |correlation| above which a pair is flagged.

    Returns
    -------
    ([JointInterval], [sentence])

    Examples
    --------
    >>> cov = np.array([[100.0, -99.0], [-99.0, 100.0]])
    >>> joint, flags = correlated_pairs(["C10", "C01"], {"C10": 100.0, "C01": 300.0}, cov, cov / 100.0)
    >>> joint[0].names, round(joint[0].coefficient, 2), flags[0][:60]
    (('C10_kpa', 'C01_kpa'), 0.99, 'C10_kpa and C01_kpa are poorly identifiable together (correl')
    """
    out, flags = [], []
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            c = corr[i, j]
            if not (np.isfinite(c) and abs(c) > limit and sd[j] > 0):
                continue
            li, lj = parameter_field(names[i]), parameter_field(names[j])
            lam = -cov[i, j] / cov[j, j]
            val = values[names[i]] + lam * values[names[j]]
            se = math.sqrt(max(cov[i, i] + 2 * lam * cov[i, j] + lam * lam * cov[j, j], 0.0))
            q = math.sqrt(_CHI2_2_95)
            box = {li: (values[names[i]] - q * sd[i], values[names[i]] + q * sd[i]),
                   lj: (values[names[j]] - q * sd[j], values[names[j]] + q * sd[j])}
            same = parameter_unit(names[i]) == parameter_unit(names[j])
            unit = parameter_unit(names[i]) if same or abs(lam) < 1e-300 else ""
            comb = f"{li} {'+' if lam >= 0 else '-'} {abs(lam):.3g} {lj}"
            text = (f"{li} and {lj} are poorly identifiable together (correlation {c:+.4f}): the data determine "
                    f"{comb} = {val:.4g} ± {2 * se:.2g}{' ' + unit if unit else ''} (2 SE), not each one; jointly "
                    f"(95 %) {li} in [{box[li][0]:.4g}, {box[li][1]:.4g}] and {lj} in [{box[lj][0]:.4g}, "
                    f"{box[lj][1]:.4g}] along that line")
            out.append(JointInterval((li, lj), float(c), float(lam), float(val), float(se), box, text))
            flags.append(text)
    return out, flags


def shape_identified(se_shape: float, shape_bounds, at_bound: bool, held: str) -> bool:
    """Whether the shape C01/(C10 + C01)'s interval is narrow: its 95 % interval within ``LIMITS.shape_resolved``
    of the admissible width, neither at a bound nor held fixed.  Whether that is enough to call it
    determined is :func:`study_coverage`'s to say (for fits of bending curves alone).

    >>> shape_identified(0.05, (-0.15, 1.07), False, ""), shape_identified(0.5, (-0.15, 1.07), False, "")
    (True, False)
    """
    width = shape_bounds[1] - shape_bounds[0]
    return bool(not at_bound and not held and width > 0 and 2 * _Z95 * se_shape <= LIMITS.shape_resolved * width)


#: The calibration study's record of the shape's coverage (written by tools/shape_coverage.py).
SHAPE_COVERAGE_FILE = Path(__file__).with_name("shape_coverage.json")


@functools.lru_cache(maxsize=4)
def study_coverage(path: str | None = None, target: float = 0.85) -> tuple[bool, str]:
    """Whether the calibration study's 2-SE coverage of the shape, where its interval was narrow, holds.

    The record (``path``, default :data:`SHAPE_COVERAGE_FILE`) lists per case of the study the runs
    whose shape interval was narrow and how many of those covered the truth.  The coverage holds
    when it reaches ``target`` in every case that had such runs (and overall); then a narrow
    interval of a fit of bending curves alone may be called determined.  Returns ``(holds, why)``,
    ``why`` the words when it does not (no record: it does not).

    >>> import json, tempfile, os
    >>> rec = {"cases": {"none": {"narrow": 10, "covered": 10}, "drift": {"narrow": 10, "covered": 6}}}
    >>> with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
    ...     json.dump(rec, f)
    >>> study_coverage(f.name)
    (False, 'in the calibration study such narrow intervals covered the truth in 16 of 20 runs (drift: 6 of 10)')
    >>> os.remove(f.name)
    """
    import json

    p = Path(path) if path else SHAPE_COVERAGE_FILE
    try:
        cases = json.loads(p.read_text(encoding="utf-8"))["cases"]
        counts = {str(k): (int(v["narrow"]), int(v["covered"])) for k, v in cases.items()}
    except (OSError, ValueError, KeyError, TypeError):
        return False, "the calibration study's record of its coverage is missing"
    n = sum(a for a, _ in counts.values())
    k = sum(b for _, b in counts.values())
    bad = [f"{c}: {b} of {a}" for c, (a, b) in counts.items() if a and b < target * a]
    if n and not bad and k >= target * n:
        return True, ""
    if not n:
        return False, "the calibration study had no run with so narrow an interval to check it on"
    return False, (f"in the calibration study such narrow intervals covered the truth in {k} of {n} runs"
                   + (f" ({'; '.join(bad)})" if bad else ""))


def identifiability(mat: MaterialFit | None, free: list[str], unc: Uncertainty, fitted: Actuator,
                    budget: UncertaintyBudget | None = None, law: str | None = None) -> list[str]:
    """Sentences: which of alpha0, the shear modulus and the shape the data determine (``FitResult.identifiability``).

    Parameters
    ----------
    mat : the bladder as fitted (:func:`bendpam.identify.uncertainty.material_fit`) or None.
    free : the model parameters varied.
    unc : their :class:`~bendpam.identify.uncertainty.Uncertainty`.
    fitted : the fitted actuator.
    budget, law : the errors' statistical and systematic parts (the ensemble of loop laws), the fit's law.

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.identify.uncertainty import Uncertainty
    >>> unc = Uncertainty({}, ["alpha0"], np.array([[0.0004]]), 0.0, 0, {}, 0.0, 40, 0.95)
    >>> identifiability(None, ["alpha0"], unc, bendpam.physics.presets.be_pam())
    ['alpha0 = 69.7 ± 0.04 deg (2 SE) is determined by the curves.']
    """
    out = []
    if "alpha0" in unc.names:
        i = unc.names.index("alpha0")
        se = float(unc.sd[i])
        sys_ = 0.0 if budget is None else budget.systematic.get("alpha0_deg", 0.0)
        n_laws = 0 if budget is None else len(budget.ensemble)
        tail = (f"; the choice of loop law (the spread of {n_laws} laws about their weighted average, systematic) "
                f"accounts for ± {2 * sys_:.2g} deg" if law and n_laws and sys_ > 0 else "")
        head = f"alpha0 = {fitted.alpha0_deg:.4g} ± {2 * se:.2g} deg (2 SE{tail})"
        if unc.at_bound.get("alpha0", False):
            out.append(f"{head} sits at a bound of its range: the curves do not determine it there.")
        elif not 2 * se <= LIMITS.alpha0_2se_deg:
            out.append(f"{head} is only loosely determined by the curves.")
        else:
            out.append(f"{head} is determined by the curves.")
    if mat is not None:
        out += _material_sentences(mat, "C10" in free and "C01" in free)
    if budget is not None and law and budget.ensemble:
        out += _better_law(budget, law)
    return out


def _better_law(budget: UncertaintyBudget, law: str) -> list[str]:
    """A sentence when another loop law of the ensemble fits clearly better (most of the weight) than the fit's."""
    own = next((m for m in budget.ensemble if m.law == law), None)
    best = max(budget.ensemble, key=lambda m: m.weight)
    if own is None or best.law == law or best.weight < 0.5:
        return []
    vals = ", ".join(f"{k} = {v:.4g}" for k, v in best.values.items() if k in ("alpha0_deg", "shear_modulus_kpa"))
    return [f"The {best.law.replace('_', '-')} loop law fits the branches better than the {law} law (NRMSE "
            f"{100 * best.nrmse:.3g} % against {100 * own.nrmse:.3g} %, weight {best.weight:.2f}) and gives {vals}; "
            "the systematic part of the standard errors spans the difference."]


def _material_sentences(mat: MaterialFit, both: bool) -> list[str]:
    """The shear modulus and the shape in words (:func:`identifiability`)."""
    out = []
    rel = (mat.se_shear_modulus_kpa or 0.0) / mat.shear_modulus_kpa
    mu_txt = f"mu = 2(C10 + C01) = {mat.shear_modulus_kpa:.4g} ± {2 * (mat.se_shear_modulus_kpa or 0):.2g} kPa (2 SE)"
    if rel <= LIMITS.mu_se:
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
    elif mat.shape_study:
        out.append(f"The shape C01/(C10 + C01) = {mat.shape:.3g} ± {2 * (mat.se_shape or 0):.2g} (2 SE) is not "
                   f"claimed although its interval is narrow: {mat.shape_study}.  The curves lie on a ridge: they fix "
                   "mu = 2(C10 + C01) and leave the shape free along it; a tension test of the bladder determines "
                   "it.")
    else:
        frac = 2 * _Z95 * (mat.se_shape or 0) / (hi - lo) if hi > lo else math.inf
        out.append(f"The shape C01/(C10 + C01) = {mat.shape:.3g} ± {2 * (mat.se_shape or 0):.2g} (2 SE) is not "
                   f"determined: its 95 % interval covers {min(100 * frac, 999):.0f} % of {adm}; only mu = "
                   "2(C10 + C01) is reliable, not C10 and C01 apart.")
    return out


def fit_flags(processed, law: str | None, metrics) -> list[str]:
    """The fit's notes on its data and model: mean curves fitted to tests with a loop, pressures without equilibrium.

    ``law`` is the loop law the fit used (None: the mean curves), ``metrics`` its
    :class:`~bendpam.identify.result.Metrics`.

    >>> from types import SimpleNamespace as NS
    >>> tests = NS(results=[NS(energy_loss_ratio=0.2), NS(energy_loss_ratio=0.18)])
    >>> [f[:30] for f in fit_flags(tests, None, NS(no_equilibrium_kpa=[200.0]))]
    ['fitted to the mean curves alth', 'no free-bending equilibrium in']
    """
    flags = []
    if law is None and has_loop(processed):
        ratio = float(np.median([r.energy_loss_ratio for r in processed.results]))
        flags.append(f"fitted to the mean curves although the tests show a loop (median energy-loss ratio "
                     f"{100 * ratio:.1f} %): the loop can bias alpha0 by more than its standard error; the default "
                     "(hysteresis-aware) fit avoids that")
    if metrics.no_equilibrium_kpa:
        what = "free-bending cycle (the unloading branch never reaches zero)" if law is not None else \
            "free-bending equilibrium"
        flags.append(f"no {what} in the fitted model at " + ", ".join(f"{p:g}" for p in metrics.no_equilibrium_kpa)
                     + " kPa; those pressures are left out of the free-curvature metric")
    return flags


def tension_identifiability(
    mu: float, se_mu: float, beta: float, se_beta: float, corr: float,
    bounds: tuple[float, float], span: tuple[float, float], at_bound: bool,
    mu_free: float, beta_free: float,
) -> str:
    """The identifiability sentence of a tension-test fit (:class:`~bendpam.identify.tension.TensionFit`).

    ``mu``, ``beta`` and their standard errors, the C10-C01 correlation, the admissible shapes
    ``bounds`` over the stretches ``span``, whether the shape sits on a bound, and the
    unconstrained fit's ``mu_free``, ``beta_free``.

    >>> tension_identifiability(600.0, 3.0, 0.33, 0.01, -0.9, (-0.15, 1.07), (0.6, 1.6), False, 600.0, 0.33)[:58]
    'The shear modulus mu = 600 +- 3 kPa is determined by the d'
    """
    lo, hi = bounds
    rel = se_mu / mu if mu > 0 else math.inf
    if rel <= LIMITS.tension_mu_se:
        head = (f"The shear modulus mu = {mu:.4g} +- {se_mu:.2g} kPa is determined by "
                "the data")
    else:
        head = (f"The shear modulus mu = {mu:.4g} +- {se_mu:.2g} kPa is only loosely "
                f"determined ({100 * rel:.0f} %)")
    adm = (f"the admissible [{lo:.4g}, {hi:.4g}] for stretches "
           f"[{span[0]:g}, {span[1]:g}]")
    if at_bound:
        if not mu_free > 0.0:
            why = f"the unconstrained fit has mu = {mu_free:.4g} kPa <= 0"
        else:
            why = f"the unconstrained fit wants beta = {beta_free:.4g}, outside {adm}"
        return (f"{head}; the shape is not: {why}, so beta = C01/(C10 + C01) sits at "
                f"the bound {beta:.4g}, set by the admissibility rule, not the data.")
    width = hi - lo
    frac = 2.0 * _Z95 * se_beta / width if width > 0 else math.inf
    if frac <= LIMITS.shape_resolved:
        return (f"{head}; so is the shape beta = C01/(C10 + C01) = {beta:.4g} +- "
                f"{se_beta:.2g} (its 95 % interval covers {100 * frac:.0f} % of "
                f"{adm}).")
    return (f"{head}; the shape is not: beta = {beta:.4g} +- {se_beta:.2g}, whose 95 % "
            f"interval covers {100 * frac:.0f} % of {adm}, so only C10 + C01 = mu/2 is "
            f"reliable, not C10 and C01 apart (correlation {corr:+.3f}).")


# ------------------------------------------------------------------------------------------------
# the search
# ------------------------------------------------------------------------------------------------
_LIMIT_WORDS = ("max", "limit", "iteration", "evaluation", "budget", "nfev")


def search_state(converged: bool, message: str = "") -> str:
    """How a search ended, from its ``converged`` flag and the optimiser's message.

    One of ``"limit"`` (stopped at its evaluation limit), ``"not-converged"``, ``"exact"`` (every
    parameter linear: solved exactly), ``"gradient"`` (the error no longer changes with any
    parameter), ``"ftol"`` (the error stopped decreasing) or ``"converged"`` (the parameters
    stopped changing).

    >>> search_state(True, "`gtol` termination condition is satisfied."), search_state(False, "iteration limit")
    ('gradient', 'limit')
    """
    msg = str(message or "").lower()
    if not converged:
        return "limit" if any(w in msg for w in _LIMIT_WORDS) else "not-converged"
    if "linear" in msg and "exact" in msg:
        return "exact"
    if "gtol" in msg or "gradient" in msg:
        return "gradient"
    if "ftol" in msg:
        return "ftol"
    return "converged"


# ------------------------------------------------------------------------------------------------
# what is wrong with a fit, and with the data
# ------------------------------------------------------------------------------------------------
def judge_fit(model: str, res) -> list[Finding]:
    """What is wrong with one fit: poor, not converged, parameters at a bound, correlated pairs, a fold.

    ``res`` is a :class:`~bendpam.identify.result.FitResult` (or anything with its ``metrics``,
    ``converged``, ``parameters``, ``correlation`` and ``correlation_names``).

    >>> from types import SimpleNamespace as NS
    >>> res = NS(metrics=NS(nrmse_cycles=0.3, nrmse_blocked_moment=0.05, nrmse_free_curvature=0.25,
    ...                     no_equilibrium_kpa=[]), converged=True, parameters={}, correlation=np.eye(1),
    ...          correlation_names=["alpha0"])
    >>> [(f.kind, dict(f.facts)) for f in judge_fit("energy", res)]
    [('poor-fit', {'nrmse': {'cycles': 0.3, 'free_curvature': 0.25}})]
    """
    out: list[Finding] = []
    m = res.metrics
    bad = {}
    if _finite(m.nrmse_cycles) and m.nrmse_cycles > LIMITS.nrmse_cycles:
        bad["cycles"] = m.nrmse_cycles
    for what, v in (("blocked_moment", m.nrmse_blocked_moment), ("free_curvature", m.nrmse_free_curvature)):
        if _finite(v) and v > LIMITS.nrmse_points:
            bad[what] = v
    if bad:
        out.append(Finding("poor-fit", "", model, facts={"nrmse": bad}))
    if not res.converged:
        out.append(Finding("not-converged", "", model))
    for name, p in res.parameters.items():
        side = at_bound(p)
        if side is not None:
            out.append(Finding("at-bound", name, model, facts={"side": side, "value": p.value, "min": p.min,
                                                               "max": p.max}))
    out += _shear_modulus_at_bound(model, res)
    out += _correlated(model, res)
    no_eq = list(getattr(m, "no_equilibrium_kpa", []) or [])
    if no_eq:
        out.append(Finding("fold", "", model, facts={"pressures_kpa": no_eq}))
    return out


def _shear_modulus_at_bound(model: str, res) -> list[Finding]:
    """The shear modulus 2 (C10 + C01) at its lower bound of 2 kPa (both constants varied)."""
    c10, c01 = res.parameters.get("C10"), res.parameters.get("C01")
    if c10 is None or c01 is None or not (c10.vary and c01.vary):
        return []
    total, lo = c10.value + c01.value, 1.0
    span = (c10.max + c01.max) - lo
    if _finite(total) and _finite(span) and span > 0 and total - lo <= LIMITS.bound_fraction * span:
        return [Finding("at-bound", "mu", model, facts={"mu": 2 * total})]
    return []


def _correlated(model: str, res) -> list[Finding]:
    """The pairs of fitted parameters with ``|r| > LIMITS.correlation`` (a caution)."""
    names = list(res.correlation_names)
    pairs = []
    for i in range(len(names)):
        for j in range(i + 1, len(names)):
            r = res.correlation[i, j]
            if _finite(r) and abs(float(r)) > LIMITS.correlation:
                pairs.append((names[i], names[j], float(r)))
    if not pairs:
        return []
    cc = any({a, b} == {"C10", "C01"} for a, b, _ in pairs)
    return [Finding("correlated", ",".join(f"{a}+{b}" for a, b, _ in pairs), model, "caution",
                    {"pairs": pairs, "C10_C01": cc})]


def _deadband(processed, actuator: Actuator, fits: Mapping) -> list[Finding]:
    """The measured deadband against the actuator's P_start (:class:`Limits`)."""
    p0, p0_se = processed.deadband()
    ps = float(actuator.P_start_kpa)
    if not _finite(p0):
        return []
    d = float(p0) - ps
    limit = max(LIMITS.deadband_kpa, LIMITS.deadband_fraction * ps)
    if not (abs(d) > limit and (not _finite(p0_se) or abs(d) > LIMITS.deadband_se * float(p0_se))):
        return []
    fitted = {m: r.parameters["P_start"].value for m, r in fits.items()
              if "P_start" in r.parameters and r.parameters["P_start"].vary}
    return [Finding("deadband", facts={"deadband_kpa": p0, "deadband_se_kpa": p0_se, "P_start_kpa": ps,
                                       "difference_kpa": d, "limit_kpa": limit, "fitted_P_start_kpa": fitted})]


_KIND_RE = re.compile(r"\b(B[EC])[\s-]?PAMs?\b", re.IGNORECASE)


def _metadata_kinds(metadata: Iterable[tuple[str, Mapping]]) -> dict[str, str]:
    """Actuator types named in the files' metadata: ``{"BE-PAM": "file: key: value", ...}``."""
    found: dict[str, str] = {}
    for name, meta in metadata:
        for k, v in (meta or {}).items():
            for m in _KIND_RE.finditer(f"{k}: {v}"):
                kind = m.group(1).upper() + "-PAM"
                found.setdefault(kind, f"{name}: “{k}: {v}”")
    return found


def _nrmse(res) -> float:
    return float(res.metrics.nrmse_cycles) if res is not None and _finite(res.metrics.nrmse_cycles) else math.nan


def _direction(actuator: Actuator, fits: Mapping, metadata, comparison, failed) -> list[Finding]:
    """Evidence that the data bend the other way than the actuator's type (:func:`judge_data`)."""
    kind = actuator.kind
    if kind not in ("BE-PAM", "BC-PAM"):
        return []
    other = "BC-PAM" if kind == "BE-PAM" else "BE-PAM"
    evidence: list[dict[str, Any]] = []
    named = _metadata_kinds(metadata)
    if other in named and kind not in named:
        evidence.append({"source": "metadata", "where": named[other]})
    first: Any = next(iter(fits.values()), None)
    chosen = _nrmse(first)
    poor = (first is None and bool(failed)) or (_finite(chosen) and chosen > LIMITS.nrmse_cycles)
    if poor and comparison is not None:
        same, alt = comparison
        e_same, e_alt = _nrmse(same), _nrmse(alt)
        if _finite(e_alt) and e_alt <= LIMITS.nrmse_cycles and (not _finite(e_same)
                                                               or e_alt * LIMITS.direction_ratio < e_same):
            evidence.append({"source": "comparison", "nrmse_other": e_alt, "nrmse_same": e_same,
                             "alpha0_other_deg": alt.parameters["alpha0"].value})
    if poor and first is not None and "alpha0" in first.parameters:
        side = at_bound(first.parameters["alpha0"])
        if (side == "upper" and kind == "BC-PAM") or (side == "lower" and kind == "BE-PAM"):
            evidence.append({"source": "alpha0-bound"})
    if not evidence:
        return []
    return [Finding("direction", facts={"kind": kind, "other": other, "evidence": evidence})]


def judge_data(processed, actuator: Actuator, fits: Mapping, *, metadata: Iterable[tuple[str, Mapping]] = (),
               comparison=None, failed: Mapping[str, str] | None = None) -> list[Finding]:
    """What is wrong with the data against the actuator: models that failed, the deadband, the bending direction.

    * ``fit-failed``: each model of ``failed`` (``{model: reason}``);
    * ``deadband``: the measured deadband ``P0 ± se`` (x-intercept of the blocked moment against
      pressure, ``processed.deadband()``) differs from the actuator's ``P_start`` by more than
      ``max(15 kPa, 30 % P_start)`` and by more than two standard errors (:class:`Limits`);
    * ``direction``: the data bend the other way than the actuator's type (a BE-PAM bends toward the
      frame, k' > 0; a BC-PAM away from it).  The tests record magnitudes, so the evidence is
      indirect; any of these counts: the files' ``metadata`` (``(file name, {key: value})``) name the
      other type; with the chosen type's fit (the first of ``fits``) poor or failed, an actuator of
      the other type fitted with the same freedom (``comparison``, ``(same, other)`` from
      :func:`bendpam.identify.compare.type_comparison`) reproduces the cycles within the NRMSE limit
      and at least 1.5 times better than the chosen type; or the chosen fit is poor with alpha0 pinned
      at the bound next to 54.74 deg.

    >>> from types import SimpleNamespace as NS
    >>> import bendpam
    >>> tests = NS(deadband=lambda: (48.0, 0.5))
    >>> [f.kind for f in judge_data(tests, bendpam.physics.presets.be_pam().replace(P_start_kpa=32.0), {})]
    ['deadband']
    """
    out = [Finding("fit-failed", "", model, facts={"reason": why}) for model, why in (failed or {}).items()]
    out += _deadband(processed, actuator, fits)
    out += _direction(actuator, fits, metadata, comparison, failed)
    return out


def judge(processed, actuator: Actuator, fits: Mapping, *, metadata: Iterable[tuple[str, Mapping]] = (),
          comparison=None, failed: Mapping[str, str] | None = None) -> list[Finding]:
    """Every finding about ``fits`` (``{model: FitResult}``) and the data, most serious first.

    :func:`judge_fit` of each fit, then :func:`judge_data` (its arguments); warnings before
    cautions, each in the order of :data:`KINDS`.

    >>> from types import SimpleNamespace as NS
    >>> import bendpam
    >>> tests = NS(deadband=lambda: (48.0, 0.5))
    >>> [f.kind for f in judge(tests, bendpam.physics.presets.be_pam().replace(P_start_kpa=32.0), {},
    ...                        failed={"energy": "P_start is above the lowest pressure"})]
    ['deadband', 'fit-failed']
    """
    out = [f for model, res in fits.items() for f in judge_fit(model, res)]
    out += judge_data(processed, actuator, fits, metadata=metadata, comparison=comparison, failed=failed)
    order = {k: i for i, k in enumerate(KINDS)}
    return sorted(out, key=lambda f: (f.severity != "warning", order.get(f.kind, len(KINDS))))


def needs_type_check(fits: Mapping) -> bool:
    """Whether the chosen actuator type (the first fit) fails to reproduce the cycles within ``LIMITS.nrmse_cycles``.

    Only then is the other type worth fitting (:func:`bendpam.identify.compare.type_comparison`).

    >>> from types import SimpleNamespace as NS
    >>> needs_type_check({}), needs_type_check({"energy": NS(metrics=NS(nrmse_cycles=0.04))})
    (True, False)
    """
    first = next(iter(fits.values()), None)
    return first is None or not (_finite(first.metrics.nrmse_cycles)
                                 and first.metrics.nrmse_cycles <= LIMITS.nrmse_cycles)
