"""``bendpam predict``, ``curve``, ``stresses``, ``actuator`` and ``demo``."""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Annotated, Optional

import numpy as np
import typer

from .app import app
from .options import (
    ActuatorOpt,
    Model,
    ModelOpt,
    MultiValueCommand,
    PresetOpt,
    PressureOpt,
    UserError,
    fmt_num,
    format_prediction_table,
    load_actuator,
    model_name,
    output_file,
    pressures_kpa,
)
from .options import pressure_kpa as checked_pressure

FIGURE_SUFFIXES = {".png", ".pdf", ".svg"}


@app.command(cls=MultiValueCommand)
def predict(
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
    from ..atomic import json_safe
    from ..law import MomentLaw
    from ..predict import prediction_table

    act = load_actuator(preset, actuator, model)
    P = pressures_kpa(pressure_kpa)
    mname = model_name(model)
    df = prediction_table(act, P, mname)
    br = MomentLaw.of(act, mname).free_branch()
    loop = _loop_model(actuator, loop_law, loop_a0_nmm, loop_a1_nmm_per_kpa, loop_angle_deg) if cycle else None
    cycles = None
    if loop is not None:
        from ..hysteresis import predict_cycle

        cycles = [predict_cycle(act, loop, p, mname) for p in P]
    if as_json:
        obj = {
            "model": mname,
            "actuator": act.to_dict() | act.derived(),
            "max_equilibrium_pressure_kpa": br.max_pressure_kpa,
            "branch_end": br.kind,
            "units": {"pressure_kpa": "kPa", "blocked_moment_nmm": "N*mm", "free_curvature_per_mm": "1/mm",
                      "free_angle_deg": "deg"},
            "results": [
                {
                    "pressure_kpa": r.pressure_kpa,
                    "blocked_moment_nmm": r.blocked_moment_nmm,
                    "free_curvature_per_mm": r.free_curvature_per_mm,
                    "free_angle_deg": r.free_angle_deg,
                    "note": r.note or None,
                    **({"cycle": _cycle_json(cycles[i])} if cycles is not None else {}),
                }
                for i, r in enumerate(df.itertuples())
            ],
            **({"hysteresis": loop.to_dict()} if loop is not None else {}),
        }
        typer.echo(json.dumps(json_safe(obj), indent=2, allow_nan=False))
        return
    typer.echo(format_prediction_table(df, f"{act.name or act.kind} — {mname.replace('_', '-')} model"))
    if math.isfinite(br.max_pressure_kpa):
        typer.echo(f"highest pressure with a free-bending equilibrium: {br.max_pressure_kpa:.4g} kPa ({br.kind})")
    if cycles is not None and loop is not None:
        typer.echo(f"\nloop ({loop.law}, a0 = {loop.a0_nmm:g} N·mm, a1 = {loop.a1_nmm_per_kpa:g} N·mm/kPa, "
                   f"angle {loop.theta_h_deg:g} deg): free-bending cycle blocked -> free -> blocked")
        typer.echo(f"{'P (kPa)':>8}  {'k_free,unloading (1/mm)':>24}  {'energy-loss ratio':>18}  note")
        for c in cycles:
            typer.echo(f"{c.pressure_kpa:8.4g}  {fmt_num(c.free_curvature_per_mm, '24.5f')}  "
                       f"{fmt_num(100 * c.energy_loss_ratio, '17.2f')}%  {c.note}")


def _loop_model(actuator_file, law, a0, a1_per_kpa, angle):
    """Loop parameters for --cycle: the actuator file's [hysteresis] table, overridden by --loop-* options."""
    from ..hysteresis import LoopModel

    base = LoopModel.from_toml(actuator_file) if actuator_file is not None else None
    given = {k: v for k, v in (("law", law), ("a0_nmm", a0), ("theta_h_deg", angle),
                               ("a1_nmm_per_kpa", a1_per_kpa)) if v is not None}
    if base is None and not {"a0_nmm", "a1_nmm_per_kpa"} & set(given):
        raise UserError("--cycle needs loop parameters: an --actuator file with a [hysteresis] table "
                        "(bendpam fit --hysteresis writes one) or --loop-a0-nmm / --loop-a1-nmm-per-kpa")
    d = (base.to_dict() if base is not None else {}) | given
    return LoopModel.from_dict(d, source="loop parameters")


def _cycle_json(c) -> dict:
    return {
        "free_curvature_unloading_per_mm": c.free_curvature_per_mm,
        "energy_loss_ratio": c.energy_loss_ratio,
        "curvature_per_mm": [float(x) for x in c.curvature_per_mm[::10]],
        "loading_nmm": [float(x) for x in c.loading_nmm[::10]],
        "unloading_nmm": [float(x) for x in c.unloading_nmm[::10]],
        "note": c.note or None,
    }


@app.command(cls=MultiValueCommand)
def curve(
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = Model.energy,
    pressure_kpa: PressureOpt = None,
    out: Annotated[
        Optional[Path], typer.Option("--out", help="Output FILE.csv, or a figure FILE.png/.pdf/.svg.")] = None,
    k_max: Annotated[
        Optional[float],
        typer.Option("--k-max", help="End of the curvature range (1/mm, magnitude along the bending direction); "
                     "default: 15% past free bending."),
    ] = None,
    points: Annotated[int, typer.Option("--points", min=2, max=100000, help="Curvature points per curve.")] = 200,
):
    """Moment-curvature curves M(P, k') as CSV or a figure."""
    if out is None:
        raise UserError("give an output file with --out FILE.csv or --out FILE.png")
    suffix = out.suffix.lower()
    if suffix not in {".csv"} | FIGURE_SUFFIXES:
        raise UserError(f"--out {str(out)!r}: unknown format {suffix or '(none)'}; use .csv, .png, .pdf or .svg")
    act = load_actuator(preset, actuator, model)
    P = np.asarray(pressures_kpa(pressure_kpa))
    if P.size * points > 10_000_000:
        raise UserError(f"--pressure-kpa x --points = {P.size * points} curve points; at most 10000000")
    mname = model_name(model)
    from ..plots import moment_curves, plot_moment_curvature, save_figure

    with output_file(out, [actuator]) as f:
        if suffix == ".csv":
            k, M = moment_curves(act, P, mname, k_max, points)
            rows = ["pressure_kpa,curvature_per_mm,moment_nmm"]
            for i, p in enumerate(P):
                rows.extend(f"{p:.10g},{kk:.12g},{mm:.12g}" for kk, mm in zip(k, M[i], strict=True))
            f.write_text("\n".join(rows) + "\n")
        else:
            import matplotlib.pyplot as plt

            fig, ax = plt.subplots(figsize=(6.5, 4.5))
            plot_moment_curvature(ax, act, P, mname, k_max, points)
            fig.tight_layout()
            save_figure(fig, f.path)
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
    from ..predict import internal_stresses

    act = load_actuator(preset, actuator, Model.force_balance)
    pressure_kpa = checked_pressure(pressure_kpa)
    if out is None:
        raise UserError("give an output file with --out FILE.png (figure), FILE.nc or FILE.csv (data)")
    suffix = out.suffix.lower()
    if suffix not in FIGURE_SUFFIXES | {".nc", ".csv"}:
        raise UserError(f"--out {str(out)!r}: unknown format {suffix or '(none)'}; use .png, .pdf, .svg, .nc or .csv")
    with output_file(out, [actuator]) as f:
        if suffix in FIGURE_SUFFIXES:
            from ..plots import plot_internal_stresses, save_figure

            save_figure(plot_internal_stresses(act, pressure_kpa, curvature), f.path)
        elif suffix == ".nc":
            internal_stresses(act, pressure_kpa, curvature).to_netcdf(f.path)
        else:
            f.write_text(internal_stresses(act, pressure_kpa, curvature).to_dataframe().to_csv())
    typer.echo(f"wrote {out}")


@app.command("actuator")
def actuator_cmd(
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = Model.energy,
    out: Annotated[Optional[Path], typer.Option("--out", help="Write the actuator as TOML here.")] = None,
):
    """Show an actuator (TOML, derived values, lock-up limits) or save it as an editable TOML file."""
    from ..braid import curvature_limits

    act = load_actuator(preset, actuator, model)
    text = act.to_toml()
    if out is not None:
        with output_file(out, [actuator]) as f:
            f.write_text(text)
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
    out: Annotated[Path, typer.Option("--out", help="Moment-curvature figure to write.")] = Path(
        "bendpam-demo/moment-curvature.png"),
):
    """Predictions for the paper's BE-PAM and BC-PAM with both models, and a moment-curvature figure."""
    from .. import presets
    from ..law import MomentLaw
    from ..plots import demo_figure, save_figure
    from ..predict import prediction_table

    t0 = time.perf_counter()
    cases = [("be-pam", [100, 125, 150, 175, 200]), ("bc-pam", [40, 60, 80, 100, 120, 140])]
    items = []
    for name, P in cases:
        for mname in ("energy", "force_balance"):
            act = presets.get(name, mname)
            df = prediction_table(act, P, mname)
            typer.echo(format_prediction_table(df, f"\n{act.name} — {mname.replace('_', '-')} model"))
            br = MomentLaw.of(act, mname).free_branch()
            if br.kind == "fold":
                typer.echo(f"fold: no free-bending equilibrium above {br.max_pressure_kpa:.4g} kPa")
            items.append((act, np.asarray(P, dtype=float), mname))
    out.parent.mkdir(parents=True, exist_ok=True)
    with output_file(out) as f:
        save_figure(demo_figure(items), f.path)
    typer.echo(f"\nwrote {out}  ({time.perf_counter() - t0:.1f} s)")
