"""Benchmark harness: medians of interleaved repeats, peak memory, subprocess wall times, JSON records.

* :func:`compare` runs several candidates side by side in one process: after a warm-up call each,
  the repeats are interleaved (A B C, B C A, C A B, ...), so drifts of the machine (frequency,
  other load, the allocator's state) hit every candidate alike.  It reports the median, min and
  max of the repeats; ratios are taken between medians.
* :func:`peak_mib` is the peak traced memory (``tracemalloc``, which sees NumPy's buffers) of one
  extra call, never mixed into the timed runs.
* :func:`wall` times a command in a fresh process (start-up included), median of several.
* :class:`Recorder` collects every figure of a run, prints the summary table (figure, value,
  target, met?) and writes ``results/<name>-<UTC timestamp>.json`` (with the machine: platform,
  CPU count, NumPy/SciPy/bendpam versions) and ``results/latest.json`` (the summary of the latest
  run of each name).  Targets are printed next to the figures, never asserted.

The allocator: glibc serves large blocks (above its mmap threshold, 128 KiB at start) with a fresh
``mmap`` each time, so a NumPy temporary of a few MiB is page-faulted in on every use; the
threshold rises only after such a block has been freed.  A process's speed thus depends on what it
did before.  :func:`settle_allocator` puts the process into the state of one that has already
freed a large array (threshold near its 32 MiB maximum), the same for every candidate; the models
benchmark also measures the cold state in a fresh process.
"""

from __future__ import annotations

import datetime as _dt
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
import tracemalloc
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

RESULTS = Path(__file__).resolve().parent / "results"


def settle_allocator() -> None:
    """Allocate and free a 30 MiB block: glibc then serves blocks up to that size from its heap."""
    import numpy as np

    x = np.ones(30 * 2**20 // 8)
    del x


@dataclass
class Stats:
    """Wall times (s) of the repeats of one candidate, and the work per call (``items``)."""

    runs: list[float]
    items: float = 1.0

    @property
    def median(self) -> float:
        return statistics.median(self.runs)

    @property
    def min(self) -> float:
        return min(self.runs)

    @property
    def max(self) -> float:
        return max(self.runs)

    @property
    def rate(self) -> float:
        """Items per second at the median time."""
        return self.items / self.median

    def to_dict(self) -> dict:
        return {"median_s": self.median, "min_s": self.min, "max_s": self.max, "repeats": len(self.runs),
                "items": self.items, "rate_per_s": self.rate, "runs_s": [round(r, 6) for r in self.runs]}

    def __str__(self) -> str:
        return f"{fmt_time(self.median)} (min {fmt_time(self.min)}, max {fmt_time(self.max)}, n={len(self.runs)})"


def compare(candidates: dict[str, Callable[[], Any] | tuple[Callable[[], Any], float]], repeats: int = 5,
            warmup: int = 1) -> dict[str, Stats]:
    """Time candidates side by side: ``{name: fn}`` or ``{name: (fn, items per call)}``.

    Each candidate is called ``warmup`` times, then ``repeats`` rounds run every candidate once, in
    an order rotated by one each round.  Returns ``{name: Stats}``.
    """
    names = list(candidates)
    fns = {n: (c if isinstance(c, tuple) else (c, 1.0)) for n, c in candidates.items()}
    for n in names:
        for _ in range(warmup):
            fns[n][0]()
    runs: dict[str, list[float]] = {n: [] for n in names}
    for r in range(repeats):
        order = names[r % len(names):] + names[:r % len(names)]
        for n in order:
            fn = fns[n][0]
            t0 = time.perf_counter()
            fn()
            runs[n].append(time.perf_counter() - t0)
    return {n: Stats(runs[n], float(fns[n][1])) for n in names}


def timed(fn: Callable[[], Any], repeats: int = 5, warmup: int = 1, items: float = 1.0) -> Stats:
    """One candidate: :func:`compare` with a single entry."""
    return compare({"x": (fn, items)}, repeats, warmup)["x"]


def peak_mib(fn: Callable[[], Any]) -> float:
    """Peak traced memory (MiB) of one call of ``fn`` above what was allocated before it."""
    tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        base, _ = tracemalloc.get_traced_memory()
        fn()
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    return (peak - base) / 2**20


def wall(cmd: list[str], repeats: int = 7, warmup: int = 1, cwd: str | None = None,
         env: dict[str, str] | None = None) -> Stats:
    """Wall time of ``cmd`` in a fresh process each time (start-up included); raises if it fails."""
    def run():
        p = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True)
        if p.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} exited {p.returncode}: {p.stderr.strip()[-400:]}")

    return timed(run, repeats, warmup)


def bendpam_cli() -> str:
    """The ``bendpam`` console script of this interpreter's environment."""
    exe = Path(sys.executable).parent / "bendpam"
    return str(exe) if exe.exists() else "bendpam"


def machine_info() -> dict:
    import numpy
    import scipy

    try:
        import bendpam

        bv = bendpam.__version__
    except Exception as exc:  # the benchmarks should still record the machine
        bv = f"unavailable ({exc})"
    return {
        "platform": platform.platform(),
        "machine": platform.machine(),
        "processor": platform.processor() or _cpu_model(),
        "cpu_count": os.cpu_count(),
        "affinity_cpus": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "python": platform.python_version(),
        "numpy": numpy.__version__,
        "scipy": scipy.__version__,
        "bendpam": bv,
        "source": source_info(),
    }


