"""Gripper grasp and quasi-static pull-out (issue 15 item 3), the grasp figure (issue 16), ``bendpam grasp``."""

import json
import math

import numpy as np
import pytest

import bendpam.cli as cli
from bendpam import presets
from bendpam.design import Gripper, grasp_sweep, plot_grasp, solve_grasp
from bendpam.design.gripper import DEFAULT_MU, DEFAULT_SPLAY_DEG
from bendpam.design.pullout import PullOut
from bendpam.errors import InputError
from bendpam.physics.law import MomentLaw


def _act(name, L0=130.0, model="energy"):
    return presets.get(name, model).replace(L0_mm=L0)


# ------------------------------------------------------------------------------------------------
# a finger pair against a hand calculation
# ------------------------------------------------------------------------------------------------
L, ELL, R, P = 130.0, 10.0, 100.0, 200.0  # finger, pad, sphere radius (mm), pressure (kPa)


def _stiff_pair(mu):
    """Two opposed fingers, nearly rigid (an 8.25 mm frame of 450 GPa, as stiff in bending as the 5 mm frame of
    2e6 MPa this test used before the plausibility ranges), hanging straight down at x = +-R.

    The sphere (radius R) is centred on the axis at the depth of the fingertips, so the straight
    fingertips touch it exactly at its equator (beta = 90 deg), with no offset of the contact surface.
    """
    act = presets.be_pam().replace(L0_mm=L, frame_thickness_mm=8.25, frame_modulus_mpa=4.5e5)
    return act, Gripper(act, fingers=2, base_radius_mm=R, fingertip_mm=ELL, contact_offset_mm=0.0, mu=mu,
                        center_depth_mm=L + ELL, splay_deg=0.0)


def test_pull_out_of_a_finger_pair_matches_the_hand_calculation():
    """Hand calculation.

    Grasp: a straight, stiff finger of bending stiffness K (the moment law is linear in k' for the
    tiny curvatures: M(P, k') = M_b(P) - K k') carries the uniform pressure moment M_b and the
    horizontal contact force N at its pad's end, a distance a - s below the section at s
    (a = L + ell).  The tip must not move into the sphere (a propped cantilever):

        int_0^L [M_b - N (a - s)] (a - s) ds / K = 0
        =>  N0 = 3 M_b (a^2 - ell^2) / (2 (a^3 - ell^3)),   independent of K.

    Pull: the contact is at the equator (beta = 90 deg), its normal horizontal; an inextensible
    straight finger cannot follow the sphere down, so the contact slips at once and carries
    T = mu N along the vertical.  Each finger pulls with N cos(beta) + mu N sin(beta) = mu N0, and
    once the sphere has moved the fingertip is above its equator, where the surface turns away,
    the stiff finger relaxes and N falls.  So the pull-out force of the pair is

        F = 2 mu N0.
    """
    mu = 0.4
    act, g = _stiff_pair(mu)
    Mb = float(MomentLaw.of(act, "energy").blocked_moment(P))
    a = L + ELL
    N0 = 3.0 * Mb * (a ** 2 - ELL ** 2) / (2.0 * (a ** 3 - ELL ** 3))
    r = solve_grasp(g, 2.0 * R, P)
    assert r.contact == "tip" and r.equilibrium
    assert r.contact_angle_deg == pytest.approx(90.0, abs=1e-3)
    assert r.normal_force_n == pytest.approx(N0, rel=1e-3)
    assert r.grip_force_n == pytest.approx(2.0 * mu * N0, rel=1e-3)
    po = r.pull_out
    assert isinstance(po, PullOut)
    assert po.pull_force_n[0] == pytest.approx(0.0, abs=1e-6)  # no vertical load at the grasp
    assert po.state[po.peak_index, 0] == "slip" and po.peak_lift_mm < 0.01
    assert po.pull_force_n[-1] < 0.5 * po.peak_force_n  # the load falls after the peak
    # the pull-out force is linear in mu here; without friction a sphere held at its equator has no grip
    assert solve_grasp(_stiff_pair(0.8)[1], 2.0 * R, P).grip_force_n == pytest.approx(4.0 * 0.8 / 2.0 * N0, rel=1e-3)
    r0 = solve_grasp(_stiff_pair(0.0)[1], 2.0 * R, P)
    assert r0.grip_force_n == 0.0 and "never pulls" in r0.note


@pytest.fixture(scope="module")
def be_pull():
    return solve_grasp(Gripper(_act("be-pam"), fingers=2), 160.0, 250.0)


