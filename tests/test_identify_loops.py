"""Identification you can trust (issue 14).

Data come from loop laws written in tests/independent_loops.py (Bouc-Wen, a geometrically spaced
Prandtl-Ishlinskii with equal weights), never from bendpam's own loop or simulator: the fit must
recover alpha0 within 0.2 deg and the shear modulus within 5 %, and its 2-SE intervals must cover
the truth.  Also: admissible materials, one computation behind the loss ratios of ``fit`` and
``predict --cycle``, the fold rule, extrapolation warnings and bands, the joint fit with a tension
test.
"""

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import bendpam
from bendpam import presets
from bendpam.cli import main
from bendpam.identify.diagnose import study_coverage
from bendpam.identify.fitting import _fold_rule, fit
from bendpam.identify.problem import Problem
from bendpam.identify.result import ExtrapolationWarning, FitResult
from bendpam.identify.tension import TensionData
from bendpam.lab import write_test
from bendpam.lab.processing import write_processed
from bendpam.physics.hysteresis import LoopModel, PrandtlIshlinskii, predict_cycle, predict_cycles
from bendpam.physics.material import MooneyRivlin
from independent_loops import BoucWen, GeometricPI, make_truth, noisy_set

PRESSURES = {"be-pam": [100, 125, 150, 175, 200], "bc-pam": [40, 60, 80, 100, 120]}
TRELOAR = Path(__file__).parent / "data" / "treloar_1944_uniaxial.csv"


def admissible_truth(name, model, d_alpha, shape=0.6, mu_factor=1.03):
    """The preset and a truth with alpha0 moved and an admissible material (shape in [0, 1])."""
    base = presets.get(name, model)
    S = (base.C10_kpa + base.C01_kpa) * mu_factor
    return base, base.replace(alpha0_deg=base.alpha0_deg + d_alpha, C10_kpa=S * (1 - shape), C01_kpa=S * shape)


_TRUTHS: dict = {}


def truth_case(name, model, law_key):
    """(base, truth actuator, LoopTruth) built once per session."""
    key = (name, model, law_key)
    if key not in _TRUTHS:
        laws = {"bouc-wen": BoucWen(), "bouc-wen-1": BoucWen(math.radians(2.0), 1.0, 0.5),
                "geometric-pi": GeometricPI(), "none": BoucWen()}
        base, truth = admissible_truth(name, model, 0.8 if name == "be-pam" else -0.6)
        kw = dict(frac=0.0, offset_nmm=0.0) if law_key == "none" else {}
        _TRUTHS[key] = (base, truth, make_truth(truth, PRESSURES[name], model, law=laws[law_key], **kw))
    return _TRUTHS[key]


def realistic(lt, fraction=0.01):
    """Noise of ``fraction`` of the median blocked moment (N*mm): inside the 0.5-3 % of real tests (issue 23).

    At the 0.3 N*mm of ``noisy_set``'s default (about 0.1 %) the loop law's misfit biases alpha0 by ten
    times the seed-to-seed spread, more than error bars scaled to the noise can cover (docs: calibration).
    """
    return fraction * float(np.median(lt.loading[:, 0, 0]))


def errors(r, truth, lt):
    a, m = r.parameters["alpha0"], r.material
    return (a.value - truth.alpha0_deg, a.stderr, m.shear_modulus_kpa / lt.shear_modulus_kpa - 1.0,
            (m.shear_modulus_kpa - lt.shear_modulus_kpa) / m.se_shear_modulus_kpa)


# --------------------------------------------------------------------------------------------
# round trips on an independent loop law
# --------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name,model,law", [("be-pam", "energy", "bouc-wen"),
                                            ("bc-pam", "force_balance", "bouc-wen-1"),
                                            ("be-pam", "force_balance", "geometric-pi")])
