"""Figures of the bending tests: the paper's Figure 4 (processed tests) and Figure 7 (a fit against them).

Both are double-column figures of three panels, drawn with the object-oriented API
(:func:`~bendpam.present.figures.style.new_figure`) inside the journal style.  They register
themselves as ``"figure4"`` and ``"figure7"`` (:mod:`bendpam.infra.accessors`), which is how
``ProcessedSet.plot()`` and ``FitResult.plot()`` reach them.
"""

from __future__ import annotations

import warnings

import matplotlib
import numpy as np
from matplotlib.collections import LineCollection

from bendpam.errors import OutsideTestedRangeWarning
from bendpam.infra.accessors import register
from bendpam.physics.hysteresis import loop_branches, predict_cycles
from bendpam.predict import free_curvature, moment
from bendpam.present.figures.style import DOUBLE_COLUMN_IN, new_figure, styled, wrap_text

__all__ = ["figure4", "figure7"]

#: Samples drawn per pressure in Figure 4 (a); a longer test is drawn every n-th sample, which the
#: panel cannot tell apart and which keeps the figure's memory bounded.
_LOOP_POINTS = 200_000
#: Points drawn per line in Figure 7 (a): a panel is about 2 in wide, 600 pixel columns at 300 dpi,
#: so a line of the curvature grid (101 points by default, up to 100 000) is drawn every n-th point
#: past 512 (the model's branches are computed on those points only).
_LINE_POINTS = 512
#: Markers of the mean curve per pressure in Figure 7 (a) (every 4th point of the default grid), and
#: at most about this many in the panel (fewer per pressure when there are many pressures).
_MARKERS, _MARKERS_TOTAL = 26, 1000


def _viridis(n: int) -> np.ndarray:
    """``n`` colours from the viridis map (dark to light), one per pressure."""
    return matplotlib.colormaps["viridis"](np.linspace(0.0, 0.9, n))


