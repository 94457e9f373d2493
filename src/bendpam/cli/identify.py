"""``bendpam fit`` and ``bendpam fit-material``: identification from processed tests."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated, Optional

import typer

from .app import app
from .options import (
    ActuatorOpt,
    Model,
    ModelOpt,
    PresetOpt,
    UserError,
    load_actuator,
    model_name,
    output_set,
    positive,
)

GaugeOpt = Annotated[Optional[float], typer.Option("--gauge-length-mm", help="Tension specimen gauge length (mm).")]
AreaOpt = Annotated[Optional[float], typer.Option("--area-mm2", help="Tension specimen cross-section (mm^2).")]
WidthOpt = Annotated[Optional[float], typer.Option("--width-mm", help="Tension specimen width (mm).")]
ThickOpt = Annotated[Optional[float], typer.Option("--thickness-mm", help="Tension specimen thickness (mm).")]


def tension_fit(path: Path, gauge_length_mm, area_mm2, width_mm, thickness_mm):
    """Read and fit a tension test from the command-line options."""
    from ..lab import read_test
    from ..tension import tension_from_test

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
    return tension_from_test(read_test(path), gauge_length_mm=gauge_length_mm, area_mm2=area_mm2)


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
    from ..identify import fit as run_fit
    from ..lab.processing import load_processed
    from ..plots import figure7, save_figure

    if out is None:
        raise UserError("give an output folder with --out OUTDIR")
    act = load_actuator(preset, actuator, model)
    data = load_processed(processed_dir)
    tfit = tension_fit(tension, gauge_length_mm, area_mm2, width_mm, thickness_mm) if tension else None
    res = run_fit(data, act, model_name(model), free=free, tension=tfit, fit_range=fit_range,
                  hysteresis=hysteresis_law if hysteresis else None)
    with output_set(out, [processed_dir, actuator, tension]) as o:
        res.save(o.staging)
        if tfit is not None:
            obj = json.loads((o.staging / "fit.json").read_text())
            obj["tension"] = tfit.to_dict()
            o.write_json("fit.json", obj)
        save_figure(figure7(data, res), o.path("figure7.png"))
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
    tf = tension_fit(tension_file, gauge_length_mm, area_mm2, width_mm, thickness_mm)
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
