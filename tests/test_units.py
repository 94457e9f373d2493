"""The unit rule (issue 10): pressure in kPa at every public edge, one test per surface.

The same quantities -- the BE-PAM's blocked moment and free-bending angle at 150 kPa and the
BC-PAM's fold pressure (energy model) -- are read from the API, the CLI's text and JSON, the TOML
that ``bendpam actuator --out`` writes and the NetCDF files of ``bendpam sweep`` and ``bendpam
stresses``; they must agree.  A pressure given in MPa warns in the API and is refused by the CLI.
The hysteresis amplitude is ``a1_nmm_per_kpa`` everywhere (LoopModel, fit.json, the fitted TOML,
``predict --cycle``).
"""

import json
import math
import tomllib

import numpy as np
import pytest
import xarray as xr
from numpy.testing import assert_allclose

import bendpam
from bendpam import Actuator, presets
from bendpam.cli import main
from bendpam.physics.hysteresis import LoopModel, predict_cycle
from bendpam.validate import UnitWarning

P_KPA = 150.0


def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def api():
    """The reference values from the library (kPa in, N*mm, deg and kPa out)."""
    be, bc = presets.be_pam("energy"), presets.bc_pam("energy")
    fb = bendpam.free_curvature(be, P_KPA)
    return {
        "blocked_nmm": float(bendpam.blocked_moment(be, P_KPA)),
        "angle_deg": float(fb.angle_deg),
        "curvature_per_mm": float(fb.curvature_per_mm),
        "fold_kpa": bendpam.free_branch(bc, "energy").max_pressure_kpa,
    }


# ------------------------------------------------------------------------------------------------
# the API
# ------------------------------------------------------------------------------------------------
def test_api_values_in_kpa(api):
    be = presets.be_pam("energy")
    # the closed form with the active pressure converted to MPa (N/mm^2): N*mm
    cot2 = 1 / math.tan(math.radians(be.alpha0_deg)) ** 2
    assert api["blocked_nmm"] == pytest.approx(
        math.pi * be.R0_start_mm**3 * (1 - 2 * cot2) * (P_KPA - be.P_start_kpa) * 1e-3, rel=1e-12)
    assert api["angle_deg"] == pytest.approx(math.degrees(api["curvature_per_mm"] * be.L0_mm), rel=1e-12)
    assert 133.5 < api["fold_kpa"] < 135.0
    df = bendpam.prediction_table(be, [P_KPA])
    assert df.pressure_kpa.iloc[0] == P_KPA
    assert df.blocked_moment_nmm.iloc[0] == api["blocked_nmm"] and df.free_angle_deg.iloc[0] == api["angle_deg"]
    law = bendpam.MomentLaw.of(be, "energy")
    assert float(law.blocked_moment(P_KPA)) == api["blocked_nmm"]
    assert float(law.free_curvature(P_KPA).angle_deg) == api["angle_deg"]
    assert law.P_start_kpa == pytest.approx(be.P_start_kpa, rel=1e-15)


# ------------------------------------------------------------------------------------------------
# the CLI: text and JSON
# ------------------------------------------------------------------------------------------------
def test_cli_text_agrees(capsys, api):
    code, out, err = run(capsys, "predict", "--preset", "be-pam", "--pressure-kpa", P_KPA)
    assert code == 0, err
    assert "P (kPa)" in out and "N·mm" in out
    row = next(line.split() for line in out.splitlines() if line.split()[:1] == [f"{P_KPA:g}"])
    assert float(row[1]) == pytest.approx(api["blocked_nmm"], abs=0.005)  # printed with 2 decimals
    assert float(row[2]) == pytest.approx(api["curvature_per_mm"], abs=5e-6)  # 5 decimals
    assert float(row[3]) == pytest.approx(api["angle_deg"], abs=0.005)
    code, out, err = run(capsys, "predict", "--preset", "bc-pam", "--pressure-kpa", "100")
    assert code == 0, err
    line = next(line for line in out.splitlines() if line.startswith("highest pressure"))
    assert line.endswith("kPa (fold)")
    assert float(line.split(":")[1].split()[0]) == pytest.approx(api["fold_kpa"], abs=0.05)  # .4g


