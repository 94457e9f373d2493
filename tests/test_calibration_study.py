"""The calibration study of the error bars (issue 23 item 3) at a small size, and its independent generators.

The generators (tools/raw_generators.py) write raw files with loop laws and instrument faults bendpam does not
assume; the study (tools/calibration_study.py) reads, processes and fits them and tabulates bias, SE, seed-to-seed
spread and 2-SE coverage.  Here: hand numbers of the fixture and the loop laws, the raw text of a generated file,
and a two-seed study whose table has the right structure and whose fits recover the generators' truths.
"""

import dataclasses
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import calibration_study as study  # noqa: E402
import raw_generators as gen  # noqa: E402

from bendpam.physics.fixture import Fixture  # noqa: E402


# --------------------------------------------------------------------------------------------
# the fixture (eq 6-8) and the loop laws, by hand
# --------------------------------------------------------------------------------------------
def test_rig_is_eq_6_to_8_by_hand_and_agrees_with_bendpams_fixture():
    rig = gen.Rig()  # d 35, r 2.5, t 4
    beta = math.radians(30.0)
    # eq 6 by hand: 35 tan 30 + (sec 30 - 1) 9 = 20.2073 + 1.3923
    assert rig.stroke(beta) == pytest.approx(35 * math.tan(beta) + (1 / math.cos(beta) - 1) * 9.0, rel=1e-12)
    assert float(rig.beta(rig.stroke(beta))) == pytest.approx(beta, abs=1e-12)
    # eq 7 at beta = 0: M = F d / 2, so 10 N*mm needs 10 * 2 / 35 N
    assert float(rig.force(10.0, 0.0)) == pytest.approx(20.0 / 35.0, rel=1e-12)
    fx = Fixture()
    s = np.linspace(0.0, 60.0, 41)
    np.testing.assert_allclose(rig.beta(s), fx.stroke_to_beta(s), atol=1e-12)
    b = rig.beta(s)
    np.testing.assert_allclose(rig.force(100.0, b), 100.0 / fx.lever(b), rtol=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-50.0, 50.0), min_size=1, max_size=40), st.floats(0.0, 2.0))
def test_play_stays_in_its_band_and_moves_only_when_pushed(path, width):
    c = np.asarray(path)
    a = gen.play(c, width)
    assert np.all(a <= c + 1e-12) and np.all(a >= c - width - 1e-12)
    inside = (c[1:] - width <= a[:-1]) & (a[:-1] <= c[1:])  # the input stays within the band: no motion
    assert np.all(a[1:][inside] == a[:-1][inside])


def _triangle(n=2001, span_deg=10.0):
    t = np.linspace(0.0, 20.0, n)
    return t, math.radians(span_deg) * (1.0 - np.abs(t / 10.0 - 1.0))


def test_stiction_breaks_away_at_the_static_limit_and_slides_at_the_kinetic_one():
    t, u = _triangle()
    H = gen.stiction(t, u, 1.0, ratio=1.6, stick_deg=1.5, decay_deg=1.0)
    after = H[1001:]  # unloading -> loading at the reversal: the friction turns from -A to about +1.6 A
    assert after.max() == pytest.approx(1.6, abs=0.02)
    assert H[-1] == pytest.approx(1.0, abs=0.01)  # 10 deg of slip later: the kinetic limit
    assert H[990] == pytest.approx(-1.0, abs=0.01)


def test_maxwell_slip_saturates_at_its_amplitude_and_creeps_at_a_dwell():
    t, u = _triangle(span_deg=20.0)  # more than twice the largest slip angle (8 deg): every element slides
    H = gen.maxwell_slip(t, u, 2.0, creep_tau_s=None)
    assert H[999] == pytest.approx(-2.0, abs=1e-9) and H[-1] == pytest.approx(2.0, abs=1e-9)
    hold = np.full(2001, math.radians(20.0))
    tt = np.linspace(0.0, 400.0, 2001)
    Hc = gen.maxwell_slip(tt, np.r_[u[:1000], hold[1000:]], 2.0)  # ramp, then a long dwell
    assert Hc[999] < -1.0 and Hc[-1] == pytest.approx(-1.0, abs=0.02)  # the creeping half (A/2) relaxed away


def test_viscous_loop_grows_with_speed_and_bouc_wen_does_not_saturate():
    t, u = _triangle()
    # a short relaxation time: the Maxwell branch acts as a dashpot, so the loop is A at 1 deg/s and 2 A at 2 deg/s
    slow = gen.viscous(t, u, 1.0, speed_rad_s=math.radians(1.0), tau_s=0.05)
    fast = gen.viscous(t / 2.0, u, 1.0, speed_rad_s=math.radians(1.0), tau_s=0.05)
    assert slow[500] == pytest.approx(-1.0, rel=1e-3) and fast[500] == pytest.approx(2.0 * slow[500], rel=1e-3)
    z = -gen.bouc_wen(t, u, 1.0, theta_c=math.radians(10.0) * 0.4) * 0.8  # z along the path
    assert np.all(np.abs(z) < 1.0)  # below its bound (1/(beta + gamma))^(1/n) = 1 everywhere
    assert z[999] > 0.5 and z[999] - z[900] > 0.0  # still growing at the reversal: not saturated


