"""Lazy access from results to their figures, the way xarray's ``.plot`` accessor works.

Computation never imports :mod:`bendpam.present`.  A figure function registers itself under a
name when its module is imported (:func:`register`); a result's ``.plot()`` asks for the function
by that name (:func:`figure`), and only then is :mod:`bendpam.present.figures` imported.  This is
the one place where a lower layer reaches the presentation layer, and it does so by name.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any, TypeVar

from bendpam.errors import BendpamError

__all__ = ["figure", "register"]

_F = TypeVar("_F", bound=Callable[..., Any])
_REGISTRY: dict[str, Callable[..., Any]] = {}
_PRESENT = "bendpam.present.figures"


def register(name: str) -> Callable[[_F], _F]:
    """Register a figure function under ``name`` (a decorator used by :mod:`bendpam.present.figures`).

    >>> @register("example.square")
    ... def draw(x):
    ...     return x * x
    >>> figure("example.square")(3)
    9
    """

    def deco(fn: _F) -> _F:
        _REGISTRY[name] = fn
        return fn

    return deco


def figure(name: str) -> Callable[..., Any]:
    """The figure function registered under ``name``, importing the figures on first use.

    >>> draw = figure("figure4")   # Figure 4 of the paper: moment-curvature loops of processed tests
    >>> callable(draw)
    True
    """
    if name not in _REGISTRY:
        importlib.import_module(_PRESENT)
    try:
        return _REGISTRY[name]
    except KeyError:
        raise BendpamError(f"no figure is registered as {name!r}; known: {', '.join(sorted(_REGISTRY))}") from None
