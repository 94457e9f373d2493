"""The soft humanoid hand, its Kapandji test and the wrist in 3-D (issue 26 items 3, 4)."""

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import bendpam.design.kapandji as kapandji_module
from bendpam.cli import main
from bendpam.design.finger import Finger
from bendpam.design.finger3d import Finger3D, FingerLoads3D, solve_finger3d
from bendpam.design.hand import PARTS, Hand, arc_frames, default_hand, hand_pose, thumb_base, thumb_chain
from bendpam.design.hand_statics import hand_statics
from bendpam.design.kapandji import KAPANDJI_POINTS, hand_workspace, kapandji, kapandji_targets
from bendpam.design.wrist import Wrist, wrist_bend, wrist_hold
from bendpam.design.wrist_tilt import WristLoad, wrist_directions, wrist_map, wrist_target
from bendpam.errors import InputError
from bendpam.physics import presets
from bendpam.physics.law import MomentLaw
from bendpam.physics.limits import section_limits


def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


# ---- kinematics, by hand ----------------------------------------------------------------------
def test_one_arc_by_hand():
    # a finger at 200 kPa: the arc of the BE-PAM's free curvature from its base along +y toward +z
    hand = default_hand()
    k = float(MomentLaw.of(presets.be_pam()).free_curvature_array([200.0])[0])
    L = 95.0
    th = k * L
    pose = hand_pose(hand, {"index": 200.0})
    assert pose.angles_deg["index"] == pytest.approx(math.degrees(th), rel=1e-12)
    expect = [30.0, 105.0 + math.sin(th) / k, (1.0 - math.cos(th)) / k]
    assert pose.tips_mm["index"].tolist() == pytest.approx(expect, abs=1e-9)
    # the other fingers are straight at 0 kPa
    assert pose.tips_mm["middle"].tolist() == pytest.approx([10.0, 108.0 + 105.0, 0.0], abs=1e-12)
    # arc length along the centreline: the sampled points are L/(n-1) apart on the arc (chords a bit shorter)
    pts = pose.centrelines_mm["index"]
    chord = 2.0 / k * math.sin(k * L / (len(pts) - 1) / 2.0)
    assert np.linalg.norm(np.diff(pts, axis=0), axis=1) == pytest.approx(chord, rel=1e-9)


@given(st.floats(0.0, 3.0), st.floats(1.0, 200.0))
@settings(max_examples=30, deadline=None)
def test_arc_end_frame_is_the_tangent_and_stays_orthonormal(theta, L):
    R = np.linalg.qr(np.array([[1.0, 0.2, 0.3], [0.1, 1.0, -0.4], [0.5, 0.3, 1.0]]))[0]
    _, R1, p1 = arc_frames(R, np.zeros(3), theta, L, None)
    assert R1 @ R1.T == pytest.approx(np.eye(3), abs=1e-12)
    t = np.cos(theta) * R[:, 0] + np.sin(theta) * R[:, 1]
    assert R1[:, 0] == pytest.approx(t, abs=1e-12)
    # the chord of a circular arc: 2 sin(theta/2)/theta of its length
    assert np.linalg.norm(p1) == pytest.approx(L * (np.sinc(theta / (2 * np.pi))), rel=1e-10, abs=1e-12)


def test_thumb_composition_at_60_deg_by_hand():
    hand = default_hand()
    L1, L2 = 70.0, 70.0
    d = math.radians(35.0)
    base = np.array([52.0, 45.0, 0.0])
    t0, n0 = np.array([math.sin(d), math.cos(d), 0.0]), np.array([0.0, 0.0, 1.0])
    b0 = np.cross(t0, n0)
    # straight proximal segment, distal bent 90 deg: its plane is the proximal one's turned 60 deg (toward the palm)
    n2 = math.cos(math.radians(60)) * n0 - math.sin(math.radians(60)) * b0
    _, tip, _ = thumb_chain(hand, 0.0, math.pi / 2, 0.0)
    expect = base + L1 * t0 + L2 * 2 / math.pi * (t0 + n2)
    assert tip == pytest.approx(expect, abs=1e-9)
    # proximal bent 90 deg, distal straight: the distal segment leaves along n0
    _, tip, _ = thumb_chain(hand, math.pi / 2, 0.0, 0.0)
    assert tip == pytest.approx(base + L1 * 2 / math.pi * (t0 + n0) + L2 * n0, abs=1e-9)
    # both bent: the normals of the two bending planes meet at 60 deg
    pts, _, _ = thumb_chain(hand, 0.8, 0.8, 0.3, s_mm=[0.0, 35.0, 70.0, 105.0, 140.0])
    pts = pts[0] if pts.ndim == 3 else pts
    n_a = np.cross(pts[1] - pts[0], pts[2] - pts[1])
    n_b = np.cross(pts[3] - pts[2], pts[4] - pts[3])
    cos = abs(n_a @ n_b) / np.linalg.norm(n_a) / np.linalg.norm(n_b)
    assert math.degrees(math.acos(cos)) == pytest.approx(60.0, abs=1e-9)


