"""``bendpam sweep``: actuator parameters crossed with pressures, in-process or on Dask."""

# no ``from __future__ import annotations``: Typer reads the annotations of the commands as objects (start-up)

import math
import os
from enum import Enum
from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from bendpam.cli.app import app
from bendpam.cli.options import (
    RANGE_HELP,
    ActuatorOpt,
    ModelOpt,
    PresetOpt,
    QuietOpt,
    UserError,
    deprecated_format,
    echo_wrote,
    load_actuator,
    model_for,
    output_file,
    output_format,
    parse_values,
    pressures_kpa,
)
from bendpam.infra.budgets import MEMORY_BUDGET_GIB, TIME_BUDGET_MIN

#: The most (case, pressure) points one block may hold: the model's working arrays take about 2 kB per point.
MAX_BLOCK_POINTS = 1_000_000
#: The largest value of --max-points (the result alone takes 104 bytes per point).
MAX_POINTS_LIMIT = 1_000_000_000


MaxMemoryOpt = Annotated[float, typer.Option(
    "--max-memory-gib", min=0.01, help="Memory budget (GiB): a sweep whose estimated peak memory is larger is "
    "refused before any work (the whole result is held in memory before it is written).")]
MaxMinutesOpt = Annotated[float, typer.Option(
    "--max-minutes", min=0.01, help="Time budget (minutes): a sweep whose estimated run time on one core is longer "
    "is refused before any work.")]


class TableFormat(str, Enum):
    """Formats of ``bendpam sweep --table-format``: the data of --out."""

    nc = "nc"
    csv = "csv"
    parquet = "parquet"
    zarr = "zarr"


class SweepFormat(str, Enum):
    """Values ``bendpam sweep --format`` accepts: the figure formats, and (deprecated) the data formats."""

    nc = "nc"
    csv = "csv"
    parquet = "parquet"
    zarr = "zarr"
    png = "png"
    pdf = "pdf"
    svg = "svg"


DATA_FORMATS = ("nc", "csv", "parquet", "zarr")
FIGURE_FORMATS = ("png", "pdf", "svg")


def sweep_formats(out: Path | None, plot: Path | None, fmt: SweepFormat | None,
                  table_fmt: TableFormat | None = None) -> tuple[str | None, str | None]:
    """The formats of --out (--table-format) and --plot (--format; a data format there is the old spelling)."""
    value = fmt.value if fmt is not None else None
    table = table_fmt.value if table_fmt is not None else None
    if value in DATA_FORMATS:
        table = deprecated_format(value, table, "sweep")
        value = None
    if table is not None and out is None:
        raise UserError(f"--table-format {table} is the format of --out; there is no --out")
    if value is not None and plot is None:
        raise UserError(f"--format {value} is the figure format of --plot; there is no --plot")
    data_fmt = output_format(out, table, DATA_FORMATS, option="--out", format_option="--table-format")
    fig_fmt = output_format(plot, value, FIGURE_FORMATS, option="--plot", default="png")
    return data_fmt, fig_fmt


def max_local_workers() -> int:
    """The most processes ``--workers`` may start: four per CPU."""
    return 4 * (os.cpu_count() or 1)


def parse_param(text: str) -> tuple[str, list[float]]:
    """``NAME=start:stop:count`` or ``NAME=v1,v2,...`` -> (name, values)."""
    if "=" not in text:
        raise UserError(f"--param {text!r}: expected NAME=start:stop:count or NAME=v1,v2 (e.g. alpha0_deg=60:80:41)")
    name, vals = text.split("=", 1)
    values = parse_values([vals], f"--param {name}")
    if not values:
        raise UserError(f"--param {text!r}: no values")
    return name.strip(), values


