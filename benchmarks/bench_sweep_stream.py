"""Streamed sweeps (issue 24): time and peak memory of sweeps written block by block into a Zarr store.

* size: 10^6 and 10^7 (case, pressure) points (``--huge`` adds 10^8), alpha0_deg x 1000 pressures,
  in-process (a thread per core), each in a fresh process: wall time of the sweep (store committed)
  and the process's peak resident memory (Linux ``VmHWM``, which includes Python, NumPy, xarray, Dask
  and zarr themselves);
* workers: cases/s of one sweep (alpha0_deg x t0_mm at 16 pressures) on a ``LocalCluster`` of 1 and 2
  worker processes, started by ``sweep_zarr`` itself (its start-up, a few seconds, is included).

Run: ``python benchmarks/bench_sweep_stream.py [--quick] [--huge]``.  The figures of a run go to
``results/`` like every benchmark's; the 10^8 run is recorded in benchmarks/README.md.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _timing import Recorder, fmt_time, header, standalone

SRC = Path(__file__).resolve().parent.parent / "src"

CHILD = r"""
import json, sys, time
sys.path.insert(0, sys.argv[1])
import numpy as np
import bendpam
from bendpam.sweep_store import sweep_zarr
out, cases, pressures, workers = sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
grid = {"alpha0_deg": np.linspace(60.0, 80.0, cases)} if pressures >= 100 else \
       {"alpha0_deg": np.linspace(60.0, 80.0, cases // 10), "t0_mm": np.linspace(1.5, 3.0, 10)}
t = time.perf_counter()
sweep_zarr(bendpam.physics.presets.be_pam(), out, np.linspace(60.0, 250.0, pressures), command=["bench"],
           workers=workers or None, max_memory_gib=None, **grid)
seconds = time.perf_counter() - t
hwm = [int(l.split()[1]) for l in open("/proc/self/status") if l.startswith("VmHWM")][0]
print(json.dumps({"seconds": seconds, "peak_mib": hwm / 1024, "cases": cases, "points": cases * pressures}))
"""


def one(cases: int, pressures: int, workers: int = 0) -> dict:
    """A streamed sweep in a fresh process: its time (s), peak memory (MiB), cases and points."""
    with tempfile.TemporaryDirectory(prefix="bench-stream-") as d:
        out = subprocess.run([sys.executable, "-c", CHILD, str(SRC), str(Path(d) / "s.zarr"), str(cases),
                              str(pressures), str(workers)], capture_output=True, text=True, check=True)
        res = json.loads(out.stdout.strip().splitlines()[-1])
        res["store_mib"] = sum(p.stat().st_size for p in (Path(d) / "s.zarr").rglob("*") if p.is_file()) / 2**20
    return res


def run(rec: Recorder, quick: bool) -> None:
    header("Streamed sweeps into a Zarr store: alpha0_deg x 1000 pressures, in-process, one fresh process each")
    sizes = [10**5, 10**6] if quick else [10**6, 10**7]
    if "--huge" in sys.argv:
        sizes.append(10**8)
    print(f"  {'points':>12} {'time':>10} {'points/s':>10} {'peak MiB':>9} {'store MiB':>10}")
    for n in sizes:
        r = one(n // 1000, 1000)
        print(f"  {n:12,} {fmt_time(r['seconds']):>10} {n / r['seconds']:10.3g} {r['peak_mib']:9.0f} "
              f"{r['store_mib']:10.0f}", flush=True)
        rec.record("stream", f"points_{n}", r)
        rec.row(f"streamed sweep, {n:.0e} points: peak memory", r["peak_mib"], "MiB", "< 1 GB",
                r["peak_mib"] * 2**20 < 1e9, note=f"{fmt_time(r['seconds'])}")
    cases = 2_000 if quick else 20_000
    header(f"Cases/s on a LocalCluster: {cases} cases (alpha0_deg x t0_mm) x 16 pressures, start-up included")
    for w in (1, 2):
        r = one(cases, 16, workers=w)
        print(f"  {w} worker{'s' * (w > 1)}: {fmt_time(r['seconds'])}, {cases / r['seconds']:.3g} cases/s, "
              f"peak {r['peak_mib']:.0f} MiB (this process)", flush=True)
        rec.record("workers", str(w), r)
        rec.row(f"streamed sweep on {w} worker{'s' * (w > 1)}", cases / r["seconds"], "case/s")


if __name__ == "__main__":
    standalone(run, "sweep_stream")
