"""The hysteresis loop model (issue 7): laws, loop prediction, simulation and identification."""

import json
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

import bendpam
from bendpam import presets
from bendpam.cli import main
from bendpam.identify.fitting import fit
from bendpam.lab.processing import ProcessedSet, ProcessingOptions, process_series, write_processed
from bendpam.lab.simulate import SimulationSettings, simulate_test
from bendpam.physics.fixture import PAPER_FIXTURE
from bendpam.physics.hysteresis import DahlLaw, LoopModel, PrandtlIshlinskii, loop_branches, predict_cycle


def triangle(theta_max, n=300, cycles=3):
    up = np.linspace(0.0, theta_max, n)
    return np.concatenate([np.concatenate([up, up[::-1][1:]]) if i == 0 else np.concatenate([up[1:], up[::-1][1:]])
                           for i in range(cycles)])


@pytest.mark.parametrize("law", [PrandtlIshlinskii(math.radians(12.0)), PrandtlIshlinskii(math.radians(80.0)),
                                 DahlLaw(math.radians(5.0))])
def test_z_stays_in_unit_interval_and_follows_the_motion(law):
    th = triangle(1.0)
    z = law.z_path(th, 0.0)
    assert np.all(np.abs(z) <= 1.0 + 1e-12)
    dz = np.diff(z)
    dth = np.diff(th)
    assert np.all(dz * dth >= -1e-15)  # z moves with theta (friction opposes the motion)


def test_prandtl_ishlinskii_loop_closes_after_the_first_cycle():
    law = PrandtlIshlinskii(math.radians(12.0))
    n = 300
    th = triangle(0.6, n, cycles=4)
    z = law.z_path(th, 0.0)
    per = 2 * n - 2
    c2 = z[2 * n - 1 - 1: 2 * n - 1 - 1 + per]
    c3 = z[2 * n - 1 - 1 + per: 2 * n - 1 - 1 + 2 * per]
    assert np.array_equal(c2, c3)  # exactly periodic from the second cycle on (wiping-out property)
    # and the steady cycle is the closed form
    up, down = law.steady_branches(th[:n], 0.6)
    assert_allclose(c2[:n], up, atol=1e-12)
    start2 = 2 * n - 2
    back = law.steady_branches(th[:n], 0.6)[1]
    assert_allclose(z[start2 + n - 1: start2 + 2 * n - 1], back, atol=1e-12)
    # a small loop never saturates the widest elements: its steady cycle keeps the memory of the
    # blocked state reached by a long loading (z0 = -1), and it still closes after the first cycle
    zs = law.z_path(triangle(0.05, n, 3), -1.0)
    away, back = law.steady_branches(np.linspace(0, 0.05, n), 0.05)
    assert_allclose(zs[:n], away, atol=1e-12)
    assert_allclose(zs[n - 1: 2 * n - 1], back, atol=1e-12)
    assert_allclose(zs[2 * n - 2: 3 * n - 2], away, atol=1e-12)


def test_dahl_steady_cycle_is_the_limit_of_the_path():
    law = DahlLaw(math.radians(5.0))
    n = 400
    th = triangle(0.3, n, cycles=6)
    z = law.z_path(th, 0.0)
    per = 2 * n - 2
    last = z[-per - 1: -per - 1 + n]
    assert_allclose(last, law.steady_branches(np.linspace(0, 0.3, n), 0.3)[0], atol=1e-9)


def test_rate_independence_of_the_laws():
    # the same path sampled 100 x more densely (i.e. run at another rate) gives the same loop
    for law in (PrandtlIshlinskii(math.radians(10.0)), DahlLaw(math.radians(5.0))):
        coarse = triangle(0.5, 61, 2)
        fine = triangle(0.5, 6001, 2)
        zc = law.z_path(coarse, -1.0)
        zf = law.z_path(fine, -1.0)
        assert_allclose(zc, zf[::100], atol=1e-12)


def test_zero_amplitude_gives_zero_loss():
    a = presets.be_pam()
    c = predict_cycle(a, LoopModel(a0_nmm=0.0, a1_nmm_per_kpa=0.0), 150.0)
    assert c.energy_loss_ratio == pytest.approx(0.0, abs=1e-12)
    assert_allclose(c.loading_nmm, c.unloading_nmm)
    assert c.free_curvature_per_mm == pytest.approx(float(bendpam.free_curvature(a, 150.0).curvature_per_mm),
                                                    rel=1e-3)
    d, tr = simulate_test(a, 150, settings=SimulationSettings(hysteresis=0.0, noise_n=0.0, noise_stroke_mm=0.0))
    assert tr["energy_loss_ratio"] == pytest.approx(0.0, abs=1e-12)
    r = process_series(d.time_s, d.stroke_mm, d.force_n, 150)
    assert abs(r.energy_loss_ratio) < 0.003


