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
N*mm per kPa.  The models underneath (:mod:`bendpam.physics.models`) work in MPa; the conversion happens
here and nowhere else.

>>> import bendpam
>>> law = bendpam.MomentLaw(bendpam.physics.presets.be_pam(), "energy")
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

from bendpam.errors import InputError, NoEquilibrium
from bendpam.physics.actuator import NEUTRAL_ANGLE_DEG, Actuator, ModelParams
from bendpam.physics.braid import (
    DEFAULT_ORDER,
    LOCK_FRACTION,
    MIN_FAR_STRETCH,
    CurvatureLimits,
    curvature_limits,
    radius_from_u,
)
from bendpam.physics.models import energy, force_balance, normalise_model
from bendpam.physics.roots import bracketed_newton, illinois
from bendpam.validate import boolean, float_array, quadrature_order
from bendpam.validate import pressure_kpa as _check_pressure

__all__ = [
    "BRANCH_END",
    "BranchTable",
    "FreeBending",
    "FreeBranch",
    "MomentLaw",
    "MomentTable",
    "StableBranch",
]

_PER_KPA = 1e-3  # MPa per kPa: the models' A is per MPa
_CHUNK = 1 << 13  # curvatures per block: keeps the (points x nodes) temporaries in cache
BRANCH_SAMPLES = 1200
#: Active pressures (kPa) below this have the straight free state (k' = 0) without a solve.
TINY_ACTIVE_KPA = 1e-9
#: Interpolation tolerance of the table behind :meth:`MomentLaw.stable_branch` (finger statics).
STABLE_BRANCH_TOL = 1e-8
#: Codes of the end of a free-bending branch (as stored in sweeps).
BRANCH_END = {"lock-up": 0, "fold": 1, "unbounded": 2, "neutral": 3}
_END_NAME = {v: k for k, v in BRANCH_END.items()}


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
        0 (default): the section integrals in closed form (elliptic integrals); N in [4, 1024]: N
        Gauss-Legendre nodes on [0, pi] instead.

    Notes
    -----
    Build one with :meth:`of` to share it (and its cached branch and table) between calls.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> law = bendpam.MomentLaw.of(bendpam.physics.presets.bc_pam(), "energy")
    >>> law.moment([40.0, 80.0], 0.0).round(2).tolist()
    [-42.11, -252.65]
    >>> round(law.free_branch().max_pressure_kpa, 1)
    134.2
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
        self.eq19_factor = boolean("eq19_factor", eq19_factor)
        self.order = quadrature_order(order)
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
        return _cached_law(actuator, normalise_model(model), boolean("eq19_factor", eq19_factor),
                           quadrature_order(order))

    def __repr__(self) -> str:
        what = f"{self.params.shape} cases" if self.is_cases else (self.actuator.name or self.actuator.kind
                                                                    if self.actuator else "actuator")
        return f"MomentLaw({what}, model={self.model!r}, eq19_factor={self.eq19_factor}, order={self.order})"

    # ---- the numerics layer -------------------------------------------------------------------
    @property
    def P_start_kpa(self):
        """Threshold pressure (kPa), float or per-case array (exactly the actuator's ``P_start_kpa``)."""
        return self.params.P_start_kpa

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
        k = float_array("curvature_per_mm", curvature_per_mm, "1/mm")
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
        h = 1e-4 * (lim.k_max - lim.k_min)  # per case for a block of cases
        if np.ndim(h):
            k = np.broadcast_to(k, np.broadcast_shapes(k.shape, np.shape(h)))
        s = np.zeros(k.shape)
        s = np.where(k + 2 * h > lim.k_max, np.ceil((k + 2 * h - lim.k_max) / h), s)
        s = np.where(k - 2 * h < lim.k_min, -np.ceil((lim.k_min - k + 2 * h) / h), s)
        s = np.clip(s, -2, 2).astype(int)
        # the five stencil points on a leading axis, so that a block of cases broadcasts on the trailing ones
        pts = k[None, ...] + (_FD_NODES.reshape((5,) + (1,) * k.ndim) - s[None, ...]) * h
        A, B = self.coefficients(pts)
        w = np.moveaxis(_FD_WEIGHTS[s + 2], -1, 0)
        return p * (np.sum(w * A, axis=0) / h) - np.sum(w * B, axis=0) / h

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
        return self.free_state_array(pressure_kpa, table=table, xtol=xtol)[0]

    def free_state_array(self, pressure_kpa, *, table: BranchTable | None = None, xtol: float = 1e-13):
        """``(k', u)``: the free-bending curvature of :meth:`free_curvature_array` and ``u = k'R`` there.

        ``u`` is the branch parameter the root is solved in (eq 5), so the radius ``R = u / k'`` of
        the free state comes without another solve of eq 5 (:func:`bendpam.physics.limits.case_limits`);
        NaN where ``k'`` is NaN, 0 where it is 0.

        >>> import bendpam
        >>> k, u = bendpam.MomentLaw.of(bendpam.physics.presets.be_pam()).free_state_array([50.0, 200.0])
        >>> k.round(5).tolist(), round(float(u[1] / k[1]), 4)  # R (mm) at 200 kPa
        ([0.0, 0.01353], 9.891)
        """
        P = _check_pressure(pressure_kpa)
        tab = self._branches if table is None else table
        if self.is_cases:
            if P.ndim != 1:
                raise InputError("pressure_kpa must be 1-D for a block of cases")
            pa = np.maximum(P[None, :] - np.asarray(self.P_start_kpa).reshape(-1, 1), 0.0)
        else:
            pa = np.maximum(P - self.P_start_kpa, 0.0).reshape(1, -1)
        k, u = _solve_free(self, tab, pa, xtol)
        shape = self.params.shape + P.shape if self.is_cases else P.shape
        return k.reshape(shape), u.reshape(shape)

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
        return _stable_branch(self, self.tabulated(STABLE_BRANCH_TOL), P, float(friction_nmm))

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
    branch; ``k_fold``/``use_ref`` the refined fold where it lies between samples.  ``xt``,
    ``x_end``, ``x_fold`` are the same in the branch parameter u = k'R (with the section means computed
    exactly, or interpolated from the shared tables) and ``path`` evaluates the law in it.
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
    xt: np.ndarray = field(repr=False)
    x_end: np.ndarray = field(repr=False)
    x_fold: np.ndarray = field(repr=False)
    path: Any = field(repr=False, compare=False)


