"""``bendpam hand``: the soft humanoid hand's pose, reachable workspace and Kapandji test (issue 26).

``register(app)`` adds the command to the ``bendpam`` Typer app.  It reads a hand description
(TOML, :meth:`bendpam.design.hand.Hand.from_toml`; without ``--hand``, the documented defaults),
poses the hand at the given pressures, optionally runs the Kapandji test and the workspace, prints
a table or (``--json``) one JSON object, and writes ``hand.json`` and the 3-D figures into ``--out``
through one :class:`~bendpam.infra.outputs.OutputSet`.
"""

# no ``from __future__ import annotations``: Typer reads the annotations of the command functions.
import math
from pathlib import Path
from typing import Annotated, Any, Optional

import typer

from bendpam.cli.options import (
    FigureFormatOpt,
    MultiValueCommand,
    PressureOpt,
    UserError,
    echo_wrote,
    output_set,
    pressures_kpa,
    print_json,
)
from bendpam.cli.options import fmt_num as _fmt

__all__ = ["register"]


def _part_pressures(values: list[float], parts: tuple, max_kpa: float) -> dict[str, float]:
    """``--pressure-kpa``: one value for every part, or one per part in the order of ``parts``."""
    if not values:
        return {}
    if len(values) not in (1, len(parts)):
        raise UserError(f"--pressure-kpa: {len(values)} values; give one (every part) or {len(parts)} "
                        f"(in the order {', '.join(parts)})")
    vals = values * len(parts) if len(values) == 1 else values
    for p in vals:
        if p > max_kpa:
            raise UserError(f"--pressure-kpa: {p:g} kPa is above the hand's max_pressure_kpa = {max_kpa:g} kPa "
                            "(set it in the hand file's [hand] table)")
    return dict(zip(parts, vals, strict=True))


def hand_cmd(
    hand_file: Annotated[Optional[Path], typer.Option("--hand", help="Hand description (TOML); default: the "
                                                      "documented default hand.")] = None,
    pressure_kpa: PressureOpt = None,
    kapandji_test: Annotated[bool, typer.Option("--kapandji", help="Run the Kapandji test (8 points).")] = False,
    workspace: Annotated[
        Optional[int], typer.Option("--workspace", help="Reachable tips over N pressures per part (2-30).")] = None,
    gravity: Annotated[
        Optional[str], typer.Option("--gravity", metavar="GX,GY,GZ", help="Solve the hand under its weight with "
                                    "gravity along this direction (hand frame: x radial, y distal, z palmar); "
                                    "each part a spatial rod.")] = None,
    mass_per_length: Annotated[
        float, typer.Option("--mass-per-length-g-mm", help="With --gravity: mass of the BE-PAMs per length "
                            "(g/mm).")] = 0.24,
    out: Annotated[Optional[Path], typer.Option("--out", help="Output folder: hand.json and the 3-D "
                                                "figures.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object instead of a table.")] = False,
    fig_format: FigureFormatOpt = None,
):
    """Pose, reachable workspace and Kapandji test of the soft humanoid hand (BE-PAM fingers, two-segment thumb).

    --pressure-kpa takes one pressure for every part or seven, in the order index, middle, ring,
    little, thumb_proximal, thumb_distal, palm_roll.  --gravity adds the hand under its weight.
    """
    from bendpam.design.hand import PARTS, Hand, default_hand, hand_pose
    from bendpam.design.kapandji import hand_workspace, kapandji

    if fig_format is not None and out is None:
        raise UserError(f"--format {fig_format.value}: the figures are written into --out; give --out DIR")
    if workspace is not None and not 2 <= workspace <= 30:
        raise UserError(f"--workspace: {workspace} must be a number of pressures from 2 to 30")
    hand = Hand.from_toml(hand_file) if hand_file is not None else default_hand()
    P = _part_pressures(pressures_kpa(pressure_kpa, None) if pressure_kpa else [], PARTS, hand.max_pressure_kpa)
    pose = hand_pose(hand, P)
    statics = _statics(hand, P, gravity, mass_per_length)
    kap = kapandji(hand) if kapandji_test else None
    ws = hand_workspace(hand, workspace) if workspace is not None else None
    record: dict[str, Any] = {"hand": hand.to_dict(), "pose": pose.to_dict(),
                              "units": {"x_mm": "radial (toward the thumb)", "y_mm": "distal (along the fingers)",
                                        "z_mm": "palmar (the side the fingers curl to)"}}
    if statics is not None:
        record["statics"] = statics.to_dict()
    if kap is not None:
        record["kapandji"] = kap.to_dict()
    if ws is not None:
        record["workspace"] = ws.to_dict()
    files: list[str] = []
    if out is not None:
        fmt = fig_format.value if fig_format is not None else "png"
        with output_set(out, [hand_file]) as o:
            files = _write(o, record, {"pose": pose, "statics": statics, "kapandji": kap, "workspace": ws}, fmt)
    if as_json:
        print_json(record)
        return
    _print(hand, pose, kap, ws)
    if statics is not None:
        _print_statics(statics)
    if out is not None:
        echo_wrote(f"wrote {out}/ ({', '.join(files)})")


