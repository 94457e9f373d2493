"""Every figure of bendpam: one home for plotting (the presentation layer).

Figure functions draw on matplotlib ``Figure``/``Axes`` objects with the object-oriented API and
return them; :mod:`matplotlib.pyplot` is never imported and the matplotlib backend is left as the
caller chose it.  They register themselves with :mod:`bendpam.infra.accessors` so that results
reach them lazily (``.plot()``).  Importing this package imports every figure module, so that
every figure is registered.

* :mod:`~bendpam.present.figures.style`: journal sizes and fonts, new figures, saving them;
* :mod:`~bendpam.present.figures.models`: moment-curvature maps, the internal stresses, the demo;
* :mod:`~bendpam.present.figures.lab`: Figures 4 and 7 of the paper (tests and fits);
* :mod:`~bendpam.present.figures.sweep`: a design sweep;
* :mod:`~bendpam.present.figures.hand`: the soft hand in 3-D (poses, Kapandji test, workspace).
"""

from bendpam.present.figures.lab import figure4, figure7
from bendpam.present.figures.models import (
    curve_range,
    demo_figure,
    moment_curvature_figure,
    moment_curves,
    plot_internal_stresses,
    plot_moment_curvature,
)
from bendpam.present.figures.style import (
    DOUBLE_COLUMN_IN,
    FIGURE_FORMATS,
    SINGLE_COLUMN_IN,
    STYLE,
    figure_format,
    figure_size,
    figure_style,
    save_figure,
    styled_figure,
)
from bendpam.present.figures.sweep import sweep_figure

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
from bendpam.present.figures import (
    design,  # noqa: F401  (registers the design figures)
    hand,  # noqa: F401  (registers the hand's figures)
    report,  # noqa: F401  (registers the report's figures)
)
