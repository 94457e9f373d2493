"""``bendpam finger``, ``bendpam grasp`` and ``bendpam wrist``: the design commands (issue 6).

``register(app)`` adds the three commands to the ``bendpam`` Typer app.  Each command parses its
options, calls :mod:`bendpam.design`, and prints a table or, with ``--json``, the results'
``to_dict()`` records inside one JSON object.

Multi-valued options (``--pressure-kpa``, ``--diameter-mm``, ``--direction-deg``) take values as
separate tokens (``--diameter-mm 80 120 160``), comma lists (``80,120,160``) or ranges
(``80:280:6``); several such options may follow each other.
"""

# no ``from __future__ import annotations``: Typer reads the annotations of the command functions.
import math
from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from bendpam.cli.options import (
    ActuatorOpt,
    FigureFormatOpt,
    ModelOpt,
    MultiValueCommand,
    PresetOpt,
    PressureOpt,
    QuietOpt,
    UserError,
    echo_wrote,
    figure_format,
    load_actuator,
    model_for,
    parse_values,
    pressures_kpa,
    print_json,
)
from bendpam.cli.options import fmt_num as _fmt

__all__ = ["register"]

#: The most equilibrium solutions one design command may compute (each takes about 10 ms).
MAX_DESIGN_POINTS = 10_000
#: grasps that ``bendpam grasp --twist`` twists at most (each a few spatial-finger solves, about a second each)
MAX_TWIST_GRASPS = 12

JsonOpt = Annotated[bool, typer.Option("--json", help="Print one JSON object instead of a table.")]
PlotOpt = Annotated[Optional[Path], typer.Option("--plot", help="Write a figure (.png/.pdf/.svg).")]
L0Opt = Annotated[Optional[float], typer.Option("--l0-mm", help="Active length L0 (mm); default: the actuator's.")]


def _record(row: dict[str, Any]) -> dict[str, Any]:
    """A table row as a JSON record: numbers as floats (NaN as null, infinity kept), empty notes as null."""
    import numpy as np

    out: dict[str, Any] = {}
    for k, v in row.items():
        if isinstance(v, bool | np.bool_):
            out[k] = bool(v)
        elif isinstance(v, str):
            out[k] = v or None
        else:
            try:
                f = float(v)
            except (TypeError, ValueError):
                out[k] = None
            else:
                out[k] = None if math.isnan(f) else f  # infinity: "inf" in the JSON (print_json)
    return out


def _plot_target(plot: Optional[Path], fmt=None):
    """Check --plot and --format (png, pdf or svg; from the suffix if --format is not given); returns --plot."""
    if plot is None:
        if fmt is not None:
            raise UserError(f"--format {fmt.value}: there is no figure to write; give --plot FILE")
        return None
    figure_format(plot, fmt, "--plot")
    return plot


def _save_plot(draw, plot: Path, fmt=None, aspect: float = 0.8) -> None:
    """Draw ``draw(ax)`` on a single-column journal figure and write it to --plot (format as checked above)."""
    from bendpam.present.figures import save_figure, styled_figure

    save_figure(styled_figure(draw, "single", aspect), plot, format=figure_format(plot, fmt, "--plot"))


def _budget(n: int, what: str) -> None:
    """Refuse a design grid of more than :data:`MAX_DESIGN_POINTS` points before computing it."""
    if n > MAX_DESIGN_POINTS:
        raise UserError(f"{what} = {n} points; at most {MAX_DESIGN_POINTS} (about 10 ms each): give fewer values")


def _length(act, l0_mm):
    if l0_mm is None:
        return act
    if not (math.isfinite(l0_mm) and l0_mm > 0):
        raise UserError(f"--l0-mm: {l0_mm:g} mm must be a positive length")
    return act.replace(L0_mm=float(l0_mm))


