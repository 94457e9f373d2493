"""Export an identified or designed bending PAM to simulators (issue 27): MuJoCo.

:func:`mujoco_model` writes the MJCF of a finger or a gripper (:mod:`bendpam.export.mjcf`);
:mod:`bendpam.sim.mujoco` applies the moment law at run time.
"""

from bendpam.export.mjcf import Densities, MujocoModel, mujoco_model

__all__ = ["Densities", "MujocoModel", "mujoco_model"]