def test_stick_then_slip_obeys_coulomb(be_pull):
    r = be_pull
    g_mu = DEFAULT_MU
    po = r.pull_out
    N, T, beta, st = po.normal_force_n, po.tangential_force_n, np.radians(po.contact_angle_deg), po.state
    assert st[0, 0] == "stick" and "slip" in st[:, 0]
    stick, slip, closed = st == "stick", st == "slip", st != "open"
    # Coulomb: |T| <= mu N while sticking, |T| = mu N while slipping, the friction dragging the
    # finger down with the sphere (T < 0 along t = (-n_y, n_x) on the finger at x > 0)
    assert np.all(np.abs(T[stick]) <= g_mu * N[stick] * (1 + 1e-9) + 1e-12)
    assert np.allclose(np.abs(T[slip]), g_mu * N[slip], rtol=1e-9)
    assert np.all(T[slip] < 0) and np.all(N[closed] > 0)
    # the lifting load is the sum of the contact forces: fingers * sum (N cos beta - T sin beta)
    parts = np.where(closed, N * np.cos(beta) - T * np.sin(beta), 0.0)
    assert np.allclose(po.pull_force_n, 2 * parts.sum(axis=1), rtol=1e-9, atol=1e-12)
    # sticking loads the fingers: the load rises with the lift until the contact slips
    first_slip = int(np.argmax(slip.any(axis=1)))
    assert np.all(np.diff(po.pull_force_n[: first_slip + 1]) > 0)
    assert np.all(np.diff(po.lift_mm) > 0) and po.lift_mm[0] == 0.0
    assert r.grip_force_n == po.peak_force_n and r.peak_lift_mm == po.peak_lift_mm
    assert "peak" in po.end or "escape" in po.end
    df = po.to_dataframe()
    assert list(df.columns[:2]) == ["lift_mm", "pull_force_n"] and len(df) == po.lift_mm.size
    # the earlier frozen-normal estimate stays available as a labelled comparison
    b = math.radians(r.contact_angle_deg)
    assert r.frozen_grip_force_n == pytest.approx(2 * r.normal_force_n * (math.cos(b) + g_mu * math.sin(b)))


def test_more_friction_holds_more():
    low, high = (solve_grasp(Gripper(_act("be-pam"), fingers=2, mu=mu), 200.0, 220.0) for mu in (0.2, 0.8))
    assert high.grip_force_n > low.grip_force_n > 0


# ------------------------------------------------------------------------------------------------
# the paper's Figure 8 trends (coarse grid)
# ------------------------------------------------------------------------------------------------
DIAMETERS = [80.0, 120.0, 160.0, 200.0, 240.0, 280.0]
PRESSURES = [130.0, 250.0]


@pytest.fixture(scope="module")
def sweeps():
    """Both default grippers (130 mm fingers) on six spheres at 130 and 250 kPa."""
    return {name: grasp_sweep(Gripper(_act(name)), DIAMETERS, PRESSURES) for name in ("be-pam", "bc-pam")}


def _sizes(ds):
    return set(np.asarray(DIAMETERS)[(np.nan_to_num(ds["grip_force_n"].values) > 0).any(axis=1)])


@pytest.mark.slow  # the shared sweep of both grippers takes about 4 s
def test_default_gripper_grasps_the_papers_range(sweeps):
    g = Gripper(_act("be-pam"))
    assert g.splay_deg == DEFAULT_SPLAY_DEG == 15.0 and g.base_radius_mm == 100.0 and g.mu == 0.5
    assert _sizes(sweeps["be-pam"]) == set(DIAMETERS)  # 80-280 mm


@pytest.mark.slow  # the shared sweep of both grippers takes about 4 s
def test_be_gripper_has_the_wider_size_range(sweeps):
    assert _sizes(sweeps["bc-pam"]) < _sizes(sweeps["be-pam"])


@pytest.mark.slow  # the shared sweep of both grippers takes about 4 s
def test_be_gripper_peaks_at_an_intermediate_diameter(sweeps):
    g = sweeps["be-pam"]["grip_force_n"].sel(pressure_kpa=250.0).values
    j = int(np.argmax(g))
    assert 0 < j < len(DIAMETERS) - 1
    assert g[j] > 1.5 * g[0] and g[j] > 1.5 * g[-1]
    # the normal force still rises with the diameter; the contact turns toward the equator
    N = sweeps["be-pam"]["contact_force_n"].sel(pressure_kpa=250.0).values
    beta = sweeps["be-pam"]["contact_angle_deg"].sel(pressure_kpa=250.0).values
    assert N[-1] > N[j] and beta[-1] > beta[j] + 20.0