def test_loop_aware_fit_recovers_alpha0_and_mu_from_an_independent_loop(name, model, law):
    base, truth, lt = truth_case(name, model, law)
    ps = noisy_set(lt, seed=7, noise_nmm=realistic(lt))
    r = fit(ps, base, model)
    # the tests show a loop, so the default fit uses the loop model on both branches
    assert r.hysteresis is not None and r.metrics.curves == "loop"
    da, se_a, dmu, z_mu = errors(r, truth, lt)
    assert abs(da) < 0.2 and abs(da) < 2 * se_a
    assert abs(dmu) < 0.05 and abs(z_mu) < 2
    # the mean-curve fit (the paper's way, --no-hysteresis) is biased by the loop more than twice as much (three
    # times before the pressure-offset member, which takes 0.09-0.18 of the weight here with its alpha0 0.2 deg up)
    r0 = fit(ps, base, model, hysteresis=None)
    assert r0.hysteresis is None and r0.metrics.curves == "mean curves"
    assert abs(r0.parameters["alpha0"].value - truth.alpha0_deg) > 2 * abs(da)
    assert any("the tests show a loop" in f for f in r0.flags)


@pytest.mark.slow  # 20 fits each, 3 to 10 s
@pytest.mark.parametrize("name,model,law", [("be-pam", "energy", "bouc-wen-1"), ("bc-pam", "energy", "bouc-wen")])
def test_two_se_intervals_cover_the_truth_of_an_independent_loop(name, model, law):
    base, truth, lt = truth_case(name, model, law)
    rows = np.array([errors(fit(noisy_set(lt, seed=1000 + s, noise_nmm=realistic(lt)), base, model, profile_points=0),
                            truth, lt) for s in range(20)])
    da, se_a, dmu, z_mu = rows.T
    assert np.max(np.abs(da)) < 0.2 and np.max(np.abs(dmu)) < 0.05
    assert np.mean(np.abs(da) < 2 * se_a) >= 0.85, da / se_a
    assert np.mean(np.abs(z_mu) < 2) >= 0.85, z_mu


def test_closed_form_prandtl_ishlinskii_matches_the_sum_over_operators():
    law = PrandtlIshlinskii(math.radians(9.0), 7)
    r = law.thresholds
    rng = np.random.default_rng(3)
    span = rng.uniform(0, 0.3, 400)
    delta = rng.uniform(0, 0.3, 400)
    delta[:7] = 2 * r  # exactly at the kinks
    span[7:14] = 2 * r
    dd = np.minimum(delta, span)[:, None]
    m = np.minimum(2 * r, span[:, None])
    step = np.minimum(dd, m)
    away, back = law.steady_branches(delta, span)
    np.testing.assert_allclose(away, (-r + step).sum(1) / r.sum(), atol=1e-14)
    np.testing.assert_allclose(back, (-r + m - step).sum(1) / r.sum(), atol=1e-14)


