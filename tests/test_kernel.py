"""The fast path's kernels (issue 24 item 4): the compiled numba loop is bit-identical to the NumPy one.

The interval of a point is the knot interval that contains it (checked against ``searchsorted``);
both kernels run the same arithmetic on it, so their moments are equal bit for bit: on random
points of every preset and model, on the knots themselves and their neighbours, at the lock-up
limits, at ``k' = 0`` and ``-0``, at pressures of zero, at ``P_start`` and below it, with a scalar or
a per-point pressure, and on a table of 24 001 knots.
"""

import os
import subprocess
import sys
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import bendpam
from bendpam.errors import InputError
from bendpam.physics import kernel as K
from bendpam.physics.kernel import KERNEL_ENV, NUMBA_MIN_POINTS, SplineKernel, kernel_choice
from bendpam.validate import UnitWarning
from strategies import actuators

numba = pytest.importorskip("numba")  # the `test` extra installs it; without it only NumPy's kernel exists

CASES = [("be-pam", "energy"), ("be-pam", "force_balance"), ("bc-pam", "energy"), ("bc-pam", "force_balance")]


def _table(name, model):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the presets' constants were fitted with the other model
        return bendpam.MomentLaw.of(bendpam.physics.presets.get(name, model), model).tabulated()


def _edge_points(kern: SplineKernel, lo: float, hi: float, rng, n: int) -> np.ndarray:
    """Random curvatures on [lo, hi], then every knot, its neighbours, the limits, 0, -0 and the smallest floats."""
    kj = kern.knots_per_mm
    near = np.concatenate([kj, np.nextafter(kj, -np.inf), np.nextafter(kj, np.inf)])
    special = np.array([lo, hi, 0.0, -0.0, 5e-324, -5e-324, np.nextafter(lo, 0.0), np.nextafter(hi, 0.0)])
    k = np.concatenate([rng.uniform(lo, hi, n), near, special])
    return k[(k >= lo) & (k <= hi)]


def _both(kern, P, k, limit=2000.0, lo=None, hi=None):
    lo = float(kern.knots_per_mm[0]) if lo is None else lo
    hi = float(kern.knots_per_mm[-1]) if hi is None else hi
    out_np, out_nb = np.full(k.size, np.nan), np.full(k.size, np.nan)
    assert kern.evaluate(P, k, out_np, limit, lo, hi, "numpy")[0]
    assert kern.evaluate(P, k, out_nb, limit, lo, hi, "numba")[0]
    return out_np, out_nb


@pytest.mark.parametrize(("name", "model"), CASES)
def test_numba_bit_identical_on_presets(name, model):
    table = _table(name, model)
    kern, lim = table.kernel, table.limits
    rng = np.random.default_rng(24)
    k = _edge_points(kern, float(lim.k_min), float(lim.k_max), rng, 20_000)
    P = rng.uniform(0.0, 400.0, k.size)
    P[:500] = 0.0
    P[500:1000] = table.P_start_kpa
    P[1000:1500] = rng.uniform(0.0, table.P_start_kpa, 500)  # below P_start: no active pressure
    a, b = _both(kern, P, k)
    assert np.isfinite(a).all() and np.array_equal(a, b)
    for p in (0.0, table.P_start_kpa, 150.0):  # one pressure for every point
        a, b = _both(kern, np.array([p]), k)
        assert np.array_equal(a, b)
    assert np.any(k < 0) and np.any(k > 0)  # both branches of the table


def test_interval_is_the_knot_interval():
    table = _table("be-pam", "energy")
    kern, lim = table.kernel, table.limits
    k = _edge_points(kern, float(lim.k_min), float(lim.k_max), np.random.default_rng(5), 50_000)
    kj = kern.knots_per_mm
    want = np.clip(np.searchsorted(kj, k, side="right") - 1, 0, kj.size - 2)
    assert np.array_equal(kern.interval(k), want)
    assert kern.interval(np.float64(0.0)).shape == ()


def test_fine_table_stays_identical():
    """A table of 2 x 12001 knots (intervals of 1e-4 rad of the Chebyshev angle): the guesses still land."""
    n1 = 12_000
    t = np.cos(np.linspace(0.0, np.pi, n1 + 1))
    kj = np.concatenate([-0.04 * (1.0 + t), 0.06 * (1.0 - t[1:])])  # k_min = -0.08, k_max = 0.12 (1/mm)
    rng = np.random.default_rng(7)
    kern = SplineKernel(kj, rng.normal(size=(kj.size - 1, 8)), 25.0)
    k = _edge_points(kern, -0.08, 0.12, rng, 20_000)
    a, b = _both(kern, rng.uniform(0.0, 300.0, k.size), k)
    assert np.array_equal(a, b)
    want = np.clip(np.searchsorted(kj, k, side="right") - 1, 0, kj.size - 2)
    assert np.array_equal(kern.interval(k), want)


@pytest.mark.parametrize(("lo", "hi", "n1"), [(-1e-3, 50.0, 64), (-20.0, 1e-4, 300), (-0.5, 0.5, 2)])
def test_unequal_limits_stay_identical(lo, hi, n1):
    """Limits 10^4-10^5 apart: the guess without np.where or clip (1 + min(k m_lo, k m_hi)) lands on the interval."""
    t = np.cos(np.linspace(0.0, np.pi, n1 + 1))
    kj = np.concatenate([0.5 * lo * (1.0 + t), 0.5 * hi * (1.0 - t[1:])])
    rng = np.random.default_rng(n1)
    kern = SplineKernel(kj, rng.normal(size=(kj.size - 1, 8)), 25.0)
    near0 = rng.uniform(0.0, 1e-3, 500) * (lo if -lo < hi else hi)  # near 0 on the short side
    k = np.concatenate([_edge_points(kern, lo, hi, rng, 5000), near0])
    a, b = _both(kern, rng.uniform(0.0, 300.0, k.size), k, lo=lo, hi=hi)
    assert np.array_equal(a, b)
    want = np.clip(np.searchsorted(kj, k, side="right") - 1, 0, kj.size - 2)
    assert np.array_equal(kern.interval(k), want)
    # outside the knots: the first or the last interval (the public method clamps; the kernels never see these)
    assert kern.interval(np.array([2.0 * lo, -np.inf, 2.0 * hi, np.inf])).tolist() == [0, 0, kj.size - 2, kj.size - 2]


