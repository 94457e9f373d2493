"""Public model API: moments, blocked moment, stiffness, free bending, internal stresses.

Thin functions over :class:`bendpam.MomentLaw` (the one object that samples the moment law), in
the units a user types:

* pressure ``pressure_kpa``: kPa (gauge), >= 0 and at most the actuator's burst limit
  ``max_pressure_kpa`` (2000 kPa unless raised).  The active pressure is ``max(P - P_start, 0)``
  (eq 50): below the threshold the actuator gives only its passive (frame + bladder) response.
  A set of pressures whose every nonzero value is below 5 kPa raises a
  :class:`~bendpam.validate.UnitWarning` (MPa passed as kPa?).
* curvature ``curvature_per_mm``: the frame curvature k', 1/mm, positive toward the frame.  BE-PAMs
  bend freely with k' > 0, BC-PAMs with k' < 0 (docs/paper-reading.md item 17).
* moments: N*mm; stiffness dM/dk': N*mm^2.

All functions broadcast pressure against curvature and share the cached law of the actuator
(:meth:`MomentLaw.of`), so repeated calls do not rebuild the free-bending branch.  Bad input
(``None``, a string, NaN, inf, a pressure above the burst limit, a curvature beyond lock-up) raises
one :class:`~bendpam.errors.InputError` line; a result beyond a plausibility bound warns with
:class:`~bendpam.errors.PlausibilityWarning` (docs/plausibility.md).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from bendpam.errors import InputError
from bendpam.infra import budgets
from bendpam.infra.budgets import MEMORY_BUDGET_GIB, memory_problem
from bendpam.physics.actuator import Actuator
from bendpam.physics.braid import DEFAULT_ORDER, Kinematics
from bendpam.physics.braid import kinematics as _kinematics
from bendpam.physics.law import FreeBending, FreeBranch, MomentLaw
from bendpam.physics.models import force_balance as _fb
from bendpam.validate import instance, integer

__all__ = [
    "active_pressure_kpa",
    "blocked_moment",
    "free_branch",
    "free_curvature",
    "internal_stresses",
    "kinematics",
    "moment",
    "moment_terms",
    "prediction_columns",
    "prediction_table",
    "tangent_stiffness",
]


_ACTUATOR = "a bendpam.Actuator (e.g. bendpam.physics.presets.get('be-pam'))"


def _law(actuator, model, eq19_factor, order) -> MomentLaw:
    return MomentLaw.of(actuator, model, eq19_factor=eq19_factor, order=order)


def _tested(actuator: Actuator, pressure_kpa, result):
    """``result``, after warning if ``pressure_kpa`` (already validated) is outside the actuator's tested range."""
    actuator.outside_tested(pressure_kpa)
    return result


def active_pressure_kpa(actuator: Actuator, pressure_kpa) -> np.ndarray:
    """Active pressure ``max(P - P_start, 0)`` in kPa (eq 50).

    >>> import bendpam
    >>> bendpam.active_pressure_kpa(bendpam.physics.presets.be_pam(), [50, 200]).tolist()
    [0.0, 132.0]
    """
    return _law(instance("actuator", actuator, Actuator, _ACTUATOR), None, True, DEFAULT_ORDER
                ).active_pressure_kpa(pressure_kpa)


def kinematics(actuator: Actuator, curvature_per_mm, *, order: int = DEFAULT_ORDER) -> Kinematics:
    """Braid kinematics at ``curvature_per_mm`` (1/mm): see :class:`bendpam.physics.braid.Kinematics` (eq 1-5).

    >>> import bendpam
    >>> kin = bendpam.kinematics(bendpam.physics.presets.be_pam(), 0.01)
    >>> round(float(kin.radius), 3), round(float(kin.eta), 4), round(float(kin.axis_curvature), 6)
    (9.949, 0.9851, 0.009095)
    """
    return _kinematics(instance("actuator", actuator, Actuator, _ACTUATOR), curvature_per_mm, order)


