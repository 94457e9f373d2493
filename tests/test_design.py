"""Design tools (issue 6): finger statics, grasping, wrist, and their CLI commands."""

import json
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import bendpam
import bendpam.cli as cli
from bendpam import presets
from bendpam.design import (
    Finger,
    FingerLoads,
    Gripper,
    Wrist,
    blocked_tip_force,
    finger_sweep,
    free_tip_trajectory,
    grasp_sweep,
    linear_tip_compliance,
    solve_finger,
    solve_grasp,
    stable_branch,
    tip_stiffness,
    wrist_bend,
    wrist_hold,
    wrist_moment,
    wrist_pressures,
    wrist_sweep,
)
from bendpam.design.parts import G_N_PER_G
from bendpam.errors import InputError
from bendpam.validate import UnitWarning


def _act(name, L0=130.0, model="energy"):
    return presets.get(name, model).replace(L0_mm=L0)


def _cross(ax, ay, bx, by):
    return ax * by - ay * bx


# ------------------------------------------------------------------------------------------------
# the stable branch of the moment law
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["be-pam", "bc-pam"])
def test_stable_branch_matches_exact_law(name):
    a = _act(name)
    for P in (0.0, 100.0, 250.0):
        br = stable_branch(a, P)
        assert br.k_lo < 0.0 < br.k_hi
        k = np.linspace(br.k_lo, br.k_hi, 301)[1:-1]
        M, dM = br.moment(k)
        exact = bendpam.moment(a, P, k)
        assert np.max(np.abs(M - exact)) <= 1e-6 * np.max(np.abs(exact)) + 1e-9
        assert np.all(dM < 0.0)  # strictly decreasing on the branch
        np.testing.assert_allclose(dM, bendpam.tangent_stiffness(a, P, k), rtol=1e-4, atol=1e-3)
        # the inverse returns the branch root and NaN outside the range
        m = np.linspace(br.moment_min, min(br.moment_max, 5000.0), 7)[1:-1]
        np.testing.assert_allclose(br.moment(br.curvature(m))[0], m, rtol=1e-9, atol=1e-7)
        assert np.isnan(br.curvature(br.moment_min - 1.0))


def test_stable_branch_fold_of_bc_pam():
    a = _act("bc-pam")
    br = stable_branch(a, 200.0)  # above the 134 kPa fold: M = 0 is out of range
    assert br.end_lo == "fold" and np.isnan(br.free_curvature)
    assert br.moment_max < 0.0
    fold = bendpam.free_branch(a).k_end_per_mm
    low = stable_branch(a, bendpam.free_branch(a).max_pressure_kpa)
    assert low.k_lo == pytest.approx(fold, rel=2e-3)


# ------------------------------------------------------------------------------------------------
# finger statics
# ------------------------------------------------------------------------------------------------
@pytest.mark.filterwarnings("ignore::bendpam.validate.UnitWarning")  # hypothesis tries 0 < P < 5 kPa too
@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(["be-pam", "bc-pam"]), P_kpa=st.floats(0.0, 130.0), bend=st.sampled_from([1, -1]),
       base=st.floats(-180.0, 180.0), tip=st.floats(0.0, 20.0))
def test_zero_load_is_the_free_shape(name, P_kpa, bend, base, tip):
    a = _act(name)
    f = Finger(a, base_angle_deg=base, bend=bend, fingertip_mm=tip)
    sh = solve_finger(f, P_kpa)
    fb = bendpam.free_curvature(a, P_kpa)
    assert sh.equilibrium and sh.stable
    assert sh.pressure_kpa == P_kpa
    np.testing.assert_allclose(sh.curvature, float(fb.curvature_per_mm), rtol=0, atol=1e-12)
    # the tip turns by the free angle in the finger's bending direction, for either actuator type
    free_angle = math.radians(abs(float(fb.angle_deg)))
    assert sh.bend_angle == pytest.approx(free_angle, abs=1e-12)
    assert sh.tip_angle == pytest.approx(math.radians(base) + bend * free_angle, abs=1e-12)
    assert sh.residual_nmm < 1e-8
    tr = free_tip_trajectory(f, [P_kpa])
    assert tr.tip_x_mm[0] == pytest.approx(sh.tip_xy[0], abs=1e-9)
    assert tr.tip_y_mm[0] == pytest.approx(sh.tip_xy[1], abs=1e-9)