# ---- finger -------------------------------------------------------------------------------------
def finger_cmd(
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = None,
    pressure_kpa: PressureOpt = None,
    l0_mm: L0Opt = None,
    tip_force_n: Annotated[Optional[str], typer.Option(
        "--tip-force-n", help="Tip force FX,FY in the bending plane, or FX,FY,FZ in space (N; z out of the plane).")
    ] = None,
    tip_moment_nmm: Annotated[Optional[str], typer.Option(
        "--tip-moment-nmm", help="Tip moment MZ (N*mm, ccw in the plane), or MX,MY,MZ in space.")] = None,
    tip_mass_g: Annotated[float, typer.Option("--tip-mass-g", help="Point mass at the fingertip (g).")] = 0.0,
    mass_per_length: Annotated[
        float, typer.Option("--mass-per-length-g-mm", help="Self-weight of the actuator (g/mm).")] = 0.0,
    gravity_deg: Annotated[
        float, typer.Option("--gravity-deg", help="Direction of gravity (deg from +x).")] = -90.0,
    base_angle_deg: Annotated[
        float, typer.Option("--base-angle-deg", help="Direction of the finger at its base (deg from +x).")] = 0.0,
    bend: Annotated[str, typer.Option("--bend", help="Curl direction when inflated: ccw or cw.")] = "ccw",
    fingertip_mm: Annotated[float, typer.Option("--fingertip-mm", help="Rigid fingertip length (mm).")] = 0.0,
    fingertip_offset_mm: Annotated[
        float, typer.Option("--fingertip-offset-mm", help="Fingertip offset toward the bending side (mm).")] = 0.0,
    blocked: Annotated[bool, typer.Option("--blocked-force", help="Also the blocked tip force at the straight "
                                          "position (roller normal to the base).")] = False,
    as_json: JsonOpt = False,
    plot: PlotOpt = None,
    fig_format: FigureFormatOpt = None,
):
    """Equilibrium shape and tip pose of a finger under tip force, tip mass and self-weight."""
    from bendpam.design.finger import Finger, FingerLoads, finger_sweep, plot_finger_shapes
    from bendpam.design.tip import blocked_tip_force

    act = _length(load_actuator(preset, actuator, model), l0_mm)
    P = pressures_kpa(pressure_kpa)
    _budget(len(P), "--pressure-kpa")
    mname = model_for(act, model)
    plot = _plot_target(plot, fig_format)
    bend_key = bend.strip().lower()
    if bend_key not in ("ccw", "cw"):
        raise UserError(f"--bend: {bend!r} is not allowed; choose ccw or cw")
    F = _components(tip_force_n, "--tip-force-n", "N", "FX,FY", 2) if tip_force_n is not None else (0.0, 0.0)
    M = _components(tip_moment_nmm, "--tip-moment-nmm", "N*mm", "MZ", 1) if tip_moment_nmm is not None else (0.0,)
    g = math.radians(gravity_deg)
    finger = Finger(act, mname, base_angle_deg=base_angle_deg, bend=1 if bend_key == "ccw" else -1,
                    fingertip_mm=fingertip_mm, fingertip_offset_mm=fingertip_offset_mm)
    if len(F) == 3 or len(M) == 3:  # loads out of the bending plane: the spatial finger
        if blocked:
            raise UserError("--blocked-force: the blocked force is for in-plane loads; give --tip-force-n FX,FY and "
                            "--tip-moment-nmm MZ")
        _finger3d(act, mname, finger, P, F, M, (tip_mass_g, mass_per_length, gravity_deg), as_json, plot, fig_format)
        return
    Mz = M[0]
    loads = FingerLoads(tip_force_n=(F[0], F[1]), tip_moment_nmm=Mz, tip_mass_g=tip_mass_g,
                        mass_per_length_g_per_mm=mass_per_length, gravity=(math.cos(g), math.sin(g)))
    _, shapes = finger_sweep(finger, P, loads)
    lims = [sh.limits() if sh.equilibrium else None for sh in shapes]  # worst section along the finger
    held = [blocked_tip_force(finger, p, loads=loads) for p in P] if blocked else None
    if plot is not None:  # with a load, the free shapes beside the loaded ones
        loaded = any(F) or Mz or tip_mass_g or mass_per_length
        free = finger_sweep(finger, P, FingerLoads())[1] if loaded else None
        _save_plot(lambda ax: plot_finger_shapes(shapes, ax=ax, free=free, title=f"{act.name or act.kind}, "
                                                 f"L0 = {act.L0_mm:g} mm"), plot, fig_format, aspect=0.9)
    rows = _finger_rows(shapes, lims, held)
    if as_json:
        obj = {"model": mname, "actuator": act.name or act.kind, "L0_mm": act.L0_mm,
               "loads": {"tip_force_n": list(F), "tip_moment_nmm": Mz, "tip_mass_g": tip_mass_g,
                         "mass_per_length_g_per_mm": mass_per_length, "gravity_deg": gravity_deg},
               "units": {"tip_x_mm": "mm", "tip_angle_deg": "deg (tangent at the tip, from +x)",
                         "bend_angle_deg": "deg (tip rotation in the bending direction)"},
               "results": rows}
        print_json(obj)
    else:
        typer.echo(f"{act.name or act.kind}, L0 = {act.L0_mm:g} mm — {mname.replace('_', '-')} model")
        _print_finger_rows(rows, blocked)
        _print_finger_limits(P, lims)
    for lm in lims:  # a prediction past a limit says so
        for v in (lm.violations if lm is not None else ()):
            typer.echo(f"bendpam: warning: past a limit: {v}", err=True)
    if plot is not None and not as_json:
        echo_wrote(f"wrote {plot}")


