r"""MJCF of a bending-PAM finger or gripper: hinge chains, masses, contact geometry, spheres.

Each bending PAM becomes a chain of ``N`` hinges along its frame line (the line of bendpam's planar
rod, :mod:`bendpam.design.rod`), each standing for a length ``h = L0 / N``: a rigid half-link of
``h/2`` at the base, ``N - 1`` links of ``h`` between the hinges, and a last half-link of ``h/2``
carrying the rigid fingertip (pad) and the site ``NAME_tip`` at the fingertip point (the point
where bendpam's finger takes its tip loads, shifted toward the bending side by the fingertip
offset).  A constant curvature ``k'`` gives every hinge the angle ``c k' h`` and puts the hinges
on the arc, so the tip angle is exact and the tip position is off by ``O((k' h)^2)``:
:func:`segments_for` picks the smallest ``N`` whose free shapes over the export's pressures are
within half the tip-error target of bendpam's rod (the other half is left to the loaded shapes
and the simulation's statics, which :mod:`bendpam.export.validation` measures).

Plane and axes: a chain's links have their local ``x`` along the frame line, ``z`` the in-plane
normal (bendpam's ``y`` rotated with the link) and ``y`` out of the plane; the hinge axis is
``(0, -1, 0)``, so a positive hinge angle turns counterclockwise in bendpam's plane (x right, y up,
MuJoCo's x-z plane for the finger).  The torques come from :class:`bendpam.sim.mujoco.PamController`
at run time; the model itself holds no spring.  Hinge ranges are the braid's lock-up curvatures.

Masses (assumptions, :class:`Densities`): the bladder tube (its wall area, rubber), the braid sleeve
(a shell of the nominal braid thickness, half filled with fibre), the frame strip and a fingertip
pad plate; end fittings and the air are left out.  Each link's inertia is a solid cylinder of the
tube's outer radius about the tube's axis, its centre of mass shifted toward the tube.

Contact: every link carries a box whose face on the bending side lies ``contact_offset_mm`` from the
frame line (the gripper's contact surface, :class:`bendpam.design.Gripper`) and that extends one
tube diameter to the other side; the pad is the same box over the fingertip, its corner the
fingertip point.  Fingers touch spheres (and the floor), never each other.

The gripper's palm is a free body that a weld holds to the mocap body ``arm``: moving the arm moves
the fingers with a velocity.  (A mocap body is moved by setting its position, without a velocity;
MuJoCo's friction is a velocity-level constraint, so fingers on a mocap palm would slide past a
sphere as if frictionless while the palm is lifted.)

MuJoCo's units are SI: lengths in m, masses in kg, torques in N*m, time in s.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from bendpam.design.finger import Finger, free_tip_trajectory
from bendpam.design.gripper import Gripper
from bendpam.design.hand import FINGERS, PARTS, Hand, finger_frame, thumb_base
from bendpam.errors import InputError
from bendpam.physics.actuator import Actuator, bladder_area_mm2
from bendpam.physics.law import MomentLaw
from bendpam.validate import number

__all__ = ["DEVICES", "HAND_CHAINS", "HAND_TIPS", "Densities", "MujocoHand", "MujocoModel", "chain_tip_xy",
           "default_pressures_kpa", "hand_model", "hand_pressures_kpa", "mujoco_model", "segments_for"]

DEVICES = ("finger", "gripper", "hand")
#: the paper's test pressures by kind (BE-PAM 100-200 kPa, BC-PAM 40-140 kPa), before the fold cap
_PAPER_RANGE_KPA = {1: (100.0, 200.0), -1: (40.0, 140.0)}
_MM = 1e-3  # mm -> m
_SEGMENTS_MAX = 200
_WELD_TIMECONST_S = 0.005  # the arm-palm weld (MuJoCo solref time constant, s)


@dataclass(frozen=True)
class Densities:
    """Material densities of the masses (kg/m^3): stated assumptions, not part of the paper.

    Parameters
    ----------
    bladder_kg_m3 : the bladder rubber (latex or silicone, default 1100).
    braid_kg_m3 : the braid fibre (PET, default 1380), over a shell of the nominal braid thickness.
    braid_fill : the fraction of that shell that is fibre (default 0.5).
    frame_kg_m3 : the frame strip (glass-fibre epoxy, default 1900).
    pad_kg_m3 : the fingertip pad (PLA, default 1240), a plate ``pad_thickness_mm`` thick.
    pad_thickness_mm : default 3 mm.

    Examples
    --------
    >>> import bendpam
    >>> round(Densities().mass_per_length_g_per_mm(bendpam.physics.presets.be_pam()), 4)   # g/mm
    0.1413
    """

    bladder_kg_m3: float = 1100.0
    braid_kg_m3: float = 1380.0
    braid_fill: float = 0.5
    frame_kg_m3: float = 1900.0
    pad_kg_m3: float = 1240.0
    pad_thickness_mm: float = 3.0

    def __post_init__(self):
        for name in ("bladder_kg_m3", "braid_kg_m3", "frame_kg_m3", "pad_kg_m3"):
            number(name, getattr(self, name), 1.0, 25000.0, unit="kg/m^3")
        number("braid_fill", self.braid_fill, 0.0, 1.0)
        number("pad_thickness_mm", self.pad_thickness_mm, 0.0, 100.0, lo_open=True, unit="mm")

    def mass_per_length_g_per_mm(self, actuator: Actuator) -> float:
        """Mass of the actuator per length of frame line, g/mm (bladder wall, braid shell, frame)."""
        a = actuator
        g_per_mm3 = 1e-6  # kg/m^3 -> g/mm^3
        bladder = float(bladder_area_mm2(a.R0_mm, a.t0_mm)) * self.bladder_kg_m3
        tb = a.braid_thickness_mm
        braid = 2.0 * math.pi * (a.R0_mm + 0.5 * tb) * tb * self.braid_fill * self.braid_kg_m3
        frame = a.frame_width_mm * a.frame_thickness_mm * self.frame_kg_m3
        return (bladder + braid + frame) * g_per_mm3


@dataclass(frozen=True)
class MujocoModel:
    """An MJCF model of a bending-PAM device and what it was built from.

    Attributes
    ----------
    xml : the MJCF text.  device : ``"finger"`` or ``"gripper"``.
    actuator, law_model : the actuator and the model of its moment law.
    segments : hinges per actuator.  chains : the chain names (``pam0``, ``pam1``, ...).
    finger : the bendpam :class:`~bendpam.design.Finger` each chain reproduces (for the gripper: one
        finger in its radial plane).  gripper : the :class:`~bendpam.design.Gripper`, or None.
    sphere_mm : the sphere's diameter (mm) placed under the gripper, or None.
    pressures_kpa : the pressures ``N`` was chosen over.
    discretisation_tip_error_pct_of_length : the chain's largest free-shape tip error there, % of L0.
    mass_g : the mass of one actuator's chain with its pad, g.

    Examples
    --------
    >>> import bendpam
    >>> m = mujoco_model(bendpam.physics.presets.be_pam(), "finger")
    >>> m.segments, m.chains, m.xml.startswith("<mujoco")
    (8, ('pam0',), True)
    """

    xml: str
    device: str
    actuator: Actuator
    law_model: str
    segments: int
    chains: tuple[str, ...]
    finger: Finger
    gripper: Gripper | None
    sphere_mm: float | None
    pressures_kpa: tuple[float, ...]
    discretisation_tip_error_pct_of_length: float
    mass_g: float
    timestep_s: float
    extra: dict[str, Any] = field(default_factory=dict, repr=False)

    def to_dict(self) -> dict[str, Any]:
        """The model's description as a JSON-ready dict (units in the key names).

        >>> import bendpam
        >>> d = mujoco_model(bendpam.physics.presets.be_pam(), "finger", segments=6).to_dict()
        >>> d["segments"], d["segment_length_mm"], d["device"]
        (6, 24.1667, 'finger')
        """
        act = self.actuator
        return {"device": self.device, "actuator": act.name or act.kind, "model": self.law_model,
                "L0_mm": act.L0_mm, "segments": self.segments,
                "segment_length_mm": round(act.L0_mm / self.segments, 4), "chains": list(self.chains),
                "pressures_kpa": list(self.pressures_kpa),
                "discretisation_tip_error_pct_of_length": round(self.discretisation_tip_error_pct_of_length, 6),
                "mass_per_actuator_g": round(self.mass_g, 4), "timestep_s": self.timestep_s,
                "sphere_mm": self.sphere_mm} | self.extra


# ------------------------------------------------------------------------------------------------
# the number of segments
# ------------------------------------------------------------------------------------------------
def chain_tip_xy(finger: Finger, curvature_per_mm, segments: int) -> np.ndarray:
    """Fingertip point (mm) of the ``segments``-hinge chain with hinge curvatures ``curvature_per_mm`` (1/mm).

    ``curvature_per_mm`` has the hinges on its last axis (or is broadcast to them); any leading axes
    are a batch.  Returns ``(..., 2)``: x and y in the finger's plane.

    >>> import bendpam
    >>> f = Finger(bendpam.physics.presets.be_pam())
    >>> chain_tip_xy(f, 0.0, 4).tolist()            # straight: L0 along +x
    [145.0, 0.0]
    """
    n = int(segments)
    h = finger.length / n
    k = np.broadcast_to(np.asarray(curvature_per_mm, dtype=float), (*np.shape(curvature_per_mm)[:-1], n)) \
        if np.ndim(curvature_per_mm) else np.full(n, float(curvature_per_mm))
    th = finger.frame_side * k * h  # hinge angles, rad
    phi = finger.base_angle + np.concatenate([np.zeros((*th.shape[:-1], 1)), np.cumsum(th, axis=-1)], axis=-1)
    lengths = np.full(n + 1, h)
    lengths[[0, -1]] = 0.5 * h
    x = finger.base_xy_mm[0] + np.sum(lengths * np.cos(phi), axis=-1)
    y = finger.base_xy_mm[1] + np.sum(lengths * np.sin(phi), axis=-1)
    pl = phi[..., -1]
    b, ell, off = finger.bend, finger.fingertip_mm, finger.fingertip_offset_mm
    return np.stack([x + ell * np.cos(pl) - b * off * np.sin(pl), y + ell * np.sin(pl) + b * off * np.cos(pl)], -1)


def default_pressures_kpa(actuator: Actuator, law_model: str | None = None, count: int = 5) -> np.ndarray:
    """The pressures (kPa) an export is checked over: the tested range, else the paper's, below the fold.

    The actuator's ``tested_pressure_kpa`` if it records one, else the paper's range for its kind
    (BE-PAM 100-200 kPa, BC-PAM 40-140 kPa); capped at 95 % of the highest pressure with a free
    shape (a fold), ``count`` pressures evenly spaced.

    >>> import bendpam
    >>> default_pressures_kpa(bendpam.physics.presets.bc_pam()).round(1).tolist()     # the fold at 134.2 kPa
    [40.0, 61.9, 83.7, 105.6, 127.5]
    """
    law = MomentLaw.of(actuator, law_model)
    tested = getattr(actuator, "tested_pressure_kpa", None)
    lo, hi = tested if tested else _PAPER_RANGE_KPA[actuator.bend_sign]
    top = 0.95 * float(law.free_branch().max_pressure_kpa)
    hi = min(hi, top)
    lo = min(lo, 0.5 * (actuator.P_start_kpa + hi))
    return np.linspace(max(lo, actuator.P_start_kpa), hi, count)


def segments_for(finger: Finger, pressures_kpa, tip_error_pct: float = 1.0) -> tuple[int, float]:
    """The fewest hinges whose free shapes at ``pressures_kpa`` (kPa) lie within half of ``tip_error_pct``.

    The error is the distance between the chain's fingertip point and bendpam's rod's (a circular
    arc of the free curvature), in % of L0, largest over the pressures.  Returns
    ``(segments, error_pct)``; at least 2 and at most 200 segments.

    >>> import bendpam
    >>> f = Finger(bendpam.physics.presets.be_pam())
    >>> n, err = segments_for(f, [100.0, 150.0, 200.0], 1.0)
    >>> n, err <= 0.5
    (8, True)
    """
    target = number("tip_error_pct", tip_error_pct, 0.0, 50.0, lo_open=True, unit="% of L0")
    k, exact = _free_tips(finger, pressures_kpa)
    if not k.size:
        raise InputError("no pressure of the export has a free shape (all above the fold): give lower pressures")
    err = math.inf
    for n in range(2, _SEGMENTS_MAX + 1):
        err = _free_error_pct(finger, k, exact, n)
        if err <= 0.5 * target:
            return n, err
    return _SEGMENTS_MAX, err


# ------------------------------------------------------------------------------------------------
# the MJCF
# ------------------------------------------------------------------------------------------------
def _fmt(*v: float) -> str:
    return " ".join(f"{x:.9g}" for x in v)


def _quat(R: np.ndarray) -> np.ndarray:
    """Unit quaternion (w, x, y, z) of a rotation matrix."""
    w = math.sqrt(max(0.0, 1.0 + R[0, 0] + R[1, 1] + R[2, 2])) / 2.0
    x = math.copysign(math.sqrt(max(0.0, 1.0 + R[0, 0] - R[1, 1] - R[2, 2])) / 2.0, R[2, 1] - R[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1.0 - R[0, 0] + R[1, 1] - R[2, 2])) / 2.0, R[0, 2] - R[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1.0 - R[0, 0] - R[1, 1] + R[2, 2])) / 2.0, R[1, 0] - R[0, 1])
    q = np.array([w, x, y, z])
    return q / np.linalg.norm(q)


def _plane_frame(azimuth: float, angle: float) -> np.ndarray:
    """Rotation whose columns are the link axes (x: along, y: out of plane, z: in-plane normal) in 3-D.

    The plane is spanned by the radial direction at ``azimuth`` and the vertical; ``angle`` (rad) is
    the in-plane direction counterclockwise from the radial one.
    """
    er = np.array([math.cos(azimuth), math.sin(azimuth), 0.0])
    ez = np.array([0.0, 0.0, 1.0])
    t = math.cos(angle) * er + math.sin(angle) * ez
    nrm = -math.sin(angle) * er + math.cos(angle) * ez
    return np.column_stack([t, np.cross(nrm, t), nrm])


def _lockup_range(finger: Finger, h: float) -> tuple[float, float]:
    lim = finger.law.limits
    a, b = sorted((finger.frame_side * float(lim.k_min) * h, finger.frame_side * float(lim.k_max) * h))
    return a, b


class _Chain:
    """Writes one actuator's chain of bodies into a parent MJCF element."""

    def __init__(self, finger: Finger, n: int, dens: Densities, contact_offset_mm: float, mu: float):
        a = finger.actuator
        self.f, self.n, self.h = finger, n, finger.length / n
        self.mpl = dens.mass_per_length_g_per_mm(a)
        self.r_out = a.R0_mm + a.braid_thickness_mm
        self.b, self.c = finger.bend, finger.frame_side
        self.off = contact_offset_mm
        self.depth = 2.0 * float(a.params.R0_start)  # contact box thickness: one tube diameter
        self.mu = mu
        self.pad_mass_g = (dens.pad_kg_m3 * 1e-6 * finger.fingertip_mm * 2.0 * self.r_out * dens.pad_thickness_mm)
        self.pad_t = dens.pad_thickness_mm
        self.range = _lockup_range(finger, self.h)

    @property
    def mass_g(self) -> float:
        return self.mpl * self.f.length + self.pad_mass_g

    def _link(self, body: ET.Element, length: float, name: str, pad: bool) -> None:
        m = self.mpl * length * 1e-3  # kg
        zc = -self.c * (self.r_out - 0.5 * self.f.actuator.frame_thickness_mm)  # tube centre from the frame line
        r = self.r_out
        ixx = 0.5 * m * (r * _MM) ** 2
        iyy = m * (3.0 * (r * _MM) ** 2 + (length * _MM) ** 2) / 12.0
        cx, cz, mass = 0.5 * length, zc, m
        I = np.array([ixx, iyy, iyy])
        if pad:  # the pad plate at the fingertip, combined (parallel axes)
            mp = self.pad_mass_g * 1e-3
            ell = self.f.fingertip_mm
            px, pz = length + 0.5 * ell, self.b * (self.off - 0.5 * self.pad_t)
            Ip = mp * np.array([(2 * r) ** 2 + self.pad_t ** 2, ell ** 2 + self.pad_t ** 2, ell ** 2 + (2 * r) ** 2]) \
                * _MM ** 2 / 12.0
            mass = m + mp
            cx, cz = (m * cx + mp * px) / mass, (m * zc + mp * pz) / mass
            d1 = np.array([(zc - cz) ** 2, (0.5 * length - cx) ** 2 + (zc - cz) ** 2, (0.5 * length - cx) ** 2])
            d2 = np.array([(pz - cz) ** 2, (px - cx) ** 2 + (pz - cz) ** 2, (px - cx) ** 2])
            I = I + m * d1 * _MM ** 2 + Ip + mp * d2 * _MM ** 2
        ET.SubElement(body, "inertial", pos=_fmt(cx * _MM, 0.0, cz * _MM), mass=f"{mass:.9g}",
                      diaginertia=_fmt(*I))
        zb = self.b * (self.off - 0.5 * self.depth)
        ET.SubElement(body, "geom", name=f"{name}_geom", type="box", pos=_fmt(0.5 * length * _MM, 0.0, zb * _MM),
                      size=_fmt(0.5 * length * _MM, r * _MM, 0.5 * self.depth * _MM), **self._contact())
        if pad and self.f.fingertip_mm > 0:
            ell = self.f.fingertip_mm
            ET.SubElement(body, "geom", name=f"{name}_pad", type="box",
                          pos=_fmt((length + 0.5 * ell) * _MM, 0.0, zb * _MM),
                          size=_fmt(0.5 * ell * _MM, r * _MM, 0.5 * self.depth * _MM),
                          **(self._contact() | {"rgba": "0.3 0.3 0.3 1"}))

    def _contact(self) -> dict[str, Any]:
        return {"contype": "1", "conaffinity": "2", "condim": "3", "friction": _fmt(self.mu, 0.005, 0.0001),
                "mass": "0", "rgba": "0.85 0.55 0.2 1"}

    def write(self, parent: ET.Element, name: str, pos_mm, R: np.ndarray) -> ET.Element:
        """The chain ``name`` as a child of ``parent`` at ``pos_mm`` (mm), link axes ``R``; returns its last body."""
        h = self.h
        body = ET.SubElement(parent, "body", name=f"{name}_base", pos=_fmt(*(np.asarray(pos_mm) * _MM)),
                             quat=_fmt(*_quat(R)))
        self._link(body, 0.5 * h, f"{name}_link0", pad=False)
        x = 0.5 * h
        for j in range(1, self.n + 1):
            last = j == self.n
            body = ET.SubElement(body, "body", name=f"{name}_link{j}", pos=_fmt(x * _MM, 0.0, 0.0))
            ET.SubElement(body, "joint", name=f"{name}_hinge{j}", type="hinge", axis="0 -1 0",
                          range=_fmt(*self.range))
            length = 0.5 * h if last else h
            self._link(body, length, f"{name}_link{j}", pad=last)
            x = length
        ell, off = self.f.fingertip_mm, self.f.fingertip_offset_mm
        ET.SubElement(body, "site", name=f"{name}_tip", pos=_fmt((0.5 * h + ell) * _MM, 0.0, self.b * off * _MM),
                      size="0.002")
        return body


