r"""Independent baselines of both moment models, written from the paper's equations (issue 13 item 1).

Nothing here imports bendpam's numerics: the equations are re-derived from ``docs/paper-reading.md``
(items 1-14, 18) so that the benchmarks compare bendpam with what a competent engineer would write
in plain NumPy, and with the per-point SciPy code a model is usually first written as.

Notation (mm, MPa, rad, N*mm): ``c = cos a0``, ``s = sin a0``, ``u = k'R``, ``omc = 1 - cos(Phi)``,
``lam1 = 1 + u omc``, ``Ibar(u) = mean_Phi (1 - c^2 lam1^2)^(-1/2)``.

* Eq 5 (item 2): ``q(u) = s u Ibar(u) = k' R0`` (``R0 = R0_start``), solved for ``u`` on the
  bracket ``(0, u_lock)`` (k' > 0) or ``(-1/2, 0)`` (k' < 0), ``u_lock = (1/c - 1)/2``.
  ``R = R0 xi``, ``xi = 1/(s Ibar)``.
* Item 3: ``dR/dk' = R0 xi' R / (1 - R0 xi' k')`` with ``xi' = -xi Ibar'/Ibar``.
* Energy model (items 5-8): ``M = P_a A - B``, ``A = pi[(2R + 3k'R^2) R' + R^3]``,
  ``B = E_f I_f k' + A_bl (1 + u) mean[dW/dlam1 (R + k'R') omc + dW/dlam2 R'/R0]`` with the
  Mooney-Rivlin ``W = C10 (I1 - 3) + C01 (I2 - 3)``, ``lam2 = eta = R/R0``, ``lam3 = 1/(lam1 eta)``.
* Force-balance model (items 9-12): ``A = R^3 (pi - c^2 J)``,
  ``B = E_f I_f k' + tbar R^2 (V + 2 pi K1) - S2 tbar R^2 c^2 J`` with
  ``J = 2 pi mean[lam1^2 omc / (1 - c^2 lam1^2)]``, ``V = 2 pi mean[(2 C10 lam1^2 - 2 C01 / lam1^2) omc]``,
  ``lbar = 1 + u``, ``tbar = t0_start / (lbar eta)``, ``K1 = -2C10/(lbar eta)^2 + 2C01 (lbar eta)^2`` and
  ``S2 = 2C10 (eta^2 - 1/(lbar eta)^2) - 2C01 (1/eta^2 - (lbar eta)^2)``.

Competent vectorised baseline (:class:`Baseline`)
    * 24-node Gauss-Legendre on [0, pi] (every integrand is even about pi) for the elliptic-type
      means ``Ibar``, ``Ibar'`` and ``J``; the means of polynomials and inverse powers of
      ``lam1 = (1 + u) - u cos(Phi)`` have closed forms and are not integrated at all:
      ``mean lam1 omc = 1 + 3u/2``, ``mean lam1^2 = 1 + 2u + 3u^2/2``,
      ``mean lam1^2 omc = 1 + 3u + 5u^2/2``, ``mean lam1^-2 = (1 + u)/(1 + 2u)^(3/2)``,
      ``mean lam1^-2 omc = (1 + 2u)^(-3/2)``, ``mean lam1^-3 omc = (2 + u)/(2 (1 + 2u)^(5/2))``
      (from ``mean 1/(a - b cos) = (a^2 - b^2)^(-1/2)`` and its derivatives in ``a``);
    * eq 5 by a bracketed vectorised Newton iteration that starts from a cubic Hermite
      interpolation of the inverse ``u(q)`` (a 513-point table per actuator; start error about
      1e-9, so one step reaches rounding and a second pass confirms it);
    * ``dR/dk'`` by implicit differentiation (no finite differences);
    * blocks of :data:`CHUNK` points so that the (points x nodes) temporaries stay in cache;
    * its own free-bending solve: the branch ``P_a = B/A`` sampled along the bending direction,
      its first fold refined by golden section, and a vectorised Illinois iteration on
      ``M = 0`` over all pressures at once.

Per-point baseline (:func:`per_point_moment`)
    ``scipy.integrate.quad`` for every mean and ``brentq`` for eq 5, one (P, k') pair at a time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

__all__ = ["CHUNK", "NODES", "Baseline", "BaselineBranch", "BatchedBaseline", "closed_means", "per_point_moment"]

NODES = 24
CHUNK = 4096
_LOCK_FRACTION = 0.99  # same admissible range as the paper reading (item 4): 99 % of u_lock
_MIN_FAR_STRETCH = 0.01


@dataclass(frozen=True)
class Params:
    """One actuator in internal units (mm, MPa, rad), read from an ``Actuator``'s user fields."""

    alpha0: float
    R0: float  # R0_start
    t0: float  # t0_start
    area: float  # bladder wall area (reference annulus)
    EI: float  # frame stiffness E_f I_f
    C10: float
    C01: float
    P_start: float  # MPa
    L0: float

    @classmethod
    def of(cls, a) -> Params:
        """From the user fields of a ``bendpam.Actuator`` (eq 51-52 re-derived here)."""
        R0, t0 = a.R0_mm, a.t0_mm
        R0s = a.R0_start_mm if a.R0_start_mm is not None else R0
        return cls(
            alpha0=math.radians(a.alpha0_deg), R0=R0s,
            t0=R0s - math.sqrt(R0s * R0s - 2.0 * R0 * t0 + t0 * t0),
            area=math.pi * (2.0 * R0 * t0 - t0 * t0),
            EI=a.frame_modulus_mpa * a.frame_width_mm * a.frame_thickness_mm**3 / 12.0,
            C10=a.C10_kpa * 1e-3, C01=a.C01_kpa * 1e-3, P_start=a.P_start_kpa * 1e-3, L0=a.L0_mm,
        )

    def replace(self, **kw) -> Params:
        return Params(**{**self.__dict__, **kw})