def _finger_rows(shapes, lims, held) -> list[dict[str, Any]]:
    """The JSON rows of the planar ``bendpam finger``: pose, z = 0 (in the plane), blocked force, limits."""
    rows = []
    for i, (sh, lm) in enumerate(zip(shapes, lims, strict=True)):
        row = sh.to_dict()
        flat = 0.0 if sh.equilibrium else None  # in-plane loads: the finger stays in its plane
        row |= {"tip_z_mm": flat, "out_of_plane_deg": flat, "twist_deg": flat}
        if held is not None:
            row["blocked_force_n"] = held[i].to_dict()["force_n"]
        row["limits"] = None if lm is None else lm.to_dict()
        rows.append(row)
    return rows


def _components(text: str, name: str, unit: str, planar: str, n_planar: int) -> tuple[float, ...]:
    """``n_planar`` numbers (the in-plane form, ``planar``) or three (X,Y,Z in space), else a one-line error."""
    parts = [p for p in str(text).replace(";", ",").split(",") if p.strip()]
    try:
        vals = [float(p) for p in parts]
    except ValueError:
        raise UserError(f"{name}: {text!r} must be {planar} or X,Y,Z ({unit})") from None
    if len(vals) not in (n_planar, 3) or not all(math.isfinite(v) for v in vals):
        raise UserError(f"{name}: {text!r} must be {n_planar if n_planar > 1 else 'one'} or three finite numbers: "
                        f"{planar} or X,Y,Z ({unit})")
    return tuple(vals)


def _finger3d(act, mname, finger, P, F, M, weights, as_json: bool, plot, fig_format) -> None:
    """``bendpam finger`` with loads out of the bending plane (:func:`bendpam.design.finger3d.solve_finger3d`)."""
    from bendpam.design.finger3d import Finger3D, FingerLoads3D, plot_finger3d, solve_finger3d
    from bendpam.present.figures import save_figure

    tip_mass_g, mass_per_length, gravity_deg = weights
    g = math.radians(gravity_deg)
    F3 = (*F, 0.0) if len(F) == 2 else F
    M3 = (0.0, 0.0, M[0]) if len(M) == 1 else M
    loads = FingerLoads3D(tip_force_n=F3, tip_moment_nmm=M3, tip_mass_g=tip_mass_g,
                          mass_per_length_g_per_mm=mass_per_length, gravity=(math.cos(g), math.sin(g), 0.0))
    f3 = Finger3D(finger)
    shapes = [solve_finger3d(f3, p, loads) for p in P]
    rows = [sh.to_dict() for sh in shapes]
    if plot is not None:
        save_figure(plot_finger3d(shapes, title=f"{act.name or act.kind}, L0 = {act.L0_mm:g} mm"), plot,
                    format=figure_format(plot, fig_format, "--plot"))
    if as_json:
        print_json({"model": mname, "actuator": act.name or act.kind, "L0_mm": act.L0_mm,
                    "loads": {"tip_force_n": list(F3), "tip_moment_nmm": list(M3), "tip_mass_g": tip_mass_g,
                              "mass_per_length_g_per_mm": mass_per_length, "gravity_deg": gravity_deg},
                    "units": {"tip_x_mm": "mm (z: out of the bending plane)",
                              "out_of_plane_deg": "deg (tip tangent out of the bending plane)",
                              "twist_deg": "deg (tip section about the frame line)",
                              "base_moment_nmm": "N*mm (along d1 in-plane normal, d2 plane normal, d3 tangent)"},
                    "results": rows})
        return
    typer.echo(f"{act.name or act.kind}, L0 = {act.L0_mm:g} mm — {mname.replace('_', '-')} model, loads in space")
    typer.echo(f"{'P (kPa)':>8} {'tip x (mm)':>10} {'tip y (mm)':>10} {'tip z (mm)':>10} {'bend (deg)':>10} "
               f"{'out (deg)':>9} {'twist (deg)':>11} {'residual':>9}  note")
    for r in rows:
        typer.echo(f"{r['pressure_kpa']:8.4g} {_fmt(r['tip_x_mm'], '10.2f')} {_fmt(r['tip_y_mm'], '10.2f')} "
                   f"{_fmt(r['tip_z_mm'], '10.2f')} {_fmt(r['bend_angle_deg'], '10.2f')} "
                   f"{_fmt(r['out_of_plane_deg'], '9.2f')} {_fmt(r['twist_deg'], '11.2f')} "
                   f"{_fmt(r['residual_nmm'], '9.1e')}" + ("  " + r["note"] if r["note"] else ""))
    if plot is not None:
        echo_wrote(f"wrote {plot}")


