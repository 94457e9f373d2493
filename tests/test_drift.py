"""Load-cell offset drift (bendpam.lab.drift): estimated from the cycle ends, flagged, corrected on request."""

import json
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bendpam import presets
from bendpam.cli import main
from bendpam.errors import InputError
from bendpam.lab import RawTest
from bendpam.lab.drift import FLAG_FRACTION, DriftEstimate, estimate_drift
from bendpam.lab.processed import ProcessingOptions, load_processed, write_processed
from bendpam.lab.processing import process_series, process_tests
from bendpam.lab.simulate import SimulationSettings, simulate_test
from bendpam.lab.writers import write_test
from bendpam.physics.fixture import PAPER_FIXTURE
from bendpam.present.report.findings import plausibility_warnings

BE = presets.be_pam()
P_KPA = 150.0


def drifting(seed: int, fraction: float = 0.01):
    """A simulated test at 150 kPa with an offset drifting by ``fraction`` of the blocked force over the test.

    Returns ``(data without drift, data with drift, truth, drift rate N/s)``.  The blocked force is
    the blocked moment over the lever at beta = 0, d/2 (eq 7), and the offset is zero at t = 0.
    """
    data, truth = simulate_test(BE, P_KPA, settings=SimulationSettings(seed=seed))
    blocked_force_n = truth["blocked_moment_nmm"] / (PAPER_FIXTURE.d_mm / 2.0)
    rate = fraction * blocked_force_n / truth["duration_s"]
    drifted = data.copy()
    drifted["force_n"] = data["force_n"] + rate * data["time_s"]
    return data, drifted, truth, rate


