"""Targets and design variables of the inverse design (:func:`bendpam.design.inverse.design_actuator`).

A target is ``NAME=VALUE@P``, ``NAME>=VALUE@P`` or ``NAME<=VALUE@P`` with ``P`` in kPa (the fold or
lock-up pressure ``max_pressure_kpa`` takes no ``@``), on one of the :data:`QUANTITIES`, and
compares magnitudes (:class:`Target`); a variable is an actuator field varied within a range,
``NAME=LOW:HIGH`` (:class:`Variable`).  Bad texts raise a one-line :class:`bendpam.InputError`.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from bendpam.errors import InputError
from bendpam.physics.actuator import NEUTRAL_ANGLE_DEG, Actuator
from bendpam.sweeps import SWEEP_PARAMETERS, build_cases
from bendpam.validate import did_you_mean

__all__ = [
    "DESIGN_VARIABLES",
    "NAN_MISS",
    "QUANTITIES",
    "TOL",
    "Target",
    "Variable",
    "parse_targets",
    "parse_variables",
]

#: Quantities a target may name: unit, meaning, and whether it is taken at a pressure (``@P``).
QUANTITIES: dict[str, tuple[str, str, bool]] = {
    "blocked_moment_nmm": ("N*mm", "blocked moment |M(P, 0)|", True),
    "free_curvature_per_mm": ("1/mm", "free-bending curvature |k'|", True),
    "free_angle_deg": ("deg", "free-bending angle |k'| L0", True),
    "tangent_stiffness_nmm2": ("N*mm^2", "|dM/dk'| at the free-bending equilibrium", True),
    "blocked_stiffness_nmm2": ("N*mm^2", "|dM/dk'| at k' = 0 (held straight)", True),
    "blocked_tip_force_n": ("N", "force holding a finger's tip at its straight position", True),
    "frame_stress_mpa": ("MPa", "largest frame stress (blocked or free)", True),
    "max_pressure_kpa": ("kPa", "fold or lock-up pressure (end of the free-bending branch)", False),
}

#: Actuator fields that may be varied (every numeric field that changes a prediction).
DESIGN_VARIABLES = SWEEP_PARAMETERS

#: the relative miss of a quantity that does not exist (no equilibrium at the pressure)
NAN_MISS = 2.0
#: a target is met within 0.1 %, a margin to 0.1 % of the required value
TOL = 1e-3

_SENSES = (">=", "<=", "=")
_TARGET_RE = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(>=|<=|==|=)\s*([^@]*?)\s*(?:@\s*(.*?)\s*)?$")
_MISS_CAP = 10.0  # a relative miss is clipped to +-10 (an unbounded branch against an '=' target)


def _finite_number(text: str) -> float | None:
    try:
        v = float(text)
    except ValueError:
        return None
    return v if math.isfinite(v) else None


@dataclass(frozen=True)
class Target:
    """One design target: ``|quantity| sense value`` at ``pressure_kpa``.

    Parameters
    ----------
    quantity : a key of :data:`QUANTITIES`.
    sense : ``"="``, ``">="`` or ``"<="``.
    value : the target, > 0, in the quantity's unit (compared with the magnitude).
    pressure_kpa : the gauge pressure, kPa, > 0; ``None`` for ``max_pressure_kpa``.

    Examples
    --------
    >>> t = Target.parse("free_angle_deg>=90@200")
    >>> t.quantity, t.sense, t.value, t.pressure_kpa, t.key
    ('free_angle_deg', '>=', 90.0, 200.0, 'free_angle_deg@200kpa')
    >>> float(t.miss(np.array([81.0]))[0])
    -0.1
    """

    quantity: str
    sense: str
    value: float
    pressure_kpa: float | None = None

    def __post_init__(self) -> None:
        self._check("target")

    def _check(self, label: str) -> None:
        where = f"{label} {self.text!r}" if self.quantity in QUANTITIES else label
        if self.quantity not in QUANTITIES:
            raise InputError(f"{label}: unknown quantity {self.quantity!r}{did_you_mean(self.quantity, QUANTITIES)}; "
                             f"allowed: {', '.join(QUANTITIES)}")
        if self.sense not in _SENSES:
            raise InputError(f"{where}: comparison {self.sense!r} is not allowed; use =, >= or <=")
        v = self.value
        if isinstance(v, bool) or not isinstance(v, int | float | np.floating | np.integer) or not (
                math.isfinite(v) and v > 0):
            raise InputError(f"{where}: the value must be a finite number > 0 (targets compare magnitudes)")
        at_p = QUANTITIES[self.quantity][2]
        if at_p and self.pressure_kpa is None:
            raise InputError(f"{where}: {self.quantity} is taken at a pressure: add @P (kPa), e.g. "
                             f"{self.quantity}{self.sense}{self.value:g}@200")
        if not at_p and self.pressure_kpa is not None:
            raise InputError(f"{where}: {self.quantity} is not taken at a pressure; drop the @")
        if self.pressure_kpa is not None:
            p = self.pressure_kpa
            if isinstance(p, bool) or not isinstance(p, int | float | np.floating | np.integer) or not (
                    math.isfinite(p) and 0 < p <= 10_000):
                raise InputError(f"{where}: the pressure after @ must be in (0, 10000] kPa")
        object.__setattr__(self, "value", float(v))
        if self.pressure_kpa is not None:
            object.__setattr__(self, "pressure_kpa", float(self.pressure_kpa))

    @classmethod
    def parse(cls, text: str, label: str = "target") -> Target:
        """``NAME=VALUE@P``, ``NAME>=VALUE@P`` or ``NAME<=VALUE@P`` (P in kPa; no @ for max_pressure_kpa).

        A bad text raises a one-line :class:`~bendpam.errors.InputError` starting ``label 'text':``.
        """
        s = str(text)
        m = _TARGET_RE.match(s)
        if not m:
            raise InputError(f"{label} {s!r}: expected NAME=VALUE@P, NAME>=VALUE@P or NAME<=VALUE@P "
                             f"(P in kPa), e.g. blocked_moment_nmm=400@200")
        name, sense, val, at = m.groups()
        sense = "=" if sense == "==" else sense
        if name not in QUANTITIES:
            raise InputError(f"{label} {s!r}: unknown quantity {name!r}{did_you_mean(name, QUANTITIES)}; "
                             f"allowed: {', '.join(QUANTITIES)}")
        v = _finite_number(val)
        if v is None:
            raise InputError(f"{label} {s!r}: the value {val!r} is not a finite number")
        p = None
        if at is not None:
            at_s = at[:-3].strip() if at.lower().endswith("kpa") else at
            p = _finite_number(at_s)
            if p is None:
                raise InputError(f"{label} {s!r}: the pressure {at!r} after @ is not a finite number (kPa)")
        t = object.__new__(cls)
        for k, x in (("quantity", name), ("sense", sense), ("value", v), ("pressure_kpa", p)):
            object.__setattr__(t, k, x)
        try:
            t._check(label)
        except InputError as exc:
            msg = str(exc)
            prefix = f"{label} {t.text!r}"
            raise InputError(f"{label} {s!r}{msg[len(prefix):]}" if msg.startswith(prefix) else msg) from None
        return t

    @property
    def text(self) -> str:
        """The canonical text, e.g. ``free_angle_deg>=90@200``."""
        at = "" if self.pressure_kpa is None else f"@{self.pressure_kpa:g}"
        return f"{self.quantity}{self.sense}{self.value:g}{at}"

    @property
    def key(self) -> str:
        """A column name for the quantity at its pressure, e.g. ``free_angle_deg@200kpa``."""
        return self.quantity if self.pressure_kpa is None else f"{self.quantity}@{self.pressure_kpa:g}kpa"

    @property
    def unit(self) -> str:
        return QUANTITIES[self.quantity][0]

    @property
    def label(self) -> str:
        """An axis label in words, e.g. ``free-bending angle |k'| L0 at 200 kPa (deg)``."""
        at = "" if self.pressure_kpa is None else f" at {self.pressure_kpa:g} kPa"
        return f"{QUANTITIES[self.quantity][1]}{at} ({self.unit})"

    @property
    def larger_is_better(self) -> bool:
        """The Pareto sense: larger is better for ``>=`` and ``=``, smaller for ``<=``."""
        return self.sense != "<="

    def miss(self, q: np.ndarray) -> np.ndarray:
        """Relative miss of magnitudes ``q``: 0 when met, else ``q/value - 1`` (clipped to +-10; NaN -> 2)."""
        q = np.asarray(q, dtype=float)
        with np.errstate(invalid="ignore", over="ignore"):
            r = np.clip(q / self.value - 1.0, -_MISS_CAP, _MISS_CAP)
        if self.sense == ">=":
            r = np.minimum(r, 0.0)
        elif self.sense == "<=":
            r = np.maximum(r, 0.0)
        return np.where(np.isnan(q), NAN_MISS, r)

    def slack(self, q: np.ndarray) -> np.ndarray:
        """Smooth constraint form: ``q/value - 1`` (``=``, ``>=``; ``>= 0`` when met) or ``1 - q/value`` (``<=``)."""
        q = np.asarray(q, dtype=float)
        with np.errstate(invalid="ignore", over="ignore"):
            r = np.clip(q / self.value - 1.0, -_MISS_CAP, _MISS_CAP)
        if self.sense == "<=":
            r = -r
        return np.where(np.isnan(q), -NAN_MISS, r)


