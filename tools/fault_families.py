"""Fault-injection families of issue 21 (item 7): what bendpam may replace, read back and refuse.

Each case runs in a folder of its own and checks, besides the one-line/exit-code rules of
:func:`fault_injection.classify`, the invariant **no file bendpam did not write is lost or changed**:
every user file hashed before the run is found afterwards with the same sha256, at its place or in a
moved-aside copy (``NAME.moved-aside-<UTC>``).  The families:

* ``guard``: foreign ``manifest.json`` folders, user files added into a bendpam set, edited set files,
  ``~`` paths (HOME pointed at a temporary folder), cross-command replacement, hand-written single
  files as ``--out``/``--plot`` targets, each without and with ``--force``;
* ``readback``: byte flips in ``curves.nc``, ``fit.json`` and raw files of ``simulate-test``, read back;
* ``plot-kill``: ``sweep --out --plot`` interrupted while it holds its lock (both old or both new);
* ``post-commit``: a signal as soon as the ``wrote`` line appears;
* ``console``: a signal right after the console script is spawned, and once its handlers are in place;
* ``budget``: FIFOs and ``/dev/zero`` as ``--actuator``, huge ranges (one line, never a hang);
* ``plausible``: absurd actuator values and pressures (one line).

``python tools/fault_injection.py`` runs them (see its ``main``); ``tests/test_faults.py`` a sample.
"""

from __future__ import annotations

import os
import random
import re
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ASIDE_RE = re.compile(r"\.moved-aside-[^/]*")


def _fi() -> Any:
    """The harness module (loaded by whoever imported this one, or imported from this folder)."""
    main = sys.modules.get("__main__")
    mod = sys.modules.get("bendpam_fault_injection") or sys.modules.get("fault_injection")
    if mod is None and hasattr(main, "classify") and hasattr(main, "Tally"):  # run as a script
        mod = main
    if mod is None:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        import fault_injection as mod  # type: ignore[no-redef]
    return mod


# ----------------------------------------------------------------------------------------------
# the user-file oracle
# ----------------------------------------------------------------------------------------------
def hashes(root: Path, names: list[str]) -> dict[str, str]:
    """sha256 of the files ``names`` (relative to ``root``; folders: every file under them)."""
    fi = _fi()
    out: dict[str, str] = {}
    for n in names:
        p = root / n
        if p.is_dir():
            out.update({str(q.relative_to(root)): fi.sha256(q) for q in p.rglob("*") if q.is_file()})
        elif p.is_file():
            out[n] = fi.sha256(p)
    return out


def lost_files(root: Path, before: dict[str, str]) -> list[str]:
    """The user files of ``before`` found nowhere under ``root`` with their sha256 (moved-aside copies count)."""
    fi = _fi()
    found: dict[str, set[str]] = {}
    for q in root.rglob("*"):
        if q.is_file() and not q.is_symlink():
            found.setdefault(ASIDE_RE.sub("", str(q.relative_to(root))), set()).add(fi.sha256(q))
    return [n for n, h in before.items() if h not in found.get(n, set())]


# ----------------------------------------------------------------------------------------------
# guard cases: what an output may replace
# ----------------------------------------------------------------------------------------------
@dataclass
class Guard:
    name: str
    setup: Callable[[Path, dict[str, Path]], list[str]]  # writes the case's files, returns the user files
    args: list[str]  # {raw} {proc} {toml} {home} are filled in
    expect: str  # "error" or "ok"
    mention: str = ""  # the error line must name this
    home: bool = False  # run with HOME pointed at <case>/home
    check: Callable[[Path], str | None] | None = None  # extra check after an ok run: None when fine


def _bendpam(folder: Path, *args: object) -> None:
    r = _fi().run(list(args), folder)
    if r.rc != 0:
        raise RuntimeError(f"case set-up failed: bendpam {' '.join(map(str, args))}: {r.stderr}")


def _foreign_manifest(d: Path, inp: dict[str, Path]) -> list[str]:
    (d / "out").mkdir()
    (d / "out" / "manifest.json").write_text('{"tool": "someone else", "files": []}\n')
    (d / "out" / "data.csv").write_text("t,x\n0,1\n")
    return ["out"]


Setup = Callable[[Path, dict[str, Path]], list[str]]


