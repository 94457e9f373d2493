"""Design sweeps (the module behind :func:`bendpam.sweep`): actuator parameters crossed with pressures.

In-process or on a Dask cluster.

``bendpam.sweep(base, pressure_kpa=[...], alpha0_deg=[...], t0_mm=[...])`` evaluates every
combination of the swept parameters (an "actuator case") at every pressure and returns an
:class:`xarray.Dataset` with dimensions ``(param_1, ..., param_n, pressure_kpa)``:

* ``blocked_moment_nmm`` (case, pressure): M(P, 0), signed as in the paper's convention;
* ``free_curvature_per_mm`` and ``free_angle_deg`` (case, pressure): the free-bending equilibrium
  on the branch connected to the straight state, NaN where there is none;
* ``max_pressure_kpa`` (case): the highest pressure with a free-bending equilibrium (the fold or
  lock-up pressure; ``inf`` if unbounded) and ``branch_end`` (0 lock-up, 1 fold, 2 unbounded,
  3 neutral);
* the structural limits of :mod:`bendpam.physics.limits` (case, pressure), each the worse of the blocked and
  free-bending states: ``frame_axial_force_n``, ``frame_stress_mpa`` (largest combined axial and
  bending stress), and the safety factors (capacity / demand, >= 1 within the limit, inf without
  demand or limit) ``frame_strength_margin``, ``buckling_margin`` (frame on the bladder as an
  elastic foundation), ``lockup_margin`` (end of the free-bending branch over ``|k'_free|``; past
  it ``P_a,end / P_a``), ``bladder_stretch_max`` with ``bladder_stretch_margin``, and
  ``min_margin``.  The strength and stretch limits are the base actuator's.

How it is computed
    The kernel evaluates a whole block of cases at once: the braid kinematics and both models
    accept per-case parameter arrays, so the lock-up limits (vectorised bisection), the
    free-bending branch of every case (the same sampling and fold refinement as
    :func:`bendpam.branch_info`, vectorised: a grid search around the sampled maximum) and the
    roots at every pressure (all pressures of all cases at once: each root's bracket and a cubic
    start from the sampled branch, then Newton's method, about 2.4 evaluations of the law a point,
    :func:`bendpam.physics.branch.solve_free`) are array operations over the block, and the
    margins' section means are in closed form.  There is no Python loop over cases or pressures.

Scaling out
    Cases are split into blocks of at most ``chunk_cases``.  With Dask installed
    (``pip install bendpam[distributed]``) the result is a ``dask.array``-backed dataset built
    with ``map_blocks``; it runs on the threaded scheduler in-process by default, on a
    distributed cluster when ``scheduler`` (an address) is given, or on a ``LocalCluster`` of
    ``workers`` processes.  Each block is computed by the same deterministic function, so every
    way of running gives bit-for-bit the same numbers (tested).  Without Dask the same blocks
    are computed in a loop.  The working memory is bounded by the block size (``chunk_cases`` x
    pressures, about 2 kB a point); a computed result holds 104 bytes a point (twice while the
    blocks are assembled).  With ``compute=False`` the dataset stays lazy and ``to_netcdf`` writes
    it block by block.

Budgets
    Before any work, :func:`sweep_estimate` estimates the peak memory from measured costs; a
    sweep past ``max_memory_gib`` (2 GiB by default, :mod:`bendpam.infra.budgets`) or past this
    machine's memory is refused in one line.  A ``scheduler`` must answer as a Dask scheduler
    within ``scheduler_timeout_s`` (10 s by default, :mod:`bendpam.infra.scheduler`).

When only ``R0_mm`` is swept, ``R0_start_mm`` keeps the base actuator's ratio ``R0_start / R0``;
``t0_start`` always follows from eq 52.

Files and progress
    :func:`to_table` turns a sweep into a tidy long table (one row per case and pressure,
    unit-named columns); :func:`write_sweep` writes it atomically as NetCDF, CSV or Parquet
    (Parquet needs ``pip install "bendpam[parquet]"``).  ``progress`` reports each finished block
    (a :class:`bendpam.infra.progress.Progress` on stderr, or a callback), in-process and on a cluster.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from bendpam.errors import InputError
from bendpam.infra.budgets import MEMORY_BUDGET_GIB, MIB, SCHEDULER_TIMEOUT_S, format_bytes, memory_problem
from bendpam.physics.actuator import Actuator, ModelParams
from bendpam.physics.braid import DEFAULT_ORDER
from bendpam.physics.law import MomentLaw
from bendpam.physics.limits import OUTPUTS as _LIMIT_OUTPUTS
from bendpam.physics.limits import case_limits
from bendpam.physics.models import resolve_model
from bendpam.validate import instance, plausible
from bendpam.validate import pressure_kpa as check_pressure

__all__ = ["SWEEP_FORMATS", "SWEEP_PARAMETERS", "SweepEstimate", "SweepPlan", "build_cases", "evaluate_cases",
           "plan_sweep", "sweep", "sweep_estimate", "sweep_format", "to_table", "write_sweep"]

#: Parameters that can be swept (Actuator field names; units in the names).
SWEEP_PARAMETERS = (
    "alpha0_deg", "R0_mm", "t0_mm", "L0_mm", "frame_thickness_mm", "frame_width_mm", "frame_modulus_mpa",
    "C10_kpa", "C01_kpa", "P_start_kpa", "R0_start_mm",
)
_BRANCH_SAMPLES = 150  # the shared-table path makes a sample cheap; folds are refined, roots polished
_OUTPUTS = ("blocked_moment_nmm", "free_curvature_per_mm", "free_angle_deg", "lockup_margin", "frame_stress_mpa",
            "frame_axial_force_n", "frame_strength_margin", "buckling_margin", "bladder_stretch_max",
            "bladder_stretch_margin", "min_margin", "max_pressure_kpa", "branch_end")
_UNITS = {
    "blocked_moment_nmm": ("N*mm", "blocked moment M(P, 0)"),
    "free_curvature_per_mm": ("1/mm", "free-bending frame curvature k' (NaN: no equilibrium on the branch)"),
    "free_angle_deg": ("deg", "free-bending angle k' L0"),
    **_LIMIT_OUTPUTS,  # frame force and stress, the margins (bendpam.physics.limits)
    "max_pressure_kpa": ("kPa", "highest pressure with a free-bending equilibrium (fold or lock-up)"),
    "branch_end": ("1", "end of the free-bending branch: 0 lock-up, 1 fold, 2 unbounded, 3 neutral"),
}


# ------------------------------------------------------------------------------------------------
# costs: what a sweep takes in memory and time (docs/budgets.md); the budgets are in infra/budgets.py
# ------------------------------------------------------------------------------------------------
#: Measured costs (one core of a 2-core x86-64 machine, 2026), rounded up about twice for slower machines.
SECONDS_PER_CASE = 3e-4    # the free-bending branch of a case: measured 0.12-0.13 ms
SECONDS_PER_POINT = 1e-5   # roots and limits per (case, pressure), assembling, NetCDF: measured 4-8 us
TABLE_SECONDS_PER_POINT = {"csv": 2e-5, "parquet": 2e-6}  # a tidy table row written: measured 10 and 1 us
WORK_BYTES_PER_POINT = 2048  # working arrays of a block being computed: measured 1.5-2 kB per point
WORK_BYTES_PER_CASE = 40_000  # and 34 kB per case
BASE_BYTES = 512 * MIB  # the process itself (Python, NumPy, xarray, Dask, pyarrow): measured 200-400 MB
#: The outputs of a point, as float64.
RESULT_BYTES_PER_POINT = 8 * len(_OUTPUTS)


@dataclass(frozen=True)
class SweepEstimate:
    """A sweep's size and a conservative estimate of its peak memory and run time (:func:`sweep_estimate`).

    >>> est = SweepEstimate(cases=100, points=1600, memory_bytes=600e6, seconds=0.05)
    >>> est.memory_text, est.time_text
    ('572 MiB', '0.05 s')
    """

    cases: int
    points: int
    memory_bytes: float
    seconds: float

    @property
    def memory_text(self) -> str:
        return format_bytes(self.memory_bytes)

    @property
    def time_text(self) -> str:
        s = self.seconds
        return f"{s:.2g} s" if s < 60 else f"{s / 60:.3g} min" if s < 3600 else f"{s / 3600:.3g} h"


def sweep_estimate(n_cases: int, n_pressures: int, n_params: int = 1, *, chunk_cases: int = 256,
                   table: str | None = None, compute: bool = True, remote: bool = False) -> SweepEstimate:
    """Peak memory and run time of a sweep, estimated before any work from the measured costs above.

    Memory: the process (``BASE_BYTES``), the blocks being computed (one per core in-process,
    ``WORK_BYTES_PER_POINT`` and ``WORK_BYTES_PER_CASE`` each; none here with ``remote``) and,
    with ``compute``, the result: its outputs (``8 x 13`` bytes a point) held twice while the
    blocks are assembled, plus a tidy table row when ``table`` ("csv" or "parquet") is written.
    Time: ``SECONDS_PER_CASE`` a case and ``SECONDS_PER_POINT`` a point (plus the table's), on
    one core (more cores and a cluster make it shorter).

    Examples
    --------
    >>> est = sweep_estimate(10_000, 100, table="csv", remote=True)        # one million points
    >>> est.points, est.memory_text, est.time_text
    (1000000, '840 MiB', '33 s')
    """
    n_cases, n_pressures = int(n_cases), int(n_pressures)
    points = n_cases * n_pressures
    block_cases = max(1, min(int(chunk_cases), n_cases))
    in_flight = 0 if remote else min(os.cpu_count() or 1, -(-n_cases // block_cases))
    work = in_flight * block_cases * (n_pressures * WORK_BYTES_PER_POINT + WORK_BYTES_PER_CASE)
    per_point = 0.0
    if compute:
        per_point = 2 * RESULT_BYTES_PER_POINT + (8 * (2 * (n_params + 1) + len(_OUTPUTS)) if table else 0)
    seconds = n_cases * SECONDS_PER_CASE + points * (SECONDS_PER_POINT + TABLE_SECONDS_PER_POINT.get(table or "", 0))
    return SweepEstimate(cases=n_cases, points=points, memory_bytes=BASE_BYTES + work + points * per_point,
                         seconds=seconds)


def build_cases(base: Actuator, values: dict[str, np.ndarray]) -> ModelParams:
    """Actuator cases from the base actuator with ``values`` (Actuator field names -> arrays of one shape).

    Every value is validated as :class:`~bendpam.Actuator` would (one line naming the parameter
    and the allowed range).  When ``R0_mm`` is swept without ``R0_start_mm``, ``R0_start_mm``
    keeps the base ratio ``R0_start / R0``; eq 51-52 are applied by :meth:`ModelParams.build`.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> cases = build_cases(bendpam.physics.presets.be_pam(), {"alpha0_deg": np.array([65.0, 70.0])})
    >>> cases.shape, np.degrees(cases.alpha0).round(1).tolist()
    ((2,), [65.0, 70.0])
    >>> build_cases(bendpam.physics.presets.be_pam(), {"t0_mm": np.array([2.0, 9.0])})
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: t0_mm = 9 mm is outside the allowed range (0, R0_mm) mm
    """
    n = np.broadcast_shapes(*(np.shape(v) for v in values.values())) if values else ()
    get = {f: np.broadcast_to(np.asarray(values.get(f, getattr(base, f)), dtype=float), n)
           for f in SWEEP_PARAMETERS if f != "R0_start_mm"}
    if "R0_start_mm" in values:
        R0s = np.broadcast_to(np.asarray(values["R0_start_mm"], dtype=float), n)
    else:
        R0s = get["R0_mm"] * (float(base.params.R0_start) / base.R0_mm)
    _validate(get, R0s, base.max_pressure_kpa)
    return ModelParams.build(R0_start_mm=np.array(R0s, dtype=float), braid_thickness_mm=base.braid_thickness_mm,
                             max_pressure_kpa=base.max_pressure_kpa,
                             **{k: np.array(v, dtype=float) for k, v in get.items()})


def _validate(get: dict[str, np.ndarray], R0s: np.ndarray, max_pressure_kpa: float) -> None:
    """The Actuator's range checks, vectorised: the first bad value is reported with its parameter."""
    def bad(name, mask, rng, unit):
        if np.any(mask):
            v = np.asarray(get[name] if name in get else R0s)[mask].ravel()[0]
            raise InputError(f"{name} = {v:g} {unit} is outside the allowed range {rng} {unit}")

    bad("alpha0_deg", (get["alpha0_deg"] <= 0) | (get["alpha0_deg"] >= 90), "(0, 90)", "deg")
    for name in ("R0_mm", "L0_mm", "frame_thickness_mm", "frame_width_mm"):
        bad(name, get[name] <= 0, "(0, inf)", "mm")
    bad("frame_modulus_mpa", get["frame_modulus_mpa"] <= 0, "(0, inf)", "MPa")
    bad("t0_mm", (get["t0_mm"] <= 0) | (get["t0_mm"] >= get["R0_mm"]), "(0, R0_mm)", "mm")
    bad("P_start_kpa", get["P_start_kpa"] < 0, "[0, inf)", "kPa")
    if np.any(R0s < get["R0_mm"]):
        v = np.asarray(R0s)[R0s < get["R0_mm"]].ravel()[0]
        raise InputError(f"R0_start_mm = {v:g} mm is outside the allowed range [R0_mm, inf) mm")
    mu = get["C10_kpa"] + get["C01_kpa"]
    if np.any(mu <= 0):
        i = np.flatnonzero(np.broadcast_to(mu, np.shape(mu)).ravel() <= 0)[0]
        c10 = np.broadcast_to(get["C10_kpa"], np.shape(mu)).ravel()[i]
        c01 = np.broadcast_to(get["C01_kpa"], np.shape(mu)).ravel()[i]
        raise InputError(f"C10_kpa + C01_kpa = {c10 + c01:g} kPa must be > 0 (C10_kpa = {c10:g}, C01_kpa = {c01:g})")
    values = {**get, "R0_start_mm": R0s, "max_pressure_kpa": max_pressure_kpa}
    for name in values:  # the physical plausibility of every case (docs/plausibility.md)
        if name != "max_pressure_kpa":
            plausible(name, values[name], values)


def evaluate_cases(base: Actuator, model: str, values: dict[str, np.ndarray], pressure_kpa, *,
                   order: int = DEFAULT_ORDER, eq19_factor: bool = True) -> dict[str, np.ndarray]:
    """The sweep kernel: all outputs for the cases in ``values`` (1-D arrays) at ``pressure_kpa``.

    Returns arrays of shape (cases, pressures) and (cases,) keyed by the names in the module doc.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> out = evaluate_cases(bendpam.physics.presets.be_pam(), "energy", {"alpha0_deg": np.array([65.0, 70.0])},
    ...                      np.array([150.0, 200.0]))
    >>> out["free_angle_deg"].round(1).tolist(), out["branch_end"].tolist()
    ([[50.1, 77.8], [68.7, 114.2]], [2.0, 2.0])
    """
    cs = build_cases(base, values)
    law = MomentLaw(cs, model, eq19_factor=eq19_factor, order=order)
    P = np.asarray(pressure_kpa, dtype=float)
    pa = np.maximum(P[None, :] - np.asarray(law.P_start_kpa)[:, None], 0.0)
    A0, _ = law.coefficients(np.zeros(cs.shape))
    tab = law.branches(_BRANCH_SAMPLES)
    k, u = law.free_state_array(P, table=tab)
    lim = case_limits(law, P, k, tab, free_u=u, frame_strength_mpa=base.frame_strength_mpa,
                      bladder_stretch_limit=base.bladder_stretch_limit)
    return {
        "blocked_moment_nmm": pa * A0[:, None],
        "free_curvature_per_mm": k,
        "free_angle_deg": np.degrees(k * cs.L0[:, None]),
        **{name: lim[name] for name in _LIMIT_OUTPUTS},
        "max_pressure_kpa": law.P_start_kpa + tab.p_end,
        "branch_end": tab.kind.astype(float),
    }


# ------------------------------------------------------------------------------------------------
# the sweep
# ------------------------------------------------------------------------------------------------
def _grid_values(params: dict) -> dict[str, np.ndarray]:
    out = {}
    for name, vals in params.items():
        if name not in SWEEP_PARAMETERS:
            raise InputError(f"cannot sweep {name!r}; choose from {', '.join(SWEEP_PARAMETERS)}")
        arr = np.atleast_1d(np.asarray(vals, dtype=float))
        if arr.ndim != 1 or arr.size == 0:
            raise InputError(f"sweep values of {name} must be a non-empty 1-D list")
        if not np.all(np.isfinite(arr)):
            raise InputError(f"sweep values of {name} must be finite")
        out[name] = arr
    return out


def _block(base, model, names, grids, P, order, eq19, idx_block):
    """Kernel for one block of flat case indices (any shape B) -> array B + (pressures, outputs)."""
    idx_block = np.asarray(idx_block)
    shape = tuple(g.size for g in grids)
    flat = idx_block.ravel()
    if names:
        sub = np.unravel_index(flat, shape)
        values = {n: g[i] for n, g, i in zip(names, grids, sub, strict=True)}
    else:
        values = {"alpha0_deg": np.full(flat.size, base.alpha0_deg)}
    res = evaluate_cases(base, model, values, P, order=order, eq19_factor=eq19)
    out = np.empty((flat.size, P.size, len(_OUTPUTS)))
    for i, name in enumerate(_OUTPUTS):
        v = res[name]
        out[:, :, i] = v if v.ndim == 2 else v[:, None]
    return out.reshape((*idx_block.shape, P.size, len(_OUTPUTS)))


def sweep(base_actuator: Actuator, pressure_kpa, model: str | None = None, *, chunk_cases: int = 256,
          scheduler: str | None = None, workers: int | None = None, compute: bool = True,
          progress: bool | Callable[[int], Any] | None = None, order: int = DEFAULT_ORDER, eq19_factor: bool = True,
          max_memory_gib: float | None = MEMORY_BUDGET_GIB, scheduler_timeout_s: float = SCHEDULER_TIMEOUT_S,
          **params) -> Any:
    """Sweep actuator parameters crossed with pressures.  See the module docstring.

    Parameters
    ----------
    base_actuator : the actuator whose other parameters are kept.
    pressure_kpa : 1-D pressures (kPa).
    model : ``"energy"``, ``"force_balance"`` or None (default): the base actuator's own model (energy
        when unknown); another than the actuator's warns (:class:`~bendpam.errors.ModelMismatchWarning`).
    chunk_cases : cases per block (memory bound).
    scheduler : address of a Dask distributed scheduler (e.g. ``"tcp://127.0.0.1:8786"``).
    workers : start a ``LocalCluster`` with this many worker processes (loopback only).
    compute : return computed (NumPy-backed) data; ``False`` keeps a lazy Dask-backed dataset.
    progress : ``True``: report progress on stderr with :class:`bendpam.infra.progress.Progress` (a bar
        on a terminal, periodic lines otherwise); a callable: called as ``progress(n)`` with the
        number of cases of each block when it is done (from worker threads on the Dask
        threaded scheduler, so it must be thread-safe; ``Progress.advance`` is); ``False``: no
        report; ``None`` (default): a bar for sweeps of at least 20 blocks when stderr is a
        terminal.  Ignored with ``compute=False``.
    max_memory_gib : the memory budget (GiB, default :data:`~bendpam.infra.budgets.MEMORY_BUDGET_GIB`;
        None: only this machine's memory): a sweep whose estimated peak (:func:`sweep_estimate`) is
        larger is refused before any work.  ``compute=False`` keeps only the blocks in memory.
    scheduler_timeout_s : how long the scheduler has to answer as a Dask scheduler before it is refused.
    **params : Actuator field names with 1-D values, e.g. ``alpha0_deg=np.linspace(60, 80, 41)``.

    Examples
    --------
    >>> import bendpam
    >>> ds = bendpam.sweep(bendpam.physics.presets.be_pam(), pressure_kpa=[150.0, 200.0], alpha0_deg=[65.0, 70.0, 75.0])
    >>> list(ds.dims), ds["blocked_moment_nmm"].attrs["units"]
    (['alpha0_deg', 'pressure_kpa'], 'N*mm')
    >>> ds["free_angle_deg"].round(1).values.tolist()      # rows: braid angle, columns: pressure
    [[50.1, 77.8], [68.7, 114.2], [80.2, 137.1]]
    """
    model, P, names, grids = _arguments(base_actuator, pressure_kpa, model, params)
    shape = tuple(g.size for g in grids)
    chunk_cases = int(chunk_cases)
    if chunk_cases < 1:
        raise InputError(f"chunk_cases = {chunk_cases} must be >= 1")
    if scheduler is not None:
        from bendpam.infra.scheduler import parse_scheduler_address

        scheduler = parse_scheduler_address(scheduler)
    _check_memory(shape, P.size, chunk_cases, compute, bool(scheduler or workers), max_memory_gib)
    # validate before any work (the same checks as Actuator): every combination of the
    # parameters that constrain each other, each other parameter on its own
    _prevalidate(base_actuator, names, grids)
    chunks = _natural_chunks(shape, chunk_cases)
    fn = _block_fn(base_actuator, model, names, grids, P, order, eq19_factor)
    data = _run_blocks(fn, shape, chunks, P.size, scheduler=scheduler, workers=workers, compute=compute,
                       progress=progress, timeout_s=scheduler_timeout_s)
    return _dataset(data, names, grids, shape, P, base_actuator, model, order)


def _check_memory(shape: tuple[int, ...], n_pressures: int, chunk_cases: int, compute: bool, remote: bool,
                  max_memory_gib: float | None) -> None:
    """Refuse, before any work, a sweep whose estimated peak memory is past the budget or the machine's memory."""
    if max_memory_gib is not None and not (isinstance(max_memory_gib, int | float) and max_memory_gib > 0):
        raise InputError(f"max_memory_gib = {max_memory_gib!r} must be a number of GiB > 0 (or None)")
    n_cases = int(np.prod(shape)) if shape else 1
    est = sweep_estimate(n_cases, n_pressures, len(shape), chunk_cases=chunk_cases, compute=compute, remote=remote)
    problem = memory_problem(est.memory_bytes, max_memory_gib)
    if problem is not None:
        raise InputError(f"a sweep of {est.points} (case, pressure) points would hold {problem}; give fewer values"
                         + (", keep it lazy (compute=False: to_netcdf then writes it block by block)" if compute
                            else ", or a smaller chunk_cases") + ", or raise max_memory_gib")


def _run_blocks(fn, shape: tuple[int, ...], chunks, n_pressures: int, *, scheduler: str | None, workers: int | None,
                compute: bool, progress: bool | Callable[[int], Any] | None, timeout_s: float = SCHEDULER_TIMEOUT_S
                ) -> Any:
    """The sweep's data (cases..., pressures, outputs): the blocks of ``fn`` in a loop without Dask, else a
    dask array, computed in-process or on a cluster, or left lazy; progress as :func:`sweep` describes."""
    n_cases = int(np.prod(shape)) if shape else 1
    n_blocks = int(np.prod([len(c) for c in chunks])) if shape else 1
    show = progress if progress is not None else (n_blocks >= 20 and sys.stderr.isatty())
    da: Any
    try:
        import dask.array as da
    except ImportError:
        da = None
    if da is None and (scheduler or workers or not compute):
        raise InputError("distributed or lazy sweeps need Dask: pip install 'bendpam[distributed]'")
    with contextlib.ExitStack() as stack:
        report: Callable[[int], Any] | None
        if callable(show):
            report = show
        elif show and compute:
            from bendpam.infra.progress import Progress

            report = stack.enter_context(Progress(n_cases, "sweep")).advance
        else:
            report = None
        remote = bool(scheduler or workers)
        if da is None:
            return _loop_blocks(_Counted(fn, report), shape, chunks)
        idx = da.arange(n_cases, chunks=n_cases).reshape(shape or (1,)).rechunk(chunks or ((1,),))
        nd = idx.ndim
        # in-process the kernel reports each block itself; on a cluster the futures do
        kernel = fn if remote or not compute or report is None else _Counted(fn, report)
        arr = idx.map_blocks(kernel, dtype=float, new_axis=[nd, nd + 1],
                             chunks=(*idx.chunks, (n_pressures,), (len(_OUTPUTS),)), meta=np.empty((0,) * (nd + 2)))
        return _compute(arr, scheduler, workers, report, idx.chunks, timeout_s) if compute else arr


def _natural_chunks(shape: tuple[int, ...], chunk_cases: int) -> tuple[tuple[int, ...], ...]:
    """Block the case grid so that each block holds at most ``chunk_cases`` cases.

    Trailing dimensions are kept whole while they fit; the first dimension that does not fit is
    split, and the ones before it go one index at a time.
    """
    out = []
    prod = 1
    split = False
    for size in reversed(shape):
        if split:
            out.append((1,) * size)
            continue
        if prod * size <= chunk_cases:
            out.append((size,))
            prod *= size
        else:
            step = max(chunk_cases // prod, 1)
            out.append(tuple(min(step, size - i) for i in range(0, size, step)))
            split = True
    return tuple(reversed(out))


_COUPLED = ({"t0_mm", "R0_mm", "R0_start_mm"}, {"C10_kpa", "C01_kpa"})


def _arguments(base_actuator: Actuator, pressure_kpa, model: str | None, params: dict
               ) -> tuple[str, np.ndarray, list[str], list[np.ndarray]]:  # fmt: skip
    """The checked arguments of a sweep: the model's plain name, the pressures (kPa), the swept names
    and their values; warns outside the actuator's tested range (:func:`sweep`, :func:`plan_sweep`)."""
    instance("base_actuator", base_actuator, Actuator, "a bendpam.Actuator")
    model = str(resolve_model(base_actuator, model))  # a plain name: it goes to workers and the attributes
    P = np.atleast_1d(check_pressure(pressure_kpa, limit_kpa=base_actuator.max_pressure_kpa))
    if P.ndim != 1 or P.size == 0:
        raise InputError("pressure_kpa must be a non-empty 1-D list of pressures >= 0 kPa")
    base_actuator.outside_tested(P)
    grids_d = _grid_values(params)
    names = list(grids_d)
    return model, P, names, [grids_d[n] for n in names]


def _prevalidate(base, names, grids) -> None:
    done = set()
    for group in _COUPLED:
        sel = [i for i, n in enumerate(names) if n in group]
        if sel:
            mesh = np.meshgrid(*(grids[i] for i in sel), indexing="ij", sparse=True)
            build_cases(base, {names[i]: m for i, m in zip(sel, mesh, strict=True)})
            done.update(sel)
    for i, n in enumerate(names):
        if i not in done:
            build_cases(base, {n: grids[i]})


class _block_fn:
    """Picklable block kernel (for distributed workers)."""

    def __init__(self, base, model, names, grids, P, order, eq19):
        self.args = (base, model, names, grids, P, order, eq19)

    def __call__(self, idx_block):
        return _block(*self.args, idx_block)


class _Counted:
    """The block kernel, reporting the number of cases of each finished block to ``report``."""

    def __init__(self, fn, report):
        self.fn, self.report = fn, report

    def __call__(self, idx_block):
        res = self.fn(idx_block)
        if self.report is not None:
            self.report(int(np.asarray(idx_block).size))
        return res


def _loop_blocks(fn, shape, chunks):
    """The same blocks as the Dask path, computed in a loop (no Dask installed)."""
    flat = np.arange(int(np.prod(shape)) if shape else 1).reshape(shape or (1,))
    bounds = [np.cumsum((0, *c)) for c in (chunks or ((1,),))]
    blocks = list(np.ndindex(*[len(c) for c in (chunks or ((1,),))]))
    out = None
    for b in blocks:
        sl = tuple(slice(bd[i], bd[i + 1]) for bd, i in zip(bounds, b, strict=True))
        res = fn(flat[sl])
        if out is None:
            out = np.empty(flat.shape + res.shape[-2:])
        out[sl] = res
    return out


def _block_cases(key, case_chunks) -> int:
    """Number of cases in the block of a Dask key ``(name, i, j, ..., 0, 0)``."""
    try:
        ids = key[1:1 + len(case_chunks)]
        return int(np.prod([case_chunks[d][i] for d, i in enumerate(ids)]))
    except (TypeError, IndexError):
        return 0


def _compute(arr, scheduler, workers, report, case_chunks, timeout_s=SCHEDULER_TIMEOUT_S):
    import dask

    if scheduler or workers:
        try:
            from distributed import Client, LocalCluster, as_completed, futures_of
        except ImportError:
            raise InputError("distributed sweeps need distributed: pip install 'bendpam[distributed]'") from None

        if scheduler:
            from bendpam.infra.scheduler import probe_scheduler

            probe_scheduler(scheduler, timeout_s)  # Dask's client would wait without end for a silent server
            client = Client(scheduler, timeout=timeout_s)
            cluster = None
        else:
            cluster = LocalCluster(n_workers=int(workers), threads_per_worker=1, processes=True,
                                   host="127.0.0.1", dashboard_address=None)
            client = Client(cluster)
        try:
            if report is None:
                return client.compute(arr).result()
            persisted = client.persist(arr)  # the blocks as futures, reported as they finish
            for done in as_completed(futures_of(persisted)):
                report(_block_cases(done.key, case_chunks))
            return client.compute(persisted).result()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    return dask.compute(arr, scheduler="threads")[0]


class SweepPlan:
    """A validated sweep cut into blocks of cases, each computed on its own (made by :func:`plan_sweep`).

    The blocks are those of :func:`sweep` (the same ``chunk_cases`` gives the same blocks and
    bit-for-bit the same numbers); they are numbered in C order over the grid of blocks.
    :meth:`compute` is picklable with the plan, so a block can run on a Dask worker.

    Examples
    --------
    >>> import bendpam
    >>> plan = plan_sweep(bendpam.physics.presets.be_pam(), [150.0, 200.0], alpha0_deg=[65, 70, 75], chunk_cases=2)
    >>> plan.shape, plan.n_blocks, plan.region(1), plan.compute(1).shape     # (cases, pressures, outputs)
    ((3,), 2, (slice(2, 3, None),), (1, 2, 13))
    """

    #: The outputs in the order of the last axis of :meth:`compute`.
    outputs = _OUTPUTS

    def __init__(self, base: Actuator, model: str, names: list[str], grids: list[np.ndarray], P: np.ndarray,
                 chunks: tuple[tuple[int, ...], ...], order: int, eq19_factor: bool) -> None:
        self.base, self.model, self.names, self.grids = base, model, list(names), list(grids)
        self.pressure_kpa, self.chunks, self.order, self.eq19_factor = P, chunks, int(order), bool(eq19_factor)
        self.shape: tuple[int, ...] = tuple(g.size for g in self.grids)
        self._bounds = [np.cumsum((0, *c)) for c in chunks]
        self._grid = tuple(len(c) for c in chunks)

    @property
    def n_blocks(self) -> int:
        """The number of blocks."""
        return int(np.prod(self._grid)) if self._grid else 1

    @property
    def block_shape(self) -> tuple[int, ...]:
        """The cases of the first (largest) block along each swept parameter."""
        return tuple(c[0] for c in self.chunks)

    def region(self, block: int) -> tuple[slice, ...]:
        """The slices of the case grid that block ``block`` covers (empty without a swept parameter)."""
        if not self._grid:
            return ()
        at = np.unravel_index(int(block), self._grid)
        return tuple(slice(int(bd[i]), int(bd[i + 1])) for bd, i in zip(self._bounds, at, strict=True))

    def compute(self, block: int) -> np.ndarray:
        """All outputs of block ``block``: an array of its cases' shape + (pressures, outputs)."""
        flat = np.arange(int(np.prod(self.shape)) if self.shape else 1).reshape(self.shape or (1,))
        idx = flat[self.region(block)] if self.shape else flat
        return _block(self.base, self.model, self.names, self.grids, self.pressure_kpa, self.order,
                      self.eq19_factor, idx)

    def dataset(self, data) -> Any:
        """The sweep's :class:`xarray.Dataset` over ``data`` (cases + (pressures, outputs)), as :func:`sweep` gives."""
        return _dataset(data, self.names, self.grids, self.shape, self.pressure_kpa, self.base, self.model, self.order)


def plan_sweep(base_actuator: Actuator, pressure_kpa, model: str | None = None, *, chunk_cases: int = 256,
               order: int = DEFAULT_ORDER, eq19_factor: bool = True, **params) -> SweepPlan:
    """Validate a sweep as :func:`sweep` does and cut it into blocks, without computing anything.

    The arguments are those of :func:`sweep`; every refusal is the same one line.  A streamed
    sweep (:func:`bendpam.sweep_store.sweep_zarr`) computes and writes the blocks one by one.

    Examples
    --------
    >>> import bendpam
    >>> plan = plan_sweep(bendpam.physics.presets.be_pam(), [150.0], alpha0_deg=[65, 70], t0_mm=[2.0, 2.5, 3.0],
    ...                   chunk_cases=4)
    >>> plan.names, plan.shape, plan.chunks, plan.n_blocks
    (['alpha0_deg', 't0_mm'], (2, 3), ((1, 1), (3,)), 2)
    """
    model, P, names, grids = _arguments(base_actuator, pressure_kpa, model, params)
    chunk_cases = int(chunk_cases)
    if chunk_cases < 1:
        raise InputError(f"chunk_cases = {chunk_cases} must be >= 1")
    _prevalidate(base_actuator, names, grids)
    chunks = _natural_chunks(tuple(g.size for g in grids), chunk_cases)
    return SweepPlan(base_actuator, model, names, grids, P, chunks, order, eq19_factor)


_UNIT_OF_SUFFIX = {"kpa": "kPa", "mpa": "MPa", "mm": "mm", "deg": "deg"}


def _dataset(data, names, grids, shape, P, base, model, order) -> Any:
    import xarray as xr

    dims = [*names, "pressure_kpa"]
    vars_ = {}
    for i, name in enumerate(_OUTPUTS):
        if name in ("max_pressure_kpa", "branch_end"):
            v = data[..., 0, i]
            d = names
        else:
            v = data[..., i]
            d = dims
        if not shape:  # no swept parameter: drop the dummy case axis
            v = v[0]
        if name == "branch_end":
            v = v.astype(np.int8)
        unit, long_name = _UNITS[name]
        vars_[name] = (d, v, {"units": unit, "long_name": long_name})  # Variables: no alignment to do
    coords = {n: (n, g, {"units": _UNIT_OF_SUFFIX.get(n.rsplit("_", 1)[-1], n.rsplit("_", 1)[-1])})
              for n, g in zip(names, grids, strict=True)}
    coords["pressure_kpa"] = ("pressure_kpa", P, {"units": "kPa"})
    ds = xr.Dataset(vars_, coords=coords)
    ds.attrs.update(model=model, base_actuator=base.to_toml(), quadrature_order=int(order),
                    branch_end_meanings="0 lock-up, 1 fold, 2 unbounded, 3 neutral",
                    sign_convention="k' > 0 toward the frame; BC-PAM values are negative")
    return ds


# ------------------------------------------------------------------------------------------------
# tables and files
# ------------------------------------------------------------------------------------------------
#: The file formats :func:`write_sweep` writes (NetCDF, a tidy CSV table, a tidy Parquet table).
SWEEP_FORMATS = ("nc", "csv", "parquet")
_SWEEP_SUFFIXES = {".nc": "nc", ".csv": "csv", ".parquet": "parquet", ".pq": "parquet"}


def to_table(ds) -> Any:
    """A sweep dataset as a tidy long table: one row per (case, pressure), a column per quantity.

    The columns are the swept parameters (one per dimension, e.g. ``alpha0_deg``), then
    ``pressure_kpa``, then every output under its own unit-named name (``blocked_moment_nmm``,
    ``free_angle_deg``, ...); per-case outputs (``max_pressure_kpa``, ``branch_end``) repeat on
    every pressure of their case.  Rows run through the cases in C order, pressures innermost.

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`sweep` (computed or lazy; a lazy one is computed here).

    Returns
    -------
    pandas.DataFrame
        With ``attrs["units"]`` (column -> unit) and the dataset's attributes in ``attrs``.

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.sweeps import sweep, to_table
    >>> ds = sweep(bendpam.physics.presets.get("be-pam"), [100, 200], alpha0_deg=[70, 72, 74])
    >>> t = to_table(ds)
    >>> t.shape[0], list(t.columns[:3])
    (6, ['alpha0_deg', 'pressure_kpa', 'blocked_moment_nmm'])
    """
    dims = [str(d) for d in ds.dims]
    if "pressure_kpa" in dims:  # pressures innermost
        dims = [d for d in dims if d != "pressure_kpa"] + ["pressure_kpa"]
    df = ds.to_dataframe(dim_order=dims).reset_index() if dims else ds.to_dataframe().reset_index(drop=True)
    df = df[[*dims, *[str(v) for v in ds.data_vars]]]
    units = {str(n): str(ds[n].attrs.get("units", "")) for n in (*dims, *ds.data_vars)}
    df.attrs = {k: v for k, v in ds.attrs.items() if isinstance(v, (str, int, float))} | {"units": units}
    return df


def sweep_format(path, format: str | None = None) -> str:
    """The file format of a sweep output: ``format`` (nc, csv, parquet) or else from the suffix of ``path``.

    Raises :class:`~bendpam.errors.InputError` (one line) for an unknown format or a suffix that
    disagrees with ``format``.

    Examples
    --------
    >>> sweep_format("runs/a.parquet"), sweep_format("table", "csv")
    ('parquet', 'csv')
    """
    from pathlib import Path

    fmt = None if format is None else str(format).lower().lstrip(".")
    if fmt is not None and fmt not in SWEEP_FORMATS:
        raise InputError(f"format = {format!r} is not a sweep format; choose {', '.join(SWEEP_FORMATS)}")
    suffix = Path(path).suffix.lower()
    from_name = _SWEEP_SUFFIXES.get(suffix)
    if from_name is not None and fmt is not None and from_name != fmt:
        raise InputError(f"path {str(path)!r} is a {suffix} file but format = {fmt!r}; give a matching name or format")
    out = from_name or fmt
    if out is None:
        raise InputError(f"path {str(path)!r}: {suffix or 'no suffix'} is not a sweep format; use .nc, .csv or "
                         ".parquet (or give format)")
    return out


def write_sweep(ds, path, format: str | None = None) -> Any:
    """Write a sweep dataset atomically as NetCDF, or as a tidy CSV or Parquet table (:func:`to_table`).

    Parameters
    ----------
    ds : xarray.Dataset
        A result of :func:`sweep`.
    path : str or os.PathLike
        Output file; its folder must exist.
    format : {'nc', 'csv', 'parquet'}, optional
        Default: from the suffix of ``path`` (see :func:`sweep_format`).

    Returns
    -------
    pathlib.Path
        ``path``.

    Notes
    -----
    CSV keeps every float exactly (shortest round-trip repr) and has a header row of unit-named
    columns; Parquet (needs ``pyarrow``: ``pip install "bendpam[parquet]"``) also keeps the column
    types and stores the units and the dataset's attributes (model, base actuator TOML) in the
    file's key-value metadata (``bendpam`` key, JSON).

    Examples
    --------
    >>> import tempfile, pathlib, pandas as pd, bendpam
    >>> ds = sweep(bendpam.physics.presets.get("be-pam"), [150], alpha0_deg=[70, 74])
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = write_sweep(ds, pathlib.Path(d) / "s.csv")
    ...     len(pd.read_csv(p))
    2
    """
    from pathlib import Path

    from bendpam.infra.atomic import atomic_path

    fmt = sweep_format(path, format)
    if fmt == "parquet":
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise InputError('writing Parquet needs pyarrow: pip install "bendpam[parquet]"') from None
    with atomic_path(path) as tmp:
        if fmt == "nc":
            ds.to_netcdf(tmp)
        elif fmt == "csv":
            to_table(ds).to_csv(tmp, index=False)
        else:
            _write_parquet(to_table(ds), tmp)
    return Path(path)


def _write_parquet(df, path) -> None:
    import json

    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.Table.from_pandas(df, preserve_index=False)
    meta = dict(table.schema.metadata or {})
    meta[b"bendpam"] = json.dumps(df.attrs, allow_nan=False).encode()
    pq.write_table(table.replace_schema_metadata(meta), path)
