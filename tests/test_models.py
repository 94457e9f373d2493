"""Physics identities and published values for the two moment models."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

import bendpam
from bendpam import presets
from bendpam.errors import InputError
from bendpam.physics.models import energy, get_model
from strategies import actuators as actuator_strategy


def closed_form(a, P):
    """docs/paper-reading.md: M(P, 0) = pi R0s^3 (1 - 2 cot^2 a0) (P - P_start), P in kPa.

    With the active pressure in MPa (N/mm^2) and R0s in mm the product is in N*mm, hence 1e-3 per kPa.
    """
    cot2 = 1 / math.tan(math.radians(a.alpha0_deg)) ** 2
    return math.pi * a.R0_start_mm**3 * (1 - 2 * cot2) * max(P - a.P_start_kpa, 0.0) * 1e-3


def test_blocked_moment_closed_form_both_models(preset_model):
    a, model = preset_model
    for P in (0.0, 50.0, 100.0, 200.0, 300.0):  # kPa
        bm_e = bendpam.blocked_moment(a, P, "energy")
        bm_f = bendpam.blocked_moment(a, P, "force_balance")
        assert bm_e == pytest.approx(closed_form(a, P), rel=1e-12, abs=1e-12)
        assert bm_f == pytest.approx(bm_e, rel=1e-12, abs=1e-9)


def test_paper_be_pam_blocked_moment_300nmm_at_200kpa():
    # section 2.2 / Figure 4(c): about 300 N*mm at 200 kPa
    for model in ("energy", "force_balance"):
        assert bendpam.blocked_moment(presets.be_pam(model), 200.0, model) == pytest.approx(300.0, rel=0.05)


def test_golden_blocked_moment_by_hand():
    # BE-PAM energy preset: pi * 10.1^3 * (1 - 2 cot^2(69.7 deg)) * (200 - 68) kPa * 1e-3 MPa/kPa
    cot2 = (math.cos(math.radians(69.7)) / math.sin(math.radians(69.7))) ** 2
    by_hand = math.pi * 1030.301 * (1 - 2 * cot2) * 0.132
    assert by_hand == pytest.approx(310.33, abs=0.01)
    assert bendpam.blocked_moment(presets.be_pam(), 200.0) == pytest.approx(by_hand, rel=1e-12)


def test_elastic_terms_vanish_at_zero_curvature(preset_model):
    # B(0) = 0 in both models: the bladder carries no elastic moment when straight (the C10 and
    # C01 terms cancel in eq 49 with the corrected sign)
    a, model = preset_model
    _, B = get_model(model).coefficients(a.params, np.array(0.0))
    assert abs(B) < 1e-9


def test_eq49_sign_as_printed_would_be_ten_times_too_large():
    # docs/paper-reading.md: with the printed sign, the constant bladder term does not cancel; check
    # that our corrected form differs from the printed one by exactly twice that term.
    a = presets.be_pam("force_balance")
    t = bendpam.moment_terms(a, 200.0, 0.0, "force_balance")
    R, tb = a.R0_start_mm, a.t0_start_mm
    C10, C01 = a.C10_kpa * 1e-3, a.C01_kpa * 1e-3  # MPa, so that the term is in N*mm
    const = 2 * math.pi * R**2 * tb * (2 * C10 - 2 * C01)
    printed = t["M_load"] - 2 * const
    assert abs(printed / t["M_load"]) > 1.5  # the printed sign is far off ...
    assert t["M_load"] == pytest.approx(closed_form(a, 200.0), rel=1e-12)  # ... ours is the closed form


def test_air_moment_is_P_dV_dtheta(preset_model, span):
    # eq 13: M_air = P dV/dtheta with V = pi R^2 L0 (1 + k'R) and theta = k' L0
    a, _ = preset_model
    k = span(a, 0.9, 17)
    h = 1e-7
    V = lambda kk: bendpam.kinematics(a, kk).volume
    dV_dtheta = (V(k + h) - V(k - h)) / (2 * h) / a.L0_mm
    P = 150.0  # kPa
    t = bendpam.moment_terms(a, P, k, "energy")
    # (P - P_start) in MPa = N/mm^2 times dV/dtheta in mm^3 gives N*mm
    assert_allclose(t["M_air"], (P - a.P_start_kpa) * 1e-3 * dV_dtheta, rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("factor", [True, False])
def test_bladder_moment_is_derivative_of_stored_energy(preset_model, span, factor):
    # eq 19: M_bl = (1 + k'R) dU_bl/dk' (or dU_bl/dk' without the printed factor)
    a, _ = preset_model
    k = span(a, 0.9, 17)
    h = 1e-7
    dU = (energy.bladder_energy(a.params, k + h) - energy.bladder_energy(a.params, k - h)) / (2 * h)
    kin = bendpam.kinematics(a, k)
    expected = (1 + kin.u) * dU if factor else dU
    got = bendpam.moment_terms(a, 100.0, k, "energy", eq19_factor=factor)["M_bl"]
    assert_allclose(got, expected, rtol=1e-6, atol=1e-6 * np.max(np.abs(expected)))


def test_frame_moment(be):
    t = bendpam.moment_terms(be, 100.0, 0.01, "energy")
    assert t["M_f"] == pytest.approx(6796.0 * 5 * 0.5**3 / 12 * 0.01)
    t = bendpam.moment_terms(be, 100.0, 0.01, "force_balance")
    assert t["M_frame"] == pytest.approx(6796.0 * 5 * 0.5**3 / 12 * 0.01)


def test_terms_sum_to_moment(preset_model, span):
    a, model = preset_model
    k = span(a, 0.8, 9)
    t = bendpam.moment_terms(a, 120.0, k, model)
    parts = [v for n, v in t.items() if n != "M_load"]
    assert_allclose(t["M_load"], parts[0] - sum(parts[1:]), rtol=1e-12, atol=1e-9)
    assert_allclose(t["M_load"], bendpam.moment(a, 120.0, k, model), rtol=1e-12, atol=1e-9)


def test_force_balance_stresses_integrate_to_moment_parts(preset_model):
    # integrate the reported internal stresses around the section and recover M_bl and M_br
    a, model = preset_model
    P, k = 150.0, 0.4 * bendpam.curvature_limits(a).k_min if a.bend_sign < 0 else 0.01  # kPa, 1/mm
    ds = bendpam.internal_stresses(a, P, k, n_phi=4001)
    assert ds["sigma_bl1_kpa"].attrs["units"] == "kPa" and ds["N_br1_n_per_mm"].attrs["units"] == "N/mm"
    phi = np.radians(ds["phi_deg"].values)
    kin = bendpam.kinematics(a, k)
    R, tb = float(kin.radius), float(kin.mean_thickness)
    h = R * (1 - np.cos(phi))
    pa = P - a.P_start_kpa  # kPa
    # elastic part (-P is in M_p, eq 49); stresses in kPa, so 1e-3 to N/mm^2 and N*mm
    m_bl = np.trapezoid((ds["sigma_bl1_kpa"].values + pa) * 1e-3 * h * tb * R, phi)
    m_br = np.trapezoid(ds["N_br1_n_per_mm"].values * h * R, phi)
    t = bendpam.moment_terms(a, P, k, "force_balance")
    assert m_bl == pytest.approx(t["M_bl"], rel=1e-6, abs=1e-6)
    assert m_br == pytest.approx(t["M_br"], rel=1e-6)
    # the braid hoop tension is P_e R (eq 31; P_e in kPa -> N/mm^2) and sigma = N / t_br (N/mm^2 -> kPa)
    assert float(ds["N_br2_n_per_mm"]) == pytest.approx(float(ds["P_e_kpa"]) * 1e-3 * R)
    assert_allclose(ds["sigma_br1_kpa"].values, ds["N_br1_n_per_mm"].values / a.braid_thickness_mm * 1e3)


def test_stresses_when_straight_are_hydrostatic(be):
    # at k' = 0 the bladder is unstretched: sigma_1 = sigma_2 = sigma_3 = -P_active and P_e = P_active
    ds = bendpam.internal_stresses(be, 200.0, 0.0)
    pa = 200.0 - be.P_start_kpa  # kPa, as the stresses
    assert_allclose(ds["sigma_bl1_kpa"].values, -pa, atol=1e-9)  # 1e-9 kPa = the former 1e-12 MPa
    assert float(ds["sigma_bl2_kpa"]) == pytest.approx(-pa)
    assert float(ds["P_e_kpa"]) == pytest.approx(pa)
    assert ds["P_e_kpa"].attrs["units"] == "kPa"
    # McKibben: axial braid tension / hoop = cot^2 alpha0
    assert_allclose(ds["N_br1_n_per_mm"].values / float(ds["N_br2_n_per_mm"]),
                    1 / math.tan(math.radians(be.alpha0_deg)) ** 2, rtol=1e-12)


def test_internal_stresses_labelled_grid(be):
    ds = bendpam.internal_stresses(be, np.array([100.0, 200.0]), np.array([0.0, 0.005, 0.01]), n_phi=37)
    assert ds["sigma_bl1_kpa"].dims == ("pressure_kpa", "curvature_per_mm", "phi_deg")
    assert ds["P_e_kpa"].dims == ("pressure_kpa", "curvature_per_mm")
    assert ds["sigma_bl1_kpa"].attrs["units"] == "kPa" and ds["N_br1_n_per_mm"].attrs["units"] == "N/mm"
    assert ds["pressure_kpa"].attrs["units"] == "kPa" and ds["pressure_kpa"].values.tolist() == [100.0, 200.0]
    one = bendpam.internal_stresses(be, 200.0, 0.005, n_phi=37)
    assert_allclose(ds["sigma_bl1_kpa"].sel(pressure_kpa=200.0, curvature_per_mm=0.005).values,
                    one["sigma_bl1_kpa"].values)


def test_broadcasting_grid_equals_pointwise(preset_model):
    a, model = preset_model
    P = np.array([0.0, 50.0, 100.0, 200.0])  # kPa
    lim = bendpam.curvature_limits(a)
    k = np.linspace(0.5 * lim.k_min, 0.5 * lim.k_max, 7)
    grid = bendpam.moment(a, P[:, None], k[None, :], model)
    assert grid.shape == (4, 7)
    for i, p in enumerate(P):
        for j, kk in enumerate(k):
            assert grid[i, j] == pytest.approx(float(bendpam.moment(a, p, kk, model)), rel=1e-12, abs=1e-10)


def test_affine_in_active_pressure_and_deadband(be):
    k = 0.004
    m = lambda P: float(bendpam.moment(be, P, k))
    # below P_start only the passive response remains
    assert m(0.0) == m(30.0) == m(be.P_start_kpa)
    assert m(0.0) < 0
    assert m(200.0) - m(150.0) == pytest.approx(m(150.0) - m(100.0), rel=1e-10)


def test_tangent_stiffness_against_finite_difference(preset_model, span):
    a, model = preset_model
    k = span(a, 0.8, 9)
    h = 1e-6
    fd = (bendpam.moment(a, 150.0, k + h, model) - bendpam.moment(a, 150.0, k - h, model)) / (2 * h)
    assert_allclose(bendpam.tangent_stiffness(a, 150.0, k, model), fd, rtol=1e-5, atol=1e-3)
    # at the lock-up limits the stencil shifts inside and still works
    lim = bendpam.curvature_limits(a)
    ts = bendpam.tangent_stiffness(a, 150.0, np.array([lim.k_min, lim.k_max]), model)
    assert np.all(np.isfinite(ts))


def test_bad_inputs(be):
    with pytest.raises(InputError, match="below zero"):
        bendpam.moment(be, -10.0, 0.0)
    with pytest.raises(InputError, match="non-finite"):
        bendpam.moment(be, np.nan, 0.0)
    with pytest.raises(InputError, match="non-finite"):
        bendpam.moment(be, 100.0, [0.0, np.inf])
    with pytest.raises(InputError, match="model"):
        bendpam.moment(be, 100.0, 0.0, model="fem")
    with pytest.raises(TypeError, match="Actuator"):
        bendpam.moment({"alpha0_deg": 70}, 100.0, 0.0)
    with pytest.raises(InputError, match="not a number"):  # a string is refused before any conversion
        bendpam.moment(be, "high", 0.0)
    with pytest.raises(InputError, match="not numeric"):
        bendpam.moment(be, [100.0, "high"], 0.0)
    with pytest.raises(InputError, match="order"):  # Gauss-Legendre order, allowed [4, 1024]
        bendpam.moment(be, 100.0, 0.0, order=2)
    with pytest.warns(bendpam.UnitWarning, match="kPa"):
        bendpam.moment(be, 0.1, 0.0)  # 0.1 MPa passed where kPa is expected


actuators = actuator_strategy()


@pytest.mark.filterwarnings("ignore::bendpam.validate.UnitWarning")  # P may be drawn in (0, 5) kPa
@settings(max_examples=60, deadline=None)
@given(a=actuators, P=st.floats(0.0, 400.0), frac=st.floats(-0.95, 0.95),
       model=st.sampled_from(["energy", "force_balance"]))
def test_property_models_finite_and_blocked_equal(a, P, frac, model):
    lim = bendpam.curvature_limits(a)
    k = frac * (lim.k_max if frac > 0 else -lim.k_min)
    m = bendpam.moment(a, P, k, model)
    assert np.isfinite(m)
    assert bendpam.blocked_moment(a, P, "energy") == pytest.approx(closed_form(a, P), rel=1e-10, abs=1e-10)
    assert bendpam.blocked_moment(a, P, "force_balance") == pytest.approx(closed_form(a, P), rel=1e-10, abs=1e-10)
    t = bendpam.moment_terms(a, P, k, model)
    assert all(np.isfinite(v) for v in t.values())


def test_linear_basis_reproduces_the_moment(preset_model, span):
    # M = P_a A - E_f I_f k' - C10 b10 - C01 b01: the decomposition identification relies on
    a, model = preset_model
    mod = get_model(model)
    k = span(a, 0.9, 13)
    A, b10, b01 = mod.basis(a.params, k)  # the numerics layer: per MPa
    pa = (150.0 - a.P_start_kpa) * 1e-3  # MPa
    C10, C01 = a.C10_kpa * 1e-3, a.C01_kpa * 1e-3  # MPa
    M = pa * A - a.frame_stiffness_nmm2 * k - C10 * b10 - C01 * b01
    assert_allclose(M, bendpam.moment(a, 150.0, k, model), rtol=1e-12, atol=1e-9)
    # and b10, b01 are the responses to unit constants (1000 kPa = 1 MPa)
    b = a.replace(C10_kpa=1000.0, C01_kpa=0.0)
    _, B = mod.coefficients(b.params, k)
    assert_allclose(B - b.frame_stiffness_nmm2 * k, b10, rtol=1e-12, atol=1e-9)
