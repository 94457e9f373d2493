"""Plausibility of processed tests: numbers that no bending actuator in this fixture can give.

A test can read and process cleanly and still not come from a bending actuator: a compression
test of a concrete cylinder, a tension test, a file whose force is in another unit.  After
processing, :func:`check_result` compares each test's numbers with bounds that follow from the
four-point fixture (eq 6-8) and from what a pneumatic actuator can do; :func:`compression_like`
recognises a record that is no cyclic bending test at all.  Each finding is a dict
(``test``, ``pressure_kpa``, ``check``, ``value``, ``bound``, ``unit``, ``message``) carried by the
processed result (:attr:`~bendpam.lab.processed.PressureResult.findings`) and shown by the summary,
the report and the command line; docs/plausibility.md ("Processed tests") states every bound and
its reason.

Bounds (:data:`PROCESSED_BOUNDS`):

* **blocked moment** at most :func:`moment_bound_nmm`: ``K pi (d/2)^3 P + F_res d/2`` with
  ``K = 2.6 (1 + 2 cot^2 10 deg)``.  At the blocked state (beta = 0) eq 7 gives ``M = F d / 2``; an
  actuator whose section fits between the two rollers on one side (radius at most ``d/2``) makes
  at most the McKibben moment ``pi R^3 (1 + 2 cot^2 alpha0) P`` times the models' 2.6, at the
  smallest plausible braid angle (10 deg); ``F_res`` (0.2 N, the detection load) covers noise.
* **energy-loss ratio** at most 60 %, and not below -5 % (a loop that runs backwards returns more
  work than it took).
* **return of the curvature**: each cycle ends within 25 % of its curvature range of where it started.
"""

from __future__ import annotations

import math

import numpy as np

from bendpam.physics.fixture import Fixture

__all__ = ["PROCESSED_BOUNDS", "check_result", "compression_like", "moment_bound_nmm"]

#: The bounds of the checks after processing (docs/plausibility.md, "Processed tests").
PROCESSED_BOUNDS = {
    "moment_factor": 2.6 * (1.0 + 2.0 / math.tan(math.radians(10.0)) ** 2),  # K: 2.6 (1 + 2 cot^2 10 deg)
    "force_resolution_n": 0.2,  # the machine's detection load (N)
    "max_loss_ratio": 0.60,
    "min_loss_ratio": -0.05,
    "max_return_fraction": 0.25,
}


def moment_bound_nmm(fixture: Fixture, pressure_kpa: float) -> float:
    """The largest blocked moment (N*mm) an actuator in ``fixture`` can make at ``pressure_kpa``.

    ``K pi (d/2)^3 P + F_res d/2``: the McKibben moment of the widest section that fits between
    two rollers ``d`` apart, times the models' 2.6, at the smallest plausible braid angle (10 deg),
    plus the moment of the force resolution at the blocked state (eq 7 at beta = 0: ``M = F d/2``).

    Examples
    --------
    >>> from bendpam.physics.fixture import PAPER_FIXTURE
    >>> round(moment_bound_nmm(PAPER_FIXTURE, 200.0), -3)     # N*mm; the paper's BE-PAM makes 330 there
    572000.0
    """
    d = float(fixture.d_mm)
    p_n_per_mm2 = max(float(pressure_kpa), 0.0) * 1e-3
    k = PROCESSED_BOUNDS["moment_factor"]
    return k * math.pi * (0.5 * d) ** 3 * p_n_per_mm2 + PROCESSED_BOUNDS["force_resolution_n"] * 0.5 * d


def _finding(result, check: str, value: float, bound: float, unit: str, message: str) -> dict:
    return {"test": result.source, "pressure_kpa": float(result.pressure_kpa), "check": check,
            "value": float(value), "bound": float(bound), "unit": unit,
            "message": f"{result.source} ({result.pressure_kpa:g} kPa): {message}"}


