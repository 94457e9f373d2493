"""``bendpam finger``, ``bendpam grasp`` and ``bendpam wrist``: the design commands (issue 6).

``register(app)`` adds the three commands to the ``bendpam`` Typer app.  They parse and print;
the logic lives in :mod:`bendpam.design`.  The shared option helpers come from
:mod:`bendpam.cli`, imported when ``register`` runs (so that ``cli.py`` can call ``register`` at
its end without an import cycle).

Multi-valued options (``--pressure-kpa``, ``--diameter-mm``, ``--direction-deg``) take values as
separate tokens (``--diameter-mm 80 120 160``), comma lists (``80,120,160``) or ranges
(``80:280:6``); several such options may follow each other.
"""

# no ``from __future__ import annotations``: Typer reads the annotations of the command functions
# defined inside ``register``, which refer to names local to it.
import json
import math
from pathlib import Path
from typing import Annotated, Optional

import typer

from .options import fmt_num as _fmt

__all__ = ["register"]

def _num(x):
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _pair(text: str, name: str, unit: str) -> tuple[float, float]:
    from .options import UserError

    parts = [p for p in str(text).replace(";", ",").split(",") if p.strip()]
    try:
        vals = [float(p) for p in parts]
    except ValueError:
        raise UserError(f"{name}: {text!r} must be two numbers X,Y ({unit})") from None
    if len(vals) != 2 or not all(math.isfinite(v) for v in vals):
        raise UserError(f"{name}: {text!r} must be two finite numbers X,Y ({unit})")
    return vals[0], vals[1]


def _plot_target(plot: Optional[Path]):
    from .options import UserError

    if plot is None:
        return None
    if plot.suffix.lower() not in {".png", ".pdf", ".svg"}:
        raise UserError(
            f"--plot {str(plot)!r}: unknown figure format {plot.suffix or '(none)'}; use .png, .pdf or .svg")
    return plot


#: The most equilibrium solutions one design command may compute (each takes about 10 ms).
MAX_DESIGN_POINTS = 10_000


def _budget(n: int, what: str) -> None:
    """Refuse a design grid of more than :data:`MAX_DESIGN_POINTS` points before computing it."""
    from .options import UserError

    if n > MAX_DESIGN_POINTS:
        raise UserError(f"{what} = {n} points; at most {MAX_DESIGN_POINTS} (about 10 ms each): give fewer values")


def _length(act, l0_mm):
    from .options import UserError

    if l0_mm is None:
        return act
    if not (math.isfinite(l0_mm) and l0_mm > 0):
        raise UserError(f"--l0-mm: {l0_mm:g} mm must be a positive length")
    return act.replace(L0_mm=float(l0_mm))