def test_cli_json_agrees(capsys, api):
    code, out, err = run(capsys, "predict", "--preset", "be-pam", "--pressure-kpa", P_KPA, "--json")
    assert code == 0, err
    obj = json.loads(out)
    assert obj["units"]["pressure_kpa"] == "kPa"
    r = obj["results"][0]
    assert r["pressure_kpa"] == P_KPA
    assert r["blocked_moment_nmm"] == pytest.approx(api["blocked_nmm"], rel=1e-15)
    assert r["free_angle_deg"] == pytest.approx(api["angle_deg"], rel=1e-15)
    assert r["free_curvature_per_mm"] == pytest.approx(api["curvature_per_mm"], rel=1e-15)
    assert obj["actuator"]["P_start_kpa"] == 68.0
    code, out, err = run(capsys, "predict", "--preset", "bc-pam", "--pressure-kpa", "100", "--json")
    assert code == 0, err
    obj = json.loads(out)
    assert obj["max_equilibrium_pressure_kpa"] == pytest.approx(api["fold_kpa"], rel=1e-15)
    assert obj["branch_end"] == "fold"


# ------------------------------------------------------------------------------------------------
# the TOML of `bendpam actuator --out`
# ------------------------------------------------------------------------------------------------
def test_actuator_toml_round_trip_in_kpa(capsys, tmp_path, api):
    f = tmp_path / "be.toml"
    code, _, err = run(capsys, "actuator", "--preset", "be-pam", "--out", f)
    assert code == 0, err
    table = tomllib.loads(f.read_text(encoding="utf-8"))["actuator"]
    assert table["P_start_kpa"] == 68.0 and table["C10_kpa"] == -318.9
    assert not {"P_start", "P_start_mpa", "C10", "C10_mpa"} & set(table)  # no pressure in another unit
    assert Actuator.from_toml(f) == presets.be_pam("energy")
    # a changed threshold goes through the TOML and the CLI unchanged
    act = presets.be_pam("energy").replace(P_start_kpa=55.0)
    g, h = tmp_path / "p55.toml", tmp_path / "p55-copy.toml"
    act.to_toml(g)
    code, _, err = run(capsys, "actuator", "--actuator", g, "--out", h)
    assert code == 0, err
    assert tomllib.loads(h.read_text(encoding="utf-8"))["actuator"]["P_start_kpa"] == 55.0
    code, out, err = run(capsys, "predict", "--actuator", h, "--pressure-kpa", P_KPA, "--json")
    assert code == 0, err
    obj = json.loads(out)
    assert obj["actuator"]["P_start_kpa"] == 55.0
    assert obj["results"][0]["blocked_moment_nmm"] == pytest.approx(float(bendpam.blocked_moment(act, P_KPA)),
                                                                    rel=1e-15)
    # 150 - 55 = 95 kPa active instead of 82: the blocked moment scales with the active pressure
    assert obj["results"][0]["blocked_moment_nmm"] == pytest.approx(api["blocked_nmm"] * 95.0 / 82.0, rel=1e-12)


