"""Vectorised root finders shared by the physics layer.

* :func:`bracketed_newton`: Newton's method safeguarded by a bracket, for an increasing function
  (the radius equation eq 5 in :mod:`bendpam.physics.braid`, the free curvature and the inverse of
  the stable branch on the spline table of :mod:`bendpam.physics.law`).
* :func:`illinois`: the Illinois variant of regula falsi (no derivative needed);
* :func:`table_newton`: Newton's method started from a table of the function and safeguarded by the
  table's bracket, secant slopes after the first step, for the free-bending roots of
  :class:`~bendpam.physics.law.MomentLaw` (:func:`bendpam.physics.branch.solve_free`).

Both work on whole arrays of independent problems at once, with no Python loop over the points.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from bendpam.errors import InputTypeError
from bendpam.validate import float_array, integer

__all__ = ["bracketed_newton", "illinois", "table_newton"]


def _callable(name: str, f: Any) -> None:
    if not callable(f):
        raise InputTypeError(f"{name} = {f!r:.60} must be a function")


def bracketed_newton(f_and_slope: Callable[[np.ndarray], tuple[Any, Any]], x, lo, hi, *, maxiter: int,
                     rtol: float | None = None) -> np.ndarray:
    """Safeguarded Newton iteration on ``f(x) = 0`` for an increasing ``f``, point by point on arrays.

    Each step evaluates ``f, df/dx = f_and_slope(x)`` and keeps the bracket: ``lo`` moves to ``x``
    where ``f < 0``, ``hi`` where ``f > 0``.  A Newton step that leaves ``[lo, hi]`` is replaced
    by the bracket's midpoint; a point where ``f == 0`` stays.  Without ``rtol`` the iteration
    runs ``maxiter`` steps; with it, it stops as soon as every point is done (its last Newton
    step inside the bracket and below ``rtol |x|``, or ``f == 0``), after at most ``maxiter``.

    For a decreasing function pass ``-f`` and ``-df/dx`` (the step ``f / (df/dx)`` is the same
    to the bit).

    Parameters
    ----------
    f_and_slope : callable
        ``x -> (f(x), f'(x))``, arrays of the shape of ``x``.
    x, lo, hi : array_like
        Starting points and brackets (broadcasting against each other).
    maxiter : int
        Most steps.
    rtol : float, optional
        Relative step size that ends the iteration (quadratic convergence: a step below
        ``1e-8 |x|`` leaves an error near ``1e-16 |x|``).

    Returns
    -------
    ndarray
        The roots, shape of ``x``.

    Examples
    --------
    >>> import numpy as np
    >>> q = np.array([2.0, 3.0, 10.0])
    >>> x = bracketed_newton(lambda x: (x * x - q, 2.0 * x), np.ones(3), np.zeros(3), q, maxiter=60, rtol=1e-8)
    >>> bool(np.allclose(x, np.sqrt(q), rtol=1e-15, atol=0.0))
    True
    """
    _callable("f_and_slope", f_and_slope)
    x, lo, hi = (float_array(name, v, "1") for name, v in (("x", x), ("lo", lo), ("hi", hi)))
    maxiter = integer("maxiter", maxiter, 0, 10_000)
    for _ in range(maxiter):
        f, df = f_and_slope(x)
        # maintain the bracket (f is increasing in x)
        lo = np.where(f < 0.0, x, lo)
        hi = np.where(f > 0.0, x, hi)
        xn = x - f / df
        outside = ~((xn >= lo) & (xn <= hi))
        xn = np.where(outside, 0.5 * (lo + hi), xn)
        if rtol is not None:
            done = ((np.abs(xn - x) <= rtol * np.abs(x)) & ~outside) | (f == 0.0)
        x = np.where(f == 0.0, x, xn)
        if rtol is not None and np.all(done):
            break
    return x


def illinois(F, a, b, tol, maxiter: int = 100):
    """Vectorised Illinois (modified regula falsi) root finder on brackets with ``F(a) >= 0 >= F(b)``.

    ``F(x, idx)`` evaluates the function at points ``x`` for the flat indices ``idx`` of the
    problem, so only unconverged points are evaluated.  A point stops when its bracket or its last
    step is below ``tol`` (scalar or per point), or ``F`` hits zero.  Returns the roots (shape of
    ``a``).  At most ``maxiter`` steps (at least one).

    Examples
    --------
    >>> import numpy as np
    >>> q = np.array([2.0, 3.0])
    >>> x = illinois(lambda x, idx: q[idx] - x * x, np.zeros(2), q, 1e-14)
    >>> bool(np.allclose(x, np.sqrt(q), rtol=1e-13))
    True
    """
    _callable("F", F)
    maxiter = integer("maxiter", maxiter, 0, 10_000)
    tol = float_array("tol", tol, "1")
    shape = np.shape(a)
    a = np.array(float_array("a", a, "1"), dtype=float).ravel()
    b = np.array(float_array("b", b, "1"), dtype=float).ravel()
    tol = np.broadcast_to(np.asarray(tol, dtype=float), shape).ravel()
    every = np.arange(a.size)
    fa, fb = F(a, every), F(b, every)
    # an unsolved point starts at NaN: its first step is never "small" (from the midpoint it was zero
    # when the first secant point fell on it, as for F = 2 - x^2 on [0, 2], and stopped there)
    x = np.where(fa == 0.0, a, np.where(fb == 0.0, b, np.nan))
    side = np.zeros(a.size)
    act = np.flatnonzero((fa != 0.0) & (fb != 0.0))
    for _ in range(max(int(maxiter), 1)):
        if act.size == 0:
            break
        aa, bb, fa_, fb_ = a[act], b[act], fa[act], fb[act]
        xs = (aa * fb_ - bb * fa_) / (fb_ - fa_)
        inside = (xs > np.minimum(aa, bb)) & (xs < np.maximum(aa, bb))
        xs = np.where(inside, xs, 0.5 * (aa + bb))
        step = np.abs(xs - x[act])
        x[act] = xs
        fx = F(xs, act)
        pos = fx > 0.0
        sd = side[act]
        # Illinois: halve the function value kept at the end that did not move twice in a row
        fb_ = np.where(pos & (sd == 1), 0.5 * fb_, fb_)
        fa_ = np.where(~pos & (sd == -1), 0.5 * fa_, fa_)
        a[act] = np.where(pos, xs, aa)
        fa[act] = np.where(pos, fx, fa_)
        b[act] = np.where(pos, bb, xs)
        fb[act] = np.where(pos, fb_, fx)
        side[act] = np.where(pos, 1.0, -1.0)
        done = (fx == 0.0) | (np.abs(b[act] - a[act]) <= tol[act]) | (step <= tol[act])
        act = act[~done]
    return x.reshape(shape)


def table_newton(G, x0, slope0, a, b, ga, gb, tol, maxiter: int = 100):
    """Roots of ``G(x) = 0`` on brackets ``[a, b]`` (``G(a) <= 0 <= G(b)``), started from a table of ``G``.

    The start ``x0`` and its slope ``slope0`` come from an interpolant of tabulated values (no
    evaluation of ``G``); the bracket's values ``ga``, ``gb`` are the table's too (``+inf`` is allowed
    at ``b``).  Each step evaluates ``G`` once, only at unconverged points (``G(x, idx)`` for the flat
    indices ``idx``), and moves by Newton's step with the last secant slope (the first with
    ``slope0``, or, where that is not finite, the secant to ``a``).  A step that leaves the bracket
    (which shrinks with every evaluation) is replaced by the bracket's midpoint.  A point stops when
    its step or its bracket is below ``tol`` (scalar or per point), or ``G`` is zero there.  With a
    start from a cubic table a point needs about two evaluations (the regula falsi of
    :func:`illinois` about five, and two more for the bracket).

    Returns the roots (shape of ``x0``).

    Examples
    --------
    >>> import numpy as np
    >>> q = np.array([2.0, 3.0])
    >>> x = table_newton(lambda x, idx: x * x - q[idx], np.array([1.4, 1.7]), np.array([2.8, 3.4]),
    ...                  np.ones(2), np.full(2, 2.0), 1.0 - q, 4.0 - q, 1e-14)
    >>> bool(np.allclose(x, np.sqrt(q), rtol=1e-15))
    True
    """
    _callable("G", G)
    maxiter = integer("maxiter", maxiter, 1, 10_000)
    shape = np.shape(x0)
    x, s0, a, b, ga, gb = (np.array(float_array(name, v, "1"), dtype=float).ravel() for name, v in
                           (("x0", x0), ("slope0", slope0), ("a", a), ("b", b), ("ga", ga), ("gb", gb)))
    tol = np.broadcast_to(np.asarray(float_array("tol", tol, "1"), dtype=float), shape).ravel()
    x = np.where(ga == 0.0, a, np.where(gb == 0.0, b, x))
    # the first slope: the table's, else the secant from the bracket's left end
    xp, gp = a.copy(), ga.copy()
    first = np.isfinite(s0) & (s0 != 0.0)
    act = np.flatnonzero((ga != 0.0) & (gb != 0.0))
    for _ in range(maxiter):
        if act.size == 0:
            break
        xa, lo, hi = x[act], a[act], b[act]
        g = G(xa, act)
        neg, pos = g < 0.0, g > 0.0
        lo, hi = np.where(neg, xa, lo), np.where(pos, xa, hi)
        a[act], b[act] = lo, hi
        with np.errstate(divide="ignore", invalid="ignore"):
            slope = np.where(first[act], s0[act], (g - gp[act]) / (xa - xp[act]))
            xn = xa - g / slope
        inside = (xn > np.minimum(lo, hi)) & (xn < np.maximum(lo, hi))
        # a step below tol is converged even where it rounds onto the bracket's end that ``xa`` just
        # became (a root found to rounding): the midpoint there would restart a converged point
        small = np.abs(xn - xa) <= tol[act]
        xn = np.where(inside, xn, np.where(small, np.clip(xn, np.minimum(lo, hi), np.maximum(lo, hi)),
                                           0.5 * (lo + hi)))
        xp[act], gp[act] = xa, g
        first[act] = False
        done = ~(neg | pos) | small | (np.abs(hi - lo) <= tol[act])
        x[act] = np.where(neg | pos, xn, xa)
        act = act[~done]
    return x.reshape(shape)