def moment(actuator: Actuator, pressure_kpa, curvature_per_mm, model: str | None = None, *,
           eq19_factor: bool = True, order: int = DEFAULT_ORDER) -> np.ndarray:
    """Output moment ``M_load(P, k')`` in N*mm (eq 21 or eq 49, corrected by eq 50-52).

    Parameters
    ----------
    actuator : Actuator
    pressure_kpa : array_like
        Gauge pressure, kPa, >= 0.
    curvature_per_mm : array_like
        Frame curvature k', 1/mm, within the lock-up limits (:func:`bendpam.curvature_limits`).
    model : {"energy", "force_balance"} or None
        ``"force-balance"`` is accepted too.  None (default): the actuator's own model
        (:attr:`Actuator.model <bendpam.Actuator.model>`, energy when unknown); another model than the
        actuator's warns (:class:`~bendpam.errors.ModelMismatchWarning`).
    eq19_factor : bool
        Energy model only: keep eq 19's ``(1 + k'R)`` factor (default, as printed).
    order : int
        0 (default): closed-form section integrals; N in [4, 1024]: N Gauss-Legendre nodes on [0, pi].

    Returns
    -------
    ndarray
        ``np.broadcast(pressure_kpa, curvature_per_mm).shape``, N*mm.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> be = bendpam.physics.presets.be_pam()
    >>> bendpam.moment(be, [[100.0], [200.0]], [0.0, 0.01]).round(1).tolist()
    [[75.2, -130.1], [310.3, 63.2]]
    """
    return _tested(actuator, pressure_kpa, _law(actuator, model, eq19_factor, order).moment(pressure_kpa,
                                                                                           curvature_per_mm))


def moment_terms(actuator: Actuator, pressure_kpa, curvature_per_mm, model: str | None = None, *,
                 eq19_factor: bool = True, order: int = DEFAULT_ORDER) -> dict[str, np.ndarray]:
    """The named parts of the moment in N*mm.

    Energy model: ``M_load, M_air, M_bl, M_f`` (eq 13, 19, 16, 21).
    Force-balance model: ``M_load, M_p, M_frame, M_bl, M_br`` (eq 23-28, 49).

    >>> import bendpam
    >>> t = bendpam.moment_terms(bendpam.physics.presets.be_pam(), 200.0, 0.01)
    >>> sorted(t)
    ['M_air', 'M_bl', 'M_f', 'M_load']
    """
    return _tested(actuator, pressure_kpa, _law(actuator, model, eq19_factor, order).terms(pressure_kpa,
                                                                                          curvature_per_mm))


def blocked_moment(actuator: Actuator, pressure_kpa, model: str | None = None, *, eq19_factor: bool = True,
                   order: int = DEFAULT_ORDER) -> np.ndarray:
    """Blocked moment ``M(P, 0)`` in N*mm.

    Both models reduce to ``pi R0_start^3 (1 - 2 cot^2 alpha0) max(P - P_start, 0)`` at k' = 0
    (docs/paper-reading.md item 14); the result is negative for a BC-PAM.

    >>> import bendpam
    >>> round(float(bendpam.blocked_moment(bendpam.physics.presets.be_pam(), 200.0)), 1)
    310.3
    """
    return _tested(actuator, pressure_kpa, _law(actuator, model, eq19_factor, order).blocked_moment(pressure_kpa))


def tangent_stiffness(actuator: Actuator, pressure_kpa, curvature_per_mm, model: str | None = None, *,
                      eq19_factor: bool = True, order: int = DEFAULT_ORDER) -> np.ndarray:
    """Tangent stiffness ``dM/dk'`` in N*mm^2 (fourth-order central difference of A and B).

    >>> import bendpam
    >>> bool(bendpam.tangent_stiffness(bendpam.physics.presets.be_pam(), 150.0, 0.005) < 0)
    True
    """
    law = _law(actuator, model, eq19_factor, order)
    return _tested(actuator, pressure_kpa, law.tangent_stiffness(pressure_kpa, curvature_per_mm))


def free_branch(actuator: Actuator, model: str | None = None, *, eq19_factor: bool = True,
                order: int = DEFAULT_ORDER) -> FreeBranch:
    """The free-bending branch of ``actuator``: fold or lock-up pressure and the sampled curve.

    >>> import bendpam
    >>> br = bendpam.free_branch(bendpam.physics.presets.bc_pam())
    >>> br.kind, round(br.max_pressure_kpa, 1)
    ('fold', 134.2)
    """
    return _law(actuator, model, eq19_factor, order).free_branch()