def test_free_arc_is_exact():
    """A constant-curvature shape is integrated exactly: the tip lies on the analytic arc."""
    a = _act("be-pam")
    f = Finger(a, nodes=11)
    sh = solve_finger(f, 200.0)
    k = float(bendpam.free_curvature(a, 200.0).curvature_per_mm)
    L = a.L0_mm
    assert sh.tip_xy[0] == pytest.approx(math.sin(k * L) / k, rel=1e-13)
    assert sh.tip_xy[1] == pytest.approx((1 - math.cos(k * L)) / k, rel=1e-13)


@pytest.mark.parametrize("name,P", [("be-pam", 150.0), ("bc-pam", 100.0)])
def test_loaded_equilibrium_residual_along_s(name, P):
    """Check M(P, k'(s)) = M_ext(s) node by node, with M_ext recomputed from the shape here."""
    a = _act(name)
    F = (0.4, -0.8)
    f = Finger(a, base_angle_deg=20.0, fingertip_mm=12.0, fingertip_offset_mm=3.0)
    sh = solve_finger(f, P, FingerLoads(tip_force_n=F, tip_moment_nmm=15.0))
    assert sh.equilibrium and sh.stable and sh.load_fraction == 1.0
    c = f.frame_side
    m_geo = 15.0 + _cross(sh.tip_xy[0] - sh.x, sh.tip_xy[1] - sh.y, *F)
    M_ext = -c * m_geo
    np.testing.assert_allclose(sh.moment_ext, M_ext, atol=1e-9)
    M = bendpam.moment(a, P, sh.curvature)
    assert np.max(np.abs(M - M_ext)) < 1e-5
    assert sh.residual_nmm < 1e-5
    # the shape is consistent: dphi/ds = c k' (trapezoidal rule), unit speed
    np.testing.assert_allclose(np.diff(sh.angle), c * np.diff(sh.s) * 0.5 * (sh.curvature[1:] + sh.curvature[:-1]),
                               atol=1e-14)
    np.testing.assert_allclose(np.gradient(sh.angle, sh.s)[1:-1], c * sh.curvature[1:-1], atol=2e-6)
    seg = np.hypot(np.diff(sh.x), np.diff(sh.y))
    assert np.all(seg <= np.diff(sh.s) + 1e-12) and np.all(seg > 0.999 * np.diff(sh.s))


def test_discretisation_converges_at_second_order():
    a = _act("be-pam")
    L = FingerLoads(tip_force_n=(0.3, -0.8), mass_per_length_g_per_mm=0.3)
    tips = {n: np.array(solve_finger(Finger(a, nodes=n), 200.0, L).tip_xy) for n in (21, 41, 81, 321)}
    e = {n: np.linalg.norm(tips[n] - tips[321]) for n in (21, 41, 81)}
    assert 3.0 < e[21] / e[41] < 5.0 and 3.0 < e[41] / e[81] < 5.0
    assert e[81] < 5e-3  # mm, the default node count


def test_self_weight_and_tip_mass():
    a = _act("be-pam")
    f = Finger(a)
    q, m = 0.25, 40.0  # g/mm, g
    sh = solve_finger(f, 150.0, FingerLoads(tip_mass_g=m, mass_per_length_g_per_mm=q))
    assert sh.equilibrium
    free = solve_finger(f, 150.0)
    assert sh.tip_xy[1] < free.tip_xy[1] and sh.bend_angle < free.bend_angle  # weight pulls the tip down
    # moment at the base from the shape: tip weight and the distributed weight (trapezoid)
    W = m * G_N_PER_G
    w = q * G_N_PER_G
    m_base = -W * (sh.tip_xy[0] - sh.x[0]) - w * np.trapezoid(sh.x - sh.x[0], sh.s)
    assert sh.moment_ext[0] == pytest.approx(-f.frame_side * m_base, rel=1e-6)


