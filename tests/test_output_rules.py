"""bendpam replaces only what bendpam wrote (issue 21): each case of the issue, through the real commands.

Commands run in-process through :func:`bendpam.cli.main` (one line on stderr and exit status 2 for
a refusal), except where the case is about the process itself (signals, SIGKILL): those run the
console script's module in a subprocess and wait for events (a line on a pipe), never a fixed delay.
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

import bendpam.infra.outputs as outputs
from bendpam.cli import main
from bendpam.errors import FileFormatError
from bendpam.infra.manifest import read_manifest, verify_file, verify_set
from bendpam.infra.outputs import OutputFile, OutputGroup, OutputSet
from bendpam.infra.registry import REGISTRY_NAME
from bendpam.infra.signals import Interrupted

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals and symbolic links")

SIM = ["simulate-test", "--preset", "be-pam", "--pressure-kpa", "100:200:3", "--cycles", "2", "--rate-hz", "10",
       "--seed", "1"]
PKG_DIR = Path(outputs.__file__).resolve().parents[1]  # src/bendpam


def run(capsys, *args) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def one_error(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("bendpam: error: "), err
    return lines[0]


def tree(folder: Path) -> dict[str, str]:
    """Every entry below ``folder`` (hidden ones too): relative path -> sha256 of a file, 'dir' of a folder."""
    out = {}
    for p in sorted(folder.rglob("*")):
        rel = p.relative_to(folder).as_posix()
        out[rel] = "dir" if p.is_dir() else hashlib.sha256(p.read_bytes()).hexdigest()
    return out


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A folder with raw tests (simulate-test) and their processed set (process)."""
    work = tmp_path_factory.mktemp("rules")
    assert main([*SIM, "--out", str(work / "raw")]) == 0
    assert main(["process", str(work / "raw"), "--out", str(work / "proc"), "--no-figure"]) == 0
    return work


# ----------------------------------------------------------------------------------------------
# a folder bendpam did not write
# ----------------------------------------------------------------------------------------------
@pytest.mark.parametrize("command", ["simulate-test", "process"])
def test_foreign_manifest_and_user_files_are_never_deleted(capsys, lab, tmp_path, command):
    target = tmp_path / "thesis"
    (target / "data").mkdir(parents=True)
    (target / "manifest.json").write_text(json.dumps({"name": "another tool", "files": ["data/x.csv"]}))
    (target / "data" / "x.csv").write_text("1,2\n")
    (target / "thesis.tex").write_text("\\documentclass{article}\n")
    before = tree(target)
    args = [*SIM] if command == "simulate-test" else ["process", lab / "raw", "--no-figure"]
    code, _, err = run(capsys, *args, "--out", target)
    assert code == 2
    line = one_error(err)
    assert "manifest.json that bendpam did not write" in line and "--force" in line
    assert tree(target) == before
    assert sorted(os.listdir(tmp_path)) == ["thesis"]  # no temporaries, no lock file

    # --force: the folder is moved aside whole, never deleted
    code, _, err = run(capsys, *args, "--out", target, "--force")
    assert code == 0, err
    aside = [p for p in tmp_path.iterdir() if p.name.startswith("thesis.moved-aside-")]
    assert len(aside) == 1 and tree(aside[0]) == before
    assert f"bendpam: warning: the old content of {target} was moved to {aside[0]}" in err
    verify_set(target, required=True)


def test_a_folder_without_manifest_is_refused_naming_a_file(capsys, lab, tmp_path):
    target = tmp_path / "Documents"
    target.mkdir()
    (target / "cv.pdf").write_bytes(b"%PDF")
    code, _, err = run(capsys, "process", lab / "raw", "--out", target, "--no-figure")
    assert code == 2 and f"'{target}/cv.pdf', which bendpam did not write" in one_error(err)
    assert (target / "cv.pdf").read_bytes() == b"%PDF"


def test_a_file_added_to_a_bendpam_set_is_kept(capsys, lab, tmp_path):
    out = tmp_path / "proc"
    assert run(capsys, "process", lab / "raw", "--out", out, "--no-figure")[0] == 0
    (out / "my-notes.txt").write_text("calibration was off on Tuesday\n")
    before = tree(out)
    code, _, err = run(capsys, "process", lab / "raw", "--out", out, "--no-figure")
    assert code == 2
    line = one_error(err)
    assert f"'{out}/my-notes.txt', which its manifest.json does not list" in line
    assert tree(out) == before
    # a file of the set changed by hand is the user's too
    (out / "my-notes.txt").unlink()
    with open(out / "summary.json", "a", encoding="utf-8") as f:
        f.write(" ")
    code, _, err = run(capsys, "process", lab / "raw", "--out", out, "--no-figure")
    assert code == 2 and f"'{out}/summary.json' was changed after bendpam wrote it" in one_error(err)
    # an unchanged set of the same command is replaced as before
    (out / "summary.json").write_text((out / "summary.json").read_text().rstrip(" "))
    assert run(capsys, "process", lab / "raw", "--out", out, "--no-figure")[0] == 0
    assert sorted(os.listdir(tmp_path)) == ["proc"]