def _set_plus(extra: str | None, edit: str | None, command: str = "process") -> Setup:
    def setup(d: Path, inp: dict[str, Path]) -> list[str]:
        if command == "process":
            _bendpam(d, "process", inp["raw"], "--out", "out", "--no-figure")
        elif command == "simulate-test":
            _bendpam(d, "simulate-test", "--preset", "be-pam", "--pressure-kpa", "150", "--cycles", "1", "--out", "out")
        else:
            _bendpam(d, "fit", inp["proc"], "--preset", "be-pam", "--out", "out", "--no-figure")
        user: list[str] = []
        if extra:
            (d / "out" / extra).write_text("my notes\n")
            user.append(f"out/{extra}")
        if edit:
            with open(d / "out" / edit, "a", encoding="utf-8") as f:
                f.write("\n")
            user.append(f"out/{edit}")
        if not user:  # another command's set: all of it is not this command's to lose
            user.append("out")
        return user
    return setup


def _hand_file(name: str, text: str = "mine\n") -> Callable[[Path, dict[str, Path]], list[str]]:
    def setup(d: Path, inp: dict[str, Path]) -> list[str]:
        (d / name).write_text(text)
        return [name]
    return setup


def _edited_own_toml(d: Path, inp: dict[str, Path]) -> list[str]:
    _bendpam(d, "actuator", "--preset", "be-pam", "--out", "a.toml")
    with open(d / "a.toml", "a", encoding="utf-8") as f:
        f.write("# my comment\n")
    return ["a.toml"]


def _home(d: Path, inp: dict[str, Path]) -> list[str]:
    (d / "home").mkdir()
    (d / "home" / "keep.txt").write_text("my home\n")
    return ["home"]


def _home_set_exists(sub: str) -> Callable[[Path], str | None]:
    def check(d: Path) -> str | None:
        return None if (d / "home" / sub / "manifest.json").is_file() else f"no set written in HOME/{sub}"
    return check


def _aside_exists(d: Path) -> str | None:
    return None if any(ASIDE_RE.search(p.name) for p in d.iterdir()) else "--force moved nothing aside"


def guard_cases() -> list[Guard]:
    proc = ["process", "{raw}", "--no-figure", "--out"]
    fit = ["fit", "{proc}", "--preset", "be-pam", "--no-figure", "--out"]
    sim = ["simulate-test", "--preset", "be-pam", "--pressure-kpa", "150", "--cycles", "1", "--out"]
    sw = ["sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:3", "--pressure-kpa", "100:200:3",
          "--no-progress"]
    cases: list[Guard] = []
    for force in (False, True):
        f = ["--force"] if force else []
        exp = "ok" if force else "error"
        chk = _aside_exists if force else None
        cases += [
            Guard(f"foreign manifest, process{' --force' * force}", _foreign_manifest, [*proc, "out", *f], exp,
                  "" if force else "manifest", check=chk),
            Guard(f"foreign manifest, fit{' --force' * force}", _foreign_manifest, [*fit, "out", *f], exp, check=chk),
            Guard(f"foreign manifest, simulate-test{' --force' * force}", _foreign_manifest, [*sim, "out", *f], exp,
                  check=chk),
            Guard(f"user file in a set{' --force' * force}", _set_plus("notes.txt", None), [*proc, "out", *f], exp,
                  "" if force else "notes.txt", check=chk),
            Guard(f"edited set file{' --force' * force}", _set_plus(None, "summary.json"), [*proc, "out", *f], exp,
                  "" if force else "summary.json", check=chk),
            Guard(f"process into simulate-test's set{' --force' * force}", _set_plus(None, None, "simulate-test"),
                  [*proc, "out", *f], exp, check=chk),
            Guard(f"fit into process's set{' --force' * force}", _set_plus(None, None, "process"),
                  [*fit, "out", *f], exp, check=chk),
            Guard(f"simulate-test into fit's set{' --force' * force}", _set_plus(None, None, "fit"),
                  [*sim, "out", *f], exp, check=chk),
            Guard(f"hand-written --out toml{' --force' * force}", _hand_file("mine.toml"),
                  ["actuator", "--preset", "be-pam", "--out", "mine.toml", *f], exp, "" if force else "mine.toml",
                  check=chk),
            Guard(f"edited bendpam toml{' --force' * force}", _edited_own_toml,
                  ["actuator", "--preset", "be-pam", "--out", "a.toml", *f], exp, check=chk),
            Guard(f"hand-written --plot png{' --force' * force}", _hand_file("mine.png"),
                  [*sw, "--out", "s.nc", "--plot", "mine.png", *f], exp, "" if force else "mine.png", check=chk),
            Guard(f"hand-written --out nc{' --force' * force}", _hand_file("s.nc"),
                  [*sw, "--out", "s.nc", *f], exp, check=chk),
            Guard(f"hand-written report html{' --force' * force}", _hand_file("r.html", "<html>mine</html>\n"),
                  ["report", "{raw}", "--preset", "be-pam", "--no-progress", "--out", "r.html", *f], exp, check=chk),
            # the home folder is refused even with --force
            Guard(f"--out ~{' --force' * force}", _home, [*proc, "~", *f], "error", home=True),
            Guard(f"--out ~/ (trailing slash){' --force' * force}", _home, [*sim, "~/", *f], "error", home=True),
        ]
    cases += [
        Guard("--out ~/p", _home, [*proc, "~/p"], "ok", home=True, check=_home_set_exists("p")),
        Guard("--out ./~ (a folder named ~)", _home, [*proc, "./~"], "ok",
              check=lambda d: None if (d / "~" / "manifest.json").is_file() else "no set in ./~"),
        Guard("--out . --force", _hand_file("keep.txt"), [*proc, ".", "--force"], "error"),
    ]
    return cases


