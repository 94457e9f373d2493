"""The MuJoCo pull-out against bendpam's over the paper's grasp cases (docs/mujoco.md quotes its table).

For the paper's gripper (three 130 mm fingers) of each preset, every sphere of 80-280 mm (20 mm
apart) at a few pressures of the paper's range where ``bendpam grasp`` reports a grip, the pull-out
of :func:`bendpam.export.validation.pullout` (MuJoCo, quasi-static) beside bendpam's; prints a
Markdown table and the largest error per preset:

    python tools/mujoco_pullout_sweep.py                 # both presets, about 2 min on 2 cores
    python tools/mujoco_pullout_sweep.py bc-pam --diameters 120,200 --pressures 130

Cases where bendpam's peak is only a lower bound (its note says so) are listed but not counted.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

import bendpam
from bendpam.design import Gripper
from bendpam.design.grasp import solve_grasps
from bendpam.export import mujoco_model
from bendpam.export.validation import pullout

PRESETS = {"be-pam": (bendpam.physics.presets.be_pam, [130.0, 160.0, 200.0]),
           "bc-pam": (bendpam.physics.presets.bc_pam, [100.0, 115.0, 127.5])}


def sweep(preset: str, diameters_mm, pressures_kpa) -> list[dict]:
    actuator = PRESETS[preset][0]().replace(L0_mm=130.0)
    gripper = Gripper(actuator)
    exported = mujoco_model(actuator, "gripper", gripper=gripper)
    rows = []
    for D, grasps in zip(diameters_mm, solve_grasps(gripper, diameters_mm, pressures_kpa), strict=True):
        for P, g in zip(pressures_kpa, grasps, strict=True):
            if not g.grip_force_n > 0:
                continue
            t = time.perf_counter()
            r = pullout(exported, float(D), float(P))
            rows.append(r | {"preset": preset, "bendpam_note": g.note, "seconds": time.perf_counter() - t})
            print(f"{preset} {D:g} mm {P:g} kPa: {r['mujoco_grip_force_n']:.3f} N vs {r['bendpam_grip_force_n']:.3f} N "
                  f"({r['error_pct']:+.2f} %), {r['bendpam_contact']}", file=sys.stderr, flush=True)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("presets", nargs="*", choices=[*PRESETS, []], help="be-pam, bc-pam (default both)")
    ap.add_argument("--diameters", default=None, help="mm, comma-separated (default 80-280 by 20)")
    ap.add_argument("--pressures", default=None, help="kPa, comma-separated (default per preset)")
    a = ap.parse_args(argv)
    Ds = np.arange(80.0, 281.0, 20.0) if a.diameters is None else [float(v) for v in a.diameters.split(",")]
    print("| gripper | sphere (mm) | pressure (kPa) | bendpam contact | MuJoCo (N) | bendpam (N) | error |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for preset in a.presets or list(PRESETS):
        Ps = PRESETS[preset][1] if a.pressures is None else [float(v) for v in a.pressures.split(",")]
        rows = sweep(preset, Ds, Ps)
        for r in rows:
            flag = " (bendpam: a lower bound)" if r["bendpam_note"] else ""
            print(f"| {preset} | {r['diameter_mm']:g} | {r['pressure_kpa']:g} | {r['bendpam_contact']} | "
                  f"{r['mujoco_grip_force_n']:.3f} | {r['bendpam_grip_force_n']:.3f} | {r['error_pct']:+.2f} %{flag} |")
        counted = [abs(r["error_pct"]) for r in rows if not r["bendpam_note"]]
        if counted:
            print(f"\n{preset}: {len(counted)} cases, largest |error| {max(counted):.2f} %, "
                  f"median {float(np.median(counted)):.2f} %\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
