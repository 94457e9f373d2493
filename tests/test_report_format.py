"""The report's words and numbers: one number format, symbols with units, plain diagnostics, warnings.

Hand examples throughout; the warnings are checked on small hand-made fits (no fitting), and on a
BE-PAM test set fitted as a BC-PAM (the README's old example) at the library level.
"""

import math
from types import SimpleNamespace as NS

import numpy as np
import pytest

from bendpam import presets
from bendpam.identify.compare import type_comparison
from bendpam.identify.diagnose import CORRELATION_LIMIT, NRMSE_CYCLES_LIMIT
from bendpam.identify.fitting import fit
from bendpam.lab.processing import process_tests
from bendpam.lab.simulate import SimulationSettings, simulate_tests
from bendpam.present.report import (
    SYMBOLS,
    describe_status,
    fmt_pct,
    fmt_value,
    report_warnings,
    symbol,
    table3_rows,
)

NB = "\u202f"  # the narrow no-break space between digit groups


def g(text: str) -> str:
    """The text with digit groups separated by ordinary spaces (easier to write by hand)."""
    return text.replace(NB, " ")


# ------------------------------------------------------------------------------------------------
# numbers
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("value", "se", "unit", "text"), [
    # the standard error to 2 significant digits, the value to the same decimal place
    (69.7345, 0.0119, "", "69.735 ± 0.012"),
    (69.7345, 0.0119, "°", "(69.735 ± 0.012)°"),
    (4666.2, 1523.0, "kPa", "(4700 ± 1500) kPa"),
    (-318.94, 7.43, "kPa", "(−318.9 ± 7.4) kPa"),
    (0.002676, 3.8e-7, "", "0.002 676 00 ± 0.000 000 38"),   # the audit's 0.002676 ± 3.8e-07
    (0.00267687, 2.9e-7, "", "0.002 676 87 ± 0.000 000 29"),
    (2.676e-4, 3.8e-8, "", "(2.676 00 ± 0.000 38) × 10⁻⁴"),  # below 10^-3: a common power of ten
    (123456.0, 20000.0, "", "(1.23 ± 0.20) × 10⁵"),          # from 10^5 up too
    (9.996, 0.0996, "", "10.00 ± 0.10"),                      # 0.0996 rounds up to 0.10: one decimal fewer
    (3.2, 150.0, "", "0 ± 150"),                              # an error larger than the value
    (0.0, 0.5, "", "0.00 ± 0.50"),
    (80.06, 0.8145, "N·mm", "(80.06 ± 0.81) N·mm"),
    (329.28, 0.0, "N·mm", "(329.3 ± 0) N·mm"),                # an error of exactly 0
    (0.0125, 0.00125, "", "0.0125 ± 0.0013"),                 # half up, as written in decimal
])
def test_value_with_standard_error(value, se, unit, text):
    assert g(fmt_value(value, se, unit)) == text


@pytest.mark.parametrize(("value", "kwargs", "text"), [
    (69.7345, {}, "69.73"),                 # four significant digits
    (69.7, {"unit": "°"}, "69.70°"),
    (32.0, {"unit": "kPa"}, "32.00 kPa"),
    (4666.2, {}, "4666"),
    (12345.6, {}, "12 350"),                # more than four digits: grouped
    (99995.0, {}, "1.000 × 10⁵"),           # rounds up into the next decade
    (0.0026760, {}, "0.002 676"),
    (-4e-5, {}, "−4.000 × 10⁻⁵"),
    (1.5e6, {}, "1.500 × 10⁶"),
    (0.0, {}, "0"),
    (56.843, {"sig": 3}, "56.8"),
    (5.0, {"unit": ""}, "5.000"),
])
def test_value_without_standard_error(value, kwargs, text):
    assert g(fmt_value(value, **kwargs)) == text


