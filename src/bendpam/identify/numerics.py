"""Numerical tools of the identification: bounded linear least squares and Chebyshev interpolation.

:func:`bounded_lstsq` solves the linear parameters of every trial exactly (variable projection);
:func:`chebyshev_interpolation` lets the kinematics be sampled on a few nodes and interpolated to
the data; :func:`halfline` turns one linear inequality into an interval.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["bounded_lstsq", "chebyshev_interpolation", "halfline"]


def chebyshev_interpolation(x: np.ndarray, hi: float, n: int = 32) -> tuple[np.ndarray, np.ndarray]:
    """Chebyshev nodes on ``[0, hi]`` and the barycentric matrix interpolating from them to ``x``.

    >>> x = np.array([0.0, 0.3, 1.0])
    >>> nodes, W = chebyshev_interpolation(x, 1.0, 8)
    >>> np.allclose(W @ np.cos(nodes), np.cos(x))
    True
    """
    j = np.arange(n)
    t = np.cos(np.pi * (j + 0.5) / n)
    nodes = 0.5 * hi * (t + 1.0)
    wts = (-1.0) ** j * np.sin(np.pi * (j + 0.5) / n)
    diff = x[:, None] - nodes[None, :]
    hit = diff == 0.0
    diff[hit] = 1.0
    W = wts / diff
    W /= W.sum(axis=1, keepdims=True)
    rows = hit.any(axis=1)
    if rows.any():
        W[rows] = hit[rows].astype(float)
    return nodes, W


def halfline(a: float, b: float) -> tuple[float, float]:
    """The ``x`` with ``a x >= b``, as an interval ``(lo, hi)``.

    >>> halfline(2.0, 1.0), halfline(-1.0, 3.0)
    ((0.5, inf), (-inf, -3.0))
    """
    if a > 0:
        return b / a, math.inf
    if a < 0:
        return -math.inf, b / a
    return (-math.inf, math.inf) if b <= 0 else (math.inf, -math.inf)


def _small_lstsq(R: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.linalg.lstsq(R, b, rcond=None)[0] if R.shape[1] else np.zeros(0)


def bounded_lstsq(A: np.ndarray, y: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """``min |A x - y|`` with ``lo <= x <= hi`` (A tall, few columns).

    One QR of ``[A | y]`` reduces the problem to ``min |R x - b|`` with ``R`` square; that is solved
    exactly by a primal active-set method (variables at a bound are fixed, released when their
    multiplier has the wrong sign; a step that leaves the box stops at the first bound), the
    method of Stark and Parker's BVLS on the small system.  ``scipy.optimize.lsq_linear`` is the
    fallback should the iteration not settle.

    >>> A = np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    >>> bounded_lstsq(A, np.array([1.0, -1.0, 0.0]), np.array([0.0, 0.0]), np.array([5.0, 5.0])).round(6).tolist()
    [0.5, 0.0]
    """
    p = A.shape[1]
    if p == 0:
        return np.zeros(0)
    sc = np.sqrt(np.einsum("ij,ij->j", A, A))
    sc[~(sc > 0)] = 1.0
    H = (A.T @ A) / np.outer(sc, sc)
    try:
        L = np.linalg.cholesky(H)
    except np.linalg.LinAlgError:
        L = None
    if L is not None and np.all(np.abs(np.diag(L)) > 1e-7):
        # columns scaled to unit norm: H = L L^T is well conditioned enough for the normal equations
        R, b = L.T, np.linalg.solve(L, (A.T @ y) / sc)
    else:
        Rb = np.asarray(np.linalg.qr(np.column_stack([A / sc, y]), mode="r"))
        R, b = Rb[:p, :p], Rb[:p, p]
    lo, hi = lo * sc, hi * sc
    x = _small_lstsq(R, b)
    if np.all(x >= lo) and np.all(x <= hi):
        return x / sc
    x = np.clip(x, lo, hi)
    fixed = (x <= lo) | (x >= hi)
    for _ in range(8 * p + 10):
        f = ~fixed
        z = x.copy()
        z[f] = _small_lstsq(R[:, f], b - R[:, ~f] @ x[~f])
        if np.all(z[f] >= lo[f]) and np.all(z[f] <= hi[f]):
            x = z
            g = R.T @ (R @ x - b)  # gradient of |R x - b|^2 / 2
            tol = 1e-12 * float(np.abs(R.T @ b).max() + 1e-300)
            bad = fixed & (((x <= lo) & (g < -tol)) | ((x >= hi) & (g > tol)))
            if not bad.any():
                return x / sc
            i = int(np.argmax(np.where(bad, np.abs(g), -1.0)))
            fixed[i] = False
            continue
        # step toward z until the first free variable meets a bound
        dz = z - x
        with np.errstate(divide="ignore", invalid="ignore"):
            t_lo = np.where(f & (z < lo), (lo - x) / dz, np.inf)
            t_hi = np.where(f & (z > hi), (hi - x) / dz, np.inf)
        t = np.minimum(t_lo, t_hi)
        i = int(np.argmin(t))
        step = float(np.clip(t[i], 0.0, 1.0))
        x = np.clip(x + step * dz, lo, hi)
        x[i] = lo[i] if t_lo[i] <= t_hi[i] else hi[i]
        fixed[i] = True
    from scipy.optimize import lsq_linear

    return lsq_linear(A, y, bounds=(lo, hi), method="bvls").x

