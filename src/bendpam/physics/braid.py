r"""Braid kinematics of a bending PAM (paper eq 1-5, with docs/paper-reading.md items 1-4).

Coordinates: ``Phi = 0`` lies at the frame; the distance of a point of the braid circle from the
frame is ``h = R (1 - cos Phi)`` with ``R`` the *deformed* radius.  With the frame curvature
``k'`` (positive toward the frame) and ``u = k' R``:

* axial stretch of the braid and bladder, eq 3 / 34:  ``lambda1(Phi) = 1 + u (1 - cos Phi)``
* inextensible fibres, eq 2 / 4:  ``cos^2 a0 lambda1^2 + sin^2 a0 lambda2^2 = 1``, so the local
  braid angle is ``cos alpha(Phi) = lambda1 cos a0`` and
  ``lambda2(Phi) = sqrt(1 - c^2 lambda1^2) / sin a0`` (c = cos a0, s = sin a0)
* radius, eq 5 (implicit, because ``u`` contains ``R``)::

      eta = R / R0 = (2 pi / s) / \int_0^{2pi} (1 - c^2 lambda1^2)^{-1/2} dPhi = xi(u)

  We write ``xi(u) = 1 / (s Ibar(u))`` with ``Ibar`` the circle mean of ``(1 - c^2 lambda1^2)^{-1/2}``
  and solve ``q(u) = u / xi(u) = u s Ibar(u) = k' R0`` for ``u``.  ``q`` is strictly increasing on
  the admissible interval, so a bracketed (safeguarded) Newton iteration converges for every point;
  it runs on whole arrays at once.
* ``dR/dk'`` by implicit differentiation:  ``R = R0 xi(u)``, ``u = k' R`` gives
  ``dR/dk' = R0 xi'(u) R / (1 - R0 xi'(u) k')`` with ``xi' = -xi Ibar'/Ibar``.
* axis curvature, eq 1: ``k = k' / (1 + k' R)``; bending angle ``theta = k' L0``; axis length
  ``L = L0 (1 + k' R)``.

Section integrals.  By default (``order = 0``, :data:`CLOSED_FORM`) every circle mean is evaluated in
closed form: with ``lambda1 = a - b cos Phi`` (``a = 1 + u``, ``b = u``) the factor
``1 - c^2 lambda1^2 = (1 - c lambda1)(1 + c lambda1)`` is a product of two terms linear in
``cos Phi``, so ``Ibar`` is a complete elliptic integral of the first kind (Byrd & Friedman 256.00)::

    Ibar(u) = (2/pi) K(m) / sqrt(D),   m = 4 c |u| / D,
    D = (1 - c)(1 + c (1 + 2u))  (u >= 0),   D = (1 + c)(1 - c (1 + 2u))  (u < 0)

and ``dIbar/du`` follows with ``dK/dm = (E - (1 - m) K) / (2 m (1 - m))`` (a series near
``m = 0``).  The means of rational functions of ``lambda1`` the models need are elementary (from
``mean 1/(alpha + beta cos Phi) = (alpha^2 - beta^2)^(-1/2)``).  A positive ``order`` uses
fixed-order Gauss-Legendre nodes on ``[0, pi]`` instead (every integrand is even about
``Phi = pi``; ``order`` nodes there, twice as many on the full circle), whose convergence to the
closed forms is exponential, see ``tests/test_kinematics.py``.  Distributions over the section
(internal stresses) always use nodes: :data:`NODE_ORDER` of them when ``order = 0``.

All lengths are mm and curvatures 1/mm.  ``R0`` and ``t0`` here are the prestrain-corrected
``R0_start`` and ``t0_start`` of the actuator (eq 51-52).

Admissible curvature range ("braid lock-up")
-------------------------------------------
* ``k' > 0``: the far-side fibres straighten, ``cos a0 (1 + 2u) -> 1`` at
  ``u_lock = (1/cos a0 - 1)/2``, where ``R -> 0`` logarithmically.  Before that the bladder lumen
  closes (``R = t_bar``).  The upper limit is the first of: the lumen closing, or ``u`` reaching
  ``LOCK_FRACTION * u_lock`` (99 %), beyond which the circular-section model has no meaning and
  the integrand is nearly singular.
* ``k' < 0``: the far-side axial stretch ``lambda1(pi) = 1 + 2u`` falls to zero at ``u = -1/2``
  (fibres fully circumferential).  The lower limit is ``lambda1(pi) = MIN_FAR_STRETCH`` (1 %), or
  the lumen closing, whichever comes first.

A curvature outside ``[k_min, k_max]`` raises ``ValueError`` naming the limit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from bendpam.errors import InputError
from bendpam.physics.actuator import Actuator, ModelParams
from bendpam.physics.roots import bracketed_newton
from bendpam.validate import float_array, instance, quadrature_order

__all__ = [
    "CLOSED_FORM",
    "DEFAULT_ORDER",
    "LOCK_FRACTION",
    "MIN_FAR_STRETCH",
    "NODE_ORDER",
    "CurvatureLimits",
    "Kinematics",
    "braid_range",
    "case_column",
    "circle_ibar",
    "curvature_limits",
    "gauss_nodes",
    "ibar_closed_form",
    "kernel_args",
    "kinematics",
    "limits",
    "radius_from_u",
    "radius_state",
    "radius_terms",
    "solve_u",
]

#: ``order = 0``: the section integrals in closed form (elliptic integrals, elementary means).
CLOSED_FORM = 0
DEFAULT_ORDER = CLOSED_FORM
#: Gauss-Legendre nodes on [0, pi] for distributions over the section when ``order = 0``.
NODE_ORDER = 32
LOCK_FRACTION = 0.99
MIN_FAR_STRETCH = 0.01
_NEWTON_MAXITER = 60


@lru_cache(maxsize=32)
def gauss_nodes(order: int = DEFAULT_ORDER) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes ``phi`` on [0, pi] and weights normalised to a circle *mean*.

    For an integrand ``f`` even about ``pi``::

        (1 / 2pi) \\int_0^{2pi} f dPhi = sum(wbar * f(phi))

    Returns read-only arrays ``(phi, wbar)`` of length ``order`` (``order = 0``: :data:`NODE_ORDER`).

    Examples
    --------
    >>> import numpy as np
    >>> phi, wbar = gauss_nodes(8)
    >>> phi.size, round(float(wbar.sum()), 12), round(float(wbar @ np.cos(phi) ** 2), 12)   # mean of cos^2 = 1/2
    (8, 1.0, 0.5)
    """
    order = quadrature_order(int(order))
    if order == CLOSED_FORM:
        order = NODE_ORDER
    x, w = np.polynomial.legendre.leggauss(order)
    phi = (x + 1.0) * (np.pi / 2.0)
    wbar = w / 2.0  # (pi/2 * w) / pi
    phi.setflags(write=False)
    wbar.setflags(write=False)
    return phi, wbar


