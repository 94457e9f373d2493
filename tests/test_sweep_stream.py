"""Streamed sweeps (issue 24): a Zarr store written block by block, resumable, bounded in memory, on Dask."""

import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import bendpam
from bendpam import presets
from bendpam.cli import main
from bendpam.errors import InputError
from bendpam.infra.fsops import part_name
from bendpam.infra.manifest import MANIFEST_NAME
from bendpam.sweep_store import default_chunk_cases, sweep_fingerprint, sweep_zarr
from bendpam.sweeps import plan_sweep

xr = pytest.importorskip("xarray")
pytest.importorskip("zarr")
pytest.importorskip("dask.array")

SRC = Path(bendpam.__file__).resolve().parent.parent
P = [60.0, 120.0, 180.0, 240.0]
GRID = {"alpha0_deg": [64.0, 67.0, 70.0, 73.0, 76.0], "t0_mm": [2.0, 2.5, 3.0]}


def base():
    return presets.be_pam()


def store_files(path: Path) -> dict[str, bytes]:
    """Every file of a store but the manifest (which records when the run started), by relative name."""
    return {p.relative_to(path).as_posix(): p.read_bytes() for p in sorted(path.rglob("*"))
            if p.is_file() and p.name != MANIFEST_NAME}


def same_values(a, b) -> bool:
    return all(np.ascontiguousarray(a[v]).tobytes() == np.ascontiguousarray(b[v]).tobytes() and a[v].dtype == b[v].dtype
               for v in a.data_vars) and set(a.data_vars) == set(b.data_vars)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The store of an uninterrupted in-process run (blocks of 1 x 2 cases: 10 blocks)."""
    path = tmp_path_factory.mktemp("ref") / "ref.zarr"
    sweep_zarr(base(), path, P, chunk_cases=2, command=["ref"], **GRID)
    return path


def test_store_holds_the_sweep_bit_for_bit_and_opens_lazily(reference):
    ds = xr.open_zarr(reference)
    mem = bendpam.sweep(base(), P, chunk_cases=2, **GRID)
    assert dict(ds.sizes) == {"alpha0_deg": 5, "t0_mm": 3, "pressure_kpa": 4}
    assert ds["free_angle_deg"].chunks == ((1,) * 5, (2, 1), (4,))  # one chunk per block
    assert all(hasattr(ds[v].data, "dask") for v in ds.data_vars)  # lazy until asked
    assert same_values(ds.compute(), mem)
    assert ds["branch_end"].dtype == np.int8
    for v in mem.data_vars:
        assert ds[v].attrs["units"] == mem[v].attrs["units"]
    assert ds["pressure_kpa"].attrs["units"] == "kPa" and ds["t0_mm"].attrs["units"] == "mm"
    assert ds.attrs["blocks"] == 10 and list(ds.attrs["block_cases"]) == [1, 2]
    # an output set: a manifest listing every file, no staging or resume state left behind
    manifest = (reference / MANIFEST_NAME).read_text()
    assert ".zmetadata" in manifest and ".bendpam-resume" not in manifest
    assert not (reference.parent / part_name(reference.name)).exists()


def test_resume_after_an_error_in_a_block_callback_gives_the_same_store(tmp_path, reference):
    target = tmp_path / "s.zarr"
    seen = []

    def stop_after_three(n):
        seen.append(n)
        if len(seen) == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        sweep_zarr(base(), target, P, chunk_cases=2, command=["s"], progress=stop_after_three, **GRID)
    assert not target.exists()  # nothing of the new set is visible
    part = tmp_path / part_name(target.name)
    marks = sorted(int(p.name) for p in (part / ".bendpam-resume" / "blocks").iterdir())
    assert len(marks) == 3
    again = []
    sweep_zarr(base(), target, P, chunk_cases=2, command=["s"], progress=again.append, **GRID)
    assert again[0] == sum(seen)  # the cases done before, reported once; then only the other blocks
    assert len(again) == 1 + 10 - 3 and sum(again) == 15
    assert store_files(target) == store_files(reference)
    assert not part.exists()


def test_a_different_command_starts_afresh_and_the_old_store_stays(tmp_path, reference):
    target = tmp_path / "s.zarr"
    sweep_zarr(base(), target, P, chunk_cases=2, command=["s"], **GRID)
    before = store_files(target)

    def boom(n):
        raise RuntimeError("stop")

    other = {**GRID, "t0_mm": [2.0, 2.6, 3.0]}
    with pytest.raises(RuntimeError):
        sweep_zarr(base(), target, P, chunk_cases=2, command=["s"], progress=boom, **other)
    assert store_files(target) == before  # the previous set is what is visible
    part = tmp_path / part_name(target.name)
    key = (part / ".bendpam-resume" / "key").read_text()
    assert key == sweep_fingerprint(plan_sweep(base(), P, chunk_cases=2, **other))
    calls = []
    sweep_zarr(base(), target, P, chunk_cases=2, command=["s"], progress=calls.append, **GRID)
    assert len(calls) == 10  # another fingerprint: nothing resumed
    assert store_files(target) == store_files(reference)


def test_the_fingerprint_covers_what_decides_the_numbers():
    fp = lambda **kw: sweep_fingerprint(plan_sweep(**{"base_actuator": base(), "pressure_kpa": P,
                                                      "chunk_cases": 2, **GRID, **kw}))
    ref = fp()
    assert fp() == ref
    assert fp(pressure_kpa=[60.0, 120.0, 180.0, 241.0]) != ref
    assert fp(chunk_cases=3) != ref
    assert fp(model="force_balance") != ref
    assert fp(base_actuator=base().replace(L0_mm=base().L0_mm + 1)) != ref
    assert fp(eq19_factor=False) != ref


def test_killed_process_resumes_to_the_same_store(tmp_path, reference):
    # the child stops for good at a block boundary (a file says so) and is killed there: no race
    ready = tmp_path / "three-blocks"
    child = textwrap.dedent(f"""
        import sys, time, pathlib
        sys.path.insert(0, {str(SRC)!r})
        import bendpam
        from bendpam.sweep_store import sweep_zarr
        n = []
        def hold(k):
            n.append(k)
            if len(n) == 3:
                pathlib.Path({str(ready)!r}).write_text("3")
                sys.stdin.read()   # until killed
        sweep_zarr(bendpam.physics.presets.be_pam(), {str(tmp_path / "s.zarr")!r}, {P!r}, chunk_cases=2,
                   command=["s"], progress=hold, **{GRID!r})
    """)
    proc = subprocess.Popen([sys.executable, "-c", child], stdin=subprocess.PIPE, cwd=tmp_path)
    try:
        while not ready.exists():
            assert proc.poll() is None, "the child ended before its third block"
            try:
                proc.wait(timeout=0.05)
            except subprocess.TimeoutExpired:
                pass
        proc.send_signal(signal.SIGKILL)
    finally:
        proc.wait()
    target = tmp_path / "s.zarr"
    assert not target.exists()
    calls = []
    sweep_zarr(base(), target, P, chunk_cases=2, command=["s"], progress=calls.append, **GRID)
    assert len(calls) == 1 + 7
    assert store_files(target) == store_files(reference)


def test_cli_writes_a_zarr_store_from_the_suffix_or_format(tmp_path, monkeypatch, reference):
    monkeypatch.chdir(tmp_path)
    args = ["sweep", "--preset", "be-pam", "--param", "alpha0_deg=64,67,70,73,76", "--param", "t0_mm=2,2.5,3",
            "--pressure-kpa", "60,120,180,240", "--chunk-cases", "2", "--out", "s.zarr", "--plot", "s.png",
            "--quiet"]
    assert main(args) == 0
    assert store_files(tmp_path / "s.zarr") == store_files(reference)
    assert (tmp_path / "s.png").stat().st_size > 0
    assert main([*args[:-3], "--format", "zarr", "--out", "t", "--quiet"]) == 0
    assert same_values(xr.open_zarr(tmp_path / "t"), xr.open_zarr(reference))


def test_default_blocks_and_memory_refusal():
    assert default_chunk_cases(16) == 2048
    plan = plan_sweep(base(), P, chunk_cases=default_chunk_cases(len(P)), **GRID)
    assert plan.n_blocks == 1
    with pytest.raises(InputError, match=r"streamed sweep in blocks of 15 cases x 4 pressures .* max_memory_gib"):
        sweep_zarr(base(), "never.zarr", P, max_memory_gib=0.01, **GRID)
    assert not Path("never.zarr").exists()


@pytest.mark.slow  # two LocalClusters, about 10-20 s
def test_cluster_runs_give_the_same_store_with_1_and_2_workers(tmp_path, reference):
    distributed = pytest.importorskip("distributed")
    one = sweep_zarr(base(), tmp_path / "one.zarr", P, chunk_cases=2, command=["ref"], workers=1, **GRID)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        two = sweep_zarr(base(), tmp_path / "two.zarr", P, chunk_cases=2, command=["ref"],
                         scheduler=cluster.scheduler_address, **GRID)
    assert store_files(one) == store_files(reference)
    assert store_files(two) == store_files(reference)


MEMORY_CHILD = """
import sys
sys.path.insert(0, sys.argv[1])
import numpy as np, bendpam
from bendpam.sweep_store import sweep_zarr
cases, pressures = int(sys.argv[3]), int(sys.argv[4])
sweep_zarr(bendpam.physics.presets.be_pam(), sys.argv[2], np.linspace(60.0, 250.0, pressures),
           alpha0_deg=np.linspace(60.0, 80.0, cases), command=["mem"])