def check_result(result, fixture: Fixture, return_gaps=None) -> list[dict]:
    """The plausibility findings of one processed test (an empty list when every number is plausible).

    ``result`` is a :class:`~bendpam.lab.processed.PressureResult`; ``return_gaps`` the curvature
    gap between each cycle's end and start as a fraction of its range (from processing; ``None``
    skips that check).

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> from bendpam.physics.fixture import PAPER_FIXTURE
    >>> test = NS(source="c.csv", pressure_kpa=200.0, blocked_moment=(2.1e6, 1.0), energy_loss_ratio=0.68)
    >>> [f["check"] for f in check_result(test, PAPER_FIXTURE, [0.01, 0.4])]
    ['blocked-moment', 'loss-ratio', 'curvature-return']
    >>> print(check_result(test, PAPER_FIXTURE)[1]["message"])
    c.csv (200 kPa): energy-loss ratio 68.0 % is above 60 %: a bending actuator's loop dissipates less ...
    """
    out = []
    bm = float(result.blocked_moment[0])
    bound = moment_bound_nmm(fixture, result.pressure_kpa)
    if math.isfinite(bm) and bm > bound:
        out.append(_finding(
            result, "blocked-moment", bm, bound, "N*mm",
            f"blocked moment {bm:.4g} N*mm (a blocked force of {2.0 * bm / fixture.d_mm:.4g} N) is beyond "
            f"{bound:.4g} N*mm, the most an actuator that fits this fixture (d = {fixture.d_mm:g} mm) makes "
            f"at this pressure: not a bending actuator, or the force is not in N"))
    ratio = float(result.energy_loss_ratio)
    if math.isfinite(ratio) and ratio > PROCESSED_BOUNDS["max_loss_ratio"]:
        out.append(_finding(
            result, "loss-ratio", ratio, PROCESSED_BOUNDS["max_loss_ratio"], "1",
            f"energy-loss ratio {100 * ratio:.1f} % is above {100 * PROCESSED_BOUNDS['max_loss_ratio']:g} %: "
            "a bending actuator's loop dissipates less (a crushed or yielding specimen dissipates this much)"))
    elif math.isfinite(ratio) and ratio < PROCESSED_BOUNDS["min_loss_ratio"]:
        out.append(_finding(
            result, "loss-ratio", ratio, PROCESSED_BOUNDS["min_loss_ratio"], "1",
            f"energy-loss ratio {100 * ratio:.1f} % is below {100 * PROCESSED_BOUNDS['min_loss_ratio']:g} %: "
            "the loop runs backwards (the actuator would return more work than it took)"))
    if return_gaps is not None and len(return_gaps):
        gaps = np.asarray(return_gaps, dtype=float)
        worst = float(np.nanmax(gaps)) if np.isfinite(gaps).any() else math.nan
        if math.isfinite(worst) and worst > PROCESSED_BOUNDS["max_return_fraction"]:
            out.append(_finding(
                result, "curvature-return", worst, PROCESSED_BOUNDS["max_return_fraction"], "1",
                f"the curvature does not return: cycle {int(np.nanargmax(gaps)) + 1} ends "
                f"{100 * worst:.0f} % of its range away from where it started (bound "
                f"{100 * PROCESSED_BOUNDS['max_return_fraction']:g} %): the specimen deforms for good"))
    return out


def compression_like(stroke_mm, force_n, threshold_mm: float) -> str | None:
    """Why a record looks like a compression (or tension) test rather than a cyclic bending test, or ``None``.

    A cyclic bending test moves the crosshead back and forth from the blocked state, where the force
    is largest, so the force falls as the stroke leaves its start.  A compression test drives the
    crosshead one way while the force keeps one sign and grows with the travel.  Looked at are the
    samples above 2 % of the peak force (a retract after the specimen broke carries no load): a
    record whose force has one sign, whose stroke reverses at most once (by more than
    ``threshold_mm``) and whose force grows with the travel from the start (correlation above 0.5)
    is a compression or tension test.

    Examples
    --------
    >>> s = np.linspace(0.0, 3.0, 200)
    >>> print(compression_like(s, -40000.0 * s, 0.15))      # doctest: +NORMALIZE_WHITESPACE
    force of one sign only (-1.2e+05 to 0 N), stroke one way over 2.94 mm while the force grows
    (correlation 1.00), no cycle: a compression or tension test
    >>> compression_like(s, 5.0 - 1.5 * s, 0.15) is None      # one release from the blocked state
    True
    """
    s = np.asarray(stroke_mm, dtype=float)
    f = np.asarray(force_n, dtype=float)
    if s.size < 3 or not (np.isfinite(s).all() and np.isfinite(f).all()):
        return None
    fmin, fmax = float(f.min()), float(f.max())
    span = max(abs(fmin), abs(fmax))
    if span == 0.0 or (min(abs(fmin), abs(fmax)) > 0.02 * span and fmin * fmax < 0):
        return None  # force of both signs
    loaded = np.abs(f) >= 0.02 * span
    sl, fl = s[loaded], np.abs(f[loaded])
    if sl.size < 3 or np.ptp(sl) <= threshold_mm:
        return None
    if not _at_most_one_reversal(sl, threshold_mm):
        return None  # back and forth: cycles
    travel = np.abs(sl - sl[0])
    if np.ptp(travel) == 0.0 or np.ptp(fl) == 0.0:
        return None
    r = float(np.corrcoef(travel, fl)[0, 1])
    if not r > 0.5:
        return None
    return (f"force of one sign only ({fmin + 0.0:.3g} to {fmax + 0.0:.3g} N), stroke one way over "
            f"{float(np.ptp(sl)):.3g} mm while the force grows (correlation {r:.2f}), no cycle: "
            "a compression or tension test")


def _at_most_one_reversal(x: np.ndarray, threshold: float) -> bool:
    """True when ``x`` rises then falls (or falls then rises, or is monotone), back-steps up to ``threshold`` aside.

    >>> _at_most_one_reversal(np.array([0.0, 1.0, 2.0, 1.0]), 0.1), _at_most_one_reversal(np.array([0, 2, 0, 2.0]), 0.1)
    (True, False)
    """
    def rises(y: np.ndarray) -> bool:
        return y.size < 2 or float(np.max(np.maximum.accumulate(y) - y)) <= threshold

    def falls(y: np.ndarray) -> bool:
        return y.size < 2 or float(np.max(y - np.minimum.accumulate(y))) <= threshold

    i, j = int(np.argmax(x)), int(np.argmin(x))
    return (rises(x[:i + 1]) and falls(x[i:])) or (falls(x[:j + 1]) and rises(x[j:]))