# ------------------------------------------------------------------------------------------------
# NetCDF: sweep and stresses
# ------------------------------------------------------------------------------------------------
def test_sweep_netcdf_agrees(capsys, tmp_path, api):
    f = tmp_path / "be.nc"
    code, _, err = run(capsys, "sweep", "--preset", "be-pam", "--param", "alpha0_deg=69.7", "--pressure-kpa",
                       P_KPA, "--out", f)
    assert code == 0, err
    with xr.open_dataset(f) as ds:
        assert ds["pressure_kpa"].attrs["units"] == "kPa" and ds["pressure_kpa"].values.tolist() == [P_KPA]
        assert ds["max_pressure_kpa"].attrs["units"] == "kPa"
        assert ds["blocked_moment_nmm"].attrs["units"] == "N*mm" and ds["free_angle_deg"].attrs["units"] == "deg"
        assert float(ds["blocked_moment_nmm"][0, 0]) == pytest.approx(api["blocked_nmm"], rel=1e-12)
        assert float(ds["free_angle_deg"][0, 0]) == pytest.approx(api["angle_deg"], rel=1e-10)
        assert Actuator.from_dict(tomllib.loads(ds.attrs["base_actuator"])["actuator"]).P_start_kpa == 68.0
    g = tmp_path / "bc.nc"
    code, _, err = run(capsys, "sweep", "--preset", "bc-pam", "--param", "alpha0_deg=36.57", "--pressure-kpa",
                       "100", "--out", g)
    assert code == 0, err
    with xr.open_dataset(g) as ds:
        assert float(ds["max_pressure_kpa"][0]) == pytest.approx(api["fold_kpa"], rel=1e-9)
        assert int(ds["branch_end"][0]) == 1  # fold


def test_swept_pressure_coordinates_are_labelled_kpa():
    ds = bendpam.sweep(presets.be_pam(), [P_KPA], P_start_kpa=[60.0, 70.0], C10_kpa=[-300.0, -318.9],
                       frame_modulus_mpa=[6796.0])
    assert ds["pressure_kpa"].attrs["units"] == "kPa"
    assert ds["P_start_kpa"].attrs["units"] == "kPa"
    assert ds["C10_kpa"].attrs["units"] == "kPa"
    assert ds["frame_modulus_mpa"].attrs["units"] == "MPa"  # a modulus, not a pressure: MPa as named


def test_stresses_netcdf_in_kpa(capsys, tmp_path):
    f = tmp_path / "s.nc"
    k = 0.005
    code, _, err = run(capsys, "stresses", "--preset", "be-pam", "--pressure-kpa", P_KPA, "--curvature", k,
                       "--out", f)
    assert code == 0, err
    ref = bendpam.internal_stresses(presets.be_pam("force_balance"), P_KPA, k)  # stresses use force balance
    with xr.open_dataset(f) as ds:
        assert ds.attrs["pressure_kpa"] == P_KPA and ds.attrs["P_start_kpa"] == 68.0
        for name in ("sigma_bl1_kpa", "sigma_bl2_kpa", "sigma_bl3_kpa", "P_e_kpa", "sigma_br1_kpa", "sigma_br2_kpa"):
            assert ds[name].attrs["units"] == "kPa", name
            assert_allclose(ds[name].values, ref[name].values, rtol=1e-12)
        for name in ("N_br1_n_per_mm", "N_br2_n_per_mm"):
            assert ds[name].attrs["units"] == "N/mm", name
        # every variable's name says its unit (the one unit rule)
        assert all(n.endswith(("_kpa", "_n_per_mm", "_mm", "_deg")) for n in ds.data_vars), list(ds.data_vars)
        # straight-state check of the unit: sigma_bl3 is -P_active, in kPa
        assert float(ds["sigma_bl3_kpa"]) == pytest.approx(-(P_KPA - 68.0), rel=1e-12)


def test_stresses_pressure_coordinate_is_kpa():
    ds = bendpam.internal_stresses(presets.be_pam("force_balance"), np.array([100.0, P_KPA]), 0.0, n_phi=9)
    assert ds["pressure_kpa"].attrs["units"] == "kPa" and ds["pressure_kpa"].values.tolist() == [100.0, P_KPA]
    assert ds["P_e_kpa"].attrs["units"] == "kPa"
    assert_allclose(ds["P_e_kpa"].values, [100.0 - 68.0, P_KPA - 68.0], rtol=1e-12)  # straight: P_e = P_active


