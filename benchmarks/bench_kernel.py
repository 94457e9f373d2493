"""The fast path's kernels (issue 24 item 4), side by side with the 0.4.0 code on the same tables.

Candidates, on N random pairs (default 10^6; k' uniform over the admissible range, P uniform on
0-300 kPa) and on one pressure for N curvatures, interleaved, for BE-PAM energy and BC-PAM
force-balance:

* ``main``: the fast path of the 0.4.0 main branch (``MomentTable.moment`` and ``_moment_kernel`` as
  they were, copied verbatim below as :func:`main_moment`, on this table's spline coefficients):
  ``check_pressure`` and ``check_curvature`` (about eight passes), then 8192-point blocks;
* ``before``: ``MomentTable.moment`` with ``BENDPAM_KERNEL=numpy`` and the NumPy kernel as it was
  before this pass of tuning (commit 7e1a5ed, copied verbatim below as :class:`BeforeKernel`):
  a guess of the interval through ``np.where`` and ``np.clip``, Python-float constants, ``np.take``;
* ``numpy``: ``MomentTable.moment`` with ``BENDPAM_KERNEL=numpy`` (one min and one max per input,
  8192-point blocks);
* ``numba``: the same with ``BENDPAM_KERNEL=numba`` (the compiled loop, one core);
* ``cubicspline``: SciPy's ``CubicSpline`` through the same knots and values (the strongest
  library baseline of issue 24; no input checks), ``M = P_a A - k' G``.

Each is timed by the wall clock (median of the repeats; the machine is shared, so the min is
shown too) and by the CPU time of the process (``time.process_time``, the median: what one core
spends, whatever else runs; every candidate runs on one thread), with ``bench_reader.interleaved``.
The results are checked: numba against numpy bit for bit, both against ``main`` (which may pick
the neighbouring interval at a knot: differences of a few units in the last place).  The first use
of numba is measured in fresh processes: ``import numba``, the first call with an empty cache
(compilation), and the first call with the cache written.

Run: ``python benchmarks/bench_kernel.py [--quick]``.
"""

from __future__ import annotations

import copy
import json
import math
import os
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _timing import Recorder, header, standalone
from bench_reader import interleaved

import bendpam
from bendpam.physics.kernel import CHUNK, KERNEL_ENV, SplineKernel

CASES = [("be-pam", "energy"), ("bc-pam", "force_balance")]
P_MAX_KPA = 300.0
TARGET_NUMBA = 1e8
TARGET_NUMPY = 5e7


def main_moment(table, pressure_kpa, curvature_per_mm):
    """``MomentTable.moment`` of the 0.4.0 main branch (commit e774cb2), verbatim but for the table's attributes."""
    p = table.law.check_pressure(pressure_kpa)
    k = table.law.check_curvature(curvature_per_mm)
    shape = np.broadcast_shapes(p.shape, k.shape)
    pf = np.ascontiguousarray(np.broadcast_to(p, shape), dtype=float).reshape(-1)
    kf = np.ascontiguousarray(np.broadcast_to(k, shape), dtype=float).reshape(-1)
    out = np.empty(kf.size)
    _main_kernel(table, pf, kf, out)
    return out.reshape(shape)


def _main_kernel(table, P, k, out, chunk: int = 8192) -> None:
    """``MomentTable._moment_kernel`` of the 0.4.0 main branch, verbatim."""
    n1 = table._n - 1
    scale = n1 / np.pi
    inv_lo, inv_hi = 1.0 / table._lo, 1.0 / table._hi
    kj = table._kj
    a3, a2, a1, a0, g3, g2, g1, g0 = (np.ascontiguousarray(table.kernel.coef[:, i]) for i in range(8))  # main's _c8
    last = kj.size - 2
    for s0 in range(0, k.size, chunk):
        kk = k[s0:s0 + chunk]
        r = np.where(kk < 0.0, kk * inv_lo, kk * inv_hi)
        np.multiply(r, -2.0, out=r)
        r += 1.0
        np.clip(r, -1.0, 1.0, out=r)
        th = np.arccos(r)
        th *= scale
        np.copysign(th, kk, out=th)
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
        pa = P[s0:s0 + chunk] - table.P_start_kpa
        np.maximum(pa, 0.0, out=pa)
        A *= pa
        G *= kk
        np.subtract(A, G, out=out[s0:s0 + chunk])


