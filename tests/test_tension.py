"""Tension-test fit with admissible constants (bendpam.identify.tension): synthetic, Treloar."""

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from bendpam.errors import FitError, InputError, ProcessingError
from bendpam.identify.tension import TensionFit, fit_tension, tension_from_test
from bendpam.lab import RawTest
from bendpam.physics.material import MooneyRivlin, admissible_shape_range

TRELOAR = Path(__file__).parent / "data" / "treloar_1944_uniaxial.csv"

FIELDS = {
    "C10_kpa",
    "C01_kpa",
    "shear_modulus_kpa",
    "shape",
    "shape_bounds",
    "shape_at_bound",
    "se_C10_kpa",
    "se_C01_kpa",
    "se_shear_modulus_kpa",
    "correlation",
    "rmse_kpa",
    "nrmse",
    "n_points",
    "stretch_min",
    "stretch_max",
    "source",
    "identifiable",
}


def treloar():
    d = pd.read_csv(TRELOAR, comment="#")
    return d["stretch"].to_numpy(), d["nominal_stress_mpa"].to_numpy() * 1e3  # kPa


def stress_kpa(c10_kpa, c01_kpa, lam):
    return MooneyRivlin(c10_kpa / 1e3, c01_kpa / 1e3).uniaxial_nominal_stress(lam) * 1e3


def raw_test(ext_mm, force_n, name="tension.csv"):
    t = np.arange(len(ext_mm)) * 0.1
    data = pd.DataFrame({"time_s": t, "stroke_mm": ext_mm, "force_n": force_n})
    return RawTest(data=data, path=Path(name), dialect="csv")


# ------------------------------------------------------------------------------------
# synthetic data
# ------------------------------------------------------------------------------------
def test_exact_data_give_the_constants_back():
    lam = np.linspace(1.0, 2.5, 60)
    fit = fit_tension(lam, stress_kpa(114.0, 300.0, lam), source="golden")
    assert isinstance(fit, TensionFit)
    assert fit.C10_kpa == pytest.approx(114.0, rel=1e-9)
    assert fit.C01_kpa == pytest.approx(300.0, rel=1e-9)
    assert fit.shear_modulus_kpa == pytest.approx(828.0, rel=1e-9)
    assert fit.shape == pytest.approx(300 / 414, rel=1e-9)
    assert not fit.shape_at_bound
    assert fit.rmse_kpa == pytest.approx(0.0, abs=1e-9)
    # the bounds hold over the data's stretches and the bladder's: [0.6, 2.5]
    assert fit.bounds_stretch_range == (0.6, 2.5)
    assert fit.shape_bounds == pytest.approx(admissible_shape_range(0.6, 2.5))
    assert fit.n_points == 60 and fit.source == "golden"
    m = fit.material()
    assert (m.C10, m.C01) == (pytest.approx(0.114), pytest.approx(0.300))
    lam2 = np.array([0.8, 1.3, 1.9])
    assert fit.predict(lam2) == pytest.approx(stress_kpa(114.0, 300.0, lam2), rel=1e-9)


def test_noisy_data_recover_the_constants_within_their_errors():
    rng = np.random.default_rng(7)
    truth = MooneyRivlin.from_shear_modulus(0.5, 0.4)  # C10 = 150, C01 = 100 kPa
    lam = np.linspace(1.0, 2.2, 80)
    p = truth.uniaxial_nominal_stress(lam) * 1e3 + rng.normal(0.0, 2.0, lam.size)
    fit = fit_tension(lam, p)
    assert not fit.shape_at_bound
    assert abs(fit.C10_kpa - 150.0) < 4 * fit.se_C10_kpa
    assert abs(fit.C01_kpa - 100.0) < 4 * fit.se_C01_kpa
    assert fit.shear_modulus_kpa == pytest.approx(500.0, rel=0.02)
    assert abs(fit.shear_modulus_kpa - 500.0) < 4 * fit.se_shear_modulus_kpa
    assert fit.rmse_kpa == pytest.approx(2.0, rel=0.25)
    assert -1.0 < fit.correlation < -0.9  # C10 and C01 trade off against each other
    # the standard error of mu is much smaller than those of C10 and C01 suggest
    assert fit.se_shear_modulus_kpa < 2 * math.hypot(fit.se_C10_kpa, fit.se_C01_kpa)


def test_a_shape_outside_the_bounds_is_held_at_the_bound_and_is_optimal():
    # beta = 1.5 is fine on [1, 1.3] but not on the bladder's [0.6, 1.6]
    truth = MooneyRivlin.from_shear_modulus(0.4, 1.5)
    lam = np.linspace(1.0, 1.3, 40)
    p = truth.uniaxial_nominal_stress(lam) * 1e3
    lo, hi = admissible_shape_range(0.6, 1.6)
    fit = fit_tension(lam, p)
    assert fit.shape_at_bound and fit.shape == pytest.approx(hi, rel=1e-12)
    assert fit.material().is_admissible(0.6, 1.6)
    assert "sits at the bound" in fit.identifiable
    # the constrained optimum beats every admissible (mu, beta) on a fine scan
    g = lam - lam**-2
    best = math.inf
    for beta in np.linspace(lo, hi, 4001):
        h = g + beta * g * (1 / lam - 1)
        mu = max(0.0, float(h @ p) / float(h @ h))
        best = min(best, float(np.sum((p - mu * h) ** 2)))
    rss = fit.rmse_kpa**2 * fit.n_points
    assert rss <= best * (1 + 1e-12)
    # without the bladder's range, [1, 1.3] alone allows it: the fit is exact
    free = fit_tension(lam, p, admissible_range=None)
    assert not free.shape_at_bound and free.shape == pytest.approx(1.5, rel=1e-9)


