"""Fault injection of the real ``bendpam`` commands (issue 12).

The commands run as subprocesses.  Every outcome must be exit 0 (with strict JSON on stdout for
``--json``), ONE line ``bendpam: error: ...`` with exit 2, or the interrupt line with 130/143 --
never a traceback, an exit-1 internal error, a hang or a mixed output set.  The harness is
``tools/fault_injection.py`` (its longer run: ``python tools/fault_injection.py``).
"""

from __future__ import annotations

import importlib.util
import signal
import sys
from pathlib import Path

import pytest

_TOOL = Path(__file__).resolve().parents[1] / "tools" / "fault_injection.py"
_spec = importlib.util.spec_from_file_location("bendpam_fault_injection", _TOOL)
assert _spec is not None and _spec.loader is not None
fi = importlib.util.module_from_spec(_spec)
sys.modules[_spec.name] = fi
_spec.loader.exec_module(fi)

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals and flock")

TIMEOUT = 90.0


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    return fi.build_inputs(tmp_path_factory.mktemp("fault_inputs"))


def _assert_clean(tally) -> None:
    assert tally.ok, "\n".join(tally.failures)


# ---- the harness itself -----------------------------------------------------------------------
def test_strict_json_refuses_nan():
    with pytest.raises(ValueError):
        fi.strict_json('{"a": NaN}')
    with pytest.raises(ValueError):
        fi.strict_json("[Infinity]")
    assert fi.strict_json('{"a": null}') == {"a": None}


def test_classify_outcomes():
    ok = fi.Run(["x"], 0, "", "", 0.1)
    assert fi.classify(ok)[0] == "ok"
    assert fi.classify(fi.Run(["x"], 2, "", "bendpam: error: bad\n", 0.1))[0] == "error"
    assert fi.classify(fi.Run(["x"], 2, "", "noise\nbendpam: error: bad\n", 0.1))[0] == "bad-error"
    assert fi.classify(fi.Run(["x"], 1, "", "bendpam: internal error (X)", 0.1))[0] == "internal"
    assert fi.classify(fi.Run(["x"], 1, "", "Traceback (most recent call last):\n", 0.1))[0] == "traceback"
    assert fi.classify(fi.Run(["x"], 130, "", fi.INTERRUPT_LINE + "\n", 0.1))[0] == "interrupt"
    assert fi.classify(fi.Run(["--json"], 0, '{"a": NaN}', "", 0.1))[0] == "bad-json"
    assert fi.classify(fi.Run(["x"], None, "", "", 9.0, hung=True))[0] == "hang"


def test_set_problem_detects_a_mixture(tmp_path):
    import json

    d = tmp_path / "set"
    d.mkdir()
    (d / "a.txt").write_text("a")
    entry = {"path": "a.txt", "size": 1, "sha256": fi.sha256(d / "a.txt")}
    (d / "manifest.json").write_text(json.dumps({"files": [entry]}))
    before = fi.snapshot(d)
    assert fi.set_problem(d, before) is None
    assert fi.set_problem(d, None) is None  # complete set
    (d / "b.txt").write_text("b")  # a file the manifest does not list
    assert fi.set_problem(d, before) is not None


# ---- bad command lines and mutated inputs ------------------------------------------------------
@pytest.mark.slow  # about 45 subprocesses, each importing bendpam (1-2 s apiece): 20-40 s
def test_bad_command_lines(inputs):
    tally = fi.Tally()
    every = fi.bad_command_lines(inputs)  # a third of them, spread over the list, and the sizes checked below
    cases = [c for i, c in enumerate(every) if i % 3 == 0 or "--workers" in c or "30000000" in c]
    assert len(cases) >= 28
    results = fi.run_cases(tally, cases, inputs["work"], jobs=3, timeout=TIMEOUT)
    _assert_clean(tally)
    # the absurd sizes are refused, not attempted
    refused = {" ".join(a): d for a, k, d in results if k == "error"}
    assert any("--workers 0" in a for a in refused)
    assert any("30000000" in a for a in refused)


