"""Reader and processing benchmark: ``read_test`` against ``pandas.read_csv``, and the peak memory of ``process``.

* A short-line CSV (``time,stroke,force``, three numbers a line, about 450 MB and 19 M lines; 45 MB
  with ``--quick``) is generated in a temporary folder and read by ``pandas.read_csv`` (all its
  defaults) and by ``bendpam.lab.read_test`` (detection, conversion and every check of the values)
  side by side in one process: interleaved repeats, median of the wall times and of the CPU times
  (less disturbed by other work on a shared machine).  Target (issue 22): ``read_test`` within 2x
  of ``pandas.read_csv``.  The peak resident memory (Linux ``VmHWM``) of each, reading
  the same file in a fresh process, is measured too.
* ``bendpam process`` (figure included) on a simulated 690-cycle test: its peak resident memory
  (``VmHWM`` of the process, read from ``/proc/self/status`` at its end; Linux only, skipped
  elsewhere), at the default 20 Hz (2.5 M samples) and, without ``--quick``, at 75 Hz (9.4 M
  samples, near the 10 M samples a simulated test may hold).  Target: under 1 GB.

Run: ``python benchmarks/bench_reader.py [--quick]``.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _timing import Recorder, Stats, header, standalone

RATIO_TARGET = 2.0  # read_test / pandas.read_csv (issue 22, item 8)
PROCESS_TARGET_MIB = 1024.0  # peak RSS of `bendpam process` on a 690-cycle test

#: Run ``CODE`` in a fresh interpreter, then print its peak resident memory (kB) as the last line.
_HWM_RUNNER = """
import sys
def _hwm_kb():
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return int(line.split()[1])
    return -1
code = 0
try:
    exec(compile(sys.argv[1], "<bench>", "exec"))
except SystemExit as exc:
    code = exc.code or 0