def guard_case(tally: Any, g: Guard, inputs: dict[str, Path], folder: Path, timeout: float = 120.0) -> None:
    fi = _fi()
    d = Path(tempfile.mkdtemp(prefix="guard-", dir=folder))
    user = g.setup(d, inputs)
    before = hashes(d, user)
    fill = {"raw": str(inputs["raw"]), "proc": str(inputs["proc"]), "toml": str(inputs["toml"]),
            "home": str(d / "home")}
    args = [a.format(**fill) for a in g.args]
    env = {"HOME": str(d / "home")} if g.home else None
    r = fi.run(args, d, timeout, env=env)
    kind, detail = fi.classify(r)
    what = f"[guard] {g.name}: bendpam {' '.join(args)}"
    tally.add(kind, what, detail)
    if kind in fi.CLEAN and kind != g.expect:
        tally.fail("wrong-outcome", what, f"expected {g.expect}, got {kind}: {r.stderr.strip()[-400:]}")
    elif kind == "error" and g.mention and g.mention not in detail:
        tally.fail("wrong-outcome", what, f"the line does not name {g.mention!r}: {detail}")
    elif kind == "ok" and g.check is not None and (why := g.check(d)) is not None:
        tally.fail("wrong-outcome", what, why)
    lost = lost_files(d, before)
    if lost:
        tally.fail("user-file-lost", what, f"lost or changed: {lost}")


# ----------------------------------------------------------------------------------------------
# read-back of damaged sets
# ----------------------------------------------------------------------------------------------
FITLOAD = ("import sys\nfrom bendpam.errors import BendpamError\nfrom bendpam.identify import FitResult\n"
           "try:\n    FitResult.load(sys.argv[1])\nexcept BendpamError as e:\n"
           "    print('bendpam: error:', e, file=sys.stderr); sys.exit(2)\n")


def _flip(path: Path, rng: random.Random) -> None:
    b = bytearray(path.read_bytes())
    i = rng.randrange(len(b))
    b[i] ^= 1 << rng.randrange(8)
    path.write_bytes(bytes(b))