def test_palm_roll_turns_the_thumb_about_the_index_axis():
    hand = default_hand()
    pose0 = hand_pose(hand)
    # the thumb's base circles the index axis (x = 30, z = 0): 22 mm radial -> 22 mm palmar at 90 deg
    _, tip90, R90 = thumb_chain(hand, 0.0, 0.0, math.pi / 2)
    line = pose0.centrelines_mm["thumb"]
    rot = np.array([[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])  # +x -> +z about the y axis
    axis = np.array([30.0, 0.0, 0.0])
    assert tip90 == pytest.approx(axis + rot @ (line[-1] - axis), abs=1e-9)
    assert R90[:, 1] == pytest.approx(rot @ np.array([-math.sin(math.radians(60)) * math.cos(math.radians(35)),
                                                      math.sin(math.radians(60)) * math.sin(math.radians(35)),
                                                      math.cos(math.radians(60))]), abs=1e-9)


def test_pressures_back_from_angles_round_trip():
    part = default_hand().part("thumb_distal")
    P = np.array([0.0, 80.0, 150.0, 290.0])
    back = part.pressure_for_angle(part.angle_deg(P), 300.0)
    assert back[0] == 0.0 and back[1:] == pytest.approx(P[1:], abs=0.05)  # kPa, interpolated on a 0.1 kPa grid


# ---- the hand file ----------------------------------------------------------------------------
def test_hand_file_round_trip_and_one_line_errors(tmp_path):
    act = tmp_path / "soft.toml"
    presets.be_pam().replace(name="soft", R0_mm=7.0).to_toml(act)
    f = tmp_path / "hand.toml"
    f.write_text('[hand]\nmax_pressure_kpa = 250\n[thumb]\nplane_deg = 45\nactuator = "soft.toml"\n'
                 "[index]\nlength_mm = 90\n")
    h = Hand.from_toml(f)
    assert (h.max_pressure_kpa, h.thumb_plane_deg, h.part("index").length_mm) == (250.0, 45.0, 90.0)
    assert h.part("thumb_distal").actuator.name == "soft" and h.part("ring").actuator.R0_mm == 8.5
    cases = {"[thumb]\nplane = 60\n": "plane", "[hands]\n": "hands", "[thumb]\nplane_deg = 200\n": "plane_deg",
             "[hand]\nmax_pressure_kpa = -3\n": "max_pressure_kpa", "[index]\nlength_mm = 'x'\n": "length_mm"}
    for text, key in cases.items():
        f.write_text(text)
        with pytest.raises(InputError) as e:
            Hand.from_toml(f)
        assert key in str(e.value) and "\n" not in str(e.value) and str(f) in str(e.value)


def test_pose_refuses_pressures_outside_the_hand_range():
    with pytest.raises(InputError, match=r"index.*300"):
        hand_pose(default_hand(), {"index": 350.0})
    with pytest.raises(InputError, match="thumb_distal"):
        hand_pose(default_hand(), {"thumb_dist": 100.0})


# ---- Kapandji ---------------------------------------------------------------------------------
def test_kapandji_targets_by_hand():
    t = kapandji_targets(default_hand())
    r = 8.5
    assert t[0].tolist() == pytest.approx([30.0 + r, 105.0 + 0.22 * 95.0, 0.0])
    assert t[3].tolist() == pytest.approx([10.0, 213.0, r])          # middle pulp
    assert t[7].tolist() == pytest.approx([-30.0, 98.0 - 15.0, r])   # the palm at the little finger's ray


def test_kapandji_reaches_a_known_point_and_reports_honestly():
    hand = default_hand()
    res = kapandji(hand, points=(4, 1), grid=6, starts=2)
    p4, p1 = res.points
    assert p4.touched_by == "tip" and p4.distance_mm <= hand.contact_tolerance_mm
    # the reported pressures give the reported distance through the kinematics (nothing forced)
    pose = hand_pose(hand, p4.pressures_kpa)
    assert np.linalg.norm(pose.tips_mm["thumb"] - np.asarray(p4.target_mm)) == pytest.approx(p4.distance_mm, abs=1e-9)
    assert set(p4.pressures_kpa) == {"thumb_proximal", "thumb_distal", "palm_roll", "middle"}
    # point 1, beside the index's proximal phalanx, is out of the default thumb's reach: said, not hidden
    assert p1.touched_by == "none" and p1.thumb_distance_mm > hand.contact_tolerance_mm
    assert p1.thumb_distance_mm <= p1.distance_mm
    d = res.to_dict()
    assert [p["number"] for p in d["points"]] == [4, 1] and d["score"] == 0
    assert {"distance_mm", "touched", "touched_by", "pressures_kpa", "target_mm"} <= set(d["points"][0])


def test_workspace_contains_the_poses():
    hand = default_hand()
    ws = hand_workspace(hand, n=4)
    P = ws.pressures_kpa
    pose = hand_pose(hand, {"thumb_proximal": P[1], "thumb_distal": P[3], "palm_roll": P[2]})
    assert ws.thumb_tips_mm[1 * 16 + 3 * 4 + 2] == pytest.approx(pose.tips_mm["thumb"], abs=1e-9)
    assert ws.to_dict()["thumb"]["hull_volume_cm3"] > 0


# ---- the hand under load (spatial rods) ---------------------------------------------------------
def test_statics_chain_the_thumb_like_one_rod_and_reduce_to_the_free_pose():
    import dataclasses

    # thumb planes at 0 deg and equal pressures: the two chained 70 mm rods are one 140 mm rod
    hand = dataclasses.replace(default_hand(), thumb_plane_deg=0.0)
    P = {"thumb_proximal": 200.0, "thumb_distal": 200.0, "palm_roll": 100.0}
    F = (0.0, 0.0, -0.3)
    st = hand_statics(hand, P, gravity=(0, 0, -1), tip_forces_n={"thumb": F}, nodes=21)
    assert st.equilibrium and st.deflection_mm["thumb"] > 5.0
    base, R0 = thumb_base(hand, math.radians(st.pose.angles_deg["palm_roll"]))
    one = Finger3D(Finger(presets.be_pam().replace(L0_mm=140.0), "energy", nodes=41), origin_mm=tuple(base),
                   rotation=R0)
    sh = solve_finger3d(one, 200.0, FingerLoads3D(tip_force_n=F, gravity=(0, 0, -1), mass_per_length_g_per_mm=0.24))
    assert np.asarray(sh.tip_xyz) == pytest.approx(st.tips_mm["thumb"], abs=2e-3)   # mm
    # no load: every rod is the free arc of the kinematics
    free = hand_statics(default_hand(), P, mass_per_length_g_per_mm=0.0, nodes=21)
    assert free.equilibrium and max(free.deflection_mm.values()) < 1e-9


# ---- the wrist in 3-D -------------------------------------------------------------------------
def test_wrist_map_reproduces_the_planar_wrist():
    w = Wrist()
    rows = [(0.0, 150.0, 0.0, 0.0), (150.0, 80.0, 0.0, 0.0), (120.0, 130.0, 0.0, 0.0)]
    m = wrist_map(w, rows)
    for i, P in enumerate(rows):
        s = wrist_bend(w, P)
        assert m.tilt_deg[i] == pytest.approx(s.angle_deg, abs=1e-7)
        assert m.direction_deg[i] == pytest.approx(s.direction_deg, abs=1e-6)
    # with a horizontal forearm and the top actuator: wrist_hold's load case, to the same tolerance
    load = WristLoad(hand_mass_g=0.0, payload_g=335.0, payload_lever_mm=100.0)
    h = wrist_hold(w, 150.0)
    assert float(wrist_map(w, [(0.0, 150.0, 0.0, 0.0)], load).tilt_deg[0]) == pytest.approx(h.angle_deg, abs=1e-7)


@given(st.floats(-0.01, 0.01), st.floats(-0.01, 0.01), st.sampled_from(["horizontal", "up", "down"]))
@settings(max_examples=25, deadline=None)
def test_load_jacobian_is_the_derivative_of_the_load_moment(bx, by, forearm):
    load = WristLoad(payload_g=550.0, forearm=forearm, up_deg=30.0)
    b = np.array([[bx, by]])
    _, J = load.moment(b, 145.0)
    h = 1e-7
    for j in range(2):
        e = np.zeros((1, 2))
        e[0, j] = h
        fd = (load.moment(b + e, 145.0)[0] - load.moment(b - e, 145.0)[0]) / (2 * h)
        assert J[0, :, j] == pytest.approx(fd[0], rel=1e-5, abs=1e-4)


def test_vertical_load_moment_by_hand():
    # near straight a hanging mass rises by |b|^2 (L^3/6 + lever L^2/2): virtual work gives
    # m = -W (L^2/3 + lever L) b (and the opposite with the hand up)
    L, lev, g = 145.0, 100.0, 550.0 * 9.80665e-3
    b = np.array([[1e-5, -2e-5]])
    for forearm, sign in (("down", -1.0), ("up", 1.0)):
        m, _ = WristLoad(hand_mass_g=0.0, payload_g=550.0, payload_lever_mm=lev, forearm=forearm).moment(b, L)
        assert m[0] == pytest.approx(sign * g * (L * L / 3.0 + lev * L) * b[0], rel=1e-5)  # O(|b| L)^2


@pytest.mark.parametrize("load", [None, WristLoad(payload_g=550.0, forearm="down")])
def test_wrist_four_directions_are_equal_for_symmetric_actuators(load):
    rows = wrist_directions(Wrist(), 140.0, load)
    tilts = [r["tilt_deg"] for r in rows]
    assert tilts == pytest.approx([tilts[0]] * 4, abs=1e-9)
    assert [r["tilt_direction_deg"] for r in rows] == pytest.approx([0.0, 90.0, 180.0, 270.0], abs=1e-9)
    need = [max(r["target"]["pressures_kpa"]) for r in rows]
    assert need == pytest.approx([need[0]] * 4, rel=1e-9)
    # the paper's 140 kPa does not reach 30 deg in this model, and the rows say which pressure does
    assert not any(r["reaches_target"] for r in rows) and all("30 deg needs" in r["note"] for r in rows)


def test_wrist_target_round_trip_and_margins():
    w = Wrist()
    load = WristLoad(payload_g=550.0)
    t = wrist_target(w, 25.0, 270.0 - 30.0, load)
    assert t.reached
    m = wrist_map(w, [t.pressures_kpa], load)
    assert float(m.tilt_deg[0]) == pytest.approx(25.0, abs=1e-6)
    assert float(m.direction_deg[0]) == pytest.approx(240.0, abs=1e-6)
    # the active actuator's margin at the end is the section limit at its pressure and curvature
    b = math.radians(25.0) / w.length_mm * np.array([math.cos(math.radians(240)), math.sin(math.radians(240))])
    i = int(np.argmax(t.pressures_kpa))
    kp = w.actuator.bend_sign * float(w.directions[i] @ b)
    ref = section_limits(w.actuator, t.pressures_kpa[i], [kp])["buckling_margin"][0]
    assert m.buckling_margin[0, i] == pytest.approx(ref, rel=1e-6)
    assert t.min_buckling_margin[i] <= m.buckling_margin[0, i] + 1e-12


# ---- the command line -------------------------------------------------------------------------
def test_cli_hand_kapandji_json(capsys, monkeypatch, tmp_path):
    fast = kapandji_module.kapandji
    monkeypatch.setattr(kapandji_module, "kapandji", lambda hand, **kw: fast(hand, grid=3, starts=1, **kw))
    code, out, err = run(capsys, "hand", "--kapandji", "--pressure-kpa", "0,0,0,0,100,200,250", "--json",
                         "--out", tmp_path / "h")
    assert code == 0, err
    d = json.loads(out)
    pts = d["kapandji"]["points"]
    assert [p["number"] for p in pts] == list(range(1, 9)) and len(KAPANDJI_POINTS) == 8
    for p in pts:
        assert isinstance(p["distance_mm"], float) and isinstance(p["touched"], bool)
        assert p["touched_by"] in ("tip", "thumb", "none") and p["touched"] == (p["touched_by"] != "none")
    assert d["pose"]["pressures_kpa"] == dict(zip(PARTS, [0.0] * 4 + [100.0, 200.0, 250.0], strict=True))
    assert sorted(p.name for p in (tmp_path / "h").iterdir()) == ["hand.json", "kapandji.png", "manifest.json",
                                                                 "pose.png"]


def test_cli_hand_refuses_in_one_line(capsys, tmp_path):
    code, _, err = run(capsys, "hand", "--pressure-kpa", "100,200")
    assert code == 2 and err.count("\n") == 1 and "--pressure-kpa" in err
    f = tmp_path / "h.toml"
    f.write_text("[thumb]\nplane_deg = 270\n")
    code, _, err = run(capsys, "hand", "--hand", f)
    assert code == 2 and err.count("\n") == 1 and "plane_deg" in err and "180" in err
    for bad in (["--gravity", "0,0,0"], ["--gravity", "1,x,0"], ["--workspace", "1"], ["--pressure-kpa", "400"]):
        code, _, err = run(capsys, "hand", *bad)
        assert code == 2 and err.count("\n") == 1 and bad[0] in err, (bad, err)


def test_cli_wrist_payload_json(capsys):
    code, out, err = run(capsys, "wrist", "--preset", "bc-pam", "--pressure-kpa", "140", "--payload-g", "550",
                         "--forearm", "down", "--json", "-q")
    assert code == 0, err
    tilt = json.loads(out)["tilt"]
    assert tilt["load"]["payload_g"] == 550.0 and tilt["load"]["hand_mass_g"] == 300.0
    rows = tilt["directions"]
    assert [r["direction_deg"] for r in rows] == [0.0, 90.0, 180.0, 270.0]
    for r in rows:
        assert r["tilt_deg"] == pytest.approx(rows[0]["tilt_deg"]) and len(r["min_buckling_margin"]) == 4
        assert r["reaches_target"] is False and r["target"]["reached"] is True