@pytest.mark.slow  # the shared sweep of both grippers takes about 4 s
def test_bc_gripper_grips_harder_where_it_has_an_equilibrium(sweeps):
    bc, be = sweeps["bc-pam"], sweeps["be-pam"]
    g_bc = bc["grip_force_n"].sel(pressure_kpa=130.0).values
    g_be = be["grip_force_n"].sel(pressure_kpa=130.0).values
    held = np.flatnonzero(np.nan_to_num(g_bc) > 0)
    assert held.size >= 3
    assert np.all(g_bc[held] > g_be[held])
    assert np.nanmax(g_bc) > 2.0 * np.nanmax(g_be)
    # above its 134 kPa fold the BC-PAM finger has no equilibrium where it touches: NaN, said so
    row = bc.sel(pressure_kpa=250.0)
    touched = ~np.isin(row["contact"].values, ["none"]) | ~row["equilibrium"].values
    assert touched.any()
    assert np.isnan(row["grip_force_n"].values[~row["equilibrium"].values]).all()
    assert all("snaps through" in n for n in row["note"].values[~row["equilibrium"].values])


def test_grip_is_nearly_linear_in_pressure():
    # the paper: "the grasping force is almost linear to the applied air pressure"
    P = np.array([130.0, 160.0, 190.0, 220.0, 250.0])
    g = grasp_sweep(Gripper(_act("be-pam")), [200.0], P)["grip_force_n"].values[0]
    assert np.all(np.diff(g) > 0)
    assert np.corrcoef(P, g)[0, 1] ** 2 > 0.99


@pytest.mark.parametrize("name,D,P", [("be-pam", 120.0, 220.0), ("be-pam", 200.0, 130.0), ("bc-pam", 160.0, 130.0)])
def test_contact_state_is_consistent(name, D, P):
    g = Gripper(_act(name))
    r = solve_grasp(g, D, P)
    assert r.pressure_kpa == P
    assert r.equilibrium and r.contact in ("tip", "body", "tip+body") and r.normal_force_n > 0
    depth = g.center_depth(D)
    R = D / 2
    sh = r.shape
    # the contact point lies on the sphere; no part of the finger penetrates it
    for px, py in r.contact_xy:
        assert math.hypot(px, py + depth) == pytest.approx(R, abs=1e-6)
    gaps = np.hypot(sh.x, sh.y + depth) - (R + g.contact_offset_mm)
    assert gaps.min() > -1e-3
    assert sh.residual_nmm < 1e-4
    # the pull starts from this grasp: same normal force, no friction yet
    po = r.pull_out
    assert po.normal_force_n[0].sum() == pytest.approx(r.normal_force_n, rel=1e-9)
    assert np.all(po.tangential_force_n[0] == 0.0)
    assert r.grip_force_n >= po.pull_force_n[0] and r.grip_force_n > 0


@pytest.mark.slow  # the shared sweep of both grippers takes about 4 s
def test_grip_rises_with_pressure(sweeps):
    for ds in sweeps.values():
        g = ds["grip_force_n"].values
        both = np.all(np.nan_to_num(g) > 0, axis=1)
        assert np.all(g[both, 1] > g[both, 0])


# ------------------------------------------------------------------------------------------------
# no contact, no equilibrium, validation
# ------------------------------------------------------------------------------------------------
def test_no_contact_and_no_equilibrium_are_reported():
    g = Gripper(_act("be-pam"))
    big, small, low = solve_grasp(g, 400.0, 250.0), solve_grasp(g, 10.0, 250.0), solve_grasp(g, 80.0, 130.0)
    for r in (big, small, low):
        assert r.contact == "none" and r.grip_force_n == 0.0 and r.equilibrium and r.pull_out is None
        assert math.isnan(r.peak_lift_mm)
    assert "too large" in big.note and "too small" in small.note and "from" in low.note
    r = solve_grasp(Gripper(_act("bc-pam")), 160.0, 200.0)  # above the BC-PAM's fold
    assert not r.equilibrium and math.isnan(r.grip_force_n) and r.pull_out is None and "snaps through" in r.note


def test_gripper_validation():
    a = _act("be-pam")
    with pytest.raises(InputError, match="fingers"):
        Gripper(a, fingers=1)
    with pytest.raises(InputError, match="mu"):
        Gripper(a, mu=-0.1)
    with pytest.raises(InputError, match="splay_deg"):
        Gripper(a, splay_deg=60.0)
    with pytest.raises(InputError, match="diameter_mm"):
        solve_grasp(Gripper(a), -5.0, 200.0)
    with pytest.raises(TypeError, match="Gripper"):
        solve_grasp(a, 100.0, 200.0)


