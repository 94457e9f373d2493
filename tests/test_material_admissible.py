"""Admissible Mooney-Rivlin materials: shear modulus, shape and admissible shapes.

The conditions are checked here independently of the closed forms in bendpam.physics.material:
on a dense grid of deformations, with the class's own energy, uniaxial stress and Cauchy
stress differences.
"""

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from bendpam.errors import InputError
from bendpam.physics.material import MooneyRivlin, admissible_shape_range, shape_limits

# the bladder's principal stretches in bending: a generous envelope.  At the paper's
# test pressures (BE-PAM 100-200 kPa, BC-PAM 40-120 kPa) the free-bending states reach
# axial stretches 0.86-1.27 and hoop stretches 0.98-1.11 with the Table 3 constants.
BLADDER = (0.6, 1.6)
TEST_PRESSURES = (0.85, 1.27)

# Table 3 of the paper, kPa
PAPER = {
    "BE-PAM energy": (-318.9, 515.5),
    "BE-PAM force balance": (-133.7, 373.3),
    "BC-PAM energy": (1485.3, -1196.8),
    "BC-PAM force balance": (1499.9, -1169.9),
}


# ------------------------------------------------------------------------------------
# an independent checker on a dense grid
# ------------------------------------------------------------------------------------
def _line(a, b, n):
    extra = [1.0, a, b, a * (1 + 1e-4), b * (1 - 1e-4)]
    return np.unique(
        np.concatenate([np.linspace(a, b, n), np.geomspace(a, b, n), extra])
    )


def violations(m: MooneyRivlin, stretch_min: float, stretch_max: float) -> list[str]:
    """The conditions ``m`` fails on a dense grid of the (widened) range: [] if none."""
    a, b = min(stretch_min, 1.0), max(stretch_max, 1.0)
    tol = 1e-9 * m.shear_modulus
    line = _line(a, b, 121)
    l1, l2 = (x.ravel() for x in np.meshgrid(line, line))
    path = _line(a, b, 801)
    # states: the biaxial square and the uniaxial path
    s1 = np.concatenate([l1, path])
    s2 = np.concatenate([l2, path**-0.5])
    s3 = 1.0 / (s1 * s2)
    out = []
    if float(np.min(m.energy(s1, s2))) < -tol:
        out.append("energy")
    lam = np.unique(
        np.concatenate([np.linspace(a, 1.0, 2001), np.linspace(1.0, b, 2001)])
    )
    if float(np.min(np.diff(m.uniaxial_nominal_stress(lam)))) < -tol * 1e-3:
        out.append("uniaxial")
    for li, lj in ((s1, s2), (s1, s3), (s2, s3)):
        d = li - lj
        ok = np.abs(d) > 1e-9
        if np.any(m.cauchy_difference(li[ok], lj[ok]) / d[ok] < -tol):
            out.append("baker_ericksen")
            break
    return out


# ------------------------------------------------------------------------------------
# shear modulus and shape
# ------------------------------------------------------------------------------------
def test_from_shear_modulus_golden_by_hand():
    # mu = 0.6 MPa, beta = 0.25: C10 = 0.6 * 0.75 / 2 = 0.225, C01 = 0.6 * 0.25 / 2
    # = 0.075
    m = MooneyRivlin.from_shear_modulus(0.6, 0.25)
    assert m.C10 == pytest.approx(0.225, rel=1e-15)
    assert m.C01 == pytest.approx(0.075, rel=1e-15)
    assert m.shear_modulus == pytest.approx(0.6, rel=1e-15)
    assert m.shape == pytest.approx(0.25, rel=1e-15)
    # neo-Hookean and "pure C01"
    assert MooneyRivlin.from_shear_modulus(0.8, 0.0) == MooneyRivlin(0.4, 0.0)
    assert MooneyRivlin.from_shear_modulus(0.8, 1.0) == MooneyRivlin(0.0, 0.4)
    # a negative shape: beta = -0.5 -> C10 = 0.3 * 1.5 = 0.45, C01 = -0.15
    m = MooneyRivlin.from_shear_modulus(0.6, -0.5)
    assert (m.C10, m.C01) == (pytest.approx(0.45), pytest.approx(-0.15))
    # the other way: C10 = 114, C01 = 300 kPa -> mu = 828 kPa, beta = 300/414
    m = MooneyRivlin(0.114, 0.300)
    assert m.shear_modulus == pytest.approx(0.828)
    assert m.shape == pytest.approx(300 / 414)
    back = MooneyRivlin.from_shear_modulus(m.shear_modulus, m.shape)
    assert (back.C10, back.C01) == (pytest.approx(0.114), pytest.approx(0.300))


