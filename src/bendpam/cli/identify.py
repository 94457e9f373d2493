"""``bendpam fit`` and ``bendpam fit-material``: identification from processed tests."""

# no ``from __future__ import annotations``: Typer reads the annotations of the commands as objects (start-up)

import json
from pathlib import Path
from typing import Annotated, Optional

import typer

from bendpam.cli.app import app
from bendpam.cli.options import (
    ActuatorOpt,
    FigureFormatOpt,
    ForceUncertaintyOpt,
    ModelOpt,
    PresetOpt,
    PressureForceUncertaintyOpt,
    PressureUncertaintyOpt,
    QuietOpt,
    UserError,
    ZeroUncertaintyOpt,
    echo_wrote,
    load_actuator,
    model_name,
    output_set,
    positive,
)

GaugeOpt = Annotated[Optional[float], typer.Option("--gauge-length-mm", help="Tension specimen gauge length (mm).")]
AreaOpt = Annotated[Optional[float], typer.Option("--area-mm2", help="Tension specimen cross-section (mm^2).")]
WidthOpt = Annotated[Optional[float], typer.Option("--width-mm", help="Tension specimen width (mm).")]
ThickOpt = Annotated[Optional[float], typer.Option("--thickness-mm", help="Tension specimen thickness (mm).")]


RangeOpt = Optional[tuple[float, float]]


def tension_fit(path: Path, gauge_length_mm, area_mm2, width_mm, thickness_mm, stretch_range=None,
                admissible_range=(0.6, 1.6), format_file: Optional[Path] = None):
    """Read and fit a tension test from the command-line options: ``(TensionFit, TensionData)``."""
    from bendpam.identify.tension import fit_tension, tension_data
    from bendpam.lab import read_test

    positive("--gauge-length-mm", gauge_length_mm, "mm")
    positive("--area-mm2", area_mm2, "mm^2")
    positive("--width-mm", width_mm, "mm")
    positive("--thickness-mm", thickness_mm, "mm")
    if gauge_length_mm is None:
        raise UserError("the tension test needs the specimen's --gauge-length-mm")
    if area_mm2 is None:
        if width_mm is None or thickness_mm is None:
            raise UserError("the tension test needs --area-mm2, or --width-mm and --thickness-mm")
        area_mm2 = width_mm * thickness_mm
    td = tension_data(read_test(path, format_file=format_file), gauge_length_mm=gauge_length_mm, area_mm2=area_mm2,
                      stretch_range=stretch_range)
    tf = fit_tension(td.stretch, td.nominal_stress_kpa, admissible_range=admissible_range, source=td.source)
    return tf, td


