"""The ``bendpam`` command line.  It parses and prints; the logic lives in the library.

Every error (unknown preset, bad TOML, negative pressure, unknown option ...) is printed as one
line ``bendpam: error: ...`` on stderr with exit code 2, never a traceback.
"""

from __future__ import annotations

import json
import math
import sys
import time
from enum import Enum
from pathlib import Path
from typing import Annotated, Optional

import numpy as np
import typer

from . import presets as _presets
from ._io import atomic_write_text, json_safe
from .actuator import Actuator
from .braid import curvature_limits

# Typer >= 0.20 vendors click; find its exception base class without importing click directly.
_ClickException = next(c for c in typer.BadParameter.__mro__ if c.__name__ == "ClickException")

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
    help="bendpam: models, tests and design tools for bending pneumatic artificial muscles.",
)


class UserError(Exception):
    """An error caused by the user's input; printed as one line, exit code 2."""


class Model(str, Enum):
    energy = "energy"
    force_balance = "force-balance"


class Preset(str, Enum):
    be_pam = "be-pam"
    bc_pam = "bc-pam"


# ---- shared option parsing ----------------------------------------------------------------------
def parse_values(tokens: list[str] | None, name: str) -> list[float]:
    """Parse numbers given as separate tokens, comma lists or ranges ``start:stop:count``."""
    out: list[float] = []
    for tok in tokens or []:
        for part in str(tok).replace(",", " ").split():
            if ":" in part:
                bits = part.split(":")
                if len(bits) != 3:
                    raise UserError(f"{name}: range {part!r} must be start:stop:count")
                try:
                    a, b, n = float(bits[0]), float(bits[1]), int(bits[2])
                except ValueError:
                    raise UserError(f"{name}: range {part!r} must be start:stop:count with numbers") from None
                if n < 1:
                    raise UserError(f"{name}: range {part!r} needs a count >= 1")
                out.extend(np.linspace(a, b, n).tolist())
            else:
                try:
                    v = float(part)
                except ValueError:
                    raise UserError(f"{name}: {part!r} is not a number") from None
                if not math.isfinite(v):
                    raise UserError(f"{name}: {part!r} is not finite")
                out.append(v)
    return out


def pressures_kpa(first: list[str] | None, more: list[str] | None) -> list[float]:
    if more and not first:
        raise UserError(f"unexpected argument(s) {' '.join(more)!r}; pressures go after --pressure-kpa")
    values = parse_values((first or []) + (more or []), "--pressure-kpa")
    if not values:
        raise UserError("give at least one pressure with --pressure-kpa (kPa), e.g. --pressure-kpa 100 150 200")
    for v in values:
        if v < 0:
            raise UserError(f"--pressure-kpa: {v:g} kPa is below zero; pressures are gauge pressures >= 0 kPa")
    return values


def load_actuator(preset: Preset | None, actuator: Path | None, model: Model) -> Actuator:
    if preset is not None and actuator is not None:
        raise UserError("give either --preset or --actuator, not both")
    if preset is None and actuator is None:
        raise UserError("give an actuator: --preset be-pam|bc-pam or --actuator FILE.toml")
    if preset is not None:
        return _presets.get(preset.value, model_name(model))
    return Actuator.from_toml(actuator)


def model_name(model: Model) -> str:
    return _presets.normalise_model(model.value)


def _num(x: float, fmt: str) -> str:
    width = fmt.split(".")[0]
    return "—".rjust(int(width) if width else 1) if x is None or not np.isfinite(x) else format(x, fmt)


def format_prediction_table(df, title: str) -> str:
    lines = [title, f"{'P (kPa)':>8}  {'M_blocked (N·mm)':>16}  {'k_free (1/mm)':>13}  {'θ_free (deg)':>12}  note"]
    for r in df.itertuples():
        lines.append(
            f"{r.pressure_kpa:8.4g}  {_num(r.blocked_moment_nmm, '16.2f')}  {_num(r.free_curvature_per_mm, '13.5f')}  "
            f"{_num(r.free_angle_deg, '12.2f')}  {r.note}"
        )
    return "\n".join(lines)


