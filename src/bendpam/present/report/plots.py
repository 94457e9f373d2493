"""The report's figures: the paper's Figures 4 and 7, and its own (the alpha0 profile, the prediction
band, the energy-loss ratios, the internal stresses), drawn to PNG in memory.

:func:`draw_figures` draws every figure the page shows, each as a :class:`Drawn` (its PNG, or why
it could not be drawn: a figure that fails does not stop the report).  :func:`alpha0_profile` and
:func:`prediction_band` read what a fit carries for the figures of their names.
"""

from __future__ import annotations

import io
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from bendpam.errors import BendpamError
from bendpam.present.figures.report import alpha0_profile_figure, band_figure, loss_figure
from bendpam.present.report.text import LAW_LABEL, MODEL_LABEL, finite, fmt_pct, fmt_value, plain_text

__all__ = ["Drawn", "alpha0_profile", "draw_figures", "prediction_band"]

_DPI = 140


def _fig_png(fig) -> bytes:
    """Render a figure to PNG bytes in memory (``dpi=140``)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=_DPI)
    return buf.getvalue()



def _get(obj, *names):
    for n in names:
        v = obj.get(n) if isinstance(obj, Mapping) else getattr(obj, n, None)
        if v is not None:
            return v
    return None


def _vector(v) -> np.ndarray | None:
    try:
        a = np.asarray(v, dtype=float).ravel()
    except (TypeError, ValueError):
        return None
    return a if a.size >= 2 else None


def alpha0_profile(res) -> dict | None:
    """The fit's α₀ profile as ``{"alpha0_deg", "objective", "nrmse_percent", "interval_deg"}``, or None.

    Reads ``res.alpha0_profile`` (:class:`bendpam.identify.result.Profile`: the objective, on the scale of
    NRMSE², minimised over every other parameter at each α₀; and the reported interval), or a
    mapping with the same keys.  ``nrmse_percent`` is ``100 √objective`` (the NRMSE of the fitted
    curves) when the objective is on that scale, else None; ``interval_deg`` is None when absent.

    >>> from types import SimpleNamespace as NS
    >>> prof = alpha0_profile(NS(alpha0_profile={"alpha0_deg": [69.6, 69.7, 69.8], "objective": [4e-4, 1e-4, 9e-4],
    ...                                          "interval_deg": (69.65, 69.75)}))
    >>> prof["nrmse_percent"].round(1).tolist(), prof["interval_deg"]
    ([2.0, 1.0, 3.0], (69.65, 69.75))
    """
    p = getattr(res, "alpha0_profile", None)
    if p is None:
        return None
    x, y = _vector(_get(p, "alpha0_deg")), _vector(_get(p, "objective"))
    if x is None or y is None or x.size != y.size or not (np.isfinite(x) & np.isfinite(y)).any():
        return None
    iv = _vector(_get(p, "interval_deg"))
    nrmse = 100.0 * np.sqrt(np.clip(y, 0.0, None)) if np.nanmin(y) >= 0 else None
    return {"alpha0_deg": x, "objective": y, "nrmse_percent": nrmse,
            "interval_deg": tuple(float(v) for v in iv[:2]) if iv is not None and np.isfinite(iv[:2]).all() else None}


def prediction_band(res, processed) -> dict | None:
    """Predictions with their uncertainty band inside and beyond the tested pressures, or None.

    Uses :meth:`bendpam.identify.result.FitResult.band` where the fit has it: the blocked moment and the
    free-bending curvature from P_start to 1.5 times the
    highest, with ±2 standard errors.  Returns ``{"pressure_kpa", "series": [(quantity, unit,
    value, lower, upper)], "extrapolated"}`` or None when the fit has no band.

    >>> from types import SimpleNamespace as NS
    >>> from bendpam.identify.result import Band
    >>> def band(P, quantity):   # a fit's band: 10 % either side
    ...     v = 0.01 * P if quantity == "blocked_moment" else 1e-4 * P
    ...     return Band(quantity, "", P, v, 0.9 * v, 1.1 * v, P > 260.0)
    >>> b = prediction_band(NS(band=band, actuator=NS(P_start_kpa=50.0)), NS(pressures_kpa=np.array([100.0, 200.0])))
    >>> b["pressure_kpa"][[0, -1]].tolist(), [s[0] for s in b["series"]], int(b["extrapolated"].sum())
    ([50.0, 300.0], ['blocked_moment', 'free_curvature'], 10)
    """
    band = getattr(res, "band", None)
    if not callable(band):
        return None
    P = np.asarray(processed.pressures_kpa, dtype=float)
    lo = max(float(res.actuator.P_start_kpa), 0.0) if finite(res.actuator.P_start_kpa) else 0.0
    grid = np.linspace(lo, 1.5 * float(P.max()), 61)
    series, extrap = [], None
    import warnings as _warnings

    for quantity in ("blocked_moment", "free_curvature"):
        try:
            with _warnings.catch_warnings():
                _warnings.simplefilter("ignore")
                b = band(grid, quantity=quantity)
        except (BendpamError, ValueError, ArithmeticError, TypeError):
            continue
        v, lw, up = (np.asarray(getattr(b, k), dtype=float) for k in ("value", "lower", "upper"))
        if v.shape != grid.shape or not np.isfinite(v).any():
            continue
        series.append((quantity, str(getattr(b, "unit", "")), v, lw, up))
        extrap = np.asarray(getattr(b, "extrapolated", np.zeros(grid.size, bool)), dtype=bool)
    if not series:
        return None
    return {"pressure_kpa": grid, "series": series, "extrapolated": extrap}


# ------------------------------------------------------------------------------------------------
# every figure of the page
# ------------------------------------------------------------------------------------------------
def _fitted_alpha0(res) -> tuple[float, str] | None:
    p = res.parameters.get("alpha0")
    return None if p is None else (p.value, fmt_value(p.value, p.stderr, "°"))


@dataclass(frozen=True)
class Drawn:
    """One figure of the report: its PNG with its alt text and caption (HTML), or why it could not be drawn.

    >>> Drawn("fig-figure4", "Figure 4", "Figure 4: the tests", "Figure 4.", missing="no data").png
    b''
    """

    fid: str
    what: str
    alt: str
    caption_html: str
    png: bytes = b""
    missing: str = ""


class _NoBar:
    def advance(self, n: int = 1, description: str | None = None) -> None:
        pass


class _Drawer:
    """Draws figures into ``figures`` (id -> :class:`Drawn`), a failure into ``notes``, advancing ``bar``."""

    def __init__(self, bar):
        self.bar = bar if bar is not None else _NoBar()
        self.figures: dict[str, Drawn] = {}
        self.notes: list[str] = []

    def skip(self, n: int = 1) -> None:
        self.bar.advance(n)

    def __call__(self, fid: str, what: str, alt: str, caption_html: str, draw: Callable) -> None:
        self.bar.advance(0, description=f"report: drawing {what}")
        try:
            png = _fig_png(draw())
        except (ValueError, ArithmeticError) as exc:
            msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            self.notes.append(f"{what}: {plain_text(msg)}")
            self.figures[fid] = Drawn(fid, what, alt, caption_html, missing=msg)
        else:
            self.figures[fid] = Drawn(fid, what, alt, caption_html, png)
        self.bar.advance()


def draw_figures(processed, actuator, fits: Mapping, models, hyst: Mapping, separate, bar=None):
    """Every figure of the report: ``(figures, notes, stresses)``.

    Figure 4 of the tests; per model of ``models`` its Figure 7, the alpha0 profile and the prediction
    band (three steps of ``bar`` each, drawn where the fit has them); the energy-loss ratios of the
    loop fits ``hyst`` and, for a loop fit of its own (``separate``), its loops; the force-balance
    model's internal stresses.  ``figures`` maps each id to a :class:`Drawn`, ``notes`` says which
    could not be drawn and why, ``stresses`` gives the pressure and curvature of the stress figure
    (or None).  ``bar`` is a :class:`bendpam.infra.progress.Progress` (or None).

    Examples
    --------
    Two virtual tests of the paper's BE-PAM, not fitted: Figure 4 alone.

    >>> from pathlib import Path
    >>> import bendpam
    >>> from bendpam.lab import RawTest
    >>> from bendpam.lab.processing import ProcessingOptions
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> be = bendpam.physics.presets.be_pam()
    >>> settings = SimulationSettings(cycles=1, rate_hz=2.0, hysteresis=0.0, seed=1)
    >>> raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv", pressure_kpa=p)
    ...         for p in (100.0, 200.0)]
    >>> processed = bendpam.process_tests(raws, keep_series=False, options=ProcessingOptions(grid_points=21))
    >>> figures, notes, stresses = draw_figures(processed, be, {}, [], {}, None)
    >>> list(figures), figures["fig-figure4"].png[:4], notes, stresses
    (['fig-figure4'], b'\x89PNG', [], None)
    """
    from bendpam.present import figures as plots

    draw = _Drawer(bar)
    who = actuator.name or actuator.kind
    draw("fig-figure4", "Figure 4",
         f"Figure 4: cyclic moment-curvature loops, blocked moment and free-bending curvature against "
         f"pressure for {who}",
         "Figure 4. (a) Filtered cyclic loops at each pressure (dashed: the mean of the branches); (b) blocked "
         "moment against pressure (mean ± SE) with the deadband line; (c) free-bending curvature against "
         "pressure (mean ± SE). Magnitudes.",
         lambda: plots.figure4(processed))
    for m in models:
        _model_figures(draw, processed, m, fits.get(m))
    _hysteresis_figures(draw, processed, hyst, separate)
    stresses = _stress_figure(draw, processed, fits)
    return draw.figures, draw.notes, stresses


def _model_figures(draw: _Drawer, processed, m: str, res) -> None:
    """Figure 7, the alpha0 profile and the prediction band of one model's fit (three steps)."""
    from bendpam.present import figures as plots

    label = MODEL_LABEL[m]
    if res is None:
        draw.skip(3)
        return
    loop_txt = " with its friction loop" if getattr(res, "hysteresis", None) is not None else ""
    draw(f"fig-figure7-{m}", f"Figure 7 ({label} model)",
         f"Figure 7: {label} model fit against the measured moment-curvature curves, blocked "
         f"moment and free-bending curvature",
         f"Figure 7, {label} model{loop_txt}. (a) Measured branches (thin), mean curve (markers) and "
         f"the fitted model (lines); (b) blocked moment; (c) free-bending curvature. NRMSE of the cycles "
         f"{fmt_pct(res.metrics.nrmse_cycles)} %.",
         lambda: plots.figure7(processed, res))
    prof = alpha0_profile(res)
    if prof is not None:
        draw(f"fig-alpha0-{m}", f"the α₀ profile ({label} model)",
             f"Profile of the fit error against the braid angle α₀, {label} model",
             f"Profile of α₀, {label} model: at each fixed α₀ every other parameter is fitted again. "
             "A sharp minimum means that the data determine α₀; the shaded band is the reported "
             "interval (±2 standard errors).",
             lambda: alpha0_profile_figure(prof, label, _fitted_alpha0(res)))
    else:
        draw.skip()
    band = prediction_band(res, processed)
    if band is not None:
        draw(f"fig-band-{m}", f"the prediction band ({label} model)",
             f"Predictions of the {label} model with their uncertainty band, inside and beyond the "
             "tested pressures",
             f"Predictions of the {label} model with a band of ±2 standard errors from the parameters' "
             "covariance; the grey span is the tested pressure range: beyond it the predictions are "
             "extrapolations and the band widens.",
             lambda: band_figure(band, processed, label))
    else:
        draw.skip()


