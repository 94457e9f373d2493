"""The moment law along the branch parameter ``u = k'R``: exact section means or shared spline tables.

The free-bending branch (:mod:`bendpam.physics.branch`) is sampled and solved in ``u = k'R``
rather than in the curvature: at a given ``u`` the section means need one pass of the quadrature
(or of the closed forms), where a curvature needs the Newton solve of eq 5 first.
:func:`branch_path` picks how the means are evaluated: exactly, or, for blocks of cases that share
a few braid angles (a sweep over a grid), interpolated from :class:`SectionTables` built once per
angle.

Units: ``A`` in N*mm per kPa (:data:`MPA_PER_KPA` converts the models' per-MPa values), ``B`` in
N*mm, curvature 1/mm.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from bendpam.errors import InputError, InputTypeError
from bendpam.physics.actuator import NEUTRAL_ANGLE_DEG, ModelParams
from bendpam.physics.braid import LOCK_FRACTION, MIN_FAR_STRETCH, curvature_limits, radius_from_u
from bendpam.physics.models import energy, force_balance, get_model
from bendpam.validate import float_array, integer, quadrature_order

if TYPE_CHECKING:
    from bendpam.physics.law import MomentLaw

__all__ = ["MPA_PER_KPA", "TABLE_MIN_CASES_PER_ANGLE", "SectionTables", "branch_path"]

#: MPa per kPa: the models' ``A`` is per MPa, the law's per kPa.
MPA_PER_KPA = 1e-3


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
        self.mod = get_model(law.model)
        self.cs = _flat_params(law)
        self.scalar = not law.is_cases
        lim = curvature_limits(law.params if self.scalar else self.cs, law.order)
        n = self.cs.alpha0.size
        self.k_min = np.broadcast_to(np.asarray(lim.k_min, dtype=float), (n,)).copy()
        self.k_max = np.broadcast_to(np.asarray(lim.k_max, dtype=float), (n,)).copy()
        self.x_min = np.broadcast_to(np.asarray(lim.u_min, dtype=float), (n,)).copy()
        self.x_max = np.broadcast_to(np.asarray(lim.u_max, dtype=float), (n,)).copy()

    def _state(self, u, rows):
        sub = self.law.params if self.scalar else self.cs.rows(rows)
        m = self.mod.section_means(u, sub.alpha0, self.law.order)
        R, dR, k = radius_from_u(u, m["ib"], m["dib"], sub.alpha0, sub.R0_start)
        return sub, m, R, dR, k

    def coef(self, u, rows):
        return self.coef_k(u, rows)[:2]

    def coef_k(self, u, rows):
        """``(A, B, k', dk'/du)`` at ``u``: the coefficients, the curvature and its slope ``1 / (R + k' dR/dk')``."""
        sub, m, R, dR, k = self._state(np.asarray(u, dtype=float), rows)
        return (*_assembled(self.law, sub, k, u, R, dR, m), k, 1.0 / (R + k * dR))

    def to_k(self, u, rows):
        return self._state(np.asarray(u, dtype=float), rows)[4]


def _assembled(law: MomentLaw, sub, k, u, R, dR, m):
    """``(A per kPa, B)`` of the law's model from kinematics and section means."""
    if law.model == "energy":
        A, b10, b01 = energy.assemble(sub, k, u, R, dR, m, eq19_factor=law.eq19_factor)
    else:
        A, b10, b01 = force_balance.assemble(sub, k, u, R, dR, m)
    return A * MPA_PER_KPA, sub.C10 * b10 + sub.C01 * b01 + sub.frame_stiffness * k