@pytest.mark.parametrize(
    "mu, shape",
    [
        (0.0, 0.5),
        (-1.0, 0.5),
        (math.nan, 0.5),
        (1.0, math.inf),
        ("1", 0.5),
        (True, 0.5),
    ],
)
def test_from_shear_modulus_rejects(mu, shape):
    with pytest.raises(InputError) as err:
        MooneyRivlin.from_shear_modulus(mu, shape)
    assert "\n" not in str(err.value)
    assert ("mu" in str(err.value)) or ("shape" in str(err.value))


def test_constructor_errors_are_input_errors_and_value_errors():
    with pytest.raises(InputError, match="initial shear modulus"):
        MooneyRivlin(-0.2, 0.1)
    with pytest.raises(ValueError):
        MooneyRivlin(math.nan, 0.1)


# ------------------------------------------------------------------------------------
# the admissible range: cases by hand
# ------------------------------------------------------------------------------------
def test_uniaxial_monotonicity_bound_by_hand():
    # dP/dl = mu [(1 - beta)(1 + 2 l^-3) + 3 beta l^-4] = 0 at l = 2:
    # beta = (1 + 2/8) / (1 + 2/8 - 3/16) = 1.25 / 1.0625 = 20/17
    uni = shape_limits(1.0, 2.0)[1]
    assert uni.condition == "uniaxial"
    assert uni.upper == pytest.approx(20 / 17, rel=1e-14)
    assert uni.lower == -math.inf  # no compression in [1, 2]
    # that material's uniaxial stress is flat at l = 2 (finite difference), rising below
    m = MooneyRivlin.from_shear_modulus(1.0, 20 / 17)
    h = 1e-6
    slope = (m.uniaxial_nominal_stress(2 + h) - m.uniaxial_nominal_stress(2 - h)) / (
        2 * h
    )
    assert slope == pytest.approx(0.0, abs=1e-8)
    assert (m.uniaxial_nominal_stress(1.9) - m.uniaxial_nominal_stress(1.8)) > 0
    # compression, l = 1/2: beta = (1 + 16) / (1 + 16 - 48) = -17/31
    assert shape_limits(0.5, 1.0)[1].lower == pytest.approx(-17 / 31, rel=1e-14)


def test_baker_ericksen_bounds_by_hand():
    # on [1, 2]: s = 1/(l_i l_j)^2 spans [2^-4, 2^2]; 1 + beta (s - 1) > 0 gives
    # beta > -1/(4 - 1) = -1/3 and beta < 1/(1 - 1/16) = 16/15 (tighter than 20/17)
    be = shape_limits(1.0, 2.0)[2]
    assert (be.lower, be.upper) == (pytest.approx(-1 / 3), pytest.approx(16 / 15))
    assert admissible_shape_range(1.0, 2.0) == (
        pytest.approx(-1 / 3),
        pytest.approx(16 / 15),
    )
    # where: beta = -1/3 - 0.01 fails sigma_2 - sigma_3 in planar extension (2, 1, 1/2)
    m = MooneyRivlin.from_shear_modulus(1.0, -1 / 3 - 0.01)
    assert (
        m.cauchy_difference(1.0, 0.5) < 0
    )  # lambda_2 > lambda_3 but sigma_2 < sigma_3
    with pytest.raises(InputError, match=r"Baker-Ericksen .* \(2, 1, 0\.5\)"):
        m.check_admissible(1.0, 2.0)
    # the bladder envelope: s_max = 0.6^-4 (equibiaxial compression), s_min = 1.6^-4
    lo, hi = admissible_shape_range(*BLADDER)
    assert lo == pytest.approx(-1 / (0.6**-4 - 1), rel=1e-14)
    assert hi == pytest.approx(1 / (1 - 1.6**-4), rel=1e-14)
    assert (round(lo, 4), round(hi, 4)) == (-0.1489, 1.1801)


def test_range_is_widened_to_contain_one_and_validated():
    assert admissible_shape_range(1.2, 1.6) == admissible_shape_range(1.0, 1.6)
    assert admissible_shape_range(0.7, 0.9) == admissible_shape_range(0.7, 1.0)
    assert admissible_shape_range(1.0, 1.0) == (-math.inf, math.inf)
    for args in [
        (0.0, 1.5),
        (-1, 1.5),
        (math.nan, 1.5),
        (1.6, 0.6),
        (0.6, math.inf),
        ("a", 2),
    ]:
        with pytest.raises(InputError) as err:
            admissible_shape_range(*args)
        assert "\n" not in str(err.value) and "stretch" in str(err.value)


def test_energy_interval_contains_the_baker_ericksen_interval():
    # Baker-Ericksen on a range containing 1 implies W >= 0 (module notes), so the grid
    # based energy interval never binds
    for a, b in [
        (0.6, 1.6),
        (0.85, 1.27),
        (0.3, 3.0),
        (1.0, 7.6),
        (0.95, 1.0),
        (0.5, 1.05),
    ]:
        energy, _, be = shape_limits(a, b)
        assert energy.lower <= be.lower and energy.upper >= be.upper
        assert not energy.exact and be.exact


