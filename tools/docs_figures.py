"""Run the walkthrough for the documentation: its figures and the output of each command.

The tutorial (docs/tutorial.md) tells the story of examples/walkthrough.sh.  This script runs the
script's ``bendpam`` commands in order, in-process (``bendpam.cli.main``), in an empty temporary
folder, followed by the few :data:`EXTRA_COMMANDS` the tutorial shows besides, and keeps

* the figures the commands write (:data:`FIGURES`, renamed for the site) and the HTML report;
* ``outputs.json``: each command line with its stdout, stderr and run time.

The documentation build (tools/docs_hooks.py) calls it in a subprocess and caches the result by a
hash of the sources, so nothing is committed and nothing is written into the source tree:

    python tools/docs_figures.py OUTDIR        # writes OUTDIR/*.png, OUTDIR/report-be.html, OUTDIR/outputs.json

It takes about 15 s on a 2-core machine.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import shlex
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "examples" / "walkthrough.sh"

#: Commands the tutorial shows besides the walkthrough's, run after it in the same folder.
EXTRA_COMMANDS: tuple[str, ...] = (
    "bendpam curve --actuator be.toml --pressure-kpa 100 150 200 --out curves.png",
)

#: Pages whose first ```python block draws figures: the block runs in its own empty folder (after the
#: walkthrough) and these files of that folder are published with the site under the same names.
PAGE_FIGURES: dict[Path, tuple[str, ...]] = {
    ROOT / "docs" / "mujoco.md": ("mujoco-grip.png",),  # needs the mujoco extra
}

#: A ```python code block of a Markdown page (its body is group 1).
PYTHON_BLOCK = re.compile(r"^```python\n(.*?)^```\n", re.MULTILINE | re.DOTALL)

#: Files of the walkthrough folder published with the site: name on the site <- path in the folder.
FIGURES: dict[str, str] = {
    "curves.png": "curves.png",
    "figure4-be.png": "processed-be/figure4.png",
    "figure7-be.png": "fit-be/figure7.png",
    "figure4-loop.png": "processed-loop/figure4.png",
    "figure7-loop.png": "fit-loop/figure7.png",
    "finger.png": "finger.png",
    "sweep.png": "sweep.png",
    "kapandji.png": "hand/kapandji.png",
    "report-be.html": "report-be.html",
}


def walkthrough_steps(script: Path = SCRIPT) -> list[tuple[str, list[str]]]:
    """The numbered steps of the walkthrough: ``[(title, [command, ...]), ...]``.

    A step starts at a comment ``# N. title``; commands are the ``bendpam ...`` lines, with
    backslash continuations joined and runs of blanks collapsed to one.
    """
    steps: list[tuple[str, list[str]]] = []
    pending = ""
    for raw in script.read_text(encoding="utf-8").splitlines():
        line = raw.strip()
        if pending:
            line = pending + " " + line
            pending = ""
        if line.endswith("\\"):
            pending = line[:-1].strip()
            continue
        if line.startswith("#"):
            text = line.lstrip("#").strip()
            number, _, title = text.partition(". ")
            if number.isdigit() and title:
                steps.append((title.strip(), []))
            continue
        if line.startswith("bendpam "):
            if not steps:
                steps.append(("", []))
            steps[-1][1].append(" ".join(line.split()))
    return steps


def walkthrough_commands(script: Path = SCRIPT) -> list[str]:
    """Every ``bendpam`` command of the walkthrough, in order (see :func:`walkthrough_steps`)."""
    return [c for _, cmds in walkthrough_steps(script) for c in cmds]


#: A ```bash code block of a Markdown page (its body is group 1).
BASH_BLOCK = re.compile(r"^```bash\n(.*?)^```\n", re.MULTILINE | re.DOTALL)


def block_commands(body: str) -> list[str]:
    """The ``bendpam`` commands of a bash code block (continuations joined, blanks collapsed)."""
    commands, pending = [], ""
    for raw in body.splitlines():
        line = (pending + " " + raw.strip()).strip() if pending else raw.strip()
        pending = ""
        if line.endswith("\\"):
            pending = line[:-1].strip()
            continue
        if line.startswith("bendpam "):
            commands.append(" ".join(line.split()))
    return commands


def tutorial_commands(markdown: str) -> list[str]:
    """Every ``bendpam`` command of the tutorial's bash blocks, in order."""
    return [c for m in BASH_BLOCK.finditer(markdown) for c in block_commands(m.group(1))]