# --------------------------------------------------------------------------------------------
# one model behind the metrics, Figure 7 and predict --cycle
# --------------------------------------------------------------------------------------------
def test_fit_figure_and_predict_cycle_use_one_computation(tmp_path, capsys):
    base, truth, lt = truth_case("be-pam", "energy", "bouc-wen")
    ps = noisy_set(lt, seed=3)
    write_processed(ps, tmp_path / "p", figure=False)
    assert main(["fit", str(tmp_path / "p"), "--preset", "be-pam", "--out", str(tmp_path / "f"), "--json"]) == 0
    obj = json.loads(capsys.readouterr().out)
    assert obj["metrics_curves"] == "loop" and obj["hysteresis"]["law"] == "pi"
    P = [e["pressure_kpa"] for e in obj["hysteresis"]["energy_loss_ratio"]]
    code = main(["predict", "--actuator", str(tmp_path / "f" / "fitted_actuator.toml"), "--pressure-kpa",
                 *[str(p) for p in P], "--cycle", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    cyc = [row["cycle"] for row in json.loads(out)["results"]]
    for e, c, pp in zip(obj["hysteresis"]["energy_loss_ratio"], cyc, obj["per_pressure"], strict=True):
        assert c["energy_loss_ratio"] == pytest.approx(e["predicted"], rel=1e-12)
        assert c["free_curvature_unloading_per_mm"] == pytest.approx(pp["free_curvature_model_per_mm"], rel=1e-12)
        assert c["loading_nmm"][0] == pytest.approx(pp["blocked_moment_model_nmm"], rel=1e-12)
    # Figure 7 draws the same cycles and quotes the same metrics
    r = FitResult.load(tmp_path / "f")
    from bendpam.present.figures import figure7

    fig = figure7(ps, r)
    line = next(ln for ln in fig.axes[1].lines if ln.get_label() == "model with its loop")
    cycles = predict_cycles(r.actuator, r.loop, line.get_xdata(), r.model)
    np.testing.assert_allclose(line.get_ydata(), [c.blocked_moment_nmm for c in cycles], rtol=1e-12)
    assert f"{100 * r.metrics.nrmse_blocked_moment:.2f} %" in fig.axes[1].get_title()
    assert f"{100 * r.metrics.nrmse_free_curvature:.2f} %" in fig.axes[2].get_title()
    # and the vectorised cycles are the single ones
    one = predict_cycle(r.actuator, r.loop, 150.0, r.model)
    many = predict_cycles(r.actuator, r.loop, [120.0, 150.0], r.model)[1]
    assert one.energy_loss_ratio == pytest.approx(many.energy_loss_ratio, rel=1e-12)
    np.testing.assert_allclose(one.unloading_nmm, many.unloading_nmm, rtol=1e-12)


def test_no_hysteresis_keeps_the_mean_curve_fit(tmp_path, capsys):
    base, truth, lt = truth_case("be-pam", "energy", "bouc-wen")
    ps = noisy_set(lt, seed=4)
    write_processed(ps, tmp_path / "p", figure=False)
    assert main(["fit", str(tmp_path / "p"), "--preset", "be-pam", "--no-hysteresis", "--no-figure", "--out",
                 str(tmp_path / "f"), "--json"]) == 0
    obj = json.loads(capsys.readouterr().out)
    assert "hysteresis" not in obj and obj["metrics_curves"] == "mean curves"
    assert not list((tmp_path / "f").glob("figure7*"))
    r = fit(ps, base, hysteresis=None)
    assert obj["parameters"]["alpha0_deg"]["value"] == pytest.approx(r.parameters["alpha0"].value, rel=1e-9)
    # data without a loop: the default fits the mean curves
    base0, truth0, lt0 = truth_case("be-pam", "energy", "none")
    r0 = fit(noisy_set(lt0, seed=1), base0)
    assert r0.hysteresis is None and abs(r0.parameters["alpha0"].value - truth0.alpha0_deg) < 0.1


# --------------------------------------------------------------------------------------------
# admissible materials, identifiability, profile, joint intervals
# --------------------------------------------------------------------------------------------
def test_inadmissible_best_fit_is_held_on_the_admissible_bound():
    # the paper's BE-PAM constants (shape C01/(C10 + C01) = 2.6) made the data; no loop
    base = presets.be_pam()
    lt = make_truth(base, PRESSURES["be-pam"], law=BoucWen(), frac=0.0, offset_nmm=0.0)
    r = fit(noisy_set(lt, seed=2), base)
    m = r.material
    lo, hi = m.shape_bounds
    assert m.shape_at_bound and m.shape == pytest.approx(hi, rel=1e-9) and not m.shape_identified
    c10, c01 = r.actuator.C10_kpa, r.actuator.C01_kpa
    assert c10 + c01 > 0
    assert MooneyRivlin(c10 / 1e3, c01 / 1e3).is_admissible(*m.stretch_range)
    assert m.stretch_range[0] <= 0.6 and m.stretch_range[1] >= 1.6
    assert any("not determined" in s and "bound" in s for s in r.identifiability)
    assert any("shear modulus" in s and "is determined" in s for s in r.identifiability)
    assert set(json.loads(r.to_json())["material"]) >= {"shear_modulus_kpa", "shape", "shape_bounds"}


def test_identified_shape_profile_and_joint_interval():
    base, truth, lt = truth_case("be-pam", "energy", "bouc-wen")
    r = fit(noisy_set(lt, seed=5), base)
    m = r.material
    assert m.shape_narrow and abs(m.shape - 0.6) < 2 * m.se_shape
    # narrow; called determined only where the shipped calibration record's coverage holds (it does not, since the
    # held-out sets joined it), and the words say which
    holds = study_coverage()[0]
    assert m.shape_identified == holds
    assert any(("is determined too" if holds else "is not claimed although its interval is narrow") in s
               for s in r.identifiability)
    # the profile of alpha0: the reported (Prandtl-Ishlinskii) law's objective, smallest at that law's alpha0 and
    # equal there to its sum of squares (NRMSE^2); the interval is about the reported value, the ensemble's average
    prof = r.alpha0_profile
    a = np.array(prof.alpha0_deg)
    obj = np.array(prof.objective)
    i = int(np.argmin(obj))
    pi = next(m for m in r.uncertainty.ensemble if m.law == "pi")
    assert a[i] == pytest.approx(pi.values["alpha0_deg"], abs=1e-9)
    assert obj[i] == pytest.approx(pi.nrmse**2, rel=1e-6)
    assert obj[0] > obj[i] and obj[-1] > obj[i]
    lo, hi = prof.interval_deg
    assert hi - lo == pytest.approx(4 * r.parameters["alpha0"].stderr, rel=1e-9)
    assert 0.5 * (lo + hi) == pytest.approx(r.parameters["alpha0"].value, abs=1e-9)
    # C10 and C01: flagged, with the combination the data determine (about their sum)
    ji = next(j for j in r.joint_intervals if j.names == ("C10_kpa", "C01_kpa"))
    assert abs(ji.correlation) > 0.95 and 0.8 < ji.coefficient < 1.2
    assert ji.value == pytest.approx(r.actuator.C10_kpa + ji.coefficient * r.actuator.C01_kpa, rel=1e-12)
    assert ji.text in r.flags
    # everything survives save/load
    d = json.loads(r.to_json())
    assert {"identifiability", "alpha0_profile", "joint_intervals", "covariance", "pressure_range_kpa"} <= set(d)


def test_save_load_round_trip_of_the_new_fields(tmp_path):
    base, truth, lt = truth_case("bc-pam", "force_balance", "bouc-wen-1")
    r = fit(noisy_set(lt, seed=6), base, "force_balance")
    r.save(tmp_path)
    r2 = FitResult.load(tmp_path)
    assert json.loads(r2.to_json()) == json.loads(r.to_json())
    assert r2.material == r.material and r2.joint_intervals == r.joint_intervals
    np.testing.assert_allclose(r2.covariance, r.covariance)


# --------------------------------------------------------------------------------------------
# folds and extrapolation
# --------------------------------------------------------------------------------------------
def test_fold_rule_holds_the_shape_where_the_model_does_not_fold():
    # shape C01/(C10 + C01) = -4 folds at 141 kPa (BC-PAM energy, mu = 600 kPa).  Admissible shapes over
    # the bladder's stretches do not fold, so the rule is exercised on a problem allowed shapes down
    # to -4.2 and a tested range taken to 150 kPa: the best fit folds inside it and must be replaced.
    import bendpam.identify.fitting as ident
    from bendpam.identify.data import fit_data

    base = presets.bc_pam("energy")
    S = 300.0
    truth = base.replace(alpha0_deg=36.6, C10_kpa=5 * S, C01_kpa=-4 * S)
    assert bendpam.MomentLaw.of(truth, "energy").free_branch().max_pressure_kpa == pytest.approx(141.5, abs=0.5)
    lt = make_truth(truth, [40, 60, 80, 100, 120], law=BoucWen(), frac=0.0, offset_nmm=0.0)

    d = fit_data(noisy_set(lt, seed=1))
    bnd = ident._bounds(base, d, None)
    args = (base, d, "energy", ["alpha0", "C10", "C01"], bnd, 32, True, None, (-4.2, 1.0))
    prob = Problem(*args)
    nl, lin, *_ = ident._solve(prob, bnd, 21, 3)
    assert ident._fold_kpa(prob, nl, lin, 150.0) is not None  # the best fit folds below 150 kPa
    p2, nl2, lin2, _, note, held = _fold_rule(prob, args, bnd, nl, lin, 150.0)
    assert ident._fold_kpa(p2, nl2, lin2, 150.0) is None
    assert p2.shape_fixed is not None and "fold rejected" in note and "held at" in held
    # with no admissible way out the fit is marked as rejected
    args_bad = (*args[:8], (-4.2, -3.9))
    p3 = Problem(*args_bad)
    nl3, lin3, *_ = ident._solve(p3, bnd, 21, 3)
    _, _, _, _, note3, _ = _fold_rule(p3, args_bad, bnd, nl3, lin3, 150.0)
    assert note3.startswith("REJECTED")


def test_predictions_outside_the_tested_range_warn_and_carry_a_band():
    base, truth, lt = truth_case("be-pam", "energy", "bouc-wen")
    r = fit(noisy_set(lt, seed=8), base)
    assert r.pressure_range_kpa == (100.0, 200.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r.predict([100.0, 150.0, 200.0], 0.005)
    with pytest.warns(ExtrapolationWarning, match="outside the tested range"):
        r.predict(260.0, 0.005)
    P = np.array([150.0, 250.0])
    b = r.band(P, "blocked_moment")
    assert b.extrapolated.tolist() == [False, True]
    assert np.all(b.lower < b.value) and np.all(b.value < b.upper)
    # by hand: the blocked moment is (P - P_start) A(0; alpha0) (no bladder term at k' = 0), so
    # its half-width is 2 (P - P_start) |dA(0)/dalpha0| SE(alpha0)
    a0, se = r.actuator.alpha0_deg, r.parameters["alpha0"].stderr
    h = 1e-4

    def A0(x):
        return float(bendpam.MomentLaw.of(r.actuator.replace(alpha0_deg=x), "energy").coefficients(0.0)[0])

    dA = (A0(a0 + h) - A0(a0 - h)) / (2 * h)
    half = 2 * (P - r.actuator.P_start_kpa) * abs(dA) * se
    np.testing.assert_allclose(b.upper - b.value, half, rtol=1e-4)
    fc = r.band([120.0, 300.0], "free_curvature")
    assert np.all(np.isfinite(fc.upper)) and (fc.upper[1] - fc.lower[1]) > (fc.upper[0] - fc.lower[0])


# --------------------------------------------------------------------------------------------
# joint fit with a tension test
# --------------------------------------------------------------------------------------------
def tension_points(truth, seed=0, n=40, noise_kpa=3.0):
    lam = np.linspace(1.0, 2.0, n)
    rng = np.random.default_rng(seed)
    stress = MooneyRivlin(truth.C10_kpa / 1e3, truth.C01_kpa / 1e3).uniaxial_nominal_stress(lam) * 1e3
    return lam, stress + rng.normal(0.0, noise_kpa, n)


def test_joint_fit_with_a_tension_test_determines_the_shape(tmp_path, capsys):
    base, truth, lt = truth_case("bc-pam", "force_balance", "bouc-wen")
    ps = noisy_set(lt, seed=9, noise_nmm=realistic(lt))
    alone = fit(ps, base, "force_balance")
    lam, stress = tension_points(truth)
    joint = fit(ps, base, "force_balance", tension_data=TensionData(lam, stress, "synthetic"))
    mj, ma = joint.material, alone.material
    assert mj.se_shape < 0.5 * ma.se_shape
    assert abs(mj.shape - 0.6) < 2 * mj.se_shape and mj.shape_identified
    assert abs(mj.shear_modulus_kpa / lt.shear_modulus_kpa - 1) < 0.05
    assert abs(joint.parameters["alpha0"].value - truth.alpha0_deg) < 0.2
    assert any("joint fit with the tension test" in f for f in joint.flags)
    # the command line: --tension FILE (a raw export of the specimen, gauge 20 mm, 2 mm^2)
    write_processed(ps, tmp_path / "p", figure=False)
    f = tmp_path / "tension.csv"
    write_test(f, pd.DataFrame({"time_s": np.arange(lam.size) * 0.5, "stroke_mm": (lam - 1) * 20.0,
                                "force_n": stress * 2.0 / 1e3}), "csv")
    code = main(["fit", str(tmp_path / "p"), "--preset", "bc-pam", "--model", "force-balance", "--tension", str(f),
                 "--gauge-length-mm", "20", "--area-mm2", "2", "--out", str(tmp_path / "fit"), "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    obj = json.loads(out)
    assert obj["tension"]["n_points"] == lam.size
    assert obj["material"]["shape"] == pytest.approx(mj.shape, abs=0.02)
    assert any("joint fit with the tension test" in s for s in obj["flags"])


# --------------------------------------------------------------------------------------------
# fit-material: Treloar with the stretch range as an option
# --------------------------------------------------------------------------------------------
def test_fit_material_cli_on_treloar_with_a_stretch_range(tmp_path, capsys):
    d = pd.read_csv(TRELOAR, comment="#")
    lam = np.concatenate([[1.0], d["stretch"].to_numpy()])
    stress_kpa = np.concatenate([[0.0], d["nominal_stress_mpa"].to_numpy() * 1e3])
    f = tmp_path / "treloar.csv"  # as a machine would record it: gauge 25 mm, 4 mm^2
    write_test(f, pd.DataFrame({"time_s": np.arange(lam.size), "stroke_mm": (lam - 1) * 25.0,
                                "force_n": stress_kpa * 4.0 / 1e3}), "csv")
    args = ["fit-material", str(f), "--gauge-length-mm", "25", "--area-mm2", "4", "--json"]
    assert main([*args, "--stretch-range", "1", "2"]) == 0
    t = json.loads(capsys.readouterr().out)
    assert t["C10_kpa"] > 0 and t["shear_modulus_kpa"] > 0 and not t["shape_at_bound"]
    used = (lam > 1.0) & (lam <= 2.0)
    pred = MooneyRivlin(t["C10_kpa"] / 1e3, t["C01_kpa"] / 1e3).uniaxial_nominal_stress(lam[used]) * 1e3
    assert np.max(np.abs(pred - stress_kpa[used]) / stress_kpa[used]) < 0.05
    # the full range: the plain fit would have mu < 0; the admissible one sits on the bound, positive
    assert main(args) == 0
    full = json.loads(capsys.readouterr().out)
    assert full["shape_at_bound"] and full["shear_modulus_kpa"] > 0 and full["C10_kpa"] > 0
    assert MooneyRivlin(full["C10_kpa"] / 1e3, full["C01_kpa"] / 1e3).is_admissible(0.6, 7.6)
    assert main([*args, "--stretch-range", "2", "1"]) == 2
    assert "--stretch-range (2, 1)" in capsys.readouterr().err  # the option, as the user wrote it


def test_loop_model_default_and_bad_hysteresis_argument():
    base, truth, lt = truth_case("be-pam", "energy", "bouc-wen")
    ps = noisy_set(lt, seed=11)
    with pytest.raises(ValueError, match="hysteresis"):
        fit(ps, base, hysteresis="coulomb")
    with pytest.raises(ValueError, match="shape"):
        fit(ps, base, bounds={"shape": (5.0, 6.0)})
    r = fit(ps, base, hysteresis="dahl", law_uncertainty=False, profile_points=0)
    assert r.hysteresis.law == "dahl" and r.hysteresis.law_shift == {} and r.alpha0_profile is None
    loop = LoopModel(law="dahl", a0_nmm=1.0, a1_nmm_per_kpa=0.1, theta_h_deg=3.0)
    c = predict_cycles(r.actuator, loop, [50.0, 150.0])
    assert math.isnan(c[0].free_curvature_per_mm) and c[0].note and math.isfinite(c[1].energy_loss_ratio)