def _flat_params(law: MomentLaw) -> ModelParams:
    """The law's parameters as 1-D arrays over the cases (one case for one actuator)."""
    p = law.params.broadcast()
    return ModelParams(**{k: np.asarray(v).reshape(-1) for k, v in p.__dict__.items()})


class _ExactUPath:
    """The branch parameter is ``u = k'R``, with the section means computed exactly (no eq 5 solve).

    Sampling and solving the free-bending branch in ``u`` needs one pass of the quadrature per
    point, where a curvature needs the Newton solve of eq 5 first (four to six passes).
    """

    def __init__(self, law: MomentLaw):
        self.law = law
        self.cs = _flat_params(law)
        self.scalar = not law.is_cases
        lim = curvature_limits(law.params if self.scalar else self.cs, law.order)
        n = self.cs.alpha0.size
        self.k_min = np.broadcast_to(np.asarray(lim.k_min, dtype=float), (n,)).copy()
        self.k_max = np.broadcast_to(np.asarray(lim.k_max, dtype=float), (n,)).copy()
        self.x_min = np.broadcast_to(np.asarray(lim.u_min, dtype=float), (n,)).copy()
        self.x_max = np.broadcast_to(np.asarray(lim.u_max, dtype=float), (n,)).copy()

    def _state(self, u, rows):
        sub = self.law.params if self.scalar else self.cs.take(rows)
        m = self.law._mod.section_means(u, sub.alpha0, self.law.order)
        R, dR, k = radius_from_u(u, m["ib"], m["dib"], sub.alpha0, sub.R0_start)
        return sub, m, R, dR, k

    def coef(self, u, rows):
        sub, m, R, dR, k = self._state(np.asarray(u, dtype=float), rows)
        return _assembled(self.law, sub, k, u, R, dR, m)

    def to_k(self, u, rows):
        return self._state(np.asarray(u, dtype=float), rows)[4]


