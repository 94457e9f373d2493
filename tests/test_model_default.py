"""The actuator's model is the default (issue 23, items 5-7).

* Every function that takes an Actuator evaluates the model its constants came from
  (``Actuator.model``) unless told otherwise; another model warns once, naming both.
* A fitted actuator remembers its tested pressure range (and the fit's identity) and warns outside it.
* Inverse design reports its assumed deadband and the targets if it moves by +-20 %; margins with
  no demand are inf ("inf" in design.json), never a round-off quotient like 1.5e15.
"""

from __future__ import annotations

import hashlib
import json
import math
import tomllib
import warnings

import numpy as np
import pytest

import bendpam
from bendpam.design import Finger, Gripper, Wrist, solve_finger
from bendpam.design.inverse import design_actuator
from bendpam.errors import ModelMismatchWarning, OutsideTestedRangeWarning
from bendpam.physics import presets
from bendpam.physics.actuator import Actuator, FitIdentity
from bendpam.physics.law import MomentLaw
from bendpam.physics.models import resolve_model

FB = presets.be_pam("force_balance")
EN = presets.be_pam("energy")


def _caught(fn):
    """Run ``fn`` recording every warning: (its result, the list of warnings)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = fn()
    return out, caught


def _of(caught, category):
    return [w for w in caught if issubclass(w.category, category)]


# ---- item 5: the actuator's model is the default --------------------------------------------------
def test_free_curvature_of_a_force_balance_actuator_uses_force_balance():
    """The issue's case: 112 deg with the force-balance model, 86 deg only when the energy model is asked for.

    Hand checks: the angle is k' L0 in degrees; each root zeroes its own model's moment and not the
    other's; and the force-balance value is the one docs/paper-reading.md item 7 quotes for the
    force-balance model with its own constants (23.4 / 65.3 / 112.4 deg at 100 / 150 / 200 kPa).
    """
    fb, caught = _caught(lambda: bendpam.free_curvature(FB, 200.0))
    assert not _of(caught, ModelMismatchWarning)
    assert float(fb.angle_deg) == pytest.approx(112.38, abs=0.01)
    k = float(fb.curvature_per_mm)
    assert math.degrees(k * FB.L0_mm) == pytest.approx(float(fb.angle_deg), rel=1e-12)
    m_fb = float(bendpam.moment(FB, 200.0, k, "force_balance"))
    m_law = float(MomentLaw(FB).moment(200.0, k))  # the law's default is the actuator's model too
    assert abs(m_fb) < 1e-6 and m_law == pytest.approx(m_fb, abs=1e-9)
    angles = bendpam.free_curvature(FB, [100.0, 150.0, 200.0]).angle_deg
    assert np.round(angles, 1).tolist() == [23.4, 65.3, 112.4]
    # the energy model with these constants: 86.2 deg, and a warning naming both models
    en, caught = _caught(lambda: bendpam.free_curvature(FB, 200.0, "energy"))
    assert float(en.angle_deg) == pytest.approx(86.20, abs=0.01)
    (w,) = _of(caught, ModelMismatchWarning)
    text = str(w.message)
    assert "\n" not in text and "force-balance model" in text and "energy model" in text
    k_en = float(en.curvature_per_mm)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelMismatchWarning)
        assert abs(float(bendpam.moment(FB, 200.0, k_en, "energy"))) < 1e-6
        assert abs(float(bendpam.moment(FB, 200.0, k_en, "force_balance"))) > 1.0  # not a root of the other


def test_resolve_model_is_the_one_rule():
    assert resolve_model(FB) == "force_balance" and resolve_model(EN) == "energy"
    assert resolve_model(EN.replace(model="")) == "energy"  # unknown: energy
    assert resolve_model(FB.params) == "energy"  # a block of cases has no model of its own
    chosen, caught = _caught(lambda: resolve_model(EN, "force-balance"))
    assert chosen == "force_balance" and len(_of(caught, ModelMismatchWarning)) == 1
    _, caught = _caught(lambda: resolve_model(EN, chosen))  # a resolved name is passed through silently
    assert not caught
    _, caught = _caught(lambda: resolve_model(EN, "force_balance", warn=False))
    assert not caught


_DEFAULTS = {
    "moment": lambda a, m: float(bendpam.moment(a, 150.0, 0.005, *m)),
    "moment_terms": lambda a, m: float(bendpam.moment_terms(a, 150.0, 0.005, *m)["M_load"]),
    "tangent_stiffness": lambda a, m: float(bendpam.tangent_stiffness(a, 150.0, 0.005, *m)),
    "free_curvature": lambda a, m: float(bendpam.free_curvature(a, 150.0, *m).curvature_per_mm),
    "free_branch": lambda a, m: float(bendpam.free_branch(a, *m).k_end_per_mm),
    "prediction_table": lambda a, m: float(bendpam.prediction_table(a, [150.0], *m)["free_angle_deg"][0]),
    "limits": lambda a, m: float(bendpam.limits(a, [150.0], *m).lockup_margin[0]),
    "MomentLaw.of": lambda a, m: float(MomentLaw.of(a, *m).moment(150.0, 0.005)),
    "MomentLaw": lambda a, m: float(MomentLaw(a, *m).moment(150.0, 0.005)),
    "sweep": lambda a, m: float(bendpam.sweep(a, [150.0], *m, alpha0_deg=[69.7])["free_angle_deg"].values.ravel()[0]),
    "Finger": lambda a, m: float(solve_finger(Finger(a, *m), 150.0).tip_angle_deg),
    "Gripper": lambda a, m: float(Gripper(a, *m).law.moment(150.0, 0.005)),
}


@pytest.mark.parametrize("name", sorted(_DEFAULTS))
def test_every_function_defaults_to_the_actuators_model(name):
    fn = _DEFAULTS[name]
    default, caught = _caught(lambda: fn(FB, ()))
    assert not _of(caught, ModelMismatchWarning)
    explicit, caught = _caught(lambda: fn(FB, ("force_balance",)))
    assert not _of(caught, ModelMismatchWarning)
    other, caught = _caught(lambda: fn(FB, ("energy",)))
    assert default == explicit and other != pytest.approx(default, rel=1e-6)
    assert len(_of(caught, ModelMismatchWarning)) == 1, [str(w.message) for w in caught]  # once per call


def test_design_objects_record_the_resolved_model():
    assert Finger(FB).model == "force_balance" and Gripper(FB).model == "force_balance"
    assert Wrist(presets.bc_pam("force_balance")).model == "force_balance" and Wrist().model == "energy"
    assert Finger(EN).model == "energy"
    w, caught = _caught(lambda: Finger(FB, "energy"))
    assert w.model == "energy" and len(_of(caught, ModelMismatchWarning)) == 1


def test_cli_uses_the_files_model_and_warns_once_for_another(tmp_path, capsys):
    from bendpam.cli import main

    f = tmp_path / "fb.toml"
    FB.to_toml(f)
    assert main(["predict", "--actuator", str(f), "--pressure-kpa", "200", "--json"]) == 0
    out, err = capsys.readouterr()
    obj = json.loads(out)
    assert obj["model"] == "force_balance" and "warning" not in err
    assert obj["results"][0]["free_angle_deg"] == pytest.approx(112.38, abs=0.01)
    assert main(["predict", "--actuator", str(f), "--pressure-kpa", "200", "--model", "energy", "--json"]) == 0
    out, err = capsys.readouterr()
    assert json.loads(out)["results"][0]["free_angle_deg"] == pytest.approx(86.20, abs=0.01)
    assert err.count("bendpam: warning:") == 1 and err.count("\n") == 1
    assert "force-balance model" in err and "energy model" in err


# ---- item 6: a fitted actuator remembers where it was tested -------------------------------------
TESTED = FB.replace(tested_pressure_kpa=(100.0, 200.0),
                    fit_identity={"processed": "be-tests", "date": "2026-11-25T18:30:00Z", "version": "0.4.0"})


def test_tested_range_and_identity_round_trip(tmp_path):
    f = tmp_path / "a.toml"
    TESTED.to_toml(f)
    back = Actuator.from_toml(f)
    assert back == TESTED and hash(back) == hash(TESTED)
    assert back.tested_pressure_kpa == (100.0, 200.0)
    assert back.fit_identity == FitIdentity(processed="be-tests", date="2026-11-25T18:30:00Z", version="0.4.0")
    raw = tomllib.loads(f.read_text(encoding="utf-8"))["actuator"]
    assert raw["tested_pressure_kpa"] == [100.0, 200.0] and raw["fit_identity"]["processed"] == "be-tests"
    assert Actuator.from_dict(TESTED.to_dict()) == TESTED
    json.dumps(TESTED.to_dict())  # plain types
    assert FB.to_dict()["tested_pressure_kpa"] is None and "tested_pressure_kpa" not in FB.to_toml()


@pytest.mark.parametrize("bad", [(200.0, 100.0), (-1.0, 100.0), (100.0,), "100:200", (100.0, math.nan)])
def test_a_bad_tested_range_is_one_line(bad):
    with pytest.raises(bendpam.InputError, match="tested_pressure_kpa") as exc:
        FB.replace(tested_pressure_kpa=bad)
    assert "\n" not in str(exc.value)


def test_a_bad_fit_identity_is_one_line(tmp_path):
    f = tmp_path / "a.toml"
    f.write_text(FB.to_toml() + "\n[actuator.fit_identity]\nprocesed = 'x'\n", encoding="utf-8")
    with pytest.raises(bendpam.InputError, match="processed") as exc:
        Actuator.from_toml(f)
    assert str(f) in str(exc.value)


_RANGE_USES = {
    "moment": lambda a, P: bendpam.moment(a, P, 0.0),
    "blocked_moment": lambda a, P: bendpam.blocked_moment(a, P),
    "free_curvature": lambda a, P: bendpam.free_curvature(a, P),
    "tangent_stiffness": lambda a, P: bendpam.tangent_stiffness(a, P, 0.0),
    "prediction_table": lambda a, P: bendpam.prediction_table(a, [P]),
    "limits": lambda a, P: bendpam.limits(a, [P]),
    "internal_stresses": lambda a, P: bendpam.internal_stresses(a, P, 0.0, n_phi=5),
    "sweep": lambda a, P: bendpam.sweep(a, [P], alpha0_deg=[69.7]),
    "finger": lambda a, P: solve_finger(Finger(a), P),
}


@pytest.mark.parametrize("name", sorted(_RANGE_USES))
def test_outside_the_tested_range_warns_once(name):
    fn = _RANGE_USES[name]
    _, caught = _caught(lambda: fn(TESTED, 150.0))
    assert not _of(caught, OutsideTestedRangeWarning)
    _, caught = _caught(lambda: fn(TESTED, 250.0))
    (w,) = _of(caught, OutsideTestedRangeWarning)
    assert str(w.message).startswith("pressure 250 kPa is outside the tested range [100, 200] kPa")
    _, caught = _caught(lambda: fn(FB, 250.0))  # not a fitted actuator: no range, no warning
    assert not _of(caught, OutsideTestedRangeWarning)


def test_the_warning_points_at_the_users_line():
    _, caught = _caught(lambda: bendpam.blocked_moment(TESTED, 250.0))
    (w,) = _of(caught, OutsideTestedRangeWarning)
    assert w.filename == __file__


def test_fit_writes_its_range_and_identity(tmp_path):
    from pathlib import Path

    from bendpam.identify import fit
    from bendpam.identify.result import ExtrapolationWarning, FitResult
    from bendpam.lab import RawTest, processing, simulate

    assert ExtrapolationWarning is OutsideTestedRangeWarning  # one warning, one implementation
    st = simulate.SimulationSettings(cycles=1, rate_hz=2.0, hysteresis=0.0, seed=1)
    raws = [RawTest(simulate.simulate_test(EN, p, settings=st)[0], Path(f"be_{p:g}kPa.csv"), "csv", pressure_kpa=p)
            for p in (100.0, 200.0)]
    processed = processing.process_tests(raws, keep_series=False,
                                         options=processing.ProcessingOptions(grid_points=21))
    res = fit(processed, EN, hysteresis=None, profile_points=0)
    assert res.actuator.tested_pressure_kpa == (100.0, 200.0) and res.actuator.model == "energy"
    assert res.actuator.fit_identity.version == bendpam.__version__
    res.save(tmp_path, processed="be-tests", extra={"note": "extra entries are hashed too"})
    fj = (tmp_path / "fit.json").read_bytes()
    assert json.loads(fj)["note"] == "extra entries are hashed too"
    act = Actuator.from_toml(tmp_path / "fitted_actuator.toml")
    assert act.tested_pressure_kpa == (100.0, 200.0)
    assert act.fit_identity.fit_json_sha256 == hashlib.sha256(fj).hexdigest()
    assert act.fit_identity.processed == "be-tests" and act.fit_identity.date.endswith("Z")
    # FitResult.predict and the actuator warn alike (one implementation); a loaded fit still knows its range
    back = FitResult.load(tmp_path)
    _, caught = _caught(lambda: back.predict(250.0, 0.0))
    assert len(_of(caught, OutsideTestedRangeWarning)) == 1
    _, caught = _caught(lambda: bendpam.blocked_moment(act, 250.0))
    assert len(_of(caught, OutsideTestedRangeWarning)) == 1


def test_cli_warns_outside_the_tested_range(tmp_path, capsys):
    from bendpam.cli import main

    f = tmp_path / "fitted.toml"
    TESTED.to_toml(f)
    runs = {
        "predict": ["predict", "--actuator", str(f), "--pressure-kpa", "150", "250"],
        "curve": ["curve", "--actuator", str(f), "--pressure-kpa", "250", "--points", "5",
                  "--out", str(tmp_path / "c.csv")],
        "sweep": ["sweep", "--actuator", str(f), "--pressure-kpa", "250", "--param", "alpha0_deg=69.7",
                  "--out", str(tmp_path / "s.nc")],
        "finger": ["finger", "--actuator", str(f), "--pressure-kpa", "250"],
        "design": ["design", "--actuator", str(f), "--target", "blocked_moment_nmm=400@250", "--vary",
                   "alpha0_deg=60:80", "--n-coarse", "16", "--starts", "1", "--no-pareto", "--quiet",
                   "--out", str(tmp_path / "d")],
    }
    for name, args in runs.items():
        code = main(args)
        out, err = capsys.readouterr()
        assert code == 0, (name, err)
        lines = [ln for ln in err.splitlines() if "tested range" in ln]
        assert len(lines) == 1, (name, err)
        assert lines[0].startswith("bendpam: warning: pressure 250 kPa is outside the tested range [100, 200] kPa")
    assert main(["predict", "--actuator", str(f), "--pressure-kpa", "150"]) == 0
    assert "tested range" not in capsys.readouterr().err


# ---- item 7: the deadband and infinite margins in design -----------------------------------------
@pytest.fixture(scope="module")
def design():
    return design_actuator(EN, ["blocked_moment_nmm=400@200"], ["alpha0_deg=60:80"], n_coarse=16, n_starts=1)


def test_design_reports_the_assumed_deadband(design):
    """A blocked moment is linear in P - P_start: moving P_start by -+20 % scales it by (200 - f 68) / 132."""
    db = design.deadband
    assert db["assumed"] is True and db["P_start_kpa"] == 68.0
    rows = {r["factor"]: r for r in db["moved"]}
    assert set(rows) == {0.8, 1.2}
    assert rows[0.8]["achieved"][0] == pytest.approx(400.0 * (200.0 - 54.4) / 132.0, rel=1e-3)  # 441.2
    assert rows[1.2]["achieved"][0] == pytest.approx(400.0 * (200.0 - 81.6) / 132.0, rel=1e-3)  # 358.8
    assert rows[0.8]["met"] == [False] and rows[1.2]["relative_error"][0] == pytest.approx(-0.1030, abs=1e-3)
    text = str(design)
    assert "deadband P_start = 68 kPa assumed" in text and "x1.2 (81.6 kPa)" in text and "358.79" in text
    obj = json.loads(design.to_json())
    assert obj["deadband"]["moved"][1]["P_start_kpa"] == pytest.approx(81.6)


def test_design_model_is_the_base_actuators():
    res, caught = _caught(lambda: design_actuator(FB, ["blocked_moment_nmm=400@200"], ["alpha0_deg=60:80"],
                                                  n_coarse=16, n_starts=1))
    assert res.model == "force_balance" and not _of(caught, ModelMismatchWarning)
    assert res.actuator.model == "force_balance"


def test_margins_with_no_demand_are_inf_not_round_off():
    """The issue's design (t0 = 3.22 mm, R0 = 9.25 mm): below P_start the frame force is round-off
    (-3.9e-14 N), which used to give a buckling margin of 1.5e15."""
    a = EN.replace(t0_mm=3.2232873835577838, R0_mm=9.250488816838152, R0_start_mm=9.250488816838152 * 10.1 / 8.5)
    lim = bendpam.limits(a, [0.0, 62.5, 68.0])
    assert np.all(np.abs(lim.frame_axial_force_n) < 1e-9)
    assert lim.buckling_margin.tolist() == [math.inf] * 3
    assert np.all(np.isinf(lim.min_margin))


def test_design_json_writes_inf_with_a_note(design):
    obj = json.loads(design.to_json())
    for name, value in design.margins.items():
        if value == math.inf:
            assert obj["margins"][name] == "inf"
            assert obj["margin_notes"][name] in ("no demand", "no limit given")
        else:
            assert obj["margins"][name] == pytest.approx(value)
    assert obj["margin_notes"]["frame_strength_margin"] == "no limit given"  # the preset gives no strength
    assert all(isinstance(v, float | str) or v is None for row in obj["margins_by_pressure"] for v in row.values())
    assert "1e+15" not in design.to_json() and "e+15" not in str(design)