def register(app: typer.Typer) -> typer.Typer:
    """Add the ``finger``, ``grasp`` and ``wrist`` commands to ``app`` (once; returns ``app``)."""
    from .options import ActuatorOpt, Model, ModelOpt, MultiValueCommand, PresetOpt, PressureOpt

    names = {c.name or (c.callback.__name__ if c.callback else None) for c in app.registered_commands}
    if {"finger", "grasp", "wrist"} <= names:
        return app

    JsonOpt = Annotated[bool, typer.Option("--json", help="Print one JSON object instead of a table.")]
    PlotOpt = Annotated[Optional[Path], typer.Option("--plot", help="Write a figure (.png/.pdf/.svg).")]
    L0Opt = Annotated[Optional[float], typer.Option("--l0-mm", help="Active length L0 (mm); default: the actuator's.")]

    # ---- finger -------------------------------------------------------------------------------
    @app.command("finger", cls=MultiValueCommand)
    def finger_cmd(
        preset: PresetOpt = None,
        actuator: ActuatorOpt = None,
        model: ModelOpt = Model.energy,
        pressure_kpa: PressureOpt = None,
        l0_mm: L0Opt = None,
        tip_force_n: Annotated[Optional[str], typer.Option("--tip-force-n", help="Tip force FX,FY (N).")] = None,
        tip_moment_nmm: Annotated[float, typer.Option("--tip-moment-nmm", help="Tip moment (N*mm, ccw).")] = 0.0,
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
    ):
        """Equilibrium shape and tip pose of a finger under tip force, tip mass and self-weight."""
        from ..design.finger import Finger, FingerLoads, blocked_tip_force, finger_sweep
        from .options import UserError, load_actuator, model_name, pressures_kpa

        act = _length(load_actuator(preset, actuator, model), l0_mm)
        P = pressures_kpa(pressure_kpa)
        _budget(len(P), "--pressure-kpa")
        mname = model_name(model)
        plot = _plot_target(plot)
        bend_key = bend.strip().lower()
        if bend_key not in ("ccw", "cw"):
            raise UserError(f"--bend: {bend!r} is not allowed; choose ccw or cw")
        F = _pair(tip_force_n, "--tip-force-n", "N") if tip_force_n is not None else (0.0, 0.0)
        g = math.radians(gravity_deg)
        finger = Finger(act, mname, base_angle_deg=base_angle_deg, bend=1 if bend_key == "ccw" else -1,
                        fingertip_mm=fingertip_mm, fingertip_offset_mm=fingertip_offset_mm)
        loads = FingerLoads(tip_force_n=F, tip_moment_nmm=tip_moment_nmm, tip_mass_g=tip_mass_g,
                            mass_per_length_g_per_mm=mass_per_length, gravity=(math.cos(g), math.sin(g)))
        df, shapes = finger_sweep(finger, P, loads)
        bforce = [blocked_tip_force(finger, p, loads=loads) for p in P] if blocked else None
        if plot is not None:
            from ..design.finger import plot_finger_shapes
            from ..plots import save_figure

            save_figure(plot_finger_shapes(shapes, title=f"{act.name or act.kind}, L0 = {act.L0_mm:g} mm"), plot)
        if as_json:
            rows = []
            for i, r in enumerate(df.itertuples()):
                row = {"pressure_kpa": float(r.pressure_kpa), "tip_x_mm": _num(r.tip_x_mm),
                       "tip_y_mm": _num(r.tip_y_mm),
                       "tip_angle_deg": _num(r.tip_angle_deg), "equilibrium": bool(r.equilibrium),
                       "note": r.note or None, "bend_angle_deg": _num(r.bend_angle_deg),
                       "base_moment_nmm": _num(r.base_moment_nmm), "residual_nmm": _num(r.residual_nmm)}
                if bforce is not None:
                    b = bforce[i]
                    row["blocked_force_n"] = [_num(b.force_n[0]), _num(b.force_n[1])] if b.equilibrium else None
                rows.append(row)
            obj = {"model": mname, "actuator": act.name or act.kind, "L0_mm": act.L0_mm,
                   "loads": {"tip_force_n": list(F), "tip_moment_nmm": tip_moment_nmm, "tip_mass_g": tip_mass_g,
                             "mass_per_length_g_per_mm": mass_per_length, "gravity_deg": gravity_deg},
                   "units": {"tip_x_mm": "mm", "tip_angle_deg": "deg (tangent at the tip, from +x)",
                             "bend_angle_deg": "deg (tip rotation in the bending direction)"},
                   "results": rows}
            typer.echo(json.dumps(obj, indent=2))
        else:
            typer.echo(f"{act.name or act.kind}, L0 = {act.L0_mm:g} mm — {mname.replace('_', '-')} model")
            head = f"{'P (kPa)':>8} {'tip x (mm)':>10} {'tip y (mm)':>10} {'tip φ (deg)':>11} {'bend (deg)':>10} " \
                   f"{'M_base (N·mm)':>13} {'residual':>9}"
            if blocked:
                head += f" {'blocked F (N)':>16}"
            typer.echo(head + "  note")
            for i, r in enumerate(df.itertuples()):
                line = (f"{r.pressure_kpa:8.4g} {_fmt(r.tip_x_mm, '10.2f')} {_fmt(r.tip_y_mm, '10.2f')} "
                        f"{_fmt(r.tip_angle_deg, '11.2f')} {_fmt(r.bend_angle_deg, '10.2f')} "
                        f"{_fmt(r.base_moment_nmm, '13.2f')} {_fmt(r.residual_nmm, '9.1e')}")
                if bforce is not None:  # with --blocked-force
                    b = bforce[i]
                    line += f" {_fmt(b.force_n[0], '7.3f')},{_fmt(b.force_n[1], '8.3f')}" if b.equilibrium \
                        else f" {'—':>16}"
                typer.echo(line + ("  " + r.note if r.note else ""))
        if plot is not None and not as_json:
            typer.echo(f"wrote {plot}")

    # ---- grasp --------------------------------------------------------------------------------
    @app.command("grasp", cls=MultiValueCommand)
    def grasp_cmd(
        preset: PresetOpt = None,
        actuator: ActuatorOpt = None,
        model: ModelOpt = Model.energy,
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
        mu: Annotated[float, typer.Option("--mu", help="Friction coefficient pad-sphere.")] = 0.5,
        fingertip_mm: Annotated[
            Optional[float],
            typer.Option("--fingertip-mm", help="Rigid fingertip (pad) length (mm); default 10.")] = None,
        contact_offset_mm: Annotated[
            Optional[float], typer.Option("--contact-offset-mm", help="Frame line to contact surface (mm); default "
                                          "by actuator type.")] = None,
        splay_deg: Annotated[float, typer.Option("--splay-deg", help="Outward tilt of the open fingers (deg).")] = 0.0,
        as_json: JsonOpt = False,
        plot: PlotOpt = None,
    ):
        """Gripping (pull-out) force of an N-finger gripper on spheres against diameter and pressure."""
        from ..design.grasp import DEFAULT_BASE_RADIUS_MM, DEFAULT_FINGERTIP_MM, Gripper, grasp_sweep
        from .options import UserError, load_actuator, model_name, parse_values, pressures_kpa

        act = _length(load_actuator(preset, actuator, model), l0_mm)
        D = parse_values(diameter_mm, "--diameter-mm")
        if not D:
            raise UserError("give at least one sphere diameter with --diameter-mm (mm), e.g. --diameter-mm 80:280:6")
        for d in D:
            if d <= 0:
                raise UserError(f"--diameter-mm: {d:g} mm is not a positive diameter")
        P = pressures_kpa(pressure_kpa, None)
        _budget(len(P) * len(D), "--pressure-kpa x --diameter-mm")
        mname = model_name(model)
        plot = _plot_target(plot)
        gr = Gripper(act, mname, fingers=fingers,
                     base_radius_mm=DEFAULT_BASE_RADIUS_MM if base_radius_mm is None else base_radius_mm,
                     fingertip_mm=DEFAULT_FINGERTIP_MM if fingertip_mm is None else fingertip_mm,
                     contact_offset_mm=contact_offset_mm, mu=mu, splay_deg=splay_deg)
        ds = grasp_sweep(gr, D, P)
        if plot is not None:
            from ..design.grasp import plot_grasp
            from ..plots import save_figure

            save_figure(plot_grasp(ds), plot)
        rows = []
        for i, d in enumerate(ds["diameter_mm"].values):
            for j, p in enumerate(ds["pressure_kpa"].values):
                rows.append({
                    "diameter_mm": float(d),
                    "pressure_kpa": float(p),
                    "grip_force_n": _num(ds["grip_force_n"].values[i, j]),
                    "contact_force_n": _num(ds["contact_force_n"].values[i, j]),
                    "contact": str(ds["contact"].values[i, j]),
                    "contact_angle_deg": _num(ds["contact_angle_deg"].values[i, j]),
                    "equilibrium": bool(ds["equilibrium"].values[i, j]),
                    "note": str(ds["note"].values[i, j]) or None,
                })
        if as_json:
            obj = {"model": mname, "actuator": act.name or act.kind, "L0_mm": act.L0_mm, "fingers": gr.fingers,
                   "base_radius_mm": gr.base_radius_mm, "fingertip_mm": gr.fingertip_mm,
                   "contact_offset_mm": gr.contact_offset_mm, "mu": gr.mu, "splay_deg": gr.splay_deg,
                   "units": {"grip_force_n": "N (whole gripper)", "contact_force_n": "N (per finger)",
                             "contact_angle_deg": "deg (sphere normal from the downward vertical)"},
                   "results": rows}
            typer.echo(json.dumps(obj, indent=2))
            return
        typer.echo(f"{gr.fingers}-finger gripper, {act.name or act.kind}, L0 = {act.L0_mm:g} mm, base radius "
                   f"{gr.base_radius_mm:g} mm, mu = {gr.mu:g} — {mname.replace('_', '-')} model")
        typer.echo(f"{'D (mm)':>7} {'P (kPa)':>8} {'grip (N)':>9} {'N/finger':>9} {'contact':>8} {'β (deg)':>8}  note")
        for r in rows:
            typer.echo(f"{r['diameter_mm']:7.4g} {r['pressure_kpa']:8.4g} {_fmt(r['grip_force_n'], '9.2f')} "
                       f"{_fmt(r['contact_force_n'], '9.2f')} {r['contact']:>8} {_fmt(r['contact_angle_deg'], '8.1f')}"
                       + (f"  {r['note']}" if r["note"] else ""))
        if plot is not None:
            typer.echo(f"wrote {plot}")

    # ---- wrist --------------------------------------------------------------------------------
    @app.command("wrist", cls=MultiValueCommand)
    def wrist_cmd(
        preset: PresetOpt = None,
        actuator: ActuatorOpt = None,
        model: ModelOpt = Model.energy,
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
                                          "(N*mm^2); default: the frame's strong axis.")] = None,
        column_stiffness: Annotated[
            float, typer.Option("--column-stiffness-nmm2", help="Bending stiffness of the column (N*mm^2).")] = 0.0,
        load_g: Annotated[float, typer.Option("--load-g", help="Mass held horizontally (g).")] = 335.0,
        lever_mm: Annotated[float, typer.Option("--lever-mm", help="Lever of the mass beyond the wrist (mm).")] = 100.0,
        hand_mass_g: Annotated[float, typer.Option("--hand-mass-g", help="Mass of the hand (g).")] = 0.0,
        hand_lever_mm: Annotated[float, typer.Option("--hand-lever-mm", help="Lever of the hand's mass (mm).")] = 50.0,
        as_json: JsonOpt = False,
        plot: PlotOpt = None,
    ):
        """Bending angle of a four-actuator wrist per direction, and the load it holds horizontally."""
        from ..design.wrist import Wrist, wrist_hold, wrist_sweep
        from .options import load_actuator, model_name, parse_values, pressures_kpa

        act = load_actuator(preset, actuator, model)
        P = pressures_kpa(pressure_kpa)
        dirs = parse_values(direction_deg, "--direction-deg") if direction_deg else [0.0, 90.0, 180.0, 270.0]
        _budget(len(P) * len(dirs), "--pressure-kpa x --direction-deg")
        mname = model_name(model)
        plot = _plot_target(plot)
        w = Wrist(act, mname, radius_mm=radius_mm, length_mm=length_mm, lateral_stiffness_nmm2=lateral_stiffness,
                  column_stiffness_nmm2=column_stiffness)
        table = wrist_sweep(w, P, dirs)
        holds = [wrist_hold(w, p, load_g=load_g, lever_mm=lever_mm, hand_mass_g=hand_mass_g,
                            hand_lever_mm=hand_lever_mm) for p in P]
        if plot is not None:
            from ..design.wrist import plot_wrist
            from ..plots import save_figure

            save_figure(plot_wrist(table, holds, title=f"wrist of four {act.kind}s, L = {w.length_mm:g} mm"), plot)
        results = [{"direction_deg": float(r.direction_deg), "pressure_kpa": float(r.pressure_kpa),
                    "angle_deg": _num(r.angle_deg), "bend_direction_deg": _num(r.bend_direction_deg),
                    "curvature_per_mm": _num(r.curvature_per_mm), "equilibrium": bool(r.equilibrium),
                    "note": r.note or None} for r in table.itertuples()]
        holding = [{"pressure_kpa": h.pressure_kpa, "angle_deg": _num(h.angle_deg),
                    "holds_horizontal": bool(h.holds_horizontal), "capacity_g": _num(h.capacity_g),
                    "equilibrium": bool(h.equilibrium), "note": h.note or None} for h in holds]
        if as_json:
            obj = {"model": mname, "actuator": act.name or act.kind, "length_mm": w.length_mm, "radius_mm": w.radius_mm,
                   "lateral_stiffness_nmm2": w.lateral_stiffness_nmm2, "column_stiffness_nmm2": w.column_stiffness_nmm2,
                   "load": {"load_g": load_g, "lever_mm": lever_mm, "hand_mass_g": hand_mass_g,
                            "hand_lever_mm": hand_lever_mm,
                            "load_moment_nmm": holds[0].load_moment_nmm if holds else None,
                            "pressure_needed_kpa": _num(holds[0].pressure_needed_kpa) if holds else None},
                   "results": results, "holding": holding}
            typer.echo(json.dumps(obj, indent=2))
            return
        typer.echo(f"wrist of four {act.name or act.kind}, L = {w.length_mm:g} mm, radius {w.radius_mm:g} mm, "
                   f"lateral stiffness {w.lateral_stiffness_nmm2:.4g} N·mm² — {mname.replace('_', '-')} model")
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
        if plot is not None:
            typer.echo(f"wrote {plot}")

    return app