def _assembled(law: MomentLaw, sub, k, u, R, dR, m):
    """``(A per kPa, B)`` of the law's model from kinematics and section means."""
    if law.model == "energy":
        A, b10, b01 = law._mod.assemble(sub, k, u, R, dR, m, eq19_factor=law.eq19_factor)
    else:
        A, b10, b01 = law._mod.assemble(sub, k, u, R, dR, m)
    return A * _PER_KPA, sub.C10 * b10 + sub.C01 * b01 + sub.frame_stiffness * k


class SectionTables:
    """Spline tables of a model's section means over ``u = k'R``, one per distinct braid angle.

    The section integrals of both models depend on ``u`` and the braid angle only
    (``section_means`` of :mod:`bendpam.physics.models.energy` and :mod:`~bendpam.physics.models.force_balance`);
    everything else is per-actuator arithmetic.  Cases that share a braid angle (a sweep over a grid)
    therefore share one table: the means at Chebyshev-Lobatto knots of ``u`` on each side of 0
    (clustered toward the braid limits, where they steepen), interpolated by a C2 cubic spline.
    The knots are doubled until the interpolation error at every interval's midpoint, relative to
    each mean's largest magnitude, is below ``tol`` (:attr:`max_rel_error`).
    """

    def __init__(self, mod, alpha0, order: int, *, knots: int = 513, tol: float = 1e-7, max_knots: int = 4097):
        self.alpha0 = np.atleast_1d(np.asarray(alpha0, dtype=float))
        c = np.cos(self.alpha0)
        # one side per angle: the bending direction (k' > 0 above the neutral angle, k' < 0 below)
        self.side = np.where(np.degrees(self.alpha0) < NEUTRAL_ANGLE_DEG, -1.0, 1.0)
        self.u_end = np.where(self.side > 0, LOCK_FRACTION * (1.0 / c - 1.0) / 2.0, -0.5 * (1.0 - MIN_FAR_STRETCH))
        # the knot count is chosen on the extreme angles (the error hardly depends on the angle), then
        # every angle is tabulated once at that count
        probe = np.unique([int(np.argmin(self.alpha0)), int(np.argmax(self.alpha0))])
        n = int(knots)
        while True:
            uj, coef, keys = self._build(mod, probe, order, n)
            self._n, self._uj, self._coef, self.keys = n, uj, coef, keys
            um = 0.5 * (uj[:, 1:] + uj[:, :-1])
            me = mod.section_means(um, self.alpha0[probe][:, None], order)
            E = np.stack([me[k] for k in keys], axis=-1)
            F = self._eval(np.broadcast_to(np.arange(probe.size)[:, None], um.shape), um, side=self.side[probe],
                           u_end=self.u_end[probe])
            scale = np.max(np.abs(coef[..., 3, :]), axis=1, keepdims=True) + 1e-300
            self.max_rel_error = float(np.max(np.abs(F - E) / scale))
            if self.max_rel_error <= tol or n >= max_knots:
                break
            n = 2 * n - 1
        if probe.size < self.alpha0.size:
            self._uj, self._coef, _ = self._build(mod, np.arange(self.alpha0.size), order, n)
        self.knots = n

    def _build(self, mod, which, order, n):
        """Knots and spline coefficients of the angles ``which`` at ``n`` knots."""
        from scipy.interpolate import CubicSpline

        t = np.cos(np.linspace(0.0, np.pi, n))
        uj = np.sort(0.5 * self.u_end[which][:, None] * (1.0 - t), axis=1)  # Chebyshev-Lobatto on [0, u_end]
        m = mod.section_means(uj, self.alpha0[which][:, None], order)
        keys = list(m)
        Y = np.stack([m[k] for k in keys], axis=-1)  # (angles, knots, keys)
        coef = np.empty((len(which), n - 1, 4, len(keys)))
        for i in range(len(which)):  # one spline per distinct angle (not per point)
            coef[i] = np.moveaxis(CubicSpline(uj[i], Y[i]).c, 0, 1)
        return uj, coef, keys

    def _eval(self, ia, u, cols=None, side=None, u_end=None):
        n = self._n
        side = self.side if side is None else side
        u_end = self.u_end if u_end is None else u_end
        t = np.clip(1.0 - 2.0 * u / u_end[ia], -1.0, 1.0)  # knots at u_end (1 - cos(pi i/(n-1)))/2
        j = np.floor(np.arccos(t) * ((n - 1) / np.pi)).astype(np.intp)
        j = np.where(side[ia] < 0, (n - 2) - j, j)  # the negative side's knots are stored increasing
        np.clip(j, 0, n - 2, out=j)
        c = self._coef[ia, j] if cols is None else self._coef[ia, j][..., cols]  # (..., 4, keys)
        dx = (u - self._uj[ia, j])[..., None]
        return ((c[..., 0, :] * dx + c[..., 1, :]) * dx + c[..., 2, :]) * dx + c[..., 3, :]

    def ibar(self, ia, u):
        """The interpolated ``Ibar(u)`` alone (eq 5), for the lumen limit."""
        ia, u = np.broadcast_arrays(np.asarray(ia), np.asarray(u, dtype=float))
        n = self._n
        t = np.clip(1.0 - 2.0 * u / self.u_end[ia], -1.0, 1.0)
        j = np.floor(np.arccos(t) * ((n - 1) / np.pi)).astype(np.intp)
        j = np.clip(np.where(self.side[ia] < 0, (n - 2) - j, j), 0, n - 2)
        c = self._coef[ia, j, :, 0]
        dx = u - self._uj[ia, j]
        return ((c[..., 0] * dx + c[..., 1]) * dx + c[..., 2]) * dx + c[..., 3]

    def means(self, ia, u) -> dict:
        """The interpolated means at ``u`` for the angles ``ia`` (indices into :attr:`alpha0`)."""
        ia, u = np.broadcast_arrays(np.asarray(ia), np.asarray(u, dtype=float))
        v = self._eval(ia, u)
        return {k: v[..., i] for i, k in enumerate(self.keys)}


