r"""Quasi-static MuJoCo runs of an export against bendpam's planar rod and its pull-out.

Each run is a copy of the exported model made quasi-static: gravity off (bendpam's finger and grasp
statics are weightless), a 1 ms step, and a joint damping that makes every hinge overdamped
(at least three times ``sqrt(K I)`` with ``K`` the blocked-state hinge stiffness and ``I`` the
hinge's diagonal inertia, and at least ``2 K dt``), so that after a pressure ramp the chain creeps
into its equilibrium; a run ends when ``max |qvel|`` is below :data:`QVEL_TOL`.  The torques are
those of :class:`bendpam.sim.mujoco.PamController`, as in any simulation of the export.

* **Free shape**: the pressures of the export in ascending order (a ramp of 100 steps to each, then
  the creep); the fingertip point (site ``pam0_tip``) against :func:`bendpam.design.finger.free_tip_trajectory`.
* **Loaded shape**: at the highest pressure, a tip force at the fingertip point against the bending
  (its moment about the base a quarter of the blocked moment, unless given), ramped over 100 steps,
  against :func:`bendpam.design.finger.solve_finger`.
* **Pull-out** (gripper): the fingers close on the fixed sphere frictionless (as bendpam's grasp
  statics; no table, which bendpam's grasp has only for the landing), then the friction is switched
  to the gripper's ``mu`` (elliptic cones, MuJoCo's no-slip pass) and the arm (the mocap body the
  palm is welded to) is lifted 0.005 mm per 0.5 ms step (10 mm/s; a shorter step than the other
  runs', for stiffer contacts); the grip force is the peak upward force of the fingers on the
  sphere, averaged over 0.2 mm of lift, against :func:`bendpam.design.grasp.solve_grasp`.

Errors: tip errors as the distance between the tips in % of L0, the pull-out error in % of
bendpam's grip force.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from bendpam.design.finger import FingerLoads, free_tip_trajectory, solve_finger
from bendpam.design.grasp import solve_grasp
from bendpam.design.hand import PARTS, Hand, default_hand, hand_pose, thumb_chain
from bendpam.errors import InputError
from bendpam.export.mjcf import HAND_CHAINS, HAND_TIPS, MujocoHand, MujocoModel, hand_model, mujoco_model
from bendpam.physics import presets
from bendpam.physics.actuator import Actuator
from bendpam.physics.hysteresis import LoopModel
from bendpam.physics.models import normalise_model, resolve_model
from bendpam.sim.mujoco import PamController, import_mujoco
from bendpam.validate import did_you_mean, number

__all__ = ["QVEL_TOL", "HandController", "HandValidation", "MujocoExport", "Validation", "hand_poses_kpa", "mujoco",
           "pullout", "validate", "validate_hand"]

#: a quasi-static run has settled when every hinge turns slower than this, rad/s
QVEL_TOL = 1e-6
_DT = 1e-3
_RAMP = 100
_CREEP = 4000
_PULL_DT = 5e-4  # the pull-out's time step, s (its contacts are the stiffer for it: see _Run)
_LIFT_MM = 0.005  # lift per step of the pull-out, mm (10 mm/s)
_SMOOTH_MM = 0.2  # the pull-out force is averaged over this much lift, mm
_GONE_MM = 2.0  # the pull-out ends when the sphere has been let go (or the load halved) for this much lift, mm


@dataclass(frozen=True)
class Validation:
    """The figures of :func:`validate` (tip errors in % of L0, pull-out error in % of bendpam's force).

    Attributes
    ----------
    free : one dict per pressure (``pressure_kpa``, the tips of both, ``tip_error_pct_of_length``,
        ``bend_angle_error_deg``, ``settled``).
    free_shape_tip_error_pct_of_length : the largest free-shape tip error.
    loaded : the loaded case (pressure, tip force, tips, error, settled).
    loaded_tip_error_pct_of_length : its tip error.
    pullout : the pull-out case (diameter, pressure, both grip forces, error), None for a finger.
    gripper_pullout_error_pct : MuJoCo's grip force against bendpam's, %, None for a finger.

    Examples
    --------
    >>> v = Validation([], 0.1, {}, 0.2)
    >>> v.to_dict()["loaded_tip_error_pct_of_length"]
    0.2
    """

    free: list[dict[str, Any]]
    free_shape_tip_error_pct_of_length: float
    loaded: dict[str, Any]
    loaded_tip_error_pct_of_length: float
    pullout: dict[str, Any] | None = None
    gripper_pullout_error_pct: float | None = None
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """The figures as a JSON-ready dict (units in the key names)."""
        return {"free_shape_tip_error_pct_of_length": _r(self.free_shape_tip_error_pct_of_length),
                "loaded_tip_error_pct_of_length": _r(self.loaded_tip_error_pct_of_length),
                "gripper_pullout_error_pct": None if self.gripper_pullout_error_pct is None
                else _r(self.gripper_pullout_error_pct),
                "free": self.free, "loaded": self.loaded, "pullout": self.pullout, "notes": self.notes}


def _r(v: float) -> float | None:
    return None if v is None or not math.isfinite(v) else round(float(v), 6)


class _Run:
    """A quasi-static copy of an exported model with its controller (``make_controller(model)``).

    ``stiffness`` (N*m/rad, one for all hinges or one per hinge of the controller) sets the damping.
    """

    def __init__(self, xml: str, make_controller, stiffness, dt: float = _DT):
        mj = import_mujoco()
        self.mj = mj
        self.m = mj.MjModel.from_xml_string(xml)
        self.d = mj.MjData(self.m)
        m = self.m
        m.opt.gravity[:] = 0.0
        m.opt.timestep = dt
        m.opt.cone = mj.mjtCone.mjCONE_ELLIPTIC
        m.opt.impratio = 10.0
        m.opt.noslip_iterations = 10
        m.opt.tolerance = 1e-12  # (the default 1e-8 leaves the weld-held palm creeping at 1e-5 rad/s)
        m.geom_solref[:] = [2 * dt, 1.0]  # the stiffest contact MuJoCo allows at this step
        mj.mj_forward(m, self.d)
        full = np.zeros((m.nv, m.nv))
        mj.mj_fullM(m, self.d, full)
        self.ctl = make_controller(m)
        pam = getattr(self.ctl, "pam", self.ctl)  # (a HandController holds its PamController)
        hinges = pam._dof_ix
        if callable(stiffness):
            stiffness = stiffness(self.ctl)
        self.diag_inertia = np.diag(full)
        m.dof_damping[hinges] = np.maximum(3.0 * np.sqrt(stiffness * self.diag_inertia[hinges]), 2.0 * dt * stiffness)
        self.P = 0.0

    @classmethod
    def of(cls, exported: MujocoModel, dt: float = _DT) -> _Run:
        """The run of a finger or gripper export (every hinge damped for its blocked-state stiffness)."""
        f = exported.finger
        h = f.length / exported.segments
        k_stiff = abs(float(f.law.tabulated().tangent_stiffness(float(max(exported.pressures_kpa)), 0.0))) / h * 1e-3
        return cls(exported.xml, lambda m: PamController(m, exported.actuator, law_model=exported.law_model),
                   k_stiff, dt)

    def step(self) -> None:
        self.ctl.apply(self.d)
        self.mj.mj_step(self.m, self.d)

    def ramp_to(self, pressure_kpa: float, steps: int = _RAMP) -> bool:
        """Ramp the pressure linearly, then creep until settled; returns whether it settled."""
        p0 = self.P
        for i in range(steps):
            self.ctl.set_pressure_kpa(p0 + (pressure_kpa - p0) * (i + 1) / steps)
            self.step()
        self.P = pressure_kpa
        return self.creep()

    def creep(self, before=None) -> bool:
        for _ in range(_CREEP):
            if before is not None:
                before()
            self.step()
            if float(np.max(np.abs(self.d.qvel))) < QVEL_TOL:
                return True
        return False

    def site(self, name: str) -> np.ndarray:
        mj = self.mj
        self.mj.mj_forward(self.m, self.d)
        return self.d.site_xpos[mj.mj_name2id(self.m, mj.mjtObj.mjOBJ_SITE, name)] * 1e3


@contextlib.contextmanager
def _mujoco_warnings() -> Iterator[list[str]]:
    """Collect MuJoCo's warnings (for the notes) instead of letting it write MUJOCO_LOG.TXT in the working folder."""
    mj = import_mujoco()
    old = mj.get_mju_user_warning()
    seen: list[str] = []
    mj.set_mju_user_warning(lambda msg: seen.append(" ".join(str(msg).split())))
    try:
        yield seen
    finally:
        mj.set_mju_user_warning(old)


def _tip_error(tip_mm: np.ndarray, exact_xy, L: float) -> float:
    return float(math.hypot(tip_mm[0] - exact_xy[0], tip_mm[2] - exact_xy[1])) / L * 100.0


def _free_runs(run: _Run, exported: MujocoModel, P: np.ndarray) -> list[dict[str, Any]]:
    f = exported.finger
    exact = free_tip_trajectory(f, P)
    rows = []
    for p in np.sort(P):
        j = int(np.flatnonzero(exact["pressure_kpa"].to_numpy() == p)[0])
        ex = (float(exact["tip_x_mm"].iloc[j]), float(exact["tip_y_mm"].iloc[j]))
        settled = run.ramp_to(float(p))
        if not all(math.isfinite(v) for v in ex):
            continue
        tip = run.site("pam0_tip")
        bend = f.bend * float(np.sum(run.d.qpos[run.ctl._qpos_ix]))
        rows.append({"pressure_kpa": float(p), "mujoco_tip_x_mm": _r(tip[0]), "mujoco_tip_y_mm": _r(tip[2]),
                     "bendpam_tip_x_mm": _r(ex[0]), "bendpam_tip_y_mm": _r(ex[1]),
                     "tip_error_pct_of_length": _r(_tip_error(tip, ex, f.length)),
                     "bend_angle_error_deg": _r(math.degrees(bend) - float(exact["bend_angle_deg"].iloc[j])),
                     "settled": settled})
    return rows


def _loaded_run(run: _Run, exported: MujocoModel, P: float, tip_force_n) -> dict[str, Any]:
    f = exported.finger
    if tip_force_n is None:
        mb = abs(float(f.law.moment(P, 0.0)))
        a = f.base_angle
        F = 0.25 * mb / f.length
        tip_force_n = (f.bend * F * math.sin(a), -f.bend * F * math.cos(a))
    fx, fy = (float(v) for v in tip_force_n)
    shape = solve_finger(f, P, FingerLoads(tip_force_n=(fx, fy)))
    if not shape.equilibrium:
        raise InputError(f"the finger has no equilibrium under the tip force ({fx:g}, {fy:g}) N at {P:g} kPa: "
                         f"{shape.note}; give a smaller tip force")
    mj = run.mj
    sid = mj.mj_name2id(run.m, mj.mjtObj.mjOBJ_SITE, "pam0_tip")
    bid = int(run.m.site_bodyid[sid])
    state = {"i": 0}

    def load():
        state["i"] += 1
        s = min(1.0, state["i"] / _RAMP)
        force = np.array([fx, 0.0, fy]) * s
        mj.mj_kinematics(run.m, run.d)
        mj.mj_comPos(run.m, run.d)
        r = run.d.site_xpos[sid] - run.d.xipos[bid]
        run.d.xfrc_applied[bid, :3] = force
        run.d.xfrc_applied[bid, 3:] = np.cross(r, force)

    for _ in range(_RAMP):
        load()
        run.step()
    settled = run.creep(load)
    tip = run.site("pam0_tip")
    err = _tip_error(tip, shape.tip_xy, f.length)
    return {"pressure_kpa": P, "tip_force_n": [fx, fy], "mujoco_tip_x_mm": _r(tip[0]), "mujoco_tip_y_mm": _r(tip[2]),
            "bendpam_tip_x_mm": _r(shape.tip_xy[0]), "bendpam_tip_y_mm": _r(shape.tip_xy[1]),
            "tip_error_pct_of_length": _r(err), "settled": settled}


def _sphere_force_n(run: _Run, sphere: int) -> float:
    """Upward force of the fingers on the sphere, N."""
    mj, d = run.mj, run.d
    f6 = np.zeros(6)
    fz = 0.0
    for i in range(d.ncon):
        c = d.contact[i]
        if sphere not in (c.geom1, c.geom2):
            continue
        mj.mj_contactForce(run.m, d, i, f6)
        fw = c.frame.reshape(3, 3).T @ f6[:3]  # on geom2, from geom1
        fz += float(fw[2]) if c.geom2 == sphere else -float(fw[2])
    return fz


def _pull(run: _Run, sphere: int, closed: float) -> tuple[float, float]:
    """Lift the arm :data:`_LIFT_MM` per step; returns the peak upward force on the sphere (N) and its lift (mm).

    The force is averaged over the last :data:`_SMOOTH_MM` of lift (a tip that slides on the sphere
    under a light load chatters: its force jumps between steps).  The fingers may close just short
    of the sphere (the chain's free shape is within 0.5 % of L0 of bendpam's): the pull goes on
    until they touch it; it ends when they have let it go, or the averaged force has stayed below
    half its peak, for :data:`_GONE_MM` of lift (a chattering tip loses the sphere for a moment), or
    after 80 mm.
    """
    z0 = float(run.d.mocap_pos[0, 2])
    w = max(1, round(_SMOOTH_MM / _LIFT_MM))
    recent = np.full(w, closed)
    peak, lift_at_peak = closed, 0.0
    touched, apart, low = _touching(run, sphere), 0, 0
    for i in range(int(80.0 / _LIFT_MM)):
        lift = (i + 1) * _LIFT_MM
        run.d.mocap_pos[0, 2] = z0 + lift * 1e-3  # the arm; the palm follows it through the weld
        run.step()
        recent[i % w] = _sphere_force_n(run, sphere)
        fz = float(np.mean(recent))
        if fz > peak:
            peak, lift_at_peak = fz, lift - 0.5 * (min(i + 1, w)) * _LIFT_MM
        touching = _touching(run, sphere)
        apart = 0 if touching else apart + 1
        low = low + 1 if fz < 0.5 * peak else 0
        if (touched and apart * _LIFT_MM > _GONE_MM) or (low * _LIFT_MM > _GONE_MM and lift > 1.0):
            break
        touched |= touching
    return peak, max(lift_at_peak, 0.0)


def _touching(run: _Run, sphere: int) -> bool:
    """Whether any geom touches the sphere."""
    return any(sphere in (run.d.contact[i].geom1, run.d.contact[i].geom2) for i in range(run.d.ncon))


def pullout(exported: MujocoModel, diameter_mm: float, pressure_kpa: float) -> dict[str, Any]:
    """The pull-out of a sphere (mm) at a pressure (kPa) in MuJoCo, beside :func:`bendpam.design.grasp.solve_grasp`.

    ``exported`` is a gripper export; the sphere is fixed where the open gripper lands on it.  Returns
    the grip forces of both (N), MuJoCo's closed force and peak lift, bendpam's, and ``error_pct``.

    >>> import bendpam
    >>> gripper = mujoco_model(bendpam.physics.presets.be_pam().replace(L0_mm=130.0), "gripper")
    >>> r = pullout(gripper, 200.0, 160.0)                       # a 200 mm sphere at 160 kPa
    >>> r["bendpam_contact"], abs(r["error_pct"]) < 5.0            # grip forces within 5 %
    ('tip', True)
    """
    gr = exported.gripper
    if gr is None:
        raise InputError("a pull-out needs a gripper export (device 'gripper')")
    with _mujoco_warnings() as warned:
        out = _pullout(exported, gr, float(diameter_mm), float(pressure_kpa))
    return out | {"mujoco_warnings": sorted(set(warned))}


def _pullout(exported: MujocoModel, gr, diameter_mm: float, P: float) -> dict[str, Any]:
    ref = solve_grasp(gr, diameter_mm, P)
    ex = mujoco_model(exported.actuator, "gripper", law_model=exported.law_model, segments=exported.segments,
                      pressures_kpa=exported.pressures_kpa, sphere_mm=diameter_mm, gripper=gr)
    run = _Run.of(ex, _PULL_DT)
    mj = run.mj
    sphere = mj.mj_name2id(run.m, mj.mjtObj.mjOBJ_GEOM, "sphere")
    floor = mj.mj_name2id(run.m, mj.mjtObj.mjOBJ_GEOM, "floor")
    run.m.geom_contype[floor] = run.m.geom_conaffinity[floor] = 0  # bendpam's grasp has no table after landing
    mu = run.m.geom_friction[:, 0].copy()
    run.m.geom_friction[:, 0] = 0.0  # frictionless closing, as bendpam's grasp statics
    noslip, run.m.opt.noslip_iterations = run.m.opt.noslip_iterations, 0  # (nothing to stick: it only adds noise)
    settled = run.ramp_to(P, 3 * _RAMP)
    closed = _sphere_force_n(run, sphere)
    run.m.geom_friction[:, 0] = mu
    run.m.opt.noslip_iterations = noslip
    peak, lift_at_peak = _pull(run, sphere, closed)
    want = float(ref.grip_force_n)
    err = (peak - want) / want * 100.0 if want > 0 else math.nan
    return {"diameter_mm": diameter_mm, "pressure_kpa": P, "mujoco_grip_force_n": _r(peak),
            "bendpam_grip_force_n": _r(want), "mujoco_closed_force_n": _r(closed),
            "mujoco_peak_lift_mm": _r(lift_at_peak), "bendpam_peak_lift_mm": _r(ref.peak_lift_mm),
            "bendpam_contact": ref.contact, "error_pct": _r(err), "settled": settled}


def validate(exported: MujocoModel, *, pressures_kpa=None, tip_force_n=None, sphere_mm: float = 200.0,
             pullout_pressure_kpa: float | None = None) -> Validation:
    """Quasi-static MuJoCo runs of ``exported`` against bendpam (see the module docstring).

    Parameters
    ----------
    exported : MujocoModel
        From :func:`bendpam.export.mujoco_model`.  For a gripper, the free and loaded shapes are
        those of one of its fingers on its own; the pull-out uses the whole gripper.
    pressures_kpa : the free-shape pressures (kPa); default: the export's.
    tip_force_n : (Fx, Fy) in the finger's plane (N); default: against the bending, a quarter of
        the blocked moment about the base.
    sphere_mm, pullout_pressure_kpa : the pull-out's sphere (mm, default 200) and pressure (kPa,
        default the export's highest).

    Examples
    --------
    >>> import bendpam
    >>> v = validate(mujoco_model(bendpam.physics.presets.be_pam(), "finger"), pressures_kpa=[150.0])
    >>> v.free_shape_tip_error_pct_of_length < 1.0, v.loaded_tip_error_pct_of_length < 1.0   # % of L0
    (True, True)
    """
    if not isinstance(exported, MujocoModel):
        raise InputError(f"exported must be a MujocoModel (bendpam.export.mujoco_model), got {type(exported).__name__}")
    P = np.asarray(exported.pressures_kpa if pressures_kpa is None else np.atleast_1d(pressures_kpa), dtype=float)
    single = exported
    if exported.device != "finger":
        single = mujoco_model(exported.actuator, "finger", law_model=exported.law_model, segments=exported.segments,
                              pressures_kpa=exported.pressures_kpa, finger=exported.finger)
    with _mujoco_warnings() as warned:
        run = _Run.of(single)
        free = _free_runs(run, single, P)
        if free:
            loaded = _loaded_run(run, single, max(r["pressure_kpa"] for r in free), tip_force_n)
    if not free:
        raise InputError("no pressure of the validation has a free shape (all above the fold): give lower pressures")
    p_top = max(r["pressure_kpa"] for r in free)  # the highest pressure with a free shape (the loaded run's)
    notes = [f"the run at {r['pressure_kpa']:g} kPa did not settle to |qvel| < {QVEL_TOL:g} rad/s"
             for r in [*free, loaded] if not r["settled"]]
    notes += [f"the {name} tip error {err:.3g} % of L0 is above 1 %" for name, err in (
        ("free-shape", max((r["tip_error_pct_of_length"] for r in free), default=0.0)),
        ("loaded", loaded["tip_error_pct_of_length"])) if err > 1.0]
    free_err = max((r["tip_error_pct_of_length"] for r in free), default=math.nan)
    pull, pull_err = None, None
    if exported.device == "gripper":
        pull = pullout(exported, sphere_mm, p_top if pullout_pressure_kpa is None else pullout_pressure_kpa)
        pull_err = pull["error_pct"]
        warned += pull["mujoco_warnings"]
        if pull_err is not None and abs(pull_err) > 5.0:
            notes.append(f"MuJoCo's pull-out force differs from bendpam's by {pull_err:+.3g} % (more than 5 %): "
                         "MuJoCo's soft contact moves the contact by a fraction of a millimetre, which matters where "
                         "the grip is a small difference (a contact near the edge of its friction cone)")
    notes += [f"MuJoCo warned: {w}" for w in sorted(set(warned))]
    return Validation(free, free_err, loaded, loaded["tip_error_pct_of_length"], pull, pull_err, notes)


# ------------------------------------------------------------------------------------------------
# the hand
# ------------------------------------------------------------------------------------------------
class HandController:
    """Drives an exported hand (:func:`bendpam.export.mjcf.hand_model`): one pressure per part of the hand.

    The chains' hinge torques are :class:`bendpam.sim.mujoco.PamController`'s, with each part's
    actuator; the palm roll's pressure sets the target of its position-controlled hinge to the palm
    segment's free bending angle there (interpolated in :meth:`bendpam.design.hand.HandPart.angle_table`,
    within 1e-5 deg of :func:`bendpam.design.hand.hand_pose`'s).  A model with a fixed palm roll takes
    no palm pressure.

    Parameters
    ----------
    model : the ``mujoco.MjModel`` of the hand.  hand : the :class:`~bendpam.design.hand.Hand` it was built from.
    loop, engine : as :class:`~bendpam.sim.mujoco.PamController`.

    Examples
    --------
    >>> import mujoco
    >>> from bendpam.design.hand import default_hand
    >>> from bendpam.export.mjcf import hand_model
    >>> hand = default_hand()
    >>> m = mujoco.MjModel.from_xml_string(hand_model(hand, segments=4).xml); d = mujoco.MjData(m)
    >>> ctl = HandController(m, hand)
    >>> ctl.set_pressure_kpa({"index": 150.0, "palm_roll": 300.0}); ctl.step(m, d, 10)
    >>> ctl.pam.pressure_kpa.tolist()[:2], round(float(np.degrees(d.ctrl[0])), 1)     # kPa; the roll's target, deg
    ([150.0, 0.0], 95.9)
    """

    def __init__(self, model, hand: Hand, *, loop=None, engine: str = "auto"):
        if not isinstance(hand, Hand):
            raise InputError(f"hand must be a bendpam.design.hand.Hand, got {type(hand).__name__}")
        self.hand = hand
        self.pam = PamController(model, {n: hand.part(n).actuator for n in HAND_CHAINS}, law_model=hand.model,
                                 loop=loop, engine=engine)
        names = [c.name for c in self.pam.chains]
        if sorted(names) != sorted(HAND_CHAINS):
            raise InputError(f"the model's bending PAMs {names} are not the hand's {list(HAND_CHAINS)}")
        mj = import_mujoco()
        self._roll = int(mj.mj_name2id(model, mj.mjtObj.mjOBJ_ACTUATOR, "palm_roll"))  # -1: a fixed roll
        self.pressures_kpa = dict.fromkeys(PARTS, 0.0)
        self.palm_roll_rad = 0.0

    def set_pressure_kpa(self, pressures_kpa: dict) -> None:
        """Set the pressures (kPa, 0 to the hand's ``max_pressure_kpa``) by part name; parts not named: 0 kPa."""
        if not isinstance(pressures_kpa, dict):
            raise InputError(f"pressures_kpa: give the pressures by part name (a dict of kPa), got "
                             f"{type(pressures_kpa).__name__}")
        given = dict(pressures_kpa)
        for name in given:
            if name not in PARTS:
                raise InputError(f"pressures_kpa: no hand part {name!r}{did_you_mean(name, PARTS)}; "
                                 f"the parts are {', '.join(PARTS)}")
        P = {n: number(f"pressures_kpa[{n!r}]", given.get(n, 0.0), 0.0, self.hand.max_pressure_kpa, unit="kPa")
             for n in PARTS}
        if self._roll < 0 and P["palm_roll"] > 0:
            raise InputError("the model's palm roll is a fixed angle: it takes no palm_roll pressure")
        # the palm segment's free angle from its table (0.1 % of the pressure range apart: within 1e-5 deg)
        table_kpa, table_deg = self.hand.part("palm_roll").angle_table(self.hand.max_pressure_kpa)
        roll = float(np.interp(P["palm_roll"], table_kpa, table_deg, right=np.nan))
        if not math.isfinite(roll):
            raise InputError(f"palm_roll: no free-bending equilibrium at {P['palm_roll']:g} kPa")
        self.pam.set_pressure_kpa([P[c.name] for c in self.pam.chains])
        self.pressures_kpa, self.palm_roll_rad = P, math.radians(roll)

    def apply(self, data) -> None:
        """The hinge torques into ``data.qfrc_applied`` and the palm roll's target into ``data.ctrl``."""
        self.pam.apply(data)
        if self._roll >= 0:
            data.ctrl[self._roll] = self.palm_roll_rad

    def step(self, model, data, nstep: int = 1) -> None:
        """``nstep`` MuJoCo steps, :meth:`apply` before each."""
        mujoco = import_mujoco()
        for _ in range(int(nstep)):
            self.apply(data)
            mujoco.mj_step(model, data)


@dataclass(frozen=True)
class HandValidation:
    """The figures of :func:`validate_hand`: every tip against :func:`bendpam.design.hand.hand_pose`.

    Attributes
    ----------
    tips : one row per pose and tip (``pressures_kpa``, ``tip``, ``length_mm``, both tips in mm,
        ``tip_error_pct_of_length``, ``settled``).
    hand_tip_error_pct_of_length : the largest tip error, % of that tip's part (the thumb: both segments).
    tip_errors_pct_of_length : per tip, its largest error.

    Examples
    --------
    >>> HandValidation([], 0.3, {"index": 0.3}).to_dict()["hand_tip_error_pct_of_length"]
    0.3
    """

    tips: list[dict[str, Any]]
    hand_tip_error_pct_of_length: float
    tip_errors_pct_of_length: dict[str, float]
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """The figures as a JSON-ready dict (units in the key names)."""
        return {"hand_tip_error_pct_of_length": _r(self.hand_tip_error_pct_of_length),
                "hand_tip_errors_pct_of_length": {k: _r(v) for k, v in self.tip_errors_pct_of_length.items()},
                "hand_tips": self.tips, "notes": self.notes}


def hand_poses_kpa(exported: MujocoHand, pressures_kpa=None) -> list[dict[str, float]]:
    """The poses :func:`validate_hand` checks: pose ``i`` gives part ``j`` (in :data:`~bendpam.design.hand.PARTS`
    order) the pressure ``i + j`` (cyclically) of ``pressures_kpa`` (kPa; default the export's), so that
    every part meets every pressure and the parts of a pose differ; no palm pressure with a fixed roll.

    >>> from bendpam.design.hand import default_hand
    >>> from bendpam.export.mjcf import hand_model
    >>> poses = hand_poses_kpa(hand_model(default_hand(), segments=4), [100.0, 200.0])
    >>> [p["index"] for p in poses], [p["middle"] for p in poses]
    ([100.0, 200.0], [200.0, 100.0])
    """
    P = sorted(float(p) for p in np.atleast_1d(np.asarray(
        exported.pressures_kpa if pressures_kpa is None else pressures_kpa, dtype=float)))
    parts = [p for p in PARTS if exported.palm_roll_deg is None or p != "palm_roll"]
    return [{n: P[(i + j) % len(P)] for j, n in enumerate(parts)} for i in range(len(P))]


def _hand_run(exported: MujocoHand) -> _Run:
    """The quasi-static run of a hand export: every hinge damped for its part's blocked-state stiffness."""
    hand = exported.hand
    top = float(max(exported.pressures_kpa))

    def stiffness(name: str, h: float) -> float:
        table = hand.part(name).law.tabulated()
        return abs(float(table.tangent_stiffness(top, 0.0))) / h * 1e-3

    def per_hinge(ctl: HandController) -> np.ndarray:  # in the controller's order of the chains
        return np.concatenate([np.full(c.segments, stiffness(c.name, c.segment_length_mm)) for c in ctl.pam.chains])

    run = _Run(exported.xml, lambda m: HandController(m, hand), per_hinge)
    roll = run.ctl._roll
    if roll >= 0:  # the palm roll's servo: overdamped as the hinges
        kp = float(run.m.actuator_gainprm[roll, 0])
        dof = int(run.m.jnt_dofadr[run.m.actuator_trnid[roll, 0]])
        run.m.dof_damping[dof] = max(3.0 * math.sqrt(kp * run.diag_inertia[dof]), 2.0 * _DT * kp)
    return run


def _hand_reference(exported: MujocoHand, P: dict[str, float]) -> dict[str, np.ndarray]:
    """bendpam's unloaded tips (mm) at the pressures ``P`` (the thumb at the fixed roll, if the model has one)."""
    hand = exported.hand
    pose = hand_pose(hand, P)
    tips = dict(pose.tips_mm)
    if exported.palm_roll_deg is not None:
        a = {n: math.radians(pose.angles_deg[n]) for n in ("thumb_proximal", "thumb_distal")}
        tips["thumb"] = thumb_chain(hand, a["thumb_proximal"], a["thumb_distal"],
                                    math.radians(exported.palm_roll_deg))[1]
    return tips


def validate_hand(exported: MujocoHand, *, pressures_kpa=None) -> HandValidation:
    """Quasi-static MuJoCo runs of a hand export against bendpam's unloaded hand
    (:func:`~bendpam.design.hand.hand_pose`).

    As the finger's free shapes (:func:`validate`; gravity off, 1 ms steps, overdamped hinges and
    palm roll): for each pose of :func:`hand_poses_kpa` a ramp of 100 steps from the previous pose,
    then the creep until ``max |qvel|`` < :data:`QVEL_TOL`; every fingertip and the thumb tip (the
    sites ``NAME_tip``) against bendpam's, the distance in % of that part's length (the thumb's:
    both segments).

    Examples
    --------
    >>> from bendpam.design.hand import default_hand
    >>> from bendpam.export.mjcf import hand_model
    >>> v = validate_hand(hand_model(default_hand()), pressures_kpa=[150.0])
    >>> v.hand_tip_error_pct_of_length < 1.0, sorted(v.tip_errors_pct_of_length)[:2]
    (True, ['index', 'little'])
    """
    if not isinstance(exported, MujocoHand):
        raise InputError(f"exported must be a MujocoHand (bendpam.export.mjcf.hand_model), got "
                         f"{type(exported).__name__}")
    hand = exported.hand
    lengths = {t: hand.part(c).length_mm for t, c in HAND_TIPS.items()}
    lengths["thumb"] += hand.part("thumb_proximal").length_mm
    rows: list[dict[str, Any]] = []
    with _mujoco_warnings() as warned:
        run = _hand_run(exported)
        before = dict.fromkeys(PARTS, 0.0)
        for P in hand_poses_kpa(exported, pressures_kpa):
            for i in range(_RAMP):
                run.ctl.set_pressure_kpa({n: before.get(n, 0.0) + (p - before.get(n, 0.0)) * (i + 1) / _RAMP
                                          for n, p in P.items()})
                run.step()
            settled, before = run.creep(), P
            ref = _hand_reference(exported, P)
            for tip, chain in HAND_TIPS.items():
                got = run.site(f"{chain}_tip")
                err = float(np.linalg.norm(got - ref[tip])) / lengths[tip] * 100.0
                rows.append({"pressures_kpa": dict(P), "tip": tip, "length_mm": lengths[tip],
                             "mujoco_tip_mm": [_r(v) for v in got], "bendpam_tip_mm": [_r(v) for v in ref[tip]],
                             "tip_error_pct_of_length": _r(err), "settled": settled})
    per_tip = {t: max(r["tip_error_pct_of_length"] for r in rows if r["tip"] == t) for t in HAND_TIPS}
    worst = max(per_tip.values())
    notes = [f"the pose at {r['pressures_kpa']} did not settle to |qvel| < {QVEL_TOL:g} rad/s"
             for r in rows if not r["settled"] and r["tip"] == "index"]
    notes += [f"the {t} tip error {e:.3g} % of its length is above 1 %" for t, e in per_tip.items() if e > 1.0]
    notes += [f"MuJoCo warned: {w}" for w in sorted(set(warned))]
    return HandValidation(rows, worst, per_tip, notes)


_validate = validate  # (the name ``validate`` is an argument of :func:`mujoco`)


@dataclass(frozen=True)
class MujocoExport:
    """An export: the device's model, one model per sphere, and the validation figures (None if not run).

    Examples
    --------
    >>> import bendpam
    >>> ex = mujoco(bendpam.physics.presets.be_pam(), "finger", validate=False)
    >>> sorted(ex.files())
    ['actuator.toml', 'export.json', 'finger.xml']
    """

    model: MujocoModel | MujocoHand
    sphere_models: dict[float, MujocoModel]
    validation: Validation | HandValidation | None
    loop: LoopModel | None = None

    def to_dict(self) -> dict[str, Any]:
        """The model's description, its files and the validation figures (``export.json``), JSON-ready."""
        toml = ["actuator.toml"] if self.model.actuator is not None else []
        d = self.model.to_dict() | {"spheres_mm": sorted(self.sphere_models),
                                    "files": [*sorted(self._models()), *toml, "export.json"]}
        if self.loop is not None:
            d["hysteresis"] = self.loop.to_dict()
        if self.validation is not None:
            d["validation"] = self.validation.to_dict()
        return d

    def _models(self) -> dict[str, str]:
        dev = self.model.device
        return {f"{dev}.xml": self.model.xml} | {f"{dev}-sphere-{d:g}mm.xml": m.xml
                                                 for d, m in self.sphere_models.items()}

    def files(self) -> dict[str, str]:
        """Every file of the export by name: the MJCF models, ``actuator.toml`` and ``export.json``."""
        import tomli_w

        from bendpam.infra.outputs import to_json

        files = self._models()
        if self.model.actuator is not None:  # (a hand from a hand file: the file has the actuators)
            toml = self.model.actuator.to_toml()
            if self.loop is not None:  # the fitted loop, for PamController(..., loop=LoopModel.from_toml(...))
                toml += "\n" + tomli_w.dumps({"hysteresis": self.loop.to_dict()})
            files["actuator.toml"] = toml
        return files | {"export.json": to_json(self.to_dict())}

    def save(self, folder, *, force: bool = False) -> list[str]:
        """Write :meth:`files` into ``folder`` as one output set (staged, swapped in whole, with a manifest)."""
        from bendpam.infra.outputs import OutputSet

        files = self.files()
        with OutputSet(folder, force=force, producer="bendpam.export.mujoco") as o:
            for name, text in files.items():
                o.write_text(name, text)
        return sorted(files)


def mujoco(actuator, device: str = "finger", *, law_model: str | None = None, segments: int | None = None,
           tip_error_pct: float = 1.0, pressures_kpa=None, spheres_mm=(), validate: bool = True,
           loop: LoopModel | None = None, **options: Any) -> MujocoExport:
    """Export ``actuator``'s finger, gripper or hand to MuJoCo: the models and, with ``validate``, the figures.

    The device's model is :func:`bendpam.export.mujoco_model` (``options`` go to it: ``gripper``,
    ``finger``, ``densities``); one more model per sphere of ``spheres_mm`` (mm, gripper only);
    :func:`validate` checks the device against bendpam (the pull-out on the first sphere, or 200 mm;
    without the loop: bendpam's statics are the loop-free law).  ``loop``, a fitted hysteresis loop,
    is written into ``actuator.toml`` beside the actuator for the simulation
    (``PamController(model, actuator, loop=LoopModel.from_toml(path))``).  ``.save(folder)`` writes the files.

    ``device="hand"``: the hand of :func:`bendpam.export.mjcf.hand_model` (``options``: ``hand``, a
    :class:`~bendpam.design.hand.Hand`, else :func:`~bendpam.design.hand.default_hand` with
    ``actuator`` in every part (None: the paper's BE-PAM); ``palm_roll_deg``; ``densities``), checked
    by :func:`validate_hand`; :class:`HandController` drives it.

    Examples
    --------
    >>> import bendpam
    >>> ex = bendpam.export.mujoco(bendpam.physics.presets.be_pam().replace(L0_mm=130.0), "gripper",
    ...                            spheres_mm=[200.0], validate=False)
    >>> sorted(ex.files())[:2], ex.model.segments
    (['actuator.toml', 'export.json'], 7)
    """
    if loop is not None and not isinstance(loop, LoopModel):
        raise InputError(f"loop must be a bendpam.physics.hysteresis.LoopModel, got {type(loop).__name__}")
    if device == "hand":
        return _mujoco_hand(actuator, law_model, segments, tip_error_pct, pressures_kpa, spheres_mm, validate, loop,
                            **options)
    base = mujoco_model(actuator, device, law_model=law_model, segments=segments, tip_error_pct=tip_error_pct,
                        pressures_kpa=pressures_kpa, **options)
    diam = [float(d) for d in np.atleast_1d(np.asarray(spheres_mm, dtype=float))]
    spheres = {d: mujoco_model(actuator, device, law_model=base.law_model, segments=base.segments,
                               pressures_kpa=base.pressures_kpa, sphere_mm=d, **options) for d in diam}
    val = _validate(base, sphere_mm=diam[0] if diam else 200.0) if validate else None
    return MujocoExport(base, spheres, val, loop)


def _mujoco_hand(actuator, law_model, segments, tip_error_pct, pressures_kpa, spheres_mm, validate, loop,
                 hand: Hand | None = None, palm_roll_deg: float | None = None, densities=None) -> MujocoExport:
    """:func:`mujoco` for the hand."""
    if np.atleast_1d(np.asarray(spheres_mm, dtype=float)).size:
        raise InputError("the spheres are objects of the gripper's grasp test; the hand export has none")
    if hand is None:
        if actuator is not None and not isinstance(actuator, Actuator):
            raise InputError(f"actuator must be a bendpam.Actuator or None, got {type(actuator).__name__}")
        model = law_model or (resolve_model(actuator) if actuator is not None else "energy")
        hand = default_hand(model, actuator)
        if actuator is None:
            actuator = presets.be_pam(hand.model)
    elif actuator is not None:
        raise InputError("give either a hand (its parts name their actuators) or an actuator for the default hand")
    elif law_model is not None and normalise_model(law_model) != hand.model:
        raise InputError(f"law_model = {law_model!r}: the hand's model is {hand.model!r} (set it in the hand)")
    base = hand_model(hand, segments=segments, tip_error_pct=tip_error_pct, pressures_kpa=pressures_kpa,
                      palm_roll_deg=palm_roll_deg, densities=densities, actuator=actuator)
    return MujocoExport(base, {}, validate_hand(base) if validate else None, loop)