def mujoco_model(actuator: Actuator, device: str = "finger", *, law_model: str | None = None,
                 segments: int | None = None, tip_error_pct: float = 1.0, pressures_kpa=None,
                 sphere_mm: float | None = None, gripper: Gripper | None = None, finger: Finger | None = None,
                 densities: Densities | None = None) -> MujocoModel:
    """The MJCF model of a finger or a gripper of ``actuator`` (see the module docstring).

    Parameters
    ----------
    actuator : Actuator
        The actuator (a preset, a TOML file's, a fit's or a design's).
    device : {"finger", "gripper"}
        ``"finger"``: one finger as :class:`bendpam.design.Finger` (base at the origin, pointing along
        +x, curling counterclockwise in the x-z plane, no fingertip unless ``finger`` says so);
        ``"gripper"``: :class:`bendpam.design.Gripper` (three fingers on a palm, a free body welded
        to the mocap body ``arm``: move ``data.mocap_pos`` to move the gripper).
    law_model : the moment law's model (None: the actuator's own).
    segments : hinges per actuator; default: :func:`segments_for` with ``tip_error_pct``.
    tip_error_pct : the tip-error target, % of L0 (default 1).
    pressures_kpa : the pressures ``segments`` is chosen over (kPa); default :func:`default_pressures_kpa`.
    sphere_mm : a sphere of this diameter (mm), fixed where the open gripper lands on it (the paper's
        pull-out test; 80-280 mm there), on a floor; gripper only.
    gripper, finger : the device's geometry, if not the default one.
    densities : :class:`Densities` (the stated default assumptions if None).

    Examples
    --------
    >>> import bendpam
    >>> m = mujoco_model(bendpam.physics.presets.be_pam().replace(L0_mm=130.0), "gripper", sphere_mm=200.0)
    >>> m.chains, m.sphere_mm, "sphere" in m.xml
    (('pam0', 'pam1', 'pam2'), 200.0, True)
    """
    if not isinstance(actuator, Actuator):
        raise InputError(f"actuator must be a bendpam.Actuator, got {type(actuator).__name__}")
    if device not in DEVICES:
        raise InputError(f"device = {device!r} is not known; choose one of {', '.join(DEVICES)}")
    if device == "hand":
        raise InputError("the hand's model is bendpam.export.mjcf.hand_model (or bendpam.export.mujoco(..., 'hand'))")
    dens = densities or Densities()
    if device == "gripper":
        gr = gripper or Gripper(actuator, law_model)
        f = gr.finger()
    else:
        if sphere_mm is not None:
            raise InputError("a sphere is an object of the gripper's grasp test; export the gripper device for it")
        gr = None
        f = finger or Finger(actuator, law_model)
    P = default_pressures_kpa(actuator, f.model) if pressures_kpa is None else np.atleast_1d(
        np.asarray(pressures_kpa, dtype=float))
    if segments is None:
        n, err = segments_for(f, P, tip_error_pct)
    else:
        n = _checked_segments(segments)
        err = _free_error_pct(f, *_free_tips(f, P), n)
    if sphere_mm is not None:
        sphere_mm = number("sphere_mm", sphere_mm, 0.0, 1e4, lo_open=True, unit="mm")
    offset = gr.contact_offset_mm if gr is not None else Gripper(actuator, f.model).contact_offset_mm
    assert offset is not None
    chain = _Chain(f, n, dens, offset, gr.mu if gr is not None else 0.5)
    dt = _timestep_s(f, chain, P)
    root = _root_element(actuator, device, n, dt)
    names = _write_device(root, chain, f, gr, sphere_mm)
    xml = ET.tostring(root, encoding="unicode")
    return MujocoModel(xml=xml, device=device, actuator=actuator, law_model=str(f.model), segments=n, chains=names,
                       finger=f, gripper=gr, sphere_mm=sphere_mm, pressures_kpa=tuple(float(p) for p in P),
                       discretisation_tip_error_pct_of_length=err, mass_g=chain.mass_g, timestep_s=dt)