def _print_finger_rows(rows: list[dict[str, Any]], blocked: bool) -> None:
    """The table of tip poses (and blocked forces) of ``bendpam finger``."""
    head = f"{'P (kPa)':>8} {'tip x (mm)':>10} {'tip y (mm)':>10} {'tip φ (deg)':>11} {'bend (deg)':>10} " \
           f"{'M_base (N·mm)':>13} {'residual':>9}"
    if blocked:
        head += f" {'blocked F (N)':>16}"
    typer.echo(head + "  note")
    for r in rows:
        line = (f"{r['pressure_kpa']:8.4g} {_fmt(r['tip_x_mm'], '10.2f')} {_fmt(r['tip_y_mm'], '10.2f')} "
                f"{_fmt(r['tip_angle_deg'], '11.2f')} {_fmt(r['bend_angle_deg'], '10.2f')} "
                f"{_fmt(r['base_moment_nmm'], '13.2f')} {_fmt(r['residual_nmm'], '9.1e')}")
        if blocked:  # with --blocked-force
            b = r["blocked_force_n"]
            line += f" {_fmt(b[0], '7.3f')},{_fmt(b[1], '8.3f')}" if b is not None else f" {'—':>16}"
        typer.echo(line + ("  " + r["note"] if r["note"] else ""))


def _print_finger_limits(P, lims) -> None:
    """The table of the worst section's margins of ``bendpam finger``."""
    typer.echo("limits along the finger (worst section; safety factors, >= 1 within the limit; "
               "inf: no demand or no limit)")
    typer.echo(f"{'P (kPa)':>8} {'N_frame (N)':>11} {'σ_frame (MPa)':>13} {'strength':>8} {'buckling':>8} "
               f"{'lock-up':>8} {'stretch':>8} {'min':>7} {'at s (mm)':>9}")
    for p_kpa, lm in zip(P, lims, strict=True):
        if lm is None:
            typer.echo(f"{p_kpa:8.4g} {'—':>11}  (no equilibrium)")
            continue
        mg = [("inf" if v == math.inf else f"{v:.2f}") for v in (
            lm.frame_strength_margin, lm.buckling_margin, lm.lockup_margin, lm.bladder_stretch_margin,
            lm.min_margin)]
        typer.echo(f"{p_kpa:8.4g} {lm.frame_axial_force_n:11.2f} {lm.frame_stress_mpa:13.2f} {mg[0]:>8} "
                   f"{mg[1]:>8} {mg[2]:>8} {mg[3]:>8} {mg[4]:>7} {lm.worst_s_mm:9.4g}")


# ---- grasp --------------------------------------------------------------------------------------
_GRASP_UNITS = {"grip_force_n": "N (whole gripper: peak load of the quasi-static pull-out)",
                "peak_lift_mm": "mm (lift of the base at the peak)",
                "frozen_grip_force_n": "N (frozen-normal estimate, for comparison only)",
                "contact_force_n": "N (per finger, at the grasp)",
                "contact_angle_deg": "deg (sphere normal from the downward vertical, at the grasp)"}


