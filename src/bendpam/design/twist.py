r"""A grasped sphere twisted about the gripper's axis: how far the fingers distort before the grip is lost.

The paper finds BE-PAM fingers "liable to be distorted under out-plane loads"; this puts a number on
it.  The grasp is :func:`bendpam.design.grasp.solve_grasp`'s (planar contact statics, each finger in
its radial plane); then a torque about the gripper's axis is put on the sphere.  Each finger's
contact resists it with a friction force ``T`` out of the finger's plane (the same on every finger,
by symmetry), and each finger is solved as a spatial rod (:func:`bendpam.design.finger3d.solve_finger3d`,
with its lateral and torsional laws and the braid's lock torque) under its contact force: the
normal force ``N`` of the grasp in the plane and ``T`` across it.

Assumptions (stated, not hidden):

* **The normal force stays the grasp's** while the sphere turns (the out-of-plane distortion changes it
  at second order; it is not re-solved) and the contact point is a dead load point on the finger.
* **Grip is lost** when ``T`` reaches the friction limit ``mu N`` (Coulomb, the gripper's ``mu``),
  or earlier if a finger has no equilibrium under ``T`` (it snaps or twists away): the torque at
  the loss is ``fingers * T * r_c`` with ``r_c`` the contact's distance from the axis.
* A body contact (on the finger's side, off the frame line) is moved onto the frame line as a force
  and a moment (a dead moment: it does not follow the section's rotation); a tip contact acts at
  the fingertip point and follows it.
* The sphere turns rigidly: its rotation is the contact point's displacement across the finger's
  plane over ``r_c``.

Units: mm, N, N*mm, kPa, degrees in names ending ``_deg``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from bendpam.design.finger3d import Finger3D, Finger3DShape, FingerLoads3D, plot_finger3d, solve_finger3d
from bendpam.design.grasp import solve_grasp
from bendpam.design.gripper import Grasp, Gripper
from bendpam.design.parts import json_number

__all__ = ["GraspTwist", "grasp_twist", "twist_grasp"]


@dataclass(frozen=True)
class GraspTwist:
    """A grasp under a twisting torque on the sphere, up to the loss of grip.

    Attributes
    ----------
    grasp : the planar :class:`~bendpam.design.gripper.Grasp` it starts from.
    contact_radius_mm : distance of the (main) contact from the gripper's axis, mm.
    lateral_compliance_mm_per_n : the contact's displacement across the finger's plane per unit friction
        force at the first step, mm/N (how easily the finger is pushed sideways).
    friction_limit_n : ``mu N`` per finger, N.
    lost_by : ``"friction"`` (the contact slips at ``mu N``), ``"finger"`` (a finger has no equilibrium
        before that) or ``"no grasp"`` (no contact or no equilibrium at the grasp).
    torque_at_loss_nmm : the twisting torque on the sphere when the grip is lost, N*mm.
    steps : one dict per load step (``fraction`` of ``mu N``, ``tangential_force_n``, ``torque_nmm``,
        ``contact_lateral_mm``, ``object_rotation_deg``, ``twist_deg``, ``out_of_plane_deg``, ``equilibrium``).
    shapes : the fingers' :class:`~bendpam.design.finger3d.Finger3DShape` at each step.

    Examples
    --------
    >>> import bendpam
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0), nodes=21)
    >>> tw = grasp_twist(gripper, 120.0, 150.0)          # a sphere too small for the fingers at 150 kPa
    >>> tw.lost_by, tw.to_dict()["torque_at_loss_nmm"]
    ('no grasp', 0.0)
    """

    grasp: Grasp
    contact_radius_mm: float
    friction_limit_n: float
    lost_by: str
    torque_at_loss_nmm: float
    steps: tuple
    shapes: tuple = field(repr=False)
    note: str = ""

    @property
    def lateral_compliance_mm_per_n(self) -> float:
        s = self.steps[0] if self.steps else {}
        return s["contact_lateral_mm"] / s["tangential_force_n"] if s and s["tangential_force_n"] else math.nan

    @property
    def at_loss(self) -> dict:
        """The last step with an equilibrium (the distortion when the grip is lost); empty without one."""
        ok = [s for s in self.steps if s["equilibrium"]]
        return ok[-1] if ok else {}

    def to_dict(self) -> dict[str, Any]:
        """The grasp, the torque at the loss of grip and the distortion there (JSON-ready, units in the names)."""
        last = self.at_loss
        return {"diameter_mm": float(self.grasp.diameter_mm), "pressure_kpa": float(self.grasp.pressure_kpa),
                "contact": self.grasp.contact, "normal_force_n": json_number(self.grasp.normal_force_n),
                "contact_radius_mm": json_number(self.contact_radius_mm),
                "friction_limit_n": json_number(self.friction_limit_n), "lost_by": self.lost_by,
                "torque_at_loss_nmm": json_number(self.torque_at_loss_nmm),
                "lateral_compliance_mm_per_n": json_number(self.lateral_compliance_mm_per_n),
                **{k: json_number(last.get(k, math.nan)) for k in (
                    "contact_lateral_mm", "object_rotation_deg", "twist_deg", "out_of_plane_deg")},
                "note": self.note or None,
                "steps": [{k: (json_number(v) if not isinstance(v, bool) else v) for k, v in s.items()}
                          for s in self.steps]}

    def plot(self, ax=None, title: str | None = None):
        """The finger at each load step in 3-D (:func:`bendpam.design.finger3d.plot_finger3d`)."""
        return plot_finger3d(list(self.shapes), ax=ax, title=title)


def _contact_loads(gripper: Gripper, grasp: Grasp, T: float) -> tuple[FingerLoads3D, np.ndarray, float, int | None]:
    """The finger's loads for the contact (normal force of the grasp, ``T`` across the plane).

    Returns the loads, the contact point (local, mm), its node (None: the fingertip point) and ``r_c``.
    """
    p = np.asarray(grasp.contact_xy[0], dtype=float)
    c = np.array([0.0, -grasp.center_depth_mm])
    n = (p - c) / np.linalg.norm(p - c)
    F = (grasp.normal_force_n * n[0], grasp.normal_force_n * n[1], T)
    if grasp.contact == "tip":
        return FingerLoads3D(tip_force_n=F), p, float(p[0]), None
    sh = grasp.shape
    assert sh is not None, "a grasp in contact has its finger's shape"
    j = int(np.argmin(np.hypot(sh.x - p[0], sh.y - p[1])))
    arm = np.array([p[0] - sh.x[j], p[1] - sh.y[j], 0.0])
    Mc = np.cross(arm, np.asarray(F))
    return (FingerLoads3D(point_forces_n=((float(sh.s[j]), F),), point_moments_nmm=((float(sh.s[j]), tuple(Mc)),)),
            p, float(p[0]), j)


def _contact_lateral(shape: Finger3DShape, grasp: Grasp, node: int | None, p) -> float:
    """Displacement of the contact point across the finger's plane, mm."""
    if node is None:
        return shape.tip_z_mm
    sh = grasp.shape
    assert sh is not None, "a grasp in contact has its finger's shape"
    arm = np.array([p[0] - sh.x[node], p[1] - sh.y[node], 0.0])
    a = sh.angle[node]
    ref = np.array([[-math.sin(a), 0.0, math.cos(a)], [math.cos(a), 0.0, math.sin(a)], [0.0, 1.0, 0.0]])
    local = ref.T @ arm  # the arm in the section's director frame at the grasp, carried by the section
    return float((shape.xyz[node] + shape.directors[node] @ local)[2])