@lru_cache(maxsize=8)
def _nodes(n: int):
    x, w = np.polynomial.legendre.leggauss(n)
    phi = (x + 1.0) * (np.pi / 2.0)
    return 1.0 - np.cos(phi), w / 2.0  # omc, weights of a circle mean


class Baseline:
    """Competent NumPy baseline of one actuator and model (see the module docstring).

    ``moment(P_kpa, k)`` takes kPa and 1/mm like bendpam; ``coefficients(k)`` returns ``(A, B)``
    with A in N*mm/kPa.
    """

    def __init__(self, actuator_or_params, model: str = "energy", *, nodes: int = NODES, chunk: int = CHUNK,
                 eq19_factor: bool = True, closed_form: bool = False):
        p = actuator_or_params if isinstance(actuator_or_params, Params) else Params.of(actuator_or_params)
        self.p = p
        self.closed_form = bool(closed_form)
        self.model = model.replace("-", "_")
        if self.model not in ("energy", "force_balance"):
            raise ValueError(f"unknown model {model!r}")
        self.eq19 = eq19_factor
        self.chunk = int(chunk)
        self.omc, self.w = _nodes(nodes)
        self.c, self.s = math.cos(p.alpha0), math.sin(p.alpha0)
        self._wd = self.c * self.omc * self.w  # Ibar' = mean c^2 lam1 omc g^(-3/2): c lam1 is in cl
        self._wj = 2.0 * np.pi * self.omc * self.w  # J = 2 pi mean lam1^2 omc / g
        self._buf = tuple(np.empty((max(self.chunk, 513), self.omc.size)) for _ in range(4))
        self.u_lock = (1.0 / self.c - 1.0) / 2.0
        self._inverse_table()
        self.k_min, self.k_max = self._limits()

    # ---- eq 5 -----------------------------------------------------------------------------
    def _buffers(self, n: int):
        """Work arrays (n x nodes): views of four arrays allocated once and reused (``out=``).

        No temporaries of block size are allocated, so none is page-faulted in afresh (glibc hands
        large blocks out by ``mmap``) and a block of :attr:`chunk` points stays in cache.
        """
        if self._buf[0].shape[0] < n:
            self._buf = tuple(np.empty((n, self.omc.size)) for _ in range(4))
        return tuple(b[:n] for b in self._buf)

    def _ibar(self, u):
        """``Ibar, Ibar'`` (and the force-balance ``J``) at ``u`` (1-D), one (n x nodes) pass."""
        if self.closed_form:
            return closed_means(u, self.c, self.model == "force_balance")
        lam, cl, g, r = self._buffers(u.size)
        np.multiply(u[:, None], self.omc, out=lam)
        lam += 1.0
        np.multiply(lam, self.c, out=cl)
        np.multiply(cl, cl, out=g)
        np.subtract(1.0, g, out=g)
        np.sqrt(g, out=r)
        np.divide(1.0, r, out=r)
        ib = r @ self.w
        r /= g  # g^(-3/2)
        r *= cl
        dib = r @ self._wd
        J = None
        if self.model == "force_balance":
            np.multiply(lam, lam, out=cl)
            cl /= g
            J = cl @ self._wj
        return ib, dib, J

    def _inverse_table(self) -> None:
        """``q(u)`` and ``dq/du`` on 513 graded points of (-1/2, u_lock): Hermite start values."""
        t = np.linspace(0.0, 1.0, 257)
        grade = 1.0 - (1.0 - t) ** 2
        u = np.concatenate([-0.5 * 0.9999 * grade[::-1][:-1], 0.9995 * self.u_lock * grade])
        ib, dib, _ = self._ibar(u)
        self._ut = u
        self._qt = self.s * u * ib
        self._dut = 1.0 / (self.s * (ib + u * dib))  # du/dq

    def _start(self, q):
        qt, ut, d = self._qt, self._ut, self._dut
        j = np.clip(np.searchsorted(qt, q) - 1, 0, qt.size - 2)
        q0, q1 = qt[j], qt[j + 1]
        h = q1 - q0
        x = (q - q0) / h
        x2 = x * x
        x3 = x2 * x
        return ((2 * x3 - 3 * x2 + 1) * ut[j] + (x3 - 2 * x2 + x) * h * d[j]
                + (-2 * x3 + 3 * x2) * ut[j + 1] + (x3 - x2) * h * d[j + 1])

    def solve_u(self, q, maxiter: int = 40):
        """Root ``u`` of ``s u Ibar(u) = q`` and the means at it: ``(u, Ibar, Ibar', J)`` (1-D ``q``)."""
        s = self.s
        pos = q >= 0.0
        lo = np.where(pos, 0.0, -0.5)
        hi = np.where(pos, self.u_lock, 0.0)
        u = np.clip(self._start(q), lo, hi)
        u = np.where(q == 0.0, 0.0, u)
        for _ in range(maxiter):
            ib, dib, J = self._ibar(u)
            f = s * u * ib - q
            lo = np.where(f < 0.0, u, lo)
            hi = np.where(f > 0.0, u, hi)
            step = f / (s * (ib + u * dib))
            if np.all(np.abs(step) <= 1e-12 * np.abs(u)):
                break  # the means at u are those of the root to ~1e-12 (quadratic convergence)
            un = u - step
            u = np.where((un >= lo) & (un <= hi), un, 0.5 * (lo + hi))
        return u, ib, dib, J

    def _limits(self):
        """Admissible k' range (item 4): braid limits, or the lumen closing (R = tbar) first."""
        p = self.p

        def k_of(u):
            ib, _, _ = self._ibar(np.atleast_1d(u))
            return u * ib[0] * self.s / p.R0

        def lumen(u):  # R - tbar scaled: R0 xi^2 (1 + u) - t0
            ib, _, _ = self._ibar(np.atleast_1d(np.asarray(u, dtype=float)))
            xi = 1.0 / (self.s * ib)
            return p.R0 * xi * xi * (1.0 + np.atleast_1d(u)) - p.t0

        ends = []
        for end in (_LOCK_FRACTION * self.u_lock, -0.5 * (1.0 - _MIN_FAR_STRETCH)):
            grid = end * np.linspace(0.0, 1.0, 201)
            neg = np.flatnonzero(lumen(grid) <= 0.0)
            if neg.size:
                a, b = grid[neg[0] - 1], grid[neg[0]]
                for _ in range(64):
                    m = 0.5 * (a + b)
                    a, b = (m, b) if lumen(m)[0] > 0.0 else (a, m)
                end = 0.5 * (a + b)
            ends.append(end)
        return float(k_of(ends[1])), float(k_of(ends[0]))

    # ---- the models ----------------------------------------------------------------------
    def _block(self, k):
        u, ib, dib, J = self.solve_u(k * self.p.R0)
        return _coefficients(self.model, self.eq19, self.p, self.c, u, k, 1.0 / (self.s * ib), ib, dib, J)

    def coefficients(self, k):
        """``(A, B)``: A in N*mm/kPa, B in N*mm; blocks of :attr:`chunk` points."""
        k = np.asarray(k, dtype=float)
        flat = k.ravel()
        A = np.empty(flat.size)
        B = np.empty(flat.size)
        n = self.chunk
        for i in range(0, flat.size, n):
            A[i:i + n], B[i:i + n] = self._block(flat[i:i + n])
        return (A * 1e-3).reshape(k.shape), B.reshape(k.shape)

    def moment(self, pressure_kpa, k):
        """``M(P, k')`` in N*mm (kPa, 1/mm), elementwise over equal-shaped arrays."""
        pa = np.maximum(np.asarray(pressure_kpa, dtype=float) - self.p.P_start * 1e3, 0.0)
        A, B = self.coefficients(k)
        return pa * A - B

    def blocked_moment(self, pressure_kpa):
        """``M(P, 0)``; uses the eq 5 solve at k' = 0 like every other point."""
        pa = np.maximum(np.asarray(pressure_kpa, dtype=float) - self.p.P_start * 1e3, 0.0)
        A, _ = self.coefficients(np.zeros(1))
        return pa * A[0]

    # ---- free bending --------------------------------------------------------------------
    def branch(self, samples: int = 256) -> BaselineBranch:
        """The free-bending branch: ``P_a = B/A`` sampled from k' = 0 along the bending direction."""
        sgn = 1.0 if self.p.alpha0 > math.atan(math.sqrt(2.0)) else -1.0
        k_lim = self.k_max if sgn > 0 else self.k_min
        kk = k_lim * np.linspace(0.0, 1.0, samples + 1) ** 1.5
        A, B = self.coefficients(kk)
        ok = sgn * A > 0.0
        n_ok = int(np.argmin(ok)) if not ok.all() else kk.size  # first index where A has the wrong sign
        with np.errstate(divide="ignore", invalid="ignore"):
            pk = np.where(ok, B / A, np.nan)
        pk[0] = 0.0
        dec = np.flatnonzero(np.diff(pk[:n_ok]) <= 0.0)
        if dec.size:  # fold: refine the maximum of B/A by golden section on [k_{j-1}, k_{j+1}]
            j = int(dec[0])
            a, b = sorted((kk[max(j - 1, 0)], kk[min(j + 1, kk.size - 1)]))

            def pf(x):
                Ax, Bx = self.coefficients(np.array([x]))
                return float(Bx[0] / Ax[0])

            g = (math.sqrt(5.0) - 1.0) / 2.0
            x1, x2 = b - g * (b - a), a + g * (b - a)
            f1, f2 = pf(x1), pf(x2)
            for _ in range(60):
                if f1 > f2:
                    b, x2, f2 = x2, x1, f1
                    x1 = b - g * (b - a)
                    f1 = pf(x1)
                else:
                    a, x1, f1 = x1, x2, f2
                    x2 = a + g * (b - a)
                    f2 = pf(x2)
            km = 0.5 * (a + b)
            pm = pf(km)
            if pm > pk[j]:  # the branch ends at km: drop a sample that already lies beyond it
                keep = np.abs(kk[:j + 1]) < abs(km)
                return BaselineBranch(sgn, np.append(kk[:j + 1][keep], km), np.append(pk[:j + 1][keep], pm), "fold",
                                      self)
            return BaselineBranch(sgn, kk[:j + 1], pk[:j + 1], "fold", self)
        if n_ok < kk.size:  # A changes sign: p -> inf, every pressure has an equilibrium
            return BaselineBranch(sgn, kk[:n_ok + 1], np.append(pk[:n_ok], np.inf), "unbounded", self)
        return BaselineBranch(sgn, kk, pk, "lock-up", self)

    def free_curvature(self, pressure_kpa, branch: BaselineBranch | None = None, xtol: float = 1e-13):
        """Free-bending k' (1/mm) at ``pressure_kpa``: 0 below P_start, NaN above the branch end."""
        return (branch or self.branch()).solve(pressure_kpa, xtol)


