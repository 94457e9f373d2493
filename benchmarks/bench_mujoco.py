"""The moment law inside MuJoCo: the overhead of ``PamController.apply`` per step, beside a bare ``mj_step``.

For the paper's BE-PAM finger (8 hinges) and three-finger gripper (3 x 7 hinges, a 200 mm sphere in
contact), at 150 kPa, the candidates are timed side by side (interleaved repeats, medians):

* ``mj_step``: MuJoCo's step alone (the torques left as they are);
* ``apply``: the law's torques for every hinge written into ``qfrc_applied`` (what a simulation adds),
  with the compiled engine (Numba) and with NumPy;
* ``apply + mj_step``: one step of a simulation driven by bendpam.

The overhead is ``apply`` against ``mj_step``; no target is asserted.  The gripper is settled on
the sphere first, so its steps include the contacts.

Run: ``python benchmarks/bench_mujoco.py [--quick]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
import mujoco
from _timing import Recorder, compare, header

import bendpam
from bendpam.export import mujoco_model
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

    def bare():
        for _ in range(steps):
            mujoco.mj_step(m, d)

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
    header(f"{name}: {len(ctl.chains)} chain(s), {ctl.dofs.size} hinges, {d.ncon} contacts")
    for k, v in us.items():
        print(f"  {k:16} {v:8.2f} us per step")
    print(f"  overhead of the law: {us['apply'] / us['mj_step']:.2f} x a bare mj_step")
    rec.record("per_step_us", name, us | {"hinges": int(ctl.dofs.size), "contacts": int(d.ncon)})
    rec.row(f"{name}: apply per step", us["apply"], "us", "", None,
            f"bare mj_step {us['mj_step']:.1f} us, NumPy engine {us['apply (numpy)']:.1f} us")


def main(quick: bool = False) -> None:
    rec = Recorder("mujoco", quick)
    be = bendpam.physics.presets.be_pam()
    steps, repeats = (500, 3) if quick else (2000, 7)
    _case("BE-PAM finger", be, "finger", rec, steps, repeats)
    _case("BE-PAM gripper on a 200 mm sphere", be.replace(L0_mm=130.0), "gripper", rec, steps, repeats,
          sphere_mm=200.0)
    rec.print_summary()
    rec.save()


if __name__ == "__main__":
    main("--quick" in sys.argv)
