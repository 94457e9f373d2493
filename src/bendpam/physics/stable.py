"""The stable branch of the moment law at one pressure: where a loaded finger can rest.

Along the branch connected to the straight state ``M(P, k')`` falls with ``k'``; beyond a fold
(``dM/dk' > 0``) the actuator snaps through.  :func:`stable_branch` finds the branch on the
spline table of the law (:class:`~bendpam.physics.law.MomentTable`), and :class:`StableBranch`
evaluates and inverts the law on it.  The entry point is
:meth:`MomentLaw.stable_branch <bendpam.physics.law.MomentLaw.stable_branch>`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from bendpam.errors import InputTypeError, NoEquilibrium
from bendpam.physics.roots import bracketed_newton
from bendpam.validate import number

if TYPE_CHECKING:
    from bendpam.physics.law import MomentTable

__all__ = ["StableBranch", "stable_branch"]


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


def stable_branch(table: MomentTable, P: float, friction: float = 0.0) -> StableBranch:
    """The :class:`StableBranch` of the tabulated law ``table`` at pressure ``P`` (kPa), shifted by ``friction`` (N*mm).

    Its ends are the folds next to ``k' = 0`` (where ``dM/dk'`` turns positive, refined by
    bisection on the spline) or the table's lock-up limits.  Raises
    :class:`~bendpam.errors.NoEquilibrium` when the straight state itself is unstable.

    Examples
    --------
    >>> import bendpam
    >>> table = bendpam.MomentLaw.of(bendpam.physics.presets.be_pam()).tabulated(1e-8)
    >>> sb = stable_branch(table, 150.0)
    >>> sb.end_lo, sb.end_hi, round(sb.free_curvature, 5)
    ('lock-up', 'fold', 0.00816)
    """
    if not all(hasattr(table, a) for a in ("law", "knot_curvatures", "derivatives")):  # a MomentTable (law.py
        raise InputTypeError(f"table = {table!r:.60} must be a MomentTable (law.tabulated()), "  # imports this one)
                             f"got {type(table).__name__}")
    P = float(table.law.check_pressure(number("P", P, unit="kPa")))
    friction = number("friction", friction, unit="N*mm")
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