def case_column(x):
    """A scalar as is; an array parameter gets a trailing axis to broadcast against the nodes.

    Per-case parameters (a block of actuator cases) meet per-node arrays of the section's
    quadrature angles on the last axis.

    Examples
    --------
    >>> import numpy as np
    >>> case_column(0.5), case_column(np.array([0.5, 0.6])).shape
    (0.5, (2, 1))
    """
    return x[..., None] if np.ndim(x) else x


def ibar(u, c, omc, wbar):
    """Circle means Ibar(u) and dIbar/du; ``u`` has shape S, ``omc = 1 - cos(phi)`` shape (n,).

    ``c = cos(alpha0)`` is a scalar or an array broadcasting against ``u`` (vectorised sweeps).
    """
    lam1 = 1.0 + u[..., None] * omc
    cl = case_column(c) * lam1
    g = 1.0 - cl * cl
    inv = 1.0 / np.sqrt(g)
    ib = inv @ wbar
    dib = ((case_column(c) * cl * omc) * (inv / g)) @ wbar
    return ib, dib


# series of dK/dm about m = 0: (pi/2) sum n c_n m^(n-1), c_n = ((2n-1)!! / (2n)!!)^2, used for m < 0.05
_DK_SERIES = []
_cn = 1.0
for _n in range(1, 15):
    _cn *= ((2 * _n - 1) / (2 * _n)) ** 2
    _DK_SERIES.append(0.5 * math.pi * _n * _cn)
_DK_SERIES_M = 0.05


def ibar_closed_form(u, c):
    """``Ibar(u)`` and ``dIbar/du`` of eq 5 in closed form (complete elliptic integrals K and E).

    ``u`` and ``c = cos(alpha0)`` broadcast; ``u`` must lie inside the admissible range
    (``c (1 + 2 max(u, 0)) < 1``, ``1 + 2u > 0``).  Agrees with Gauss-Legendre quadrature to
    rounding (about 1e-14, tests/test_kinematics.py).

    Examples
    --------
    >>> import numpy as np
    >>> ib, dib = ibar_closed_form(np.array([0.0, 0.05]), np.cos(np.radians(69.7)))
    >>> ib.round(6).tolist(), dib.round(6).tolist()      # Ibar(0) = 1 / sin(alpha0)
    ([1.066224, 1.073917], [0.145896, 0.162064])
    """
    from scipy.special import ellipe, ellipk

    u, c = float_array("u", u, "1"), float_array("c", c, "1")
    pos = u >= 0.0
    cu = c * u
    D = np.where(pos, (1.0 - c) * (1.0 + c + 2.0 * cu), (1.0 + c) * (1.0 - c - 2.0 * cu))
    dD = np.where(pos, 2.0 * c * (1.0 - c), -2.0 * c * (1.0 + c))
    m = 4.0 * np.abs(cu) / D
    K, E = ellipk(m), ellipe(m)
    rD = 1.0 / np.sqrt(D)
    ib = (2.0 / math.pi) * K * rD
    small = m < _DK_SERIES_M
    mm = np.where(small, 0.5, m)
    dKdm = (E - (1.0 - mm) * K) / (2.0 * mm * (1.0 - mm))
    if np.any(small):  # the series only where it is used (a few points of a branch, near u = 0)
        dKdm = np.array(np.broadcast_to(dKdm, np.shape(m)))
        ms = m[small]
        ser = np.zeros_like(ms)
        for coef in reversed(_DK_SERIES):
            ser = ser * ms + coef
        dKdm[small] = ser
    dm = (4.0 * c * np.where(pos, 1.0, -1.0) - m * dD) / D
    dib = (2.0 / math.pi) * rD * (dKdm * dm - 0.5 * K * dD / D)
    return ib, dib


