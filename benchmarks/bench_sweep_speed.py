"""Many-pressure sweeps side by side (issue 24 items 3 and 5): this code, an earlier commit and the batched baseline.

Every candidate runs in its own long-lived worker process (this ``src/``, or ``git archive REF src``
of an earlier commit unpacked in a temporary folder), so that two versions of bendpam can be timed
in one run; the driver sends the repeats to the workers in an order rotated each round (interleaved)
and reports medians, min and max.  Candidates:

* ``sweep``: ``bendpam.sweep`` of this code (the whole call: blocks, the margins, the dataset);
* ``sweep@REF``: the same call on the earlier commit (``--against``, default :data:`BEFORE`, the
  commit before item 3);
* ``free`` and ``free@REF``: bendpam's kernel doing only what the baseline does (``MomentLaw`` of a
  block of cases: the blocked moment and ``free_state_array`` on the sweep's 150-sample branch table),
  in the same blocks of 256 cases, on one thread like the baseline (``sweep`` runs its blocks on
  Dask's threads);
* ``baseline``: :class:`baseline.BatchedBaseline`, the competent baseline batched over the cases of a
  block (no Python loop over cases) and given bendpam's closed forms: the strongest baseline; it
  computes the blocked moment and the free curvature only (no margins, no dataset).

Configurations (BE-PAM and BC-PAM, energy; ``alpha0_deg`` x ``t0_mm`` grids, blocks of 256 cases):

* 200 cases x 1000 pressures (20 cases share a braid angle: the shared-table path);
* 32 braid angles x 1000 pressures (the default block of a streamed sweep; the exact path), BE-PAM and BC-PAM;
* 2000 cases x 16 pressures, and 2000 distinct braid angles x 16 pressures.

The free curvatures of each candidate are compared with this code's (NaN pattern, largest difference
relative to the largest |k'|).  Run: ``python benchmarks/bench_sweep_speed.py [--quick] [--against REF]``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

#: The commit before the many-pressure work of issue 24 item 3 (Illinois roots, quadrature margins).
BEFORE = "e774cb2"
TARGET_SPEEDUP = 2.0
#: The branch samples of a sweep (``bendpam.sweeps._BRANCH_SAMPLES``; the baseline samples 256).
SWEEP_SAMPLES = 150


def _config(i: int, quick: bool):
    """``(label, preset, pressures, alpha0_deg, t0_mm)`` of configuration ``i``."""
    n = 1 if quick else 2
    cfgs = [
        ("200 cases x 1000 P (20 cases an angle)", "be-pam", np.linspace(70.0, 300.0, 1000),
         np.linspace(60.0, 80.0, 5 * n), np.linspace(1.5, 3.0, 20)),
        ("BC-PAM 200 cases x 1000 P", "bc-pam", np.linspace(40.0, 300.0, 1000),
         np.linspace(40.0, 50.0, 5 * n), np.linspace(1.5, 3.0, 20)),
        ("32 angles x 1000 P (one streamed block)", "be-pam", np.linspace(70.0, 300.0, 1000),
         np.linspace(60.0, 80.0, 16 * n), np.array([2.0])),
        ("BC-PAM 32 angles x 1000 P (one streamed block)", "bc-pam", np.linspace(40.0, 300.0, 1000),
         np.linspace(40.0, 50.0, 16 * n), np.array([2.0])),
        ("2000 cases x 16 P", "be-pam", np.linspace(80.0, 250.0, 16),
         np.linspace(60.0, 80.0, 50 * n), np.linspace(1.5, 3.0, 20)),
        ("2000 distinct angles x 16 P", "be-pam", np.linspace(80.0, 250.0, 16),
         np.linspace(60.0, 80.0, 1000 * n), np.array([2.0])),
    ]
    return cfgs[i]


N_CONFIGS = 6


# ------------------------------------------------------------------------------------------------
# the worker: one bendpam (whatever is on its path), jobs from stdin, one JSON line back per job
# ------------------------------------------------------------------------------------------------
def _job(what: str, config: int, quick: bool, cache: dict):
    """The function that one timed call of candidate ``what`` runs (its inputs built outside the timing)."""
    import bendpam

    _, preset, P, a0, t0 = _config(config, quick)
    base = bendpam.physics.presets.get(preset)
    if what == "sweep":
        def fn():
            ds = bendpam.sweep(base, P, "energy", alpha0_deg=a0, t0_mm=t0, progress=False)
            return ds["free_curvature_per_mm"].values.reshape(-1, P.size)
        return fn
    A, T = (g.ravel() for g in np.meshgrid(a0, t0, indexing="ij"))
    if what == "free":  # bendpam's kernel doing the baseline's work: blocked moment and free k'
        from bendpam.physics.law import MomentLaw
        from bendpam.sweeps import build_cases

        def free():
            ks = []
            for i in range(0, A.size, 256):
                law = MomentLaw(build_cases(base, {"alpha0_deg": A[i:i + 256], "t0_mm": T[i:i + 256]}), "energy")
                A0, _ = law.coefficients(np.zeros(law.params.shape))
                _blocked = np.maximum(P[None, :] - np.asarray(law.P_start_kpa)[:, None], 0.0) * A0[:, None]
                ks.append(law.free_state_array(P, table=law.branches(SWEEP_SAMPLES))[0])
            return np.concatenate(ks)
        return free
    from baseline import BatchedBaseline, Params

    if config not in cache:  # the per-case parameters are built outside the timing
        cache[config] = [Params.of(base.replace(alpha0_deg=float(x), t0_mm=float(y)))
                         for x, y in zip(A, T, strict=True)]
    params = cache[config]

    def batched():
        ks = []
        for i in range(0, len(params), 256):  # blocks of cases, as the sweep's
            ks.append(BatchedBaseline(params[i:i + 256], "energy").sweep(P)[1])
        return np.concatenate(ks)
    return batched


def _worker() -> None:
    from _timing import settle_allocator

    settle_allocator()
    cache: dict = {}
    for line in sys.stdin:
        job = json.loads(line)
        fn = _job(job["what"], job["config"], job["quick"], cache)
        t0 = time.perf_counter()
        k = fn()
        dt = time.perf_counter() - t0
        if job.get("save"):
            np.save(job["save"], k)
        print(json.dumps({"s": dt}), flush=True)


class _Worker:
    def __init__(self, src: Path):
        env = dict(os.environ, PYTHONPATH=str(src))
        self.p = subprocess.Popen([sys.executable, str(Path(__file__).resolve()), "--worker"], env=env, cwd=str(HERE),
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)

    def run(self, **job) -> float:
        assert self.p.stdin is not None and self.p.stdout is not None
        self.p.stdin.write(json.dumps(job) + "\n")
        self.p.stdin.flush()
        line = self.p.stdout.readline()
        if not line:
            raise RuntimeError("a benchmark worker died")
        return float(json.loads(line)["s"])

    def close(self) -> None:
        if self.p.stdin is not None:
            self.p.stdin.close()
        self.p.wait(timeout=60)


def _checkout(ref: str, into: Path) -> Path:
    """``src/`` of commit ``ref`` unpacked under ``into`` (``git archive``; the repository is not touched)."""
    repo = HERE.parent
    tar = into / "src.tar"
    with open(tar, "wb") as f:
        subprocess.run(["git", "-C", str(repo), "archive", ref, "src"], stdout=f, check=True)
    with tarfile.open(tar) as t:
        t.extractall(into, filter="data")
    return into / "src"


def run(rec, quick: bool, against: str = BEFORE) -> None:
    from _timing import Stats, header

    repeats = 3 if quick else 7
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        new, old = _Worker(HERE.parent / "src"), _Worker(_checkout(against, d))
        # the baseline is independent of bendpam: it runs in this code's worker
        workers = {"sweep": new, f"sweep@{against}": old, "free": new, f"free@{against}": old, "baseline": new}
        what = {"sweep": "sweep", f"sweep@{against}": "sweep", "free": "free", f"free@{against}": "free",
                "baseline": "baseline"}
        names = list(workers)
        header(f"Sweeps side by side: this code, {against} (before issue 24 item 3) and the batched baseline "
               f"(medians of {repeats}, interleaved)")
        try:
            for ci in range(N_CONFIGS):
                label, _, P, a0, t0 = _config(ci, quick)
                n_cases = a0.size * t0.size
                # the results (and a warm-up) of every candidate
                ks = {}
                for n in names:
                    f = d / f"k{ci}-{names.index(n)}.npy"
                    workers[n].run(what=what[n], config=ci, quick=quick, save=str(f))
                    ks[n] = np.load(f)
                runs: dict[str, list[float]] = {n: [] for n in names}
                for r in range(repeats):
                    for n in names[r % len(names):] + names[:r % len(names)]:
                        runs[n].append(workers[n].run(what=what[n], config=ci, quick=quick))
                st = {n: Stats(runs[n], n_cases) for n in names}
                ref = ks["sweep"]
                agree = {}
                for n in names[1:]:
                    same_nan = bool(np.array_equal(np.isnan(ref), np.isnan(ks[n])))
                    dk = float(np.nanmax(np.abs(ref - ks[n])) / np.nanmax(np.abs(ref)))
                    agree[n] = {"same_nan": same_nan, "max_dk_rel": dk}
                speedup = st[f"sweep@{against}"].median / st["sweep"].median
                free_speedup = st[f"free@{against}"].median / st["free"].median
                vs_base = st["baseline"].median / st["free"].median
                print(f"  {label}: {n_cases} cases x {P.size} P")
                for n in names:
                    nan = "equal" if n == "sweep" or agree[n]["same_nan"] else "DIFFERENT"
                    extra = "" if n == "sweep" else (f"; k' vs this code: max {agree[n]['max_dk_rel']:.1e} of the "
                                                     f"largest, NaN pattern {nan}")
                    print(f"    {n:18} {st[n]}  {st[n].rate:9.4g} cases/s{extra}")
                print(f"    sweep: this code / {against} {speedup:.2f}x; the same work as the baseline (free): "
                      f"this code / {against} {free_speedup:.2f}x, this code / batched baseline {vs_base:.2f}x")
                rec.record("sweep_speed", label, {"cases": n_cases, "pressures": P.size, "timing": st,
                                                  "agreement": agree, "speedup_vs_before": speedup,
                                                  "free_speedup_vs_before": free_speedup,
                                                  "free_ratio_vs_batched_baseline": vs_base, "before": against})
                rec.row(f"{label}: sweep vs {against}", speedup, "x", ">= 2x" if P.size == 1000 else "",
                        speedup >= TARGET_SPEEDUP if P.size == 1000 else None, f"{st['sweep'].rate:.3g} cases/s")
                rec.row(f"{label}: blocked + free k' vs batched baseline", vs_base, "x", "", None,
                        f"{st['free'].rate:.3g} against {st['baseline'].rate:.3g} cases/s")
        finally:
            for w in {id(w): w for w in workers.values()}.values():
                w.close()


if __name__ == "__main__":
    if "--worker" in sys.argv:
        _worker()
        sys.exit(0)
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--against", default=BEFORE, help=f"the earlier commit (default {BEFORE})")
    args = ap.parse_args()
    from _timing import Recorder, settle_allocator

    settle_allocator()
    rec = Recorder("sweep_speed", args.quick)
    run(rec, args.quick, args.against)
    rec.print_summary()
    rec.save()