def test_a_set_of_another_command_is_not_replaced(capsys, lab, tmp_path):
    raw = tmp_path / "raw-csv"
    assert run(capsys, *SIM, "--out", raw)[0] == 0
    before = tree(raw)
    code, _, err = run(capsys, "fit", lab / "proc", "--preset", "be-pam", "--out", raw)
    assert code == 2
    assert "holds the output of 'bendpam simulate-test', which 'bendpam fit' would replace" in one_error(err)
    assert tree(raw) == before
    assert read_manifest(raw)["producer"] == "simulate-test"
    code, _, err = run(capsys, "fit", lab / "proc", "--preset", "be-pam", "--out", raw, "--force")
    assert code == 0, err
    assert read_manifest(raw)["producer"] == "fit"
    aside = next(p for p in tmp_path.iterdir() if p.name.startswith("raw-csv.moved-aside-"))
    assert tree(aside) == before


# ----------------------------------------------------------------------------------------------
# outputs and inputs, links, the home folder
# ----------------------------------------------------------------------------------------------
def test_out_equal_inside_or_containing_an_input_is_refused(capsys, lab, tmp_path):
    raw = tmp_path / "work" / "raw"
    raw.mkdir(parents=True)
    for f in (lab / "raw").iterdir():
        (raw / f.name).write_bytes(f.read_bytes())
    cases = [
        (["process", raw, "--out", raw, "--no-figure"], "is the input folder"),
        (["process", raw, "--out", raw / "proc", "--no-figure"], "is inside the input folder"),
        (["process", raw, "--out", tmp_path / "work", "--no-figure"], "is inside the output folder"),
        (["report", raw, "--preset", "be-pam", "--no-progress", "--out", raw / "report.html"],
         "is inside the input folder"),
        (["actuator", "--actuator", tmp_path / "be.toml", "--out", tmp_path / "be.toml"], "is the input"),
    ]
    assert main(["actuator", "--preset", "be-pam", "--out", str(tmp_path / "be.toml")]) == 0
    capsys.readouterr()
    before = tree(tmp_path)
    for args, words in cases:
        code, _, err = run(capsys, *args)
        assert code == 2 and words in one_error(err), (args, err)
        assert tree(tmp_path) == before, args  # the input folder is untouched: no temporaries, no lock


def test_a_dangling_symlink_is_refused(capsys, lab, tmp_path):
    link = tmp_path / "out"
    link.symlink_to(tmp_path / "elsewhere" / "proc")
    code, _, err = run(capsys, "process", lab / "raw", "--out", link, "--no-figure")
    assert code == 2 and "is a symbolic link to" in one_error(err) and "which does not exist" in err
    assert not (tmp_path / "elsewhere").exists()
    code, _, err = run(capsys, "curve", "--preset", "be-pam", "--pressure-kpa", "150", "--out", link / "c.csv")
    assert code == 2 and "does not exist" in one_error(err)
    assert not (tmp_path / "elsewhere").exists()
    # a link to an existing folder is followed: the set goes there
    (tmp_path / "real").mkdir()
    good = tmp_path / "good"
    good.symlink_to(tmp_path / "real")
    assert run(capsys, "process", lab / "raw", "--out", good, "--no-figure")[0] == 0
    assert good.is_symlink() and (tmp_path / "real" / "manifest.json").is_file()


def test_the_home_folder_is_never_replaced(capsys, lab, tmp_path, monkeypatch):
    home = tmp_path / "home"
    home.mkdir()  # empty: it was replaced by the output set before issue 21
    monkeypatch.setenv("HOME", str(home))
    monkeypatch.chdir(tmp_path)
    for force in ([], ["--force"]):
        code, _, err = run(capsys, "process", lab / "raw", "--out", "~", "--no-figure", *force)
        assert code == 2 and "output folder '~' is your home folder; bendpam never replaces it" in one_error(err)
        assert os.listdir(home) == []
    code, _, err = run(capsys, "process", lab / "raw", "--out", tmp_path, "--no-figure", "--force")
    assert code == 2 and "holds your home folder" in one_error(err)
    # ./~ is a folder named ~ here
    assert run(capsys, "process", lab / "raw", "--out", "./~", "--no-figure")[0] == 0
    assert (tmp_path / "~" / "manifest.json").is_file() and os.listdir(home) == []
    # ~/x is expanded
    assert run(capsys, "process", lab / "raw", "--out", "~/proc", "--no-figure")[0] == 0
    assert (home / "proc" / "manifest.json").is_file()