@app.command("sweep")
def sweep_cmd(
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = None,
    param: Annotated[
        Optional[list[str]],
        typer.Option("--param", metavar="NAME=VALUES",
                     help=f"Swept parameter NAME=VALUES, {RANGE_HELP} (repeat for more)."),
    ] = None,
    pressure_kpa: Annotated[
        Optional[list[str]], typer.Option("--pressure-kpa", metavar="KPA...", help=f"Pressures (kPa): {RANGE_HELP}.")
    ] = None,
    scheduler: Annotated[Optional[str], typer.Option("--scheduler", help="Dask scheduler address.")] = None,
    workers: Annotated[Optional[int], typer.Option("--workers", help="Start a local Dask cluster of N processes.")]
    = None,
    chunk_cases: Annotated[Optional[int], typer.Option(
        "--chunk-cases", min=1, max=1_000_000, show_default=False,
        help="Actuator cases per block (memory bound; default 256, or 32768 (case, pressure) points a block for a "
        ".zarr store).")] = None,
    max_points: Annotated[Optional[int], typer.Option(
        "--max-points", min=1, max=MAX_POINTS_LIMIT, show_default=False,
        help="Refuse sweeps larger than this many (case, pressure) points (default: as many as fit "
        "--max-memory-gib).")] = None,
    max_memory_gib: MaxMemoryOpt = MEMORY_BUDGET_GIB,
    max_minutes: MaxMinutesOpt = TIME_BUDGET_MIN,
    out: Annotated[Optional[Path], typer.Option(
        "--out", help="Output file: NetCDF (.nc), a tidy table of one row per case and pressure (.csv, .parquet), or "
        "a Zarr store (.zarr, a folder) written block by block in bounded memory and resumed when the same command "
        "is run again after an interruption."
    )] = None,
    plot: Annotated[Optional[Path], typer.Option("--plot", help="Quick figure of one output (.png, .pdf, .svg).")]
    = None,
    fmt: Annotated[Optional[SweepFormat], typer.Option(
        "--format", metavar="[png|pdf|svg]", help="Figure format of --plot: png, pdf or svg (default: from the "
        "file name).")] = None,
    table_fmt: Annotated[Optional[TableFormat], typer.Option(
        "--table-format", help="Format of --out: nc, csv, parquet or zarr (default: from the file name).")] = None,
    plot_var: Annotated[str, typer.Option("--plot-var", help="Output to plot.")] = "free_angle_deg",
    plot_x: Annotated[Optional[str], typer.Option("--plot-x", help="Parameter on the x axis (default: first).")]
    = None,
    plot_y: Annotated[
        Optional[str], typer.Option("--plot-y", help="Parameter or 'pressure_kpa' on the y axis (default: second).")
    ] = None,
    at: Annotated[
        Optional[list[str]],
        typer.Option("--at", metavar="NAME=VALUE", help="Fix a dimension of the plot, e.g. pressure_kpa=150 "
                     "(repeat for more; default: the middle value)."),
    ] = None,
    quiet: QuietOpt = False,
    progress: Annotated[bool, typer.Option("--progress/--no-progress", hidden=True,
                                           help="Same as --quiet (--no-progress).")] = True,
):
    """Design sweep: actuator parameters crossed with pressures (in-process or on Dask)."""
    if out is None and plot is None:
        raise UserError("give --out FILE.nc|.csv|.parquet|.zarr and/or --plot FILE.png|.pdf|.svg")
    fixed_at = parse_at(at)
    data_fmt, fig_fmt = sweep_formats(out, plot, fmt, table_fmt)
    grids, P, n_cases = sweep_grid(param, pressure_kpa, max_points, chunk_cases or 1)
    chunk_cases = chunk_cases or (default_zarr_chunk(len(P)) if data_fmt == "zarr" else 256)
    sweep_grid(param, pressure_kpa, max_points, chunk_cases)  # the block size checked
    check_budgets(len(grids), len(P), n_cases, chunk_cases, data_fmt, bool(scheduler or workers), max_memory_gib,
                  max_minutes)
    scheduler = check_run(out, data_fmt, scheduler, workers)
    act = load_actuator(preset, actuator, model)
    run: dict[str, Any] = dict(chunk_cases=chunk_cases, scheduler=scheduler, workers=workers,
                               quiet=quiet or not progress, max_memory_gib=max_memory_gib, actuator=actuator)
    if data_fmt == "zarr":
        assert out is not None
        ds = write_store(out, act, P, model_for(act, model), grids, **run)
    else:
        ds = sweep_in_memory(out, data_fmt, act, P, model_for(act, model), grids, **run)
    if plot is not None:
        from bendpam.present.figures import save_figure, sweep_figure

        with output_file(plot, [actuator]) as f:
            save_figure(sweep_figure(ds, plot_var, plot_x, plot_y, at=fixed_at), f.path, format=fig_fmt)
        echo_wrote(f"wrote {plot}")