def _free_tips(f: Finger, P) -> tuple[np.ndarray, np.ndarray]:
    """The free curvatures (1/mm) and bendpam's free fingertip points (mm) at the pressures with a free shape."""
    free = free_tip_trajectory(f, P)
    ok = np.isfinite(free["free_curvature_per_mm"].to_numpy())
    exact = np.stack([free["tip_x_mm"].to_numpy()[ok], free["tip_y_mm"].to_numpy()[ok]], -1)
    return free["free_curvature_per_mm"].to_numpy()[ok], exact


def _free_error_pct(f: Finger, k: np.ndarray, exact: np.ndarray, n: int) -> float:
    """The largest distance between the n-hinge chain's free tips and bendpam's, % of L0 (NaN without any)."""
    if not k.size:
        return math.nan
    tip = chain_tip_xy(f, np.repeat(k[:, None], n, axis=1), n)
    return float(np.max(np.hypot(*(tip - exact).T))) / f.length * 100.0


def _timestep_s(f: Finger, chain: _Chain, P) -> float:
    """A time step that keeps the stiffest hinge stable with the explicit law torque (a fifth of its period)."""
    table = f.law.tabulated()
    p = float(np.max(P))
    kf = f.law.free_curvature(p).curvature_per_mm
    ks = np.array([0.0, float(kf) if np.isfinite(kf) else 0.0])
    stiff = float(np.max(np.abs(table.tangent_stiffness(p, ks)))) / chain.h * 1e-3  # N*m/rad
    m = chain.mpl * chain.h * 1e-3
    inertia = m * (chain.h * _MM) ** 2 / 3.0 + 0.5 * m * (chain.r_out * _MM) ** 2
    omega = 2.0 * math.sqrt(stiff / inertia)  # the chain's fastest (alternating) mode, about
    dt = 0.2 * 2.0 * math.pi / omega / 5.0
    return float(min(1e-3, _round_down(dt)))


