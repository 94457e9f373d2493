"""Streamed sweeps: the blocks of a sweep written to a Zarr store as they finish, resumable, on Dask or not.

:func:`sweep_zarr` computes the same blocks as :func:`bendpam.sweep` (:func:`bendpam.sweeps.plan_sweep`)
and writes each one into its own chunks of a Zarr store as soon as it is done, so the memory a
sweep takes is bounded by the block size (the blocks in flight), not by the number of points:
a 10^7-point sweep peaks under 1 GB, and so does a 10^8-point one.  The store's layout
(dimensions, coordinates, variables and their ``units``, chunks, completion) is documented in
docs/formats.md; ``xarray.open_zarr(path)`` opens it lazily (Dask arrays, one chunk per block).

Output set
    The store is an output set (:class:`bendpam.infra.outputs.OutputSet`, producer ``sweep``):
    it is built in a staging folder beside the target and put in place whole when the last
    block is written, with a ``manifest.json``.  An interrupted sweep leaves the target as it
    was (the previous store, or nothing).

Resumption
    The staging folder is *kept* when a sweep is interrupted (an error, SIGINT/SIGTERM, a kill),
    with a fingerprint of everything that decides the numbers (:func:`sweep_fingerprint`: the
    base actuator, model, options, swept values, pressures and blocks) and one marker file per
    finished block.  Run again with the same inputs and options, the sweep continues after the
    blocks already marked; the final store is the same, value for value and byte for byte, as
    one written in a single run (each block is computed by the same deterministic function and
    written into its own chunks).  A run with anything else on the same target starts afresh.
    Where it runs (in-process, ``workers``, ``scheduler``) is not in the fingerprint: a sweep
    started on one core may be finished on a cluster.

Dask
    In-process, the blocks are computed on a pool of threads (one per core), at most two per
    thread in flight.  With ``workers`` (a :class:`distributed.LocalCluster` of that many
    processes, on loopback) or ``scheduler`` (the address of a running cluster, which must
    answer within ``scheduler_timeout_s``), each block is computed on a worker and its result
    sent back to this process, which writes it: the workers need no access to the store's
    file system, and at most two blocks per worker thread are in flight.  Every way of running
    gives bit-for-bit the same store (tested with 1 and 2 workers).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.errors import InputError
from bendpam.infra.budgets import MEMORY_BUDGET_GIB, SCHEDULER_TIMEOUT_S, memory_problem
from bendpam.infra.fsops import fsync_dir, fsync_file
from bendpam.infra.outputs import OutputSet
from bendpam.physics.actuator import Actuator
from bendpam.physics.braid import DEFAULT_ORDER
from bendpam.sweeps import SweepPlan, plan_sweep, sweep_estimate
from bendpam.version import __version__

__all__ = ["STORE_LAYOUT", "ZARR_BLOCK_POINTS", "default_chunk_cases", "sweep_fingerprint", "sweep_zarr"]

#: The layout of the store, recorded in its attributes (``bendpam_layout``) and in the fingerprint.
STORE_LAYOUT = "bendpam sweep zarr 1"
#: The (case, pressure) points of a block (and so of a chunk) when the block size is not given:
#: about 64 MiB of working arrays while it is computed, 256 KiB a variable once written.
ZARR_BLOCK_POINTS = 32_768
_PER_CASE = ("max_pressure_kpa", "branch_end")


def default_chunk_cases(n_pressures: int) -> int:
    """Cases a block holds by default in a streamed sweep: :data:`ZARR_BLOCK_POINTS` points, at least one case.

    Examples
    --------
    >>> default_chunk_cases(16), default_chunk_cases(1000), default_chunk_cases(10**6)
    (2048, 32, 1)
    """
    return max(1, ZARR_BLOCK_POINTS // max(1, int(n_pressures)))


def sweep_fingerprint(plan: SweepPlan) -> str:
    """A SHA-256 of everything that decides a streamed sweep's store: its resume key.

    The bendpam version and store layout, the base actuator, model, quadrature order and eq 19
    factor, the swept parameters with their values, the pressures and the blocks.

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.sweeps import plan_sweep
    >>> base = bendpam.physics.presets.be_pam()
    >>> a = sweep_fingerprint(plan_sweep(base, [150.0], alpha0_deg=[65, 70]))
    >>> a == sweep_fingerprint(plan_sweep(base, [150.0], alpha0_deg=[65, 70])), len(a)
    (True, 64)
    >>> a == sweep_fingerprint(plan_sweep(base, [150.0], alpha0_deg=[65, 71]))
    False
    """
    h = hashlib.sha256()
    head = {"layout": STORE_LAYOUT, "version": __version__, "model": plan.model, "order": plan.order,
            "eq19_factor": plan.eq19_factor, "base": plan.base.to_toml(), "names": plan.names,
            "chunks": [list(c) for c in plan.chunks], "outputs": list(plan.outputs)}
    h.update(json.dumps(head, sort_keys=True).encode())
    for arr in (*plan.grids, plan.pressure_kpa):
        h.update(b"|")
        h.update(np.ascontiguousarray(arr, dtype="<f8").tobytes())
    return h.hexdigest()


def sweep_zarr(base_actuator: Actuator, target: str | os.PathLike[str], pressure_kpa, model: str | None = None, *,
               chunk_cases: int | None = None, scheduler: str | None = None, workers: int | None = None,
               progress: Callable[[int], Any] | None = None, order: int = DEFAULT_ORDER, eq19_factor: bool = True,
               max_memory_gib: float | None = MEMORY_BUDGET_GIB, scheduler_timeout_s: float = SCHEDULER_TIMEOUT_S,
               force: bool = False, command: str | Sequence[str] | None = None,
               inputs: Iterable[str | os.PathLike[str]] = (), producer: str = "sweep", **params) -> Path:
    """Run a sweep block by block into the Zarr store ``target`` (an output set), resuming an interrupted one.

    Parameters
    ----------
    base_actuator, pressure_kpa, model, order, eq19_factor, scheduler, workers, scheduler_timeout_s, **params
        As :func:`bendpam.sweep`.
    target : path
        The store (a folder, conventionally ``NAME.zarr``); replaced whole when the sweep ends.
    chunk_cases : int, optional
        Cases per block and per chunk (default :func:`default_chunk_cases`).  Part of the fingerprint.
    progress : callable, optional
        Called as ``progress(n)`` in this thread with the number of cases of each block once it is
        written (and once, at the start, with the cases already done by an interrupted run).
    max_memory_gib : float or None
        The memory budget; the estimate (:func:`bendpam.sweeps.sweep_estimate`) counts only the blocks in flight.
    force, command, inputs, producer
        As :class:`bendpam.infra.outputs.OutputSet`.

    Returns
    -------
    pathlib.Path
        The store, complete (``xarray.open_zarr`` reads it lazily).

    Examples
    --------
    >>> import tempfile, pathlib, xarray as xr, bendpam
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = sweep_zarr(bendpam.physics.presets.be_pam(), pathlib.Path(d) / "s.zarr", [150.0, 200.0],
    ...                    alpha0_deg=[65.0, 70.0, 75.0], chunk_cases=2, command=["demo"])
    ...     ds = xr.open_zarr(p)
    ...     print(dict(ds.sizes), ds["free_angle_deg"].chunks, ds["free_angle_deg"].round(1).values.tolist())
    {'alpha0_deg': 3, 'pressure_kpa': 2} ((2, 1), (2,)) [[50.1, 77.8], [68.7, 114.2], [80.2, 137.1]]
    """
    chunk = default_chunk_cases(np.size(pressure_kpa)) if chunk_cases is None else chunk_cases
    plan = plan_sweep(base_actuator, pressure_kpa, model, chunk_cases=chunk, order=order, eq19_factor=eq19_factor,
                      **params)
    remote = bool(scheduler or workers)
    if scheduler is not None:
        from bendpam.infra.scheduler import parse_scheduler_address

        scheduler = parse_scheduler_address(scheduler)
    _check_memory(plan, chunk, remote, max_memory_gib)
    _need_zarr()
    with OutputSet(target, inputs=inputs, command=command, force=force, producer=producer,
                   resume_key=sweep_fingerprint(plan)) as out:
        marks = out.resume_dir / "blocks"
        done = _done_blocks(marks, plan.n_blocks) if out.resumed and (out.resume_dir / "template").is_file() else set()
        if not done and not (out.resume_dir / "template").is_file():
            _write_template(plan, out.staging, out.resume_dir)
        writer = _Writer(plan, out.staging, marks, progress)
        if progress is not None and done:
            progress(sum(writer.cases(b) for b in done))
        todo = [b for b in range(plan.n_blocks) if b not in done]
        if remote:
            _run_cluster(plan, todo, writer, scheduler, workers, scheduler_timeout_s)
        else:
            _run_local(plan, todo, writer)
    return out.target


def _check_memory(plan: SweepPlan, chunk_cases: int, remote: bool, max_memory_gib: float | None) -> None:
    if max_memory_gib is not None and not (isinstance(max_memory_gib, int | float) and max_memory_gib > 0):
        raise InputError(f"max_memory_gib = {max_memory_gib!r} must be a number of GiB > 0 (or None)")
    n_cases = int(np.prod(plan.shape)) if plan.shape else 1
    est = sweep_estimate(n_cases, plan.pressure_kpa.size, len(plan.shape), chunk_cases=chunk_cases, compute=False,
                         remote=remote)
    problem = memory_problem(est.memory_bytes, max_memory_gib)
    if problem is not None:
        raise InputError(f"a streamed sweep in blocks of {min(chunk_cases, n_cases)} cases x "
                         f"{plan.pressure_kpa.size} pressures would hold {problem}; give a smaller chunk_cases "
                         "or raise max_memory_gib")


def _need_zarr() -> None:
    try:
        import dask.array  # noqa: F401
        import zarr  # noqa: F401
    except ImportError:
        raise InputError('streamed sweeps need zarr and dask: pip install "bendpam[zarr]"') from None


def _done_blocks(marks: Path, n_blocks: int) -> set[int]:
    """The blocks whose marker file an interrupted run left (each written whole before it was marked)."""
    try:
        return {int(p.name) for p in marks.iterdir() if p.name.isdigit() and int(p.name) < n_blocks}
    except FileNotFoundError:
        return set()


def _write_template(plan: SweepPlan, store: Path, state: Path) -> None:
    """Write the store's metadata and coordinates (no data chunk), then mark it written."""
    import dask.array as da

    for p in store.iterdir():  # what a run killed while writing the template left
        if p.name != state.name:
            with contextlib.suppress(FileNotFoundError):
                if p.is_dir():
                    import shutil

                    shutil.rmtree(p)
                else:
                    p.unlink()
    n_out = len(plan.outputs)
    data = da.zeros((*(plan.shape or (1,)), plan.pressure_kpa.size, n_out),
                    chunks=(*(plan.chunks or ((1,),)), (plan.pressure_kpa.size,), (n_out,)))
    ds = plan.dataset(data)
    ds.attrs.update(bendpam_layout=STORE_LAYOUT, bendpam_version=__version__, blocks=plan.n_blocks,
                    block_cases=list(plan.block_shape),
                    chunking="one chunk per block: block_cases along the swept parameters, every pressure")
    for v in ds.data_vars.values():
        v.encoding["_FillValue"] = None if v.dtype == np.int8 else np.nan  # every chunk is written
    with _quiet_zarr():
        ds.to_zarr(store, mode="a", compute=False, zarr_format=2, consolidated=True)
    (state / "blocks").mkdir(exist_ok=True)
    for dirpath, _, files in os.walk(store):
        for f in files:
            fsync_file(Path(dirpath) / f)
        fsync_dir(Path(dirpath))
    (state / "template").touch()