status = open("/proc/self/status").read()
print([line.split()[1] for line in status.splitlines() if line.startswith("VmHWM")][0])
"""


@pytest.mark.slow  # a 2*10^6-point sweep, about 15 s; the 10^7 and 10^8 runs are in benchmarks/bench_sweep_stream.py
@pytest.mark.skipif(not Path("/proc/self/status").exists(), reason="VmHWM is read from Linux /proc")
def test_millions_of_points_peak_under_1_gb(tmp_path):
    # the in-memory sweep holds about 285 bytes a point (2.85 GB per 10^7): 2*10^6 points would take
    # about 570 MB there; streamed, the peak stays at the blocks in flight whatever the size
    cases, pressures = 2_000, 1_000
    out = subprocess.run([sys.executable, "-c", MEMORY_CHILD, str(SRC), str(tmp_path / "big.zarr"), str(cases),
                          str(pressures)], capture_output=True, text=True, check=True, cwd=tmp_path)
    peak_kib = int(out.stdout.split()[-1])
    assert peak_kib * 1024 < 1e9, f"peak {peak_kib / 1024:.0f} MiB"
    ds = xr.open_zarr(tmp_path / "big.zarr")
    assert ds["free_angle_deg"].size == cases * pressures == 2 * 10**6
    last = ds["free_angle_deg"].isel(alpha0_deg=-1).values  # one block read back, lazily
    direct = bendpam.sweep(presets.be_pam(), np.linspace(60.0, 250.0, pressures), alpha0_deg=[80.0],
                           chunk_cases=default_chunk_cases(pressures))
    np.testing.assert_allclose(last, direct["free_angle_deg"].values[0], rtol=1e-12)  # (other blocks)


def test_cli_run_again_after_an_interruption_resumes(tmp_path, monkeypatch, capsys, reference):
    from bendpam.sweeps import SweepPlan

    monkeypatch.chdir(tmp_path)
    compute = SweepPlan.compute

    def stop_at_block_4(self, block):
        if block == 4:
            raise KeyboardInterrupt
        return compute(self, block)

    args = ["sweep", "--preset", "be-pam", "--param", "alpha0_deg=64,67,70,73,76", "--param", "t0_mm=2,2.5,3",
            "--pressure-kpa", "60,120,180,240", "--chunk-cases", "2", "--out", "s.zarr", "--quiet"]
    monkeypatch.setattr(SweepPlan, "compute", stop_at_block_4)
    assert main(args) != 0
    err = capsys.readouterr().err
    assert "the finished blocks are kept in" in err and "run the same command again" in err
    assert not (tmp_path / "s.zarr").exists()
    monkeypatch.setattr(SweepPlan, "compute", compute)
    assert main(args) == 0
    assert store_files(tmp_path / "s.zarr") == store_files(reference)