def test_shape_identifiability_in_words():
    rng = np.random.default_rng(3)
    truth = MooneyRivlin(0.15, 0.10)
    wide = np.linspace(1.0, 2.5, 60)
    narrow = np.linspace(1.0, 1.08, 30)
    fw = fit_tension(
        wide, truth.uniaxial_nominal_stress(wide) * 1e3 + rng.normal(0, 2.0, wide.size)
    )
    fn = fit_tension(
        narrow,
        truth.uniaxial_nominal_stress(narrow) * 1e3 + rng.normal(0, 2.0, narrow.size),
    )
    assert "is determined by the data; so is the shape" in fw.identifiable
    assert "the shape is not" in fn.identifiable
    assert "only C10 + C01 = mu/2 is reliable" in fn.identifiable
    for f in (fw, fn):
        assert f.identifiable.endswith(".") and "\n" not in f.identifiable


def test_to_dict_is_strict_json_with_every_field():
    lam = np.linspace(1.0, 2.0, 11)
    fit = fit_tension(lam, stress_kpa(200.0, 100.0, lam), source="x.csv")
    d = fit.to_dict()
    assert FIELDS <= set(d)
    back = json.loads(json.dumps(d, allow_nan=False))
    assert back["C10_kpa"] == pytest.approx(200.0) and back["source"] == "x.csv"
    assert isinstance(back["shape_bounds"], list) and isinstance(
        back["shape_at_bound"], bool
    )


# ------------------------------------------------------------------------------------
# Treloar (1944)
# ------------------------------------------------------------------------------------
def test_treloar_up_to_stretch_2():
    lam, p = treloar()
    assert lam.size == 24 and p.max() == pytest.approx(6317.64)
    fit = fit_tension(lam, p, stretch_range=(1.0, 2.0), source="Treloar 1944")
    assert fit.n_points == 6 and fit.stretch_max == pytest.approx(1.9)
    lo, hi = fit.shape_bounds
    assert (lo, hi) == pytest.approx(admissible_shape_range(0.6, 1.9))
    assert fit.C10_kpa > 0.0
    assert (
        lo * fit.shear_modulus_kpa / 2 <= fit.C01_kpa <= hi * fit.shear_modulus_kpa / 2
    )
    assert not fit.shape_at_bound
    assert fit.C10_kpa == pytest.approx(82.78, abs=0.01)
    assert fit.C01_kpa == pytest.approx(137.27, abs=0.01)
    # the stress within 5 %: largest relative error on the six points used (2.1 %)
    used = (lam >= 1.0) & (lam <= 2.0)
    rel = np.abs(fit.predict(lam[used]) - p[used]) / p[used]
    assert rel.max() < 0.05
    assert float(np.sqrt(np.mean(rel**2))) < 0.02
    assert "so is the shape" in fit.identifiable


def test_treloar_full_range_unconstrained_is_unphysical_constrained_is_held():
    lam, p = treloar()
    # plain least squares (what the old fit did): a negative shear modulus and C01
    g = 2 * (lam - lam**-2)
    c10, c01 = np.linalg.lstsq(np.column_stack([g, g / lam]), p, rcond=None)[0]
    assert c01 < 0 and c10 + c01 < 0  # about 409 and -751 kPa: mu = -685 kPa
    with pytest.raises(InputError):
        MooneyRivlin(c10 / 1e3, c01 / 1e3)
    fit = fit_tension(lam, p, source="Treloar 1944")
    assert fit.shape_at_bound
    assert fit.bounds_stretch_range == (0.6, 7.6)
    assert fit.shape == pytest.approx(fit.shape_bounds[0], rel=1e-12)  # the lower bound
    assert fit.shear_modulus_kpa > 0 and fit.C10_kpa > 0
    assert fit.material().is_admissible(0.6, 7.6)
    assert "mu = -684.5 kPa <= 0" in fit.identifiable


