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

The work behind the free and stable branches lives in :mod:`bendpam.physics.branch` (sampling,
folds and roots of the free-bending branch, over blocks of cases), :mod:`bendpam.physics.sections`
(the law along ``u = k'R``, exact or on shared section tables) and :mod:`bendpam.physics.stable`;
this module re-exports the classes they return.

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
import warnings
from functools import cached_property, lru_cache
from typing import Any

import numpy as np

from bendpam.errors import InputError, PlausibilityWarning
from bendpam.physics.actuator import Actuator, ModelParams
from bendpam.physics.braid import (
    DEFAULT_ORDER,
    LOCK_FRACTION,
    MIN_FAR_STRETCH,
    CurvatureLimits,
    braid_range,
    curvature_limits,
)
from bendpam.physics.branch import (
    BRANCH_END,
    BRANCH_SAMPLES,
    BranchTable,
    FreeBending,
    FreeBranch,
    assemble_free,
    branch_table,
    describe_branch,
    solve_free,
)
from bendpam.physics.kernel import SplineKernel
from bendpam.physics.models import energy, force_balance, resolve_model
from bendpam.physics.roots import bracketed_newton
from bendpam.physics.sections import MPA_PER_KPA
from bendpam.physics.stable import StableBranch, stable_branch
from bendpam.validate import MPA_SUSPECT_KPA, boolean, float_array, instance, integer, number, quadrature_order
from bendpam.validate import pressure_kpa as _check_pressure

#: ``BRANCH_END``, ``BranchTable``, ``FreeBending``, ``FreeBranch`` (:mod:`bendpam.physics.branch`) and
#: ``StableBranch`` (:mod:`bendpam.physics.stable`) are re-exported: the law's methods return them.
__all__ = [
    "BRANCH_END",
    "BranchTable",
    "FreeBending",
    "FreeBranch",
    "MomentLaw",
    "MomentTable",
    "StableBranch",
]

_CHUNK = 1 << 13  # curvatures per block: keeps the (points x nodes) temporaries in cache
#: A pneumatic moment above this many times the McKibben bound ``pi R0_start^3 (1 + 2 cot^2 alpha0) P_a`` is flagged
#: (:class:`~bendpam.errors.PlausibilityWarning`, docs/plausibility.md).
MCKIBBEN_FACTOR = 10.0
#: A free-bending angle beyond this (deg, a full turn) is flagged: the actuator would pass through itself.
FULL_TURN_DEG = 360.0
#: The numerics' entries (:meth:`MomentLaw.coefficients`, :meth:`MomentLaw.basis`) accept curvatures this fraction
#: of the admissible span beyond the lock-up limits: the limits of another quadrature order differ by rounding.
_LIMIT_SLACK = 1e-9
_ACTUATOR = "a bendpam.Actuator (e.g. bendpam.physics.presets.get('be-pam'))"
#: Interpolation tolerance of the table behind :meth:`MomentLaw.stable_branch` (finger statics).
STABLE_BRANCH_TOL = 1e-8


class MomentLaw:
    """The moment law of one actuator (or of a block of cases) under one model.

    Parameters
    ----------
    actuator : Actuator or ModelParams
        One actuator, or a block of actuator cases (a :class:`~bendpam.ModelParams` whose fields
        are arrays of one shape; sweeps and design searches build these).
    model : {"energy", "force_balance"} or None
        ``"force-balance"`` is accepted too.  None (default): the actuator's own
        :attr:`~bendpam.Actuator.model` (energy when unknown, and for a block of cases); another model
        than the actuator's warns (:class:`~bendpam.errors.ModelMismatchWarning`).
    eq19_factor : bool
        Energy model only: keep eq 19's ``(1 + k'R)`` factor (default, as printed; see
        docs/paper-reading.md item 7).  Ignored by the force-balance model, which has no such factor.
    order : int
        0 (default): the section integrals in closed form (elliptic integrals); N in [4, 1024]: N
        Gauss-Legendre nodes on [0, pi] instead.

    Notes
    -----
    Build one with :meth:`of` to share it (and its cached branch and table) between calls.

    Every method validates its arguments: a pressure above the actuator's ``max_pressure_kpa``
    (the burst limit, 2 MPa by default), a curvature beyond the lock-up limits (:attr:`limits`),
    NaN, inf, ``None`` or a string raise one :class:`~bendpam.errors.InputError` line.  A result
    beyond a plausibility bound warns (:class:`~bendpam.errors.PlausibilityWarning`,
    docs/plausibility.md).

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> law = bendpam.MomentLaw.of(bendpam.physics.presets.bc_pam(), "energy")
    >>> law.moment([40.0, 80.0], 0.0).round(2).tolist()
    [-42.11, -252.65]
    >>> round(law.free_branch().max_pressure_kpa, 1)
    134.2
    """

    def __init__(self, actuator: Actuator | ModelParams, model: str | None = None, *, eq19_factor: bool = True,
                 order: int = DEFAULT_ORDER):
        instance("actuator", actuator, (Actuator, ModelParams), _ACTUATOR + " or a ModelParams block of cases")
        if isinstance(actuator, Actuator):
            self.actuator: Actuator | None = actuator
            self.params = actuator.params
        else:
            self.actuator = None
            self.params = _checked_cases(actuator)
        #: The burst limit (kPa): pressures above it are refused (the smallest of a block of cases).
        self.max_pressure_kpa = float(np.min(self.params.max_pressure_kpa))
        self.model = resolve_model(actuator, model)
        self.eq19_factor = boolean("eq19_factor", eq19_factor)
        self.order = quadrature_order(order)
        self.is_cases = self.params.shape != ()
        self._mod = energy if self.model == "energy" else force_balance
        self._opts: dict[str, Any] = {"order": self.order}
        if self.model == "energy":
            self._opts["eq19_factor"] = self.eq19_factor

    @classmethod
    def of(cls, actuator: Actuator, model: str | None = None, *, eq19_factor: bool = True,
           order: int = DEFAULT_ORDER) -> MomentLaw:
        """The shared (cached) law of ``actuator``: its branch and table are built once."""
        instance("actuator", actuator, Actuator, _ACTUATOR)
        return _cached_law(actuator, resolve_model(actuator, model), boolean("eq19_factor", eq19_factor),
                           quadrature_order(order))

    def __repr__(self) -> str:
        what = f"{self.params.shape} cases" if self.is_cases else (self.actuator.name or self.actuator.kind
                                                                    if self.actuator else "actuator")
        return f"MomentLaw({what}, model={self.model!r}, eq19_factor={self.eq19_factor}, order={self.order})"

    def _repr_html_(self) -> str:
        """A short summary for a notebook: the actuator, the model, the quadrature (never the tables).

        >>> import bendpam
        >>> "energy" in MomentLaw.of(bendpam.physics.presets.be_pam())._repr_html_()
        True
        """
        from bendpam.infra.display import summary_html

        what = f"{self.params.shape} cases" if self.is_cases else (self.actuator.name or self.actuator.kind
                                                                    if self.actuator else "actuator")
        return summary_html(f"MomentLaw of {what}", [("model", self.model), ("eq19_factor", self.eq19_factor),
                                                      ("quadrature order", self.order)])

    # ---- the numerics layer -------------------------------------------------------------------
    @property
    def P_start_kpa(self):
        """Threshold pressure (kPa), float or per-case array (exactly the actuator's ``P_start_kpa``)."""
        return self.params.P_start_kpa

    @cached_property
    def limits(self) -> CurvatureLimits:
        """Admissible curvature range (braid lock-up, lumen closure), see :func:`bendpam.curvature_limits`."""
        return curvature_limits(self.params, self.order)

    def check_pressure(self, pressure_kpa, name: str = "pressure_kpa") -> np.ndarray:
        """Pressures (kPa) checked like every entry: finite, >= 0 and at most the burst limit ``max_pressure_kpa``."""
        return _check_pressure(pressure_kpa, name, limit_kpa=self.max_pressure_kpa)

    @cached_property
    def _braid_range(self) -> CurvatureLimits:
        return braid_range(self.params, self.order)

    @cached_property
    def _inside(self) -> tuple[Any, Any]:
        """Curvatures surely inside :attr:`_braid_range`, without solving eq 5: ``q = k' R0 = s u Ibar(u)`` with
        ``Ibar >= 1`` everywhere and ``Ibar >= 1/s`` for ``u > 0``, so ``|q| >= s |u|`` and ``q >= u`` there."""
        p = self.params
        u_hi = LOCK_FRACTION * (1.0 / np.cos(p.alpha0) - 1.0) / 2.0
        return -np.sin(p.alpha0) * 0.5 * (1.0 - MIN_FAR_STRETCH) / p.R0_start, u_hi / p.R0_start

    def _curvature(self, curvature_per_mm, params: ModelParams | None) -> np.ndarray:
        """Curvatures (1/mm) checked at the numerics' entries: finite and inside the braid's range (eq 1-5)."""
        k = float_array("curvature_per_mm", curvature_per_mm, "1/mm")
        if params is None:
            lo, hi = self._inside
            with np.errstate(invalid="ignore"):
                if np.all((k >= lo) & (k <= hi)):  # the fast path (False for NaN)
                    return k
        lim = self._braid_range if params is None else braid_range(instance("params", params, ModelParams,
                                                                            "a ModelParams"), self.order)
        lim.check(k, slack=_LIMIT_SLACK)
        return k

    def coefficients(self, curvature_per_mm, params: ModelParams | None = None):
        """``(A, B)`` with ``M = P_a A - B``: A in N*mm/kPa, B in N*mm.

        For a block of cases ``curvature_per_mm`` broadcasts against the case shape (or against
        ``params``, a subset of the cases, when given).  Large inputs are evaluated in blocks.
        A curvature that is not finite or lies beyond the braid's range, where eq 5 has no solution
        (:func:`bendpam.physics.braid.braid_range`, which contains :attr:`limits`), is refused.
        """
        k = self._curvature(curvature_per_mm, params)
        p = self.params if params is None else params
        if k.size <= _CHUNK or np.ndim(p.alpha0) or k.ndim == 0:
            A, B = self._mod.coefficients(p, k, **self._opts)
            return A * MPA_PER_KPA, B
        flat = k.ravel()
        A = np.empty(flat.size)
        B = np.empty(flat.size)
        for s in range(0, flat.size, _CHUNK):
            a, b = self._mod.coefficients(p, flat[s:s + _CHUNK], **self._opts)
            A[s:s + _CHUNK], B[s:s + _CHUNK] = a, b
        return (A * MPA_PER_KPA).reshape(k.shape), B.reshape(k.shape)

    def basis(self, curvature_per_mm, params: ModelParams | None = None):
        """Linear decomposition ``M = P_a A - E_f I_f k' - C10 b10 - C01 b01`` (P_a, C10, C01 in kPa).

        Returns ``(A, b10, b01)`` in N*mm/kPa; they depend only on the kinematics (alpha0,
        R0_start, t0_start), so identification solves C10, C01, E_f and P_start linearly.
        Curvatures are checked as in :meth:`coefficients`.
        """
        k = self._curvature(curvature_per_mm, params)
        A, b10, b01 = self._mod.basis(self.params if params is None else params, k, **self._opts)
        return A * MPA_PER_KPA, b10 * MPA_PER_KPA, b01 * MPA_PER_KPA

    # ---- validated evaluation -----------------------------------------------------------------
    def check_curvature(self, curvature_per_mm) -> np.ndarray:
        """``curvature_per_mm`` as a float array inside the lock-up limits, else a one-line InputError."""
        k = float_array("curvature_per_mm", curvature_per_mm, "1/mm")
        self.limits.check(k)
        return k

    def active_pressure_kpa(self, pressure_kpa) -> np.ndarray:
        """Active pressure ``max(P - P_start, 0)`` in kPa (eq 50)."""
        return np.maximum(self.check_pressure(pressure_kpa) - self.P_start_kpa, 0.0)

    def moment(self, pressure_kpa, curvature_per_mm) -> np.ndarray:
        """``M(P, k')`` in N*mm (eq 21 or eq 49 with eq 50-52), broadcasting pressure against curvature.

        The kinematics are computed once per value of the (un-broadcast) curvature array, so
        ``moment(P[:, None], k[None, :])`` costs little more than the kinematics of ``k``.
        """
        p = self.active_pressure_kpa(pressure_kpa)
        k = self.check_curvature(curvature_per_mm)
        A, B = self.coefficients(k)
        _flag_moment(self.params, p, p * A, "pneumatic moment")
        return p * A - B

    def blocked_moment(self, pressure_kpa) -> np.ndarray:
        """``M(P, 0)`` in N*mm: ``pi R0_start^3 (1 - 2 cot^2 alpha0) P_a`` for both models (negative for a BC-PAM)."""
        p = self.active_pressure_kpa(pressure_kpa)
        A0, _ = self.coefficients(np.zeros(()))
        _flag_moment(self.params, p, p * A0, "blocked moment")
        return p * A0

    def terms(self, pressure_kpa, curvature_per_mm) -> dict[str, np.ndarray]:
        """The named parts of the moment in N*mm.

        Energy model: ``M_load, M_air, M_bl, M_f`` (eq 13, 19, 16, 21).  Force-balance model:
        ``M_load, M_p, M_frame, M_bl, M_br`` (eq 23-28, 49).
        """
        p = self.active_pressure_kpa(pressure_kpa)
        k = self.check_curvature(curvature_per_mm)
        return self._mod.terms(self.params, p * MPA_PER_KPA, k, **self._opts)

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
        samples = integer("samples", samples, 8, 1_000_000)
        if samples == BRANCH_SAMPLES:
            return self._branches
        return branch_table(self, samples)

    @cached_property
    def _branches(self) -> BranchTable:
        return branch_table(self, BRANCH_SAMPLES)

    def free_branch(self) -> FreeBranch:
        """The free-bending branch of one actuator: its end (fold or lock-up) and the sampled curve."""
        if self.is_cases:
            raise InputError("free_branch() describes one actuator; use branches() for a block of cases")
        return describe_branch(self, self._branches)

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
        P = self.check_pressure(pressure_kpa)
        number("xtol", xtol, 0.0, 0.1, lo_open=True)
        tab = self._branches if table is None else instance("table", table, BranchTable, "a BranchTable")
        if self.is_cases:
            if P.ndim != 1:
                raise InputError("pressure_kpa must be 1-D for a block of cases")
            pa = np.maximum(P[None, :] - np.asarray(self.P_start_kpa).reshape(-1, 1), 0.0)
        else:
            pa = np.maximum(P - self.P_start_kpa, 0.0).reshape(1, -1)
        k, u = solve_free(self, tab, pa, xtol)
        shape = self.params.shape + P.shape if self.is_cases else P.shape
        return k.reshape(shape), u.reshape(shape)

    def free_curvature(self, pressure_kpa, *, xtol: float = 1e-13) -> FreeBending:
        """Free-bending equilibria ``M(P, k') = 0`` on the branch connected to the straight state.

        Above the fold (or lock-up) pressure there is no equilibrium on the branch: the curvature
        is NaN, the status ``"no-equilibrium"`` and the reason says why.  A root on a
        disconnected branch beyond a fold is never returned.  The root is bracketed and started from
        the sampled branch and polished by Newton's method on it (:func:`bendpam.physics.branch.solve_free`)
        to ``xtol`` relative to the branch's range in ``u = k'R``.
        """
        if self.is_cases:
            raise InputError("free_curvature() describes one actuator; use free_curvature_array() for cases")
        P = self.check_pressure(pressure_kpa)
        k = self.free_curvature_array(P, xtol=xtol)
        return _flag_angle(assemble_free(self, P, k, self.free_branch()))

    # ---- the stable branch for loaded fingers -------------------------------------------------
    def stable_branch(self, pressure_kpa: float, friction_nmm: float = 0.0) -> StableBranch:
        """The stable part of the law at one pressure (see :class:`StableBranch`), from the table.

        ``friction_nmm`` shifts the law by a saturated hysteretic moment, ``M = M_load - friction``.
        Raises :class:`~bendpam.errors.NoEquilibrium` when the straight state itself is unstable.
        """
        if self.is_cases:
            raise InputError("stable_branch() describes one actuator")
        P = self.check_pressure(pressure_kpa)
        if P.size != 1:
            raise InputError(f"pressure_kpa has {P.size} values: stable_branch() takes one pressure")
        cap = _mckibben_nmm(self.params, self.max_pressure_kpa)  # a friction moment beyond every moment it could resist
        friction = number("friction_nmm", friction_nmm, -cap, cap, unit="N*mm")
        return stable_branch(self.tabulated(STABLE_BRANCH_TOL), float(P.ravel()[0]), friction)

    # ---- the fast path ------------------------------------------------------------------------
    def tabulated(self, tol: float = 1e-6) -> MomentTable:
        """The fast path: :class:`MomentTable` of this law with interpolation error below ``tol`` (cached)."""
        if self.is_cases:
            raise InputError("tabulated() builds the table of one actuator")
        key = number("tol", tol, 0.0, 0.1, lo_open=True)
        tabs = self.__dict__.setdefault("_tables", {})
        if key not in tabs:
            tabs[key] = MomentTable(self, tol=key)
        return tabs[key]


def _mckibben_nmm(params: ModelParams, pa_kpa):
    """:data:`MCKIBBEN_FACTOR` times the McKibben bound ``pi R0_start^3 (1 + 2 cot^2 alpha0) P_a`` (N*mm; P_a, kPa)."""
    cot2 = 1.0 / np.tan(params.alpha0) ** 2
    return MCKIBBEN_FACTOR * np.pi * params.R0_start ** 3 * (1.0 + 2.0 * cot2) * np.asarray(pa_kpa) * 1e-3


def _flag_moment(params: ModelParams, pa_kpa, moment_nmm, what: str) -> None:
    """Warn when a pneumatic moment exceeds :data:`MCKIBBEN_FACTOR` times the McKibben bound (docs/plausibility.md).

    The bound ``pi R0_start^3 (1 + 2 cot^2 alpha0) P_a`` is the largest moment the pressure can give
    through a McKibben sleeve of the actuator's size: the blocked moment is
    ``pi R0_start^3 (1 - 2 cot^2 alpha0) P_a``, and bending only shrinks the radius.
    """
    bound = _mckibben_nmm(params, pa_kpa)
    with np.errstate(invalid="ignore"):
        over = np.abs(moment_nmm) > bound
    if np.any(over):
        i = int(np.flatnonzero(np.broadcast_to(over, np.shape(over)))[0])
        m = float(np.ravel(moment_nmm)[i])
        b = float(np.ravel(np.broadcast_to(bound, np.shape(over)))[i])
        warnings.warn(f"{what} {m:.4g} N*mm is beyond {MCKIBBEN_FACTOR:g} times the McKibben bound "
                      f"pi R0_start^3 (1 + 2 cot^2 alpha0) P_a ({b / MCKIBBEN_FACTOR:.4g} N*mm): "
                      "the model is outside what it describes", PlausibilityWarning, stacklevel=4)


def _flag_angle(fb: FreeBending) -> FreeBending:
    """Warn when a free-bending angle is beyond a full turn (:data:`FULL_TURN_DEG`): the actuator would cross itself."""
    with np.errstate(invalid="ignore"):
        over = np.abs(np.asarray(fb.angle_deg)) > FULL_TURN_DEG
    if np.any(over):
        i = int(np.flatnonzero(np.ravel(over))[0])
        warnings.warn(f"free-bending angle {float(np.ravel(fb.angle_deg)[i]):.4g} deg at "
                      f"{float(np.ravel(fb.pressure_kpa)[i]):g} kPa is beyond a full turn ({FULL_TURN_DEG:g} deg): "
                      "the actuator would pass through itself, and the planar model ends there",
                      PlausibilityWarning, stacklevel=4)
    return fb


def _checked_cases(params: ModelParams) -> ModelParams:
    """A hand-made block of cases: every field finite numbers of shapes that broadcast (``R0`` may be None)."""
    for name, value in params.__dict__.items():
        if value is None and name == "R0":
            continue
        v = float_array(f"ModelParams.{name}", value, "model units")
        if v.size and not np.all(np.isfinite(v)):
            raise InputError(f"ModelParams.{name} has a non-finite value")
    try:
        _ = params.shape
    except ValueError:
        raise InputError("the fields of the ModelParams do not broadcast to one shape of cases") from None
    return params


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

    Evaluation is a gather of 4 x 2 cubic coefficients per point and Horner steps
    (:class:`~bendpam.physics.kernel.SplineKernel`: NumPy, or a compiled numba loop with bit-identical
    results; the table's ``kernel``); the interval is the knot interval containing the point, found
    from ``arccos`` of the Chebyshev map and one comparison, no search.  Complex curvatures are accepted by
    :meth:`coefficients` and :meth:`derivatives` (the interval comes from the real part), for
    complex-step derivatives.

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
        instance("law", law, MomentLaw, "the MomentLaw of one actuator")
        if law.is_cases:
            raise InputError("MomentTable tabulates the MomentLaw of one actuator, not a block of cases")
        if not (isinstance(tol, float | int) and not isinstance(tol, bool) and 0 < tol < 0.1):
            raise InputError(f"tol = {tol!r} must be a number in (0, 0.1)")
        knots = integer("knots", knots, 5, 1 << 20)
        max_knots = integer("max_knots", max_knots, 5, 1 << 20)
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
        # per interval (a3, a2, a1, a0, g3, g2, g1, g0): the moment kernels (bendpam.physics.kernel)
        self.kernel = SplineKernel(kj, self._coef.transpose(0, 2, 1).reshape(-1, 8), self.P_start_kpa)
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
        """The knot interval of each curvature (of its real part): the largest knot ``<= k'``."""
        return self.kernel.interval(np.real(k))

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
        """Interpolated ``(A, B)`` (N*mm/kPa, N*mm) at ``curvature_per_mm``, checked like :meth:`moment`."""
        k = self._curvature(curvature_per_mm)
        v, _ = self._eval(k, False)
        return v[..., 0], k * v[..., 1]

    def _curvature(self, curvature_per_mm) -> np.ndarray:
        """Real or complex curvatures whose real part is finite and inside the lock-up limits.

        One min and one max decide (NaN fails both); the full check runs only to name a bad value.
        """
        if isinstance(curvature_per_mm, complex | np.complexfloating) or np.iscomplexobj(curvature_per_mm):
            k = np.asarray(curvature_per_mm)
            self._check_real(np.real(k))
            if not np.all(np.isfinite(np.imag(k))):
                raise InputError("curvature_per_mm has a non-finite imaginary part")
            return k
        k = float_array("curvature_per_mm", curvature_per_mm, "1/mm")
        self._check_real(k)
        return k

    def _check_real(self, k: np.ndarray) -> None:
        lim = self.limits
        if k.size == 0 or not (float(lim.k_min) <= float(k.min()) and float(k.max()) <= float(lim.k_max)):
            lim.check(k)

    def derivatives(self, curvature_per_mm):
        """``(A, B, dA/dk', dB/dk')`` from the splines (complex curvatures allowed)."""
        k = self._curvature(curvature_per_mm)
        v, d = self._eval(k, True)
        A, G = v[..., 0], v[..., 1]
        return A, k * G, d[..., 0], G + k * d[..., 1]

    def moment(self, pressure_kpa, curvature_per_mm):
        """``M(P, k')`` in N*mm, broadcasting; the same validation as :meth:`MomentLaw.moment`.

        One pass checks the range and finiteness of each input; the moment comes from
        :class:`~bendpam.physics.kernel.SplineKernel`: NumPy in cache-sized blocks, or the compiled
        numba loop for large calls when numba is installed (bit-identical results;
        :func:`~bendpam.physics.kernel.kernel_choice`, environment variable ``BENDPAM_KERNEL``).
        """
        p = float_array("pressure_kpa", pressure_kpa, "kPa")
        k = float_array("curvature_per_mm", curvature_per_mm, "1/mm")
        try:
            shape = np.broadcast_shapes(p.shape, k.shape)
        except ValueError:
            raise InputError(f"pressure_kpa of shape {p.shape} and curvature_per_mm of shape {k.shape} "
                             "do not broadcast to one shape") from None
        size = math.prod(shape)
        pf = p.reshape(-1) if p.size == 1 or p.shape == shape else np.broadcast_to(p, shape).reshape(-1)
        kf = k.reshape(-1) if k.shape == shape else np.broadcast_to(k, shape).reshape(-1)
        out = np.empty(size)
        law, lim = self.law, self.limits
        ok, pmax = self.kernel.evaluate(pf, kf, out, law.max_pressure_kpa, float(lim.k_min), float(lim.k_max))
        if not ok:  # the full checks name the bad value
            law.check_pressure(p)
            law.check_curvature(k)
            raise InputError("pressure_kpa or curvature_per_mm is not finite or is out of range")
        if 0.0 < pmax < MPA_SUSPECT_KPA:
            law.check_pressure(p)  # warns: MPa passed as kPa?
        return out.reshape(shape)

    __call__ = moment

    def tangent_stiffness(self, pressure_kpa, curvature_per_mm):
        """``dM/dk'`` (N*mm^2) from the spline derivatives, checked like :meth:`moment`."""
        p = float_array("pressure_kpa", pressure_kpa, "kPa")
        top = self.law.max_pressure_kpa
        if p.size == 0 or not (0.0 <= float(p.min()) and MPA_SUSPECT_KPA <= float(p.max()) <= top):
            p = self.law.check_pressure(p)  # names a bad value, or warns (MPa passed as kPa?)
        _, _, dA, dB = self.derivatives(curvature_per_mm)
        return np.maximum(p - self.P_start_kpa, 0.0) * dA - dB

    def free_curvature(self, pressure_kpa, *, newton_steps: int = 6) -> FreeBending:
        """Free-bending curvature from the tables: the same branch as :meth:`MomentLaw.free_curvature`.

        Starts from the sampled branch (monotone ``P_a(k') = B/A``) and polishes with safeguarded
        Newton steps on the interpolated moment.
        """
        law = self.law
        P = law.check_pressure(pressure_kpa)
        newton_steps = integer("newton_steps", newton_steps, 0, 100)
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
        return _flag_angle(assemble_free(law, P, k.reshape(P.shape), br))