@pytest.mark.parametrize("name,P", [("be-pam", 150.0), ("bc-pam", 100.0)])
def test_small_tip_load_agrees_with_linear_beam_theory(name, P):
    a = _act(name)
    f = Finger(a, fingertip_mm=10.0)
    C = linear_tip_compliance(f, P)  # from the tangent stiffness dM/dk' at the free curvature
    free = solve_finger(f, P)
    n = np.array([-math.sin(free.tip_angle), math.cos(free.tip_angle)])  # normal to the free tip
    eps = 2e-3  # N
    sh = solve_finger(f, P, FingerLoads(tip_force_n=tuple(eps * n)))
    d = (np.array(sh.tip_xy) - np.array(free.tip_xy)) / eps
    np.testing.assert_allclose(d, C[:2, :2] @ n, rtol=3e-3)
    assert (sh.tip_angle - free.tip_angle) / eps == pytest.approx(C[2, :2] @ n, rel=3e-3)
    # the exact tip stiffness of the unloaded finger is the inverse of the same compliance
    ts = tip_stiffness(f, P)
    np.testing.assert_allclose(ts.compliance, C, rtol=2e-3, atol=1e-4 * np.abs(C).max())
    np.testing.assert_allclose(ts.matrix @ ts.compliance, np.eye(3), atol=1e-8)


def test_tip_stiffness_is_symmetric_under_dead_loads():
    f = Finger(_act("be-pam"))
    ts = tip_stiffness(f, 150.0, FingerLoads(tip_force_n=(0.3, -0.5), mass_per_length_g_per_mm=0.2))
    C = ts.compliance
    assert np.max(np.abs(C - C.T)) < 1e-4 * np.max(np.abs(C))
    assert np.all(np.linalg.eigvalsh(0.5 * (C + C.T)) > 0)  # positive definite: a stable equilibrium


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(["be-pam", "bc-pam"]), fx=st.floats(-0.6, 0.6), fy=st.floats(-0.6, 0.6),
       mt=st.floats(-20.0, 20.0), base=st.floats(-90.0, 90.0), axis=st.floats(-60.0, 60.0),
       mass=st.floats(0.0, 30.0))
def test_mirror_symmetry(name, fx, fy, mt, base, axis, mass):
    f = Finger(_act(name), base_xy_mm=(3.0, -2.0), base_angle_deg=base, fingertip_mm=5.0, fingertip_offset_mm=2.0)
    L = FingerLoads(tip_force_n=(fx, fy), tip_moment_nmm=mt, tip_mass_g=mass, mass_per_length_g_per_mm=0.1,
                    gravity=(0.2, -1.0))
    s1 = solve_finger(f, 120.0, L)
    s2 = solve_finger(f.mirrored(axis), 120.0, L.mirrored(axis))
    assert s1.equilibrium == s2.equilibrium
    if not s1.equilibrium:
        return
    a = math.radians(axis)
    c2, s2_ = math.cos(2 * a), math.sin(2 * a)
    xm, ym = c2 * s1.x + s2_ * s1.y, s2_ * s1.x - c2 * s1.y
    np.testing.assert_allclose(s2.x, xm, atol=1e-7)
    np.testing.assert_allclose(s2.y, ym, atol=1e-7)
    np.testing.assert_allclose(s2.curvature, s1.curvature, atol=1e-10)  # the same actuator state


def test_snap_through_is_reported_not_a_wrong_shape():
    a = _act("be-pam")
    f = Finger(a)  # horizontal, bending up; an upward tip force helps the bending past the fold
    ok = solve_finger(f, 100.0, FingerLoads(tip_force_n=(0.0, 2.0)))
    assert ok.equilibrium
    sh = solve_finger(f, 100.0, FingerLoads(tip_force_n=(0.0, 5.0)))
    assert not sh.equilibrium and "snap-through" in sh.note and "fold" in sh.note
    assert 0.0 < sh.load_fraction < 1.0
    assert np.all(np.isnan(sh.x)) and math.isnan(sh.tip_xy[0])
    lim = sh.limit  # the last equilibrium reached, still on the stable branch
    assert lim is not None and np.all(lim.curvature < stable_branch(a, 100.0).k_hi)


