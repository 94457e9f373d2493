"""Cycle processing and the virtual testing machine: simulate -> write -> read -> process round trips."""

import hashlib
import json

import numpy as np
import pytest
from numpy.testing import assert_allclose

import bendpam
from bendpam import presets
from bendpam.cli import main
from bendpam.lab import read_test
from bendpam.lab.processed import ProcessingOptions, deadband_fit, load_processed, write_processed
from bendpam.lab.processing import ProcessingError, find_turning_points, process_series, process_tests
from bendpam.lab.simulate import SimulationSettings, simulate_test, simulate_tests
from bendpam.physics.fixture import PAPER_FIXTURE

FORMATS = ["csv", "testxpert", "bluehill", "mts"]
CASES = {"be-pam": [100, 125, 150, 175, 200], "bc-pam": [40, 60, 80, 100, 120]}


def triangle(n_cycles=3, amp=10.0, n=400, dwell=0):
    up = np.linspace(0, amp, n)
    one = np.concatenate([up, np.full(dwell, amp), up[::-1], np.zeros(dwell)])
    return np.tile(one, n_cycles)


def test_turning_points_with_noise_and_dwell():
    rng = np.random.default_rng(0)
    s = triangle(3, dwell=50) + rng.normal(0, 0.05, 3 * (800 + 100))
    idx, is_max = find_turning_points(s, 0.5)
    assert idx[0] == 0 and not is_max[0]
    assert is_max.sum() == 3 and (~is_max).sum() == 4
    assert np.all(np.diff(idx) > 0)
    assert np.all(s[idx[is_max]] > 9.5) and np.all(s[idx[~is_max][1:]] < 0.5)


def test_turning_points_starting_downward():
    s = 10 - triangle(2)
    idx, is_max = find_turning_points(s, 1.0)
    assert is_max[0] and not is_max[1]