# ------------------------------------------------------------------------------------
# the admissible range: properties
# ------------------------------------------------------------------------------------
ranges = st.tuples(st.floats(0.3, 1.3), st.floats(0.7, 4.0)).filter(
    lambda r: r[1] - r[0] >= 0.05
)


@settings(max_examples=60, deadline=None)
@given(r=ranges, mu=st.floats(1e-3, 10.0), t=st.floats(0.0, 1.0))
def test_every_shape_inside_passes_on_a_dense_grid(r, mu, t):
    a, b = r
    lo, hi = admissible_shape_range(a, b)
    assume(math.isfinite(lo) and math.isfinite(hi))
    assert lo <= 0.0 and hi >= 1.0  # [0, 1] is always admissible
    m = MooneyRivlin.from_shear_modulus(mu, lo + t * (hi - lo))
    assert m.is_admissible(a, b)
    m.check_admissible(a, b)
    assert violations(m, a, b) == []


@settings(max_examples=60, deadline=None)
@given(r=ranges, mu=st.floats(1e-3, 10.0), upper=st.booleans())
def test_a_shape_just_outside_fails_somewhere(r, mu, upper):
    a, b = r
    lo, hi = admissible_shape_range(a, b)
    assume(math.isfinite(lo) and math.isfinite(hi))
    step = 0.01 * max(1.0, abs(hi if upper else lo))
    beta = hi + step if upper else lo - step
    m = MooneyRivlin.from_shear_modulus(mu, beta)
    assert not m.is_admissible(a, b)
    assert violations(m, a, b) != []
    with pytest.raises(InputError) as err:
        m.check_admissible(a, b)
    msg = str(err.value)
    assert "\n" not in msg and "stretch" in msg and "admissible shapes" in msg


@settings(max_examples=40, deadline=None)
@given(r=ranges, mu=st.floats(1e-3, 10.0), beta=st.floats(-3.0, 4.0))
def test_is_admissible_agrees_with_the_dense_grid(r, mu, beta):
    a, b = r
    lo, hi = admissible_shape_range(a, b)
    # away from the ends (the grid cannot resolve a shape within a hair of a bound)
    assume(min(abs(beta - lo), abs(beta - hi)) > 0.02 * max(1.0, abs(beta)))
    m = MooneyRivlin.from_shear_modulus(mu, beta)
    assert m.is_admissible(a, b) == (violations(m, a, b) == [])


# ------------------------------------------------------------------------------------
# the paper's Table 3 constants
# ------------------------------------------------------------------------------------
def test_paper_table3_constants_are_not_admissible_on_the_bladder_range():
    verdict = {}
    for name, (c10, c01) in PAPER.items():
        m = MooneyRivlin(c10 / 1e3, c01 / 1e3)
        with pytest.raises(InputError) as err:
            m.check_admissible(*BLADDER)
        verdict[name] = (round(m.shape, 3), str(err.value))
        assert violations(m, *BLADDER) != []
    # which condition fails first, and where
    assert verdict["BE-PAM energy"][0] == 2.622
    assert "negative strain energy" in verdict["BE-PAM energy"][1]
    assert "(0.6, 0.6, 2.778)" in verdict["BE-PAM energy"][1]  # equibiaxial compression
    assert verdict["BE-PAM force balance"][0] == 1.558
    assert "not monotone in uniaxial tension" in verdict["BE-PAM force balance"][1]
    assert "peaks at stretch 1.52" in verdict["BE-PAM force balance"][1]
    for name in ("BC-PAM energy", "BC-PAM force balance"):
        assert verdict[name][0] < -3.5
        assert "negative strain energy" in verdict[name][1]
        assert "(1.6, 1.6, 0.3906)" in verdict[name][1]  # equibiaxial extension


def test_paper_table3_constants_at_the_test_pressures():
    # on the narrower range the tests reach, only the BE-PAM force-balance pair passes
    ok = {
        name: MooneyRivlin(c10 / 1e3, c01 / 1e3).is_admissible(*TEST_PRESSURES)
        for name, (c10, c01) in PAPER.items()
    }
    assert ok == {
        "BE-PAM energy": False,
        "BE-PAM force balance": True,
        "BC-PAM energy": False,
        "BC-PAM force balance": False,
    }
    # BE-PAM (energy): its uniaxial stress already peaks inside that range
    with pytest.raises(InputError, match=r"peaks at stretch 1\.24"):
        MooneyRivlin(-0.3189, 0.5155).check_admissible(*TEST_PRESSURES)
