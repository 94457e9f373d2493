import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.integrate import quad

import bendpam
from bendpam.errors import InputError
from bendpam.physics.braid import LOCK_FRACTION, gauss_nodes
from strategies import actuators as actuator_strategy


def eq5_quad(u, alpha0):
    """Reference eq 5 by adaptive quadrature: xi(u) = (2 pi / sin a0) / int_0^2pi (1 - c^2 l1^2)^-1/2."""
    c = math.cos(alpha0)
    val = quad(lambda p: 1.0 / math.sqrt(1.0 - (c * (1.0 + u * (1.0 - math.cos(p)))) ** 2), 0.0, 2 * math.pi,
               epsabs=0, epsrel=1e-13, limit=400)[0]
    return 2 * math.pi / math.sin(alpha0) / val


def test_eta_at_zero_is_one_exactly(preset_model):
    a, _ = preset_model
    kin = bendpam.kinematics(a, 0.0)
    assert kin.eta == 1.0
    assert kin.radius == a.R0_start_mm
    assert kin.u == 0.0


def test_dR_at_zero_golden(preset_model):
    # by hand: dxi/du(0) = -cot^2 a0 and du/dk' = R0, so dR/dk'(0) = -R0^2 cot^2 a0
    a, _ = preset_model
    kin = bendpam.kinematics(a, 0.0)
    assert kin.dradius == pytest.approx(-a.R0_start_mm**2 / math.tan(math.radians(a.alpha0_deg)) ** 2, rel=1e-12)


def test_eq5_against_adaptive_quadrature(preset_model, span):
    a, _ = preset_model
    k = span(a, 0.97, 15)
    kin = bendpam.kinematics(a, k)
    ref = np.array([eq5_quad(u, math.radians(a.alpha0_deg)) for u in kin.u])
    assert_allclose(kin.eta, ref, rtol=1e-11)
    assert_allclose(kin.u, k * kin.radius, rtol=1e-12, atol=1e-16)


def test_dR_against_finite_differences(preset_model, span):
    a, _ = preset_model
    k = span(a, 0.95, 21)
    h = 1e-7
    fd = (bendpam.kinematics(a, k + h).radius - bendpam.kinematics(a, k - h).radius) / (2 * h)
    assert_allclose(bendpam.kinematics(a, k).dradius, fd, rtol=2e-6, atol=1e-8)


def test_braid_constraint_and_angles(be):
    kin = bendpam.kinematics(be, np.array([-0.03, 0.0, 0.01, 0.1]))
    a0 = math.radians(be.alpha0_deg)
    c, s = math.cos(a0), math.sin(a0)
    assert_allclose(c**2 * kin.lambda1**2 + s**2 * kin.lambda2_braid**2, 1.0, atol=1e-14)  # eq 2
    assert_allclose(np.cos(kin.braid_angle), c * kin.lambda1, atol=1e-14)  # eq 4
    assert_allclose(kin.axis_curvature, kin.curvature / (1 + kin.curvature * kin.radius))  # eq 1
    assert_allclose(kin.angle, kin.curvature * be.L0_mm)
    # R0/R is the circle mean of 1/lambda2_braid (eq 35)
    assert_allclose(1.0 / kin.eta, (1.0 / kin.lambda2_braid) @ kin.weights, rtol=1e-13)


def test_radius_falls_with_curvature(be, bc, span):
    for a in (be, bc):
        k = span(a, 0.9, 31)
        R = bendpam.kinematics(a, k).radius
        assert np.all(np.diff(R) < 0)  # R falls monotonically as k' increases, on both sides
        assert R[0] > a.R0_start_mm > R[-1]


@pytest.mark.parametrize("frac", [0.5, 0.9, 0.99])
def test_quadrature_convergence(preset_model, frac, span):
    a, model = preset_model
    k = span(a, frac, 9)
    R = {n: bendpam.kinematics(a, k, order=n).radius for n in (8, 16, 32, 128)}
    M = {n: bendpam.moment(a, 150.0, k, model, order=n) for n in (8, 16, 32, 128)}
    err = {n: np.max(np.abs(R[n] - R[128]) / R[128]) for n in (8, 16, 32)}
    merr = {n: np.max(np.abs(M[n] - M[128])) / np.max(np.abs(M[128])) for n in (8, 16, 32)}
    assert err[32] < 1e-9 and merr[32] < 1e-7
    assert err[16] <= err[8] + 1e-15 and merr[16] <= merr[8] + 1e-15


def test_full_circle_equals_half_range_by_symmetry(be):
    # every integrand is even about pi: a 2n-point rule on [0, 2pi] equals the n-point rule on [0, pi]
    kin = bendpam.kinematics(be, 0.05)
    x, w = np.polynomial.legendre.leggauss(64)
    phi_full = (x + 1) * np.pi
    c = math.cos(math.radians(be.alpha0_deg))
    f = lambda p: 1.0 / np.sqrt(1 - (c * (1 + kin.u * (1 - np.cos(p)))) ** 2)
    full = np.sum(w * np.pi * f(phi_full)) / (2 * np.pi)
    phi, wbar = gauss_nodes(32)
    assert full == pytest.approx(f(phi) @ wbar, rel=1e-12)
    assert_allclose(f(phi), f(2 * np.pi - phi), rtol=1e-14)


