import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from scipy.optimize import brentq

from bendpam.physics.fixture import PAPER_FIXTURE, Fixture


def test_golden_values_by_hand():
    f = PAPER_FIXTURE
    # beta = 0.5 rad: ds = 35 tan(0.5) + (sec(0.5) - 1) * (4 + 2*2.5) = 19.120587 + 1.255445
    assert f.beta_to_stroke(0.5) == pytest.approx(20.376032490453607, rel=1e-14)
    assert f.stroke_to_beta(20.376032490453607) == pytest.approx(0.5, rel=1e-13)
    # eq 7: M = 10 N * (35 + 9 sin 0.5) / (2 cos^2 0.5)
    assert f.force_to_moment(10.0, 0.5) == pytest.approx(255.24099845633447, rel=1e-14)
    # eq 8: k' = 2 beta / L0
    assert f.beta_to_curvature(0.5) == pytest.approx(1.0 / 145.0)
    # at the blocked state the lever is d / 2
    assert f.lever(0.0) == pytest.approx(17.5)
    assert f.stroke_to_beta(0.0) == 0.0


def test_stroke_to_beta_is_the_bracketed_root_of_eq6():
    for f in (PAPER_FIXTURE, Fixture(20.0, 3.0, 6.0, 100.0), Fixture(10.0, 0.0, 0.0, 145.0), Fixture(5.0, 4.0, 2.0)):
        s = np.array([1e-6, 0.3, 3.0, 20.0, 60.0, 150.0])
        ref = [brentq(lambda b, f=f, x=x: f.d_mm * math.tan(b) + (1 / math.cos(b) - 1) * f.c - x,
                      0.0, math.pi / 2 - 1e-12, xtol=1e-15) for x in s]
        assert_allclose(f.stroke_to_beta(s), ref, rtol=1e-12, atol=1e-15)


@settings(max_examples=200, deadline=None)
@given(d=st.floats(1.0, 100.0), r=st.floats(0.0, 10.0), t=st.floats(0.0, 10.0), beta=st.floats(-1.5, 1.5))
def test_round_trips(d, r, t, beta):
    f = Fixture(d, r, t, 145.0)
    s = f.beta_to_stroke(beta)
    assert f.stroke_to_beta(s) == pytest.approx(beta, rel=1e-10, abs=1e-12)
    k = f.beta_to_curvature(beta)
    assert f.curvature_to_stroke(k) == pytest.approx(s, rel=1e-10, abs=1e-10)
    assert f.moment_to_force(f.force_to_moment(3.7, beta), beta) == pytest.approx(3.7)


def test_monotone_and_vectorised():
    s = np.linspace(0, 100, 10001)
    b = PAPER_FIXTURE.stroke_to_beta(s)
    assert np.all(np.diff(b) > 0) and b[-1] < math.pi / 2


def test_convert_with_tare():
    beta, k, M = PAPER_FIXTURE.convert([0.0, 20.376032490453607], [10.5, 10.5], tare_n=0.5)
    assert_allclose(beta, [0.0, 0.5], atol=1e-13)
    assert_allclose(M, [175.0, 255.24099845633447], rtol=1e-12)


@pytest.mark.parametrize("text", ["35,2.5", "a,b,c", "35;2.5;4;1", ""])
def test_bad_fixture_string(text):
    with pytest.raises(ValueError, match="d,r,t"):
        Fixture.from_string(text)


@pytest.mark.parametrize("kw", [dict(d_mm=0.0), dict(r_mm=-1.0), dict(L0_mm=float("nan")), dict(t_mm="x")])
def test_bad_fixture_values(kw):
    with pytest.raises(ValueError, match="fixture"):
        Fixture(**kw)


def test_fixture_string_ok():
    f = Fixture.from_string("40, 3, 5", L0_mm=130)
    assert (f.d_mm, f.r_mm, f.t_mm, f.L0_mm) == (40.0, 3.0, 5.0, 130.0)
