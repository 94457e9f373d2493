"""Budgets in size, count, memory and time (issue 21 items 3 and 6): each finding of the audit, refused in one line.

Inputs that are not regular files, too large or nested too deeply; ranges with more values than a
command evaluates in about a minute; sweeps past the memory or time budget; a Dask scheduler that
is malformed or does not answer; internal_stresses on many pressures (chunked, identical results).
The refusals are asserted, never the time they take.
"""

import json
import os
import socket
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

import bendpam
from bendpam import presets
from bendpam.cli import main
from bendpam.errors import FileFormatError, InputError
from bendpam.infra import budgets
from bendpam.infra.budgets import (
    FILE_SIZE_LIMITS,
    MIB,
    check_input_file,
    format_bytes,
    loads_toml,
    memory_problem,
    nesting_depth,
    read_input_bytes,
    value_limit,
)
from bendpam.infra.scheduler import parse_scheduler_address, probe_scheduler
from bendpam.sweeps import BASE_BYTES, RESULT_BYTES_PER_POINT, SECONDS_PER_CASE, SECONDS_PER_POINT, sweep_estimate

ACTUATOR_TOML = presets.be_pam().to_toml()
needs_fifo = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes need os.mkfifo (POSIX)")


def one_error_line(capsys, *args) -> str:
    code = main([str(a) for a in args])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.startswith("bendpam: error:") and err.count("\n") == 1 and "Traceback" not in err, err
    return err


