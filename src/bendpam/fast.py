"""Fast evaluation of the moment models from cached per-actuator tables.

Why tables
    Both models are affine in the active pressure, ``M = P_a A(k') - B(k')``, and ``A``, ``B``
    depend on the curvature only (for one actuator and model).  So the expensive part, eq 5 and the
    section integrals, is a function of one variable.  :class:`MomentTable` tabulates it once
    (exact path, 64 Gauss nodes on [0, pi]) at Chebyshev-distributed knots over the whole
    admissible range (the knots cluster toward the lock-up limits, where the functions steepen),
    and interpolates with a C2 cubic spline.  ``B`` is tabulated as ``G = B / k'`` (``B(0) = 0``),
    so the elastic term keeps its relative accuracy near the straight state.

Error control
    With the default 2049 knots the interpolation error, measured at build time against the exact
    path at every knot interval's midpoint, is below 1e-6 of the size of the terms
    ``|P_a A| + |B|`` for the paper's actuators (typically 1e-7); :attr:`MomentTable.max_rel_error`
    reports the measured bound, and a table whose bound exceeds ``tol`` is refined (knots doubled)
    until it meets it.  The exact path :func:`bendpam.moment` is unchanged; this is an opt-in fast
    path, checked against it in ``tests/test_fast.py`` over a hypothesis-drawn domain.

Speed
    Evaluation is a gather of 4 x 2 cubic coefficients per point (the interval index comes from
    ``arccos`` of the Chebyshev map, no search) and two Horner steps: several million scattered
    (P, k') pairs per second in one process (``benchmarks/bench_models.py``).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from scipy.interpolate import CubicSpline

from .actuator import Actuator
from .braid import curvature_limits
from .models import get_model
from .predict import FreeBending, _pressure, assemble_free_bending, branch_info
from .presets import normalise_model

__all__ = ["MomentTable", "moment_table"]

_TABLE_ORDER = 64


class MomentTable:
    """Cubic-spline tables of ``A(k')`` and ``G(k') = B(k') / k'`` for one actuator and model.

    Parameters
    ----------
    actuator : Actuator
    model : ``"energy"`` or ``"force_balance"``
    knots : initial number of Chebyshev knots (odd numbers include the centre).
    tol : target bound of the relative interpolation error (relative to ``|P_a A| + |B|``).
    eq19_factor : energy model option, as in :func:`bendpam.moment`.
    """

    def __init__(self, actuator: Actuator, model: str = "energy", *, knots: int = 2049, tol: float = 1e-6,
                 eq19_factor: bool = True, max_knots: int = 65537):
        if not isinstance(actuator, Actuator):
            raise TypeError(f"actuator must be a bendpam.Actuator, got {type(actuator).__name__}")
        self.actuator = actuator
        self.model = normalise_model(model)
        self.eq19_factor = bool(eq19_factor)
        self._mod = get_model(self.model)
        self.limits = curvature_limits(actuator)
        n = int(knots)
        while True:
            self._build(n)
            if self.max_rel_error <= tol or n >= max_knots:
                break
            n = 2 * n - 1
        self.knots = n

    # ---- construction ---------------------------------------------------------------------------
    def _exact(self, k):
        A, B = self._mod.coefficients(self.actuator, k, order=_TABLE_ORDER, eq19_factor=self.eq19_factor)
        return A, B

    def _g(self, k, B):
        """B / k, with the limit B'(0) at k = 0 (fourth-order central difference)."""
        G = np.empty_like(B)
        nz = np.abs(k) > 1e-12 * self._h
        G[nz] = B[nz] / k[nz]
        if np.any(~nz):
            h = 1e-4 * self._h
            kk = np.array([-2 * h, -h, h, 2 * h])
            _, Bh = self._exact(kk)
            G[~nz] = (Bh[0] - 8 * Bh[1] + 8 * Bh[2] - Bh[3]) / (12 * h)
        return G

    def _build(self, n: int) -> None:
        lo, hi = self.limits.k_min, self.limits.k_max
        self._c, self._h = 0.5 * (hi + lo), 0.5 * (hi - lo)
        kj = self._c - self._h * np.cos(np.linspace(0.0, np.pi, n))
        kj[0], kj[-1] = lo, hi
        A, B = self._exact(kj)
        G = self._g(kj, B)
        spl = CubicSpline(kj, np.stack([A, G], axis=-1))
        self._kj = kj
        self._coef = np.ascontiguousarray(np.moveaxis(spl.c, 0, -2))  # (n-1, 4, 2)
        self._dspl = spl.derivative()
        self._n = n
        # error estimate at the interval midpoints, against the exact path
        km = 0.5 * (kj[1:] + kj[:-1])
        Ae, Be = self._exact(km)
        Af, Bf = self.coefficients(km)
        P_scale = 0.5  # MPa: the error bound covers active pressures up to 500 kPa
        scale = P_scale * np.abs(Ae) + np.abs(Be) + 1e-300
        self.max_rel_error = float(np.max((P_scale * np.abs(Af - Ae) + np.abs(Bf - Be)) / scale))

    # ---- evaluation -----------------------------------------------------------------------------
    def _interval(self, k):
        t = np.clip((self._c - k) / self._h, -1.0, 1.0)  # cos(theta), theta in [0, pi]
        j = np.floor(np.arccos(t) * ((self._n - 1) / np.pi)).astype(np.intp)
        np.clip(j, 0, self._n - 2, out=j)
        return j

    def coefficients(self, curvature):
        """Interpolated ``(A, B)`` at ``curvature`` (1/mm); no range check."""
        k = np.asarray(curvature, dtype=float)
        j = self._interval(k)
        c = self._coef[j]  # (..., 4, 2)
        dx = (k - self._kj[j])[..., None]
        v = ((c[..., 0, :] * dx + c[..., 1, :]) * dx + c[..., 2, :]) * dx + c[..., 3, :]
        return v[..., 0], k * v[..., 1]

    def _check(self, curvature):
        k = np.asarray(curvature, dtype=float)
        self.limits.check(k)
        return k

    def moment(self, pressure, curvature):
        """``M(P, k')`` in N*mm (P in MPa, k' in 1/mm), broadcasting; same validation as the exact path."""
        p = np.maximum(_pressure(pressure) - self.actuator.P_start, 0.0)
        k = self._check(curvature)
        A, B = self.coefficients(k)
        return p * A - B

    __call__ = moment

    def tangent_stiffness(self, pressure, curvature):
        """``dM/dk'`` (N*mm^2) from the spline derivatives."""
        p = np.maximum(_pressure(pressure) - self.actuator.P_start, 0.0)
        k = self._check(curvature)
        _, G = self._split(k)
        dA, dG = np.moveaxis(self._dspl(k), -1, 0)
        return p * dA - (G + k * dG)

    def _split(self, k):
        j = self._interval(k)
        c = self._coef[j]
        dx = (k - self._kj[j])[..., None]
        v = ((c[..., 0, :] * dx + c[..., 1, :]) * dx + c[..., 2, :]) * dx + c[..., 3, :]
        return v[..., 0], v[..., 1]

    def free_curvature(self, pressure, *, newton_steps: int = 6) -> FreeBending:
        """Free-bending curvature from the tables: same branch logic as :func:`bendpam.free_curvature`.

        Starts from the sampled branch (monotone ``p(k') = B/A``) and polishes with safeguarded
        Newton steps on the interpolated moment.
        """
        act = self.actuator
        P = _pressure(pressure)
        br = branch_info(act, self.model, eq19_factor=self.eq19_factor)
        kt, pt = br.k_table, br.p_table
        finite = np.isfinite(pt)
        d = br.direction

        def solve(q):
            x = np.interp(q, pt[finite], kt[finite])
            j = np.clip(np.searchsorted(pt, q), 1, kt.size - 1)
            lo, hi = np.minimum(kt[j - 1], kt[j]), np.maximum(kt[j - 1], kt[j])
            for _ in range(newton_steps):
                A, G = self._split(x)
                f = q * A - x * G
                # d f > 0 before the root along the branch, < 0 after it: shrink the bracket
                ahead = d * f > 0
                if d > 0:
                    lo, hi = np.where(ahead, x, lo), np.where(~ahead, x, hi)
                else:
                    hi, lo = np.where(ahead, x, hi), np.where(~ahead, x, lo)
                dA, dG = np.moveaxis(self._dspl(x), -1, 0)
                xn = x - f / (q * dA - (G + x * dG))
                x = np.where((xn >= lo) & (xn <= hi), xn, 0.5 * (lo + hi))
            return x

        return assemble_free_bending(act, P, br, solve)


@lru_cache(maxsize=64)
def _cached(actuator: Actuator, model: str, eq19_factor: bool) -> MomentTable:
    return MomentTable(actuator, model, eq19_factor=eq19_factor)


def moment_table(actuator: Actuator, model: str = "energy", *, eq19_factor: bool = True) -> MomentTable:
    """The cached :class:`MomentTable` of ``actuator`` and ``model`` (built on first use)."""
    return _cached(actuator, normalise_model(model), bool(eq19_factor))
