"""The four-point bending fixture of the cyclic moment test (paper section 2.2, eq 6-8).

The testing machine's crosshead moves by ``ds`` (stroke, counted from the blocked, straight state)
and the connecting plates at the actuator's ends pitch by ``beta``.  With the horizontal distance
``d`` between the two rollers on one side, the roller radius ``r`` and the plate thickness ``t``:

* eq 6:  ``d tan(beta) + (sqrt(1 + tan^2 beta) - 1)(t + 2r) = ds``
* eq 7:  ``M = F [d + (2r + t) sin(beta)] / (2 cos^2 beta)``   ("2 cos beta^2" read as 2 cos^2 beta,
  docs/paper-reading.md item 16)
* eq 8:  ``k' = 2 beta / L0``

The left side of eq 6 increases monotonically on ``[0, pi/2)`` from 0 to infinity, so each stroke
has exactly one root there.  Writing ``x = tan(beta)`` and ``c = t + 2r`` it is the root of the
quadratic ``(c^2 - d^2) x^2 + 2 d (ds + c) x + c^2 - (ds + c)^2 = 0`` that satisfies the unsquared
equation (``ds + c - d x >= 0``); we evaluate it in that closed form (vectorised, exact to rounding)
and the tests check it against a bracketed ``scipy.optimize.brentq`` root.

Magnitudes: the fixture gives ``beta >= 0`` and the moment magnitude.  The paper reports
magnitudes; a BC-PAM bends with k' < 0 in bendpam's sign convention, which the processing step
applies (``Fixture`` itself is sign-free).  Strokes slightly below zero (noise around the blocked
state) are mapped by odd extension, ``beta(-ds) = -beta(ds)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from bendpam.errors import InputError
from bendpam.validate import float_array, plausible

__all__ = ["PAPER_FIXTURE", "Fixture"]


@dataclass(frozen=True)
class Fixture:
    """Four-point bending fixture geometry (mm).

    Parameters
    ----------
    d_mm : horizontal distance between the two loading rollers on one side (paper: 35 mm).
    r_mm : loading roller radius (paper: 2.5 mm).
    t_mm : connecting plate thickness (paper: 4 mm).
    L0_mm : active length of the actuator, for k' = 2 beta / L0 (paper: 145 mm).

    Notes
    -----
    Each dimension must be a finite number in its physical plausibility range
    (:data:`bendpam.validate.PLAUSIBLE`: ``d`` 1 mm to 2 m, ``r`` and ``t`` up to 200 mm, ``L0`` as an
    actuator's, 1 mm to 5 m), else one :class:`~bendpam.errors.InputError` line names it.

    Examples
    --------
    >>> fx = Fixture()                                   # the paper's fixture
    >>> beta, k, M = fx.convert(10.0, 5.0)               # stroke 10 mm, force 5 N
    >>> round(float(beta), 4), round(float(k), 6), round(float(M), 2)   # rad, 1/mm, N*mm
    (0.2694, 0.003716, 100.61)
    """

    d_mm: float = 35.0
    r_mm: float = 2.5
    t_mm: float = 4.0
    L0_mm: float = 145.0

    def __post_init__(self) -> None:
        for name in ("d_mm", "r_mm", "t_mm", "L0_mm"):
            v = getattr(self, name)
            try:
                fv = float(v)
            except (TypeError, ValueError, OverflowError):
                raise InputError(f"fixture {name} = {v!r} is not a number") from None
            lo = 0.0
            if not math.isfinite(fv) or fv < lo or (fv == 0.0 and name in ("d_mm", "L0_mm")):
                rng = "(0, inf)" if name in ("d_mm", "L0_mm") else "[0, inf)"
                raise InputError(f"fixture {name} = {v!r} mm is outside the allowed range {rng} mm")
            plausible("L0_mm" if name == "L0_mm" else f"fixture_{name}", fv, label=f"fixture {name}")
            object.__setattr__(self, name, fv)

    @property
    def c(self) -> float:
        """Lever offset ``t + 2r`` (mm)."""
        return self.t_mm + 2.0 * self.r_mm

    @classmethod
    def from_string(cls, text: str, L0_mm: float = 145.0, *, name: str = "fixture") -> Fixture:
        """Parse ``"d,r,t"`` (mm); ``name`` names the value in the error message (the CLI gives its option).

        Examples
        --------
        >>> Fixture.from_string("35, 2.5, 4")
        Fixture(d_mm=35.0, r_mm=2.5, t_mm=4.0, L0_mm=145.0)
        >>> Fixture.from_string("35,2.5")
        Traceback (most recent call last):
        ...
        bendpam.errors.InputError: fixture '35,2.5': expected three numbers d,r,t in mm, e.g. 35,2.5,4
        """
        parts = [p for p in str(text).replace(";", ",").split(",") if p.strip()]
        if len(parts) != 3:
            raise InputError(f"{name} {text!r}: expected three numbers d,r,t in mm, e.g. 35,2.5,4")
        try:
            d, r, t = (float(p) for p in parts)
        except ValueError:
            raise InputError(f"{name} {text!r}: expected three numbers d,r,t in mm, e.g. 35,2.5,4") from None
        return cls(d, r, t, L0_mm)

    # ---- eq 6 ---------------------------------------------------------------------------------
    def stroke_to_beta(self, stroke_mm):
        """Plate pitch angle beta (rad) from the stroke ``ds`` (mm, from the blocked state), eq 6."""
        s = _data("stroke_mm", stroke_mm, "mm")
        a = np.abs(s)
        c, d = self.c, self.d_mm
        e = a + c
        qb = 2.0 * d * e
        qc = c * c - e * e  # <= 0
        # numerically stable root of qa x^2 + qb x + qc = 0 with x >= 0 and e - d x >= 0:
        # x = -2 qc / (qb + sqrt(qb^2 - 4 qa qc))   (the '+' root, written without cancellation)
        # qb^2 - 4 qa qc simplifies to 4 c^2 (e^2 + d^2 - c^2): no cancellation
        disc = 2.0 * c * np.sqrt(e * e + d * d - c * c)
        den = qb + disc
        x = np.divide(-2.0 * qc, den, out=np.zeros_like(den), where=den > 0.0)
        return np.sign(s) * np.arctan(x)

    def beta_to_stroke(self, beta):
        """Stroke ``ds`` (mm) from beta (rad), eq 6 evaluated directly (odd extension for beta < 0)."""
        b = _beta(beta)
        ab = np.abs(b)
        return np.sign(b) * (self.d_mm * np.tan(ab) + (1.0 / np.cos(ab) - 1.0) * self.c)

    # ---- eq 8 ---------------------------------------------------------------------------------
    def beta_to_curvature(self, beta):
        """Frame curvature magnitude k' = 2 beta / L0 (1/mm), eq 8."""
        return 2.0 * _beta(beta) / self.L0_mm

    def curvature_to_beta(self, curvature):
        """beta = k' L0 / 2 (rad), the inverse of eq 8."""
        return 0.5 * _data("curvature", curvature, "1/mm") * self.L0_mm

    def stroke_to_curvature(self, stroke_mm):
        """k' (1/mm) from the stroke (mm): eq 6 then eq 8."""
        return self.beta_to_curvature(self.stroke_to_beta(stroke_mm))

    def curvature_to_stroke(self, curvature):
        """Stroke (mm) that bends the actuator to k' (1/mm)."""
        return self.beta_to_stroke(self.curvature_to_beta(curvature))

    # ---- eq 7 ---------------------------------------------------------------------------------
    def lever(self, beta):
        """Moment per unit force ``[d + (2r + t) sin(beta)] / (2 cos^2 beta)`` (mm), eq 7."""
        b = np.abs(_beta(beta))
        return (self.d_mm + self.c * np.sin(b)) / (2.0 * np.cos(b) ** 2)

    def force_to_moment(self, force_n, beta):
        """Moment (N*mm) from the machine force F_load (N) at pitch beta (rad), eq 7."""
        return _data("force_n", force_n, "N") * self.lever(beta)

    def moment_to_force(self, moment_nmm, beta):
        """Machine force (N) that balances the moment (N*mm) at pitch beta (rad), inverse of eq 7."""
        return _data("moment_nmm", moment_nmm, "N*mm") / self.lever(beta)

    def convert(self, stroke_mm, force_n, tare_n: float = 0.0):
        """Raw (stroke, force) to (beta, k', M): eq 6-8, with an optional force tare (N).

        The tare is subtracted from the force before eq 7; use it for the self-weight of the
        actuator and the connecting plates, as read with the actuator unpressurised.
        """
        beta = self.stroke_to_beta(stroke_mm)
        tare = _data("tare_n", tare_n, "N")
        if tare.ndim:
            raise InputError(f"tare_n has shape {tare.shape}; one force (N) expected")
        f = _data("force_n", force_n, "N") - float(tare)
        return beta, self.beta_to_curvature(beta), self.force_to_moment(f, beta)


def _data(name: str, value, unit: str) -> np.ndarray:
    """A float array of finite values (strokes and forces in their plausible ranges), else one InputError line."""
    v = float_array(name, value, unit)
    if v.size and not np.all(np.isfinite(v)):
        i = int(np.flatnonzero(~np.isfinite(v.ravel()))[0])
        raise InputError(f"{name} has a non-finite value {float(v.ravel()[i])!r} at index {i}")
    key = {"stroke_mm": "stroke_mm", "force_n": "force_n", "tare_n": "force_n"}.get(name)
    if key is not None:
        plausible(key, v, label=name, indexed=v.ndim > 0)
    return v


def _beta(beta) -> np.ndarray:
    """Plate pitch angles (rad) in (-pi/2, pi/2), else one InputError line."""
    b = _data("beta", beta, "rad")
    if np.any(np.abs(b) >= np.pi / 2):
        raise InputError("beta must lie in (-pi/2, pi/2)")
    return b


#: The paper's fixture (section 2.2): d = 35 mm, r = 2.5 mm, t = 4 mm, L0 = 145 mm.
PAPER_FIXTURE = Fixture()
