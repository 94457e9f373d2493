"""Processed cyclic tests made with a loop law that is NOT bendpam's (for the identification tests).

bendpam fits a Prandtl-Ishlinskii (or Dahl) loop; the round trips here must not hand it data made
by the same law, nor by ``bendpam.lab.simulate`` (which uses bendpam's laws).  This module builds
:class:`~bendpam.lab.processing.PressureResult` objects directly from the quasi-static model
curves of a known actuator plus a **Bouc-Wen** loop, written here from its textbook form:

    dz/dx = s - beta_bw |z|^(n-1) z - gamma_bw s |z|^n,     s = sign(dx),  x = theta / theta_c

with ``beta_bw + gamma_bw = 1`` so that ``z`` saturates at ``+-1`` (Ismail, Ikhouane and Rodellar,
"The hysteresis Bouc-Wen model, a survey", Arch. Comput. Methods Eng. 16 (2009), eq 2-3).  The
moment is ``M = M_qs(P, k') - A(P) z`` with ``A = frac * |M_qs(P, 0)| + offset_nmm``; ``z`` starts at
-1 (the blocked state reached by a long loading, as in a real test) and is integrated along the
bending angle ``theta = |k'| L0`` with fourth-order Runge-Kutta steps.

The machine's free state is the first zero of the unloading branch (the test reverses there); each
cycle then runs blocked -> free -> blocked.  Noise: Gaussian, smoothed along each branch by a
5-point moving average (the processing's low-pass makes real residuals correlated), ``noise_nmm``
its standard deviation after smoothing.
"""

from __future__ import annotations

import math

import numpy as np

import bendpam
from bendpam.lab.processing import PressureResult, ProcessedSet, ProcessingOptions
from bendpam.physics.fixture import PAPER_FIXTURE

__all__ = ["BoucWen", "GeometricPI", "LoopTruth", "make_truth", "noisy_set"]


class BoucWen:
    """Rate-independent Bouc-Wen law with characteristic angle ``theta_c_rad`` and exponent ``n``."""

    def __init__(self, theta_c_rad: float = math.radians(4.0), n: float = 1.5, beta_bw: float = 0.75,
                 steps: int = 600):
        self.theta_c = float(theta_c_rad)
        self.n = float(n)
        self.beta = float(beta_bw)
        self.gamma = 1.0 - self.beta
        self.steps = int(steps)

    def _rate(self, z, s):
        az = np.abs(z)
        return s - self.beta * az ** (self.n - 1.0) * z - self.gamma * s * az**self.n

    def run(self, z0, span_rad, s: float, n_steps: int):
        """``z`` at ``n_steps + 1`` equally spaced points of a monotone motion of ``span_rad`` (per row)."""
        z = np.array(z0, dtype=float)
        span = np.asarray(span_rad, dtype=float)
        h = span / self.theta_c / n_steps
        out = np.empty((n_steps + 1, *z.shape))
        out[0] = z
        for i in range(n_steps):
            k1 = self._rate(z, s)
            k2 = self._rate(z + 0.5 * h * k1, s)
            k3 = self._rate(z + 0.5 * h * k2, s)
            k4 = self._rate(z + h * k3, s)
            z = np.clip(z + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4), -1.0, 1.0)
            out[i + 1] = z
        return out

    def first_unloading(self, theta_max: float, n: int):
        """``z`` at ``n`` equally spaced angles of ``[0, theta_max]`` leaving the saturated blocked state."""
        return self.run(-np.ones(1), np.array([theta_max]), 1.0, n - 1)[:, 0]

    def cycles(self, span_rad, cycles: int, n_grid: int):
        """``(z_unloading, z_loading)``, each ``(n_P, cycles, n_grid)`` on the grid from the blocked state."""
        span = np.asarray(span_rad, dtype=float)
        stride = self.steps // (n_grid - 1)
        steps = stride * (n_grid - 1)
        z = -np.ones(span.size)
        zu = np.empty((span.size, cycles, n_grid))
        zl = np.empty_like(zu)
        for c in range(cycles):
            zz = self.run(z, span, 1.0, steps)[::stride]  # blocked -> free
            zu[:, c] = zz.T
            z = zz[-1]
            zz = self.run(z, span, -1.0, steps)[::stride]  # free -> blocked
            zl[:, c] = zz.T[:, ::-1]
            z = zz[-1]
        return zu, zl