# ---- commands -------------------------------------------------------------------------------------
PresetOpt = Annotated[Optional[Preset], typer.Option("--preset", help="Built-in actuator from the paper.")]
ActuatorOpt = Annotated[
    Optional[Path], typer.Option("--actuator", help="Actuator TOML file (see `bendpam actuator --preset be-pam`).")
]
ModelOpt = Annotated[Model, typer.Option("--model", help="Moment model.")]
PressureOpt = Annotated[
    Optional[list[str]],
    typer.Option("--pressure-kpa", help="Gauge pressure(s) in kPa: '100 150 200', '100,150' or '100:200:5'."),
]
MorePressures = Annotated[Optional[list[str]], typer.Argument(hidden=True, metavar="[P ...]")]


@app.command()
def predict(
    more: MorePressures = None,
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = Model.energy,
    pressure_kpa: PressureOpt = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object instead of a table.")] = False,
    cycle: Annotated[
        bool, typer.Option("--cycle", help="Also predict the hysteresis loop of a free-bending cycle (needs loop "
                           "parameters: the [hysteresis] table of --actuator, or the --loop-* options).")
    ] = False,
    loop_law: Annotated[Optional[str], typer.Option("--loop-law", help="Loop law: pi or dahl.")] = None,
    loop_a0_nmm: Annotated[Optional[float], typer.Option("--loop-a0-nmm", help="Loop amplitude, constant part (N·mm).")]
    = None,
    loop_a1_nmm_per_kpa: Annotated[
        Optional[float], typer.Option("--loop-a1-nmm-per-kpa", help="Loop amplitude per active pressure (N·mm/kPa).")
    ] = None,
    loop_angle_deg: Annotated[Optional[float], typer.Option("--loop-angle-deg", help="Loop angle (deg).")] = None,
):
    """Blocked moment and free bending curvature/angle at each pressure (and, with --cycle, the loop)."""
    from .predict import branch_info, prediction_table

    act = load_actuator(preset, actuator, model)
    P = pressures_kpa(pressure_kpa, more)
    mname = model_name(model)
    df = prediction_table(act, P, mname)
    br = branch_info(act, mname)
    loop = _loop_model(actuator, loop_law, loop_a0_nmm, loop_a1_nmm_per_kpa, loop_angle_deg) if cycle else None
    cycles = None
    if loop is not None:
        from .hysteresis import predict_cycle

        cycles = [predict_cycle(act, loop, p, mname) for p in P]
    if as_json:
        obj = {
            "model": mname,
            "actuator": act.to_dict() | act.derived(),
            "max_equilibrium_pressure_kpa": json_safe(br.max_pressure * 1e3),
            "branch_end": br.kind,
            "units": {"pressure_kpa": "kPa", "blocked_moment_nmm": "N*mm", "free_curvature_per_mm": "1/mm",
                      "free_angle_deg": "deg"},
            "results": [
                {
                    "pressure_kpa": json_safe(r.pressure_kpa),
                    "blocked_moment_nmm": json_safe(r.blocked_moment_nmm),
                    "free_curvature_per_mm": json_safe(r.free_curvature_per_mm),
                    "free_angle_deg": json_safe(r.free_angle_deg),
                    "note": r.note or None,
                    **({"cycle": _cycle_json(cycles[i])} if cycles is not None else {}),
                }
                for i, r in enumerate(df.itertuples())
            ],
            **({"hysteresis": loop.to_dict()} if loop is not None else {}),
        }
        typer.echo(json.dumps(obj, indent=2))
        return
    typer.echo(format_prediction_table(df, f"{act.name or act.kind} — {mname.replace('_', '-')} model"))
    if math.isfinite(br.max_pressure):
        typer.echo(f"highest pressure with a free-bending equilibrium: {br.max_pressure * 1e3:.4g} kPa ({br.kind})")
    if cycles is not None:
        typer.echo(f"\nloop ({loop.law}, a0 = {loop.a0_nmm:g} N·mm, a1 = {loop.a1_nmm_per_mpa:g} N·mm/MPa, "
                   f"angle {loop.theta_h_deg:g} deg): free-bending cycle blocked -> free -> blocked")
        typer.echo(f"{'P (kPa)':>8}  {'k_free,unloading (1/mm)':>24}  {'energy-loss ratio':>18}  note")
        for c in cycles:
            typer.echo(f"{c.pressure_kpa:8.4g}  {_num(c.free_curvature_per_mm, '24.5f')}  "
                       f"{_num(100 * c.energy_loss_ratio, '17.2f')}%  {c.note}")


