"""Export an identified or designed bending PAM to simulators (issue 27): MuJoCo.

:func:`mujoco` exports a finger or a gripper: its MJCF models (:func:`mujoco_model`,
:mod:`bendpam.export.mjcf`) and the quasi-static checks against bendpam
(:func:`validate`, :mod:`bendpam.export.validation`); :mod:`bendpam.sim.mujoco` applies the moment
law at run time.
"""

from bendpam.export.mjcf import Densities, MujocoModel, mujoco_model
from bendpam.export.validation import MujocoExport, Validation, mujoco, validate

__all__ = ["Densities", "MujocoExport", "MujocoModel", "Validation", "mujoco", "mujoco_model", "validate"]