def grasp_cmd(
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = None,
    diameter_mm: Annotated[
        Optional[list[str]],
        typer.Option("--diameter-mm", help="Sphere diameter(s), mm: '80 120 160', '80,120' or '80:280:6'."),
    ] = None,
    pressure_kpa: PressureOpt = None,
    l0_mm: L0Opt = None,
    fingers: Annotated[int, typer.Option("--fingers", help="Number of fingers.")] = 3,
    base_radius_mm: Annotated[
        Optional[float], typer.Option("--base-radius-mm", help="Base-circle radius of the fingers (mm); "
                                      "default 100.")] = None,
    mu: Annotated[
        Optional[float], typer.Option("--mu", help="Coulomb friction coefficient pad-sphere; default 0.5.")] = None,
    fingertip_mm: Annotated[
        Optional[float],
        typer.Option("--fingertip-mm", help="Rigid fingertip (pad) length (mm); default 10.")] = None,
    contact_offset_mm: Annotated[
        Optional[float], typer.Option("--contact-offset-mm", help="Frame line to contact surface (mm); default "
                                      "by actuator type.")] = None,
    splay_deg: Annotated[
        Optional[float], typer.Option("--splay-deg", help="Outward tilt of the open fingers (deg); "
                                      "default 15.")] = None,
    twist: Annotated[bool, typer.Option("--twist", help="Also twist each grasped sphere about the gripper's axis "
                                        "until the grip slips (the fingers as 3-D rods; at most 12 grasps).")] = False,
    as_json: JsonOpt = False,
    plot: PlotOpt = None,
    fig_format: FigureFormatOpt = None,
):
    """Grip (pull-out) force of an N-finger gripper on spheres against diameter and pressure.

    Each grasp is pulled out quasi-statically (the base lifted step by step, the fingers'
    statics with their moment law, Coulomb stick/slip at the contacts); the grip force is the
    peak lifting load before the sphere escapes.  With --twist, each grasp is also twisted about
    the gripper's axis until the contacts slip: the torque then and the fingers' distortion.
    """
    from bendpam.design.grasp import grasp_dataset, plot_grasp, solve_grasps
    from bendpam.design.gripper import (
        DEFAULT_BASE_RADIUS_MM,
        DEFAULT_FINGERTIP_MM,
        DEFAULT_MU,
        DEFAULT_SPLAY_DEG,
        Gripper,
    )

    act = _length(load_actuator(preset, actuator, model), l0_mm)
    D = parse_values(diameter_mm, "--diameter-mm")
    if not D:
        raise UserError("give at least one sphere diameter with --diameter-mm (mm), e.g. --diameter-mm 80:280:6")
    for d in D:
        if d <= 0:
            raise UserError(f"--diameter-mm: {d:g} mm is not a positive diameter")
    P = pressures_kpa(pressure_kpa, None)
    _budget(len(P) * len(D), "--pressure-kpa x --diameter-mm")
    _twist_budget(twist, len(P) * len(D))
    mname = model_for(act, model)
    plot = _plot_target(plot, fig_format)
    gr = Gripper(act, mname, fingers=fingers,
                 base_radius_mm=DEFAULT_BASE_RADIUS_MM if base_radius_mm is None else base_radius_mm,
                 fingertip_mm=DEFAULT_FINGERTIP_MM if fingertip_mm is None else fingertip_mm,
                 contact_offset_mm=contact_offset_mm, mu=DEFAULT_MU if mu is None else mu,
                 splay_deg=DEFAULT_SPLAY_DEG if splay_deg is None else splay_deg)
    grasps = solve_grasps(gr, D, P)
    if plot is not None:
        ds = grasp_dataset(gr, grasps)
        _save_plot(lambda ax: plot_grasp(ds, ax=ax), plot, fig_format)
    rows = [g.to_dict() for row in grasps for g in row]
    if twist:
        _add_twists(gr, grasps, rows)
    if as_json:
        print_json({**gr.to_dict(), "units": _GRASP_UNITS, "results": rows})
        return
    _print_grasps(gr, rows)
    if twist:
        _print_twists(rows)
    if plot is not None:
        echo_wrote(f"wrote {plot}")


def _print_grasps(gr, rows: list[dict[str, Any]]) -> None:
    """The table of ``bendpam grasp``: one row per sphere and pressure."""
    act = gr.actuator
    typer.echo(f"{gr.fingers}-finger gripper, {act.name or act.kind}, L0 = {act.L0_mm:g} mm, base radius "
               f"{gr.base_radius_mm:g} mm, splay {gr.splay_deg:g}°, mu = {gr.mu:g} — "
               f"{gr.model.replace('_', '-')} model; grip = peak load of the quasi-static pull-out "
               "(frozen = frozen-normal estimate, for comparison)")
    typer.echo(f"{'D (mm)':>7} {'P (kPa)':>8} {'grip (N)':>9} {'lift (mm)':>9} {'frozen (N)':>10} "
               f"{'N/finger':>9} {'contact':>8} {'β (deg)':>8}  note")
    for r in rows:
        typer.echo(f"{r['diameter_mm']:7.4g} {r['pressure_kpa']:8.4g} {_fmt(r['grip_force_n'], '9.2f')} "
                   f"{_fmt(r['peak_lift_mm'], '9.2f')} {_fmt(r['frozen_grip_force_n'], '10.2f')} "
                   f"{_fmt(r['contact_force_n'], '9.2f')} {r['contact']:>8} {_fmt(r['contact_angle_deg'], '8.1f')}"
                   + (f"  {r['note']}" if r["note"] else ""))


def _twist_budget(twist: bool, n: int) -> None:
    if twist and n > MAX_TWIST_GRASPS:
        raise UserError(f"--twist: {n} grasps; at most {MAX_TWIST_GRASPS} (each a few 3-D finger solves): give "
                        "fewer --diameter-mm or --pressure-kpa values")