def test_bc_pam_above_its_fold_has_no_free_finger():
    a = _act("bc-pam")
    sh = solve_finger(Finger(a), 200.0)
    assert not sh.equilibrium and "fold" in sh.note and np.all(np.isnan(sh.curvature))
    # a tip force alone cannot help: near the tip its moment vanishes
    sh = solve_finger(Finger(a), 200.0, FingerLoads(tip_force_n=(0.0, -1.0)))
    assert not sh.equilibrium and "snaps through" in sh.note
    # but a tip moment inside the stable range holds it: an equilibrium that exists only under load
    br = stable_branch(a, 200.0)
    m = 0.5 * (br.moment_min + max(br.moment_max, 2 * br.moment_min))
    sh = solve_finger(Finger(a), 200.0, FingerLoads(tip_moment_nmm=-Finger(a).frame_side * m))
    assert sh.equilibrium and "only under these loads" in sh.note
    np.testing.assert_allclose(sh.curvature, br.curvature(m), atol=1e-9)


def test_axial_compression_buckles():
    """A straight (deadband) finger under axial compression: stable below the Euler load, not above."""
    a = _act("be-pam")
    K = -float(bendpam.tangent_stiffness(a, 0.0, 0.0))
    P_euler = math.pi ** 2 * K / (4 * a.L0_mm ** 2)
    f = Finger(a)
    below = solve_finger(f, 0.0, FingerLoads(tip_force_n=(-0.8 * P_euler, 0.0)))
    above = solve_finger(f, 0.0, FingerLoads(tip_force_n=(-1.3 * P_euler, 0.0)))
    assert below.equilibrium and below.stable
    assert not above.equilibrium and "buckles" in above.note


def test_blocked_tip_force():
    for name in ("be-pam", "bc-pam"):
        a = _act(name)
        f = Finger(a)
        P = 120.0
        bf = blocked_tip_force(f, P)
        assert bf.equilibrium and bf.constraint == "roller"
        assert bf.shape.tip_xy[1] == pytest.approx(0.0, abs=1e-6)  # held on the straight line
        assert bf.force_n[0] == 0.0
        # linear beam with uniform curvature: F = 3 EI k / (2 L) = 1.5 M_blocked / L (within 10 %)
        lin = 1.5 * abs(float(bendpam.blocked_moment(a, P))) / a.L0_mm
        assert -bf.force_n[1] == pytest.approx(lin, rel=0.1)
        assert bf.shape.residual_nmm < 1e-5
    # the blocked force grows with pressure
    f = Finger(_act("be-pam"))
    F = [-blocked_tip_force(f, p).force_n[1] for p in (100.0, 150.0, 200.0, 250.0)]
    assert np.all(np.diff(F) > 0)
    # a pin at an arbitrary point
    bf = blocked_tip_force(f, 200.0, target_xy_mm=(110.0, 60.0))
    assert bf.equilibrium and bf.constraint == "pin"
    assert bf.shape.tip_xy == pytest.approx((110.0, 60.0), abs=1e-6)
    # above the BC-PAM's fold the tip region snaps: reported
    bad = blocked_tip_force(Finger(_act("bc-pam")), 200.0)
    assert not bad.equilibrium and "snaps through" in bad.note and math.isnan(bad.force_n[1])


def test_finger_input_validation():
    a = _act("be-pam")
    with pytest.raises(InputError, match="bend"):
        Finger(a, bend="up")
    with pytest.raises(InputError, match="nodes"):
        Finger(a, nodes=3)
    with pytest.raises(InputError, match="tip_force_n"):
        FingerLoads(tip_force_n=(1.0,))
    with pytest.raises(InputError, match="tip_mass_g"):
        FingerLoads(tip_mass_g=-1.0)
    with pytest.raises(InputError, match="pressure"):
        solve_finger(Finger(a), -100.0)
    with pytest.raises(InputError, match="gravity"):
        FingerLoads(gravity=(0.0, 0.0))


# ------------------------------------------------------------------------------------------------
# units: kPa at every edge, one-line InputError for a bad pressure, UnitWarning for MPa
# ------------------------------------------------------------------------------------------------
DESIGN_CALLS = ["solve_finger", "finger_sweep", "free_tip_trajectory", "blocked_tip_force", "tip_stiffness",
                "linear_tip_compliance", "friction_nmm", "stable_branch", "solve_grasp", "grasp_sweep",
                "wrist_bend", "wrist_bend_direction", "wrist_moment", "wrist_hold", "wrist_sweep",
                "wrist_pressures"]