def _round_down(dt: float) -> float:
    """``dt`` rounded down to 1, 2 or 5 times a power of ten."""
    e = 10.0 ** math.floor(math.log10(dt))
    return max(m * e for m in (1.0, 2.0, 5.0) if m * e <= dt)


def _root_element(actuator: Actuator, device: str, n: int, dt: float) -> ET.Element:
    from bendpam.version import __version__

    root = ET.Element("mujoco", model=f"bendpam {actuator.name or actuator.kind} {device}")
    ET.SubElement(root, "compiler", angle="radian", autolimits="true")
    ET.SubElement(root, "option", timestep=f"{dt:.6g}", integrator="implicitfast", gravity="0 0 -9.80665")
    custom = ET.SubElement(root, "custom")
    ET.SubElement(custom, "text", name="bendpam:version", data=__version__)
    return root


def _write_device(root: ET.Element, chain: _Chain, f: Finger, gr: Gripper | None, sphere_mm) -> tuple[str, ...]:
    custom = root.find("custom")
    assert custom is not None
    default = ET.SubElement(root, "default")
    ET.SubElement(default, "joint", damping=_fmt(_damping(chain)), armature="0")
    world = ET.SubElement(root, "worldbody")
    ET.SubElement(world, "light", pos="0 0 1", dir="0 0 -1", directional="true")
    names: tuple[str, ...]
    if gr is None:
        names = ("pam0",)
        x0, y0 = f.base_xy_mm
        chain.write(world, "pam0", (x0, 0.0, y0), _plane_frame(0.0, f.base_angle))
    else:
        R = 0.5 * sphere_mm if sphere_mm is not None else 0.0
        depth = gr.center_depth(sphere_mm) if sphere_mm is not None else f.length + f.fingertip_mm
        palm_z = depth + R
        ET.SubElement(world, "geom", name="floor", type="plane", size="1 1 0.01", contype="2", conaffinity="1",
                      rgba="0.8 0.8 0.8 1")
        # the arm is a mocap body; the palm a free body welded to it, so that moving the arm moves the
        # fingers with a velocity (a mocap body is moved kinematically, with no velocity: its children's
        # contacts would slide past the sphere without any friction)
        ET.SubElement(world, "body", name="arm", mocap="true", pos=_fmt(0.0, 0.0, palm_z * _MM))
        palm = ET.SubElement(world, "body", name="palm", pos=_fmt(0.0, 0.0, palm_z * _MM))
        ET.SubElement(palm, "freejoint", name="palm_free")
        equality = ET.SubElement(root, "equality")
        ET.SubElement(equality, "weld", name="arm_palm", body1="palm", body2="arm",
                      solref=_fmt(_WELD_TIMECONST_S, 1.0))
        ET.SubElement(palm, "geom", name="palm_geom", type="cylinder", size=_fmt(gr.base_radius_mm * 1.1 * _MM, 0.005),
                      pos="0 0 0.005", contype="0", conaffinity="0", rgba="0.4 0.4 0.45 1")
        names = tuple(f"pam{i}" for i in range(gr.fingers))
        x0, y0 = f.base_xy_mm
        for i, nm in enumerate(names):
            az = 2.0 * math.pi * i / gr.fingers
            pos = (x0 * math.cos(az), x0 * math.sin(az), y0)
            chain.write(palm, nm, pos, _plane_frame(az, f.base_angle))
        if sphere_mm is not None:
            ET.SubElement(world, "geom", name="sphere", type="sphere", size=_fmt(R * _MM), pos=_fmt(0, 0, R * _MM),
                          contype="2", conaffinity="1", condim="3", friction=_fmt(gr.mu, 0.005, 0.0001),
                          rgba="0.2 0.5 0.8 1")
    _write_numerics(custom, {nm: chain for nm in names})
    return names


