"""The look of every bendpam figure: journal sizes and fonts, new figures, and saving them.

Figures are sized for a journal column (single column :data:`SINGLE_COLUMN_IN` = 3.5 in / 89 mm,
double column :data:`DOUBLE_COLUMN_IN` = 7.2 in / 183 mm) with 7-9 pt text and consistent line
widths.  The style is applied through :func:`figure_style` (a :func:`matplotlib.rc_context`), so
matplotlib's global settings are never changed: every figure function draws inside it (the
:func:`styled` decorator), and :func:`save_figure` saves inside it (PDF and SVG keep their text as
text, with embedded TrueType fonts, and carry no creation date, so the same figure gives the same
bytes).

The figures are :class:`matplotlib.figure.Figure` objects made by :func:`new_figure`, drawn with
the object-oriented API on an Agg canvas: :mod:`matplotlib.pyplot` is never imported and the
backend the caller chose (or will choose) is left alone.  In Jupyter a returned figure shows
itself; :func:`save_figure` writes PNG, PDF or SVG atomically.
"""

from __future__ import annotations

import functools
import sys
import textwrap
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeVar, cast

import matplotlib
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from bendpam.errors import InputError
from bendpam.infra.accessors import register
from bendpam.infra.atomic import atomic_path
from bendpam.validate import file_format

if TYPE_CHECKING:
    from matplotlib.typing import RcKeyType

__all__ = [
    "DOUBLE_COLUMN_IN",
    "FIGURE_FORMATS",
    "SINGLE_COLUMN_IN",
    "STYLE",
    "figure_format",
    "figure_size",
    "figure_style",
    "new_figure",
    "save_figure",
    "styled",
    "styled_figure",
    "wrap_text",
]

#: Width of a single journal column, in (89 mm).
SINGLE_COLUMN_IN = 3.5
#: Width of a double (full-page) journal column, in (183 mm).
DOUBLE_COLUMN_IN = 7.2
#: The figure formats :func:`save_figure` writes.
FIGURE_FORMATS = ("png", "pdf", "svg")

#: The rc settings of every bendpam figure (applied with :func:`figure_style`).
STYLE: dict[RcKeyType, Any] = {
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


def styled(fn: _F) -> _F:
    """Decorator: run a figure function inside :func:`figure_style`.

    Examples
    --------
    >>> import matplotlib
    >>> @styled
    ... def font_size():
    ...     return matplotlib.rcParams["font.size"]
    >>> font_size()
    8.0
    """

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with figure_style():
            return fn(*args, **kwargs)

    return cast(_F, wrapper)


def new_figure(figsize: tuple[float, float] | None = None, **kwargs: Any) -> Figure:
    """A :class:`matplotlib.figure.Figure` on an Agg canvas, outside :mod:`matplotlib.pyplot`.

    ``figsize`` is in inches (default: the rc setting, :data:`STYLE` inside :func:`figure_style`);
    other keywords go to :class:`~matplotlib.figure.Figure`.  Draw on it with ``fig.add_subplot()``
    or ``fig.subplots()``; nothing needs closing (the figure goes when the last reference does).

    Examples
    --------
    >>> fig = new_figure((3.5, 2.0))
    >>> ax = fig.add_subplot()
    >>> fig.get_size_inches().tolist(), type(fig.canvas).__name__
    ([3.5, 2.0], 'FigureCanvasAgg')
    """
    fig = Figure(figsize=figsize, **kwargs)
    FigureCanvasAgg(fig)  # a renderer for tight_layout and for measuring text, whatever the backend
    return fig


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


def wrap_text(text: str, width_in: float, size_pt: float = 8.0) -> str:
    """Wrap ``text`` into lines that fit ``width_in`` inches at ``size_pt`` points (about 0.5 em a character).

    Line breaks already in ``text`` are kept.

    Examples
    --------
    >>> print(wrap_text("a title that is too long for one narrow column", 1.5))
    a title that is too long
    for one narrow column
    """
    chars = max(int(width_in * 72.0 / (0.52 * size_pt)), 12)
    return "\n".join(textwrap.fill(part, chars) for part in text.split("\n"))


@styled
def styled_figure(draw: Callable[[Any], Any], width: str = "single", aspect: float = 0.8) -> Figure:
    """A one-axes figure of journal size drawn by ``draw(ax)`` inside :func:`figure_style`; returns the figure.

    For drawing functions that take an ``ax`` (the design figures).

    Examples
    --------
    >>> fig = styled_figure(lambda ax: ax.plot([0, 1], [0, 1]), aspect=0.5)
    >>> fig.get_size_inches().tolist(), len(fig.axes[0].lines)
    ([3.5, 1.75], 1)
    """
    fig = new_figure(figure_size(width, aspect))
    draw(fig.add_subplot())
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


@register("save_figure")
def save_figure(fig, path, format: str | None = None, dpi: int | None = None) -> Path:
    """Save ``fig`` atomically to ``path`` as PNG, PDF or SVG, close it, and return the path.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        A figure of this package (:func:`new_figure`), or one made with :mod:`matplotlib.pyplot`
        (which is then closed, as :func:`matplotlib.pyplot.close` would).
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
    pyplot = sys.modules.get("matplotlib.pyplot")  # only if the caller uses pyplot: never imported here
    if pyplot is not None:
        pyplot.close(fig)  # a figure pyplot does not manage is left as it is
    return Path(path)