def readback_case(tally: Any, which: str, inputs: dict[str, Path], folder: Path, seed: int,
                  fit_dir: Path | None = None, timeout: float = 120.0) -> None:
    """Flip one bit of a bendpam set's file and read it back: one line naming the file, exit 2."""
    import shutil

    fi = _fi()
    rng = random.Random(seed)
    d = Path(tempfile.mkdtemp(prefix=f"readback-{which}-", dir=folder))
    if which == "curves.nc":
        shutil.copytree(inputs["proc"], d / "set")
        _flip(d / "set" / "curves.nc", rng)
        args = ["fit", str(d / "set"), "--preset", "be-pam", "--no-figure", "--out", str(d / "f")]
        r = fi.run(args, d, timeout)
    elif which == "raw":
        shutil.copytree(inputs["raw"], d / "set")
        name = rng.choice(sorted(p.name for p in (d / "set").glob("*.csv")))
        _flip(d / "set" / name, rng)
        which = name
        args = ["process", str(d / "set"), "--no-figure", "--out", str(d / "p")]
        r = fi.run(args, d, timeout)
    else:  # fit.json, read back by the library
        assert fit_dir is not None
        shutil.copytree(fit_dir, d / "set")
        _flip(d / "set" / "fit.json", rng)
        args = ["FitResult.load", str(d / "set")]
        t0 = time.monotonic()
        p = subprocess.run([sys.executable, "-c", FITLOAD, str(d / "set")], capture_output=True, text=True,
                           timeout=timeout, env=fi.child_env())
        r = fi.Run(args, p.returncode, p.stdout, p.stderr, time.monotonic() - t0)
    kind, detail = fi.classify(r)
    what = f"[readback] bit flip in {which}: {' '.join(args)}"
    tally.add(kind, what, detail)
    if kind != "error":
        tally.fail("wrong-outcome", what, f"a damaged set was read back: {kind} {r.stderr.strip()[-300:]}")
    elif which not in detail:
        tally.fail("wrong-outcome", what, f"the line does not name {which}: {detail}")


def make_fit(inputs: dict[str, Path], folder: Path) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    if not (folder / "fit" / "fit.json").is_file():
        _bendpam(folder, "fit", inputs["proc"], "--preset", "be-pam", "--no-figure", "--out", "fit")
    return folder / "fit"


# ----------------------------------------------------------------------------------------------
# signals: --out with --plot, after the commit, at start-up of the console script
# ----------------------------------------------------------------------------------------------
def _popen(argv: list[str], cwd: Path) -> subprocess.Popen:
    return subprocess.Popen(argv, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            stdin=subprocess.DEVNULL, env=_fi().child_env())


def _finish(p: subprocess.Popen, args: list[str], t0: float, timeout: float) -> Any:
    fi = _fi()
    try:
        out, err = p.communicate(timeout=timeout)
        return fi.Run(args, p.returncode, out, err, time.monotonic() - t0)
    except subprocess.TimeoutExpired:
        p.kill()
        out, err = p.communicate()
        return fi.Run(args, None, out, err, time.monotonic() - t0, hung=True)


def plot_kill_case(tally: Any, folder: Path, sig: int, timeout: float = 120.0) -> None:
    """``sweep --out s.nc --plot s.png`` over a previous pair, signalled while it holds its lock."""
    fi = _fi()
    folder.mkdir(parents=True, exist_ok=True)
    args = ["sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:40", "--pressure-kpa", "100:200:20",
            "--no-progress", "--out", "s.nc", "--plot", "s.png"]
    if not (folder / "s.nc").exists():
        r = fi.run(args, folder, timeout)
        if r.rc != 0:
            tally.fail("bad-error", "sweep --plot (baseline)", r.stderr[-400:])
            return
    before = {n: fi.snapshot(folder / n) for n in ("s.nc", "s.png")}
    t0 = time.monotonic()
    p = _popen(fi.cli(*args), folder)
    fi.wait_until(lambda: any(n.endswith(".bendpam-lock") for n in os.listdir(folder)), p, timeout)
    p.send_signal(sig)
    r = _finish(p, args, t0, timeout)
    what = f"[plot-kill] sweep --out s.nc --plot s.png, {signal.Signals(sig).name} once it held the lock"
    kind, detail = fi.classify(r)
    if r.rc == -sig and fi._only_notes(r.stderr) and r.stdout.strip():
        tally.counts["cases"] += 1
        tally.counts["late"] += 1
    else:
        tally.add(kind, what, detail)
    now = {n: fi.snapshot(folder / n) for n in ("s.nc", "s.png")}
    changed = [n for n in now if now[n] != before[n]]
    if changed and len(changed) != 2:
        tally.fail("mixed", what, f"only {changed} changed: --out and --plot not committed together")
    if kind == "interrupt" and fi.INTERRUPT_LINE in r.stderr and changed:
        tally.fail("mixed", what, f"'no outputs were changed' but {changed} changed")
    if changed and fi.file_problem(folder / "s.nc"):
        tally.fail("mixed", what, fi.file_problem(folder / "s.nc"))
    left = [n for n in os.listdir(folder) if _fi().TEMP_RE.fullmatch(n)]
    if left:
        tally.fail("leftover", what, str(left))