def sweep_in_memory(out: Path | None, data_fmt: str | None, act: Any, P: list[float], model: str,
                    grids: dict[str, Any], *, chunk_cases: int, scheduler: str | None, workers: int | None, quiet: bool,
                    max_memory_gib: float, actuator: Path | None) -> Any:
    """The sweep computed whole, then written to ``out`` (NetCDF, CSV, Parquet) if given; its dataset."""
    from bendpam.infra.progress import Progress
    from bendpam.sweeps import sweep, write_sweep

    n_cases = math.prod(len(v) for v in grids.values())
    with Progress(n_cases, "sweep", quiet=quiet) as bar:
        ds = sweep(act, P, model, chunk_cases=chunk_cases, scheduler=scheduler, workers=workers,
                   progress=bar.advance, max_memory_gib=max_memory_gib, **grids)
    if out is not None:
        with output_file(out, [actuator]) as f:
            write_sweep(ds, f.path, data_fmt)
        shape = " x ".join(f"{d}={n}" for d, n in ds.sizes.items())
        rows = f", {math.prod(ds.sizes.values())} rows" if data_fmt != "nc" else ""
        echo_wrote(f"wrote {out} ({shape}{rows})")
    return ds


def default_zarr_chunk(n_pressures: int) -> int:
    """Cases a block of a .zarr store holds by default (:func:`bendpam.sweep_store.default_chunk_cases`)."""
    from bendpam.sweep_store import default_chunk_cases

    return default_chunk_cases(n_pressures)


def write_store(out: Path, act: Any, P: list[float], model: str, grids: dict[str, Any], *, chunk_cases: int,
                scheduler: str | None, workers: int | None, quiet: bool, max_memory_gib: float,
                actuator: Path | None) -> Any:
    """Stream the sweep into the Zarr store ``out`` (resuming an interrupted run of the same command); its dataset.

    The dataset is opened lazily from the store written (for --plot).
    """
    import xarray as xr

    from bendpam.cli.options import RUN_COMMAND, RUN_FORCE, as_given, command_line
    from bendpam.infra.progress import Progress
    from bendpam.sweep_store import sweep_zarr

    n_cases = math.prod(len(v) for v in grids.values())
    inputs = [actuator] if actuator is not None else []
    try:
        with Progress(n_cases, "sweep", quiet=quiet) as bar:
            path = sweep_zarr(act, as_given(out), P, model, chunk_cases=chunk_cases, scheduler=scheduler,
                              workers=workers, progress=bar.advance, max_memory_gib=max_memory_gib,
                              force=RUN_FORCE.get(), command=command_line(), inputs=inputs,
                              producer=RUN_COMMAND.get() or "sweep", **grids)
    except BaseException:
        from bendpam.infra.fsops import part_name

        kept = Path(os.path.expanduser(str(out))).parent / part_name(out.name)
        if kept.is_dir() and any((kept / ".bendpam-resume" / "blocks").glob("*")):
            typer.echo(f"bendpam: the finished blocks are kept in {str(kept)!r}; run the same command again to "
                       "resume the sweep", err=True)
        raise
    ds = xr.open_zarr(path)
    shape = " x ".join(f"{d}={n}" for d, n in ds.sizes.items())
    echo_wrote(f"wrote {out} ({shape}, {ds.attrs.get('blocks')} blocks of {chunk_cases} cases)")
    return ds


def parse_at(at: list[str] | None) -> dict[str, float]:
    """The ``--at NAME=VALUE`` items as ``{name: value}``."""
    fixed_at = {}
    for item in at or []:
        name, sep, value = item.partition("=")
        vals = parse_values([value], f"--at {name}") if sep else []
        if len(vals) != 1:
            raise UserError(f"--at {item!r}: expected NAME=VALUE, e.g. pressure_kpa=150")
        fixed_at[name.strip()] = vals[0]
    return fixed_at


def check_run(out: Path | None, data_fmt: str | None, scheduler: str | None, workers: int | None) -> str | None:
    """Refuse, before any work, a Parquet --out without pyarrow and a --scheduler/--workers request that cannot run.

    Returns the scheduler's address (read from --scheduler, which must answer as a Dask scheduler).
    """
    if data_fmt == "parquet":
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise UserError(f'--out {str(out)!r}: writing Parquet needs pyarrow: pip install "bendpam[parquet]"') \
                from None
    if scheduler and workers:
        raise UserError("give either --scheduler or --workers, not both")
    if workers is not None and workers < 1:
        raise UserError(f"--workers {workers}: give at least 1 worker process")
    if workers is not None and workers > max_local_workers():
        raise UserError(f"--workers {workers}: at most {max_local_workers()} local processes (4 per CPU); "
                        "use --scheduler for a larger cluster")
    return None if scheduler is None else scheduler_address(scheduler)