def _write_numerics(custom: ET.Element, chains: dict[str, _Chain]) -> None:
    """The ``<custom>`` numerics :class:`bendpam.sim.mujoco.PamController` reads, one pair per chain (in order)."""
    for nm, chain in chains.items():
        ET.SubElement(custom, "numeric", name=f"bendpam:{nm}:segment_length_mm", data=_fmt(chain.h))
        ET.SubElement(custom, "numeric", name=f"bendpam:{nm}:frame_side", data=str(chain.c))


def _damping(chain: _Chain) -> float:
    """Joint damping (N*m*s/rad): a tenth of critical for one link on the blocked-state stiffness."""
    table = chain.f.law.tabulated()
    stiff = abs(float(table.tangent_stiffness(200.0, 0.0))) / chain.h * 1e-3
    m = chain.mpl * chain.h * 1e-3
    inertia = m * (chain.h * _MM) ** 2 / 3.0
    return 0.2 * math.sqrt(stiff * inertia)


# ------------------------------------------------------------------------------------------------
# the hand (bendpam.design.hand)
# ------------------------------------------------------------------------------------------------
#: the hand's chains (every part but the palm roll, a hinge), in the model's order
HAND_CHAINS = tuple(p for p in PARTS if p != "palm_roll")
#: the hand's tips and the chain whose end each is
HAND_TIPS = {**{f: f for f in FINGERS}, "thumb": "thumb_distal"}
#: the palm-roll servo's stiffness: this many times the thumb's weight times its reach, per rad
_ROLL_STIFFNESS = 1000.0
_G = 9.80665
# hand frame (t, n, b) columns -> link axes (x along, y out of the plane = -b, z = n)
_LINK_AXES = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