def _loop_model(actuator_file, law, a0, a1_per_kpa, angle):
    """Loop parameters for --cycle: the actuator file's [hysteresis] table, overridden by --loop-* options."""
    from .hysteresis import LoopModel

    base = LoopModel.from_toml(actuator_file) if actuator_file is not None else None
    given = {k: v for k, v in (("law", law), ("a0_nmm", a0), ("theta_h_deg", angle),
                               ("a1_nmm_per_mpa", None if a1_per_kpa is None else a1_per_kpa * 1e3)) if v is not None}
    if base is None and not {"a0_nmm", "a1_nmm_per_mpa"} & set(given):
        raise UserError("--cycle needs loop parameters: an --actuator file with a [hysteresis] table "
                        "(bendpam fit --hysteresis writes one) or --loop-a0-nmm / --loop-a1-nmm-per-kpa")
    d = (base.to_dict() if base is not None else {}) | given
    return LoopModel.from_dict(d, source="loop parameters")


def _cycle_json(c) -> dict:
    return {
        "free_curvature_unloading_per_mm": json_safe(c.free_curvature_per_mm),
        "energy_loss_ratio": json_safe(c.energy_loss_ratio),
        "curvature_per_mm": [float(x) for x in c.curvature_per_mm[::10]],
        "loading_nmm": [float(x) for x in c.loading_nmm[::10]],
        "unloading_nmm": [float(x) for x in c.unloading_nmm[::10]],
        "note": c.note or None,
    }


@app.command()
def curve(
    more: MorePressures = None,
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = Model.energy,
    pressure_kpa: PressureOpt = None,
    out: Annotated[Optional[Path], typer.Option("--out", help="Output FILE.csv, or a figure FILE.png/.pdf/.svg.")] = None,
    k_max: Annotated[
        Optional[float],
        typer.Option("--k-max", help="End of the curvature range (1/mm, magnitude along the bending direction); "
                     "default: 15% past free bending."),
    ] = None,
    points: Annotated[int, typer.Option("--points", min=2, max=100000, help="Curvature points per curve.")] = 200,
):
    """Moment-curvature curves M(P, k') as CSV or a figure."""
    from .plots import moment_curves, plot_moment_curvature, save_figure

    if out is None:
        raise UserError("give an output file with --out FILE.csv or --out FILE.png")
    suffix = out.suffix.lower()
    if suffix not in {".csv", ".png", ".pdf", ".svg"}:
        raise UserError(f"--out {str(out)!r}: unknown format {suffix or '(none)'}; use .csv, .png, .pdf or .svg")
    act = load_actuator(preset, actuator, model)
    P = np.asarray(pressures_kpa(pressure_kpa, more)) * 1e-3
    mname = model_name(model)
    if suffix == ".csv":
        k, M = moment_curves(act, P, mname, k_max, points)
        rows = ["pressure_kpa,curvature_per_mm,moment_nmm"]
        for i, p in enumerate(P):
            rows.extend(f"{p * 1e3:.10g},{kk:.12g},{mm:.12g}" for kk, mm in zip(k, M[i]))
        atomic_write_text(out, "\n".join(rows) + "\n")
    else:
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        plot_moment_curvature(ax, act, P, mname, k_max, points)
        fig.tight_layout()
        save_figure(fig, out)
    typer.echo(f"wrote {out}")


