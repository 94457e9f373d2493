"""The ensemble of loop laws behind the fit's systematic uncertainty (issue 23 item 2).

Each new law alone, against hand-derived numbers; then the ensemble's weights, the cycle bootstrap
and how both parts reach fit.json.
"""

import math

import numpy as np
import pytest

from bendpam.physics.hysteresis import BoucWen, DahlLaw, MaxwellSlip, PrandtlIshlinskii, ViscousLoop, make_law


def triangle(span, cycles, n=400, start=0.0):
    """A path blocked -> free -> blocked: ``cycles`` triangles of amplitude ``span`` from ``start``."""
    up = np.linspace(0.0, span, n + 1)
    one = np.concatenate([up, span - up[1:]])
    return start + np.concatenate([one] + [one[1:]] * (cycles - 1))


def loop_area(theta, z):
    """The enclosed area of the last cycle of a closed path (shoelace formula)."""
    return 0.5 * abs(float(np.sum(theta[:-1] * z[1:] - theta[1:] * z[:-1])))


# --------------------------------------------------------------------------------------------
# Bouc-Wen (exponent 2, beta = gamma = 1/2)
# --------------------------------------------------------------------------------------------
def test_bouc_wen_saturates_at_one_and_returns_linearly():
    law = BoucWen(0.1)
    th = np.array([0.0, 0.1, 0.2, 5.0, 4.95, 4.9, 4.85])
    z = law.z_path(th)
    assert z[1] == pytest.approx(math.tanh(1.0)) and z[2] == pytest.approx(math.tanh(2.0))
    assert z[3] == pytest.approx(1.0, abs=1e-15)  # saturated: tanh(50)
    # back from z = 1 the slope is -1/theta_c until z = 0, then tanh: 0.5, 0, -tanh(0.5)
    assert z[4:].tolist() == pytest.approx([0.5, 0.0, -math.tanh(0.5)], abs=1e-12)


def test_bouc_wen_steady_cycle_is_the_path_after_many_cycles():
    law, span = BoucWen(0.08), 0.3
    th = triangle(span, 6)
    z = law.z_path(th, -1.0)
    n = 400
    away, back = law.steady_branches(np.linspace(0.0, span, n + 1), span)
    last_up, last_down = z[-2 * n - 1: -n], z[-n - 1:]
    assert np.allclose(last_up, away, atol=1e-9) and np.allclose(last_down, back, atol=1e-9)
    # turning value z_b = tanh(span / theta_c - z_b)
    zb = away[-1]
    assert zb == pytest.approx(math.tanh(span / 0.08 - zb), abs=1e-12)


# --------------------------------------------------------------------------------------------
# Maxwell-slip (equal slip moments)
# --------------------------------------------------------------------------------------------
def test_maxwell_slip_energy_loss_per_cycle_is_the_sum_of_the_parallelograms():
    law = MaxwellSlip(4.0, n=2)  # slip angles r = 0.5 and 1.5 rad
    span = 4.0
    th = triangle(span, 3, n=4000)
    z = law.z_path(th, -1.0)
    last = th[-8001:], z[-8001:]
    # element j dissipates 2 span - 4 r_j: (8 - 2 + 8 - 6) / 2 = 4
    assert loop_area(*last) == pytest.approx(4.0, rel=1e-6)
    # a loop narrower than both elements' 2 r_j dissipates nothing
    small = triangle(0.9, 2, n=100)
    assert loop_area(small[-201:], law.z_path(small, -1.0)[-201:]) == pytest.approx(0.0, abs=1e-12)


def test_maxwell_slip_steady_branches_match_the_path_and_differ_from_pi():
    law, span = MaxwellSlip(0.2, n=16), 0.15
    th = triangle(span, 3)
    z = law.z_path(th, -1.0)
    away, back = law.steady_branches(np.linspace(0.0, span, 401), span)
    assert np.allclose(z[-801:-400], away, atol=1e-12) and np.allclose(z[-401:], back, atol=1e-12)
    # the stiff elements slip first: steeper than PI right after the reversal
    pi_away, _ = PrandtlIshlinskii(0.2, 16).steady_branches(np.array([0.01]), span)
    assert law.steady_branches(np.array([0.01]), span)[0][0] > pi_away[0] + 0.05


# --------------------------------------------------------------------------------------------
# the rate-dependent viscous loop (Maxwell fluid)
# --------------------------------------------------------------------------------------------
def test_viscous_loop_relaxes_to_the_rate_and_its_steady_cycle_matches_the_path():
    law = ViscousLoop(tau_s=2.0, omega_ref_rad_s=0.05)
    t = np.linspace(0.0, 10.0, 1001)
    z = law.z_path(0.02 * t, t)
    assert np.allclose(z, 0.4 * (1.0 - np.exp(-t / 2.0)), atol=1e-12)  # exact for a constant rate
    span, period = 0.3, 20.0
    th = triangle(span, 5, n=500)
    tt = np.arange(th.size) * (period / 1000.0)
    zp = law.z_path(th, tt)
    away, back = law.steady_branches(np.linspace(0.0, span, 501), span, period)
    assert np.allclose(zp[-1001:-500], away, atol=1e-6) and np.allclose(zp[-501:], back, atol=1e-6)


def test_viscous_loop_widens_with_the_rate():
    law = ViscousLoop(tau_s=1.0, omega_ref_rad_s=0.1)
    d = np.linspace(0.0, 0.2, 201)
    slow = law.steady_branches(d, 0.2, 40.0)[0]
    fast = law.steady_branches(d, 0.2, 4.0)[0]
    assert fast[-1] > 5 * slow[-1]  # ten times the rate: a loop ~ten times as high, a little rounder


def test_unequal_times_and_unknown_laws_are_refused():
    from bendpam.errors import InputError

    with pytest.raises(InputError, match="equally spaced"):
        ViscousLoop().z_path(np.array([0.0, 0.1, 0.2]), np.array([0.0, 1.0, 3.0]))
    with pytest.raises(InputError, match="bouc_wen"):
        make_law("lugre", 5.0)
    assert isinstance(make_law("bouc-wen", 5.0), BoucWen) and isinstance(make_law("maxwell_slip", 5.0), MaxwellSlip)
    assert isinstance(make_law("dahl", 5.0), DahlLaw)


# --------------------------------------------------------------------------------------------
# breakaway friction (stiction)
# --------------------------------------------------------------------------------------------
def test_breakaway_sticks_peaks_at_the_static_level_and_decays_to_the_kinetic():
    from bendpam.physics.hysteresis import Breakaway

    law = Breakaway(0.05, ratio=1.6, decay=3.0)
    d = np.linspace(0.0, 1.0, 2001)
    z = law.z_path(d, -1.0)
    # stick: slope 1.6 / 0.05 = 32 /rad from -1 to 1.6, i.e. for 2.6 / 32 rad
    i_peak = int(np.argmax(z))
    assert z[i_peak] == pytest.approx(1.6, abs=32 * 5e-4) and d[i_peak] == pytest.approx(2.6 / 32, abs=1e-3)
    assert z[-1] == pytest.approx(1.0 + 0.6 * math.exp(-(1.0 - 2.6 / 32) / 0.15), rel=1e-9)
    # steady cycle = the path after a few cycles
    span = 0.4
    th = triangle(span, 4)
    zp = law.z_path(th, -1.0)
    away, back = law.steady_branches(np.linspace(0.0, span, 401), span)
    assert np.allclose(zp[-801:-400], away, atol=1e-9) and np.allclose(zp[-401:], back, atol=1e-9)
