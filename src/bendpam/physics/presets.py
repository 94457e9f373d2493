"""The paper's two actuators (Table 1 geometry, Table 3 constants for each model).

``be_pam(model="energy")`` and ``bc_pam(model="force_balance")`` etc. return an
:class:`~bendpam.physics.actuator.Actuator`.  The geometry is shared (Table 1, merged cells); each model has
its own identified braid angle and Mooney-Rivlin constants (Table 3; the unit "kPa^-1" is read as
kPa, docs/paper-reading.md item 8).  P_start is 68 kPa for the BE-PAM and 32 kPa for the BC-PAM
(docs/paper-reading.md item 15).
"""

from __future__ import annotations

from bendpam.errors import InputError
from bendpam.physics.actuator import Actuator
from bendpam.physics.models import normalise_model

__all__ = ["PRESETS", "bc_pam", "be_pam", "get", "normalise_model"]

MODELS = ("energy", "force_balance")

_TABLE1 = dict(
    R0_mm=8.5,
    t0_mm=2.5,
    L0_mm=145.0,
    frame_thickness_mm=0.5,
    frame_width_mm=5.0,
    frame_modulus_mpa=6796.0,
)

# Table 3: (alpha0_deg, C10_kpa, C01_kpa) per model
_TABLE3 = {
    ("be-pam", "energy"): (69.7, -318.9, 515.5),
    ("be-pam", "force_balance"): (69.7, -133.7, 373.3),
    ("bc-pam", "energy"): (36.57, 1485.3, -1196.8),
    ("bc-pam", "force_balance"): (36.60, 1499.9, -1169.9),
}

_START: dict[str, dict[str, float]] = {"be-pam": dict(P_start_kpa=68.0, R0_start_mm=10.1),
                                       "bc-pam": dict(P_start_kpa=32.0, R0_start_mm=8.6)}


def _make(which: str, model: str) -> Actuator:
    m = normalise_model(model)
    a0, c10, c01 = _TABLE3[(which, m)]
    label = "BE-PAM" if which == "be-pam" else "BC-PAM"
    return Actuator(
        alpha0_deg=a0,
        C10_kpa=c10,
        C01_kpa=c01,
        name=f"{label} (paper, {m.replace('_', '-')} constants)",
        model=m,
        **_TABLE1,  # type: ignore[arg-type]
        **_START[which],  # type: ignore[arg-type]
    )


def be_pam(model: str = "energy") -> Actuator:
    """The paper's bending-extensile PAM (nominal alpha0 = 68 deg) with ``model``'s Table 3 constants.

    >>> be = be_pam()
    >>> be.kind, be.alpha0_deg, be.C10_kpa, be.C01_kpa, be.P_start_kpa
    ('BE-PAM', 69.7, -318.9, 515.5, 68.0)
    >>> be_pam("force-balance").C10_kpa
    -133.7
    """
    return _make("be-pam", model)


def bc_pam(model: str = "energy") -> Actuator:
    """The paper's bending-contractile PAM (nominal alpha0 = 35 deg) with ``model``'s Table 3 constants.

    >>> bc = bc_pam()
    >>> bc.kind, bc.alpha0_deg, bc.P_start_kpa, bc.name
    ('BC-PAM', 36.57, 32.0, 'BC-PAM (paper, energy constants)')
    """
    return _make("bc-pam", model)


PRESETS = {"be-pam": be_pam, "bc-pam": bc_pam}


def get(name: str, model: str = "energy") -> Actuator:
    """Look a preset up by name (``"be-pam"`` or ``"bc-pam"``, case and ``_``/``-`` insensitive).

    >>> get("BC_PAM", "force_balance").name
    'BC-PAM (paper, force-balance constants)'
    """
    key = str(name).strip().lower().replace("_", "-")
    if key not in PRESETS:
        raise InputError(f"unknown preset {name!r}; choose one of: {', '.join(PRESETS)}")
    return PRESETS[key](model)
