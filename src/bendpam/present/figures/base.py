"""Figures: moment-curvature maps, the force-balance model's internal stresses, test and fit figures.

Every function draws on a matplotlib ``Axes``/``Figure`` and returns it; :func:`save_figure`
writes PNG, PDF or SVG atomically.  The non-interactive Agg backend is used unless the caller
already chose one.

Figures are sized for a journal column (single column :data:`SINGLE_COLUMN_IN` = 3.5 in / 89 mm,
double column :data:`DOUBLE_COLUMN_IN` = 7.2 in / 183 mm) with 7-9 pt text and consistent line
widths.  The style is applied through :func:`figure_style` (a :func:`matplotlib.rc_context`), so
matplotlib's global settings are never changed: every figure function here draws inside it, and
:func:`save_figure` saves inside it (PDF and SVG keep their text as text, with embedded TrueType
fonts, and carry no creation date, so the same figure gives the same bytes).
"""

from __future__ import annotations

import functools
import os
import textwrap
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import matplotlib

if not os.environ.get("MPLBACKEND"):
    matplotlib.use("Agg")

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.ticker import MaxNLocator

from bendpam.errors import InputError
from bendpam.infra.accessors import register
from bendpam.infra.atomic import atomic_path
from bendpam.physics.braid import curvature_limits
from bendpam.predict import active_pressure_kpa, free_curvature, internal_stresses, moment
from bendpam.validate import file_format

__all__ = [
    "DOUBLE_COLUMN_IN",
    "FIGURE_FORMATS",
    "SINGLE_COLUMN_IN",
    "STYLE",
    "curve_range",
    "demo_figure",
    "figure4",
    "figure7",
    "figure_format",
    "figure_size",
    "figure_style",
    "moment_curvature_figure",
    "moment_curves",
    "plot_internal_stresses",
    "plot_moment_curvature",
    "save_figure",
    "styled_figure",
    "sweep_figure",
]

#: Width of a single journal column, in (89 mm).
SINGLE_COLUMN_IN = 3.5
#: Width of a double (full-page) journal column, in (183 mm).
DOUBLE_COLUMN_IN = 7.2
#: The figure formats :func:`save_figure` writes.
FIGURE_FORMATS = ("png", "pdf", "svg")

#: The rc settings of every bendpam figure (applied with :func:`figure_style`).
STYLE: dict[str, Any] = {
    "figure.figsize": (SINGLE_COLUMN_IN, 2.6),
    "figure.dpi": 100,
    "savefig.dpi": 300,
    "font.size": 8,
    "axes.titlesize": 8,
    "axes.labelsize": 8,
    "xtick.labelsize": 7,
    "ytick.labelsize": 7,
    "legend.fontsize": 7,
    "legend.title_fontsize": 7,
    "figure.titlesize": 9,
    "lines.linewidth": 1.0,
    "lines.markersize": 3.0,
    "axes.linewidth": 0.6,
    "grid.linewidth": 0.4,
    "xtick.major.width": 0.6,
    "ytick.major.width": 0.6,
    "xtick.minor.width": 0.4,
    "ytick.minor.width": 0.4,
    "xtick.major.size": 3.0,
    "ytick.major.size": 3.0,
    "patch.linewidth": 0.6,
    "errorbar.capsize": 2.0,
    "legend.frameon": False,
    "legend.handlelength": 1.8,
    "axes.titlepad": 4.0,
    "pdf.fonttype": 42,
    "ps.fonttype": 42,
    "svg.fonttype": "none",
    "svg.hashsalt": "bendpam",
}

_F = TypeVar("_F", bound=Callable[..., Any])


def figure_style():
    """A context manager applying :data:`STYLE` (journal sizes and fonts) without touching rcParams.

    Examples
    --------
    >>> import matplotlib
    >>> with figure_style():
    ...     inside = matplotlib.rcParams["font.size"]
    >>> inside, matplotlib.rcParams["font.size"] == inside
    (8.0, False)
    """
    return matplotlib.rc_context(STYLE)


