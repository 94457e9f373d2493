"""Output sets (issue 12): all-or-nothing folders and files, locks, signals."""

from __future__ import annotations

import hashlib
import importlib.metadata
import json
import os
import random
import signal
import subprocess
import sys
import threading
import time
from datetime import datetime
from pathlib import Path

import numpy as np
import pytest

import bendpam.infra.fsops as fsops
import bendpam.infra.outputs as outputs
from bendpam.errors import InputError
from bendpam.infra.outputs import (
    Interrupted,
    OutputBusy,
    OutputFile,
    OutputSet,
    interrupts,
    json_safe,
    to_json,
)
from bendpam.infra.registry import REGISTRY_NAME

PKG_DIR = Path(outputs.__file__).resolve().parent.parent  # src/bendpam

# The child processes load bendpam.infra.outputs without running bendpam/__init__.py (which
# imports SciPy, xarray, ...: about a second per process); the module needs only
# bendpam.errors and bendpam.infra.atomic.
CHILD = r"""
import sys, time, types
pkg = types.ModuleType("bendpam")
pkg.__path__ = [sys.argv[1]]
sys.modules["bendpam"] = pkg
import signal
from bendpam.errors import InputError
from bendpam.infra.outputs import Interrupted, OutputSet, interrupts

# a test run started in the background may inherit SIGINT ignored; a terminal has it on
signal.signal(signal.SIGINT, signal.default_int_handler)
target, tag, n, pause, hold, timeout = sys.argv[2:8]
n, pause, hold, timeout = int(n), float(pause), float(hold), float(timeout)


def main():
    with interrupts():
        try:
            print("ready", flush=True)
            with OutputSet(target, lock_timeout_s=timeout, command=[tag]) as out:
                print("locked", flush=True)
                for i in range(n):
                    out.write_text(f"f{i}.txt", f"{tag} {i}\n" * 200)
                    time.sleep(pause)
                    if i == n // 2 - 1:
                        print("half", flush=True)
                        time.sleep(hold)
                obj = {"tag": tag, "n": n, "x": float("nan")}
                out.write_json(f"only_{tag}.json", obj)
        except Interrupted as exc:
            print("bendpam: interrupted; no outputs were changed", file=sys.stderr)
            return exc.exit_code
        except InputError as exc:
            print(f"bendpam: error: {exc}", file=sys.stderr)
            return 2
    return 0


sys.exit(main())
"""


# --------------------------------------------------------------------------------------
# helpers
# --------------------------------------------------------------------------------------
def _no_constant(name: str) -> None:
    raise AssertionError(f"non-standard JSON constant {name}")


def strict_loads(text: str | bytes) -> object:
    """json.loads that fails on NaN / Infinity / -Infinity."""
    return json.loads(text, parse_constant=_no_constant)


def sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file below ``folder``: relative POSIX path -> bytes."""
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def expected_set(tag: str, n: int = 6) -> dict[str, bytes]:
    """The files (without the manifest) that CHILD / write_set write for ``tag``."""
    files = {f"f{i}.txt": (f"{tag} {i}\n" * 200).encode() for i in range(n)}
    files[f"only_{tag}.json"] = to_json({"tag": tag, "n": n, "x": None}).encode()
    return files


def write_set(target: Path, tag: str, n: int = 6) -> dict[str, bytes]:
    """Write the set of ``tag`` in this process; returns the full snapshot."""
    with OutputSet(target, command=["test", tag]) as out:
        for name, data in expected_set(tag, n).items():
            out.write_bytes(name, data)
    return snapshot(target)


def check_set(target: Path, expected: dict[str, bytes]) -> dict:
    """``target`` holds exactly ``expected`` plus a manifest that describes it."""
    files = snapshot(target)
    manifest = strict_loads(files.pop("manifest.json"))
    assert isinstance(manifest, dict)
    assert files == expected
    listed = {f["path"]: (f["size"], f["sha256"]) for f in manifest["files"]}
    assert listed == {k: (len(v), sha(v)) for k, v in files.items()}
    return manifest


def only(parent: Path, *names: str) -> None:
    """``parent`` holds these names and nothing else: no temporaries, no lock file (bendpam's record of
    the single files it wrote there, :data:`bendpam.infra.registry.REGISTRY_NAME`, aside)."""
    assert sorted(n for n in os.listdir(parent) if n != REGISTRY_NAME) == sorted(names)


def bendpam_wrote(path: Path, text: str) -> None:
    """``path`` as an earlier bendpam run left it (a single file bendpam may replace)."""
    with OutputFile(path) as o:
        o.write_text(text)


def child(
    tmp_path: Path,
    target: Path,
    tag: str,
    *,
    n: int = 6,
    pause: float = 0.0,
    hold: float = 0.0,
    timeout: float = 0.0,
) -> subprocess.Popen[str]:
    script = tmp_path / "child.py"
    if not script.exists():
        script.write_text(CHILD)
    args = [
        sys.executable,
        str(script),
        str(PKG_DIR),
        str(target),
        tag,
        str(n),
        str(pause),
        str(hold),
        str(timeout),
    ]
    return subprocess.Popen(
        args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )


def wait_for(proc: subprocess.Popen[str], word: str) -> None:
    assert proc.stdout is not None
    for line in proc.stdout:
        if line.strip() == word:
            return
    raise AssertionError(f"child exited before {word!r}: {proc.wait()} {proc.stderr}")


# --------------------------------------------------------------------------------------
# a normal set
# --------------------------------------------------------------------------------------
def test_normal_set_and_manifest(tmp_path):
    raw = tmp_path / "raw"
    (raw / "sub").mkdir(parents=True)
    (raw / "a.csv").write_text("1,2\n")
    (raw / "sub" / "b.txt").write_bytes(b"\x00\x01")
    cfg = tmp_path / "cfg.toml"
    cfg.write_text("x = 1\n")
    out_dir = tmp_path / "results" / "out"  # the parent is created

    t0 = datetime.now().astimezone()
    with OutputSet(out_dir, inputs=[raw, cfg]) as out:
        out.write_text("summary.txt", "hello\n")
        out.write_bytes("bin/data.bin", bytes(range(256)))
        out.write_json("summary.json", {"a": 1.5, "b": [1, 2]})
        out.path("figures/fig.png").write_bytes(b"PNG")  # any writer
        (out.staging / "extra.txt").write_text("e")  # a writer given the folder
        assert not out_dir.exists()  # nothing visible before the end
        assert out.files == [
            "summary.txt",
            "bin/data.bin",
            "summary.json",
            "figures/fig.png",
        ]
    t1 = datetime.now().astimezone()

    m = check_set(
        out_dir,
        {
            "summary.txt": b"hello\n",
            "bin/data.bin": bytes(range(256)),
            "summary.json": b'{\n  "a": 1.5,\n  "b": [\n    1,\n    2\n  ]\n}\n',
            "figures/fig.png": b"PNG",
            "extra.txt": b"e",
        },
    )
    assert m == out.manifest
    assert m["format"] == "bendpam-output-set" and m["format_version"] == 1
    assert m["bendpam_version"] == importlib.metadata.version("bendpam")
    assert m["command"] == sys.argv
    assert m["target"] == str(out_dir.resolve())
    start = datetime.fromisoformat(m["started_utc"])
    end = datetime.fromisoformat(m["finished_utc"])
    assert start.utcoffset().total_seconds() == 0
    assert t0.timestamp() - 1e-3 <= start.timestamp() <= end.timestamp()
    assert end.timestamp() <= t1.timestamp() + 1e-3
    # inputs: folders expanded to their files, each with size and a sha256 we recompute
    want = [raw / "a.csv", raw / "sub" / "b.txt", cfg]
    assert [i["path"] for i in m["inputs"]] == [str(p.resolve()) for p in want]
    for entry, p in zip(m["inputs"], want, strict=True):
        assert entry["size"] == p.stat().st_size
        assert entry["sha256"] == sha(p.read_bytes())
    only(out_dir.parent, "out")
    assert oct(out_dir.stat().st_mode & 0o777) == oct(0o777 & ~outputs.UMASK)


def test_command_argument_and_empty_set(tmp_path):
    with OutputSet(tmp_path / "o", command="bendpam process 'raw dir' --out o"):
        pass
    m = check_set(tmp_path / "o", {})
    assert m["command"] == ["bendpam", "process", "raw dir", "--out", "o"]
    assert m["inputs"] == []


def test_set_is_replaced_whole(tmp_path):
    target = tmp_path / "out"
    write_set(target, "old")
    with OutputSet(target) as out:
        out.write_text("f0.txt", "new")
    check_set(target, {"f0.txt": b"new"})  # the old only_old.json and f1.. are gone
    only(tmp_path, "out")


def test_fallback_swap_without_renameat2(tmp_path, monkeypatch):
    monkeypatch.setattr(fsops, "exchange", lambda a, b: False)
    target = tmp_path / "out"
    write_set(target, "old")
    write_set(target, "new", n=3)
    check_set(target, expected_set("new", 3))
    only(tmp_path, "out")


def test_exchange_really_swaps(tmp_path):
    if fsops.RENAMEAT2 is None:
        pytest.skip("no renameat2 here")
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    b.mkdir()
    (a / "x").write_text("a")
    (b / "y").write_text("b")
    if not fsops.exchange(a, b):
        pytest.skip("this file system refuses RENAME_EXCHANGE")
    assert os.listdir(a) == ["y"] and os.listdir(b) == ["x"]


def test_killed_fallback_swap_is_rolled_back(tmp_path):
    # a fallback swap killed between "target -> old" and "staging -> target"
    old_files = write_set(tmp_path / "src", "old")
    os.rename(tmp_path / "src", tmp_path / ".out.bendpam-old-99999-0123abcd")
    (tmp_path / ".out.bendpam-tmp-99999-zz_9abcd").mkdir()  # its staging folder
    target = tmp_path / "out"
    with pytest.raises(RuntimeError), OutputSet(target) as out:
        only(tmp_path, "out", ".out.bendpam-lock", out.staging.name)
        raise RuntimeError("boom")
    assert snapshot(target) == old_files
    only(tmp_path, "out")


# --------------------------------------------------------------------------------------
# failures leave the target as it was
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "exc",
    [RuntimeError("boom"), KeyboardInterrupt(), Interrupted(143, signal.SIGTERM)],
    ids=type,
)
def test_exception_leaves_target_unchanged(tmp_path, exc):
    target = tmp_path / "out"
    before = write_set(target, "old")
    inode = target.stat().st_ino
    with pytest.raises(type(exc)), OutputSet(target) as out:
        out.write_text("f0.txt", "new")
        out.write_json("only_new.json", {"x": 1})
        raise exc
    assert snapshot(target) == before
    assert target.stat().st_ino == inode
    only(tmp_path, "out")


def test_exception_with_new_target_leaves_nothing(tmp_path):
    with pytest.raises(ValueError), OutputSet(tmp_path / "new") as out:
        out.write_text("a.txt", "a")
        raise ValueError("x")
    only(tmp_path)


def test_failure_during_commit_leaves_target_unchanged(tmp_path, monkeypatch):
    target = tmp_path / "out"
    before = write_set(target, "old")

    def broken(a, b):
        raise OSError(5, "simulated I/O error")

    monkeypatch.setattr(fsops, "exchange", broken)
    with pytest.raises(OSError, match="simulated"), OutputSet(target) as out:
        out.write_text("f0.txt", "new")
    assert snapshot(target) == before
    only(tmp_path, "out")


def test_sigkill_mid_set_then_next_run_cleans_up(tmp_path):
    target = tmp_path / "out"
    before = write_set(target, "old")
    proc = child(tmp_path, target, "new", hold=60)
    try:
        wait_for(proc, "half")
        proc.kill()
        assert proc.wait(10) == -signal.SIGKILL
    finally:
        proc.kill()
    assert snapshot(target) == before
    stale = [n for n in os.listdir(tmp_path) if n.startswith(".out.bendpam-tmp-")]
    assert len(stale) == 1 and f"-{proc.pid}-" in stale[0]
    assert (tmp_path / stale[0] / "f0.txt").exists()  # half a set was written
    assert (tmp_path / ".out.bendpam-lock").exists()  # the lock file, not the lock

    # the next run takes the orphaned lock and removes the staging folder at once, even
    # when it fails itself
    with pytest.raises(RuntimeError), OutputSet(target):
        assert not (tmp_path / stale[0]).exists()
        raise RuntimeError("fails too")
    assert snapshot(target) == before
    only(tmp_path, "child.py", "out")
    write_set(target, "next", n=2)
    check_set(target, expected_set("next", 2))
    only(tmp_path, "child.py", "out")


# --------------------------------------------------------------------------------------
# signals
# --------------------------------------------------------------------------------------
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=lambda s: s.name)
def test_signal_at_random_time_gives_old_or_new_set(tmp_path, sig):
    code = {signal.SIGINT: 130, signal.SIGTERM: 143}[sig]
    seed = random.randrange(2**32)
    rng = random.Random(seed)
    n, pause, runs = 6, 0.03, 10
    old, new = expected_set("old"), expected_set("new")
    procs, results = [], [None] * runs

    def deliver(i: int, proc: subprocess.Popen[str], delay: float) -> None:
        wait_for(proc, "ready")
        time.sleep(delay)
        proc.send_signal(sig)
        _, err = proc.communicate(timeout=20)
        results[i] = (proc.returncode, err, delay)

    threads = []
    for i in range(runs):
        (tmp_path / f"r{i}").mkdir()
        write_set(tmp_path / f"r{i}" / "out", "old")
        proc = child(tmp_path, tmp_path / f"r{i}" / "out", "new", n=n, pause=pause)
        procs.append(proc)
        delay = rng.uniform(0.0, n * pause)
        threads.append(threading.Thread(target=deliver, args=(i, proc, delay)))
    try:
        for t in threads:
            t.start()
        for t in threads:
            t.join(30)
    finally:
        for p in procs:
            p.kill()
    interrupted = 0
    for i, res in enumerate(results):
        assert res is not None, f"run {i} (seed {seed}) did not finish"
        rc, err, delay = res
        target = tmp_path / f"r{i}" / "out"
        assert rc in (0, code, -sig), (
            f"run {i} (seed {seed}, {delay} s): exit {rc}: {err}"
        )
        files = snapshot(target)
        files.pop("manifest.json")
        if rc in (0, -sig):
            # finished: either before the signal or, for -sig, just after it had left
            # interrupts() (default handlers again) -- the complete new set either way
            assert files == new, f"run {i} (seed {seed})"
        else:
            interrupted += 1
            assert "bendpam: interrupted; no outputs were changed" in err
            assert files in (old, new), f"run {i} (seed {seed}): a mixture"
        check_set(target, files)
        only(target.parent, "out")
    assert interrupted >= 1, f"seed {seed}: no run was interrupted"


def test_interrupted_is_not_an_exception():
    assert issubclass(Interrupted, BaseException)
    assert not issubclass(Interrupted, Exception)
    e = Interrupted(143, signal.SIGTERM)
    assert e.exit_code == 143 and str(e) == "interrupted by SIGTERM"


@pytest.mark.parametrize("sig,code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_interrupts_maps_signals_and_restores_handlers(sig, code):
    before = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    with pytest.raises(Interrupted) as info, interrupts():
        signal.raise_signal(sig)
    assert info.value.exit_code == code and info.value.signum == sig
    assert {s: signal.getsignal(s) for s in before} == before


def test_second_signal_during_cleanup_is_ignored(tmp_path, monkeypatch):
    target = tmp_path / "out"
    before = write_set(target, "old")
    real_remove = fsops.remove_path

    def slow_remove(path):
        signal.raise_signal(signal.SIGTERM)  # the impatient second signal
        real_remove(path)

    with pytest.raises(Interrupted) as info, interrupts():
        with OutputSet(target) as out:
            out.write_text("f0.txt", "new")
            monkeypatch.setattr(fsops, "remove_path", slow_remove)
            signal.raise_signal(signal.SIGINT)
    assert info.value.exit_code == 130  # the first signal wins
    assert snapshot(target) == before
    only(tmp_path, "out")


def test_signal_during_cleanup_of_an_error_is_delivered(tmp_path, monkeypatch):
    real_remove = fsops.remove_path

    def remove_then_signal(path):
        signal.raise_signal(signal.SIGTERM)
        real_remove(path)

    with pytest.raises(Interrupted) as info, interrupts():
        with OutputSet(tmp_path / "out") as out:
            out.write_text("a.txt", "a")
            monkeypatch.setattr(fsops, "remove_path", remove_then_signal)
            raise ValueError("bad data")
    assert info.value.exit_code == 143
    assert isinstance(info.value.__context__, ValueError)
    only(tmp_path)


def test_signal_during_swap_is_held_until_the_set_is_in_place(tmp_path, monkeypatch):
    target = tmp_path / "out"
    write_set(target, "old")
    real_exchange = fsops.exchange

    def exchange(a, b):
        signal.raise_signal(signal.SIGINT)
        return real_exchange(a, b)

    monkeypatch.setattr(fsops, "exchange", exchange)
    with pytest.raises(Interrupted), interrupts():
        with OutputSet(target) as out:
            out.write_text("f0.txt", "new")
    check_set(target, {"f0.txt": b"new"})
    only(tmp_path, "out")


# --------------------------------------------------------------------------------------
# concurrent runs
# --------------------------------------------------------------------------------------
def test_second_run_refuses_then_waits(tmp_path):
    target = tmp_path / "out"
    proc = child(tmp_path, target, "first", hold=1.0)
    try:
        wait_for(proc, "half")
        with pytest.raises(OutputBusy) as info, OutputSet(target):
            pass
        msg = str(info.value)
        assert msg == (
            f"another bendpam run is writing {target} (pid {proc.pid}); "
            "wait for it or choose another folder"
        )
        assert isinstance(info.value, InputError)
        with pytest.raises(OutputBusy, match=r"did not finish within 0\.1 s"):
            OutputSet(target, lock_timeout_s=0.1).__enter__()
        with OutputFile(tmp_path / "other.csv") as f:  # other targets are not locked
            f.write_text("x\n")
        # waiting: we get the lock once the first run has committed its set
        with OutputSet(target, lock_timeout_s=20) as out:
            check_set(target, expected_set("first"))
            out.write_text("second.txt", "2")
        assert proc.wait(10) == 0
    finally:
        proc.kill()
    check_set(target, {"second.txt": b"2"})
    only(tmp_path, "child.py", "other.csv", "out")


def test_two_processes_one_wins(tmp_path):
    target = tmp_path / "out"
    procs = [child(tmp_path, target, tag, hold=1.0) for tag in ("a", "b")]
    try:
        results = [(p.wait(20), p.communicate()[1]) for p in procs]
    finally:
        for p in procs:
            p.kill()
    codes = sorted(rc for rc, _ in results)
    assert codes == [0, 2], results
    loser = next(err for rc, err in results if rc == 2)
    assert "another bendpam run is writing" in loser and str(target) in loser
    winner = "ab"[[rc for rc, _ in results].index(0)]
    check_set(target, expected_set(winner))
    only(tmp_path, "child.py", "out")


def test_lock_in_one_process(tmp_path):
    target = tmp_path / "f.csv"
    with OutputFile(target) as f:
        with pytest.raises(OutputBusy, match=f"pid {os.getpid()}"), OutputFile(target):
            pass
        f.write_text("a\n")
    assert target.read_text() == "a\n"
    only(tmp_path, "f.csv")


# --------------------------------------------------------------------------------------
# refusals
# --------------------------------------------------------------------------------------
def test_output_inside_inputs_is_refused(tmp_path, monkeypatch):
    raw = tmp_path / "raw"
    raw.mkdir()
    (raw / "a.csv").write_text("1\n")
    out = tmp_path / "out"
    write_set(out, "old")
    cases = [
        (raw, [raw], "is the input folder"),
        (raw / "processed", [raw], "is inside the input folder"),
        (tmp_path / "x", [tmp_path], "is inside the input folder"),
        (out, [out / "f0.txt"], "is inside the output folder"),
        (tmp_path, [raw / "a.csv"], "is inside the output folder"),
        (raw / "a.csv", [tmp_path / "cfg"], "does not exist"),
        (raw / "a.csv", [], "exists and is not a folder"),
    ]
    for target, inputs, words in cases:
        with (
            pytest.raises(InputError, match=words) as info,
            OutputSet(target, inputs=inputs),
        ):
            pass
        msg = str(info.value)
        assert "\n" not in msg
        named = [*inputs[:1], target] if words != "does not exist" else inputs
        assert all(repr(str(p)) in msg for p in named), msg  # one line naming both
    # equivalent spellings of the same folder
    monkeypatch.chdir(tmp_path)
    with (
        pytest.raises(InputError, match="is the input folder"),
        OutputSet("raw/../raw/", inputs=[raw]),
    ):
        pass
    # replacing the folder we are working in
    monkeypatch.chdir(out)
    with pytest.raises(InputError, match="current folder"), OutputSet(out):
        pass
    monkeypatch.chdir(tmp_path)
    assert sorted(os.listdir(raw)) == ["a.csv"]
    only(tmp_path, "out", "raw")
    check_set(out, expected_set("old"))


def test_foreign_folder_needs_force(tmp_path):
    target = tmp_path / "Documents"
    target.mkdir()
    (target / "thesis.tex").write_text("precious")
    with pytest.raises(InputError, match=r"thesis\.tex', which bendpam did not write \(no bendpam manifest\.json"), \
            OutputSet(target):
        pass
    assert (target / "thesis.tex").read_text() == "precious"
    # issue 21: forcing moves the user's folder aside, it never deletes it
    with OutputSet(target, force=True) as out:
        out.write_text("a.txt", "a")
    check_set(target, {"a.txt": b"a"})
    assert out.moved_aside is not None and out.moved_aside.parent == tmp_path
    assert (out.moved_aside / "thesis.tex").read_text() == "precious"
    empty = tmp_path / "empty"
    empty.mkdir()
    with OutputSet(empty) as out2:  # an empty folder is fine
        out2.write_text("a.txt", "a")
    check_set(empty, {"a.txt": b"a"})
    only(tmp_path, "Documents", "empty", out.moved_aside.name)


@pytest.mark.parametrize(
    "name",
    [
        "..",
        "../x.txt",
        "a/../../x.txt",
        "a/..",
        "/etc/x",
        "",
        ".",
        "manifest.json",
        "./manifest.json",
    ],
)
def test_bad_output_names_are_refused(tmp_path, name):
    with OutputSet(tmp_path / "out") as out:
        with pytest.raises(InputError):
            out.write_text(name, "x")
        with pytest.raises(InputError):
            out.path(name)
    check_set(tmp_path / "out", {})
    only(tmp_path, "out")


def test_good_output_names(tmp_path):
    with OutputSet(tmp_path / "out") as out:
        out.write_text("./a.txt", "a")
        out.write_text(Path("d") / "b.txt", "b")
        out.write_text("d/./c..txt", "c")
    check_set(tmp_path / "out", {"a.txt": b"a", "d/b.txt": b"b", "d/c..txt": b"c"})
    assert out.files == ["a.txt", "d/b.txt", "d/c..txt"]


def test_closed_set_refuses_writes(tmp_path):
    out = OutputSet(tmp_path / "out")
    with pytest.raises(RuntimeError, match="not open"):
        out.path("a.txt")
    with out:
        pass
    with pytest.raises(RuntimeError, match="not open"):
        out.write_text("a.txt", "a")


# --------------------------------------------------------------------------------------
# strict JSON
# --------------------------------------------------------------------------------------
def test_write_json_and_manifest_are_strict(tmp_path):
    obj = {
        "nan": float("nan"),
        "inf": float("inf"),
        "ninf": -np.inf,
        "np": np.float32("nan"),
        "arr": np.array([1.0, np.nan, np.inf]),
        "nested": ({"x": np.float64(2.5)}, [np.int64(3), np.bool_(True)]),
        np.int64(7): "numpy key",
        -np.inf: "inf key",
        "p": tmp_path / "p",
    }
    with OutputSet(tmp_path / "out", command=["nan", "inf"]) as out:
        out.write_json("r.json", obj)
    text = (tmp_path / "out" / "r.json").read_text()
    assert "NaN" not in text and "Infinity" not in text
    assert strict_loads(text) == {
        "nan": None,
        "inf": "inf",  # infinity is a string, null means missing (docs/formats.md)
        "ninf": "-inf",
        "np": None,
        "arr": [1.0, None, "inf"],
        "nested": [{"x": 2.5}, [3, True]],
        "7": "numpy key",
        "-inf": "inf key",
        "p": str(tmp_path / "p"),
    }
    strict_loads((tmp_path / "out" / "manifest.json").read_text())
    assert json_safe(np.float64("inf")) == "inf" and json_safe(np.array(2.0)) == 2.0
    with pytest.raises(ValueError):  # the strictness is real
        json.dumps(float("nan"), allow_nan=False)


# --------------------------------------------------------------------------------------
# OutputFile
# --------------------------------------------------------------------------------------
def test_output_file(tmp_path):
    target = tmp_path / "curves.csv"
    # (an output inside an input folder is refused since issue 21: the input is elsewhere)
    with OutputFile(target, inputs=[Path(__file__)]) as f:
        assert f.path.suffix == ".csv" and f.path.parent == tmp_path
        f.path.write_text("a,b\n1,2\n")
        assert not target.exists()
    assert target.read_text() == "a,b\n1,2\n"
    assert oct(target.stat().st_mode & 0o777) == oct(0o666 & ~outputs.UMASK)
    target.chmod(0o640)
    with OutputFile(target) as f:
        f.write_json({"x": float("nan")})
    assert strict_loads(target.read_text()) == {"x": None}
    assert oct(target.stat().st_mode & 0o777) == oct(0o640)  # the old permissions
    only(tmp_path, "curves.csv")


@pytest.mark.parametrize(
    "exc", [RuntimeError("boom"), Interrupted(130, signal.SIGINT)], ids=type
)
def test_output_file_failure_leaves_target(tmp_path, exc):
    target = tmp_path / "report.html"
    bendpam_wrote(target, "old")
    with pytest.raises(type(exc)), OutputFile(target) as f:
        f.write_text("new, half")
        raise exc
    assert target.read_text() == "old"
    only(tmp_path, "report.html")
    with pytest.raises(RuntimeError, match="nothing was written"), OutputFile(target):
        pass
    assert target.read_text() == "old"
    only(tmp_path, "report.html")


def test_output_file_refusals_and_stale_temporaries(tmp_path):
    data = tmp_path / "data.csv"
    data.write_text("1\n")
    link = tmp_path / "link.csv"
    link.symlink_to(data)
    for target, inputs, words in [
        (data, [data], "is the input"),
        (link, [data], "is the input"),
        (tmp_path, [], "existing folder"),
        (tmp_path / "missing" / "x.csv", [], "does not exist"),
    ]:
        with pytest.raises(InputError, match=words), OutputFile(target, inputs=inputs):
            pass
    assert data.read_text() == "1\n"
    # a temporary left by a killed run is removed by the next run on the same file
    stale = tmp_path / ".out.csv.bendpam-tmp-99999-deadbeef.csv"
    stale.write_text("half")
    with OutputFile(tmp_path / "out.csv") as f:
        assert not stale.exists()
        f.write_text("ok\n")
    only(tmp_path, "data.csv", "link.csv", "out.csv")


# --------------------------------------------------------------------------------------
# resumable sets (issue 24): a kept, locked staging folder with a key
# --------------------------------------------------------------------------------------
def _interrupted_resumable(target, key, name="a.txt"):
    with pytest.raises(KeyboardInterrupt):
        with OutputSet(target, command=["t"], resume_key=key) as out:
            out.write_text(name, name)
            raise KeyboardInterrupt


def test_resumable_set_keeps_its_staging_for_the_same_key_only(tmp_path):
    target = tmp_path / "out"
    part = tmp_path / fsops.part_name("out")
    _interrupted_resumable(target, "k1")
    assert not target.exists() and (part / "a.txt").read_text() == "a.txt"
    assert (part / ".bendpam-resume" / "key").read_text() == "k1"
    with OutputSet(target, command=["t"], resume_key="k2") as out:  # another key: afresh
        assert not out.resumed and not (out.staging / "a.txt").exists()
        out.write_text("b.txt", "b")
    assert sorted(p.name for p in target.iterdir()) == ["b.txt", "manifest.json"]
    assert not part.exists()
    _interrupted_resumable(target, "k3")
    with OutputSet(target, command=["t"], resume_key="k3") as out:
        assert out.resumed and (out.staging / "a.txt").is_file()
    manifest = json.loads((target / "manifest.json").read_text())
    assert [f["path"] for f in manifest["files"]] == ["a.txt"]  # the key and markers are not in the set


def test_a_plain_set_on_the_target_removes_a_kept_staging_folder(tmp_path):
    target = tmp_path / "out"
    _interrupted_resumable(target, "k1")
    with OutputSet(target, command=["t"]) as out:
        out.write_text("c.txt", "c")
    assert not (tmp_path / fsops.part_name("out")).exists()
    assert fsops.ANY_TEMP.fullmatch(fsops.part_name("out"))  # skipped when a folder is hashed as an input


def test_resume_key_must_be_a_printable_string(tmp_path):
    with pytest.raises(InputError, match="resume_key"):
        OutputSet(tmp_path / "out", resume_key="")


def test_a_signal_inside_a_weakref_callback_stops_the_run_at_the_next_output(capsys, tmp_path):
    # a SIGINT that Python handles while a finalizer or weakref callback runs (garbage collection)
    # cannot raise there: Python would print "Exception ignored in ..." and go on. interrupts()
    # keeps it, and the output's commit raises it: nothing is written, no traceback is printed.
    import signal
    import weakref

    from bendpam.infra.signals import Interrupted, interrupts

    class Thing:
        pass

    reached = []
    with pytest.raises(Interrupted) as info:
        with interrupts(), OutputSet(tmp_path / "out") as out:
            out.write_text("a.txt", "a")
            thing = Thing()
            _ref = weakref.ref(thing, lambda _r: signal.raise_signal(signal.SIGINT))
            del thing  # the callback runs here, and the signal's handler inside it
            reached.append("after the callback")
    assert info.value.exit_code == 130 and info.value.signum == signal.SIGINT
    assert reached == ["after the callback"] and not (tmp_path / "out").exists()
    assert "Exception ignored" not in capsys.readouterr().err


@pytest.mark.parametrize("kind", ["set", "file"])
def test_an_interrupt_just_after_the_lock_is_taken_leaves_no_lock_file(tmp_path, monkeypatch, kind):
    # a signal whose handler runs between taking the lock and the with block's start (here: inside the
    # group look-up, where the interpreter checks for signals) must release the lock: __exit__ never runs then
    # (found as a leftover '.report.html.bendpam-lock' by the fault injection's signal test, now and then)
    target = tmp_path / ("out" if kind == "set" else "out.txt")

    def interrupted():
        raise KeyboardInterrupt

    monkeypatch.setattr(outputs, "current_group", interrupted)
    with pytest.raises(KeyboardInterrupt):
        with OutputSet(target, command=["t"]) if kind == "set" else OutputFile(target, command=["t"]):
            pass
    assert sorted(p.name for p in tmp_path.iterdir()) == []