def _coefficients(model, eq19, p, c, u, k, xi, ib, dib, J):
    """``(A per MPa, B)`` of either model at the kinematic state ``u, k' = u/R, xi = R/R0`` (eq 5) and its means.

    ``p`` holds the actuator's fields (scalars, or arrays broadcasting against ``u`` for a batch of cases).
    """
    R0 = p.R0
    R = R0 * xi
    eta = xi
    C1, C2 = p.C10, p.C01
    if model == "energy":
        dxi = -xi * dib / ib
        dR = R0 * dxi * R / (1.0 - R0 * dxi * k)
        A = np.pi * ((2.0 * R + 3.0 * k * R * R) * dR + R**3)
        q = 1.0 + 2.0 * u
        rq = 1.0 / np.sqrt(q)
        rq3 = rq / q
        e2 = eta * eta
        l1o = 1.0 + 1.5 * u  # mean lam1 omc
        l3o = (2.0 + u) * rq3 / (2.0 * q)  # mean lam1^-3 omc
        l2 = 1.0 + u * (2.0 + 1.5 * u)  # mean lam1^2
        lm2 = (1.0 + u) * rq3  # mean lam1^-2
        d1 = (R + k * dR) * (2.0 * (C1 + C2 * e2) * l1o - 2.0 * (C1 / e2 + C2) * l3o)
        e3 = e2 * eta
        d2 = (dR / R0) * (2.0 * C1 * eta - 2.0 * C1 * lm2 / e3 - 2.0 * C2 / e3 + 2.0 * C2 * eta * l2)
        fac = p.area * (1.0 + u) if eq19 else p.area
        return A, fac * (d1 + d2) + p.EI * k
    le = (1.0 + u) * eta
    le2 = le * le
    tb = p.t0 / le
    q = 1.0 + 2.0 * u
    var = 2.0 * np.pi * (2.0 * C1 * (1.0 + u * (3.0 + 2.5 * u)) - 2.0 * C2 / (q * np.sqrt(q)))
    k1 = -2.0 * C1 / le2 + 2.0 * C2 * le2
    s2 = 2.0 * C1 * (eta * eta - 1.0 / le2) - 2.0 * C2 / (eta * eta) + 2.0 * C2 * le2
    w = tb * R * R
    A = R**3 * (np.pi - c * c * J)
    return A, p.EI * k + w * (var + 2.0 * np.pi * k1) - s2 * w * c * c * J