def test_missing_values_and_bad_digits():
    for bad in (None, math.nan, math.inf, -math.inf, "x"):
        assert fmt_value(bad) == "—"
    # a missing or negative standard error: the value alone
    assert fmt_value(1.2345, None) == fmt_value(1.2345, math.nan) == fmt_value(1.2345, -1.0) == "1.235"
    assert fmt_value(-0.00001, 0.5) == "0.00 ± 0.50"  # no negative zero
    with pytest.raises(ValueError, match="sig"):
        fmt_value(1.0, sig=0)


def test_percentages():
    assert fmt_pct(0.56843) == "56.8"
    assert fmt_pct(0.011497) == "1.15"
    assert fmt_pct(0.10, sig=2) == "10"
    assert fmt_pct(None) == fmt_pct(math.nan) == "—"


# ------------------------------------------------------------------------------------------------
# symbols, units, words
# ------------------------------------------------------------------------------------------------
def test_symbols_with_units():
    assert symbol("alpha0").heading(False) == "α₀ (°)"
    assert symbol("alpha0_deg") is symbol("alpha0")
    assert symbol("C10_kpa").heading(False) == "C₁₀ (kPa)"
    assert symbol("C01").html == "C<sub>01</sub>"
    assert symbol("P_start_kpa").heading() == "P<sub>start</sub> (kPa)"
    assert symbol("frame_modulus_mpa").heading(False) == "E_f (MPa)"
    assert symbol("shear_modulus_kpa").text == "μ" and "shear modulus" in symbol("mu").meaning
    assert symbol("theta_h_deg").unit == "°" and symbol("a1_nmm_per_kpa").unit == "N·mm/kPa"
    # a field without a symbol of its own is shown in words, its unit from its name
    assert symbol("tip_load_n").heading(False) == "tip load (N)"
    assert symbol("reach_per_mm").heading(False) == "reach (1/mm)"
    for s in SYMBOLS.values():
        assert s.text and s.html and s.meaning and "_kpa" not in s.meaning and "_deg" not in s.meaning


def test_every_actuator_and_fit_field_has_a_display_name():
    from bendpam.identify.result import HYST_PARAMETERS, PARAMETERS

    act = presets.be_pam()
    names = [*act.to_dict(), *act.derived()]
    names += [f for f, _ in PARAMETERS.values()] + list(PARAMETERS)
    names += [f for f, _ in HYST_PARAMETERS.values()] + list(HYST_PARAMETERS)
    for n in names:
        if n in ("name", "model"):
            continue
        s = symbol(n)
        assert s in SYMBOLS.values(), f"{n} has no symbol of its own"
        assert s.html != n, f"{n} is shown by its code name"


@pytest.mark.parametrize(("converged", "message", "words"), [
    (True, "`gtol` termination condition is satisfied.", "no longer changes"),
    (True, "`xtol` termination condition is satisfied.", "stopped changing"),
    (True, "`ftol` termination condition is satisfied.", "stopped decreasing"),
    (True, "converged", "stopped changing"),
    (True, "linear least squares (exact)", "solved exactly"),
    (False, "The maximum number of function evaluations is exceeded.", "evaluation limit"),
    (False, "the search stopped before converging (iteration limit)", "evaluation limit"),
    (False, "something else", "did not converge"),
])
def test_status_in_plain_words(converged, message, words):
    text = describe_status(converged, message)
    assert words in text and text.endswith(".")
    for raw in ("gtol", "xtol", "ftol", "termination", "`"):
        assert raw not in text


# ------------------------------------------------------------------------------------------------
# warnings on hand-made fits
# ------------------------------------------------------------------------------------------------
def _param(value, lo, hi, se=0.1, vary=True):
    return NS(value=value, stderr=se, min=lo, max=hi, vary=vary, initial=value)