def _design_call(name, p):
    """Call the public design function ``name`` with ``p`` as (one of) its pressure(s), kPa."""
    be = _act("be-pam")
    f, g, w = Finger(be), Gripper(be), Wrist()
    calls = {
        "solve_finger": lambda: solve_finger(f, p),
        "finger_sweep": lambda: finger_sweep(f, [p]),
        "free_tip_trajectory": lambda: free_tip_trajectory(f, [p]),
        "blocked_tip_force": lambda: blocked_tip_force(f, p),
        "tip_stiffness": lambda: tip_stiffness(f, p, FingerLoads(tip_force_n=(0.0, 0.2))),  # bent: finite
        "linear_tip_compliance": lambda: linear_tip_compliance(f, p),
        "friction_nmm": lambda: f.friction_nmm(p),
        "stable_branch": lambda: stable_branch(be, p),
        "solve_grasp": lambda: solve_grasp(g, 160.0, p),
        "grasp_sweep": lambda: grasp_sweep(g, [160.0], [p]),
        "wrist_bend": lambda: wrist_bend(w, (p, 0.0, 0.0, 0.0)),
        "wrist_bend_direction": lambda: wrist_bend(w, direction_deg=0.0, pressure_kpa=p),
        "wrist_moment": lambda: wrist_moment(w, (0.0, p, 0.0, 0.0), 10.0, 90.0),
        "wrist_hold": lambda: wrist_hold(w, p),
        "wrist_sweep": lambda: wrist_sweep(w, [p], (0.0,)),
        "wrist_pressures": lambda: wrist_pressures(90.0, p),
    }
    return calls[name]()


@pytest.mark.parametrize("name", DESIGN_CALLS)
@pytest.mark.parametrize("bad", [-100.0, "150", "abc", None, float("nan"), [[]]])
def test_design_functions_refuse_a_bad_pressure(name, bad):
    with pytest.raises(InputError, match="pressure") as exc:
        _design_call(name, bad)
    assert "\n" not in str(exc.value) and "MPa" not in str(exc.value)
    if bad == -100.0:
        assert "below zero" in str(exc.value) and "kPa" in str(exc.value)


def test_a_list_of_pressures_is_all_numbers():
    f = Finger(_act("be-pam"))
    for bad in ([100.0, "150"], [100.0, -1.0], [100.0, math.inf], [], "abc"):
        with pytest.raises(InputError, match="pressure"):
            finger_sweep(f, bad)
    with pytest.raises(InputError, match="pressure"):
        grasp_sweep(Gripper(_act("be-pam")), [160.0], [100.0, "150"])
    with pytest.raises(InputError, match="4 pressures"):
        wrist_bend(Wrist(), (100.0, 0.0, 0.0))


@pytest.mark.parametrize("name", DESIGN_CALLS)
def test_a_pressure_in_mpa_warns_once(name):
    with pytest.warns(UnitWarning, match="kPa") as rec:
        try:
            _design_call(name, 0.15)
        except bendpam.NoEquilibrium:
            pass
    assert sum(issubclass(r.category, UnitWarning) for r in rec) == 1  # once, not per evaluation of the law


def test_solve_finger_with_a_pressure_in_mpa_warns():
    f = Finger(_act("be-pam"))
    with pytest.warns(UnitWarning, match="MPa") as rec:
        sh = solve_finger(f, 0.15)  # meant 150 kPa: below P_start, so the finger stays straight
    assert sh.pressure_kpa == 0.15 and sh.bend_angle == pytest.approx(0.0, abs=1e-12)
    assert len(rec) == 1 and rec[0].filename == __file__  # once, and at the caller's line