def _add_twists(gr, grasps, rows: list[dict[str, Any]]) -> None:
    """Each grasp twisted about the gripper's axis until the grip slips (:func:`bendpam.design.twist.twist_grasp`)."""
    from bendpam.design.twist import twist_grasp

    for r, g in zip(rows, (g for row in grasps for g in row), strict=True):
        r["twist"] = twist_grasp(gr, g).to_dict()


def _print_twists(rows: list[dict[str, Any]]) -> None:
    """The twist table of ``bendpam grasp --twist``: the torque when the grip slips and the distortion there."""
    typer.echo("twisted about the gripper's axis until the grip is lost (docs/out-of-plane.md)")
    typer.echo(f"{'D (mm)':>7} {'P (kPa)':>8} {'torque (N·mm)':>13} {'across (mm)':>11} {'object (deg)':>12} "
               f"{'twist (deg)':>11} {'mm/N':>6}  lost by")
    for r in rows:
        t = r["twist"]
        typer.echo(f"{r['diameter_mm']:7.4g} {r['pressure_kpa']:8.4g} {_fmt(t['torque_at_loss_nmm'], '13.1f')} "
                   f"{_fmt(t['contact_lateral_mm'], '11.2f')} {_fmt(t['object_rotation_deg'], '12.2f')} "
                   f"{_fmt(t['twist_deg'], '11.2f')} {_fmt(t['lateral_compliance_mm_per_n'], '6.1f')}  {t['lost_by']}")


# ---- wrist --------------------------------------------------------------------------------------
_HOLDING = ("pressure_kpa", "angle_deg", "holds_horizontal", "capacity_g", "equilibrium", "note")
_HandMassOpt = Annotated[Optional[float], typer.Option(
    "--hand-mass-g", help="Mass of the hand (g); default 0 in the holding table, 300 in the tilt of --payload-g.")]
_HandLeverOpt = Annotated[Optional[float], typer.Option(
    "--hand-lever-mm", help="Lever of the hand's mass (mm); default 50 in the holding table, 80 in the tilt of "
    "--payload-g.")]
_PayloadOpt = Annotated[Optional[float], typer.Option(
    "--payload-g", help="Tilt in each direction carrying the hand and this payload at --lever-mm (g), with the "
    "pressures for --tilt-deg and the frame-buckling margins.")]
_ForearmOpt = Annotated[str, typer.Option(
    "--forearm", help="With --payload-g: horizontal (actuator at 90 deg on top), up (hand above the wrist) or down.")]
_TiltOpt = Annotated[float, typer.Option("--tilt-deg", help="With --payload-g: the target tilt (deg).")]