def test_generated_file_raw_text_carries_the_pressure_the_drift_and_coloured_noise(tmp_path):
    case = dataclasses.replace(gen.CASES["drift"], pressures_kpa=(150.0,), cycles=2, noise_fraction=0.0)
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    info = gen.generate_set(case, 3, tmp_path / "a")
    clean = gen.generate_set(dataclasses.replace(case, drift_fraction=0.0), 3, tmp_path / "b")
    lines = (tmp_path / "a" / info["files"][0]).read_text(encoding="utf-8").splitlines()
    assert lines[0] == "# Pressure: 150 kPa" and lines[3] == "time_s,stroke_mm,force_n"
    last = [float(x) for x in lines[-1].split(",")]
    last0 = [float(x) for x in (tmp_path / "b" / clean["files"][0]).read_text().splitlines()[-1].split(",")]
    blocked = info["tests"][0]["blocked_force_n"]
    assert last[2] - last0[2] == pytest.approx(0.01 * blocked, abs=2e-5)  # 1 % of the blocked force at the end
    # the noise: AR(1), lag-one correlation as asked
    rng = np.random.default_rng(0)
    noisy = dataclasses.replace(case, drift_fraction=0.0, noise_fraction=0.02, noise_ar1=0.9)
    t, _s, f, inf = gen.machine_test(noisy, gen.case_truth(noisy), 150.0, rng, gen.Rig())
    _t, _s, f0, _ = gen.machine_test(dataclasses.replace(noisy, noise_fraction=0.0), gen.case_truth(noisy), 150.0,
                                     np.random.default_rng(0), gen.Rig())
    e = (f - f0) / inf["blocked_force_n"]
    assert np.std(e) == pytest.approx(0.02, rel=0.25)
    assert np.corrcoef(e[1:], e[:-1])[0, 1] == pytest.approx(0.9, abs=0.05)


def test_testxpert_and_bluehill_files_read_back_with_their_pressure(tmp_path):
    from bendpam.lab import read_test

    for name in ("maxwell-creep", "stiction"):
        case = dataclasses.replace(gen.CASES[name], pressures_kpa=gen.CASES[name].pressures_kpa[:1], cycles=1)
        folder = tmp_path / name
        folder.mkdir()
        info = gen.generate_set(case, 1, folder)
        raw = read_test(folder / info["files"][0])
        assert raw.pressure_kpa == case.pressures_kpa[0] and raw.pressure_source == "metadata"
        assert raw.dialect == case.dialect and len(raw.data) == info["tests"][0]["samples"]


# --------------------------------------------------------------------------------------------
# the study at a small size
# --------------------------------------------------------------------------------------------
SMALL = {  # two cycles at 10 Hz (the full study: three at 20 Hz)
    "none": dataclasses.replace(gen.CASES["none"], cycles=2, rate_hz=10.0),
    "stiction": dataclasses.replace(gen.CASES["stiction"], pressures_kpa=(100.0, 150.0, 200.0), cycles=2,
                                    rate_hz=10.0),
    "drift": dataclasses.replace(gen.CASES["drift"], pressures_kpa=(120.0, 200.0), cycles=2, rate_hz=10.0),
}


@pytest.fixture(scope="module")
def small_study():
    return study.run_study(list(SMALL), seeds=2, cases=SMALL)


def test_study_table_has_a_row_per_case_and_variant(small_study, tmp_path):
    records, rows, meta = small_study
    assert [(r["case"], r["variant"]) for r in rows] == [("none", "none"), ("stiction", "none"),
                                                       ("drift", "linear"), ("drift", "none")]
    assert meta["runs"] == len(records) == 8 and all(r["failed"] == 0 for r in rows)
    text = study.tables(rows, meta)
    head = [ln for ln in text.splitlines() if ln.startswith("| case |")]
    assert len(head) == 3  # alpha0 and mu; shape and drift flags; the drift correction's uncertainty
    table = text.splitlines()
    first = table.index(head[0])
    body = table[first + 2: first + 2 + len(rows)]
    assert [ln.split(" | ")[0] for ln in body] == ["| none", "| stiction", "| drift (corrected)",
                                                  "| drift (not corrected)"]
    assert all(ln.count("|") == head[0].count("|") for ln in body)
    page = tmp_path / "calibration.md"
    page.write_text(f"# t\n\nbefore\n{study.START}\nold\n{study.END}\nafter\n", encoding="utf-8")
    study.write_docs(page, text)
    new = page.read_text(encoding="utf-8")
    assert "old" not in new and text in new and new.endswith(f"{study.END}\nafter\n")


