"""Identification: the actuator's parameters from processed cyclic tests (paper section 3.4, eq 53-55).

* :mod:`bendpam.identify.fitting`: :func:`fit`, :class:`FitResult` and the metrics of eq 53-55.
* :mod:`bendpam.identify.tension`: admissible Mooney-Rivlin constants from a uniaxial tension test.

The names of :mod:`bendpam.identify.fitting` are re-exported here (``bendpam.identify.fit`` is the
function, as it was before the package was split into modules).
"""

from __future__ import annotations

from bendpam.identify.fitting import (
    HYST_PARAMETERS,
    LOOP_THRESHOLD,
    PARAMETERS,
    Band,
    ExtrapolationWarning,
    FitResult,
    HysteresisFit,
    JointInterval,
    LossRatio,
    MaterialFit,
    Metrics,
    Parameter,
    Profile,
    bladder_stretch_range,
    branch_nrmse,
    developed_range,
    fit,
    has_loop,
    parse_free,
    predicted_loss_ratios,
    score,
)

__all__ = [
    "HYST_PARAMETERS",
    "LOOP_THRESHOLD",
    "PARAMETERS",
    "Band",
    "ExtrapolationWarning",
    "FitResult",
    "HysteresisFit",
    "JointInterval",
    "LossRatio",
    "MaterialFit",
    "Metrics",
    "Parameter",
    "Profile",
    "bladder_stretch_range",
    "branch_nrmse",
    "developed_range",
    "fit",
    "has_loop",
    "parse_free",
    "predicted_loss_ratios",
    "score",
]
