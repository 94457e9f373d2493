"""Timing helper shared by the benchmarks: best wall time of repeats and peak traced memory."""

from __future__ import annotations

import math
import time
import tracemalloc


def measure(fn, repeat: int = 3):
    """Run ``fn`` ``repeat`` times; return ``(result, best seconds, peak MiB of one more traced run)``."""
    best = math.inf
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    tracemalloc.start()
    fn()
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return out, best, peak / 2**20