def test_design_results_are_in_kpa():
    a = _act("be-pam")
    f = Finger(a)
    df, shapes = finger_sweep(f, [100.0, 150.0])
    assert df["pressure_kpa"].tolist() == [100.0, 150.0] and [sh.pressure_kpa for sh in shapes] == [100.0, 150.0]
    assert free_tip_trajectory(f, [100.0, 150.0])["pressure_kpa"].tolist() == [100.0, 150.0]
    assert df["bend_angle_deg"][1] == pytest.approx(float(bendpam.free_curvature(a, 150.0).angle_deg), rel=1e-12)
    assert stable_branch(a, 150.0).pressure_kpa == 150.0
    assert wrist_sweep(Wrist(), [150.0], (0.0,))["pressure_kpa"].tolist() == [150.0]
    # the onset pressure in the note, in kPa
    low = solve_grasp(Gripper(a), 80.0, 130.0)
    assert low.pressure_kpa == 130.0 and " kPa" in low.note
    onset = float(low.note.split("contact from ")[1].split(" kPa")[0])
    assert 130.0 < onset < 200.0  # about 178 kPa with the default (15 deg splayed) gripper


def test_no_equilibrium_is_its_own_error():
    f = Finger(_act("bc-pam"))  # above its 134 kPa fold: no free finger
    with pytest.raises(bendpam.NoEquilibrium, match="kPa"):
        tip_stiffness(f, 200.0)
    with pytest.raises(bendpam.NoEquilibrium, match="kPa"):
        linear_tip_compliance(f, 200.0)


# ------------------------------------------------------------------------------------------------
# grasp: see tests/test_grasp.py (grasp, pull-out, figure and the grasp command)
# ------------------------------------------------------------------------------------------------


# ------------------------------------------------------------------------------------------------
# wrist
# ------------------------------------------------------------------------------------------------
def test_wrist_bends_over_30_deg_in_four_directions():
    w = Wrist()  # four BC-PAMs, energy constants, L = 145 mm, frame lateral stiffness
    angles = []
    for d in (0.0, 90.0, 180.0, 270.0):
        st_ = wrist_bend(w, direction_deg=d, pressure_kpa=200.0)
        assert st_.equilibrium
        assert st_.direction_deg == pytest.approx(d, abs=1e-6)
        angles.append(st_.angle_deg)
    assert min(angles) > 30.0 and max(angles) - min(angles) < 1e-6
    # at 100 kPa it does not get there; without lateral stiffness it bends more
    assert wrist_bend(w, direction_deg=0, pressure_kpa=100.0).angle_deg < 30.0
    assert wrist_bend(Wrist(lateral_stiffness_nmm2=0.0), direction_deg=0, pressure_kpa=100.0).angle_deg > \
        wrist_bend(w, direction_deg=0, pressure_kpa=100.0).angle_deg
    # halfway between two actuators: both inflated, bends at 45 deg
    d = wrist_bend(w, direction_deg=45, pressure_kpa=150.0)
    assert d.direction_deg == pytest.approx(45.0, abs=1e-6)


def test_wrist_equilibrium_balances_the_moments():
    w = Wrist()
    st_ = wrist_bend(w, pressures_kpa=(150.0, 50.0, 0.0, 0.0))
    assert st_.equilibrium and st_.pressures_kpa == (150.0, 50.0, 0.0, 0.0)
    m, ok, _ = wrist_moment(w, st_.pressures_kpa, st_.angle_deg, st_.direction_deg)
    assert ok and np.max(np.abs(m)) < 1e-6
    # each actuator's in-plane curvature is the projection of the shared curvature
    kap, psi = st_.curvature, math.radians(st_.direction_deg)
    s = w.actuator.bend_sign
    for i, th in enumerate(np.radians(w.positions_deg)):
        assert st_.actuator_curvatures[i] == pytest.approx(s * kap * math.cos(psi - th), abs=1e-12)


def test_wrist_holds_the_bottle_horizontally():
    w = Wrist()
    h = wrist_hold(w, 150.0)  # 335 g at 100 mm
    assert h.equilibrium and h.holds_horizontal and h.angle_deg > 0.0 and h.pressure_kpa == 150.0
    assert h.capacity_g > 335.0
    assert not wrist_hold(w, 100.0).holds_horizontal
    assert 100.0 < h.pressure_needed_kpa < 150.0
    # at the needed pressure the wrist sits exactly horizontal; the capacity is consistent
    assert wrist_hold(w, h.pressure_needed_kpa).angle_deg == pytest.approx(0.0, abs=1e-6)
    assert wrist_hold(w, 150.0, load_g=h.capacity_g).angle_deg == pytest.approx(0.0, abs=1e-6)
    # the load moment at the straight wrist: W (L/2 + lever)
    assert h.load_moment_nmm == pytest.approx(335 * G_N_PER_G * (145.0 / 2 + 100.0))