def test_simulate_rate_is_bounded_before_allocation(inputs):
    r = fi.run(["simulate-test", "--preset", "be-pam", "--pressure-kpa", "150", "--rate-hz", "1e6",
                "--out", "sim_big"], inputs["work"], timeout=30)
    kind, line = fi.classify(r)
    assert kind == "error", r.stderr
    # refused by its sample count before anything is allocated (the message counts the samples);
    # no wall-clock bound here: the time of a run says nothing on a loaded machine
    assert "samples" in line and "--rate-hz" in line and "--cycles" in line
    assert not (inputs["work"] / "sim_big").exists()
    assert fi.temporaries(inputs["work"] / "sim_big") == []


@pytest.mark.slow  # about 35 subprocesses, each importing bendpam (1-2 s apiece): 15-25 s
def test_mutated_inputs(inputs, tmp_path):
    tally = fi.Tally()
    cases = fi.mutated_cases(inputs, tmp_path, seed=3, small=True)
    assert len(cases) >= 20
    fi.run_cases(tally, cases, inputs["work"], jobs=3, timeout=TIMEOUT)
    _assert_clean(tally)


def test_toml_scalar_hysteresis_is_one_line(inputs, tmp_path):
    t = tmp_path / "act.toml"
    t.write_text("hysteresis = 5\n" + inputs["toml"].read_text())
    r = fi.run(["predict", "--actuator", t, "--pressure-kpa", "150", "--cycle"], inputs["work"], timeout=TIMEOUT)
    kind, line = fi.classify(r)
    assert kind == "error" and "hysteresis" in line, r.stderr


# ---- signals and concurrency ---------------------------------------------------------------------
@pytest.mark.parametrize("sig, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_signal_gives_exit_code_and_one_line(inputs, tmp_path, sig, code):
    tally = fi.Tally()
    fi.kill_case(tally, "report", inputs, tmp_path, sig, 1.5, mid_work=True)  # once it holds its output's lock
    _assert_clean(tally)
    assert tally.counts["interrupt"] == 1


@pytest.mark.slow
@pytest.mark.parametrize("command", list(fi.KILL_COMMANDS))
def test_random_kills_keep_output_sets_whole(inputs, tmp_path, command):
    tally = fi.Tally()
    max_delay = {"process": 2.5, "fit": 3.0, "report": 4.0, "sweep": 2.5}[command]
    fi.kill_series(tally, command, inputs, tmp_path, n=2, seed=sorted(fi.KILL_COMMANDS).index(command),
                   max_delay=max_delay, startup_fraction=0.0)
    _assert_clean(tally)


def test_sigint_during_startup_is_one_line(inputs):
    import subprocess
    import time

    p = subprocess.Popen(fi.cli("predict", "--preset", "be-pam", "--pressure-kpa", "150"), cwd=inputs["work"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=fi.child_env())
    # bendpam_entry installs its handlers (SIGINT, then SIGTERM, which Python itself leaves alone) before it
    # imports the package: once SIGTERM is caught, the import is under way, on a machine of any speed
    if fi.catches(p.pid, signal.SIGTERM) is None:  # no /proc: by the clock
        time.sleep(0.08)
    else:
        assert fi.wait_until(lambda: bool(fi.catches(p.pid, signal.SIGTERM)), p), p.communicate()
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=TIMEOUT)
    assert p.returncode == 130 and err.strip() == fi.INTERRUPT_LINE


@pytest.mark.slow
@pytest.mark.parametrize("command", ["process", "sweep"])
def test_concurrent_runs_never_mix(inputs, tmp_path, command):
    tally = fi.Tally()
    fi.concurrent_case(tally, command, inputs, tmp_path, stagger=0.0)
    _assert_clean(tally)


# ---- issue 21: what bendpam may replace, read back and refuse (tools/fault_families.py) -----------
_FAM = _TOOL.parent / "fault_families.py"
_fspec = importlib.util.spec_from_file_location("bendpam_fault_families", _FAM)
assert _fspec is not None and _fspec.loader is not None
ff = importlib.util.module_from_spec(_fspec)
sys.modules[_fspec.name] = ff
_fspec.loader.exec_module(ff)


def test_lost_files_finds_moved_aside_copies_and_changes(tmp_path):
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "notes.txt").write_text("mine")
    before = ff.hashes(tmp_path, ["out"])
    assert ff.lost_files(tmp_path, before) == []
    (tmp_path / "out").rename(tmp_path / "out.moved-aside-20260101T000000Z")
    assert ff.lost_files(tmp_path, before) == []  # moved aside, not lost
    (tmp_path / "out.moved-aside-20260101T000000Z" / "notes.txt").write_text("changed")
    assert ff.lost_files(tmp_path, before) == ["out/notes.txt"]


