"""``bendpam predict``, ``curve``, ``stresses``, ``actuator`` and ``demo``."""

# no ``from __future__ import annotations``: Typer reads the annotations of the commands as objects (start-up)

import math
import time
from pathlib import Path
from typing import Annotated, Optional

import typer

from bendpam.cli.app import app
from bendpam.cli.options import (
    FIGURE_FORMATS,
    ActuatorOpt,
    FigureFormatOpt,
    Model,
    ModelOpt,
    MultiValueCommand,
    PresetOpt,
    PressureOpt,
    UserError,
    echo_wrote,
    figure_format,
    fmt_num,
    format_prediction_table,
    load_actuator,
    model_for,
    output_file,
    output_format,
    pressures_kpa,
    print_json,
    table_rows,
)
from bendpam.cli.options import pressure_kpa as checked_pressure


def _data_or_figure(out: Path, fmt, data_formats: tuple[str, ...]) -> str:
    """The format of an --out that may be data (``data_formats``) or a figure (--format png/pdf/svg)."""
    kind = output_format(out, fmt, (*data_formats, *FIGURE_FORMATS), option="--out")
    assert kind is not None  # out is given
    return kind


@app.command(cls=MultiValueCommand)
def predict(
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = None,
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
    from bendpam.physics.law import MomentLaw
    from bendpam.physics.limits import OUTPUTS as LIMIT_OUTPUTS
    from bendpam.predict import prediction_columns  # (a few rows: no pandas DataFrame)

    act = load_actuator(preset, actuator, model)
    P = pressures_kpa(pressure_kpa)
    mname = model_for(act, model)
    df = prediction_columns(act, P, mname)
    br = MomentLaw.of(act, mname).free_branch()
    loop = _loop_model(actuator, loop_law, loop_a0_nmm, loop_a1_nmm_per_kpa, loop_angle_deg) if cycle else None
    cycles = None
    if loop is not None:
        from bendpam.physics.hysteresis import predict_cycles

        # the same computation as the loss ratios and loop metrics of `bendpam fit` (one function)
        cycles = predict_cycles(act, loop, P, mname)
    if as_json:
        oop = _out_of_plane(act, P, df["free_curvature_per_mm"], mname)
        obj = {
            "model": mname,
            "actuator": act.to_dict() | act.derived(),
            "max_equilibrium_pressure_kpa": br.max_pressure_kpa,
            "branch_end": br.kind,
            "units": {"pressure_kpa": "kPa", "blocked_moment_nmm": "N*mm", "free_curvature_per_mm": "1/mm",
                      "free_angle_deg": "deg", **{k: u for k, (u, _) in LIMIT_OUTPUTS.items()},
                      "lateral_stiffness_nmm2": "N*mm^2", "torsional_stiffness_nmm2_per_rad": "N*mm^2/rad",
                      "torsion_lock_torque_nmm": "N*mm"},
            "results": [
                {
                    "pressure_kpa": r.pressure_kpa,
                    "blocked_moment_nmm": r.blocked_moment_nmm,
                    "free_curvature_per_mm": r.free_curvature_per_mm,
                    "free_angle_deg": r.free_angle_deg,
                    **{k: getattr(r, k) for k in LIMIT_OUTPUTS},
                    **{k: v[i] for k, v in oop.items()},
                    "note": r.note or None,
                    "limit_note": r.limit_note or None,
                    **({"cycle": _cycle_json(cycles[i])} if cycles is not None else {}),
                }
                for i, r in enumerate(table_rows(df))
            ],
            **({"hysteresis": loop.to_dict()} if loop is not None else {}),
        }
        print_json(obj)
        _warn_limits(df)
        return
    typer.echo(format_prediction_table(df, f"{act.name or act.kind} — {mname.replace('_', '-')} model"))
    if math.isfinite(br.max_pressure_kpa):
        typer.echo(f"highest pressure with a free-bending equilibrium: {br.max_pressure_kpa:.4g} kPa ({br.kind})")
    typer.echo("\n".join(_limits_table(df)))
    _warn_limits(df)
    if cycles is not None and loop is not None:
        typer.echo(f"\nloop ({loop.law}, a0 = {loop.a0_nmm:g} N·mm, a1 = {loop.a1_nmm_per_kpa:g} N·mm/kPa, "
                   f"angle {loop.theta_h_deg:g} deg): free-bending cycle blocked -> free -> blocked")
        typer.echo(f"{'P (kPa)':>8}  {'k_free,unloading (1/mm)':>24}  {'energy-loss ratio':>18}  note")
        for c in cycles:
            typer.echo(f"{c.pressure_kpa:8.4g}  {fmt_num(c.free_curvature_per_mm, '24.5f')}  "
                       f"{fmt_num(100 * c.energy_loss_ratio, '17.2f')}%  {c.note}")


def _out_of_plane(act, P, k_free, mname) -> dict[str, list]:
    """Lateral and torsional stiffness and the braid's lock torque at each free curvature (None without one)."""
    import numpy as np

    from bendpam.physics.spatial import spatial_stiffness

    keys = ("lateral_stiffness_nmm2", "torsional_stiffness_nmm2_per_rad", "torsion_lock_torque_nmm")
    out: dict[str, list] = {k: [None] * len(P) for k in keys}
    k_free = np.asarray(k_free, dtype=float)
    ok = np.flatnonzero(np.isfinite(k_free))
    if ok.size:
        st = spatial_stiffness(act, np.asarray(P, dtype=float)[ok], k_free[ok], model=mname)
        for k in keys:
            for j, v in zip(ok, np.atleast_1d(getattr(st, k)), strict=True):
                out[k][j] = float(v)
    return out


def _loop_model(actuator_file, law, a0, a1_per_kpa, angle):
    """Loop parameters for --cycle: the actuator file's [hysteresis] table, overridden by --loop-* options."""
    from bendpam.physics.hysteresis import LoopModel

    base = LoopModel.from_toml(actuator_file) if actuator_file is not None else None
    given = {k: v for k, v in (("law", law), ("a0_nmm", a0), ("theta_h_deg", angle),
                               ("a1_nmm_per_kpa", a1_per_kpa)) if v is not None}
    if base is None and not {"a0_nmm", "a1_nmm_per_kpa"} & set(given):
        raise UserError("--cycle needs loop parameters: an --actuator file with a [hysteresis] table "
                        "(bendpam fit --hysteresis writes one) or --loop-a0-nmm / --loop-a1-nmm-per-kpa")
    d = (base.to_dict() if base is not None else {}) | given
    return LoopModel.from_dict(d, source="loop parameters")


def _margin(x, width: int) -> str:
    """A safety factor for the limits table: 2 decimals, ``inf`` (no demand or no limit), a dash for NaN."""
    x = float(x)
    return ("inf" if x == math.inf else fmt_num(x, f"{width}.2f")).rjust(width)


def _limits_table(df) -> list[str]:
    """The margins of the prediction table (:func:`bendpam.physics.limits`), one line per pressure."""
    lines = ["limits (safety factors, >= 1 within the limit; inf: no demand or no limit given)",
             f"{'P (kPa)':>8}  {'N_frame (N)':>11}  {'σ_frame (MPa)':>13}  {'strength':>8}  {'buckling':>8}  "
             f"{'lock-up':>8}  {'stretch':>7}  {'(max)':>6}  {'min':>6}"]
    for r in table_rows(df):
        lines.append(f"{r.pressure_kpa:8.4g}  {fmt_num(r.frame_axial_force_n, '11.2f')}  "
                     f"{fmt_num(r.frame_stress_mpa, '13.2f')}  {_margin(r.frame_strength_margin, 8)}  "
                     f"{_margin(r.buckling_margin, 8)}  {_margin(r.lockup_margin, 8)}  "
                     f"{_margin(r.bladder_stretch_margin, 7)}  {fmt_num(r.bladder_stretch_max, '6.3f')}  "
                     f"{_margin(r.min_margin, 6)}")
    return lines


def _warn_limits(df) -> None:
    """One ``bendpam: warning:`` line on stderr per limit a prediction is past."""
    for note in df["limit_note"]:
        for line in filter(None, str(note).split("; ")):
            typer.echo(f"bendpam: warning: past a limit: {line}", err=True)


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
    model: ModelOpt = None,
    pressure_kpa: PressureOpt = None,
    out: Annotated[
        Optional[Path], typer.Option("--out", help="Output FILE.csv, or a figure FILE.png/.pdf/.svg.")] = None,
    k_max: Annotated[
        Optional[float],
        typer.Option("--k-max", help="End of the curvature range (1/mm, magnitude along the bending direction); "
                     "default: 15% past free bending."),
    ] = None,
    points: Annotated[int, typer.Option("--points", min=2, max=100000, help="Curvature points per curve.")] = 200,
    fig_format: FigureFormatOpt = None,
):
    """Moment-curvature curves M(P, k') as CSV or a figure."""
    import numpy as np

    if out is None:
        raise UserError("give an output file with --out FILE.csv or --out FILE.png")
    kind = _data_or_figure(out, fig_format, ("csv",))
    act = load_actuator(preset, actuator, model)
    P = np.asarray(pressures_kpa(pressure_kpa))
    if P.size * points > 10_000_000:
        raise UserError(f"--pressure-kpa x --points = {P.size * points} curve points; at most 10000000")
    mname = model_for(act, model)
    from bendpam.present.figures import moment_curvature_figure, moment_curves, save_figure

    with output_file(out, [actuator]) as f:
        if kind == "csv":
            k, M = moment_curves(act, P, mname, k_max, points)
            rows = ["pressure_kpa,curvature_per_mm,moment_nmm"]
            for i, p in enumerate(P):
                rows.extend(f"{p:.10g},{kk:.12g},{mm:.12g}" for kk, mm in zip(k, M[i], strict=True))
            f.write_text("\n".join(rows) + "\n")
        else:
            save_figure(moment_curvature_figure(act, P, mname, k_max, points), f.path, format=kind)
    echo_wrote(f"wrote {out}")


