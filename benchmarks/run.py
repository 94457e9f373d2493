"""Run every benchmark and print its figures: ``python benchmarks/run.py [--quick]``."""

from __future__ import annotations

import runpy
import sys
from pathlib import Path

HERE = Path(__file__).parent

if __name__ == "__main__":
    quick = "--quick" in sys.argv
    for name, args in (("bench_models.py", ["--n", "200000"] if quick else []),
                       ("bench_processing.py", ["--samples", "2e5"] if quick else []),
                       ("bench_fit_sweep.py", [])):
        print(f"\n=== {name} {' '.join(args)} ===", flush=True)
        sys.argv = [str(HERE / name), *args]
        runpy.run_path(str(HERE / name), run_name="__main__")