def _statics(hand, P: dict, gravity: Optional[str], mass_per_length: float):
    """The loaded hand of --gravity (None without it)."""
    if gravity is None:
        if mass_per_length != 0.24:
            raise UserError("--mass-per-length-g-mm goes with --gravity GX,GY,GZ")
        return None
    from bendpam.design.hand_statics import hand_statics

    parts = [p for p in gravity.replace(";", ",").split(",") if p.strip()]
    try:
        g = [float(p) for p in parts]
    except ValueError:
        raise UserError(f"--gravity: {gravity!r} must be three numbers GX,GY,GZ (a direction)") from None
    if len(g) != 3 or not all(math.isfinite(v) for v in g) or not any(g):
        raise UserError(f"--gravity: {gravity!r} must be three finite numbers GX,GY,GZ, not all 0 (a direction)")
    if not (math.isfinite(mass_per_length) and 0.0 <= mass_per_length <= 10.0):
        raise UserError(f"--mass-per-length-g-mm: {mass_per_length:g} g/mm must be in [0, 10]")
    return hand_statics(hand, P, gravity=tuple(g), mass_per_length_g_per_mm=mass_per_length)


def _print_statics(st) -> None:
    """The loaded tips of --gravity."""
    g = ", ".join(f"{v:.3g}" for v in st.gravity)
    typer.echo(f"\nunder its weight ({st.mass_per_length_g_per_mm:g} g/mm, gravity along ({g})): "
               + ("" if st.equilibrium else f"NO EQUILIBRIUM: {st.note}"))
    for k, t in st.tips_mm.items():
        xyz = ", ".join(_fmt(v, ".1f") for v in t)
        typer.echo(f"{k:>8} tip ({xyz}) mm, moved {_fmt(st.deflection_mm[k], '.2f')} mm")


def _write(o, record: dict, results: dict, fmt: str) -> list[str]:
    """hand.json and the figures into the output set's staging folder; returns the file names."""
    from bendpam.infra.accessors import figure
    from bendpam.infra.outputs import to_json

    o.write_text("hand.json", to_json(record))
    save = figure("save_figure")
    names = ["hand.json"]
    for stem, res in results.items():
        if res is not None:
            save(res.plot(), Path(o.staging) / f"{stem}.{fmt}", format=fmt)
            names.append(f"{stem}.{fmt}")
    return names


def _print(hand, pose, kap, ws) -> None:
    """The tables of ``bendpam hand``."""
    typer.echo(f"soft hand: max {hand.max_pressure_kpa:g} kPa, thumb planes at {hand.thumb_plane_deg:g}°, "
               f"contact tolerance {hand.contact_tolerance_mm:g} mm — {hand.model.replace('_', '-')} model")
    typer.echo(f"{'part':>15} {'L (mm)':>7} {'P (kPa)':>8} {'angle (deg)':>11} {'max angle':>9}")
    reach = hand.reach_deg()
    for part in hand.parts:
        n = part.name
        typer.echo(f"{n:>15} {part.length_mm:7.4g} {pose.pressures_kpa[n]:8.4g} {_fmt(pose.angles_deg[n], '11.1f')} "
                   f"{_fmt(reach[n], '9.1f')}")
    typer.echo("tips (mm): " + "; ".join(f"{k} ({', '.join(f'{v:.1f}' for v in t)})" for k, t in pose.tips_mm.items()))
    if kap is not None:
        d = kap.to_dict()
        typer.echo(f"\nKapandji test: score {kap.score} (points touched by the tip in an unbroken run from 1); "
                   f"touched by the tip: {', '.join(map(str, d['touched_by_tip'])) or 'none'}; by the thumb only: "
                   f"{', '.join(map(str, d['touched_by_thumb_only'])) or 'none'}")
        typer.echo(f"{'#':>2} {'point':<48} {'d tip (mm)':>10} {'d thumb':>8} {'touched by':>10}  pressures (kPa)")
        for p in kap.points:
            pr = ", ".join(f"{k} {v:.0f}" for k, v in p.pressures_kpa.items())
            typer.echo(f"{p.number:>2} {p.description:<48} {_fmt(p.distance_mm, '10.1f')} "
                       f"{_fmt(p.thumb_distance_mm, '8.1f')} {p.touched_by:>10}  {pr}")
    if ws is not None:
        d = ws.to_dict()["thumb"]
        typer.echo(f"\nthumb tip workspace: {d['points']} poses, convex hull {d['hull_volume_cm3']:.0f} cm³")


def register(app: typer.Typer) -> typer.Typer:
    """Add the ``hand`` command to ``app`` (once; returns ``app``).

    >>> import typer
    >>> app = register(register(typer.Typer()))
    >>> [c.name for c in app.registered_commands]
    ['hand']
    """
    if "hand" in {c.name for c in app.registered_commands}:
        return app
    app.command("hand", cls=MultiValueCommand)(hand_cmd)
    return app
