"""bendpam runs where POSIX-only modules do not exist (the Windows issue, item 1).

The command line is run in a subprocess whose import system refuses ``fcntl``, ``termios``,
``resource``, ``pwd`` and ``grp`` (a meta-path hook installed before anything of bendpam is
imported): every command must still load, write its outputs whole and lock them (with the soft
lock), and ``python -m bendpam`` works.  A source check keeps POSIX-only imports out of module level.
"""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

import bendpam.infra.locks as locks
from bendpam.infra.manifest import verify_set
from bendpam.infra.outputs import OutputBusy, OutputSet

SRC = Path(locks.__file__).resolve().parents[2]  # src
POSIX_ONLY = ("fcntl", "termios", "resource", "pwd", "grp", "posix", "msvcrt", "winreg", "_winapi")

BLOCKER = r"""
import importlib.abc, sys
BLOCKED = {"fcntl", "termios", "resource", "pwd", "grp"}


class NoPosix(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ImportError(f"No module named {name!r} (blocked by test_portable)")
        return None


for name in BLOCKED:
    sys.modules.pop(name, None)
sys.meta_path.insert(0, NoPosix())
"""

RUN_CLI = BLOCKER + r"""
import bendpam_entry
from bendpam.cli.app import main
code = main(sys.argv[1:])
assert not BLOCKED & set(sys.modules), sorted(BLOCKED & set(sys.modules))
sys.exit(code)
"""


