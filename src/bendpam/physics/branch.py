r"""The free-bending branch: the equilibria ``M(P, k') = 0`` connected to the straight state.

Along the bending direction the equilibrium active pressure is ``P_a = B(k') / A(k')`` (eq 50 with
``M = P_a A - B``).  The branch is the part where ``P_a`` rises from 0; it ends at a fold (the
moment-curvature curve is N-shaped and the actuator snaps through), at the braid lock-up limit, or
never.  Everything here is vectorised over a block of actuator cases (sweeps, design searches):

* :func:`branch_table` samples each case's branch in ``u = k'R`` (:mod:`bendpam.physics.sections`)
  and refines its fold (:class:`BranchTable`);
* :func:`solve_free` finds the free-bending roots at given active pressures on it;
* :func:`describe_branch` and :func:`assemble_free` give one actuator's :class:`FreeBranch` and
  :class:`FreeBending`.

The entry points are the methods of :class:`~bendpam.physics.law.MomentLaw` (``branches``,
``free_branch``, ``free_curvature``, ``free_state_array``), which cache the table.

>>> import bendpam
>>> bendpam.MomentLaw.of(bendpam.physics.presets.bc_pam()).free_branch().kind
'fold'
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from bendpam.errors import InputTypeError
from bendpam.physics.roots import illinois, table_newton
from bendpam.physics.sections import branch_path
from bendpam.validate import float_array, instance, integer

if TYPE_CHECKING:
    from bendpam.physics.law import MomentLaw

__all__ = [
    "BRANCH_END",
    "BRANCH_SAMPLES",
    "TINY_ACTIVE_KPA",
    "BranchTable",
    "FreeBending",
    "FreeBranch",
    "assemble_free",
    "branch_table",
    "describe_branch",
    "solve_free",
]

#: Codes of the end of a free-bending branch (as stored in sweeps).
BRANCH_END = {"lock-up": 0, "fold": 1, "unbounded": 2, "neutral": 3}
_END_NAME = {v: k for k, v in BRANCH_END.items()}
#: Active pressures (kPa) below this have the straight free state (k' = 0) without a solve.
TINY_ACTIVE_KPA = 1e-9
#: Samples of the branch table (:meth:`MomentLaw.branches <bendpam.physics.law.MomentLaw.branches>` caches it).
BRANCH_SAMPLES = 1200


@dataclass(frozen=True)
class BranchTable:
    """Sampled free-bending branches of a block of cases (arrays over the cases, shape (n,)).

    ``kt``, ``pt`` (n, samples + 1): curvature (1/mm) and active pressure (kPa) from the
    straight state along the bending direction; ``pt`` is increasing up to the branch end and
    ``inf`` after it.  ``kind`` holds :data:`BRANCH_END` codes; ``p_end`` is the active
    pressure (kPa) at the end (``inf`` when unbounded or neutral); ``k_end`` the curvature there;
    ``k_lim`` the lock-up limit in the bending direction; ``last`` the last table index on the
    branch; ``k_fold``/``use_ref`` the refined fold where it lies between samples.  ``xt``,
    ``x_end``, ``x_fold`` are the same in the branch parameter u = k'R (with the section means computed
    exactly, or interpolated from the shared tables) and ``path`` evaluates the law in it.

    Built by :func:`branch_table`.

    Examples
    --------
    >>> import bendpam
    >>> tab = bendpam.MomentLaw.of(bendpam.physics.presets.be_pam()).branches()
    >>> tab.kt.shape, [k for k, v in BRANCH_END.items() if v == tab.kind[0]]
    ((1, 1201), ['unbounded'])
    """

    sgn: np.ndarray
    k_lim: np.ndarray
    kind: np.ndarray
    p_end: np.ndarray
    k_end: np.ndarray
    last: np.ndarray
    kt: np.ndarray = field(repr=False)
    pt: np.ndarray = field(repr=False)
    k_fold: np.ndarray = field(repr=False)
    use_ref: np.ndarray = field(repr=False)
    xt: np.ndarray = field(repr=False)
    x_end: np.ndarray = field(repr=False)
    x_fold: np.ndarray = field(repr=False)
    path: Any = field(repr=False, compare=False)


def _law(law) -> None:
    """One InputTypeError line unless ``law`` is a :class:`~bendpam.MomentLaw` (by its attributes: the law module
    imports this one, so this one cannot import it)."""
    if not all(hasattr(law, a) for a in ("params", "check_curvature", "branches")):
        raise InputTypeError(f"law = {law!r:.60} must be a MomentLaw, got {type(law).__name__}")


def branch_table(law: MomentLaw, samples: int = BRANCH_SAMPLES) -> BranchTable:
    """Sample ``P_a(x) = B/A`` along each case's bending direction; find its end (fold, lock-up).

    ``x`` is the branch parameter u = k'R, evaluated exactly or on shared tables
    (:func:`~bendpam.physics.sections.branch_path`).  :meth:`MomentLaw.branches
    <bendpam.physics.law.MomentLaw.branches>` caches the table of the default sample count.

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.physics.law import MomentLaw
    >>> tab = branch_table(MomentLaw(bendpam.physics.presets.bc_pam()), 200)
    >>> tab.kind.tolist() == [BRANCH_END["fold"]], tab.p_end.round(1).tolist()   # active kPa
    (True, [102.2])
    """
    _law(law)
    samples = integer("samples", samples, 8, 1_000_000)
    ev = branch_path(law)
    sgn = ev.cs.bend_sign
    ncase = sgn.size
    x_lim = np.where(sgn > 0, ev.x_max, ev.x_min)
    k_lim = np.where(sgn > 0, ev.k_max, ev.k_min)
    xk, pk, n_ok = _sample(ev, sgn, x_lim, samples)
    n = xk.shape[-1] - 1
    has_dec, j = _first_fall(pk, n_ok)
    x_fold, p_fold, use_ref = _refine_folds(ev, xk, pk, has_dec, j)
    kind = np.where(has_dec, BRANCH_END["fold"], np.where(n_ok < n, BRANCH_END["unbounded"], BRANCH_END["lock-up"]))
    kind = np.where(sgn == 0, BRANCH_END["neutral"], kind)
    unstable = has_dec & (j == 0)
    p_end = np.where(kind == BRANCH_END["fold"], np.where(unstable, 0.0, p_fold),
                     np.where(kind == BRANCH_END["unbounded"], np.inf,
                              np.take_along_axis(pk, np.minimum(n_ok, n)[:, None], -1)[:, 0]))
    p_end = np.where(kind == BRANCH_END["neutral"], np.inf, p_end)
    # a refined fold before sample j ends the branch there: sample j is already past it (on the unstable side)
    past = use_ref & (np.abs(x_fold) < np.abs(np.take_along_axis(xk, j[:, None], -1)[:, 0]))
    last = np.where(kind == BRANCH_END["fold"], np.where(past, j - 1, j), np.minimum(n_ok, n))
    pt = np.where(np.arange(n + 1)[None, :] <= last[:, None], pk, np.inf)
    nxt = np.clip(last + 1, 0, n)
    x_after = np.take_along_axis(xk, nxt[:, None], -1)[:, 0]
    x_end = np.where(kind == BRANCH_END["fold"], np.where(unstable, 0.0, x_fold),
                     np.where(kind == BRANCH_END["unbounded"], x_after, x_lim))
    x_end = np.where(kind == BRANCH_END["neutral"], 0.0, x_end)
    every = np.arange(ncase)
    kt = ev.to_k(xk, every[:, None])
    return BranchTable(sgn=sgn, k_lim=k_lim, kind=kind, p_end=p_end, k_end=ev.to_k(x_end, every), last=last, kt=kt,
                       pt=pt, k_fold=ev.to_k(x_fold, every), use_ref=use_ref, xt=xk, x_end=x_end, x_fold=x_fold,
                       path=ev)


def _sample(ev, sgn, x_lim, samples: int):
    """``(x, P_a)`` from the straight state (a first column of zeros) to the limit ``x_lim`` at ``samples``
    graded points, and ``n_ok``: the first sample where ``A`` turns against the bending direction (``P_a``
    undefined from there; ``samples`` when it never does)."""
    ncase = sgn.size
    frac = np.linspace(0.0, 1.0, samples + 1)[1:] ** 1.5  # graded: denser near 0 where the curve starts
    xg = x_lim[:, None] * frac
    A, B = ev.coef(xg, np.arange(ncase)[:, None])
    sA = sgn[:, None] * A
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.where(sA > 0.0, B / A, np.nan)
    n = xg.shape[-1]
    bad_a = ~(sA > 0.0)
    n_ok = np.where(bad_a.any(-1), np.argmax(bad_a, -1), n)
    pk = np.concatenate([np.zeros((ncase, 1)), p], axis=-1)
    xk = np.concatenate([np.zeros((ncase, 1)), xg], axis=-1)
    return xk, pk, n_ok


def _first_fall(pk, n_ok):
    """``(has_dec, j)``: whether the sampled ``P_a`` stops rising before ``n_ok``, and the sample where it does."""
    n = pk.shape[-1] - 1
    valid = np.arange(n + 1)[None, :] <= n_ok[:, None]
    pk_valid = np.where(valid, pk, np.nan)
    dec = (np.diff(pk_valid, axis=-1) <= 0.0) & valid[:, 1:]
    has_dec = dec.any(-1)
    j = np.where(has_dec, np.argmax(dec, -1), 0)
    return has_dec, j


def _refine_folds(ev, xk, pk, has_dec, j):
    """``(x_fold, p_fold, use_ref)``: the sampled fold at ``j``, refined by a grid search for the maximum of
    ``P_a`` on ``[xk[j-1], xk[j+1]]`` where that finds a higher point (``use_ref``).

    Each pass evaluates :data:`_FOLD_GRID` interior points of the bracket at once and keeps the two
    cells around the highest, a factor ``2 / (_FOLD_GRID + 1)`` a pass: :data:`_FOLD_PASSES` passes shrink
    the bracket to about 1e-10 of a sample interval (as the 48 steps of the golden section it replaced,
    in a quarter of the passes).
    """
    n = xk.shape[-1] - 1
    lo = np.take_along_axis(xk, np.clip(j - 1, 0, n)[:, None], -1)[:, 0]
    hi = np.take_along_axis(xk, np.clip(j + 1, 0, n)[:, None], -1)[:, 0]
    a_, b_ = np.minimum(lo, hi), np.maximum(lo, hi)
    rows = np.flatnonzero(has_dec & (j > 0))
    x_fold = np.take_along_axis(xk, j[:, None], -1)[:, 0].copy()
    pj = np.take_along_axis(pk, j[:, None], -1)[:, 0]
    p_fold = pj.copy()
    use_ref = np.zeros(xk.shape[0], dtype=bool)
    if rows.size:

        def p_of(x, r):
            Ax, Bx = ev.coef(x, r)
            with np.errstate(divide="ignore", invalid="ignore"):
                return Bx / Ax

        a, b = a_[rows], b_[rows]
        frac = np.arange(1, _FOLD_GRID + 1) / (_FOLD_GRID + 1.0)
        rep = np.repeat(rows, _FOLD_GRID)
        at = np.arange(rows.size)
        for _ in range(_FOLD_PASSES):
            xs = a[:, None] + (b - a)[:, None] * frac
            f = p_of(xs.ravel(), rep).reshape(xs.shape)
            i = np.argmax(np.where(np.isfinite(f), f, -np.inf), axis=1)
            a = np.where(i > 0, xs[at, np.maximum(i - 1, 0)], a)
            b = np.where(i < _FOLD_GRID - 1, xs[at, np.minimum(i + 1, _FOLD_GRID - 1)], b)
        xm = 0.5 * (a + b)
        pm = p_of(xm, rows)
        ref = np.isfinite(pm) & (pm > pj[rows])
        use_ref[rows] = ref
        x_fold[rows] = np.where(ref, xm, x_fold[rows])
        p_fold[rows] = np.where(ref, pm, p_fold[rows])
    return x_fold, p_fold, use_ref


#: Interior points a pass of the fold's grid search, and the passes (``(2 / 16)^12 ~ 7e-12``).
_FOLD_GRID = 15
_FOLD_PASSES = 12


def solve_free(law: MomentLaw, tab: BranchTable, pa: np.ndarray, xtol: float = 1e-13) -> tuple[np.ndarray, np.ndarray]:
    """Roots ``(k', u = k'R)`` of ``M = 0`` at active pressures ``pa`` (cases, pressures) (kPa); NaN above the end.

    All pressures of all cases at once: the sampled branch ``tab`` gives each root's bracket (the
    samples it lies between) and a start, the root of a cubic Hermite interpolant of ``P_a(u)`` on
    the bracket (slopes from the neighbouring samples); Newton's method on ``P_a(u) - P_a``
    with the interpolant's slope, then secant slopes (:func:`~bendpam.physics.roots.table_newton`),
    polishes it to ``xtol`` relative to the branch's end in ``u``, in about two evaluations of the law.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> from bendpam.physics.law import MomentLaw
    >>> law = MomentLaw(bendpam.physics.presets.be_pam())
    >>> k, u = solve_free(law, law.branches(), np.array([[0.0, 82.0]]))    # active kPa
    >>> k.round(5).tolist()                              # 1/mm
    [[0.0, 0.00816]]
    """
    _law(law)
    instance("tab", tab, BranchTable, "a BranchTable (law.branches())")
    pa = float_array("pa", pa, "kPa")
    k = np.zeros(pa.shape)
    u = np.zeros(pa.shape)
    above = pa > tab.p_end[:, None]
    # below 1e-9 kPa of active pressure the root is straight to rounding (B(0) = 0 is itself only
    # zero to rounding there, which would spoil the first bracket)
    solve = (pa > TINY_ACTIVE_KPA) & ~above & (tab.sgn[:, None] != 0)
    k[above] = np.nan
    u[above] = np.nan
    if not np.any(solve):
        return k, u
    case, col = np.nonzero(solve)
    q = pa[case, col]
    j = np.clip(_bracket_index(tab.pt, pa)[case, col], 1, tab.xt.shape[-1] - 1)
    x0, s0, a, b, ga, gb = _start(tab, case, j, q)
    sgn = tab.sgn[case]
    ev = tab.path
    # the curvature at the last evaluation and its slope: k' at the root by one Taylor step (the root is
    # within xtol of it, so the step's error is of order xtol^2), without another evaluation of the law
    x_last, k_last, dk_last = np.full(q.size, np.nan), np.zeros(q.size), np.zeros(q.size)
    g_last = np.zeros(q.size)

    def G(x, idx):  # P_a(u) - q, increasing along the branch; past A's sign change (unbounded end) beyond the root
        A, B, kx, dk = ev.coef_k(x, case[idx])
        x_last[idx], k_last[idx], dk_last[idx] = x, kx, dk
        with np.errstate(divide="ignore", invalid="ignore"):
            g = np.where(sgn[idx] * A > 0.0, B / A - q[idx], np.inf)
        g_last[idx] = g
        return g

    tol = xtol * np.abs(tab.x_end[case]) + 1e-300
    x = table_newton(G, x0, s0, a, b, ga, gb, tol)
    stuck = np.flatnonzero(np.abs(g_last) > 1e-6 * np.maximum(q, 1.0))
    if stuck.size:  # B and A vanish together near an unbounded end: P_a = B/A never reaches q there
        x[stuck] = _moment_root(ev, case[stuck], sgn[stuck], q[stuck], a[stuck], b[stuck], x[stuck], tol[stuck])
        x_last[stuck] = np.nan
    near = np.isfinite(x_last) & np.isfinite(k_last) & np.isfinite(dk_last) & (np.abs(x - x_last) <= tol)
    kx = np.where(near, k_last + dk_last * (x - x_last), 0.0)
    if not np.all(near):  # a root on a bracket's end (never evaluated), or one found by the bracket's width
        kx[~near] = ev.to_k(x[~near], case[~near])
    k[case, col] = kx
    u[case, col] = x
    return k, u


def _moment_root(ev, case, sgn, q, a, b, x, tol) -> np.ndarray:
    """Roots of ``sgn (B - q A) = 0``, the moment's own sign, on ``[a, b]`` (:func:`~bendpam.physics.roots.illinois`).

    ``P_a = B / A`` is the branch's parametrisation of the root; where ``A`` and ``B`` vanish together (an
    unbounded end whose pole cancels), ``P_a`` jumps without reaching ``q`` and Newton on it stops short,
    while ``B - q A`` (the moment at ``q``, up to a factor) stays continuous and changes sign at the root.
    Points whose ends do not bracket a sign change keep ``x``.
    """
    def F(xx, idx):  # decreasing through the root: illinois's F(a) >= 0 >= F(b)
        A, B = ev.coef(xx, case[idx])
        return sgn[idx] * (q[idx] * A - B)

    every = np.arange(q.size)
    ok = (F(a, every) > 0.0) & (F(b, every) < 0.0)
    if not ok.any():
        return x
    out = x.copy()
    out[ok] = illinois(lambda xx, idx: F(xx, np.flatnonzero(ok)[idx]), a[ok], b[ok], tol[ok])
    return out


def _bracket_index(pt: np.ndarray, pa: np.ndarray) -> np.ndarray:
    """``(cases, pressures)``: per case, the first table index with ``pt >= pa`` (``pt`` rises, then is inf).

    A sorted search per case, all cases at once and without (cases, pressures, samples) arrays: the
    pressures of each case are sorted, a vectorised bisection finds how many lie at or below each
    sample, and a cumulative count turns that into each pressure's index.
    """
    if pt.shape[0] == 1:
        return np.searchsorted(pt[0], pa[0], side="left")[None, :]
    n, m = pa.shape
    order = np.argsort(pa, axis=-1, kind="stable")
    ps = np.take_along_axis(pa, order, -1)
    lo = np.zeros(pt.shape, dtype=np.intp)  # the number of sorted pressures <= each sample, by bisection
    hi = np.full(pt.shape, m, dtype=np.intp)
    for _ in range(max(m, 1).bit_length()):
        mid = (lo + hi) >> 1
        at_or_below = np.take_along_axis(ps, np.minimum(mid, m - 1), -1) <= pt
        step = lo < hi
        lo = np.where(step & at_or_below, mid + 1, lo)
        hi = np.where(step & ~at_or_below, mid, hi)
    # pt[i] < ps[l] exactly when l >= lo[i]: count the samples below each sorted pressure
    rows = np.arange(n)[:, None]
    counts = np.bincount((rows * (m + 1) + lo).ravel(), minlength=n * (m + 1)).reshape(n, m + 1)
    out = np.empty((n, m), dtype=np.intp)
    np.put_along_axis(out, order, np.cumsum(counts, axis=-1)[:, :m], -1)
    return out


def _sample_slopes(xt: np.ndarray, pt: np.ndarray, last: np.ndarray, case: np.ndarray, at: np.ndarray,
                   width: int = 5) -> np.ndarray:
    """``dP_a/du`` at samples ``at`` of cases ``case``: the derivative of the polynomial through ``width`` samples.

    The stencil is centred where it fits and shifted to stay within samples ``0 .. last`` at the
    branch's start and end (fourth order on the graded samples with the default 5); NaN past the
    last sample, or where the branch has fewer samples than the stencil.
    """
    n = xt.shape[-1]
    lc = last[case]
    i0 = np.clip(np.minimum(at - width // 2, lc - (width - 1)), 0, max(n - width, 0))
    x = [xt[case, i0 + d] for d in range(width)]
    p = [pt[case, i0 + d] for d in range(width)]
    xe = xt[case, np.clip(at, 0, n - 1)]
    d = np.zeros(np.shape(at))
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        for i in range(width):  # Lagrange: L_i'(x) = sum over m != i of prod over r != i, m of (x - x_r) / ...
            dl = np.zeros(np.shape(at))
            for m in range(width):
                if m == i:
                    continue
                term = 1.0 / (x[i] - x[m])
                for r in range(width):
                    if r not in (i, m):
                        term = term * (xe - x[r]) / (x[i] - x[r])
                dl += term
            d += p[i] * dl
    return np.where((at <= lc) & (lc >= width - 1), d, np.nan)


def _start(tab: BranchTable, case, j, q):
    """Start, slope and bracket of each root: ``(x0, slope0, a, b, ga, gb)`` with ``g = P_a(u) - q``.

    The bracket is the samples ``j - 1, j`` (past the last sample: the refined fold, or the end of an
    unbounded branch, where ``g = +inf``); the start is the root of the cubic Hermite interpolant of
    ``P_a`` on it (slopes :func:`_sample_slopes`; zero at a refined fold, which is a maximum), found by two
    Newton steps on the cubic; an unbounded end starts at the bracket's midpoint without a slope.
    """
    last = tab.last[case]
    beyond = j > last
    fold_end = (tab.kind[case] == BRANCH_END["fold"]) & tab.use_ref[case] & beyond
    unb = (tab.kind[case] == BRANCH_END["unbounded"]) & beyond
    ja = np.where(fold_end | unb, last, j - 1)
    a, b = tab.xt[case, ja], tab.xt[case, j]
    pa_, pb_ = tab.pt[case, ja], tab.pt[case, j]
    if 2 * case.size > tab.xt.size:  # many pressures a case: every sample's slope once, then look them up
        rows = np.broadcast_to(np.arange(tab.xt.shape[0])[:, None], tab.xt.shape)
        d = _sample_slopes(tab.xt, tab.pt, tab.last, rows, np.broadcast_to(np.arange(tab.xt.shape[1]), tab.xt.shape))
        da, db = d[case, ja], d[case, j]
    else:
        da, db = (_sample_slopes(tab.xt, tab.pt, tab.last, case, i) for i in (ja, j))
    b = np.where(fold_end, tab.x_fold[case], np.where(unb, tab.x_end[case], b))
    pb_ = np.where(fold_end, tab.p_end[case], np.where(unb, np.inf, pb_))
    db = np.where(fold_end, 0.0, db)
    ga, gb = pa_ - q, pb_ - q
    h = b - a
    t = np.clip(np.where(unb, 0.5, ga / np.where(unb, -1.0, ga - gb)), 0.0, 1.0)  # the chord's root
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        for _ in range(2):  # Newton on the cubic Hermite interpolant of g over t in [0, 1] (two: as good as four)
            t2, t3 = t * t, t * t * t
            g = ((2 * t3 - 3 * t2 + 1) * ga + (t3 - 2 * t2 + t) * h * da + (3 * t2 - 2 * t3) * gb
                 + (t3 - t2) * h * db)
            dg = (6 * t2 - 6 * t) * (ga - gb) + (3 * t2 - 4 * t + 1) * h * da + (3 * t2 - 2 * t) * h * db
            tn = t - g / dg
            ok = ~unb & np.isfinite(tn)
            t = np.where(ok, np.clip(tn, 0.0, 1.0), t)
        t2 = t * t
        dg = (6 * t2 - 6 * t) * (ga - gb) + (3 * t2 - 4 * t + 1) * h * da + (3 * t2 - 2 * t) * h * db
        slope0 = np.where(unb, np.nan, dg / h)
    return a + t * h, slope0, a, b, ga, gb


@dataclass(frozen=True)
class FreeBranch:
    """The free-bending branch of an actuator: equilibria ``M(P, k') = 0`` connected to k' = 0.

    Along the bending direction the equilibrium active pressure is ``p(k') = B(k') / A(k')``.  The
    branch is the part where ``p`` rises from 0; it ends at a fold (local maximum of ``p``: the
    moment-curvature curve is N-shaped and the actuator snaps through), at the braid lock-up
    limit, or never (``p`` grows without bound).

    Attributes
    ----------
    direction : +1 (toward the frame), -1 (away), 0 (neutral braid angle).
    k_end_per_mm : curvature where the branch ends.
    p_end_active_kpa : active pressure at the branch end; ``inf`` if unbounded.
    max_pressure_kpa : highest (gauge) pressure with a free-bending equilibrium on the branch.
    kind : ``"fold"``, ``"lock-up"``, ``"unbounded"`` or ``"neutral"``.
    reason : a sentence explaining the end of the branch.
    k_table_per_mm, p_table_kpa : the sampled branch ``(k', P_a)`` from k' = 0 to its end (monotone in P_a).

    Examples
    --------
    >>> import bendpam
    >>> br = bendpam.free_branch(bendpam.physics.presets.bc_pam())
    >>> br.kind, br.direction, round(br.k_end_per_mm, 6), round(br.max_pressure_kpa, 1)
    ('fold', -1, -0.010106, 134.2)
    """

    direction: int
    k_end_per_mm: float
    p_end_active_kpa: float
    max_pressure_kpa: float
    kind: str
    reason: str
    k_table_per_mm: np.ndarray = field(repr=False)
    p_table_kpa: np.ndarray = field(repr=False)


def describe_branch(law: MomentLaw, tab: BranchTable) -> FreeBranch:
    """The :class:`FreeBranch` of one actuator from its sampled branch ``tab`` (one case).

    Examples
    --------
    >>> import bendpam
    >>> from bendpam.physics.law import MomentLaw
    >>> law = MomentLaw(bendpam.physics.presets.be_pam())
    >>> br = describe_branch(law, law.branches())
    >>> br.kind, br.direction
    ('unbounded', 1)
    """
    _law(law)
    instance("tab", tab, BranchTable, "a BranchTable (law.branches())")
    sgn = int(tab.sgn[0])
    kind = _END_NAME[int(tab.kind[0])]
    P0 = float(law.P_start_kpa)
    last = int(tab.last[0])
    kt, pt = tab.kt[0, : last + 1], tab.pt[0, : last + 1]
    k_end, p_end = float(tab.k_end[0]), float(tab.p_end[0])
    lim = law.limits
    if kind == "neutral":
        z = np.zeros(1)
        return FreeBranch(0, 0.0, math.inf, math.inf, kind,
                          "neutral braid angle (54.74 deg): M(P, 0) = 0 at every pressure", z, z)
    if kind == "fold":
        if p_end == 0.0:
            return FreeBranch(sgn, 0.0, 0.0, P0, kind,
                              "the straight state is unstable: M decreases with curvature at P_start "
                              "(negative passive stiffness)", kt[:1], pt[:1])
        if bool(tab.use_ref[0]):
            kt, pt = np.append(kt, k_end), np.append(pt, p_end)
        side = "k' > 0" if sgn > 0 else "k' < 0"
        return FreeBranch(sgn, k_end, p_end, P0 + p_end, kind,
                          f"fold of the moment-curvature curve (N-shaped): the free-bending branch ({side}) ends at "
                          f"k' = {k_end:.5g} 1/mm, P = {P0 + p_end:.4g} kPa; above it the actuator snaps through "
                          "and there is no free-bending equilibrium on this branch", kt, pt)
    if kind == "unbounded":
        return FreeBranch(sgn, k_end, math.inf, math.inf, kind,
                          "pressure moment vanishes before lock-up: every pressure has an equilibrium",
                          np.append(kt, k_end), np.append(pt, math.inf))
    return FreeBranch(sgn, k_end, p_end, P0 + p_end, kind,
                      f"braid lock-up limit k' = {k_end:.5g} 1/mm reached at P = {P0 + p_end:.4g} kPa "
                      f"({lim.reason_max if sgn > 0 else lim.reason_min})", kt, pt)


@dataclass(frozen=True)
class FreeBending:
    """Free-bending equilibria ``M(P, k') = 0`` at given pressures (one actuator).

    Attributes
    ----------
    pressure_kpa : the pressures asked for (input shape).
    curvature_per_mm : k' (1/mm); NaN where no equilibrium exists on the branch.
    angle_deg : theta = k' L0 (deg); NaN likewise.
    status : ``"ok"``, ``"deadband"`` (P <= P_start: straight) or ``"no-equilibrium"``.
    reason : empty for ``"ok"``, else an explanation.
    max_pressure_kpa : highest pressure that still has a free-bending equilibrium (inf if none).
    branch : the :class:`FreeBranch` used.

    Examples
    --------
    >>> import bendpam
    >>> fb = bendpam.free_curvature(bendpam.physics.presets.be_pam(), [50.0, 150.0])
    >>> fb.status.tolist(), fb.curvature_per_mm.round(5).tolist(), fb.angle_deg.round(2).tolist()
    (['deadband', 'ok'], [0.0, 0.00816], [0.0, 67.78])
    >>> bendpam.free_curvature(bendpam.physics.presets.bc_pam(), 150.0).status.item()   # above the BC-PAM's fold
    'no-equilibrium'
    """

    pressure_kpa: np.ndarray
    curvature_per_mm: np.ndarray
    angle_deg: np.ndarray
    status: np.ndarray
    reason: np.ndarray
    max_pressure_kpa: float
    branch: FreeBranch = field(repr=False)

    @property
    def ok(self) -> np.ndarray:
        """True where an equilibrium exists (``status != "no-equilibrium"``)."""
        return self.status != "no-equilibrium"


def assemble_free(law: MomentLaw, P: np.ndarray, k: np.ndarray, br: FreeBranch) -> FreeBending:
    """:class:`FreeBending` at pressures ``P`` (kPa) from the curvatures ``k`` (1/mm) solved on the branch ``br``.

    Examples
    --------
    >>> import numpy as np, bendpam
    >>> from bendpam.physics.law import MomentLaw
    >>> law = MomentLaw(bendpam.physics.presets.be_pam())
    >>> fb = assemble_free(law, np.array([50.0, 150.0]), np.array([0.0, 0.00816]), law.free_branch())
    >>> fb.status.tolist(), fb.angle_deg.round(1).tolist()
    (['deadband', 'ok'], [0.0, 67.7])
    """
    _law(law)
    instance("br", br, FreeBranch, "a FreeBranch (law.free_branch())")
    P, k = float_array("P", P, "kPa"), float_array("k", k, "1/mm")
    P0 = float(law.P_start_kpa)
    flat = P.ravel()
    status = np.full(flat.shape, "ok", dtype=object)
    reason = np.full(flat.shape, "", dtype=object)
    below = flat < P0
    status[below] = "deadband"
    reason[below] = f"below the threshold pressure P_start = {P0:g} kPa: no active moment"
    if br.direction == 0:
        reason[flat > P0] = br.reason
    else:
        none = np.isnan(k.ravel())
        status[none] = "no-equilibrium"
        reason[none] = br.reason
    L0 = float(law.params.L0)
    return FreeBending(pressure_kpa=P, curvature_per_mm=k, angle_deg=np.degrees(k * L0),
                       status=status.reshape(P.shape).astype(str), reason=reason.reshape(P.shape).astype(str),
                       max_pressure_kpa=br.max_pressure_kpa, branch=br)

