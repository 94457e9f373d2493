"""The findings of :mod:`bendpam.identify.diagnose` in words: the report's warning box and its notes on each fit.

The report judges nothing itself: :func:`bendpam.identify.diagnose.judge` says what is wrong with
the fits and the data, and :func:`report_warnings` puts each finding into a title, what it means
and what to try (:class:`ReportWarning`); the same problem in two models is one warning that
names both.  :func:`diagnosis` describes one fit's search in plain sentences, :func:`fit_notes`
collects the notes the fit itself carries.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from bendpam.identify.diagnose import LIMITS, Finding, judge, judge_fit
from bendpam.physics.actuator import Actuator
from bendpam.present.report.tables import shear_modulus
from bendpam.present.report.text import (
    MODEL_LABEL,
    corr_text,
    describe_status,
    finite,
    fmt_pct,
    fmt_value,
    plain_text,
    symbol,
)

__all__ = ["ReportWarning", "diagnosis", "fit_notes", "plausibility_warnings", "report_warnings"]


@dataclass(frozen=True)
class ReportWarning:
    """A problem the report shows in its warning box.

    Attributes
    ----------
    kind : ``"fit-failed"``, ``"poor-fit"``, ``"not-converged"``, ``"at-bound"``, ``"correlated"``,
        ``"fold"``, ``"deadband"`` or ``"direction"`` (:data:`bendpam.identify.diagnose.KINDS`), or
        ``"implausible"`` (a test no bending actuator gives: :func:`plausibility_warnings`) or ``"drift"`` (a
        load-cell offset that drifts, :mod:`bendpam.lab.drift`).
    title : one line (plain text with symbols such as α₀ and P_start).
    meaning : what it means for the results.
    action : what to try.
    models : the models it concerns (empty for a problem of the data).
    severity : ``"warning"`` (the results should not be used as they are) or ``"caution"``.

    Examples
    --------
    >>> w = ReportWarning("fold", "No free-bending equilibrium: energy model (at 200 kPa)", "The law folds.",
    ...                   "Compare with Figure 7.", ("energy",))
    >>> w.text()
    'No free-bending equilibrium: energy model (at 200 kPa). The law folds. Compare with Figure 7.'
    """

    kind: str
    title: str
    meaning: str
    action: str
    models: tuple[str, ...] = ()
    severity: str = "warning"

    def text(self) -> str:
        """The warning as plain text on one line (for a terminal)."""
        return plain_text(f"{self.title}. {self.meaning} {self.action}")


# ------------------------------------------------------------------------------------------------
# one fit's findings: (head, detail, meaning, action); the same (kind, key) of several models is merged
# ------------------------------------------------------------------------------------------------
_NRMSE_WHAT = {"cycles": "loading cycles", "blocked_moment": "blocked moment",
               "free_curvature": "free-bending curvature"}


def _poor_fit(f: Finding, res) -> tuple[str, str, str, str]:
    bad = [f"{_NRMSE_WHAT[k]} {fmt_pct(v)} %" for k, v in f.facts["nrmse"].items()]
    return ("Poor fit", "NRMSE of the " + ", of the ".join(bad),
            f"The fitted model misses the measured curves by far more than the paper's fits (3-9 %; the limits here "
            f"are {fmt_pct(LIMITS.nrmse_cycles, sig=2)} % for the loading cycles and "
            f"{fmt_pct(LIMITS.nrmse_points, sig=2)} % for the blocked moment and free-bending curvature), so its "
            "parameters do not describe this actuator.",
            "Check that the preset or actuator file is the actuator that was tested (its type, geometry and "
            "P_start), look at Figure 7 for where the model leaves the data, and consider fitting P_start too "
            "(`--free alpha0,C10,C01,P_start`).")


def _not_converged(f: Finding, res) -> tuple[str, str, str, str]:
    return ("The search did not converge", "",
            "The parameters are where the search stopped, not necessarily the best fit.",
            "Fit fewer parameters (a narrower `--free`), or check the data for outliers in Figure 4.")


def _at_bound(f: Finding, res) -> tuple[str, str, str, str]:
    if f.key == "mu":
        return ("The shear modulus μ = 2(C₁₀ + C₀₁) is at its lower bound",
                f"μ = {fmt_value(f.facts['mu'], unit='kPa')}",
                "The fit wants a bladder without stiffness (or with a negative one), which is not physical.",
                "Check the actuator's geometry and P_start, or fix C₁₀ and C₀₁ from a tension test (`--tension`).")
    sym, x = symbol(f.key), f.facts
    return (f"{sym.text} is at a bound of its allowed range",
            f"{fmt_value(x['value'], unit=sym.unit)}, the {x['side']} bound of {fmt_value(x['min'], unit=sym.unit)} "
            f"to {fmt_value(x['max'], unit=sym.unit)}",
            "The fit would move it further if it could, so the value is set by the bound, not by the data, and "
            "its standard error means nothing.",
            ("Check that the actuator's type and nominal α₀ are right (the range is ±10 % of the nominal value, "
             "on the actuator's side of 54.74°)." if f.key == "alpha0" else
             "Check the nominal values and units of the actuator, or hold this parameter fixed."))


def _correlated(f: Finding, res) -> tuple[str, str, str, str]:
    pairs, cc = f.facts["pairs"], f.facts["C10_C01"]
    mu, mu_se = shear_modulus(res)
    detail = ", ".join((f"{symbol(a).text}–{symbol(b).text} " if len(pairs) > 1 else "") + f"r = {corr_text(r)}"
                       for a, b, r in pairs)
    if cc and mu is not None and finite(mu):
        detail += f"; μ = {fmt_value(mu, mu_se, 'kPa')}"
    return ("Strongly correlated parameters: " + "; ".join(f"{symbol(a).text} and {symbol(b).text}"
                                                           for a, b, _ in pairs),
            detail,
            "The data determine a combination of each pair, not each one: the values trade off against each other "
            "and their standard errors are large."
            + (" For C₁₀ and C₀₁ the combination that is determined is the shear modulus μ = 2(C₁₀ + C₀₁), given "
               "in the title and in Table 3." if cc else ""),
            "Report the combination, hold one parameter of the pair fixed (e.g. `--free alpha0,C10`), or measure "
            "C₁₀ and C₀₁ in a tension test (`--tension`).")


def _fold(f: Finding, res) -> tuple[str, str, str, str]:
    return ("No free-bending equilibrium inside the tested range",
            "at " + ", ".join(f"{p:g}" for p in f.facts["pressures_kpa"]) + " kPa",
            "The fitted moment law folds there (snap-through): the model has no free-bending state although "
            "the test found one, and those pressures are left out of the free-curvature error.",
            "Compare the model with the data in Figure 7 (c); a fold inside the tested range usually means that "
            "the parameters are wrong or that the actuator type does not match.")


_FIT_WORDS = {"poor-fit": _poor_fit, "not-converged": _not_converged, "at-bound": _at_bound,
              "correlated": _correlated, "fold": _fold}


def _fit_warning(findings: Sequence[Finding], fits: Mapping) -> ReportWarning:
    """One warning for the same finding of one or more models, naming each model with its own detail."""
    f0 = findings[0]
    head, _, meaning, action = _FIT_WORDS[f0.kind](f0, fits.get(f0.model))
    parts = []
    for f in findings:
        detail = _FIT_WORDS[f.kind](f, fits.get(f.model))[1]
        parts.append(f"{MODEL_LABEL.get(f.model, f.model)} model" + (f" ({detail})" if detail else ""))
    return ReportWarning(f0.kind, f"{head}: " + "; ".join(parts), meaning, action, tuple(f.model for f in findings),
                         f0.severity)


# ------------------------------------------------------------------------------------------------
# the data's findings
# ------------------------------------------------------------------------------------------------
def _fit_failed(f: Finding) -> ReportWarning:
    return ReportWarning(
        "fit-failed", f"The {MODEL_LABEL.get(f.model, f.model)} model could not be fitted: {f.facts['reason']}",
        "No parameters of this model reproduce the tests, so it is left out of the tables and figures.",
        "Check that the actuator's type, geometry and P_start are those of the tested actuator (see the "
        "other warnings), or fit P_start too (`--free alpha0,C10,C01,P_start`).", (f.model,))


def _deadband(f: Finding) -> ReportWarning:
    x = f.facts
    d, limit = x["difference_kpa"], x["limit_kpa"]
    fitted = [f"{MODEL_LABEL.get(m, m)} model {fmt_value(v, unit='kPa')}" for m, v in x["fitted_P_start_kpa"].items()]
    return ReportWarning(
        "deadband", f"The measured deadband, {fmt_value(x['deadband_kpa'], x['deadband_se_kpa'], 'kPa')}, is far "
        f"from the actuator's P_start of {fmt_value(x['P_start_kpa'], unit='kPa')}",
        f"The blocked moment extrapolates to zero {fmt_value(abs(d), sig=2, unit='kPa')} "
        f"{'above' if d > 0 else 'below'} the pressure at which the model lets the bladder start to act "
        f"(more than {fmt_value(limit, sig=2, unit='kPa')} apart); with the wrong P_start the other "
        "parameters absorb the difference"
        + (f" (fitted P_start: {', '.join(fitted)})." if fitted else "."),
        "Use the actuator that was tested (its preset or an `--actuator` file with its P_start), or fit "
        "P_start too (`--free alpha0,C10,C01,P_start`).")


def _evidence(e: Mapping, kind: str, other: str) -> str:
    if e["source"] == "metadata":
        return f"the files' metadata name a {other} ({e['where']})"
    if e["source"] == "comparison":
        e_same = e["nrmse_same"]
        return (f"given the same freedom (α₀ anywhere on its side of 54.74°, P_start fitted), an actuator of "
                f"the other type reproduces the cycles within {fmt_pct(e['nrmse_other'])} % (α₀ = "
                f"{fmt_value(e['alpha0_other_deg'], unit='°')}), the {kind} "
                + (f"only within {fmt_pct(e_same)} %" if finite(e_same) else "not at all"))
    return "the fit pushes α₀ against the bound next to 54.74°, the angle that separates the two types"


def _direction(f: Finding) -> ReportWarning:
    kind, other = f.facts["kind"], f.facts["other"]
    sense = "toward the frame (k′ > 0)" if other == "BE-PAM" else "away from the frame (k′ < 0)"
    return ReportWarning(
        "direction", f"The data look like a {other}, which bends {sense}, but the actuator is a {kind}",
        "Evidence: " + "; ".join(_evidence(e, kind, other) for e in f.facts["evidence"])
        + ". A model of the wrong type cannot describe the tests, whatever its parameters.",
        f"Check the preset or the actuator file (a {other} has α₀ "
        f"{'above' if other == 'BE-PAM' else 'below'} 54.74°; e.g. `--preset "
        f"{other.lower()}`), and how the actuator was mounted in the fixture.")


_DATA_WORDS = {"fit-failed": _fit_failed, "deadband": _deadband, "direction": _direction}


def plausibility_warnings(processed) -> list[ReportWarning]:
    """A warning per plausibility finding of the processed tests (:mod:`bendpam.lab.plausibility`), naming the test.

    >>> from types import SimpleNamespace as NS
    >>> found = {"check": "loss-ratio", "message": "c.csv (200 kPa): energy-loss ratio 68.0 % is above 60 %: ..."}
    >>> w = plausibility_warnings(NS(findings=[found]))[0]
    >>> w.kind, w.title
    ('implausible', 'Implausible test: c.csv (200 kPa): energy-loss ratio 68.0 % is above 60 %: ...')
    """
    out = []
    for f in getattr(processed, "findings", []):
        if f.get("check") in ("drift", "set drift"):  # bendpam.lab.drift: an instrument fault, not the actuator
            out.append(ReportWarning(
                "drift", f"Load-cell drift: {f['message']}",
                "The force reading drifts across the cycles by more than the fit can tolerate; the blocked moment "
                "and the fitted parameters are biased by it unless it was corrected.",
                "Re-zero the load cell and let it warm up before testing, or process the test with the linear "
                "drift correction."))
            continue
        out.append(ReportWarning(
            "implausible", f"Implausible test: {f['message']}",
            "These numbers cannot come from a bending actuator in this fixture; the tables, the fits and the "
            "deadband include them as they are.",
            "Check that the file is a four-point-bending cyclic test of this actuator and that its force is in N "
            "and its stroke in mm; remove it from the input if it is not."))
    return out


def report_warnings(processed, actuator: Actuator, fits: Mapping, *, metadata: Iterable[tuple[str, Mapping]] = (),
                    comparison=None, failed: Mapping[str, str] | None = None) -> list[ReportWarning]:
    """Everything the report warns about, most serious first: :func:`bendpam.identify.diagnose.judge` in words.

    Per model: a fit that failed, a poor fit, a search that did not converge, parameters at a bound,
    strongly correlated pairs (a caution), no free-bending equilibrium at a tested pressure; for the
    data: a deadband far from P_start and data that bend the other way than the actuator's type
    (the limits and the evidence: :mod:`bendpam.identify.diagnose`).  The same problem in two models
    is one warning naming both.

    Parameters
    ----------
    processed : :class:`~bendpam.lab.processing.ProcessedSet`
    actuator : the nominal :class:`~bendpam.physics.actuator.Actuator` the fits started from.
    fits : ``{model: FitResult}`` of the fits that succeeded.
    metadata : ``(file name, {key: value})`` pairs read from the raw files' headers.
    comparison : ``(same, other)`` from :func:`bendpam.identify.compare.type_comparison`, or None to
        skip that evidence.
    failed : ``{model: reason}`` of the fits that failed.

    Returns
    -------
    list of :class:`ReportWarning`

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> import bendpam
    >>> tests = NS(deadband=lambda: (48.0, 0.5))
    >>> w = report_warnings(tests, bendpam.physics.presets.be_pam().replace(P_start_kpa=32.0), {})
    >>> w[0].kind, w[0].title
    ('deadband', "The measured deadband, (48.00 ± 0.50) kPa, is far from the actuator's P_start of 32.00 kPa")
    """
    out: list = []
    groups: dict[tuple[str, str], list[Finding]] = {}
    for f in judge(processed, actuator, fits, metadata=metadata, comparison=comparison, failed=failed):
        if f.kind in _DATA_WORDS:
            out.append(_DATA_WORDS[f.kind](f))
        elif (f.kind, f.key) in groups:
            groups[(f.kind, f.key)].append(f)
        else:
            groups[(f.kind, f.key)] = [f]
            out.append(groups[(f.kind, f.key)])
    return [_fit_warning(x, fits) if isinstance(x, list) else x for x in out]


# ------------------------------------------------------------------------------------------------
# one fit in plain sentences
# ------------------------------------------------------------------------------------------------
def diagnosis(model: str, res) -> list[str]:
    """Plain sentences about one fit: the search, its cost, the residuals, the size of the error.

    >>> from types import SimpleNamespace as NS
    >>> res = NS(converged=True, message="`ftol` termination condition is satisfied.", nfev=655, time_s=0.23,
    ...          autocorrelation=0.8, metrics=NS(nrmse_cycles=0.04, nrmse_blocked_moment=0.03,
    ...                                          nrmse_free_curvature=0.05, no_equilibrium_kpa=[]),
    ...          parameters={}, correlation=[[1.0]], correlation_names=["alpha0"])
    >>> for sentence in diagnosis("energy", res):
    ...     print(sentence[:60])
    The fit converged: the error stopped decreasing.
    The search evaluated the model 655 times in 0.23 s.
    Neighbouring residuals are strongly correlated (lag-1 autoco
    The model reproduces the loading cycles within 4.00 % (NRMSE
    """
    warned = any(f.severity == "warning" for f in judge_fit(model, res))
    out = [describe_status(bool(res.converged), str(getattr(res, "message", "")))]
    if warned and res.converged:
        out.append("Converging only means that the search found a minimum, not that the model matches the data: "
                   "see the warnings at the top.")
    out.append(f"The search evaluated the model {int(res.nfev)} times in {fmt_value(res.time_s, sig=2)} s.")
    rho = float(getattr(res, "autocorrelation", 0.0) or 0.0)
    if rho > LIMITS.autocorrelation:
        out.append(f"Neighbouring residuals are strongly correlated (lag-1 autocorrelation {rho:.2f}): the model "
                   "misses part of the curves' shape systematically, beyond the measurement noise; the standard "
                   "errors are widened to allow for this.")
    else:
        out.append(f"The residuals look like measurement noise (lag-1 autocorrelation {rho:.2f}).")
    m = res.metrics
    out.append(f"The model reproduces the loading cycles within {fmt_pct(m.nrmse_cycles)} % (NRMSE, eq 53), the "
               f"blocked moment within {fmt_pct(m.nrmse_blocked_moment)} % and the free-bending curvature within "
               f"{fmt_pct(m.nrmse_free_curvature)} %; the paper's fits reach 3.3-5.5 %, 2.6-4.9 % and 1.9-8.8 %.")
    return out


def fit_notes(res) -> list[str]:
    """Plain-language notes a fit carries: its flags and any identifiability notes (as given, once each).

    >>> from types import SimpleNamespace as NS
    >>> fit_notes(NS(flags=["C10_kpa is at a bound"], identifiability=["alpha0 is determined.", ""]))
    ['C10_kpa is at a bound', 'alpha0 is determined.']
    """
    out: list[str] = []
    for attr in ("flags", "notes", "identifiability"):
        v = getattr(res, attr, None)
        if v is None:
            continue
        items = [v] if isinstance(v, str) else (list(v.values()) if isinstance(v, Mapping) else list(v))
        for it in items:
            s = str(it).strip()
            if s and s not in out:
                out.append(s)
    return out
