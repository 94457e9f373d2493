"""Design tools: fingers under in-plane loads, grippers grasping spheres, and a four-actuator wrist.

* :mod:`bendpam.design.finger`: planar statics of a finger (rod along the frame line, the paper's
  moment law section by section), tip pose, blocked tip force, tip stiffness.
* :mod:`bendpam.design.grasp`: an N-finger gripper closing on a sphere, contact and pull-out force
  (the paper's Figure 8 test).
* :mod:`bendpam.design.wrist`: four BC-PAMs around a column (the paper's Figure 9 wrist): bending
  angle and direction, holding capacity.

Units: mm, N, N*mm, MPa for pressures passed to functions (kPa in table columns), rad (degrees in
names ending ``_deg``), grams for masses.
"""

from .finger import (
    BlockedTipForce,
    Finger,
    FingerLoads,
    FingerShape,
    StableBranch,
    TipStiffness,
    blocked_tip_force,
    finger_sweep,
    free_tip_trajectory,
    linear_tip_compliance,
    plot_finger_shapes,
    solve_finger,
    stable_branch,
    tip_stiffness,
)
from .grasp import Grasp, Gripper, grasp_sweep, plot_grasp, solve_grasp
from .wrist import (
    Wrist,
    WristHold,
    WristState,
    plot_wrist,
    wrist_bend,
    wrist_hold,
    wrist_moment,
    wrist_pressures,
    wrist_sweep,
)

__all__ = [
    "BlockedTipForce",
    "Finger",
    "FingerLoads",
    "FingerShape",
    "StableBranch",
    "TipStiffness",
    "blocked_tip_force",
    "finger_sweep",
    "free_tip_trajectory",
    "linear_tip_compliance",
    "plot_finger_shapes",
    "solve_finger",
    "stable_branch",
    "tip_stiffness",
    "Grasp",
    "Gripper",
    "grasp_sweep",
    "plot_grasp",
    "solve_grasp",
    "Wrist",
    "WristHold",
    "WristState",
    "plot_wrist",
    "wrist_bend",
    "wrist_hold",
    "wrist_moment",
    "wrist_pressures",
    "wrist_sweep",
]