class _TablePath:
    """The branch parameter is ``u = k'R``; the section means come from shared :class:`SectionTables`."""

    def __init__(self, law: MomentLaw, cs: ModelParams, uniq, inverse):
        self.law, self.cs = law, cs
        self.tables = SectionTables(law._mod, uniq, law.order)
        self.ia = inverse
        self.x_min, self.x_max = self._u_limits()
        self.k_min = self.to_k(self.x_min, np.arange(self.ia.size))  # 0 on the side that is not tabulated
        self.k_max = self.to_k(self.x_max, np.arange(self.ia.size))

    def _state(self, u, rows):
        sub = self.cs.take(rows)
        m = self.tables.means(self.ia[rows], u)
        R, dR, k = radius_from_u(u, m["ib"], m["dib"], sub.alpha0, sub.R0_start)
        return sub, m, R, dR, k

    def coef(self, u, rows):
        sub, m, R, dR, k = self._state(u, rows)
        return _assembled(self.law, sub, k, u, R, dR, m)

    def to_k(self, u, rows):
        m = self.tables.means(self.ia[rows], u)
        sub = self.cs.take(rows)
        return radius_from_u(u, m["ib"], m["dib"], sub.alpha0, sub.R0_start)[2]

    def _u_limits(self):
        """The braid limit in u on the bending side, cut where the bladder lumen closes (``R = t_bar``)."""
        n = self.ia.size
        rows = np.arange(n)[:, None]
        end = self.tables.u_end[self.ia]
        grid = end[:, None] * np.linspace(0.0, 1.0, 65)

        def lumen(u, rows=rows):
            sub = self.cs.take(rows)
            xi = 1.0 / (np.sin(sub.alpha0) * self.tables.ibar(self.ia[rows], u))
            return sub.R0_start * xi * xi * (1.0 + u) - sub.t0_start

        neg = lumen(grid) <= 0.0
        has = neg.any(axis=-1)
        j = np.where(has, np.argmax(neg, axis=-1), 1)
        a = np.take_along_axis(grid, (j - 1)[:, None], -1)[:, 0]
        b = np.take_along_axis(grid, j[:, None], -1)[:, 0]
        if has.any():
            for _ in range(64):
                mid = 0.5 * (a + b)
                pos = lumen(mid, np.arange(n)) > 0
                a, b = np.where(pos, mid, a), np.where(pos, b, mid)
        u_end = np.where(has, 0.5 * (a + b), end)
        pos_side = self.tables.side[self.ia] > 0
        return np.where(pos_side, 0.0, u_end), np.where(pos_side, u_end, 0.0)