POST_COMMANDS = {
    "process": ["process", "{raw}", "--no-figure", "--out", "out"],
    "fit": ["fit", "{proc}", "--preset", "be-pam", "--no-figure", "--out", "out"],
    "simulate-test": ["simulate-test", "--preset", "be-pam", "--pressure-kpa", "100:200:3", "--cycles", "1",
                      "--out", "out"],
    "sweep": ["sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:5", "--pressure-kpa", "100:200:5",
              "--no-progress", "--out", "s.nc", "--plot", "s.png"],
}


def post_commit_case(tally: Any, command: str, inputs: dict[str, Path], folder: Path, sig: int,
                     timeout: float = 120.0, early_wrote_ok: bool = False) -> None:
    """A signal as soon as the 'wrote' line appears: exit 0, or 130/143 saying 'interrupted after writing'.

    What the last line says must be what is on disk: 'after writing' with a complete new set,
    'no outputs were changed' with no set.  The 'wrote' line itself must be true: a run that printed
    it and then rolled its outputs back fails, unless ``early_wrote_ok`` (the CI sample, while the
    known defect stands: the CLI commits the outputs of a command when the command returns, after
    its 'wrote' lines).
    """
    fi = _fi()
    d = Path(tempfile.mkdtemp(prefix=f"post-{command}-", dir=folder))
    args = [a.format(raw=inputs["raw"], proc=inputs["proc"]) for a in POST_COMMANDS[command]]
    t0 = time.monotonic()
    p = _popen(fi.cli(*args), d)
    assert p.stdout is not None
    first = ""
    deadline = time.monotonic() + timeout
    for line in p.stdout:  # event-driven: the line itself is the trigger
        first += line
        if line.startswith("wrote") or "\nwrote" in first:
            p.send_signal(sig)
            break
        if time.monotonic() > deadline:
            break
    r = _finish(p, args, t0, timeout)
    r.stdout = first + r.stdout
    what = f"[post-commit] {command}, {signal.Signals(sig).name} at the 'wrote' line"
    kind, detail = fi.classify(r)
    if r.rc == -sig and fi._only_notes(r.stderr):
        tally.counts["cases"] += 1
        tally.counts["late"] += 1
        kind = "late"
    else:
        tally.add(kind, what, detail)
    if "wrote" not in r.stdout:
        tally.fail("wrong-outcome", what, f"no 'wrote' line: {r.stderr.strip()[-300:]}")
    target = d / ("s.nc" if command == "sweep" else "out")
    if kind == "interrupt" and fi.INTERRUPT_LINE in r.stderr:
        if target.exists():
            tally.fail("mixed", what, "it says 'no outputs were changed' but the new output is there")
        elif not early_wrote_ok:
            tally.fail("wrong-outcome", what, "the 'wrote' line was printed, then the outputs were rolled back "
                       "('no outputs were changed'): the commit comes after the 'wrote' line")
    elif not target.exists():
        tally.fail("mixed", what, f"{kind} (exit {r.rc}) but no output")
    why = fi.set_problem(target, None)
    if why is not None:
        tally.fail("mixed", what, why)
    left = [n for n in os.listdir(d) if _fi().TEMP_RE.fullmatch(n)]
    if left:
        tally.fail("leftover", what, str(left))


def console_script(folder: Path) -> Path:
    """A console script as pip writes it for ``bendpam = "bendpam_entry:main"``, for this interpreter."""
    s = folder / "bendpam"
    if not s.exists():
        s.write_text(f"#!{sys.executable}\nimport sys\nfrom bendpam_entry import main\nif __name__ == '__main__':\n"
                     "    sys.argv[0] = sys.argv[0].removesuffix('.exe')\n    sys.exit(main())\n")
        s.chmod(0o755)
    return s


