"""Start-up benchmark: short CLI commands side by side with ``python -c "import typer"``.

* ``python -c pass``, ``python -c "import typer"``, ``bendpam --help``, ``bendpam --version`` and
  ``bendpam predict --preset be-pam --pressure-kpa 150``, each in a fresh process, their repeats
  interleaved (median of 15 after one warm-up run each); the targets are ratios to
  ``import typer`` (<= 1.2 for ``--help`` and ``--version``: the command line costs about what
  the library that parses it costs);
* what each of those commands leaves in ``sys.modules`` (NumPy, pandas, pyplot, ``scipy.io``...);
* ``bendpam fit`` on 25 simulated pressures with and without its figure (interleaved, median of 5);
* ``python -c "import bendpam"`` and the heavy modules it imports;
* what reading ``curves.nc`` would add to ``fit``'s imports: ``scipy.io`` (SciPy's NetCDF-3 reader)
  and ``xarray`` (its lazy backends), each imported after what ``fit`` imports anyway (NumPy,
  ``scipy.optimize``, ``scipy.special``, ``scipy.spatial``), against ``numpy.load`` of the set's
  ``curves.npz`` (nothing to import), which ``fit`` reads since issue 24 item 6; fresh processes,
  interleaved, median;

* the floor of ``fit`` with its figure on this machine: the libraries it cannot do without
  (``python -c "import numpy, scipy.optimize, scipy.special, matplotlib.figure, ...backend_agg"``),
  and where one ``fit`` spends its time (imports, reading, the fit, the figure's import, build and
  PNG), in a fresh process.

With ``--against REF`` (default :data:`BEFORE`, the code before this round of issue 24 item 6;
``--against none`` skips it) every command also runs from ``src/`` of that commit (``git
archive``; the repository is not touched), interleaved with this code's: before and after, side
by side.

Every process runs with bytecode caching on, in a private cache folder (``PYTHONPYCACHEPREFIX``),
as an installed package would (a checkout run with ``PYTHONDONTWRITEBYTECODE`` recompiles every
module each time), and with the ``src`` measured first on ``PYTHONPATH``.

Run: ``python benchmarks/bench_startup.py [--quick] [--against REF|none]``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _timing import Recorder, bendpam_cli, compare, header, standalone
from bench_sweep_speed import _checkout as checkout  # src/ of a commit, by git archive

ROOT = Path(__file__).resolve().parent.parent
HEAVY = ("numpy", "pandas", "matplotlib", "matplotlib.pyplot", "scipy", "scipy.io", "xarray", "dask", "pydantic")
RATIO_TARGET = 1.2  # --help and --version against `python -c "import typer"`
FIT_TARGET_S = 1.0  # `bendpam fit` on 25 pressures with its figure
#: The code before this round of issue 24 item 6 (lazy command modules, curves.npz, figure 7's drawing).
BEFORE = "7e1a5ed"
#: What `fit` with its figure cannot do without: NumPy, SciPy's optimiser and special functions, Figure on Agg.
FLOOR = "import numpy, scipy.optimize, scipy.special, matplotlib.figure, matplotlib.backends.backend_agg"

LIST_MODULES = """
import json, sys
sys.argv = ["bendpam", *json.loads(sys.argv[1])]
import bendpam_entry
rc = bendpam_entry.main()
print(json.dumps([m for m in {heavy!r} if m in sys.modules]), file=sys.stderr)
"""


def env(cache: str, src: Path = ROOT / "src") -> dict[str, str]:
    """The sources ``src`` first (this checkout's by default), bytecode cached in ``cache`` (as installed)."""
    e = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    e["PYTHONPATH"] = os.pathsep.join([str(src), *filter(None, [os.environ.get("PYTHONPATH")])])
    e["PYTHONPYCACHEPREFIX"] = cache
    return e


#: CPU seconds (user + system) of every run of each command line, warm-up first (:func:`runner`).
CPU: dict[tuple[str, ...], list[float]] = {}


def runner(cmd: list[str], e: dict[str, str], cwd: str):
    """Run ``cmd`` in a fresh process; its CPU time (the child's rusage) goes to :data:`CPU`.

    On this shared 2-core machine the wall time of a command moves with the other users' load
    (2-3 x at a load of 6); its CPU time much less, so both are reported.
    """
    key = (*cmd, e["PYTHONPATH"])

    def run():
        with tempfile.TemporaryFile() as err:
            p = subprocess.Popen(cmd, env=e, cwd=cwd, stdout=subprocess.DEVNULL, stderr=err)
            _, status, usage = os.wait4(p.pid, 0)
            p.returncode = os.waitstatus_to_exitcode(status)
            if p.returncode != 0:
                err.seek(0)
                raise RuntimeError(f"{' '.join(cmd)} exited {p.returncode}: {err.read().decode()[-400:]}")
        CPU.setdefault(key, []).append(usage.ru_utime + usage.ru_stime)

    run.key = key  # type: ignore[attr-defined]
    return run


def cpu_median(run) -> float:
    """Median CPU seconds of the timed runs of a :func:`runner` (its first run, the warm-up, left out)."""
    runs = CPU[run.key][1:]
    return sorted(runs)[len(runs) // 2]


def heavy_after(args: list[str], e: dict[str, str], cwd: str) -> list[str]:
    p = subprocess.run([sys.executable, "-c", LIST_MODULES.format(heavy=HEAVY), json.dumps(args)], env=e, cwd=cwd,
                       capture_output=True, text=True, check=True)
    return json.loads(p.stderr.strip().splitlines()[-1])


def commands(rec: Recorder, quick: bool, e: dict[str, str], cwd: str, before: dict[str, str] | None,
             ref: str) -> None:
    cli = bendpam_cli()
    reps = 5 if quick else 15
    header(f"Start-up: fresh processes side by side, interleaved, median of {reps}"
           + (f" (@{ref}: the code before)" if before else ""))
    args = {"--help": ["--help"], "--version": ["--version"],
            "predict": ["predict", "--preset", "be-pam", "--pressure-kpa", "150"]}
    cands = {"python -c pass": runner([sys.executable, "-c", "pass"], e, cwd),
             "import typer": runner([sys.executable, "-c", "import typer"], e, cwd),
             **{name: runner([cli, *a], e, cwd) for name, a in args.items()}}
    if before:
        cands |= {f"{name} @{ref}": runner([cli, *a], before, cwd) for name, a in args.items()}
    st = compare(cands, repeats=reps, warmup=1)
    typer_s, typer_cpu = st["import typer"].median, cpu_median(cands["import typer"])
    for name, s in st.items():
        cpu = cpu_median(cands[name])
        print(f"  {name:24} {s}   {s.median / typer_s:.2f} x import typer;  CPU {cpu * 1e3:5.0f} ms, "
              f"{cpu / typer_cpu:.2f} x")
        rec.record("startup", name, s)
        rec.record("startup", f"{name}: CPU s", cpu)
    for name in ("--help", "--version"):
        ratio, cpu_ratio = st[name].median / typer_s, cpu_median(cands[name]) / typer_cpu
        rec.record("startup", f"{name} / import typer", ratio)
        was = (f"; @{ref}: {st[f'{name} @{ref}'].median / typer_s:.2f} x, CPU "
               f"{cpu_median(cands[f'{name} @{ref}']) / typer_cpu:.2f} x" if before else "")
        rec.row(f"`bendpam {name}` / `python -c 'import typer'`", ratio, "x", f"<= {RATIO_TARGET:g}",
                ratio <= RATIO_TARGET, f"{st[name].median * 1e3:.0f} ms vs {typer_s * 1e3:.0f} ms; CPU "
                f"{cpu_ratio:.2f} x{was}")
    was = f"; @{ref}: {st[f'predict @{ref}'].median * 1e3:.0f} ms" if before else ""
    rec.row("`bendpam predict --preset be-pam --pressure-kpa 150`", st["predict"].median, "s", "", None,
            f"{st['predict'].median / typer_s:.1f} x import typer{was}")
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


#: One `fit` with its figure, in a fresh process: the time (s, wall and CPU) of each stage.
PHASES = """
import json, sys, time
marks = [("start", time.perf_counter(), time.process_time())]
def mark(name):
    marks.append((name, time.perf_counter(), time.process_time()))
import bendpam_entry, bendpam.cli.identify
mark("command line (typer, bendpam.cli, its fit module)")
from bendpam.identify.fitting import fit
from bendpam.lab.processed import load_processed
from bendpam.physics import presets
mark("fit's modules (NumPy, SciPy's optimiser...)")
data = load_processed(sys.argv[1])
mark("reading the processed set")
res = fit(data, presets.be_pam(), None, free="alpha0,C10,C01", hysteresis="auto")
mark("the fit (identify/: the loop ensemble)")
from bendpam.present.figures import figure7, save_figure
mark("the figure's modules (matplotlib)")
fig = figure7(data, res)
mark("figure 7: build")
save_figure(fig, sys.argv[2])
mark("figure 7: 300-dpi PNG")
print(json.dumps([[b[0], b[1] - a[1], b[2] - a[2]] for a, b in zip(marks, marks[1:])]))
"""


def phases(e: dict[str, str], cwd: str, proc: Path, png: Path, reps: int) -> list[tuple[str, float, float]]:
    """Median wall and CPU seconds of each stage of :data:`PHASES` over ``reps`` fresh processes."""
    runs = [json.loads(subprocess.run([sys.executable, "-c", PHASES, str(proc), str(png)], env=e, cwd=cwd,
                                      capture_output=True, text=True, check=True).stdout.strip().splitlines()[-1])
            for _ in range(reps)]
    return [(runs[0][i][0], sorted(r[i][1] for r in runs)[reps // 2], sorted(r[i][2] for r in runs)[reps // 2])
            for i in range(len(runs[0]))]


def fit(rec: Recorder, quick: bool, e: dict[str, str], cwd: str, before: dict[str, str] | None, ref: str) -> None:
    cli = bendpam_cli()
    reps = 3 if quick else 5
    header(f"`bendpam fit` on 25 simulated pressures: with and without its figure, interleaved, median of {reps}"
           + (f" (@{ref}: the code before)" if before else ""))
    with tempfile.TemporaryDirectory() as d:
        raw, proc = Path(d) / "raw", Path(d) / "proc"
        runner([cli, "simulate-test", "--preset", "be-pam", "--pressure-kpa", "100:220:25", "--out", str(raw)], e,
               cwd)()
        runner([cli, "process", str(raw), "--out", str(proc), "--no-figure", "--quiet"], e, cwd)()
        base = [cli, "fit", str(proc), "--preset", "be-pam", "--quiet", "--out"]
        outs = iter(range(1000))
        cands = {"with figure": runner([*base, str(Path(d) / f"fit-{next(outs)}")], e, cwd),
                 "--no-figure": runner([*base, str(Path(d) / f"fit-{next(outs)}"), "--no-figure"], e, cwd),
                 "floor: " + FLOOR.replace("matplotlib.backends.", "..."): runner([sys.executable, "-c", FLOOR], e,
                                                                                  cwd)}
        if before:  # reads the same set (its curves.nc: that code knows no curves.npz)
            cands |= {f"with figure @{ref}": runner([*base, str(Path(d) / f"fit-{next(outs)}")], before, cwd),
                      f"--no-figure @{ref}": runner([*base, str(Path(d) / f"fit-{next(outs)}"), "--no-figure"],
                                                    before, cwd)}
        st = compare(cands, repeats=reps, warmup=1)
        heavy = {"with figure": heavy_after([*base[1:], str(Path(d) / "fit-c")], e, cwd),
                 "--no-figure": heavy_after([*base[1:], str(Path(d) / "fit-d"), "--no-figure"], e, cwd)}
        stages = phases(e, cwd, proc, Path(d) / "phases.png", reps)
    for name, s in st.items():
        cpu = cpu_median(cands[name])
        print(f"  {name:40} {s}   CPU {cpu:.2f} s"
              + (f"   heavy modules: {', '.join(heavy[name]) or 'none'}" if name in heavy else ""))
        rec.record("fit", name, s)
        rec.record("fit", f"{name}: CPU s", cpu)
    for name, h in heavy.items():
        rec.record("fit", f"heavy modules: {name}", h)
    print(f"  one `fit` with its figure, stage by stage (fresh processes, median of {reps}; wall, CPU):")
    for name, w, c in stages:
        print(f"    {name:52} {w * 1e3:7.0f} ms {c * 1e3:7.0f} ms")
    rec.record("fit", "stages (name, wall s, CPU s)", stages)
    floor = next(v for k, v in st.items() if k.startswith("floor"))
    the_fit = next(w for n, w, _ in stages if n.startswith("the fit"))
    fig_cpu, nofig_cpu = cpu_median(cands["with figure"]), cpu_median(cands["--no-figure"])
    was = (f"; @{ref}: {st[f'with figure @{ref}'].median:.2f} s (CPU {cpu_median(cands[f'with figure @{ref}']):.2f}"
           f" s), --no-figure {st[f'--no-figure @{ref}'].median:.2f} s" if before else "")
    rec.row("`bendpam fit`, 25 pressures, with its figure", st["with figure"].median, "s", f"<= {FIT_TARGET_S:g} s",
            st["with figure"].median <= FIT_TARGET_S,
            f"CPU {fig_cpu:.2f} s; --no-figure {st['--no-figure'].median:.2f} s (CPU {nofig_cpu:.2f} s){was}")
    floor_cpu = next(cpu_median(c) for k, c in cands.items() if k.startswith("floor"))
    fit_cpu = next(c for n, _, c in stages if n.startswith("the fit"))
    rec.row("`fit`'s floor here: its libraries' import + the fit's numerics", floor.median + the_fit, "s", "", None,
            f"import {floor.median:.2f} s (`{FLOOR}`) + the fit {the_fit:.2f} s; CPU {floor_cpu:.2f} + "
            f"{fit_cpu:.2f} s")
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
    rec.row("`fit`: import scipy.io after scipy.optimize (saved by reading curves.npz)", med["scipy.io"], "s", "",
            None, f"xarray {med['xarray'] * 1e3:.0f} ms")


def import_report(e: dict[str, str], cwd: str) -> list[str]:
    code = f"import json, sys, bendpam; print(json.dumps([m for m in {list(HEAVY)!r} if m in sys.modules]))"
    return json.loads(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                                     env=e, cwd=cwd).stdout)


def run(rec: Recorder, quick: bool, against: str | None = BEFORE) -> None:
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as cwd, \
            tempfile.TemporaryDirectory() as old:
        e = env(cache)
        before = env(cache, checkout(against, Path(old))) if against else None
        rec.record("startup", "environment", {"PYTHONPYCACHEPREFIX": "a private folder (bytecode cached)",
                                              "PYTHONPATH": "this checkout's src first", "cli": bendpam_cli(),
                                              "before": against})
        commands(rec, quick, e, cwd, before, against or "")
        heavy = import_report(e, cwd)
        print(f"  heavy modules after `import bendpam`: {', '.join(heavy) or 'none'}")
        rec.record("startup", "heavy_modules", heavy)
        rec.row("heavy modules imported by `import bendpam`", ", ".join(heavy) or "none", "", "none", not heavy)
        fit(rec, quick, e, cwd, before, against or "")
        reader_imports(rec, quick, e, cwd)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--against", default=BEFORE, help=f"the earlier commit, or 'none' (default {BEFORE})")
    cli_args = ap.parse_args()
    ref = None if cli_args.against.lower() == "none" else cli_args.against
    standalone(lambda rec, quick: run(rec, quick, ref), "startup")
