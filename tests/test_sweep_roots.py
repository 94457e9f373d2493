"""Many-pressure sweeps (issue 24 item 3): free-bending roots by Newton on the branch table, closed-form margins.

* :func:`bendpam.physics.roots.table_newton` on functions whose roots are known, with good and bad starts;
* the roots of :func:`bendpam.physics.branch.solve_free` solve ``M(P, k') = 0`` (residual against the
  exact law), agree with the Illinois polish they replaced, stay on the stable side of a fold, and take
  about two evaluations of the law a point (counted, not timed);
* the per-case bracket search against a brute-force count, ties included (hypothesis);
* the axial-force means of the margins in closed form against Gauss-Legendre quadrature.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

import bendpam
from bendpam import presets
from bendpam.physics import branch as branch_mod
from bendpam.physics.branch import _bracket_index, solve_free
from bendpam.physics.law import MomentLaw
from bendpam.physics.models import force_balance
from bendpam.physics.roots import illinois, table_newton
from bendpam.sweeps import build_cases, evaluate_cases


# ------------------------------------------------------------------------------------------------
# the root finder
# ------------------------------------------------------------------------------------------------
def test_table_newton_cube_roots_from_a_coarse_table():
    """x^3 = q on [1, 3]: a start from the chord (slope of the chord), and a wrong-signed start slope."""
    q = np.linspace(1.5, 26.0, 50)
    a, b = np.ones(q.size), np.full(q.size, 3.0)
    ga, gb = 1.0 - q, 27.0 - q
    x0 = a + (b - a) * ga / (ga - gb)
    calls = []

    def G(x, idx):
        calls.append(idx.size)
        return x**3 - q[idx]

    x = table_newton(G, x0, np.full(q.size, 13.0), a, b, ga, gb, 1e-15)
    assert_allclose(x, np.cbrt(q), rtol=1e-15)
    calls.clear()
    x = table_newton(G, x0, np.full(q.size, -1.0), a, b, ga, gb, 1e-15)  # a bad slope: bisection takes over
    assert_allclose(x, np.cbrt(q), rtol=1e-15)
    # an infinite value at the bracket's end (past a pole) and a root on a bracket's end
    x = table_newton(lambda x, idx: np.where(x < 2.0, x - 1.5, np.inf), np.array([1.9, 1.0]), np.array([np.nan, 1.0]),
                     np.array([1.0, 1.0]), np.array([2.0, 2.0]), np.array([-0.5, 0.0]), np.array([np.inf, 0.5]), 1e-14)
    assert x[0] == pytest.approx(1.5, abs=1e-14) and x[1] == 1.0


def test_table_newton_stops_on_a_root_found_to_rounding():
    """A Newton step that rounds onto the bracket's end just set by the iterate is converged, not restarted.

    ``G(x) = (x - 1) + 1e-20`` started at ``x = 1``: ``G = 1e-20 > 0`` makes 1 the bracket's right end
    and the step ``-1e-20`` rounds back onto it.  Before the fix the midpoint of the bracket replaced
    it and the point took about twenty more evaluations (bisection toward 1 by halves).
    """
    calls = []

    def G(x, idx):
        calls.append(idx.size)
        return (x - 1.0) + 1e-20

    x = table_newton(G, np.array([1.0]), np.array([1.0]), np.array([0.5]), np.array([1.5]),
                     np.array([-0.5]), np.array([0.5]), 1e-14)
    assert x[0] == 1.0 and len(calls) == 1


def test_table_newton_refuses_bad_arguments():
    with pytest.raises(bendpam.errors.InputError):
        table_newton("f", 1.0, 1.0, 0.0, 2.0, -1.0, 1.0, 1e-12)


# ------------------------------------------------------------------------------------------------
# the free-bending roots
# ------------------------------------------------------------------------------------------------
def _counted_solve(law, tab, pa):
    calls = []
    real = branch_mod.table_newton

    def counting(G, *args, **kw):
        def G2(x, idx):
            calls.append(idx.size)
            return G(x, idx)
        return real(G2, *args, **kw)

    branch_mod.table_newton = counting
    try:
        k, u = solve_free(law, tab, pa)
    finally:
        branch_mod.table_newton = real
    return k, u, calls


@pytest.mark.parametrize("name,model", [("be-pam", "energy"), ("bc-pam", "energy"), ("bc-pam", "force_balance")])
def test_free_roots_solve_the_law_in_about_two_evaluations(name, model):
    base = presets.get(name, model)
    t0 = np.linspace(1.6, 2.8, 8)  # 8 cases a braid angle: the shared-table path of a sweep
    cs = build_cases(base, {"alpha0_deg": np.repeat(base.alpha0_deg + np.array([-2.0, 1.0]), 8),
                            "t0_mm": np.tile(t0, 2)})
    law = MomentLaw(cs, model)
    tab = law.branches(150)
    P = np.linspace(20.0, 300.0, 400)
    pa = np.maximum(P[None, :] - np.asarray(law.P_start_kpa)[:, None], 0.0)
    k, u, calls = _counted_solve(law, tab, pa)
    solved = np.isfinite(k) & (k != 0.0)
    assert calls[0] == solved.sum() and sum(calls) <= 3.0 * calls[0]  # about 2.4 a point; Illinois took 7
    # the residual of the law the roots are polished on: P_a(u) = B/A at the root
    case, col = np.nonzero(solved)
    A, B = tab.path.coef(u[case, col], case)
    assert_allclose(B / A, pa[case, col], rtol=1e-11)
    # the same roots as the Illinois iteration they replaced (same brackets, to its tolerance)
    j = np.clip(_bracket_index(tab.pt, pa)[case, col], 1, tab.xt.shape[-1] - 1)
    _, _, a, b, _, _ = branch_mod._start(tab, case, j, pa[case, col])
    q = pa[case, col]

    def F(x, idx):  # the moment's sign along the branch, as the replaced code polished it
        A_, B_ = tab.path.coef(x, case[idx])
        return tab.sgn[case[idx]] * (q[idx] * A_ - B_)

    x_ill = illinois(F, a, b, 1e-15 * np.abs(tab.x_end[case]))
    assert_allclose(u[case, col], x_ill, rtol=1e-11, atol=1e-13 * np.abs(tab.x_end).max())
    # on the branch: never past its end (a fold's unstable side)
    assert np.all(np.abs(k[solved]) <= np.abs(tab.k_end[case]) * (1 + 1e-12))


def test_a_fold_between_samples_keeps_the_stable_root():
    """A refined fold that lies before the sample where P_a first falls ends the branch there (regression:
    that sample stayed on the branch and pressures just below the fold got the unstable root)."""
    base = presets.bc_pam("energy")
    a0 = base.alpha0_deg + np.linspace(-5.0, 5.0, 10)[8]
    t0 = np.linspace(1.5, 3.0, 20)
    P = np.linspace(30.0, 300.0, 1000)[425:433]
    out = evaluate_cases(base, "energy", {"alpha0_deg": np.full(t0.size, a0), "t0_mm": t0}, P)
    k = out["free_curvature_per_mm"]
    for c in (13, 14, 19):  # 13 had the unstable root at 4 of its 5 pressures below the fold
        fb = bendpam.free_curvature(base.replace(alpha0_deg=float(a0), t0_mm=float(t0[c])), P, "energy")
        assert np.array_equal(np.isnan(k[c]), np.isnan(fb.curvature_per_mm))
        ok = np.isfinite(k[c])
        assert_allclose(k[c][ok], fb.curvature_per_mm[ok], rtol=1e-6)  # the table path: means to 1e-7
        assert np.all(np.abs(k[c][ok]) <= abs(fb.branch.k_end_per_mm) * (1 + 1e-9))


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 6), st.integers(1, 30), st.integers(2, 12), st.integers(0, 2**31 - 1))
def test_bracket_index_is_a_per_case_sorted_search(n, m, samples, seed):
    """Against a brute-force count of the samples below each pressure, with ties and infinite tails."""
    rng = np.random.default_rng(seed)
    pt = np.cumsum(rng.integers(0, 3, (n, samples)).astype(float), axis=-1)
    pt[rng.random((n, samples)) < 0.1] = np.inf
    pt = np.sort(pt, axis=-1)
    pa = rng.integers(0, 3 * samples, (n, m)).astype(float)
    expected = (pt[:, None, :] < pa[:, :, None]).sum(-1)
    assert np.array_equal(_bracket_index(pt, pa), expected)


# ------------------------------------------------------------------------------------------------
# the margins' closed forms
# ------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["be-pam", "bc-pam"])
def test_axial_force_means_in_closed_form_equal_the_quadrature(name):
    """Closed form (order 0) against 128-node Gauss-Legendre: 1e-12 of the largest force over the admissible
    range; the 32-node quadrature used before differs by up to 2e-9 near lock-up (its own error)."""
    a = presets.get(name)
    lim = bendpam.curvature_limits(a)
    k = np.linspace(lim.k_min, lim.k_max, 401)
    kin = bendpam.kinematics(a, k)
    closed = force_balance.axial_forces(a.params, 0.15, kin.u, kin.radius)
    for order, tol in ((128, 1e-12), (32, 2e-9)):
        quad = force_balance.axial_forces(a.params, 0.15, kin.u, kin.radius, order=order)
        for key in ("F_br", "F_bl", "N_frame"):
            assert np.max(np.abs(closed[key] - quad[key])) <= tol * np.max(np.abs(quad[key])), (order, key)
    # by hand at k' = 0: mean cot^2 alpha = cot^2 alpha0, mean lambda1^-2 = 1
    cot2, lm2 = force_balance._axial_means(np.zeros(1), np.cos(a.params.alpha0))
    assert cot2[0] == pytest.approx(1.0 / np.tan(a.params.alpha0) ** 2, rel=1e-14) and lm2[0] == 1.0


def test_refined_fold_is_the_maximum_of_the_branch():
    """The fold's grid search: ``P_a`` at the refined fold is the highest on a dense grid around it (to rounding).

    BC-PAM with the energy model folds (docs/paper-reading.md); a dense grid of 4001 points over two
    sample intervals each side of the fold, evaluated exactly, finds nothing higher than ``p_end`` beyond
    rounding, and its best point lies within one grid step of ``x_fold``.
    """
    law = MomentLaw(build_cases(presets.bc_pam(), {"alpha0_deg": np.array([40.0, 45.0, 50.0])}), "energy")
    tab = law.branches(150)
    folds = np.flatnonzero((tab.kind == branch_mod.BRANCH_END["fold"]) & tab.use_ref)
    assert folds.size >= 1
    for c in folds:
        h = np.max(np.abs(np.diff(tab.xt[c, : tab.last[c] + 1])))
        xs = tab.x_fold[c] + np.linspace(-2.0, 2.0, 4001) * h
        A, B = tab.path.coef(xs, np.full(xs.size, c))
        p = B / A
        assert tab.p_end[c] >= np.nanmax(p) * (1.0 - 1e-13)
        assert abs(xs[np.nanargmax(p)] - tab.x_fold[c]) <= 4.0 * h / 4000


def test_lock_up_search_finds_the_sign_change_to_adjacent_floats():
    """The lock-up limits' sign-change search (15 interior points a pass, 16 passes): ``sqrt(q)`` as the
    sign change of ``q - u^2`` to the last bits, as the 64 halvings it replaced."""
    from bendpam.physics.braid import _bisect

    q = np.linspace(0.1, 3.0, 7)
    u = _bisect(lambda m: q[:, None] - m * m, np.zeros(q.size), np.full(q.size, 2.0))
    assert_allclose(u, np.sqrt(q), rtol=4e-16)