def circle_ibar(u, c, order: int = DEFAULT_ORDER):
    """``Ibar(u)`` and ``dIbar/du``: closed form for ``order = 0``, else Gauss-Legendre with ``order`` nodes.

    Examples
    --------
    >>> import numpy as np
    >>> c = np.cos(np.radians(69.7))
    >>> exact, quad = circle_ibar(np.array([0.05]), c), circle_ibar(np.array([0.05]), c, order=32)
    >>> bool(abs(exact[0][0] - quad[0][0]) < 1e-12)
    True
    """
    if order == CLOSED_FORM:
        return ibar_closed_form(u, c)
    phi, wbar = gauss_nodes(order)
    return ibar(float_array("u", u, "1"), float_array("c", c, "1"), 1.0 - np.cos(phi), wbar)


def solve_u(q_target, alpha0: Any, order: int = DEFAULT_ORDER, u_bounds: tuple[float, float] | None = None):
    """Solve eq 5 for ``u = k' R`` given ``q = k' R0`` (vectorised safeguarded Newton).

    Parameters
    ----------
    q_target : array_like
        Dimensionless curvature ``k' R0``.
    alpha0 : float
        Initial braid angle, rad.
    order : int
        0 (default): closed-form section integrals; N > 0: N Gauss-Legendre nodes on [0, pi].
    u_bounds : (float, float), optional
        Bracket for ``u``; defaults to ``(-1/2, u_lock)``.  Each target must lie inside
        ``q(u_bounds)``; callers check the curvature limits first.

    Returns
    -------
    u, ibar, dibar : ndarray
        The root, and the circle mean ``Ibar(u)`` and its derivative at the root.

    Examples
    --------
    >>> import numpy as np
    >>> u, ibar, dibar = solve_u(np.array([0.0, 0.05]), np.radians(69.7))
    >>> u.round(5).tolist()                      # u = k'R: R shrinks as the actuator bends
    [0.0, 0.04964]
    """
    q, a0 = float_array("q_target", q_target, "1"), float_array("alpha0", alpha0, "rad")
    alpha0 = a0 if a0.ndim else float(a0)
    c, s = np.cos(alpha0), np.sin(alpha0)
    if np.ndim(alpha0):
        q = np.broadcast_to(q, np.broadcast_shapes(q.shape, np.shape(alpha0)))
    if np.ndim(alpha0) == 0 and u_bounds is None and q.size >= _UNIFORM_MIN_POINTS:
        # one actuator, many points: a start within about 1e-13 of the root from a uniform-in-q Hermite table, then one
        # Newton step; Ibar and its slope at the root follow from the values at the start (the step is
        # below 1e-13 |u|, so the corrections leave errors far below 1e-12).  Points whose step is larger
        # (none expected) take the safeguarded iteration below.
        u0 = _uniform_inverse(float(alpha0), int(order)).start(q)
        ib, dib = circle_ibar(u0, c, order)
        step = (s * u0 * ib - q) / (s * (ib + u0 * dib))
        u = np.where(q == 0.0, 0.0, u0 - step)
        ib = ib - dib * (u0 - u)
        bad = ~(np.abs(step) <= 1e-13 * np.abs(u0) + 1e-16)
        if np.any(bad):
            u, ib, dib = (np.array(x, dtype=float, copy=True) for x in np.broadcast_arrays(u, ib, dib))
            ub, ibb, dibb = _newton(q[bad], float(alpha0), order, u0[bad], (-0.5, (1.0 / c - 1.0) / 2.0))
            u[bad], ib[bad], dib[bad] = ub, ibb, dibb
        return u, ib, dib
    if u_bounds is None:
        u_bounds = (-0.5, (1.0 / c - 1.0) / 2.0)
    if np.ndim(alpha0) == 0:
        # start from a monotone interpolation of the inverse q -> u (tabulated once per alpha0)
        qt, ut, dt = _inverse_table(float(alpha0), int(order))
        u0 = _hermite_start(q, qt, ut, dt)
    else:
        # per-point braid angles (sweeps): interpolate a table of q over (alpha0, normalised u)
        u0 = _universal_start(q, np.broadcast_to(alpha0, q.shape), int(order))
    return _newton(q, alpha0, order, u0, u_bounds)


def _newton(q, alpha0, order: int, u0, u_bounds):
    """Bracketed Newton iteration on ``s u Ibar(u) = q`` from ``u0``; returns ``u, Ibar, dIbar/du``."""
    c, s = np.cos(alpha0), np.sin(alpha0)
    lo = np.where(q >= 0.0, 0.0, u_bounds[0])
    hi = np.where(q >= 0.0, u_bounds[1], 0.0)
    eps = 1e-9 * (hi - lo)
    u = np.where(q == 0.0, 0.0, np.clip(u0, lo + eps, hi - eps))

    def f_and_slope(u):  # q(u) - q is increasing in u
        ib, dib = circle_ibar(u, c, order)
        return s * u * ib - q, s * (ib + u * dib)

    # Newton converges quadratically: a step below 1e-8 |u| leaves an error near 1e-16 |u|
    u = bracketed_newton(f_and_slope, u, lo, hi, maxiter=_NEWTON_MAXITER, rtol=1e-8)
    ib, dib = circle_ibar(u, c, order)
    return u, ib, dib


@dataclass(frozen=True)
class _UniformInverse:
    """Cubic Hermite table of the inverse ``u(q)`` of eq 5 on a uniform grid in ``q`` (one braid angle)."""

    q0: float
    inv_h: float
    u: np.ndarray
    du: np.ndarray  # du/dq times the grid step

    def start(self, q):
        """``u`` at ``q`` (clipped to the table's range): the interval from one multiply, no search."""
        n = self.u.size - 1
        x = np.clip((q - self.q0) * self.inv_h, 0.0, float(n))
        j = np.minimum(x.astype(np.intp), n - 1)
        x = x - j
        u0, u1, d0, d1 = self.u[j], self.u[j + 1], self.du[j], self.du[j + 1]
        y = 1.0 - x
        return y * y * ((1.0 + 2.0 * x) * u0 + x * d0) + x * x * ((3.0 - 2.0 * x) * u1 - y * d1)