@dataclass(frozen=True)
class MujocoHand:
    """An MJCF model of the soft hand of :mod:`bendpam.design.hand` and what it was built from.

    Attributes
    ----------
    xml : the MJCF text.  hand : the :class:`~bendpam.design.hand.Hand`.  law_model : its moment-law model.
    segments : hinges per chain (:data:`HAND_CHAINS`).  pressures_kpa : the pressures they were chosen over.
    discretisation_tip_error_pct_of_length : per chain, its largest free-shape tip error there, % of its length.
    mass_g : per chain, g.  timestep_s : the model's time step, s.
    palm_roll_deg : the fixed palm roll (deg), or None: a position-controlled hinge (actuator ``palm_roll``).
    actuator : the one actuator of every part (written to ``actuator.toml``), or None (a hand file's own).

    Examples
    --------
    >>> from bendpam.design.hand import default_hand
    >>> m = hand_model(default_hand())
    >>> m.device, m.segments["index"], m.segments["thumb_distal"], m.palm_roll_deg
    ('hand', 9, 7, None)
    """

    xml: str
    hand: Hand
    law_model: str
    segments: dict[str, int]
    pressures_kpa: tuple[float, ...]
    discretisation_tip_error_pct_of_length: dict[str, float]
    mass_g: dict[str, float]
    timestep_s: float
    palm_roll_deg: float | None = None
    actuator: Actuator | None = None
    device: str = "hand"

    def to_dict(self) -> dict[str, Any]:
        """The model's description as a JSON-ready dict (units in the key names).

        >>> from bendpam.design.hand import default_hand
        >>> d = hand_model(default_hand(), segments=6).to_dict()
        >>> d["segments"]["middle"], d["segment_length_mm"]["middle"], d["palm_roll"]
        (6, 17.5, 'position-controlled hinge')
        """
        hand = self.hand
        act = self.actuator
        return {"device": "hand", "actuator": None if act is None else act.name or act.kind, "model": self.law_model,
                "chains": list(HAND_CHAINS), "segments": dict(self.segments),
                "length_mm": {c: hand.part(c).length_mm for c in HAND_CHAINS},
                "segment_length_mm": {c: round(hand.part(c).length_mm / n, 4) for c, n in self.segments.items()},
                "pressures_kpa": list(self.pressures_kpa),
                "discretisation_tip_error_pct_of_length": {
                    c: round(e, 6) for c, e in self.discretisation_tip_error_pct_of_length.items()},
                "mass_g": {c: round(m, 4) for c, m in self.mass_g.items()}, "timestep_s": self.timestep_s,
                "palm_roll": "position-controlled hinge" if self.palm_roll_deg is None else "fixed",
                "palm_roll_deg": self.palm_roll_deg, "hand": hand.to_dict()}