def synthetic(M0=200.0, kf=0.01, H=10.0, cycles=3, rate=20.0, speed=30.0, partial=False):
    """Linear model M = M0 (1 - k/kf) with a constant friction +-H (sharp reversals)."""
    f = PAPER_FIXTURE
    sf = float(f.curvature_to_stroke(kf))
    t_ramp = sf / (speed / 60)
    n = int(t_ramp * rate)
    up = np.linspace(0, sf, n)
    parts = []
    for _ in range(cycles):
        parts += [up, up[::-1][1:]]
    if partial:
        parts.append(up[: n // 2])
    s = np.concatenate(parts)
    direction = np.sign(np.gradient(s))
    beta = f.stroke_to_beta(s)
    k = f.beta_to_curvature(beta)
    M = M0 * (1 - k / kf) - H * direction
    F = f.moment_to_force(M, beta)
    t = np.arange(s.size) / rate
    return t, s, F


def test_process_synthetic_linear_loop():
    t, s, F = synthetic()
    r = process_series(t, s, F, 150.0, options=ProcessingOptions(cutoff_hz=0))
    assert r.n_cycles == 3
    # branches: loading (upper) = M0(1 - k/kf) + H, unloading (lower) = ... - H
    g = r.curvature_grid
    inner = (g > 0.1 * g[-1]) & (g < 0.9 * g[-1])
    assert_allclose(r.mean_loading[inner], 200 * (1 - g[inner] / 0.01) + 10, atol=0.05)
    assert_allclose(r.mean_unloading[inner], 200 * (1 - g[inner] / 0.01) - 10, atol=0.05)
    assert_allclose(r.mean_curve[inner], 200 * (1 - g[inner] / 0.01), atol=0.05)
    assert r.blocked_moment[0] == pytest.approx(210.0, rel=1e-3)
    assert r.free_curvature[0] == pytest.approx(0.01, rel=1e-6)
    # loss = 2H * theta_f, stored = M0 theta_f / 2  ->  ratio = 4 H / M0 = 0.2
    assert r.energy_loss_ratio == pytest.approx(0.2, abs=0.003)
    assert r.blocked_moment_mean_curve == pytest.approx(200.0, abs=0.5)


def test_partial_cycle_offset_and_flips_are_handled():
    t, s, F = synthetic(partial=True)
    # machine records compression as negative, stroke decreasing, with an offset of 12 mm
    r = process_series(t, 12.0 - s, -F, 150.0, options=ProcessingOptions(cutoff_hz=0))
    assert r.n_cycles == 3
    assert r.free_curvature[0] == pytest.approx(0.01, rel=1e-6)
    assert any("partial" in n for n in r.notes)
    assert any("force sign" in n for n in r.notes) and any("stroke direction" in n for n in r.notes)


def test_deadband_fit_golden():
    P = np.array([100.0, 150.0, 200.0])
    p0, se, a, b = deadband_fit(P, 2.5 * (P - 68.0))
    assert p0 == pytest.approx(68.0) and se == pytest.approx(0.0, abs=1e-9) and a == pytest.approx(2.5)
    p0, se, _, _ = deadband_fit(P, 2.5 * (P - 68.0) + np.array([1.0, -2.0, 1.0]))
    assert p0 == pytest.approx(68.0, abs=1.0) and se > 0
    assert np.isnan(deadband_fit([100.0], [10.0])[0])


@pytest.mark.parametrize(
    "args,msg",
    [
        ((np.arange(10.0), np.arange(10.0), np.ones(10)), "at least 20"),
        ((np.r_[np.arange(30.0), 5.0], np.ones(31), np.ones(31)), "time does not increase"),
        ((np.arange(50.0), np.ones(50), np.ones(50)), "does not move"),
        ((np.arange(50.0), np.arange(50.0), -np.arange(50.0)), "no complete cycle"),
        ((np.arange(50.0), np.r_[np.ones(49), np.nan], np.ones(50)), "not finite"),
    ],
)
def test_bad_series(args, msg):
    with pytest.raises(ProcessingError, match=msg) as exc:
        process_series(*args, 100.0, source="x.csv")
    assert "\n" not in str(exc.value) and "x.csv" in str(exc.value)


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """Each actuator simulated once per format (energy model, default settings, some dwell and offset)."""
    out = {}
    for name, P in CASES.items():
        a = presets.get(name, "energy")
        for fmt in FORMATS:
            d = tmp_path_factory.mktemp(f"{name}-{fmt}")
            st = SimulationSettings(seed=7, dwell_s=1.5, stroke_offset_mm=2.0, hysteresis=0.06)
            truth = simulate_tests(a, P, d, "energy", dialect=fmt, settings=st)
            out[(name, fmt)] = (d, truth)
    return out


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("name", list(CASES))
def test_simulate_process_round_trip(simulated, name, fmt):
    d, truth = simulated[(name, fmt)]
    a = presets.get(name, "energy")
    sign = a.bend_sign
    files = [d / f for f in truth["files"]]
    digest = {f: hashlib.sha256(f.read_bytes()).hexdigest() for f in files}
    tests = [read_test(f) for f in files]
    assert {t.dialect for t in tests} == {fmt}
    assert all(t.pressure_source == "metadata" for t in tests)
    ps = process_tests(tests)
    for r, tr in zip(ps.results, truth["pressures"]):
        assert r.pressure_kpa == tr["pressure_kpa"]
        assert r.n_cycles == 3
        bm, bm_se = r.blocked_moment
        assert bm == pytest.approx(tr["blocked_moment_nmm"], rel=0.01, abs=1.0)
        assert r.free_curvature[0] == pytest.approx(tr["free_curvature_per_mm"], rel=0.02, abs=2e-5)
        assert abs(r.energy_loss_ratio - tr["energy_loss_ratio"]) < 0.02  # 2 percentage points
        # the hysteresis-free mean curve recovers the quasi-static model away from the reversals,
        # where the Dahl loop is saturated (free angle > 3 theta_c)
        if tr["free_curvature_per_mm"] * a.L0_mm < 3 * np.radians(5.0):
            continue
        g = r.curvature_grid
        mid = (g > 0.3 * g[-1]) & (g < 0.7 * g[-1])
        model = sign * bendpam.moment(a, r.pressure_kpa, sign * g[mid])
        assert_allclose(r.mean_curve[mid], model, atol=0.02 * tr["model_blocked_moment_nmm"])
    p0, se = ps.deadband()
    assert p0 == pytest.approx(truth["deadband_kpa"], abs=2.0)
    assert np.isfinite(se)
    # inputs untouched
    assert {f: hashlib.sha256(f.read_bytes()).hexdigest() for f in files} == digest


def test_write_and_load_processed(simulated, tmp_path):
    d, truth = simulated[("be-pam", "csv")]
    ps = process_tests([read_test(d / f) for f in truth["files"]])
    written = write_processed(ps, tmp_path / "out")
    assert set(written) == {"curves.nc", "curves.npz", "curves.csv", "summary.json", "figure4.png"}
    summ = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert set(summ["pressures"][0]) >= {
        "pressure_kpa", "cycles", "blocked_moment_nmm", "blocked_moment_se_nmm", "blocked_moment_mean_curve_nmm",
        "free_curvature_per_mm", "free_curvature_se_per_mm", "energy_loss_ratio"}
    assert "deadband_kpa" in summ and "deadband_se_kpa" in summ
    back = load_processed(tmp_path / "out")
    assert_allclose(back.pressures_kpa, ps.pressures_kpa)
    for r0, r1 in zip(ps.results, back.results):
        assert_allclose(r1.branches, r0.branches)
        assert r1.blocked_moment[0] == pytest.approx(r0.blocked_moment[0])
    assert not [p for p in (tmp_path / "out").iterdir() if p.name.startswith(".")]


def test_no_free_state_is_explicit():
    a = presets.bc_pam("energy")
    with pytest.raises(ValueError, match="no free state"):
        simulate_test(a, 170.0, settings=SimulationSettings(hysteresis=0.0))
    with pytest.raises(ValueError, match="P_start"):
        simulate_test(a, 20.0)


def test_rate_independence_of_the_loop():
    a = presets.be_pam()
    slow, t1 = simulate_test(a, 150, settings=SimulationSettings(noise_n=0, noise_stroke_mm=0, speed_mm_min=10))
    fast, t2 = simulate_test(a, 150, settings=SimulationSettings(noise_n=0, noise_stroke_mm=0, speed_mm_min=60))
    assert t1["energy_loss_ratio"] == pytest.approx(t2["energy_loss_ratio"], rel=1e-9)
    r1 = process_series(slow.time_s, slow.stroke_mm, slow.force_n, 150)
    r2 = process_series(fast.time_s, fast.stroke_mm, fast.force_n, 150)
    assert r1.energy_loss_ratio == pytest.approx(r2.energy_loss_ratio, abs=0.005)


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_simulate_and_process(capsys, tmp_path):
    code, out, err = run(capsys, "simulate-test", "--preset", "be-pam", "--pressure-kpa", "100", "150", "200",
                         "--out", str(tmp_path / "raw"), "--format", "bluehill", "--seed", "1", "--cycles", "2")
    assert code == 0, err
    truth = json.loads((tmp_path / "raw" / "truth.json").read_text())
    assert len(truth["files"]) == 3
    code, out, err = run(capsys, "process", str(tmp_path / "raw"), "--out", str(tmp_path / "p"), "--json")
    assert code == 0, err
    summ = json.loads(out)
    assert [p["cycles"] for p in summ["pressures"]] == [2, 2, 2]
    assert summ["deadband_kpa"] == pytest.approx(68.0, abs=3.0)
    code, out, err = run(capsys, "process", str(tmp_path / "raw" / truth["files"][0]), "--pressure-kpa", "123",
                         "--out", str(tmp_path / "q"), "--no-figure")
    assert code == 0, err
    assert "123" in out and not (tmp_path / "q" / "figure4.png").exists()


@pytest.mark.parametrize(
    "args,words",
    [
        (["process", "nonexistent.csv", "--out", "o"], ["no such file"]),
        (["process", "raw", "--out", "o", "--pressure-kpa", "100,150,200"], ["pressure"]),
        (["process", "raw", "--out", "o", "--fixture", "1,2"], ["d,r,t"]),
        (["process", "raw"], ["--out"]),
        (["process", "raw", "--out", "o", "--cutoff-hz", "100"], ["Nyquist"]),
        (["simulate-test", "--preset", "bc-pam", "--pressure-kpa", "10", "--out", "s"], ["P_start"]),
        (["simulate-test", "--preset", "be-pam", "--pressure-kpa", "100", "--out", "s", "--rate-hz", "-1"],
         ["--rate-hz -1.0"]),
        (["simulate-test", "--preset", "be-pam", "--pressure-kpa", "100", "--out", "s", "--format", "xls"], ["xls"]),
    ],
)
def test_cli_errors(capsys, tmp_path, monkeypatch, args, words):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "raw").mkdir()
    a = presets.be_pam()
    data, _ = simulate_test(a, 150, settings=SimulationSettings(seed=0))
    from bendpam.lab import write_test

    write_test(tmp_path / "raw" / "t.csv", data, "csv", pressure_kpa=150)
    write_test(tmp_path / "raw" / "u.csv", data, "csv", pressure_kpa=160)
    code, out, err = run(capsys, *args)
    assert code == 2, (out, err)
    lines = err.splitlines()
    assert all(ln.startswith("bendpam: error:") for ln in lines), err
    # one line, or (a problem found in the files: issue 22) one line per bad file and a count of them
    per_file = "--cutoff-hz" in args
    assert len(lines) == (3 if per_file else 1), err
    if per_file:
        assert "t.csv" in lines[0] and "u.csv" in lines[1] and "2 of 2 file(s)" in lines[2]
    for w in words:
        assert w in err


def test_branch_times_are_kept_and_an_old_set_loads_without_them(simulated, tmp_path):
    import xarray as xr

    d, truth = simulated[("be-pam", "csv")]
    ps = process_tests([read_test(d / f) for f in truth["files"]], keep_series=True)
    r = ps.results[0]
    s = r.series
    # the loading branch of cycle 1 begins at its free reversal: its times on the grid rise to the blocked end
    first = s[s["cycle"] == 1]
    start = float(first.loc[first["branch"] == "loading", "time_s"].iloc[0])
    t_load = r.branch_times_s[0, 0]
    k_load = first.loc[first["branch"] == "loading"]
    expect = np.interp(r.curvature_grid[50], k_load["curvature_per_mm"].to_numpy()[::-1],
                       k_load["time_s"].to_numpy()[::-1]) - start
    assert t_load[50] == pytest.approx(expect, rel=1e-6)
    assert np.all(np.diff(t_load) <= 0) and np.all(np.diff(r.branch_times_s[0, 1]) >= 0)
    write_processed(ps, tmp_path / "out", figure=False)
    with xr.open_dataset(tmp_path / "out" / "curves.nc") as ds:
        assert ds["time_s"].attrs["units"] == "s"
    import pandas as pd  # the spreadsheet copy carries the same times, row for row; empty for the mean curves

    table = pd.read_csv(tmp_path / "out" / "curves.csv")
    rows = table[(table["pressure_kpa"] == r.pressure_kpa) & (table["cycle"] == 1) & (table["branch"] == "loading")]
    assert_allclose(rows["time_s"].to_numpy(), t_load, rtol=1e-9)
    assert table.loc[table["cycle"] == 0, "time_s"].isna().all()
    back = load_processed(tmp_path / "out")
    for r0, r1 in zip(ps.results, back.results):
        assert_allclose(r1.branch_times_s, r0.branch_times_s)
    old = tmp_path / "old.nc"  # a set saved before 0.4 had no times: it loads, the fit approximates the rate
    with xr.open_dataset(tmp_path / "out" / "curves.nc") as ds:
        ds.drop_vars("time_s").load().to_netcdf(old, format="NETCDF3_64BIT")
    assert all(r.branch_times_s is None for r in load_processed(old).results)


def test_isolated_spikes_are_replaced_and_noted():
    data, _ = simulate_test(presets.be_pam(), 150.0, settings=SimulationSettings(cycles=2, rate_hz=10.0, seed=3))
    t, s, f = (data[c].to_numpy() for c in ("time_s", "stroke_mm", "force_n"))
    clean = process_series(t, s, f, 150.0, keep_series=False)
    spiked = f.copy()
    top = int(np.argmax(f))
    spiked[[top + 3, 400, 401, 900]] += [60.0, -8.0, -8.5, 5.0]  # N: a glitch near the blocked state, a pair, one
    res = process_series(t, s, spiked, 150.0, keep_series=False)
    assert any("4 isolated spike(s) in the force (N)" in n and "+59.9 at" in n for n in res.notes), res.notes
    assert res.blocked_moment[0] == pytest.approx(clean.blocked_moment[0], rel=1e-3)
    kept = process_series(t, s, spiked, 150.0, keep_series=False, options=ProcessingOptions(despike_sigmas=0))
    assert not any("spike" in n for n in kept.notes)
    assert abs(kept.blocked_moment[0] / clean.blocked_moment[0] - 1.0) > 0.01  # the glitch moves it when kept
    with pytest.raises(bendpam.errors.InputError, match="despike_sigmas"):
        ProcessingOptions(despike_sigmas=2.0)


def test_steps_and_sharp_reversals_are_not_spikes():
    from bendpam.lab.checks import noise_spikes

    rng = np.random.default_rng(5)
    tri = np.abs(((np.arange(400) / 20.0) % 2.0) - 1.0) * 10.0  # a reversal every 20 samples: steps of 0.5
    assert noise_spikes(tri + rng.normal(0.0, 0.01, 400), 8.0)[0].size == 0
    saw = (np.arange(600) % 50) * 0.2  # stick-slip: ramps, then a drop of 9.8 in one sample
    assert noise_spikes(saw + rng.normal(0.0, 0.01, 600), 8.0)[0].size == 0
    coarse = np.round(np.sin(np.linspace(0.0, 20.0, 2000)) * 5.0) / 5.0  # quantised to 0.2, mostly repeated samples
    assert noise_spikes(coarse, 8.0)[0].size == 0
    # noise that grows with the force (a gain's): large near the peaks, where the column's own median noise is small
    base = 10.0 * np.abs(np.sin(np.linspace(0.0, 12.0, 40000))) ** 4
    hetero = base + rng.normal(0.0, 1.0, base.size) * (0.002 + 0.02 * base)
    assert noise_spikes(hetero, 8.0)[0].size == 0
