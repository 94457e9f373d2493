import numpy as np
import pytest
from numpy.testing import assert_allclose

from bendpam.physics.material import MooneyRivlin


def test_energy_zero_and_stress_free_at_identity():
    m = MooneyRivlin(0.114, 0.300)
    assert m.energy(1.0, 1.0) == pytest.approx(0.0, abs=1e-15)
    assert m.dW_dl1(1.0, 1.0) == pytest.approx(0.0, abs=1e-15)
    assert m.dW_dl2(1.0, 1.0) == pytest.approx(0.0, abs=1e-15)


def test_energy_golden_value_by_hand():
    # l1 = 2, l2 = 1 -> l3 = 1/2: I1 = 4 + 1 + 1/4 = 5.25, I2 = 1/4 + 1 + 4 = 5.25
    m = MooneyRivlin(0.1, 0.2)
    assert m.energy(2.0, 1.0) == pytest.approx(0.1 * 2.25 + 0.2 * 2.25)


def test_partial_derivatives_match_finite_differences():
    m = MooneyRivlin(-0.3189, 0.5155)
    l1 = np.linspace(0.6, 1.8, 7)[:, None]
    l2 = np.linspace(0.7, 1.4, 5)[None, :]
    h = 1e-6
    assert_allclose(m.dW_dl1(l1, l2), (m.energy(l1 + h, l2) - m.energy(l1 - h, l2)) / (2 * h), rtol=1e-7, atol=1e-9)
    assert_allclose(m.dW_dl2(l1, l2), (m.energy(l1, l2 + h) - m.energy(l1, l2 - h)) / (2 * h), rtol=1e-7, atol=1e-9)


def test_uniaxial_stress_is_energy_derivative():
    # uniaxial: l2 = l3 = l^-1/2, nominal stress = dW/dl along that path
    m = MooneyRivlin(0.114, 0.300)
    lam = np.linspace(0.7, 3.0, 9)
    h = 1e-6
    W = lambda x: m.energy(x, x**-0.5)
    assert_allclose(m.uniaxial_nominal_stress(lam), (W(lam + h) - W(lam - h)) / (2 * h), rtol=1e-7)
    # small-strain limit: Young's modulus E = 6 (C10 + C01)
    eps = 1e-5
    assert m.uniaxial_nominal_stress(1 + eps) / eps == pytest.approx(6 * (0.114 + 0.300), rel=1e-4)


def test_cauchy_difference_form():
    m = MooneyRivlin(0.2, 0.1)
    assert m.cauchy_difference(1.2, 1.2) == 0.0
    assert m.cauchy_difference(2.0, 1.0) == pytest.approx(2 * 0.2 * 3 - 2 * 0.1 * (0.25 - 1.0))


@pytest.mark.parametrize("c10,c01", [(0.0, 0.0), (-0.2, 0.1), (float("nan"), 0.1)])
def test_invalid_constants(c10, c01):
    with pytest.raises(ValueError):
        MooneyRivlin(c10, c01)