_GUARD_SAMPLE = ["foreign manifest, process", "user file in a set --force", "hand-written --plot png",
                 "--out ~ --force"]


@pytest.mark.slow  # about 6 subprocesses: 5-15 s
def test_guards_keep_user_files(inputs, tmp_path):
    from concurrent.futures import ThreadPoolExecutor

    cases = [g for g in ff.guard_cases() if g.name in _GUARD_SAMPLE]  # the tool runs all of them
    assert len(cases) == len(_GUARD_SAMPLE)
    tally = fi.Tally()
    with ThreadPoolExecutor(2) as ex:
        list(ex.map(lambda g: ff.guard_case(tally, g, inputs, tmp_path, TIMEOUT), cases))
    _assert_clean(tally)
    assert tally.counts["error"] == 3 and tally.counts["ok"] == 1


@pytest.mark.parametrize("which", ["curves.nc", "raw"])
def test_damaged_set_read_back_is_refused_naming_the_file(inputs, tmp_path, which):
    tally = fi.Tally()
    ff.readback_case(tally, which, inputs, tmp_path, seed=5, timeout=TIMEOUT)
    _assert_clean(tally)


def test_signal_after_the_commit_says_what_is_true(inputs, tmp_path):
    tally = fi.Tally()
    # the last line must match the disk ('after writing' and a complete set, or 'no outputs were changed' and
    # none), and a 'wrote' line is printed only once the outputs are committed (never before a roll-back)
    ff.post_commit_case(tally, "process", inputs, tmp_path, signal.SIGINT, timeout=TIMEOUT)
    _assert_clean(tally)


def test_console_script_signal_once_its_handlers_are_in(tmp_path):
    tally = fi.Tally()
    ff.console_case(tally, tmp_path, signal.SIGTERM, "handlers", timeout=TIMEOUT)
    _assert_clean(tally)
    assert tally.counts["interrupt"] == 1


@pytest.mark.skipif(not hasattr(__import__("os"), "mkfifo"), reason="POSIX FIFOs")
def test_fifo_actuator_is_refused_in_one_line(inputs, tmp_path):
    tally = fi.Tally()
    case = [c for c in ff.budget_lines(tmp_path) if c[0] == "fifo" and c[1][0] == "predict"]
    ff.refusal_cases(tally, case, tmp_path, timeout=10.0)
    _assert_clean(tally)


@pytest.mark.parametrize("how", ["alpha0_deg=0.001", "R0_start_mm=1e22"])
def test_absurd_actuator_value_is_refused(inputs, tmp_path, how):
    tally = fi.Tally()
    case = [c for c in ff.plausible_lines(inputs, tmp_path) if c[0] == f"plausible {how}"]
    ff.refusal_cases(tally, case, tmp_path, timeout=TIMEOUT)
    _assert_clean(tally)


def test_absurd_pressure_is_refused(inputs, tmp_path):
    tally = fi.Tally()
    case = [c for c in ff.plausible_lines(inputs, tmp_path) if c[1][0] == "predict" and "1e6" in c[1]]
    ff.refusal_cases(tally, case, tmp_path, timeout=TIMEOUT)
    _assert_clean(tally)
