"""Where the time goes: cProfile of the sweep kernel and of the fast path, top functions by own time.

* sweep: ``bendpam.sweeps.evaluate_cases`` (the kernel ``bendpam.sweep`` runs on each block of
  cases; profiled directly because the sweep runs it in Dask's worker threads) on a block of 256
  cases at 16 pressures and on 50 cases at 1000 pressures, plus the share of ``bendpam.sweep``
  outside the kernel (Dask graph, xarray dataset);
* fast path: ``law.tabulated().moment`` on 10^6 scattered pairs (BE-PAM energy);
* exact path: ``law.moment`` on 10^5 pairs.

Run: ``python benchmarks/profile_hotspots.py [--top 8]``.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _timing import settle_allocator, timed

import bendpam
from bendpam.sweeps import evaluate_cases


def top(label: str, fn, n: int) -> None:
    prof = cProfile.Profile()
    t0 = time.perf_counter()
    prof.runcall(fn)
    wall = time.perf_counter() - t0
    st = pstats.Stats(prof)
    total = sum(v[2] for v in st.stats.values())  # own time of every function
    rows = sorted(((v[2], v[3], v[1], k) for k, v in st.stats.items()), reverse=True)[:n]
    print(f"\n{label}: {wall * 1e3:.0f} ms under cProfile; top {n} by own time")
    print(f"  {'own %':>6} {'own ms':>8} {'cum ms':>8} {'calls':>7}  function")
    for own, cum, calls, (fname, line, func) in rows:
        where = f"{Path(fname).parent.name}/{Path(fname).name}:{line}" if line else fname
        print(f"  {100 * own / total:6.1f} {own * 1e3:8.1f} {cum * 1e3:8.1f} {calls:7d}  {func} ({where})")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--top", type=int, default=8)
    n = ap.parse_args().top
    settle_allocator()
    base = bendpam.physics.presets.be_pam()
    a0, t0 = np.meshgrid(np.linspace(60.0, 80.0, 64), np.linspace(1.5, 3.0, 4), indexing="ij")
    cases = {"alpha0_deg": a0.ravel(), "t0_mm": t0.ravel()}
    P16, P1000 = np.linspace(80.0, 250.0, 16), np.linspace(70.0, 300.0, 1000)
    evaluate_cases(base, "energy", {k: v[:4] for k, v in cases.items()}, P16)  # warm caches
    top("sweep kernel, 256 cases x 16 pressures", lambda: evaluate_cases(base, "energy", cases, P16), n)
    top("sweep kernel, 50 cases x 1000 pressures",
        lambda: evaluate_cases(base, "energy", {k: v[:50] for k, v in cases.items()}, P1000), n)
    grid = {"alpha0_deg": np.linspace(60.0, 80.0, 64), "t0_mm": np.linspace(1.5, 3.0, 4)}
    bendpam.sweep(base, pressure_kpa=P16, alpha0_deg=[65.0], t0_mm=[2.0])  # imports Dask and xarray
    kernel = timed(lambda: evaluate_cases(base, "energy", cases, P16), repeats=3).median
    whole = timed(lambda: bendpam.sweep(base, pressure_kpa=P16, **grid), repeats=3).median
    print(f"\nbendpam.sweep of the same 256 cases x 16 pressures: {whole * 1e3:.0f} ms, the kernel alone "
          f"{kernel * 1e3:.0f} ms ({100 * kernel / whole:.0f} %; medians of 3, without cProfile)")

    law = bendpam.MomentLaw.of(base)
    tab = law.tabulated()
    rng = np.random.default_rng(0)
    k = rng.uniform(law.limits.k_min, law.limits.k_max, 1_000_000)
    P = rng.uniform(0.0, 300.0, k.size)
    tab.moment(P, k)
    top("fast path, 10^6 pairs", lambda: tab.moment(P, k), n)
    law.moment(P[:100_000], k[:100_000])
    top("exact path, 10^5 pairs", lambda: law.moment(P[:100_000], k[:100_000]), n)


if __name__ == "__main__":
    main()