def source_info() -> dict:
    """The code measured: git commit, whether src/ differs from it, and a hash of src/bendpam/*.py."""
    import hashlib

    root = Path(__file__).resolve().parent.parent
    h = hashlib.sha256()
    for f in sorted((root / "src" / "bendpam").rglob("*.py")):
        h.update(f.relative_to(root).as_posix().encode())
        h.update(f.read_bytes())
    info = {"src_sha256": h.hexdigest()[:16]}
    try:  # read-only git queries
        run = lambda *a: subprocess.run(["git", *a], cwd=root, capture_output=True, text=True, timeout=10).stdout
        info["commit"] = run("rev-parse", "--short", "HEAD").strip()
        info["src_modified"] = bool(run("status", "--porcelain", "--", "src").strip())
    except (OSError, subprocess.SubprocessError):
        pass
    return info


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text(encoding="utf-8").splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return ""


def fmt_time(s: float) -> str:
    if not math.isfinite(s):
        return str(s)
    if s >= 100:
        return f"{s / 60:.1f} min" if s < 7200 else f"{s / 3600:.1f} h"
    if s >= 1:
        return f"{s:.2f} s"
    if s >= 1e-3:
        return f"{s * 1e3:.1f} ms"
    return f"{s * 1e6:.0f} us"


def fmt(x: float, unit: str = "") -> str:
    """Compact number: 3 significant digits, engineering-style exponents for rates."""
    if isinstance(x, str):
        return x
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "n/a"
    if unit == "s":
        return fmt_time(x)
    ax = abs(x)
    if ax != 0 and (ax >= 1e5 or ax < 1e-2):
        s = f"{x:.2e}"
    elif ax >= 100:
        s = f"{x:,.0f}"
    else:
        s = f"{x:.3g}"
    return f"{s} {unit}".rstrip()


@dataclass
class Row:
    figure: str
    value: Any
    unit: str = ""
    target: str = ""
    met: bool | None = None
    note: str = ""

    def to_dict(self) -> dict:
        return {"figure": self.figure, "value": self.value, "unit": self.unit, "target": self.target,
                "met": self.met, "note": self.note}


@dataclass
class Recorder:
    """Collects the figures of one run; :meth:`save` writes the JSON files."""

    name: str
    quick: bool = False
    summary: list[Row] = field(default_factory=list)
    sections: dict[str, Any] = field(default_factory=dict)
    started: float = field(default_factory=time.perf_counter)
    stamp: str = field(default_factory=lambda: _dt.datetime.now(_dt.UTC).strftime("%Y%m%dT%H%M%SZ"))

    def row(self, figure: str, value, unit: str = "", target: str = "", met: bool | None = None, note: str = "") -> Row:
        """A line of the summary table (the figures with a target, and the headline numbers)."""
        r = Row(figure, value, unit, target, met, note)
        self.summary.append(r)
        return r

    def record(self, section: str, key: str, value) -> None:
        """Detailed data (nested dicts of plain numbers and strings) for the JSON file."""
        self.sections.setdefault(section, {})[key] = _plain(value)

    def print_summary(self) -> None:
        w = max([len(r.figure) for r in self.summary] + [6])
        print(f"\n{'figure':{w}}  {'value':>14}  {'target':<18} met?")
        print("-" * (w + 42))
        for r in self.summary:
            met = "-" if r.met is None else ("yes" if r.met else "NO")
            print(f"{r.figure:{w}}  {fmt(r.value, r.unit):>14}  {r.target:<18} {met}"
                  + (f"   ({r.note})" if r.note else ""))
        n_t = sum(r.met is not None for r in self.summary)
        n_ok = sum(bool(r.met) for r in self.summary)
        print(f"\n{n_ok} of {n_t} targets met; total benchmark time {fmt_time(time.perf_counter() - self.started)}")

    def save(self) -> Path:
        RESULTS.mkdir(parents=True, exist_ok=True)
        elapsed = time.perf_counter() - self.started
        doc = {
            "name": self.name,
            "utc": self.stamp,
            "quick": self.quick,
            "argv": sys.argv,
            "elapsed_s": elapsed,
            "machine": machine_info(),
            "summary": [r.to_dict() for r in self.summary],
            "sections": self.sections,
        }
        suffix = "-quick" if self.quick else ""
        path = RESULTS / f"{self.name}{suffix}-{self.stamp}.json"
        path.write_text(json.dumps(_plain(doc), indent=1, allow_nan=False) + "\n")
        latest_path = RESULTS / "latest.json"
        try:
            latest = json.loads(latest_path.read_text())
        except (OSError, ValueError):
            latest = {}
        latest[self.name + suffix] = {"file": path.name, "utc": self.stamp, "quick": self.quick, "elapsed_s": elapsed,
                                      "machine": doc["machine"], "summary": doc["summary"]}
        latest_path.write_text(json.dumps(_plain(latest), indent=1, allow_nan=False) + "\n")
        print(f"results: {path.relative_to(RESULTS.parent.parent)} (and {latest_path.name})")
        return path


def _plain(x):
    """JSON-able: NumPy scalars to Python, tuples to lists, non-finite floats as strings."""
    try:
        import numpy as np
    except ImportError:  # pragma: no cover
        np = None
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_plain(v) for v in x]
    if isinstance(x, Stats):
        return x.to_dict()
    if isinstance(x, Row):
        return x.to_dict()
    if np is not None and isinstance(x, np.generic):
        return x.item()
    if np is not None and isinstance(x, np.ndarray):
        return _plain(x.tolist())
    if isinstance(x, float):
        return x if math.isfinite(x) else str(x)  # "inf", "nan": the files stay strict JSON
    return x


def standalone(run: Callable[[Recorder, bool], None], name: str) -> None:
    """Entry point of a single benchmark script: ``--quick``, then the summary and the JSON files."""
    quick = "--quick" in sys.argv
    settle_allocator()
    rec = Recorder(name, quick)
    run(rec, quick)
    rec.print_summary()
    rec.save()


def header(title: str) -> None:
    print(f"\n== {title} ==", flush=True)