#: A block of cases uses the shared section tables when it has at least this many cases per angle.
TABLE_MIN_CASES_PER_ANGLE = 8


def _path(law: MomentLaw):
    """The exact path (in u), or the shared-table path for blocks of cases with few distinct braid angles."""
    if law.is_cases:
        cs = _flat_params(law)
        uniq, inverse = np.unique(cs.alpha0, return_inverse=True)
        if cs.alpha0.size >= TABLE_MIN_CASES_PER_ANGLE * uniq.size:
            return _TablePath(law, cs, uniq, inverse.reshape(-1))
    return _ExactUPath(law)


def _branch_table(law: MomentLaw, samples: int) -> BranchTable:
    """Sample ``P_a(x) = B/A`` along each case's bending direction; find its end (fold, lock-up).

    ``x`` is the branch parameter u = k'R, evaluated exactly or on shared tables (:func:`_path`).
    """
    ev = _path(law)
    cs = ev.cs
    sgn = cs.bend_sign
    ncase = sgn.size
    x_lim = np.where(sgn > 0, ev.x_max, ev.x_min)
    k_lim = np.where(sgn > 0, ev.k_max, ev.k_min)
    frac = np.linspace(0.0, 1.0, samples + 1)[1:] ** 1.5  # graded: denser near 0 where the curve starts
    xg = x_lim[:, None] * frac
    allrows = np.arange(ncase)[:, None]
    A, B = ev.coef(xg, allrows)
    sA = sgn[:, None] * A
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.where(sA > 0.0, B / A, np.nan)
    n = xg.shape[-1]
    bad_a = ~(sA > 0.0)
    n_ok = np.where(bad_a.any(-1), np.argmax(bad_a, -1), n)
    pk = np.concatenate([np.zeros((ncase, 1)), p], axis=-1)
    xk = np.concatenate([np.zeros((ncase, 1)), xg], axis=-1)
    idx = np.arange(n + 1)
    valid = idx[None, :] <= n_ok[:, None]
    pk_valid = np.where(valid, pk, np.nan)
    dec = (np.diff(pk_valid, axis=-1) <= 0.0) & valid[:, 1:]
    has_dec = dec.any(-1)
    j = np.where(has_dec, np.argmax(dec, -1), 0)
    # fold refinement: golden-section maximisation of p on [xk[j-1], xk[j+1]]
    lo = np.take_along_axis(xk, np.clip(j - 1, 0, n)[:, None], -1)[:, 0]
    hi = np.take_along_axis(xk, np.clip(j + 1, 0, n)[:, None], -1)[:, 0]
    a_, b_ = np.minimum(lo, hi), np.maximum(lo, hi)
    rows = np.flatnonzero(has_dec & (j > 0))
    x_fold = np.take_along_axis(xk, j[:, None], -1)[:, 0].copy()
    pj = np.take_along_axis(pk, j[:, None], -1)[:, 0]
    p_fold = pj.copy()
    use_ref = np.zeros(ncase, dtype=bool)
    if rows.size:

        def p_of(x):
            Ax, Bx = ev.coef(x, rows)
            with np.errstate(divide="ignore", invalid="ignore"):
                return Bx / Ax

        a, b = a_[rows], b_[rows]
        g = (math.sqrt(5.0) - 1.0) / 2.0
        x1, x2 = b - g * (b - a), a + g * (b - a)
        f1, f2 = p_of(x1), p_of(x2)
        for _ in range(48):  # the bracket shrinks by 0.618^48 ~ 1e-10 of a sample interval
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
        x_fold[rows] = np.where(ref, xm, x_fold[rows])
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
    x_after = np.take_along_axis(xk, nxt[:, None], -1)[:, 0]
    x_end = np.where(kind == BRANCH_END["fold"], np.where(unstable, 0.0, x_fold),
                     np.where(kind == BRANCH_END["unbounded"], x_after, x_lim))
    x_end = np.where(kind == BRANCH_END["neutral"], 0.0, x_end)
    every = np.arange(ncase)
    kt = ev.to_k(xk, allrows)
    return BranchTable(sgn=sgn, k_lim=k_lim, kind=kind, p_end=p_end, k_end=ev.to_k(x_end, every), last=last, kt=kt,
                       pt=pt, k_fold=ev.to_k(x_fold, every), use_ref=use_ref, xt=xk, x_end=x_end, x_fold=x_fold,
                       path=ev)