# ----------------------------------------------------------------------------------------------
# several outputs of one command commit together
# ----------------------------------------------------------------------------------------------
SWEEP = ["sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:3", "--pressure-kpa", "100:200:3", "-q"]


def listing(folder: Path) -> list[str]:
    """The folder's entries, without bendpam's record of the single files it wrote there."""
    return sorted(n for n in os.listdir(folder) if n != REGISTRY_NAME)


def written_by_bendpam_before(path: Path, data: bytes) -> None:
    """``path`` as an earlier bendpam run would have left it (recorded as bendpam's)."""
    with OutputFile(path) as o:
        o.write_bytes(data)


def test_sweep_out_and_plot_commit_together(capsys, tmp_path, monkeypatch):
    data, fig = tmp_path / "s.csv", tmp_path / "s.png"
    written_by_bendpam_before(data, b"old data\n")
    written_by_bendpam_before(fig, b"old figure")
    import bendpam.present.figures as figures

    def interrupted_while_plotting(*args, **kwargs):
        raise Interrupted(130, signal.SIGINT)  # Ctrl-C between the data and the figure

    monkeypatch.setattr(figures, "save_figure", interrupted_while_plotting)
    code, _, err = run(capsys, *SWEEP, "--out", data, "--plot", fig)
    assert code == 130 and err.strip() == "bendpam: interrupted; no outputs were changed"
    assert data.read_text() == "old data\n" and fig.read_bytes() == b"old figure"
    assert listing(tmp_path) == ["s.csv", "s.png"]
    monkeypatch.undo()
    code, _, err = run(capsys, *SWEEP, "--out", data, "--plot", fig)
    assert code == 0, err
    assert data.read_text().startswith("alpha0_deg") and fig.read_bytes()[:4] == b"\x89PNG"
    assert listing(tmp_path) == ["s.csv", "s.png"]


def test_output_group_rolls_back_sets_and_files(tmp_path):
    out, f = tmp_path / "out", tmp_path / "f.txt"
    with OutputSet(out) as s:
        s.write_text("a.txt", "old")
    written_by_bendpam_before(f, b"old")
    with pytest.raises(Interrupted), OutputGroup():
        with OutputSet(out) as s:
            s.write_text("a.txt", "new")
        assert (out / "a.txt").read_text() == "new"  # in place: the run may read it back
        with OutputFile(f) as o:
            o.write_text("new")
        raise Interrupted(143, signal.SIGTERM)
    assert (out / "a.txt").read_text() == "old" and f.read_text() == "old"
    verify_set(out, required=True)
    assert listing(tmp_path) == ["f.txt", "out"]
    with OutputGroup():
        with OutputSet(out) as s:
            s.write_text("a.txt", "new")
        with OutputFile(f) as o:
            o.write_text("new")
    assert (out / "a.txt").read_text() == "new" and f.read_text() == "new"
    assert listing(tmp_path) == ["f.txt", "out"]


def test_one_target_twice_in_a_run_is_one_line(tmp_path):
    with OutputGroup():
        with OutputFile(tmp_path / "a.csv") as o:
            o.write_text("1\n")
        with pytest.raises(outputs.OutputBusy, match="written twice by this run"), OutputFile(tmp_path / "a.csv"):
            pass


# ----------------------------------------------------------------------------------------------
# signals: honest words
# ----------------------------------------------------------------------------------------------
def test_signal_after_the_commit_says_what_was_written(capsys, tmp_path, monkeypatch):
    real = outputs.record_written

    def record_then_signal(path):
        real(path)
        signal.raise_signal(signal.SIGTERM)  # held until every output is final

    monkeypatch.setattr(outputs, "record_written", record_then_signal)
    out = tmp_path / "be.toml"
    code, _, err = run(capsys, "actuator", "--preset", "be-pam", "--out", out)
    assert code == 143
    assert err.strip().splitlines()[-1] == f"bendpam: interrupted after writing {out}"
    assert "alpha0_deg" in out.read_text()


def _entry(code: str, *args: object, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-c", code, *map(str, args)], cwd=cwd, capture_output=True, text=True,
                          timeout=120, stdin=subprocess.DEVNULL)