#: Intervals of the uniform inverse table: the start is within about 1e-13 of the root (tested).
_UNIFORM_INTERVALS = 8192
#: Calls with fewer points take two evaluations from the small table instead of building the uniform one
#: (about 1.2 ms a braid angle): a fit visits a hundred braid angles with a few thousand points each.
_UNIFORM_MIN_POINTS = 4096


@lru_cache(maxsize=64)
def _uniform_inverse(alpha0: float, order: int) -> _UniformInverse:
    """Build :class:`_UniformInverse` between ``q`` at 99.99 % of the range to each limit."""
    c, s = math.cos(alpha0), math.sin(alpha0)
    ends = np.array([-0.5 * 0.9999, 0.9999 * (1.0 / c - 1.0) / 2.0])
    ib_e, _ = circle_ibar(ends, c, order)
    q_ends = s * ends * ib_e
    qg = np.linspace(q_ends[0], q_ends[1], _UNIFORM_INTERVALS + 1)
    qt, ut, dt = _inverse_table(alpha0, order)
    u, ib, dib = _newton(qg, alpha0, order, _hermite_start(qg, qt, ut, dt), (-0.5, (1.0 / c - 1.0) / 2.0))
    h = (q_ends[1] - q_ends[0]) / _UNIFORM_INTERVALS
    du = h / (s * (ib + u * dib))
    for a in (u, du):
        a.setflags(write=False)
    return _UniformInverse(float(q_ends[0]), 1.0 / h, u, du)


_A_GRID = np.radians(np.linspace(0.5, 89.5, 179))
_NU = np.concatenate([-(1.0 - (1.0 - np.linspace(0.0, 1.0, 65)[::-1]) ** 2)[:-1],
                      (1.0 - (1.0 - np.linspace(0.0, 1.0, 65)) ** 2)]) * 0.9999


@lru_cache(maxsize=8)
def _universal_table(order: int) -> np.ndarray:
    """q(alpha0, nu) on a grid: nu in (-1, 0) means u = nu / 2, nu in [0, 1) means u = nu u_lock."""
    c, s = np.cos(_A_GRID)[:, None], np.sin(_A_GRID)[:, None]
    u_lock = (1.0 / c - 1.0) / 2.0
    u = np.where(_NU < 0.0, 0.5 * _NU, _NU * u_lock)
    ib, _ = circle_ibar(u, c, order)
    q = s * u * ib
    q.setflags(write=False)
    return q


def _universal_start(q, alpha0, order: int):
    """Starting values of u for per-point braid angles: interpolate the (alpha0, nu) table.

    The row is interpolated linearly in alpha0 (0.5 deg steps), then inverted linearly in nu; a
    Newton iteration from there needs a few steps.
    """
    Q = _universal_table(order)
    qf = np.asarray(q, dtype=float).ravel()
    af = np.asarray(alpha0, dtype=float).ravel()
    t = np.clip((af - _A_GRID[0]) / (_A_GRID[1] - _A_GRID[0]), 0.0, _A_GRID.size - 1.000001)
    i = t.astype(np.intp)
    w = (t - i)[:, None]
    out = np.empty(qf.size)
    for s0 in range(0, qf.size, 8192):  # bounded memory: 8192 x 129 rows at a time
        sl = slice(s0, s0 + 8192)
        row = (1.0 - w[sl]) * Q[i[sl]] + w[sl] * Q[i[sl] + 1]
        j = np.clip((row < qf[sl, None]).sum(-1), 1, _NU.size - 1)
        q0 = np.take_along_axis(row, (j - 1)[:, None], -1)[:, 0]
        q1 = np.take_along_axis(row, j[:, None], -1)[:, 0]
        f = np.clip((qf[sl] - q0) / np.where(q1 > q0, q1 - q0, 1.0), 0.0, 1.0)
        out[sl] = _NU[j - 1] + f * (_NU[j] - _NU[j - 1])
    nu = out
    u_lock = (1.0 / np.cos(af) - 1.0) / 2.0
    return np.where(nu < 0.0, 0.5 * nu, nu * u_lock).reshape(np.shape(q))