@app.command()
def stresses(
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    pressure_kpa: Annotated[float, typer.Option("--pressure-kpa", help="Gauge pressure, kPa.")] = 200.0,
    curvature: Annotated[float, typer.Option("--curvature", help="Frame curvature k', 1/mm.")] = 0.0,
    out: Annotated[Optional[Path], typer.Option("--out", help="Figure (.png/.pdf/.svg) or data (.nc/.csv).")] = None,
):
    """Force-balance internal stresses around the cross-section (eq 37-48)."""
    from .predict import internal_stresses

    act = load_actuator(preset, actuator, Model.force_balance)
    if pressure_kpa < 0:
        raise UserError(f"--pressure-kpa: {pressure_kpa:g} kPa is below zero")
    if out is None:
        raise UserError("give an output file with --out FILE.png (figure), FILE.nc or FILE.csv (data)")
    suffix = out.suffix.lower()
    if suffix in {".png", ".pdf", ".svg"}:
        from .plots import plot_internal_stresses, save_figure

        save_figure(plot_internal_stresses(act, pressure_kpa * 1e-3, curvature), out)
    elif suffix == ".nc":
        from ._io import atomic_path

        ds = internal_stresses(act, pressure_kpa * 1e-3, curvature)
        with atomic_path(out) as tmp:
            ds.to_netcdf(tmp)
    elif suffix == ".csv":
        ds = internal_stresses(act, pressure_kpa * 1e-3, curvature)
        atomic_write_text(out, ds.to_dataframe().to_csv())
    else:
        raise UserError(f"--out {str(out)!r}: unknown format {suffix or '(none)'}; use .png, .pdf, .svg, .nc or .csv")
    typer.echo(f"wrote {out}")


@app.command("actuator")
def actuator_cmd(
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = Model.energy,
    out: Annotated[Optional[Path], typer.Option("--out", help="Write the actuator as TOML here.")] = None,
):
    """Show an actuator (TOML, derived values, lock-up limits) or save it as an editable TOML file."""
    act = load_actuator(preset, actuator, model)
    text = act.to_toml()
    if out is not None:
        act.to_toml(out)
        typer.echo(f"wrote {out}")
        return
    lim = curvature_limits(act)
    typer.echo(text.rstrip())
    typer.echo("\n# derived")
    for k, v in act.derived().items():
        typer.echo(f"# {k} = {v:.6g}")
    typer.echo(f"# curvature range (braid lock-up) = [{lim.k_min:.6g}, {lim.k_max:.6g}] 1/mm")


@app.command()
def demo(
    out: Annotated[Path, typer.Option("--out", help="Moment-curvature figure to write.")] = Path("bendpam-demo.png"),
):
    """Predictions for the paper's BE-PAM and BC-PAM with both models, and a moment-curvature figure."""
    from .plots import demo_figure, save_figure
    from .predict import branch_info, prediction_table

    t0 = time.perf_counter()
    cases = [("be-pam", [100, 125, 150, 175, 200]), ("bc-pam", [40, 60, 80, 100, 120, 140])]
    items = []
    for name, P in cases:
        for mname in ("energy", "force_balance"):
            act = _presets.get(name, mname)
            df = prediction_table(act, P, mname)
            typer.echo(format_prediction_table(df, f"\n{act.name} — {mname.replace('_', '-')} model"))
            br = branch_info(act, mname)
            if br.kind == "fold":
                typer.echo(f"fold: no free-bending equilibrium above {br.max_pressure * 1e3:.4g} kPa")
            items.append((act, np.asarray(P) * 1e-3, mname))
    save_figure(demo_figure(items), out)
    typer.echo(f"\nwrote {out}  ({time.perf_counter() - t0:.1f} s)")


def collect_raw_files(paths: list[Path]) -> list[Path]:
    """Expand folders into their raw test files (see :func:`bendpam.lab.files.collect_raw_files`)."""
    from .lab.files import collect_raw_files as _collect

    try:
        return _collect(paths)
    except ValueError as exc:
        raise UserError(str(exc)) from None


class Format(str, Enum):
    csv = "csv"
    testxpert = "testxpert"
    bluehill = "bluehill"
    mts = "mts"