def hand_pressures_kpa(hand: Hand, count: int = 3) -> np.ndarray:
    """The pressures (kPa) a hand export is checked over: from the start of the paper's (or the tested) range
    of its actuators to the hand's ``max_pressure_kpa``, capped at 95 % of the lowest fold of its parts.

    >>> from bendpam.design.hand import default_hand
    >>> hand_pressures_kpa(default_hand()).tolist()
    [100.0, 200.0, 300.0]
    """
    lo = min(float(default_pressures_kpa(p.actuator, hand.model, 2)[0]) for p in hand.parts)
    folds = [float(MomentLaw.of(p.actuator, hand.model).free_branch().max_pressure_kpa) for p in hand.parts]
    hi = min(hand.max_pressure_kpa, 0.95 * min(folds))
    return np.linspace(min(lo, 0.5 * hi), hi, count)


def hand_model(hand: Hand, *, segments: int | None = None, tip_error_pct: float = 1.0, pressures_kpa=None,
               palm_roll_deg: float | None = None, densities: Densities | None = None,
               actuator: Actuator | None = None) -> MujocoHand:
    """The MJCF model of the soft hand: a hinge chain per BE-PAM part, the palm roll a hinge.

    The model's world frame is bendpam's hand frame (x radial, y distal, z palmar; MuJoCo's m), the
    palm fixed in it, gravity along ``-z`` (the palm up; set ``model.opt.gravity`` for another
    orientation).  Each finger is a chain like the finger device's (:func:`mujoco_model`) from
    :func:`~bendpam.design.hand.finger_frame`, bending toward its ``n``; the palm roll is a hinge
    (joint and position actuator ``palm_roll``, target in rad) about the index axis carrying the
    thumb's proximal chain at :func:`~bendpam.design.hand.thumb_base`; the distal chain starts at the
    proximal one's end, its plane turned by the hand's ``thumb_plane_deg`` (as
    :func:`~bendpam.design.hand.thumb_chain`).  Each tip carries a contact sphere of the hand's
    ``radius_mm`` (``NAME_fingertip``) and a site ``NAME_tip`` (the thumb's: ``thumb_distal_tip``).

    Parameters
    ----------
    hand : the :class:`~bendpam.design.hand.Hand`.
    segments : hinges per chain (every chain); default: for each chain the fewest within half of
        ``tip_error_pct`` (% of its length) over ``pressures_kpa`` (:func:`segments_for`).
    pressures_kpa : default :func:`hand_pressures_kpa`.
    palm_roll_deg : a fixed palm roll (deg, 0 to 180) instead of the hinge.
    densities : the masses' :class:`Densities`.  actuator : the one actuator of every part, if so (for the record).

    Examples
    --------
    >>> from bendpam.design.hand import default_hand
    >>> m = hand_model(default_hand(), palm_roll_deg=90.0, segments=4)
    >>> m.palm_roll_deg, '<position' in m.xml, m.mass_g["index"] > 0
    (90.0, False, True)
    """
    if not isinstance(hand, Hand):
        raise InputError(f"hand must be a bendpam.design.hand.Hand, got {type(hand).__name__}")
    if palm_roll_deg is not None:
        palm_roll_deg = number("palm_roll_deg", palm_roll_deg, 0.0, 180.0, unit="deg")
    if pressures_kpa is None:
        P = hand_pressures_kpa(hand)
    else:
        P = np.atleast_1d(np.asarray(pressures_kpa, dtype=float))
        for p in P:  # (the range's top is the hand's max_pressure_kpa)
            number("pressures_kpa", p, 0.0, hand.max_pressure_kpa, unit="kPa")
    dens = densities or Densities()
    chains: dict[str, _Chain] = {}
    errs: dict[str, float] = {}
    for name in HAND_CHAINS:
        part = hand.part(name)
        f = Finger(part.actuator, hand.model)
        if segments is None:
            n, errs[name] = segments_for(f, P, tip_error_pct)
        else:
            n = _checked_segments(segments)
            errs[name] = _free_error_pct(f, *_free_tips(f, P), n)
        gr = Gripper(part.actuator, hand.model)
        assert gr.contact_offset_mm is not None
        chains[name] = _Chain(f, n, dens, gr.contact_offset_mm, gr.mu)
    dt = min(_timestep_s(c.f, c, P) for c in chains.values())
    root = _root_element(hand.part("index").actuator, "hand", max(c.n for c in chains.values()), dt)
    _write_hand(root, hand, chains, palm_roll_deg)
    return MujocoHand(xml=ET.tostring(root, encoding="unicode"), hand=hand, law_model=hand.model,
                      segments={c: ch.n for c, ch in chains.items()}, pressures_kpa=tuple(float(p) for p in P),
                      discretisation_tip_error_pct_of_length=errs, mass_g={c: ch.mass_g for c, ch in chains.items()},
                      timestep_s=dt, palm_roll_deg=palm_roll_deg, actuator=actuator)