print("VmHWM_kB", _hwm_kb(), code)
"""


def peak_rss_mib(code: str, args: list[str] | None = None) -> float | None:
    """Peak resident memory (MiB) of a fresh Python process running ``code``; None where ``/proc`` is missing."""
    if not Path("/proc/self/status").exists():  # Linux only
        return None
    p = subprocess.run([sys.executable, "-c", _HWM_RUNNER, code, *(args or [])], capture_output=True, text=True,
                       env=os.environ.copy())
    last = (p.stdout.strip().splitlines() or [""])[-1].split()
    if p.returncode != 0 or len(last) != 3 or last[0] != "VmHWM_kB" or last[2] != "0":
        raise RuntimeError(f"benchmark subprocess failed: {p.stderr.strip()[-600:]}")
    return int(last[1]) / 1024.0


def write_short_lines(path: Path, n_lines: int) -> int:
    """``time,stroke,force`` and ``n_lines`` rows of three numbers (a slow ramp, a sine, a cosine); bytes written."""
    import numpy as np

    step = 1_000_000
    with open(path, "w", encoding="ascii", newline="\n") as fh:
        fh.write("time,stroke,force\n")
        for start in range(0, n_lines, step):
            i = np.arange(start, min(n_lines, start + step))
            t = i * 0.001
            stroke = 10.0 + 10.0 * np.sin(2 * np.pi * t / 20.0)
            force = 20.0 + 15.0 * np.cos(2 * np.pi * t / 20.0) + 0.01 * np.sin(i * 1.7)
            fh.write("\n".join(f"{a:.3f},{b:.4f},{c:.3f}" for a, b, c in zip(t.tolist(), stroke.tolist(),
                                                                           force.tolist(), strict=True)))
            fh.write("\n")
    return path.stat().st_size


def interleaved(cands: dict, repeats: int, items: float) -> tuple[dict[str, Stats], dict[str, Stats]]:
    """Wall and CPU times of each candidate: one warm-up call each, then ``repeats`` rounds in rotated order.

    The CPU time (``time.process_time``) is less disturbed than the wall time by other work on a
    shared machine; both are reported.
    """
    names = list(cands)
    for n in names:
        cands[n]()
    wall: dict[str, list[float]] = {n: [] for n in names}
    cpu: dict[str, list[float]] = {n: [] for n in names}
    for r in range(repeats):
        for n in names[r % len(names):] + names[:r % len(names)]:
            w0, c0 = time.perf_counter(), time.process_time()
            cands[n]()
            cpu[n].append(time.process_time() - c0)
            wall[n].append(time.perf_counter() - w0)
    return ({n: Stats(wall[n], items) for n in names}, {n: Stats(cpu[n], items) for n in names})


def simulated_690(folder: Path, rate_hz: float) -> tuple[Path, int]:
    """A 690-cycle BE-PAM test at 200 kPa sampled at ``rate_hz``, written as CSV: ``(path, samples)``."""
    from bendpam import presets
    from bendpam.lab import write_test
    from bendpam.lab.simulate import SimulationSettings, simulate_test

    data, _ = simulate_test(presets.be_pam(), 200.0, settings=SimulationSettings(cycles=690, rate_hz=rate_hz, seed=0))
    path = folder / f"be_690cycles_{rate_hz:g}Hz_200kPa.csv"
    write_test(path, data, "csv", pressure_kpa=200)
    return path, len(data)


def run_read(rec: Recorder, quick: bool, folder: Path) -> None:
    import pandas as pd

    from bendpam.lab import read_test

    n_lines = 1_900_000 if quick else 19_000_000
    path = folder / "short_lines.csv"
    t0 = time.perf_counter()
    size = write_short_lines(path, n_lines)
    header(f"Reading a short-line CSV: {size / 1e6:.0f} MB, {n_lines:,} lines (written in "
           f"{time.perf_counter() - t0:.0f} s); median of interleaved runs")
    got = read_test(path, pressure_kpa=100)
    assert len(got.data) == n_lines, len(got.data)
    del got
    st, cpu = interleaved({"pandas.read_csv": lambda: pd.read_csv(path),
                           "read_test": lambda: read_test(path, pressure_kpa=100)}, 3 if quick else 5, n_lines)
    for k, s in st.items():
        print(f"  {k:16} {s}  -> {s.rate:12,.0f} lines/s; CPU {cpu[k]}")
    ratio = st["read_test"].median / st["pandas.read_csv"].median
    cpu_ratio = cpu["read_test"].median / cpu["pandas.read_csv"].median
    print(f"  read_test / pandas.read_csv = {ratio:.2f} wall, {cpu_ratio:.2f} CPU (target <= {RATIO_TARGET:g})")
    mem = {
        "pandas.read_csv": peak_rss_mib("import sys, pandas; pandas.read_csv(sys.argv[2])", [str(path)]),
        "read_test": peak_rss_mib("import sys; from bendpam.lab import read_test; read_test(sys.argv[2], "
                                  "pressure_kpa=100)", [str(path)]),
    }
    for k, v in mem.items():
        if v is not None:
            print(f"  peak RSS {k:16} {v:8.0f} MiB (fresh process)")
    rec.record("reader", "file_mb", size / 1e6)
    rec.record("reader", "lines", n_lines)
    rec.record("reader", "timing", st)
    rec.record("reader", "cpu", cpu)
    rec.record("reader", "peak_rss_mib", mem)
    rec.row("read_test / pandas.read_csv", ratio, "x", f"<= {RATIO_TARGET:g}", ratio <= RATIO_TARGET,
            f"{size / 1e6:.0f} MB short-line CSV, wall time")
    rec.row("read_test / pandas.read_csv (CPU)", cpu_ratio, "x", f"<= {RATIO_TARGET:g}", cpu_ratio <= RATIO_TARGET,
            "CPU time of the same runs")
    if mem["read_test"] is not None:
        rec.row("read_test peak RSS", mem["read_test"], "MiB", "", None,
                f"pandas.read_csv {mem['pandas.read_csv']:.0f} MiB")


def run_process(rec: Recorder, quick: bool, folder: Path) -> None:
    rates = (20.0,) if quick else (20.0, 75.0)
    header("Peak RSS of `bendpam process` (figure included) on a simulated 690-cycle test, fresh process")
    for rate in rates:
        path, n = simulated_690(folder, rate)
        out = folder / f"out_{rate:g}"
        code = ("import sys, runpy; sys.argv = ['bendpam', 'process', sys.argv[2], '--out', sys.argv[3], "
                "'--force', '-q']; runpy.run_module('bendpam', run_name='__main__')")
        t0 = time.perf_counter()
        mib = peak_rss_mib(code, [str(path), str(out)])
        wall_s = time.perf_counter() - t0
        path.unlink()
        if mib is None:
            print("  (no /proc/self/status: peak RSS not measured on this platform)")
            return
        print(f"  690 cycles at {rate:g} Hz ({n:,} samples): peak {mib:.0f} MiB, {wall_s:.0f} s")
        rec.record("process_690", f"{rate:g}Hz", {"samples": n, "peak_rss_mib": mib, "wall_s": wall_s})
        rec.row(f"process 690 cycles @ {rate:g} Hz peak RSS", mib, "MiB", f"< {PROCESS_TARGET_MIB:g}",
                mib < PROCESS_TARGET_MIB, f"{n:,} samples")


def run(rec: Recorder, quick: bool) -> None:
    with tempfile.TemporaryDirectory(prefix="bendpam-bench-") as d:
        run_read(rec, quick, Path(d))
        run_process(rec, quick, Path(d))


if __name__ == "__main__":
    standalone(run, "reader")