@app.command()
def process(
    inputs: Annotated[list[Path], typer.Argument(help="Raw test files, or a folder of them.", show_default=False)],
    out: Annotated[Path, typer.Option("--out", help="Output folder.")] = None,
    pressure_kpa: PressureOpt = None,
    l0_mm: Annotated[float, typer.Option("--l0-mm", help="Active length L0 for k' = 2 beta / L0 (mm).")] = 145.0,
    fixture: Annotated[str, typer.Option("--fixture", help="Fixture geometry d,r,t in mm.")] = "35,2.5,4",
    cutoff_hz: Annotated[
        Optional[float], typer.Option("--cutoff-hz", help="Low-pass cutoff (Hz); default 1 Hz (max 40% of Nyquist); 0 = off.")
    ] = None,
    tare_n: Annotated[float, typer.Option("--tare-n", help="Force tare for self-weight (N).")] = 0.0,
    reversal_fraction: Annotated[
        float, typer.Option("--reversal-fraction", help="Stroke-reversal threshold, fraction of the stroke range.")
    ] = 0.05,
    grid_points: Annotated[int, typer.Option("--grid-points", help="Points of the common curvature grid.")] = 101,
    figure: Annotated[bool, typer.Option("--figure/--no-figure", help="Write figure4.png.")] = True,
    as_json: Annotated[bool, typer.Option("--json", help="Print summary.json to stdout.")] = False,
):
    """Process raw four-point-bending cyclic tests into moment-curvature curves and Table 2 values."""
    from .fixture import Fixture
    from .lab import read_test
    from .lab.processing import ProcessingOptions, process_tests, write_processed

    if out is None:
        raise UserError("give an output folder with --out OUTDIR")
    files = collect_raw_files(inputs)
    pressures = parse_values(pressure_kpa, "--pressure-kpa") if pressure_kpa else []
    if pressures and len(pressures) not in (1, len(files)) or (len(pressures) == 1 and len(files) > 1):
        raise UserError(
            f"--pressure-kpa: got {len(pressures)} pressure(s) for {len(files)} file(s); give one per file, in order"
        )
    for v in pressures:
        if v < 0:
            raise UserError(f"--pressure-kpa: {v:g} kPa is below zero")
    fx = Fixture.from_string(fixture, L0_mm=l0_mm)
    opts = ProcessingOptions(cutoff_hz=cutoff_hz, reversal_fraction=reversal_fraction, grid_points=grid_points,
                             tare_n=tare_n)
    tests = [read_test(f, pressure_kpa=pressures[i] if pressures else None) for i, f in enumerate(files)]
    processed = process_tests(tests, fixture=fx, options=opts)
    write_processed(processed, out, figure=figure)
    if as_json:
        typer.echo((out / "summary.json").read_text())
        return
    summ = processed.summary()
    typer.echo(f"{'P (kPa)':>8} {'cycles':>6} {'M_blocked (N·mm)':>18} {'k_free (1/mm)':>20} {'loss ratio':>10}")
    for r in summ["pressures"]:
        typer.echo(
            f"{r['pressure_kpa']:8.4g} {r['cycles']:6d} {r['blocked_moment_nmm']:9.2f} ± {_num(r['blocked_moment_se_nmm'], '6.2f')} "
            f"{r['free_curvature_per_mm']:10.5f} ± {_num(r['free_curvature_se_per_mm'], '7.1e')} {100 * r['energy_loss_ratio']:9.2f}%"
        )
        for note in r["notes"]:
            typer.echo(f"         note: {note}")
    typer.echo(f"deadband: {_num(summ['deadband_kpa'], '.4g')} ± {_num(summ['deadband_se_kpa'], '.2g')} kPa")
    typer.echo(f"wrote {out}/ (curves.nc, curves.csv, summary.json{', figure4.png' if figure else ''})")