def _hysteresis_figures(draw: _Drawer, processed, hyst: Mapping, separate) -> None:
    """The energy-loss ratios of the loop fits, and the loops of a loop fit of its own (two steps)."""
    from bendpam.present import figures as plots

    if hyst:
        draw("fig-hysteresis", "the energy-loss ratios",
             "Energy-loss ratio per pressure, measured and predicted by the fitted loop model",
             "Energy-loss ratio (loop area / stored energy) per pressure: measured (markers, mean over the "
             "cycles) and predicted by the fitted loop model of each model (lines). The fitted loops "
             "themselves are drawn against the measured branches in Figure 7 (a)"
             + (" and below." if separate is not None else "."),
             lambda: loss_figure(processed, {f"{MODEL_LABEL.get(m, m)} model with its loop":
                                              r.hysteresis.energy_loss_ratio for m, r in hyst.items()}))
    else:
        draw.skip()
    if separate is not None and separate.hysteresis is not None:
        hl = MODEL_LABEL[separate.model]
        draw("fig-hysteresis-loops", "the hysteresis loops",
             f"Measured hysteresis loops against the fitted loop model ({hl} model)",
             f"Hysteresis: (a) measured branches and the fitted loops ({hl} model with a "
             f"{LAW_LABEL.get(separate.hysteresis.law, separate.hysteresis.law)} loop); (b) blocked moment; "
             "(c) free-bending curvature.",
             lambda: plots.figure7(processed, separate))
    else:
        draw.skip()


def _stress_figure(draw: _Drawer, processed, fits: Mapping) -> dict | None:
    """The force-balance model's internal stresses at the highest pressure and half its free curvature."""
    from bendpam.present import figures as plots

    if "force_balance" not in fits:
        draw.skip()
        return None
    fb_act = fits["force_balance"].actuator
    top = processed.results[-1]
    k_mag = 0.5 * float(top.free_curvature[0])
    k_signed = (fb_act.bend_sign or 1) * k_mag
    kt = fmt_value(k_signed)
    draw("fig-stresses", "the internal stresses",
         f"Force-balance internal stresses around the cross-section at {top.pressure_kpa:g} kPa and "
         f"k′ = {kt} 1/mm",
         f"Force-balance model (fitted actuator): bladder and braid stresses around the cross-section "
         f"at P = {top.pressure_kpa:g} kPa, the highest tested pressure, and k′ = {kt} 1/mm, "
         f"half the measured free-bending curvature there (k′ = ±|k|/2, signed by the actuator type).",
         lambda: plots.plot_internal_stresses(fb_act, top.pressure_kpa, k_signed))
    return {"pressure_kpa": top.pressure_kpa, "curvature_per_mm": k_signed}
