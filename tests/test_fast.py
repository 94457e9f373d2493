"""The fast table path against the exact path (issue 5), over a hypothesis-drawn domain."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

import bendpam
from bendpam import MomentLaw, presets
from bendpam.physics.fast import MomentTable, moment_table
from strategies import actuators as actuator_strategy

TOL = 1e-6


def check_against_exact(table, P, k, order=128):
    """|M_fast - M_ref| <= TOL (|P_a A| + |B|) against a 256-node reference (order 128 on [0, pi]).

    ``P`` in kPa (so ``A`` is per kPa).  The scale is floored at 0.1 % of its median: the elastic
    term B crosses zero away from k' = 0 in the force-balance model, where no relative error is
    meaningful.
    """
    law = table.law
    ref_law = MomentLaw(law.actuator, law.model, eq19_factor=law.eq19_factor, order=order)
    A, B = ref_law.coefficients(k)
    pa = np.maximum(P - law.actuator.P_start_kpa, 0.0)
    ref = pa * A - B
    got = table.moment(P, k)
    terms = np.abs(pa * A) + np.abs(B)
    scale = np.maximum(terms, 1e-3 * np.median(terms))  # B and M cross zero: floor the scale
    err = np.abs(got - ref) / scale
    assert err.max() <= TOL, err.max()
    return err.max()


@pytest.mark.parametrize("name", ["be-pam", "bc-pam"])
@pytest.mark.parametrize("model", ["energy", "force_balance"])
def test_presets_full_range(name, model):
    a = presets.get(name, model)
    t = moment_table(a, model)
    assert t.max_rel_error <= TOL
    lim = bendpam.curvature_limits(a)
    rng = np.random.default_rng(1)
    k = np.concatenate([rng.uniform(lim.k_min, lim.k_max, 20000), [lim.k_min, 0.0, lim.k_max]])
    P = rng.uniform(0.0, 500.0, k.size)  # kPa
    check_against_exact(t, P, k)
    # agrees with the public exact path as well
    assert_allclose(t.moment(150.0, k[:50]), bendpam.moment(a, 150.0, k[:50], model), rtol=1e-6, atol=1e-6)


actuators = actuator_strategy(E=(500.0, 20000.0))


@settings(max_examples=25, deadline=None)
@given(a=actuators, model=st.sampled_from(["energy", "force_balance"]), seed=st.integers(0, 2**31 - 1))
def test_fast_equals_exact_over_the_domain(a, model, seed):
    t = MomentTable(MomentLaw(a, model))
    assert t.max_rel_error <= TOL
    lim = bendpam.curvature_limits(a)
    rng = np.random.default_rng(seed)
    k = rng.uniform(lim.k_min, lim.k_max, 400)
    P = rng.uniform(0.0, 500.0, k.size)  # kPa
    check_against_exact(t, P, k)


@settings(max_examples=15, deadline=None)
@given(a=actuators, model=st.sampled_from(["energy", "force_balance"]))
def test_fast_free_curvature_and_stiffness(a, model):
    t = MomentLaw(a, model).tabulated()
    P = np.linspace(0.0, 400.0, 41)  # kPa
    fast = t.free_curvature(P)
    exact = bendpam.free_curvature(a, P, model)
    assert np.array_equal(fast.status, exact.status)
    ok = exact.status == "ok"
    assert_allclose(fast.curvature_per_mm[ok], exact.curvature_per_mm[ok], rtol=1e-6, atol=1e-9)
    assert np.all(np.isnan(fast.curvature_per_mm[~ok & (exact.status == "no-equilibrium")]))
    k = 0.5 * np.nan_to_num(exact.curvature_per_mm[ok])
    if k.size:
        assert_allclose(t.tangent_stiffness(P[ok], k), bendpam.tangent_stiffness(a, P[ok], k, model),
                        rtol=1e-4, atol=1e-3 * np.abs(bendpam.tangent_stiffness(a, P[ok], k, model)).max())


def test_fast_validates_like_the_exact_path():
    t = moment_table(presets.be_pam())
    with pytest.raises(ValueError, match="below zero"):
        t.moment(-100.0, 0.0)
    with pytest.raises(ValueError, match="lock-up"):
        t.moment(100.0, 1.0)
    with pytest.raises(TypeError):
        MomentTable("be-pam")
    with pytest.raises(TypeError):
        MomentTable(presets.be_pam())  # the table tabulates a MomentLaw, not an actuator
    with pytest.warns(bendpam.UnitWarning):
        t.moment(0.1, 0.0)  # 0.1 is a pressure in MPa
    assert moment_table(presets.be_pam()) is t  # cached
    assert t is MomentLaw.of(presets.be_pam(), "energy").tabulated()  # the law's own table