def cli_without_posix(*args: object, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-c", RUN_CLI, *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=300, stdin=subprocess.DEVNULL)


@pytest.mark.skipif(sys.platform == "win32", reason="simulates a system without the POSIX modules")
def test_the_cli_runs_without_posix_only_modules(tmp_path):
    steps = [
        ["--version"],
        ["actuator", "--preset", "be-pam", "--out", "be.toml"],
        ["simulate-test", "--preset", "be-pam", "--pressure-kpa", "100:200:3", "--cycles", "2", "--rate-hz", "10",
         "--seed", "1", "--out", "raw"],
        ["process", "raw", "--out", "proc", "--no-figure"],
        ["process", "raw", "--out", "proc", "--no-figure"],  # a set replaced under the soft lock
        ["sweep", "--actuator", "be.toml", "--param", "alpha0_deg=60:80:3", "--pressure-kpa", "100:200:3", "-q",
         "--out", "s.csv", "--plot", "s.png"],
    ]
    for args in steps:
        r = cli_without_posix(*args, cwd=tmp_path)
        assert r.returncode == 0, (args, r.stderr[-2000:])
        assert "Traceback" not in r.stderr and "warning" not in r.stderr.lower(), r.stderr
    verify_set(tmp_path / "proc", required=True)
    verify_set(tmp_path / "raw", required=True)
    # no lock files left (only bendpam's record of the single files it wrote, .bendpam-files.json)
    assert sorted(os.listdir(tmp_path)) == [".bendpam-files.json", "be.toml", "proc", "raw", "s.csv", "s.png"]
    # a refusal is still one line
    r = cli_without_posix("process", "raw", "--out", "raw", cwd=tmp_path)
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "is the input folder" in r.stderr


def test_python_m_bendpam(tmp_path):
    r = subprocess.run([sys.executable, "-m", "bendpam", "--version"], cwd=tmp_path, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0 and r.stdout.startswith("bendpam "), r.stderr
    r = subprocess.run([sys.executable, "-m", "bendpam", "actuator", "--preset", "be-pam", "--out", "be.toml"],
                       cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and (tmp_path / "be.toml").is_file(), r.stderr


def test_a_pipe_in_the_windows_code_page_gets_ascii_words_not_a_crash(tmp_path):
    # on Windows a redirected standard output is cp1252, which has no Greek letters: the table's theta_free, the
    # limits' sigma and the notes' mu must come out in words (or as cp1252 has them), with exit status 0
    env = {**os.environ, "PYTHONIOENCODING": "cp1252"}
    env.pop("PYTHONUTF8", None)
    r = subprocess.run([sys.executable, "-m", "bendpam", "predict", "--preset", "be-pam", "--pressure-kpa", "200"],
                       cwd=tmp_path, capture_output=True, timeout=120, env=env)
    out = r.stdout.decode("cp1252")
    assert r.returncode == 0, r.stderr.decode("cp1252")
    assert "theta_free" in out and "sigma_frame" in out and "N·mm" in out
    assert "internal error" not in r.stderr.decode("cp1252")


def _module_level_imports(tree: ast.Module) -> list[tuple[int, str]]:
    """Imports that run when the module is imported: module level, including under if/try (not in functions)."""
    found: list[tuple[int, str]] = []

    def visit(body: list[ast.stmt]) -> None:
        for node in body:
            if isinstance(node, ast.Import):
                found.extend((node.lineno, a.name.split(".")[0]) for a in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                found.append((node.lineno, node.module.split(".")[0]))
            elif isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
                continue
            elif isinstance(node, ast.If | ast.Try | ast.With):
                for field in ("body", "orelse", "finalbody"):
                    visit(getattr(node, field, None) or [])
                for handler in getattr(node, "handlers", None) or []:
                    visit(handler.body)

    visit(tree.body)
    return found


def test_no_module_imports_a_posix_only_api_at_top_level():
    bad = []
    for path in sorted(SRC.rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for lineno, name in _module_level_imports(tree):
            if name in POSIX_ONLY:
                bad.append(f"{path.relative_to(SRC).as_posix()}:{lineno}: import {name}")
    assert bad == [], "import these where they are used, guarded per platform:\n" + "\n".join(bad)


def test_the_check_sees_a_top_level_import():
    tree = ast.parse("import os\ntry:\n    import fcntl\nexcept ImportError:\n    pass\ndef f():\n    import pwd\n")
    assert [n for _, n in _module_level_imports(tree)] == ["os", "fcntl"]


def _text_io_without_encoding(tree: ast.AST) -> list[int]:
    """Lines that read a file as text with the platform's encoding: ``x.read_text()`` without ``encoding=``, or
    ``open(...)`` in text mode without it (on Windows that is cp1252, not the UTF-8 bendpam writes)."""
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call) or any(k.arg == "encoding" for k in node.keywords):
            continue
        f = node.func
        if isinstance(f, ast.Attribute) and f.attr == "read_text" and not node.args:
            found.append(node.lineno)
        elif isinstance(f, ast.Name) and f.id == "open":
            mode = node.args[1] if len(node.args) > 1 else next((k.value for k in node.keywords if k.arg == "mode"),
                                                                 None)
            if not (isinstance(mode, ast.Constant) and "b" in str(mode.value)):
                found.append(node.lineno)
    return found


def test_text_is_read_and_written_with_a_named_encoding():
    bad = [f"{path.relative_to(SRC).as_posix()}:{line}" for path in sorted(SRC.rglob("*.py"))
           for line in _text_io_without_encoding(ast.parse(path.read_text(encoding="utf-8")))]
    assert bad == [], "name the encoding (utf-8) where text is read:\n" + "\n".join(bad)
    sample = ("Path('a').read_text()\nopen('b')\nopen('c', 'rb')\nopen('d', encoding='utf-8')\n"
              "x.read_text(encoding='u')\n")
    assert _text_io_without_encoding(ast.parse(sample)) == [1, 2]


# ----------------------------------------------------------------------------------------------
# the soft lock (no native lock on this system)
# ----------------------------------------------------------------------------------------------
@pytest.fixture
def soft_locks(monkeypatch):
    monkeypatch.setattr(locks, "_NATIVE", [None])


def test_soft_lock_refuses_a_second_writer_and_cleans_up(tmp_path, soft_locks):
    target = tmp_path / "out"
    lock_file = tmp_path / ".out.bendpam-lock"
    with OutputSet(target) as out:
        assert lock_file.is_file()
        other = locks.TargetLock(target)
        locks._HELD.discard(other.path)  # pretend to be another process
        try:
            with pytest.raises(OutputBusy, match=f"pid {os.getpid()}"):
                other.acquire()
        finally:
            locks._HELD.add(other.path)
        out.write_text("a.txt", "a")
    assert sorted(os.listdir(tmp_path)) == ["out"]


def test_soft_lock_of_a_dead_process_is_taken_over(tmp_path, soft_locks):
    p = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True, text=True)
    dead = int(p.stdout)  # a pid that has exited (and was reaped)
    lock_file = tmp_path / ".out.bendpam-lock"
    lock_file.write_bytes(b"\0" * 8 + f"{dead}\n".encode())
    with OutputSet(tmp_path / "out") as out:
        out.write_text("a.txt", "a")
    assert sorted(os.listdir(tmp_path)) == ["out"]


def _import_failing(monkeypatch, make_error):
    """``import filelock`` raising ``make_error()``."""
    import builtins

    real = builtins.__import__

    def fake(name, *args, **kwargs):
        if name == "filelock":
            raise make_error()
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", fake)


def test_a_signal_during_filelocks_import_is_the_interrupt_not_an_internal_error(monkeypatch):
    """A SIGTERM that lands while filelock's dataclasses are set up comes back as RuntimeError("Error calling
    __set_name__ ...") raised from it (seen once in test_outputs' random-signal test in a CI run): the lock raises the
    interrupt, so the command exits as interrupted (143), not as a bug (1)."""
    from bendpam.infra.signals import Interrupted

    def wrapped():
        err = RuntimeError("Error calling __set_name__ on 'Field' instance 'lock_generation' in 'FileLockContext'")
        err.__cause__ = Interrupted(143, 15)
        return err

    _import_failing(monkeypatch, wrapped)
    with pytest.raises(Interrupted) as caught:
        locks._filelock_fns()
    assert caught.value.exit_code == 143


def test_without_filelock_the_lock_falls_back(monkeypatch):
    _import_failing(monkeypatch, lambda: ImportError("No module named 'filelock'"))
    assert locks._filelock_fns() is None