# ------------------------------------------------------------------------------------------------
# the figure: gaps where there is no contact or no equilibrium
# ------------------------------------------------------------------------------------------------
def _fake_sweep():
    import xarray as xr

    D = np.array([80.0, 120.0, 160.0, 200.0])
    P = np.array([130.0, 250.0])
    grip = np.array([[0.0, 1.0], [2.0, 3.0], [0.0, np.nan], [1.5, 2.5]])
    contact = np.array([["none", "tip"], ["tip", "body"], ["tip", "none"], ["tip", "tip"]])
    eq = np.array([[True, True], [True, True], [True, False], [True, True]])
    dims = ("diameter_mm", "pressure_kpa")
    return xr.Dataset({"grip_force_n": (dims, grip), "contact": (dims, contact), "equilibrium": (dims, eq)},
                      coords={"diameter_mm": D, "pressure_kpa": P}, attrs={"fingers": 3, "actuator": "BE-PAM"})


def test_plot_leaves_gaps_where_there_is_no_contact(tmp_path):
    from bendpam.present.figures import SINGLE_COLUMN_IN, save_figure

    fig = plot_grasp(_fake_sweep())
    ax = fig.axes[0]
    lines = [ln for ln in ax.get_lines() if ln.get_label().endswith("kPa")]
    assert [ln.get_label() for ln in lines] == ["130 kPa", "250 kPa"]
    y130, y250 = (np.asarray(ln.get_ydata(), float) for ln in lines)
    # 'no contact' is a gap (NaN: matplotlib draws neither a point nor a line through it), not 0 N
    assert np.isnan(y130[0]) and y130[1] == 2.0 and y130[2] == 0.0  # a contact that holds nothing stays 0
    assert np.isnan(y250[2]) and y250[1] == 3.0  # no equilibrium: a gap too
    assert len({ln.get_marker() for ln in lines}) == 2  # distinct markers
    assert fig.get_size_inches()[0] == pytest.approx(SINGLE_COLUMN_IN)
    out = tmp_path / "grasp.png"
    save_figure(fig, out)
    assert out.read_bytes()[:4] == b"\x89PNG"


# ------------------------------------------------------------------------------------------------
# bendpam grasp
# ------------------------------------------------------------------------------------------------
def run(capsys, *args):
    code = cli.main(list(args))
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_grasp_reports_the_pull_out_force(capsys, tmp_path):
    fig = tmp_path / "grasp.png"
    code, out, err = run(capsys, "grasp", "--preset", "be-pam", "--l0-mm", "130", "--diameter-mm", "80", "200",
                         "400", "--pressure-kpa", "130", "250", "--json", "--plot", str(fig))
    assert code == 0, err
    obj = json.loads(out)
    assert obj["splay_deg"] == DEFAULT_SPLAY_DEG and obj["mu"] == DEFAULT_MU and "pull-out" in obj["units"][
        "grip_force_n"]
    res = obj["results"]
    assert len(res) == 6
    by = {(r["diameter_mm"], r["pressure_kpa"]): r for r in res}
    for key in ("grip_force_n", "peak_lift_mm", "frozen_grip_force_n", "pull_end", "contact_force_n", "contact"):
        assert key in res[0]
    none = by[(400.0, 250.0)]
    assert none["contact"] == "none" and none["grip_force_n"] == 0.0 and none["peak_lift_mm"] is None
    assert by[(80.0, 130.0)]["contact"] == "none"
    ref = solve_grasp(Gripper(_act("be-pam")), 200.0, 250.0)
    assert by[(200.0, 250.0)]["grip_force_n"] == pytest.approx(ref.grip_force_n, rel=1e-9)
    assert by[(200.0, 250.0)]["peak_lift_mm"] == pytest.approx(ref.peak_lift_mm)
    assert by[(200.0, 250.0)]["grip_force_n"] > by[(200.0, 130.0)]["grip_force_n"] > 0
    assert fig.read_bytes()[:4] == b"\x89PNG"


def test_cli_grasp_table(capsys):
    code, out, err = run(capsys, "grasp", "--preset", "bc-pam", "--l0-mm", "130", "--diameter-mm", "160",
                         "--pressure-kpa", "130,200", "--mu", "0.6", "--splay-deg", "10")
    assert code == 0, err
    lines = out.splitlines()
    assert "pull-out" in lines[0] and "mu = 0.6" in lines[0] and "splay 10°" in lines[0]
    assert "grip (N)" in lines[1] and "frozen (N)" in lines[1]
    rows = lines[2:]
    assert rows[0].split()[:2] == ["160", "130"] and float(rows[0].split()[2]) > 0
    assert "snaps through" in rows[1]


@pytest.mark.parametrize("args,word", [
    (["--mu", "-1"], "mu"),
    (["--splay-deg", "80"], "--splay-deg 80"),
    (["--fingers", "1"], "fingers"),
])
def test_cli_grasp_bad_option_is_one_line(capsys, args, word):
    code, _out, err = run(capsys, "grasp", "--preset", "be-pam", "--diameter-mm", "100", "--pressure-kpa", "150",
                          *args)
    assert code == 2
    assert err.startswith("bendpam: error:") and err.count("\n") == 1 and word in err