def console_case(tally: Any, folder: Path, sig: int, when: str, timeout: float = 120.0) -> None:
    """The console script signalled right after spawn (``when='spawn'``) or once its handlers are in ('handlers').

    Right after spawn the interpreter may not run Python yet: the signal's default action (exit -sig,
    nothing written, for SIGINT perhaps a KeyboardInterrupt) is the known start-up window (counted
    apart).  Once the script catches SIGTERM it must print the one line.
    """
    fi = _fi()
    folder.mkdir(parents=True, exist_ok=True)
    d = Path(tempfile.mkdtemp(prefix="console-", dir=folder))
    args = ["simulate-test", "--preset", "be-pam", "--pressure-kpa", "150", "--cycles", "1", "--out", "out"]
    t0 = time.monotonic()
    p = _popen([str(console_script(folder)), *args], d)
    if when == "handlers":
        if fi.catches(p.pid, signal.SIGTERM) is not None:
            fi.wait_until(lambda: bool(fi.catches(p.pid, signal.SIGTERM)), p, timeout)
    p.send_signal(sig)
    r = _finish(p, args, t0, timeout)
    moment = "right after spawn" if when == "spawn" else "once its handlers are in"
    what = f"[console] bendpam script, {signal.Signals(sig).name} {moment}"
    if r.rc == -sig and when == "spawn" and not r.stdout.strip() and (
            not r.stderr.strip() or r.stderr.rstrip().endswith("KeyboardInterrupt")):
        tally.counts["cases"] += 1
        tally.counts["startup"] += 1
        tally.startup.append(f"{what}: exit {r.rc}")
    else:
        kind, detail = fi.classify(r)
        tally.add(kind, what, detail)
        if kind == "ok":
            tally.fail("wrong-outcome", what, "the signal was ignored")
    out = d / "out"
    if out.exists() and fi.set_problem(out, None) is not None:
        tally.fail("mixed", what, fi.set_problem(out, None))


# ----------------------------------------------------------------------------------------------
# budgets and plausibility: one line, never a hang
# ----------------------------------------------------------------------------------------------
def budget_lines(folder: Path) -> list[tuple[str, list[str]]]:
    """``(label, args)``: inputs and sizes that must be refused within a budget. FIFOs on POSIX only."""
    cases: list[tuple[str, list[str]]] = []
    if hasattr(os, "mkfifo"):
        fifo = folder / "fifo.toml"
        if not fifo.exists():
            os.mkfifo(fifo)
        cases.append(("fifo", ["predict", "--actuator", str(fifo), "--pressure-kpa", "150"]))
        fdir = folder / "fifo_raw"
        fdir.mkdir(exist_ok=True)
        if not (fdir / "be-pam_150kPa.csv").exists():
            os.mkfifo(fdir / "be-pam_150kPa.csv")
        cases.append(("fifo", ["process", str(fdir), "--no-figure", "--out", "p"]))
    if Path("/dev/zero").exists():
        cases.append(("dev-zero", ["predict", "--actuator", "/dev/zero", "--pressure-kpa", "150"]))
        cases.append(("dev-zero", ["inspect", "/dev/zero"]))
    cases += [
        # (1000 x 1000 points is about 10 s of legitimate work, inside the time budget: not a refusal case)
        ("huge-range", ["sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:1000000", "--no-progress",
                        "--out", "s.nc"]),
        ("huge-range", ["sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:100000", "--pressure-kpa",
                        "100:200:1000", "--no-progress", "--out", "s.nc"]),
        ("huge-range", ["simulate-test", "--preset", "be-pam", "--pressure-kpa", "100:200:1000", "--cycles", "50",
                        "--out", "sim"]),
        ("huge-range", ["curve", "--preset", "be-pam", "--pressure-kpa", "100:200:10000", "--points", "1000",
                        "--out", "c.csv"]),
        ("huge-range", ["predict", "--preset", "be-pam", "--pressure-kpa", "100:200:1000000", "--json"]),
    ]
    return cases


PLAUSIBLE = {
    "alpha0_deg=0.001": lambda t: re.sub(r"alpha0_deg = .*", "alpha0_deg = 0.001", t),
    "R0_start_mm=1e22": lambda t: re.sub(r"R0_start_mm = .*", "R0_start_mm = 1e22", t),
    "R0_mm=1e22": lambda t: re.sub(r"R0_mm = .*", "R0_mm = 1e22", t),
    "t0_mm=1e-9": lambda t: re.sub(r"t0_mm = .*", "t0_mm = 1e-9", t),
}


