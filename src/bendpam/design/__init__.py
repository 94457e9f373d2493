"""Design tools: fingers under in-plane loads, grippers grasping spheres, and a four-actuator wrist.

* :mod:`bendpam.design.finger`: planar statics of a finger (rod along the frame line, the paper's
  moment law section by section), tip pose, structural limits; :mod:`bendpam.design.tip`: the
  blocked tip force and the tip stiffness.
* :mod:`bendpam.design.grasp`: an N-finger gripper closing on a sphere, contact and pull-out force
  (the paper's Figure 8 test): the gripper and a grasp (:mod:`bendpam.design.gripper`), the
  contact statics while closing (:mod:`bendpam.design.contact`), the pull-out
  (:mod:`bendpam.design.pullout`).
* :mod:`bendpam.design.inverse`: inverse design, actuator parameters from targets on its
  predictions (:func:`design_actuator`); its targets and variables (:mod:`bendpam.design.targets`),
  problem (:mod:`bendpam.design.problem`) and result (:mod:`bendpam.design.result`).
* :mod:`bendpam.design.wrist`: four BC-PAMs around a column (the paper's Figure 9 wrist): bending
  angle and direction, holding capacity.
* :mod:`bendpam.design.rod`: the one rod solver and Newton method they share;
  :mod:`bendpam.design.parts`: checked pressures and other small shared pieces.

Figures are drawn by :mod:`bendpam.present.figures.design`; the ``plot_*`` functions here reach
them by name (:func:`bendpam.infra.accessors.figure`).

Units: mm, N, N*mm, kPa for every pressure (arguments ``pressure_kpa``/``pressures_kpa``, result
fields and table columns), degrees in names ending ``_deg`` (rad inside), grams for masses.  Bad
input raises :class:`bendpam.InputError`; a pressure that looks like MPa (every nonzero value
below 5 kPa) warns with :class:`bendpam.UnitWarning`.  The moment law is the actuator's shared
:class:`bendpam.MomentLaw`; :class:`StableBranch` is :class:`bendpam.StableBranch`.
"""

from bendpam.design.finger import (
    Finger,
    FingerLoads,
    FingerShape,
    finger_sweep,
    free_tip_trajectory,
    plot_finger_shapes,
    solve_finger,
    stable_branch,
)
from bendpam.design.grasp import grasp_sweep, plot_grasp, solve_grasp
from bendpam.design.gripper import Grasp, Gripper
from bendpam.design.inverse import design_actuator
from bendpam.design.result import DesignResult
from bendpam.design.targets import Target, Variable
from bendpam.design.tip import BlockedTipForce, TipStiffness, blocked_tip_force, linear_tip_compliance, tip_stiffness
from bendpam.design.wrist import (
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
from bendpam.physics.law import StableBranch

__all__ = [
    "BlockedTipForce",
    "DesignResult",
    "Finger",
    "FingerLoads",
    "FingerShape",
    "Grasp",
    "Gripper",
    "StableBranch",
    "Target",
    "TipStiffness",
    "Variable",
    "Wrist",
    "WristHold",
    "WristState",
    "blocked_tip_force",
    "design_actuator",
    "finger_sweep",
    "free_tip_trajectory",
    "grasp_sweep",
    "linear_tip_compliance",
    "plot_finger_shapes",
    "plot_grasp",
    "plot_wrist",
    "solve_finger",
    "solve_grasp",
    "stable_branch",
    "tip_stiffness",
    "wrist_bend",
    "wrist_hold",
    "wrist_moment",
    "wrist_pressures",
    "wrist_sweep",
]