def _styled(fn: _F) -> _F:
    """Run a figure function inside :func:`figure_style`."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with figure_style():
            return fn(*args, **kwargs)

    return wrapper  # type: ignore[return-value]


def figure_size(width: str = "single", aspect: float = 0.75) -> tuple[float, float]:
    """Figure size (in) for a journal column: ``width`` ``'single'`` or ``'double'``, height = aspect x width.

    Examples
    --------
    >>> figure_size("single"), figure_size("double", 0.35)
    ((3.5, 2.625), (7.2, 2.52))
    """
    if width not in ("single", "double"):
        raise InputError(f"width = {width!r} must be 'single' or 'double' (journal column)")
    if not (np.isfinite(aspect) and aspect > 0):
        raise InputError(f"aspect = {aspect!r} must be a positive number")
    w = SINGLE_COLUMN_IN if width == "single" else DOUBLE_COLUMN_IN
    return (w, round(w * float(aspect), 4))


def _wrap(text: str, width_in: float, size_pt: float = 8.0) -> str:
    """Wrap ``text`` into lines that fit ``width_in`` inches at ``size_pt`` (about 0.5 em per character)."""
    chars = max(int(width_in * 72.0 / (0.52 * size_pt)), 12)
    return "\n".join(textwrap.fill(part, chars) for part in text.split("\n"))


@_styled
def styled_figure(draw: Callable[[Any], Any], width: str = "single", aspect: float = 0.8):
    """A one-axes figure of journal size drawn by ``draw(ax)`` inside :func:`figure_style`; returns the figure.

    For drawing functions that take an ``ax`` (the design figures).
    """
    fig, ax = plt.subplots(figsize=figure_size(width, aspect))
    draw(ax)
    fig.tight_layout()
    return fig


def figure_format(path, format: str | None = None) -> str:
    """The figure format for ``path``: ``format`` if given, else the suffix (png, pdf or svg; png if none).

    Raises :class:`~bendpam.errors.InputError` (one line) for another format or a suffix that
    disagrees with ``format``.

    Examples
    --------
    >>> figure_format("fig.PDF"), figure_format("fig", "svg"), figure_format("fig")
    ('pdf', 'svg', 'png')
    """
    return file_format(path, format, FIGURE_FORMATS, default="png")


def curve_range(actuator, pressures_kpa, model: str = "energy", k_max: float | None = None, n: int = 200) -> np.ndarray:
    """Curvature grid (1/mm) from 0 toward the bending direction, to ``k_max`` (magnitude).

    The default end is 15 % past the largest free-bending curvature at the given pressures (or past
    the fold curvature where there is no equilibrium), clipped to the lock-up limit.
    """
    lim = curvature_limits(actuator)
    sgn = actuator.bend_sign or 1
    k_lim = lim.k_max if sgn > 0 else lim.k_min
    if k_max is None:
        fb = free_curvature(actuator, pressures_kpa, model)
        ks = np.abs(fb.curvature_per_mm[np.isfinite(fb.curvature_per_mm)])
        end = ks.max() if ks.size else 0.0
        if np.any(~fb.ok):
            end = max(end, abs(fb.branch.k_end_per_mm))
        if end <= 0.0:
            end = 0.1 * abs(k_lim)
        end = min(1.15 * end, abs(k_lim))
    else:
        end = float(k_max)
        if not np.isfinite(end) or end <= 0.0:
            raise InputError(
                f"k_max = {k_max!r} 1/mm must be a positive number (magnitude along the bending direction)")
        if end > abs(k_lim):
            raise InputError(
                f"k_max = {end:g} 1/mm is beyond the braid lock-up limit |k'| = {abs(k_lim):.6g} 1/mm for this actuator"
            )
    return sgn * np.linspace(0.0, end, int(n))


def moment_curves(actuator, pressures_kpa, model: str = "energy", k_max: float | None = None, n: int = 200):
    """Moment-curvature curves: returns ``(k, M)`` with ``M`` of shape (n_pressures, n), N*mm."""
    P = np.atleast_1d(np.asarray(pressures_kpa, dtype=float))
    k = curve_range(actuator, P, model, k_max, n)
    return k, moment(actuator, P[:, None], k[None, :], model)


@_styled
def plot_moment_curvature(ax, actuator, pressures_kpa, model: str = "energy", k_max: float | None = None, n: int = 200,
                          title: str | None = None):
    """Draw M(P, k') curves and the free-bending points on ``ax``.  Returns ``ax``."""
    P = np.atleast_1d(np.asarray(pressures_kpa, dtype=float))
    k, M = moment_curves(actuator, P, model, k_max, n)
    fb = free_curvature(actuator, P, model)
    colors = plt.cm.viridis(np.linspace(0.0, 0.9, P.size))
    for i, p in enumerate(P):
        ax.plot(k, M[i], color=colors[i], label=f"{p:g} kPa")
        if fb.status[i] == "ok" and np.isfinite(fb.curvature_per_mm[i]):
            ax.plot([fb.curvature_per_mm[i]], [0.0], "o", color=colors[i], ms=4)
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel("frame curvature k' (1/mm)")
    ax.set_ylabel("moment M (N·mm)")
    ax.set_title(title or f"{actuator.name or actuator.kind}\n{model.replace('_', '-')} model")
    ax.xaxis.set_major_locator(MaxNLocator(5))
    # the fold note is the legend's title, so that the two never overlap
    fold = f"no equilibrium above {fb.max_pressure_kpa:.4g} kPa (fold)" if np.any(~fb.ok) else None
    leg = ax.legend(ncol=2, title=fold)
    if fold:
        leg.get_title().set_color("crimson")
    return ax


@_styled
def moment_curvature_figure(actuator, pressures_kpa, model: str = "energy", k_max: float | None = None,
                            n: int = 200, title: str | None = None):
    """A single-column figure of :func:`plot_moment_curvature` (the figure of ``bendpam curve``)."""
    fig, ax = plt.subplots(figsize=figure_size("single", 0.85))
    plot_moment_curvature(ax, actuator, pressures_kpa, model, k_max, n, title=title)
    fig.tight_layout()
    return fig


def _section_panel(ax, phi, R, values, label, unit, color):
    """Draw the section (circle of radius R, frame at the bottom) with ``values`` as a radial band."""
    vmax = float(np.max(np.abs(values))) or 1.0
    r = R * (1.0 + 0.45 * values / vmax)
    # Phi = 0 (frame) at the bottom: x = R sin(Phi), y = -R cos(Phi)
    x0, y0 = R * np.sin(phi), -R * np.cos(phi)
    x1, y1 = r * np.sin(phi), -r * np.cos(phi)
    ax.plot(x0, y0, color="0.3", lw=1.0)
    ax.plot(x1, y1, color=color, lw=1.2)
    for j in range(0, phi.size, max(phi.size // 48, 1)):
        ax.plot([x0[j], x1[j]], [y0[j], y1[j]], color=color, lw=0.5, alpha=0.6)
    ax.plot([-0.35 * R, 0.35 * R], [-R, -R], color="k", lw=3, solid_capstyle="butt")
    ax.text(0.0, -1.6 * R, "frame (Φ = 0)", ha="center", va="top", fontsize=7)
    j = int(np.argmax(np.abs(values)))
    ax.plot([x1[j]], [y1[j]], "o", color=color, ms=3)  # the extreme value, given in the title
    ax.set_aspect("equal")
    ax.set_xlim(-1.6 * R, 1.6 * R)
    ax.set_ylim(-2.0 * R, 1.6 * R)
    ax.axis("off")
    ax.set_title(f"{label}\nband: value / max (circle = 0)\n"
                 f"dot: {values[j]:.3g} {unit} at Φ = {np.degrees(phi[j]):.0f}°")


@_styled
def plot_internal_stresses(actuator, pressure_kpa: float, curvature: float, *, fig=None):
    """Force-balance internal state (eq 37-48) around the cross-section at one (P, k').

    Top: the section (frame at the bottom, Phi = 0) with the bladder axial stress sigma_bl,1(Phi)
    and the braid axial line tension N_br,1(Phi) drawn as radial bands.  Bottom: the same fields
    unrolled over Phi, with the uniform hoop stress sigma_bl,2, radial stress sigma_bl,3 = -P and
    interfacial pressure P_e as horizontal lines.  A double-column figure whose labels do not
    overlap (tested).
    """
    ds = internal_stresses(actuator, float(pressure_kpa), float(curvature), n_phi=361)
    fig = fig or plt.figure(figsize=(DOUBLE_COLUMN_IN, 5.6))
    grid = fig.add_gridspec(2, 2, height_ratios=(1.25, 1.0))
    ax_a = fig.add_subplot(grid[0, 0])
    ax_b = fig.add_subplot(grid[0, 1])
    ax1 = fig.add_subplot(grid[1, :])
    phi = np.radians(ds["phi_deg"].values)
    R = float(ds["R_mm"])
    s1 = ds["sigma_bl1_kpa"].values
    n1 = ds["N_br1_n_per_mm"].values
    _section_panel(ax_a, phi, R, s1, "(a) bladder axial stress σ_bl,1 (kPa)", "kPa", "C0")
    _section_panel(ax_b, phi, R, n1, "(b) braid axial line tension N_br,1 (N/mm)", "N/mm", "C1")
    deg = ds["phi_deg"].values
    ax1.plot(deg, s1, color="C0", label="σ_bl,1 bladder axial (kPa)")
    ax1.axhline(float(ds["sigma_bl2_kpa"]), color="C2", ls="--", label="σ_bl,2 bladder hoop (kPa)")
    ax1.axhline(float(ds["P_e_kpa"]), color="C3", ls=":", label="P_e interfacial (kPa)")
    ax1.axhline(float(ds["sigma_bl3_kpa"]), color="C4", ls="-.", label="σ_bl,3 = -P (kPa)")
    ax2 = ax1.twinx()
    ax2.plot(deg, n1, color="C1", label="N_br,1 braid axial (N/mm)")
    ax2.set_ylabel("braid line tension (N/mm)")
    ax1.set_xlabel("Φ (deg), 0 at the frame")
    ax1.set_ylabel("stress (kPa)")
    ax1.set_xlim(0, 360)
    ax1.set_xticks(np.arange(0, 361, 45))
    ax1.set_title("(c) around the section")
    h1, l1 = ax1.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax1.legend(h1 + h2, l1 + l2, loc="upper center", bbox_to_anchor=(0.5, -0.3), ncol=3)
    pa = float(active_pressure_kpa(actuator, pressure_kpa))
    fig.suptitle(
        _wrap(f"{actuator.name or actuator.kind}: force-balance internal state", DOUBLE_COLUMN_IN, 9) + "\n"
        f"P = {pressure_kpa:g} kPa (active {pa:g} kPa), k' = {curvature:g} 1/mm, R = {R:.3g} mm, "
        f"t̄ = {float(ds['t_bar_mm']):.3g} mm",
    )
    fig.tight_layout()
    return fig


@_styled
def demo_figure(items):
    """A grid of moment-curvature plots; ``items`` is a list of ``(actuator, pressures_kpa, model)``."""
    n = len(items)
    ncol = 2
    nrow = (n + 1) // 2
    fig, axes = plt.subplots(nrow, ncol, figsize=(DOUBLE_COLUMN_IN, 2.7 * nrow), squeeze=False)
    for ax, (act, P, model) in zip(axes.ravel(), items, strict=False):  # spare axes are hidden below
        plot_moment_curvature(ax, act, P, model)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    fig.tight_layout()
    return fig


def save_figure(fig, path, format: str | None = None, dpi: int | None = None) -> Path:
    """Save ``fig`` atomically to ``path`` as PNG, PDF or SVG, close it, and return the path.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    path : str or os.PathLike
        Output file; its folder must exist.
    format : {'png', 'pdf', 'svg'}, optional
        Default: from the suffix of ``path`` (png when it has none); a suffix that disagrees is
        an error (see :func:`figure_format`).
    dpi : int, optional
        Resolution of a PNG (default 300 dots per inch; vector formats ignore it).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> fig = styled_figure(lambda ax: ax.plot([0, 1], [0, 1]))
    >>> with tempfile.TemporaryDirectory() as d:
    ...     p = save_figure(fig, pathlib.Path(d) / "line.pdf")
    ...     p.read_bytes()[:5]
    b'%PDF-'
    """
    fmt = figure_format(path, format)
    metadata: dict[str, Any] = {"pdf": {"CreationDate": None}, "svg": {"Date": None}}.get(fmt, {})
    with figure_style(), atomic_path(path) as tmp:
        fig.savefig(tmp, format=fmt, dpi=dpi or STYLE["savefig.dpi"], metadata=metadata)
    plt.close(fig)
    return Path(path)


@register("figure4")
@_styled
def figure4(processed, title: str = ""):
    """A figure like the paper's Figure 4 for a :class:`~bendpam.lab.processing.ProcessedSet`.

    (a) the filtered loops at each pressure (moment against curvature, every cycle), with the
    hysteresis-free mean curve dashed; (b) blocked moment against pressure with standard-error bars
    and the deadband fit line; (c) free-bending curvature against pressure with standard-error bars.
    """
    from bendpam.lab.processing import deadband_fit

    res = processed.results
    fig, axes = plt.subplots(1, 3, figsize=(DOUBLE_COLUMN_IN, 2.8))
    ax = axes[0]
    colors = plt.cm.viridis(np.linspace(0.0, 0.9, len(res)))
    for c, r in zip(colors, res, strict=True):
        if r.series is not None:
            sel = r.series[r.series.cycle > 0]
            ax.plot(sel.curvature_per_mm, sel.moment_nmm, color=c, lw=0.7, alpha=0.8)
        else:
            for ci in range(r.n_cycles):
                ax.plot(r.curvature_grid, r.branches[ci, 0], color=c, lw=0.7)
                ax.plot(r.curvature_grid, r.branches[ci, 1], color=c, lw=0.7)
        ax.plot(r.curvature_grid, r.mean_curve, "--", color=c, lw=1.2, label=f"{r.pressure_kpa:g} kPa")
    ax.set_xlabel("curvature |k'| (1/mm)")
    ax.set_ylabel("moment |M| (N·mm)")
    ax.set_title("(a) cyclic loops\n(dashed: mean of the branches)")
    ax.legend()
    P = processed.pressures_kpa
    bm = np.array([r.blocked_moment for r in res])
    kf = np.array([r.free_curvature for r in res])
    ax = axes[1]
    ax.errorbar(P, bm[:, 0], yerr=np.nan_to_num(bm[:, 1]), fmt="o", label="max moment per cycle\n(mean ± SE)")
    p0, se, a, b = deadband_fit(P, bm[:, 0])
    if np.isfinite(a):
        xx = np.linspace(min(p0 if np.isfinite(p0) else P.min(), P.min()), P.max(), 50)
        ax.plot(xx, a * xx + b, "-", color="C1",
                label=(f"linear fit, deadband\n{p0:.3g} ± {se:.2g} kPa" if np.isfinite(se)
                       else f"linear fit, deadband\n{p0:.3g} kPa"))
    ax.axhline(0, color="0.6", lw=0.8)
    ax.set_xlabel("pressure (kPa)")
    ax.set_ylabel("blocked moment (N·mm)")
    ax.set_title("(b) blocked moment")
    ax.legend()
    ax = axes[2]
    ax.errorbar(P, kf[:, 0], yerr=np.nan_to_num(kf[:, 1]), fmt="s", color="C2")
    ax.set_xlabel("pressure (kPa)")
    ax.set_ylabel("free-bending |k'| (1/mm)")
    ax.set_title("(c) free-bending curvature")
    if title:
        fig.suptitle(_wrap(title, DOUBLE_COLUMN_IN, 9))
    fig.tight_layout()
    return fig


@register("figure7")
@_styled
def figure7(processed, fit_result, title: str = ""):
    """A figure like the paper's Figure 7: a fitted model against processed data.

    (a) the data's branches (thin) and mean curve (markers) with the model curve at each pressure;
    (b) blocked moment against pressure, data (mean ± SE) and model; (c) free-bending curvature
    against pressure, data (mean ± SE) and model (pressures without an equilibrium are marked).
    Magnitudes, as in the paper.

    With a fitted loop every panel shows the model the fit used, the computations behind its
    metrics (:func:`bendpam.identify.metrics.score`): (a) both branches on each test's own path, blocked
    state to its measured free curvature; (b) and (c) the predicted free cycle of
    :func:`bendpam.physics.hysteresis.predict_cycles` (its largest moment and the curvature where its
    unloading branch reaches zero, as ``bendpam predict --cycle``), the quasi-static model dashed.
    """
    act = fit_result.actuator
    model = fit_result.model
    loop = getattr(fit_result, "loop", None)
    s = act.bend_sign or 1
    res = processed.results
    fig, axes = plt.subplots(1, 3, figsize=(DOUBLE_COLUMN_IN, 3.0))
    ax = axes[0]
    colors = plt.cm.viridis(np.linspace(0.0, 0.9, len(res)))
    # at most about six pressures in the legend (the colours run in order of pressure)
    shown = set(np.unique(np.linspace(0, len(res) - 1, min(len(res), 6)).round().astype(int)).tolist())
    # one collection per kind of line and one scatter for the markers (a few artists, not five per
    # pressure: drawing 25 pressures stays fast)
    thin, thick, thick_c, mk_x, mk_y, mk_c = [], [], [], [], [], []
    for i, (c, r) in enumerate(zip(colors, res, strict=True)):
        k = r.curvature_grid
        thin += [np.column_stack([k, r.mean_loading]), np.column_stack([k, r.mean_unloading])]
        mk_x.append(k[::4])
        mk_y.append(r.mean_curve[::4])
        mk_c += [c] * k[::4].size
        if i in shown:
            ax.plot([], [], "o", color=c, ms=3, label=f"{r.pressure_kpa:g} kPa")
        if loop is not None:
            from bendpam.physics.hysteresis import loop_branches

            kf_r = float(r.free_curvature[0])
            up, low = loop_branches(act, loop, r.pressure_kpa, kf_r, k, model)
            thick += [np.column_stack([k, up]), np.column_stack([k, low])]
            thick_c += [c, c]
        else:
            kk = np.linspace(0.0, k[-1], 120)
            thick.append(np.column_stack([kk, s * moment(act, r.pressure_kpa, s * kk, model)]))
            thick_c.append(c)
    ax.add_collection(LineCollection(thin, colors=np.repeat(colors, 2, axis=0), linewidths=0.6, alpha=0.5))
    ax.add_collection(LineCollection(thick, colors=thick_c, linewidths=1.3 if loop is not None else 1.5))
    ax.scatter(np.concatenate(mk_x), np.concatenate(mk_y), s=9, c=mk_c, marker="o", linewidths=0, zorder=3)
    ax.autoscale_view()
    ax.set_xlabel("curvature |k'| (1/mm)")
    ax.set_ylabel("moment |M| (N·mm)")
    loop_txt = " with its loop" if loop is not None else ""
    ax.set_title(f"(a) data (thin: branches, markers:\nmean), {model.replace('_', '-')} model{loop_txt}")
    ax.legend(loc="upper right")
    P = processed.pressures_kpa
    bm = np.array([r.blocked_moment for r in res])
    kf = np.array([r.free_curvature for r in res])
    Pm = np.linspace(min(P.min(), act.P_start_kpa), P.max() * 1.05, 100)
    ax = axes[1]
    ax.errorbar(P, bm[:, 0], yerr=np.nan_to_num(bm[:, 1]), fmt="o", label="data")
    cycles = None
    if loop is not None:
        from bendpam.physics.hysteresis import predict_cycles

        cycles = predict_cycles(act, loop, Pm, model)
        ax.plot(Pm, [c.blocked_moment_nmm for c in cycles], "-", label="model with its loop")
        ax.plot(Pm, np.abs(moment(act, Pm, 0.0, model)), "--", color="0.5", lw=0.8, label="quasi-static")
    else:
        ax.plot(Pm, np.abs(moment(act, Pm, 0.0, model)), "-", label="model")
    ax.set_xlabel("pressure (kPa)")
    ax.set_ylabel("blocked moment (N·mm)")
    ax.set_title(f"(b) blocked moment\nNRMSE {100 * fit_result.metrics.nrmse_blocked_moment:.2f} %")
    ax.legend(loc="upper left")
    ax = axes[2]
    ax.errorbar(P, kf[:, 0], yerr=np.nan_to_num(kf[:, 1]), fmt="s", color="C2", label="data")
    fb = free_curvature(act, Pm, model)
    if cycles is not None:
        ax.plot(Pm, [c.free_curvature_per_mm for c in cycles], "-", color="C3", label="model with its loop\n"
                "(unloading branch)")
        ax.plot(Pm, np.abs(fb.curvature_per_mm), "--", color="0.5", lw=0.8, label="quasi-static")
    else:
        ax.plot(Pm, np.abs(fb.curvature_per_mm), "-", color="C3", label="model")
    if np.any(~fb.ok):
        ax.axvline(fb.max_pressure_kpa, color="crimson", ls=":", lw=1,
                   label=f"no equilibrium above\n{fb.max_pressure_kpa:.4g} kPa")
    nf = fit_result.metrics.nrmse_free_curvature
    ax.set_title("(c) free-bending curvature\nNRMSE " + ("n/a" if not np.isfinite(nf) else f"{100 * nf:.2f} %"))
    ax.set_xlabel("pressure (kPa)")
    ax.set_ylabel("free-bending |k'| (1/mm)")
    ax.legend(loc="upper left")
    fig.suptitle(_wrap(title or f"{act.name or act.kind}: {model.replace('_', '-')} model fit, NRMSE of the cycles "
                       f"{100 * fit_result.metrics.nrmse_cycles:.2f} %", DOUBLE_COLUMN_IN, 9))
    fig.tight_layout()
    return fig


@register("sweep")
@_styled
def sweep_figure(ds, var: str = "free_angle_deg", x: str | None = None, y: str | None = None,
                 at: dict[str, float] | None = None):
    """Colour map (or line) of one sweep output against one or two of its dimensions.

    ``x`` and ``y`` default to the first two dimensions of ``var`` with more than one value (a
    single pressure is not an axis).  The other dimensions are fixed at ``at`` (``{dim: value}``,
    the nearest value is taken) or else at their middle value; the title names them.
    """
    if var not in ds.data_vars:
        raise InputError(f"variable {var!r} is not a sweep output; choose from {', '.join(ds.data_vars)}")
    da_ = ds[var]
    dims = list(da_.dims)
    at = dict(at or {})
    for d in at:
        if d not in dims:
            raise InputError(f"--at {d}: not a dimension of {var}; choose from {', '.join(dims)}")
    free = [str(d) for d in dims if da_[d].size > 1 and d not in at]
    xd: str = x or (free[0] if free else str(dims[0]))
    yd: str | None = y or next((d for d in free if d != xd), None)
    for dim in (xd, yd):
        if dim is not None and dim not in dims:
            raise InputError(f"{dim!r} is not a dimension of {var}; choose from {', '.join(dims)}")
    index = {}
    for d in dims:
        if d in (xd, yd):
            continue
        vals = np.asarray(da_[d].values, dtype=float)
        index[d] = int(np.argmin(np.abs(vals - float(at[d])))) if d in at else vals.size // 2
    fixed = {d: float(da_[d].values[i]) for d, i in index.items()}
    sel = da_.isel(index) if index else da_
    fig, ax = plt.subplots(figsize=figure_size("single", 0.85))
    if yd is None:
        ax.plot(sel[xd].values, np.asarray(sel.values, dtype=float), "-o", ms=3)
        ax.set_ylabel(f"{var} ({da_.attrs.get('units', '')})")
    else:
        z = np.asarray(sel.transpose(yd, xd).values, dtype=float)
        m = ax.pcolormesh(sel[xd].values, sel[yd].values, np.ma.masked_invalid(z), shading="auto", cmap="viridis")
        fig.colorbar(m, ax=ax, label=f"{var} ({da_.attrs.get('units', '')})")
        if np.any(~np.isfinite(z)):
            ax.contour(sel[xd].values, sel[yd].values, np.isfinite(z).astype(float), levels=[0.5], colors="crimson",
                       linewidths=1.0)
        ax.set_ylabel(yd)
    ax.set_xlabel(xd)
    title = _wrap(da_.attrs.get("long_name", var), 0.8 * SINGLE_COLUMN_IN)
    if fixed:
        title += "\n" + _wrap(", ".join(f"{d} = {v:g}" for d, v in fixed.items()), 0.8 * SINGLE_COLUMN_IN)
    ax.set_title(title)
    fig.tight_layout()
    return fig