def test_loss_grows_with_amplitude_and_is_higher_near_threshold_with_a_constant_part():
    a = presets.be_pam()
    # a1 in N*mm per kPa of active pressure (60 N*mm/MPa = 0.06 N*mm/kPa)
    small = predict_cycle(a, LoopModel(a0_nmm=1.0, a1_nmm_per_kpa=0.060), 150.0).energy_loss_ratio
    large = predict_cycle(a, LoopModel(a0_nmm=1.0, a1_nmm_per_kpa=0.120), 150.0).energy_loss_ratio
    assert 0 < small < large
    loop = LoopModel(a0_nmm=5.0, a1_nmm_per_kpa=0.100)
    near = predict_cycle(a, loop, 90.0).energy_loss_ratio
    far = predict_cycle(a, loop, 200.0).energy_loss_ratio
    assert near > far  # the residual fabric friction dominates near P_start (Table 2's trend)


def test_interfacial_amplitude_equals_linear_when_straight():
    a = presets.bc_pam("force_balance")
    lin = LoopModel(a0_nmm=2.0, a1_nmm_per_kpa=0.150)
    inter = LoopModel(a0_nmm=2.0, a1_nmm_per_kpa=0.150, amplitude="interfacial")
    assert inter.amplitude_nmm(a, 100.0, 0.0) == pytest.approx(float(lin.amplitude_nmm(a, 100.0, 0.0)))
    # by hand: a0 + a1 (P - P_start) = 2 + 0.15 (100 - 32) N*mm
    assert float(lin.amplitude_nmm(a, 100.0, 0.0)) == pytest.approx(2.0 + 0.15 * 68.0)
    # away from straight the interfacial pressure changes (eq 45)
    assert inter.amplitude_nmm(a, 100.0, -0.006) != pytest.approx(float(lin.amplitude_nmm(a, 100.0, -0.006)))
    c = predict_cycle(a, inter, 100.0, "force_balance")
    assert 0 < c.energy_loss_ratio < 1


@pytest.mark.parametrize("kw,word", [(dict(a0_nmm=-1.0), "a0_nmm"), (dict(law="coulomb"), "law"),
                                     (dict(theta_h_deg=0.0), "theta_h_deg"), (dict(amplitude="cubic"), "amplitude")])
def test_bad_loop_parameters(kw, word):
    with pytest.raises(ValueError, match=word):
        LoopModel(**kw)


def simulate_processed(truth, pressures, model, st):
    rng = np.random.default_rng(st.seed)
    res, trs = [], []
    for p in pressures:
        d, tr = simulate_test(truth, p, model, settings=st, rng=rng)
        trs.append(tr)
        res.append(process_series(d.time_s.to_numpy(), d.stroke_mm.to_numpy(), d.force_n.to_numpy(), p,
                                  keep_series=False))
    return ProcessedSet(res, PAPER_FIXTURE, ProcessingOptions()), trs


@pytest.mark.parametrize("name,model,P", [("be-pam", "energy", [100, 125, 150, 175, 200]),
                                          ("bc-pam", "force_balance", [40, 60, 80, 100, 120])])
def test_round_trip_recovers_the_loop(name, model, P):
    base = presets.get(name, model)
    S = base.C10_kpa + base.C01_kpa  # an admissible material (Table 3's constants are not)
    truth = base.replace(alpha0_deg=base.alpha0_deg + 0.6, C10_kpa=0.4 * S, C01_kpa=0.6 * S)
    st = SimulationSettings(hysteresis=0.05, hysteresis_offset_nmm=3.0, hysteresis_angle_deg=12.0, seed=11)
    ps, trs = simulate_processed(truth, P, model, st)
    r = fit(ps, base, model, hysteresis="pi")
    assert r.converged
    hp = {p.field: p for p in r.hysteresis.parameters.values()}
    assert hp["a1_nmm_per_kpa"].unit == "N*mm/kPa"
    true = {"a0_nmm": 3.0, "a1_nmm_per_kpa": trs[0]["loop"]["a1_nmm_per_kpa"], "theta_h_deg": 12.0}
    for k, v in true.items():
        est, se = hp[k].value, hp[k].stderr
        assert se is not None and se > 0
        assert abs(est - v) <= 3 * se + 1e-3 * abs(v), (k, est, se, v)
    for e in r.hysteresis.energy_loss_ratio:
        assert abs(e.predicted - e.measured) < 0.02  # within 2 percentage points
    assert r.hysteresis.nrmse_branches < 0.02
    assert abs(r.parameters["alpha0"].value - truth.alpha0_deg) < 0.1
    # the predicted loop at each pressure: unloading below loading everywhere inside
    kf = ps.results[-1].free_curvature[0]
    k = np.linspace(0.05 * kf, 0.95 * kf, 50)
    up, low = loop_branches(r.actuator, r.loop, ps.results[-1].pressure_kpa, kf, k, model)
    assert np.all(up > low)


