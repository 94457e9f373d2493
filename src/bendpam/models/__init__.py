"""The two quasi-static moment models.

* :mod:`bendpam.models.energy`: virtual-work model, eq 9-21.
* :mod:`bendpam.models.force_balance`: force-balance model, eq 22-49.

Both expose ``coefficients(actuator, curvature, order=..., **options) -> (A, B)`` with
``M(P, k') = max(P - P_start, 0) * A(k') - B(k')`` and ``terms(...)`` returning the named parts.
"""

from __future__ import annotations

from ..presets import normalise_model
from . import energy, force_balance

__all__ = ["energy", "force_balance", "get_model", "MODEL_NAMES"]

MODEL_NAMES = ("energy", "force_balance")


def get_model(model: str):
    """Return the module implementing ``model`` (``"energy"`` or ``"force_balance"``/``"force-balance"``)."""
    return {"energy": energy, "force_balance": force_balance}[normalise_model(model)]