def _rsqrt_m1(y):
    """``(1 + y)^(-1/2) - 1``, accurate for small ``y``."""
    return np.expm1(-0.5 * np.log1p(y))


def closed_means(u, c, want_j: bool = False):
    """``Ibar, Ibar'`` (and ``J``) in closed form: what the baseline computes when given bendpam's closed forms.

    Derived here from the means' definitions: ``1 - c^2 lam1^2`` is a quadratic in ``cos Phi``, so
    ``Ibar(u) = (2/pi) K(m) / sqrt(D)`` with ``D = (1 - c)(1 + c + 2cu)`` (u >= 0) or ``(1 + c)(1 - c - 2cu)``
    (u < 0) and ``m = 4 c |u| / D``; ``Ibar'`` by the chain rule with ``dK/dm = (E - (1 - m) K) / (2 m (1 - m))``
    (its series below m = 1e-3).  ``J = 2 pi mean(lam1^2 omc / (1 - c^2 lam1^2))``: partial fractions in
    ``1 -+ c lam1`` and ``mean 1/(a + b cos) = (a^2 - b^2)^(-1/2)`` give
    ``J = (2 pi / c^2) ((g(-2cu/(1 - c)) - g(2cu/(1 + c))) / (2cu) - 1)`` with ``g(y) = (1 + y)^(-1/2) - 1``.
    """
    from scipy.special import ellipe, ellipk

    u = np.asarray(u, dtype=float)
    c = np.asarray(c, dtype=float)
    pos = u >= 0.0
    cu = c * u
    D = np.where(pos, (1.0 - c) * (1.0 + c + 2.0 * cu), (1.0 + c) * (1.0 - c - 2.0 * cu))
    dD = np.where(pos, 2.0 * c * (1.0 - c), -2.0 * c * (1.0 + c))
    m = 4.0 * np.abs(cu) / D
    dm = np.where(pos, 4.0 * c, -4.0 * c) / D - m * dD / D
    K, E = ellipk(m), ellipe(m)
    small = m < 1e-3
    ms = np.where(small, 0.5, m)
    dK = np.where(small, 0.5 * np.pi * (0.25 + m * (9.0 / 32.0 + m * (75.0 / 256.0 + m * (1225.0 / 4096.0)))),
                  (E - (1.0 - ms) * K) / (2.0 * ms * (1.0 - ms)))
    rD = 1.0 / np.sqrt(D)
    ib = (2.0 / np.pi) * K * rD
    dib = (2.0 / np.pi) * rD * (dK * dm - 0.5 * K * dD / D)
    J = None
    if want_j:
        x = np.where(cu == 0.0, 1e-300, 2.0 * cu)
        J = (2.0 * np.pi / (c * c)) * ((_rsqrt_m1(-x / (1.0 - c)) - _rsqrt_m1(x / (1.0 + c))) / x - 1.0)
    return ib, dib, J