@dataclass(frozen=True)
class Variable:
    """A design variable: an actuator field varied within ``[low, high]`` (units in the name).

    >>> Variable.parse("alpha0_deg=60:80")
    Variable(name='alpha0_deg', low=60.0, high=80.0)
    """

    name: str
    low: float
    high: float

    def __post_init__(self) -> None:
        self._check("vary", f"{self.name}={self.low:g}:{self.high:g}")

    def _check(self, label: str, text: str) -> None:
        if self.name == "braid_thickness_mm":
            raise InputError(f"{label} {text!r}: braid_thickness_mm changes no predicted quantity (it cancels out of "
                             f"the moment); vary one of: {', '.join(DESIGN_VARIABLES)}")
        if self.name not in DESIGN_VARIABLES:
            raise InputError(f"{label} {text!r}: {self.name!r} is not a numeric actuator parameter"
                             f"{did_you_mean(self.name, DESIGN_VARIABLES)}; vary one of: {', '.join(DESIGN_VARIABLES)}")
        for v in (self.low, self.high):
            if isinstance(v, bool) or not isinstance(v, int | float | np.floating | np.integer) or not math.isfinite(v):
                raise InputError(f"{label} {text!r}: the range ends must be finite numbers")
        if not self.low < self.high:
            raise InputError(f"{label} {text!r}: the range must be LOW:HIGH with LOW < HIGH")
        object.__setattr__(self, "low", float(self.low))
        object.__setattr__(self, "high", float(self.high))

    @classmethod
    def parse(cls, text: str, label: str = "vary") -> Variable:
        """``NAME=LOW:HIGH`` (units in the name); a one-line InputError starting ``label 'text':`` if bad."""
        s = str(text)
        name, sep, rng = s.partition("=")
        bits = rng.split(":")
        if not sep or len(bits) != 2:
            raise InputError(f"{label} {s!r}: expected NAME=LOW:HIGH, e.g. alpha0_deg=60:80")
        lo, hi = _finite_number(bits[0]), _finite_number(bits[1])
        if lo is None or hi is None:
            raise InputError(f"{label} {s!r}: LOW and HIGH must be finite numbers, e.g. alpha0_deg=60:80")
        v = object.__new__(cls)
        for k, x in (("name", name.strip()), ("low", lo), ("high", hi)):
            object.__setattr__(v, k, x)
        v._check(label, s)
        return v

    @property
    def text(self) -> str:
        return f"{self.name}={self.low:g}:{self.high:g}"


