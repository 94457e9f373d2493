"""Incompressible Mooney-Rivlin bladder material (paper eq 18, 32-33).

The strain-energy density, with the paper's misprint in eq 18 read as ``(I2 - 3)``
(docs/paper-reading.md item 8) and ``C11 = 0``::

    W = C10 (I1 - 3) + C01 (I2 - 3)

with ``I1 = l1^2 + l2^2 + l3^2``, ``I2 = l1^-2 + l2^-2 + l3^-2`` and incompressibility
``l3 = 1 / (l1 l2)`` (eq 17, 36).  Units follow the package convention: the constants
are in MPa (N/mm^2), so ``W`` is an energy per reference volume in N*mm/mm^3 = MPa.

The class is small and pure so it can be tested in isolation (the way ``felupe`` and
``hyperelastic`` treat their material laws).  It accepts arrays and broadcasts.

Shear modulus and shape
-----------------------
Only ``mu = 2 (C10 + C01)``, the initial shear modulus, is well determined by most
tests; the split between the two constants is a *shape*::

    beta = C01 / (C10 + C01),    C10 = mu (1 - beta) / 2,    C01 = mu beta / 2

``beta = 0`` is neo-Hookean; ``beta`` in ``[0, 1]`` means both constants are >= 0.

Admissibility
-------------
For ``mu > 0`` each condition below is linear in ``beta`` at each deformation, so the
shapes satisfying it over a set of deformations form one closed interval, and
:func:`admissible_shape_range` intersects three of them.  The deformations are those
the bladder sees: principal in-plane stretches ``(l1, l2)`` anywhere in the square
``[s_min, s_max]^2`` (biaxial; equibiaxial, planar and in-plane uniaxial states lie
inside it) with ``l3 = 1/(l1 l2)``, plus uniaxial tension and compression
``(l, l^-1/2, l^-1/2)`` for ``l`` in ``[s_min, s_max]``.  The range is always widened
to contain 1, the undeformed state from which every deformation is reached.

1. **Energy**, ``W >= 0``.  Since ``I1, I2 >= 3`` this reads
   ``(I1 - 3) + beta (I2 - I1) >= 0``.  Computed on a log-spaced grid (241 x 241
   points of the square, 2001 of the uniaxial path); it never decides the result,
   because Baker-Ericksen on a range containing 1 implies ``W >= 0``: integrate
   ``dW = sum_i sigma_i d(ln l_i)`` along ``l_i(t) = l_i^t`` (which stays in the
   range); as ``sum_i ln l_i = 0`` the integrand is
   ``(1/3) sum_{i<j} (sigma_i - sigma_j)(ln l_i - ln l_j) >= 0``.  It is kept because
   a negative strain energy is the plainest reason to reject a material.
2. **Uniaxial monotonicity**: the nominal stress ``P = 2 (l - l^-2)(C10 + C01/l)``
   does not decrease on ``[s_min, s_max]``.  With ``q(l) = l^4 + 2 l - 3``,
   ``l^4 dP/dl = mu [(q + 3) - beta q]``, so exactly
   ``1 + 3/q(s_min) <= beta <= 1 + 3/q(s_max)``.
3. **Baker-Ericksen**: ``(sigma_i - sigma_j)(l_i - l_j) > 0`` for every pair of
   principal directions with ``l_i != l_j`` (Truesdell and Noll, *The Non-Linear Field
   Theories of Mechanics*, sec. 51).  For Mooney-Rivlin
   ``sigma_i - sigma_j = 2 (l_i^2 - l_j^2)(C10 + C01 s)`` with ``s = 1/(l_i l_j)^2``,
   so the condition is ``1 + beta (s - 1) > 0`` for every ``s`` the deformations
   produce.  Exactly, ``s`` spans ``[min(s_min^2, s_max^-4), max(s_max^2, s_min^-4)]``:
   ``s_max^2`` is the pair (2, 3) in planar extension ``(s_max, 1, 1/s_max)``,
   ``s_min^-4`` the in-plane pair near equibiaxial compression ``(s_min, s_min)``.

Why these: (1) is what "physically inadmissible" means, (2) is what a tension test
shows directly (a peak in the force), (3) is the classical statement that the stresses
follow the stretches, for every pair of directions including the thickness.  The strict
inequalities hold inside the interval; at an end the binding condition holds with
equality at one deformation (a zero tangent or stress difference), so the interval is
returned closed.  Shapes in ``[0, 1]`` pass on every range; how far outside one may go
shrinks as the range widens: ``[-0.149, 1.180]`` on ``[0.6, 1.6]``, ``[-0.018, 1.0003]``
on ``[0.6, 7.6]``.  Stronger conditions (strong ellipticity, Hill's inequalities) are
not checked.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from bendpam.errors import InputError
from bendpam.validate import finite_number, float_array

__all__ = [
    "BindingState",
    "MooneyRivlin",
    "ShapeLimit",
    "admissible_shape_range",
    "shape_limits",
    "within",
]

#: Relative slack when a shape is compared with its bounds (a fit may land on one).
_BOUND_TOL = 1e-9


@dataclass(frozen=True)
class MooneyRivlin:
    """Two-parameter incompressible Mooney-Rivlin solid.

    Parameters
    ----------
    C10, C01 : float
        Material constants in MPa.  Either may be negative (the paper's Table 3 fits
        are), but the initial shear modulus ``mu = 2 (C10 + C01)`` must be positive.
        Whether the pair is physical over a range of stretches is a separate question:
        :meth:`is_admissible`.

    Examples
    --------
    >>> m = MooneyRivlin(0.114, 0.300)
    >>> round(m.shear_modulus, 3), round(m.shape, 4)
    (0.828, 0.7246)
    """

    C10: float
    C01: float

    def __post_init__(self) -> None:
        for name in ("C10", "C01"):
            value = getattr(self, name)
            if isinstance(value, float | int) and not isinstance(value, bool) and math.isfinite(value):
                continue  # a number: the common case, fast
            v = float_array(name, value, "MPa")
            if not np.all(np.isfinite(v)):
                raise InputError(f"{name} = {getattr(self, name)!r} MPa is not finite")
        if np.any(np.asarray(self.C10 + self.C01) <= 0):
            raise InputError(
                f"C10 + C01 = {self.C10 + self.C01:g} MPa must be > 0 "
                "(the initial shear modulus 2(C10 + C01) must be positive)"
            )

    @classmethod
    def from_shear_modulus(cls, mu: float, shape: float) -> MooneyRivlin:
        """The material with initial shear modulus ``mu`` (MPa) and shape ``beta``.

        Parameters
        ----------
        mu : float
            Initial shear modulus ``2 (C10 + C01)`` in MPa, finite and > 0.
        shape : float
            ``beta = C01 / (C10 + C01)`` (dimensionless, finite), so
            ``C10 = mu (1 - beta) / 2`` and ``C01 = mu beta / 2``.  0 is neo-Hookean;
            :func:`admissible_shape_range` tells how far outside ``[0, 1]`` is physical.

        Returns
        -------
        MooneyRivlin

        Raises
        ------
        InputError
            For ``mu <= 0`` or a non-finite argument.

        Examples
        --------
        >>> m = MooneyRivlin.from_shear_modulus(0.6, 0.25)
        >>> round(m.C10, 12), round(m.C01, 12)
        (0.225, 0.075)
        """
        mu_v = finite_number("mu", mu, "MPa")
        if mu_v <= 0.0:
            raise InputError(f"mu = {mu_v:g} MPa is outside the allowed range (0, inf)")
        beta = finite_number("shape", shape, "")
        return cls(C10=0.5 * mu_v * (1.0 - beta), C01=0.5 * mu_v * beta)

    @property
    def shear_modulus(self) -> float:
        """Initial shear modulus ``mu = 2 (C10 + C01)`` in MPa."""
        return 2.0 * (self.C10 + self.C01)

    @property
    def shape(self) -> float:
        """Shape ``beta = C01 / (C10 + C01)`` (dimensionless; 0 is neo-Hookean)."""
        return self.C01 / (self.C10 + self.C01)

    # -- energy and its derivatives, with l3 = 1/(l1 l2) eliminated --------------------
    def energy(self, l1, l2):
        """Strain-energy density W(l1, l2) in MPa (eq 18, corrected)."""
        l1 = np.asarray(l1, dtype=float)
        l2 = np.asarray(l2, dtype=float)
        a, b = l1 * l1, l2 * l2
        i1 = a + b + 1.0 / (a * b)
        i2 = 1.0 / a + 1.0 / b + a * b
        return self.C10 * (i1 - 3.0) + self.C01 * (i2 - 3.0)

    def dW_dl1(self, l1, l2):
        """Partial derivative of W with respect to l1 (l3 eliminated), MPa."""
        l1 = np.asarray(l1, dtype=float)
        l2 = np.asarray(l2, dtype=float)
        return 2.0 * self.C10 * (l1 - 1.0 / (l1**3 * l2 * l2)) + 2.0 * self.C01 * (
            l1 * l2 * l2 - 1.0 / l1**3
        )

    def dW_dl2(self, l1, l2):
        """Partial derivative of W with respect to l2 (l3 eliminated), MPa."""
        return self.dW_dl1(l2, l1)

    # -- stresses ----------------------------------------------------------------------
    def cauchy_difference(self, la, lb):
        """Cauchy stress difference ``sigma_a - sigma_b`` (eq 32-33), MPa.

        ``sigma_a - sigma_b = 2 C10 (la^2 - lb^2) - 2 C01 (la^-2 - lb^-2)`` for two
        principal stretches of an incompressible Mooney-Rivlin solid.
        """
        la = np.asarray(la, dtype=float)
        lb = np.asarray(lb, dtype=float)
        return 2.0 * self.C10 * (la * la - lb * lb) - 2.0 * self.C01 * (
            1.0 / (la * la) - 1.0 / (lb * lb)
        )

    def uniaxial_nominal_stress(self, stretch):
        """Nominal (engineering) stress in uniaxial tension, MPa.

        ``P = 2 (l - l^-2) (C10 + C01 / l)``: the standard result for an incompressible
        Mooney-Rivlin solid with ``l2 = l3 = l^-1/2``.
        """
        lam = np.asarray(stretch, dtype=float)
        return 2.0 * (lam - lam**-2) * (self.C10 + self.C01 / lam)

    # -- admissibility -----------------------------------------------------------------
    def is_admissible(self, stretch_min: float, stretch_max: float) -> bool:
        """Whether the constants are physical for stretches in a range.

        True when the shape lies in :func:`admissible_shape_range` (energy >= 0,
        monotone uniaxial stress, Baker-Ericksen; module notes), with a relative slack
        of 1e-9 at the ends.

        Parameters
        ----------
        stretch_min, stretch_max : float
            Smallest and largest principal in-plane stretch to handle (> 0).

        Returns
        -------
        bool

        Examples
        --------
        >>> MooneyRivlin(0.114, 0.300).is_admissible(0.6, 1.6)
        True
        >>> MooneyRivlin(-0.3189, 0.5155).is_admissible(0.6, 1.6)  # BE-PAM, Table 3
        False
        """
        return self._violation(stretch_min, stretch_max) is None

    def check_admissible(self, stretch_min: float, stretch_max: float) -> None:
        """Raise :class:`~bendpam.errors.InputError` unless :meth:`is_admissible`.

        The one-line message names the first failing condition (in the order energy,
        uniaxial monotonicity, Baker-Ericksen), the stretches where it fails and the
        admissible shapes.

        Parameters
        ----------
        stretch_min, stretch_max : float
            Smallest and largest principal in-plane stretch to handle (> 0).

        Raises
        ------
        InputError
            If a condition fails somewhere on the range (or the range is invalid).

        Examples
        --------
        >>> MooneyRivlin(0.114, 0.300).check_admissible(0.6, 1.6)
        >>> try:
        ...     MooneyRivlin(1.4853, -1.1968).check_admissible(0.6, 1.6)
        ... except InputError as err:
        ...     print(str(err)[:76])
        Mooney-Rivlin C10 = 1485.3 kPa, C01 = -1196.8 kPa has negative strain energy
        """
        msg = self._violation(stretch_min, stretch_max)
        if msg is not None:
            raise InputError(msg)

    def _label(self) -> str:
        return (
            f"Mooney-Rivlin C10 = {self.C10 * 1e3:.6g} kPa, "
            f"C01 = {self.C01 * 1e3:.6g} kPa"
        )

    def _violation(self, stretch_min: float, stretch_max: float) -> str | None:
        a, b = _span(stretch_min, stretch_max)
        limits = _limits(a, b)
        lo = max(lim.lower for lim in limits)
        hi = min(lim.upper for lim in limits)
        beta = self.shape
        if within(beta, lo, hi):
            return None
        tail = (
            f"admissible shapes beta = C01/(C10 + C01) on stretches [{a:g}, {b:g}] "
            f"are [{lo:.4g}, {hi:.4g}], this material has beta = {beta:.4g}"
        )
        energy, uniaxial, be = limits
        if not within(beta, energy.lower, energy.upper):
            l1, l2, w = _worst_energy(self, a, b)
            return (
                f"{self._label()} has negative strain energy W = {w * 1e3:.4g} kPa at "
                f"principal stretches ({l1:.4g}, {l2:.4g}, {1.0 / (l1 * l2):.4g}); "
                f"{tail}"
            )
        if not within(beta, uniaxial.lower, uniaxial.upper):
            lam = _uniaxial_turning_point(beta, a, b)
            if lam > 1.0:
                where = f"peaks at stretch {lam:.4g} and falls from there to {b:g}"
            else:
                where = f"falls with stretch from {a:g} up to stretch {lam:.4g}"
            return (
                f"{self._label()} is not monotone in uniaxial tension: the nominal "
                f"stress {where}; {tail}"
            )
        # Baker-Ericksen, the only one left: report the extreme s on the failing side
        at = be.lower_at if beta < be.lower else be.upper_at
        s = 1.0 / at.pair_product**2
        factor = 2.0 * (self.C10 + self.C01 * s)
        i, j = at.pair
        return (
            f"{self._label()} violates the Baker-Ericksen inequality "
            f"(sigma_{i} - sigma_{j})(lambda_{i} - lambda_{j}) > 0 at principal "
            f"stretches {at.text}: there (sigma_{i} - sigma_{j})/(lambda_{i}^2 - "
            f"lambda_{j}^2) = 2(C10 + C01/(lambda_{i} lambda_{j})^2) = "
            f"{factor * 1e3:.4g} kPa < 0; {tail}"
        )


# --------------------------------------------------------------------------------------
# admissible shapes
# --------------------------------------------------------------------------------------
@dataclass(frozen=True)
class BindingState:
    """A principal-stretch state where a shape bound is attained.

    Attributes
    ----------
    stretches : tuple of float
        Principal stretches ``(l1, l2, l3)`` with ``l3 = 1/(l1 l2)`` (NaN when the
        bound is infinite).
    pair : tuple of int
        The pair of directions ``(i, j)`` (1-based) a Baker-Ericksen bound concerns.
    limit : bool
        True when the bound is attained only as ``l_i -> l_j`` (near this state).

    Examples
    --------
    >>> uniaxial = shape_limits(0.6, 1.6)[1]
    >>> [round(l, 4) for l in uniaxial.upper_at.stretches]     # uniaxial stretch 1.6
    [1.6, 0.7906, 0.7906]
    """

    stretches: tuple[float, float, float]
    pair: tuple[int, int] = (1, 2)
    limit: bool = False

    @property
    def pair_product(self) -> float:
        """``l_i l_j`` for the pair."""
        i, j = self.pair
        return self.stretches[i - 1] * self.stretches[j - 1]

    @property
    def text(self) -> str:
        """The state as ``(l1, l2, l3)``, prefixed "near" for a limit."""
        body = "(" + ", ".join(f"{v:.4g}" for v in self.stretches) + ")"
        if self.limit:
            return f"near {body} (lambda_{self.pair[0]} -> lambda_{self.pair[1]})"
        return body


@dataclass(frozen=True)
class ShapeLimit:
    """The shapes ``beta`` one condition allows over a range of stretches.

    Attributes
    ----------
    condition : str
        ``"energy"`` (W >= 0), ``"uniaxial"`` (non-decreasing uniaxial nominal stress)
        or ``"baker_ericksen"``.
    lower, upper : float
        The closed interval of admissible shapes (``-inf``/``inf`` when unbounded).
    lower_at, upper_at : BindingState
        Where each bound is attained.
    exact : bool
        True for a closed form, False for the grid computation (the energy condition).

    Examples
    --------
    >>> for lim in shape_limits(0.6, 1.6):
    ...     print(lim.condition, lim.exact)
    energy False
    uniaxial True
    baker_ericksen True
    """

    condition: str
    lower: float
    upper: float
    lower_at: BindingState
    upper_at: BindingState
    exact: bool


_NOWHERE = BindingState((math.nan, math.nan, math.nan))


def _span(stretch_min: Any, stretch_max: Any) -> tuple[float, float]:
    """The validated range, widened to contain 1."""
    a = finite_number("stretch_min", stretch_min, "")
    b = finite_number("stretch_max", stretch_max, "")
    for name, v in (("stretch_min", a), ("stretch_max", b)):
        if v <= 0.0:
            raise InputError(f"{name} = {v:g} is outside the allowed range (0, inf)")
    if a > b:
        raise InputError(
            f"stretch_min = {a:g} is above stretch_max = {b:g}; "
            "expected stretch_min <= stretch_max"
        )
    return min(a, 1.0), max(b, 1.0)


def within(beta: float, lo: float, hi: float) -> bool:
    """``lo <= beta <= hi`` with a relative slack of 1e-9 at each bound (a fit may land on one).

    Examples
    --------
    >>> within(1.0 + 1e-12, 0.0, 1.0), within(1.001, 0.0, 1.0)
    (True, False)
    """
    for name, v in (("beta", beta), ("lo", lo), ("hi", hi)):  # numbers (bounds may be infinite), not NaN
        if np.any(np.isnan(float_array(name, v, "1"))):
            raise InputError(f"{name} = {v!r} is not a number")
    lo_ok = lo - _BOUND_TOL * max(1.0, abs(lo)) <= beta
    return lo_ok and beta <= hi + _BOUND_TOL * max(1.0, abs(hi))


def _grid_states(a: float, b: float) -> tuple[np.ndarray, np.ndarray]:
    """In-plane stretches (l1, l2) of the grid: the square and the uniaxial path."""
    line = np.exp(np.linspace(math.log(a), math.log(b), 241))
    line = np.unique(np.concatenate([line, [1.0]]))
    l1, l2 = np.meshgrid(line, line)
    path = np.exp(np.linspace(math.log(a), math.log(b), 2001))
    return np.concatenate([l1.ravel(), path]), np.concatenate([l2.ravel(), path**-0.5])


def _grid_state(l1: float, l2: float) -> BindingState:
    return BindingState((float(l1), float(l2), float(1.0 / (l1 * l2))))


def _energy_limit(a: float, b: float) -> ShapeLimit:
    l1, l2 = _grid_states(a, b)
    p, q = l1 * l1, l2 * l2
    i1 = p + q + 1.0 / (p * q)
    i2 = 1.0 / p + 1.0 / q + p * q
    e, d = i1 - 3.0, i2 - i1  # W / (mu/2) = e + beta d
    lower, upper = -math.inf, math.inf
    lower_at = upper_at = _NOWHERE
    pos = (d > 1e-10) & (e > 0.0)
    if pos.any():
        r = np.where(pos, -e / np.where(pos, d, 1.0), -np.inf)
        k = int(np.argmax(r))
        lower, lower_at = float(r[k]), _grid_state(l1[k], l2[k])
    neg = (d < -1e-10) & (e > 0.0)
    if neg.any():
        r = np.where(neg, e / np.where(neg, -d, 1.0), np.inf)
        k = int(np.argmin(r))
        upper, upper_at = float(r[k]), _grid_state(l1[k], l2[k])
    return ShapeLimit("energy", lower, upper, lower_at, upper_at, exact=False)


def _q(lam: float) -> float:
    return lam**4 + 2.0 * lam - 3.0


def _uniaxial_limit(a: float, b: float) -> ShapeLimit:
    lower, lower_at = -math.inf, _NOWHERE
    upper, upper_at = math.inf, _NOWHERE
    if a < 1.0:
        lower, lower_at = 1.0 + 3.0 / _q(a), BindingState((a, a**-0.5, a**-0.5))
    if b > 1.0:
        upper, upper_at = 1.0 + 3.0 / _q(b), BindingState((b, b**-0.5, b**-0.5))
    return ShapeLimit("uniaxial", lower, upper, lower_at, upper_at, exact=True)


def _baker_ericksen_limit(a: float, b: float) -> ShapeLimit:
    # s = 1/(l_i l_j)^2 over all pairs: its extremes and where they occur (module notes)
    s_max, at_max = max(
        (b * b, BindingState((b, 1.0, 1.0 / b), (2, 3))),
        (a**-4, BindingState((a, a, a**-2), (1, 2), limit=True)),
        key=lambda t: t[0],
    )
    s_min, at_min = min(
        (a * a, BindingState((a, 1.0, 1.0 / a), (2, 3))),
        (b**-4, BindingState((b, b, b**-2), (1, 2), limit=True)),
        key=lambda t: t[0],
    )
    lower, lower_at = -math.inf, _NOWHERE
    upper, upper_at = math.inf, _NOWHERE
    if s_max > 1.0:
        lower, lower_at = -1.0 / (s_max - 1.0), at_max
    if s_min < 1.0:
        upper, upper_at = 1.0 / (1.0 - s_min), at_min
    return ShapeLimit("baker_ericksen", lower, upper, lower_at, upper_at, exact=True)


@lru_cache(maxsize=512)
def _limits(a: float, b: float) -> tuple[ShapeLimit, ShapeLimit, ShapeLimit]:
    if a == b:  # only the undeformed state: nothing constrains the shape
        inf = math.inf
        return (
            ShapeLimit("energy", -inf, inf, _NOWHERE, _NOWHERE, exact=True),
            ShapeLimit("uniaxial", -inf, inf, _NOWHERE, _NOWHERE, exact=True),
            ShapeLimit("baker_ericksen", -inf, inf, _NOWHERE, _NOWHERE, exact=True),
        )
    return _energy_limit(a, b), _uniaxial_limit(a, b), _baker_ericksen_limit(a, b)


def _worst_energy(m: MooneyRivlin, a: float, b: float) -> tuple[float, float, float]:
    l1, l2 = _grid_states(a, b)
    w = m.energy(l1, l2)
    k = int(np.argmin(w))
    return float(l1[k]), float(l2[k]), float(w[k])


def _uniaxial_turning_point(beta: float, a: float, b: float) -> float:
    """Stretch where ``dP/dl = 0`` for a shape outside the uniaxial interval."""
    target = 3.0 / (beta - 1.0)  # q(l) = target there
    lo, hi = (1.0, b) if beta > 1.0 else (a, 1.0)
    from scipy.optimize import brentq

    return float(brentq(lambda x: _q(x) - target, lo, hi, xtol=1e-14))


def shape_limits(
    stretch_min: float, stretch_max: float
) -> tuple[ShapeLimit, ShapeLimit, ShapeLimit]:
    """Per-condition admissible shapes over a range of stretches.

    Parameters
    ----------
    stretch_min, stretch_max : float
        Smallest and largest principal in-plane stretch (> 0); the range is widened
        to contain 1.

    Returns
    -------
    tuple of ShapeLimit
        Energy, uniaxial monotonicity and Baker-Ericksen, in that order (module notes).

    Examples
    --------
    >>> for lim in shape_limits(0.6, 1.6)[1:]:
    ...     print(lim.condition, round(lim.lower, 4), round(lim.upper, 4))
    uniaxial -0.796 1.4442
    baker_ericksen -0.1489 1.1801
    """
    return _limits(*_span(stretch_min, stretch_max))


def admissible_shape_range(
    stretch_min: float, stretch_max: float
) -> tuple[float, float]:
    """The shapes ``beta = C01/(C10 + C01)`` that are physical over a stretch range.

    For ``mu > 0``, a Mooney-Rivlin material with shape ``beta`` has non-negative strain
    energy, a non-decreasing uniaxial nominal stress and satisfies the Baker-Ericksen
    inequalities for every deformation with principal in-plane stretches in
    ``[stretch_min, stretch_max]`` (biaxial square, equibiaxial, uniaxial; module
    notes) exactly when ``beta_lo <= beta <= beta_hi``.  The interval contains
    ``[0, 1]``.

    Parameters
    ----------
    stretch_min, stretch_max : float
        Smallest and largest principal in-plane stretch (> 0, min <= max).  The range
        is widened to contain 1 (the undeformed state).

    Returns
    -------
    (float, float)
        ``(beta_lo, beta_hi)``; infinite only for the degenerate range ``[1, 1]``.  The
        bounds are closed forms (uniaxial, Baker-Ericksen); the energy interval,
        computed on a grid, is implied by Baker-Ericksen and never binds.

    Raises
    ------
    InputError
        For a non-finite or non-positive stretch, or ``stretch_min > stretch_max``.

    Examples
    --------
    >>> lo, hi = admissible_shape_range(0.6, 1.6)
    >>> round(lo, 4), round(hi, 4)
    (-0.1489, 1.1801)

    By hand: ``s_max = 0.6^-4`` and ``s_min = 1.6^-4`` (Baker-Ericksen):

    >>> round(-1 / (0.6**-4 - 1), 4), round(1 / (1 - 1.6**-4), 4)
    (-0.1489, 1.1801)
    """
    limits = shape_limits(stretch_min, stretch_max)
    return max(lim.lower for lim in limits), min(lim.upper for lim in limits)
