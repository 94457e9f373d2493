"""``bendpam design``: inverse design of an actuator from targets (parsing and printing only).

The work is :func:`bendpam.design.inverse.design_actuator`.
"""

# no ``from __future__ import annotations``: Typer reads the annotations of the commands as objects (start-up)

from pathlib import Path
from typing import Annotated, Optional

import typer

from bendpam.cli.app import app
from bendpam.cli.options import (
    ActuatorOpt,
    FigureFormatOpt,
    ModelOpt,
    PresetOpt,
    UserError,
    echo_wrote,
    load_actuator,
    model_for,
    output_set,
    pressure_kpa,
    pressures_kpa,
)

__all__: list[str] = []  # the command registers itself on the app (bendpam.cli.app); nothing to import

_TARGET_HELP = (
    "A target NAME=VALUE@P, NAME>=VALUE@P or NAME<=VALUE@P (P in kPa; repeat for more). NAME: blocked_moment_nmm, "
    "free_curvature_per_mm, free_angle_deg, tangent_stiffness_nmm2 (|dM/dk'| at free bending), "
    "blocked_stiffness_nmm2 (at k'=0), blocked_tip_force_n (a finger's tip held straight), frame_stress_mpa, or "
    "max_pressure_kpa (fold or lock-up pressure, no @). Targets compare MAGNITUDES: a BC-PAM's negative blocked "
    "moment or curvature is met by a positive value."
)
_VARY_HELP = ("A design variable NAME=LOW:HIGH, an actuator parameter (alpha0_deg, R0_mm, t0_mm, L0_mm, "
              "frame_thickness_mm, frame_width_mm, frame_modulus_mpa, C10_kpa, C01_kpa, P_start_kpa, R0_start_mm); "
              "repeat for more.")


@app.command("design")
def design_cmd(
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = None,
    target: Annotated[Optional[list[str]], typer.Option("--target", metavar="NAME=VALUE@P", help=_TARGET_HELP)]
    = None,
    vary: Annotated[Optional[list[str]], typer.Option("--vary", metavar="NAME=LOW:HIGH", help=_VARY_HELP)] = None,
    max_pressure_kpa: Annotated[
        Optional[float], typer.Option("--max-pressure-kpa", help="Operating pressure (kPa): every margin must hold "
                                      "up to it (default: the highest target pressure).")] = None,
    min_margin: Annotated[float, typer.Option("--min-margin", help="Safety factor required of every margin "
                                              "(frame, buckling, lock-up, bladder stretch, fold pressure), >= 1.")]
    = 1.0,
    n_coarse: Annotated[int, typer.Option("--n-coarse", min=16, max=2**20,
                                          help="Designs in the coarse map (a power of 2).")] = 2048,
    starts: Annotated[int, typer.Option("--starts", min=1, max=64, help="Local searches from the best designs.")] = 4,
    pareto: Annotated[Optional[bool], typer.Option("--pareto/--no-pareto",
                                                   help="Pareto front of two targets (default: with two).")] = None,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the quasi-random coarse map.")] = 0,
    scheduler: Annotated[Optional[str], typer.Option("--scheduler", help="Dask scheduler address for the "
                                                     "coarse map (then a grid).")] = None,
    out: Annotated[Optional[Path], typer.Option("--out", help="Output folder: design.json, design.toml, "
                                                "coarse_map.csv, pareto.csv, figures.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print design.json's content.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", help="No progress report.")] = False,
    fig_format: FigureFormatOpt = None,
):
    """Inverse design: actuator parameters within ranges that meet targets at pressures, with safety margins.

    Example: bendpam design --preset be-pam --target blocked_moment_nmm=400@200 --target free_angle_deg=90@200
    --vary alpha0_deg=60:80 --vary R0_mm=6:12 --vary t0_mm=1:3 --max-pressure-kpa 250 --min-margin 1.5 --out design/
    """
    from bendpam.design.inverse import design_actuator
    from bendpam.design.targets import parse_targets, parse_variables
    from bendpam.infra.outputs import to_json

    if fig_format is not None and out is None:
        raise UserError(f"--format {fig_format.value}: the figures are written into --out; give --out DIR")
    if not target:
        raise UserError("give at least one --target, e.g. --target blocked_moment_nmm=400@200")
    if not vary:
        raise UserError("give at least one --vary range, e.g. --vary alpha0_deg=60:80")
    targets = parse_targets(target, "--target")
    at = [repr(t.pressure_kpa) for t in targets if t.pressure_kpa is not None]
    if at:  # the pressures after '@' are kPa: the same refusal of MPa-looking values as --pressure-kpa
        pressures_kpa(at, None, "--target ...@P")
    if scheduler is not None:
        from bendpam.infra.scheduler import parse_scheduler_address

        scheduler = parse_scheduler_address(scheduler, name="--scheduler")
    act = load_actuator(preset, actuator, model)
    variables = parse_variables(act, vary, "--vary")
    if max_pressure_kpa is not None and not max_pressure_kpa > 0:
        raise UserError(f"--max-pressure-kpa: {max_pressure_kpa:g} kPa must be > 0")
    if max_pressure_kpa is not None:
        pressure_kpa(max_pressure_kpa, "--max-pressure-kpa")
    if not min_margin >= 1.0:
        raise UserError(f"--min-margin: {min_margin:g} must be a safety factor >= 1")
    if pareto and len(targets) != 2:
        raise UserError(f"--pareto needs exactly two --target; {len(targets)} given")
    res = design_actuator(act, targets, variables, model=model_for(act, model), max_pressure_kpa=max_pressure_kpa,
                          min_margin=min_margin, n_coarse=n_coarse, n_starts=starts, pareto=pareto,
                          scheduler=scheduler, seed=seed, progress=not quiet)
    if out is not None:
        with output_set(out, [actuator]) as o:
            files = res.save(o.staging, figure_format=fig_format.value if fig_format is not None else "png")
    if as_json:
        typer.echo(to_json(res.to_dict()), nl=False)
        return
    typer.echo(res.summary())
    if out is not None:
        echo_wrote(f"wrote {out}/ ({', '.join(files)})")