def check_tutorial(markdown: str) -> list[str]:
    """Differences between the tutorial's commands and the walkthrough's (empty if none)."""
    extras = set(EXTRA_COMMANDS)
    shown = [c for c in tutorial_commands(markdown) if c not in extras]
    expected = walkthrough_commands()
    problems = []
    for i, (a, b) in enumerate(zip(shown, expected, strict=False)):
        if a != b:
            problems.append(f"command {i + 1} of the tutorial is `{a}`, the walkthrough's is `{b}`")
            break
    if not problems and len(shown) != len(expected):
        problems.append(f"the tutorial shows {len(shown)} walkthrough commands, examples/walkthrough.sh has "
                        f"{len(expected)}")
    return problems


def run_commands(commands: list[str], folder: Path) -> list[dict]:
    """Run each ``bendpam ...`` command in ``folder`` in this process; stop at the first failure."""
    os.environ.setdefault("MPLBACKEND", "Agg")
    from bendpam.cli import main

    results = []
    here = Path.cwd()
    os.chdir(folder)
    try:
        for command in commands:
            argv = shlex.split(command)[1:]
            out, err = io.StringIO(), io.StringIO()
            t0 = time.perf_counter()
            with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
                code = main(argv)
            seconds = time.perf_counter() - t0
            if code != 0:
                raise RuntimeError(f"`{command}` exited with status {code}: {err.getvalue().strip()}")
            results.append({"command": command, "stdout": out.getvalue(), "stderr": err.getvalue(),
                            "seconds": round(seconds, 2)})
    finally:
        os.chdir(here)
    return results


def run_page_figures(out_dir: Path) -> list[str]:
    """Run the first ```python block of each page of :data:`PAGE_FIGURES` and copy its figures to ``out_dir``."""
    os.environ.setdefault("MPLBACKEND", "Agg")
    names: list[str] = []
    here = Path.cwd()
    for page, files in PAGE_FIGURES.items():
        block = PYTHON_BLOCK.search(page.read_text(encoding="utf-8"))
        if block is None:
            raise RuntimeError(f"{page.name} has no ```python block to draw {', '.join(files)}")
        with tempfile.TemporaryDirectory(prefix="bendpam-page-") as tmp:
            os.chdir(tmp)
            try:
                with contextlib.redirect_stdout(io.StringIO()):
                    exec(compile(block.group(1), str(page), "exec"), {"__name__": "__docs__"})
            finally:
                os.chdir(here)
            for name in files:
                shutil.copyfile(Path(tmp) / name, out_dir / name)
                names.append(name)
    return names


def generate(out_dir: Path) -> dict:
    """Run the walkthrough and the extra commands; write the figures and ``outputs.json`` to ``out_dir``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bendpam-walkthrough-") as tmp:
        folder = Path(tmp)
        results = run_commands([*walkthrough_commands(), *EXTRA_COMMANDS], folder)
        for name, rel in FIGURES.items():
            shutil.copyfile(folder / rel, out_dir / name)
    page_files = run_page_figures(out_dir)
    record = {"commands": results, "files": sorted([*FIGURES, *page_files]),
              "seconds": round(time.perf_counter() - t0, 1)}
    (out_dir / "outputs.json").write_text(json.dumps(record, indent=1), encoding="utf-8")
    return record


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        print("usage: python tools/docs_figures.py OUTDIR", file=sys.stderr)
        return 2
    record = generate(Path(args[0]))
    print(f"wrote {len(record['files'])} files and outputs.json to {args[0]} in {record['seconds']} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
