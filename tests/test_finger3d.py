"""The spatial finger (issue 26 item 2): bendpam.design.finger3d on the rod of bendpam.design.rod3d."""

import json
import math

import numpy as np
import pytest

from bendpam.design import Finger, FingerLoads, solve_finger
from bendpam.design.finger3d import Finger3D, FingerLoads3D, solve_finger3d
from bendpam.errors import InputError
from bendpam.physics.presets import bc_pam, be_pam
from bendpam.physics.spatial import spatial_stiffness


@pytest.mark.parametrize("act, P, loads", [
    (be_pam(), 150.0, FingerLoads(tip_force_n=(0.3, -0.5), tip_moment_nmm=5.0, tip_mass_g=10.0,
                                  mass_per_length_g_per_mm=0.05)),
    (bc_pam(), 100.0, FingerLoads(tip_force_n=(0.0, -1.0), gravity=(1.0, -1.0))),
])
def test_in_plane_loads_reproduce_the_planar_finger(act, P, loads):
    f = Finger(act, base_angle_deg=-30.0, bend=-1, fingertip_mm=12.0, fingertip_offset_mm=3.0, nodes=41)
    planar = solve_finger(f, P, loads)
    sh = solve_finger3d(Finger3D(f), P, loads)
    assert planar.equilibrium and sh.equilibrium
    L = act.L0_mm
    assert np.max(np.abs(sh.xyz[:, :2] - np.c_[planar.x, planar.y])) < 1e-6 * L
    assert np.max(np.abs(np.array(sh.tip_xyz[:2]) - planar.tip_xy)) < 1e-6 * L
    assert np.all(sh.xyz[:, 2] == 0.0) and sh.twist_deg == 0.0 and sh.out_of_plane_deg == 0.0
    np.testing.assert_allclose(sh.curvature, planar.curvature, atol=1e-9)


def test_straight_finger_is_a_cantilever_by_hand():
    # below P_start the BE-PAM is straight and has no lock torque: a linear cantilever of EI_lat and GJ
    a = be_pam()
    f3 = Finger3D(Finger(a, nodes=21))
    st = spatial_stiffness(a, 0.0, 0.0)
    EI, GJ, L = float(st.lateral_stiffness_nmm2), float(st.torsional_stiffness_nmm2_per_rad), a.L0_mm
    F = 0.01  # N: small, linear
    sh = solve_finger3d(f3, 0.0, FingerLoads3D(tip_force_n=(0.0, 0.0, F)))
    assert sh.tip_z_mm == pytest.approx(F * L ** 3 / (3.0 * EI), rel=1e-3)
    assert sh.twist_deg == pytest.approx(0.0, abs=1e-9)
    T = 1.0  # N*mm about the axis
    sh = solve_finger3d(f3, 0.0, FingerLoads3D(tip_moment_nmm=(T, 0.0, 0.0)))
    assert math.radians(sh.twist_deg) == pytest.approx(T * L / GJ, rel=1e-3)  # GJ from the rod's spline table


def test_rigid_motion_of_the_whole_problem():
    a = be_pam()
    f = Finger(a, nodes=31)
    loads = FingerLoads3D(tip_force_n=(0.2, -0.3, 0.8), tip_moment_nmm=(3.0, 0.0, -2.0))
    ref = solve_finger3d(Finger3D(f, sleeve_lock=False), 150.0, loads)
    c, s = math.cos(0.7), math.sin(0.7)
    R = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]) @ np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    o = np.array([10.0, -5.0, 3.0])
    moved = FingerLoads3D(tip_force_n=R @ loads.tip_force_n, tip_moment_nmm=R @ loads.tip_moment_nmm,
                          gravity=R @ loads.gravity)
    sh = solve_finger3d(Finger3D(f, origin_mm=o, rotation=R, sleeve_lock=False), 150.0, moved)
    np.testing.assert_allclose(sh.xyz, o + ref.xyz @ R.T, atol=1e-7)
    assert sh.twist_deg == pytest.approx(ref.twist_deg, abs=1e-7)
    assert sh.tip_z_mm == pytest.approx(ref.tip_z_mm, abs=1e-7)


