"""The figures of :mod:`bendpam.design`: finger shapes, grip force, wrist bending, inverse-design maps.

Each function is registered with :mod:`bendpam.infra.accessors` under a name, and the design
layer's ``plot_*`` functions reach it by that name (``figure("grasp")(ds)``), so that computing a
design never imports this presentation layer.

==================  ====================================================================
name                function
==================  ====================================================================
``finger_shapes``   :func:`plot_finger_shapes` (finger shapes at several pressures)
``grasp``           :func:`plot_grasp` (grip force against sphere diameter)
``wrist``           :func:`plot_wrist` (wrist bending angle against pressure)
``coarse_map``      :func:`plot_coarse_map` (an inverse design's coarse map)
``pareto``          :func:`plot_pareto` (an inverse design's Pareto front)
``save_figure``     :func:`bendpam.present.figures.save_figure` (for ``DesignResult.save``)
==================  ====================================================================
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import matplotlib
import numpy as np
from matplotlib.colors import LogNorm

from bendpam.design.targets import NAN_MISS, TOL
from bendpam.design.wrist import wrist_pressures
from bendpam.errors import InputError
from bendpam.infra.accessors import register
from bendpam.present.figures.style import figure_size, figure_style, new_figure, save_figure

if TYPE_CHECKING:
    from bendpam.design.result import DesignResult

__all__ = [
    "plot_coarse_map",
    "plot_finger3d",
    "plot_finger_shapes",
    "plot_grasp",
    "plot_pareto",
    "plot_wrist",
]

# the design layer saves its figures through the accessor too (DesignResult.save)
register("save_figure")(save_figure)

_MARKERS = ("o", "s", "^", "D", "v", "P", "X", "*", "<", ">", "h", "p")


@register("finger_shapes")
def plot_finger_shapes(shapes, ax=None, title: str | None = None, free=None):
    """Draw finger shapes (frame line, fingertip, tip point) on ``ax``; returns the figure.

    Shapes without equilibrium are drawn dashed from their last equilibrium (``limit``) if any.
    ``free``: the same pressures' unloaded shapes, drawn dotted in the same colours (free and loaded).

    Examples
    --------
    >>> from bendpam.physics.presets import be_pam
    >>> from bendpam.design import Finger, solve_finger
    >>> finger = Finger(be_pam())
    >>> fig = plot_finger_shapes([solve_finger(finger, p) for p in (100.0, 150.0)])
    >>> len(fig.axes)                                     # fig.savefig("shapes.png") to keep it
    1
    """
    if ax is None:
        fig = new_figure((6.0, 5.0))
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    shapes = list(shapes)
    colors = matplotlib.colormaps["viridis"](np.linspace(0.0, 0.9, max(len(shapes), 1)))
    for sh, col in zip(shapes, colors, strict=False):
        draw, style = (sh, "-") if sh.equilibrium else (sh.limit, "--")
        label = f"{sh.pressure_kpa:g} kPa" + (", loaded" if free else "") + ("" if sh.equilibrium else
                                                                              " (no equilibrium)")
        if draw is None:
            ax.plot([], [], style, color=col, label=label)
            continue
        ax.plot(draw.x, draw.y, style, color=col, label=label)
        ax.plot([draw.x[-1], draw.tip_xy[0]], [draw.y[-1], draw.tip_xy[1]], style, color=col, lw=3, alpha=0.6)
        ax.plot(*draw.tip_xy, "o", color=col, ms=4)
    free = list(free or [])
    for sh, col in zip(free, colors, strict=False):
        if sh.equilibrium:
            ax.plot(sh.x, sh.y, ":", color=col, lw=1.2)
    if free:
        ax.plot([], [], ":", color="0.3", lw=1.2, label="free (no load)")
    if shapes:
        x0, y0 = shapes[0].finger.base_xy_mm
        ax.plot(x0, y0, "ks", ms=6)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title)
    return fig


@register("finger3d")
def plot_finger3d(shapes, ax=None, title: str | None = None):
    """Draw spatial finger shapes in 3-D (frame line, tip point, the bending plane's base); returns the figure.

    Shapes without equilibrium are drawn dashed from their last equilibrium (``limit``) if any.

    Examples
    --------
    >>> from bendpam.physics.presets import be_pam
    >>> from bendpam.design import Finger
    >>> from bendpam.design.finger3d import Finger3D, FingerLoads3D, solve_finger3d
    >>> sh = solve_finger3d(Finger3D(Finger(be_pam(), nodes=11)), 150.0, FingerLoads3D(tip_force_n=(0.0, 0.0, 0.5)))
    >>> fig = plot_finger3d([sh])
    >>> fig.axes[0].name
    '3d'
    """
    if ax is None:
        fig = new_figure((6.0, 5.0))
        ax = fig.add_subplot(projection="3d")
    else:
        fig = ax.figure
    shapes = list(shapes)
    colors = matplotlib.colormaps["viridis"](np.linspace(0.0, 0.9, max(len(shapes), 1)))
    pts = []
    for sh, col in zip(shapes, colors, strict=False):
        draw, style = (sh, "-") if sh.equilibrium else (sh.limit, "--")
        label = f"{sh.pressure_kpa:g} kPa" + ("" if sh.equilibrium else " (no equilibrium)")
        if draw is None:
            ax.plot([], [], [], style, color=col, label=label)
            continue
        xyz, tip = draw.xyz, np.asarray(draw.tip_xyz)
        ax.plot(xyz[:, 0], xyz[:, 1], xyz[:, 2], style, color=col, label=label)
        ax.plot([xyz[-1, 0], tip[0]], [xyz[-1, 1], tip[1]], [xyz[-1, 2], tip[2]], style, color=col, lw=3, alpha=0.6)
        ax.scatter([tip[0]], [tip[1]], [tip[2]], color=col, s=12)
        pts.append(np.vstack([xyz, tip]))
    if pts:
        P = np.vstack(pts)
        mid, half = 0.5 * (P.max(0) + P.min(0)), 0.5 * float(np.max(P.max(0) - P.min(0))) + 1.0
        ax.set_xlim(mid[0] - half, mid[0] + half)
        ax.set_ylim(mid[1] - half, mid[1] + half)
        ax.set_zlim(mid[2] - half, mid[2] + half)
        b = shapes[0].finger3d.base_xyz_mm
        ax.scatter([b[0]], [b[1]], [b[2]], color="k", marker="s", s=20)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title)
    return fig


@register("grasp")
def plot_grasp(ds, ax=None, title: str | None = None):
    """Grip (pull-out) force against sphere diameter, one line per pressure (cf. the paper's Figure 8(c, d)).

    ``ds`` is a :func:`grasp_sweep` result.  Where the gripper has no contact or no equilibrium the
    line has a gap (no point, no line through it), never a 0 N point; each pressure has its own
    marker and colour.  The figure is sized for a journal column (:func:`bendpam.present.figures.figure_size`).
    Returns the figure.

    Examples
    --------
    >>> from bendpam.physics.presets import be_pam
    >>> from bendpam.design import Gripper, grasp_sweep
    >>> gripper = Gripper(be_pam().replace(L0_mm=130.0))
    >>> fig = plot_grasp(grasp_sweep(gripper, [160.0, 200.0], [160.0]))
    >>> len(fig.axes)                                     # fig.savefig("grip.png") to keep it
    1
    """
    with figure_style():
        if ax is None:
            fig = new_figure(figure_size("single", 0.8))
            ax = fig.add_subplot()
        else:
            fig = ax.figure
        P = ds["pressure_kpa"].values
        D = ds["diameter_mm"].values
        grip = np.array(ds["grip_force_n"].values, dtype=float)
        hole = (ds["contact"].values == "none") | ~ds["equilibrium"].values.astype(bool) | ~np.isfinite(grip)
        colors = matplotlib.colormaps["viridis"](np.linspace(0.0, 0.85, max(P.size, 1)))
        for j, p in enumerate(P):
            y = np.where(hole[:, j], np.nan, grip[:, j])
            ax.plot(D, y, "-", marker=_MARKERS[j % len(_MARKERS)], color=colors[j], label=f"{p:g} kPa")
        ax.set_xlabel("sphere diameter (mm)")
        ax.set_ylabel("grip (pull-out) force (N)")
        ax.set_ylim(bottom=0.0)
        ax.grid(alpha=0.3)
        ax.legend(title="gaps: no contact or\nno equilibrium", ncol=1 if P.size <= 5 else 2)
        ax.set_title(title or f"{ds.attrs.get('fingers', '')}-finger gripper, {ds.attrs.get('actuator', '')}")
        fig.tight_layout()
    return fig


def _wrist_curve_groups(table, positions_deg) -> list[tuple[list[float], np.ndarray, np.ndarray, str]]:
    """Free-bending curves of ``table`` grouped where they coincide: ``(directions, P, angle, label)``.

    With identical actuators the curves of symmetric directions (each single actuator, or each
    pair) are the same; such curves are drawn once and the label says which directions share it.
    """
    groups: list[tuple[list[float], np.ndarray, np.ndarray]] = []
    for d, grp in table.groupby("direction_deg", sort=False):
        grp = grp.sort_values("pressure_kpa")
        P = grp["pressure_kpa"].to_numpy(dtype=float)
        a = grp["angle_deg"].to_numpy(dtype=float)
        for dirs, P0, a0 in groups:
            scale = max(float(np.nanmax(np.abs(a0), initial=0.0)), 1.0)
            if P0.shape == P.shape and np.array_equal(P0, P) and np.allclose(a0, a, rtol=0.0, atol=1e-6 * scale,
                                                                           equal_nan=True):
                dirs.append(float(d))
                break
        else:
            groups.append(([float(d)], P, a))
    out = []
    for dirs, P, a in groups:
        names = []
        for d in dirs:
            on = [p for p, v in zip(positions_deg, wrist_pressures(d, 100.0, positions_deg), strict=True) if v > 0]
            names.append("+".join(f"{p:g}" for p in on) + "°")
        pair = len(names[0].split("+")) > 1
        if len(dirs) == 1:
            label = f"actuator{'s' if pair else ''} {names[0]} inflated (toward {dirs[0]:g}°)"
        else:
            label = (f"{'pairs' if pair else 'actuators'} {', '.join(names)}, {'each pair' if pair else 'one'} "
                     "inflated:\nthe same curve by symmetry")
        out.append((dirs, P, a, label))
    return out


@register("wrist")
def plot_wrist(table, holds=(), ax=None, title: str | None = None, positions_deg=(0.0, 90.0, 180.0, 270.0)):
    """Bending angle against pressure per inflated actuator (and the holding angles with the load, dashed).

    Each curve has its own colour, line style and marker, and its legend entry names the inflated
    actuator(s) by their position (deg) and the bending direction.  Directions whose curves
    coincide (identical actuators at symmetric positions) are drawn once, and the legend says so
    instead of drawing identical lines on top of each other.

    Parameters
    ----------
    table : pandas.DataFrame
        From :func:`wrist_sweep`.
    holds : sequence of :class:`WristHold`, optional
        From :func:`wrist_hold`, one per pressure (drawn dashed in black).
    ax : matplotlib Axes, optional
        Default: a new single-column figure.
    title : str, optional
    positions_deg : 4 floats
        The actuators' positions (deg), to name them (default the :class:`Wrist` default).

    Returns
    -------
    matplotlib.figure.Figure

    Examples
    --------
    >>> from bendpam.design import Wrist, wrist_sweep
    >>> fig = plot_wrist(wrist_sweep(Wrist(), [100.0, 150.0], directions_deg=(90.0,)))
    >>> len(fig.axes) >= 1                                # fig.savefig("wrist.png") to keep it
    True
    """
    own = ax is None
    with figure_style():
        if ax is None:
            fig = new_figure(figure_size("single", 1.15))
            ax = fig.add_subplot()
        else:
            fig = ax.figure
        _draw_wrist(ax, table, holds, title, positions_deg)
        if own:
            fig.tight_layout()
    return fig


def _draw_wrist(ax, table, holds, title, positions_deg) -> None:
    """The curves of :func:`plot_wrist` on ``ax``: a colour, line style and marker per distinct curve."""
    styles = ("-", "--", "-.", ":")
    markers = ("o", "s", "^", "D", "v", "P")
    for i, (_, P, a, label) in enumerate(_wrist_curve_groups(table, positions_deg)):
        ax.plot(P, a, linestyle=styles[i % len(styles)], marker=markers[i % len(markers)], color=f"C{i % 10}",
                label=label)
    holds = list(holds)
    if holds:
        ax.plot([h.pressure_kpa for h in holds], [h.angle_deg for h in holds], "s--", color="k", mfc="none",
                label=f"holding {holds[0].load_g:g} g at {holds[0].lever_mm:g} mm")
        ax.axhline(0.0, color="0.5", lw=0.8)
    ax.axhline(30.0, color="tab:red", lw=0.8, ls=":", label="30°")
    ax.set_xlabel("pressure (kPa)")
    ax.set_ylabel("bending angle (deg)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", loc="upper center", bbox_to_anchor=(0.5, -0.2), borderaxespad=0.0)
    if title:
        ax.set_title(title)


@register("coarse_map")
def plot_coarse_map(result: DesignResult):
    """The coarse map in the first two variables (colour: largest relative miss), the design starred.

    Examples
    --------
    >>> from bendpam.physics.presets import be_pam
    >>> from bendpam.design.inverse import design_actuator
    >>> res = design_actuator(be_pam(), ["blocked_moment_nmm=400@200"], ["alpha0_deg=60:80"], n_coarse=16, n_starts=1)
    >>> fig = plot_coarse_map(res)
    >>> len(fig.axes)                                     # the map and its colour bar
    2
    """
    c = result.coarse
    names = [v.name for v in result.variables]
    fig = new_figure((3.5, 2.9), layout="constrained")
    ax = fig.add_subplot()
    v = np.clip(np.nan_to_num(c["violation"], nan=NAN_MISS), 1e-3, 3.0)
    x = c["X"][:, 0]
    y = c["X"][:, 1] if len(names) > 1 else v
    sc = ax.scatter(x, y, c=v, s=5, cmap="viridis_r", norm=LogNorm(1e-3, 3.0), linewidths=0)
    bx = result.values[names[0]]
    by = result.values[names[1]] if len(names) > 1 else max(1e-3, float(np.max(np.abs(result.relative_error))))
    ax.plot([bx], [by], marker="*", color="tab:red", ms=11, mec="k", mew=0.6, ls="none",
            label="design" if result.feasible else "closest design")
    ax.set_xlabel(names[0])
    ax.set_ylabel(names[1] if len(names) > 1 else "largest relative miss")
    if len(names) == 1:
        ax.set_yscale("log")
    cb = fig.colorbar(sc, ax=ax, pad=0.01)
    cb.set_label("largest relative miss", fontsize=8)
    ax.legend(fontsize=7, loc="best")
    ax.set_title(f"coarse map ({len(x)} designs, {c['method']})", fontsize=8)
    return fig


@register("pareto")
def plot_pareto(result: DesignResult):
    """The Pareto front of the two targets over the coarse map's designs that meet every margin.

    Examples
    --------
    >>> from bendpam.physics.presets import be_pam
    >>> from bendpam.design.inverse import design_actuator
    >>> res = design_actuator(be_pam(), ["blocked_moment_nmm>=300@150", "free_angle_deg>=60@150"],
    ...                       ["alpha0_deg=60:80", "R0_mm=7:10"], n_coarse=16, n_starts=1)
    >>> fig = plot_pareto(res)
    >>> len(fig.axes)                                     # fig.savefig("pareto.png") to keep it
    1
    """
    pf = result.pareto
    if pf is None:
        raise InputError("this design has no Pareto front (it needs exactly two targets)")
    t1, t2 = pf.targets
    fig = new_figure((3.5, 2.8), layout="constrained")
    ax = fig.add_subplot()
    Q = result.coarse["quantities"]
    ok = np.isfinite(result.coarse["min_margin"]) & (result.coarse["min_margin"] >= result.min_margin_required * (
        1 - TOL)) if np.any(np.isfinite(result.coarse["min_margin"])) else np.ones(len(Q), bool)
    ax.scatter(Q[ok, 0], Q[ok, 1], s=3, color="0.75", linewidths=0, label="designs (margins met)")
    ax.plot(pf.quantities[:, 0], pf.quantities[:, 1], "-o", color="tab:blue", ms=3, lw=1.2, label="Pareto front")
    ax.axvline(t1.value, color="k", ls="--", lw=0.7)
    ax.axhline(t2.value, color="k", ls="--", lw=0.7)
    ax.plot([result.achieved[0]], [result.achieved[1]], marker="*", color="tab:red", ms=11, mec="k", mew=0.6,
            ls="none", label="design" if result.feasible else "closest design")
    ax.set_xlabel(t1.label, fontsize=8)
    ax.set_ylabel(t2.label, fontsize=8)
    ax.legend(fontsize=6.5, loc="best")
    return fig
