"""``bendpam export mujoco``: an actuator's finger or gripper, or the soft hand, as a MuJoCo model (parsing and
printing only).

The work is :func:`bendpam.export.mujoco_model` (:func:`~bendpam.export.mjcf.hand_model`) and
:func:`bendpam.export.validation.validate` (:func:`~bendpam.export.validation.validate_hand`).
"""

# no ``from __future__ import annotations``: Typer reads the annotations of the commands as objects (start-up)

import math
from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from bendpam.cli.app import app
from bendpam.cli.options import (
    ActuatorOpt,
    BendpamCommand,
    ModelOpt,
    PresetOpt,
    PressureOpt,
    UserError,
    echo_wrote,
    load_actuator,
    model_for,
    model_name,
    output_set,
    parse_values,
    pressures_kpa,
    print_json,
)

__all__ = ["export_app"]

export_app = typer.Typer(no_args_is_help=True, rich_markup_mode=None,
                         help="Export an actuator's finger or gripper, or the soft hand, to a simulator (MuJoCo).")
app.add_typer(export_app, name="export")


@export_app.command("mujoco", cls=BendpamCommand)
def mujoco_cmd(
    out: Annotated[Path, typer.Option("--out", help="Output folder: DEVICE.xml (MJCF), one DEVICE-sphere-Dmm.xml "
                                      "per sphere, actuator.toml (not for a --hand file's hand), export.json.")],
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = None,
    device: Annotated[str, typer.Option("--device", help="finger (one finger), gripper (three fingers on a "
                                        "palm) or hand (the soft humanoid hand of `bendpam hand`).")] = "finger",
    hand_file: Annotated[Optional[Path], typer.Option("--hand", help="Hand description (TOML, as `bendpam hand` "
                                                      "takes; --device hand); default: the documented default "
                                                      "hand with --preset/--actuator (BE-PAM) in every part.")] = None,
    palm_roll_deg: Annotated[Optional[float], typer.Option("--palm-roll-deg", help="Fix the hand's palm roll at "
                                                           "this angle, 0-180 deg (default: a position-controlled "
                                                           "hinge).")] = None,
    segments: Annotated[Optional[int], typer.Option("--segments", help="Hinges per actuator, 2-200 (default: "
                                                    "from --tip-error-pct).")] = None,
    tip_error_pct: Annotated[float, typer.Option("--tip-error-pct", help="Tip-error target against bendpam's rod, "
                                                 "% of L0 (default 1).")] = 1.0,
    spheres: Annotated[Optional[list[str]], typer.Option("--spheres", help="Sphere diameter(s) of the grasp "
                                                         "tests, mm: '80 200', '80,200' or '80:280:6' "
                                                         "(gripper).")] = None,
    pressure_kpa: PressureOpt = None,
    l0_mm: Annotated[Optional[float], typer.Option("--l0-mm", help="Active length L0 (mm); default: the "
                                                   "actuator's.")] = None,
    validate: Annotated[bool, typer.Option("--validate/--no-validate", help="Run the quasi-static MuJoCo checks "
                                           "against bendpam (a few seconds).")] = True,
    as_json: Annotated[bool, typer.Option("--json", help="Print export.json's content.")] = False,
):
    """An MJCF model of a bending-PAM finger, gripper or soft hand: hinge chains driven by the moment law.

    Each actuator is a chain of hinges (their number from the tip-error target), with masses from
    its geometry and contact boxes; bendpam.sim.mujoco applies the moment law at every step with
    the pressure as the control input (the hand: one pressure per part, HandController). Example:
    bendpam export mujoco --preset be-pam --device gripper --l0-mm 130 --spheres 200 --out be-gripper
    """
    from bendpam.export.mjcf import DEVICES
    from bendpam.export.validation import mujoco

    if device not in DEVICES:
        raise UserError(f"--device {device!r}: choose one of {', '.join(DEVICES)}")
    options = _hand_options(device, hand_file, palm_roll_deg, preset, actuator, model, l0_mm)
    act = load_actuator(preset, actuator, model) if device != "hand" or preset or actuator else None
    if l0_mm is not None and act is not None:  # (not for the hand: _hand_options refused it)
        if not (math.isfinite(l0_mm) and l0_mm > 0):
            raise UserError(f"--l0-mm: {l0_mm:g} mm must be a positive length")
        act = act.replace(L0_mm=float(l0_mm))
    if segments is not None and not 2 <= segments <= 200:
        raise UserError(f"--segments: {segments} is outside the allowed range [2, 200]")
    if not (math.isfinite(tip_error_pct) and 0 < tip_error_pct <= 50):
        raise UserError(f"--tip-error-pct: {tip_error_pct:g} is outside the allowed range (0, 50] % of L0")
    D = parse_values(spheres, "--spheres")
    for d in D:
        if not 0 < d <= 2000:
            raise UserError(f"--spheres: {d:g} mm is outside the allowed range (0, 2000] mm")
    if D and device != "gripper":
        raise UserError("--spheres: the spheres are objects of the gripper's grasp tests; give --device gripper")
    P = pressures_kpa(pressure_kpa, None) if pressure_kpa else None
    loop = None
    if actuator is not None:  # a fit's [hysteresis] table goes along, for the simulation
        from bendpam.physics.hysteresis import LoopModel

        loop = LoopModel.from_toml(actuator)
    law_model = model_for(act, model) if act is not None else model_name(model)  # (the default hand: --model's)
    res = mujoco(act, device, law_model=law_model, segments=segments, tip_error_pct=tip_error_pct,
                 pressures_kpa=P, spheres_mm=D, validate=validate, loop=loop, **options)
    summary = res.to_dict()
    with output_set(out, [actuator, hand_file]) as o:
        for name, text in res.files().items():
            o.write_text(name, text)
    if as_json:
        print_json(summary)
        return
    _print_summary(summary)
    echo_wrote(f"wrote {out}/ ({', '.join(summary['files'])})")


