"""The gripper of :mod:`bendpam.design.grasp`: N identical fingers on a base circle, and one grasp's result.

:class:`Gripper` holds the geometry (fingers on a base circle pointing down, tilted outward by a
splay angle, a rigid tip pad, the contact surface's offset from the frame line, friction) and the
placement rule of the open gripper on a sphere (:meth:`Gripper.landing`); :class:`Grasp` is the
result of one grasp and its pull-out.  The model is described in :mod:`bendpam.design.grasp`.

Units: mm, N, kPa, degrees in names ending ``_deg``.  Bad input raises :class:`bendpam.InputError`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from bendpam.design.finger import Finger, FingerShape
from bendpam.design.parts import json_number
from bendpam.errors import InputError
from bendpam.physics.actuator import Actuator
from bendpam.physics.law import MomentLaw
from bendpam.physics.models import resolve_model
from bendpam.validate import number

if TYPE_CHECKING:
    from bendpam.design.pullout import PullOut

__all__ = [
    "DEFAULT_BASE_RADIUS_MM",
    "DEFAULT_FINGERTIP_MM",
    "DEFAULT_MU",
    "DEFAULT_SPLAY_DEG",
    "Grasp",
    "Gripper",
]

#: default base-circle radius of the fingers' frame lines, mm (see :class:`Gripper`)
DEFAULT_BASE_RADIUS_MM = 100.0
#: default rigid fingertip (tip pad) length, mm
DEFAULT_FINGERTIP_MM = 10.0
#: default outward tilt of the open fingers from the vertical, degrees (see :class:`Gripper`)
DEFAULT_SPLAY_DEG = 15.0
#: default friction coefficient pad-sphere
DEFAULT_MU = 0.5


@dataclass(frozen=True)
class Gripper:
    """An N-finger gripper of identical bending-PAM fingers (validated, immutable).

    Parameters
    ----------
    actuator : Actuator
        The finger actuator; ``L0_mm`` is the finger's active length (the paper's grippers: 130 mm,
        ``actuator.replace(L0_mm=130)``).
    model : {"energy", "force_balance"} or None
        None (default): the actuator's own model (energy when unknown); another than the actuator's warns.
    fingers : int
        Number of fingers, in [2, 12] (default 3).
    base_radius_mm : float
        Radius of the circle of the fingers' frame lines at the base, mm (default 100 mm).  The
        paper does not give its gripper's geometry; the defaults (100 mm, ``splay_deg`` 15,
        ``fingertip_mm`` 10, ``mu`` 0.5) were chosen so that three 130 mm fingers grasp the
        paper's whole 80-280 mm range: with the BE-PAM's energy constants every diameter from
        190 kPa (160-280 mm from 160 kPa, 180-280 mm at 130 kPa); the BC-PAM, only below its
        134 kPa fold, 120-180 and 240-260 mm at 130 kPa.  See docs/grasp.md.
    fingertip_mm : float
        Rigid fingertip (tip pad) length, mm (default 10).
    contact_offset_mm : float, optional
        Distance from the frame line to the finger's contact surface on the sphere's side, mm.
        Default: half the frame thickness for a BE-PAM, ``2 R0_start_mm`` for a BC-PAM.
    mu : float
        Coulomb friction coefficient pad-sphere for the pull-out, in [0, 5] (default 0.5: TPU on
        PLA).
    center_depth_mm : float, optional
        Depth of the sphere's centre below the base plane, mm.  Default: the placement rule in the
        module docstring.
    splay_deg : float
        Outward tilt of the open (straight) fingers from the vertical, degrees, in [-45, 45]
        (default 15; 0: pointing straight down).
    nodes : int
        Collocation nodes per finger (default 61).

    Examples
    --------
    The paper's gripper: three 130 mm BE-PAM fingers.

    >>> import bendpam
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> gripper.fingers, gripper.base_radius_mm, gripper.mu
    (3, 100.0, 0.5)
    """

    actuator: Actuator
    model: str | None = None
    fingers: int = 3
    base_radius_mm: float = DEFAULT_BASE_RADIUS_MM
    fingertip_mm: float = DEFAULT_FINGERTIP_MM
    contact_offset_mm: float | None = None
    mu: float = DEFAULT_MU
    center_depth_mm: float | None = None
    splay_deg: float = DEFAULT_SPLAY_DEG
    nodes: int = 61

    def __post_init__(self):
        s = object.__setattr__
        if not isinstance(self.actuator, Actuator):
            raise TypeError(f"actuator must be a bendpam.Actuator, got {type(self.actuator).__name__}")
        s(self, "model", resolve_model(self.actuator, self.model))
        nf = self.fingers
        if isinstance(nf, bool) or not isinstance(nf, int | np.integer) or not 2 <= int(nf) <= 12:
            raise InputError(f"fingers = {nf!r} is outside the allowed range [2, 12] (an integer)")
        s(self, "fingers", int(nf))
        s(self, "base_radius_mm", number("base_radius_mm", self.base_radius_mm, 0.0, 1e4, lo_open=True, unit="mm"))
        s(self, "fingertip_mm", number("fingertip_mm", self.fingertip_mm, 0.0, 1e4, unit="mm"))
        if self.contact_offset_mm is None:
            off = (self.actuator.frame_thickness_mm / 2.0 if self.actuator.bend_sign > 0
                   else 2.0 * float(self.actuator.params.R0_start))
            s(self, "contact_offset_mm", off)
        else:
            s(self, "contact_offset_mm", number("contact_offset_mm", self.contact_offset_mm, 0.0, 1e3, unit="mm"))
        s(self, "mu", number("mu", self.mu, 0.0, 5.0))
        if self.center_depth_mm is not None:
            s(self, "center_depth_mm", number("center_depth_mm", self.center_depth_mm, unit="mm"))
        s(self, "splay_deg", number("splay_deg", self.splay_deg, -45.0, 45.0, unit="deg"))
        # the finger validates nodes and the actuator
        self.finger()

    def finger(self) -> Finger:
        """One finger in its radial plane: base at ``(R_b, 0)``, pointing down (tilted outward by
        ``splay_deg``), curling toward the axis (clockwise in the plane, ``bend=-1``)."""
        offset = self.contact_offset_mm
        assert offset is not None, "set by __post_init__ before the first call"
        return Finger(self.actuator, self.model, base_xy_mm=(self.base_radius_mm, 0.0),
                      base_angle_deg=-90.0 + self.splay_deg,
                      bend=-1, fingertip_mm=self.fingertip_mm, fingertip_offset_mm=offset,
                      nodes=self.nodes)

    @property
    def law(self) -> MomentLaw:
        """The finger actuator's shared moment law under the gripper's model (:meth:`bendpam.MomentLaw.of`)."""
        return MomentLaw.of(self.actuator, self.model)

    def to_dict(self) -> dict[str, Any]:
        """The gripper as a JSON-ready dict (units in the key names), as ``bendpam grasp --json`` prints it.

        >>> import bendpam
        >>> d = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0)).to_dict()
        >>> d["fingers"], d["L0_mm"], d["contact_offset_mm"]
        (3, 130.0, 0.25)
        """
        act = self.actuator
        return {"model": self.model, "actuator": act.name or act.kind, "L0_mm": act.L0_mm, "fingers": self.fingers,
                "base_radius_mm": self.base_radius_mm, "fingertip_mm": self.fingertip_mm,
                "contact_offset_mm": self.contact_offset_mm, "mu": self.mu, "splay_deg": self.splay_deg}

    def center_depth(self, diameter_mm: float) -> float:
        """Depth of the sphere's centre below the base plane, mm (placement rule or the given value)."""
        D = number("diameter_mm", diameter_mm, 0.0, 1e5, lo_open=True, unit="mm")
        return self.landing(0.5 * D)[0]

    def landing(self, R: float) -> tuple[float, float]:
        """Placement on a sphere of radius ``R`` (mm): depth of its centre below the base plane (mm), landing angle.

        The open gripper comes down until the palm touches the top of the sphere, the lowest point of
        the straight fingers reaches the table the sphere rests on, or the open fingers' contact
        surface (frame line offset by ``contact_offset_mm``, then the pad) touches the sphere, whichever
        comes first.  In the last case the second value is the angle beta (deg) of the sphere's normal at
        the landing point from the downward vertical, else NaN.
        """
        if self.center_depth_mm is not None:
            return self.center_depth_mm, math.nan
        f = self.finger()
        p0 = f.base_angle
        t = np.array([math.cos(p0), math.sin(p0)])
        nrm = f.bend * np.array([-math.sin(p0), math.cos(p0)])  # toward the bending side (the sphere)
        sig = np.linspace(0.0, f.length + f.fingertip_mm, 801)
        pts = np.array(f.base_xy_mm)[None, :] + sig[:, None] * t[None, :] + f.fingertip_offset_mm * nrm[None, :]
        depth = -pts[:, 1]
        d = max(R, float(np.max(-(np.array(f.base_xy_mm)[1] + sig * t[1]))) - R)
        inside = np.abs(pts[:, 0]) < R
        if np.any(inside):
            cand = depth[inside] + np.sqrt(R * R - pts[inside, 0] ** 2)
            j = int(np.argmax(cand))
            if cand[j] >= d:
                px, py = pts[inside][j]
                nx, ny = px / R, (py + cand[j]) / R
                return float(cand[j]), math.degrees(math.atan2(nx, -ny))
        return d, math.nan