class BeforeKernel(SplineKernel):
    """``SplineKernel``'s NumPy kernel of commit 7e1a5ed (before this tuning), verbatim but for the names."""

    def __init__(self, kern: SplineKernel):
        super().__init__(kern.knots_per_mm, kern.coef, kern.P_start_kpa)
        kj = self.knots_per_mm
        self._m_lo, self._m_hi = -2.0 / float(kj[0]), -2.0 / float(kj[-1])
        self._scale, self._shift = self._n1 / math.pi, self._n1 - 0.5

    def _interval_before(self, kk: np.ndarray) -> np.ndarray:
        r = np.where(kk < 0.0, kk * self._m_lo, kk * self._m_hi)  # -2 k / (lock-up limit on k's side)
        r += 1.0
        np.clip(r, -1.0, 1.0, out=r)
        th = np.arccos(r)
        th *= self._scale
        np.copysign(th, kk, out=th)  # k < 0: n1 - th (left piece), k >= 0: n1 + th
        th += self._shift
        j = th.astype(np.intp)  # in [0, intervals): th is in [-0.5, 2 n1 - 0.5] up to rounding
        j += kk >= np.take(self._next, j)
        return j

    def _moment_numpy(self, P, k, out) -> None:
        z3, z2, z1, z0 = self._zcols
        kj, Ps = self.knots_per_mm, self.P_start_kpa
        pa_all = max(float(P[0]) - Ps, 0.0) if P.size == 1 else None
        for s0 in range(0, k.size, CHUNK):
            kk = k[s0:s0 + CHUNK]
            j = self._interval_before(kk)
            dx = (kk - np.take(kj, j)).astype(complex)
            V = np.take(z3, j)
            V *= dx
            V += np.take(z2, j)
            V *= dx
            V += np.take(z1, j)
            V *= dx
            V += np.take(z0, j)
            A, G = V.real, V.imag
            if pa_all is None:
                pa = P[s0:s0 + CHUNK] - Ps
                np.maximum(pa, 0.0, out=pa)
                A *= pa
            else:
                A *= pa_all
            G *= kk
            np.subtract(A, G, out=out[s0:s0 + CHUNK])


def _with_kernel(name, fn):
    def run():
        old = os.environ.get(KERNEL_ENV)
        os.environ[KERNEL_ENV] = name
        try:
            return fn()
        finally:
            if old is None:
                os.environ.pop(KERNEL_ENV, None)
            else:
                os.environ[KERNEL_ENV] = old
    return run


def _case(rec: Recorder, name: str, model: str, n: int, reps: int) -> dict:
    from scipy.interpolate import CubicSpline

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the constants were fitted with the other model
        law = bendpam.MomentLaw.of(bendpam.physics.presets.get(name, model), model)
    tab = law.tabulated()
    lim = law.limits
    rng = np.random.default_rng(0)
    k = rng.uniform(lim.k_min, lim.k_max, n)
    P = rng.uniform(0.0, P_MAX_KPA, n)
    kj = tab.knot_curvatures
    v, _ = tab._eval(kj, False)  # A and G = B/k' at the knots
    spl = CubicSpline(kj, v)
    Ak, Bk = tab.coefficients(k)
    Ps = tab.P_start_kpa
    before = copy.copy(tab)
    before.kernel = BeforeKernel(tab.kernel)

    def cubic(P=P):
        v = spl(k)
        return np.maximum(P - Ps, 0.0) * v[:, 0] - k * v[:, 1]

    out = {}
    for label, PP in (("random P", P), ("one P", 150.0)):
        cands = {"main": lambda PP=PP: main_moment(tab, PP, k),
                 "before": _with_kernel("numpy", lambda PP=PP: before.moment(PP, k)),
                 "numpy": _with_kernel("numpy", lambda PP=PP: tab.moment(PP, k)),
                 "numba": _with_kernel("numba", lambda PP=PP: tab.moment(PP, k)),
                 "cubicspline": lambda PP=PP: cubic(PP)}
        wall, cpu = interleaved(cands, reps, n)
        st = {c: {"wall_median_s": wall[c].median, "wall_min_s": wall[c].min, "cpu_median_s": cpu[c].median,
                  "cpu_min_s": cpu[c].min, "cpu_max_s": cpu[c].max} for c in cands}
        m_np, m_nb, m_main = cands["numpy"](), cands["numba"](), cands["main"]()
        same_before = bool(np.array_equal(m_np, cands["before"]()))
        scale = np.abs(np.maximum(np.asarray(PP) - Ps, 0.0) * Ak) + np.abs(Bk)
        scale = np.maximum(scale, 1e-3 * np.median(scale))
        check = {"numba_equals_numpy": bool(np.array_equal(m_np, m_nb)), "numpy_equals_before": same_before,
                 "points_differing_from_main": int(np.count_nonzero(m_np != m_main)),
                 "max_rel_diff_from_main": float(np.max(np.abs(m_np - m_main) / scale)),
                 "max_rel_diff_cubicspline": float(np.max(np.abs(cands["cubicspline"]() - m_np) / scale))}
        print(f"{name + ' ' + model:20} {label:9}" + "".join(
            f" {c}: {n / s['cpu_median_s']:.3g}/s cpu ({n / s['wall_median_s']:.3g} wall)" for c, s in st.items()))
        print(f"{'':30} NumPy kernel before -> now, CPU rate of the median (slowest) repeat: "
              f"{n / st['before']['cpu_median_s']:.3g} ({n / st['before']['cpu_max_s']:.3g}) -> "
              f"{n / st['numpy']['cpu_median_s']:.3g} ({n / st['numpy']['cpu_max_s']:.3g}) /s")
        print(f"{'':30} numba == numpy bit for bit: {check['numba_equals_numpy']}, numpy == before: {same_before}; "
              f"differs from main at {check['points_differing_from_main']} of {n} points, by at most "
              f"{check['max_rel_diff_from_main']:.1e} (relative to |P_a A| + |B|); CubicSpline within "
              f"{check['max_rel_diff_cubicspline']:.1e}")
        rec.record("kernel", f"{name}/{model}/{label}", {"n": n, "timing": st, "check": check})
        out[label] = {c: n / s["cpu_median_s"] for c, s in st.items()} | {
            "ok": check["numba_equals_numpy"], "same_before": same_before}
    return out