def plausible_lines(inputs: dict[str, Path], folder: Path) -> list[tuple[str, list[str]]]:
    base = inputs["toml"].read_text()
    cases: list[tuple[str, list[str]]] = []
    for i, (how, mutate) in enumerate(PLAUSIBLE.items()):
        t = folder / f"plaus_{i}.toml"
        t.write_text(mutate(base))
        cases.append((f"plausible {how}", ["predict", "--actuator", str(t), "--pressure-kpa", "150", "--json"]))
    cases += [
        ("plausible --pressure-kpa 1e6", ["predict", "--preset", "be-pam", "--pressure-kpa", "1e6", "--json"]),
        ("plausible --pressure-kpa 1e6", ["simulate-test", "--preset", "be-pam", "--pressure-kpa", "1e6",
                                          "--cycles", "1", "--out", "sim"]),
    ]
    return cases


@dataclass
class LineResult:
    label: str
    args: list[str]
    kind: str
    detail: str
    seconds: float = 0.0
    extra: dict[str, Any] = field(default_factory=dict)


def refusal_cases(tally: Any, cases: list[tuple[str, list[str]]], cwd: Path, jobs: int = 2,
                  timeout: float = 60.0) -> list[LineResult]:
    """Each case must end in ONE line with exit 2 within ``timeout`` (a hang is killed and counted)."""
    from concurrent.futures import ThreadPoolExecutor

    fi = _fi()
    folders = [Path(tempfile.mkdtemp(prefix=f"refuse{i:03d}-", dir=cwd)) for i in range(len(cases))]
    with ThreadPoolExecutor(jobs) as ex:
        runs = list(ex.map(lambda c, d: fi.run(c[1], d, timeout), cases, folders))
    out = []
    for (label, args), r in zip(cases, runs, strict=True):
        kind, detail = fi.classify(r)
        what = f"[{label}] bendpam {' '.join(args)}"
        tally.add(kind, what, detail)
        if kind == "ok":
            tally.fail("wrong-outcome", what, f"accepted ({r.seconds:.0f} s); expected a one-line refusal")
        out.append(LineResult(label, args, kind, detail, r.seconds))
    return out


# ----------------------------------------------------------------------------------------------
# the long run's part
# ----------------------------------------------------------------------------------------------
def run_families(tally: Any, inputs: dict[str, Path], work: Path, seed: int, jobs: int = 2, n_flips: int = 4,
                 n_signals: int = 2, log: Callable[[str], None] = print) -> None:
    """Every family of this module, for the long run of ``tools/fault_injection.py``."""
    from concurrent.futures import ThreadPoolExecutor

    t0 = time.monotonic()
    (work / "guard").mkdir(parents=True, exist_ok=True)
    with ThreadPoolExecutor(jobs) as ex:
        list(ex.map(lambda g: guard_case(tally, g, inputs, work / "guard"), guard_cases()))
    log(f"  guard cases: done ({time.monotonic() - t0:.0f} s)")
    fit_dir = make_fit(inputs, work / "fitsrc")
    (work / "readback").mkdir(exist_ok=True)
    jobs_rb = [(w, seed * 1000 + k) for w in ("curves.nc", "raw", "fit.json") for k in range(n_flips)]
    with ThreadPoolExecutor(jobs) as ex:
        list(ex.map(lambda j: readback_case(tally, j[0], inputs, work / "readback", j[1], fit_dir), jobs_rb))
    log(f"  damaged sets read back: done ({time.monotonic() - t0:.0f} s)")
    sigs = [signal.SIGINT, signal.SIGTERM]
    (work / "postcommit").mkdir(exist_ok=True)
    for k in range(n_signals):
        plot_kill_case(tally, work / "plotkill", sigs[k % 2])
        for c in POST_COMMANDS:
            post_commit_case(tally, c, inputs, work / "postcommit", sigs[k % 2])
        for when in ("spawn", "handlers"):
            console_case(tally, work / "console", sigs[k % 2], when)
    log(f"  signals (--plot, post-commit, console script): done ({time.monotonic() - t0:.0f} s)")
    (work / "refuse").mkdir(exist_ok=True)
    refusal_cases(tally, budget_lines(work / "refuse") + plausible_lines(inputs, work / "refuse"), work / "refuse",
                  jobs=jobs, timeout=30.0)
    log(f"  budgets and plausibility: done ({time.monotonic() - t0:.0f} s)")
