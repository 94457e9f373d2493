"""Start-up benchmark: wall time of short CLI commands and what ``import bendpam`` pulls in.

* ``bendpam --help``, ``bendpam --version`` and ``bendpam predict --preset be-pam --pressure-kpa 200``,
  each in a fresh process (median of 7 after one warm-up run, so the OS file cache is warm);
* ``python -c "import bendpam"`` alone, and the heavy modules it leaves in ``sys.modules``;
* the largest cumulative imports under ``python -X importtime -c "import bendpam"``.

Run: ``python benchmarks/bench_startup.py [--quick]``.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _timing import Recorder, bendpam_cli, header, standalone, wall

HEAVY = ("matplotlib", "xarray", "pandas", "dask", "scipy.stats", "scipy.optimize", "scipy.integrate",
         "scipy.interpolate", "scipy.signal", "netCDF4", "h5netcdf", "typer", "rich")
TARGETS = {"--help": 0.3, "--version": 0.3, "predict": 0.8}


def import_report() -> tuple[list[str], list[tuple[float, str]]]:
    code = f"import json, sys, bendpam; print(json.dumps([m for m in {list(HEAVY)!r} if m in sys.modules]))"
    heavy = json.loads(subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                                      check=True).stdout)
    p = subprocess.run([sys.executable, "-X", "importtime", "-c", "import bendpam"], capture_output=True, text=True,
                       check=True)
    rows = []
    for line in p.stderr.splitlines():
        if not line.startswith("import time:") or "|" not in line:
            continue
        parts = [x.strip() for x in line[len("import time:"):].split("|")]
        try:
            rows.append((int(parts[1]) / 1e6, parts[2]))
        except ValueError:
            continue
    top = [r for r in rows if not r[1].startswith(" ")]  # top-level imports only
    return heavy, sorted(top, reverse=True)[:8]


def run(rec: Recorder, quick: bool) -> None:
    cli = bendpam_cli()
    reps = 3 if quick else 7
    header(f"Start-up: fresh processes, median of {reps}")
    cmds = {"--help": [cli, "--help"], "--version": [cli, "--version"],
            "predict": [cli, "predict", "--preset", "be-pam", "--pressure-kpa", "200"],
            "import bendpam": [sys.executable, "-c", "import bendpam"]}
    if not quick:
        cmds["python -c pass"] = [sys.executable, "-c", "pass"]
    for name, cmd in cmds.items():
        s = wall(cmd, repeats=reps, warmup=0 if quick else 1)
        print(f"  {name:16} {s}")
        rec.record("startup", name, s)
        if name in TARGETS:
            t = TARGETS[name]
            rec.row(f"`bendpam {name}` wall time" if name != "predict" else
                    "`bendpam predict --preset be-pam --pressure-kpa 200`", s.median, "s", f"< {t:g} s", s.median < t)
        elif name == "import bendpam":
            rec.row("`python -c 'import bendpam'` wall time", s.median, "s", "", None)
    heavy, top = import_report()
    print(f"  heavy modules after `import bendpam`: {', '.join(heavy) or 'none'}")
    print("  largest top-level imports (-X importtime, cumulative):")
    for t, mod in top:
        print(f"    {t * 1e3:7.1f} ms  {mod}")
    rec.record("startup", "heavy_modules", heavy)
    rec.record("startup", "importtime_top", [{"module": m, "cumulative_s": t} for t, m in top])
    rec.row("heavy modules imported by `import bendpam`", ", ".join(heavy) or "none", "", "none of the big ones",
            not any(m in heavy for m in ("matplotlib", "xarray", "pandas", "dask", "scipy.stats", "scipy.optimize")))


if __name__ == "__main__":
    standalone(run, "startup")