def _fit(nrmse=0.02, alpha0=(69.7, 62.73, 76.67), corr=-0.5, converged=True, no_eq=(), bm=0.02, fbc=0.05):
    params = {"alpha0": _param(*alpha0), "C10": _param(-300.0, -5000.0, 5000.0, 8.0),
              "C01": _param(500.0, -5000.0, 5000.0, 8.0), "P_start": _param(68.0, 0.0, 98.0, None, vary=False)}
    return NS(parameters=params, correlation=np.array([[1.0, 0.1, 0.1], [0.1, 1.0, corr], [0.1, corr, 1.0]]),
              correlation_names=["alpha0", "C10", "C01"], converged=converged, message="converged", material=None,
              metrics=NS(nrmse_cycles=nrmse, nrmse_blocked_moment=bm, nrmse_free_curvature=fbc,
                         no_equilibrium_kpa=list(no_eq)))


def _processed(p0=68.0, se=0.5):
    return NS(deadband=lambda: (p0, se))


def _kinds(warnings):
    return sorted(w.kind for w in warnings)


def test_a_good_fit_raises_nothing():
    act = presets.be_pam()
    assert report_warnings(_processed(), act, {"energy": _fit()}) == []


def test_poor_fit_threshold():
    act = presets.be_pam()
    assert _kinds(report_warnings(_processed(), act, {"energy": _fit(nrmse=0.9 * NRMSE_CYCLES_LIMIT)})) == []
    w = report_warnings(_processed(), act, {"energy": _fit(nrmse=1.1 * NRMSE_CYCLES_LIMIT)})
    assert _kinds(w) == ["poor-fit"] and "11.0 %" in w[0].title and w[0].models == ("energy",)
    # the blocked moment and free-bending curvature have their own, wider limit (20 %)
    assert _kinds(report_warnings(_processed(), act, {"energy": _fit(bm=0.19, fbc=0.19)})) == []
    assert _kinds(report_warnings(_processed(), act, {"energy": _fit(fbc=0.21)})) == ["poor-fit"]


def test_bound_correlation_convergence_and_fold():
    act = presets.be_pam()
    span = 76.67 - 62.73
    near = report_warnings(_processed(), act, {"energy": _fit(alpha0=(76.67 - 0.5e-3 * span, 62.73, 76.67))})
    assert _kinds(near) == ["at-bound"] and "upper bound" in near[0].title and "α₀" in near[0].title
    off = report_warnings(_processed(), act, {"energy": _fit(alpha0=(76.67 - 2e-3 * span, 62.73, 76.67))})
    assert off == []
    corr = report_warnings(_processed(), act, {"energy": _fit(corr=-(CORRELATION_LIMIT + 0.01))})
    assert _kinds(corr) == ["correlated"] and corr[0].severity == "caution" and "C₁₀ and C₀₁" in corr[0].title
    assert report_warnings(_processed(), act, {"energy": _fit(corr=-(CORRELATION_LIMIT - 0.01))}) == []
    assert _kinds(report_warnings(_processed(), act, {"energy": _fit(converged=False)})) == ["not-converged"]
    fold = report_warnings(_processed(), act, {"energy": _fit(no_eq=[200.0])})
    assert _kinds(fold) == ["fold"] and "200 kPa" in fold[0].title


def test_the_same_problem_in_two_models_is_one_warning():
    act = presets.be_pam()
    w = report_warnings(_processed(), act, {"energy": _fit(nrmse=0.5), "force_balance": _fit(nrmse=0.6)})
    assert _kinds(w) == ["poor-fit"] and w[0].models == ("energy", "force_balance")
    assert "energy model" in w[0].title and "force-balance model" in w[0].title and "60.0 %" in w[0].title


@pytest.mark.parametrize(("p0", "se", "p_start", "warned"), [
    (48.0, 0.5, 32.0, True),    # 16 kPa apart > max(15 kPa, 30 % of 32 kPa)
    (46.0, 0.5, 32.0, False),   # 14 kPa apart
    (87.0, 0.5, 68.0, False),   # 19 kPa apart < 30 % of 68 kPa = 20.4 kPa
    (90.0, 0.5, 68.0, True),    # 22 kPa apart
    (48.0, 9.0, 32.0, False),   # 16 kPa apart, but within two standard errors
    (math.nan, math.nan, 32.0, False),  # no deadband (fewer than two pressures)
])
def test_deadband_against_p_start(p0, se, p_start, warned):
    act = presets.be_pam().replace(P_start_kpa=p_start)
    w = report_warnings(_processed(p0, se), act, {"energy": _fit()})
    assert ("deadband" in _kinds(w)) is warned
    if warned:
        assert "far from the actuator's P_start" in w[0].title


