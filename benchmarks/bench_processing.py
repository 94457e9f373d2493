"""Benchmark: raw samples processed per second (issue 3 target: >= 1e6 samples/s on one core).

Builds a long simulated cyclic test (BE-PAM at 200 kPa, many cycles at a high sampling rate),
writes it as plain CSV and testXpert, and times reading and processing separately, with the
peak memory of each stage (tracemalloc).  Run:  python benchmarks/bench_processing.py
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from bendpam import presets
from bendpam.lab import read_test, write_test
from bendpam.lab.processing import process_series
from bendpam.lab.simulate import SimulationSettings, simulate_test

sys.path.insert(0, str(Path(__file__).parent))
from _timing import measure  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=float, default=1e6, help="approximate number of raw samples")
    args = ap.parse_args()
    a = presets.be_pam()
    # one cycle at 200 kPa and 30 mm/min is ~236 s; choose the rate to reach the sample count in 10 cycles
    rate = args.samples / (10 * 236.0)
    data, _ = simulate_test(a, 200, settings=SimulationSettings(cycles=10, rate_hz=rate, seed=0))
    n = len(data)
    print(f"raw samples: {n:,} (10 cycles at {rate:.0f} Hz)")
    _, t_proc, mem = measure(lambda: process_series(data.time_s.to_numpy(), data.stroke_mm.to_numpy(),
                                                  data.force_n.to_numpy(), 200.0, keep_series=False))
    print(f"process_series: {t_proc:.3f} s  -> {n / t_proc:,.0f} samples/s   peak {mem:.0f} MiB   (target >= 1,000,000)")
    with tempfile.TemporaryDirectory() as d:
        for dialect in ("csv", "testxpert"):
            p = Path(d) / f"t_200kPa.{dialect}.txt"
            write_test(p, data, dialect, pressure_kpa=200)
            rt, t_read, mem = measure(lambda: read_test(p))
            print(f"read_test[{dialect}]: {t_read:.3f} s  -> {n / t_read:,.0f} samples/s   peak {mem:.0f} MiB")
            _, t_all, _ = measure(lambda: process_series(rt.data.time_s.to_numpy(), rt.data.stroke_mm.to_numpy(),
                                                       rt.data.force_n.to_numpy(), 200.0, keep_series=False), 1)
            print(f"read + process [{dialect}]: {t_read + t_all:.3f} s -> {n / (t_read + t_all):,.0f} samples/s")


if __name__ == "__main__":
    main()