# ------------------------------------------------------------------------------------
# raw tests
# ------------------------------------------------------------------------------------
def test_tension_from_test_uses_the_loading_branch_only():
    lam = np.linspace(1.0, 2.2, 50)
    load = stress_kpa(150.0, 100.0, lam) / 1e3 * 2.0  # N on a 2 mm^2 strip
    # loading, then an unloading branch 20 % below it (hysteresis), on a 25 mm gauge
    ext = np.concatenate([(lam - 1) * 25.0, (lam[::-1] - 1) * 25.0]) + 3.0  # offset
    force = np.concatenate([load, 0.8 * load[::-1]])
    fit = tension_from_test(raw_test(ext, force), gauge_length_mm=25.0, area_mm2=2.0)
    assert fit.n_points == 50 and fit.source == "tension.csv"
    assert (fit.C10_kpa, fit.C01_kpa) == (pytest.approx(150.0), pytest.approx(100.0))
    # a machine that records tension as negative stroke and force
    neg = tension_from_test(raw_test(-ext, -force), gauge_length_mm=25.0, area_mm2=2.0)
    assert (neg.C10_kpa, neg.C01_kpa) == (pytest.approx(150.0), pytest.approx(100.0))
    # stretch_range passes through
    part = tension_from_test(
        raw_test(ext, force),
        gauge_length_mm=25.0,
        area_mm2=2.0,
        stretch_range=(1.0, 1.5),
    )
    assert part.stretch_max <= 1.5 and part.n_points < 50


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (
            {"gauge_length_mm": 0.0, "area_mm2": 2.0},
            r"gauge_length_mm = 0(\.0)? .*\(0, inf\) mm",
        ),
        (
            {"gauge_length_mm": -5, "area_mm2": 2.0},
            r"gauge_length_mm = -5 .*\(0, inf\)",
        ),
        ({"gauge_length_mm": math.nan, "area_mm2": 2.0}, r"gauge_length_mm = nan"),
        ({"gauge_length_mm": 20.0, "area_mm2": 0}, r"area_mm2 = 0 .*\(0, inf\) mm\^2"),
        ({"gauge_length_mm": 20.0, "area_mm2": "x"}, r"area_mm2 = 'x' is not a number"),
    ],
)
def test_tension_from_test_rejects_bad_specimen_sizes(kwargs, match):
    lam = np.linspace(1.0, 2.0, 20)
    raw = raw_test((lam - 1) * 20, stress_kpa(150.0, 100.0, lam) / 1e3)
    with pytest.raises(InputError, match=match) as err:
        tension_from_test(raw, **kwargs)
    assert "\n" not in str(err.value)


def test_tension_from_test_refuses_short_or_unstretched_tests():
    with pytest.raises(
        ProcessingError, match=r"tension\.csv: 4 sample\(s\) .* at least 5"
    ):
        tension_from_test(
            raw_test([0, 1, 2, 3], [0, 1, 2, 3]), gauge_length_mm=20, area_mm2=2
        )
    # 20 samples but only 0.1 mm on a 20 mm gauge: stretch 1.005
    ext = np.linspace(0, 0.1, 20)
    with pytest.raises(
        ProcessingError, match=r"largest stretch is 1\.005 .* above 1\.01"
    ):
        tension_from_test(raw_test(ext, ext), gauge_length_mm=20, area_mm2=2)
    assert issubclass(ProcessingError, InputError)


# ------------------------------------------------------------------------------------
# bad inputs to fit_tension
# ------------------------------------------------------------------------------------
LAM = np.linspace(1.0, 2.0, 11)
P = stress_kpa(150.0, 100.0, LAM)


@pytest.mark.parametrize(
    "args, kwargs, match",
    [
        ((LAM, P[:-1]), {}, "stretch has 11 values but nominal_stress_kpa has 10"),
        (
            (np.r_[LAM[:-1], np.nan], P),
            {},
            "stretch has a non-finite value nan at index 10",
        ),
        ((LAM, np.r_[P[:-1], np.inf]), {}, "nominal_stress_kpa has a non-finite value"),
        ((np.r_[0.0, LAM[1:]], P), {}, r"stretch = 0 at index 0 is not > 0"),
        ((LAM.reshape(11, 1), P), {}, "one-dimensional"),
        ((["a"] * 11, P), {}, "stretch is not numeric"),
        (
            (LAM, P),
            {"stretch_range": (2.0, 1.0)},
            r"stretch_range = \(2, 1\) is not a valid",
        ),
        ((LAM, P), {"stretch_range": 1.5}, "stretch_range = 1.5 is not a pair"),
        ((LAM, P), {"admissible_range": (0.0, 1.6)}, r"admissible_range = \(0, 1\.6\)"),
        (
            (LAM, P),
            {"stretch_range": (1.0, 1.15)},
            r"1 point\(s\) with stretch != 1 inside",
        ),
        ((np.ones(5), P[:5]), {}, r"0 point\(s\) with stretch != 1; .* at least 3"),
    ],
)
def test_fit_tension_rejects_bad_input(args, kwargs, match):
    with pytest.raises(InputError, match=match) as err:
        fit_tension(*args, **kwargs)
    assert "\n" not in str(err.value)


def test_fit_tension_refuses_data_without_stiffness():
    with pytest.raises(FitError, match="no positive shear modulus") as err:
        fit_tension(LAM, -P, source="upside-down.csv")
    assert str(err.value).startswith("upside-down.csv: ") and "\n" not in str(err.value)