def free_curvature(actuator: Actuator, pressure_kpa, model: str | None = None, *, eq19_factor: bool = True,
                   order: int = DEFAULT_ORDER, xtol: float = 1e-13) -> FreeBending:
    """Free-bending curvature: the root of ``M(P, k') = 0`` on the branch the actuator bends along.

    The branch starts at k' = 0 (straight, at P_start) and runs in the bending direction
    (k' > 0 for a BE-PAM, k' < 0 for a BC-PAM) while the equilibrium pressure ``P_a = B/A``
    rises.  Above the fold pressure (or the lock-up pressure) there is no equilibrium on it: the
    curvature is NaN, the status ``"no-equilibrium"`` and the reason says why.  A root on a
    disconnected branch beyond a fold is never returned.

    >>> import bendpam
    >>> fb = bendpam.free_curvature(bendpam.physics.presets.bc_pam(), [100.0, 150.0])
    >>> fb.status.tolist(), round(fb.max_pressure_kpa, 1)
    (['ok', 'no-equilibrium'], 134.2)
    """
    return _tested(actuator, pressure_kpa, _law(actuator, model, eq19_factor, order).free_curvature(pressure_kpa,
                                                                                                   xtol=xtol))


# ------------------------------------------------------------------------------------------------
# internal stresses (force-balance model)
# ------------------------------------------------------------------------------------------------
#: User-facing names (with their units) of the force-balance stress state's variables.
_STRESS_NAMES = {
    "sigma_bl1": "sigma_bl1_kpa",
    "sigma_bl2": "sigma_bl2_kpa",
    "sigma_bl3": "sigma_bl3_kpa",
    "P_e": "P_e_kpa",
    "N_br1": "N_br1_n_per_mm",
    "N_br2": "N_br2_n_per_mm",
    "sigma_br1": "sigma_br1_kpa",
    "sigma_br2": "sigma_br2_kpa",
    "t_bar": "t_bar_mm",
    "R": "R_mm",
}


#: Unit, meaning and scale from the model's units (MPa, N/mm, rad, mm) of each variable of the stress state.
_STRESS_UNITS = {
    "sigma_bl1": ("kPa", "bladder axial stress (eq 43)", 1e3),
    "sigma_bl2": ("kPa", "bladder hoop stress (eq 44)", 1e3),
    "sigma_bl3": ("kPa", "bladder radial stress, -P_active (eq 37)", 1e3),
    "P_e": ("kPa", "interfacial pressure bladder-braid (eq 45)", 1e3),
    "N_br1": ("N/mm", "braid axial line tension sigma_br1 * t_br (eq 48)", 1.0),
    "N_br2": ("N/mm", "braid hoop line tension P_e R (eq 31)", 1.0),
    "sigma_br1": ("kPa", "braid nominal axial stress (eq 48)", 1e3),
    "sigma_br2": ("kPa", "braid nominal hoop stress (eq 31)", 1e3),
    "braid_angle": ("deg", "local braid angle alpha(Phi)", 1.0),
    "t_bar": ("mm", "mean bladder thickness (eq 40)", 1.0),
    "R": ("mm", "deformed radius (eq 5)", 1.0),
}


def internal_stresses(actuator: Actuator, pressure_kpa, curvature_per_mm, *, n_phi: int = 181,
                      order: int = DEFAULT_ORDER, max_memory_gib: float | None = MEMORY_BUDGET_GIB) -> Any:
    """Internal state of the force-balance model (eq 37-48) around the cross-section.

    The stress state exists in the force-balance model only: an actuator whose constants were
    identified with the energy model warns (:class:`~bendpam.errors.ModelMismatchWarning`).

    Parameters
    ----------
    pressure_kpa : float or 1-D array, kPa.
    curvature_per_mm : float or 1-D array, 1/mm.
    n_phi : number of angles on [0, 360] deg (2 to 100 000).
    max_memory_gib : memory budget (GiB; None: only this machine's memory).  The result holds
        ``8 x (4 n_phi + 7)`` bytes per (pressure, curvature); a result larger than the budget is
        refused before any work.  The states are computed in chunks of pressures, so the
        working arrays take at most about 64 MiB beside the result.

    Returns
    -------
    xarray.Dataset
        Dimensions ``pressure_kpa`` and ``curvature_per_mm`` (when given as arrays) and
        ``phi_deg`` (0 at the frame).  Variables, each named with its unit (also in
        ``attrs["units"]``): ``sigma_bl1_kpa``, ``sigma_bl2_kpa``, ``sigma_bl3_kpa``, ``P_e_kpa``,
        ``sigma_br1_kpa``, ``sigma_br2_kpa``, ``N_br1_n_per_mm``, ``N_br2_n_per_mm``,
        ``braid_angle_deg``, ``t_bar_mm``, ``R_mm``.

    Examples
    --------
    >>> import bendpam
    >>> ds = bendpam.internal_stresses(bendpam.physics.presets.bc_pam("force_balance"), 120.0, -0.006)
    >>> ds["P_e_kpa"].attrs["units"], ds["sigma_bl1_kpa"].dims
    ('kPa', ('phi_deg',))
    """
    law = _law(actuator, "force_balance", True, order)
    P = law.check_pressure(pressure_kpa)
    k = law.check_curvature(curvature_per_mm)
    if P.ndim > 1 or k.ndim > 1:
        raise InputError("internal_stresses takes scalar or 1-D pressure_kpa and curvature_per_mm")
    phi = np.linspace(0.0, 2.0 * np.pi, integer("n_phi", n_phi, 2, 100_000))
    pa = law.active_pressure_kpa(P) * 1e-3  # MPa inside the numerics
    Pg = pa.reshape(pa.shape + (1,) * k.ndim)
    S = np.broadcast_shapes(Pg.shape, k.shape)
    _check_stress_memory(S, P, k, phi.size, max_memory_gib)
    arrays = _stress_arrays(law, Pg, k, phi, S, order)
    return _tested(actuator, P, _stress_dataset(actuator, arrays, P, k, phi))


