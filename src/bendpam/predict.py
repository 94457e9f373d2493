"""Public model API: moments, blocked moment, stiffness, free bending, internal stresses.

Units (SciPy-style functional API, validated here at the boundary):

* pressure ``P``: MPa (gauge), >= 0.  The active pressure is ``max(P - P_start, 0)`` (eq 50):
  below the threshold the bladder does not press on the braid and the actuator gives only its
  passive (frame + bladder) response.
* curvature ``k'``: 1/mm, positive toward the frame.  BE-PAMs bend freely with k' > 0, BC-PAMs
  with k' < 0 (NOTES.md item 15).
* moments: N*mm; stiffness dM/dk': N*mm^2.

All functions broadcast ``pressure`` against ``curvature``.  Because ``M`` is affine in the active
pressure, kinematics are computed once per curvature value of the *un-broadcast* curvature array,
so ``moment(a, P[:, None], k[None, :])`` costs little more than the kinematics of ``k``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import xarray as xr
from scipy.optimize import minimize_scalar

from .actuator import Actuator
from .braid import DEFAULT_ORDER, curvature_limits
from .braid import kinematics as _kinematics
from .models import force_balance as _fb
from .models import get_model
from .presets import normalise_model

__all__ = [
    "moment",
    "moment_terms",
    "blocked_moment",
    "tangent_stiffness",
    "free_curvature",
    "FreeBending",
    "BranchInfo",
    "branch_info",
    "internal_stresses",
    "kinematics",
    "active_pressure",
    "prediction_table",
]


def _check_actuator(actuator) -> Actuator:
    if not isinstance(actuator, Actuator):
        raise TypeError(f"actuator must be a bendpam.Actuator, got {type(actuator).__name__}")
    return actuator


def _pressure(pressure, name: str = "pressure") -> np.ndarray:
    try:
        p = np.asarray(pressure, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {pressure!r} is not numeric (MPa)") from None
    if p.size and not np.all(np.isfinite(p)):
        i = int(np.flatnonzero(~np.isfinite(p.ravel()))[0])
        raise ValueError(f"{name} has a non-finite value {p.ravel()[i]!r} at index {i}")
    if p.size and np.any(p < 0.0):
        i = int(np.flatnonzero(p.ravel() < 0.0)[0])
        raise ValueError(f"{name} = {p.ravel()[i]:g} MPa at index {i} is below zero; allowed range [0, inf) MPa (gauge)")
    return p


def _curvature(actuator, curvature, order) -> np.ndarray:
    try:
        k = np.asarray(curvature, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"curvature = {curvature!r} is not numeric (1/mm)") from None
    curvature_limits(actuator, order).check(k)
    return k


def active_pressure(actuator, pressure) -> np.ndarray:
    """Active pressure ``max(P - P_start, 0)`` in MPa (eq 50)."""
    return np.maximum(_pressure(pressure) - actuator.P_start, 0.0)


def kinematics(actuator, curvature, *, order: int = DEFAULT_ORDER):
    """Braid kinematics at ``curvature`` (1/mm): see :class:`bendpam.braid.Kinematics` (eq 1-5)."""
    return _kinematics(_check_actuator(actuator), curvature, order)


def moment(actuator, pressure, curvature, model: str = "energy", *, order: int = DEFAULT_ORDER, eq19_factor: bool = True):
    """Output moment ``M_load(P, k')`` in N*mm (eq 21 or eq 49, corrected by eq 50-52).

    Parameters
    ----------
    actuator : Actuator
    pressure : array_like
        Gauge pressure P, MPa, >= 0.
    curvature : array_like
        Frame curvature k', 1/mm, within the lock-up limits (:func:`bendpam.braid.curvature_limits`).
    model : {"energy", "force_balance"}
        ``"force-balance"`` is accepted too.
    order : int
        Gauss-Legendre order on [0, pi] (default 32).
    eq19_factor : bool
        Energy model only: keep eq 19's ``(1 + k'R)`` factor (default, as printed).

    Returns
    -------
    ndarray
        ``np.broadcast(pressure, curvature).shape``, N*mm.
    """
    act = _check_actuator(actuator)
    mod = get_model(model)
    p = active_pressure(act, pressure)
    k = _curvature(act, curvature, order)
    A, B = _chunked_coefficients(mod, act, k, order, eq19_factor)
    return p * A - B


_CHUNK = 1 << 15


def _chunked_coefficients(mod, act, k, order, eq19_factor):
    """``mod.coefficients`` in blocks of 32768 curvatures, so memory stays bounded for large inputs."""
    if k.size <= _CHUNK:
        return mod.coefficients(act, k, order=order, eq19_factor=eq19_factor)
    flat = k.ravel()
    A = np.empty(flat.size)
    B = np.empty(flat.size)
    for s in range(0, flat.size, _CHUNK):
        A[s:s + _CHUNK], B[s:s + _CHUNK] = mod.coefficients(act, flat[s:s + _CHUNK], order=order,
                                                            eq19_factor=eq19_factor)
    return A.reshape(k.shape), B.reshape(k.shape)


def moment_terms(actuator, pressure, curvature, model: str = "energy", *, order: int = DEFAULT_ORDER, eq19_factor: bool = True):
    """The named parts of the moment in N*mm.

    Energy model: ``M_load, M_air, M_bl, M_f`` (eq 13, 19, 16, 21).
    Force-balance model: ``M_load, M_p, M_frame, M_bl, M_br`` (eq 23-28, 49).
    """
    act = _check_actuator(actuator)
    mod = get_model(model)
    p = active_pressure(act, pressure)
    k = _curvature(act, curvature, order)
    return mod.terms(act, p, k, order=order, eq19_factor=eq19_factor)


def blocked_moment(actuator, pressure, model: str = "energy", *, order: int = DEFAULT_ORDER, eq19_factor: bool = True):
    """Blocked moment ``M(P, 0)`` in N*mm.

    Both models reduce to ``pi R0_start^3 (1 - 2 cot^2 alpha0) max(P - P_start, 0)`` at k' = 0
    (NOTES.md item 12); the result is negative for a BC-PAM.
    """
    return moment(actuator, pressure, 0.0, model, order=order, eq19_factor=eq19_factor)


def tangent_stiffness(actuator, pressure, curvature, model: str = "energy", *, order: int = DEFAULT_ORDER, eq19_factor: bool = True):
    """Tangent stiffness ``dM/dk'`` in N*mm^2, by a fourth-order central difference of A and B.

    The step is ``1e-4`` of the admissible curvature span; near a lock-up limit the stencil is
    shifted to stay inside the admissible range (one-sided, still fourth order).  The error is
    below ~1e-8 relative for the presets (tested against a finer step).
    """
    act = _check_actuator(actuator)
    mod = get_model(model)
    p = active_pressure(act, pressure)
    k = _curvature(act, curvature, order)
    lim = curvature_limits(act, order)
    h = 1e-4 * (lim.k_max - lim.k_min)
    # integer shift s: the nodes k + (t - s) h, t = -2..2, stay inside the admissible range
    s = np.zeros(k.shape)
    s = np.where(k + 2 * h > lim.k_max, np.ceil((k + 2 * h - lim.k_max) / h), s)
    s = np.where(k - 2 * h < lim.k_min, -np.ceil((lim.k_min - k + 2 * h) / h), s)
    s = np.clip(s, -2, 2).astype(int)
    pts = k[..., None] + (_FD_NODES - s[..., None]) * h
    A, B = mod.coefficients(act, pts, order=order, eq19_factor=eq19_factor)
    w = _FD_WEIGHTS[s + 2]
    return p * (np.sum(w * A, axis=-1) / h) - np.sum(w * B, axis=-1) / h


def _fd5_weights() -> np.ndarray:
    """First-derivative weights of the 5-point stencil t = -2..2, evaluated at t = s, s = -2..2."""
    t = np.arange(-2.0, 3.0)
    V = np.vander(t, 5, increasing=True).T  # V[m, j] = t_j^m
    rows = []
    for s in t:
        rhs = np.array([m * s ** (m - 1) if m else 0.0 for m in range(5)])
        rows.append(np.linalg.solve(V, rhs))
    return np.array(rows)


_FD_NODES = np.arange(-2.0, 3.0)
_FD_WEIGHTS = _fd5_weights()


# ------------------------------------------------------------------------------------------------
# free bending
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class BranchInfo:
    """The free-bending branch of an actuator: equilibria ``M(P, k') = 0`` connected to k' = 0.

    Along the bending direction the equilibrium active pressure is ``p(k') = B(k') / A(k')``.  The
    branch is the part where ``p`` rises from 0; it ends at a fold (local maximum of ``p``: the
    moment-curvature curve is N-shaped and the actuator snaps through), at the braid lock-up
    limit, or never (``p`` grows without bound).

    Attributes
    ----------
    direction : +1 (toward the frame), -1 (away), 0 (neutral braid angle).
    k_end : curvature (1/mm) where the branch ends.
    p_end_active : active pressure (MPa) at the branch end; ``inf`` if unbounded.
    max_pressure : highest absolute pressure (MPa) with a free-bending equilibrium on the branch.
    kind : ``"fold"``, ``"lock-up"``, ``"unbounded"`` or ``"neutral"``.
    reason : a sentence explaining the end of the branch.
    k_table, p_table : sampled branch ``(k', p_active)`` from k' = 0 to ``k_end`` (monotone in p).
    """

    direction: int
    k_end: float
    p_end_active: float
    max_pressure: float
    kind: str
    reason: str
    k_table: np.ndarray = field(repr=False)
    p_table: np.ndarray = field(repr=False)


_BRANCH_SAMPLES = 1200


@lru_cache(maxsize=128)
def _branch(actuator: Actuator, model: str, order: int, eq19_factor: bool) -> BranchInfo:
    mod = get_model(model)
    sgn = actuator.bend_sign
    lim = curvature_limits(actuator, order)
    if sgn == 0:
        z = np.zeros(1)
        return BranchInfo(0, 0.0, 0.0, math.inf, "neutral",
                          "neutral braid angle (54.74 deg): M(P, 0) = 0 at every pressure", z, z)
    k_lim = lim.k_max if sgn > 0 else lim.k_min
    # graded grid: denser near 0 where the curve starts
    frac = np.linspace(0.0, 1.0, _BRANCH_SAMPLES + 1)[1:] ** 1.5
    kg = k_lim * frac
    A, B = mod.coefficients(actuator, kg, order=order, eq19_factor=eq19_factor)
    sA = sgn * A
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.where(sA > 0.0, B / A, np.nan)

    def p_of(kk):
        a, b = mod.coefficients(actuator, np.array([kk]), order=order, eq19_factor=eq19_factor)
        return float(b[0] / a[0])

    # index of the first sample where A loses its sign (pressure -> inf before it)
    bad_a = np.flatnonzero(~(sA > 0.0))
    n_ok = bad_a[0] if bad_a.size else kg.size
    # first decrease of p (local maximum = fold); a non-positive first value means the straight
    # state is already unstable for any active pressure
    pk = np.concatenate([[0.0], p[:n_ok]])
    kk = np.concatenate([[0.0], kg[:n_ok]])
    dec = np.flatnonzero(np.diff(pk) <= 0.0)
    if dec.size:
        j = dec[0]  # pk[j] >= pk[j+1]: maximum near kk[j]
        if j == 0:
            return BranchInfo(sgn, 0.0, 0.0, actuator.P_start, "fold",
                              "the straight state is unstable: M decreases with curvature at P_start "
                              "(negative passive stiffness)", kk[:1], pk[:1])
        lo, hi = kk[j - 1], kk[j + 1]
        res = minimize_scalar(lambda x: -p_of(x), bounds=(min(lo, hi), max(lo, hi)), method="bounded",
                              options={"xatol": 1e-12 * abs(k_lim)})
        k_end = float(res.x)
        p_end = max(-float(res.fun), pk[j])
        if p_end > pk[j]:
            kt, pt = np.append(kk[: j + 1], k_end), np.append(pk[: j + 1], p_end)
        else:
            k_end, kt, pt = kk[j], kk[: j + 1], pk[: j + 1]
        sign_word = "k' > 0" if sgn > 0 else "k' < 0"
        return BranchInfo(
            sgn, k_end, p_end, actuator.P_start + p_end, "fold",
            f"fold of the moment-curvature curve (N-shaped): the free-bending branch ({sign_word}) ends at "
            f"k' = {k_end:.5g} 1/mm, P = {1e3 * (actuator.P_start + p_end):.4g} kPa; above it the actuator "
            "snaps through and there is no free-bending equilibrium on this branch",
            kt, pt,
        )
    if n_ok < kg.size:  # A changed sign: p -> +inf, every pressure has an equilibrium
        return BranchInfo(sgn, float(kg[n_ok]), math.inf, math.inf, "unbounded",
                          "pressure moment vanishes before lock-up: every pressure has an equilibrium",
                          np.append(kk, kg[n_ok]), np.append(pk, math.inf))
    return BranchInfo(
        sgn, float(k_lim), float(pk[-1]), actuator.P_start + float(pk[-1]), "lock-up",
        f"braid lock-up limit k' = {k_lim:.5g} 1/mm reached at P = {1e3 * (actuator.P_start + pk[-1]):.4g} kPa "
        f"({lim.reason_max if sgn > 0 else lim.reason_min})",
        kk, pk,
    )


def branch_info(actuator, model: str = "energy", *, order: int = DEFAULT_ORDER, eq19_factor: bool = True) -> BranchInfo:
    """The free-bending branch of ``actuator`` (cached): fold or lock-up pressure and the sampled curve."""
    return _branch(_check_actuator(actuator), normalise_model(model), int(order), bool(eq19_factor))


@dataclass(frozen=True)
class FreeBending:
    """Free-bending equilibria ``M(P, k') = 0`` at given pressures.

    Attributes
    ----------
    pressure : MPa (input shape).
    curvature : k' (1/mm); NaN where no equilibrium exists on the branch.
    angle : theta = k' L0 (rad); NaN likewise.
    status : ``"ok"``, ``"deadband"`` (P <= P_start: straight) or ``"no-equilibrium"``.
    reason : empty for ``"ok"``, else an explanation.
    max_pressure : highest pressure (MPa) that still has a free-bending equilibrium (inf if none).
    branch : the :class:`BranchInfo` used.
    """

    pressure: np.ndarray
    curvature: np.ndarray
    angle: np.ndarray
    status: np.ndarray
    reason: np.ndarray
    max_pressure: float
    branch: BranchInfo = field(repr=False)

    @property
    def angle_deg(self) -> np.ndarray:
        return np.degrees(self.angle)

    @property
    def ok(self) -> np.ndarray:
        return self.status != "no-equilibrium"


def free_curvature(actuator, pressure, model: str = "energy", *, order: int = DEFAULT_ORDER, eq19_factor: bool = True,
                   xtol: float = 1e-13) -> FreeBending:
    """Free-bending curvature: the root of ``M(P, k') = 0`` on the branch the actuator bends along.

    The branch starts at k' = 0 (straight, at P_start) and runs in the bending direction
    (k' > 0 for a BE-PAM, k' < 0 for a BC-PAM) while the equilibrium pressure ``p(k') = B/A``
    rises.  Above the fold pressure (or the lock-up pressure) there is no equilibrium on it: the
    curvature is NaN, the status ``"no-equilibrium"`` and the reason says why.  A root on a
    disconnected branch beyond a fold is never returned.

    The root is bracketed from the sampled branch and polished by a vectorised Illinois
    (regula falsi) iteration to ``xtol`` relative to the curvature range.
    """
    act = _check_actuator(actuator)
    mod = get_model(model)
    P = _pressure(pressure)
    br = branch_info(act, model, order=order, eq19_factor=eq19_factor)
    return assemble_free_bending(act, P, br,
                                 lambda pa: _solve_branch(act, mod, br, pa, order, eq19_factor, xtol))


def assemble_free_bending(act, P, br: BranchInfo, solve) -> FreeBending:
    """Statuses, reasons and roots of free bending at pressures ``P`` (MPa) on the branch ``br``.

    ``solve(pa)`` returns the roots for the active pressures ``pa`` that have an equilibrium on the
    branch (``0 < pa <= br.p_end_active``); the exact path and the fast path share this logic.
    """
    pa = np.maximum(P - act.P_start, 0.0).ravel()
    k = np.zeros(pa.shape)
    status = np.full(pa.shape, "ok", dtype=object)
    reason = np.full(pa.shape, "", dtype=object)
    below = P.ravel() < act.P_start
    status[below] = "deadband"
    reason[below] = f"below the threshold pressure P_start = {act.P_start_kpa:g} kPa: no active moment"
    if br.direction == 0:
        reason[pa > 0] = br.reason
    else:
        above = pa > br.p_end_active
        k[above] = np.nan
        status[above] = "no-equilibrium"
        reason[above] = br.reason
        want = (pa > 0) & ~above
        if np.any(want):
            k[want] = solve(pa[want])
    k = k.reshape(P.shape)
    return FreeBending(pressure=P, curvature=k, angle=k * act.L0, status=status.reshape(P.shape).astype(str),
                       reason=reason.reshape(P.shape).astype(str), max_pressure=br.max_pressure, branch=br)


def _solve_branch(act, mod, br: BranchInfo, pa, order, eq19_factor, xtol):
    """Root of ``sgn (pa A(k) - B(k)) = 0`` inside the branch-table brackets (vectorised Illinois)."""
    sgn = br.direction
    kt, pt = br.k_table, br.p_table
    j = np.searchsorted(pt, pa, side="left")
    j = np.clip(j, 1, kt.size - 1)

    # F = sgn (pa A - B) = sgn A (pa - p): F >= 0 at the table point before the root, <= 0 after
    def F(x, idx):
        A, B = mod.coefficients(act, x, order=order, eq19_factor=eq19_factor)
        return sgn * (pa[idx] * A - B)

    return illinois(F, kt[j - 1], kt[j], xtol * abs(br.k_end if br.k_end else 1.0))


def illinois(F, a, b, tol, maxiter: int = 100):
    """Vectorised Illinois (modified regula falsi) root finder on brackets with ``F(a) >= 0 >= F(b)``.

    ``F(x, idx)`` evaluates the function at points ``x`` for the flat indices ``idx`` of the
    problem, so only unconverged points are evaluated.  A point stops when its bracket or its last
    step is below ``tol`` (scalar or per point), or ``F`` hits zero.  Returns the roots (shape of
    ``a``).
    """
    shape = np.shape(a)
    a = np.array(a, dtype=float).ravel()
    b = np.array(b, dtype=float).ravel()
    tol = np.broadcast_to(np.asarray(tol, dtype=float), shape).ravel()
    every = np.arange(a.size)
    fa, fb = F(a, every), F(b, every)
    x = np.where(fa == 0.0, a, np.where(fb == 0.0, b, 0.5 * (a + b)))
    side = np.zeros(a.size)
    act = np.flatnonzero((fa != 0.0) & (fb != 0.0))
    for _ in range(maxiter):
        if act.size == 0:
            break
        aa, bb, fa_, fb_ = a[act], b[act], fa[act], fb[act]
        xs = (aa * fb_ - bb * fa_) / (fb_ - fa_)
        inside = (xs > np.minimum(aa, bb)) & (xs < np.maximum(aa, bb))
        xs = np.where(inside, xs, 0.5 * (aa + bb))
        step = np.abs(xs - x[act])
        x[act] = xs
        fx = F(xs, act)
        pos = fx > 0.0
        sd = side[act]
        # Illinois: halve the function value kept at the end that did not move twice in a row
        fb_ = np.where(pos & (sd == 1), 0.5 * fb_, fb_)
        fa_ = np.where(~pos & (sd == -1), 0.5 * fa_, fa_)
        a[act] = np.where(pos, xs, aa)
        fa[act] = np.where(pos, fx, fa_)
        b[act] = np.where(pos, bb, xs)
        fb[act] = np.where(pos, fb_, fx)
        side[act] = np.where(pos, 1.0, -1.0)
        done = (fx == 0.0) | (np.abs(b[act] - a[act]) <= tol[act]) | (step <= tol[act])
        act = act[~done]
    return x.reshape(shape)


# ------------------------------------------------------------------------------------------------
# internal stresses (force-balance model)
# ------------------------------------------------------------------------------------------------
def internal_stresses(actuator, pressure, curvature, *, n_phi: int = 181, order: int = DEFAULT_ORDER) -> xr.Dataset:
    """Internal state of the force-balance model (eq 37-48) around the cross-section.

    Parameters
    ----------
    pressure : float or 1-D array, MPa.
    curvature : float or 1-D array, 1/mm.
    n_phi : number of angles on [0, 360] deg.

    Returns
    -------
    xarray.Dataset
        Dimensions ``pressure_kpa`` and ``curvature_per_mm`` (when given as arrays) and
        ``phi_deg`` (0 at the frame).  Variables, units in ``attrs["units"]``: ``sigma_bl1``,
        ``sigma_bl2``, ``sigma_bl3``, ``P_e``, ``sigma_br1``, ``sigma_br2`` (MPa), ``N_br1``,
        ``N_br2`` (N/mm), ``braid_angle_deg`` (deg), ``t_bar``, ``R`` (mm).
    """
    act = _check_actuator(actuator)
    P = _pressure(pressure)
    k = _curvature(act, curvature, order)
    if P.ndim > 1 or k.ndim > 1:
        raise ValueError("internal_stresses takes scalar or 1-D pressure and curvature")
    phi = np.linspace(0.0, 2.0 * np.pi, int(n_phi))
    pa = np.maximum(P - act.P_start, 0.0)
    Pg = pa.reshape(pa.shape + (1,) * k.ndim)
    st = _fb.stress_state(act, Pg, k, phi, order=order)
    dims = (["pressure_kpa"] if P.ndim else []) + (["curvature_per_mm"] if k.ndim else [])
    units = {
        "sigma_bl1": ("MPa", "bladder axial stress (eq 43)"),
        "sigma_bl2": ("MPa", "bladder hoop stress (eq 44)"),
        "sigma_bl3": ("MPa", "bladder radial stress, -P_active (eq 37)"),
        "P_e": ("MPa", "interfacial pressure bladder-braid (eq 45)"),
        "N_br1": ("N/mm", "braid axial line tension sigma_br1 * t_br (eq 48)"),
        "N_br2": ("N/mm", "braid hoop line tension P_e R (eq 31)"),
        "sigma_br1": ("MPa", "braid nominal axial stress (eq 48)"),
        "sigma_br2": ("MPa", "braid nominal hoop stress (eq 31)"),
        "braid_angle": ("deg", "local braid angle alpha(Phi)"),
        "t_bar": ("mm", "mean bladder thickness (eq 40)"),
        "R": ("mm", "deformed radius (eq 5)"),
    }
    S = np.broadcast_shapes(Pg.shape, k.shape)
    data = {}
    for name, arr in st.items():
        arr = np.asarray(arr)
        per_angle = arr.ndim == len(S) + 1
        full = np.broadcast_to(arr, S + ((phi.size,) if per_angle else ()))
        d = dims + (["phi_deg"] if per_angle else [])
        if name == "braid_angle":
            full, name = np.degrees(full), "braid_angle_deg"
        unit, long_name = units["braid_angle" if name == "braid_angle_deg" else name]
        data[name] = xr.DataArray(np.array(full), dims=d, attrs={"units": unit, "long_name": long_name})
    coords = {"phi_deg": np.degrees(phi)}
    if P.ndim:
        coords["pressure_kpa"] = P * 1e3
    if k.ndim:
        coords["curvature_per_mm"] = k
    ds = xr.Dataset(data, coords=coords)
    ds["phi_deg"].attrs.update(units="deg", long_name="angle around the section, 0 at the frame")
    if P.ndim:
        ds["pressure_kpa"].attrs.update(units="kPa")
    else:
        ds.attrs["pressure_kpa"] = float(P) * 1e3
    if k.ndim:
        ds["curvature_per_mm"].attrs.update(units="1/mm")
    else:
        ds.attrs["curvature_per_mm"] = float(k)
    ds.attrs.update(model="force_balance", actuator=act.name or act.kind, P_start_kpa=act.P_start_kpa)
    return ds


# ------------------------------------------------------------------------------------------------
# tables
# ------------------------------------------------------------------------------------------------
def prediction_table(actuator, pressure_kpa, model: str = "energy", *, order: int = DEFAULT_ORDER,
                     eq19_factor: bool = True):
    """Blocked moment and free bending at each pressure, as a :class:`pandas.DataFrame`.

    Columns: ``pressure_kpa``, ``blocked_moment_nmm``, ``free_curvature_per_mm``,
    ``free_angle_deg``, ``status`` and ``note`` (the reason where there is no equilibrium).
    Signs follow the paper: k' > 0 toward the frame, so BC-PAM values are negative.
    """
    import pandas as pd

    P_kpa = np.atleast_1d(np.asarray(pressure_kpa, dtype=float))
    P = _pressure(P_kpa * 1e-3, "pressure")
    bm = blocked_moment(actuator, P, model, order=order, eq19_factor=eq19_factor)
    fb = free_curvature(actuator, P, model, order=order, eq19_factor=eq19_factor)
    return pd.DataFrame(
        {
            "pressure_kpa": P_kpa,
            "blocked_moment_nmm": bm,
            "free_curvature_per_mm": fb.curvature,
            "free_angle_deg": fb.angle_deg,
            "status": fb.status,
            "note": fb.reason,
        }
    )
