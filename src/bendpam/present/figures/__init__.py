"""Every figure of bendpam: one home for plotting (the presentation layer).

Figure functions draw on matplotlib ``Figure``/``Axes`` objects with the object-oriented API and
return them; :mod:`matplotlib.pyplot` is never imported and the matplotlib backend is left as the
caller chose it.  They register themselves with :mod:`bendpam.infra.accessors` so that results
reach them lazily (``.plot()``).  Importing this package imports no figure module (nor matplotlib):
it registers every figure's name, and a figure module is imported when one of its names is first
used (``from bendpam.present.figures import figure7`` imports :mod:`.lab` and :mod:`.style` only,
which is all ``bendpam fit`` needs).

* :mod:`~bendpam.present.figures.style`: journal sizes and fonts, new figures, saving them;
* :mod:`~bendpam.present.figures.models`: moment-curvature maps, the internal stresses, the demo;
* :mod:`~bendpam.present.figures.lab`: Figures 4 and 7 of the paper (tests and fits);
* :mod:`~bendpam.present.figures.sweep`: a design sweep;
* :mod:`~bendpam.present.figures.hand`: the soft hand in 3-D (poses, Kapandji test, workspace).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from bendpam.infra.accessors import figure, register

if TYPE_CHECKING:
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

#: The module of each name of ``__all__`` (imported on first use).
_HOME = {name: "lab" for name in ("figure4", "figure7")} | {"sweep_figure": "sweep"} | {
    name: "models" for name in ("curve_range", "demo_figure", "moment_curvature_figure", "moment_curves",
                                "plot_internal_stresses", "plot_moment_curvature")} | {
    name: "style" for name in ("DOUBLE_COLUMN_IN", "FIGURE_FORMATS", "SINGLE_COLUMN_IN", "STYLE", "figure_format",
                               "figure_size", "figure_style", "save_figure", "styled_figure")}

#: The module of each figure registered with :func:`bendpam.infra.accessors.register` (a test checks the list).
_REGISTERED = {"figure4": "lab", "figure7": "lab", "save_figure": "style", "sweep": "sweep"} | {
    name: "design" for name in ("finger_shapes", "finger3d", "grasp", "wrist", "coarse_map", "pareto")} | {
    name: "hand" for name in ("hand_pose", "kapandji", "hand_workspace", "hand_statics", "wrist_map")} | {
    name: "report" for name in ("alpha0_profile", "prediction_band", "loss_ratios")}


def __getattr__(name: str) -> Any:
    """A name of ``__all__``, from its module (imported now)."""
    if name not in _HOME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_HOME[name]}"), name)


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


def _on_first_use(name: str, module: str):
    """A stand-in registered as ``name``: it imports ``module`` (whose figure replaces it) and calls that figure."""

    def draw(*args: Any, **kwargs: Any) -> Any:
        importlib.import_module(f"{__name__}.{module}")
        return figure(name)(*args, **kwargs)

    draw.__name__ = draw.__qualname__ = name
    draw.__doc__ = f"The figure {name!r} of :mod:`bendpam.present.figures.{module}` (imported when first drawn)."
    return draw


for _name, _module in _REGISTERED.items():
    register(_name)(_on_first_use(_name, _module))