def parse_targets(targets: Iterable[Target | str], label: str = "target") -> tuple[Target, ...]:
    """Targets from :class:`Target` objects or texts; duplicates refused (one line each).

    >>> [t.key for t in parse_targets(["blocked_moment_nmm=400@200", "max_pressure_kpa>=250"])]
    ['blocked_moment_nmm@200kpa', 'max_pressure_kpa']
    """
    if isinstance(targets, str | Target):
        targets = [targets]
    out = tuple(t if isinstance(t, Target) else Target.parse(t, label) for t in targets)
    if not out:
        raise InputError(f"give at least one {label}, e.g. blocked_moment_nmm=400@200")
    seen = set()
    for t in out:
        k = (t.key, t.sense)
        if k in seen:
            raise InputError(f"{label} {t.text!r}: the same quantity, pressure and comparison is given twice")
        seen.add(k)
    return out


def parse_variables(base: Actuator, vary: Iterable[Variable | str] | Mapping[str, Sequence[float]],
                    label: str = "vary") -> tuple[Variable, ...]:
    """Variables from :class:`Variable` objects, texts or ``{name: (low, high)}``, checked against ``base``.

    Every design in the box of ranges must be a valid actuator (each end alone, then the
    corners for the parameters that constrain each other: ``t0_mm < R0_mm``, ``R0_start_mm >=
    R0_mm``, ``C10_kpa + C01_kpa > 0``), and a braid-angle range may not contain the neutral
    angle 54.74 deg.

    >>> from bendpam.physics.presets import be_pam
    >>> parse_variables(be_pam(), {"alpha0_deg": (60, 80), "R0_mm": (7, 10)})
    (Variable(name='alpha0_deg', low=60.0, high=80.0), Variable(name='R0_mm', low=7.0, high=10.0))
    """
    if isinstance(vary, Mapping):
        items: list[Variable] = []
        for k, r in vary.items():
            try:
                lo, hi = r
            except (TypeError, ValueError):
                raise InputError(f"{label} {k!r}: give the range as (low, high)") from None
            items.append(Variable(str(k), lo, hi))
    else:
        if isinstance(vary, str | Variable):
            vary = [vary]
        items = [v if isinstance(v, Variable) else Variable.parse(v, label) for v in vary]
    if not items:
        raise InputError(f"give at least one {label} range, e.g. alpha0_deg=60:80")
    names = [v.name for v in items]
    dup = [n for n in names if names.count(n) > 1]
    if dup:
        raise InputError(f"{label} {dup[0]}: the parameter is given twice")
    for v in items:
        if v.name == "alpha0_deg" and v.low < NEUTRAL_ANGLE_DEG < v.high:
            raise InputError(f"{label} {v.text!r}: the range contains the neutral braid angle 54.74 deg, where the "
                             "bending direction flips; keep it above (BE-PAM) or below (BC-PAM)")
        for end in (v.low, v.high):
            try:
                build_cases(base, {v.name: np.array([end])})
            except InputError as exc:
                raise InputError(f"{label} {v.text!r}: {exc}") from None
    n = len(items)
    if n <= 12:
        corners = np.array(np.meshgrid(*([0.0, 1.0],) * n, indexing="ij")).reshape(n, -1)
        vals = {v.name: v.low + corners[j] * (v.high - v.low) for j, v in enumerate(items)}
        try:
            build_cases(base, vals)
        except InputError as exc:
            raise InputError(f"{label} {', '.join(v.text for v in items)}: {exc} at a corner of the ranges; "
                             "narrow the ranges so that every combination is a valid actuator") from None
    return tuple(items)