@dataclass
class BaselineBranch:
    """Sampled free-bending branch of a :class:`Baseline` (``kt`` from 0, ``pt`` increasing)."""

    sgn: float
    kt: np.ndarray
    pt: np.ndarray
    kind: str
    law: Baseline

    @property
    def max_pressure_kpa(self) -> float:
        return self.law.p.P_start * 1e3 + float(self.pt[-1])

    def solve(self, pressure_kpa, xtol: float = 1e-13):
        P = np.asarray(pressure_kpa, dtype=float)
        pa = np.maximum(P.ravel() - self.law.p.P_start * 1e3, 0.0)
        k = np.zeros(pa.size)
        k[pa > self.pt[-1]] = np.nan
        idx = np.flatnonzero((pa > 0.0) & (pa <= self.pt[-1]))
        if idx.size == 0:
            return k.reshape(P.shape)
        q = pa[idx]
        j = np.clip(np.searchsorted(self.pt, q), 1, self.pt.size - 1)
        a, b = self.kt[j - 1], self.kt[j]
        sgn = self.sgn

        def F(x, sel):  # sgn*M: > 0 before the root along the branch, < 0 after it
            A, B = self.law.coefficients(x)
            return sgn * (q[sel] * A - B)

        k[idx] = _illinois(F, a, b, xtol * abs(self.kt[-1]))
        return k.reshape(P.shape)


