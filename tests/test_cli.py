import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

import bendpam
from bendpam import presets
from bendpam.cli import main


def run(capsys, *args):
    code = main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_demo(capsys, tmp_path):
    fig = tmp_path / "demo.png"
    code, out, err = run(capsys, "demo", "--out", str(fig))
    assert code == 0, err
    assert fig.stat().st_size > 10000 and fig.read_bytes()[:4] == b"\x89PNG"
    for word in ("BE-PAM", "BC-PAM", "energy model", "force-balance model", "fold"):
        assert word in out
    assert "310.33" in out  # BE-PAM blocked moment at 200 kPa


def test_predict_json(capsys):
    code, out, err = run(capsys, "predict", "--preset", "bc-pam", "--pressure-kpa", "40", "100", "150", "--json")
    assert code == 0, err
    obj = json.loads(out)
    assert obj["model"] == "energy"
    assert obj["actuator"]["alpha0_deg"] == 36.57
    res = obj["results"]
    assert [r["pressure_kpa"] for r in res] == [40.0, 100.0, 150.0]
    assert set(res[0]) == {"pressure_kpa", "blocked_moment_nmm", "free_curvature_per_mm", "free_angle_deg", "note",
                           "frame_axial_force_n", "frame_stress_mpa", "frame_strength_margin", "buckling_margin",
                           "lockup_margin", "bladder_stretch_max", "bladder_stretch_margin", "min_margin",
                           "limit_note", "lateral_stiffness_nmm2", "torsional_stiffness_nmm2_per_rad",
                           "torsion_lock_torque_nmm"}
    assert res[0]["blocked_moment_nmm"] < 0 and res[0]["free_curvature_per_mm"] < 0 and res[0]["note"] is None
    assert res[2]["free_curvature_per_mm"] is None and res[2]["free_angle_deg"] is None
    assert "fold" in res[2]["note"]
    assert 120 < obj["max_equilibrium_pressure_kpa"] < 140
    ref = bendpam.free_curvature(presets.bc_pam(), 100.0)
    assert res[1]["free_curvature_per_mm"] == pytest.approx(float(ref.curvature_per_mm))


def test_predict_table_and_ranges(capsys):
    code, out, err = run(capsys, "predict", "--preset", "be-pam", "--model", "force-balance", "--pressure-kpa",
                         "100:200:3")
    assert code == 0, err
    assert "force-balance model" in out
    assert out.count("\n") >= 5
    assert "310.33" in out and "150" in out


def test_curve_csv_matches_library(capsys, tmp_path):
    f = tmp_path / "c.csv"
    code, out, err = run(capsys, "curve", "--preset", "be-pam", "--pressure-kpa", "150,200", "--out", str(f),
                         "--points", "25")
    assert code == 0, err
    df = pd.read_csv(f)
    assert list(df.columns) == ["pressure_kpa", "curvature_per_mm", "moment_nmm"]
    assert len(df) == 50
    sub = df[df.pressure_kpa == 200]
    np.testing.assert_allclose(sub.moment_nmm, bendpam.moment(presets.be_pam(), 200.0, sub.curvature_per_mm.values),
                               rtol=1e-8, atol=1e-6)
    # default range runs just past free bending
    k_free = float(bendpam.free_curvature(presets.be_pam(), 200.0).curvature_per_mm)
    assert k_free < sub.curvature_per_mm.max() < 1.2 * k_free


def test_curve_k_max_and_png(capsys, tmp_path):
    f = tmp_path / "c.png"
    code, _, err = run(capsys, "curve", "--preset", "bc-pam", "--pressure-kpa", "60", "140", "--out", str(f),
                       "--k-max", "0.012")
    assert code == 0, err
    assert f.read_bytes()[:4] == b"\x89PNG"
    g = tmp_path / "c.csv"
    run(capsys, "curve", "--preset", "bc-pam", "--pressure-kpa", "60", "--out", str(g), "--k-max", "0.012")
    df = pd.read_csv(g)
    assert df.curvature_per_mm.min() == pytest.approx(-0.012) and df.curvature_per_mm.max() == 0.0


