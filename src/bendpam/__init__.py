"""bendpam: models, tests and design tools for bending pneumatic artificial muscles.

Units at every public edge: pressure in kPa, lengths in mm, force in N, moments in N*mm,
curvature in 1/mm, angles in degrees; the name of an argument, field, column or key says its unit
(``pressure_kpa``, ``alpha0_deg``).  MPa and radians live only inside the numerics.

Quick start::

    import bendpam
    a = bendpam.physics.presets.be_pam()
    bendpam.blocked_moment(a, 200.0)               # N*mm at 200 kPa
    bendpam.free_curvature(a, [100.0, 200.0]).angle_deg
    law = bendpam.MomentLaw.of(a, "energy")         # the moment law as one object

Heavy modules (SciPy's optimisers, xarray, pandas, matplotlib, Dask) are imported only by the
functions that need them, so ``import bendpam`` and the command line start quickly.
"""

from __future__ import annotations

from typing import Any

from bendpam import errors
from bendpam.errors import (
    BendpamError,
    FileFormatError,
    FitError,
    InputError,
    InputTypeError,
    ModelMismatchWarning,
    NoEquilibrium,
    OutsideTestedRangeWarning,
    PlausibilityWarning,
    ProcessingError,
)
from bendpam.physics import braid, material, models, presets
from bendpam.physics.actuator import NEUTRAL_ANGLE_DEG, Actuator, ModelParams
from bendpam.physics.braid import CurvatureLimits, Kinematics, curvature_limits
from bendpam.physics.law import FreeBending, FreeBranch, MomentLaw, MomentTable, StableBranch
from bendpam.physics.limits import Limits, limits
from bendpam.physics.material import MooneyRivlin
from bendpam.predict import (
    active_pressure_kpa,
    blocked_moment,
    free_branch,
    free_curvature,
    internal_stresses,
    kinematics,
    moment,
    moment_terms,
    prediction_table,
    tangent_stiffness,
)
from bendpam.validate import UnitWarning
from bendpam.version import __version__ as __version__

__all__ = [
    "NEUTRAL_ANGLE_DEG",
    "Actuator",
    "BendpamError",
    "CurvatureLimits",
    "FileFormatError",
    "FitError",
    "FreeBending",
    "FreeBranch",
    "InputError",
    "InputTypeError",
    "Kinematics",
    "Limits",
    "ModelMismatchWarning",
    "ModelParams",
    "MomentLaw",
    "MomentTable",
    "MooneyRivlin",
    "NoEquilibrium",
    "OutsideTestedRangeWarning",
    "PlausibilityWarning",
    "ProcessingError",
    "StableBranch",
    "UnitWarning",
    "active_pressure_kpa",
    "blocked_moment",
    "braid",
    "curvature_limits",
    "design_actuator",
    "errors",
    "fit",
    "free_branch",
    "free_curvature",
    "internal_stresses",
    "kinematics",
    "limits",
    "material",
    "models",
    "moment",
    "moment_terms",
    "prediction_table",
    "presets",
    "process_tests",
    "read_test",
    "read_tests",
    "simulate_test",
    "sweep",
    "tangent_stiffness",
]

# Functions whose modules import heavy dependencies are loaded on first use.
_LAZY = {
    "sweep": ("sweeps", "sweep"),
    "design_actuator": ("design.inverse", "design_actuator"),
    "fit": ("identify.fitting", "fit"),
    "read_test": ("lab.readers", "read_test"),
    "read_tests": ("lab.readers", "read_tests"),
    "process_tests": ("lab.processing", "process_tests"),
    "simulate_test": ("lab.simulate", "simulate_test"),
    "fast": ("physics.fast", None),
    "sweeps": ("sweeps", None),
    "identify": ("identify", None),
    "hysteresis": ("physics.hysteresis", None),
    "design": ("design", None),
    "lab": ("lab", None),
    "physics": ("physics", None),
    "present": ("present", None),
    "infra": ("infra", None),
    "plots": ("present.figures", None),
    "report": ("present.report", None),
    "fixture": ("physics.fixture", None),
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        mod_name, attr = _LAZY[name]
        mod = importlib.import_module(f".{mod_name}", __name__)
        value = mod if attr is None else getattr(mod, attr)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'bendpam' has no attribute {name!r}")