def _solve_free(law: MomentLaw, tab: BranchTable, pa: np.ndarray, xtol: float) -> tuple[np.ndarray, np.ndarray]:
    """Roots ``(k', u = k'R)`` of ``M = 0`` at active pressures ``pa`` (cases, pressures) (kPa); NaN above the end."""
    k = np.zeros(pa.shape)
    u = np.zeros(pa.shape)
    above = pa > tab.p_end[:, None]
    # below 1e-9 kPa of active pressure the root is straight to rounding (B(0) = 0 is itself only
    # zero to rounding there, which would spoil the first bracket)
    solve = (pa > TINY_ACTIVE_KPA) & ~above & (tab.sgn[:, None] != 0)
    k[above] = np.nan
    u[above] = np.nan
    if not np.any(solve):
        return k, u
    case, col = np.nonzero(solve)
    q = pa[case, col]
    # bracket: first table index with p >= q (the table is increasing up to its end, then inf)
    if tab.pt.shape[0] == 1:
        jall = np.searchsorted(tab.pt[0], pa[0], side="left")[None, :]
    else:
        jall = (tab.pt[:, None, :] < pa[:, :, None]).sum(-1)  # (cases, pressures): no per-point copies
    j = np.clip(jall[case, col], 1, tab.xt.shape[-1] - 1)
    a = tab.xt[case, j - 1]
    b = tab.xt[case, j]
    last = tab.last[case]
    beyond = j > last
    fold_end = (tab.kind[case] == BRANCH_END["fold"]) & tab.use_ref[case] & beyond
    unb = (tab.kind[case] == BRANCH_END["unbounded"]) & beyond
    b = np.where(fold_end, tab.x_fold[case], np.where(unb, tab.x_end[case], b))
    a = np.where(fold_end | unb, tab.xt[case, last], a)
    sgn = tab.sgn[case]
    ev = tab.path

    def F(x, idx):
        A, B = ev.coef(x, case[idx])
        return sgn[idx] * (q[idx] * A - B)

    tol = xtol * np.abs(tab.x_end[case]) + 1e-300
    x = illinois(F, a, b, tol)
    k[case, col] = ev.to_k(x, case)
    u[case, col] = x
    return k, u


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

    Examples
    --------
    >>> import bendpam
    >>> br = bendpam.free_branch(bendpam.physics.presets.bc_pam())
    >>> br.kind, br.direction, round(br.k_end_per_mm, 6), round(br.max_pressure_kpa, 1)
    ('fold', -1, -0.010106, 134.2)
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

    Examples
    --------
    >>> import bendpam
    >>> fb = bendpam.free_curvature(bendpam.physics.presets.be_pam(), [50.0, 150.0])
    >>> fb.status.tolist(), fb.curvature_per_mm.round(5).tolist(), fb.angle_deg.round(2).tolist()
    (['deadband', 'ok'], [0.0, 0.00816], [0.0, 67.78])
    >>> bendpam.free_curvature(bendpam.physics.presets.bc_pam(), 150.0).status.item()   # above the BC-PAM's fold
    'no-equilibrium'
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
_TABLE_P_SCALE_KPA = 500.0  # the error bound covers active pressures up to 500 kPa