def scheduler_address(text: str) -> str:
    """The address of ``--scheduler`` (an address or a scheduler file), refused unless a Dask scheduler answers it."""
    from bendpam.infra.budgets import SCHEDULER_TIMEOUT_S
    from bendpam.infra.scheduler import parse_scheduler_address, probe_scheduler

    address = parse_scheduler_address(text, name="--scheduler")
    probe_scheduler(address, SCHEDULER_TIMEOUT_S)
    return address


def check_budgets(n_params: int, n_pressures: int, n_cases: int, chunk_cases: int, data_fmt: str | None,
                  remote: bool, max_memory_gib: float, max_minutes: float) -> None:
    """Refuse, before any work, a sweep whose estimated peak memory or run time is past its budget."""
    from bendpam.infra.budgets import GIB, memory_problem
    from bendpam.sweeps import sweep_estimate

    table = data_fmt if data_fmt in ("csv", "parquet") else None
    stream = data_fmt == "zarr"  # written block by block: only the blocks in flight are held
    est = sweep_estimate(n_cases, n_pressures, n_params, chunk_cases=chunk_cases, table=table, remote=remote,
                         compute=not stream)
    size = (f"{est.points} (case, pressure) points ({n_cases} case{'s' * (n_cases != 1)} x {n_pressures} "
            f"pressure{'s' * (n_pressures != 1)})")
    problem = memory_problem(est.memory_bytes, max_memory_gib)
    raise_it = (", or raise --max-memory-gib if this machine has the memory"
                if est.memory_bytes > max_memory_gib * GIB else "")
    if problem is not None and stream:
        raise UserError(f"the sweep of {size} in blocks of {chunk_cases} cases holds {problem}; give a smaller "
                        f"--chunk-cases{raise_it}")
    if problem is not None:
        raise UserError(f"the sweep of {size} holds its whole result in memory before writing it: {problem}; give "
                        f"fewer values, or write a Zarr store (--out NAME.zarr: block by block){raise_it}")
    if est.seconds > 60.0 * max_minutes:
        raise UserError(f"the sweep of {size} would take about {est.time_text} on one core (a conservative estimate), "
                        f"more than --max-minutes {max_minutes:g}; give fewer values, or raise --max-minutes (the "
                        "estimate is for one core: more cores, --workers or --scheduler finish sooner)")


def sweep_grid(param: list[str] | None, pressure_kpa: list[str] | None, max_points: int | None,
               chunk_cases: int) -> tuple[dict[str, Any], list[float], int]:
    """``(grids, pressures, n_cases)`` from --param and --pressure-kpa, within --max-points and the block size."""
    import numpy as np

    from bendpam.sweeps import SWEEP_PARAMETERS

    params = dict(parse_param(p) for p in (param or []))
    for name in params:
        if name not in SWEEP_PARAMETERS:
            raise UserError(f"--param {name}: cannot sweep it; choose from {', '.join(SWEEP_PARAMETERS)}")
    if not pressure_kpa:
        raise UserError("give the pressures with --pressure-kpa, e.g. 100:250:16")
    P = pressures_kpa(pressure_kpa)
    n_points = len(P) * math.prod(len(v) for v in params.values())
    if max_points is not None and n_points > max_points:
        raise UserError(f"the sweep has {n_points} (case, pressure) points, more than --max-points {max_points}; "
                        "raise --max-points to run it")
    n_cases = n_points // len(P)
    block = min(chunk_cases, n_cases) * len(P)
    if block > MAX_BLOCK_POINTS:
        raise UserError(f"--chunk-cases {chunk_cases} with {len(P)} pressures gives {block} (case, pressure) points "
                        f"per block, more than {MAX_BLOCK_POINTS} (about 2 kB of memory each); use --chunk-cases "
                        f"{max(MAX_BLOCK_POINTS // len(P), 1)} or fewer, or fewer pressures")
    # typed Any: mypy would check the arrays against sweep()'s other keyword parameters
    grids: dict[str, Any] = {k: np.asarray(v) for k, v in params.items()}
    return grids, P, n_cases
