"""The moment law inside MuJoCo: the overhead of ``PamController.apply`` per step, beside a bare ``mj_step``.

For the paper's BE-PAM finger (8 hinges), three-finger gripper (3 x 7 hinges, a 200 mm sphere in
contact) and the default soft hand (six chains, 49 hinges, the palm roll's servo; ``HandController``),
at 150 kPa, the candidates are timed side by side (interleaved repeats, medians):

* ``mj_step``: MuJoCo's step alone (the torques left as they are);
* ``apply``: the law's torques for every hinge written into ``qfrc_applied`` (what a simulation adds),
  with the compiled engine (Numba) and with NumPy;
* ``apply + mj_step``: one step of a simulation driven by bendpam.

The overhead is ``apply`` against ``mj_step``; no target is asserted.  The bare steps keep the last
torques and replace the law's stiffness by MuJoCo's own joint springs (the law linearised about the
settled state), so that they stay a stable simulation.  The gripper is settled on
the sphere first, so its steps include the contacts.

Run: ``python benchmarks/bench_mujoco.py [--quick]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
import mujoco
import numpy as np
from _timing import Recorder, compare, header

import bendpam
from bendpam.design.hand import PARTS, default_hand, hand_pose
from bendpam.export import HandController, hand_model, mujoco_model
from bendpam.sim.mujoco import PamController


def _case(name: str, actuator, device: str, rec: Recorder, steps: int, repeats: int, **kw) -> None:
    ex = mujoco_model(actuator, device, **kw)
    m = mujoco.MjModel.from_xml_string(ex.xml)
    d = mujoco.MjData(m)
    m.opt.gravity[:] = 0.0
    ctl = PamController(m, actuator, engine="numba")
    ctl.set_pressure_kpa(150.0)
    ctl.step(m, d, 2000)  # settle (the gripper onto the sphere)
    slow = PamController(m, actuator, engine="numpy")
    slow.set_pressure_kpa(150.0)
    _time(name, m, d, ctl, slow, rec, steps, repeats)


def _hand_case(rec: Recorder, steps: int, repeats: int) -> None:
    """The default soft hand: six chains, the palm roll's servo, every part at 150 kPa (HandController)."""
    hand = default_hand()
    m = mujoco.MjModel.from_xml_string(hand_model(hand).xml)
    d = mujoco.MjData(m)
    m.opt.gravity[:] = 0.0
    ctl, slow = HandController(m, hand, engine="numba"), HandController(m, hand, engine="numpy")
    pose = hand_pose(hand, dict.fromkeys(PARTS, 150.0))
    for c in (ctl, slow):
        c.set_pressure_kpa(pose.pressures_kpa)
    # at rest in the free shapes (every hinge at k' h of its part; the roll at its target): with the model's
    # light damping a ramp leaves the chains swinging for seconds
    for c in ctl.pam.chains:
        d.qpos[c.qpos] = c.frame_side * np.radians(pose.angles_deg[c.name]) / hand.part(c.name).length_mm \
            * c.segment_length_mm
    d.qpos[m.jnt_qposadr[m.actuator_trnid[0, 0]]] = ctl.palm_roll_rad
    ctl.step(m, d, 100)
    _time("BE-PAM soft hand", m, d, ctl, slow, rec, steps, repeats)


def _time(name: str, m, d, ctl, slow, rec: Recorder, steps: int, repeats: int) -> None:

    springs = _linearised_springs(m, d, getattr(ctl, "pam", ctl))

    def bare():  # the law's torques held, plus MuJoCo's own springs at their tangent stiffness (see below)
        springs(True)
        for _ in range(steps):
            mujoco.mj_step(m, d)
        springs(False)

    def apply():
        for _ in range(steps):
            ctl.apply(d)

    def apply_numpy():
        for _ in range(steps):
            slow.apply(d)

    def both():
        for _ in range(steps):
            ctl.apply(d)
            mujoco.mj_step(m, d)

    st = compare({"mj_step": (bare, steps), "apply": (apply, steps), "apply (numpy)": (apply_numpy, steps),
                  "apply + mj_step": (both, steps)}, repeats=repeats)
    us = {k: v.median / steps * 1e6 for k, v in st.items()}
    pam = getattr(ctl, "pam", ctl)
    header(f"{name}: {len(pam.chains)} chain(s), {pam.dofs.size} hinges, {d.ncon} contacts")
    for k, v in us.items():
        print(f"  {k:16} {v:8.2f} us per step")
    print(f"  overhead of the law: {us['apply'] / us['mj_step']:.2f} x a bare mj_step")
    rec.record("per_step_us", name, us | {"hinges": int(pam.dofs.size), "contacts": int(d.ncon)})
    rec.row(f"{name}: apply per step", us["apply"], "us", "", None,
            f"bare mj_step {us['mj_step']:.1f} us, NumPy engine {us['apply (numpy)']:.1f} us")


def _linearised_springs(m, d, pam: PamController):
    """A switch for the bare steps: each hinge a MuJoCo joint spring at the law's tangent stiffness about the
    current state.  (Bare steps keep the last torques; held constant, they run the chains into their limits:
    the finger's state went to NaN, which MuJoCo resets, within 0.4 s of simulated time.)"""
    q0 = d.qpos.copy()
    pam.apply(d)
    tau0 = d.qfrc_applied[pam.dofs].copy()
    eps = 1e-6
    d.qpos[pam.qpos] += eps
    pam.apply(d)
    stiffness = np.maximum(-(d.qfrc_applied[pam.dofs] - tau0) / eps, 0.0)  # N*m/rad (each hinge on its own)
    d.qpos[:] = q0
    pam.apply(d)
    joints = m.dof_jntid[pam.dofs]
    m.qpos_spring[pam.qpos] = q0[pam.qpos]

    def switch(on: bool) -> None:
        m.jnt_stiffness[joints] = stiffness if on else 0.0

    return switch


def main(quick: bool = False) -> None:
    rec = Recorder("mujoco", quick)
    be = bendpam.physics.presets.be_pam()
    steps, repeats = (500, 3) if quick else (2000, 7)
    _case("BE-PAM finger", be, "finger", rec, steps, repeats)
    _case("BE-PAM gripper on a 200 mm sphere", be.replace(L0_mm=130.0), "gripper", rec, steps, repeats,
          sphere_mm=200.0)
    _hand_case(rec, steps, repeats)
    rec.print_summary()
    rec.save()


if __name__ == "__main__":
    main("--quick" in sys.argv)
