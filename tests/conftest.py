import numpy as np
import pytest

import bendpam
from bendpam import presets

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
