"""Fixtures shared by the tests, and hypothesis's profiles.

Hypothesis draws its examples from a seed fixed per test (``derandomize``): the suite gives the same result
on every run and machine, so the check that gates a landing cannot fail by the luck of a draw.  To explore new
examples, run with ``HYPOTHESIS_PROFILE=explore`` (random draws, more of them); a failure it finds is then
kept as a test of its own.
"""

import os

import numpy as np
import pytest
from hypothesis import settings

import bendpam
from bendpam import presets

settings.register_profile("repeatable", derandomize=True)
settings.register_profile("explore", derandomize=False, max_examples=400)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))

MODELS = ["energy", "force_balance"]


@pytest.fixture(params=[(n, m) for n in ("be-pam", "bc-pam") for m in MODELS], ids=lambda p: f"{p[0]}-{p[1]}")
def preset_model(request):
    """Each paper actuator with each model's Table 3 constants: (actuator, model)."""
    name, model = request.param
    return presets.get(name, model), model


@pytest.fixture
def be():
    return presets.be_pam("energy")


@pytest.fixture
def bc():
    return presets.bc_pam("energy")


@pytest.fixture
def span():
    """``span(actuator, frac, n)``: n curvatures over ``frac`` of the admissible range."""
    return curvature_span


def curvature_span(actuator, frac=0.9, n=41):
    lim = bendpam.curvature_limits(actuator)
    return np.linspace(frac * lim.k_min, frac * lim.k_max, n)


@pytest.fixture(scope="session")
def study_case():
    """``study_case(name, seed)``: a calibration-study case's raw tests (tools/calibration_study.py) read and
    processed as the study does: ``(processed set, start actuator, truth)``."""
    import sys
    import tempfile
    import warnings
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))
    import calibration_study as study

    from bendpam.lab import read_test
    from bendpam.lab.processing import process_tests
    from bendpam.physics.fixture import Fixture

    def make(name: str, seed: int = 0):
        case = study.ALL_CASES[name]
        with tempfile.TemporaryDirectory() as folder, warnings.catch_warnings():
            warnings.simplefilter("ignore")
            truth = study.generator(case).generate_set(case, seed, folder)
            ps = process_tests([read_test(Path(folder) / n) for n in truth["files"]],
                               fixture=Fixture(L0_mm=truth["fixture_L0_mm"]), keep_series=False)
        return ps, study.generator(case).start_actuator(case), truth

    return make