def grasp_twist(gripper: Gripper, diameter_mm, pressure_kpa, *, fractions=(0.25, 0.5, 0.75, 1.0),
                sleeve_lock: bool = True) -> GraspTwist:
    """The grasp of a sphere (diameter mm, pressure kPa) under a twisting torque, up to the loss of grip.

    ``fractions`` of the friction limit ``mu N`` at which each finger is solved (the last is the loss
    of grip by friction unless a finger loses its equilibrium first).  ``sleeve_lock=False`` drops the
    braid's lock torque from the fingers' twist law (a sensitivity check).  See the module notes.

    >>> import bendpam
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0), nodes=21)
    >>> tw = grasp_twist(gripper, 180.0, 150.0, fractions=(1.0,))     # a 180 mm sphere at 150 kPa
    >>> tw.lost_by, round(tw.torque_at_loss_nmm), round(tw.at_loss["object_rotation_deg"], 1)   # N*mm, deg
    ('friction', 58, 3.1)
    """
    _fractions(fractions)
    return twist_grasp(gripper, solve_grasp(gripper, diameter_mm, pressure_kpa), fractions=fractions,
                       sleeve_lock=sleeve_lock)


def _fractions(fractions) -> np.ndarray:
    from bendpam.errors import InputError

    fr = np.asarray(fractions, dtype=float).ravel()
    if fr.size == 0 or not np.all((fr > 0.0) & (fr <= 1.0)) or np.any(np.diff(fr) <= 0):
        raise InputError(f"fractions = {fractions!r} must rise within (0, 1] (fractions of the friction limit)")
    return fr


def twist_grasp(gripper: Gripper, grasp: Grasp, *, fractions=(0.25, 0.5, 0.75, 1.0),
                sleeve_lock: bool = True) -> GraspTwist:
    """:func:`grasp_twist` from a grasp already solved (:func:`bendpam.design.grasp.solve_grasp` with ``gripper``).

    >>> import bendpam
    >>> from bendpam.design.grasp import solve_grasp
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0), nodes=21)
    >>> twist_grasp(gripper, solve_grasp(gripper, 100.0, 150.0)).lost_by     # too small to reach
    'no grasp'
    """
    fr = _fractions(fractions)
    if grasp.contact == "none" or not grasp.equilibrium:
        return GraspTwist(grasp, math.nan, 0.0, "no grasp", 0.0, (), (), grasp.note or "no contact")
    limit = gripper.mu * grasp.normal_force_n
    f3 = Finger3D(gripper.finger(), sleeve_lock=sleeve_lock)
    steps, shapes, lost = [], [], "friction"
    _, p, rc, node = _contact_loads(gripper, grasp, 0.0)
    for f in fr:
        T = float(f * limit)
        loads = _contact_loads(gripper, grasp, T)[0]
        sh = solve_finger3d(f3, grasp.pressure_kpa, loads)
        shapes.append(sh)
        ok = sh.equilibrium
        z = _contact_lateral(sh, grasp, node, p) if ok else math.nan
        steps.append({"fraction": float(f), "tangential_force_n": T, "torque_nmm": gripper.fingers * T * rc,
                      "contact_lateral_mm": z, "object_rotation_deg": math.degrees(math.atan2(z, rc)),
                      "twist_deg": sh.twist_deg if ok else math.nan,
                      "out_of_plane_deg": sh.out_of_plane_deg if ok else math.nan, "equilibrium": bool(ok)})
        if not ok:
            lost = "finger"
            break
    torque = steps[-1]["torque_nmm"] if lost == "friction" else \
        (steps[-2]["torque_nmm"] if len(steps) > 1 else 0.0)
    note = "" if lost == "friction" else f"a finger has no equilibrium at {steps[-1]['fraction']:.2g} of mu N: " + \
        (shapes[-1].note or "")
    return GraspTwist(grasp, rc, limit, lost, torque, tuple(steps), tuple(shapes), note)