def test_a_table_the_guess_cannot_serve_is_refused(monkeypatch):
    monkeypatch.setattr(K, "_GUESS_TOL", 1e-9)  # as if 5 knots were 2 x 10^7: the guess would be too coarse
    with pytest.raises(InputError, match=r"SplineKernel takes at most 2 x 10\^7 knots \(a first guess must land "
                                         r"within a quarter interval\), not 5") as e:
        SplineKernel(np.array([-1.0, -0.5, 0.0, 0.5, 1.0]), np.zeros((4, 8)), 10.0)
    assert "\n" not in str(e.value)


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(actuators(), st.integers(0, 2**32 - 1))
def test_numba_bit_identical_on_drawn_actuators(act, seed):
    table = bendpam.MomentLaw(act, "energy").tabulated()
    lim = table.limits
    rng = np.random.default_rng(seed)
    k = _edge_points(table.kernel, float(lim.k_min), float(lim.k_max), rng, 2000)
    a, b = _both(table.kernel, rng.uniform(0.0, 300.0, k.size), k)
    assert np.array_equal(a, b)


def test_moment_same_with_either_kernel_and_matches_the_hand_formula(monkeypatch):
    table = _table("bc-pam", "energy")
    lim = table.limits
    k = np.linspace(float(lim.k_min), float(lim.k_max), 3001)
    P = np.linspace(0.0, 300.0, 3001)
    monkeypatch.setenv(KERNEL_ENV, "numpy")
    m_np = table.moment(P[:, None], k[::100])  # broadcasting: 3001 x 31
    monkeypatch.setenv(KERNEL_ENV, "numba")
    m_nb = table.moment(P[:, None], k[::100])
    assert m_np.shape == (3001, 31) and np.array_equal(m_np, m_nb)
    A, B = table.coefficients(k[::100])  # M = max(P - P_start, 0) A - B (eq 50)
    np.testing.assert_allclose(m_np, np.maximum(P[:, None] - table.P_start_kpa, 0.0) * A - B, rtol=1e-12,
                               atol=1e-9)


@pytest.mark.parametrize("kernel", ["numpy", "numba"])
def test_moment_refuses_bad_input_in_one_line(monkeypatch, kernel):
    monkeypatch.setenv(KERNEL_ENV, kernel)
    table = _table("be-pam", "energy")
    kmax = float(table.limits.k_max)
    k = np.linspace(0.0, kmax, 10)
    nan_words = r"curvature_per_mm has a non-finite value \S*nan\S* at index 10"
    for P, kk, words in [(100.0, np.append(k, np.nan), nan_words),
                         (100.0, np.append(k, 2 * kmax), "beyond the braid lock-up limit"),
                         (np.array([100.0, -1.0]), 0.0, "pressure_kpa = -1 kPa at index 1 is below zero"),
                         (np.array([100.0, np.inf]), 0.0, r"non-finite value \S*inf\S* at index 1"),
                         (5000.0, k, "above the burst limit 2000 kPa"),
                         (np.ones(3) * 100, np.zeros(4), "do not broadcast")]:
        with pytest.raises(InputError, match=words) as e:
            table.moment(P, kk)
        assert "\n" not in str(e.value)
    with pytest.warns(UnitWarning, match="below 5 kPa"):
        table.moment(0.2, k)
    assert table.moment(100.0, np.empty(0)).shape == (0,)


def test_choice_by_environment(monkeypatch):
    monkeypatch.delenv(KERNEL_ENV, raising=False)
    assert kernel_choice(10) == "numpy"
    assert kernel_choice(NUMBA_MIN_POINTS) == "numba"
    monkeypatch.setenv(KERNEL_ENV, "numpy")
    assert kernel_choice(10**9) == "numpy"
    monkeypatch.setenv(KERNEL_ENV, " NUMBA ")
    assert kernel_choice(1) == "numba"
    monkeypatch.setenv(KERNEL_ENV, "fortran")
    with pytest.raises(InputError, match="BENDPAM_KERNEL = 'fortran' must be one of auto, numpy, numba"):
        kernel_choice(1)


def test_without_numba_auto_falls_back_and_forcing_it_says_why(monkeypatch):
    monkeypatch.setattr(K, "_numba_module", lambda: None)
    K.numba_kernel.cache_clear()
    K._have_numba.cache_clear()
    try:
        monkeypatch.delenv(KERNEL_ENV, raising=False)
        assert kernel_choice(10**9) == "numpy"
        monkeypatch.setenv(KERNEL_ENV, "numba")
        with pytest.raises(InputError, match=r"needs numba \(pip install 'bendpam\[fast\]'\)"):
            kernel_choice(1)
    finally:
        K.numba_kernel.cache_clear()
        K._have_numba.cache_clear()


def test_small_calls_do_not_import_numba(tmp_path):
    code = ("import sys, bendpam, numpy as np\n"
            "t = bendpam.MomentLaw.of(bendpam.physics.presets.be_pam()).tabulated()\n"
            "t.moment(np.linspace(0, 300, 1000), 0.01)\n"
            "print('numba' in sys.modules)\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    env.pop(KERNEL_ENV, None)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=tmp_path,
                       env=env)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "False"
