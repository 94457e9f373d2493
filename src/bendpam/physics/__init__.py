"""The physics layer: the actuator, its materials and braid kinematics, the two moment models, the
moment law that samples them, the limits and the hysteresis loop models.

Modules here import only each other, :mod:`bendpam.errors`, :mod:`bendpam.validate` and
:mod:`bendpam.infra` (a test checks it), never the lab, identification, design or presentation
layers.

* :mod:`~bendpam.physics.actuator`, :mod:`~bendpam.physics.presets`: the actuator's parameters.
* :mod:`~bendpam.physics.material`: the bladder's Mooney-Rivlin law.
* :mod:`~bendpam.physics.braid`: braid kinematics, eq 1-5.
* :mod:`~bendpam.physics.fixture`: the four-point-bending fixture, eq 6-8.
* :mod:`~bendpam.physics.models`: the energy (eq 9-21) and force-balance (eq 22-49) models.
* :mod:`~bendpam.physics.law`: :class:`~bendpam.physics.law.MomentLaw`, the only sampler of the models,
  and its spline table; the free-bending branch (:mod:`~bendpam.physics.branch`), the law along
  ``u = k'R`` (:mod:`~bendpam.physics.sections`) and the stable branch (:mod:`~bendpam.physics.stable`).
* :mod:`~bendpam.physics.fast`: the tabulated fast path; :mod:`~bendpam.physics.kernel`: its NumPy and optional
  numba kernels (bit-identical).
* :mod:`~bendpam.physics.limits`: frame stress, buckling, lock-up and bladder-stretch margins.
* :mod:`~bendpam.physics.hysteresis`: loop models around the quasi-static law.
* :mod:`~bendpam.physics.roots`: the vectorised root finders they share (bracketed Newton, Illinois,
  Newton from a table).
"""


def __getattr__(name: str):
    """Submodules on first use (``bendpam.physics.presets``), as an import statement would give them."""
    import importlib
    import importlib.util

    if importlib.util.find_spec(f"{__name__}.{name}") is not None:
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
