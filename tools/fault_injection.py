#!/usr/bin/env python
"""Fault injection for the ``bendpam`` command line (issue 12).

Runs the real commands as subprocesses and checks, for every case, that the outcome is one of

* exit 0 (and strict JSON on stdout with ``--json``: no ``NaN``/``Infinity``),
* exit 2 with ONE line ``bendpam: error: ...`` on stderr (``bendpam: warning:`` lines may precede it),
* exit 130/143 with the line ``bendpam: interrupted; no outputs were changed`` (SIGINT/SIGTERM), or
  ``bendpam: interrupted after writing DIR`` when the signal came after the outputs were committed,

and never a traceback, an exit-1 internal error or a hang.  Runs killed at random times (SIGINT,
SIGTERM, SIGKILL) of ``process``, ``fit``, ``report`` and ``sweep`` check the output-set invariant:
``--out`` is either exactly the previous complete set (sha256 of every file) or a complete new set
whose ``manifest.json`` matches its files, never a mixture; no temporaries are left after a signal
exit or after the next run.  Concurrent runs on one ``--out`` must refuse with one line or both
complete.

Usage::

    python tools/fault_injection.py [--quick] [--seed N] [--workdir DIR]

``tests/test_faults.py`` imports this module for its (smaller) suite.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

INTERRUPT_LINE = "bendpam: interrupted; no outputs were changed"
#: the interrupt line once the outputs were committed (issue 21)
INTERRUPT_AFTER = "bendpam: interrupted after writing "
TIMEOUT_S = 120.0
TEMP_RE = re.compile(r"\..+\.bendpam-(lock|tmp-|old-|del-).*")


# ----------------------------------------------------------------------------------------------
# running and classifying
# ----------------------------------------------------------------------------------------------
@dataclass
class Run:
    args: list[str]
    rc: int | None
    stdout: str
    stderr: str
    seconds: float
    hung: bool = False


def cli(*args: object) -> list[str]:
    return [sys.executable, "-m", "bendpam_entry", *(str(a) for a in args)]


def child_env() -> dict[str, str]:
    """The environment of every command run here: no progress lines, however long a command takes.

    Off a terminal a command writes a progress line every few seconds of work; a command that
    fails after that would show two lines on stderr.  What the checks see must not depend on the
    load of the machine, so the interval is infinite (``BENDPAM_PROGRESS_INTERVAL_S=inf``).
    """
    return {**os.environ, "BENDPAM_PROGRESS_INTERVAL_S": "inf"}


def run(args: Sequence[object], cwd: Path, timeout: float = TIMEOUT_S, env: dict[str, str] | None = None) -> Run:
    """Run ``bendpam args`` in ``cwd``; ``env`` adds to (or overrides) :func:`child_env`."""
    argv = [str(a) for a in args]
    t0 = time.monotonic()
    try:
        p = subprocess.run(cli(*argv), cwd=cwd, capture_output=True, text=True, timeout=timeout,
                           stdin=subprocess.DEVNULL, env={**child_env(), **(env or {})})
    except subprocess.TimeoutExpired as exc:
        out = exc.stdout.decode(errors="replace") if isinstance(exc.stdout, bytes) else (exc.stdout or "")
        err = exc.stderr.decode(errors="replace") if isinstance(exc.stderr, bytes) else (exc.stderr or "")
        return Run(argv, None, out, err, time.monotonic() - t0, hung=True)
    return Run(argv, p.returncode, p.stdout, p.stderr, time.monotonic() - t0)


def _no_constant(name: str):
    raise ValueError(f"non-JSON constant {name}")


def strict_json(text: str):
    """``json.loads`` that refuses NaN, Infinity and -Infinity."""
    return json.loads(text, parse_constant=_no_constant)


#: The last line of a refusal of several input files (issue 22: every bad file named at once).
_COUNT_LINE = re.compile(r"bendpam: error: \d+ of \d+ file\(s\) cannot be processed")


def _per_file_refusal(errors: list[str]) -> bool:
    """One line per bad input file (each naming a different file), then the count line."""
    if len(errors) < 3 or not _COUNT_LINE.match(errors[-1]):
        return False
    files = [ln[len("bendpam: error: "):].split(":", 1)[0] for ln in errors[:-1]]
    return len(set(files)) == len(files)


def classify(r: Run) -> tuple[str, str]:
    """``(kind, detail)``: kind is ok, error, interrupt, traceback, internal, hang, bad-json or bad-error."""
    err_lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    if r.hung:
        return "hang", f"no exit within the timeout ({r.seconds:.0f} s)"
    if "Traceback (most recent call last)" in r.stderr:
        return "traceback", r.stderr[-2000:]
    if r.rc == 1:
        return "internal", r.stderr.strip()[-500:]
    if r.rc == 0:
        if "--json" in r.args:
            try:
                strict_json(r.stdout)
            except ValueError as exc:
                return "bad-json", f"{exc}: {r.stdout[:300]!r}"
        return "ok", ""
    if r.rc == 2:
        errors = [ln for ln in err_lines if ln.startswith("bendpam: error:")]
        others = [ln for ln in err_lines if not ln.startswith(("bendpam: error:", *NOTE_PREFIXES))]
        if len(errors) == 1 and not others and err_lines[-1] == errors[0]:
            return "error", errors[0]
        if not others and _per_file_refusal(errors) and err_lines[-1] == errors[-1]:
            return "error", errors[-1]
        return "bad-error", r.stderr.strip()[-800:]
    if r.rc in (130, 143):
        if err_lines and (err_lines[-1] == INTERRUPT_LINE or err_lines[-1].startswith(INTERRUPT_AFTER)):
            return "interrupt", ""
        return "bad-error", f"exit {r.rc}: {r.stderr.strip()[-500:]}"
    return "bad-error", f"exit {r.rc}: {r.stderr.strip()[-500:]}"


CLEAN = {"ok", "error", "interrupt"}
#: stderr lines a successful command may print (warnings about the result, not errors)
NOTE_PREFIXES = ("bendpam: warning:", "bendpam: caution:")


def _only_notes(stderr: str) -> bool:
    """True when stderr is empty or holds only warning/caution lines."""
    return all(ln.startswith(NOTE_PREFIXES) for ln in stderr.splitlines() if ln.strip())


# ----------------------------------------------------------------------------------------------
# output sets
# ----------------------------------------------------------------------------------------------
def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def snapshot(target: Path) -> dict[str, str] | None:
    """sha256 of every file of a target folder (or of a target file, under the key '')."""
    if not target.exists():
        return None
    if target.is_file():
        return {"": sha256(target)}
    return {str(p.relative_to(target)): sha256(p) for p in sorted(target.rglob("*")) if p.is_file()}


def temporaries(target: Path) -> list[str]:
    name = target.name
    if not target.parent.is_dir():
        return []
    return sorted(e for e in os.listdir(target.parent) if e.startswith(f".{name}.bendpam-") and TEMP_RE.fullmatch(e))


def manifest_problem(target: Path) -> str | None:
    """None when ``target`` is a complete set (its manifest.json lists exactly its files)."""
    m = target / "manifest.json"
    if not m.is_file():
        return "no manifest.json"
    try:
        man = strict_json(m.read_text())
    except ValueError as exc:
        return f"manifest.json is not strict JSON ({exc})"
    listed = {f["path"]: (f["size"], f["sha256"]) for f in man.get("files", [])}
    present = {str(p.relative_to(target)) for p in target.rglob("*") if p.is_file()} - {"manifest.json"}
    if set(listed) != present:
        return f"manifest lists {sorted(listed)} but the folder holds {sorted(present)}"
    for name, (size, digest) in listed.items():
        p = target / name
        if p.stat().st_size != size or sha256(p) != digest:
            return f"{name} does not match manifest.json"
    return None


def file_problem(target: Path) -> str | None:
    """None when a single-file target (report .html, sweep .nc) is complete."""
    data = target.read_bytes()
    if target.suffix == ".html":
        return None if data.rstrip().endswith(b"</html>") else "report.html is incomplete"
    if target.suffix == ".nc":
        if not data.startswith(b"\x89HDF") and not data.startswith(b"CDF"):
            return "not a NetCDF file"
        try:
            import xarray as xr

            with xr.open_dataset(target) as ds:
                ds.load()
        except Exception as exc:  # any failure to read back is an incomplete file
            return f"the NetCDF file does not load ({type(exc).__name__}: {exc})"
        return None
    return None


def set_problem(target: Path, before: dict[str, str] | None) -> str | None:
    """The output-set invariant: previous set exactly, or a complete new set; None when it holds."""
    now = snapshot(target)
    if now == before:
        return None
    if now is None:
        return "the previous output disappeared"
    if target.is_dir():
        why = manifest_problem(target)
        return None if why is None else f"mixed or incomplete set: {why}"
    why = file_problem(target)
    return None if why is None else f"mixed or incomplete file: {why}"


# ----------------------------------------------------------------------------------------------
# tallies
# ----------------------------------------------------------------------------------------------
@dataclass
class Tally:
    counts: Counter = field(default_factory=Counter)
    failures: list[str] = field(default_factory=list)
    startup: list[str] = field(default_factory=list)

    def add(self, kind: str, what: str, detail: str = "") -> None:
        self.counts["cases"] += 1
        self.counts[kind] += 1
        if kind not in CLEAN:
            self.failures.append(f"[{kind}] {what}: {detail}")

    def fail(self, kind: str, what: str, detail: str) -> None:
        self.counts[kind] += 1
        self.failures.append(f"[{kind}] {what}: {detail}")

    def report(self) -> str:
        c = self.counts
        rows = [("cases tried", c["cases"]), ("clean exits (0)", c["ok"]),
                ("clean errors (one line, exit 2)", c["error"]),
                ("interrupts (130/143)", c["interrupt"]), ("killed by SIGKILL", c["killed"]),
                ("signals after completion (exit -sig)", c["late"]),
                ("signals during start-up (see below)", c["startup"]),
                ("concurrent refusals", c["busy"]), ("tracebacks", c["traceback"]),
                ("exit-1 internal errors", c["internal"]), ("hangs", c["hang"]),
                ("other bad exits / multi-line errors", c["bad-error"]), ("NaN/Infinity in --json", c["bad-json"]),
                ("mixed output sets", c["mixed"]), ("leftover temporaries", c["leftover"]),
                ("user files lost or changed", c["user-file-lost"]),
                ("wrong outcomes (accepted/refused/said wrongly)", c["wrong-outcome"])]
        return "\n".join(f"{k:>38}: {v}" for k, v in rows)

    @property
    def ok(self) -> bool:
        return not self.failures


def check_run(tally: Tally, r: Run, what: str) -> str:
    kind, detail = classify(r)
    tally.add(kind, what, detail)
    return kind


# ----------------------------------------------------------------------------------------------
# inputs
# ----------------------------------------------------------------------------------------------
def build_inputs(work: Path) -> dict[str, Path]:
    """Small raw tests, their processed folder and a fit: the fixtures of every case."""
    work.mkdir(parents=True, exist_ok=True)
    steps = [
        ["simulate-test", "--preset", "be-pam", "--pressure-kpa", "100:200:3", "--cycles", "2", "--rate-hz", "10",
         "--seed", "1", "--out", "raw"],
        ["process", "raw", "--out", "proc", "--no-figure"],
        ["actuator", "--preset", "be-pam", "--out", "be.toml"],
    ]
    for s in steps:
        r = run(s, work)
        if r.rc != 0:
            raise RuntimeError(f"building inputs failed: {' '.join(s)}: {r.stderr}")
    return {"work": work, "raw": work / "raw", "proc": work / "proc", "toml": work / "be.toml"}


# the commands whose outputs are killed at random times: (name, args with {out}, target name)
KILL_COMMANDS: dict[str, tuple[list[str], str]] = {
    "process": (["process", "{raw}", "--out", "{out}"], "proc_out"),
    "fit": (["fit", "{proc}", "--preset", "be-pam", "--out", "{out}"], "fit_out"),
    "report": (["report", "{raw}", "--preset", "be-pam", "--no-progress", "--out", "{out}"], "report.html"),
    "sweep": (["sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:40", "--pressure-kpa", "100:200:20",
               "--no-progress", "--out", "{out}"], "sweep.nc"),
}


def kill_args(command: str, inputs: dict[str, Path], out: Path) -> list[str]:
    args, _ = KILL_COMMANDS[command]
    return [a.format(raw=inputs["raw"], proc=inputs["proc"], out=out) for a in args]


def catches(pid: int, signum: int) -> bool | None:
    """Whether process ``pid`` has a handler for ``signum`` (Linux ``/proc``); None where that is unknown."""
    try:
        status = Path(f"/proc/{pid}/status").read_text(encoding="utf-8")
    except OSError:
        return None
    mask = next((line.split()[1] for line in status.splitlines() if line.startswith("SigCgt:")), None)
    return None if mask is None else bool(int(mask, 16) >> (signum - 1) & 1)


def wait_until(ready: Callable[[], bool], p: subprocess.Popen, timeout: float = TIMEOUT_S) -> bool:
    """Poll ``ready()`` until it holds (True) or ``p`` has ended (False); the timeout only guards a hang."""
    deadline = time.monotonic() + timeout
    while p.poll() is None:
        if ready():
            return True
        if time.monotonic() > deadline:
            raise TimeoutError("the awaited state never came")
        time.sleep(0.002)
    return False


def kill_case(tally: Tally, command: str, inputs: dict[str, Path], folder: Path, sig: int, delay: float,
              fraction: float | None = None, mid_work: bool = False) -> None:
    """Run ``command`` into a target holding a previous complete output; send ``sig`` after ``delay``.

    With ``fraction``, the signal is sent at that fraction of the baseline run's duration instead
    (at least 0.3 s, after start-up).  With ``mid_work``, it is sent as soon as the command holds
    the lock on its output (``.<target>.bendpam-lock`` appears: the work under way), whatever the
    time: the one way to land mid-work on a machine of any speed and load.
    """
    _, target_name = KILL_COMMANDS[command]
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / target_name
    args = kill_args(command, inputs, target)
    if snapshot(target) is None:  # a previous complete set to compare with
        r = run(args, folder)
        if classify(r)[0] != "ok":
            tally.fail("bad-error", f"{command} (baseline)", r.stderr[-500:])
            return
        if fraction is not None:
            delay = max(0.3, fraction * r.seconds)
    what = f"{command} killed by {signal.Signals(sig).name} after {delay:.2f} s"
    before = snapshot(target)
    t0 = time.monotonic()
    lock = target.parent / f".{target.name}.bendpam-lock"
    p = subprocess.Popen(cli(*args), cwd=folder, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         stdin=subprocess.DEVNULL, env=child_env())
    if mid_work:
        wait_until(lock.exists, p)  # nothing fills its pipes meanwhile: no progress lines (child_env)
        what = f"{command} killed by {signal.Signals(sig).name} once it held the lock"
    else:
        time.sleep(max(0.0, delay - (time.monotonic() - t0)))
    if p.poll() is None:
        p.send_signal(sig)
    try:
        out, err = p.communicate(timeout=TIMEOUT_S)
        r = Run(args, p.returncode, out, err, time.monotonic() - t0)
    except subprocess.TimeoutExpired:
        p.kill()
        out, err = p.communicate()
        r = Run(args, None, out, err, time.monotonic() - t0, hung=True)
    now = snapshot(target)
    if r.rc == -signal.SIGKILL:
        tally.counts["cases"] += 1
        tally.counts["killed"] += 1
    elif r.rc == -sig and _only_notes(r.stderr) and r.stdout.strip() and set_problem(target, None) is None:
        # the signal came after the command had finished and printed its result (the new output is complete):
        # the process ended by the signal's default action while exiting (a shell reports 128 + signal)
        tally.counts["cases"] += 1
        tally.counts["late"] += 1
    elif r.rc == -sig and now == before and not r.stdout.strip() and "bendpam/cli/app.py" not in r.stderr \
            and (not r.stderr.strip() or r.stderr.rstrip().endswith("KeyboardInterrupt")):
        # the signal came while Python started or imported bendpam, before main() installed its handlers:
        # the default action (and for SIGINT a KeyboardInterrupt traceback); nothing was written yet
        tally.counts["cases"] += 1
        tally.counts["startup"] += 1
        tally.startup.append(f"{what}: exit {r.rc}, {len(r.stderr.splitlines())} line(s) on stderr")
    else:
        kind, detail = classify(r)
        tally.add(kind, what, detail)
    why = set_problem(target, before)
    if why is not None:
        tally.fail("mixed", what, why)
    if r.rc != -signal.SIGKILL and temporaries(target):
        tally.fail("leftover", what, f"after a signal exit: {temporaries(target)}")
    if r.rc == -signal.SIGKILL:  # the next run must clean up after the killed one
        r2 = run(args, folder)
        kind, detail = classify(r2)
        tally.add(kind, f"{command} after a SIGKILL", detail)
        if kind == "ok" and (set_problem(target, None) is not None):
            tally.fail("mixed", f"{command} after a SIGKILL", set_problem(target, None) or "")
        if temporaries(target):
            tally.fail("leftover", f"{command} after a SIGKILL", str(temporaries(target)))


def kill_series(tally: Tally, command: str, inputs: dict[str, Path], folder: Path, n: int, seed: int,
                max_delay: float, startup_fraction: float = 0.1) -> None:
    """``n`` runs killed at random times (SIGINT, SIGTERM, SIGKILL in turn).

    A fraction ``startup_fraction`` of the kill times falls in the first 0.4 s (interpreter start-up and
    imports), the rest between 0.4 s and ``max_delay``.
    """
    rng = random.Random(seed)
    folder.mkdir(parents=True, exist_ok=True)
    sigs = [signal.SIGINT, signal.SIGTERM, signal.SIGKILL]
    for i in range(n):
        delay = rng.uniform(0.4, max_delay) if rng.random() >= startup_fraction else rng.uniform(0.0, 0.4)
        kill_case(tally, command, inputs, folder, sigs[i % 3], delay)


def concurrent_case(tally: Tally, command: str, inputs: dict[str, Path], folder: Path, stagger: float = 0.0) -> None:
    """Two runs on one --out: one refuses with one line, or both complete; never a mixture."""
    _, target_name = KILL_COMMANDS[command]
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / target_name
    args = kill_args(command, inputs, target)
    with ThreadPoolExecutor(2) as ex:
        f1 = ex.submit(run, args, folder)
        time.sleep(stagger)
        f2 = ex.submit(run, args, folder)
        results = [f1.result(), f2.result()]
    what = f"two concurrent {command} runs (stagger {stagger:.2f} s)"
    kinds = []
    for r in results:
        kind, detail = classify(r)
        if kind == "error" and ("another bendpam" in detail.lower() or "busy" in detail.lower()
                                or "lock" in detail.lower() or "running" in detail.lower()):
            kind = "busy"
            tally.counts["cases"] += 1
            tally.counts["busy"] += 1
        else:
            tally.add(kind, what, detail)
        kinds.append(kind)
    if not all(k in ("ok", "busy") for k in kinds) or "ok" not in kinds:
        tally.fail("bad-error", what, f"outcomes {kinds}: {[r.stderr[-300:] for r in results]}")
    why = set_problem(target, None)
    if why is not None:
        tally.fail("mixed", what, why)
    if temporaries(target):
        tally.fail("leftover", what, str(temporaries(target)))


# ----------------------------------------------------------------------------------------------
# bad command lines
# ----------------------------------------------------------------------------------------------
def bad_command_lines(inp: dict[str, Path]) -> list[list[str]]:
    raw, proc, toml = str(inp["raw"]), str(inp["proc"]), str(inp["toml"])
    f100 = str(inp["raw"] / "be-pam_100kPa.csv")
    sim = ["simulate-test", "--preset", "be-pam", "--out", "sim_x"]
    sw = ["sweep", "--preset", "be-pam", "--no-progress"]
    return [
        # simulate-test: sizes and ranges
        [*sim, "--pressure-kpa", "150", "--rate-hz", "1e6"],
        [*sim, "--pressure-kpa", "150", "--rate-hz", "1e5", "--cycles", "1000"],
        [*sim, "--pressure-kpa", "150", "--rate-hz", "0"],
        [*sim, "--pressure-kpa", "150", "--rate-hz", "-5"],
        [*sim, "--pressure-kpa", "150", "--rate-hz", "nan"],
        [*sim, "--pressure-kpa", "150", "--cycles", "0"],
        [*sim, "--pressure-kpa", "150", "--cycles", "-1"],
        [*sim, "--pressure-kpa", "150", "--cycles", "99999999999999999999"],
        [*sim, "--pressure-kpa", "150", "--dwell-s", "1e6", "--cycles", "1000"],
        [*sim, "--pressure-kpa", "150", "--speed-mm-min", "1e-6"],
        [*sim, "--pressure-kpa", "150", "--noise-n", "-1"],
        [*sim, "--pressure-kpa", "150", "--hysteresis", "inf"],
        [*sim, "--pressure-kpa", "150", "--hysteresis-law", "bogus"],
        [*sim, "--pressure-kpa", "150", "--fixture", "1,2"],
        [*sim, "--pressure-kpa", "150", "--fixture", "-35,2.5,4"],
        [*sim, "--pressure-kpa", "100:200:30000000"],
        [*sim, "--pressure-kpa", "1e300"],
        [*sim, "--pressure-kpa", "-100"],
        [*sim, "--pressure-kpa", "10"],
        [*sim, "--pressure-kpa", "100:200"],
        [*sim, "--pressure-kpa", "a:b:c"],
        ["simulate-test", "--preset", "be-pam", "--pressure-kpa", "150", "--out", f100],  # a file for a folder
        # process
        ["process", raw, "--out", "p_x", "--grid-points", "0"],
        ["process", raw, "--out", "p_x", "--grid-points", "100000000"],
        ["process", raw, "--out", "p_x", "--cutoff-hz", "-1"],
        ["process", raw, "--out", "p_x", "--cutoff-hz", "1e9"],
        ["process", raw, "--out", "p_x", "--l0-mm", "-1"],
        ["process", raw, "--out", "p_x", "--l0-mm", "0"],
        ["process", raw, "--out", "p_x", "--reversal-fraction", "2"],
        ["process", raw, "--out", "p_x", "--reversal-fraction", "-0.1"],
        ["process", raw, "--out", "p_x", "--rate-hz", "1e6"],
        ["process", raw, "--out", "p_x", "--pressure-kpa", "1,2"],
        ["process", raw, "--out", "p_x", "--columns", "time=nope"],
        ["process", raw, "--out", "p_x", "--tare-n", "inf"],
        ["process", "missing_dir", "--out", "p_x"],
        ["process", raw, "--out", raw],  # into its own input
        ["process", raw, "--out", f100],  # a file for a folder
        ["process", toml, "--out", "p_x"],  # a TOML for a raw file
        # fit
        ["fit", proc, "--preset", "be-pam", "--out", "f_x", "--free", "bogus"],
        ["fit", proc, "--preset", "be-pam", "--out", "f_x", "--free", ""],
        ["fit", proc, "--preset", "be-pam", "--out", "f_x", "--fit-range", "half"],
        ["fit", proc, "--preset", "be-pam", "--out", "f_x", "--hysteresis", "--hysteresis-law", "x"],
        ["fit", proc, "--preset", "be-pam", "--out", "f_x", "--tension", f100, "--width-mm", "-1",
         "--thickness-mm", "1", "--gauge-length-mm", "10"],
        ["fit", proc, "--preset", "be-pam", "--out", "f_x", "--tension", f100, "--gauge-length-mm", "10"],
        ["fit", f100, "--preset", "be-pam", "--out", "f_x"],  # a file for a folder
        ["fit", "missing_dir", "--preset", "be-pam", "--out", "f_x"],
        ["fit", proc, "--out", "f_x"],
        ["fit", proc, "--preset", "be-pam", "--actuator", toml, "--out", "f_x"],
        ["fit", proc, "--actuator", raw, "--out", "f_x"],  # a folder for a file
        ["fit-material", f100, "--width-mm", "-1", "--thickness-mm", "1", "--gauge-length-mm", "10"],
        # report
        ["report", raw, "--preset", "be-pam", "--out", "r.pdf"],
        ["report", raw, "--preset", "be-pam", "--out", "nodir/r.html"],
        ["report", raw, "--preset", "be-pam", "--out", "r.html", "--pressure-kpa", "1,2"],
        ["report", raw, "--preset", "be-pam", "--out", "r.html", "--model", "bogus"],
        ["report", raw, "--preset", "be-pam", "--out", "r.html", "--l0-mm", "-3"],
        ["report", raw, "--preset", "be-pam", "--out", raw],  # a folder for a file
        # sweep
        [*sw, "--pressure-kpa", "100", "--out", "s.nc", "--workers", "0"],
        [*sw, "--pressure-kpa", "100", "--out", "s.nc", "--workers", "-1"],
        [*sw, "--pressure-kpa", "100", "--out", "s.nc", "--workers", "100000"],
        [*sw, "--pressure-kpa", "100", "--out", "s.csv"],
        [*sw, "--pressure-kpa", "100", "--out", "s.nc", "--chunk-cases", "0"],
        [*sw, "--pressure-kpa", "100", "--out", "s.nc", "--max-points", "-5"],
        [*sw, "--pressure-kpa", "100:200:1000000", "--param", "alpha0_deg=60:80:1000000", "--out", "s.nc"],
        [*sw, "--pressure-kpa", "100:200:100000", "--param", "alpha0_deg=60:80:100", "--out", "s.nc",
         "--max-points", "1000000000"],
        [*sw, "--pressure-kpa", "100", "--param", "bogus=1:2:3", "--out", "s.nc"],
        [*sw, "--pressure-kpa", "100", "--param", "alpha0_deg", "--out", "s.nc"],
        [*sw, "--pressure-kpa", "100", "--out", "nodir/s.nc"],
        [*sw, "--pressure-kpa", "100", "--out", raw + ".nc", "--plot", raw],
        # predict and friends
        ["predict", "--preset", "be-pam", "--pressure-kpa", "100:200:30000000"],
        ["predict", "--preset", "be-pam", "--pressure-kpa", "1e9", "--json"],
        ["predict", "--preset", "be-pam", "--pressure-kpa", "150", "--cycle", "--json"],
        ["predict", "--preset", "be-pam", "--pressure-kpa", "150", "--cycle", "--loop-law", "pi",
         "--loop-a0-nmm", "-1", "--loop-a1-nmm-per-kpa", "0.1", "--loop-angle-deg", "5"],
        ["predict", "--actuator", "missing.toml", "--pressure-kpa", "150"],
        ["predict", "--actuator", raw, "--pressure-kpa", "150"],
        ["curve", "--preset", "be-pam", "--pressure-kpa", "150", "--points", "0", "--out", "c.csv"],
        ["curve", "--preset", "be-pam", "--pressure-kpa", "100:200:1000", "--points", "100000", "--out", "c.csv"],
        ["stresses", "--preset", "be-pam", "--pressure-kpa", "150", "--json"],
        ["inspect", f100, "--json"],
        ["bogus-command"],
        ["process"],
        ["--debug", "fit", proc],
        # later finds: design grids, seeds
        [*sim, "--pressure-kpa", "150", "--seed", "-1"],
        ["finger", "--preset", "be-pam", "--pressure-kpa", "100:200:1000000", "--json"],
        ["grasp", "--preset", "be-pam", "--pressure-kpa", "100:200:1000", "--diameter-mm", "50:200:1000", "--json"],
        ["wrist", "--preset", "be-pam", "--pressure-kpa", "100:200:1000000", "--json"],
        ["grasp", "--preset", "be-pam", "--pressure-kpa", "150", "--diameter-mm", "100", "--fingers", "0"],
        ["hand", "--pressure-kpa", "100:200:1000000", "--json"],
        ["hand", "--workspace", "1000", "--json"],
        ["wrist", "--preset", "bc-pam", "--pressure-kpa", "140", "--payload-g", "-5", "--json"],
    ]


# ----------------------------------------------------------------------------------------------
# mutated inputs
# ----------------------------------------------------------------------------------------------
def _mutate_raw(src: Path, dst: Path, how: str, rng: random.Random) -> None:
    data = src.read_bytes()
    if how == "truncate-half":
        data = data[: len(data) // 2]
    elif how == "truncate-header":
        data = data[:200]
    elif how == "empty":
        data = b""
    elif how == "garble":
        b = bytearray(data)
        for _ in range(max(1, len(b) // 50)):
            b[rng.randrange(len(b))] = rng.randrange(256)
        data = bytes(b)
    elif how == "binary":
        data = bytes(rng.randrange(256) for _ in range(4000))
    elif how == "nan-force":
        data = re.sub(rb",(-?[0-9.]+)\r?\n", b",nan\n", data)
    elif how == "const-stroke":
        lines = data.decode().splitlines()
        out = [ln if not ln[:1].isdigit() else ",".join([ln.split(",")[0], "1.0", ln.split(",")[2]]) for ln in lines]
        data = ("\n".join(out) + "\n").encode()
    elif how == "utf16":
        data = data.decode().encode("utf-16")
    elif how == "crlf-mixed":
        data = data.replace(b"\n", b"\r", 40)
    elif how == "dup-time":
        lines = data.decode().splitlines()
        data = ("\n".join(lines[:60] + lines[40:]) + "\n").encode()
    dst.parent.mkdir(parents=True, exist_ok=True)
    dst.write_bytes(data)


RAW_MUTATIONS = ["truncate-half", "truncate-header", "empty", "garble", "binary", "nan-force", "const-stroke",
                 "utf16", "crlf-mixed", "dup-time"]

TOML_MUTATIONS: dict[str, Callable[[str], str]] = {
    "hysteresis=5": lambda t: t + "\n[hysteresis]\nlaw = \"pi\"\nhysteresis = 5\n",
    "hysteresis-table-strings": lambda t: t + "\n[hysteresis]\nlaw = \"pi\"\na0_nmm = \"1\"\n",
    "hysteresis-scalar-key": lambda t: t.replace("[actuator]", "hysteresis = 5\n[actuator]"),
    "alpha0=true": lambda t: re.sub(r"alpha0_deg = .*", "alpha0_deg = true", t),
    "alpha0='70'": lambda t: re.sub(r"alpha0_deg = .*", 'alpha0_deg = "70"', t),
    "alpha0=nan": lambda t: re.sub(r"alpha0_deg = .*", "alpha0_deg = nan", t),
    "alpha0=inf": lambda t: re.sub(r"alpha0_deg = .*", "alpha0_deg = inf", t),
    "alpha0=1e308": lambda t: re.sub(r"alpha0_deg = .*", "alpha0_deg = 1e308", t),
    "alpha0=[70]": lambda t: re.sub(r"alpha0_deg = .*", "alpha0_deg = [70]", t),
    "R0=-1": lambda t: re.sub(r"R0_mm = .*", "R0_mm = -1", t),
    "unknown-key": lambda t: t.replace("[actuator]", "[actuator]\nbogus_key = 1"),
    "unknown-table": lambda t: t + "\n[bogus]\nx = 1\n",
    "syntax-error": lambda t: t.replace("=", ":", 1),
    "empty": lambda t: "",
    "missing-alpha0": lambda t: re.sub(r"alpha0_deg = .*\n", "", t),
    "int-overflow": lambda t: re.sub(r"L0_mm = .*", "L0_mm = 9223372036854775807", t),
}


def _rewrite_nc(src: Path, dst: Path, how: str) -> None:
    import numpy as np
    import xarray as xr

    with xr.open_dataset(src) as ds:
        ds = ds.load()
    if how == "no-attrs":
        ds.attrs = {}
        for v in ds.variables.values():
            v.attrs = {}
    elif how == "all-nan":
        for name, v in ds.data_vars.items():
            if np.issubdtype(v.dtype, np.floating):
                ds[name] = v.copy(data=np.full(v.shape, np.nan))
    elif how == "one-point":
        first = next(iter(ds.dims))
        ds = ds.isel({first: slice(0, 1)})
    dst.unlink(missing_ok=True)
    ds.to_netcdf(dst)


def mutated_cases(inp: dict[str, Path], folder: Path, seed: int, n_garble: int = 1,
                  small: bool = False) -> list[list[str]]:
    """Write the mutated inputs under ``folder`` and return the command lines that read them.

    ``small``: each mutated file through one command only (the test suite's size).
    """
    rng = random.Random(seed)
    folder.mkdir(parents=True, exist_ok=True)
    src = inp["raw"] / "be-pam_150kPa.csv"
    cases: list[list[str]] = []
    for how in RAW_MUTATIONS:
        for k in range(n_garble if how in ("garble", "binary") else 1):
            d = folder / f"raw_{how}_{k}"
            if d.exists():
                shutil.rmtree(d)
            d.mkdir()
            shutil.copy(inp["raw"] / "be-pam_100kPa.csv", d / "be-pam_100kPa.csv")
            _mutate_raw(src, d / "be-pam_150kPa.csv", how, rng)
            cases.append(["process", str(d), "--out", str(folder / f"p_{how}_{k}"), "--no-figure", "--json"])
            if k == 0 and not small and how in ("truncate-half", "garble", "nan-force"):
                cases.append(["report", str(d), "--preset", "be-pam", "--no-progress", "--model", "energy",
                              "--out", str(folder / f"r_{how}.html")])
                cases.append(["inspect", str(d / "be-pam_150kPa.csv"), "--json"])
    # processed folders
    for how in ("no-attrs", "all-nan", "one-point"):
        d = folder / f"proc_{how}"
        if d.exists():
            shutil.rmtree(d)
        shutil.copytree(inp["proc"], d)
        _rewrite_nc(inp["proc"] / "curves.nc", d / "curves.nc", how)
        cases.append(["fit", str(d), "--preset", "be-pam", "--out", str(folder / f"f_{how}"), "--json"])
    for how, data in (("nc-truncated", (inp["proc"] / "curves.nc").read_bytes()[:3000]), ("nc-garbage", b"junk" * 100),
                      ("summary-garbage", None), ("no-nc", None)):
        d = folder / f"proc_{how}"
        if d.exists():
            shutil.rmtree(d)
        shutil.copytree(inp["proc"], d)
        if how == "summary-garbage":
            (d / "summary.json").write_text("{not json")
        elif how == "no-nc":
            (d / "curves.nc").unlink()
        else:
            (d / "curves.nc").write_bytes(data or b"")
        cases.append(["fit", str(d), "--preset", "be-pam", "--out", str(folder / f"f_{how}"), "--json"])
    # actuator TOML files
    base = inp["toml"].read_text()
    for i, (how, mutate) in enumerate(TOML_MUTATIONS.items()):
        t = folder / f"act_{i}.toml"
        t.write_text(mutate(base))
        cases.append(["predict", "--actuator", str(t), "--pressure-kpa", "100:200:3", "--cycle", "--json"])
        if how in ("alpha0=true", "hysteresis=5", "unknown-key", "alpha0=nan") and not small:
            cases.append(["fit", str(inp["proc"]), "--actuator", str(t), "--out", str(folder / f"fa_{i}")])
            cases.append(["sweep", "--actuator", str(t), "--pressure-kpa", "100:200:3", "--out",
                          str(folder / f"s_{i}.nc"), "--no-progress"])
            cases.append(["simulate-test", "--actuator", str(t), "--pressure-kpa", "150", "--cycles", "1",
                          "--out", str(folder / f"sim_{i}")])
    return cases


def run_cases(tally: Tally, cases: Iterable[list[str]], cwd: Path, jobs: int = 2, timeout: float = TIMEOUT_S,
              label: str = "") -> list[tuple[list[str], str, str]]:
    """Run ``cases`` ``jobs`` at a time, each in an empty folder of its own under ``cwd``.

    Several cases name the same relative output (``--out p_x``); in one shared folder the outcome of
    one would depend on which other case runs at the same time (``another bendpam run is writing``).
    Their own folders keep every outcome independent of the scheduling (concurrent runs on one
    output are :func:`concurrent_case`'s subject).
    """
    cases = list(cases)
    folders = [Path(tempfile.mkdtemp(prefix=f"case{i:03d}-", dir=cwd)) for i in range(len(cases))]
    with ThreadPoolExecutor(jobs) as ex:
        runs = list(ex.map(lambda a, d: run(a, d, timeout), cases, folders))
    out = []
    for args, r in zip(cases, runs, strict=True):
        kind, detail = classify(r)
        tally.add(kind, f"{label}bendpam {' '.join(args)}", detail)
        out.append((args, kind, detail))
    return out


# ----------------------------------------------------------------------------------------------
# main
# ----------------------------------------------------------------------------------------------
def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="A shorter run (about a minute).")
    ap.add_argument("--seed", type=int, default=12)
    ap.add_argument("--workdir", type=Path, default=None, help="Keep the files here (default: a temporary folder).")
    ap.add_argument("--jobs", type=int, default=max(2, min(4, os.cpu_count() or 1)))
    ap.add_argument("-v", "--verbose", action="store_true")
    a = ap.parse_args(argv)
    work = a.workdir or Path(tempfile.mkdtemp(prefix="bendpam-faults-"))
    t0 = time.monotonic()
    tally = Tally()
    inputs = build_inputs(work / "inputs")
    n_kill = 6 if a.quick else 9
    max_delay = {"process": 2.5, "fit": 3.0, "report": 4.5, "sweep": 2.5}
    for i, command in enumerate(KILL_COMMANDS):
        kill_series(tally, command, inputs, work / f"kill_{command}", n_kill, a.seed + i, max_delay[command])
        print(f"  kills of {command}: done ({time.monotonic() - t0:.0f} s)", flush=True)
    for command in KILL_COMMANDS:
        for stagger in ((0.0, 0.5) if a.quick else (0.0, 0.3, 1.0)):
            concurrent_case(tally, command, inputs, work / f"conc_{command}", stagger)
    print(f"  concurrent runs: done ({time.monotonic() - t0:.0f} s)", flush=True)
    run_cases(tally, bad_command_lines(inputs), work / "inputs", jobs=a.jobs)
    print(f"  bad command lines: done ({time.monotonic() - t0:.0f} s)", flush=True)
    for rep in range(1 if a.quick else 2):
        cases = mutated_cases(inputs, work / f"mutated_{rep}", a.seed * 100 + rep, n_garble=2 if a.quick else 5)
        if rep > 0:  # later rounds repeat only the randomly garbled files
            cases = [c for c in cases if "garble" in " ".join(c) or "binary" in " ".join(c)]
        run_cases(tally, cases, work / "inputs", jobs=a.jobs)
    print(f"  mutated inputs: done ({time.monotonic() - t0:.0f} s)", flush=True)
    sys.modules.setdefault("fault_injection", sys.modules[__name__])  # one harness module for both files
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import fault_families  # issue 21: guards, read-back, post-commit and console signals, budgets, plausibility

    fault_families.run_families(tally, inputs, work / "families", a.seed, jobs=a.jobs, n_flips=2 if a.quick else 4,
                                n_signals=1 if a.quick else 2, log=lambda m: print(m, flush=True))
    print(f"\nbendpam fault injection ({'quick' if a.quick else 'full'}, seed {a.seed}, "
          f"{time.monotonic() - t0:.0f} s, files in {work})")
    print(tally.report())
    if tally.startup:
        print("\nsignals during start-up (before main() installs its handlers; known, see the README):")
        for f in tally.startup:
            print("  " + f)
    if tally.failures:
        print("\nfailures:")
        for f in tally.failures:
            print("  " + f.replace("\n", "\n    "))
    if a.workdir is None and not tally.failures:
        shutil.rmtree(work, ignore_errors=True)
    return 0 if tally.ok else 1


if __name__ == "__main__":
    sys.exit(main())