class BatchedBaseline:
    """The competent baseline of a block of actuator cases at once (sweeps): no Python loop over cases.

    Every case's parameters are arrays; the section means are the closed forms of :func:`closed_means`
    (the strongest baseline: it is given bendpam's closed forms).  The free-bending branch is
    sampled in ``u = k'R``, where a point needs no solve of eq 5 (``k' = u / R(u)``), for all cases
    in one array; folds are refined by a vectorised golden section, and the roots at every pressure of
    every case by one vectorised Illinois iteration on ``M = 0`` in ``u``, bracketed by a vectorised
    bisection in the sampled branch.  :meth:`sweep` gives the blocked moment and the free curvature.
    """

    def __init__(self, params: list[Params], model: str = "energy", *, eq19_factor: bool = True):
        self.model = model.replace("-", "_")
        self.eq19 = eq19_factor
        self.f = {name: np.array([getattr(p, name) for p in params], dtype=float)
                  for name in Params.__dataclass_fields__}
        a0 = self.f["alpha0"]
        self.c, self.s = np.cos(a0), np.sin(a0)
        self.sgn = np.where(a0 > math.atan(math.sqrt(2.0)), 1.0, -1.0)
        self.u_end = self._u_limits()

    def _take(self, rows):
        return _Fields({name: v[rows] for name, v in self.f.items()})

    def coef(self, u, rows):
        """``(A per MPa, B)`` and ``k'`` at ``u`` for the cases ``rows`` (arrays of one shape)."""
        ib, dib, J = closed_means(u, self.c[rows], self.model == "force_balance")
        xi = 1.0 / (self.s[rows] * ib)
        p = self._take(rows)
        k = u / (p.R0 * xi)
        A, B = _coefficients(self.model, self.eq19, p, self.c[rows], u, k, xi, ib, dib, J)
        return A, B, k

    def _u_limits(self):
        """The end of the admissible range in the bending direction: 99 % of lock-up, or the lumen closing."""
        n = self.c.size
        end = np.where(self.sgn > 0, _LOCK_FRACTION * (1.0 / self.c - 1.0) / 2.0, -0.5 * (1.0 - _MIN_FAR_STRETCH))
        rows = np.arange(n)[:, None]

        def lumen(u, rows):
            ib, _, _ = closed_means(u, self.c[rows])
            xi = 1.0 / (self.s[rows] * ib)
            return self.f["R0"][rows] * xi * xi * (1.0 + u) - self.f["t0"][rows]

        grid = end[:, None] * np.linspace(0.0, 1.0, 201)
        neg = lumen(grid, rows) <= 0.0
        has = neg.any(-1)
        j = np.where(has, np.argmax(neg, -1), 1)
        a, b = grid[np.arange(n), j - 1], grid[np.arange(n), j]
        for _ in range(64):
            mid = 0.5 * (a + b)
            pos = lumen(mid, np.arange(n)) > 0.0
            a, b = np.where(pos, mid, a), np.where(pos, b, mid)
        return np.where(has, 0.5 * (a + b), end)

    def branch(self, samples: int = 256):
        """``(ut, pt, last)``: the sampled branch in u from 0 (``pt`` rising to index ``last``, inf after)."""
        n = self.c.size
        rows = np.arange(n)[:, None]
        ug = self.u_end[:, None] * np.linspace(0.0, 1.0, samples + 1) ** 1.5
        A, B, _ = self.coef(ug, rows)
        ok = self.sgn[:, None] * A > 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            pt = np.where(ok, B / A * 1e3, np.nan)  # kPa
        pt[:, 0] = 0.0
        idx = np.arange(samples + 1)[None, :]
        n_ok = np.where(ok.all(-1), samples + 1, np.argmin(ok, -1))
        dec = (np.diff(pt, axis=-1) <= 0.0) & (idx[:, 1:] < n_ok[:, None])
        fold = dec.any(-1)
        j = np.argmax(dec, -1)
        last = np.where(fold, j, np.where(n_ok <= samples, n_ok, samples))
        ut = ug.copy()
        pt = np.where(~fold[:, None] & (n_ok[:, None] <= samples) & (idx == n_ok[:, None]), np.inf, pt)
        f = np.flatnonzero(fold & (j > 0))
        if f.size:  # golden section on [u_{j-1}, u_{j+1}] for the maximum of B/A
            jf = j[f]
            lo, hi = ug[f, jf - 1], ug[f, np.minimum(jf + 1, samples)]

            def pf(x):
                A_, B_, _ = self.coef(x, f)
                return B_ / A_ * 1e3

            g = (math.sqrt(5.0) - 1.0) / 2.0
            x1, x2 = hi - g * (hi - lo), lo + g * (hi - lo)
            f1, f2 = pf(x1), pf(x2)
            for _ in range(60):
                left = f1 > f2
                hi, lo = np.where(left, x2, hi), np.where(left, lo, x1)
                new = np.where(left, hi - g * (hi - lo), lo + g * (hi - lo))
                fn = pf(new)
                x1, f1, x2, f2 = (np.where(left, new, x2), np.where(left, fn, f2),
                                  np.where(left, x1, new), np.where(left, f1, fn))
            um = 0.5 * (lo + hi)
            pm = pf(um)
            better = pm > pt[f, jf]
            before = np.abs(um) < np.abs(ug[f, jf])  # the maximum lies before sample j: it replaces it
            at = np.where(before, jf, jf + 1)
            ut[f[better], at[better]] = um[better]
            pt[f[better], at[better]] = pm[better]
            last[f[better]] = at[better]
        pt = np.where(idx <= last[:, None], pt, np.inf)
        return ut, pt, last

    def sweep(self, pressure_kpa, samples: int = 256, xtol: float = 1e-13):
        """``(blocked moment N*mm, free k' 1/mm)``, arrays (cases, pressures); NaN above the branch's end."""
        P = np.asarray(pressure_kpa, dtype=float)
        n = self.c.size
        rows = np.arange(n)[:, None]
        pa = np.maximum(P[None, :] - self.f["P_start"][:, None] * 1e3, 0.0)
        A0, _, _ = self.coef(np.zeros((n, 1)), rows)
        blocked = pa * A0 * 1e-3
        ut, pt, last = self.branch(samples)
        p_end = pt[np.arange(n), last]
        k = np.where(pa > p_end[:, None], np.nan, 0.0)
        case, col = np.nonzero((pa > 0.0) & (pa <= p_end[:, None]))
        q = pa[case, col]
        lo, hi = np.zeros(q.size, dtype=np.intp), last[case].copy()
        for _ in range(int(samples + 2).bit_length()):  # bisection: the first sample with pt >= q
            mid = (lo + hi) // 2
            below = pt[case, mid] < q
            lo, hi = np.where(below, mid + 1, lo), np.where(below, hi, mid)
        j = np.maximum(lo, 1)
        sg = self.sgn[case]

        def F(x, sel):
            A, B, _ = self.coef(x, case[sel])
            return sg[sel] * (q[sel] * 1e-3 * A - B)

        u = _illinois(F, ut[case, j - 1], ut[case, j], xtol * float(np.abs(self.u_end).max()))
        k[case, col] = self.coef(u, case)[2]
        return blocked, k