class MomentTable:
    """Cubic-spline tables of ``A(k')`` and ``G(k') = B(k') / k'`` of one :class:`MomentLaw`.

    The knots are Chebyshev-Lobatto points on ``[k_min, 0]`` and ``[0, k_max]`` (so ``k' = 0`` is
    a knot and the knots cluster toward the lock-up limits, where the functions steepen); one C2
    cubic spline runs through all of them.  ``B`` is tabulated as ``G = B/k'`` (``B(0) = 0``) so
    the elastic term keeps its relative accuracy near the straight state.  The exact values come
    from the law itself (its quadrature order).  The interpolation error is measured at build time against
    the exact path at every interval's midpoint (times a margin of 1.5), relative to ``|P_a A| + |B|`` with
    ``P_a = 500 kPa``; while it exceeds ``tol`` the knots are doubled (:attr:`max_rel_error`).
    With the default 513 knots a side and ``tol = 1e-6`` a table takes about 3 ms to build and its
    error is 1-6e-7 (checked against a 128-node reference in ``tests/test_fast.py``).

    Evaluation is a gather of 4 x 2 cubic coefficients per point (the interval index comes from
    ``arccos`` of the Chebyshev map, no search) and Horner steps; complex curvatures are accepted
    (the interval comes from the real part), for complex-step derivatives.

    Examples
    --------
    >>> import bendpam
    >>> law = bendpam.MomentLaw.of(bendpam.physics.presets.be_pam(), "energy")
    >>> table = law.tabulated()                          # built once per law, then cached
    >>> table.max_rel_error < 1e-6
    True
    >>> round(float(table.moment(200.0, 0.01)), 3), round(float(law.moment(200.0, 0.01)), 3)   # N*mm
    (63.183, 63.183)
    """

    def __init__(self, law: MomentLaw, *, knots: int = 513, tol: float = 1e-6, max_knots: int = 32769):
        if not isinstance(law, MomentLaw) or law.is_cases:
            raise TypeError("MomentTable tabulates the MomentLaw of one actuator")
        if not (isinstance(tol, float | int) and tol > 0):
            raise InputError(f"tol = {tol!r} must be a positive number")
        self.law = law
        self._exact_law = law
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
        # the same coefficients as eight contiguous arrays, for the chunked real-valued kernel
        self._c8 = tuple(np.ascontiguousarray(spl.c[i, :, j]) for j in range(2) for i in range(4))
        km = 0.5 * (kj[1:] + kj[:-1])
        Ae, Be = self._exact(km)
        Af, Bf = self.coefficients(km)
        P = _TABLE_P_SCALE_KPA
        scale = P * np.abs(Ae) + np.abs(Be) + 1e-300
        # the midpoint is close to, not exactly at, each interval's largest error: a 1.5 margin
        self.max_rel_error = 1.5 * float(np.max((P * np.abs(Af - Ae) + np.abs(Bf - Be)) / scale))

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
        """``M(P, k')`` in N*mm, broadcasting; the same validation as :meth:`MomentLaw.moment`.

        Evaluated in blocks of 8192 points that stay in cache: one ``arccos`` gives the interval
        on either side of 0, then eight gathers and two Horner steps, in place.
        """
        p = _check_pressure(pressure_kpa)
        k = self.law.check_curvature(curvature_per_mm)
        shape = np.broadcast_shapes(p.shape, k.shape)
        pf = np.ascontiguousarray(np.broadcast_to(p, shape), dtype=float).reshape(-1)
        kf = np.ascontiguousarray(np.broadcast_to(k, shape), dtype=float).reshape(-1)
        out = np.empty(kf.size)
        self._moment_kernel(pf, kf, out)
        return out.reshape(shape)

    def _moment_kernel(self, P, k, out, chunk: int = 8192) -> None:
        """``out = max(P - P_start, 0) A(k) - k G(k)`` for 1-D float arrays, in cache-sized blocks."""
        n1 = self._n - 1
        scale = n1 / np.pi
        inv_lo, inv_hi = 1.0 / self._lo, 1.0 / self._hi
        kj = self._kj
        a3, a2, a1, a0, g3, g2, g1, g0 = self._c8
        last = kj.size - 2
        for s0 in range(0, k.size, chunk):
            kk = k[s0:s0 + chunk]
            r = np.where(kk < 0.0, kk * inv_lo, kk * inv_hi)  # fraction of the way to the lock-up limit
            np.multiply(r, -2.0, out=r)
            r += 1.0
            np.clip(r, -1.0, 1.0, out=r)
            th = np.arccos(r)
            th *= scale
            np.copysign(th, kk, out=th)  # k < 0: n1 - th (left piece), k > 0: n1 + th
            th += n1
            j = th.astype(np.intp)
            np.clip(j, 0, last, out=j)
            dx = kk - np.take(kj, j)
            A = np.take(a3, j)
            A *= dx
            A += np.take(a2, j)
            A *= dx
            A += np.take(a1, j)
            A *= dx
            A += np.take(a0, j)
            G = np.take(g3, j)
            G *= dx
            G += np.take(g2, j)
            G *= dx
            G += np.take(g1, j)
            G *= dx
            G += np.take(g0, j)
            pa = P[s0:s0 + chunk] - self.P_start_kpa
            np.maximum(pa, 0.0, out=pa)
            A *= pa
            G *= kk
            np.subtract(A, G, out=out[s0:s0 + chunk])

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

            def f_and_slope(x):  # -M: the moment falls with k' along the branch (either direction)
                A, B, dA, dB = self.derivatives(x)
                return -(q * A - B), -(q * dA - dB)

            k[want] = bracketed_newton(f_and_slope, x, lo, hi, maxiter=newton_steps)
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

    Examples
    --------
    >>> import bendpam
    >>> sb = bendpam.MomentLaw.of(bendpam.physics.presets.be_pam(), "energy").stable_branch(150.0)
    >>> round(sb.k_lo, 5), round(sb.k_hi, 5), sb.end_lo, sb.end_hi
    (-0.04709, 0.03371, 'lock-up', 'fold')
    >>> round(sb.free_curvature, 5)                     # 1/mm
    0.00816
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

        def f_and_slope(k):  # m - M: M falls with k' on the branch
            f, d = self.moment(k)
            return -(f - m), -d

        # Newton polish on the spline law
        k = bracketed_newton(f_and_slope, k, np.full(k.shape, self.k_lo), np.full(k.shape, self.k_hi), maxiter=4)
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
    _, _, dA, dB = table.derivatives(kg)
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