# ------------------------------------------------------------------------------------------------
# a pressure in MPa: a warning in the API, a refusal in the CLI
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("call", [
    lambda a: bendpam.blocked_moment(a, 0.15),
    lambda a: bendpam.moment(a, 0.15, 0.005),
    lambda a: bendpam.free_curvature(a, [0.1, 0.15]),
    lambda a: bendpam.tangent_stiffness(a, 0.15, 0.005),
    lambda a: bendpam.moment_terms(a, 0.15, 0.005),
    lambda a: bendpam.internal_stresses(a, 0.15, 0.0),
    lambda a: bendpam.prediction_table(a, [0.15]),
    lambda a: bendpam.active_pressure_kpa(a, 0.15),
    lambda a: bendpam.MomentLaw.of(a).tabulated().moment(0.15, 0.0),
    lambda a: bendpam.sweep(a, [0.15], alpha0_deg=[69.7]),
    lambda a: LoopModel(a0_nmm=1.0, a1_nmm_per_kpa=0.1).amplitude_nmm(a, 0.15),
], ids=["blocked_moment", "moment", "free_curvature", "tangent_stiffness", "moment_terms", "internal_stresses",
        "prediction_table", "active_pressure_kpa", "MomentTable.moment", "sweep", "LoopModel.amplitude_nmm"])
def test_api_warns_for_mpa(call):
    with pytest.warns(UnitWarning, match="kPa"):
        call(presets.be_pam())


def test_api_does_not_warn_for_kpa_or_zero():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", UnitWarning)
        bendpam.blocked_moment(presets.be_pam(), [0.0, P_KPA])
        bendpam.blocked_moment(presets.be_pam(), 0.0)  # zero alone is not a unit mistake
        bendpam.free_curvature(presets.be_pam(), [5.0, 100.0])


@pytest.mark.parametrize("args", [
    ["predict", "--preset", "be-pam", "--pressure-kpa", "0.15"],
    ["predict", "--preset", "be-pam", "--pressure-kpa", "0.1", "0.15", "0.2"],
    ["curve", "--preset", "be-pam", "--pressure-kpa", "0.15", "--out", "c.csv"],
    ["simulate-test", "--preset", "be-pam", "--pressure-kpa", "0.15", "--out", "raw"],
    pytest.param(["stresses", "--preset", "be-pam", "--pressure-kpa", "0.15", "--out", "s.nc"], id="stresses"),
    pytest.param(["sweep", "--preset", "be-pam", "--pressure-kpa", "0.15", "--out", "w.nc"], id="sweep"),
], ids=lambda a: a[0] if isinstance(a, list) else None)
@pytest.mark.filterwarnings("ignore::bendpam.validate.UnitWarning")  # printed by the commands that do not refuse
def test_cli_refuses_mpa(capsys, tmp_path, monkeypatch, args):
    monkeypatch.chdir(tmp_path)
    i = args.index("--pressure-kpa") + 1
    largest = max(float(t) for t in args[i:] if not t.startswith("--") and t.replace(".", "").isdigit())
    code, out, err = run(capsys, *args)
    assert code == 2, (out, err)
    assert err.startswith("bendpam: error:") and err.count("\n") == 1, err
    assert "kPa" in err and f"{largest:g}" in err  # names the unit and the largest value given
    assert "Traceback" not in err
    assert not list(tmp_path.iterdir())  # nothing written