@app.command()
def fit(
    processed_dir: Annotated[Path, typer.Argument(help="Output folder of `bendpam process`.", show_default=False)],
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = None,
    free: Annotated[str, typer.Option("--free", help="Parameters to identify, of alpha0, C10, C01, P_start, E_f, "
                                      "R0_start: 'alpha0 C10 C01' or 'alpha0,C10,C01'.")]
    = "alpha0,C10,C01",
    tension: Annotated[Optional[Path], typer.Option(
        "--tension", help="Bladder tension-test export: fitted together with the curves (one likelihood).")] = None,
    gauge_length_mm: GaugeOpt = None,
    area_mm2: AreaOpt = None,
    width_mm: WidthOpt = None,
    thickness_mm: ThickOpt = None,
    fit_range: Annotated[str, typer.Option("--fit-range", help="'developed' (loop developed) or 'all' points.")]
    = "developed",
    hysteresis: Annotated[
        bool, typer.Option("--hysteresis/--no-hysteresis",
                           help="Fit both branches with the loop model when the tests show a loop (default); "
                           "--no-hysteresis fits the mean curves, as the paper.")
    ] = True,
    hysteresis_law: Annotated[str, typer.Option("--hysteresis-law", help="Loop law: pi (Prandtl-Ishlinskii) or dahl.")]
    = "pi",
    admissible_range: Annotated[RangeOpt, typer.Option(
        "--admissible-range", help="Stretches LO HI the bladder material must be physical over besides the "
        "tested ones (the range it will predict).")] = (0.6, 1.6),
    force_uncertainty_pct: ForceUncertaintyOpt = 0.0,
    pressure_uncertainty_kpa: PressureUncertaintyOpt = 0.0,
    zero_uncertainty_n: ZeroUncertaintyOpt = None,
    pressure_force_uncertainty_n_per_kpa: PressureForceUncertaintyOpt = None,
    out: Annotated[Optional[Path], typer.Option("--out", help="Output folder.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print fit.json to stdout.")] = False,
    fig_format: FigureFormatOpt = None,
    quiet: QuietOpt = False,
    figure: Annotated[bool, typer.Option("--figure/--no-figure", help="Draw figure7 (default).")] = True,
):
    """Identify model parameters (alpha0, C10, C01, ...) from processed cyclic tests (section 3.4)."""
    from bendpam.identify.fitting import fit as run_fit
    from bendpam.identify.uncertainty import Instrument
    from bendpam.infra.progress import Progress
    from bendpam.lab.processing import load_processed

    if out is None:
        raise UserError("give an output folder with --out OUTDIR")
    fig_name = f"figure7.{fig_format.value if fig_format is not None else 'png'}"
    act = load_actuator(preset, actuator, model)
    # the identification reports no steps: the stage it is in and the time taken
    with Progress(None, "fit (reading)", quiet=quiet) as bar:
        data = load_processed(processed_dir)
        tfit, tdata = tension_fit(tension, gauge_length_mm, area_mm2, width_mm, thickness_mm,
                                  admissible_range=admissible_range) if tension else (None, None)
        bar.advance(0, description="fit (identifying)")
        res = run_fit(data, act, model_name(model), free=free, tension=tfit, tension_data=tdata,
                      fit_range=fit_range, hysteresis="auto" if hysteresis else None, hysteresis_law=hysteresis_law,
                      admissible_range=admissible_range,
                      instrument=Instrument(force_uncertainty_pct, pressure_uncertainty_kpa, zero_uncertainty_n,
                                            pressure_force_uncertainty_n_per_kpa))
        bar.advance(0, description="fit (writing)")
        with output_set(out, [processed_dir, actuator, tension]) as o:
            res.save(o.staging, processed=Path(processed_dir).resolve().name,
                     extra={"tension": tfit.to_dict()} if tfit is not None else None)
            if figure:  # matplotlib is imported only when a figure is drawn
                from bendpam.present.figures import figure7, save_figure

                save_figure(figure7(data, res), o.path(fig_name))
        bar.advance(0, description="fit")
    if as_json:
        typer.echo((out / "fit.json").read_text(encoding="utf-8"))
        return
    typer.echo(str(res))
    echo_wrote(f"wrote {out}/ (fit.json, fitted_actuator.toml{', ' + fig_name if figure else ''})")


@app.command("fit-material")
def fit_material(
    tension_file: Annotated[Path, typer.Argument(help="Uniaxial tension export of the bladder.", show_default=False)],
    gauge_length_mm: GaugeOpt = None,
    area_mm2: AreaOpt = None,
    width_mm: WidthOpt = None,
    thickness_mm: ThickOpt = None,
    stretch_range: Annotated[RangeOpt, typer.Option(
        "--stretch-range", help="Fit only the points with stretch in LO HI (default: the whole loading branch).")]
    = None,
    admissible_range: Annotated[RangeOpt, typer.Option(
        "--admissible-range", help="Stretches LO HI the constants must be physical over besides the data's.")]
    = (0.6, 1.6),
    out: Annotated[Optional[Path], typer.Option("--out", help="Write tension_fit.json here (a folder).")] = None,
    format_file: Annotated[Optional[Path], typer.Option(
        "--format-file", metavar="PATH",
        help="Read the tension export by this format declaration (TOML; docs/formats.md), with no detection.")]
    = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the result as JSON.")] = False,
):
    """Fit Mooney-Rivlin C10, C01 to a uniaxial tension test of the bladder material."""
    if not tension_file.exists():
        raise UserError(f"{tension_file}: no such file")
    tf, _ = tension_fit(tension_file, gauge_length_mm, area_mm2, width_mm, thickness_mm, stretch_range,
                        admissible_range, format_file)
    text = json.dumps(tf.to_dict(), indent=2, allow_nan=False)
    if out is not None:
        with output_set(out, [tension_file]) as o:
            o.write_text("tension_fit.json", text)
    if as_json:
        typer.echo(text)
        return
    typer.echo(f"C10 = {tf.C10_kpa:.1f} ± {tf.se_C10_kpa:.1f} kPa, C01 = {tf.C01_kpa:.1f} ± {tf.se_C01_kpa:.1f} kPa "
               f"(initial shear modulus {tf.shear_modulus_kpa:.1f} ± {tf.se_shear_modulus_kpa:.1f} kPa, correlation "
               f"{tf.correlation:+.3f}, RMSE {tf.rmse_kpa:.2f} kPa, {tf.n_points} points, stretch "
               f"{tf.stretch_min:.3f} to {tf.stretch_max:.3f})")
    typer.echo(tf.identifiable)