@lru_cache(maxsize=64)
def _inverse_table(alpha0: float, order: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Table ``(q(u), u, du/dq)`` on (-1/2, u_lock), increasing, for Newton starting values."""
    c, s = math.cos(alpha0), math.sin(alpha0)
    u_lock = (1.0 / c - 1.0) / 2.0
    t = np.linspace(0.0, 1.0, 513)
    u = np.concatenate([-0.5 * (1.0 - (1.0 - t[::-1]) ** 2)[:-1] * 0.9999, u_lock * (1.0 - (1.0 - t) ** 2) * 0.9999])
    ib, dib = circle_ibar(u, c, order)
    q = s * u * ib
    dudq = 1.0 / (s * (ib + u * dib))
    for a in (q, u, dudq):
        a.setflags(write=False)
    return q, u, dudq


def _hermite_start(q, qt, ut, dt):
    """Cubic Hermite interpolation of the inverse ``u(q)`` from the table (values and slopes)."""
    j = np.clip(np.searchsorted(qt, q) - 1, 0, qt.size - 2)
    h = qt[j + 1] - qt[j]
    x = np.clip((q - qt[j]) / h, 0.0, 1.0)
    x2 = x * x
    h00 = (1.0 + 2.0 * x) * (1.0 - x) ** 2
    h10 = x * (1.0 - x) ** 2
    h01 = x2 * (3.0 - 2.0 * x)
    h11 = x2 * (x - 1.0)
    return h00 * ut[j] + h10 * h * dt[j] + h01 * ut[j + 1] + h11 * h * dt[j + 1]


@dataclass(frozen=True)
class CurvatureLimits:
    """Admissible range of the frame curvature k' (1/mm), with the reasons.

    For one actuator the fields are floats; for a block of cases (:class:`~bendpam.ModelParams`
    with array fields) ``k_min``, ``k_max``, ``u_min`` and ``u_max`` are arrays and the reasons
    describe the first case.

    Examples
    --------
    >>> import bendpam
    >>> lim = bendpam.curvature_limits(bendpam.physics.presets.be_pam())
    >>> round(lim.k_min, 4), round(lim.k_max, 4)        # 1/mm
    (-0.0471, 0.1878)
    >>> lim.reason_max
    "braid lock-up: far-side fibres within 1% of straight (u = k'R = 0.9318 of u_lock = 0.9412)"
    >>> lim.check(0.2)
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: curvature_per_mm k' = 0.2 1/mm is beyond the braid lock-up limit ...
    """

    k_min: Any
    k_max: Any
    reason_min: str
    reason_max: str
    u_min: Any
    u_max: Any

    def check(self, curvature, *, name: str = "curvature_per_mm", slack: float = 0.0) -> None:
        """Raise :class:`~bendpam.errors.InputError` if a curvature is outside ``[k_min, k_max]`` or not finite.

        ``slack``: tolerate curvatures this fraction of ``k_max - k_min`` beyond either limit (the
        rounding of limits computed with another quadrature order).
        """
        k = float_array(name, curvature, "1/mm")
        if k.size == 0:
            return
        if not np.all(np.isfinite(k)):
            bad = np.flatnonzero(~np.isfinite(k.ravel()))[0]
            raise InputError(f"{name} has a non-finite value {k.ravel()[bad]!r} at index {int(bad)}")
        kmin, kmax = float(k.min()), float(k.max())
        lo, hi = float(np.min(self.k_min)), float(np.max(self.k_max))
        pad = slack * (np.asarray(self.k_max) - np.asarray(self.k_min))
        if np.any(k > self.k_max + pad):
            raise InputError(
                f"{name} k' = {kmax:.6g} 1/mm is beyond the braid lock-up limit k'_max = {hi:.6g} 1/mm "
                f"({self.reason_max}); allowed range [{lo:.6g}, {hi:.6g}] 1/mm"
            )
        if np.any(k < self.k_min - pad):
            raise InputError(
                f"{name} k' = {kmin:.6g} 1/mm is beyond the braid lock-up limit k'_min = {lo:.6g} 1/mm "
                f"({self.reason_min}); allowed range [{lo:.6g}, {hi:.6g}] 1/mm"
            )


def _bisect(f, a, b, iters: int = 64, points: int = 15):
    """Vectorised search for the sign change of ``f`` between ``a`` (f > 0) and ``b`` (f <= 0).

    ``f`` takes ``(cases, points)`` arrays.  Each pass evaluates ``points`` interior points of every
    bracket at once and keeps the cell where the sign changes (four bits a pass with 15 points), until
    the bracket has shrunk as much as ``iters`` halvings would shrink it (64: to adjacent floats).
    """
    frac = np.arange(1, points + 1) / (points + 1.0)
    rows = np.arange(np.size(a))
    for _ in range(math.ceil(iters / math.log2(points + 1.0) - 1e-9)):
        m = a[:, None] + (b - a)[:, None] * frac
        pos = f(m) > 0  # f > 0 up to the sign change: the number of leading True is the cell
        i = np.argmin(np.concatenate([pos, np.zeros((rows.size, 1), dtype=bool)], axis=1), axis=1)
        a, b = (np.where(i > 0, m[rows, np.maximum(i - 1, 0)], a),
                np.where(i < points, m[rows, np.minimum(i, points - 1)], b))
    return 0.5 * (a + b)


def limits(params, order: int = DEFAULT_ORDER) -> CurvatureLimits:
    """Lock-up limits of one actuator or of a block of cases (:class:`~bendpam.ModelParams`).

    On each side the limit is the first of: the lumen closing (``R = t_bar``, found on a
    201-point scan of ``u`` and refined by bisection) or the braid limit (99 % of ``u_lock`` for
    k' > 0; far-side stretch 1 % for k' < 0).  Vectorised over cases; no Python loop over them.

    Examples
    --------
    Three braid angles at once (the paper's BE-PAM otherwise):

    >>> import dataclasses, numpy as np, bendpam
    >>> be = bendpam.physics.presets.be_pam()
    >>> cases = dataclasses.replace(be.params, alpha0=np.radians([60.0, 70.0, 80.0]))
    >>> limits(cases).k_max.round(4).tolist()            # 1/mm
    [0.1038, 0.1917, 0.4511]
    """
    kernel_args(params)
    order = quadrature_order(order)
    scalar = np.ndim(params.alpha0) == 0 and np.ndim(params.R0_start) == 0 and np.ndim(params.t0_start) == 0
    shape = np.broadcast_shapes(np.shape(params.alpha0), np.shape(params.R0_start), np.shape(params.t0_start))
    a0 = np.broadcast_to(np.asarray(params.alpha0, dtype=float), shape).ravel()
    R0 = np.broadcast_to(np.asarray(params.R0_start, dtype=float), shape).ravel()
    t0 = np.broadcast_to(np.asarray(params.t0_start, dtype=float), shape).ravel()
    c, s = np.cos(a0), np.sin(a0)
    u_lock = (1.0 / c - 1.0) / 2.0

    def xi(u, cc, ss):
        ib, _ = circle_ibar(u, cc, order)
        return 1.0 / (ss * ib)

    def lumen(u):  # R - t_bar, scaled: R0 xi^2 (1 + u) - t0  (t_bar = t0 / ((1 + u) xi))
        x = xi(u, c[:, None], s[:, None])
        return R0[:, None] * x * x * (1.0 + u) - t0[:, None]

    ends = []
    closes = []
    for end in (LOCK_FRACTION * u_lock, np.full(a0.shape, -0.5 * (1.0 - MIN_FAR_STRETCH))):
        grid = end[:, None] * np.linspace(0.0, 1.0, 201)
        neg = lumen(grid) <= 0.0
        has = neg.any(axis=-1)
        j = np.where(has, np.argmax(neg, axis=-1), 1)
        a = np.take_along_axis(grid, (j - 1)[:, None], -1)[:, 0]
        b = np.take_along_axis(grid, j[:, None], -1)[:, 0]
        root = _bisect(lumen, a, b) if has.any() else a
        ends.append(np.where(has, root, end))
        closes.append(has)
    u_hi, u_lo = ends
    k_max = u_hi / (R0 * xi(u_hi[:, None], c[:, None], s[:, None])[:, 0])
    k_min = u_lo / (R0 * xi(u_lo[:, None], c[:, None], s[:, None])[:, 0])
    if closes[0][0]:
        reason_max = (f"bladder lumen closes (R = t_bar) at u = k'R = {u_hi[0]:.4g}, before braid lock-up "
                      f"u_lock = {u_lock[0]:.4g}")
    else:
        reason_max = (f"braid lock-up: far-side fibres within {100 * (1 - LOCK_FRACTION):g}% of straight "
                      f"(u = k'R = {u_hi[0]:.4g} of u_lock = {u_lock[0]:.4g})")
    if closes[1][0]:
        reason_min = f"bladder lumen closes (R = t_bar) at u = k'R = {u_lo[0]:.4g}"
    else:
        reason_min = (f"braid lock-up: far-side axial stretch lambda1(pi) = 1 + 2k'R falls to {MIN_FAR_STRETCH:g} "
                      "(fibres fully circumferential)")
    if scalar:
        return CurvatureLimits(float(k_min[0]), float(k_max[0]), reason_min, reason_max, float(u_lo[0]), float(u_hi[0]))
    return CurvatureLimits(k_min.reshape(shape), k_max.reshape(shape), reason_min, reason_max,
                           u_lo.reshape(shape), u_hi.reshape(shape))


def kernel_args(params, *arrays: tuple[str, Any, str]) -> tuple[np.ndarray, ...]:
    """The numerics' entry check: ``params`` a :class:`~bendpam.ModelParams`, each ``(name, value, unit)`` a
    float array; one :class:`~bendpam.errors.InputError` line otherwise (NaN passes: the kernels propagate it).

    Examples
    --------
    >>> import bendpam
    >>> kernel_args(bendpam.physics.presets.be_pam().params, ("curvature", [0.0, 0.01], "1/mm"))[0].tolist()
    [0.0, 0.01]
    >>> kernel_args(None, ("curvature", 0.0, "1/mm"))
    Traceback (most recent call last):
    ...
    bendpam.errors.InputTypeError: params = None must be a ModelParams (actuator.params), got NoneType
    """
    instance("params", params, (ModelParams, _Section), "a ModelParams (actuator.params)")
    return tuple(float_array(name, value, unit) for name, value, unit in arrays)


def braid_range(params, order: int = DEFAULT_ORDER) -> CurvatureLimits:
    """The curvatures eq 1-5 describe: the braid limits of :func:`limits` without the lumen closure (cheap).

    ``k'_max`` where ``u = k'R`` reaches :data:`LOCK_FRACTION` of ``u_lock`` and ``k'_min`` where the
    far-side stretch falls to :data:`MIN_FAR_STRETCH`, from two closed-form evaluations of eq 5 per
    case (no scan): the range :meth:`bendpam.MomentLaw.coefficients` and ``basis`` accept.  It
    contains the lock-up limits of :func:`limits`, which the lumen closing can narrow.

    Examples
    --------
    >>> import bendpam
    >>> be = bendpam.physics.presets.be_pam()
    >>> r, lim = braid_range(be.params), bendpam.curvature_limits(be)
    >>> round(r.k_min, 4), round(r.k_max, 4), bool(r.k_min <= lim.k_min and lim.k_max <= r.k_max)
    (-0.0471, 0.1878, True)
    """
    kernel_args(params)
    a0 = np.asarray(params.alpha0, dtype=float)
    shape = np.broadcast_shapes(a0.shape, np.shape(params.R0_start))
    R0 = np.broadcast_to(np.asarray(params.R0_start, dtype=float), shape)
    a0 = np.broadcast_to(a0, R0.shape)
    c, s = np.cos(a0).reshape(-1), np.sin(a0).reshape(-1)
    u_hi = LOCK_FRACTION * (1.0 / c - 1.0) / 2.0
    u_lo = np.full(c.shape, -0.5 * (1.0 - MIN_FAR_STRETCH))
    ib, _ = circle_ibar(np.concatenate([u_lo, u_hi]), np.concatenate([c, c]), order)  # one evaluation, both ends
    k_lo, k_hi = (x.reshape(R0.shape) for x in np.split(np.concatenate([u_lo, u_hi]) * np.concatenate([s, s]) * ib
                                                       / np.concatenate([R0.reshape(-1)] * 2), 2))
    u_lo, u_hi = u_lo.reshape(R0.shape), u_hi.reshape(R0.shape)
    reason_max = (f"braid lock-up: far-side fibres within {100 * (1 - LOCK_FRACTION):g}% of straight, beyond which "
                  "eq 5 has no solution")
    reason_min = (f"braid lock-up: far-side axial stretch lambda1(pi) = 1 + 2k'R falls to {MIN_FAR_STRETCH:g} "
                  "(fibres fully circumferential)")
    if np.ndim(k_hi) == 0:
        return CurvatureLimits(float(k_lo), float(k_hi), reason_min, reason_max, float(u_lo), float(u_hi))
    return CurvatureLimits(k_lo, k_hi, reason_min, reason_max, u_lo, u_hi)


@lru_cache(maxsize=512)
def _scalar_limits(alpha0: float, R0: float, t0: float, order: int) -> CurvatureLimits:
    return limits(_Section(alpha0, R0, t0), order)


@dataclass(frozen=True)
class _Section:
    alpha0: float
    R0_start: float
    t0_start: float


def curvature_limits(actuator, order: int = DEFAULT_ORDER) -> CurvatureLimits:
    """The braid lock-up limits ``[k'_min, k'_max]`` of ``actuator`` (1/mm), cached per geometry.

    ``actuator`` is an :class:`~bendpam.Actuator` or a :class:`~bendpam.ModelParams`; anything
    else raises :class:`~bendpam.errors.InputTypeError` (an InputError).

    Examples
    --------
    >>> import bendpam
    >>> lim = bendpam.curvature_limits(bendpam.physics.presets.bc_pam())
    >>> round(lim.k_min, 4), round(lim.k_max, 4)          # 1/mm; a BC-PAM bends toward k' < 0
    (-0.0413, 0.0275)
    """
    instance("actuator", actuator, (Actuator, ModelParams, _Section), "a bendpam.Actuator or a ModelParams")
    order = quadrature_order(order)
    p = getattr(actuator, "params", actuator)
    if np.ndim(p.alpha0) == 0 and np.ndim(p.R0_start) == 0 and np.ndim(p.t0_start) == 0:
        return _scalar_limits(float(p.alpha0), float(p.R0_start), float(p.t0_start), order)
    return limits(p, order)


@dataclass(frozen=True)
class Kinematics:
    """Kinematic state at frame curvatures ``curvature`` (any shape S).

    Scalar-per-section fields have shape S; fields around the section have shape ``S + (n,)``
    at the quadrature angles ``phi`` (rad, in [0, pi]; the section is symmetric about ``pi``).

    Attributes
    ----------
    curvature : k' (1/mm), frame curvature, positive toward the frame.
    u : k' R, dimensionless.
    radius : R (mm), deformed braid radius (eq 5).
    dradius : dR/dk' (mm^2), implicit derivative of eq 5.
    eta : R / R0_start (eq 5; also the bladder hoop stretch lambda_bl,2, eq 17/38).
    axis_curvature : k = k'/(1 + k'R) (1/mm), eq 1.
    angle : theta = k' L0 (rad).
    axis_length : L = L0 (1 + k'R) (mm).
    mean_axial_stretch : lambda1_bar = 1 + k'R (eq 39).
    mean_thickness : t_bar = t0_start / (lambda1_bar eta) (mm), eq 40 with docs/paper-reading.md item 12.
    phi : quadrature angles (rad), shape (n,).
    weights : circle-mean weights, shape (n,).
    lambda1 : axial stretch around the section (eq 3/34), shape S + (n,).
    lambda2_braid : braid circumferential stretch (eq 4), shape S + (n,).
    braid_angle : local braid angle alpha(Phi) (rad), cos alpha = lambda1 cos alpha0, shape S + (n,).

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> kin = bendpam.kinematics(bendpam.physics.presets.be_pam(), [0.0, 0.01])
    >>> kin.radius.round(3).tolist(), np.degrees(kin.angle).round(2).tolist()   # mm, deg
    ([10.1, 9.949], [0.0, 83.08])
    >>> kin.lambda1.shape                                  # 2 curvatures x 32 quadrature angles
    (2, 32)
    """

    curvature: np.ndarray
    u: np.ndarray
    radius: np.ndarray
    dradius: np.ndarray
    eta: np.ndarray
    axis_curvature: np.ndarray
    angle: np.ndarray
    axis_length: np.ndarray
    mean_axial_stretch: np.ndarray
    mean_thickness: np.ndarray
    phi: np.ndarray
    weights: np.ndarray
    lambda1: np.ndarray
    lambda2_braid: np.ndarray
    braid_angle: np.ndarray

    @property
    def angle_deg(self) -> np.ndarray:
        return np.degrees(self.angle)

    @property
    def volume(self) -> np.ndarray:
        """Enclosed volume V = pi R^2 L0 (1 + k'R) (mm^3), the volume used by eq 13."""
        return np.pi * self.radius**2 * self.axis_length


def radius_from_u(u, ib, dib, alpha0, R0, k=None):
    """``R, dR/dk', k'`` from ``u = k'R`` and the circle means ``Ibar(u)``, ``dIbar/du`` (eq 5).

    ``R = R0 xi(u)`` with ``xi = 1 / (s Ibar)``; ``dR/dk' = R0 xi' R / (1 - R0 xi' k')`` (implicit
    differentiation).  ``k'`` is ``u / R`` unless given.  Scalars or arrays that broadcast;
    ``alpha0`` in rad, ``R0`` (the prestrain-corrected ``R0_start``) in mm.

    Examples
    --------
    >>> import numpy as np
    >>> a0 = np.radians(69.7)
    >>> ib, dib = circle_ibar(np.array([0.0, 0.05]), np.cos(a0))
    >>> R, dR, k = radius_from_u(np.array([0.0, 0.05]), ib, dib, a0, 10.1)
    >>> R.round(4).tolist(), k.round(6).tolist()      # mm, 1/mm
    ([10.1, 10.0277], [0.0, 0.004986])
    """
    u, ib, dib, alpha0, R0 = (float_array(n, v, unit) for n, v, unit in (
        ("u", u, "1"), ("ib", ib, "1"), ("dib", dib, "1"), ("alpha0", alpha0, "rad"), ("R0", R0, "mm")))
    s = np.sin(alpha0)
    # eta(0) = 1 and xi'(0) = -cot^2 alpha0 hold exactly; don't let quadrature rounding blur them
    at0 = u == 0.0
    xi = np.where(at0, 1.0, 1.0 / (s * ib))
    R = R0 * xi
    if k is None:
        k = u / R
    dxi = np.where(at0, -1.0 / np.tan(alpha0) ** 2, -xi * dib / ib)
    dR = R0 * dxi * R / (1.0 - R0 * dxi * k)
    return R, dR, k


def radius_state(kprime, alpha0, R0, order: int = DEFAULT_ORDER):
    """Eq 5 at ``kprime``: ``u, R, dR/dk', Ibar, dIbar/du`` (no limit checks).

    ``kprime`` in 1/mm, ``alpha0`` in rad, ``R0`` (``R0_start``) in mm; ``R`` in mm, ``dR/dk'`` in mm^2.

    Examples
    --------
    >>> import numpy as np
    >>> u, R, dR, ib, dib = radius_state([0.0, 0.01], np.radians(69.7), 10.1)
    >>> u.round(6).tolist(), R.round(4).tolist()
    ([0.0, 0.099494], [10.1, 9.9494])
    """
    k, R0 = float_array("kprime", kprime, "1/mm"), float_array("R0", R0, "mm")
    u, ib, dib = solve_u(k * R0, alpha0, order)
    R, dR, _ = radius_from_u(u, ib, dib, alpha0, R0, k)
    return u, R, dR, ib, dib


def radius_terms(kprime, alpha0: float, R0: float, order: int = DEFAULT_ORDER):
    """Core of eq 5 for the models: ``u, R, dR/dk'`` at ``kprime`` (no limit checks).

    The first three results of :func:`radius_state` (same units).

    Examples
    --------
    >>> import numpy as np
    >>> u, R, dR = radius_terms(0.01, np.radians(69.7), 10.1)
    >>> round(float(R), 4), round(float(dR), 2)       # mm, mm^2
    (9.9494, -16.17)
    """
    u, R, dR, _, _ = radius_state(kprime, alpha0, R0, order)
    return u, R, dR


def kinematics(actuator, curvature_per_mm, order: int = DEFAULT_ORDER) -> Kinematics:
    """Kinematics (eq 1-5) of ``actuator`` at frame curvature(s) ``curvature_per_mm`` (1/mm).

    Raises :class:`~bendpam.errors.InputError` if a curvature lies beyond the braid lock-up
    limits (see :func:`curvature_limits`) or is not a finite number, or ``actuator`` is not one
    actuator (an :class:`~bendpam.Actuator`, or a :class:`~bendpam.ModelParams` of one case).

    >>> import bendpam
    >>> kin = bendpam.kinematics(bendpam.physics.presets.be_pam(), [0.0, 0.01])
    >>> round(float(kin.radius[0]), 6), bool(kin.radius[1] < kin.radius[0])
    (10.1, True)
    """
    instance("actuator", actuator, (Actuator, ModelParams), "a bendpam.Actuator")
    p = actuator.params if isinstance(actuator, Actuator) else actuator
    if p.shape != ():
        raise InputError("kinematics() describes one actuator, not a block of cases")
    order = quadrature_order(order)
    k = float_array("curvature_per_mm", curvature_per_mm, "1/mm")
    curvature_limits(actuator, order).check(k)
    a0 = float(p.alpha0)
    R0 = float(p.R0_start)
    u, R, dR = radius_terms(k, a0, R0, order)
    phi, wbar = gauss_nodes(order)
    lam1 = 1.0 + u[..., None] * (1.0 - np.cos(phi))
    cl = np.clip(math.cos(a0) * lam1, -1.0, 1.0)
    lam2b = np.sqrt(1.0 - cl * cl) / math.sin(a0)
    eta = R / R0
    lbar = 1.0 + u
    return Kinematics(
        curvature=k,
        u=u,
        radius=R,
        dradius=dR,
        eta=eta,
        axis_curvature=k / (1.0 + u),
        angle=k * float(p.L0),
        axis_length=float(p.L0) * lbar,
        mean_axial_stretch=lbar,
        mean_thickness=float(p.t0_start) / (lbar * eta),
        phi=phi,
        weights=wbar,
        lambda1=lam1,
        lambda2_braid=lam2b,
        braid_angle=np.arccos(cl),
    )