@app.command("simulate-test")
def simulate_test_cmd(
    more: MorePressures = None,
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = Model.energy,
    pressure_kpa: PressureOpt = None,
    out: Annotated[Optional[Path], typer.Option("--out", help="Output folder for the raw files and truth.json.")] = None,
    fmt: Annotated[Format, typer.Option("--format", help="Export dialect to write.")] = Format.csv,
    noise_n: Annotated[float, typer.Option("--noise-n", help="Force noise, standard deviation (N).")] = 0.05,
    noise_stroke_mm: Annotated[float, typer.Option("--noise-stroke-mm", help="Stroke noise, standard deviation (mm).")] = 0.002,
    hysteresis: Annotated[
        float, typer.Option("--hysteresis", help="Pressure part of the loop amplitude, as a fraction of the blocked moment.")
    ] = 0.06,
    hysteresis_angle_deg: Annotated[
        float, typer.Option("--hysteresis-angle-deg",
                            help="Loop angle (deg): saturation angle (pi) or characteristic angle (dahl).")
    ] = 5.0,
    hysteresis_law: Annotated[str, typer.Option("--hysteresis-law", help="Loop law: pi (Prandtl-Ishlinskii) or dahl.")]
    = "pi",
    hysteresis_offset_nmm: Annotated[
        float, typer.Option("--hysteresis-offset-nmm", help="Constant part of the loop amplitude (N·mm).")
    ] = 0.0,
    cycles: Annotated[int, typer.Option("--cycles", help="Cycles per pressure.")] = 3,
    speed_mm_min: Annotated[float, typer.Option("--speed-mm-min", help="Crosshead speed (mm/min).")] = 30.0,
    rate_hz: Annotated[float, typer.Option("--rate-hz", help="Sampling rate (Hz).")] = 20.0,
    dwell_s: Annotated[float, typer.Option("--dwell-s", help="Dwell at each end of a stroke (s).")] = 0.0,
    stroke_offset_mm: Annotated[float, typer.Option("--stroke-offset-mm", help="Machine stroke at the blocked state (mm).")] = 0.0,
    fixture: Annotated[str, typer.Option("--fixture", help="Fixture geometry d,r,t in mm.")] = "35,2.5,4",
    seed: Annotated[Optional[int], typer.Option("--seed", help="Random seed.")] = None,
):
    """Write the raw files a testing machine would record for a model actuator (a virtual test)."""
    from .fixture import Fixture
    from .lab.simulate import SimulationSettings, simulate_tests

    if out is None:
        raise UserError("give an output folder with --out DIR")
    if out.exists() and not out.is_dir():
        raise UserError(f"--out {str(out)!r} exists and is not a folder")
    act = load_actuator(preset, actuator, model)
    P = pressures_kpa(pressure_kpa, more)
    st = SimulationSettings(cycles=cycles, speed_mm_min=speed_mm_min, rate_hz=rate_hz, noise_n=noise_n,
                            noise_stroke_mm=noise_stroke_mm, hysteresis=hysteresis,
                            hysteresis_angle_deg=hysteresis_angle_deg, hysteresis_law=hysteresis_law,
                            hysteresis_offset_nmm=hysteresis_offset_nmm, dwell_s=dwell_s,
                            stroke_offset_mm=stroke_offset_mm, seed=seed)
    fx = Fixture.from_string(fixture, L0_mm=act.L0_mm)
    truth = simulate_tests(act, P, out, model_name(model), dialect=fmt.value, fixture=fx, settings=st)
    for t in truth["pressures"]:
        typer.echo(
            f"{t['file']}: {t['samples']} samples, blocked {t['blocked_moment_nmm']:.2f} N·mm, "
            f"free k' {t['free_curvature_per_mm']:.5f} 1/mm, loss ratio {100 * t['energy_loss_ratio']:.1f}%"
        )
    typer.echo(f"wrote {out}/ ({len(truth['files'])} files and truth.json)")


def _tension(path: Path, gauge_length_mm, area_mm2, width_mm, thickness_mm):
    from .identify import tension_from_test
    from .lab import read_test

    if gauge_length_mm is None:
        raise UserError("the tension test needs the specimen's --gauge-length-mm")
    if area_mm2 is None:
        if width_mm is None or thickness_mm is None:
            raise UserError("the tension test needs --area-mm2, or --width-mm and --thickness-mm")
        area_mm2 = width_mm * thickness_mm
    return tension_from_test(read_test(path), gauge_length_mm=gauge_length_mm, area_mm2=area_mm2)


GaugeOpt = Annotated[Optional[float], typer.Option("--gauge-length-mm", help="Tension specimen gauge length (mm).")]
AreaOpt = Annotated[Optional[float], typer.Option("--area-mm2", help="Tension specimen cross-section (mm^2).")]
WidthOpt = Annotated[Optional[float], typer.Option("--width-mm", help="Tension specimen width (mm).")]
ThickOpt = Annotated[Optional[float], typer.Option("--thickness-mm", help="Tension specimen thickness (mm).")]


