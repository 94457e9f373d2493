"""Figures of the models: moment-curvature maps and the force-balance model's internal stresses.

Every function draws on a matplotlib ``Axes``/``Figure`` (:func:`~bendpam.present.figures.style.new_figure`,
never :mod:`matplotlib.pyplot`) inside the journal style and returns it.
"""

from __future__ import annotations

import matplotlib
import numpy as np
from matplotlib.ticker import MaxNLocator

from bendpam.errors import InputError
from bendpam.physics.braid import curvature_limits
from bendpam.physics.models import resolve_model
from bendpam.predict import active_pressure_kpa, free_curvature, internal_stresses, moment
from bendpam.present.figures.style import DOUBLE_COLUMN_IN, figure_size, new_figure, styled, wrap_text

__all__ = [
    "curve_range",
    "demo_figure",
    "moment_curvature_figure",
    "moment_curves",
    "plot_internal_stresses",
    "plot_moment_curvature",
]


def curve_range(actuator, pressures_kpa, model: str | None = None, k_max: float | None = None,
                n: int = 200) -> np.ndarray:
    """Curvature grid (1/mm) from 0 toward the bending direction, to ``k_max`` (magnitude).

    The default end is 15 % past the largest free-bending curvature at the given pressures (or past
    the fold curvature where there is no equilibrium), clipped to the lock-up limit.

    Examples
    --------
    >>> from bendpam.physics import presets
    >>> curve_range(presets.be_pam(), [100, 200], n=5).round(4).tolist()   # 1/mm
    [0.0, 0.0039, 0.0078, 0.0117, 0.0156]
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


def moment_curves(actuator, pressures_kpa, model: str | None = None, k_max: float | None = None, n: int = 200):
    """Moment-curvature curves: returns ``(k, M)`` with ``M`` of shape (n_pressures, n), N*mm.

    Examples
    --------
    >>> from bendpam.physics import presets
    >>> k, M = moment_curves(presets.be_pam(), [100, 200], n=3)
    >>> k.round(4).tolist(), M.round(1).tolist()   # 1/mm, N*mm
    ([0.0, 0.0078, 0.0156], [[75.2, -94.1, -199.9], [310.3, 108.8, -31.6]])
    """
    P = np.atleast_1d(np.asarray(pressures_kpa, dtype=float))
    model = resolve_model(actuator, model)
    k = curve_range(actuator, P, model, k_max, n)
    return k, moment(actuator, P[:, None], k[None, :], model)


@styled
def plot_moment_curvature(ax, actuator, pressures_kpa, model: str | None = None, k_max: float | None = None,
                          n: int = 200, title: str | None = None):
    """Draw M(P, k') curves and the free-bending points on ``ax``.  Returns ``ax``.

    Examples
    --------
    >>> from bendpam.physics import presets
    >>> from bendpam.present.figures.style import new_figure
    >>> ax = plot_moment_curvature(new_figure().add_subplot(), presets.be_pam(), [100, 200], n=20)
    >>> [t.get_text() for t in ax.get_legend().get_texts()]
    ['100 kPa', '200 kPa']
    """
    P = np.atleast_1d(np.asarray(pressures_kpa, dtype=float))
    model = resolve_model(actuator, model)
    k, M = moment_curves(actuator, P, model, k_max, n)
    fb = free_curvature(actuator, P, model)
    colors = matplotlib.colormaps["viridis"](np.linspace(0.0, 0.9, P.size))
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


@styled
def moment_curvature_figure(actuator, pressures_kpa, model: str | None = None, k_max: float | None = None,
                            n: int = 200, title: str | None = None):
    """A single-column figure of :func:`plot_moment_curvature` (the figure of ``bendpam curve``).

    Examples
    --------
    >>> from bendpam.physics import presets
    >>> fig = moment_curvature_figure(presets.be_pam(), [100, 200], n=20)
    >>> fig.get_size_inches().tolist()   # in: one journal column
    [3.5, 2.975]
    """
    fig = new_figure(figure_size("single", 0.85))
    plot_moment_curvature(fig.add_subplot(), actuator, pressures_kpa, model, k_max, n, title=title)
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


def _unrolled_panel(ax1, ds, s1, n1) -> None:
    """Panel (c): the stresses unrolled over Phi, the braid line tension on a second y axis."""
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


@styled
def plot_internal_stresses(actuator, pressure_kpa: float, curvature: float, *, fig=None):
    """Force-balance internal state (eq 37-48) around the cross-section at one (P, k').

    Top: the section (frame at the bottom, Phi = 0) with the bladder axial stress sigma_bl,1(Phi)
    and the braid axial line tension N_br,1(Phi) drawn as radial bands.  Bottom: the same fields
    unrolled over Phi, with the uniform hoop stress sigma_bl,2, radial stress sigma_bl,3 = -P and
    interfacial pressure P_e as horizontal lines.  A double-column figure whose labels do not
    overlap (tested).  ``fig``: draw on this figure instead of a new one.

    Examples
    --------
    >>> from bendpam.physics import presets
    >>> fig = plot_internal_stresses(presets.be_pam("force_balance"), 150.0, 0.004)
    >>> [ax.get_title().split(" (")[0] for ax in fig.axes[:3]]
    ['(a) bladder axial stress σ_bl,1', '(b) braid axial line tension N_br,1', '(c) around the section']
    """
    ds = internal_stresses(actuator, float(pressure_kpa), float(curvature), n_phi=361)
    fig = fig or new_figure((DOUBLE_COLUMN_IN, 5.6))
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
    _unrolled_panel(ax1, ds, s1, n1)
    pa = float(active_pressure_kpa(actuator, pressure_kpa))
    fig.suptitle(
        wrap_text(f"{actuator.name or actuator.kind}: force-balance internal state", DOUBLE_COLUMN_IN, 9) + "\n"
        f"P = {pressure_kpa:g} kPa (active {pa:g} kPa), k' = {curvature:g} 1/mm, R = {R:.3g} mm, "
        f"t̄ = {float(ds['t_bar_mm']):.3g} mm",
    )
    fig.tight_layout()
    return fig


@styled
def demo_figure(items):
    """A grid of moment-curvature plots; ``items`` is a list of ``(actuator, pressures_kpa, model)``.

    Two columns (double-column width), as many rows as needed; a spare axes is hidden.

    Examples
    --------
    >>> from bendpam.physics import presets
    >>> be, bc = presets.be_pam(), presets.bc_pam()
    >>> fig = demo_figure([(be, [100, 200], "energy"), (bc, [40, 80], "energy"), (be, [150], "energy")])
    >>> [ax.get_visible() for ax in fig.axes]
    [True, True, True, False]
    """
    n = len(items)
    ncol = 2
    nrow = (n + 1) // 2
    fig = new_figure((DOUBLE_COLUMN_IN, 2.7 * nrow))
    axes = fig.subplots(nrow, ncol, squeeze=False)
    for ax, (act, P, model) in zip(axes.ravel(), items, strict=False):  # spare axes are hidden below
        plot_moment_curvature(ax, act, P, model)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    fig.tight_layout()
    return fig
