"""The report's own figures: the alpha0 profile, the prediction band and the energy-loss ratios.

Drawn on :func:`~bendpam.present.figures.style.new_figure` objects inside the journal style
(never :mod:`matplotlib.pyplot`), and registered with :mod:`bendpam.infra.accessors`; the report
(:mod:`bendpam.present.report.plots`) renders them to PNG.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from matplotlib.figure import Figure

from bendpam.infra.accessors import register
from bendpam.present.figures.style import DOUBLE_COLUMN_IN, figure_style, new_figure

__all__ = ["alpha0_profile_figure", "band_figure", "loss_figure"]

@register("alpha0_profile")
def alpha0_profile_figure(prof: dict, label: str, fitted: tuple[float, str] | None = None) -> Figure:
    """The alpha0 profile of a fit (the best objective at each fixed alpha0) with the reported interval.

    ``prof`` is :func:`bendpam.present.report.plots.alpha0_profile`'s dictionary; ``label`` the model's
    name for the title; ``fitted`` the fitted alpha0 (deg) and its text for the legend, if any.

    >>> prof = {"alpha0_deg": np.array([69.6, 69.7, 69.8]), "objective": np.array([4e-4, 1e-4, 9e-4]),
    ...         "nrmse_percent": np.array([2.0, 1.0, 3.0]), "interval_deg": (69.65, 69.75)}
    >>> fig = alpha0_profile_figure(prof, "energy", (69.7, "69.70 ± 0.03°"))
    >>> len(fig.axes), fig.axes[0].get_xlabel()
    (1, 'α₀ (°)')
    """
    with figure_style():
        x = prof["alpha0_deg"]
        y = prof["nrmse_percent"] if prof["nrmse_percent"] is not None else prof["objective"]
        fig = new_figure((0.6 * DOUBLE_COLUMN_IN, 2.6))
        ax = fig.add_subplot()
        ok = np.isfinite(x) & np.isfinite(y)
        order = np.argsort(x[ok])
        ax.plot(x[ok][order], y[ok][order], "o-", ms=3, lw=1.2, color="C0", label="best fit at fixed α₀")
        if prof["interval_deg"] is not None:
            ax.axvspan(*prof["interval_deg"], color="C1", alpha=0.2, lw=0, label="reported interval (±2 SE)")
        if fitted is not None:
            ax.axvline(fitted[0], color="C3", lw=1.2, label=f"fitted α₀ = {fitted[1]}")
        ax.set_xlabel("α₀ (°)")
        ax.set_ylabel("NRMSE of the fitted curves (%)" if prof["nrmse_percent"] is not None else "objective")
        ax.set_title(f"Profile of α₀, {label} model")
        ax.legend()
        fig.tight_layout()
    return fig


_BAND_LABEL = {"blocked_moment": "blocked moment (N·mm)", "free_curvature": "free-bending curvature (1/mm)",
               "moment": "moment (N·mm)"}


@register("prediction_band")
def band_figure(band: dict, processed, label: str) -> Figure:
    """Predictions of a fit with their ±2 SE band against pressure, the tested range shaded, the data as dots.

    ``band`` is :func:`bendpam.present.report.plots.prediction_band`'s dictionary; ``processed`` the
    processed set (its pressures and results); ``label`` the model's name for the title.

    >>> from types import SimpleNamespace as NS
    >>> P = np.linspace(50.0, 300.0, 6)
    >>> band = {"pressure_kpa": P, "series": [("blocked_moment", "N*mm", P, 0.9 * P, 1.1 * P)]}
    >>> processed = NS(pressures_kpa=np.array([100.0, 200.0]),
    ...                results=[NS(blocked_moment=(100.0, 1.0)), NS(blocked_moment=(200.0, 1.0))])
    >>> fig = band_figure(band, processed, "energy")
    >>> len(fig.axes), fig.axes[0].get_ylabel()
    (1, 'blocked moment (N·mm)')
    """
    with figure_style():
        series = band["series"]
        fig = new_figure((DOUBLE_COLUMN_IN, 2.6))
        axes = fig.subplots(1, len(series), squeeze=False)
        P = processed.pressures_kpa
        x = band["pressure_kpa"]
        for ax, (name, _unit, mid, lo, hi) in zip(axes[0], series, strict=True):
            ax.axvspan(P.min(), P.max(), color="0.88", lw=0, label="tested range")
            ok = np.isfinite(lo) & np.isfinite(hi)
            ax.fill_between(x, np.where(ok, lo, np.nan), np.where(ok, hi, np.nan), color="C0", alpha=0.3, lw=0,
                            label="±2 SE band")
            ax.plot(x, mid, "-", color="C0", lw=1.2, label="prediction")
            data = ([r.blocked_moment[0] for r in processed.results] if name == "blocked_moment"
                    else [r.free_curvature[0] for r in processed.results])
            ax.plot(P, data, "o", color="k", ms=3, label="data")
            ax.set_xlabel("pressure (kPa)")
            ax.set_ylabel(_BAND_LABEL.get(name, name.replace("_", " ")))
            ax.legend()
        fig.suptitle(f"{label.capitalize()} model: predictions with their uncertainty band")
        fig.tight_layout()
    return fig


@register("loss_ratios")
def loss_figure(processed, predicted: Mapping[str, list]) -> Figure:
    """Energy-loss ratio per cycle against pressure: measured, and predicted by each fit's loop model.

    ``predicted`` maps a legend label to a list of points with ``pressure_kpa`` and ``predicted``
    (a fit's ``hysteresis.energy_loss_ratio``).

    >>> from types import SimpleNamespace as NS
    >>> processed = NS(pressures_kpa=np.array([100.0, 200.0]),
    ...                results=[NS(energy_loss_ratio=0.18), NS(energy_loss_ratio=0.22)])
    >>> e = [NS(pressure_kpa=100.0, predicted=0.17), NS(pressure_kpa=200.0, predicted=0.23)]
    >>> fig = loss_figure(processed, {"energy model with its loop": e})
    >>> len(fig.axes[0].lines)
    2
    """
    with figure_style():
        fig = new_figure((0.6 * DOUBLE_COLUMN_IN, 2.6))
        ax = fig.add_subplot()
        P = processed.pressures_kpa
        ax.plot(P, [100 * float(r.energy_loss_ratio) for r in processed.results], "o", color="k", ms=4,
                label="measured")
        for i, (name, e) in enumerate(predicted.items()):
            ax.plot([x.pressure_kpa for x in e], [100 * x.predicted for x in e], "s-" if i == 0 else "^--",
                    ms=3, lw=1.1, color=f"C{i}", label=name)
        ax.set_xlabel("pressure (kPa)")
        ax.set_ylabel("energy-loss ratio (%)")
        ax.set_ylim(bottom=0)
        ax.set_title("Energy lost per cycle, measured and predicted")
        ax.legend()
        fig.tight_layout()
    return fig