class GeometricPI:
    """A Prandtl-Ishlinskii sum of ``n`` stop operators with geometrically spaced thresholds, equal weights.

    bendpam's law spaces its thresholds uniformly and weights each by its threshold; here
    ``r_j = r_min q^j`` up to ``theta_max_rad / 2`` with equal weights, so the loop's shape differs.
    """

    def __init__(self, theta_max_rad: float = math.radians(10.0), n: int = 12, r_min_rad: float = math.radians(0.1)):
        self.r = np.geomspace(r_min_rad, 0.5 * theta_max_rad, n)

    def _z(self, s):
        return s.sum(-1) / self.r.sum()

    def first_unloading(self, theta_max: float, n: int):
        th = np.linspace(0.0, theta_max, n)
        return self._z(np.clip(-self.r + th[:, None], -self.r, self.r))

    def cycles(self, span_rad, cycles: int, n_grid: int):
        span = np.asarray(span_rad, dtype=float)[:, None, None]
        t = np.linspace(0.0, 1.0, n_grid)[None, :, None] * span  # distance from the blocked state
        s = np.broadcast_to(-self.r, (span.shape[0], 1, self.r.size))
        zu = np.empty((span.shape[0], cycles, n_grid))
        zl = np.empty_like(zu)
        for c in range(cycles):
            up = np.clip(s + t, -self.r, self.r)  # blocked -> free
            zu[:, c] = self._z(up)
            s_free = up[:, -1:, :]
            down = np.clip(s_free - (span - t), -self.r, self.r)  # free -> blocked, at distance t from blocked
            zl[:, c] = self._z(down)
            s = down[:, :1, :]
        return zu, zl


class LoopTruth:
    """Noise-free cycles of one actuator at several pressures (magnitudes, N*mm and 1/mm)."""

    def __init__(self, actuator, model, pressures, grid, loading, unloading, kf, A):
        self.actuator, self.model = actuator, model
        self.pressures = np.asarray(pressures, float)
        self.grid, self.loading, self.unloading = grid, loading, unloading  # (nP, n), (nP, cycles, n)
        self.kf, self.A = kf, A

    @property
    def shear_modulus_kpa(self) -> float:
        return 2.0 * (self.actuator.C10_kpa + self.actuator.C01_kpa)


def make_truth(actuator, pressures, model="energy", *, law=None, frac=0.05, offset_nmm=1.0, cycles=3,
               n_grid=101) -> LoopTruth:
    """The noise-free cycles (see the module notes)."""
    law = law or BoucWen()
    s = actuator.bend_sign or 1
    L0 = actuator.L0_mm
    P = np.asarray(pressures, float)
    lim = bendpam.curvature_limits(actuator)
    k_lim = 0.95 * abs(lim.k_max if s > 0 else lim.k_min)
    law_m = bendpam.MomentLaw.of(actuator, model)
    Mb = np.abs(law_m.moment(P, 0.0))
    A = frac * Mb + offset_nmm
    # 1. free state: first zero of the unloading branch from the saturated blocked state
    kk = np.linspace(0.0, k_lim, 4001)
    z_un = law.first_unloading(k_lim * L0, kk.size)
    kf = np.empty(P.size)
    for i, p in enumerate(P):
        m = s * law_m.moment(p, s * kk) - A[i] * z_un
        j = int(np.flatnonzero(m <= 0.0)[0])
        kf[i] = kk[j - 1] + (kk[j] - kk[j - 1]) * m[j - 1] / (m[j - 1] - m[j])
    # 2. cycles on the grid [0, kf]
    grid = np.linspace(0.0, 1.0, n_grid)[None, :] * kf[:, None]
    mqs = np.stack([s * law_m.moment(p, s * grid[i]) for i, p in enumerate(P)])
    zu, zl = law.cycles(kf * L0, cycles, n_grid)
    low = mqs[:, None, :] - A[:, None, None] * zu
    up = mqs[:, None, :] - A[:, None, None] * zl
    return LoopTruth(actuator, model, P, grid, up, low, kf, A)


def _smooth_noise(rng, shape, sd):
    e = rng.normal(0.0, 1.0, (*shape[:-1], shape[-1] + 4))
    m = (e[..., :-4] + e[..., 1:-3] + e[..., 2:-2] + e[..., 3:-1] + e[..., 4:]) / math.sqrt(5.0)
    return sd * m


def noisy_set(truth: LoopTruth, seed: int, noise_nmm: float = 0.3) -> ProcessedSet:
    """A :class:`ProcessedSet` of the truth's cycles with noise (a new draw per seed)."""
    rng = np.random.default_rng(seed)
    L0 = truth.actuator.L0_mm  # the paper's fixture has the same active length
    res = []
    for i, p in enumerate(truth.pressures):
        g = truth.grid[i]
        up = truth.loading[i] + _smooth_noise(rng, truth.loading[i].shape, noise_nmm)
        low = truth.unloading[i] + _smooth_noise(rng, truth.unloading[i].shape, noise_nmm)
        n = up.shape[0]
        br = np.stack([up, low], axis=1)  # (cycles, 2, n)
        bm = up[:, 0].copy()
        kf = truth.kf[i] + rng.normal(0.0, 1e-3 * truth.kf[i], n)
        th = g * L0
        loss = np.trapezoid(up - low, th, axis=-1)
        stored = np.trapezoid(0.5 * (up + low), th, axis=-1)
        res.append(PressureResult(float(p), f"bouc-wen {p:g} kPa", n, g.copy(), br, bm, kf, loss / stored, loss,
                                  stored, 20.0, 1.0))
    return ProcessedSet(res, PAPER_FIXTURE, ProcessingOptions())