class SectionTables:
    """Spline tables of a model's section means over ``u = k'R``, one per distinct braid angle.

    The section integrals of both models depend on ``u`` and the braid angle only
    (``section_means`` of :mod:`bendpam.physics.models.energy` and :mod:`~bendpam.physics.models.force_balance`);
    everything else is per-actuator arithmetic.  Cases that share a braid angle (a sweep over a grid)
    therefore share one table: the means at Chebyshev-Lobatto knots of ``u`` on each side of 0
    (clustered toward the braid limits, where they steepen), interpolated by a C2 cubic spline.
    The knots are doubled until the interpolation error at every interval's midpoint, relative to
    each mean's largest magnitude, is below ``tol`` (:attr:`max_rel_error`).

    ``mod`` is the model module (:func:`bendpam.physics.models.get_model`), ``alpha0`` the distinct
    braid angles (rad).

    Examples
    --------
    >>> import numpy as np
    >>> from bendpam.physics.models import energy
    >>> tables = SectionTables(energy, np.radians([65.0, 70.0]), 0)
    >>> tables.max_rel_error < 1e-7, tables.knots
    (True, 513)
    >>> exact = energy.section_means(0.05, np.radians(70.0), 0)["ib"]
    >>> bool(abs(tables.means(1, 0.05)["ib"] - exact) < 1e-9)
    True
    """

    def __init__(self, mod, alpha0, order: int, *, knots: int = 513, tol: float = 1e-7, max_knots: int = 4097):
        if mod not in (energy, force_balance):
            raise InputError(f"mod = {mod!r} must be a model module (bendpam.physics.models.get_model(name))")
        self.alpha0 = np.atleast_1d(float_array("alpha0", alpha0, "rad"))
        if self.alpha0.size == 0 or not np.all((self.alpha0 > 0.0) & (self.alpha0 < np.pi / 2)):
            raise InputError("alpha0 must be one or more braid angles in (0, pi/2) rad")
        order, knots, max_knots = quadrature_order(order), integer("knots", knots, 5, 1 << 20), \
            integer("max_knots", max_knots, 5, 1 << 20)
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
        self.tables = SectionTables(get_model(law.model), uniq, law.order)
        self.ia = inverse
        self.x_min, self.x_max = self._u_limits()
        self.k_min = self.to_k(self.x_min, np.arange(self.ia.size))  # 0 on the side that is not tabulated
        self.k_max = self.to_k(self.x_max, np.arange(self.ia.size))

    def _state(self, u, rows):
        sub = self.cs.rows(rows)
        m = self.tables.means(self.ia[rows], u)
        R, dR, k = radius_from_u(u, m["ib"], m["dib"], sub.alpha0, sub.R0_start)
        return sub, m, R, dR, k

    def coef(self, u, rows):
        return self.coef_k(u, rows)[:2]

    def coef_k(self, u, rows):
        """``(A, B, k', dk'/du)`` at ``u``, as :meth:`_ExactUPath.coef_k`."""
        sub, m, R, dR, k = self._state(u, rows)
        return (*_assembled(self.law, sub, k, u, R, dR, m), k, 1.0 / (R + k * dR))

    def to_k(self, u, rows):
        ia, u = np.broadcast_arrays(self.ia[rows], np.asarray(u, dtype=float))
        m = self.tables._eval(ia, u, cols=[self.tables.keys.index("ib"), self.tables.keys.index("dib")])  # Ibar alone
        return radius_from_u(u, m[..., 0], m[..., 1], self.cs.alpha0[rows], self.cs.R0_start[rows])[2]

    def _u_limits(self):
        """The braid limit in u on the bending side, cut where the bladder lumen closes (``R = t_bar``)."""
        n = self.ia.size
        rows = np.arange(n)[:, None]
        end = self.tables.u_end[self.ia]
        grid = end[:, None] * np.linspace(0.0, 1.0, 65)

        def lumen(u, rows=rows):
            sub = self.cs.rows(rows)
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


def branch_path(law: MomentLaw) -> _ExactUPath | _TablePath:
    """The law along the branch parameter ``u = k'R``: exact, or on shared tables for blocks of cases.

    Blocks of cases with few distinct braid angles (at least :data:`TABLE_MIN_CASES_PER_ANGLE`
    cases an angle) share :class:`SectionTables`; otherwise the section means are computed
    exactly.  The path's ``coef(u, rows)`` gives ``(A, B)`` (N*mm/kPa, N*mm) of the cases ``rows``
    at ``u`` (``coef_k``: also ``k'`` and ``dk'/du``), ``to_k(u, rows)`` the curvature (1/mm) there;
    ``x_min``, ``x_max`` (``k_min``, ``k_max``) are the admissible range of ``u`` (of the curvature) of every case.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> from bendpam.physics.law import MomentLaw
    >>> path = branch_path(MomentLaw(bendpam.physics.presets.be_pam()))
    >>> A, B = path.coef(np.array([[0.0, 0.05]]), np.arange(1)[:, None])
    >>> A.round(4).tolist(), path.to_k(np.array([0.05]), np.arange(1)).round(6).tolist()
    ([[2.351, 2.1476]], [0.004986])
    """
    if not all(hasattr(law, a) for a in ("params", "check_curvature", "order")):  # a MomentLaw (law.py imports us)
        raise InputTypeError(f"law = {law!r:.60} must be a MomentLaw, got {type(law).__name__}")
    if law.is_cases:
        cs = _flat_params(law)
        uniq, inverse = np.unique(cs.alpha0, return_inverse=True)
        if cs.alpha0.size >= TABLE_MIN_CASES_PER_ANGLE * uniq.size:
            return _TablePath(law, cs, uniq, inverse.reshape(-1))
    return _ExactUPath(law)

