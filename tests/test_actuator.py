import math

import pytest

from bendpam import Actuator, ModelParams, presets
from bendpam.errors import InputError
from bendpam.physics.actuator import NEUTRAL_ANGLE_DEG


def base(**kw):
    d = dict(alpha0_deg=68.0, R0_mm=8.5, t0_mm=2.5, L0_mm=145.0, frame_thickness_mm=0.5, frame_width_mm=5.0,
             frame_modulus_mpa=6796.0, C10_kpa=114.0, C01_kpa=300.0)
    d.update(kw)
    return Actuator(**d)


def test_presets_table1_and_table3():
    a = presets.be_pam("energy")
    assert (a.alpha0_deg, a.C10_kpa, a.C01_kpa) == (69.7, -318.9, 515.5)
    assert (a.R0_mm, a.t0_mm, a.L0_mm, a.R0_start_mm, a.P_start_kpa) == (8.5, 2.5, 145.0, 10.1, 68.0)
    b = presets.bc_pam("force-balance")
    assert (b.alpha0_deg, b.C10_kpa, b.C01_kpa, b.P_start_kpa, b.R0_start_mm) == (36.60, 1499.9, -1169.9, 32.0, 8.6)
    assert presets.be_pam("force_balance").C10_kpa == -133.7
    assert presets.bc_pam().C01_kpa == -1196.8
    assert a.kind == "BE-PAM" and b.kind == "BC-PAM"
    assert a.bend_sign == 1 and b.bend_sign == -1


def test_eq52_prestrain_by_hand():
    a = presets.be_pam()
    # area pi (8.5^2 - 6^2) = pi 36.25; t0s = 10.1 - sqrt(10.1^2 - 36.25)
    assert a.t0_start_mm == pytest.approx(10.1 - math.sqrt(102.01 - 36.25))
    # eq 51: the wall area is unchanged
    assert math.pi * (a.R0_start_mm**2 - (a.R0_start_mm - a.t0_start_mm) ** 2) == pytest.approx(a.bladder_area_mm2)
    assert a.bladder_area_mm2 == pytest.approx(math.pi * 36.25)
    assert base().t0_start_mm == pytest.approx(2.5)  # no prestrain by default
    # the numerics' view carries the same derived values (mm)
    assert a.params.t0_start == pytest.approx(a.t0_start_mm)
    assert a.params.bladder_area == pytest.approx(a.bladder_area_mm2)
    assert a.params.R0_start == a.R0_start_mm


def test_internal_units():
    """``actuator.params`` is the numerics' view in mm / MPa / rad; the actuator itself has unit-named fields."""
    a = base(P_start_kpa=68.0)
    p = a.params
    assert isinstance(p, ModelParams) and p.shape == ()
    assert p.alpha0 == pytest.approx(math.radians(68.0))
    assert p.C10 == pytest.approx(0.114) and p.C01 == pytest.approx(0.3) and p.P_start == pytest.approx(0.068)
    assert p.frame_stiffness == pytest.approx(6796.0 * 5.0 * 0.125 / 12.0)
    assert a.frame_stiffness_nmm2 == pytest.approx(6796.0 * 5.0 * 0.125 / 12.0)
    assert a.frame_inertia_mm4 == pytest.approx(5.0 * 0.125 / 12.0)
    # the internal-unit properties are gone from the Actuator (issue 10)
    for gone in ("alpha0", "C10", "C01", "P_start", "R0", "t0", "L0", "R0_start", "t0_start", "bladder_area",
                 "frame_inertia", "frame_stiffness"):
        assert not hasattr(a, gone), gone


