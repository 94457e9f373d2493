"""Model-evaluation benchmarks (issue 5): speed, accuracy and peak memory, with baselines run side by side.

For each preset (BE-PAM, BC-PAM) and model (energy, force-balance):

* scattered evaluation of ``M(P, k')`` on N random pairs (default 10^6):
  - ``fast``: :class:`bendpam.fast.MomentTable` (spline tables, built once per actuator; build time
    reported separately),
  - ``exact``: :func:`bendpam.moment` (vectorised safeguarded Newton for eq 5, 32 Gauss nodes),
  - ``numpy``: a plain vectorised NumPy implementation of the kind one writes first (uniform
    trapezoid rule with 256 nodes, bisection for eq 5 from a fixed bracket, finite-difference
    dR/dk') -- written here, independent of bendpam,
  - ``per-point``: the researcher's per-point loop (``scipy.integrate.quad`` for the integrals,
    ``brentq`` for eq 5, finite differences for the derivatives), timed on a few hundred points
    and reported per second;
  - maximum error of each against a 256-node reference (order 128 on [0, pi]), relative to
    ``|P_a A| + |B|`` (the size of the two terms; M itself crosses zero), floored at 0.1 % of the
    median of that size (B also crosses zero, away from k' = 0, in the force-balance model);
* a dense P x k' grid (1000 x 1000), against the cost of its kinematics alone;
* free-bending solves per second (exact and fast paths).

Run: ``python benchmarks/bench_models.py [--n 1000000]``.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq

import bendpam
from bendpam import presets
from bendpam.fast import MomentTable
from bendpam.models import get_model

sys.path.insert(0, str(Path(__file__).parent))
from _timing import measure  # noqa: E402


# ---------------------------------------------------------------------------------------------
# baseline 1: per-point, quad + brentq (how the models are usually coded first)
# ---------------------------------------------------------------------------------------------
def _pp_radius(a, k):
    c, s, R0 = math.cos(a.alpha0), math.sin(a.alpha0), a.R0_start

    def xi(u):
        val = quad(lambda f: 1.0 / math.sqrt(1.0 - (c * (1.0 + u * (1.0 - math.cos(f)))) ** 2), 0.0, 2 * math.pi)[0]
        return 2 * math.pi / (s * val)

    if k == 0.0:
        return R0
    lo, hi = (0.0, 0.999 * (1 / c - 1) / 2) if k > 0 else (-0.4999, 0.0)
    u = brentq(lambda uu: uu - k * R0 * xi(uu), lo, hi, xtol=1e-14)
    return R0 * xi(u)


def per_point_moment(a, model, P, k):
    h = 1e-6
    R = _pp_radius(a, k)
    dR = (_pp_radius(a, k + h) - _pp_radius(a, k - h)) / (2 * h)
    pa = max(P - a.P_start, 0.0)
    c = math.cos(a.alpha0)
    C1, C2 = a.C10, a.C01
    if model == "energy":
        def U(kk):
            RR = _pp_radius(a, kk)
            eta = RR / a.R0_start

            def W(f):
                l1 = 1 + kk * RR * (1 - math.cos(f))
                l3 = 1 / (l1 * eta)
                return C1 * (l1**2 + eta**2 + l3**2 - 3) + C2 * (1 / l1**2 + 1 / eta**2 + 1 / l3**2 - 3)

            return a.bladder_area * quad(W, 0, 2 * math.pi)[0] / (2 * math.pi)

        dU = (U(k + h) - U(k - h)) / (2 * h)
        return math.pi * pa * ((2 * R + 3 * k * R * R) * dR + R**3) - (1 + k * R) * dU - a.frame_stiffness * k
    u = k * R
    eta = R / a.R0_start
    lbar = 1 + u
    tb = a.t0_start / (lbar * eta)
    le2 = (lbar * eta) ** 2
    J = quad(lambda f: (1 + u * (1 - math.cos(f))) ** 2 * (1 - math.cos(f)) /
             (1 - (c * (1 + u * (1 - math.cos(f)))) ** 2), 0, 2 * math.pi)[0]
    var = quad(lambda f: (2 * C1 * (1 + u * (1 - math.cos(f))) ** 2 - 2 * C2 / (1 + u * (1 - math.cos(f))) ** 2)
               * (1 - math.cos(f)), 0, 2 * math.pi)[0]
    const1 = -2 * C1 / le2 + 2 * C2 * le2
    sig2e = 2 * C1 * (eta**2 - 1 / le2) - 2 * C2 * (1 / eta**2 - le2)
    m_bl = tb * R * R * (var + 2 * math.pi * const1)
    return pa * math.pi * R**3 - a.frame_stiffness * k - m_bl - (pa * R - sig2e * tb) * R * R * c * c * J


# ---------------------------------------------------------------------------------------------
# baseline 2: plain vectorised NumPy (trapezoid, bisection, finite differences)
# ---------------------------------------------------------------------------------------------
def numpy_moment(a, model, P, k, n=256, iters=60):
    phi = np.linspace(0.0, 2 * np.pi, n + 1)[:-1]  # periodic trapezoid
    omc = 1 - np.cos(phi)
    c, s, R0 = math.cos(a.alpha0), math.sin(a.alpha0), a.R0_start

    def radius(kk):
        lo = np.where(kk >= 0, 0.0, -0.4999)
        hi = np.where(kk >= 0, 0.999 * (1 / c - 1) / 2, 0.0)
        for _ in range(iters):
            u = 0.5 * (lo + hi)
            lam = 1 + u[:, None] * omc
            xi = 1.0 / (s * np.mean(1 / np.sqrt(1 - (c * lam) ** 2), axis=1))
            f = u - kk * R0 * xi
            lo, hi = np.where(f < 0, u, lo), np.where(f < 0, hi, u)
        u = 0.5 * (lo + hi)
        lam = 1 + u[:, None] * omc
        return R0 / (s * np.mean(1 / np.sqrt(1 - (c * lam) ** 2), axis=1)), u

    h = 1e-7
    R, u = radius(k)
    dR = (radius(k + h)[0] - radius(k - h)[0]) / (2 * h)
    pa = np.maximum(P - a.P_start, 0.0)
    C1, C2 = a.C10, a.C01
    lam1 = 1 + u[:, None] * omc
    eta = (R / R0)[:, None]
    if model == "energy":
        def U(kk):
            RR, uu = radius(kk)
            l1 = 1 + uu[:, None] * omc
            e = (RR / R0)[:, None]
            l3 = 1 / (l1 * e)
            W = C1 * (l1**2 + e**2 + l3**2 - 3) + C2 * (1 / l1**2 + 1 / e**2 + 1 / l3**2 - 3)
            return a.bladder_area * W.mean(axis=1)

        dU = (U(k + h) - U(k - h)) / (2 * h)
        return np.pi * pa * ((2 * R + 3 * k * R * R) * dR + R**3) - (1 + u) * dU - a.frame_stiffness * k
    lbar = 1 + u
    e1 = eta[:, 0]
    tb = a.t0_start / (lbar * e1)
    le2 = (lbar * e1) ** 2
    J = 2 * np.pi * np.mean(lam1**2 * omc / (1 - (c * lam1) ** 2), axis=1)
    var = 2 * np.pi * np.mean((2 * C1 * lam1**2 - 2 * C2 / lam1**2) * omc, axis=1)
    const1 = -2 * C1 / le2 + 2 * C2 * le2
    sig2e = 2 * C1 * (e1**2 - 1 / le2) - 2 * C2 * (1 / e1**2 - le2)
    m_bl = tb * R * R * (var + 2 * np.pi * const1)
    return pa * np.pi * R**3 - a.frame_stiffness * k - m_bl - (pa * R - sig2e * tb) * R * R * c * c * J


# ---------------------------------------------------------------------------------------------
def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=1_000_000, help="scattered (P, k') pairs")
    ap.add_argument("--n-numpy", type=int, default=20_000, help="pairs for the plain NumPy baseline")
    ap.add_argument("--n-point", type=int, default=100, help="pairs for the per-point baseline")
    args = ap.parse_args()
    rows = []
    for name in ("be-pam", "bc-pam"):
        for model in ("energy", "force_balance"):
            a = presets.get(name, model)
            lim = bendpam.curvature_limits(a)
            rng = np.random.default_rng(0)
            k = rng.uniform(0.98 * lim.k_min, 0.98 * lim.k_max, args.n)
            P = rng.uniform(0.0, 0.3, args.n)
            t0 = time.perf_counter()
            table = MomentTable(a, model)
            t_build = time.perf_counter() - t0
            M_fast, t_fast, m_fast = measure(lambda: table.moment(P, k))
            n_ex = min(args.n, 200_000)
            M_ex, t_ex, m_ex = measure(lambda: bendpam.moment(a, P[:n_ex], k[:n_ex], model), repeat=1)
            n_np = args.n_numpy
            M_np, t_np, m_np = measure(lambda: numpy_moment(a, model, P[:n_np], k[:n_np]), repeat=1)
            n_pp = args.n_point
            t0 = time.perf_counter()
            M_pp = np.array([per_point_moment(a, model, float(P[i]), float(k[i])) for i in range(n_pp)])
            t_pp = time.perf_counter() - t0
            # errors against the 256-node reference
            n_ref = 100_000
            A, B = get_model(model).coefficients(a, k[:n_ref], order=128)
            pa = np.maximum(P[:n_ref] - a.P_start, 0.0)
            ref = pa * A - B
            terms = np.abs(pa * A) + np.abs(B)
            scale = np.maximum(terms, 1e-3 * np.median(terms))  # B and M cross zero: floor the scale

            def err(M, n):
                return float(np.max(np.abs(M[:n] - ref[:n]) / scale[:n]))

            rate = {"fast": args.n / t_fast, "exact": n_ex / t_ex, "numpy": n_np / t_np, "per-point": n_pp / t_pp}
            rows.append((name, model, rate, {"fast": err(M_fast, n_ref), "exact": err(M_ex, n_ref),
                                             "numpy": err(M_np, n_np), "per-point": err(M_pp, n_pp)},
                         {"fast": m_fast, "exact": m_ex, "numpy": m_np}, t_build))
    print(f"\nScattered M(P, k') evaluations ({args.n:,} random pairs over 98 % of the admissible range)")
    print(f"{'actuator':8} {'model':13} {'method':10} {'evals/s':>12} {'x per-point':>12} {'x numpy':>9} "
          f"{'max rel err':>12} {'peak MiB':>9}")
    for name, model, rate, errs, mem, t_build in rows:
        for meth in ("fast", "exact", "numpy", "per-point"):
            mm = f"{mem[meth]:9.0f}" if meth in mem else f"{'-':>9}"
            print(f"{name:8} {model:13} {meth:10} {rate[meth]:12.3g} {rate[meth] / rate['per-point']:12.0f} "
                  f"{rate[meth] / rate['numpy']:9.1f} {errs[meth]:12.1e} {mm}")
        print(f"{'':8} {'':13} table build {t_build * 1e3:.0f} ms (once per actuator and model)")

    # dense grid: affine in P, the cost is the kinematics of the curvature axis
    a = presets.be_pam()
    Pg = np.linspace(0.07, 0.3, 1000)
    kg = np.linspace(-0.04, 0.15, 1000)
    _, t_grid, m_grid = measure(lambda: bendpam.moment(a, Pg[:, None], kg[None, :]))
    _, t_kin, _ = measure(lambda: bendpam.kinematics(a, kg))
    print(f"\nDense grid 1000 x 1000 (exact path): {t_grid * 1e3:.1f} ms = {1e6 / t_grid:.3g} evals/s, "
          f"peak {m_grid:.0f} MiB; kinematics of the 1000 curvatures alone {t_kin * 1e3:.1f} ms "
          f"(grid / kinematics = {t_grid / t_kin:.1f})")

    # free bending
    for name in ("be-pam", "bc-pam"):
        a = presets.get(name)
        Pf = np.linspace(0.0, 0.3, 100_000)
        table = MomentTable(a)
        _, t_fast, m1 = measure(lambda: table.free_curvature(Pf))
        _, t_ex, m2 = measure(lambda: bendpam.free_curvature(a, Pf[:20000]), repeat=1)
        print(f"free bending {name}: fast {Pf.size / t_fast:.3g} /s (peak {m1:.0f} MiB), exact "
              f"{20000 / t_ex:.3g} /s (peak {m2:.0f} MiB)   (target >= 1e5 /s)")


if __name__ == "__main__":
    main()