def test_mirror_out_of_plane_load_and_lock():
    f3 = Finger3D(Finger(be_pam(), nodes=31))
    up = solve_finger3d(f3, 150.0, FingerLoads3D(tip_force_n=(0.0, 0.0, 2.0)))
    down = solve_finger3d(f3, 150.0, FingerLoads3D(tip_force_n=(0.0, 0.0, -2.0)))
    assert up.tip_z_mm == pytest.approx(-down.tip_z_mm, rel=1e-9)
    assert up.twist_deg == pytest.approx(-down.twist_deg, rel=1e-9, abs=1e-12)
    free = solve_finger3d(Finger3D(Finger(be_pam(), nodes=31), sleeve_lock=False), 150.0,
                          FingerLoads3D(tip_force_n=(0.0, 0.0, 2.0)))
    assert abs(free.twist_deg) > abs(up.twist_deg)  # the braid's lock holds part of the twist


def test_no_equilibrium_is_explicit():
    f3 = Finger3D(Finger(bc_pam(), nodes=11))
    sh = solve_finger3d(f3, 100.0, FingerLoads3D(tip_force_n=(0.0, 40.0, 5.0)))
    assert not sh.equilibrium and sh.note.startswith("no equilibrium")
    assert np.all(np.isnan(sh.xyz)) and sh.limit is not None and sh.limit.load_fraction < 1.0
    d = sh.to_dict()
    assert d["equilibrium"] is False and d["tip_z_mm"] is None
    json.dumps(d)


def test_results_dict_dataframe_save(tmp_path):
    sh = solve_finger3d(Finger3D(Finger(be_pam(), nodes=11)), 150.0, FingerLoads3D(tip_force_n=(0.0, 0.0, 0.5)))
    d = sh.to_dict()
    assert {"tip_z_mm", "out_of_plane_deg", "twist_deg"} <= set(d)
    assert sh.to_dataframe().shape == (11, 10)
    files = sh.save(tmp_path / "out", figures=False)  # the figure: tests of the CLI's --plot
    assert sorted(files) == ["finger3d.csv", "finger3d.json"]
    assert json.loads((tmp_path / "out" / "finger3d.json").read_text())["tip_z_mm"] == pytest.approx(d["tip_z_mm"])


def test_bad_input_is_one_line():
    with pytest.raises(InputError, match="tip_force_n"):
        FingerLoads3D(tip_force_n=(1.0, 2.0))
    with pytest.raises(InputError, match="rotation"):
        Finger3D(Finger(be_pam()), rotation=np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(InputError, match="beyond the active length"):
        solve_finger3d(Finger3D(Finger(be_pam())), 100.0, FingerLoads3D(point_forces_n=((500.0, (0, 0, 1)),)))


def test_cli_finger_forces_and_moments_in_space(capsys, tmp_path):
    from bendpam.cli import main

    fig = tmp_path / "f3.png"
    assert main(["finger", "--preset", "be-pam", "--pressure-kpa", "150", "--tip-force-n", "0,-0.5,1",
                 "--tip-moment-nmm", "10,0,-3", "--json", "--plot", str(fig)]) == 0
    res = json.loads(capsys.readouterr().out)["results"][0]
    # the force across the plane pushes the tip along +z; the moment about x twists it (beyond the lock)
    assert res["equilibrium"] and res["tip_z_mm"] > 10.0 and res["out_of_plane_deg"] > 5.0
    assert res["residual_nmm"] < 1e-6 and set(res["base_moment_nmm"]) != {0.0}
    assert fig.read_bytes()[:4] == b"\x89PNG"
    # the in-plane forms work as before, and say that the finger stays in its plane
    assert main(["finger", "--preset", "be-pam", "--pressure-kpa", "150", "--tip-force-n", "0,-0.5",
                 "--tip-moment-nmm", "-3", "--json"]) == 0
    res2 = json.loads(capsys.readouterr().out)["results"][0]
    planar = solve_finger(Finger(be_pam()), 150.0, FingerLoads(tip_force_n=(0.0, -0.5), tip_moment_nmm=-3.0))
    assert res2["tip_x_mm"] == pytest.approx(planar.tip_xy[0], rel=1e-12) and res2["tip_z_mm"] == 0.0
    assert main(["finger", "--preset", "be-pam", "--pressure-kpa", "150", "--tip-moment-nmm", "1,2"]) == 2
    assert "--tip-moment-nmm" in capsys.readouterr().err