@app.command()
def fit(
    processed_dir: Annotated[Path, typer.Argument(help="Output folder of `bendpam process`.", show_default=False)],
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = Model.energy,
    free: Annotated[str, typer.Option("--free", help="Parameters to identify: alpha0,C10,C01,P_start,E_f,R0_start.")]
    = "alpha0,C10,C01",
    tension: Annotated[Optional[Path], typer.Option("--tension", help="Bladder tension-test export (start values).")]
    = None,
    gauge_length_mm: GaugeOpt = None,
    area_mm2: AreaOpt = None,
    width_mm: WidthOpt = None,
    thickness_mm: ThickOpt = None,
    fit_range: Annotated[str, typer.Option("--fit-range", help="'developed' (loop developed) or 'all' points.")]
    = "developed",
    hysteresis: Annotated[
        bool, typer.Option("--hysteresis", help="Also identify a rate-independent loop from both branches.")
    ] = False,
    hysteresis_law: Annotated[str, typer.Option("--hysteresis-law", help="Loop law: pi (Prandtl-Ishlinskii) or dahl.")]
    = "pi",
    out: Annotated[Optional[Path], typer.Option("--out", help="Output folder.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print fit.json to stdout.")] = False,
):
    """Identify model parameters (alpha0, C10, C01, ...) from processed cyclic tests (section 3.4)."""
    from .identify import fit as _fit
    from .plots import figure7, save_figure
    from .lab.processing import load_processed

    if out is None:
        raise UserError("give an output folder with --out OUTDIR")
    act = load_actuator(preset, actuator, model)
    data = load_processed(processed_dir)
    tfit = _tension(tension, gauge_length_mm, area_mm2, width_mm, thickness_mm) if tension else None
    res = _fit(data, act, model_name(model), free=free, tension=tfit, fit_range=fit_range,
               hysteresis=hysteresis_law if hysteresis else None)
    res.save(out)
    if tfit is not None:
        obj = json.loads((out / "fit.json").read_text())
        obj["tension"] = tfit.to_dict()
        atomic_write_text(out / "fit.json", json.dumps(obj, indent=2))
    save_figure(figure7(data, res), out / "figure7.png")
    if as_json:
        typer.echo((out / "fit.json").read_text())
        return
    typer.echo(str(res))
    typer.echo(f"wrote {out}/ (fit.json, fitted_actuator.toml, figure7.png)")


