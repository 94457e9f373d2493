"""The 3-D figures of the soft hand (:mod:`bendpam.design.hand`, :mod:`bendpam.design.kapandji`).

==================  ====================================================================
name                function
==================  ====================================================================
``hand_pose``       :func:`plot_hand_pose` (the hand's centrelines at one set of pressures)
``kapandji``        :func:`plot_kapandji` (the thumb's closest pose for each Kapandji point)
``hand_workspace``  :func:`plot_hand_workspace` (the tips reachable over a pressure grid)
``hand_statics``    :func:`plot_hand_statics` (the hand under its weight and tip loads)
``wrist_map``       :func:`plot_wrist_map` (the wrist's tilt for each pressure combination)
==================  ====================================================================

The hand frame is the one of :mod:`bendpam.design.hand` (x radial, y distal, z palmar; mm), drawn
with equal scales on the three axes; the wrist's map is drawn in the plane of its actuators.
"""

from __future__ import annotations

import numpy as np

from bendpam.infra.accessors import register
from bendpam.present.figures.style import figure_size, figure_style, new_figure

__all__ = ["plot_hand_pose", "plot_hand_statics", "plot_hand_workspace", "plot_kapandji", "plot_wrist_map"]

_TOUCH_COLOURS = {"tip": "tab:green", "thumb": "tab:orange", "none": "tab:red"}


def _axes3d(ax):
    """A 3-D axes (a new single-column figure when ``ax`` is None) and whether the figure is new."""
    if ax is not None:
        return ax.figure, ax, False
    fig = new_figure(figure_size("single", 1.0))
    return fig, fig.add_subplot(projection="3d"), True


