"""Processing a folder: every file reported, --keep-going, replicates, plausibility after processing (issue 22, 6-7)."""

import json
import math
import shutil
import warnings

import numpy as np
import pytest

import bendpam
from bendpam.cli import main
from bendpam.errors import PlausibilityWarning, ProcessingError
from bendpam.identify.data import branch_data, fit_data
from bendpam.lab.batch import FilesRefused, process_files
from bendpam.lab.plausibility import PROCESSED_BOUNDS, check_result, compression_like, moment_bound_nmm
from bendpam.lab.processed import load_processed
from bendpam.lab.processing import NotABendingTest, process_series
from bendpam.lab.simulate import SimulationSettings, simulate_test, simulate_tests
from bendpam.physics.fixture import PAPER_FIXTURE, Fixture

SETTINGS = SimulationSettings(cycles=2, rate_hz=5.0, seed=1)


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def _compression_csv(path, n=400, top_n=-120000.0, travel_mm=3.0, seed=3):
    """A monotone compression record (a concrete cylinder): the stroke one way, the force of one sign."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.25
    s = travel_mm * t / t[-1]
    f = top_n * (s / travel_mm) ** 1.3 + rng.normal(0.0, 5.0, n) - 10.0
    lines = ["time_s,stroke_mm,force_n"] + [f"{a:.3f},{b:.5f},{c:.2f}" for a, b, c in zip(t, s, f, strict=True)]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """Three simulated pressures, a second specimen at 150 kPa, a garbage file and a compression test."""
    base = tmp_path_factory.mktemp("folder")
    raw = base / "raw"
    be = bendpam.physics.presets.be_pam()
    truth = simulate_tests(be, [100, 150, 200], raw, settings=SETTINGS)
    rep = simulate_tests(be, [150], base / "rep", settings=SimulationSettings(cycles=2, rate_hz=5.0, seed=7))
    shutil.copy(base / "rep" / rep["files"][0], raw / "specimen2_150kPa.csv")
    (raw / "garbage.csv").write_bytes(b"\x00\x01 not a test ;;; \xff\xfe\n" * 20)
    _compression_csv(raw / "concrete_200kPa.csv")
    return base, raw, truth


def test_without_keep_going_every_bad_file_is_named_and_nothing_is_written(capsys, folder):
    base, raw, _ = folder
    out_dir = base / "refused"
    code, out, err = run(capsys, "process", str(raw), "--out", str(out_dir), "--no-figure")
    assert code == 2
    lines = [ln for ln in err.splitlines() if ln.startswith("bendpam: error:")]
    assert any("garbage.csv" in ln for ln in lines)
    assert any("concrete_200kPa.csv" in ln and "not a cyclic bending test" in ln for ln in lines)
    assert lines[-1].startswith("bendpam: error: 2 of 6 file(s) cannot be processed")
    assert "Traceback" not in err
    assert not out_dir.exists()  # nothing written


def test_keep_going_reports_each_file_replicates_and_the_compression_test(capsys, folder):
    base, raw, truth = folder
    code, out, err = run(capsys, "process", str(raw), "--out", str(base / "kept"), "--no-figure", "--keep-going")
    assert code == 0, err
    # one line per file, in the order read
    assert f"{raw / 'garbage.csv'}: skipped: " in out
    line = next(ln for ln in out.splitlines() if ln.startswith(f"{raw / 'concrete_200kPa.csv'}: "))
    assert "skipped: lines 2-401: not a cyclic bending test" in line and "force of one sign only" in line
    assert f"{raw / 'specimen2_150kPa.csv'}: read (1 test)" in out
    for name in truth["files"]:
        assert f"{raw / name}: read (1 test)" in out
    # Table 2: both replicates at 150 kPa, then their mean with its spread and n
    rows150 = [ln for ln in out.splitlines() if ln.strip().startswith("150 ")]
    assert len(rows150) == 2 and "#1" in rows150[0] and "#2" in rows150[1]
    assert "std over n = 2 replicates" in out
    summ = json.loads((base / "kept" / "summary.json").read_text())
    assert [p["pressure_kpa"] for p in summ["pressures"]] == [100.0, 150.0, 150.0, 200.0]
    assert [p["replicate"] for p in summ["pressures"]] == [1, 1, 2, 1]
    rep = next(g for g in summ["replicates"] if g["pressure_kpa"] == 150.0)
    a, b = (p["blocked_moment_nmm"] for p in summ["pressures"] if p["pressure_kpa"] == 150.0)
    assert rep["n"] == 2
    assert rep["blocked_moment_nmm"] == pytest.approx((a + b) / 2, rel=1e-12)
    assert rep["blocked_moment_std_nmm"] == pytest.approx(abs(a - b) / math.sqrt(2), rel=1e-9)
    t150 = next(p for p in truth["pressures"] if p["pressure_kpa"] == 150.0)["blocked_moment_nmm"]
    assert rep["blocked_moment_nmm"] == pytest.approx(t150, rel=0.02)
    assert next(g for g in summ["replicates"] if g["pressure_kpa"] == 100.0)["blocked_moment_std_nmm"] is None
    # every file in the JSON; the compression test is a plausibility warning naming it and its numbers
    status = {f["file"].rsplit("/", 1)[-1]: f["status"] for f in summ["files"]}
    assert status == {"garbage.csv": "skipped", "concrete_200kPa.csv": "skipped", "specimen2_150kPa.csv": "read",
                      **{name: "read" for name in truth["files"]}}
    warned = [w for w in summ["warnings"] if w["check"] == "not-bending"]
    assert len(warned) == 1 and "concrete_200kPa.csv" in warned[0]["message"] and "N)" in warned[0]["message"]


def test_json_carries_files_replicates_and_warnings(capsys, folder):
    base, raw, _ = folder
    code, out, err = run(capsys, "process", str(raw), "--out", str(base / "j"), "--no-figure", "--keep-going",
                         "--json")
    assert code == 0, err
    summ = json.loads(out)
    assert {"files", "replicates", "warnings", "pressures"} <= set(summ)
    assert sum(f["status"] == "skipped" for f in summ["files"]) == 2


def test_the_fit_uses_every_replicate(folder):
    _, raw, _ = folder
    files = sorted(p for p in raw.iterdir() if p.suffix == ".csv")
    processed = process_files(files, keep_going=True, keep_series=False)
    assert processed.pressures_kpa.tolist() == [100.0, 150.0, 150.0, 200.0]
    d = fit_data(processed, "all")
    assert d.P.tolist() == [100.0, 150.0, 150.0, 200.0]  # each replicate's curve is data, not only the mean
    assert np.unique(d.seg).size == 4
    two = [r for r in processed.results if r.pressure_kpa == 150.0]
    assert not np.allclose(two[0].mean_curve, two[1].mean_curve)  # two specimens, two curves
    assert branch_data(processed, 145.0).kc.size == 2 * sum(r.curvature_grid.size for r in processed.results)
    # deadband: the line through every test (replicates are points of their own)
    p0, _ = processed.deadband()
    assert p0 == pytest.approx(68.0, abs=3.0)


def test_library_refuses_naming_every_bad_file(folder):
    _, raw, _ = folder
    files = sorted(p for p in raw.iterdir() if p.suffix == ".csv")
    with pytest.raises(FilesRefused) as info:
        process_files(files, keep_series=False)
    assert len(info.value.problems) == 2
    assert "\n" not in str(info.value)
    assert all(any(p.startswith(str(raw / n)) for p in info.value.problems)
               for n in ("garbage.csv", "concrete_200kPa.csv"))
    with pytest.raises(ProcessingError, match="none of the 1 file"):
        process_files([raw / "garbage.csv"], keep_going=True)


def test_save_load_round_trip_keeps_replicates_and_findings(tmp_path, folder):
    _, raw, _ = folder
    files = sorted(p for p in raw.iterdir() if p.suffix == ".csv")
    processed = process_files(files, keep_going=True, keep_series=False)
    processed.results[0].findings = [{"test": "x", "check": "loss-ratio", "message": "x: hand-made"}]
    processed.save(tmp_path / "o", figure=False)
    back = load_processed(tmp_path / "o")
    assert [r.replicate for r in back.results] == [1, 1, 2, 1]
    assert back.results[0].findings[0]["check"] == "loss-ratio"
    assert [r.source for r in back.results] == [r.source for r in processed.results]
    for r, s in zip(back.results, processed.results, strict=True):
        np.testing.assert_allclose(r.blocked_moments, s.blocked_moments)
    # the file keeps the layout older code reads: the same variables and dimensions
    import xarray as xr

    with xr.open_dataset(tmp_path / "o" / "curves.nc") as ds:
        assert ds["moment_nmm"].dims == ("pressure_kpa", "cycle", "branch", "point")
        assert ds["blocked_moment_cycle_nmm"].dims == ("pressure_kpa", "cycle")
        old = ds.drop_vars("replicate").load()
    old.attrs = {k: v for k, v in old.attrs.items() if k not in ("plausibility_json", "specimens")}
    old.to_netcdf(tmp_path / "old.nc")
    older = load_processed(tmp_path / "old.nc")  # a file without the new fields still reads
    assert [r.replicate for r in older.results] == [1, 1, 1, 1] and all(not r.findings for r in older.results)


# --- plausibility after processing ----------------------------------------------------------------
def test_moment_bound_by_hand():
    # K = 2.6 (1 + 2 cot^2 10 deg): cot 10 deg = 5.671282, cot^2 = 32.16344, K = 2.6 * 65.32688 = 169.8499
    # pi (35/2)^3 = pi 5359.375 = 16836.94 mm^3; at 200 kPa = 0.2 N/mm^2: 3367.39 N*mm; * K = 571951.6;
    # plus the force resolution's moment at the blocked state, 0.2 N * 35/2 mm = 3.5 N*mm
    assert PROCESSED_BOUNDS["moment_factor"] == pytest.approx(169.8499, rel=1e-6)
    assert moment_bound_nmm(PAPER_FIXTURE, 200.0) == pytest.approx(571951.6 + 3.5, rel=1e-6)
    assert moment_bound_nmm(Fixture(70.0, 2.5, 4.0), 200.0) == pytest.approx(8 * 571951.6 + 7.0, rel=1e-6)
    assert moment_bound_nmm(PAPER_FIXTURE, 0.0) == pytest.approx(3.5)


def test_a_force_ten_thousand_times_too_large_is_warned_about():
    data, _ = simulate_test(bendpam.physics.presets.be_pam(), 150.0, settings=SETTINGS)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ok = process_series(data.time_s, data.stroke_mm, data.force_n, 150.0, source="ok.csv")
        bad = process_series(data.time_s, data.stroke_mm, 1e4 * data.force_n, 150.0, source="force_x1e4.csv")
    assert ok.findings == []
    assert [f["check"] for f in bad.findings] == ["blocked-moment"]
    f = bad.findings[0]
    assert f["value"] == pytest.approx(1e4 * ok.blocked_moment[0], rel=1e-9)
    assert f["bound"] == pytest.approx(moment_bound_nmm(PAPER_FIXTURE, 150.0))
    assert "force_x1e4.csv" in f["message"] and f"{f['value']:.4g}" in f["message"]
    plaus = [w for w in caught if issubclass(w.category, PlausibilityWarning)]
    assert len(plaus) == 1 and "force_x1e4.csv" in str(plaus[0].message)
    assert bad.summary()["warnings"] == [f["message"]]


def test_loss_ratio_and_return_bounds():
    from types import SimpleNamespace as NS

    def test(ratio):
        return NS(source="t.csv", pressure_kpa=100.0, blocked_moment=(50.0, 1.0), energy_loss_ratio=ratio)

    assert check_result(test(0.59), PAPER_FIXTURE) == []
    assert [f["check"] for f in check_result(test(0.61), PAPER_FIXTURE)] == ["loss-ratio"]
    assert "61.0 %" in check_result(test(0.61), PAPER_FIXTURE)[0]["message"]
    assert [f["check"] for f in check_result(test(-0.10), PAPER_FIXTURE)] == ["loss-ratio"]
    assert check_result(test(0.2), PAPER_FIXTURE, [0.02, 0.24]) == []
    found = check_result(test(0.2), PAPER_FIXTURE, [0.02, 0.5])
    assert [f["check"] for f in found] == ["curvature-return"] and "cycle 2" in found[0]["message"]


def test_compression_detection_is_not_fooled_by_a_bending_test():
    data, _ = simulate_test(bendpam.physics.presets.be_pam(), 150.0, settings=SETTINGS)
    s, f = data.stroke_mm.to_numpy(), data.force_n.to_numpy()
    assert compression_like(s, f, 0.05 * np.ptp(s)) is None
    ramp = np.linspace(0.0, 2.0, 300)
    assert compression_like(ramp, 5000.0 * ramp + 1.0, 0.1) is not None      # tension, one sign
    assert compression_like(ramp, np.sin(8 * ramp) * 100.0, 0.1) is None   # force of both signs
    with pytest.raises(NotABendingTest, match=r"c\.csv: not a cyclic bending test"):
        process_series(np.arange(300.0), ramp, -4e4 * ramp, 100.0, source="c.csv")


def test_report_lists_each_replicate_their_mean_and_the_warnings(folder):
    from bendpam.present.report.findings import plausibility_warnings
    from bendpam.present.report.html import _tests_context

    _, raw, _ = folder
    files = sorted(p for p in raw.iterdir() if p.suffix == ".csv")
    processed = process_files(files, keep_going=True, keep_series=False)
    summ = processed.summary()
    ctx = _tests_context(bendpam.physics.presets.be_pam(), summ, 0.2)
    heads = [str(r.cells[0].text) for r in ctx["table2"].rows]
    assert heads == ["100", "150 (#1)", "150 (#2)", "150 mean (n = 2)", "200"]
    mean_row = ctx["table2"].rows[3]
    rep = next(g for g in summ["replicates"] if g["pressure_kpa"] == 150.0)
    assert mean_row.cells[2].value == rep["blocked_moment_nmm"]
    assert mean_row.cells[2].se == rep["blocked_moment_std_nmm"]
    assert len(ctx["skipped_files"]) == 2
    w = plausibility_warnings(processed)
    assert len(w) == 1 and w[0].kind == "implausible" and "concrete_200kPa.csv" in w[0].title


# --- real exports (tests/data/real/dev): concrete tests on an MTS 793 frame --------------------------
REAL = __import__("pathlib").Path(__file__).parent / "data" / "real" / "dev"
CONCRETE = ["lebedigital_MTS793_DEU_compression_BAM_M03_W01.dat", "lebedigital_MTS793_DEU_compression_BAM_M05_W04.dat",
            "lebedigital_MTS793_DEU_compression_Wolf82_Probe3.dat"]


def test_real_concrete_compression_tests_are_recognised(folder):
    _, raw, truth = folder
    files = [raw / truth["files"][0]] + [REAL / n for n in CONCRETE]
    processed = process_files(files, pressures_kpa=[None, 200.0, 200.0, 200.0], keep_going=True, keep_series=False)
    assert [f["status"] for f in processed.files] == ["read", "skipped", "skipped", "skipped"]
    assert [w["check"] for w in processed.findings] == ["not-bending"] * 3
    for f in processed.files[1:]:
        assert "not a cyclic bending test" in f["reason"] and "force of one sign only" in f["reason"]


def test_real_cyclic_concrete_test_is_warned_about_its_blocked_moment():
    # the example: a cyclic (E-modulus) concrete test on an MTS frame processed as a bending actuator
    path = REAL / "lebedigital_MTS793_DEU_cyclic_Emodul_BALosMV6.dat"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlausibilityWarning)
        processed = process_files([path], pressures_kpa=[200.0], keep_series=False)
    (r,) = processed.results
    checks = {f["check"]: f for f in r.findings}
    assert "blocked-moment" in checks
    # the raw text: the first data block (line 14 names, line 15 units kN, data to line 623), 'Ch 1 Kraft' in kN
    lines = path.read_text(encoding="latin-1").splitlines()
    assert lines[13].split("\t")[3] == "Ch 1 Kraft" and lines[14].split("\t")[3] == "kN"
    kraft_kn = [float(ln.split("\t")[3].replace(",", ".")) for ln in lines[15:622] if ln.split("\t")[0].isdigit()]
    peak_n = 1000.0 * max(abs(v) for v in kraft_kn)
    blocked_force_n = 2.0 * checks["blocked-moment"]["value"] / PAPER_FIXTURE.d_mm  # eq 7 at beta = 0
    assert blocked_force_n == pytest.approx(peak_n, rel=0.03)
    assert checks["blocked-moment"]["value"] > 3 * moment_bound_nmm(PAPER_FIXTURE, 200.0)