def process(data, drift="none"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return process_series(data["time_s"], data["stroke_mm"], data["force_n"], P_KPA, keep_series=False,
                              options=ProcessingOptions(drift=drift), source="sim.csv")


def triangle_test(rate_n_per_s: float, shape, offset_n: float = 0.0, cycles: int = 3):
    """Noiseless triangular cycles (10 mm, 100 s each) with a force ``shape(stroke)`` per branch plus a drift."""
    t = np.arange(0.0, 100.0 * cycles + 0.05, 0.05) + 0.0123  # no sample on a window's edge
    phase = (t / 100.0) % 1.0
    s = 10.0 * (1.0 - np.abs(phase * 2.0 - 1.0))
    loading = phase >= 0.5
    f = shape(s) + np.where(loading, 0.3, 0.0) * (1.0 - s / 10.0) + offset_n + rate_n_per_s * t
    cyc = [(2000 * i, 2000 * i + 1000, 2000 * (i + 1)) for i in range(cycles)]
    return t, s, f, cyc


@settings(max_examples=25, deadline=None)
@given(rate=st.floats(-1e-2, 1e-2), offset=st.floats(-5.0, 5.0), stiffness=st.floats(0.2, 2.0))
def test_noiseless_drift_is_recovered_exactly(rate, offset, stiffness):
    # any loop that repeats from cycle to cycle, any constant offset: the slope is the drift itself
    t, s, f, cyc = triangle_test(rate, lambda s: 12.0 - stiffness * s, offset)
    est = estimate_drift(t, s, f, cyc)
    assert est is not None
    assert est.rate_n_per_s == pytest.approx(rate, abs=1e-12)
    assert est.free_rate_n_per_s == pytest.approx(rate, abs=1e-12)
    assert est.blocked_rate_n_per_s == pytest.approx(rate, abs=1e-12)
    assert not est.differs


def test_constant_offset_is_no_drift():
    t, s, f, cyc = triangle_test(0.0, lambda s: 12.0 - s, offset_n=0.7)
    f = f + np.random.default_rng(3).normal(0.0, 0.05, t.size)
    est = estimate_drift(t, s, f, cyc)
    assert abs(est.rate_n_per_s) < 3 * est.rate_se_n_per_s
    assert not est.flagged


def test_creep_at_the_blocked_end_is_told_apart():
    # a force that relaxes in proportion to itself (creep) moves the blocked ends, not the free ones
    t, s, f, cyc = triangle_test(0.0, lambda s: 12.0 - 1.15 * s)
    f = f * (1.0 - 1e-4 * t) + np.random.default_rng(4).normal(0.0, 0.01, t.size)
    est = estimate_drift(t, s, f, cyc)
    assert est.differs
    assert "creep" in est.message()


def test_single_cycle_has_no_estimate():
    t, s, f, cyc = triangle_test(1e-3, lambda s: 12.0 - s, cycles=1)
    assert estimate_drift(t, s, f, cyc) is None  # 4 windows, one per end: nothing to compare


def test_one_percent_drift_estimated_within_its_se_and_flagged():
    _, drifted, truth, rate = drifting(seed=6)
    res = process(drifted)
    est = res.drift
    # rate: 1 % of 2 * 204.35 N*mm / 35 mm = 0.1168 N over 262.5 s
    assert rate == pytest.approx(0.01 * 2 * truth["blocked_moment_nmm"] / 35.0 / truth["duration_s"])
    assert abs(est.rate_n_per_s - rate) <= est.rate_se_n_per_s
    assert est.flagged and not est.corrected
    assert est.drift_n == pytest.approx(0.01 * est.blocked_force_n, rel=0.25)
    flagged = [f for f in res.findings if f["check"] == "drift"]
    assert len(flagged) == 1
    msg = flagged[0]["message"]
    assert "times the force noise" in msg and "of the blocked force" in msg and "would move the blocked moment" in msg
    assert est.blocked_moment_shift_nmm < 0  # an offset growing toward compression inflates the later maxima


def test_drift_estimates_are_calibrated_over_seeds():
    zs = []
    for seed in range(10):
        _, drifted, _, rate = drifting(seed)
        est = process(drifted).drift
        zs.append((est.rate_n_per_s - rate) / est.rate_se_n_per_s)
        assert est.flagged
    zs = np.array(zs)
    assert np.all(np.abs(zs) < 3.5)
    assert 0.5 < math.sqrt(float(np.mean(zs**2))) < 2.0


def test_linear_correction_recovers_the_blocked_moment():
    clean, drifted, truth, _ = drifting(seed=2)
    raw = process(drifted)
    fixed = process(drifted, drift="linear")
    nodrift = process(clean)
    true_bm = truth["blocked_moment_nmm"]
    assert fixed.drift.corrected
    assert abs(fixed.blocked_moment[0] - true_bm) <= 0.01 * true_bm
    # the correction removes the drift's bias: closer to the no-drift processing than without it
    bias_fixed = abs(fixed.blocked_moment[0] - nodrift.blocked_moment[0])
    assert bias_fixed < abs(raw.blocked_moment[0] - nodrift.blocked_moment[0])
    # and it moves the blocked moment by what the report said it would
    assert fixed.blocked_moment[0] - raw.blocked_moment[0] == pytest.approx(raw.drift.blocked_moment_shift_nmm,
                                                                           abs=0.1)
    assert "moved the blocked moment" in fixed.drift.message()


def test_no_drift_is_not_flagged_over_seeds():
    flagged = [process(simulate_test(BE, P_KPA, settings=SimulationSettings(seed=seed))[0]).drift.flagged
               for seed in range(10)]
    assert sum(flagged) <= 1


def test_flag_needs_size_as_well_as_significance():
    small = DriftEstimate(rate_n_per_s=1e-6, rate_se_n_per_s=1e-8, duration_s=300.0, t0_s=0.0, noise_n=0.01,
                          blocked_force_n=10.0, points=12)
    assert small.sigmas > 3 and abs(small.drift_n) < FLAG_FRACTION * 10.0
    assert not small.flagged


def test_option_is_checked():
    with pytest.raises(InputError, match="drift = 'quadratic'; choose one of: none, linear"):
        ProcessingOptions(drift="quadratic")


def test_process_tests_drift_argument_and_summary():
    _, drifted, _, _ = drifting(seed=1)
    raws = [RawTest(drifted, __import__("pathlib").Path("be_150kPa.csv"), "csv", pressure_kpa=P_KPA)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        summary = process_tests(raws, keep_series=False, drift="linear").summary()
    d = summary["pressures"][0]["drift"]
    assert d["corrected"] and d["flagged"]
    assert json.loads(json.dumps(d))["rate_n_per_s"] == d["rate_n_per_s"]
    assert any(w["check"] == "drift" for w in summary["warnings"])


def test_drift_survives_the_processed_files(tmp_path):
    _, drifted, _, _ = drifting(seed=1)
    raws = [RawTest(drifted, __import__("pathlib").Path("be_150kPa.csv"), "csv", pressure_kpa=P_KPA)]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        processed = process_tests(raws, keep_series=False)
    write_processed(processed, tmp_path, figure=False)
    back = load_processed(tmp_path).results[0]
    before = processed.results[0].drift
    assert (back.drift.rate_n_per_s, back.drift.rate_se_n_per_s) == (before.rate_n_per_s, before.rate_se_n_per_s)
    assert back.drift.message() == before.message()
    assert back.drift.flagged and [f["check"] for f in back.findings] == ["drift"]


def test_report_words_a_drift_as_a_load_cell_fault():
    _, drifted, _, _ = drifting(seed=1)
    res = process(drifted)
    warns = plausibility_warnings(type("S", (), {"findings": res.findings})())
    assert [w.kind for w in warns] == ["drift"]
    assert warns[0].title.startswith("Load-cell drift: sim.csv (150 kPa)")


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_drift_flag_and_json(capsys, tmp_path):
    _, drifted, truth, _ = drifting(seed=3)
    raw = tmp_path / "raw"
    raw.mkdir()
    write_test(raw / "be_150kPa.csv", drifted, "csv", pressure_kpa=P_KPA)
    code, out, err = run(capsys, "process", str(raw), "--out", str(tmp_path / "plain"), "--no-figure")
    assert code == 0, err
    assert "load-cell offset drifts" in out and "--drift linear subtracts" in out
    code, out, err = run(capsys, "process", str(raw), "--out", str(tmp_path / "fixed"), "--no-figure",
                         "--drift", "linear", "--json")
    assert code == 0, err
    d = json.loads(out)["pressures"][0]
    assert d["drift"]["corrected"] and d["drift"]["flagged"]
    assert abs(d["blocked_moment_nmm"] - truth["blocked_moment_nmm"]) <= 0.01 * truth["blocked_moment_nmm"]
    on_disk = json.loads((tmp_path / "fixed" / "summary.json").read_text())
    assert on_disk["pressures"][0]["drift"]["corrected"]
    code, out, err = run(capsys, "process", str(raw), "--out", str(tmp_path / "bad"), "--drift", "quadratic")
    assert code == 2 and "--drift" in err


def test_force_recorded_negative_is_estimated_in_processing_orientation():
    # compression recorded as negative: processing flips the force, so an offset growing in the record
    # (+rate) is a drift of -rate toward the blocked state, and the correction still recovers the moment
    clean, _, truth, rate = drifting(seed=4)
    flipped = clean.copy()
    flipped["force_n"] = -clean["force_n"] + rate * clean["time_s"]
    res = process(flipped, drift="linear")
    assert abs(res.drift.rate_n_per_s + rate) <= 3 * res.drift.rate_se_n_per_s
    assert any("force sign flipped" in n for n in res.notes)
    assert abs(res.blocked_moment[0] - truth["blocked_moment_nmm"]) <= 0.01 * truth["blocked_moment_nmm"]


def test_corrected_alpha0_lands_within_two_se_of_the_truth():
    # issue 23: a drifting test is flagged, and with the linear correction its alpha0 is within 2 SE of the truth
    from pathlib import Path

    from bendpam.identify.fitting import fit

    rng = np.random.default_rng(11)
    raws = []
    for p in (100.0, 150.0, 200.0):
        data, truth = simulate_test(BE, p, settings=SimulationSettings(hysteresis=0.0, rate_hz=5.0), rng=rng)
        data["force_n"] += 0.01 * truth["blocked_moment_nmm"] / (PAPER_FIXTURE.d_mm / 2) / truth["duration_s"] \
            * data["time_s"]
        raws.append(RawTest(data, Path(f"be_{p:g}kPa.csv"), "csv", pressure_kpa=p))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        processed = process_tests(raws, keep_series=False, drift="linear",
                                  options=ProcessingOptions(grid_points=41))
        alpha0 = fit(processed, BE).parameters["alpha0"]
    assert sum(r.drift.flagged for r in processed.results) >= 2  # the shortest test (100 kPa, 85 s) is marginal
    assert all(r.drift.corrected for r in processed.results)
    assert abs(alpha0.value - BE.alpha0_deg) <= 2 * alpha0.stderr


def test_a_drift_too_small_for_any_test_alone_is_found_in_the_set():
    """Four tests drifting by 0.15 % of the blocked force each: no test is flagged alone, the set's pooled slope is,
    and the set says so once (summary, a warning); four tests without a drift say nothing."""
    from pathlib import Path

    from bendpam.errors import PlausibilityWarning
    from bendpam.lab.drift import SET_FLAG_SIGMAS, set_drift

    def raws(fraction):
        out = []
        for seed in range(4):
            clean, drifted, _, _ = drifting(seed=40 + seed, fraction=fraction)
            out.append(RawTest(drifted if fraction else clean, Path(f"be_{seed}.csv"), "csv", pressure_kpa=P_KPA))
        return out

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        drifts = process_tests(raws(0.0015), keep_series=False)
    ests = [r.drift for r in drifts.results]
    assert not any(e.flagged for e in ests)
    rate, z = set_drift(ests)
    assert z >= SET_FLAG_SIGMAS and rate > 0
    found = [f for f in drifts.summary()["warnings"] if f["check"] == "set drift"]
    assert len(found) == 1 and "4 tests' slopes pooled" in found[0]["message"]
    assert [w.kind for w in plausibility_warnings(drifts)] == ["drift"]  # the report: a load-cell fault
    assert sum("drifts in the set as a whole" in str(w.message) for w in caught
               if issubclass(w.category, PlausibilityWarning)) == 1
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        quiet = process_tests(raws(0.0), keep_series=False)
    assert set_drift([r.drift for r in quiet.results])[1] < SET_FLAG_SIGMAS
    assert not [f for f in quiet.summary()["warnings"] if f["check"] == "set drift"]


def test_an_uncorrected_drift_the_set_shares_is_counted_in_the_fits_error_bars():
    from types import SimpleNamespace as NS

    from bendpam.identify.data import drift_offsets

    one = DriftEstimate(2e-4, 1e-4, 200.0, 0.0, 0.05, 10.0, 12, blocked_moment_shift_nmm=-2.0)  # 2 SE: not flagged
    d = NS(seg=np.array([0, 1, 2]))
    assert not one.flagged
    assert drift_offsets(NS(results=[NS(drift=one)]), d) == []  # alone: no evidence of a drift
    many = drift_offsets(NS(results=[NS(drift=one)] * 3), d)  # three alike: 3.5 SE pooled
    assert [o.sd for o in many] == pytest.approx([math.hypot(2.0, 1.0)] * 3)
    assert [o.shift for o in many] == [-2.0] * 3  # what correcting it would move the moments by
    # corrected: the rate's own error and half the disagreement of the free and blocked ends' slopes
    fixed = DriftEstimate(2e-4, 1e-5, 200.0, 0.0, 0.05, 10.0, 12, free_rate_n_per_s=1e-4, blocked_rate_n_per_s=3e-4,
                          blocked_moment_nmm=300.0, corrected=True)
    (_, sd, shift, common), = drift_offsets(NS(results=[NS(drift=fixed)]), NS(seg=np.array([0])))
    assert common == 0.0  # a log from t = 0: zeroed there
    assert shift == 0.0
    assert sd == pytest.approx(math.hypot(1e-5, 1e-4) * 100.0 * 30.0)


def test_an_uncorrected_drift_says_how_far_correcting_it_would_move_alpha0():
    """Issue 23 item 1: the fit of a drifting set left uncorrected says by how much alpha0 would move when
    corrected; the linearised figure has the sign and about the size of an actual refit with --drift linear."""
    import re
    import sys
    import tempfile
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))
    import raw_generators as gen

    from bendpam.identify.fitting import fit
    from bendpam.lab import read_test
    from bendpam.physics.fixture import Fixture

    case = gen.CASES["drift"]
    with tempfile.TemporaryDirectory() as folder:
        truth = gen.generate_set(case, 0, folder)
        raws = [read_test(Path(folder) / name) for name in truth["files"]]
    fx = Fixture(L0_mm=truth["fixture_L0_mm"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        left = fit(process_tests(raws, fixture=fx, keep_series=False), gen.start_actuator(case), profile_points=0)
        fixed = fit(process_tests(raws, fixture=fx, keep_series=False, drift="linear"), gen.start_actuator(case),
                    profile_points=0)
    note = [f for f in left.flags if "left uncorrected" in f]
    assert len(note) == 1 and "--drift linear" in note[0]
    said = float(re.search(r"alpha0 by about ([-+0-9.e]+) deg", note[0]).group(1))
    moved = fixed.actuator.alpha0_deg - left.actuator.alpha0_deg
    assert np.sign(said) == np.sign(moved) and 0.6 < said / moved < 1.6
    assert not [f for f in fixed.flags if "left uncorrected" in f]  # corrected: nothing to say


def test_drifts_left_uncorrected_are_one_mode_whose_doubt_is_the_shift_correcting_them_makes():
    # one load cell: the tests' shifts (with their signs) move the parameters together, by what the linearised
    # refit says correcting them would; only each shift's own error (s / z) is independent of the others'
    from bendpam.identify.data import DriftOffset, offset_modes
    from bendpam.identify.uncertainty import offset_shift, sandwich_covariance

    rng = np.random.default_rng(4)
    J = rng.normal(size=(12, 3))
    rows = [np.arange(0, 4), np.arange(4, 8), np.arange(8, 12)]
    w = np.ones(12)
    groups = np.zeros(12, dtype=int)
    shifts = [-0.5, -0.8, -1.1]
    exact = [DriftOffset(r, abs(s), s) for r, s in zip(rows, shifts, strict=True)]  # known exactly (z infinite)
    cov, _ = sandwich_covariance(J, np.zeros(12), groups, [], offset_modes(exact, w))
    move = offset_shift(J, [(r, s * w[r]) for r, s in zip(rows, shifts, strict=True)])
    assert np.sqrt(np.diag(cov)) == pytest.approx(np.abs(move), rel=1e-9)
    # with an error of its own (z = 2 each), the doubt is the mode plus three independent offsets of s / 2
    loose = [DriftOffset(r, math.hypot(s, s / 2.0), s) for r, s in zip(rows, shifts, strict=True)]
    cov2, _ = sandwich_covariance(J, np.zeros(12), groups, [], offset_modes(loose, w))
    alone = sum(np.outer(g, g) for g in (s / 2.0 * J[r].sum(axis=0) for r, s in zip(rows, shifts, strict=True)))
    B = np.linalg.inv(J.T @ J)
    assert cov2 == pytest.approx(cov + B @ alone @ B, rel=1e-9)
    # a corrected drift (no shift) stays its own test's error
    assert [u.tolist() for _, u in offset_modes([DriftOffset(rows[0], 0.3, 0.0)], w)] == [[0.3] * 4]
    # when the load cell was zeroed (a log after its clock) is one procedure's doubt: one mode, as the shifts
    zeroed = [DriftOffset(r, 0.0, 0.0, s) for r, s in zip(rows, shifts, strict=True)]
    cov3, _ = sandwich_covariance(J, np.zeros(12), groups, [], offset_modes(zeroed, w))
    assert cov3 == pytest.approx(cov, rel=1e-9)


def test_a_log_that_starts_after_its_clock_is_taken_as_zeroed_halfway():
    rate = 1e-3  # N/s, from the clock's zero
    t, s, f, cyc = triangle_test(rate, lambda x: 10.0 - 0.9 * x)
    late = t + 150.0  # the log starts 150 s after the clock: the offset has grown by rate * 150 N already
    est = estimate_drift(late, s, f + rate * 150.0, cyc)
    assert est.zero_s == pytest.approx(0.5 * late[0])
    assert est.zero_sd_n == pytest.approx(rate * 0.5 * late[0] / math.sqrt(3.0), rel=0.02)
    left = (f + rate * 150.0 - est.offset_n(late)) - (f - rate * t)  # what the correction leaves: constant
    assert float(np.ptp(left)) < 2e-3 and abs(left[0]) <= math.sqrt(3.0) * est.zero_sd_n * 1.05
    assert "taken as zero at" in est.message() and DriftEstimate.from_dict(est.to_dict()) == est
    day = estimate_drift(t + 36000.0, s, f, cyc)  # a clock of the day: zeroed at the first sample
    assert day.zero_time_s == day.t0_s and day.zero_sd_n == 0.0
    zero = estimate_drift(t - t[0], s, f, cyc)  # a log from t = 0
    assert zero.zero_sd_n == 0.0
