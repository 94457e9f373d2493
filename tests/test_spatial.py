"""Out-of-plane and torsional stiffness of a bending PAM (issue 26 item 1): bendpam.physics.spatial."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bendpam.errors import InputError
from bendpam.physics.law import MomentLaw
from bendpam.physics.presets import bc_pam, be_pam
from bendpam.physics.spatial import (
    SpatialTable,
    frame_strong_axis_inertia_mm4,
    frame_torsion_constant_mm4,
    lateral_stiffness_nmm2,
    section_energy_n,
    spatial_stiffness,
    torsion_lock_torque_nmm,
    torsional_stiffness_nmm2_per_rad,
)

ACTUATORS = {"be": be_pam(), "bc": bc_pam()}


def _beam_theory(a):
    """Frame strip + bladder tube at rest, by hand (docs/out-of-plane.md): N*mm^2 and N*mm^2/rad."""
    E, t, w = a.frame_modulus_mpa, a.frame_thickness_mm, a.frame_width_mm
    mu = 2.0 * (a.C10_kpa + a.C01_kpa) * 1e-3  # MPa
    A, R = a.bladder_area_mm2, a.R0_start_mm
    cot2 = 1.0 / math.tan(math.radians(a.alpha0_deg)) ** 2
    ei = E * t * w ** 3 / 12.0 + 0.5 * (4.0 * mu) * A * R ** 2  # plane-strain modulus 4 mu, wall at radius R
    gj = E / 2.6 * w * t ** 3 / 3.0 * (1.0 - 0.63 * t / w) + mu * A * R ** 2 * (1.5 + 4.0 * cot2)
    return ei, gj


@pytest.mark.parametrize("name", ["be", "bc"])
def test_zero_pressure_is_beam_theory_of_frame_and_tube(name):
    a = ACTUATORS[name]
    ei, gj = _beam_theory(a)
    for P in (0.0, a.P_start_kpa):  # no active pressure up to P_start
        s = spatial_stiffness(a, P, 0.0)
        assert float(s.lateral_stiffness_nmm2) == pytest.approx(ei, rel=1e-9)
        assert float(s.torsional_stiffness_nmm2_per_rad) == pytest.approx(gj, rel=1e-9)
        assert abs(float(s.torsion_lock_torque_nmm)) < 1e-9
    assert frame_strong_axis_inertia_mm4(5.0, 0.5) == pytest.approx(0.5 * 125.0 / 12.0)
    assert frame_torsion_constant_mm4(5.0, 0.5) == pytest.approx(5.0 * 0.125 / 3.0 * (1.0 - 0.063))


@pytest.mark.parametrize("name", ["be", "bc"])
def test_lock_torque_at_zero_curvature_by_hand(name):
    # straight actuator: the taut family shrinks the radius by dR/dtau = -R0^2 cot(alpha0), so
    # T_lock = P_a dV/dtau = P_a 2 pi R0^3 cot(alpha0), linear in the active pressure
    a = ACTUATORS[name]
    P = np.array([a.P_start_kpa + 40.0, a.P_start_kpa + 80.0])
    expect = (P - a.P_start_kpa) * 1e-3 * 2.0 * math.pi * a.R0_start_mm ** 3 / math.tan(math.radians(a.alpha0_deg))
    np.testing.assert_allclose(torsion_lock_torque_nmm(a, P, 0.0), expect, rtol=1e-9)


@pytest.mark.parametrize("name, P, k", [("be", 150.0, 0.008), ("be", 200.0, -0.01), ("bc", 100.0, -0.005)])
def test_finite_differences_of_the_energy_agree(name, P, k):
    a = ACTUATORS[name]
    s = spatial_stiffness(a, P, k)
    h = 1e-5
    E = section_energy_n(a, P, k, [-h, 0.0, h])
    assert (E[0] - 2 * E[1] + E[2]) / h ** 2 == pytest.approx(float(s.lateral_stiffness_nmm2), rel=1e-5)
    ht = 1e-5
    T = section_energy_n(a, P, k, 0.0, [0.0, ht, 2 * ht])
    lock = (-3 * T[0] + 4 * T[1] - T[2]) / (2 * ht)  # one-sided: the energy has a kink |tau| at 0
    assert lock == pytest.approx(float(s.torsion_lock_torque_nmm), rel=1e-5)
    assert (T[0] - 2 * T[1] + T[2]) / ht ** 2 == pytest.approx(float(s.torsional_stiffness_nmm2_per_rad), rel=2e-3)
    # a symmetric braid: even in the twist and in the lateral curvature
    assert section_energy_n(a, P, k, 0.0, -ht) == pytest.approx(float(T[1]), rel=1e-14)
    assert section_energy_n(a, P, k, -h) == pytest.approx(float(E[2]), rel=1e-13)


@pytest.mark.parametrize("name", ["be", "bc"])
def test_in_plane_part_is_the_moment_law(name):
    a = ACTUATORS[name]
    k = np.array([-0.004, 0.0, 0.003])
    P = 90.0
    s = spatial_stiffness(a, P, k)
    law = MomentLaw.of(a)
    np.testing.assert_array_equal(s.moment_nmm, law.moment(P, k))
    np.testing.assert_array_equal(s.inplane_stiffness_nmm2, -law.tangent_stiffness(P, k))
    # the energy's in-plane derivative is the energy model's moment (eq 13, 16, 18 without eq 19's factor)
    h = 1e-6
    E = section_energy_n(a, P, np.stack([k - h, k + h]))
    np.testing.assert_allclose(-(E[1] - E[0]) / (2 * h), MomentLaw.of(a, "energy", eq19_factor=False).moment(P, k),
                               rtol=1e-6, atol=1e-6)


def test_vectorised_and_free_curvature_default():
    a = be_pam()
    P = np.array([100.0, 150.0, 200.0])
    s = spatial_stiffness(a, P)
    np.testing.assert_allclose(s.curvature_per_mm, MomentLaw.of(a).free_curvature(P).curvature_per_mm)
    one = [float(lateral_stiffness_nmm2(a, p, k)) for p, k in zip(P, s.curvature_per_mm, strict=True)]
    np.testing.assert_allclose(s.lateral_stiffness_nmm2, one, rtol=1e-12)
    gj = torsional_stiffness_nmm2_per_rad(a, P[:, None], np.array([0.0, 0.005])[None, :])
    assert gj.shape == (3, 2)
    d = s.to_dict()
    assert len(d["lateral_stiffness_nmm2"]) == 3 and "torsion_lock_torque_nmm" in d


def test_table_interpolates_the_stiffnesses():
    a = bc_pam()
    br = MomentLaw.of(a).stable_branch(100.0)
    tab = SpatialTable(a, 100.0, br.k_lo, br.k_hi)
    k = np.array([-0.004, -0.001, 0.002])
    EI, GJ, T = tab(k)
    s = spatial_stiffness(a, 100.0, k)
    np.testing.assert_allclose(EI, s.lateral_stiffness_nmm2, rtol=1e-6)
    np.testing.assert_allclose(GJ, s.torsional_stiffness_nmm2_per_rad, rtol=1e-6)
    np.testing.assert_allclose(T, s.torsion_lock_torque_nmm, rtol=1e-6)
    assert np.iscomplexobj(tab(k + 1e-30j)[0])


@settings(max_examples=15, deadline=None)
@given(P=st.one_of(st.just(0.0), st.floats(5.0, 250.0)), frac=st.floats(-0.5, 0.5))
def test_stiffnesses_positive_on_the_working_range(P, frac):
    a = be_pam()
    lim = MomentLaw.of(a).limits
    k = frac * (lim.k_max if frac > 0 else -lim.k_min) * 0.5
    s = spatial_stiffness(a, P, k)
    assert float(s.lateral_stiffness_nmm2) > a.frame_modulus_mpa * frame_strong_axis_inertia_mm4(5.0, 0.5) * 0.9
    assert np.isfinite(s.torsional_stiffness_nmm2_per_rad)


def test_bad_input_is_one_line():
    with pytest.raises(InputError, match="curvature_per_mm"):
        spatial_stiffness(be_pam(), 100.0, 1.0)
    with pytest.raises(InputError, match="frame_shear_modulus_mpa"):
        spatial_stiffness(be_pam(), 100.0, 0.0, frame_shear_modulus_mpa=-1.0)


def test_predict_json_gives_the_stiffnesses_at_the_free_curvature(capsys):
    import json

    from bendpam.cli import main

    assert main(["predict", "--preset", "bc-pam", "--pressure-kpa", "100", "200", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)["results"]
    s = spatial_stiffness(bc_pam(), 100.0)
    assert res[0]["lateral_stiffness_nmm2"] == pytest.approx(float(s.lateral_stiffness_nmm2), rel=1e-12)
    assert res[0]["torsional_stiffness_nmm2_per_rad"] == pytest.approx(float(s.torsional_stiffness_nmm2_per_rad))
    assert res[0]["torsion_lock_torque_nmm"] == pytest.approx(float(s.torsion_lock_torque_nmm))
    assert res[1]["lateral_stiffness_nmm2"] is None  # above the fold: no free curvature