def wrist_cmd(
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = None,
    pressure_kpa: PressureOpt = None,
    direction_deg: Annotated[
        Optional[list[str]],
        typer.Option("--direction-deg", help="Bending direction(s), deg: multiples of 45 (default 0 90 180 270)."),
    ] = None,
    length_mm: Annotated[
        Optional[float], typer.Option("--length-mm", help="Wrist length (mm); default L0.")] = None,
    radius_mm: Annotated[float, typer.Option("--radius-mm", help="Mounting radius around the column (mm).")] = 20.0,
    lateral_stiffness: Annotated[
        Optional[float], typer.Option("--lateral-stiffness-nmm2", help="Out-of-plane stiffness of one actuator "
                                      "(N*mm^2); default: the actuator's, unpressurised.")] = None,
    column_stiffness: Annotated[
        float, typer.Option("--column-stiffness-nmm2", help="Bending stiffness of the column (N*mm^2).")] = 0.0,
    load_g: Annotated[float, typer.Option("--load-g", help="Mass held horizontally (g).")] = 335.0,
    lever_mm: Annotated[float, typer.Option("--lever-mm", help="Lever of the mass beyond the wrist (mm).")] = 100.0,
    hand_mass_g: _HandMassOpt = None,
    hand_lever_mm: _HandLeverOpt = None,
    payload_g: _PayloadOpt = None,
    forearm: _ForearmOpt = "horizontal",
    tilt_deg: _TiltOpt = 30.0,
    as_json: JsonOpt = False,
    plot: PlotOpt = None,
    fig_format: FigureFormatOpt = None,
    quiet: QuietOpt = False,
):
    """Bending angle of a four-actuator wrist per direction, and the load it holds horizontally.

    With --payload-g: the tilt reached in each of the four directions at the highest --pressure-kpa,
    carrying the hand and the payload, the pressures a --tilt-deg tilt needs and the actuators'
    frame-buckling margins on the way.
    """
    from bendpam.design.wrist import Wrist, plot_wrist

    tilt_load = _tilt_load(payload_g, forearm, tilt_deg, hand_mass_g, hand_lever_mm, lever_mm)
    hand_mass_g = 0.0 if hand_mass_g is None else hand_mass_g
    hand_lever_mm = 50.0 if hand_lever_mm is None else hand_lever_mm
    act = load_actuator(preset, actuator, model)
    P = pressures_kpa(pressure_kpa)
    dirs = parse_values(direction_deg, "--direction-deg") if direction_deg else [0.0, 90.0, 180.0, 270.0]
    _budget(len(P) * len(dirs), "--pressure-kpa x --direction-deg")
    mname = model_for(act, model)
    plot = _plot_target(plot, fig_format)
    w = Wrist(act, mname, radius_mm=radius_mm, length_mm=length_mm, lateral_stiffness_nmm2=lateral_stiffness,
              column_stiffness_nmm2=column_stiffness)
    table, holds = _wrist_runs(w, P, dirs, dict(load_g=load_g, lever_mm=lever_mm, hand_mass_g=hand_mass_g,
                                                 hand_lever_mm=hand_lever_mm), quiet)
    if plot is not None:
        _save_plot(lambda ax: plot_wrist(table, holds, ax=ax, positions_deg=w.positions_deg,
                                         title=f"wrist of four {act.kind}s, L = {w.length_mm:g} mm"),
                   plot, fig_format, aspect=1.15)
    results = [_record(r) for r in table.to_dict("records")]
    holding = [{k: d[k] for k in _HOLDING} for d in (h.to_dict() for h in holds)]
    tilt = _tilt(w, max(P), tilt_load, tilt_deg)
    if as_json:
        obj = {"model": mname, "actuator": act.name or act.kind, "length_mm": w.length_mm, "radius_mm": w.radius_mm,
               "lateral_stiffness_nmm2": w.lateral_stiffness_nmm2, "column_stiffness_nmm2": w.column_stiffness_nmm2,
               "load": {"load_g": load_g, "lever_mm": lever_mm, "hand_mass_g": hand_mass_g,
                        "hand_lever_mm": hand_lever_mm,
                        "load_moment_nmm": holds[0].load_moment_nmm if holds else None,
                        "pressure_needed_kpa": holds[0].to_dict()["pressure_needed_kpa"] if holds else None},
               "results": results, "holding": holding}
        if tilt is not None:
            obj["tilt"] = tilt
        print_json(obj)
        return
    typer.echo(f"wrist of four {act.name or act.kind}, L = {w.length_mm:g} mm, radius {w.radius_mm:g} mm, "
               f"lateral stiffness {w.lateral_stiffness_nmm2:.4g} N·mm² — {mname.replace('_', '-')} model")
    _print_wrist(results, holding, holds, load_g, lever_mm, hand_mass_g, hand_lever_mm)
    if tilt is not None:
        _print_tilt(tilt)
    if plot is not None:
        echo_wrote(f"wrote {plot}")


def _wrist_runs(w, P, dirs, load: dict[str, float], quiet: bool):
    """The free bending per direction (a table) and the holding at each pressure, with a progress bar."""
    import pandas as pd

    from bendpam.design.wrist import wrist_hold, wrist_sweep
    from bendpam.infra.progress import Progress

    # one step per direction (each is independent of the others) and per holding pressure
    with Progress(len(dirs) + len(P), "wrist", quiet=quiet) as bar:
        parts = []
        for d in dirs:
            parts.append(wrist_sweep(w, P, [d]))
            bar.advance()
        table = pd.concat(parts, ignore_index=True)
        holds = []
        for p in P:
            holds.append(wrist_hold(w, p, **load))
            bar.advance()
    return table, holds


def _print_wrist(results, holding, holds, load_g, lever_mm, hand_mass_g, hand_lever_mm) -> None:
    """The tables of ``bendpam wrist``: bending per direction, then the holding per pressure."""
    typer.echo(f"{'dir (deg)':>9} {'P (kPa)':>8} {'angle (deg)':>11} {'toward (deg)':>12}  note")
    for r in results:
        typer.echo(f"{r['direction_deg']:9.4g} {r['pressure_kpa']:8.4g} {_fmt(r['angle_deg'], '11.2f')} "
                   f"{_fmt(r['bend_direction_deg'], '12.1f')}" + (f"  {r['note']}" if r["note"] else ""))
    if holds:
        typer.echo(f"\nholding {load_g:g} g at {lever_mm:g} mm (hand {hand_mass_g:g} g at {hand_lever_mm:g} mm), "
                   f"forearm horizontal, upper actuator inflated: load moment {holds[0].load_moment_nmm:.1f} N·mm, "
                   f"horizontal from {holds[0].pressure_needed_kpa:.4g} kPa")
        typer.echo(f"{'P (kPa)':>8} {'angle (deg)':>11} {'horizontal':>10} {'capacity (g)':>12}")
        for h in holding:
            typer.echo(f"{h['pressure_kpa']:8.4g} {_fmt(h['angle_deg'], '11.2f')} "
                       f"{'yes' if h['holds_horizontal'] else 'no':>10} {_fmt(h['capacity_g'], '12.1f')}"
                       + (f"  {h['note']}" if h["note"] else ""))


