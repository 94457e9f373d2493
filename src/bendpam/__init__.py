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

``import bendpam`` imports nothing but the errors and the version: every other name here (the
models, NumPy with them) is imported the first time it is used, and heavy modules (SciPy's
optimisers, xarray, pandas, matplotlib, Dask) only by the functions that need them, so the
command line starts quickly (``bendpam --help`` does not import NumPy).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

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
from bendpam.version import __version__ as __version__

if TYPE_CHECKING:  # what the lazy names below are, for type checkers and editors
    from bendpam.design.inverse import design_actuator
    from bendpam.identify.fitting import fit
    from bendpam.lab.processing import process_tests
    from bendpam.lab.readers import read_test
    from bendpam.lab.simulate import simulate_test
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
    from bendpam.sweeps import sweep
    from bendpam.validate import UnitWarning

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

# Everything else is loaded on first use (PEP 562), NumPy included: the command line's ``--help`` and
# ``--version`` import this package and must not pay for the numerics.  name: (module, attribute or
# None for the module itself).
_LAZY: dict[str, tuple[str, str | None]] = {
    **{name: (f"physics.{name}", None) for name in ("braid", "material", "models", "presets")},
    **{name: ("physics.actuator", name) for name in ("NEUTRAL_ANGLE_DEG", "Actuator", "ModelParams")},
    **{name: ("physics.braid", name) for name in ("CurvatureLimits", "Kinematics", "curvature_limits")},
    **{name: ("physics.law", name) for name in ("FreeBending", "FreeBranch", "MomentLaw", "MomentTable",
                                                "StableBranch")},
    **{name: ("physics.limits", name) for name in ("Limits", "limits")},
    "MooneyRivlin": ("physics.material", "MooneyRivlin"),
    **{name: ("predict", name) for name in ("active_pressure_kpa", "blocked_moment", "free_branch",
                                            "free_curvature", "internal_stresses", "kinematics", "moment",
                                            "moment_terms", "prediction_table", "tangent_stiffness")},
    "UnitWarning": ("validate", "UnitWarning"),
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
    "export": ("export", None),
    "sim": ("sim", None),
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


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