def _finish(ax, points: np.ndarray, title: str | None, own: bool) -> None:
    """Equal scales around ``points`` (n, 3), labels and the title; the layout of a figure of our own."""
    lo, hi = np.nanmin(points, axis=0), np.nanmax(points, axis=0)
    mid, half = (lo + hi) / 2.0, max(float(np.max(hi - lo)) / 2.0, 1.0)
    ax.set_xlim(mid[0] - half, mid[0] + half)
    ax.set_ylim(mid[1] - half, mid[1] + half)
    ax.set_zlim(mid[2] - half, mid[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x, radial (mm)")
    ax.set_ylabel("y, distal (mm)")
    ax.set_zlabel("z, palmar (mm)")
    ax.view_init(elev=35, azim=-120)
    if title:
        ax.set_title(title)
    if own:
        ax.figure.tight_layout()


def _palm(hand) -> np.ndarray:
    """The palm's outline (5, 3): wrist crease to the knuckle line, in the plane z = 0 (mm)."""
    xs = [b[0] for b in hand.finger_bases_mm.values()]
    ys = [b[1] for b in hand.finger_bases_mm.values()]
    r = hand.radius_mm
    x0, x1, y1 = min(xs) - r, max(xs) + r, min(ys)
    return np.array([[x0, 0.0, 0.0], [x1, 0.0, 0.0], [x1, y1, 0.0], [x0, y1, 0.0], [x0, 0.0, 0.0]])


def _draw_pose(ax, pose, colour=None, label: str | None = None, alpha: float = 1.0) -> np.ndarray:
    """The centrelines of ``pose`` on ``ax``; returns every point drawn (n, 3)."""
    drawn = [_palm(pose.hand)]
    ax.plot(*drawn[0].T, color="0.6", lw=0.8)
    for i, (name, pts) in enumerate(pose.centrelines_mm.items()):
        c = colour or ("tab:blue" if name == "thumb" else ("0.5" if name == "palm_roll" else "0.2"))
        ax.plot(*pts.T, color=c, lw=1.0 if name == "palm_roll" else 2.0, alpha=alpha,
                ls=":" if name == "palm_roll" else "-", label=label if i == 0 else None)
        drawn.append(pts)
    return np.vstack(drawn)


@register("hand_pose")
def plot_hand_pose(pose, ax=None, title: str | None = None):
    """Draw the hand at one set of pressures (a :class:`~bendpam.design.hand.HandPose`) in 3-D; returns the figure.

    Fingers dark, thumb blue, the palm roll (the thumb base's path around the index axis) dotted.

    Examples
    --------
    >>> from bendpam.design.hand import default_hand, hand_pose
    >>> fig = plot_hand_pose(hand_pose(default_hand(), {"index": 200.0}))
    >>> fig.axes[0].name                                  # fig.savefig("hand.png") to keep it
    '3d'
    """
    with figure_style():
        fig, ax, own = _axes3d(ax)
        pts = _draw_pose(ax, pose)
        for name, tip in pose.tips_mm.items():
            ax.scatter(*tip, s=8, color="tab:blue" if name == "thumb" else "0.2")
        _finish(ax, pts, title or "hand pose", own)
    return fig


@register("kapandji")
def plot_kapandji(result, ax=None, title: str | None = None):
    """Draw the Kapandji test (a :class:`~bendpam.design.kapandji.KapandjiResult`): each point, coloured by
    what touches it (green the tip, orange the thumb, red nothing), and the thumb's closest pose for it (with the
    finger that carries the point, when it flexes to meet the thumb), over the hand at its finger pressures.

    Examples
    --------
    >>> from bendpam.design.hand import default_hand
    >>> from bendpam.design.kapandji import kapandji
    >>> fig = plot_kapandji(kapandji(default_hand(), points=(4,), grid=5, starts=1))
    >>> fig.axes[0].name
    '3d'
    """
    from bendpam.design.hand import hand_pose

    with figure_style():
        fig, ax, own = _axes3d(ax)
        drawn = []
        base = hand_pose(result.hand, result.finger_pressures_kpa)
        drawn.append(_draw_pose(ax, base, colour="0.75", alpha=0.6))
        cmap = [f"C{i}" for i in range(10)]
        for i, p in enumerate(result.points):
            pose = hand_pose(result.hand, {k: v for k, v in p.pressures_kpa.items() if v == v})
            for part in ("thumb", *(f for f in pose.centrelines_mm if f in p.pressures_kpa)):  # and a moved finger
                ax.plot(*pose.centrelines_mm[part].T, color=cmap[i % 10], lw=1.2, alpha=0.8)
            t = np.asarray(p.target_mm)
            ax.scatter(*t, s=25, color=_TOUCH_COLOURS[p.touched_by], edgecolors="k", linewidths=0.4, zorder=5)
            ax.text(*t, f" {p.number}", fontsize=7)
            drawn.append(pose.centrelines_mm["thumb"])
        for by, c in _TOUCH_COLOURS.items():
            ax.scatter([], [], [], color=c, label=f"touched: {by}")
        ax.legend(fontsize="x-small", loc="upper left")
        _finish(ax, np.vstack(drawn), title or f"Kapandji test: score {result.score}", own)
    return fig


@register("hand_workspace")
def plot_hand_workspace(ws, ax=None, title: str | None = None):
    """Draw the reachable tips (a :class:`~bendpam.design.kapandji.HandWorkspace`): each finger's tip path and the
    thumb tip's cloud, over the straight hand.

    Examples
    --------
    >>> from bendpam.design.hand import default_hand
    >>> from bendpam.design.kapandji import hand_workspace
    >>> fig = plot_hand_workspace(hand_workspace(default_hand(), n=4))
    >>> fig.axes[0].name
    '3d'
    """
    from bendpam.design.hand import hand_pose

    with figure_style():
        fig, ax, own = _axes3d(ax)
        pts = [_draw_pose(ax, hand_pose(ws.hand), colour="0.75", alpha=0.6)]
        for f, tips in ws.finger_tips_mm.items():
            ax.plot(*tips.T, lw=1.2, marker=".", ms=3, label=f)
            pts.append(tips)
        t = ws.thumb_tips_mm
        ax.scatter(*t.T, s=2, color="tab:blue", alpha=0.25, label="thumb tip")
        pts.append(t)
        ax.legend(fontsize="x-small", loc="upper left")
        _finish(ax, np.vstack(pts), title or "reachable tips", own)
    return fig


@register("hand_statics")
def plot_hand_statics(statics, ax=None, title: str | None = None):
    """Draw the loaded hand (a :class:`~bendpam.design.hand_statics.HandStatics`): each rod's loaded centreline
    (fingers dark, thumb blue) over the unloaded pose (light grey).

    Examples
    --------
    >>> from bendpam.design.hand import default_hand
    >>> from bendpam.design.hand_statics import hand_statics
    >>> fig = plot_hand_statics(hand_statics(default_hand(), mass_per_length_g_per_mm=0.0, nodes=11))
    >>> fig.axes[0].name
    '3d'
    """
    with figure_style():
        fig, ax, own = _axes3d(ax)
        pts = [_draw_pose(ax, statics.pose, colour="0.8", alpha=0.7)]
        for name, sh in statics.shapes.items():
            xyz = np.asarray(sh.xyz, dtype=float)
            ax.plot(*xyz.T, color="tab:blue" if name.startswith("thumb") else "0.2", lw=2.0)
            pts.append(xyz)
        g = np.asarray(statics.gravity)
        ax.quiver(0.0, 0.0, 0.0, *(40.0 * g), color="tab:red", arrow_length_ratio=0.2)
        ax.text(*(45.0 * g), "g", color="tab:red", fontsize=8)
        _finish(ax, np.vstack(pts), title or "hand under load (grey: unloaded)", own)
    return fig


@register("wrist_map")
def plot_wrist_map(wmap, ax=None, title: str | None = None):
    """Draw an orientation map of the wrist (a :class:`~bendpam.design.wrist_tilt.WristMap`): each pressure
    combination's tilt as a point ``(tilt cos psi, tilt sin psi)`` (deg) in the plane of the actuators, coloured
    by the smallest frame-buckling margin (red below 1); crosses where there is no equilibrium (at the origin).

    Examples
    --------
    >>> from bendpam.design.wrist import Wrist
    >>> from bendpam.design.wrist_tilt import wrist_map
    >>> fig = plot_wrist_map(wrist_map(Wrist(), [[0.0, 150.0, 0.0, 0.0], [150.0, 150.0, 0.0, 0.0]]))
    >>> len(fig.axes)                                     # the map and its colour bar
    2
    """
    import matplotlib

    with figure_style():
        own = ax is None
        if own:
            fig = new_figure(figure_size("single", 0.9))
            ax = fig.add_subplot()
        else:
            fig = ax.figure
        t = np.nan_to_num(np.asarray(wmap.tilt_deg, dtype=float))
        psi = np.radians(np.nan_to_num(np.asarray(wmap.direction_deg, dtype=float)))
        margin = np.min(np.asarray(wmap.buckling_margin, dtype=float), axis=1)
        ok = np.asarray(wmap.equilibrium, dtype=bool)
        norm = matplotlib.colors.Normalize(vmin=0.0, vmax=2.0)
        sc = ax.scatter(t[ok] * np.cos(psi[ok]), t[ok] * np.sin(psi[ok]), c=np.minimum(margin[ok], 2.0),
                        cmap="RdYlGn", norm=norm, s=14, edgecolors="k", linewidths=0.3)
        if np.any(~ok):
            ax.scatter(np.zeros(int(np.sum(~ok))), np.zeros(int(np.sum(~ok))), marker="x", color="k",
                       label="no equilibrium")
            ax.legend(fontsize="x-small")
        fig.colorbar(sc, ax=ax, label="smallest buckling margin")
        for r in (15.0, 30.0):
            a = np.linspace(0.0, 2.0 * np.pi, 181)
            ax.plot(r * np.cos(a), r * np.sin(a), color="0.7", lw=0.6, ls=":")
        ax.set_aspect("equal")
        ax.set_xlabel("tilt toward 0 deg (deg)")
        ax.set_ylabel("tilt toward 90 deg (deg)")
        ax.set_title(title or "wrist orientation per pressure combination")
        if own:
            fig.tight_layout()
    return fig
