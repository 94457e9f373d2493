"""Scaling benchmark: how time and peak memory grow with points, pressures, cases and raw samples.

Each dimension is grown x10 and x100 from a small start, everything else fixed:

* points: scattered ``law.moment`` (exact path) and ``law.tabulated().moment`` (fast path), BE-PAM energy;
* pressures: ``bendpam.sweep`` of a fixed block of cases;
* cases: ``bendpam.sweep`` at 16 pressures;
* raw samples: ``process_series`` on a simulated test.

Time: median of 3 runs; memory: peak traced (``tracemalloc``) of one more run.

Run: ``python benchmarks/bench_scaling.py [--quick]``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _timing import Recorder, fmt_time, header, peak_mib, standalone, timed
from bench_processing import process, simulated_test

import bendpam


def _table(rec: Recorder, dim: str, unit: str, sizes, make):
    """``make(size)`` returns the function to time; prints one small table."""
    print(f"  {dim:>9} {'time':>10} {'x time':>7} {unit + '/s':>12} {'peak MiB':>9} {'x mem':>6}")
    rows = []
    for n in sizes:
        fn = make(n)
        st = timed(fn, repeats=3, warmup=1, items=n)
        mem = peak_mib(fn)
        rows.append({"size": n, "timing": st, "peak_mib": mem})
        t0, m0 = rows[0]["timing"].median, rows[0]["peak_mib"]
        print(f"  {n:9,} {fmt_time(st.median):>10} {st.median / t0:7.1f} {st.rate:12.3g} {mem:9.1f} "
              f"{mem / m0 if m0 > 0 else float('nan'):6.1f}")
    rec.record("scaling", dim, rows)
    first, last = rows[0], rows[-1]
    grow = last["size"] / first["size"]
    rec.row(f"scaling x{grow:g} {dim}: time / peak memory", last["timing"].median / first["timing"].median, "x",
            "", None, f"memory x{last['peak_mib'] / max(first['peak_mib'], 1e-9):.1f}")


def run(rec: Recorder, quick: bool) -> None:
    a = bendpam.physics.presets.be_pam()
    law = bendpam.MomentLaw.of(a)
    tab = law.tabulated()
    lim = law.limits
    rng = np.random.default_rng(0)
    s = 10 if quick else 1

    def pts(n, f):
        k = rng.uniform(lim.k_min, lim.k_max, n)
        P = rng.uniform(0.0, 300.0, n)
        return lambda: f(P, k)

    header("Scaling with points: exact path law.moment (BE-PAM energy)")
    _table(rec, "points (exact)", "pt", [10_000 // s, 100_000 // s, 1_000_000 // s], lambda n: pts(n, law.moment))
    header("Scaling with points: fast path law.tabulated().moment")
    _table(rec, "points (fast)", "pt", [10_000 // s, 100_000 // s, 1_000_000 // s], lambda n: pts(n, tab.moment))

    a0 = np.linspace(60.0, 80.0, 4 if quick else 20)
    header(f"Scaling with pressures: bendpam.sweep of {a0.size} cases (alpha0_deg)")
    _table(rec, "pressures", "P", [16, 160, 1600],
           lambda n: lambda: bendpam.sweep(a, pressure_kpa=np.linspace(70.0, 300.0, n), alpha0_deg=a0))

    P16 = np.linspace(80.0, 250.0, 16)
    header("Scaling with cases: bendpam.sweep at 16 pressures (alpha0_deg x t0_mm)")
    t0 = np.linspace(1.5, 3.0, 4)
    _table(rec, "cases", "case", [4, 40, 400] if quick else [20, 200, 2000],
           lambda n: lambda: bendpam.sweep(a, pressure_kpa=P16, alpha0_deg=np.linspace(60.0, 80.0, n // 4), t0_mm=t0))

    header("Scaling with raw samples: process_series (BE-PAM, 200 kPa, 10 cycles)")
    data = {n: simulated_test(n) for n in ([2_000, 20_000, 200_000] if quick else [10_000, 100_000, 1_000_000])}
    _table(rec, "samples", "sample", list(data), lambda n: lambda: process(data[n]))


if __name__ == "__main__":
    standalone(run, "scaling")