def test_lock_up_limits(be, bc):
    for a in (be, bc):
        lim = bendpam.curvature_limits(a)
        assert lim.k_min < 0 < lim.k_max
        u_lock = (1 / math.cos(math.radians(a.alpha0_deg)) - 1) / 2
        assert lim.u_max <= LOCK_FRACTION * u_lock + 1e-15
        # far side stretch at the lower limit is 1 + 2 u_min >= 0
        assert 1 + 2 * lim.u_min >= 0.0
        with pytest.raises(InputError, match="lock-up"):
            bendpam.kinematics(a, lim.k_max * 1.01)
        with pytest.raises(InputError, match="lock-up"):
            lim.check(lim.k_max * 1.01)
        with pytest.raises(InputError, match="lock-up"):
            bendpam.moment(a, 100.0, lim.k_min * 1.01)
        bendpam.kinematics(a, [lim.k_min, lim.k_max])  # the limits themselves are admissible
    # BC-PAM: the lumen closes (R = t_bar) before the braid locks
    lim = bendpam.curvature_limits(bc)
    kin = bendpam.kinematics(bc, lim.k_max)
    assert "lumen" in lim.reason_max
    assert kin.radius == pytest.approx(kin.mean_thickness, rel=1e-9)


def test_nonfinite_curvature_rejected(be):
    with pytest.raises(ValueError, match="non-finite"):
        bendpam.kinematics(be, [0.0, np.nan])


actuators = actuator_strategy(a0=((15.0, 53.0), (57.0, 85.0)), R0=(3.0, 20.0), tf=(0.05, 0.6), Rs=(1.0, 1.3),
                              c10=(-500.0, 2000.0), c01=(0.0, 1000.0), ps=(30.0, 30.0))


@settings(max_examples=60, deadline=None)
@given(a=actuators, frac=st.floats(-0.98, 0.98))
def test_property_kinematics_finite_and_consistent(a, frac):
    lim = bendpam.curvature_limits(a)
    k = frac * (lim.k_max if frac > 0 else -lim.k_min)
    kin = bendpam.kinematics(a, k)
    for name in ("u", "radius", "dradius", "eta", "mean_thickness"):
        assert np.all(np.isfinite(getattr(kin, name))), name
    assert kin.radius > 0
    assert kin.u == pytest.approx(k * kin.radius, rel=1e-10, abs=1e-14)
    assert np.all(kin.lambda1 >= 0)
    # the sign of dR/dk' is negative on both sides (R falls as k' increases)
    assert kin.dradius < 0


# ------------------------------------------------------------------------------------------------
# closed forms of the section integrals (order = 0, the default)
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("alpha0_deg", [12.0, 30.0, 45.0, 56.0, 69.7, 80.0, 88.0])
def test_ibar_closed_form_equals_adaptive_quadrature(alpha0_deg):
    from bendpam.physics.braid import ibar_closed_form

    c = math.cos(math.radians(alpha0_deg))
    u_lock = (1 / c - 1) / 2
    for u in (-0.49, -0.2, -1e-9, 0.0, 1e-9, 0.3 * u_lock, 0.9 * u_lock, LOCK_FRACTION * u_lock):
        f = lambda p, u=u: 1.0 / math.sqrt(1 - (c * (1 + u * (1 - math.cos(p)))) ** 2)
        df = lambda p, u=u, f=f: c * c * (1 + u * (1 - math.cos(p))) * (1 - math.cos(p)) * f(p) ** 3
        ref = quad(f, 0, math.pi, epsabs=0, epsrel=1e-13, limit=200)[0] / math.pi
        dref = quad(df, 0, math.pi, epsabs=0, epsrel=1e-13, limit=200)[0] / math.pi
        ib, dib = ibar_closed_form(np.array(u), c)
        assert float(ib) == pytest.approx(ref, rel=1e-12), u
        assert float(dib) == pytest.approx(dref, rel=1e-11, abs=1e-13), u


def test_closed_form_models_equal_high_order_quadrature(preset_model, span):
    a, model = preset_model
    k = span(a, 0.98, 41)
    exact = bendpam.moment_terms(a, 150.0, k, model)
    quad256 = bendpam.moment_terms(a, 150.0, k, model, order=256)
    scale = np.max(np.abs(quad256["M_load"]))
    for name in exact:
        assert_allclose(exact[name], quad256[name], rtol=0, atol=1e-11 * scale, err_msg=name)
    assert_allclose(bendpam.kinematics(a, k).radius, bendpam.kinematics(a, k, order=256).radius, rtol=1e-13)


@pytest.mark.parametrize("alpha0_deg", [15.0, 40.0, 69.7, 85.0])
def test_one_newton_step_from_the_uniform_table_reaches_rounding(alpha0_deg):
    from bendpam.physics.braid import _hermite_start, _inverse_table, _newton, solve_u

    a0 = math.radians(alpha0_deg)
    c = math.cos(a0)
    u_lock = (1 / c - 1) / 2
    # 4200 points (>= _UNIFORM_MIN_POINTS): the uniform-table path
    u_true = np.concatenate([np.linspace(-0.49, 0, 2100), np.linspace(0, LOCK_FRACTION * u_lock, 2100)])
    q = math.sin(a0) * u_true * bendpam.physics.braid.circle_ibar(u_true, c)[0]
    u, ib, dib = solve_u(q, a0)
    qt, ut, dt = _inverse_table(a0, 0)
    u_ref, ib_ref, dib_ref = _newton(q, a0, 0, _hermite_start(q, qt, ut, dt), (-0.5, u_lock))
    assert_allclose(u, u_ref, rtol=1e-13, atol=1e-15)
    assert_allclose(u, u_true, rtol=1e-12, atol=1e-15)
    assert_allclose(ib, ib_ref, rtol=1e-13)
    assert_allclose(dib, dib_ref, rtol=1e-10, atol=1e-12)