class _Fields:
    """Attribute access to a dict of per-case arrays (what :func:`_coefficients` reads)."""

    def __init__(self, d):
        self.__dict__.update(d)


def _illinois(F, a, b, tol, maxiter: int = 100):
    """Vectorised Illinois iteration on brackets with ``F(a) >= 0 >= F(b)``; only live points are evaluated."""
    a, b = a.astype(float).copy(), b.astype(float).copy()
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
        xs = np.where((xs > np.minimum(aa, bb)) & (xs < np.maximum(aa, bb)), xs, 0.5 * (aa + bb))
        step = np.abs(xs - x[act])
        x[act] = xs
        fx = F(xs, act)
        pos = fx > 0.0
        sd = side[act]
        fb_ = np.where(pos & (sd == 1), 0.5 * fb_, fb_)
        fa_ = np.where(~pos & (sd == -1), 0.5 * fa_, fa_)
        a[act] = np.where(pos, xs, aa)
        fa[act] = np.where(pos, fx, fa_)
        b[act] = np.where(pos, bb, xs)
        fb[act] = np.where(pos, fb_, fx)
        side[act] = np.where(pos, 1.0, -1.0)
        done = (fx == 0.0) | (np.abs(b[act] - a[act]) <= tol) | (step <= tol)
        act = act[~done]
    return x


