"""Identification: the actuator's parameters from processed cyclic tests (paper section 3.4, eq 53-55).

* :mod:`bendpam.identify.fitting`: :func:`fit` and its objective (variable projection);
* :mod:`bendpam.identify.result`: :class:`FitResult` and its parts (save, load);
* :mod:`bendpam.identify.diagnose`: every judgement of a fit, by one table of limits;
* :mod:`bendpam.identify.data`, :mod:`bendpam.identify.metrics`, :mod:`bendpam.identify.numerics`,
  :mod:`bendpam.identify.uncertainty`: the curves a fit uses, the metrics of eq 53-55, the linear
  algebra and the covariance;
* :mod:`bendpam.identify.compare`: both actuator types fitted with the same freedom;
* :mod:`bendpam.identify.tension`: admissible Mooney-Rivlin constants from a uniaxial tension test.

The names below are re-exported here (``bendpam.identify.fit`` is the function, as it was before
the package was split into modules).
"""

from __future__ import annotations

from bendpam.identify.data import bladder_stretch_range, developed_range
from bendpam.identify.diagnose import LOOP_THRESHOLD, has_loop
from bendpam.identify.fitting import fit
from bendpam.identify.metrics import branch_nrmse, predicted_loss_ratios, score
from bendpam.identify.result import (
    HYST_PARAMETERS,
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
    parse_free,
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
