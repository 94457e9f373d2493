r"""Structural limits of a bending PAM as physics: frame force, stress and buckling, lock-up, bladder stretch.

For an actuator at each pressure, in two states:

* **blocked**: ``k' = 0`` (held straight, the blocked-moment test);
* **free**: ``k'`` the free-bending curvature on the branch connected to the straight state
  (:meth:`bendpam.MomentLaw.free_curvature`); NaN where the branch has ended (fold or lock-up).

bendpam computes

1. the frame's **axial force** ``N`` (N, tension positive) from the axial force balance of a
   cross-section (:func:`bendpam.physics.models.force_balance.axial_forces`, eq 22-26 with eq 43-48)::

       N = pi R^2 P_a - F_br - F_bl

   where ``pi R^2 P_a`` is the pressure on the lumen plus the hydrostatic part of the bladder's
   axial stress (eq 49's reading, docs/paper-reading.md item 9), ``F_br`` the braid's axial resultant and
   ``F_bl`` the bladder's elastic axial resultant.  With no external axial load the frame carries
   the rest.  At ``k' = 0`` this is ``N = pi R0_start^2 P_a (1 - 2 cot^2 alpha0)``: the classic McKibben
   force ``P pi R^2 (3 cos^2 a - 1) / sin^2 a`` with the opposite sign, because the frame holds the
   actuator at its length.  A BE-PAM (alpha0 > 54.74 deg) pulls its frame (tension), a BC-PAM
   pushes it (compression), and ``N R0_start`` is the blocked moment.
2. the frame's **stresses** (MPa): axial ``N / (w h)``, bending ``E_f h |k'| / 2``, and the largest
   combined ``|N| / (w h) + E_f h |k'| / 2``, against the actuator's optional ``frame_strength_mpa``.
3. **buckling** of the frame under compression (below).
4. the **lock-up margin** of free bending: the curvature at which the free-bending branch ends
   (braid lock-up, or a fold of the moment law) over the free curvature; past the end of the
   branch, where there is no free-bending equilibrium, the ratio of the active pressures
   ``P_a,end / P_a`` (< 1).
5. the bladder's **largest principal stretch** from the as-made tube, against the optional
   ``bladder_stretch_limit``.

Every margin is a safety factor, capacity / demand: ``>= 1`` within the limit, ``inf`` when
there is no demand (a frame in tension cannot buckle; a demand below ``1e-9`` of the capacity is
round-off and counts as none) or no limit is given.  ``min_margin`` is the
smallest; the margins reported per pressure are the worse of the two states.

Buckling model (Hetényi's beam on an elastic foundation)
--------------------------------------------------------
The frame (a strip of width ``w``, thickness ``h``, modulus ``E_f``, length ``L0``) lies between the
bladder and the braid.  Under a compression ``-N`` it can buckle out of its plane, into the
bladder wall and against the braid, in half-waves of length ``L0 / m``.  bendpam treats it as a
beam on a Winkler foundation (Hetényi, *Beams on Elastic Foundation*, 1946, ch. 10)::

    E_f I_f w'''' - N w'' + beta w = 0,   N_cr = min over m = 1, 2, ... of  E_f I_f (m pi / L0)^2 + beta (L0 / (m pi))^2

with pinned ends (``w = w'' = 0``), for which the sine modes are exact.  The minimum lies at one
of the two integers around ``m* = (L0 / pi) (beta / E_f I_f)^(1/4)``; for ``m* >> 1``,
``N_cr -> 2 sqrt(beta E_f I_f)``.  The foundation modulus (force per length per deflection,
N/mm^2) is the bladder wall under the frame as a thin elastic layer::

    beta = E_bl w / t_f,   E_bl = 6 (C10 + C01),   t_f = t0_start / eta

``E_bl`` is the small-strain Young's modulus of the incompressible Mooney-Rivlin bladder and
``t_f`` the wall thickness under the frame (there ``lambda1 = 1``, so incompressibility gives
``t0_start / eta`` with ``eta = R / R0_start``).  The buckling margin is ``N_cr / max(-N, 0)``.

Assumptions (stated, with their direction):

* **Pinned ends.**  The frame ends sit in the end fittings, which would rather clamp them.  Pinned
  ends give the exact closed form above and a lower bound of the clamped load (rotational restraint
  can only raise it); with the paper's frames the buckle has about 15 half-waves and the clamped
  load is only 0.7 % higher (a finite-difference eigenvalue check), so the choice is conservative
  and hardly matters.  Without a foundation it would (a factor 4, Euler).
* **A Winkler foundation from the bladder wall alone.**  The layer estimate ``E w / t`` is the
  classical one for a face sheet on a thin core.  It leaves out the braid's tension over the frame
  (which resists outward waves) and the shell action of the pressurised tube; both stiffen the
  foundation, so ``beta`` and the margin are on the low (safe) side.  The pressure itself adds no
  foundation stiffness here: the supply holds it constant, and a buckle of the strip hardly changes
  the volume.  The small-strain modulus is used at every pressure (the Table 3 BC-PAM constants
  soften at large strain, docs/paper-reading.md item 19).
* **The tube is rigid at the buckling wavelength.**  Half-waves are about 10 mm, against which the
  pressurised tube (the bladder alone is 15 times as stiff in bending as the frame, and the tube
  carries an effective tension ``|N|``) resists about 20 times ``beta``, so the frame buckles
  relative to a fixed base.  The actuator as a whole cannot buckle under
  its own pressure: its net axial force is zero.
* **Uniform compression.**  ``N`` is the section's value at the state's (uniform) curvature.  Along
  a loaded finger, where ``N`` varies, each section is checked as if its compression acted along the
  whole frame (the worst section governs, conservative).
* **The energy model has no stress state.**  Its states are evaluated with the force-balance
  section (eq 43-48) at the energy model's curvature; at ``k' = 0`` the two coincide exactly.
* **Active pressure.**  Like the moment models, the forces use ``P_a = max(P - P_start, 0)``
  (eq 50): the bladder is taken stress-free at ``P_start``.  The deadband's own end force
  ``P_start pi R0_start^2`` (7 N for the paper's BC-PAM) is left out with it.

With the paper's BC-PAM (Table 3 energy constants) ``beta = 3.52 N/mm^2`` and ``N_cr = 70.7 N``:
the blocked frame's margin falls below 1 at about 148 kPa (0.69 at 200 kPa).  The paper's frame
buckled in the blocked test at about 184-200 kPa (its 802 N*mm blocked moment is reached at
184 kPa), so the model is conservative by about 25 %, as the neglected braid stiffening suggests.
In free bending the BC-PAM's frame compression is largely relieved.  See docs/limits.md.

Bladder stretch
---------------
The principal stretches from the as-made tube (``R0_mm``, ``t0_mm``) with the models' kinematics:
hoop at the inner surface ``(R - t_bar) / (R0 - t0)`` (eq 5, 40; at ``k' = 0`` this is the prestrain of
eq 51-52, the largest hoop stretch of the inflated thick tube), axial ``lambda1 = 1 + k'R (1 - cos Phi)``
(largest at ``Phi = pi`` for ``k' > 0``, 1 at the frame) and radial ``1 / (lambda_hoop lambda1)``
at the outer surface (largest where ``lambda1`` is smallest).  The margin is in strain:
``(limit - 1) / (stretch - 1)``.

Units: pressure kPa, force N, stress MPa (``_mpa``), curvature 1/mm, foundation modulus N/mm^2.

>>> import bendpam
>>> lim = bendpam.limits(bendpam.physics.presets.bc_pam(), [100.0, 200.0])
>>> lim.buckling_margin.round(2).tolist()
[1.7, 0.69]
>>> lim.violations[0]
'frame buckling: margin 0.69 at 200 kPa (blocked)'
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from bendpam.errors import InputError, PlausibilityWarning
from bendpam.physics.actuator import Actuator, ModelParams
from bendpam.physics.braid import DEFAULT_ORDER, curvature_limits, radius_state, solve_u
from bendpam.physics.branch import BRANCH_END, BranchTable
from bendpam.physics.law import MomentLaw
from bendpam.physics.models.force_balance import axial_forces
from bendpam.validate import float_array, instance, plausible

_ACTUATOR = "a bendpam.Actuator (e.g. bendpam.physics.presets.get('be-pam'))"
#: A frame bending strain ``h |k'| / 2`` beyond this is flagged (:class:`~bendpam.errors.PlausibilityWarning`): the
#: models' frame is a linear-elastic beam (eq 16, 27), which no frame material stays near at 20 % strain.
FRAME_STRAIN_BOUND = 0.2

__all__ = [
    "MARGINS",
    "OUTPUTS",
    "Limits",
    "buckling_load",
    "case_limits",
    "foundation_modulus",
    "frame_width_mm",
    "limits",
    "section_limits",
]

#: The margins, each a safety factor capacity / demand (>= 1 within the limit), and how violations name them.
MARGINS = {
    "frame_strength_margin": "frame strength",
    "buckling_margin": "frame buckling",
    "lockup_margin": "braid lock-up",
    "bladder_stretch_margin": "bladder stretch",
}
#: The per-pressure outputs (worse of the blocked and free states), as in sweeps, with units and meanings.
OUTPUTS = {
    "frame_axial_force_n": ("N", "frame axial force (tension > 0) of the state with the larger |N|, blocked or free"),
    "frame_stress_mpa": ("MPa", "largest frame stress |N|/(w h) + E_f h |k'|/2, blocked or free"),
    "frame_strength_margin": ("1", "frame_strength_mpa / frame stress (inf: no strength given)"),
    "buckling_margin": ("1", "frame buckling load (Hetenyi, elastic foundation) / frame compression"),
    "lockup_margin": ("1", "free-bending branch end curvature / |k'_free|; past the end P_a,end / P_a"),
    "bladder_stretch_max": ("1", "largest principal stretch of the bladder from the as-made tube"),
    "bladder_stretch_margin": ("1", "(bladder_stretch_limit - 1) / (stretch - 1) (inf: no limit given)"),
    "min_margin": ("1", "smallest of the margins (>= 1: within every limit)"),
}
_BRANCH_NAME = {v: k for k, v in BRANCH_END.items()}


# ------------------------------------------------------------------------------------------------
# the pieces
# ------------------------------------------------------------------------------------------------
def frame_width_mm(params: ModelParams):
    """Frame width ``w = 12 E_f I_f / (E_f h^3)`` (mm) from the numerics' view of an actuator.

    >>> import bendpam
    >>> round(float(frame_width_mm(bendpam.physics.presets.bc_pam().params)), 12)
    5.0
    """
    instance("params", params, ModelParams, "a ModelParams (actuator.params)")
    return _width(params)


def _width(params: ModelParams):
    return 12.0 * params.frame_stiffness / (params.frame_modulus * params.frame_thickness**3)


def foundation_modulus(params: ModelParams, eta=1.0):
    """Winkler modulus of the bladder wall under the frame, ``beta = 6 (C10 + C01) w eta / t0_start`` (N/mm^2).

    ``eta = R / R0_start`` (eq 5) thins the wall under the frame to ``t0_start / eta``.  Scalars or
    arrays that broadcast against the parameters.

    >>> import bendpam
    >>> round(float(foundation_modulus(bendpam.physics.presets.bc_pam().params)), 4)
    3.5195
    """
    instance("params", params, ModelParams, "a ModelParams (actuator.params)")
    eta = _positive("eta", eta, "1")
    plausible("stretch", eta, label="eta")  # R / R0_start: a hoop stretch of the bladder
    return _foundation(params, eta)


def _foundation(params: ModelParams, eta):
    """:func:`foundation_modulus` without the checks (the kernel's own, validated states)."""
    E_bl = 6.0 * (params.C10 + params.C01)  # MPa: small-strain Young's modulus of the bladder
    return E_bl * _width(params) * eta / params.t0_start


def buckling_load(stiffness_nmm2, foundation_n_per_mm2, length_mm):
    """Critical compression (N) of a pinned-pinned beam on a Winkler foundation (Hetényi) and its half-waves.

    ``N_cr = min over m >= 1 of EI (m pi / L)^2 + beta (L / (m pi))^2``, the minimum taken at one of
    the integers around ``m* = (L / pi) (beta / EI)^(1/4)``.  Returns ``(N_cr, m)``, arrays of the
    broadcast shape.  With ``beta = 0`` this is Euler's ``pi^2 EI / L^2``.

    >>> n, m = buckling_load(353.96, 3.5193, 145.0)
    >>> round(float(n), 2), int(m)
    (70.71, 15)
    """
    EI = _positive("stiffness_nmm2", stiffness_nmm2, "N*mm^2")
    beta = _positive("foundation_n_per_mm2", foundation_n_per_mm2, "N/mm^2", zero=True)
    L = _positive("length_mm", length_mm, "mm")
    with np.errstate(over="ignore", invalid="ignore"):
        n_cr, m = _buckling(EI, beta, L)
    if not np.all(np.isfinite(n_cr)):
        raise InputError("buckling_load: the inputs are too large for a finite buckling load (N); check their units")
    return n_cr, m


def _buckling(EI, beta, L):
    """:func:`buckling_load` without the checks (arrays of the kernel's own states)."""
    m_star = (L / np.pi) * np.sqrt(np.sqrt(beta / EI))
    lo = np.maximum(np.floor(m_star), 1.0)
    best, m_best = None, None
    for m in (lo, lo + 1.0):
        a = m * np.pi / L
        n = EI * a * a + beta / (a * a)
        if best is None:
            best, m_best = n, m
        else:
            m_best = np.where(n < best, m, m_best)
            best = np.minimum(n, best)
    return best, m_best


def _positive(name: str, value, unit: str, *, zero: bool = False) -> np.ndarray:
    """``value`` as a float array of finite numbers > 0 (>= 0 with ``zero``), else one InputError line."""
    v = float_array(name, value, unit)
    bad = ~np.isfinite(v) | ((v < 0.0) if zero else (v <= 0.0))
    if np.any(bad):
        x = float(v.ravel()[int(np.flatnonzero(bad.ravel())[0])])
        raise InputError(f"{name} = {x:g} {unit} must be finite and {'>= 0' if zero else '> 0'}")
    return v


def _broadcasts_to(shape: tuple[int, ...], target: tuple[int, ...]) -> bool:
    try:
        return np.broadcast_shapes(shape, target) == target
    except ValueError:
        return False


#: A demand below this fraction of the capacity is round-off, not a demand: its margin is inf ("no demand").
NO_DEMAND = 1e-9


def _ratio(capacity, demand):
    """Safety factor ``capacity / demand``: inf where there is no demand (``demand <= NO_DEMAND * capacity``,
    round-off included, so never a stand-in like 1e15); NaN where the demand is NaN."""
    d = np.asarray(demand, dtype=float)
    c = np.asarray(capacity, dtype=float)
    some = d > NO_DEMAND * np.abs(c)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(some, c / np.where(some, d, 1.0), np.inf)
    return np.where(np.isnan(d), np.nan, r)


def _as_made(params: ModelParams):
    """Outer and inner radius of the as-made bladder (mm): ``R0`` and ``sqrt(R0^2 - A_bl / pi)`` (eq 51)."""
    R0 = params.R0_start if params.R0 is None else params.R0
    return R0, np.sqrt(R0 * R0 - params.bladder_area / np.pi)


def _section(params, p_active_mpa, k, u, R, *, strength, stretch_limit, external_n=0.0, order=DEFAULT_ORDER):
    """Every limit quantity of sections at curvature ``k`` (kinematics ``u, R`` of eq 5); arrays broadcast."""
    f = axial_forces(params, p_active_mpa, u, R, order=order)
    N = f["N_frame"] + external_n
    h = params.frame_thickness
    area = _width(params) * h
    sig_a = N / area
    sig_b = params.frame_modulus * h * 0.5 * np.abs(k)
    sig = np.abs(sig_a) + sig_b
    beta = _foundation(params, f["eta"])
    n_cr, m = _buckling(np.asarray(params.frame_stiffness, dtype=float), beta, np.asarray(params.L0, dtype=float))
    R0, ri0 = _as_made(params)
    lam_hoop = (R - f["t_bar"]) / ri0  # inner surface: the largest hoop stretch
    u = np.asarray(u, dtype=float)
    far = 1.0 + 2.0 * u  # lambda1 at Phi = pi
    lam_z_max = np.maximum(far, 1.0)
    lam_r = R0 / (R * np.minimum(far, 1.0))  # outer surface, where lambda1 is smallest
    stretch = np.maximum(np.maximum(lam_hoop, lam_z_max), lam_r)
    return {
        "axial_force_n": N,
        "axial_stress_mpa": sig_a,
        "bending_stress_mpa": sig_b,
        "stress_mpa": sig,
        "strength_margin": _ratio(strength, sig) if strength is not None else np.where(np.isnan(sig), np.nan, np.inf),
        "foundation_modulus_n_per_mm2": beta,
        "buckling_load_n": n_cr,
        "buckling_half_waves": m,
        "buckling_margin": _ratio(n_cr, -N),
        "bladder_stretch": stretch,
        "stretch_margin": (_ratio(stretch_limit - 1.0, stretch - 1.0) if stretch_limit is not None
                           else np.where(np.isnan(stretch), np.nan, np.inf)),
    }


_STATE_KEYS = ("axial_force_n", "axial_stress_mpa", "bending_stress_mpa", "stress_mpa", "strength_margin",
               "foundation_modulus_n_per_mm2", "buckling_load_n", "buckling_half_waves", "buckling_margin",
               "bladder_stretch", "stretch_margin")


def section_limits(actuator: Actuator, pressure_kpa, curvature_per_mm, *, external_axial_force_n=0.0,
                   lockup_curvature_per_mm=None, order: int = DEFAULT_ORDER) -> dict[str, np.ndarray]:
    """The limit quantities of sections of ``actuator`` at given curvatures (a loaded finger's sections).

    Parameters
    ----------
    pressure_kpa : float, kPa.
    curvature_per_mm : array_like, frame curvatures k' (1/mm) within the lock-up limits.
    external_axial_force_n : array_like
        Axial tension (N) the external loads put on each section (the component of the loads
        beyond it along the frame line); the frame carries it on top of the section's own balance.
    lockup_curvature_per_mm : array_like, optional
        The curvature at which the branch ends in each section's direction (lock-up or a fold of
        the loaded law); the lock-up margin is its ratio to ``|k'|`` (inf without it).

    Returns
    -------
    dict of str to ndarray
        Arrays of the curvature's shape: the per-state quantities of :class:`Limits`
        (``axial_force_n`` ... ``stretch_margin``) and ``lockup_margin``.

    Examples
    --------
    >>> import bendpam
    >>> sec = section_limits(bendpam.physics.presets.bc_pam(), 200.0, [0.0, -0.005])
    >>> sec["axial_force_n"].round(1).tolist()
    [-102.8, -53.7]
    """
    instance("actuator", actuator, Actuator, _ACTUATOR)
    P_arr = MomentLaw.of(actuator, order=order).check_pressure(pressure_kpa)
    if P_arr.size != 1:
        raise InputError(f"pressure_kpa has {P_arr.size} values: section_limits() takes one pressure")
    P = float(P_arr.ravel()[0])
    k = float_array("curvature_per_mm", curvature_per_mm, "1/mm")
    curvature_limits(actuator, order).check(k)
    external = float_array("external_axial_force_n", external_axial_force_n, "N")
    if not np.all(np.isfinite(external)):
        raise InputError("external_axial_force_n has a non-finite value")
    plausible("force_n", external, label="external_axial_force_n")
    lock = None if lockup_curvature_per_mm is None else float_array("lockup_curvature_per_mm",
                                                                    lockup_curvature_per_mm, "1/mm")
    if lock is not None and np.any(np.isnan(lock)):
        raise InputError("lockup_curvature_per_mm has a NaN (inf: no lock-up in that direction)")
    for name, arr in (("external_axial_force_n", external), ("lockup_curvature_per_mm", lock)):
        if arr is not None and not _broadcasts_to(arr.shape, k.shape):
            raise InputError(f"{name} has shape {arr.shape}; it must broadcast to curvature_per_mm's {k.shape}")
    p = actuator.params
    u, R, _dR, _ib, _dib = radius_state(k, p.alpha0, p.R0_start, order)
    pa = max(P - actuator.P_start_kpa, 0.0) * 1e-3
    out = _section(p, pa, k, u, R, strength=actuator.frame_strength_mpa,
                   stretch_limit=actuator.bladder_stretch_limit, external_n=external, order=order)
    out = {key: np.broadcast_to(v, k.shape).copy() for key, v in out.items()}
    if lock is None:
        out["lockup_margin"] = np.full(k.shape, np.inf)
    else:
        out["lockup_margin"] = _ratio(np.abs(lock), np.abs(k))
    return out


# ------------------------------------------------------------------------------------------------
# the case-block kernel (sweeps, design searches, and limits() for one actuator)
# ------------------------------------------------------------------------------------------------
def _flat(params: ModelParams) -> ModelParams:
    """Every field as a 1-D float array over the cases (``None`` stays ``None``)."""
    shp = params.shape
    n = int(np.prod(shp)) if shp else 1
    return ModelParams(**{key: (None if v is None else np.broadcast_to(np.asarray(v, dtype=float), shp).reshape(n))
                          for key, v in params.__dict__.items()})


def case_limits(law: MomentLaw, pressure_kpa, free_curvature, table: BranchTable | None = None, *,
                free_u=None, frame_strength_mpa: float | None = None,
                bladder_stretch_limit: float | None = None) -> dict[str, Any]:
    """The limits of a block of cases (or one actuator) at 1-D pressures: the kernel of sweeps and :func:`limits`.

    Parameters
    ----------
    law : MomentLaw
        The law of the cases (its parameters, model order and branch table).
    pressure_kpa : (p,) kPa, validated by the caller.
    free_curvature : (cases, p) or (p,) 1/mm
        The free-bending curvature from :meth:`MomentLaw.free_curvature_array` with ``table``
        (NaN past the end of the branch).
    table : the :class:`~bendpam.physics.branch.BranchTable` the curvatures came from (default: the law's).
    free_u : (cases, p) or (p,), optional
        ``u = k'R`` at the free curvatures (:meth:`MomentLaw.free_state_array`), so that ``R = u/k'``
        needs no solve of eq 5.  Without it ``u`` comes from :func:`bendpam.physics.braid.solve_u`.
    frame_strength_mpa, bladder_stretch_limit : the limits (the same for every case), or None.

    Returns
    -------
    dict
        The names of :data:`OUTPUTS` as arrays (cases, p), ``"blocked"`` and ``"free"`` (dicts of
        the per-state quantities, (cases, p)), ``max_pressure_kpa`` and ``branch_end`` (cases,).

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> from bendpam.sweeps import build_cases
    >>> law = bendpam.MomentLaw(build_cases(bendpam.physics.presets.bc_pam(), {"t0_mm": np.array([2.0, 2.5])}))
    >>> P = np.array([100.0, 200.0])
    >>> r = case_limits(law, P, law.free_curvature_array(P))
    >>> r["buckling_margin"].shape, bool(r["buckling_margin"][1, 1] < 1.0)
    ((2, 2), True)
    """
    instance("law", law, MomentLaw, "a MomentLaw")
    tab = law.branches() if table is None else table
    cs = _flat(law.params)
    m = cs.alpha0.size
    P = np.asarray(pressure_kpa, dtype=float).reshape(-1)
    k = np.asarray(free_curvature, dtype=float).reshape(m, P.size)
    pa_kpa = np.maximum(P[None, :] - cs.P_start_kpa[:, None], 0.0)
    opts = dict(strength=frame_strength_mpa, stretch_limit=bladder_stretch_limit, order=law.order)
    blocked, free = _states(cs, k, pa_kpa * 1e-3, free_u, opts)
    # lock-up: the branch's end curvature (the lock-up limit, or the fold) over |k'|; past it P_a,end / P_a
    k_cap = np.abs(np.where(tab.kind == BRANCH_END["fold"], tab.k_end, tab.k_lim))[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):
        past = np.where(pa_kpa > 0.0, tab.p_end[:, None] / np.where(pa_kpa > 0.0, pa_kpa, 1.0), np.inf)
        on = np.where(k != 0.0, k_cap / np.abs(k), np.inf)
    free["lockup_margin"] = np.where(np.isnan(k), past, on)
    blocked["lockup_margin"] = np.full((m, P.size), np.inf)
    out = _worse(blocked, free)
    out["blocked"], out["free"] = blocked, free
    out["max_pressure_kpa"] = cs.P_start_kpa + tab.p_end
    out["branch_end"] = tab.kind
    return out


def _states(cs: ModelParams, k: np.ndarray, pa: np.ndarray, free_u, opts: dict) -> tuple[dict, dict]:
    """The per-state quantities (:func:`_section`) of the blocked and the free states, arrays (cases, p).

    ``k`` is the free curvature (NaN past the branch end), ``pa`` the active pressure in MPa; a free
    state at ``k' = 0`` (deadband, neutral angle) is the blocked state.
    """
    m, n = k.shape
    col = cs.col()
    zero = np.zeros((m, 1))
    blocked = _section(col, pa, zero, zero, col.R0_start, **opts)
    blocked = {key: np.broadcast_to(v, (m, n)).copy() for key, v in blocked.items()}
    free = {key: np.where(np.isnan(k), np.nan, v) for key, v in blocked.items()}
    rows, cols = np.nonzero(np.isfinite(k) & (k != 0.0))
    if rows.size:
        kk = k[rows, cols]
        sub = cs.take(rows)
        if free_u is not None:
            u = np.asarray(free_u, dtype=float).reshape(m, n)[rows, cols]
        else:
            u = solve_u(kk * sub.R0_start, sub.alpha0, opts["order"])[0]  # eq 5, per-case braid angles
        st = _section(sub, pa[rows, cols], kk, u, u / kk, **opts)
        for key in _STATE_KEYS:
            free[key][rows, cols] = st[key]
    free["curvature_per_mm"] = k
    blocked["curvature_per_mm"] = np.zeros((m, n))
    return blocked, free


def _worse(blocked: dict, free: dict) -> dict[str, Any]:
    """The outputs of :data:`OUTPUTS`: at each pressure the worse of the blocked and free states."""
    larger = np.abs(free["axial_force_n"]) > np.abs(blocked["axial_force_n"])  # False where free is NaN
    out: dict[str, Any] = {
        "frame_axial_force_n": np.where(larger, free["axial_force_n"], blocked["axial_force_n"]),
        "frame_stress_mpa": np.fmax(blocked["stress_mpa"], free["stress_mpa"]),
        "frame_strength_margin": np.fmin(blocked["strength_margin"], free["strength_margin"]),
        "buckling_margin": np.fmin(blocked["buckling_margin"], free["buckling_margin"]),
        "lockup_margin": free["lockup_margin"],
        "bladder_stretch_max": np.fmax(blocked["bladder_stretch"], free["bladder_stretch"]),
        "bladder_stretch_margin": np.fmin(blocked["stretch_margin"], free["stretch_margin"]),
    }
    out["min_margin"] = np.minimum.reduce([out[name] for name in MARGINS])
    return out


# ------------------------------------------------------------------------------------------------
# one actuator
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Limits:
    """The structural limits of one actuator at a set of pressures (arrays over ``pressure_kpa``).

    The per-pressure fields are the worse of the blocked (``k' = 0``) and free-bending states;
    ``blocked`` and ``free`` hold each state's quantities (dicts of arrays, keys ``axial_force_n``,
    ``axial_stress_mpa``, ``bending_stress_mpa``, ``stress_mpa``, ``strength_margin``,
    ``foundation_modulus_n_per_mm2``, ``buckling_load_n``, ``buckling_half_waves``,
    ``buckling_margin``, ``bladder_stretch``, ``stretch_margin``, ``lockup_margin``,
    ``curvature_per_mm``; NaN in ``free`` where there is no free-bending equilibrium).  Every margin
    is capacity / demand: >= 1 within the limit, inf without demand or without a limit.

    Attributes
    ----------
    pressure_kpa : (p,) kPa.
    frame_axial_force_n : N, tension > 0: the state with the larger ``|N|``.
    frame_stress_mpa : largest ``|N|/(w h) + E_f h |k'|/2``, MPa.
    frame_strength_margin, buckling_margin, lockup_margin, bladder_stretch_margin, min_margin : safety factors.
    bladder_stretch_max : largest principal stretch of the bladder from the as-made tube.
    max_pressure_kpa : highest pressure with a free-bending equilibrium (the branch end; inf if none).
    branch_end : ``"lock-up"``, ``"fold"``, ``"unbounded"`` or ``"neutral"``.
    frame_strength_mpa, bladder_stretch_limit : the limits used (None: not checked).
    violations : one line per margin below 1, e.g. ``"frame buckling: margin 0.69 at 200 kPa (blocked)"``.

    Examples
    --------
    >>> import bendpam
    >>> lim = bendpam.limits(bendpam.physics.presets.bc_pam().replace(frame_strength_mpa=400.0), [100.0, 200.0])
    >>> lim.ok, lim.past_limit.tolist(), lim.frame_strength_margin.round(1).tolist()
    (False, [False, True], [24.0, 9.7])
    >>> round(float(lim.blocked["buckling_load_n"][1]), 1), int(lim.blocked["buckling_half_waves"][1])
    (70.7, 15)
    """

    model: str
    pressure_kpa: np.ndarray
    frame_axial_force_n: np.ndarray
    frame_stress_mpa: np.ndarray
    frame_strength_margin: np.ndarray
    buckling_margin: np.ndarray
    lockup_margin: np.ndarray
    bladder_stretch_max: np.ndarray
    bladder_stretch_margin: np.ndarray
    min_margin: np.ndarray
    max_pressure_kpa: float
    branch_end: str
    frame_strength_mpa: float | None
    bladder_stretch_limit: float | None
    violations: tuple[str, ...]
    blocked: dict[str, np.ndarray] = field(repr=False, compare=False)
    free: dict[str, np.ndarray] = field(repr=False, compare=False)
    violation_index: tuple[int, ...] = field(default=(), repr=False, compare=False)

    @property
    def notes(self) -> np.ndarray:
        """Per pressure: its violations joined by ``"; "`` (empty within every limit), an array of str."""
        out: list[list[str]] = [[] for _ in range(self.pressure_kpa.size)]
        for i, line in zip(self.violation_index, self.violations, strict=True):
            out[i].append(line)
        return np.array(["; ".join(x) for x in out], dtype=str)

    @property
    def ok(self) -> bool:
        """True when every margin at every pressure is >= 1."""
        return not self.violations

    @property
    def past_limit(self) -> np.ndarray:
        """Per pressure: True where some margin is below 1."""
        return self.min_margin < 1.0

    def to_dict(self) -> dict[str, Any]:
        """Plain lists and numbers (JSON-ready after :func:`bendpam.infra.atomic.json_safe`), units in the keys."""
        per = {name: getattr(self, name).tolist() for name in ("pressure_kpa", *OUTPUTS)}
        return {
            "model": self.model, **per,
            "blocked": {key: v.tolist() for key, v in self.blocked.items()},
            "free": {key: v.tolist() for key, v in self.free.items()},
            "max_pressure_kpa": self.max_pressure_kpa, "branch_end": self.branch_end,
            "frame_strength_mpa": self.frame_strength_mpa, "bladder_stretch_limit": self.bladder_stretch_limit,
            "violations": list(self.violations),
        }

    def to_dataframe(self) -> Any:
        """One row per pressure: the per-pressure fields, then ``blocked_*`` and ``free_*`` columns."""
        import pandas as pd

        cols: dict[str, Any] = {name: getattr(self, name) for name in ("pressure_kpa", *OUTPUTS)}
        for state, d in (("blocked", self.blocked), ("free", self.free)):
            cols.update({f"{state}_{key}": v for key, v in d.items()})
        return pd.DataFrame(cols)


def _fmt_margin(x: float) -> str:
    return f"{x:.2f}" if x >= 0.01 else f"{x:.2g}"


def violation_lines(pressure_kpa, margins: dict[str, np.ndarray], blocked: dict, free: dict, branch_end: str,
                    max_pressure_kpa: float) -> list[tuple[int, str]]:
    """``(pressure index, line)`` per margin below 1: the limit, the margin, the pressure and the state."""
    lines: list[tuple[int, str]] = []
    per_state = {"frame_strength_margin": "strength_margin", "buckling_margin": "buckling_margin",
                 "bladder_stretch_margin": "stretch_margin"}
    for i, P in enumerate(np.asarray(pressure_kpa, dtype=float)):
        for name, label in MARGINS.items():
            v = float(margins[name][i])
            if not v < 1.0:
                continue
            if name == "lockup_margin":
                if math.isnan(float(free["curvature_per_mm"][i])):
                    what = "free-bending fold" if branch_end == "fold" else label
                    lines.append((i, f"{what}: margin {_fmt_margin(v)} at {P:g} kPa (no free-bending equilibrium "
                                     f"above {max_pressure_kpa:.4g} kPa)"))
                else:
                    lines.append((i, f"{label}: margin {_fmt_margin(v)} at {P:g} kPa (free)"))
                continue
            key = per_state[name]
            states = [s for s, d in (("blocked", blocked), ("free", free)) if float(d[key][i]) < 1.0]
            lines.append((i, f"{label}: margin {_fmt_margin(v)} at {P:g} kPa ({' and '.join(states)})"))
    return lines


def _flag_frame_strain(actuator: Actuator, P: np.ndarray, k_free: np.ndarray) -> None:
    """Warn when the free state bends the frame beyond :data:`FRAME_STRAIN_BOUND` (docs/plausibility.md)."""
    with np.errstate(invalid="ignore"):
        strain = 0.5 * actuator.frame_thickness_mm * np.abs(k_free)
        over = strain > FRAME_STRAIN_BOUND
    if np.any(over):
        i = int(np.flatnonzero(over)[0])
        warnings.warn(f"frame bending strain h |k'| / 2 = {100 * strain[i]:.3g} % at {P[i]:g} kPa is beyond "
                      f"{100 * FRAME_STRAIN_BOUND:g} %: the models' frame is a linear-elastic beam (eq 16, 27), "
                      "which no frame material stays near there", PlausibilityWarning, stacklevel=3)


def limits(actuator: Actuator, pressure_kpa, model: str | None = None, *, eq19_factor: bool = True,
           order: int = DEFAULT_ORDER) -> Limits:
    """The structural limits of ``actuator`` at each pressure: see the module docstring and :class:`Limits`.

    Parameters
    ----------
    actuator : Actuator
        Its optional ``frame_strength_mpa`` and ``bladder_stretch_limit`` are the limits checked.
    pressure_kpa : float or 1-D array, kPa (gauge).
    model : {"energy", "force_balance"} or None: the model whose free-bending curvature is used; None
        (default): the actuator's own (energy when unknown); another than the actuator's warns.

    Examples
    --------
    >>> import bendpam
    >>> lim = bendpam.limits(bendpam.physics.presets.be_pam(), [100.0, 200.0])
    >>> lim.frame_axial_force_n.round(1).tolist(), lim.buckling_margin.tolist()
    ([7.4, 30.7], [inf, inf])
    """
    instance("actuator", actuator, Actuator, _ACTUATOR)
    law = MomentLaw.of(actuator, model, eq19_factor=eq19_factor, order=order)
    P = law.check_pressure(pressure_kpa)
    if P.ndim > 1:
        raise InputError(f"pressure_kpa must be a number or a 1-D list of pressures, got shape {P.shape}")
    P = np.atleast_1d(P)
    actuator.outside_tested(P)
    tab = law.branches()
    k, u = law.free_state_array(P, table=tab)
    r = case_limits(law, P, k, tab, free_u=u, frame_strength_mpa=actuator.frame_strength_mpa,
                    bladder_stretch_limit=actuator.bladder_stretch_limit)
    one = {name: r[name][0] for name in OUTPUTS}
    blocked = {key: v[0] for key, v in r["blocked"].items()}
    free = {key: v[0] for key, v in r["free"].items()}
    kind = _BRANCH_NAME[int(r["branch_end"][0])]
    p_max = float(r["max_pressure_kpa"][0])
    lines = violation_lines(P, one, blocked, free, kind, p_max)
    _flag_frame_strain(actuator, P, free["curvature_per_mm"])
    return Limits(model=str(law.model), pressure_kpa=P, **one, max_pressure_kpa=p_max, branch_end=kind,
                  frame_strength_mpa=actuator.frame_strength_mpa, bladder_stretch_limit=actuator.bladder_stretch_limit,
                  violations=tuple(t for _, t in lines), blocked=blocked, free=free,
                  violation_index=tuple(i for i, _ in lines))