# ------------------------------------------------------------------------------------------------
# the hysteresis amplitude: a1_nmm_per_kpa everywhere
# ------------------------------------------------------------------------------------------------
def test_loop_amplitude_is_per_kpa_everywhere(capsys, tmp_path):
    assert "a1_nmm_per_kpa" in LoopModel.__dataclass_fields__
    assert "a1_nmm_per_mpa" not in LoopModel.__dataclass_fields__
    be = presets.be_pam()
    # by hand: A = a0 + a1 (P - P_start) with a1 in N*mm per kPa
    assert float(LoopModel(a0_nmm=2.0, a1_nmm_per_kpa=0.05).amplitude_nmm(be, P_KPA)) == pytest.approx(
        2.0 + 0.05 * (P_KPA - 68.0), rel=1e-15)

    raw, proc, fitd = tmp_path / "raw", tmp_path / "p", tmp_path / "f"
    code, _, err = run(capsys, "simulate-test", "--preset", "be-pam", "--pressure-kpa", "100", "150", "200",
                       "--out", raw, "--seed", "4", "--hysteresis", "0.05", "--hysteresis-offset-nmm", "2",
                       "--hysteresis-angle-deg", "10", "--hysteresis-law", "pi")
    assert code == 0, err
    truth = json.loads((raw / "truth.json").read_text())
    loop_true = truth["pressures"][0]["loop"]
    assert set(loop_true) >= {"a0_nmm", "a1_nmm_per_kpa", "theta_h_deg"} and "a1_nmm_per_mpa" not in loop_true
    a1_true = loop_true["a1_nmm_per_kpa"]
    code, _, err = run(capsys, "process", raw, "--out", proc, "--no-figure")
    assert code == 0, err
    code, out, err = run(capsys, "fit", proc, "--preset", "be-pam", "--hysteresis", "--out", fitd, "--json")
    assert code == 0, err
    # fit.json: the parameter and its unit
    fj = json.loads((fitd / "fit.json").read_text())
    par = fj["hysteresis"]["parameters"]
    assert set(par) == {"a0_nmm", "a1_nmm_per_kpa", "theta_h_deg"}
    assert par["a1_nmm_per_kpa"]["unit"] == "N*mm/kPa"
    a1 = par["a1_nmm_per_kpa"]["value"]
    assert 0 < a1 < 5  # N*mm per kPa: a few tenths for this loop (it would be hundreds per MPa)
    assert a1 == pytest.approx(a1_true, rel=0.5)  # the simulator's loop, recovered (same unit)
    assert json.loads(out)["hysteresis"]["parameters"]["a1_nmm_per_kpa"]["value"] == a1
    # the fitted TOML: the same loop
    toml = fitd / "fitted_actuator.toml"
    hyst = tomllib.loads(toml.read_text(encoding="utf-8"))["hysteresis"]
    assert hyst["a1_nmm_per_kpa"] == a1 and "a1_nmm_per_mpa" not in hyst
    loop = LoopModel.from_toml(toml)
    assert loop.a1_nmm_per_kpa == a1
    act = Actuator.from_toml(toml)
    # predict --cycle with the TOML's loop = the API's predict_cycle
    code, out, err = run(capsys, "predict", "--actuator", toml, "--pressure-kpa", P_KPA, "--cycle", "--json")
    assert code == 0, err
    obj = json.loads(out)
    assert obj["hysteresis"]["a1_nmm_per_kpa"] == a1
    ref = predict_cycle(act, loop, P_KPA)
    assert obj["results"][0]["cycle"]["energy_loss_ratio"] == pytest.approx(ref.energy_loss_ratio, rel=1e-12)
    # --loop-a1-nmm-per-kpa overrides the TOML's value, in N*mm/kPa
    code, out, err = run(capsys, "predict", "--actuator", toml, "--pressure-kpa", P_KPA, "--cycle",
                         "--loop-a1-nmm-per-kpa", 2 * a1, "--json")
    assert code == 0, err
    obj2 = json.loads(out)
    assert obj2["hysteresis"]["a1_nmm_per_kpa"] == 2 * a1
    ref2 = predict_cycle(act, LoopModel(law=loop.law, a0_nmm=loop.a0_nmm, a1_nmm_per_kpa=2 * a1,
                                        theta_h_deg=loop.theta_h_deg, amplitude=loop.amplitude), P_KPA)
    assert obj2["results"][0]["cycle"]["energy_loss_ratio"] == pytest.approx(ref2.energy_loss_ratio, rel=1e-12)
    assert ref2.energy_loss_ratio > ref.energy_loss_ratio
    # and the text output names the unit
    code, out, err = run(capsys, "predict", "--actuator", toml, "--pressure-kpa", P_KPA, "--cycle")
    assert code == 0, err
    assert f"a1 = {a1:g} N·mm/kPa" in out