@dataclass(frozen=True)
class Grasp:
    """One grasp: a gripper on a sphere at one pressure, and its pull-out.

    Attributes
    ----------
    diameter_mm, pressure_kpa : sphere diameter (mm), gauge pressure (kPa).
    contact : contact at the grasp, before the pull: ``"tip"``, ``"body"``, ``"tip+body"`` or ``"none"``.
    normal_force_n : normal (contact) force per finger at the grasp, N (sum over its contacts; 0 for none).
    grip_force_n : pull-out (gripping) force of the whole gripper, N: the peak of the lifting load
        of the quasi-static pull-out (0 without contact or when the load never pulls; NaN without
        an equilibrium).
    contact_xy : contact point(s) in the finger plane at the grasp (x radial, y up), mm.
    contact_angle_deg : angle beta of the sphere's outward normal at the (main) contact from the
        downward vertical at the grasp (0: under the sphere, 90: at the equator).
    center_depth_mm : depth of the sphere's centre below the base plane at the grasp, mm.
    equilibrium : False where the finger has no stable equilibrium at the grasp (snap-through): forces NaN.
    note : why there is no contact or no equilibrium, else empty.
    shape : the finger's :class:`FingerShape` at the grasp (free or in contact), None if not computed.
    frozen_grip_force_n : the earlier estimate ``fingers * sum N (cos beta + mu sin beta)`` with the
        grasp's normal forces frozen (a labelled comparison, not the grip force), N.
    peak_lift_mm : lift of the base at the peak of the pull, mm (NaN without a pull-out).
    pull_out : the :class:`PullOut` history, None without contact.

    Examples
    --------
    >>> import bendpam
    >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
    >>> from bendpam.design.grasp import solve_grasp
    >>> grasp = solve_grasp(gripper, 180.0, 150.0)        # a 180 mm sphere at 150 kPa
    >>> grasp.contact, grasp.equilibrium, grasp.grip_force_n > 0
    ('tip', True, True)
    """

    diameter_mm: float
    pressure_kpa: float
    contact: str
    normal_force_n: float
    grip_force_n: float
    contact_xy: tuple
    contact_angle_deg: float
    center_depth_mm: float
    equilibrium: bool
    note: str
    shape: FingerShape | None = field(default=None, repr=False)
    frozen_grip_force_n: float = math.nan
    peak_lift_mm: float = math.nan
    pull_out: PullOut | None = field(default=None, repr=False)

    def to_dict(self) -> dict[str, Any]:
        """The grasp's numbers as a JSON-ready dict (units in the key names; null: not defined, no note).

        >>> import bendpam
        >>> from bendpam.design.grasp import solve_grasp
        >>> gripper = Gripper(bendpam.physics.presets.be_pam().replace(L0_mm=130.0))
        >>> d = solve_grasp(gripper, 180.0, 120.0).to_dict()
        >>> d["contact"], d["grip_force_n"], d["contact_angle_deg"], d["pull_end"]
        ('none', 0.0, None, None)
        """
        return {
            "diameter_mm": float(self.diameter_mm),
            "pressure_kpa": float(self.pressure_kpa),
            "grip_force_n": json_number(self.grip_force_n),
            "peak_lift_mm": json_number(self.peak_lift_mm),
            "frozen_grip_force_n": json_number(self.frozen_grip_force_n),
            "contact_force_n": json_number(self.normal_force_n),
            "contact": str(self.contact),
            "contact_angle_deg": json_number(self.contact_angle_deg),
            "equilibrium": bool(self.equilibrium),
            "note": str(self.note) or None,
            "pull_end": (self.pull_out.end if self.pull_out is not None else "") or None,
        }

    @classmethod
    def no_contact(cls, D: float, P: float, depth: float, note: str, shape: FingerShape | None = None,
                   equilibrium: bool = True) -> Grasp:
        """A grasp without contact (zero forces) or, with ``equilibrium=False``, without equilibrium (NaN forces)."""
        f = 0.0 if equilibrium else math.nan
        return cls(D, P, "none", f, f, (), math.nan, depth, equilibrium, note, shape, frozen_grip_force_n=f)