def _hand_options(device: str, hand_file: Optional[Path], palm_roll_deg: Optional[float], preset, actuator, model,
                  l0_mm: Optional[float]) -> dict[str, Any]:
    """The hand's options of :func:`bendpam.export.mujoco` (none for the other devices)."""
    if device != "hand":
        if hand_file is not None or palm_roll_deg is not None:
            flag = "--hand" if hand_file is not None else "--palm-roll-deg"
            raise UserError(f"{flag}: an option of the hand; give --device hand")
        return {}
    if l0_mm is not None:
        raise UserError("--l0-mm: the hand's parts have their own lengths (set them in the --hand file)")
    if palm_roll_deg is not None and not (math.isfinite(palm_roll_deg) and 0 <= palm_roll_deg <= 180):
        raise UserError(f"--palm-roll-deg: {palm_roll_deg:g} is outside the allowed range [0, 180] deg")
    options: dict[str, Any] = {"palm_roll_deg": palm_roll_deg}
    if hand_file is not None:
        if preset is not None or actuator is not None or model is not None:
            raise UserError("--hand: the hand file names its actuators and model ([hand] actuator, model); "
                            "drop --preset/--actuator/--model")
        from bendpam.design.hand import Hand

        options["hand"] = Hand.from_toml(hand_file)
    return options


def _print_summary(s: dict[str, Any]) -> None:
    if s["device"] == "hand":
        _print_hand(s)
        return
    typer.echo(f"{s['device']} of {s['actuator']} ({s['model'].replace('_', '-')} model), L0 = {s['L0_mm']:g} mm: "
               f"{s['segments']} hinges of {s['segment_length_mm']:g} mm, {s['mass_per_actuator_g']:.1f} g per "
               "actuator, "
               f"time step {s['timestep_s']:g} s")
    typer.echo(f"discretisation: free-shape tip error {s['discretisation_tip_error_pct_of_length']:.3f} % of L0 "
               f"over {', '.join(f'{p:g}' for p in s['pressures_kpa'])} kPa")
    v = s.get("validation")
    if not v:
        return
    typer.echo(f"MuJoCo against bendpam (quasi-static): free-shape tip error "
               f"{v['free_shape_tip_error_pct_of_length']:.3f} % of L0, loaded tip error "
               f"{v['loaded_tip_error_pct_of_length']:.3f} % of L0")
    pull = v.get("pullout")
    if pull:
        err = "no grip in bendpam" if pull["error_pct"] is None else f"{pull['error_pct']:+.2f} %"
        typer.echo(f"pull-out of a {pull['diameter_mm']:g} mm sphere at {pull['pressure_kpa']:g} kPa: MuJoCo "
                   f"{pull['mujoco_grip_force_n']:.3f} N, bendpam {pull['bendpam_grip_force_n']:.3f} N ({err})")
    for note in v.get("notes") or []:
        typer.echo(f"note: {note}")


def _print_hand(s: dict[str, Any]) -> None:
    roll = "a position-controlled hinge" if s["palm_roll_deg"] is None else f"fixed at {s['palm_roll_deg']:g}°"
    typer.echo(f"soft hand ({s['model'].replace('_', '-')} model): palm roll {roll}, time step {s['timestep_s']:g} s")
    for c, n in s["segments"].items():
        typer.echo(f"  {c:<15} {s['length_mm'][c]:6g} mm  {n:3d} hinges  {s['mass_g'][c]:5.1f} g  discretisation "
                   f"{s['discretisation_tip_error_pct_of_length'][c]:.3f} % of its length")
    v = s.get("validation")
    if not v:
        return
    tips = ", ".join(f"{t} {e:.3f}" for t, e in v["hand_tip_errors_pct_of_length"].items())
    typer.echo(f"MuJoCo against bendpam's unloaded hand (quasi-static, {len(v['hand_tips']) // 5} poses over "
               f"{', '.join(f'{p:g}' for p in s['pressures_kpa'])} kPa): tip error "
               f"{v['hand_tip_error_pct_of_length']:.3f} % of the part's length at most ({tips})")
    for note in v.get("notes") or []:
        typer.echo(f"note: {note}")
