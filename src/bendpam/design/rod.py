r"""The one rod solver of :mod:`bendpam.design`: a planar rod along the frame line, and its Newton method.

A finger (:mod:`bendpam.design.finger`), a gripper's finger in contact (:mod:`bendpam.design.grasp`)
and a held fingertip (:mod:`bendpam.design.tip`) are all the same inextensible rod of length ``L``
along the actuator's frame line, discretised on ``n`` equally spaced nodes.  The unknowns are the
nodal frame curvatures ``k'`` (1/mm); the tangent angle is their trapezoidal integral and each
segment is integrated exactly as a circular arc of linearly varying angle (:class:`Rod`), so a
constant-curvature (free) shape is exact.  The equilibrium of each section, ``M(P, k'(s)) =
M_ext(s)``, is written with the actuator's moment law (its stable branch) and the moments of the
loads beyond ``s`` (planar cross products, :func:`cross`).

The equations are solved by one damped, bracketed Newton method (:func:`newton_batch`): exact
Jacobians by the complex step (:func:`complex_jacobian`, or one the caller supplies), a
backtracking line search on the squared residual (Armijo), and steps kept strictly inside box
bounds (at most 90 % of the way to a bound: the stable branch of the law).  It solves a batch of
independent systems at once (the pull-outs of a grasp sweep); :func:`newton` is the same method
for one system, and :func:`continuation` follows a solution along a path parameter.

Units: mm, N, N*mm, rad; curvatures in 1/mm.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from bendpam.design.finger import Finger, FingerLoads
    from bendpam.physics.law import StableBranch

__all__ = [
    "MAX_NEWTON",
    "MIN_STEP",
    "NEWTON_TOL",
    "Rod",
    "complex_jacobian",
    "continuation",
    "cross",
    "newton",
    "newton_batch",
    "sinc",
]

#: Newton's tolerance on ``max |residual|`` (the residuals are scaled: moments by a moment scale)
NEWTON_TOL = 1e-10
#: Newton steps at most (default of :func:`newton` and :func:`newton_batch`)
MAX_NEWTON = 40
#: the smallest step of :func:`continuation` along its path parameter
MIN_STEP = 1.0 / 2048
_EPS = 1e-30  # the complex step


def sinc(x):
    """``sin(x)/x``, analytic (complex-step safe), 1 at 0.

    >>> import numpy as np
    >>> sinc(np.array([0.0, np.pi / 2])).round(6).tolist()
    [1.0, 0.63662]
    """
    small = np.abs(x) < 1e-3
    xs = np.where(small, 1.0, x)
    x2 = x * x
    return np.where(small, 1.0 - x2 / 6.0 + x2 * x2 / 120.0, np.sin(xs) / xs)


def cross(ax, ay, bx, by):
    """z-component of the planar cross product ``a x b`` (batched; complex-step safe).

    The counterclockwise moment (N*mm) of a force ``b`` (N) at lever ``a`` (mm):

    >>> cross(10.0, 0.0, 0.0, 2.0)
    20.0
    """
    return ax * by - ay * bx


class Rod:
    """Geometry and load moments of the discretised finger (batched over leading axes).

    Built from a :class:`~bendpam.design.finger.Finger` (its length, nodes, base, frame side and
    rigid fingertip) and its dead :class:`~bendpam.design.finger.FingerLoads`.  Arrays of nodal
    curvatures ``k`` have the nodes on the last axis and any leading (batch) axes; complex values
    are allowed (complex-step Jacobians).

    Attributes
    ----------
    n, L, h : nodes, active length (mm), node spacing (mm).
    s : (n,) arc length of the nodes, mm.  w : (n,) trapezoidal weights, mm.
    c : the frame side (+1 or -1).  ell, off : fingertip length and offset, mm.
    F, q, Mt : the tip force (N, with the tip mass's weight), distributed load (N/mm), tip moment (N*mm).

    Examples
    --------
    A constant curvature is an exact circular arc:

    >>> import numpy as np
    >>> from bendpam.physics.presets import be_pam
    >>> from bendpam.design.finger import Finger, FingerLoads
    >>> rod = Rod(Finger(be_pam()), FingerLoads())
    >>> phi, x, y, xt, yt = rod.geometry(np.full((1, rod.n), 0.01))     # 1/mm
    >>> round(float(np.degrees(phi[0, -1])), 6), round(float(xt[0]), 4)  # 145 mm * 0.01 rad/mm; 100 sin(1.45)
    (83.07888, 99.2713)
    """

    def __init__(self, finger: Finger, loads: FingerLoads):
        self.f = finger
        n = finger.nodes
        L = finger.length
        self.n, self.L = n, L
        self.s = np.linspace(0.0, L, n)
        self.h = L / (n - 1)
        self.w = np.full(n, self.h)
        self.w[[0, -1]] *= 0.5
        self.c = finger.frame_side
        self.x0, self.y0 = finger.base_xy_mm
        self.phi0 = finger.base_angle
        self.ell, self.off = finger.fingertip_mm, finger.fingertip_offset_mm
        self.loads = loads
        self.F = loads.tip_resultant()
        self.q = loads.distributed()
        self.Mt = loads.tip_moment_nmm
        self.rem = L - self.s  # length beyond each node

    def geometry(self, k):
        """Angles, node positions and fingertip point of nodal curvatures ``k``: ``(phi, x, y, xt, yt)``."""
        h = self.h
        kap = self.c * k
        inc = 0.5 * h * (kap[..., 1:] + kap[..., :-1])
        zero = np.zeros((*k.shape[:-1], 1), dtype=k.dtype)
        phi = self.phi0 + np.concatenate([zero, np.cumsum(inc, axis=-1)], axis=-1)
        mid = 0.5 * (phi[..., 1:] + phi[..., :-1])
        sc = h * sinc(0.5 * inc)
        x = self.x0 + np.concatenate([zero, np.cumsum(np.cos(mid) * sc, axis=-1)], axis=-1)
        y = self.y0 + np.concatenate([zero, np.cumsum(np.sin(mid) * sc, axis=-1)], axis=-1)
        pl = phi[..., -1]
        b = self.f.bend
        xt = x[..., -1] + self.ell * np.cos(pl) - b * self.off * np.sin(pl)
        yt = y[..., -1] + self.ell * np.sin(pl) + b * self.off * np.cos(pl)
        return phi, x, y, xt, yt

    def point(self, phi, x, y, sc):
        """Position and angle at arc length ``sc`` (batched scalar) on the arcs between nodes."""
        h = self.h
        jr = np.clip(np.floor(np.real(sc) / h).astype(int), 0, self.n - 2)
        idx = jr[..., None]
        p0 = np.take_along_axis(phi, idx, -1)[..., 0]
        p1 = np.take_along_axis(phi, idx + 1, -1)[..., 0]
        x0 = np.take_along_axis(x, idx, -1)[..., 0]
        y0 = np.take_along_axis(y, idx, -1)[..., 0]
        tau = sc - jr * h
        dp = (p1 - p0) * tau / h
        pm = p0 + 0.5 * dp
        ln = tau * sinc(0.5 * dp)
        return x0 + ln * np.cos(pm), y0 + ln * np.sin(pm), p0 + dp

    def load_moment(self, x, y, xt, yt, lam=1.0):
        """Counterclockwise moment m(s_j) of the dead loads beyond each node, N*mm."""
        Fx, Fy = self.F
        m = lam * (self.Mt + cross(xt[..., None] - x, yt[..., None] - y, Fx, Fy))
        qx, qy = self.q
        if qx or qy:
            w = self.h
            # X_j = int_{s_j}^L x du by the trapezoidal rule
            cx = np.cumsum(0.5 * w * (x[..., 1:] + x[..., :-1])[..., ::-1], axis=-1)[..., ::-1]
            cy = np.cumsum(0.5 * w * (y[..., 1:] + y[..., :-1])[..., ::-1], axis=-1)[..., ::-1]
            zero = np.zeros((*x.shape[:-1], 1), dtype=x.dtype)
            X = np.concatenate([cx, zero], axis=-1)
            Y = np.concatenate([cy, zero], axis=-1)
            m = m + lam * cross(X - self.rem * x, Y - self.rem * y, qx, qy)
        return m

    def moment_scale(self, branch: StableBranch) -> float:
        """Moment scale (N*mm) of Newton's tolerance: blocked moment, fold moments and load moments (not lock-up)."""
        load = abs(self.Mt) + math.hypot(*self.F) * (self.L + self.ell) + math.hypot(*self.q) * self.L ** 2
        folds = [abs(m) for m, e in ((branch.moment_max, branch.end_lo), (branch.moment_min, branch.end_hi))
                 if e == "fold"]
        return max([abs(float(branch.moment(0.0)[0])), load, 1.0, *folds])


def complex_jacobian(fun: Callable[[Any], Any], u: np.ndarray) -> np.ndarray:
    """Exact Jacobian of a real-analytic vector function by the complex step (one batched call).

    ``fun`` maps states with the unknowns on the last axis (any leading axes) to residuals.

    >>> import numpy as np
    >>> complex_jacobian(lambda U: U ** 2, np.array([1.0, 3.0])).tolist()
    [[2.0, 0.0], [0.0, 6.0]]
    """
    m = u.size
    U = u[None, :] + 1j * _EPS * np.eye(m)
    return (np.imag(fun(U)) / _EPS).T


def _complex_jacobians(fun, rows, u):
    """Complex-step Jacobians ``(b, m, m)`` of the systems ``rows`` of a batch at the states ``u`` (b, m)."""
    m = u.shape[1]
    R = fun(rows, u[:, None, :] + 1j * _EPS * np.eye(m)[None])
    return np.swapaxes(np.imag(R) / _EPS, 1, 2)


def newton_batch(fun, u0, lo, hi, *, tol: float = NEWTON_TOL, maxit: int = MAX_NEWTON, jac=None, admissible=None):
    """Damped Newton on a batch of independent systems ``fun(rows, U) = 0``, keeping ``lo < u < hi``.

    Parameters
    ----------
    fun : callable ``fun(rows, U)``
        The residuals of the systems ``rows`` (an index array into the batch) at the states ``U``
        of shape ``(len(rows), J, m)`` (``J`` states per system), same shape.  Real-analytic
        (complex-step safe) unless ``jac`` is given.
    u0 : (B, m) array
        Starting states.
    lo, hi : arrays broadcastable to (B, m)
        Bounds (``-inf``/``inf`` for none); every iterate stays strictly inside, at most 90 % of
        the way to a bound per step (the stable branch of the moment law).
    tol : float
        Convergence on ``max |residual|`` of each system.
    maxit : int
        Newton steps at most.
    jac : callable ``jac(rows, u) -> (len(rows), m, m)``, optional
        The Jacobians at the states ``u`` (``len(rows)``, m); default: the exact complex step of ``fun``.
    admissible : callable ``admissible(rows, u) -> (len(rows),) bool``, optional
        Where the bounds are not a box: a trial state that is not admissible is refused by the
        line search like one that does not decrease the residual (the wrist's stable branches).

    Returns
    -------
    (u, ok, nr) : the last states (B, m), whether each system converged (B,), and ``max |residual|`` (B,).

    Notes
    -----
    Each step solves the Newton system (least squares where it is singular), shortens it to stay
    inside the bounds, then halves it (at most 30 times) until the squared residual decreases by
    the Armijo factor ``1 - 1e-4 alpha`` at an ``admissible`` state.  A system fails when the step
    is not finite, the line search fails, or the step shrinks below ``1e-12``; its state stays the
    last accepted one.

    Examples
    --------
    Two systems ``u^2 = a`` solved together:

    >>> import numpy as np
    >>> a = np.array([4.0, 9.0])
    >>> u, ok, nr = newton_batch(lambda rows, U: U ** 2 - a[rows, None, None], np.ones((2, 1)), 0.0, np.inf)
    >>> u.ravel().round(12).tolist(), ok.tolist()
    ([2.0, 3.0], [True, True])
    """
    u = np.array(u0, dtype=float)
    lo = np.broadcast_to(np.asarray(lo, dtype=float), u.shape)
    hi = np.broadcast_to(np.asarray(hi, dtype=float), u.shape)
    if jac is None:
        def jac(rows, v):
            return _complex_jacobians(fun, rows, v)

    def res(rows, V):
        return np.real(fun(rows, V[:, None, :]))[:, 0]

    r = res(np.arange(len(u)), u)
    nr = np.max(np.abs(r), axis=1)
    ok = nr < tol
    live = ~ok & np.isfinite(nr)
    for _ in range(maxit):
        sel = np.flatnonzero(live)
        if not sel.size:
            break
        us, rs = u[sel], r[sel]
        du = _newton_step(jac(sel, us), rs)
        bad = ~np.all(np.isfinite(du), axis=1)
        du[bad] = 0.0
        alpha = _to_bounds(us, du, lo[sel], hi[sel])
        acc, un, rn = _line_search(res, sel, us, rs, du, alpha, ~bad, admissible)
        acc &= alpha >= 1e-12  # a vanishing step fails; the state stays the last accepted one
        u[sel[acc]] = un[acc]
        r[sel[acc]] = rn[acc]
        nr[sel] = np.max(np.abs(r[sel]), axis=1)
        done = nr[sel] < tol
        ok[sel[done]] = True
        live[sel[done | ~acc]] = False
    return u, ok, nr


def _newton_step(J: np.ndarray, r: np.ndarray) -> np.ndarray:
    """The Newton steps ``-J^-1 r`` of a batch (least squares where a Jacobian is singular)."""
    try:
        return np.linalg.solve(J, -r[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return np.stack([np.linalg.lstsq(J[i], -r[i], rcond=None)[0] for i in range(len(r))])


def _to_bounds(u: np.ndarray, du: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The step length (<= 1) that goes at most 90 % of the way to a bound, per system."""
    with np.errstate(divide="ignore", invalid="ignore"):
        a_hi = np.where(du > 0, 0.9 * (hi - u) / du, np.inf)
        a_lo = np.where(du < 0, 0.9 * (lo - u) / du, np.inf)
    return np.minimum(1.0, np.minimum(a_hi.min(axis=1), a_lo.min(axis=1)))


def _line_search(res, sel, us, rs, du, alpha, pending, admissible=None):
    """Backtracking (Armijo on the squared residual, 30 halvings at most); ``alpha`` is updated in place.

    Returns ``(accepted, u, r)`` per system of ``sel``.
    """
    n2 = np.sum(rs * rs, axis=1)
    acc = np.zeros(len(sel), dtype=bool)
    un, rn = us.copy(), rs.copy()
    pend = np.flatnonzero(pending)
    for _ in range(30):
        if not pend.size:
            break
        trial = us[pend] + alpha[pend, None] * du[pend]
        rt = res(sel[pend], trial)
        n2t = np.sum(rt * rt, axis=1)
        good = np.isfinite(n2t) & (n2t <= (1.0 - 1e-4 * alpha[pend]) * n2[pend])
        if admissible is not None:
            good &= admissible(sel[pend], trial)
        gi = pend[good]
        un[gi], rn[gi], acc[gi] = trial[good], rt[good], True
        pend = pend[~good]
        alpha[pend] *= 0.5
    return acc, un, rn


def newton(fun, u0, lo, hi, tol: float = NEWTON_TOL, maxit: int = MAX_NEWTON) -> tuple[np.ndarray, bool, float]:
    """:func:`newton_batch` for one system ``fun(u) = 0`` keeping ``lo < u < hi``: ``(u, ok, |r|_inf)``.

    ``fun`` maps states with the unknowns on the last axis (any leading axes) to residuals and is
    complex-step safe (its Jacobian is the exact complex step).

    >>> import numpy as np
    >>> u, ok, nr = newton(lambda U: U ** 2 - 2.0, np.array([1.0]), np.array([0.0]), np.array([10.0]))
    >>> round(float(u[0]), 9), ok
    (1.414213562, True)
    """
    u, ok, nr = newton_batch(lambda rows, U: fun(U), np.asarray(u0, dtype=float)[None, :],
                             np.asarray(lo, dtype=float)[None, :], np.asarray(hi, dtype=float)[None, :],
                             tol=tol, maxit=maxit)
    return u[0], bool(ok[0]), float(nr[0])


def continuation(system, u0) -> tuple[np.ndarray, float]:
    """Continuation in a path parameter t in [0, 1]: ``system(t) -> (fun, lo, hi)`` solved by :func:`newton`.

    ``u0`` must be (close to) the solution at t = 0.  Adaptive steps (doubling on success, halving
    on failure down to :data:`MIN_STEP`).  Returns the last solution and the parameter reached (1.0
    on success; -1.0 if even the start does not converge).

    >>> import numpy as np
    >>> def system(t):                                    # u^2 = 1 + 3 t, from u = 1 at t = 0
    ...     return (lambda U: U ** 2 - (1.0 + 3.0 * t)), np.array([0.0]), np.array([10.0])
    >>> u, t = continuation(system, np.array([1.0]))
    >>> round(float(u[0]), 12), t
    (2.0, 1.0)
    """
    fun, lo, hi = system(0.0)
    u, ok, _ = newton(fun, np.asarray(u0, dtype=float), lo, hi, NEWTON_TOL)
    if not ok:
        return np.asarray(u0, dtype=float), -1.0
    t, step = 0.0, 1.0
    while t < 1.0:
        step = min(step, 1.0 - t)
        fun, lo, hi = system(t + step)
        un, ok, _ = newton(fun, u, lo, hi, NEWTON_TOL)
        if ok:
            u, t = un, t + step
            step *= 2.0
        else:
            step *= 0.5
            if step < MIN_STEP:
                break
    return u, t
