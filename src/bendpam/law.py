r"""The moment law ``M(P, k')`` as one object: :class:`MomentLaw`.

Both models of the paper are affine in the active pressure ``P_a = max(P - P_start, 0)``
(eq 50)::

    M(P, k') = P_a A(k') - B(k')

with ``A`` and ``B`` functions of the curvature alone (for one actuator and model).  A
:class:`MomentLaw` is built once from an :class:`~bendpam.Actuator` (or a block of actuator cases,
a :class:`~bendpam.ModelParams` with array fields), a model name and the model's options, and owns
everything that samples the law:

* :meth:`MomentLaw.coefficients` ``(A, B)``, :meth:`~MomentLaw.basis` (the linear decomposition used
  by identification), :meth:`~MomentLaw.terms` (the named parts of eq 21 or eq 49);
* :attr:`MomentLaw.limits` (braid lock-up and lumen closure);
* the free-bending branch (:meth:`~MomentLaw.free_branch`: the curve ``P_a = B/A`` connected to
  the straight state, ending at a fold or at lock-up) and its roots
  (:meth:`~MomentLaw.free_curvature`);
* the stable branch at one pressure that a loaded finger rests on (:meth:`~MomentLaw.stable_branch`);
* :meth:`MomentLaw.tabulated`: the fast path, a spline table of ``A`` and ``B/k'`` with a measured
  error bound (:class:`MomentTable`).

Units at every public edge: pressure in kPa, curvature in 1/mm, moments in N*mm, so ``A`` is in
N*mm per kPa.  The models underneath (:mod:`bendpam.models`) work in MPa; the conversion happens
here and nowhere else.

>>> import bendpam
>>> law = bendpam.MomentLaw(bendpam.presets.be_pam(), "energy")
>>> round(float(law.blocked_moment(200.0)), 1)
310.3
>>> round(float(law.free_curvature(200.0).angle_deg), 1)
112.4
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property, lru_cache
from typing import Any

import numpy as np

from .actuator import Actuator, ModelParams
from .braid import DEFAULT_ORDER, CurvatureLimits, curvature_limits
from .checks import pressure_kpa as _check_pressure
from .errors import InputError, NoEquilibrium
from .models import energy, force_balance, normalise_model

__all__ = [
    "MomentLaw",
    "FreeBranch",
    "FreeBending",
    "BranchTable",
    "StableBranch",
    "MomentTable",
    "BRANCH_END",
    "illinois",
]

_PER_KPA = 1e-3  # MPa per kPa: the models' A is per MPa
_CHUNK = 1 << 13  # curvatures per block: keeps the (points x nodes) temporaries in cache
BRANCH_SAMPLES = 1200
#: Codes of the end of a free-bending branch (as stored in sweeps).
BRANCH_END = {"lock-up": 0, "fold": 1, "unbounded": 2, "neutral": 3}
_END_NAME = {v: k for k, v in BRANCH_END.items()}


def _order(order) -> int:
    if isinstance(order, bool) or not isinstance(order, int | np.integer):
        raise InputError(f"order = {order!r} must be an integer (Gauss-Legendre nodes on [0, pi])")
    if not 4 <= int(order) <= 1024:
        raise InputError(f"order = {order} is outside the allowed range [4, 1024]")
    return int(order)


class MomentLaw:
    """The moment law of one actuator (or of a block of cases) under one model.

    Parameters
    ----------
    actuator : Actuator or ModelParams
        One actuator, or a block of actuator cases (a :class:`~bendpam.ModelParams` whose fields
        are arrays of one shape; sweeps and design searches build these).
    model : {"energy", "force_balance"}
        ``"force-balance"`` is accepted too.
    eq19_factor : bool
        Energy model only: keep eq 19's ``(1 + k'R)`` factor (default, as printed; see
        docs/paper-reading.md item 7).  Ignored by the force-balance model, which has no such factor.
    order : int
        Gauss-Legendre nodes on [0, pi] for the section integrals (default 32).

    Notes
    -----
    Build one with :meth:`of` to share it (and its cached branch and table) between calls.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> law = bendpam.MomentLaw.of(bendpam.presets.bc_pam(), "energy")
    >>> law.moment([40.0, 80.0], 0.0).round(2).tolist()
    [-22.91, -137.45]
    >>> round(law.free_branch().max_pressure_kpa, 1)
    133.9
    """

    def __init__(self, actuator: Actuator | ModelParams, model: str = "energy", *, eq19_factor: bool = True,
                 order: int = DEFAULT_ORDER):
        if isinstance(actuator, Actuator):
            self.actuator: Actuator | None = actuator
            self.params = actuator.params
        elif isinstance(actuator, ModelParams):
            self.actuator = None
            self.params = actuator
        else:
            raise TypeError(f"actuator must be a bendpam.Actuator, got {type(actuator).__name__}")
        self.model = normalise_model(model)
        if not isinstance(eq19_factor, bool | np.bool_):
            raise InputError(f"eq19_factor = {eq19_factor!r} must be True or False")
        self.eq19_factor = bool(eq19_factor)
        self.order = _order(order)
        self.is_cases = self.params.shape != ()
        self._mod = energy if self.model == "energy" else force_balance
        self._opts: dict[str, Any] = {"order": self.order}
        if self.model == "energy":
            self._opts["eq19_factor"] = self.eq19_factor

    @classmethod
    def of(cls, actuator: Actuator, model: str = "energy", *, eq19_factor: bool = True,
           order: int = DEFAULT_ORDER) -> MomentLaw:
        """The shared (cached) law of ``actuator``: its branch and table are built once."""
        if not isinstance(actuator, Actuator):
            raise TypeError(f"actuator must be a bendpam.Actuator, got {type(actuator).__name__}")
        if not isinstance(eq19_factor, bool | np.bool_):
            raise InputError(f"eq19_factor = {eq19_factor!r} must be True or False")
        return _cached_law(actuator, normalise_model(model), bool(eq19_factor), _order(order))

    def __repr__(self) -> str:
        what = f"{self.params.shape} cases" if self.is_cases else (self.actuator.name or self.actuator.kind
                                                                    if self.actuator else "actuator")
        return f"MomentLaw({what}, model={self.model!r}, eq19_factor={self.eq19_factor}, order={self.order})"

    # ---- the numerics layer -------------------------------------------------------------------
    @property
    def P_start_kpa(self):
        """Threshold pressure (kPa), float or per-case array."""
        return self.params.P_start * 1e3

    @cached_property
    def limits(self) -> CurvatureLimits:
        """Admissible curvature range (braid lock-up, lumen closure), see :func:`bendpam.curvature_limits`."""
        return curvature_limits(self.params, self.order)

    def coefficients(self, curvature_per_mm, params: ModelParams | None = None):
        """``(A, B)`` with ``M = P_a A - B``: A in N*mm/kPa, B in N*mm; no range check.

        For a block of cases ``curvature_per_mm`` broadcasts against the case shape (or against
        ``params``, a subset of the cases, when given).  Large inputs are evaluated in blocks.
        """
        k = np.asarray(curvature_per_mm, dtype=float)
        p = self.params if params is None else params
        if k.size <= _CHUNK or np.ndim(p.alpha0) or k.ndim == 0:
            A, B = self._mod.coefficients(p, k, **self._opts)
            return A * _PER_KPA, B
        flat = k.ravel()
        A = np.empty(flat.size)
        B = np.empty(flat.size)
        for s in range(0, flat.size, _CHUNK):
            a, b = self._mod.coefficients(p, flat[s:s + _CHUNK], **self._opts)
            A[s:s + _CHUNK], B[s:s + _CHUNK] = a, b
        return (A * _PER_KPA).reshape(k.shape), B.reshape(k.shape)

    def basis(self, curvature_per_mm, params: ModelParams | None = None):
        """Linear decomposition ``M = P_a A - E_f I_f k' - C10 b10 - C01 b01`` (P_a, C10, C01 in kPa).

        Returns ``(A, b10, b01)`` in N*mm/kPa; they depend only on the kinematics (alpha0,
        R0_start, t0_start), so identification solves C10, C01, E_f and P_start linearly.
        """
        k = np.asarray(curvature_per_mm, dtype=float)
        A, b10, b01 = self._mod.basis(self.params if params is None else params, k, **self._opts)
        return A * _PER_KPA, b10 * _PER_KPA, b01 * _PER_KPA

    # ---- validated evaluation -----------------------------------------------------------------
    def check_curvature(self, curvature_per_mm) -> np.ndarray:
        """``curvature_per_mm`` as a float array inside the lock-up limits, else a one-line InputError."""
        if isinstance(curvature_per_mm, bool | str | bytes):
            raise InputError(f"curvature_per_mm = {curvature_per_mm!r} is not a number (1/mm expected)")
        try:
            k = np.asarray(curvature_per_mm, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"curvature_per_mm = {curvature_per_mm!r} is not numeric (1/mm expected)") from None
        self.limits.check(k)
        return k

    def active_pressure_kpa(self, pressure_kpa) -> np.ndarray:
        """Active pressure ``max(P - P_start, 0)`` in kPa (eq 50)."""
        return np.maximum(_check_pressure(pressure_kpa) - self.P_start_kpa, 0.0)

    def moment(self, pressure_kpa, curvature_per_mm) -> np.ndarray:
        """``M(P, k')`` in N*mm (eq 21 or eq 49 with eq 50-52), broadcasting pressure against curvature.

        The kinematics are computed once per value of the (un-broadcast) curvature array, so
        ``moment(P[:, None], k[None, :])`` costs little more than the kinematics of ``k``.
        """
        p = self.active_pressure_kpa(pressure_kpa)
        k = self.check_curvature(curvature_per_mm)
        A, B = self.coefficients(k)
        return p * A - B

    def blocked_moment(self, pressure_kpa) -> np.ndarray:
        """``M(P, 0)`` in N*mm: ``pi R0_start^3 (1 - 2 cot^2 alpha0) P_a`` for both models (negative for a BC-PAM)."""
        p = self.active_pressure_kpa(pressure_kpa)
        A0, _ = self.coefficients(np.zeros(()))
        return p * A0

    def terms(self, pressure_kpa, curvature_per_mm) -> dict[str, np.ndarray]:
        """The named parts of the moment in N*mm.

        Energy model: ``M_load, M_air, M_bl, M_f`` (eq 13, 19, 16, 21).  Force-balance model:
        ``M_load, M_p, M_frame, M_bl, M_br`` (eq 23-28, 49).
        """
        p = self.active_pressure_kpa(pressure_kpa)
        k = self.check_curvature(curvature_per_mm)
        return self._mod.terms(self.params, p * _PER_KPA, k, **self._opts)

    def tangent_stiffness(self, pressure_kpa, curvature_per_mm) -> np.ndarray:
        """Tangent stiffness ``dM/dk'`` in N*mm^2, by a fourth-order central difference of A and B.

        The step is ``1e-4`` of the admissible curvature span; near a lock-up limit the stencil is
        shifted to stay inside the admissible range (one-sided, still fourth order).
        """
        p = self.active_pressure_kpa(pressure_kpa)
        k = self.check_curvature(curvature_per_mm)
        lim = self.limits
        h = 1e-4 * (lim.k_max - lim.k_min)
        s = np.zeros(k.shape)
        s = np.where(k + 2 * h > lim.k_max, np.ceil((k + 2 * h - lim.k_max) / h), s)
        s = np.where(k - 2 * h < lim.k_min, -np.ceil((lim.k_min - k + 2 * h) / h), s)
        s = np.clip(s, -2, 2).astype(int)
        pts = k[..., None] + (_FD_NODES - s[..., None]) * h
        A, B = self.coefficients(pts)
        w = _FD_WEIGHTS[s + 2]
        return p * (np.sum(w * A, axis=-1) / h) - np.sum(w * B, axis=-1) / h

    # ---- free bending -------------------------------------------------------------------------
    def branches(self, samples: int = BRANCH_SAMPLES) -> BranchTable:
        """The sampled free-bending branch of every case (cached for the default sample count)."""
        if samples == BRANCH_SAMPLES:
            return self._branches
        return _branch_table(self, int(samples))

    @cached_property
    def _branches(self) -> BranchTable:
        return _branch_table(self, BRANCH_SAMPLES)

    def free_branch(self) -> FreeBranch:
        """The free-bending branch of one actuator: its end (fold or lock-up) and the sampled curve."""
        if self.is_cases:
            raise InputError("free_branch() describes one actuator; use branches() for a block of cases")
        return _describe_branch(self, self._branches)

    def free_curvature_array(self, pressure_kpa, *, table: BranchTable | None = None, xtol: float = 1e-13):
        """Free-bending curvature (1/mm) only: NaN where there is no equilibrium on the branch, 0 below P_start.

        For a block of cases ``pressure_kpa`` is 1-D and the result has shape ``cases + (pressures,)``.
        """
        P = _check_pressure(pressure_kpa)
        tab = self._branches if table is None else table
        if self.is_cases:
            if P.ndim != 1:
                raise InputError("pressure_kpa must be 1-D for a block of cases")
            pa = np.maximum(P[None, :] - np.asarray(self.P_start_kpa).reshape(-1, 1), 0.0)
        else:
            pa = np.maximum(P - self.P_start_kpa, 0.0).reshape(1, -1)
        k = _solve_free(self, tab, pa, xtol)
        return k.reshape(self.params.shape + P.shape) if self.is_cases else k.reshape(P.shape)

    def free_curvature(self, pressure_kpa, *, xtol: float = 1e-13) -> FreeBending:
        """Free-bending equilibria ``M(P, k') = 0`` on the branch connected to the straight state.

        Above the fold (or lock-up) pressure there is no equilibrium on the branch: the curvature
        is NaN, the status ``"no-equilibrium"`` and the reason says why.  A root on a
        disconnected branch beyond a fold is never returned.  The root is bracketed from the
        sampled branch and polished by a vectorised Illinois iteration to ``xtol`` relative to
        the branch's curvature range.
        """
        if self.is_cases:
            raise InputError("free_curvature() describes one actuator; use free_curvature_array() for cases")
        P = _check_pressure(pressure_kpa)
        k = self.free_curvature_array(P, xtol=xtol)
        return _assemble_free(self, P, k, self.free_branch())

    # ---- the stable branch for loaded fingers -------------------------------------------------
    def stable_branch(self, pressure_kpa: float, friction_nmm: float = 0.0) -> StableBranch:
        """The stable part of the law at one pressure (see :class:`StableBranch`), from the table.

        ``friction_nmm`` shifts the law by a saturated hysteretic moment, ``M = M_load - friction``.
        Raises :class:`~bendpam.errors.NoEquilibrium` when the straight state itself is unstable.
        """
        if self.is_cases:
            raise InputError("stable_branch() describes one actuator")
        P = float(_check_pressure(pressure_kpa, "pressure_kpa"))
        return _stable_branch(self, self.tabulated(), P, float(friction_nmm))

    # ---- the fast path ------------------------------------------------------------------------
    def tabulated(self, tol: float = 1e-6) -> MomentTable:
        """The fast path: :class:`MomentTable` of this law with interpolation error below ``tol`` (cached)."""
        if self.is_cases:
            raise InputError("tabulated() builds the table of one actuator")
        key = float(tol)
        tabs = self.__dict__.setdefault("_tables", {})
        if key not in tabs:
            tabs[key] = MomentTable(self, tol=key)
        return tabs[key]


@lru_cache(maxsize=128)
def _cached_law(actuator: Actuator, model: str, eq19_factor: bool, order: int) -> MomentLaw:
    return MomentLaw(actuator, model, eq19_factor=eq19_factor, order=order)


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
# the free-bending branch, vectorised over cases
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class BranchTable:
    """Sampled free-bending branches of a block of cases (arrays over the cases, shape (n,)).

    ``kt``, ``pt`` (n, samples + 1): curvature (1/mm) and active pressure (kPa) from the
    straight state along the bending direction; ``pt`` is increasing up to the branch end and
    ``inf`` after it.  ``kind`` holds :data:`BRANCH_END` codes; ``p_end`` is the active
    pressure (kPa) at the end (``inf`` when unbounded or neutral); ``k_end`` the curvature there;
    ``k_lim`` the lock-up limit in the bending direction; ``last`` the last table index on the
    branch; ``k_fold``/``use_ref`` the refined fold where it lies between samples.
    """

    sgn: np.ndarray
    k_lim: np.ndarray
    kind: np.ndarray
    p_end: np.ndarray
    k_end: np.ndarray
    last: np.ndarray
    kt: np.ndarray = field(repr=False)
    pt: np.ndarray = field(repr=False)
    k_fold: np.ndarray = field(repr=False)
    use_ref: np.ndarray = field(repr=False)

    def take(self, rows) -> BranchTable:
        return BranchTable(**{k: np.asarray(v)[rows] for k, v in self.__dict__.items()})


def _flat_params(law: MomentLaw) -> ModelParams:
    """The law's parameters as 1-D arrays over the cases (one case for one actuator)."""
    p = law.params.broadcast()
    return ModelParams(**{k: np.asarray(v).reshape(-1) for k, v in p.__dict__.items()})


def _branch_table(law: MomentLaw, samples: int) -> BranchTable:
    """Sample ``p(k') = B/A`` along each case's bending direction; find its end (fold, lock-up)."""
    cs = _flat_params(law)
    sgn = cs.bend_sign
    lim = curvature_limits(cs, law.order)
    k_lim = np.where(sgn > 0, lim.k_max, lim.k_min)
    frac = np.linspace(0.0, 1.0, samples + 1)[1:] ** 1.5  # graded: denser near 0 where the curve starts
    kg = k_lim[:, None] * frac
    A, B = law.coefficients(kg, cs.col())
    sA = sgn[:, None] * A
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.where(sA > 0.0, B / A, np.nan)
    n = kg.shape[-1]
    bad_a = ~(sA > 0.0)
    n_ok = np.where(bad_a.any(-1), np.argmax(bad_a, -1), n)
    pk = np.concatenate([np.zeros((kg.shape[0], 1)), p], axis=-1)
    kk = np.concatenate([np.zeros((kg.shape[0], 1)), kg], axis=-1)
    idx = np.arange(n + 1)
    valid = idx[None, :] <= n_ok[:, None]
    pk_valid = np.where(valid, pk, np.nan)
    dec = (np.diff(pk_valid, axis=-1) <= 0.0) & valid[:, 1:]
    has_dec = dec.any(-1)
    j = np.where(has_dec, np.argmax(dec, -1), 0)
    # fold refinement: golden-section maximisation of p on [kk[j-1], kk[j+1]]
    lo = np.take_along_axis(kk, np.clip(j - 1, 0, n)[:, None], -1)[:, 0]
    hi = np.take_along_axis(kk, np.clip(j + 1, 0, n)[:, None], -1)[:, 0]
    a_, b_ = np.minimum(lo, hi), np.maximum(lo, hi)
    rows = np.flatnonzero(has_dec & (j > 0))
    k_fold = np.take_along_axis(kk, j[:, None], -1)[:, 0].copy()
    pj = np.take_along_axis(pk, j[:, None], -1)[:, 0]
    p_fold = pj.copy()
    use_ref = np.zeros(kg.shape[0], dtype=bool)
    if rows.size:
        sub = cs.take(rows)

        def p_of(x):
            Ax, Bx = law.coefficients(x, sub)
            with np.errstate(divide="ignore", invalid="ignore"):
                return Bx / Ax

        a, b = a_[rows], b_[rows]
        g = (math.sqrt(5.0) - 1.0) / 2.0
        x1, x2 = b - g * (b - a), a + g * (b - a)
        f1, f2 = p_of(x1), p_of(x2)
        for _ in range(60):
            left = f1 > f2  # the maximum lies in [a, x2]
            b = np.where(left, x2, b)
            a = np.where(left, a, x1)
            new = np.where(left, b - g * (b - a), a + g * (b - a))
            fnew = p_of(new)
            x1, f1, x2, f2 = (np.where(left, new, x2), np.where(left, fnew, f2),
                              np.where(left, x1, new), np.where(left, f1, fnew))
        xm = 0.5 * (a + b)
        pm = p_of(xm)
        ref = np.isfinite(pm) & (pm > pj[rows])
        use_ref[rows] = ref
        k_fold[rows] = np.where(ref, xm, k_fold[rows])
        p_fold[rows] = np.where(ref, pm, p_fold[rows])
    kind = np.where(has_dec, BRANCH_END["fold"], np.where(n_ok < n, BRANCH_END["unbounded"], BRANCH_END["lock-up"]))
    kind = np.where(sgn == 0, BRANCH_END["neutral"], kind)
    unstable = has_dec & (j == 0)
    p_end = np.where(kind == BRANCH_END["fold"], np.where(unstable, 0.0, p_fold),
                     np.where(kind == BRANCH_END["unbounded"], np.inf,
                              np.take_along_axis(pk, np.minimum(n_ok, n)[:, None], -1)[:, 0]))
    p_end = np.where(kind == BRANCH_END["neutral"], np.inf, p_end)
    last = np.where(kind == BRANCH_END["fold"], j, np.minimum(n_ok, n))
    pt = np.where(idx[None, :] <= last[:, None], pk, np.inf)
    nxt = np.clip(last + 1, 0, n)
    k_after = np.take_along_axis(kk, nxt[:, None], -1)[:, 0]
    k_end = np.where(kind == BRANCH_END["fold"], np.where(unstable, 0.0, k_fold),
                     np.where(kind == BRANCH_END["unbounded"], k_after, k_lim))
    k_end = np.where(kind == BRANCH_END["neutral"], 0.0, k_end)
    return BranchTable(sgn=sgn, k_lim=k_lim, kind=kind, p_end=p_end, k_end=k_end, last=last, kt=kk, pt=pt,
                       k_fold=k_fold, use_ref=use_ref)


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


def _solve_free(law: MomentLaw, tab: BranchTable, pa: np.ndarray, xtol: float) -> np.ndarray:
    """Roots of ``M = 0`` at active pressures ``pa`` (cases, pressures) (kPa); NaN above the branch end."""
    k = np.zeros(pa.shape)
    above = pa > tab.p_end[:, None]
    solve = (pa > 0.0) & ~above & (tab.sgn[:, None] != 0)
    k[above] = np.nan
    if not np.any(solve):
        return k
    case, col = np.nonzero(solve)
    q = pa[case, col]
    kt, pt = tab.kt[case], tab.pt[case]
    # bracket: first table index with p >= q (the table is increasing up to its end, then inf)
    j = np.clip((pt < q[:, None]).sum(-1), 1, kt.shape[-1] - 1)
    a = np.take_along_axis(kt, (j - 1)[:, None], -1)[:, 0]
    b = np.take_along_axis(kt, j[:, None], -1)[:, 0]
    last = tab.last[case]
    beyond = j > last
    fold_end = (tab.kind[case] == BRANCH_END["fold"]) & tab.use_ref[case] & beyond
    unb = (tab.kind[case] == BRANCH_END["unbounded"]) & beyond
    b = np.where(fold_end, tab.k_fold[case], np.where(unb, tab.k_end[case], b))
    a = np.where(fold_end | unb, np.take_along_axis(kt, last[:, None], -1)[:, 0], a)
    sgn = tab.sgn[case]
    cs = _flat_params(law) if law.is_cases else law.params

    def F(x, idx):
        sub = cs.take(case[idx]) if law.is_cases else None
        A, B = law.coefficients(x, sub)
        return sgn[idx] * (q[idx] * A - B)

    tol = xtol * np.abs(tab.k_end[case]) + 1e-300
    k[case, col] = illinois(F, a, b, tol)
    return k


@dataclass(frozen=True)
class FreeBranch:
    """The free-bending branch of an actuator: equilibria ``M(P, k') = 0`` connected to k' = 0.

    Along the bending direction the equilibrium active pressure is ``p(k') = B(k') / A(k')``.  The
    branch is the part where ``p`` rises from 0; it ends at a fold (local maximum of ``p``: the
    moment-curvature curve is N-shaped and the actuator snaps through), at the braid lock-up
    limit, or never (``p`` grows without bound).

    Attributes
    ----------
    direction : +1 (toward the frame), -1 (away), 0 (neutral braid angle).
    k_end_per_mm : curvature where the branch ends.
    p_end_active_kpa : active pressure at the branch end; ``inf`` if unbounded.
    max_pressure_kpa : highest (gauge) pressure with a free-bending equilibrium on the branch.
    kind : ``"fold"``, ``"lock-up"``, ``"unbounded"`` or ``"neutral"``.
    reason : a sentence explaining the end of the branch.
    k_table_per_mm, p_table_kpa : the sampled branch ``(k', P_a)`` from k' = 0 to its end (monotone in P_a).
    """

    direction: int
    k_end_per_mm: float
    p_end_active_kpa: float
    max_pressure_kpa: float
    kind: str
    reason: str
    k_table_per_mm: np.ndarray = field(repr=False)
    p_table_kpa: np.ndarray = field(repr=False)


def _describe_branch(law: MomentLaw, tab: BranchTable) -> FreeBranch:
    sgn = int(tab.sgn[0])
    kind = _END_NAME[int(tab.kind[0])]
    P0 = float(law.P_start_kpa)
    last = int(tab.last[0])
    kt, pt = tab.kt[0, : last + 1], tab.pt[0, : last + 1]
    k_end, p_end = float(tab.k_end[0]), float(tab.p_end[0])
    lim = law.limits
    if kind == "neutral":
        z = np.zeros(1)
        return FreeBranch(0, 0.0, math.inf, math.inf, kind,
                          "neutral braid angle (54.74 deg): M(P, 0) = 0 at every pressure", z, z)
    if kind == "fold":
        if p_end == 0.0:
            return FreeBranch(sgn, 0.0, 0.0, P0, kind,
                              "the straight state is unstable: M decreases with curvature at P_start "
                              "(negative passive stiffness)", kt[:1], pt[:1])
        if bool(tab.use_ref[0]):
            kt, pt = np.append(kt, k_end), np.append(pt, p_end)
        side = "k' > 0" if sgn > 0 else "k' < 0"
        return FreeBranch(sgn, k_end, p_end, P0 + p_end, kind,
                          f"fold of the moment-curvature curve (N-shaped): the free-bending branch ({side}) ends at "
                          f"k' = {k_end:.5g} 1/mm, P = {P0 + p_end:.4g} kPa; above it the actuator snaps through "
                          "and there is no free-bending equilibrium on this branch", kt, pt)
    if kind == "unbounded":
        return FreeBranch(sgn, k_end, math.inf, math.inf, kind,
                          "pressure moment vanishes before lock-up: every pressure has an equilibrium",
                          np.append(kt, k_end), np.append(pt, math.inf))
    return FreeBranch(sgn, k_end, p_end, P0 + p_end, kind,
                      f"braid lock-up limit k' = {k_end:.5g} 1/mm reached at P = {P0 + p_end:.4g} kPa "
                      f"({lim.reason_max if sgn > 0 else lim.reason_min})", kt, pt)


@dataclass(frozen=True)
class FreeBending:
    """Free-bending equilibria ``M(P, k') = 0`` at given pressures (one actuator).

    Attributes
    ----------
    pressure_kpa : the pressures asked for (input shape).
    curvature_per_mm : k' (1/mm); NaN where no equilibrium exists on the branch.
    angle_deg : theta = k' L0 (deg); NaN likewise.
    status : ``"ok"``, ``"deadband"`` (P <= P_start: straight) or ``"no-equilibrium"``.
    reason : empty for ``"ok"``, else an explanation.
    max_pressure_kpa : highest pressure that still has a free-bending equilibrium (inf if none).
    branch : the :class:`FreeBranch` used.
    """

    pressure_kpa: np.ndarray
    curvature_per_mm: np.ndarray
    angle_deg: np.ndarray
    status: np.ndarray
    reason: np.ndarray
    max_pressure_kpa: float
    branch: FreeBranch = field(repr=False)

    @property
    def ok(self) -> np.ndarray:
        """True where an equilibrium exists (``status != "no-equilibrium"``)."""
        return self.status != "no-equilibrium"


def _assemble_free(law: MomentLaw, P: np.ndarray, k: np.ndarray, br: FreeBranch) -> FreeBending:
    P0 = float(law.P_start_kpa)
    flat = P.ravel()
    status = np.full(flat.shape, "ok", dtype=object)
    reason = np.full(flat.shape, "", dtype=object)
    below = flat < P0
    status[below] = "deadband"
    reason[below] = f"below the threshold pressure P_start = {P0:g} kPa: no active moment"
    if br.direction == 0:
        reason[flat > P0] = br.reason
    else:
        none = np.isnan(k.ravel())
        status[none] = "no-equilibrium"
        reason[none] = br.reason
    L0 = float(law.params.L0)
    return FreeBending(pressure_kpa=P, curvature_per_mm=k, angle_deg=np.degrees(k * L0),
                       status=status.reshape(P.shape).astype(str), reason=reason.reshape(P.shape).astype(str),
                       max_pressure_kpa=br.max_pressure_kpa, branch=br)


# ------------------------------------------------------------------------------------------------
# the fast path: spline tables of A and B/k'
# ------------------------------------------------------------------------------------------------
_TABLE_ORDER = 64
_TABLE_P_SCALE_KPA = 500.0  # the error bound covers active pressures up to 500 kPa


class MomentTable:
    """Cubic-spline tables of ``A(k')`` and ``G(k') = B(k') / k'`` of one :class:`MomentLaw`.

    The knots are Chebyshev-Lobatto points on ``[k_min, 0]`` and ``[0, k_max]`` (so ``k' = 0`` is
    a knot and the knots cluster toward the lock-up limits, where the functions steepen); one C2
    cubic spline runs through all of them.  ``B`` is tabulated as ``G = B/k'`` (``B(0) = 0``) so
    the elastic term keeps its relative accuracy near the straight state.  The exact values come
    from the law at 64 Gauss nodes.  The interpolation error is measured at build time against
    the exact path at every interval's midpoint, relative to ``|P_a A| + |B|`` with
    ``P_a = 500 kPa``; while it exceeds ``tol`` the knots are doubled (:attr:`max_rel_error`).

    Evaluation is a gather of 4 x 2 cubic coefficients per point (the interval index comes from
    ``arccos`` of the Chebyshev map, no search) and Horner steps; complex curvatures are accepted
    (the interval comes from the real part), for complex-step derivatives.
    """

    def __init__(self, law: MomentLaw, *, knots: int = 1025, tol: float = 1e-6, max_knots: int = 32769):
        if not isinstance(law, MomentLaw) or law.is_cases:
            raise TypeError("MomentTable tabulates the MomentLaw of one actuator")
        if not (isinstance(tol, float | int) and tol > 0):
            raise InputError(f"tol = {tol!r} must be a positive number")
        self.law = law
        self._exact_law = law if law.order == _TABLE_ORDER else MomentLaw(
            law.actuator if law.actuator is not None else law.params, law.model, eq19_factor=law.eq19_factor,
            order=_TABLE_ORDER)
        self.limits = law.limits
        self.P_start_kpa = float(law.P_start_kpa)
        n = int(knots)
        while True:
            self._build(n)
            if self.max_rel_error <= tol or n >= max_knots:
                break
            n = 2 * n - 1
        self.knots = n

    def _exact(self, k):
        return self._exact_law.coefficients(k)

    def _build(self, n: int) -> None:
        from scipy.interpolate import CubicSpline

        lo, hi = float(self.limits.k_min), float(self.limits.k_max)
        t = np.cos(np.linspace(0.0, np.pi, n))  # 1 .. -1
        left = 0.5 * lo * (1.0 + t)  # lo*(1+t)/2: from lo (t = 1) to 0 (t = -1)
        right = 0.5 * hi * (1.0 - t)  # from 0 to hi
        kj = np.concatenate([left, right[1:]])
        kj[0], kj[n - 1], kj[-1] = lo, 0.0, hi
        A, B = self._exact(kj)
        G = np.empty_like(B)
        nz = kj != 0.0
        G[nz] = B[nz] / kj[nz]
        h = 1e-5 * min(-lo, hi)
        _, Bh = self._exact(np.array([-2 * h, -h, h, 2 * h]))
        G[~nz] = (Bh[0] - 8 * Bh[1] + 8 * Bh[2] - Bh[3]) / (12 * h)
        spl = CubicSpline(kj, np.stack([A, G], axis=-1))
        self._lo, self._hi, self._n = lo, hi, n
        self._kj = kj
        self._coef = np.ascontiguousarray(np.moveaxis(spl.c, 0, -2))  # (intervals, 4, 2)
        km = 0.5 * (kj[1:] + kj[:-1])
        Ae, Be = self._exact(km)
        Af, Bf = self.coefficients(km)
        P = _TABLE_P_SCALE_KPA
        scale = P * np.abs(Ae) + np.abs(Be) + 1e-300
        self.max_rel_error = float(np.max((P * np.abs(Af - Ae) + np.abs(Bf - Be)) / scale))

    @property
    def knot_curvatures(self) -> np.ndarray:
        """The knots (1/mm), increasing; ``k' = 0`` is one of them."""
        return self._kj

    @property
    def zero_index(self) -> int:
        """Index of the knot ``k' = 0``."""
        return self._n - 1

    def _interval(self, k):
        kr = np.real(k)
        n = self._n
        tl = np.clip(2.0 * kr / self._lo - 1.0, -1.0, 1.0)  # left piece: t = 2k/lo - 1 in [-1, 1]
        tr = np.clip(1.0 - 2.0 * kr / self._hi, -1.0, 1.0)
        jl = np.floor(np.arccos(tl) * ((n - 1) / np.pi))
        jr = (n - 1) + np.floor(np.arccos(tr) * ((n - 1) / np.pi))
        j = np.where(kr < 0.0, jl, jr).astype(np.intp)
        np.clip(j, 0, self._kj.size - 2, out=j)
        return j

    def _eval(self, k, derivative: bool):
        j = self._interval(k)
        c = self._coef[j]
        dx = (k - self._kj[j])[..., None]
        v = ((c[..., 0, :] * dx + c[..., 1, :]) * dx + c[..., 2, :]) * dx + c[..., 3, :]
        if not derivative:
            return v, None
        d = (3.0 * c[..., 0, :] * dx + 2.0 * c[..., 1, :]) * dx + c[..., 2, :]
        return v, d

    def coefficients(self, curvature_per_mm):
        """Interpolated ``(A, B)`` (N*mm/kPa, N*mm) at ``curvature_per_mm``; no range check."""
        k = np.asarray(curvature_per_mm)
        if not np.iscomplexobj(k):
            k = k.astype(float, copy=False)
        v, _ = self._eval(k, False)
        return v[..., 0], k * v[..., 1]

    def derivatives(self, curvature_per_mm):
        """``(A, B, dA/dk', dB/dk')`` from the splines (complex curvatures allowed)."""
        k = np.asarray(curvature_per_mm)
        if not np.iscomplexobj(k):
            k = k.astype(float, copy=False)
        v, d = self._eval(k, True)
        A, G = v[..., 0], v[..., 1]
        return A, k * G, d[..., 0], G + k * d[..., 1]

    def moment(self, pressure_kpa, curvature_per_mm):
        """``M(P, k')`` in N*mm, broadcasting; the same validation as :meth:`MomentLaw.moment`."""
        p = np.maximum(_check_pressure(pressure_kpa) - self.P_start_kpa, 0.0)
        k = self.law.check_curvature(curvature_per_mm)
        A, B = self.coefficients(k)
        return p * A - B

    __call__ = moment

    def tangent_stiffness(self, pressure_kpa, curvature_per_mm):
        """``dM/dk'`` (N*mm^2) from the spline derivatives."""
        p = np.maximum(_check_pressure(pressure_kpa) - self.P_start_kpa, 0.0)
        k = self.law.check_curvature(curvature_per_mm)
        _, _, dA, dB = self.derivatives(k)
        return p * dA - dB

    def free_curvature(self, pressure_kpa, *, newton_steps: int = 6) -> FreeBending:
        """Free-bending curvature from the tables: the same branch as :meth:`MomentLaw.free_curvature`.

        Starts from the sampled branch (monotone ``P_a(k') = B/A``) and polishes with safeguarded
        Newton steps on the interpolated moment.
        """
        law = self.law
        P = _check_pressure(pressure_kpa)
        tab = law.branches()
        br = law.free_branch()
        kt, pt = br.k_table_per_mm, br.p_table_kpa
        finite = np.isfinite(pt)
        d = br.direction
        pa = np.maximum(P - self.P_start_kpa, 0.0).ravel()
        k = np.zeros(pa.shape)
        above = pa > float(tab.p_end[0])
        want = (pa > 0.0) & ~above & (d != 0)
        k[above] = np.nan
        if np.any(want):
            q = pa[want]
            x = np.interp(q, pt[finite], kt[finite])
            j = np.clip(np.searchsorted(pt, q), 1, kt.size - 1)
            lo, hi = np.minimum(kt[j - 1], kt[j]), np.maximum(kt[j - 1], kt[j])
            for _ in range(newton_steps):
                A, B, dA, dB = self.derivatives(x)
                f = q * A - B
                ahead = d * f > 0  # before the root along the branch
                if d > 0:
                    lo, hi = np.where(ahead, x, lo), np.where(~ahead, x, hi)
                else:
                    hi, lo = np.where(ahead, x, hi), np.where(~ahead, x, lo)
                xn = x - f / (q * dA - dB)
                x = np.where((xn >= lo) & (xn <= hi), xn, 0.5 * (lo + hi))
            k[want] = x
        return _assemble_free(law, P, k.reshape(P.shape), br)


# ------------------------------------------------------------------------------------------------
# the stable branch at one pressure (loaded fingers)
# ------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class StableBranch:
    """The stable part of the moment law ``M(P, k')`` at one pressure.

    Along the branch connected to the straight state (``k' = 0``) ``M`` decreases strictly with
    ``k'``; it is the only part of the law on which a loaded finger can rest (a segment with
    ``dM/dk' > 0`` is unstable and snaps through).

    Attributes
    ----------
    pressure_kpa : the pressure.
    k_lo, k_hi : ends of the branch, 1/mm (``k_lo < 0 < k_hi``).
    moment_max, moment_min : ``M`` at ``k_lo`` and ``k_hi`` (N*mm): the range of moments the
        actuator can balance at this pressure.
    end_lo, end_hi : ``"fold"`` or ``"lock-up"``: what ends the branch on each side.
    free_curvature : the free curvature on the branch (1/mm), NaN if ``M = 0`` is outside the range.
    friction_nmm : the constant shift of the law (saturated friction), N*mm.
    """

    pressure_kpa: float
    k_lo: float
    k_hi: float
    moment_max: float
    moment_min: float
    end_lo: str
    end_hi: str
    free_curvature: float
    friction_nmm: float
    table: MomentTable = field(repr=False, compare=False)
    p_active_kpa: float = field(repr=False, compare=False, default=0.0)

    def moment(self, k):
        """``M`` (N*mm) and ``dM/dk'`` (N*mm^2) from the table, broadcasting ``k`` (complex allowed)."""
        A, B, dA, dB = self.table.derivatives(k)
        pa = self.p_active_kpa
        return pa * A - B - self.friction_nmm, pa * dA - dB

    def curvature(self, m):
        """Invert ``M(P, k') = m`` on the branch (1/mm); NaN outside ``[moment_min, moment_max]``."""
        m = np.asarray(m, dtype=float)
        kj = self.table.knot_curvatures
        lo = np.searchsorted(kj, self.k_lo)
        hi = np.searchsorted(kj, self.k_hi, side="right")
        kk = np.concatenate([[self.k_lo], kj[lo:hi], [self.k_hi]])
        mm, _ = self.moment(kk)
        k = np.interp(-m, -mm, kk)
        for _ in range(4):  # Newton polish on the spline law
            f, d = self.moment(k)
            k = np.clip(k - (f - m) / d, self.k_lo, self.k_hi)
        return np.where((m <= self.moment_max) & (m >= self.moment_min), k, np.nan)

    def describe_end(self, side: int) -> str:
        k, kind = (self.k_hi, self.end_hi) if side > 0 else (self.k_lo, self.end_lo)
        m = self.moment_min if side > 0 else self.moment_max
        what = "a fold of the moment law (N-shaped: beyond it the actuator snaps through)" if kind == "fold" \
            else "braid lock-up"
        return f"{what} at k' = {k:.5g} 1/mm, M = {m:.4g} N*mm"


def _stable_branch(law: MomentLaw, table: MomentTable, P: float, friction: float) -> StableBranch:
    pa = max(P - table.P_start_kpa, 0.0)
    kg = table.knot_curvatures
    A, B, dA, dB = table.derivatives(kg)
    dm = pa * dA - dB
    i0 = table.zero_index
    if dm[i0] >= 0.0:
        raise NoEquilibrium(
            f"pressure = {P:g} kPa: the straight state is unstable (dM/dk' = {dm[i0]:.4g} N*mm^2 >= 0 at "
            "k' = 0), so the actuator has no stable branch to rest on"
        )
    bad = np.flatnonzero(dm >= 0.0)
    left, right = bad[bad < i0], bad[bad > i0]

    def fold(i, j):  # dm changes sign between knots i and j: refine its zero by bisection on the spline
        a, b = kg[i], kg[j]
        da = dm[i]
        for _ in range(60):
            mid = 0.5 * (a + b)
            _, _, dAm, dBm = table.derivatives(mid)
            dmm = pa * dAm - dBm
            if (dmm < 0.0) == (da < 0.0):
                a, da = mid, dmm
            else:
                b = mid
        return float(a)

    if right.size:
        k_hi, end_hi = fold(right[0] - 1, right[0]), "fold"
    else:
        k_hi, end_hi = float(kg[-1]), "lock-up"
    if left.size:
        k_lo, end_lo = fold(left[-1] + 1, left[-1]), "fold"
    else:
        k_lo, end_lo = float(kg[0]), "lock-up"
    br = StableBranch(P, k_lo, k_hi, math.nan, math.nan, end_lo, end_hi, math.nan, friction, table, pa)
    m_lo = float(br.moment(k_lo)[0])
    m_hi = float(br.moment(k_hi)[0])
    kf = math.nan
    if m_hi < 0.0 < m_lo:
        kf = float(StableBranch(P, k_lo, k_hi, m_lo, m_hi, end_lo, end_hi, math.nan, friction, table, pa)
                   .curvature(0.0))
    elif m_hi == 0.0 or m_lo == 0.0:
        kf = 0.0
    return StableBranch(P, k_lo, k_hi, m_lo, m_hi, end_lo, end_hi, kf, friction, table, pa)