def test_stresses_outputs(capsys, tmp_path):
    for name in ("s.png", "s.nc", "s.csv"):
        code, _, err = run(capsys, "stresses", "--preset", "be-pam", "--pressure-kpa", "200", "--curvature", "0.01",
                           "--out", str(tmp_path / name))
        assert code == 0, err
    ds = xr.open_dataset(tmp_path / "s.nc")
    # stresses are in kPa at every public edge (issue 10; they were MPa before)
    assert "sigma_bl1_kpa" in ds and ds["sigma_bl1_kpa"].attrs["units"] == "kPa"
    assert ds["P_e_kpa"].attrs["units"] == "kPa" and ds.attrs["pressure_kpa"] == 200.0
    ds.close()


def test_actuator_toml_round_trip(capsys, tmp_path):
    f = tmp_path / "be.toml"
    code, out, _ = run(capsys, "actuator", "--preset", "be-pam", "--out", str(f))
    assert code == 0
    code, out, err = run(capsys, "predict", "--actuator", str(f), "--pressure-kpa", "200", "--json")
    assert code == 0, err
    assert json.loads(out)["results"][0]["blocked_moment_nmm"] == pytest.approx(310.3292566, rel=1e-8)
    code, out, _ = run(capsys, "actuator", "--preset", "bc-pam")
    assert "curvature range" in out and "t0_start_mm" in out


@pytest.mark.parametrize(
    "args,words",
    [
        (["predict", "--preset", "foo", "--pressure-kpa", "1"], ["foo"]),
        (["predict", "--preset", "be-pam", "--pressure-kpa", "-5"], ["below zero"]),
        (["predict", "--preset", "be-pam"], ["--pressure-kpa"]),
        (["predict", "--preset", "be-pam", "--pressure-kpa", "abc"], ["abc"]),
        (["predict", "--preset", "be-pam", "--pressure-kpa", "100", "--bogus"], ["--bogus"]),
        (["predict", "--pressure-kpa", "100"], ["--preset"]),
        (["predict", "--preset", "be-pam", "--actuator", "x.toml", "--pressure-kpa", "100"], ["not both"]),
        (["predict", "--actuator", "/nonexistent/a.toml", "--pressure-kpa", "100"], ["not found"]),
        (["predict", "--preset", "be-pam", "--model", "fem", "--pressure-kpa", "100"], ["fem"]),
        (["curve", "--preset", "be-pam", "--pressure-kpa", "100", "--out", "x.txt"], [".txt"]),
        # a relative path inside the test's folder (it used to be /nonexistent/x.csv: while the bug below
        # stands, that creates /nonexistent on the machine)
        pytest.param(["curve", "--preset", "be-pam", "--pressure-kpa", "100", "--out", "missing-folder/x.csv"],
                     ["does not exist"], id="missing-output-folder"),
        (["curve", "--preset", "be-pam", "--pressure-kpa", "100", "--out", "c.csv", "--k-max", "5"], ["lock-up"]),
        (["curve", "--preset", "be-pam", "--pressure-kpa", "100", "--out", "c.csv", "--k-max", "-1"], ["positive"]),
        (["stresses", "--preset", "be-pam", "--curvature", "9", "--out", "s.png"], ["lock-up"]),
        (["nonsense"], ["nonsense"]),
    ],
)
def test_errors_are_one_line_exit_2(capsys, tmp_path, monkeypatch, args, words):
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, *args)
    assert code == 2
    assert err.startswith("bendpam: error:") and err.count("\n") == 1, err
    assert "Traceback" not in err
    for w in words:
        assert w in err
    assert not list(tmp_path.iterdir())  # nothing half-written


def test_bad_toml_error(capsys, tmp_path):
    f = tmp_path / "bad.toml"
    f.write_text("[actuator]\nalpha0_deg = 95\n")
    code, _, err = run(capsys, "predict", "--actuator", str(f), "--pressure-kpa", "100")
    assert code == 2 and str(f) in err and err.count("\n") == 1


def test_no_arguments_prints_help(capsys):
    code, out, _ = run(capsys)
    assert code == 0 and "predict" in out and "demo" in out


