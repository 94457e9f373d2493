"""Identification and sweep benchmarks (issue 5).

* a full three-parameter fit (alpha0, C10, C01) from processed data at 6 pressures, both models,
  against the paper's "iterative identification procedure" taken as a plain Nelder-Mead search on
  the same objective with the exact model (the baseline, run side by side);
* sweep throughput in-process (cases/s, points/s) and the peak memory of a lazy sweep written to
  NetCDF block by block, against the memory its full result would need.

Run: ``python benchmarks/bench_fit_sweep.py``.
"""

from __future__ import annotations

import sys
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np
from scipy.optimize import minimize

import bendpam
from bendpam import presets
from bendpam.fixture import PAPER_FIXTURE
from bendpam.identify import fit, score
from bendpam.lab.processing import ProcessedSet, ProcessingOptions, process_series
from bendpam.lab.simulate import SimulationSettings, simulate_test

sys.path.insert(0, str(Path(__file__).parent))
from _timing import measure  # noqa: E402


def processed_set(truth, pressures, model):
    rng = np.random.default_rng(0)
    res = []
    for p in pressures:
        d, _ = simulate_test(truth, p, model, settings=SimulationSettings(), rng=rng)
        res.append(process_series(d.time_s.to_numpy(), d.stroke_mm.to_numpy(), d.force_n.to_numpy(), p,
                                  keep_series=False))
    return ProcessedSet(res, PAPER_FIXTURE, ProcessingOptions())


def main() -> None:
    print("Three-parameter fit (alpha0, C10, C01), 6 pressures (target < 0.5 s)")
    for name, P in (("bc-pam", [40, 60, 80, 100, 120, 140]), ("be-pam", [100, 120, 140, 160, 180, 200])):
        for model in ("energy", "force_balance"):
            base = presets.get(name, model)
            truth = base.replace(alpha0_deg=base.alpha0_deg + 0.8, C10_kpa=base.C10_kpa * 1.05)
            ps = processed_set(truth, P, model)
            r, best, mem = measure(lambda: fit(ps, base, model))
            r_all, best_all, _ = measure(lambda: fit(ps, base, model, fit_range="all"))
            # baseline: Nelder-Mead on the same eq-53 objective from the paper's start values
            t0 = time.perf_counter()
            nev = [0]

            def obj(x):
                nev[0] += 1
                try:
                    a = base.replace(alpha0_deg=x[0], C10_kpa=x[1], C01_kpa=x[2])
                    return score(ps, a, model).nrmse_cycles
                except ValueError:
                    return 1e9

            res = minimize(obj, [base.alpha0_deg, 114.0, 300.0], method="Nelder-Mead",
                           options={"maxfev": 400, "xatol": 1e-4, "fatol": 1e-9})
            t_nm = time.perf_counter() - t0
            print(f"  {name} {model:13}: bendpam fit {best:.3f} s, peak {mem:.0f} MiB (NRMSE {100 * r.metrics.nrmse_cycles:.2f} %, "
                  f"alpha0 {r.parameters['alpha0'].value:.3f} vs true {truth.alpha0_deg:.3f}); fit_range='all' "
                  f"{best_all:.3f} s (NRMSE {100 * r_all.metrics.nrmse_cycles:.2f} %, alpha0 "
                  f"{r_all.parameters['alpha0'].value:.3f});  Nelder-Mead baseline {t_nm:.2f} s, {nev[0]} "
                  f"evaluations, NRMSE {100 * res.fun:.2f} %  -> {t_nm / best_all:.0f}x")

    print("\nSweep throughput (in-process, threaded Dask scheduler)")
    base = presets.be_pam()
    a0 = np.linspace(60, 80, 41)
    t0v = np.linspace(1.5, 3.0, 7)
    P = np.linspace(80, 250, 16)
    bendpam.sweep(base, P, alpha0_deg=a0[:3], t0_mm=t0v[:2])  # warm up
    t0 = time.perf_counter()
    bendpam.sweep(base, P, alpha0_deg=a0, t0_mm=t0v)
    dt = time.perf_counter() - t0
    n_cases = a0.size * t0v.size
    print(f"  {n_cases} cases x {P.size} pressures in {dt:.2f} s: {n_cases / dt:.0f} cases/s, "
          f"{n_cases * P.size / dt:.0f} points/s")
    # memory: lazy sweeps written block by block; the peak does not grow with the sweep
    P = np.linspace(70, 300, 1000)
    for n_a0 in (10, 40):
        a0 = np.linspace(60, 80, n_a0)
        c10 = np.linspace(-400, 200, 10)
        n_pts = a0.size * c10.size * P.size
        with tempfile.TemporaryDirectory() as d:
            tracemalloc.start()
            t0 = time.perf_counter()
            ds = bendpam.sweep(base, P, alpha0_deg=a0, C10_kpa=c10, compute=False, chunk_cases=10)
            ds.to_netcdf(Path(d) / "s.nc")
            dt = time.perf_counter() - t0
            _, peak = tracemalloc.get_traced_memory()
            tracemalloc.stop()
        print(f"  lazy sweep of {n_pts:,} points ({a0.size * c10.size} cases x {P.size} pressures, blocks of 10 "
              f"cases) to NetCDF in {dt:.1f} s ({n_pts / dt:,.0f} points/s): peak traced memory "
              f"{peak / 2**20:.0f} MiB for a result of {n_pts * 5 * 8 / 2**20:.0f} MiB")


if __name__ == "__main__":
    main()