@pytest.mark.parametrize("sig, rc", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_signal_while_the_process_exits_is_one_line(tmp_path, sig, rc):
    # the console script's handlers are back once main() returns: the line still tells the truth
    code = ("import bendpam_entry, os, signal, sys, time\n"
            "from bendpam.cli.app import main\n"
            "assert main(['actuator', '--preset', 'be-pam', '--out', sys.argv[1]]) == 0\n"
            f"os.kill(os.getpid(), {int(sig)})\n"
            "time.sleep(60)\n")
    r = _entry(code, tmp_path / "be.toml", cwd=tmp_path)
    assert r.returncode == rc, r.stderr
    assert r.stderr.splitlines() == [f"bendpam: interrupted after writing {tmp_path / 'be.toml'}"]


@pytest.mark.parametrize("sig, rc", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_signal_before_bendpam_is_imported_is_one_line(tmp_path, sig, rc):
    # the handlers are installed by the console script's import of bendpam_entry, before anything else
    code = f"import bendpam_entry, signal, time\nsignal.raise_signal({int(sig)})\ntime.sleep(60)\n"
    r = _entry(code, cwd=tmp_path)
    assert r.returncode == rc and r.stderr == "bendpam: interrupted; no outputs were changed\n"


# ----------------------------------------------------------------------------------------------
# a single-file output after SIGKILL
# ----------------------------------------------------------------------------------------------
KILLED_WRITER = r"""
import sys, time, types
pkg = types.ModuleType("bendpam")
pkg.__path__ = [sys.argv[1]]
sys.modules["bendpam"] = pkg
from bendpam.infra.atomic import atomic_path
from bendpam.infra.outputs import OutputFile

with OutputFile(sys.argv[2]) as f:
    with atomic_path(f.path) as tmp:     # a writer with its own temporary (save_figure)
        tmp.write_bytes(b"half a figure")
        print("ready", flush=True)
        time.sleep(120)
"""


def test_temporaries_and_lock_of_a_killed_single_file_output_are_cleaned(capsys, tmp_path):
    target = tmp_path / "o-plot.png"
    script = tmp_path.parent / f"{tmp_path.name}-writer.py"
    script.write_text(KILLED_WRITER)
    p = subprocess.Popen([sys.executable, str(script), str(PKG_DIR), str(target)], stdout=subprocess.PIPE, text=True)
    try:
        assert p.stdout is not None and p.stdout.readline().strip() == "ready"
        p.kill()
        assert p.wait(30) == -signal.SIGKILL
    finally:
        p.kill()
        script.unlink()
    left = sorted(os.listdir(tmp_path))
    assert len(left) == 2 and left[0].startswith("..o-plot.png.bendpam-tmp-"), left  # the writer's temporary
    assert left[1] == ".o-plot.png.bendpam-lock"  # and the lock file
    code, _, err = run(capsys, "curve", "--preset", "be-pam", "--pressure-kpa", "150", "--out", target)
    assert code == 0, err
    assert listing(tmp_path) == ["o-plot.png"]


# ----------------------------------------------------------------------------------------------
# reading a set back: its manifest is checked
# ----------------------------------------------------------------------------------------------
def test_a_damaged_set_is_refused_when_read_back(capsys, lab, tmp_path):
    proc = tmp_path / "proc"
    assert run(capsys, "process", lab / "raw", "--out", proc, "--no-figure")[0] == 0
    assert verify_set(proc)["producer"] == "process"
    verify_file(proc / "curves.nc")
    data = bytearray((proc / "curves.nc").read_bytes())
    data[len(data) // 2] ^= 0xFF
    (proc / "curves.nc").write_bytes(bytes(data))
    with pytest.raises(FileFormatError, match=r"curves\.nc: does not match the manifest\.json of its folder"):
        verify_set(proc)
    with pytest.raises(FileFormatError, match=r"curves\.nc: does not match"):
        verify_file(proc / "curves.nc")
    verify_file(proc / "summary.json")  # the other files are fine
    (proc / "curves.nc").unlink()
    with pytest.raises(FileFormatError, match="missing"):
        verify_set(proc)
    (proc / "manifest.json").write_text("[]")
    with pytest.raises(FileFormatError, match="not a bendpam manifest"):
        verify_set(proc)
    with pytest.raises(FileFormatError, match=r"no manifest\.json"):
        verify_set(tmp_path, required=True)
    assert verify_set(tmp_path) is None


def test_commands_refuse_a_damaged_input_set(capsys, lab, tmp_path):
    proc = tmp_path / "proc"
    assert run(capsys, "process", lab / "raw", "--out", proc, "--no-figure")[0] == 0
    summary = proc / "summary.json"
    summary.write_text(summary.read_text().replace('"cycles"', '"cycles" ', 1))
    code, _, err = run(capsys, "fit", proc, "--preset", "be-pam", "--out", tmp_path / "fit")
    assert code == 2
    assert one_error(err) == (f"bendpam: error: {summary}: does not match the manifest.json of its folder "
                              "(size or sha256 differ: changed or damaged after bendpam wrote it)")
    assert sorted(os.listdir(tmp_path)) == ["proc"]
    # an input folder with another tool's manifest.json is not bendpam's to check
    raw = tmp_path / "theirs"
    raw.mkdir()
    for f in (lab / "raw").glob("*.csv"):
        (raw / f.name).write_bytes(f.read_bytes())
    (raw / "manifest.json").write_text('{"instrument": "Zwick"}')
    assert run(capsys, "process", raw, "--out", tmp_path / "p2", "--no-figure")[0] == 0


def test_file_browser_litter_is_not_user_data(tmp_path):
    out = tmp_path / "out"
    with OutputSet(out) as s:
        s.write_text("a.txt", "a")
    (out / ".DS_Store").write_bytes(b"\0Bud1")
    with OutputSet(out) as s:  # replaced with the set
        s.write_text("a.txt", "b")
    assert sorted(os.listdir(out)) == ["a.txt", "manifest.json"]
    empty = tmp_path / "shown-in-a-browser"
    empty.mkdir()
    (empty / "Thumbs.db").write_bytes(b"x")
    with OutputSet(empty) as s:
        s.write_text("a.txt", "a")
    assert sorted(os.listdir(empty)) == ["a.txt", "manifest.json"]


def test_the_library_reads_a_bendpam_set_only_as_it_was_written(capsys, lab, tmp_path):
    """``load_processed``, ``FitResult.load`` and ``read_test`` check a bendpam set's manifest (issue 21, item 5)."""
    from bendpam.identify.result import FitResult
    from bendpam.lab.processed import load_processed
    from bendpam.lab.readers import read_test

    proc, fit, raw = tmp_path / "proc", tmp_path / "fit", tmp_path / "raw"
    assert run(capsys, "process", lab / "raw", "--out", proc, "--no-figure")[0] == 0
    assert run(capsys, "fit", proc, "--preset", "be-pam", "--out", fit, "--no-figure")[0] == 0
    assert run(capsys, *SIM, "--out", raw)[0] == 0
    load_processed(proc), FitResult.load(fit), read_test(next(raw.glob("*.csv")))  # intact: read
    for f in (proc / "curves.nc", fit / "fit.json", next(raw.glob("*.csv"))):
        data = bytearray(f.read_bytes())
        data[len(data) // 2] ^= 0x01
        f.write_bytes(bytes(data))
    with pytest.raises(FileFormatError, match=r"curves\.nc: does not match the manifest\.json"):
        load_processed(proc)
    with pytest.raises(FileFormatError, match=r"fit\.json: does not match the manifest\.json"):
        FitResult.load(fit)
    with pytest.raises(FileFormatError, match=r"\.csv: does not match the manifest\.json"):
        read_test(next(raw.glob("*.csv")))


def test_a_single_file_bendpam_did_not_write_is_never_overwritten(capsys, tmp_path):
    """``--out F.toml`` over a hand-written file: refused; forced, the old file is moved aside (issue 21, 25)."""
    f = tmp_path / "F.toml"
    f.write_text("# my hand-edited actuator\n")
    code, _, err = run(capsys, "actuator", "--preset", "be-pam", "--out", f)
    assert code == 2
    assert one_error(err).startswith(f"bendpam: error: output file '{f}' exists and is not a file bendpam wrote")
    assert "--force" in err and "moved aside, not deleted" in err
    assert f.read_text() == "# my hand-edited actuator\n" and sorted(os.listdir(tmp_path)) == ["F.toml"]
    # forced: written, and the user's file kept beside it
    code, _, err = run(capsys, "actuator", "--preset", "be-pam", "--out", f, "--force")
    assert code == 0, err
    aside = [p for p in tmp_path.iterdir() if p.name.startswith("F.toml.moved-aside-")]
    assert len(aside) == 1 and aside[0].read_text() == "# my hand-edited actuator\n"
    assert "alpha0_deg" in f.read_text() and "moved to" in err
    # a file bendpam wrote and nobody changed is replaced without force ...
    assert run(capsys, "actuator", "--preset", "bc-pam", "--out", f)[0] == 0
    # ... but not once it was edited
    f.write_text(f.read_text() + "# edited\n")
    assert run(capsys, "actuator", "--preset", "be-pam", "--out", f)[0] == 2
    assert f.read_text().endswith("# edited\n")