@app.command()
def stresses(
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    pressure_kpa: Annotated[float, typer.Option("--pressure-kpa", help="Gauge pressure, kPa.")] = 200.0,
    curvature: Annotated[float, typer.Option("--curvature", help="Frame curvature k', 1/mm.")] = 0.0,
    out: Annotated[Optional[Path], typer.Option("--out", help="Figure (.png/.pdf/.svg) or data (.nc/.csv).")] = None,
    fig_format: FigureFormatOpt = None,
):
    """Force-balance internal stresses around the cross-section (eq 37-48)."""
    from bendpam.predict import internal_stresses

    act = load_actuator(preset, actuator, Model.force_balance)
    pressure_kpa = checked_pressure(pressure_kpa)
    if out is None:
        raise UserError("give an output file with --out FILE.png (figure), FILE.nc or FILE.csv (data)")
    kind = _data_or_figure(out, fig_format, ("nc", "csv"))
    with output_file(out, [actuator]) as f:
        if kind in FIGURE_FORMATS:
            from bendpam.present.figures import plot_internal_stresses, save_figure

            save_figure(plot_internal_stresses(act, pressure_kpa, curvature), f.path, format=kind)
        elif kind == "nc":
            internal_stresses(act, pressure_kpa, curvature).to_netcdf(f.path)
        else:
            f.write_text(internal_stresses(act, pressure_kpa, curvature).to_dataframe().to_csv())
    echo_wrote(f"wrote {out}")


