import math

import pytest

from bendpam import Actuator, presets
from bendpam.actuator import NEUTRAL_ANGLE_DEG


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
    assert a.t0_start == pytest.approx(10.1 - math.sqrt(102.01 - 36.25))
    # eq 51: the wall area is unchanged
    assert math.pi * (a.R0_start**2 - (a.R0_start - a.t0_start) ** 2) == pytest.approx(a.bladder_area)
    assert a.bladder_area == pytest.approx(math.pi * 36.25)
    assert base().t0_start == pytest.approx(2.5)  # no prestrain by default


def test_internal_units():
    a = base(P_start_kpa=68.0)
    assert a.alpha0 == pytest.approx(math.radians(68.0))
    assert a.C10 == pytest.approx(0.114) and a.C01 == pytest.approx(0.3) and a.P_start == pytest.approx(0.068)
    assert a.frame_stiffness == pytest.approx(6796.0 * 5.0 * 0.125 / 12.0)


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
    ],
)
def test_bad_values_name_parameter_value_and_range(kw, words):
    with pytest.raises(ValueError) as exc:
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
        ("[actuator]\nalpha0 = 70\n", ["unknown actuator parameter", "alpha0"]),
        ("alpha0_deg = = 3\n", ["invalid TOML", "line 1"]),
        (
            "[actuator]\nalpha0_deg=95\nR0_mm=8.5\nt0_mm=2.5\nL0_mm=145\nframe_thickness_mm=0.5\nframe_width_mm=5\n"
            "frame_modulus_mpa=6796\nC10_kpa=100\nC01_kpa=100\n",
            ["alpha0_deg", "95"],
        ),
    ],
)
def test_bad_toml(tmp_path, text, words):
    p = tmp_path / "a.toml"
    p.write_text(text)
    with pytest.raises(ValueError) as exc:
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
