"""The two quasi-static moment models.

* :mod:`bendpam.physics.models.energy`: virtual-work model, eq 9-21.
* :mod:`bendpam.physics.models.force_balance`: force-balance model, eq 22-49.

Both expose ``coefficients(actuator, curvature, order=..., **options) -> (A, B)`` with
``M(P, k') = max(P - P_start, 0) * A(k') - B(k')`` and ``terms(...)`` returning the named parts.
"""

from __future__ import annotations

from bendpam.errors import InputError, ModelMismatchWarning, warn_user
from bendpam.physics.models import energy, force_balance

__all__ = ["MODEL_NAMES", "energy", "force_balance", "get_model", "normalise_model", "resolve_model"]

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


class _Chosen(str):
    """A model name already resolved against its actuator (:func:`resolve_model` passes it through unchanged).

    Functions hand the resolved name down to the ones they call; those do not warn a second time.
    """

    __slots__ = ()


def resolve_model(actuator, model: str | None = None, *, warn: bool = True) -> str:
    """The model to evaluate ``actuator`` with: ``model`` if given, else the one its constants came from.

    The one place where the default model is chosen: ``model=None`` gives the actuator's own
    :attr:`~bendpam.Actuator.model` (``"energy"`` when it is unknown, ``""``, or for a block of
    cases).  An explicit ``model`` that differs from the actuator's warns once with
    :class:`~bendpam.errors.ModelMismatchWarning` (``warn=False``: on purpose, e.g. a fit that starts
    from constants of the other model).  The name returned is canonical and is passed through
    unchanged (no second warning) by the functions it is handed to.

    >>> import bendpam
    >>> fb = bendpam.physics.presets.be_pam("force_balance")
    >>> resolve_model(fb), resolve_model(bendpam.physics.presets.be_pam()), resolve_model(fb, "fb")
    ('force_balance', 'energy', 'force_balance')
    """
    if isinstance(model, _Chosen):
        return model
    own = getattr(actuator, "model", "") or ""
    if model is None:
        return _Chosen(own or "energy")
    name = normalise_model(model)
    if warn and own and own != name:
        label = getattr(actuator, "name", "") or getattr(actuator, "kind", "actuator")
        warn_user(f"{label}: its constants were identified with the {own.replace('_', '-')} model; "
                  f"using them with the {name.replace('_', '-')} model", ModelMismatchWarning)
    return _Chosen(name)
