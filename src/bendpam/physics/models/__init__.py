"""The two quasi-static moment models.

* :mod:`bendpam.physics.models.energy`: virtual-work model, eq 9-21.
* :mod:`bendpam.physics.models.force_balance`: force-balance model, eq 22-49.

Both expose ``coefficients(actuator, curvature, order=..., **options) -> (A, B)`` with
``M(P, k') = max(P - P_start, 0) * A(k') - B(k')`` and ``terms(...)`` returning the named parts.
"""

from __future__ import annotations

from bendpam.errors import InputError
from bendpam.physics.models import energy, force_balance

__all__ = ["MODEL_NAMES", "energy", "force_balance", "get_model", "normalise_model"]

MODEL_NAMES = ("energy", "force_balance")


def normalise_model(model: str) -> str:
    """Map ``"energy"``, ``"force_balance"``, ``"force-balance"``, ``"fb"`` to a canonical name.

    >>> normalise_model("Force-Balance"), normalise_model("fb"), normalise_model("energy")
    ('force_balance', 'force_balance', 'energy')
    """
    key = str(model).strip().lower().replace("-", "_")
    aliases = {"energy": "energy", "virtual_work": "energy", "force_balance": "force_balance", "fb": "force_balance"}
    if key not in aliases:
        raise InputError(f"model = {model!r} is not known; choose 'energy' or 'force-balance'")
    return aliases[key]


def get_model(model: str):
    """Return the module implementing ``model`` (``"energy"`` or ``"force_balance"``/``"force-balance"``).

    >>> get_model("force-balance").__name__
    'bendpam.physics.models.force_balance'
    """
    return {"energy": energy, "force_balance": force_balance}[normalise_model(model)]