def test_console_script_entry_point(tmp_path):
    exe = Path(sys.executable).with_name("bendpam")
    if not exe.exists():
        pytest.skip("the bendpam console script is not installed next to this interpreter")
    r = subprocess.run([str(exe), "predict", "--preset", "be-pam", "--pressure-kpa", "-1"],
                       capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 2 and r.stderr.strip().startswith("bendpam: error:") and "Traceback" not in r.stderr


def test_python_dash_m_entry_point(tmp_path):
    r = subprocess.run([sys.executable, "-m", "bendpam.cli", "predict", "--preset", "be-pam", "--pressure-kpa", "-1"],
                       capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 2 and r.stderr.strip().startswith("bendpam: error:") and "Traceback" not in r.stderr


def test_version(capsys):
    from importlib.metadata import PackageNotFoundError, version

    try:  # the installed distribution's version (an editable install may lag behind __version__)
        expected = version("bendpam")
    except PackageNotFoundError:  # pragma: no cover - running from a source tree
        expected = bendpam.__version__
    code, out, _ = run(capsys, "--version")
    assert code == 0 and out.strip() == f"bendpam {expected}"


def test_internal_error_is_one_line_exit_1(capsys, monkeypatch):
    import bendpam.predict

    def boom(*args, **kwargs):
        raise ZeroDivisionError("deliberate")

    monkeypatch.setattr(bendpam.predict, "prediction_columns", boom)  # what `bendpam predict` calls
    code, out, err = run(capsys, "predict", "--preset", "be-pam", "--pressure-kpa", "100")
    assert code == 1 and out == ""
    assert err.startswith("bendpam: internal error (ZeroDivisionError: deliberate)") and err.count("\n") == 1, err
    assert "Traceback" not in err


def test_demo_default_output(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, "demo")
    assert code == 0, err
    fig = tmp_path / "bendpam-demo" / "moment-curvature.png"
    assert fig.read_bytes()[:4] == b"\x89PNG"
    assert "bendpam-demo/moment-curvature.png" in out


@pytest.mark.parametrize(("signum", "code"), [(2, 130), (15, 143)])
def test_a_signal_during_a_compiled_modules_import_is_an_interrupt(monkeypatch, capsys, signum, code):
    """pybind11 turns an exception inside a module's initialisation into ImportError("initialization failed")
    raised from it: a Ctrl-C (or SIGTERM) there is still an interrupt, one line and its exit status, not a bug."""
    import importlib

    from bendpam.infra.signals import Interrupted

    cli_app = importlib.import_module("bendpam.cli.app")  # the module (bendpam.cli.app the name is the Typer app)

    def run(args):
        try:
            raise Interrupted(code, signum)
        except Interrupted as exc:
            raise ImportError("initialization failed") from exc

    monkeypatch.setattr(cli_app, "_run", run)
    assert cli_app.main(["predict", "--preset", "be-pam", "--pressure-kpa", "100"]) == code
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "interrupted" in err[0] and "internal error" not in err[0]


@pytest.mark.parametrize(("given", "named"), [(["--rate-hz", "-5"], "--rate-hz -5.0"),
                                              (["--speed-mm-min=0"], "--speed-mm-min 0.0"),
                                              (["--hysteresis-angle-deg", "-3"], "--hysteresis-angle-deg -3.0")])
def test_a_simulation_setting_out_of_range_is_named_as_the_option(capsys, tmp_path, given, named):
    """The library's refusal (``rate_hz = -5.0 ...``) in the command line's words, ``=`` form included, exit 2."""
    code, _, err = run(capsys, "simulate-test", "--preset", "be-pam", "--pressure-kpa", "100", *given,
                       "--out", str(tmp_path / "raw"))
    assert code == 2 and err.startswith(f"bendpam: error: {named} is outside the allowed range")
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "raw").exists()


@pytest.mark.parametrize(("option", "value"), [("--despike-sigmas", "2"), ("--reversal-fraction", "0.7")])
def test_a_processing_option_out_of_range_is_named_as_the_option(capsys, tmp_path, option, value):
    """The refusal names the command line's option, not the API's field, and nothing is written."""
    raw = tmp_path / "t_150kPa.csv"
    raw.write_text("time_s,stroke_mm,force_n\n0,0,1\n0.1,0.1,0.9\n", encoding="utf-8")
    code, _, err = run(capsys, "process", str(raw), option, value, "--out", str(tmp_path / "out"))
    assert code == 2 and err.startswith(f"bendpam: error: {option} {float(value)} is outside the allowed")
    assert not (tmp_path / "out").exists()