# ------------------------------------------------------------------------------------------------
# per-point baseline: quad + brentq, one pair at a time
# ------------------------------------------------------------------------------------------------
def per_point_moment(p: Params, model: str, P_kpa: float, k: float) -> float:
    """``M(P, k')`` (N*mm) for one pair, with ``scipy.integrate.quad`` and ``brentq`` (kPa, 1/mm)."""
    from scipy.integrate import quad
    from scipy.optimize import brentq

    c, s, R0 = math.cos(p.alpha0), math.sin(p.alpha0), p.R0
    tp = 2.0 * math.pi

    def mean(f):
        return quad(f, 0.0, math.pi, epsabs=1e-13, epsrel=1e-12, limit=200)[0] / math.pi

    def ibar(u):
        return mean(lambda f: 1.0 / math.sqrt(1.0 - (c * (1.0 + u * (1.0 - math.cos(f)))) ** 2))

    if k == 0.0:
        u = 0.0
    else:
        lo, hi = (0.0, (1.0 / c - 1.0) / 2.0 * (1 - 1e-12)) if k > 0 else (-0.5 * (1 - 1e-12), 0.0)
        u = brentq(lambda uu: s * uu * ibar(uu) - k * R0, lo, hi, xtol=1e-15, rtol=1e-14)
    ib = ibar(u)
    R = R0 / (s * ib)
    eta = R / R0
    pa = max(P_kpa - p.P_start * 1e3, 0.0) * 1e-3
    C1, C2 = p.C10, p.C01
    if model == "energy":
        dib = mean(lambda f: c * c * (1.0 + u * (1.0 - math.cos(f))) * (1.0 - math.cos(f))
                   / (1.0 - (c * (1.0 + u * (1.0 - math.cos(f)))) ** 2) ** 1.5)
        dxi = -(1.0 / (s * ib)) * dib / ib
        dR = R0 * dxi * R / (1.0 - R0 * dxi * k)

        def dW(f):
            omc = 1.0 - math.cos(f)
            l1 = 1.0 + u * omc
            dw1 = 2 * C1 * (l1 - 1 / (l1**3 * eta**2)) + 2 * C2 * (l1 * eta**2 - 1 / l1**3)
            dw2 = 2 * C1 * (eta - 1 / (l1**2 * eta**3)) + 2 * C2 * (l1**2 * eta - 1 / eta**3)
            return dw1 * (R + k * dR) * omc + dw2 * dR / R0

        m_air = pa * math.pi * ((2 * R + 3 * k * R * R) * dR + R**3)
        return m_air - p.area * (1.0 + u) * mean(dW) - p.EI * k
    lbar = 1.0 + u
    tb = p.t0 / (lbar * eta)
    le2 = (lbar * eta) ** 2
    J = tp * mean(lambda f: (1 + u * (1 - math.cos(f))) ** 2 * (1 - math.cos(f))
                  / (1 - (c * (1 + u * (1 - math.cos(f)))) ** 2))
    var = tp * mean(lambda f: (2 * C1 * (1 + u * (1 - math.cos(f))) ** 2 - 2 * C2 / (1 + u * (1 - math.cos(f))) ** 2)
                    * (1 - math.cos(f)))
    k1 = -2 * C1 / le2 + 2 * C2 * le2
    s2 = 2 * C1 * (eta**2 - 1 / le2) - 2 * C2 * (1 / eta**2 - le2)
    m_bl = tb * R * R * (var + tp * k1)
    return pa * math.pi * R**3 - p.EI * k - m_bl - (pa * R - s2 * tb) * R * R * c * c * J