def test_direction_from_the_files_metadata():
    act = presets.bc_pam()
    meta = [("a_100kPa.csv", {"Actuator": "BE-PAM no. 3"})]
    w = report_warnings(_processed(32.0), act, {"energy": _fit(alpha0=(36.6, 32.9, 40.2))}, metadata=meta)
    assert _kinds(w) == ["direction"]
    assert "look like a BE-PAM" in w[0].title and "a_100kPa.csv" in w[0].meaning and "--preset be-pam" in w[0].action
    # the files naming the actuator's own type: nothing
    same = [("a_100kPa.csv", {"Specimen": "BC PAM"})]
    assert report_warnings(_processed(32.0), act, {"energy": _fit(alpha0=(36.6, 32.9, 40.2))}, metadata=same) == []


def test_direction_from_a_better_fit_of_the_other_type():
    act = presets.bc_pam()
    poor = _fit(nrmse=0.5, alpha0=(36.6, 32.9, 40.2))
    other = _fit(nrmse=0.03)
    same_type = _fit(nrmse=0.2)
    w = report_warnings(_processed(32.0), act, {"energy": poor}, comparison=(same_type, other))
    assert _kinds(w) == ["direction", "poor-fit"] and "within 3.00 %" in w[0].meaning
    # the same type, given the same freedom, does about as well: no evidence
    close = _fit(nrmse=0.04)
    assert _kinds(report_warnings(_processed(32.0), act, {"energy": poor}, comparison=(close, other))) == ["poor-fit"]
    # a good fit of the chosen type is never second-guessed
    assert report_warnings(_processed(32.0), act, {"energy": _fit(alpha0=(36.6, 32.9, 40.2))},
                           comparison=(same_type, other)) == []


# ------------------------------------------------------------------------------------------------
# the README's old example, at the library level: BE-PAM tests fitted as a BC-PAM
# ------------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def be_processed(tmp_path_factory):
    from bendpam.lab import read_test

    out = tmp_path_factory.mktemp("be")
    simulate_tests(presets.be_pam("energy"), [100, 150, 200], out, "energy", dialect="csv",
                   settings=SimulationSettings(seed=11, cycles=2))
    return process_tests([read_test(f) for f in sorted(out.glob("*.csv"))])


def test_be_pam_data_with_the_bc_pam_preset(be_processed):
    bc = presets.bc_pam("energy")
    fits = {"energy": fit(be_processed, bc, "energy")}
    # no metadata: the evidence of the direction comes from the fits alone
    w = report_warnings(be_processed, bc, fits, comparison=type_comparison(be_processed, bc, "energy"))
    kinds = _kinds(w)
    assert "deadband" in kinds and "direction" in kinds and "poor-fit" in kinds, [x.title for x in w]
    assert w[0].kind == "direction" and w[1].kind == "deadband"  # most serious first
    dead = next(x for x in w if x.kind == "deadband")
    p0, se = be_processed.deadband()
    assert fmt_value(p0, se, "kPa") in dead.title and "32.00 kPa" in dead.title
    assert abs(p0 - 68.0) < 1.0  # the BE-PAM's P_start, measured
    # the right preset: no warning but cautions
    be = presets.be_pam("energy")
    good = {"energy": fit(be_processed, be, "energy")}
    assert all(x.severity == "caution" for x in report_warnings(be_processed, be, good))
    # Table 3's row: ± with matching digits, a bound marked
    row = table3_rows(fits)[0]
    assert " ± " in row["alpha0"] and row["alpha0"].endswith(" *")
