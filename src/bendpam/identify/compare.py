"""Both actuator types fitted with the same freedom: evidence of the bending direction.

The tests record magnitudes, so whether the data bend toward the frame (a BE-PAM) or away from it
(a BC-PAM) shows only in which type describes them.  :func:`type_comparison` fits both, each with
alpha0 anywhere on its side of 54.74 deg and P_start free, and
:func:`bendpam.identify.diagnose.judge_data` weighs the two.
"""

from __future__ import annotations

from bendpam.errors import BendpamError
from bendpam.identify.fitting import fit
from bendpam.physics.actuator import NEUTRAL_ANGLE_DEG, Actuator

__all__ = ["type_comparison"]

#: alpha0 (deg) of each side of the neutral angle: the bend sign -> (lo, hi).
_SIDES = {1: (NEUTRAL_ANGLE_DEG + 0.05, 85.0), -1: (15.0, NEUTRAL_ANGLE_DEG - 0.05)}


def _side_fit(processed, actuator: Actuator, model: str | None, free, sign: int):
    """A quick fit with alpha0 anywhere on one side of 54.74 deg (``sign``) and P_start free, or None."""
    rng = _SIDES[sign]
    names = list(dict.fromkeys(["alpha0", *free, "P_start"]))
    act = actuator.replace(alpha0_deg=0.5 * (rng[0] + rng[1]))
    try:
        return fit(processed, act, model, free=names, bounds={"alpha0": rng}, law_uncertainty=False,
                   profile_points=0)
    except (BendpamError, ValueError, ArithmeticError):
        return None


def type_comparison(processed, actuator: Actuator, model: str | None = None, free=("alpha0", "C10", "C01")):
    """Fit both actuator types with the same freedom: ``(same, other)`` FitResults (None where a fit fails).

    Both fits free alpha0 across their whole side of 54.74 deg and P_start besides ``free``, so that
    neither a wrong nominal alpha0 nor a wrong P_start decides which type describes the data better.
    Used by :func:`bendpam.identify.diagnose.judge_data` as evidence of the bending direction.
    Returns ``(None, None)`` for a neutral actuator.

    Examples
    --------
    Virtual tests of the paper's BE-PAM (coarse, without a loop) taken for a BC-PAM: the other type
    describes them better.

    >>> from pathlib import Path
    >>> import bendpam
    >>> from bendpam.lab import RawTest
    >>> from bendpam.lab.processing import ProcessingOptions
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> be = bendpam.physics.presets.be_pam()
    >>> settings = SimulationSettings(cycles=1, rate_hz=2.0, hysteresis=0.0, seed=1)
    >>> raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv", pressure_kpa=p)
    ...         for p in (100.0, 200.0)]
    >>> processed = bendpam.process_tests(raws, keep_series=False, options=ProcessingOptions(grid_points=21))
    >>> same, other = type_comparison(processed, bendpam.physics.presets.bc_pam())
    >>> other.metrics.nrmse_cycles < same.metrics.nrmse_cycles
    True
    """
    sign = int(actuator.bend_sign)
    if sign == 0:
        return None, None
    from bendpam.lab.processed import as_processed

    processed = as_processed(processed)  # a ProcessedSet, or the folder it was written to
    return (_side_fit(processed, actuator, model, free, sign), _side_fit(processed, actuator, model, free, -sign))
