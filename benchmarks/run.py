"""Run every benchmark in one process and print the summary: ``python benchmarks/run.py [--quick] [--only NAME ...]``.

``--quick`` uses smaller sizes and fewer repeats (under a minute on a 2-core machine).  Every run
is recorded in ``benchmarks/results/all[-quick]-<UTC timestamp>.json`` with the machine, and
summarised in ``benchmarks/results/latest.json``.  Targets are printed next to the figures; they
are not asserted (a missed target is a number to improve, not a failure of the run).
"""

from __future__ import annotations

import argparse
import importlib
import sys
import time
import traceback
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _timing import Recorder, fmt_time, settle_allocator  # noqa: E402

#: In run order: the start-up figures first (fresh processes), the heavy in-process ones after.
BENCHMARKS = ("startup", "processing", "reader", "models", "fit_sweep", "scaling")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller sizes, fewer repeats (< 1 min)")
    ap.add_argument("--only", nargs="+", choices=BENCHMARKS, help="run only these benchmarks")
    args = ap.parse_args(argv)
    sys.argv = [sys.argv[0]] + (["--quick"] if args.quick else [])
    settle_allocator()
    rec = Recorder("all", args.quick)
    failed = []
    for name in args.only or BENCHMARKS:
        t0 = time.perf_counter()
        print(f"\n######## bench_{name}{' (quick)' if args.quick else ''} ########", flush=True)
        try:
            importlib.import_module(f"bench_{name}").run(rec, args.quick)
        except Exception:  # keep the other benchmarks' figures
            traceback.print_exc()
            failed.append(name)
            rec.row(f"bench_{name}", "FAILED", "", "", False)
        rec.record("elapsed_s", name, time.perf_counter() - t0)
        print(f"[bench_{name}: {fmt_time(time.perf_counter() - t0)}]", flush=True)
    rec.print_summary()
    rec.save()
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