#: The variables of the stress state that vary around the section (the others are one value per state).
_PER_ANGLE = ("sigma_bl1", "N_br1", "sigma_br1", "braid_angle")
#: Working memory of the stress state per element of a chunk (its temporaries), bytes.
_STRESS_WORK_BYTES = 160


def _check_stress_memory(S: tuple[int, ...], P: np.ndarray, k: np.ndarray, n_phi: int,
                         max_memory_gib: float | None) -> None:
    """Refuse, before any work, an :func:`internal_stresses` result larger than the memory budget."""
    if max_memory_gib is not None and not (isinstance(max_memory_gib, int | float) and max_memory_gib > 0):
        raise InputError(f"max_memory_gib = {max_memory_gib!r} must be a number of GiB > 0 (or None)")
    n = int(np.prod(S))
    need = 8.0 * n * (len(_PER_ANGLE) * n_phi + len(_STRESS_UNITS) - len(_PER_ANGLE)) + budgets.CHUNK_BYTES
    problem = memory_problem(need, max_memory_gib)
    if problem is not None:
        size = " x ".join([f"{P.size} pressures"] * bool(P.ndim) + [f"{k.size} curvatures"] * bool(k.ndim)
                          + [f"{n_phi} angles"])
        raise InputError(f"internal_stresses: {size} would hold {problem}; give fewer pressures, curvatures or "
                         "angles (n_phi), or raise max_memory_gib")