def _checked_segments(segments) -> int:
    if isinstance(segments, bool) or not isinstance(segments, int | np.integer) or not 2 <= segments <= 200:
        raise InputError(f"segments = {segments!r} is outside the allowed range [2, 200] (an integer)")
    return int(segments)


def _about_y(angle: float) -> np.ndarray:
    """Rotation by ``angle`` (rad) about ``-y`` (the palm roll: +x toward +z)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])


def _write_hand(root: ET.Element, hand: Hand, chains: dict[str, _Chain], palm_roll_deg: float | None) -> None:
    """The palm, the fingers, the palm roll and the thumb into ``root`` (see :func:`hand_model`)."""
    custom = root.find("custom")
    assert custom is not None
    default = ET.SubElement(root, "default")
    ET.SubElement(default, "joint", damping=_fmt(max(_damping(c) for c in chains.values())), armature="0")
    world = ET.SubElement(root, "worldbody")
    ET.SubElement(world, "light", pos="0 0 1", dir="0 0 -1", directional="true")
    palm = ET.SubElement(world, "body", name="palm")
    r = hand.radius_mm
    xs = [xy[0] for xy in hand.finger_bases_mm.values()]
    top = min(xy[1] for xy in hand.finger_bases_mm.values())
    ET.SubElement(palm, "geom", name="palm_geom", type="box", pos=_fmt(0.5 * (min(xs) + max(xs)) * _MM,
                  0.5 * top * _MM, 0.0), size=_fmt((0.5 * (max(xs) - min(xs)) + r) * _MM, 0.5 * top * _MM, r * _MM),
                  contype="1", conaffinity="2", rgba="0.4 0.4 0.45 1")
    ends = {}
    for f in FINGERS:
        R, p = finger_frame(hand, f)
        ends[f] = chains[f].write(palm, f, p, R @ _LINK_AXES)
    axis = np.array([hand.finger_bases_mm["index"][0], 0.0, 0.0])
    roll = ET.SubElement(palm, "body", name="thumb_roll", pos=_fmt(*(axis * _MM)))
    thumb_mass = (chains["thumb_proximal"].mass_g + chains["thumb_distal"].mass_g) * 1e-3  # kg
    reach = (hand.part("thumb_proximal").length_mm + hand.part("thumb_distal").length_mm
             + math.hypot(hand.thumb_base_mm[0] - axis[0], hand.thumb_base_mm[1])) * _MM
    if palm_roll_deg is None:
        top_deg = float(hand.part("palm_roll").angle_table(hand.max_pressure_kpa)[1][-1])
        kp = _ROLL_STIFFNESS * thumb_mass * _G * reach
        inertia = thumb_mass * reach ** 2 / 3.0
        ET.SubElement(roll, "joint", name="palm_roll", type="hinge", axis="0 -1 0",
                      range=_fmt(0.0, math.radians(top_deg)), damping=_fmt(2.0 * math.sqrt(kp * inertia)))
        actuators = ET.SubElement(root, "actuator")
        ET.SubElement(actuators, "position", name="palm_roll", joint="palm_roll", kp=_fmt(kp),
                      ctrlrange=_fmt(0.0, math.radians(top_deg)))
    else:
        roll.set("quat", _fmt(*_quat(_about_y(math.radians(palm_roll_deg)))))
        ET.SubElement(custom, "numeric", name="bendpam:palm_roll_deg", data=_fmt(palm_roll_deg))
    pb, Rb = thumb_base(hand, 0.0)
    ends["thumb_proximal"] = chains["thumb_proximal"].write(roll, "thumb_proximal", pb - axis, Rb @ _LINK_AXES)
    a = math.radians(hand.thumb_plane_deg)  # the distal plane: the frame turned by -a about the tangent
    turn = np.array([[1.0, 0.0, 0.0], [0.0, math.cos(a), math.sin(a)], [0.0, -math.sin(a), math.cos(a)]])
    h1 = chains["thumb_proximal"].h
    ends["thumb_distal"] = chains["thumb_distal"].write(ends["thumb_proximal"], "thumb_distal", (0.5 * h1, 0.0, 0.0),
                                                        _LINK_AXES.T @ turn @ _LINK_AXES)
    for tip, chain in HAND_TIPS.items():
        c = chains[chain]
        ET.SubElement(ends[chain], "geom", name=f"{tip}_fingertip", type="sphere", size=_fmt(r * _MM),
                      pos=_fmt(0.5 * c.h * _MM, 0.0, 0.0), **(c._contact() | {"rgba": "0.3 0.3 0.3 1"}))
    _write_numerics(custom, chains)
