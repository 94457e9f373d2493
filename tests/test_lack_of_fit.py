"""The misfit the cycle bootstrap cannot see: a lack-of-fit test against the cycles as replicates.

Resampling a test's cycles sees the noise; a misfit of the model, the same in every cycle, it does not.  Each
curve's residual sum of squares ``SSR`` is compared with its pure error ``PE`` (the variance of its mean over
the cycles): the share ``1 - PE / SSR`` of the curve's sandwich meat is added.  Checked by hand on a line, as
properties (nothing added where the model fits to the noise, more the larger the misfit), and on the tenth
held-out set's braid friction, whose laws all share a bias the bootstrap alone did not cover.
"""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bendpam.identify.fitting import fit
from bendpam.identify.uncertainty import sandwich_covariance

J = np.column_stack([np.ones(4), np.arange(4.0)])  # a line: offset and slope
ROWS = np.arange(4)
GROUP = np.zeros(4, int)


def parts(r, U):
    """The covariance with the cycles ``U``; the bootstrap's alone (residuals zero); the sandwich's alone."""
    both, _ = sandwich_covariance(J, r, GROUP, [(ROWS, U)])
    boot, _ = sandwich_covariance(J, np.zeros(4), GROUP, [(ROWS, U)])
    plain, _ = sandwich_covariance(J, r, GROUP)
    return both, boot, plain


def test_the_misfits_share_is_added_by_hand():
    r = np.array([0.2, -0.2, -0.2, 0.2])  # SSR 0.16, a misfit the line cannot follow (no autocorrelation left)
    U = np.array([[0.4, 0.0, 0.0, 0.0], [-0.4, 0.0, 0.0, 0.0]])  # PE = (0.16 + 0.16) / (2 * 1) = 0.16: all noise
    both, boot, _ = parts(r, U)
    np.testing.assert_allclose(both, boot, atol=1e-15)
    U2 = U / np.sqrt(2.0)  # PE = 0.08: half the sum of squares is misfit
    both, boot, plain = parts(r, U2)
    np.testing.assert_allclose(both, boot + 0.5 * plain, rtol=1e-12)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-1.0, 1.0), min_size=4, max_size=4), st.lists(st.floats(-1.0, 1.0), min_size=4, max_size=4),
       st.floats(1.0, 5.0))
def test_more_misfit_never_narrows_the_bars(res, dev, grow):
    r = np.array(res)
    U = np.vstack([np.array(dev), -np.array(dev)])
    both, boot, plain = parts(r, U)
    assert np.all(np.diag(both) >= np.diag(boot) - 1e-12)  # the bootstrap's part is always there
    assert np.all(np.diag(both) <= np.diag(boot + plain) + 1e-12)  # at most the whole sandwich on top
    more, _, _ = parts(grow * r, U)
    assert np.all(np.diag(more) >= np.diag(both) - 1e-12)


@pytest.fixture(scope="module")
def braid(study_case):
    """The tenth held-out set's braid friction following the load (seed 0), fitted."""
    ps, act, truth = study_case("h10-braid-gaindrift", 0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fit(ps, act, profile_points=0), truth


def test_a_loop_no_law_has_is_covered(braid):
    """Every law is biased alike on this loop (about -0.1 to -0.3 deg); the misfit, 15-36 times the cycles' pure
    error, widens alpha0's bar from 0.044 deg (the bootstrap and the laws' spread) to about 0.11 deg."""
    result, truth = braid
    a = result.parameters["alpha0"]
    assert a.value - truth["alpha0_deg"] < -0.1  # the bias is there
    assert abs(a.value - truth["alpha0_deg"]) <= 2.0 * a.stderr
    assert "misfit beyond the cycles' scatter" in result.uncertainty.resampling
    said = [f for f in result.flags if "times what the scatter of their cycles explains" in f]
    assert len(said) == 1 and "a bias that every loop law shares may remain" in said[0]


def test_a_model_that_fits_to_the_noise_says_nothing(study_case):
    """The main set's stiction case: the residuals 1-3 times the cycles' pure error, below the note's 4."""
    ps, act, _ = study_case("stiction", 0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = fit(ps, act, profile_points=0)
    assert not any("scatter of their cycles" in f for f in result.flags)


def test_offset_widening_on_clean_curves_names_the_declaration(study_case):
    """The main set's stiction case (residuals 1-3 times the pure error): the offset members widen alpha0's bar for
    nothing the curves show, and the fit names the declaration that replaces them."""
    ps, act, _ = study_case("stiction", 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = fit(ps, act, profile_points=0)
    widened = [f for f in result.flags if "widen alpha0's error bar" in f]
    assert len(widened) == 1 and "if the load cell was tared with the fixture as tested" in widened[0]
    assert "bias of the model" not in widened[0]


def test_offset_widening_under_a_misfit_says_what_a_declaration_gives_up(study_case):
    """The eleventh held-out set's crystallisation loop (seed 1): the residuals are 7 times the cycles' pure error
    and the offset members take most of the weight; their wider bar may be covering the model's bias (every member
    shares one of about -2 deg here), so the words say a declaration gives that up."""
    ps, act, _ = study_case("h11-liangrogers-thermal", 1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = fit(ps, act, profile_points=0)
    assert any("times what the scatter of their cycles explains" in f for f in result.flags)
    widened = [f for f in result.flags if "widen alpha0's error bar" in f]
    assert len(widened) == 1 and "may also be covering a bias of the model" in widened[0]
    assert "--zero-uncertainty-n" in widened[0]
