r"""The soft hand under its own weight and fingertip loads: each BE-PAM part a spatial rod.

:func:`hand_statics` poses the hand of :mod:`bendpam.design.hand` at given pressures with loads:
every finger and each thumb segment is solved as a Kirchhoff rod in three dimensions
(:func:`bendpam.design.finger3d.solve_finger3d`: the in-plane law is the paper's moment law, the
out-of-plane and twist laws those of :mod:`bendpam.physics.spatial`), in the hand frame of
:mod:`bendpam.design.hand` (x radial, y distal, z palmar; mm).

* **Fingers**: each from its base along ``+y``, bending toward ``+z``, under gravity (its own weight,
  ``mass_per_length_g_per_mm``) and its fingertip force.
* **Thumb**: two rods chained.  The palm roll is held at its free angle (the palm segment is taken
  as rigid under the thumb's load, a stated simplification).  The distal segment starts at the
  proximal one's loaded tip, its bending plane turned by ``thumb_plane_deg`` about the tangent; its
  weight and tip force reach the proximal segment as a force and a moment at the joint.  The two are
  solved in turn until the thumb tip moves less than 1e-3 mm (at most 6 rounds; the result says when
  it stopped short).

Without loads every part is the arc of its free curvature, exactly :func:`~bendpam.design.hand.hand_pose`.
The default mass per length, 0.24 g/mm, is an assumption (about 35 g for a 145 mm BE-PAM: bladder,
braid, frame and fittings; the paper gives none).

Units: kPa, mm, N, g, g/mm; gravity is a direction (normalised) in the hand frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from bendpam.design.finger import Finger
from bendpam.design.finger3d import Finger3D, FingerLoads3D, solve_finger3d
from bendpam.design.hand import FINGERS, Hand, finger_frame, hand_pose, save_result, thumb_base
from bendpam.design.parts import G_N_PER_G, checked_vector, json_number
from bendpam.errors import InputError
from bendpam.infra.accessors import figure
from bendpam.validate import did_you_mean, integer, number

__all__ = ["DEFAULT_MASS_PER_LENGTH_G_PER_MM", "HandStatics", "hand_statics"]

#: default mass per length of the hand's BE-PAMs, g/mm (an assumption: see the module docstring)
DEFAULT_MASS_PER_LENGTH_G_PER_MM = 0.24
_ROUNDS = 6
_TOL_MM = 1e-3


@dataclass(frozen=True)
class HandStatics:
    """The loaded hand: each rod's shape and the tips.

    Attributes
    ----------
    pose : the unloaded :class:`~bendpam.design.hand.HandPose` at the same pressures.
    shapes : per finger, ``"thumb_proximal"`` and ``"thumb_distal"``: the
        :class:`~bendpam.design.finger3d.Finger3DShape` (hand frame).
    tips_mm : per finger and ``"thumb"``: the loaded tip (3,), mm.
    deflection_mm : per finger and ``"thumb"``: the tip's distance from its unloaded position, mm.
    equilibrium : every rod found a stable equilibrium (and the thumb's chain converged).
    note : why not, else empty.
    gravity, mass_per_length_g_per_mm : the load case.

    Examples
    --------
    >>> from bendpam.design.hand import default_hand
    >>> st = hand_statics(default_hand(), mass_per_length_g_per_mm=0.0, nodes=11)    # no load: the free pose
    >>> st.equilibrium, max(st.deflection_mm.values()) < 1e-9
    (True, True)
    """

    pose: Any
    shapes: dict
    tips_mm: dict
    deflection_mm: dict
    equilibrium: bool
    note: str
    gravity: tuple
    mass_per_length_g_per_mm: float

    def to_dict(self) -> dict[str, Any]:
        """The loaded tips (mm), their deflections (mm) and each rod's summary, as a JSON-ready dict."""
        return {"gravity": list(self.gravity), "mass_per_length_g_per_mm": self.mass_per_length_g_per_mm,
                "equilibrium": bool(self.equilibrium), "note": self.note or None,
                "tips_mm": {k: [json_number(x) for x in v] for k, v in self.tips_mm.items()},
                "deflection_mm": {k: json_number(v) for k, v in self.deflection_mm.items()},
                "parts": {k: s.to_dict() for k, s in self.shapes.items()}}

    def plot(self, ax=None, title: str | None = None):
        """A 3-D figure: the loaded rods over the unloaded pose
        (:func:`~bendpam.present.figures.hand.plot_hand_statics`).

        >>> from bendpam.design.hand import default_hand
        >>> fig = hand_statics(default_hand(), {"ring": 150.0}, nodes=11).plot()
        >>> len(fig.axes)
        1
        """
        return figure("hand_statics")(self, ax=ax, title=title)

    def save(self, out_dir, *, figure_format: str = "png") -> dict[str, str]:
        """Write ``statics.json`` (:meth:`to_dict`) and ``statics.<format>`` into ``out_dir``; ``{name: path}``."""
        return save_result(out_dir, "statics", self.to_dict(), lambda: self.plot(), figure_format)


def _vec(v) -> tuple[float, float, float]:
    return float(v[0]), float(v[1]), float(v[2])


def _loads(gravity: np.ndarray, mpl: float, tip) -> FingerLoads3D:
    return FingerLoads3D(tip_force_n=_vec(tip), gravity=_vec(gravity), mass_per_length_g_per_mm=mpl)


def _tip_forces(hand: Hand, tip_forces_n: dict | None) -> dict[str, tuple[float, float, float]]:
    out = {}
    for name, f in dict(tip_forces_n or {}).items():
        if name not in (*FINGERS, "thumb"):
            raise InputError(f"tip_forces_n: no tip {name!r}{did_you_mean(name, (*FINGERS, 'thumb'))}; "
                             f"the tips are {', '.join((*FINGERS, 'thumb'))}")
        out[name] = checked_vector(f"tip_forces_n[{name!r}]", f, "N")
    return out


def _segment(hand: Hand, name: str, origin, R: np.ndarray, P: float, loads: FingerLoads3D, nodes: int):
    """One part as a spatial rod from ``origin`` with base frame ``R`` (columns t, n, b) in the hand frame."""
    part = hand.part(name)
    f3 = Finger3D(Finger(part.actuator, part.model, nodes=nodes), origin_mm=tuple(origin), rotation=R)
    return solve_finger3d(f3, P, loads)


def _joint_load(shape, gravity: np.ndarray, mpl: float, tip_force: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Force (N) and moment about the base (N*mm) that a loaded segment puts on whatever holds its base."""
    x = np.asarray(shape.xyz, dtype=float)
    s = np.asarray(shape.s, dtype=float)
    w = mpl * G_N_PER_G * gravity  # N/mm along the rod
    ds = np.diff(s)
    mid = 0.5 * (x[1:] + x[:-1]) - x[0]
    F = tip_force + w * float(s[-1] - s[0])
    M = np.cross(np.asarray(shape.tip_xyz) - x[0], tip_force) + np.cross(mid, w).T @ ds
    return F, M


def _thumb(hand: Hand, P: dict, ang: dict, gravity, mpl, tip_force, nodes: int):
    """The two thumb rods solved in turn (module docstring); (proximal, distal, converged)."""
    base, R0 = thumb_base(hand, ang["palm_roll"])
    turn = math.radians(hand.thumb_plane_deg)
    Rx = np.array([[1.0, 0.0, 0.0], [0.0, math.cos(turn), math.sin(turn)], [0.0, -math.sin(turn), math.cos(turn)]])
    F, M = np.zeros(3), np.zeros(3)
    tip = None
    for _ in range(_ROUNDS):
        prox = _segment(hand, "thumb_proximal", base, R0, P["thumb_proximal"],
                        FingerLoads3D(tip_force_n=_vec(F), tip_moment_nmm=_vec(M), gravity=_vec(gravity),
                                      mass_per_length_g_per_mm=mpl), nodes)
        if not prox.equilibrium:
            return prox, None, False
        d = np.asarray(prox.directors[-1])
        R1 = np.column_stack([d[:, 2], d[:, 0], d[:, 1]]) @ Rx  # (t, n, b) at the joint, the plane turned
        dist = _segment(hand, "thumb_distal", prox.tip_xyz, R1, P["thumb_distal"],
                        _loads(gravity, mpl, _vec(tip_force)), nodes)
        if not dist.equilibrium:
            return prox, dist, False
        F, M = _joint_load(dist, gravity, mpl, tip_force)
        new = np.asarray(dist.tip_xyz)
        if tip is not None and np.linalg.norm(new - tip) < _TOL_MM:
            return prox, dist, True
        tip = new
    return prox, dist, False


def hand_statics(hand: Hand, pressures_kpa: dict | None = None, *, gravity=(0.0, 0.0, -1.0),
                 mass_per_length_g_per_mm: float = DEFAULT_MASS_PER_LENGTH_G_PER_MM,
                 tip_forces_n: dict | None = None, nodes: int = 41) -> HandStatics:
    """The hand at ``pressures_kpa`` (kPa per part, as :func:`~bendpam.design.hand.hand_pose`) under its weight
    and fingertip forces: every finger and thumb segment a spatial rod (module docstring).

    Parameters
    ----------
    gravity : (gx, gy, gz)
        Direction of gravity in the hand frame (normalised; default ``-z``: palm up).
    mass_per_length_g_per_mm : float
        Mass of the BE-PAMs per length, g/mm (0: no weight).
    tip_forces_n : dict, optional
        Forces on the tips, N, hand axes: ``{"index": (Fx, Fy, Fz), ..., "thumb": (...)}``.
    nodes : int
        Collocation nodes per rod (11 to 201).

    Examples
    --------
    Palm up, the index at 200 kPa sags under its weight and a 0.2 N load on its tip; the straight middle
    finger under its weight alone:

    >>> from bendpam.design.hand import default_hand
    >>> st = hand_statics(default_hand(), {"index": 200.0}, tip_forces_n={"index": (0.0, 0.0, -0.2)})
    >>> st.equilibrium, round(st.deflection_mm["index"], 1), round(st.deflection_mm["middle"], 2)   # mm
    (True, 3.3, 1.38)
    """
    if not isinstance(hand, Hand):
        raise TypeError(f"hand must be a bendpam.design.hand.Hand, got {type(hand).__name__}")
    pose = hand_pose(hand, pressures_kpa)
    g = np.asarray(checked_vector("gravity", gravity, "direction"), dtype=float)
    if not np.linalg.norm(g) > 0:
        raise InputError("gravity = (0, 0, 0) has no direction; give a direction in the hand frame, e.g. (0, 0, -1)")
    g = g / np.linalg.norm(g)
    mpl = number("mass_per_length_g_per_mm", mass_per_length_g_per_mm, 0.0, 10.0, unit="g/mm")
    n = integer("nodes", nodes, 11, 201)
    forces = _tip_forces(hand, tip_forces_n)
    ang = {k: math.radians(v) for k, v in pose.angles_deg.items()}
    shapes, tips, defl, notes = {}, {}, {}, []
    for f in FINGERS:
        R, p = finger_frame(hand, f)
        sh = _segment(hand, f, p, R, pose.pressures_kpa[f], _loads(g, mpl, forces.get(f, (0.0, 0.0, 0.0))), n)
        shapes[f] = sh
        if not sh.equilibrium:
            notes.append(f"{f}: {sh.note}")
        tips[f] = np.asarray(sh.tip_xyz, dtype=float)
    prox, dist, ok = _thumb(hand, pose.pressures_kpa, ang, g, mpl, np.asarray(forces.get("thumb", (0.0,) * 3)), n)
    shapes["thumb_proximal"] = prox
    if dist is not None:
        shapes["thumb_distal"] = dist
    tips["thumb"] = np.asarray(dist.tip_xyz if dist is not None else (math.nan,) * 3, dtype=float)
    if not ok:
        why = [s.note for s in (prox, dist) if s is not None and not s.equilibrium]
        notes.append("thumb: " + (why[0] if why else f"the two segments did not settle in {_ROUNDS} rounds"))
    for k, t in tips.items():
        defl[k] = float(np.linalg.norm(t - pose.tips_mm[k]))
    return HandStatics(pose, shapes, tips, defl, not notes, "; ".join(notes), tuple(float(v) for v in g), mpl)