@app.command("actuator")
def actuator_cmd(
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = None,
    out: Annotated[Optional[Path], typer.Option("--out", help="Write the actuator as TOML here.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object (parameters, derived values, "
                                          "curvature range) instead of TOML.")] = False,
):
    """Show an actuator (TOML, derived values, lock-up limits) or save it as an editable TOML file."""
    from bendpam.physics.braid import curvature_limits

    act = load_actuator(preset, actuator, model)
    text = act.to_toml()
    if out is not None:
        with output_file(out, [actuator]) as f:
            f.write_text(text)
        echo_wrote(f"wrote {out}")
        if not as_json:
            return
    lim = curvature_limits(act)
    if as_json:
        print_json({"actuator": act.to_dict(), "derived": act.derived(),
                    "curvature_range_per_mm": [lim.k_min, lim.k_max]})
        return
    typer.echo(text.rstrip())
    typer.echo("\n# derived")
    for k, v in act.derived().items():
        typer.echo(f"# {k} = {v:.6g}")
    typer.echo(f"# curvature range (braid lock-up) = [{lim.k_min:.6g}, {lim.k_max:.6g}] 1/mm")


@app.command()
def demo(
    out: Annotated[Optional[Path], typer.Option(
        "--out", help="Moment-curvature figure to write (.png, .pdf, .svg); default "
        "bendpam-demo/moment-curvature.png (or the --format's suffix).", show_default=False)] = None,
    fig_format: FigureFormatOpt = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object of the predictions instead of "
                                          "tables.")] = False,
):
    """Predictions for the paper's BE-PAM and BC-PAM with both models, and a moment-curvature figure."""
    import numpy as np

    from bendpam.physics import presets
    from bendpam.physics.law import MomentLaw
    from bendpam.predict import prediction_table
    from bendpam.present.figures import demo_figure, save_figure

    if out is None:
        out = Path(f"bendpam-demo/moment-curvature.{fig_format.value if fig_format is not None else 'png'}")
    fmt = figure_format(out, fig_format)
    t0 = time.perf_counter()
    cases = [("be-pam", [100, 125, 150, 175, 200]), ("bc-pam", [40, 60, 80, 100, 120, 140])]
    items, records = [], []
    for name, P in cases:
        for mname in ("energy", "force_balance"):
            act = presets.get(name, mname)
            df = prediction_table(act, P, mname)
            br = MomentLaw.of(act, mname).free_branch()
            if as_json:
                records.append({"actuator": act.name, "model": mname, "max_equilibrium_pressure_kpa":
                                br.max_pressure_kpa, "branch_end": br.kind, "results": [
                                    {k: (getattr(r, k) or None) if k == "note" else getattr(r, k) for k in (
                                        "pressure_kpa", "blocked_moment_nmm", "free_curvature_per_mm",
                                        "free_angle_deg", "note")} for r in df.itertuples()]})
                items.append((act, np.asarray(P, dtype=float), mname))
                continue
            typer.echo(format_prediction_table(df, f"\n{act.name} — {mname.replace('_', '-')} model"))
            if br.kind == "fold":
                typer.echo(f"fold: no free-bending equilibrium above {br.max_pressure_kpa:.4g} kPa")
            items.append((act, np.asarray(P, dtype=float), mname))
    out.parent.mkdir(parents=True, exist_ok=True)
    with output_file(out) as f:
        save_figure(demo_figure(items), f.path, format=fmt)
    if as_json:
        print_json({"predictions": records, "figure": str(out)})
        return
    echo_wrote(f"\nwrote {out}  ({time.perf_counter() - t0:.1f} s)")