def test_study_recovers_the_generators_truths_and_flags_the_drift(small_study):
    records, rows, _ = small_study
    by = {(r["case"], r["variant"]): r for r in rows}
    for key in (("none", "none"), ("stiction", "none"), ("drift", "linear")):
        a, m = by[key]["alpha0"], by[key]["mu"]
        assert abs(a["bias"]) < 0.2 and abs(m["bias"]) < 3.0  # deg, % of the truth
        assert 0 < a["mean_se"] < 0.2 and a["n"] == 2
    # no loop and no fault: the truth within 2 SE (at most one false drift flag in 6 tests); the drift is
    # flagged, and correcting it removes its bias
    assert by[("none", "none")]["alpha0"]["coverage"] == 1.0 and by[("none", "none")]["drift_flagged"] <= 1
    assert by[("drift", "none")]["drift_flagged"] >= 3  # of 4 tests (two cycles each)
    assert abs(by[("drift", "linear")]["alpha0"]["bias"]) < 0.5 * abs(by[("drift", "none")]["alpha0"]["bias"])
    assert by[("drift", "linear")]["alpha0_drift_se"]["mean_se"] > by[("drift", "linear")]["alpha0"]["mean_se"]
    # every run's truth is the case's
    truth = gen.case_truth(SMALL["stiction"])
    assert {r["truth"]["alpha0_deg"] for r in records if r["case"] == "stiction"} == {truth.alpha0_deg}


def test_the_docs_page_names_the_command_that_regenerates_it():
    page = (ROOT / "docs" / "calibration.md").read_text(encoding="utf-8")
    assert "python tools/calibration_study.py" in page
    for case_set in [*study.SETS, "main-tared"]:
        start, end = study.markers(case_set)
        assert page.index(start) < page.index(end)
    assert "python tools/calibration_study.py --tared" in page
    # --tared declares what the page says: a zero to 5 mN and no force in proportion to the pressure
    from bendpam.identify.uncertainty import Instrument

    tared = Instrument(*study.TARED)
    assert tared.offset_uncertainties() == {"F_off": 0.005, "F_P": 0.0} and "zero known to 5 mN" in page


def test_the_study_fits_as_the_commands_do(small_study, tmp_path):
    """``bendpam process --drift linear`` then ``bendpam fit`` on the generated files give the study's alpha0."""
    import json

    from bendpam.cli import main

    raw = tmp_path / "raw"
    raw.mkdir()
    gen.generate_set(SMALL["drift"], 1, raw)
    assert main(["process", str(raw), "--out", str(tmp_path / "p"), "--drift", "linear", "--no-figure",
                 "--quiet"]) == 0
    assert main(["fit", str(tmp_path / "p"), "--preset", "be-pam", "--no-figure", "--quiet", "--out",
                 str(tmp_path / "f")]) == 0
    cli = json.loads((tmp_path / "f" / "fit.json").read_text(encoding="utf-8"))
    rec = next(r for r in small_study[0] if (r["case"], r["variant"], r["seed"]) == ("drift", "linear", 1))
    assert cli["parameters"]["alpha0_deg"]["value"] == pytest.approx(rec["alpha0_deg"], abs=1e-6)
    # the same options: the same SE (to the Monte-Carlo error of a resampling term, should the fit use one)
    assert cli["parameters"]["alpha0_deg"]["stderr"] == pytest.approx(rec["se_alpha0_deg"], rel=0.1)


def test_every_holdout5_case_generates_files_that_read_back(tmp_path):
    """The fifth held-out set (new loop laws and faults): each case writes one file per pressure that reads back."""
    from bendpam.lab import read_test

    assert set(gen.HOLDOUT5) <= set(study.ALL_CASES) and study.SETS["holdout5"] is gen.HOLDOUT5
    for name, full in gen.HOLDOUT5.items():
        case = dataclasses.replace(full, pressures_kpa=full.pressures_kpa[-1:], cycles=2)
        folder = tmp_path / name.replace("+", "_")
        folder.mkdir()
        info = gen.generate_set(case, 1, folder)
        raw = read_test(folder / info["files"][0])
        assert raw.pressure_kpa == case.pressures_kpa[0] and raw.dialect == case.dialect
        assert len(raw.data) == info["tests"][0]["samples"] and np.all(np.isfinite(raw.data["force_n"]))
    # the new rate-independent laws saturate where their textbook forms say
    t, u = _triangle(span_deg=20.0)
    H = gen.iwan_lognormal(t, u, 2.0, median_deg=1.0, sigma_ln=0.5)
    assert H[999] == pytest.approx(-2.0, abs=1e-9) and H[-1] == pytest.approx(2.0, abs=1e-9)
    H = gen.asymmetric_stop(t, u, 1.0, up=1.3, down=0.7)
    assert H[999] == pytest.approx(-0.7, abs=1e-9) and H[-1] == pytest.approx(1.3, abs=1e-9)
