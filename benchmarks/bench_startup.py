"""Start-up benchmark: short CLI commands side by side with ``python -c "import typer"``.

* ``python -c pass``, ``python -c "import typer"``, ``bendpam --help``, ``bendpam --version`` and
  ``bendpam predict --preset be-pam --pressure-kpa 150``, each in a fresh process, their repeats
  interleaved (median of 15 after one warm-up run each); the targets are ratios to
  ``import typer`` (<= 1.2 for ``--help`` and ``--version``: the command line costs about what
  the library that parses it costs);
* what each of those commands leaves in ``sys.modules`` (NumPy, pandas, pyplot, ``scipy.io``...);
* ``bendpam fit`` on 25 simulated pressures with and without its figure (interleaved, median of 5);
* ``python -c "import bendpam"`` and the heavy modules it imports;
* what reading ``curves.nc`` adds to ``fit``'s imports: ``scipy.io`` (SciPy's NetCDF-3 reader) and
  ``xarray`` (its lazy backends), each imported after what ``fit`` imports anyway (NumPy,
  ``scipy.optimize``, ``scipy.special``, ``scipy.spatial``), against ``numpy.load`` of an ``.npz``
  (nothing to import): the choice of issue 24 item 6, fresh processes, interleaved, median.

Every process runs with bytecode caching on, in a private cache folder (``PYTHONPYCACHEPREFIX``),
as an installed package would (a checkout run with ``PYTHONDONTWRITEBYTECODE`` recompiles every
module each time), and with this checkout's ``src`` first on ``PYTHONPATH``.

Run: ``python benchmarks/bench_startup.py [--quick]``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _timing import Recorder, bendpam_cli, compare, header, standalone

ROOT = Path(__file__).resolve().parent.parent
HEAVY = ("numpy", "pandas", "matplotlib", "matplotlib.pyplot", "scipy", "scipy.io", "xarray", "dask", "pydantic")
RATIO_TARGET = 1.2  # --help and --version against `python -c "import typer"`
FIT_TARGET_S = 1.0  # `bendpam fit` on 25 pressures with its figure

LIST_MODULES = """
import json, sys
sys.argv = ["bendpam", *json.loads(sys.argv[1])]
import bendpam_entry
rc = bendpam_entry.main()
print(json.dumps([m for m in {heavy!r} if m in sys.modules]), file=sys.stderr)
"""


def env(cache: str) -> dict[str, str]:
    """This checkout's sources first, bytecode cached in ``cache`` (as in an installed package)."""
    e = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    e["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), *filter(None, [os.environ.get("PYTHONPATH")])])
    e["PYTHONPYCACHEPREFIX"] = cache
    return e


def runner(cmd: list[str], e: dict[str, str], cwd: str):
    def run():
        p = subprocess.run(cmd, env=e, cwd=cwd, capture_output=True, text=True)
        if p.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} exited {p.returncode}: {p.stderr.strip()[-400:]}")

    return run


def heavy_after(args: list[str], e: dict[str, str], cwd: str) -> list[str]:
    p = subprocess.run([sys.executable, "-c", LIST_MODULES.format(heavy=HEAVY), json.dumps(args)], env=e, cwd=cwd,
                       capture_output=True, text=True, check=True)
    return json.loads(p.stderr.strip().splitlines()[-1])


def commands(rec: Recorder, quick: bool, e: dict[str, str], cwd: str) -> None:
    cli = bendpam_cli()
    reps = 5 if quick else 15
    header(f"Start-up: fresh processes side by side, interleaved, median of {reps}")
    args = {"--help": ["--help"], "--version": ["--version"],
            "predict": ["predict", "--preset", "be-pam", "--pressure-kpa", "150"]}
    cands = {"python -c pass": [sys.executable, "-c", "pass"],
             "import typer": [sys.executable, "-c", "import typer"],
             **{name: [cli, *a] for name, a in args.items()}}
    st = compare({name: runner(cmd, e, cwd) for name, cmd in cands.items()}, repeats=reps, warmup=1)
    typer_s = st["import typer"].median
    for name, s in st.items():
        ratio = s.median / typer_s
        print(f"  {name:16} {s}   {ratio:.2f} x import typer")
        rec.record("startup", name, s)
    for name in ("--help", "--version"):
        ratio = st[name].median / typer_s
        rec.record("startup", f"{name} / import typer", ratio)
        rec.row(f"`bendpam {name}` / `python -c 'import typer'`", ratio, "x", f"<= {RATIO_TARGET:g}",
                ratio <= RATIO_TARGET, f"{st[name].median * 1e3:.0f} ms vs {typer_s * 1e3:.0f} ms")
    rec.row("`bendpam predict --preset be-pam --pressure-kpa 150`", st["predict"].median, "s", "", None,
            f"{st['predict'].median / typer_s:.1f} x import typer")
    print("  heavy modules loaded by each command:")
    for name, a in args.items():
        heavy = heavy_after(a, e, cwd)
        print(f"    {name:10} {', '.join(heavy) or 'none'}")
        rec.record("startup", f"heavy modules: {name}", heavy)
    rec.row("`bendpam --help`, `--version`: NumPy, pandas, pyplot, scipy.io imported",
            ", ".join(sorted(set(heavy_after(["--help"], e, cwd)) | set(heavy_after(["--version"], e, cwd)))) or "none",
            "", "none", not ({"numpy", "pandas", "matplotlib.pyplot", "scipy.io"}
                             & (set(heavy_after(["--help"], e, cwd)) | set(heavy_after(["--version"], e, cwd)))))
    pandas = "pandas" in heavy_after(args["predict"], e, cwd)
    rec.row("`bendpam predict`: pandas imported", "yes" if pandas else "no", "", "no", not pandas)


