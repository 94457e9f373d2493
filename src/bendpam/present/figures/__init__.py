"""Every figure of bendpam: one home for plotting (the presentation layer).

Figure functions draw on matplotlib ``Figure``/``Axes`` objects and return them; they register
themselves with :mod:`bendpam.infra.accessors` so that results reach them lazily (``.plot()``).
Importing this package imports every figure module, so that every figure is registered.
"""

from bendpam.present.figures.base import (
    DOUBLE_COLUMN_IN,
    FIGURE_FORMATS,
    SINGLE_COLUMN_IN,
    STYLE,
    curve_range,
    demo_figure,
    figure4,
    figure7,
    figure_format,
    figure_size,
    figure_style,
    moment_curvature_figure,
    moment_curves,
    plot_internal_stresses,
    plot_moment_curvature,
    save_figure,
    styled_figure,
    sweep_figure,
)

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
from bendpam.present.figures import design  # noqa: F401  (registers the design figures)
