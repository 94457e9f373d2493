"""Processing benchmark: raw samples per second for ``process_series`` and for read + process.

A long simulated cyclic test (BE-PAM at 200 kPa, 10 cycles at a high sampling rate) is processed
in memory, then written as plain CSV and as a testXpert export and read back and processed.  All
candidates run side by side (interleaved repeats, median); peak traced memory of one extra run.

Run: ``python benchmarks/bench_processing.py [--quick]``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _timing import Recorder, compare, header, peak_mib, standalone

TARGET = 1e6  # samples/s on one core (issue 3)


def simulated_test(samples: float, pressure_kpa: float = 200.0):
    """A BE-PAM test at ``pressure_kpa`` with about ``samples`` raw samples (10 cycles)."""
    from bendpam import presets
    from bendpam.lab.simulate import SimulationSettings, simulate_test

    a = presets.be_pam()
    _, truth = simulate_test(a, pressure_kpa, settings=SimulationSettings(cycles=10, rate_hz=0.5, seed=0))
    rate = samples / truth["duration_s"]
    data, _ = simulate_test(a, pressure_kpa, settings=SimulationSettings(cycles=10, rate_hz=rate, seed=0))
    return data


def process(data, pressure_kpa: float = 200.0):
    from bendpam.lab.processing import process_series

    return process_series(data.time_s.to_numpy(), data.stroke_mm.to_numpy(), data.force_n.to_numpy(), pressure_kpa,
                          keep_series=False)


def run(rec: Recorder, quick: bool) -> None:
    from bendpam.lab import read_test, write_test

    data = simulated_test(2e5 if quick else 1e6)
    n = len(data)
    header(f"Processing: {n:,} raw samples (BE-PAM, 200 kPa, 10 cycles); samples/s, median of interleaved runs")
    with tempfile.TemporaryDirectory() as d:
        files = {}
        for dialect in ("csv", "testxpert"):
            p = Path(d) / f"t_200kPa.{dialect}.txt"
            write_test(p, data, dialect, pressure_kpa=200)
            files[dialect] = p
        cands = {"process_series": (lambda: process(data), n)}
        for dialect, p in files.items():
            cands[f"read {dialect}"] = (lambda p=p: read_test(p), n)
            cands[f"read+process {dialect}"] = (lambda p=p: process(read_test(p).data), n)
        st = compare(cands, repeats=3 if quick else 5)
        mem = {k: peak_mib(v[0]) for k, v in cands.items() if k.startswith(("process", "read+"))}
    for k, s in st.items():
        m = f", peak {mem[k]:.0f} MiB" if k in mem else ""
        print(f"  {k:24} {s}  -> {s.rate:12,.0f} samples/s{m}")
    rec.record("processing", "samples", n)
    rec.record("processing", "timing", st)
    rec.record("processing", "peak_mib", mem)
    rec.row("process_series samples/s", st["process_series"].rate, "/s", ">= 1e6", st["process_series"].rate >= TARGET,
            "issue 3 target")
    for dialect in ("csv", "testxpert"):
        r = st[f"read+process {dialect}"].rate
        rec.row(f"read+process {dialect} samples/s", r, "/s", "", None)


if __name__ == "__main__":
    standalone(run, "processing")