def run_cli(*args, cwd) -> subprocess.CompletedProcess:
    """The command in its own process: a reader that blocks on a named pipe fails the test instead of hanging it."""
    env = dict(os.environ, BENDPAM_PROGRESS_INTERVAL_S="inf")
    env["PYTHONPATH"] = os.pathsep.join([str(Path(bendpam.__file__).parents[1]), env.get("PYTHONPATH", "")])
    return subprocess.run([sys.executable, "-m", "bendpam", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, env=env, timeout=120)


# ---- input files: regular files within a size per kind ------------------------------------------
@needs_fifo
def test_a_named_pipe_is_refused_as_actuator_and_raw_file(tmp_path):
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    for args, kind in [(["predict", "--actuator", fifo, "--pressure-kpa", "150"], "an actuator file"),
                       (["inspect", fifo], "a raw test file"),
                       (["process", fifo, "--out", tmp_path / "out"], "a raw test file")]:
        r = run_cli(*args, cwd=tmp_path)
        assert r.returncode == 2, r.stderr
        assert r.stderr == f"bendpam: error: {fifo}: is a named pipe, not a regular file; expected {kind}\n"
    with pytest.raises(FileFormatError, match="named pipe"):  # the library readers too
        bendpam.Actuator.from_toml(fifo)
    with pytest.raises(FileFormatError, match="named pipe"):
        bendpam.read_test(fifo)


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero here")
def test_dev_zero_is_refused_before_reading(capsys):
    err = one_error_line(capsys, "predict", "--actuator", "/dev/zero", "--pressure-kpa", "150")
    assert "/dev/zero: is a character device, not a regular file; expected an actuator file" in err
    err = one_error_line(capsys, "inspect", "/dev/zero")
    assert "character device" in err and "raw test file" in err


def test_a_folder_is_not_an_actuator_file(tmp_path, capsys):
    err = one_error_line(capsys, "predict", "--actuator", tmp_path, "--pressure-kpa", "150")
    assert f"{tmp_path}: is a folder, not a regular file; expected an actuator file" in err


def test_files_past_the_size_of_their_kind_are_refused(tmp_path, capsys, monkeypatch):
    big = tmp_path / "big.toml"
    with open(big, "wb") as fh:  # sparse: one byte past the limit
        fh.truncate(FILE_SIZE_LIMITS["actuator file"] + 1)
    err = one_error_line(capsys, "predict", "--actuator", big, "--pressure-kpa", "150")
    assert "1 MiB is larger than the 1 MiB limit for an actuator file" in err
    raw = tmp_path / "be_150kPa.csv"
    raw.write_text("time_s,stroke_mm,force_n\n" + "".join(f"{i / 10},{i / 100},1.0\n" for i in range(100)))
    monkeypatch.setitem(FILE_SIZE_LIMITS, "raw test file", 1000)
    err = one_error_line(capsys, "inspect", raw)
    assert f"{raw}: {format_bytes(raw.stat().st_size)} is larger than the 1000 B limit for a raw test file" in err


def test_read_input_bytes_reads_at_most_the_limit(tmp_path, monkeypatch):
    p = tmp_path / "a.toml"
    p.write_text(ACTUATOR_TOML)
    assert read_input_bytes(p, "actuator file") == ACTUATOR_TOML.encode()
    assert check_input_file(p, "actuator file") == len(ACTUATOR_TOML.encode())
    monkeypatch.setitem(FILE_SIZE_LIMITS, "actuator file", 10)
    with pytest.raises(FileFormatError, match="larger than the 10 B limit for an actuator file"):
        read_input_bytes(p, "actuator file")
    with pytest.raises(ValueError, match="unknown kind"):
        check_input_file(p, "poem")


def test_format_bytes_by_hand():
    assert format_bytes(0) == "0 B"
    assert format_bytes(1023) == "1023 B"
    assert format_bytes(1000 * MIB) == "1000 MiB"
    assert format_bytes(1536) == "1.5 KiB"
    assert format_bytes(2 * MIB) == "2 MiB"
    assert format_bytes(3 << 40) == "3 TiB"


# ---- TOML nesting ---------------------------------------------------------------------------------
def test_deeply_nested_toml_is_refused_in_one_line(tmp_path, capsys):
    deep = tmp_path / "deep.toml"
    deep.write_text("a = " + "{b = " * 5000 + "1" + "}" * 5000 + "\n")  # past the parser's recursion
    err = one_error_line(capsys, "predict", "--actuator", deep, "--pressure-kpa", "150")
    assert "deep.toml: tables or arrays nested too deeply to read; an actuator file nests at most 3 deep" in err
    dotted = tmp_path / "dotted.toml"
    dotted.write_text("[" + ".".join(["a"] * 50) + "]\nx = 1\n")  # parses, 51 deep
    err = one_error_line(capsys, "actuator", "--actuator", dotted)
    assert "dotted.toml: tables or arrays nested 51 deep; an actuator file nests at most 3 deep" in err


def test_nesting_depth_by_hand():
    assert nesting_depth(3.0) == 0
    assert nesting_depth([]) == 1
    assert nesting_depth({"actuator": {"R0_mm": 9.0}, "hysteresis": {"law": "pi"}}) == 2
    assert nesting_depth({"a": [1, [2, {"b": [3]}]]}) == 5
    deep: dict = {}
    node = deep
    for _ in range(100_000):  # far past Python's recursion limit: counted without recursion
        node["a"] = {}
        node = node["a"]
    assert nesting_depth(deep) == 100_001  # the innermost (empty) table counts too


def test_loads_toml_keeps_the_parser_message():
    assert loads_toml(ACTUATOR_TOML, "a.toml")["actuator"]["R0_mm"] == presets.be_pam().R0_mm
    with pytest.raises(FileFormatError, match=r"^x.toml: invalid TOML: "):
        loads_toml("a = = 1", "x.toml")


# ---- values per option: what a command evaluates in about a minute -----------------------------------
def test_huge_ranges_are_refused_before_they_are_expanded(capsys):
    err = one_error_line(capsys, "predict", "--preset", "be-pam", "--pressure-kpa", "100:200:999999")
    assert "--pressure-kpa: range '100:200:999999' gives 999999 values; bendpam predict takes at most 100000" in err
    err = one_error_line(capsys, "sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:1000000",
                         "--pressure-kpa", "150", "--out", "never.nc")
    assert "--param alpha0_deg: range '60:80:1000000' gives 1000000 values; bendpam sweep takes at most 100000" in err
    err = one_error_line(capsys, "curve", "--preset", "be-pam", "--pressure-kpa", "100:200:1001", "--out", "never.csv")
    assert "bendpam curve takes at most 1000" in err
    err = one_error_line(capsys, "predict", "--preset", "be-pam", "--pressure-kpa", "100:200:60000",
                         "100:200:60000")
    assert "range '100:200:60000' gives 60000 values after 60000" in err


def test_value_limits_per_command():
    assert value_limit("predict") == 100_000 and value_limit("sweep") == 100_000
    assert value_limit("curve") == 1_000 and value_limit("simulate-test") == 1_000
    assert value_limit("finger") == 10_000 and value_limit("no-such-command") == budgets.DEFAULT_VALUE_LIMIT
    assert all(v <= budgets.MAX_OPTION_VALUES for v in budgets.VALUE_LIMITS.values())


# ---- sweeps: memory and time estimated before any work ---------------------------------------------------
def test_sweep_estimate_by_hand():
    est = sweep_estimate(1000, 10, remote=True)  # no blocks in this process
    assert est.points == 10_000
    assert est.memory_bytes == BASE_BYTES + 10_000 * 2 * RESULT_BYTES_PER_POINT  # 104 bytes a point, twice
    assert est.seconds == pytest.approx(1000 * SECONDS_PER_CASE + 10_000 * SECONDS_PER_POINT)
    assert RESULT_BYTES_PER_POINT == 8 * 13
    table = sweep_estimate(1000, 10, 2, table="csv", remote=True)  # + a row of 2 params, pressure, 13 outputs
    assert table.memory_bytes - est.memory_bytes == 10_000 * 8 * (2 * 3 + 13)
    lazy = sweep_estimate(10**6, 10, compute=False, remote=True)
    assert lazy.memory_bytes == BASE_BYTES  # nothing held: the blocks are written as they come
    blocks = sweep_estimate(1000, 10, chunk_cases=100)
    assert blocks.memory_bytes > est.memory_bytes  # the blocks being computed take memory too


def test_the_old_default_max_points_sweep_is_refused_before_work(capsys, tmp_path):
    # 10^8 points: what --max-points allowed by default before it followed the memory budget
    err = one_error_line(capsys, "sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:10000",
                         "--param", "t0_mm=1.5:3:1000", "--pressure-kpa", "100:200:10", "--out", tmp_path / "s.csv")
    assert "the sweep of 100000000 (case, pressure) points (10000000 cases x 10 pressures) holds its whole" in err
    assert "more than the memory budget of 2 GiB" in err and "--max-memory-gib" in err
    assert not (tmp_path / "s.csv").exists()


def test_a_sweep_past_the_time_budget_is_refused(capsys, tmp_path):
    # 10^6 cases at one pressure: small in memory (about 0.7 GiB), about 5 min on one core
    err = one_error_line(capsys, "sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:1000",
                         "--param", "t0_mm=1.5:3:1000", "--pressure-kpa", "150", "--out", tmp_path / "s.nc",
                         "--max-minutes", "1")
    assert "the sweep of 1000000 (case, pressure) points (1000000 cases x 1 pressure) would take about 5.17 min" in err
    assert "more than --max-minutes 1" in err


def test_max_points_still_refuses(capsys, tmp_path):
    err = one_error_line(capsys, "sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:5", "--pressure-kpa",
                         "100:200:3", "--out", tmp_path / "s.nc", "--max-points", "10")
    assert "15 (case, pressure) points, more than --max-points 10" in err


def test_the_library_sweep_refuses_past_its_memory_budget():
    base = presets.be_pam()
    grid = dict(alpha0_deg=np.linspace(60, 80, 10_000), t0_mm=np.linspace(1.5, 3, 10_000))
    with pytest.raises(InputError, match=r"^a sweep of 1000000000 \(case, pressure\) points would hold about "
                                         r"[\d.]+ GiB, more than the memory budget of 2 GiB"):
        bendpam.sweep(base, np.linspace(100, 200, 10), **grid)
    with pytest.raises(InputError, match="max_memory_gib"):
        bendpam.sweep(base, [150.0], alpha0_deg=[70.0], max_memory_gib=-1)
    small = bendpam.sweep(base, [150.0], alpha0_deg=[70.0, 72.0], max_memory_gib=None)
    assert small["free_angle_deg"].shape == (2, 1)


def test_memory_problem_names_the_budget_or_the_machine(monkeypatch):
    assert memory_problem(1.0 * budgets.GIB) is None
    assert memory_problem(3.0 * budgets.GIB) == "about 3 GiB, more than the memory budget of 2 GiB"
    monkeypatch.setattr(budgets, "physical_memory_bytes", lambda: 4 * budgets.GIB)
    assert memory_problem(5.0 * budgets.GIB, None) == "about 5 GiB, more than this machine's memory (4 GiB)"
    assert memory_problem(5.0 * budgets.GIB, 8.0) == "about 5 GiB, more than this machine's memory (4 GiB)"


# ---- internal_stresses: chunked, bounded, identical ---------------------------------------------------
def test_internal_stresses_in_chunks_equal_one_block(monkeypatch):
    act = presets.bc_pam("force_balance")
    cases = [(np.linspace(40, 140, 301), np.array([-0.01, -0.004, 0.0])), (np.linspace(40, 140, 301), -0.004),
             (120.0, np.linspace(-0.01, 0.0, 97)), (120.0, -0.006)]
    for P, k in cases:
        whole = bendpam.internal_stresses(act, P, k, n_phi=37)
        monkeypatch.setattr(budgets, "CHUNK_BYTES", 2000)  # a few rows a chunk
        chunked = bendpam.internal_stresses(act, P, k, n_phi=37)
        monkeypatch.undo()
        assert list(chunked.data_vars) == list(whole.data_vars)
        for name in whole.data_vars:
            assert chunked[name].dims == whole[name].dims
            assert np.array_equal(chunked[name].values, whole[name].values, equal_nan=True), name


def test_internal_stresses_refuses_a_result_past_the_budget():
    act = presets.bc_pam("force_balance")
    P = np.linspace(40, 140, 2_000_000)  # 2e6 x 181 angles: about 11 GiB of result
    with pytest.raises(InputError, match=r"^internal_stresses: 2000000 pressures x 181 angles would hold about 11 "
                                         r"GiB, more than the memory budget of 2 GiB"):
        bendpam.internal_stresses(act, P, -0.004)
    # 8 x (4 x 181 + 7) bytes a state: 3 x 100 states take 1.75 MB, past a 1 MiB budget
    with pytest.raises(InputError, match="3 pressures x 100 curvatures x 181 angles"):
        bendpam.internal_stresses(act, [60.0, 90.0, 120.0], np.linspace(-0.01, 0, 100), max_memory_gib=1 / 1024)


# ---- the scheduler: parsed, then asked within a timeout ---------------------------------------------
def test_scheduler_addresses_are_parsed(tmp_path):
    assert parse_scheduler_address("tcp://10.0.0.5:8786") == "tcp://10.0.0.5:8786"
    assert parse_scheduler_address("cluster-1.lab:8786") == "tcp://cluster-1.lab:8786"
    assert parse_scheduler_address("TLS://[::1]:8786") == "tls://[::1]:8786"
    sf = tmp_path / "scheduler.json"
    sf.write_text(json.dumps({"type": "Scheduler", "address": "tcp://10.0.0.5:8786"}))
    assert parse_scheduler_address(str(sf)) == "tcp://10.0.0.5:8786"
    for text, word in [("nonsense", "not a Dask scheduler address"), ("tcp://host:99999", "port from 1 to 65535"),
                       ("ftp://host:21", "unknown protocol 'ftp'"), ("tcp://host", "tcp://HOST:PORT"),
                       ("host:", "not a Dask scheduler address"), ("", "not a Dask scheduler address"),
                       (str(tmp_path / "missing.json"), "scheduler file not found")]:
        with pytest.raises(InputError, match=word):
            parse_scheduler_address(text)
    bad = tmp_path / "bad.json"
    bad.write_text("[1, 2]")
    with pytest.raises(InputError, match="not a Dask scheduler file"):
        parse_scheduler_address(str(bad))
    if hasattr(os, "mkfifo"):  # a scheduler file that is a named pipe is refused, not waited on
        os.mkfifo(tmp_path / "pipe.json")
        with pytest.raises(InputError, match="is a named pipe, not a regular file; expected a scheduler file"):
            parse_scheduler_address(str(tmp_path / "pipe.json"))


def test_scheduler_nonsense_is_one_line(capsys, tmp_path):
    err = one_error_line(capsys, "sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:3", "--pressure-kpa",
                         "150", "--out", tmp_path / "s.nc", "--scheduler", "nonsense")
    assert "--scheduler 'nonsense': not a Dask scheduler address; expected tcp://HOST:PORT" in err
    err = one_error_line(capsys, "design", "--preset", "be-pam", "--target", "blocked_moment_nmm=400@200",
                         "--vary", "alpha0_deg=60:80", "--scheduler", "tcp://x:0")
    assert "--scheduler 'tcp://x:0': expected tcp://HOST:PORT" in err


class SilentServer:
    """A TCP server on 127.0.0.1 that accepts connections and says nothing; it stops itself on exit."""

    def __enter__(self):
        self.sock = socket.create_server(("127.0.0.1", 0))
        self.sock.settimeout(0.2)
        self.address = f"tcp://127.0.0.1:{self.sock.getsockname()[1]}"
        self.stop = threading.Event()
        self.accepted: list[socket.socket] = []
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()
        return self

    def _serve(self):
        while not self.stop.is_set():
            try:
                conn, _ = self.sock.accept()
            except TimeoutError:
                continue
            except OSError:
                return
            self.accepted.append(conn)  # held open, never answered

    def __exit__(self, *exc):
        self.stop.set()
        self.thread.join(timeout=5)
        for conn in self.accepted:
            conn.close()
        self.sock.close()


def test_a_silent_server_is_refused_within_the_timeout(capsys, tmp_path, monkeypatch):
    pytest.importorskip("distributed")
    with SilentServer() as server:
        with pytest.raises(InputError, match=rf"^no Dask scheduler answered at {server.address} within 0.5 s$"):
            probe_scheduler(server.address, timeout_s=0.5)
        assert server.accepted  # it was reached: the silence is what is refused
        with pytest.raises(InputError, match="no Dask scheduler answered"):
            bendpam.sweep(presets.be_pam(), [150.0], alpha0_deg=[70.0], scheduler=server.address,
                          scheduler_timeout_s=0.5)
        monkeypatch.setattr(budgets, "SCHEDULER_TIMEOUT_S", 0.5)
        err = one_error_line(capsys, "sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:3",
                             "--pressure-kpa", "150", "--out", tmp_path / "s.nc", "--scheduler",
                             server.address.removeprefix("tcp://"))
        assert f"no Dask scheduler answered at {server.address} within 0.5 s" in err


def test_a_dask_worker_is_not_a_scheduler():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        assert probe_scheduler(cluster.scheduler_address, timeout_s=10)["type"] == "Scheduler"
        worker = next(iter(cluster.scheduler.workers))
        with pytest.raises(InputError, match="answered, but as a Dask Worker, not a scheduler"):
            probe_scheduler(worker, timeout_s=10)


def test_simulate_tests_refuse_a_run_past_the_sample_budget_before_writing(tmp_path):
    from bendpam.lab.simulate import MAX_TOTAL_SAMPLES, SimulationSettings, simulate_tests

    # 50 cycles of the be-pam at 20 Hz: about 9.5e4 samples per test (30 mm/min over a free stroke of
    # 20-45 mm, 4 ramps... per cycle); 1000 tests are about 1e8 samples, past 3e7
    out = tmp_path / "sim"
    with pytest.raises(InputError, match=r"1000 tests of 50 cycles at 20 Hz would record about [\d,]+ samples"):
        simulate_tests(presets.be_pam(), np.linspace(100.0, 200.0, 1000), out,
                       settings=SimulationSettings(cycles=50))
    assert not out.exists()
    assert MAX_TOTAL_SAMPLES == 30_000_000


def test_simulate_test_cli_refuses_the_harness_case_quickly(capsys, tmp_path):
    rc = main(["simulate-test", "--preset", "be-pam", "--pressure-kpa", "100:200:1000", "--cycles", "50",
               "--out", str(tmp_path / "sim")])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1 and "more than the limit of 30,000,000 for one run" in err[0]
    assert not (tmp_path / "sim").exists()