def _means(processed) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Pressures (kPa), blocked moment and free curvature ``[mean, SE]`` rows, one per pressure."""
    res = processed.results
    return (processed.pressures_kpa, np.array([r.blocked_moment for r in res]),
            np.array([r.free_curvature for r in res]))


def _deadband_line(processed, P: np.ndarray, bm: np.ndarray) -> tuple[float, float, float, float] | None:
    """``(P0, SE, slope, intercept)`` of the set's deadband line, or None without one.

    The deadband ``P0`` and its SE are the set's own (:meth:`~bendpam.lab.processing.ProcessedSet.deadband`);
    the least-squares line through the blocked moments passes through ``(P0, 0)`` and through the
    data's centroid, which gives its slope.
    """
    p0, se = processed.deadband()
    p_mean, m_mean = float(np.mean(P)), float(np.mean(bm))
    if not (np.isfinite(p0) and np.isfinite(m_mean)) or p_mean == p0:
        return None
    a = m_mean / (p_mean - p0)
    return p0, se, a, -a * p0


def _loops_panel(ax, processed) -> None:
    """Figure 4 (a): every cycle's loop (or branches) and the dashed mean curve, per pressure."""
    res = processed.results
    for c, r in zip(_viridis(len(res)), res, strict=True):
        if r.series is not None:
            # the two columns plotted (not a copy of the frame), every n-th sample past _LOOP_POINTS
            sel = np.flatnonzero(r.series["cycle"].to_numpy() > 0)
            sel = sel[::max(1, -(-sel.size // _LOOP_POINTS))]
            ax.plot(r.series["curvature_per_mm"].to_numpy()[sel], r.series["moment_nmm"].to_numpy()[sel], color=c,
                    lw=0.7, alpha=0.8)
        else:
            for ci in range(r.n_cycles):
                ax.plot(r.curvature_grid, r.branches[ci, 0], color=c, lw=0.7)
                ax.plot(r.curvature_grid, r.branches[ci, 1], color=c, lw=0.7)
        rep = int(getattr(r, "replicate", 1))  # a second test at one pressure is a replicate: #2, #3, ...
        ax.plot(r.curvature_grid, r.mean_curve, "--", color=c, lw=1.2,
                label=f"{r.pressure_kpa:g} kPa" + (f" #{rep}" if rep > 1 else ""))
    ax.set_xlabel("curvature |k'| (1/mm)")
    ax.set_ylabel("moment |M| (N·mm)")
    ax.set_title("(a) cyclic loops\n(dashed: mean of the branches)")
    ax.legend()


@register("figure4")
@styled
def figure4(processed, title: str = ""):
    """A figure like the paper's Figure 4 for a :class:`~bendpam.lab.processing.ProcessedSet`.

    (a) the filtered loops at each pressure (moment against curvature, every cycle; a test of more
    than 200 000 samples drawn every n-th sample), with the hysteresis-free mean curve dashed;
    (b) blocked moment against pressure with standard-error bars and the deadband fit line;
    (c) free-bending curvature against pressure with standard-error bars.

    Examples
    --------
    >>> from pathlib import Path
    >>> from bendpam.lab import RawTest
    >>> from bendpam.lab.processing import process_tests
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> from bendpam.physics import presets
    >>> be, settings = presets.be_pam(), SimulationSettings(cycles=1, rate_hz=2.0, seed=1)
    >>> raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv",
    ...                 pressure_kpa=p) for p in (100.0, 150.0, 200.0)]
    >>> fig = figure4(process_tests(raws, keep_series=False))
    >>> [ax.get_title().split("\\n")[0] for ax in fig.axes]
    ['(a) cyclic loops', '(b) blocked moment', '(c) free-bending curvature']
    """
    fig = new_figure((DOUBLE_COLUMN_IN, 2.8))
    axes = fig.subplots(1, 3)
    _loops_panel(axes[0], processed)
    P, bm, kf = _means(processed)
    ax = axes[1]
    ax.errorbar(P, bm[:, 0], yerr=np.nan_to_num(bm[:, 1]), fmt="o", label="max moment per cycle\n(mean ± SE)")
    line = _deadband_line(processed, P, bm[:, 0])
    if line is not None:
        p0, se, a, b = line
        xx = np.linspace(min(p0, P.min()), P.max(), 50)
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
        fig.suptitle(wrap_text(title, DOUBLE_COLUMN_IN, 9))
    fig.tight_layout()
    return fig


def _every_nth(n: int, at_most: int) -> np.ndarray:
    """Indices of every m-th of ``n`` points, the last one included, so that at most about ``at_most`` are drawn.

    >>> _every_nth(5, 512).tolist(), _every_nth(10, 4).tolist()
    ([0, 1, 2, 3, 4], [0, 3, 6, 9])
    """
    idx = np.arange(0, n, max(1, -(-n // at_most)))
    return idx if idx[-1] == n - 1 else np.append(idx, n - 1)


def _loop_lines(act, loop, res, ks: list[np.ndarray], model) -> list[tuple[np.ndarray, np.ndarray]]:
    """The model's loop branches ``(upper, lower)`` of each test on its curvatures ``ks`` (one call for one size)."""
    if len({k.size for k in ks}) == 1:  # one row per test (the usual set: one grid size)
        P = np.array([[r.pressure_kpa] for r in res])
        kf = np.array([[float(r.free_curvature[0])] for r in res])
        up, low = loop_branches(act, loop, P, kf, np.stack(ks), model)
        return list(zip(up, low, strict=True))
    return [loop_branches(act, loop, r.pressure_kpa, float(r.free_curvature[0]), k, model)
            for r, k in zip(res, ks, strict=True)]


def _fit_curves_panel(ax, processed, fit_result) -> None:
    """Figure 7 (a): the data's branches (thin), mean curves (markers) and the model's curves (thick).

    Each line is drawn with at most about :data:`_LINE_POINTS` points and each mean curve with
    :data:`_MARKERS` markers (fewer with many pressures), whatever the size of the curvature grid.
    """
    act, model = fit_result.actuator, fit_result.model
    loop = getattr(fit_result, "loop", None)
    s = act.bend_sign or 1
    res = processed.results
    colors = _viridis(len(res))
    # at most about six pressures in the legend (the colours run in order of pressure)
    shown = set(np.unique(np.linspace(0, len(res) - 1, min(len(res), 6)).round().astype(int)).tolist())
    # one collection per kind of line and one scatter for the markers (a few artists, not five per
    # pressure: drawing 25 pressures stays fast)
    thin, thick, thick_c, mk_x, mk_y, mk_c = [], [], [], [], [], []
    markers = max(3, min(_MARKERS, _MARKERS_TOTAL // max(len(res), 1)))
    lines = [_every_nth(r.curvature_grid.size, _LINE_POINTS) for r in res]
    loops = _loop_lines(act, loop, res, [r.curvature_grid[line] for r, line in zip(res, lines, strict=True)],
                        model) if loop is not None else None
    for i, (c, r, line) in enumerate(zip(colors, res, lines, strict=True)):
        k = r.curvature_grid[line]
        thin += [np.column_stack([k, r.mean_loading[line]]), np.column_stack([k, r.mean_unloading[line]])]
        mark = slice(None, None, max(4, -(-r.curvature_grid.size // markers)))
        mk_x.append(r.curvature_grid[mark])
        mk_y.append(r.mean_curve[mark])
        mk_c += [c] * mk_x[-1].size
        if i in shown:
            ax.plot([], [], "o", color=c, ms=3, label=f"{r.pressure_kpa:g} kPa")
        if loops is not None:
            up, low = loops[i]
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


def _fit_blocked_panel(ax, P, bm, Pm, fit_result):
    """Figure 7 (b): blocked moment, data and model; returns the predicted free cycles (None without a loop)."""
    act, model = fit_result.actuator, fit_result.model
    loop = getattr(fit_result, "loop", None)
    ax.errorbar(P, bm[:, 0], yerr=np.nan_to_num(bm[:, 1]), fmt="o", label="data")
    cycles = None
    if loop is not None:
        cycles = predict_cycles(act, loop, Pm, model)
        ax.plot(Pm, [c.blocked_moment_nmm for c in cycles], "-", label="model with its loop")
        ax.plot(Pm, np.abs(moment(act, Pm, 0.0, model)), "--", color="0.5", lw=0.8, label="quasi-static")
    else:
        ax.plot(Pm, np.abs(moment(act, Pm, 0.0, model)), "-", label="model")
    ax.set_xlabel("pressure (kPa)")
    ax.set_ylabel("blocked moment (N·mm)")
    ax.set_title(f"(b) blocked moment\nNRMSE {100 * fit_result.metrics.nrmse_blocked_moment:.2f} %")
    ax.legend(loc="upper left")
    return cycles


def _fit_free_panel(ax, P, kf, Pm, fit_result, cycles) -> None:
    """Figure 7 (c): free-bending curvature, data and model (the fold marked)."""
    act, model = fit_result.actuator, fit_result.model
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


@register("figure7")
@styled
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

    Examples
    --------
    >>> from pathlib import Path
    >>> from bendpam.identify.fitting import fit
    >>> from bendpam.lab import RawTest
    >>> from bendpam.lab.processing import process_tests
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> from bendpam.physics import presets
    >>> be, settings = presets.be_pam(), SimulationSettings(cycles=1, rate_hz=2.0, seed=1)
    >>> raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv",
    ...                 pressure_kpa=p) for p in (100.0, 150.0, 200.0)]
    >>> processed = process_tests(raws, keep_series=False)
    >>> fig = figure7(processed, fit(processed, be, free=("alpha0",), hysteresis=None))
    >>> [ax.get_title().split("\\n")[0] for ax in fig.axes]
    ['(a) data (thin: branches, markers:', '(b) blocked moment', '(c) free-bending curvature']
    """
    act, model = fit_result.actuator, fit_result.model
    fig = new_figure((DOUBLE_COLUMN_IN, 3.0))
    axes = fig.subplots(1, 3)
    P, bm, kf = _means(processed)
    Pm = np.linspace(min(P.min(), act.P_start_kpa), P.max() * 1.05, 100)
    with warnings.catch_warnings():  # the model's lines run from P_start past the tested pressures on purpose
        warnings.simplefilter("ignore", OutsideTestedRangeWarning)
        _fit_curves_panel(axes[0], processed, fit_result)
        cycles = _fit_blocked_panel(axes[1], P, bm, Pm, fit_result)
        _fit_free_panel(axes[2], P, kf, Pm, fit_result, cycles)
    fig.suptitle(wrap_text(title or f"{act.name or act.kind}: {model.replace('_', '-')} model fit, NRMSE of the "
                           f"cycles {100 * fit_result.metrics.nrmse_cycles:.2f} %", DOUBLE_COLUMN_IN, 9))
    fig.tight_layout()
    return fig