def _stress_arrays(law: MomentLaw, Pg: np.ndarray, k: np.ndarray, phi: np.ndarray, S: tuple[int, ...],
                   order: int) -> dict[str, np.ndarray]:
    """The stress state of shape ``S`` (+ angles) in the dataset's units, computed in chunks of rows of ``S``.

    Each chunk's temporaries take at most about :data:`bendpam.infra.budgets.CHUNK_BYTES`; the
    values are the same as in one block (the state is computed element by element).
    """
    per_row = int(np.prod(S[1:])) * max(phi.size, order)
    rows = max(1, budgets.CHUNK_BYTES // (_STRESS_WORK_BYTES * per_row))
    Pb, kb = np.broadcast_to(Pg, S), np.broadcast_to(k, S)
    out: dict[str, np.ndarray] = {}
    for start in range(0, S[0] if S else 1, rows):
        sl = slice(start, start + rows) if S else ()
        st = _fb.stress_state(law.params, Pb[sl], kb[sl], phi, order=order)
        for name, arr in st.items():
            if name not in out:
                out[name] = np.empty(S + ((phi.size,) if name in _PER_ANGLE else ()))
            scale = _STRESS_UNITS[name][2]
            chunk = np.degrees(arr) if name == "braid_angle" else np.asarray(arr) * scale
            out[name][sl] = chunk
    return out


def _stress_dataset(actuator: Actuator, arrays: dict[str, np.ndarray], P: np.ndarray, k: np.ndarray,
                    phi: np.ndarray) -> Any:
    """The :func:`internal_stresses` dataset from the stress state ``arrays`` (the dataset's units)."""
    import xarray as xr

    dims = (["pressure_kpa"] if P.ndim else []) + (["curvature_per_mm"] if k.ndim else [])
    data = {}
    for name, arr in arrays.items():
        d = dims + (["phi_deg"] if name in _PER_ANGLE else [])
        unit, long_name, _scale = _STRESS_UNITS[name]
        data["braid_angle_deg" if name == "braid_angle" else _STRESS_NAMES[name]] = xr.DataArray(
            arr, dims=d, attrs={"units": unit, "long_name": long_name})
    coords: dict[str, Any] = {"phi_deg": np.degrees(phi)}
    if P.ndim:
        coords["pressure_kpa"] = P
    if k.ndim:
        coords["curvature_per_mm"] = k
    ds = xr.Dataset(data, coords=coords)
    ds["phi_deg"].attrs.update(units="deg", long_name="angle around the section, 0 at the frame")
    if P.ndim:
        ds["pressure_kpa"].attrs.update(units="kPa", long_name="gauge pressure")
    else:
        ds.attrs["pressure_kpa"] = float(P)
    if k.ndim:
        ds["curvature_per_mm"].attrs.update(units="1/mm", long_name="frame curvature k'")
    else:
        ds.attrs["curvature_per_mm"] = float(k)
    ds.attrs.update(model="force_balance", actuator=actuator.name or actuator.kind, P_start_kpa=actuator.P_start_kpa)
    return ds


# ------------------------------------------------------------------------------------------------
# tables
# ------------------------------------------------------------------------------------------------
def prediction_columns(actuator: Actuator, pressure_kpa, model: str | None = None, *, eq19_factor: bool = True,
                       order: int = DEFAULT_ORDER) -> dict[str, np.ndarray]:
    """The columns of :func:`prediction_table` as a dict of NumPy arrays (no pandas: a few rows print faster).

    >>> import bendpam
    >>> cols = prediction_columns(bendpam.physics.presets.be_pam(), [100, 200])
    >>> list(cols)[:3], cols["pressure_kpa"].tolist()
    (['pressure_kpa', 'blocked_moment_nmm', 'free_curvature_per_mm'], [100.0, 200.0])
    """
    from bendpam.physics.limits import OUTPUTS, limits

    law = _law(actuator, model, eq19_factor, order)
    P = np.atleast_1d(law.check_pressure(pressure_kpa))
    if P.ndim != 1:
        raise InputError(f"pressure_kpa must be a number or a 1-D list of pressures, got shape {P.shape}")
    fb = law.free_curvature(P)
    lim = limits(actuator, P, law.model, eq19_factor=eq19_factor, order=order)  # warns outside the tested range
    return {
        "pressure_kpa": P,
        "blocked_moment_nmm": law.blocked_moment(P),
        "free_curvature_per_mm": fb.curvature_per_mm,
        "free_angle_deg": fb.angle_deg,
        **{name: getattr(lim, name) for name in OUTPUTS},
        "status": fb.status,
        "note": fb.reason,
        "limit_note": lim.notes,
    }


def prediction_table(actuator: Actuator, pressure_kpa, model: str | None = None, *, eq19_factor: bool = True,
                     order: int = DEFAULT_ORDER) -> Any:
    """Blocked moment, free bending and the structural limits at each pressure, as a :class:`pandas.DataFrame`.

    Columns: ``pressure_kpa``, ``blocked_moment_nmm``, ``free_curvature_per_mm``,
    ``free_angle_deg``; the limits of :func:`bendpam.physics.limits` (the worse of the blocked and free
    states): ``frame_axial_force_n``, ``frame_stress_mpa``, the safety factors
    ``frame_strength_margin``, ``buckling_margin``, ``lockup_margin``, ``bladder_stretch_margin``
    (>= 1 within the limit, inf without demand or limit), ``bladder_stretch_max`` and
    ``min_margin``; ``status``, ``note`` (the reason where there is no equilibrium) and
    ``limit_note`` (each limit the prediction is past, empty within every limit).
    Signs follow the paper: k' > 0 toward the frame, so BC-PAM values are negative.
    :func:`prediction_columns` gives the same columns without pandas.

    >>> import bendpam
    >>> bendpam.prediction_table(bendpam.physics.presets.be_pam(), [100, 200]).columns.tolist()[:3]
    ['pressure_kpa', 'blocked_moment_nmm', 'free_curvature_per_mm']
    """
    import pandas as pd

    return pd.DataFrame(prediction_columns(actuator, pressure_kpa, model, eq19_factor=eq19_factor, order=order))