@pytest.mark.parametrize(
    "kw,words",
    [
        (dict(alpha0_deg=90.0), ["alpha0_deg", "90", "(0, 90)"]),
        (dict(alpha0_deg=0.0), ["alpha0_deg", "(0, 90)"]),
        (dict(alpha0_deg=-5.0), ["alpha0_deg", "-5"]),
        (dict(t0_mm=8.5), ["t0_mm", "8.5"]),
        (dict(t0_mm=9.0), ["t0_mm"]),
        (dict(R0_mm=-1.0), ["R0_mm"]),
        (dict(frame_modulus_mpa=-10.0), ["frame_modulus_mpa", "-10"]),
        (dict(frame_thickness_mm=0.0), ["frame_thickness_mm"]),
        (dict(L0_mm=float("nan")), ["L0_mm", "not finite"]),
        (dict(C10_kpa=-300.0, C01_kpa=100.0), ["C10_kpa + C01_kpa", "> 0"]),
        (dict(P_start_kpa=-1.0), ["P_start_kpa", "[0, inf)"]),
        (dict(R0_start_mm=8.0), ["R0_start_mm", "8.5"]),
        (dict(alpha0_deg="abc"), ["alpha0_deg", "not a number"]),
        (dict(alpha0_deg="70"), ["alpha0_deg", "not a number"]),  # a string is not a number
        (dict(alpha0_deg=True), ["alpha0_deg", "not a number"]),  # nor is a bool
    ],
)
def test_bad_values_name_parameter_value_and_range(kw, words):
    with pytest.raises(InputError) as exc:
        base(**kw)
    msg = str(exc.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg


def test_immutable_and_replace():
    a = base()
    import dataclasses

    with pytest.raises(dataclasses.FrozenInstanceError):
        a.alpha0_deg = 70.0
    b = a.replace(alpha0_deg=70.0)
    assert b.alpha0_deg == 70.0 and a.alpha0_deg == 68.0
    with pytest.raises(ValueError, match="unknown actuator parameter"):
        a.replace(alpha=1)
    with pytest.raises(ValueError, match="alpha0_deg"):
        a.replace(alpha0_deg=95)
    assert hash(a) == hash(base())


def test_neutral_angle():
    assert NEUTRAL_ANGLE_DEG == pytest.approx(54.7356103, abs=1e-6)
    assert base(alpha0_deg=NEUTRAL_ANGLE_DEG).kind == "neutral"


def test_toml_round_trip(tmp_path):
    a = presets.bc_pam("force_balance")
    p = tmp_path / "bc.toml"
    a.to_toml(p)
    b = Actuator.from_toml(p)
    assert b == a
    assert "alpha0_deg = 36.6" in p.read_text()
    assert not list(tmp_path.glob(".*"))  # no temporary file left behind


@pytest.mark.parametrize(
    "text,words",
    [
        ("[actuator]\nalpha0_deg = 70\n", ["missing actuator parameter"]),
        ("[actuator]\nalpha0 = 70\n", ["unknown actuator parameter", "alpha0", "did you mean 'alpha0_deg'"]),
        ("alpha0_deg = = 3\n", ["invalid TOML", "line 1"]),
        (
            "[actuator]\nalpha0_deg=95\nR0_mm=8.5\nt0_mm=2.5\nL0_mm=145\nframe_thickness_mm=0.5\nframe_width_mm=5\n"
            "frame_modulus_mpa=6796\nC10_kpa=100\nC01_kpa=100\n",
            ["alpha0_deg", "95"],
        ),
        (
            "[actuator]\nalpha0_deg=true\nR0_mm=8.5\nt0_mm=2.5\nL0_mm=145\nframe_thickness_mm=0.5\nframe_width_mm=5\n"
            "frame_modulus_mpa=6796\nC10_kpa=100\nC01_kpa=100\n",
            ["alpha0_deg", "True", "not a number"],
        ),
    ],
)
def test_bad_toml(tmp_path, text, words):
    p = tmp_path / "a.toml"
    p.write_text(text)
    with pytest.raises(InputError) as exc:
        Actuator.from_toml(p)
    msg = str(exc.value)
    assert str(p) in msg and "\n" not in msg
    for w in words:
        assert w in msg


def test_missing_toml(tmp_path):
    with pytest.raises(ValueError, match="not found"):
        Actuator.from_toml(tmp_path / "nope.toml")


def test_unknown_preset_and_model():
    with pytest.raises(ValueError, match="unknown preset"):
        presets.get("xx-pam")
    with pytest.raises(ValueError, match="model"):
        presets.be_pam("fem")


def test_outputs_have_ordinary_permissions(tmp_path):
    import os
    import stat

    p = tmp_path / "a.toml"
    presets.be_pam().to_toml(p)
    umask = os.umask(0)
    os.umask(umask)
    assert stat.S_IMODE(p.stat().st_mode) == 0o666 & ~umask


def test_actuator_files_know_their_model(tmp_path, capsys):
    from bendpam.cli import main

    assert presets.be_pam("force_balance").model == "force_balance"
    f = tmp_path / "be.toml"
    assert main(["actuator", "--preset", "be-pam", "--model", "force-balance", "--out", str(f)]) == 0
    a = Actuator.from_toml(f)
    assert a.model == "force_balance" and a.C10_kpa == presets.be_pam("force_balance").C10_kpa
    capsys.readouterr()
    assert main(["predict", "--actuator", str(f), "--model", "force-balance", "--pressure-kpa", "150"]) == 0
    assert "warning" not in capsys.readouterr().err
    assert main(["predict", "--actuator", str(f), "--model", "energy", "--pressure-kpa", "150"]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "force-balance model" in err and "warning" in err
    with pytest.raises(InputError, match="model"):
        a.replace(model="elastic")


def test_unknown_toml_table_is_named(tmp_path):
    f = tmp_path / "a.toml"
    f.write_text(presets.be_pam().to_toml() + "\n[bogus]\nx = 1\n")
    with pytest.raises(InputError, match="bogus"):
        Actuator.from_toml(f)
    f.write_text(presets.be_pam().to_toml() + "\n[hysteresis]\na0_nmm = 1.0\n")
    assert Actuator.from_toml(f) == presets.be_pam()