def test_cli_fit_hysteresis_and_predict_cycle(tmp_path, capsys):
    raw = tmp_path / "raw"
    code = main(["simulate-test", "--preset", "be-pam", "--pressure-kpa", "100", "150", "200", "--out", str(raw),
                 "--seed", "2", "--hysteresis", "0.05", "--hysteresis-offset-nmm", "2", "--hysteresis-angle-deg", "10",
                 "--hysteresis-law", "pi"])
    assert code == 0
    truth = json.loads((raw / "truth.json").read_text())
    assert truth["settings"]["hysteresis_law"] == "pi"
    assert main(["process", str(raw), "--out", str(tmp_path / "p"), "--no-figure"]) == 0
    capsys.readouterr()
    code = main(["fit", str(tmp_path / "p"), "--preset", "be-pam", "--hysteresis", "--out", str(tmp_path / "f"),
                 "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    h = json.loads(out)["hysteresis"]
    assert h["law"] == "pi" and set(h["parameters"]) == {"a0_nmm", "a1_nmm_per_kpa", "theta_h_deg"}
    assert h["parameters"]["a1_nmm_per_kpa"]["unit"] == "N*mm/kPa"
    assert {"pressure_kpa", "measured", "predicted"} <= set(h["energy_loss_ratio"][0])
    assert h["nrmse_branches"] < 0.02
    assert "[hysteresis]" in (tmp_path / "f" / "fitted_actuator.toml").read_text()
    code = main(["predict", "--actuator", str(tmp_path / "f" / "fitted_actuator.toml"), "--pressure-kpa", "150",
                 "--cycle", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    cyc = json.loads(out)["results"][0]["cycle"]
    measured = next(e["measured"] for e in h["energy_loss_ratio"] if e["pressure_kpa"] == 150.0)
    assert cyc["energy_loss_ratio"] == pytest.approx(measured, abs=0.02)
    assert main(["predict", "--preset", "be-pam", "--pressure-kpa", "150", "--cycle"]) == 2
    assert main(["simulate-test", "--preset", "be-pam", "--pressure-kpa", "150", "--out", str(tmp_path / "d"),
                 "--hysteresis-law", "dahl", "--cycles", "2"]) == 0
    assert main(["simulate-test", "--preset", "be-pam", "--pressure-kpa", "150", "--out", str(tmp_path / "e"),
                 "--hysteresis-law", "coulomb"]) == 2
    assert "coulomb" in capsys.readouterr().err


def test_figure7_draws_the_loop(tmp_path):
    base = presets.be_pam()
    st = SimulationSettings(hysteresis=0.05, hysteresis_angle_deg=10.0, seed=3)
    ps, _ = simulate_processed(base, [100, 150, 200], "energy", st)
    r = fit(ps, base, hysteresis="pi")
    from bendpam.present.figures import figure7, save_figure

    fig = figure7(ps, r)
    from matplotlib.collections import LineCollection

    thin, thick = [c for c in fig.axes[0].collections if isinstance(c, LineCollection)]
    save_figure(fig, tmp_path / "f7.png")
    assert (tmp_path / "f7.png").read_bytes()[:4] == b"\x89PNG"
    # per pressure: two data branches (thin) and two model branches, the loop's (thick)
    assert len(thin.get_segments()) == 2 * 3 and len(thick.get_segments()) == 2 * 3
    up, low = thick.get_segments()[:2]
    assert np.max(np.abs(up[:, 1] - low[:, 1])) > 1.0  # the loop is open: two different branches (N*mm)
    write_processed(ps, tmp_path / "p", figure=False)


def test_finger_loading_and_unloading_shapes_differ():
    from bendpam.design import Finger, FingerLoads, solve_finger

    a = presets.be_pam()
    loop = LoopModel(a0_nmm=3.0, a1_nmm_per_kpa=0.120, theta_h_deg=10.0)
    loads = FingerLoads(tip_force_n=(0.0, -0.3))
    plain = solve_finger(Finger(a), 150.0, loads)
    opening = solve_finger(Finger(a, loop=loop, motion="unloading"), 150.0, loads)
    closing = solve_finger(Finger(a, loop=loop, motion="loading"), 150.0, loads)
    assert plain.equilibrium and opening.equilibrium and closing.equilibrium
    # friction holds the finger back while it opens and while it is pushed back: the loading shape
    # bends further than the quasi-static one, the unloading shape less
    assert opening.tip_angle_deg < plain.tip_angle_deg < closing.tip_angle_deg
    # with zero amplitude the loop changes nothing
    zero = solve_finger(Finger(a, loop=LoopModel(), motion="loading"), 150.0, loads)
    assert zero.tip_angle_deg == pytest.approx(plain.tip_angle_deg, abs=1e-9)