FIRST_USE = r"""
import time, json, numpy as np
t0 = time.perf_counter(); import numba; t_imp = time.perf_counter() - t0
import bendpam
t = bendpam.MomentLaw.of(bendpam.physics.presets.be_pam()).tabulated()
k = np.linspace(-0.01, 0.01, 1000); P = np.full(1000, 150.0); out = np.empty(1000)
t0 = time.perf_counter()
t.kernel.evaluate(P, k, out, 2000.0, -0.02, 0.02, "numba")
print(json.dumps({"import_numba_s": t_imp, "first_call_s": time.perf_counter() - t0}))
"""


def first_use(rec: Recorder) -> dict:
    """``import numba`` and the first compiled call in fresh processes: empty cache, then the cache written."""
    res = {}
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "PYTHONPATH": os.pathsep.join(sys.path)}
        for label in ("empty cache (compiles)", "cache written (loads)"):
            r = subprocess.run([sys.executable, "-c", FIRST_USE], env=env, capture_output=True, text=True, check=True)
            res[label] = json.loads(r.stdout.strip().splitlines()[-1])
            print(f"numba first use, {label}: import numba {res[label]['import_numba_s']:.2f} s, "
                  f"first call {res[label]['first_call_s']:.2f} s")
    rec.record("kernel", "first_use", res)
    return res


def run(rec: Recorder, quick: bool = False) -> None:
    n = 200_000 if quick else 1_000_000
    reps = 5 if quick else 15
    header(f"Fast-path kernels: {n:,} points, main (0.4.0) vs before vs numpy vs numba vs CubicSpline, {reps} "
           "interleaved repeats; rates per second of one core's CPU time (median), wall-clock rate in brackets")
    rates = [_case(rec, name, model, n, reps) for name, model in CASES]
    worst = {c: min(r[lab][c] for r in rates for lab in r) for c in ("main", "before", "numpy", "numba", "cubicspline")}
    ident = all(r[lab]["ok"] for r in rates for lab in r)
    same = all(r[lab]["same_before"] for r in rates for lab in r)
    rec.row("fast path, numba kernel (one core, CPU time)", worst["numba"], "evals/s", f">= {TARGET_NUMBA:.0e}",
            worst["numba"] >= TARGET_NUMBA, "worst of 2 actuators x random/one P")
    rec.row("fast path, NumPy kernel (CPU time)", worst["numpy"], "evals/s", f">= {TARGET_NUMPY:.0e}",
            worst["numpy"] >= TARGET_NUMPY, f"before: {worst['before']:.3g}/s, main 0.4.0: {worst['main']:.3g}/s")
    rec.row("NumPy kernel: same results as before", "yes" if same else "NO", "", "identical", same)
    rec.row("numba vs NumPy kernel: bit-identical", "yes" if ident else "NO", "", "identical", ident)
    rec.row("NumPy kernel vs CubicSpline (same knots)", worst["numpy"] / worst["cubicspline"], "x", "", None,
            f"numba {worst['numba'] / worst['cubicspline']:.3g} x")
    fu = first_use(rec)
    rec.row("numba first call, empty cache", fu["empty cache (compiles)"]["first_call_s"], "s", "", None,
            "once per machine and bendpam version")
    rec.row("numba import + cached load", fu["cache written (loads)"]["import_numba_s"]
            + fu["cache written (loads)"]["first_call_s"], "s", "", None, "once per process, on first large call")


if __name__ == "__main__":
    standalone(run, "kernel")