@app.command("fit-material")
def fit_material(
    tension_file: Annotated[Path, typer.Argument(help="Uniaxial tension export of the bladder.", show_default=False)],
    gauge_length_mm: GaugeOpt = None,
    area_mm2: AreaOpt = None,
    width_mm: WidthOpt = None,
    thickness_mm: ThickOpt = None,
    out: Annotated[Optional[Path], typer.Option("--out", help="Write tension_fit.json here (a folder).")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the result as JSON.")] = False,
):
    """Fit Mooney-Rivlin C10, C01 to a uniaxial tension test of the bladder material."""
    if not tension_file.exists():
        raise UserError(f"{tension_file}: no such file")
    tf = _tension(tension_file, gauge_length_mm, area_mm2, width_mm, thickness_mm)
    text = json.dumps(tf.to_dict(), indent=2)
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        atomic_write_text(out / "tension_fit.json", text)
    if as_json:
        typer.echo(text)
        return
    typer.echo(f"C10 = {tf.C10_kpa:.1f} ± {tf.C10_se_kpa:.1f} kPa, C01 = {tf.C01_kpa:.1f} ± {tf.C01_se_kpa:.1f} kPa "
               f"(correlation {tf.correlation:+.3f}, RMSE {tf.rmse_kpa:.2f} kPa, {tf.n_points} points up to "
               f"stretch {tf.max_stretch:.3f})")


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
    model: ModelOpt = Model.energy,
    param: Annotated[
        Optional[list[str]],
        typer.Option("--param", help="Swept parameter NAME=start:stop:count or NAME=v1,v2 (repeat for more)."),
    ] = None,
    pressure_kpa: Annotated[
        Optional[list[str]], typer.Option("--pressure-kpa", help="Pressures (kPa): '100:250:16' or '100,150'.")
    ] = None,
    scheduler: Annotated[Optional[str], typer.Option("--scheduler", help="Dask scheduler address.")] = None,
    workers: Annotated[Optional[int], typer.Option("--workers", help="Start a local Dask cluster of N processes.")]
    = None,
    chunk_cases: Annotated[int, typer.Option("--chunk-cases", help="Actuator cases per block (memory bound).")]
    = 256,
    out: Annotated[Optional[Path], typer.Option("--out", help="Output NetCDF file (.nc).")] = None,
    plot: Annotated[Optional[Path], typer.Option("--plot", help="Quick figure (.png) of one output.")] = None,
    plot_var: Annotated[str, typer.Option("--plot-var", help="Output to plot.")] = "free_angle_deg",
    plot_x: Annotated[Optional[str], typer.Option("--plot-x", help="Parameter on the x axis (default: first).")]
    = None,
    plot_y: Annotated[
        Optional[str], typer.Option("--plot-y", help="Parameter or 'pressure_kpa' on the y axis (default: second).")
    ] = None,
    progress: Annotated[bool, typer.Option("--progress/--no-progress", help="Progress bar.")] = True,
):
    """Design sweep: actuator parameters crossed with pressures (in-process or on Dask)."""
    from ._io import atomic_path
    from .sweeps import SWEEP_PARAMETERS, sweep

    if out is None and plot is None:
        raise UserError("give --out FILE.nc and/or --plot FILE.png")
    if out is not None and out.suffix.lower() != ".nc":
        raise UserError(f"--out {str(out)!r}: the sweep is written as NetCDF; use a .nc file")
    if scheduler and workers:
        raise UserError("give either --scheduler or --workers, not both")
    act = load_actuator(preset, actuator, model)
    params = dict(parse_param(p) for p in (param or []))
    for name in params:
        if name not in SWEEP_PARAMETERS:
            raise UserError(f"--param {name}: cannot sweep it; choose from {', '.join(SWEEP_PARAMETERS)}")
    P = parse_values(pressure_kpa, "--pressure-kpa")
    if not P:
        raise UserError("give the pressures with --pressure-kpa, e.g. 100:250:16")
    ds = sweep(act, P, model_name(model), chunk_cases=chunk_cases, scheduler=scheduler, workers=workers,
               progress=progress and sys.stderr.isatty(), **{k: np.asarray(v) for k, v in params.items()})
    if out is not None:
        with atomic_path(out) as tmp:
            ds.to_netcdf(tmp)
        typer.echo(f"wrote {out} ({' x '.join(f'{d}={n}' for d, n in ds.sizes.items())})")
    if plot is not None:
        from .plots import save_figure, sweep_figure

        save_figure(sweep_figure(ds, plot_var, plot_x, plot_y), plot)
        typer.echo(f"wrote {plot}")


def main(argv: list[str] | None = None) -> int:
    """Entry point: run the app, turning every user error into one line and exit code 2."""
    args = list(sys.argv[1:] if argv is None else argv)
    if not args:
        args = ["--help"]
    try:
        app(args=args, prog_name="bendpam", standalone_mode=False)
    except typer.Exit as exc:
        return exc.exit_code
    except typer.Abort:
        typer.echo("bendpam: aborted", err=True)
        return 1
    except _ClickException as exc:
        typer.echo(f"bendpam: error: {exc.format_message()}", err=True)
        return 2
    except (UserError, ValueError, FileNotFoundError, PermissionError, IsADirectoryError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        typer.echo(f"bendpam: error: {msg}", err=True)
        return 2
    except OSError as exc:
        typer.echo(f"bendpam: error: {exc.strerror or exc}: {exc.filename or ''}".rstrip(": "), err=True)
        return 2
    return 0


def _register_extensions() -> None:
    from .cli_design import register as register_design
    from .cli_report import register as register_report

    register_report(app)
    register_design(app)


_register_extensions()

if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
