"""Export an identified or designed bending PAM to simulators (issue 27): MuJoCo.

:func:`mujoco` exports a finger, a gripper or the soft hand: its MJCF models (:func:`mujoco_model`,
:func:`hand_model`, :mod:`bendpam.export.mjcf`) and the quasi-static checks against bendpam
(:func:`validate`, :func:`validate_hand`, :mod:`bendpam.export.validation`); :mod:`bendpam.sim.mujoco`
applies the moment law at run time (:class:`HandController`: one pressure per part of the hand).
"""

from bendpam.export.mjcf import Densities, MujocoHand, MujocoModel, hand_model, mujoco_model
from bendpam.export.validation import (
    HandController,
    HandValidation,
    MujocoExport,
    Validation,
    mujoco,
    validate,
    validate_hand,
)

__all__ = ["Densities", "HandController", "HandValidation", "MujocoExport", "MujocoHand", "MujocoModel", "Validation",
           "hand_model", "mujoco", "mujoco_model", "validate", "validate_hand"]
