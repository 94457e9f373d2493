"""bendpam: models, tests and design tools for bending pneumatic artificial muscles.

Units inside the library: mm, N, MPa (N/mm^2), N*mm, 1/mm and radians.  Interfaces that users
type (the CLI, TOML files, Actuator fields) carry the unit in the name (``pressure_kpa``,
``alpha0_deg``).

Quick start::

    import bendpam
    a = bendpam.presets.be_pam()
    bendpam.blocked_moment(a, 0.2)                # N*mm at 200 kPa
    bendpam.free_curvature(a, [0.1, 0.2]).angle_deg
"""

from __future__ import annotations

from . import braid, fast, material, models, presets
from .actuator import NEUTRAL_ANGLE_DEG, Actuator
from .braid import CurvatureLimits, Kinematics, curvature_limits
from .material import MooneyRivlin
from .predict import (
    BranchInfo,
    FreeBending,
    active_pressure,
    blocked_moment,
    branch_info,
    free_curvature,
    internal_stresses,
    kinematics,
    moment,
    moment_terms,
    prediction_table,
    tangent_stiffness,
)

from .sweeps import sweep  # noqa: E402  (the function; the module is bendpam.sweeps)

__version__ = "0.1.0"

__all__ = [
    "Actuator",
    "NEUTRAL_ANGLE_DEG",
    "MooneyRivlin",
    "Kinematics",
    "CurvatureLimits",
    "braid",
    "fast",
    "BranchInfo",
    "FreeBending",
    "active_pressure",
    "blocked_moment",
    "branch_info",
    "curvature_limits",
    "free_curvature",
    "internal_stresses",
    "kinematics",
    "material",
    "models",
    "moment",
    "moment_terms",
    "prediction_table",
    "presets",
    "sweep",
    "tangent_stiffness",
]