def _tilt_load(payload_g, forearm: str, tilt_deg: float, hand_mass_g, hand_lever_mm, lever_mm: float):
    """The load of the --payload-g tilt (None without --payload-g), its options checked."""
    from bendpam.design.wrist_tilt import DEFAULT_HAND_LEVER_MM, DEFAULT_HAND_MASS_G, FOREARM, WristLoad

    if payload_g is None:
        return None
    if forearm not in FOREARM:
        raise UserError(f"--forearm: {forearm!r} is not allowed; choose {', '.join(FOREARM)}")
    if not (math.isfinite(tilt_deg) and 0.0 < tilt_deg < 180.0):
        raise UserError(f"--tilt-deg: {tilt_deg:g} deg must be between 0 and 180")
    for name, v in (("--payload-g", payload_g), ("--hand-mass-g", hand_mass_g), ("--hand-lever-mm", hand_lever_mm),
                    ("--lever-mm", lever_mm)):
        if v is not None and not (math.isfinite(v) and v >= 0.0):
            raise UserError(f"{name}: {v:g} must be a finite value >= 0")
    return WristLoad(hand_mass_g=DEFAULT_HAND_MASS_G if hand_mass_g is None else hand_mass_g,
                     hand_lever_mm=DEFAULT_HAND_LEVER_MM if hand_lever_mm is None else hand_lever_mm,
                     payload_g=payload_g, payload_lever_mm=lever_mm, forearm=forearm)


def _tilt(w, pressure_kpa: float, load, tilt_deg: float) -> dict[str, Any] | None:
    """The --payload-g section: per direction, the tilt at ``pressure_kpa`` with ``load`` (None: no section)."""
    if load is None:
        return None
    from bendpam.design.wrist_tilt import wrist_directions

    return {"load": load.to_dict(), "target_tilt_deg": tilt_deg,
            "directions": wrist_directions(w, pressure_kpa, load, target_tilt_deg=tilt_deg)}


def _print_tilt(tilt: dict[str, Any]) -> None:
    """The table of the --payload-g tilt: one row per direction."""
    ld = tilt["load"]
    typer.echo(f"\ntilt carrying the hand ({ld['hand_mass_g']:g} g at {ld['hand_lever_mm']:g} mm) and "
               f"{ld['payload_g']:g} g at {ld['payload_lever_mm']:g} mm, forearm {ld['forearm']}; target "
               f"{tilt['target_tilt_deg']:g}° (buckling margins: each actuator's smallest on the way)")
    typer.echo(f"{'dir (deg)':>9} {'P (kPa)':>8} {'tilt (deg)':>10} {'toward':>7} {'reached':>7} "
               f"{'P for target (kPa)':>26} {'buckling margins':>24}")
    for r in tilt["directions"]:
        need = ",".join(_fmt(p, ".0f") for p in r["target"]["pressures_kpa"])
        mg = ",".join("inf" if m == "inf" else _fmt(m, ".2f") for m in r["min_buckling_margin"])
        typer.echo(f"{r['direction_deg']:9.4g} {r['pressure_kpa']:8.4g} {_fmt(r['tilt_deg'], '10.1f')} "
                   f"{_fmt(r['tilt_direction_deg'], '7.0f')} {'yes' if r['reaches_target'] else 'no':>7} "
                   f"{need:>26} {mg:>24}" + (f"  {r['note']}" if r["note"] else ""))


# ---- registration -------------------------------------------------------------------------------
def register(app: typer.Typer) -> typer.Typer:
    """Add the ``finger``, ``grasp`` and ``wrist`` commands to ``app`` (once; returns ``app``).

    >>> import typer
    >>> app = register(register(typer.Typer()))
    >>> [c.name for c in app.registered_commands]
    ['finger', 'grasp', 'wrist']
    """
    names = {c.name or (c.callback.__name__ if c.callback else None) for c in app.registered_commands}
    if {"finger", "grasp", "wrist"} <= names:
        return app
    app.command("finger", cls=MultiValueCommand)(finger_cmd)
    app.command("grasp", cls=MultiValueCommand)(grasp_cmd)
    app.command("wrist", cls=MultiValueCommand)(wrist_cmd)
    return app