def test_wrist_pressures_and_validation():
    assert wrist_pressures(90, 100.0) == (0.0, 100.0, 0.0, 0.0)
    assert wrist_pressures(315, 100.0) == (100.0, 0.0, 0.0, 100.0)
    with pytest.raises(InputError, match="direction_deg"):
        wrist_pressures(30, 100.0)
    with pytest.raises(InputError, match="radius_mm"):
        Wrist(radius_mm=-1.0)


# ------------------------------------------------------------------------------------------------
# CLI
# ------------------------------------------------------------------------------------------------
def run(capsys, *args):
    code = cli.main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_finger_json_and_plot(capsys, tmp_path):
    fig = tmp_path / "finger.png"
    code, out, err = run(capsys, "finger", "--preset", "be-pam", "--pressure-kpa", "100", "150", "200",
                         "--tip-force-n", "0,-0.5", "--tip-mass-g", "20", "--json", "--plot", str(fig))
    assert code == 0, err
    obj = json.loads(out)
    res = obj["results"]
    assert [r["pressure_kpa"] for r in res] == [100.0, 150.0, 200.0]
    for key in ("pressure_kpa", "tip_x_mm", "tip_y_mm", "tip_angle_deg", "equilibrium", "note"):
        assert key in res[0]
    assert all(r["equilibrium"] is True for r in res)
    sh = solve_finger(Finger(presets.be_pam()), 150.0, FingerLoads(tip_force_n=(0, -0.5), tip_mass_g=20))
    assert res[1]["tip_x_mm"] == pytest.approx(sh.tip_xy[0]) and res[1]["tip_angle_deg"] == pytest.approx(
        sh.tip_angle_deg)
    assert fig.read_bytes()[:4] == b"\x89PNG"


def test_cli_finger_no_equilibrium(capsys):
    code, out, err = run(capsys, "finger", "--preset", "bc-pam", "--pressure-kpa", "100,200", "--json")
    assert code == 0, err
    res = json.loads(out)["results"]
    assert res[0]["equilibrium"] is True and res[1]["equilibrium"] is False
    assert res[1]["tip_x_mm"] is None and "fold" in res[1]["note"]


def test_cli_wrist(capsys):
    code, out, err = run(capsys, "wrist", "--preset", "bc-pam", "--pressure-kpa", "150", "200", "--direction-deg",
                         "0", "90", "180", "270", "--json")
    assert code == 0, err
    obj = json.loads(out)
    angles = [r["angle_deg"] for r in obj["results"] if r["pressure_kpa"] == 200.0]
    assert len(angles) == 4 and min(angles) > 30.0
    assert [h["holds_horizontal"] for h in obj["holding"]] == [True, True]
    code, out, err = run(capsys, "wrist", "--preset", "bc-pam", "--pressure-kpa", "100")
    assert code == 0 and "holding 335 g" in out


@pytest.mark.parametrize("args,word", [
    (["finger", "--preset", "be-pam", "--pressure-kpa", "100", "--tip-force-n", "1"], "--tip-force-n"),
    (["finger", "--preset", "be-pam", "--pressure-kpa", "-5"], "below zero"),
    (["finger", "--preset", "be-pam", "--pressure-kpa", "100", "--bend", "up"], "--bend"),
    (["grasp", "--preset", "be-pam", "--pressure-kpa", "100"], "--diameter-mm"),
    (["grasp", "--preset", "be-pam", "--diameter-mm", "0", "--pressure-kpa", "100"], "positive"),
    (["grasp", "--preset", "be-pam", "--diameter-mm", "80", "--pressure-kpa", "100", "--fingers", "1"], "fingers"),
    (["wrist", "--preset", "bc-pam", "--pressure-kpa", "100", "--direction-deg", "30"], "--direction-deg 30"),
    (["finger", "--preset", "be-pam", "--pressure-kpa", "100", "--plot", "x.txt"], "--plot"),
])
def test_cli_errors_are_one_line(capsys, args, word):
    code, _out, err = run(capsys, *args)
    assert code == 2
    assert err.startswith("bendpam: error:") and err.count("\n") == 1 and word in err