@contextlib.contextmanager
def _quiet_zarr() -> Any:
    """Zarr warns of the staging folder's own state (``.bendpam-resume``), which is no part of the store."""
    import warnings

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*bendpam-resume is not recognized")
        yield


class _Writer:
    """Writes a computed block into its chunks, then its marker file; reports its cases."""

    def __init__(self, plan: SweepPlan, store: Path, marks: Path, progress: Callable[[int], Any] | None) -> None:
        import zarr

        self.plan, self.marks, self.progress, self.store = plan, marks, progress, store
        with _quiet_zarr():
            group = zarr.open_group(str(store), mode="r+", zarr_format=2)
        self.arrays: dict[str, Any] = {name: group[name] for name in plan.outputs}

    def _flush(self, region: tuple[slice, ...]) -> None:
        """Flush the block's chunks to disk before its marker is made (a marker never outlives its data)."""
        at = [str(s.start // n) for s, n in zip(region, self.plan.block_shape, strict=True)]
        for name in self.plan.outputs:
            key = ".".join(at if name in _PER_CASE else [*at, "0"]) or "0"
            chunk = self.store / name / key
            if chunk.exists():  # (a chunk all NaN is not written: it reads back as NaN)
                fsync_file(chunk)
            fsync_dir(chunk.parent)

    def cases(self, block: int) -> int:
        return int(np.prod([s.stop - s.start for s in self.plan.region(block)]))

    def __call__(self, block: int, res: np.ndarray) -> None:
        region = self.plan.region(block)
        squeeze = not self.plan.shape  # no swept parameter: the one dummy case is dropped
        for i, name in enumerate(self.plan.outputs):
            v = res[..., 0, i] if name in _PER_CASE else res[..., i]
            if squeeze:
                v = v[0]
            if name == "branch_end":
                v = v.astype(np.int8)
            where: Any = (*region, Ellipsis) if region else Ellipsis
            self.arrays[name][where] = v
        self._flush(region)
        fd = os.open(self.marks / str(block), os.O_CREAT | os.O_WRONLY, 0o644)
        os.close(fd)
        if self.progress is not None:
            self.progress(self.cases(block))


def _run_local(plan: SweepPlan, todo: list[int], write: _Writer) -> None:
    """The blocks on a pool of threads, at most two a thread in flight, written here as they finish."""
    from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait

    threads = max(1, min(os.cpu_count() or 1, len(todo)))
    pending: dict[Future[np.ndarray], int] = {}
    queue = iter(todo)
    pool = ThreadPoolExecutor(threads, thread_name_prefix="bendpam-sweep")
    try:
        while True:
            while len(pending) < 2 * threads and (b := next(queue, None)) is not None:
                pending[pool.submit(plan.compute, b)] = b
            if not pending:
                return
            finished, _ = wait(pending, return_when=FIRST_COMPLETED)
            for f in sorted(finished, key=pending.__getitem__):
                write(pending.pop(f), f.result())
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _worker_version() -> str:
    """The bendpam version a Dask worker imports."""
    from bendpam.version import __version__ as version

    return version


def _compute_block(plan: SweepPlan, block: int) -> np.ndarray:
    """One block, on a Dask worker."""
    return plan.compute(block)


def _run_cluster(plan: SweepPlan, todo: list[int], write: _Writer, scheduler: str | None, workers: int | None,
                 timeout_s: float) -> None:
    """The blocks on Dask workers, sent back and written here; at most two a worker thread in flight."""
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError:
        raise InputError("sweeps on a Dask cluster need distributed: pip install 'bendpam[distributed]'") from None
    with contextlib.ExitStack() as stack:
        if scheduler:
            from bendpam.infra.scheduler import probe_scheduler

            probe_scheduler(scheduler, timeout_s)  # Dask's client would wait without end for a silent server
            client = stack.enter_context(Client(scheduler, timeout=timeout_s))
        else:
            cluster = stack.enter_context(LocalCluster(n_workers=int(workers or 1), threads_per_worker=1,
                                                       processes=True, host="127.0.0.1", dashboard_address=None))
            client = stack.enter_context(Client(cluster))
        other = sorted({str(v) for v in client.run(_worker_version).values()} - {__version__})
        if other:  # the store records this version; blocks of another would not be the same numbers
            raise InputError(f"the Dask workers run bendpam {', '.join(other)}, this process {__version__}; "
                             "install the same version on every worker")
        window = 2 * max(1, sum(client.nthreads().values()))
        shared = client.scatter(plan, broadcast=True)
        queue = iter(todo)

        tag = os.urandom(4).hex()
        live: dict[str, tuple[int, Any]] = {}  # key -> (block, future)

        def submit(b: int) -> Any:
            f = client.submit(_compute_block, shared, b, key=f"bendpam-sweep-{tag}-{b}", pure=False)
            live[f.key] = (b, f)
            return f

        running = as_completed([submit(b) for _, b in zip(range(window), queue, strict=False)])
        try:
            for f in running:
                write(live.pop(f.key)[0], f.result())
                f.release()
                if (nxt := next(queue, None)) is not None:
                    running.add(submit(nxt))
        finally:
            if live:
                client.cancel([f for _, f in live.values()])