def fit(rec: Recorder, quick: bool, e: dict[str, str], cwd: str) -> None:
    cli = bendpam_cli()
    reps = 3 if quick else 5
    header(f"`bendpam fit` on 25 simulated pressures: with and without its figure, interleaved, median of {reps}")
    with tempfile.TemporaryDirectory() as d:
        raw, proc = Path(d) / "raw", Path(d) / "proc"
        runner([cli, "simulate-test", "--preset", "be-pam", "--pressure-kpa", "100:220:25", "--out", str(raw)], e,
               cwd)()
        runner([cli, "process", str(raw), "--out", str(proc), "--no-figure", "--quiet"], e, cwd)()
        base = [cli, "fit", str(proc), "--preset", "be-pam", "--quiet", "--out"]
        st = compare({"with figure": runner([*base, str(Path(d) / "fit-a")], e, cwd),
                      "--no-figure": runner([*base, str(Path(d) / "fit-b"), "--no-figure"], e, cwd)},
                     repeats=reps, warmup=1)
        heavy = {"with figure": heavy_after([*base[1:], str(Path(d) / "fit-c")], e, cwd),
                 "--no-figure": heavy_after([*base[1:], str(Path(d) / "fit-d"), "--no-figure"], e, cwd)}
    for name, s in st.items():
        print(f"  {name:12} {s}   heavy modules: {', '.join(heavy[name]) or 'none'}")
        rec.record("fit", name, s)
        rec.record("fit", f"heavy modules: {name}", heavy[name])
    rec.row("`bendpam fit`, 25 pressures, with its figure", st["with figure"].median, "s", f"<= {FIT_TARGET_S:g} s",
            st["with figure"].median <= FIT_TARGET_S, f"--no-figure {st['--no-figure'].median:.2f} s")
    rec.row("`bendpam fit`: pyplot / scipy.io imported",
            ", ".join(sorted({m for h in heavy.values() for m in h} & {"matplotlib.pyplot", "scipy.io"})) or "none",
            "", "none", not ({m for h in heavy.values() for m in h} & {"matplotlib.pyplot", "scipy.io"}))


READER_IMPORT = """
import time
import numpy, scipy.optimize, scipy.special, scipy.spatial
t0 = time.perf_counter()
{stmt}
print(time.perf_counter() - t0)
"""


def reader_imports(rec: Recorder, quick: bool, e: dict[str, str], cwd: str) -> None:
    """Seconds that ``import scipy.io`` / ``import xarray`` add once ``fit``'s other imports are loaded."""
    reps = 5 if quick else 15
    stmts = {"scipy.io": "import scipy.io", "xarray": "import xarray", "numpy.load (.npz)": "pass"}
    runs: dict[str, list[float]] = {n: [] for n in stmts}
    for _ in range(reps):
        for name, stmt in stmts.items():
            out = subprocess.run([sys.executable, "-c", READER_IMPORT.format(stmt=stmt)], env=e, cwd=cwd,
                                 capture_output=True, text=True, check=True).stdout
            runs[name].append(float(out.strip().splitlines()[-1]))
    med = {n: sorted(v)[len(v) // 2] for n, v in runs.items()}
    header(f"Reading curves.nc in `fit`: the import each reader adds after fit's own imports, median of {reps}")
    for n, v in med.items():
        print(f"  {n:18} {v * 1e3:7.1f} ms")
    rec.record("fit", "reader import after fit's imports (s)", med)
    rec.row("`fit`: import scipy.io after scipy.optimize", med["scipy.io"], "s", "", None,
            f"xarray {med['xarray'] * 1e3:.0f} ms; an .npz would save this much, not more")


def import_report(e: dict[str, str], cwd: str) -> list[str]:
    code = f"import json, sys, bendpam; print(json.dumps([m for m in {list(HEAVY)!r} if m in sys.modules]))"
    return json.loads(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                                     env=e, cwd=cwd).stdout)


def run(rec: Recorder, quick: bool) -> None:
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as cwd:
        e = env(cache)
        rec.record("startup", "environment", {"PYTHONPYCACHEPREFIX": "a private folder (bytecode cached)",
                                              "PYTHONPATH": "this checkout's src first", "cli": bendpam_cli()})
        commands(rec, quick, e, cwd)
        heavy = import_report(e, cwd)
        print(f"  heavy modules after `import bendpam`: {', '.join(heavy) or 'none'}")
        rec.record("startup", "heavy_modules", heavy)
        rec.row("heavy modules imported by `import bendpam`", ", ".join(heavy) or "none", "", "none", not heavy)
        fit(rec, quick, e, cwd)
        reader_imports(rec, quick, e, cwd)


if __name__ == "__main__":
    standalone(run, "startup")
