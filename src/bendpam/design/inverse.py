"""Inverse design of a bending PAM: actuator parameters chosen to meet targets on its predictions.

``design_actuator(base, targets, vary)`` searches the actuator parameters in ``vary`` (each within
a range) for the design whose predicted behaviour meets ``targets`` (equalities or bounds at
given pressures) while every safety margin stays above ``min_margin`` up to the operating
pressure.  The command line is ``bendpam design``.

Targets
    ``NAME=VALUE@P``, ``NAME>=VALUE@P`` or ``NAME<=VALUE@P`` with ``P`` in kPa (the fold or
    lock-up pressure ``max_pressure_kpa`` takes no ``@``).  The quantities (:data:`QUANTITIES`):

    * ``blocked_moment_nmm``: ``|M(P, 0)|``, N*mm;
    * ``free_curvature_per_mm``, ``free_angle_deg``: ``|k'|`` and ``|k'| L0`` at the free-bending
      equilibrium on the branch connected to the straight state (none above the fold);
    * ``tangent_stiffness_nmm2``: ``|dM/dk'|`` at the free-bending equilibrium, N*mm^2: the
      moment per unit curvature a load needs to bend the free actuator further (its small-load
      bending stiffness); ``blocked_stiffness_nmm2``: the same at ``k' = 0`` (held straight).
      Both from :meth:`bendpam.MomentLaw.tangent_stiffness`;
    * ``blocked_tip_force_n``: the force that holds the tip of a finger made of the actuator
      (base clamped, no fingertip) at its straight position, along the normal to the finger, N,
      as :func:`bendpam.design.blocked_tip_force` computes it;
    * ``frame_stress_mpa``: the frame stress at free bending (the sweep kernel's output), MPa;
    * ``max_pressure_kpa``: the highest pressure with a free-bending equilibrium (fold or
      lock-up pressure; ``inf`` when unbounded), kPa.

    **Targets compare magnitudes.**  In the paper's convention a BC-PAM's blocked moment and
    free curvature are negative (it bends away from the frame); a target is written with a
    positive value and compared with ``|quantity|``, so ``blocked_moment_nmm=300@150`` asks a
    BC-PAM for ``M(150 kPa, 0) = -300 N*mm``.  For the same reason a braid-angle range may not
    contain the neutral angle 54.74 deg, where the bending direction flips.

Constraints
    Every safety margin of the sweep kernel (:func:`bendpam.sweeps.evaluate_cases`: the outputs
    whose names end in ``_margin``, factors capacity/demand, ``inf`` with no demand) must be at
    least ``min_margin`` at every pressure up to the operating pressure ``max_pressure_kpa``
    (default: the highest target pressure), and so must the pressure margin
    ``P_end / max_pressure_kpa`` of the free-bending branch's end (fold or lock-up).  A pressure
    without a free-bending equilibrium fails every margin.

The search
    1. Coarse map: a scrambled Sobol sample of ``n_coarse`` designs over the box of ranges (the
       vectorised sweep kernel, blocks of 256 designs at all the pressures at once).  With
       ``scheduler`` the coarse map is a factorial grid of about ``n_coarse`` designs computed
       by :func:`bendpam.sweep` on that Dask cluster (the sweeps' distributed path works on grids).
    2. Local stage from the ``n_starts`` best distinct designs of the map: bounded least squares
       (``scipy.optimize.least_squares``, trust-region reflective) on the normalised misses of
       the targets and of the margins; the Jacobian is a forward difference whose ``n + 1``
       designs are evaluated as one block of the kernel.
    3. Among the designs that meet every target and margin, the best one has the largest
       smallest safety margin (SLSQP: maximise ``s`` with ``ln(margin / min_margin) >= s`` for
       every margin, targets as constraints); when no design meets them all, the best is the
       closest one (smallest sum of squared relative misses, margins weighted 30x so that it keeps them
       when it can), and the
       result says which targets bind: those out of reach even alone, else those whose removal
       lets the others be met (or the safety limits, when the targets can be met without them).

    ``blocked_tip_force_n`` is costly (a finger solve, about 20-40 ms); the search uses the
    small-deflection closed form ``F = 3 |M(P, 0)| / (2 L0)`` (a uniform moment ``M0`` and a
    tip force ``F`` normal to a cantilever give a tip deflection ``M0 L^2 / 2EI - F L^3 / 3EI``,
    zero for ``F = 3 M0 / 2L`` whatever the stiffness; within 1-5 % of the finger solution for
    the paper's actuators), corrected by the ratio of the finger solution to the closed form,
    recomputed at each start and at the optimum until it settles (space mapping), so the final
    design meets the target on the finger solution itself.

Pareto front
    With exactly two targets (``pareto=None``, or forced with ``pareto=True``), the
    non-dominated designs in those two quantities among the designs that satisfy every margin:
    for a ``>=`` or ``=`` target larger is better, for ``<=`` smaller is better.  The coarse
    map's non-dominated designs are refined by three rounds of 512 designs drawn around them
    (in shrinking cubes clipped to the box, so that fronts lying on the box's faces are found).

Results are deterministic for a given ``seed``.
"""

from __future__ import annotations

import math
import re
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.errors import BendpamError, InputError
from bendpam.infra.atomic import atomic_write_text
from bendpam.physics.actuator import NEUTRAL_ANGLE_DEG, Actuator
from bendpam.physics.law import MomentLaw
from bendpam.physics.models import normalise_model
from bendpam.sweeps import SWEEP_PARAMETERS, build_cases, evaluate_cases
from bendpam.validate import did_you_mean

__all__ = [
    "DESIGN_VARIABLES",
    "QUANTITIES",
    "DesignResult",
    "ParetoFront",
    "Target",
    "Variable",
    "design_actuator",
    "parse_targets",
    "parse_variables",
    "plot_coarse_map",
    "plot_pareto",
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

_SENSES = (">=", "<=", "=")
_TARGET_RE = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_]*)\s*(>=|<=|==|=)\s*([^@]*?)\s*(?:@\s*(.*?)\s*)?$")
_KERNEL_2D = ("blocked_moment_nmm", "free_curvature_per_mm", "free_angle_deg", "frame_stress_mpa")
_STIFFNESS = ("tangent_stiffness_nmm2", "blocked_stiffness_nmm2")
_FD_STEP = 1e-6  # forward-difference step in the unit box
_MISS_CAP = 10.0  # a relative miss is clipped to +-10 (an unbounded branch against an '=' target)
_NAN_MISS = 2.0  # the miss of a quantity that does not exist (no equilibrium at the pressure)
_W_CONSTRAINT = 30.0  # weight of the margins' misses in the least squares (the closest design keeps them)
_MARGIN_CAP = 1e3  # margins above this count as "no demand" in the max-min objective
_TOL = 1e-3  # a target is met within 0.1 %, a margin to 0.1 % of the required value
_BLOCK = 256  # designs per block of the coarse map


def _finite_number(text: str) -> float | None:
    try:
        v = float(text)
    except ValueError:
        return None
    return v if math.isfinite(v) else None


# ------------------------------------------------------------------------------------------------
# targets and variables
# ------------------------------------------------------------------------------------------------
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
        return np.where(np.isnan(q), _NAN_MISS, r)

    def slack(self, q: np.ndarray) -> np.ndarray:
        """Smooth constraint form: ``q/value - 1`` (``=``, ``>=``; ``>= 0`` when met) or ``1 - q/value`` (``<=``)."""
        q = np.asarray(q, dtype=float)
        with np.errstate(invalid="ignore", over="ignore"):
            r = np.clip(q / self.value - 1.0, -_MISS_CAP, _MISS_CAP)
        if self.sense == "<=":
            r = -r
        return np.where(np.isnan(q), -_NAN_MISS, r)


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
    """Targets from :class:`Target` objects or texts; duplicates refused (one line each)."""
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


# ------------------------------------------------------------------------------------------------
# the problem: evaluation of blocks of designs
# ------------------------------------------------------------------------------------------------
class _Problem:
    """Targets, variables and margins of one design problem; evaluates blocks of designs."""

    def __init__(self, base: Actuator, model: str, targets: tuple[Target, ...], variables: tuple[Variable, ...],
                 max_pressure_kpa: float | None, min_margin: float, seed: int = 0):
        self.base = base
        self.model = model
        self.targets = targets
        self.variables = variables
        self.lo = np.array([v.low for v in variables])
        self.hi = np.array([v.high for v in variables])
        self.min_margin = float(min_margin)
        tp = sorted({t.pressure_kpa for t in targets if t.pressure_kpa is not None})
        if max_pressure_kpa is not None and tp and tp[-1] > max_pressure_kpa:
            bad = next(t for t in targets if t.pressure_kpa is not None and t.pressure_kpa > max_pressure_kpa)
            raise InputError(f"target {bad.text!r}: its pressure is above the operating pressure "
                             f"max_pressure_kpa = {max_pressure_kpa:g} kPa")
        self.p_op = float(max_pressure_kpa) if max_pressure_kpa is not None else (tp[-1] if tp else None)
        grid = [] if self.p_op is None else [self.p_op * f for f in (0.25, 0.5, 0.75, 1.0)]
        P = sorted(set(tp) | set(grid))
        self.margin_pressures = np.array(sorted(set(grid) | set(tp)), dtype=float)
        self.P = np.array(P if P else [100.0], dtype=float)  # a placeholder pressure when none is needed
        self.ip = {float(p): i for i, p in enumerate(self.P)}
        self.op_mask = np.isin(self.P, self.margin_pressures) if self.p_op is not None else np.zeros(self.P.size, bool)
        self.tip_factor = np.ones(len(targets))  # space-mapping correction of the tip-force closed form
        self.version = 0
        self._cache: dict[bytes, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        self.margin_names: list[str] = []
        self.n_evaluations = 0
        self.rng = np.random.default_rng(seed)

    # ---- designs --------------------------------------------------------------------------------
    def x_of(self, U: np.ndarray) -> np.ndarray:
        return self.lo + np.asarray(U, dtype=float) * (self.hi - self.lo)

    def values(self, X: np.ndarray) -> dict[str, np.ndarray]:
        X = np.atleast_2d(X)
        return {v.name: X[:, j].copy() for j, v in enumerate(self.variables)}

    def actuator(self, x: np.ndarray, name: str = "") -> Actuator:
        """The Actuator at ``x`` (R0_start_mm follows R0_mm as in :func:`bendpam.sweeps.build_cases`)."""
        ch: dict[str, Any] = {v.name: float(x[j]) for j, v in enumerate(self.variables)}
        if "R0_mm" in ch and "R0_start_mm" not in ch:
            ch["R0_start_mm"] = ch["R0_mm"] * (float(self.base.params.R0_start) / self.base.R0_mm)
        ch["model"] = self.model
        ch["name"] = name
        return self.base.replace(**ch)

    # ---- evaluation -----------------------------------------------------------------------------
    def kernel(self, X: np.ndarray) -> dict[str, np.ndarray]:
        self.n_evaluations += len(X)
        return evaluate_cases(self.base, self.model, self.values(X), self.P)

    def assemble(self, X: np.ndarray, r: Mapping[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        """Target quantities ``(m, n_targets)`` and margins ``(m, n_margins)`` from kernel outputs ``r``."""
        X = np.atleast_2d(X)
        m = len(X)
        vals = self.values(X)
        q = np.empty((m, len(self.targets)))
        law_cases = None
        for i, t in enumerate(self.targets):
            if t.pressure_kpa is None:  # max_pressure_kpa
                q[:, i] = r["max_pressure_kpa"]
                continue
            P = t.pressure_kpa
            j = self.ip[P]
            if t.quantity in _KERNEL_2D:
                q[:, i] = np.abs(np.asarray(r[t.quantity])[:, j])
            elif t.quantity == "blocked_tip_force_n":
                L0 = vals.get("L0_mm", np.full(m, self.base.L0_mm))
                q[:, i] = 1.5 * np.abs(np.asarray(r["blocked_moment_nmm"])[:, j]) / L0 * self.tip_factor[i]
            else:
                if law_cases is None:
                    law_cases = build_cases(self.base, vals)
                k = (np.asarray(r["free_curvature_per_mm"])[:, j] if t.quantity == "tangent_stiffness_nmm2"
                     else np.zeros(m))
                q[:, i] = _stiffness(law_cases, self.model, P, k)
        return q, self._margins(r)

    def _margins(self, r: Mapping[str, np.ndarray]) -> np.ndarray:
        names = [k for k in r if k.endswith("_margin") and k != "min_margin" and np.ndim(r[k]) == 2]
        cols = []
        n = len(next(iter(r.values())))
        if self.p_op is None:  # no pressure to hold the margins at (only a fold/lock-up pressure target)
            self.margin_names = []
            return np.empty((n, 0))
        for k in names:
            v = np.asarray(r[k], dtype=float)[:, self.op_mask]
            cols.append(v.min(axis=1) if v.shape[1] else np.full(n, np.inf))
        if self.p_op is not None:
            names = [*names, "pressure_margin"]
            cols.append(np.asarray(r["max_pressure_kpa"], dtype=float) / self.p_op)
        self.margin_names = names
        return np.column_stack(cols) if cols else np.empty((n, 0))

    def evaluate(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        X = np.atleast_2d(X)
        return self.assemble(X, self.kernel(X))

    def block(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``u`` and its ``n`` one-sided difference neighbours as one block: (q, margins, steps).

        A step that crosses a jump (a fold born at a finite pressure, an equilibrium that
        disappears: a relative change over 1 % or a change of finiteness) is taken to the other
        side instead, so that the differences describe the side of ``u`` that is smooth.
        """
        u = np.asarray(u, dtype=float)
        key = u.tobytes() + self.version.to_bytes(4, "little")
        hit = self._cache.get(key)
        if hit is not None:
            return hit
        n = u.size
        h = np.where(u + _FD_STEP <= 1.0, _FD_STEP, -_FD_STEP)
        U = np.vstack([u, u + np.diag(h)])
        q, mg = self.evaluate(self.x_of(U))
        jump = _jumps(np.hstack([q, mg]))
        if np.any(jump):
            j = np.flatnonzero(jump)
            hb = -h[j]
            ok = (u[j] + hb >= 0.0) & (u[j] + hb <= 1.0)
            j, hb = j[ok], hb[ok]
            if j.size:
                Ub = np.tile(u, (j.size, 1))
                Ub[np.arange(j.size), j] += hb
                qb, mgb = self.evaluate(self.x_of(Ub))
                better = ~_jumps(np.vstack([np.hstack([q[:1], mg[:1]]), np.hstack([qb, mgb])]))
                for r in np.flatnonzero(better):
                    q[j[r] + 1], mg[j[r] + 1], h[j[r]] = qb[r], mgb[r], hb[r]
        if len(self._cache) > 256:
            self._cache.clear()
        self._cache[key] = (q, mg, h)
        assert len(q) == n + 1
        return q, mg, h

    def set_tip_factor(self, f: np.ndarray) -> None:
        self.tip_factor = np.asarray(f, dtype=float)
        self.version += 1

    # ---- residuals ------------------------------------------------------------------------------
    def rows(self, q: np.ndarray, mg: np.ndarray, sel: Sequence[int], constraints: bool = True) -> np.ndarray:
        """Least-squares residuals: target misses (``sel``) then weighted margin misses."""
        parts = [self.targets[i].miss(q[:, i])[:, None] for i in sel]
        if constraints and mg.shape[1]:
            parts.append(_W_CONSTRAINT * self.margin_miss(mg))
        return np.hstack(parts) if parts else np.zeros((len(q), 0))

    def margin_miss(self, mg: np.ndarray) -> np.ndarray:
        with np.errstate(invalid="ignore"):
            r = np.minimum(mg / self.min_margin - 1.0, 0.0)
        return np.where(np.isnan(mg), -_NAN_MISS, r)

    def violation(self, q: np.ndarray, mg: np.ndarray, sel: Sequence[int], constraints: bool = True) -> np.ndarray:
        """The largest relative miss of a target or margin, per design."""
        parts = [np.abs(self.targets[i].miss(q[:, i])) for i in sel]
        if constraints and mg.shape[1]:
            parts.extend(np.abs(self.margin_miss(mg)).T)
        return np.max(np.vstack(parts), axis=0) if parts else np.zeros(len(q))

    def log_margin(self, mg: np.ndarray) -> np.ndarray:
        """``ln(min(margin, cap) / min_margin)`` per margin (NaN: no equilibrium -> very negative)."""
        m = np.where(np.isnan(mg), 1e-6, np.clip(mg, 1e-6, _MARGIN_CAP))
        return np.log(m / self.min_margin)

    def objective(self, mg: np.ndarray) -> np.ndarray:
        """The smallest log margin per design (capped: designs with no finite margin score ln(cap/min))."""
        if not mg.shape[1]:
            return np.zeros(len(mg))
        return self.log_margin(mg).min(axis=1)


def _jumps(V: np.ndarray) -> np.ndarray:
    """Rows 1.. of ``V`` that differ from row 0 by a jump (over 1 % relative, or in finiteness)."""
    a, b = V[:1], V[1:]
    fa, fb = np.isfinite(a), np.isfinite(b)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        rel = np.abs(b - a) / np.maximum(np.abs(a), 1e-300)
    return np.any((fa != fb) | (fa & fb & (rel > 1e-2)), axis=1)


def _stiffness(cases, model: str, P: float, k: np.ndarray) -> np.ndarray:
    """``|dM/dk'|`` (N*mm^2) of each case at pressure ``P`` and curvature ``k`` (NaN where k is NaN).

    One law for the whole block; should a curvature be refused, the cases are taken one by one so
    that only the refused ones are NaN.
    """
    out = np.full(k.shape, np.nan)
    ok = np.flatnonzero(np.isfinite(k))
    if ok.size == 0:
        return out
    try:
        out[ok] = np.abs(MomentLaw(cases.take(ok), model).tangent_stiffness(P, k[ok]))
        return out
    except BendpamError:
        pass
    for c in ok:
        try:
            out[c] = abs(float(MomentLaw(cases.take(c), model).tangent_stiffness(P, k[c])))
        except BendpamError:
            pass
    return out


# ------------------------------------------------------------------------------------------------
# local solvers
# ------------------------------------------------------------------------------------------------
def _least_squares(prob: _Problem, u0: np.ndarray, sel: Sequence[int], constraints: bool = True,
                   max_nfev: int = 60) -> np.ndarray:
    """Stage A: bounded least squares of the misses from ``u0`` (unit box)."""
    from scipy.optimize import least_squares

    def fun(u):
        q, mg, _ = prob.block(u)
        return prob.rows(q[:1], mg[:1], sel, constraints)[0]

    def jac(u):
        q, mg, h = prob.block(u)
        R = prob.rows(q, mg, sel, constraints)
        return ((R[1:] - R[0]) / h[:, None]).T

    u0 = np.clip(np.asarray(u0, dtype=float), 1e-9, 1 - 1e-9)
    if fun(u0).size == 0:
        return u0
    sol = least_squares(fun, u0, jac=jac, bounds=(0.0, 1.0), method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12,
                        max_nfev=max_nfev)
    return np.clip(sol.x, 0.0, 1.0)


def _max_margin(prob: _Problem, u0: np.ndarray) -> np.ndarray:
    """Stage B: SLSQP maximising the smallest log margin while every target stays met."""
    from scipy.optimize import minimize

    n = u0.size
    eq = [i for i, t in enumerate(prob.targets) if t.sense == "="]
    ineq = [i for i, t in enumerate(prob.targets) if t.sense != "="]
    s_max = math.log(_MARGIN_CAP / prob.min_margin)

    def parts(z):
        q, mg, h = prob.block(z[:n])
        E = np.column_stack([prob.targets[i].slack(q[:, i]) for i in eq]) if eq else np.zeros((n + 1, 0))
        G = np.column_stack([prob.targets[i].slack(q[:, i]) for i in ineq]) if ineq else np.zeros((n + 1, 0))
        LM = prob.log_margin(mg)
        return E, G, LM, h

    def grad(F, h):
        return ((F[1:] - F[0]) / h[:, None]).T  # (outputs, n)

    def eq_f(z):
        return parts(z)[0][0]

    def eq_j(z):
        E, _, _, h = parts(z)
        return np.hstack([grad(E, h), np.zeros((E.shape[1], 1))])

    def in_f(z):
        _, G, LM, _ = parts(z)
        return np.concatenate([G[0], LM[0] - z[n]])

    def in_j(z):
        _, G, LM, h = parts(z)
        jg = np.hstack([grad(G, h), np.zeros((G.shape[1], 1))])
        jm = np.hstack([grad(LM, h), -np.ones((LM.shape[1], 1))])
        return np.vstack([jg, jm])

    _, mg0, _ = prob.block(u0)
    if not mg0.shape[1] or prob.objective(mg0[:1])[0] >= s_max - 1e-9:
        return u0
    s0 = float(np.clip(prob.objective(mg0[:1])[0], 0.0, s_max))
    cons: list[dict[str, Any]] = [{"type": "ineq", "fun": in_f, "jac": in_j}]
    if eq:
        cons.append({"type": "eq", "fun": eq_f, "jac": eq_j})
    z0 = np.append(np.clip(u0, 0.0, 1.0), s0)
    try:
        sol = minimize(lambda z: -z[n], z0, jac=lambda z: np.append(np.zeros(n), -1.0), method="SLSQP",
                       bounds=[(0.0, 1.0)] * n + [(0.0, s_max)], constraints=cons,
                       options={"maxiter": 25, "ftol": 1e-9})
    except (ValueError, FloatingPointError):  # pragma: no cover - SLSQP refusing a degenerate problem
        return u0
    return np.clip(sol.x[:n], 0.0, 1.0)


def _local(prob: _Problem, u0: np.ndarray, sel: Sequence[int], constraints: bool = True,
           maximise: bool = True) -> tuple[np.ndarray, float, float]:
    """Stage A, then (when feasible) stage B and a polish: ``(u, violation, objective)``."""
    u = _least_squares(prob, u0, sel, constraints)
    q, mg, _ = prob.block(u)
    viol = float(prob.violation(q[:1], mg[:1], sel, constraints)[0])
    obj = float(prob.objective(mg[:1])[0]) if constraints else 0.0
    if maximise and constraints and viol <= _TOL * 0.1 and len(sel) == len(prob.targets):
        ub = _max_margin(prob, u)
        ub = _least_squares(prob, ub, sel, constraints, max_nfev=20)
        qb, mgb, _ = prob.block(ub)
        vb = float(prob.violation(qb[:1], mgb[:1], sel, constraints)[0])
        ob = float(prob.objective(mgb[:1])[0])
        if vb <= _TOL * 0.1 and ob >= obj:
            return ub, vb, ob
    return u, viol, obj


def _distinct(U: np.ndarray, order: np.ndarray, k: int, min_dist: float = 0.15) -> list[int]:
    """The first ``k`` indices of ``order`` at least ``min_dist`` apart in the unit box."""
    chosen: list[int] = []
    for i in order:
        if all(np.max(np.abs(U[i] - U[j])) >= min_dist for j in chosen):
            chosen.append(int(i))
        if len(chosen) >= k:
            break
    return chosen


def _progress(total: int, description: str, show: bool | None) -> Any:
    """The shared progress bar (:class:`bendpam.infra.progress.Progress`); silent unless ``show``."""
    from bendpam.infra.progress import Progress

    return Progress(total, description, quiet=not show)


# ------------------------------------------------------------------------------------------------
# results
# ------------------------------------------------------------------------------------------------
@dataclass
class ParetoFront:
    """Non-dominated designs in two target quantities (sorted by the first).

    Attributes
    ----------
    targets : the two :class:`Target` objects (their quantities and pressures; the Pareto sense is
        larger is better for ``>=``/``=``, smaller for ``<=``).
    quantities : ``(K, 2)`` the two magnitudes of each design, in the targets' units.
    X : ``(K, n)`` the variables of each design (:attr:`DesignResult.variables` order).
    min_margin : ``(K,)`` the smallest safety margin of each design.
    """

    targets: tuple[Target, Target]
    quantities: np.ndarray
    X: np.ndarray
    min_margin: np.ndarray
    variable_names: tuple[str, ...]

    def columns(self) -> dict[str, np.ndarray]:
        out = {self.targets[0].key: self.quantities[:, 0], self.targets[1].key: self.quantities[:, 1]}
        out.update({n: self.X[:, j] for j, n in enumerate(self.variable_names)})
        out["min_margin"] = self.min_margin
        return out

    def to_csv(self) -> str:
        cols = self.columns()
        lines = [",".join(cols)]
        for r in range(len(self.quantities)):
            lines.append(",".join(f"{float(v[r]):.10g}" for v in cols.values()))
        return "\n".join(lines) + "\n"


@dataclass
class DesignResult:
    """The outcome of :func:`design_actuator`.

    Attributes
    ----------
    actuator : the best design (the closest one when the targets cannot be met), an
        :class:`~bendpam.Actuator` whose ``model`` field records the model.
    model : the moment model.
    targets, variables : the problem.
    values : ``{variable: value}`` at the best design.
    achieved : ``(n_targets,)`` the magnitudes predicted for the best design by the public
        functions (:func:`bendpam.blocked_moment`, :func:`bendpam.free_curvature`,
        :func:`bendpam.tangent_stiffness`, :func:`bendpam.free_branch`,
        :func:`bendpam.design.blocked_tip_force`), independently of the search.
    relative_error : ``achieved / value - 1`` per target; ``met`` whether each target is met (0.1 %).
    feasible : every target met and every margin >= ``min_margin`` (to 0.1 %).
    message : a plain-words account (why not, when not feasible).
    binding : the targets (texts) or limits that prevent meeting the rest (empty when feasible).
    active : the bounds and margins at their limit at the best design.
    closest : the variables of the closest design (== ``values``) when not feasible, else None.
    margins : ``{name: value}`` the smallest of each margin over the operating pressures.
    margins_by_pressure : ``{pressure_kpa: {name: value}}`` at the target and operating pressures.
    min_margin, min_margin_required, max_pressure_kpa : the smallest margin, the required one,
        the operating pressure (kPa; None when no target has a pressure).
    sensitivities : ``{target key: {variable: d ln(quantity) / d ln(variable)}}`` at the best
        design (central differences; ``min_margin`` too when finite).
    coarse : the coarse map: ``X`` (N, n), ``quantities`` (N, n_targets), ``violation`` (N,),
        ``min_margin`` (N,), and ``method`` (``"sobol"`` or ``"grid"``).
    pareto : the :class:`ParetoFront` (two targets) or None.
    search : seed, sizes, evaluations and the elapsed time.

    Examples
    --------
    >>> import bendpam
    >>> res = design_actuator(bendpam.physics.presets.be_pam(), ["blocked_moment_nmm=400@200"],
    ...                       ["alpha0_deg=60:80"], n_coarse=64, n_starts=1)
    >>> res.met.tolist(), res.binding, round(res.actuator.alpha0_deg, 2)
    ([True], (), 79.87)
    """

    actuator: Actuator
    model: str
    targets: tuple[Target, ...]
    variables: tuple[Variable, ...]
    values: dict[str, float]
    achieved: np.ndarray
    relative_error: np.ndarray
    met: np.ndarray
    feasible: bool
    message: str
    binding: tuple[str, ...]
    active: tuple[str, ...]
    closest: dict[str, float] | None
    margins: dict[str, float]
    margins_by_pressure: dict[float, dict[str, float]]
    min_margin: float
    min_margin_required: float
    max_pressure_kpa: float | None
    sensitivities: dict[str, dict[str, float]]
    coarse: dict[str, Any] = field(repr=False)
    pareto: ParetoFront | None = field(repr=False)
    search: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """design.json's content (units in the key names; ``null`` = infinite or not defined)."""
        from bendpam.version import __version__

        return {
            "bendpam_version": __version__,
            "model": self.model,
            "feasible": self.feasible,
            "message": self.message,
            "binding": list(self.binding),
            "active": list(self.active),
            "targets": [
                {"target": t.text, "quantity": t.quantity, "unit": t.unit, "comparison": t.sense, "value": t.value,
                 "pressure_kpa": t.pressure_kpa, "achieved": float(a), "relative_error": float(e), "met": bool(m),
                 "compared": "magnitude"}
                for t, a, e, m in zip(self.targets, self.achieved, self.relative_error, self.met, strict=True)],
            "variables": [{"name": v.name, "low": v.low, "high": v.high, "value": self.values[v.name]}
                          for v in self.variables],
            "closest_design": self.closest,
            "constraints": {"min_margin": self.min_margin_required, "max_pressure_kpa": self.max_pressure_kpa},
            "margins": dict(self.margins),
            "min_margin": self.min_margin,
            "margins_by_pressure": [{"pressure_kpa": p, **m} for p, m in self.margins_by_pressure.items()],
            "sensitivities": {"meaning": "d ln(quantity) / d ln(variable) at the design", **self.sensitivities},
            "actuator": self.actuator.to_dict(),
            "pareto": None if self.pareto is None else {
                "quantities": [t.key for t in self.pareto.targets], "n_designs": len(self.pareto.quantities),
                "better": ["larger" if t.larger_is_better else "smaller" for t in self.pareto.targets],
                "file": "pareto.csv"},
            "search": dict(self.search),
            "null_means": "infinite (no demand, no limit, an unbounded free-bending branch) or not defined",
        }

    def to_json(self) -> str:
        from bendpam.infra.outputs import to_json

        return to_json(self.to_dict())

    def save(self, out_dir, *, figures: bool = True) -> dict[str, str]:
        """Write design.json, design.toml, coarse_map.csv, pareto.csv and figures into ``out_dir``.

        Each file is written atomically (for a whole set, use :class:`bendpam.infra.outputs.OutputSet`,
        as ``bendpam design --out`` does).  Returns ``{file name: path}``.
        """
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        files: dict[str, str] = {}

        def put(name: str, text: str) -> None:
            atomic_write_text(out / name, text)
            files[name] = str(out / name)

        put("design.json", self.to_json())
        put("design.toml", self.actuator.to_toml())
        cols = {v.name: self.coarse["X"][:, j] for j, v in enumerate(self.variables)}
        cols.update({t.key: self.coarse["quantities"][:, i] for i, t in enumerate(self.targets)})
        cols["violation"] = self.coarse["violation"]
        cols["min_margin"] = self.coarse["min_margin"]
        lines = [",".join(cols)] + [",".join(f"{float(c[r]):.8g}" for c in cols.values())
                                    for r in range(len(self.coarse["X"]))]
        put("coarse_map.csv", "\n".join(lines) + "\n")
        if self.pareto is not None:
            put("pareto.csv", self.pareto.to_csv())
        if figures:
            from bendpam.present.figures import save_figure

            save_figure(plot_coarse_map(self), out / "coarse_map.png")
            files["coarse_map.png"] = str(out / "coarse_map.png")
            if self.pareto is not None:
                save_figure(plot_pareto(self), out / "pareto.png")
                files["pareto.png"] = str(out / "pareto.png")
        return files

    def summary(self) -> str:
        """A short human summary: targets against achieved values, feasibility, margins."""
        head = "feasible: every target met" if self.feasible else "NOT FEASIBLE: the targets cannot all be met"
        lines = [f"design ({self.model.replace('_', '-')} model): {head}"]
        w = max(len(t.text) for t in self.targets)
        for t, a, e, m in zip(self.targets, self.achieved, self.relative_error, self.met, strict=True):
            a_s = f"{a:.5g}" if np.isfinite(a) else ("inf" if a == np.inf else "none")
            e_s = f"{100 * e:+.3f} %" if np.isfinite(e) else "—"
            lines.append(f"  {t.text:<{w}}  achieved {a_s} {t.unit} ({e_s}) {'ok' if m else 'MISSED'}")
        lines.append("  variables: " + ", ".join(f"{k} = {v:.5g}" for k, v in self.values.items()))
        if self.margins:
            ms = ", ".join(f"{k} {_fmt_margin(v)}" for k, v in self.margins.items())
            lines.append(f"  margins (>= {self.min_margin_required:g} required"
                         + (f" up to {self.max_pressure_kpa:g} kPa" if self.max_pressure_kpa else "") + f"): {ms}")
        if self.active:
            lines.append(f"  at their limit: {', '.join(self.active)}")
        lines.append(f"  {self.message}")
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.summary()


def _fmt_margin(v: float) -> str:
    return "inf" if v == math.inf else ("none" if not np.isfinite(v) else f"{v:.3g}")


# ------------------------------------------------------------------------------------------------
# the search
# ------------------------------------------------------------------------------------------------
def design_actuator(base: Actuator, targets: Iterable[Target | str], vary, *, model: str = "energy",
                    max_pressure_kpa: float | None = None, min_margin: float = 1.0, n_coarse: int = 2048,
                    n_starts: int = 4, pareto: bool | None = None, scheduler: str | None = None, seed: int = 0,
                    progress: bool | None = None) -> DesignResult:
    """Inverse design: the actuator parameters in ``vary`` that meet ``targets`` (see the module doc).

    Parameters
    ----------
    base : Actuator
        The actuator whose other parameters are kept.
    targets : Target objects or texts ``NAME=VALUE@P``, ``NAME>=VALUE@P``, ``NAME<=VALUE@P`` (P in
        kPa; ``max_pressure_kpa>=VALUE`` without @).  Targets compare magnitudes (a BC-PAM's
        negative blocked moment is met by a positive value).
    vary : Variable objects, texts ``NAME=LOW:HIGH`` or a mapping ``{name: (low, high)}`` of
        :data:`DESIGN_VARIABLES` (units in the names).
    model : ``"energy"`` or ``"force_balance"``.
    max_pressure_kpa : the operating pressure (kPa): every margin must hold up to it, and the
        fold or lock-up pressure must exceed it by ``min_margin``.  Default: the highest target
        pressure.
    min_margin : the safety factor required of every margin (>= 1).
    n_coarse : designs in the coarse map (rounded up to a power of 2; 16 to 2**20).
    n_starts : local searches from the best distinct designs of the map (1 to 64).
    pareto : compute the Pareto front of two targets (None: when there are exactly two).
    scheduler : a Dask scheduler address: the coarse map (a grid) is computed there.
    seed : seed of the Sobol sample (results are deterministic for a seed).
    progress : show a progress bar.

    Returns
    -------
    DesignResult

    Examples
    --------
    >>> import bendpam
    >>> res = design_actuator(bendpam.physics.presets.be_pam(), ["blocked_moment_nmm=400@200"],
    ...                       ["alpha0_deg=60:80"], n_coarse=64, n_starts=1)
    >>> res.feasible, round(res.values["alpha0_deg"], 2), round(float(res.achieved[0]), 3)
    (True, 79.87, 400.0)
    """
    t_start = time.perf_counter()
    if not isinstance(base, Actuator):
        raise TypeError(f"base must be a bendpam.Actuator, got {type(base).__name__}")
    model = normalise_model(model)
    tg = parse_targets(targets)
    variables = parse_variables(base, vary)
    if max_pressure_kpa is not None:
        if isinstance(max_pressure_kpa, bool) or not (isinstance(max_pressure_kpa, int | float | np.floating)
                                                      and math.isfinite(max_pressure_kpa) and max_pressure_kpa > 0):
            raise InputError(f"max_pressure_kpa = {max_pressure_kpa!r} must be a pressure > 0 kPa")
    if isinstance(min_margin, bool) or not (isinstance(min_margin, int | float | np.floating)
                                            and math.isfinite(min_margin) and min_margin >= 1.0):
        raise InputError(f"min_margin = {min_margin!r} must be a safety factor >= 1")
    n_coarse = _int_in("n_coarse", n_coarse, 16, 2**20)
    n_starts = _int_in("n_starts", n_starts, 1, 64)
    if pareto and len(tg) != 2:
        raise InputError(f"a Pareto front needs exactly two targets; {len(tg)} given")
    want_pareto = len(tg) == 2 if pareto is None else bool(pareto)
    prob = _Problem(base, model, tg, variables, max_pressure_kpa, float(min_margin), int(seed))
    n = len(variables)
    all_t = list(range(len(tg)))

    m = math.ceil(math.log2(n_coarse))
    n_map = (1 << m) if scheduler is None else max(2, round(n_coarse ** (1.0 / n))) ** n
    # progress in designs: the coarse map's, then _BLOCK per local search and per final stage
    with _progress(n_map + _BLOCK * (n_starts + 2), "design", progress) as bar:
        # 1. the coarse map
        if scheduler is None:
            from scipy.stats import qmc

            U = qmc.Sobol(n, scramble=True, rng=np.random.default_rng(seed)).random_base2(m)
            X = prob.x_of(U)
            qs, ms = [], []
            for s in range(0, len(X), _BLOCK):
                q, mg = prob.evaluate(X[s:s + _BLOCK])
                qs.append(q)
                ms.append(mg)
                bar.advance(len(q), "design: coarse map")
            Q, MG = np.vstack(qs), np.vstack(ms)
            method = "sobol"
        else:
            U, X, Q, MG = _coarse_grid(prob, n_coarse, scheduler, bar.advance)
            method = "grid"
        # correct the tip-force closed form at the centre of the box before ranking
        tip = [i for i, t in enumerate(tg) if t.quantity == "blocked_tip_force_n"]
        if tip:
            f0 = _tip_correction(prob, prob.x_of(np.full(n, 0.5)), tip)
            Q[:, tip] *= f0[tip] / prob.tip_factor[tip]
            prob.set_tip_factor(f0)
        viol = prob.violation(Q, MG, all_t)
        score = np.sum(prob.rows(Q, MG, all_t) ** 2, axis=1)
        obj = prob.objective(MG)
        order = np.lexsort((-obj, np.round(score, 12)))
        starts = _distinct(U, order, n_starts)

        # 2-3. local searches
        best: tuple[np.ndarray, float, float] | None = None
        for i in starts:
            if tip:
                prob.set_tip_factor(_tip_correction(prob, X[i], tip))
            u, v, o = _local(prob, U[i], all_t)
            if best is None or _better((v, o), (best[1], best[2])):
                best = (u, v, o)
            bar.advance(_BLOCK, "design: local search")
        assert best is not None
        u_best = best[0]
        if tip:  # space mapping: re-solve until the finger-solve correction settles, then again after stage B
            u_best = _settle_tip(prob, u_best, tip, all_t)
            u_best = _settle_tip(prob, _local(prob, u_best, all_t)[0], tip, all_t)
        u_best = np.where(u_best < 1e-8, 0.0, np.where(u_best > 1.0 - 1e-8, 1.0, u_best))  # on a bound: exactly
        x_best = prob.x_of(u_best)
        q_b, mg_b = prob.evaluate(x_best[None, :])
        feasible_search = float(prob.violation(q_b, mg_b, all_t)[0]) <= _TOL

        # diagnosis
        binding: tuple[str, ...] = ()
        detail = ""
        if not feasible_search:
            binding, detail = _diagnose(prob, U, Q, MG, u_best)
        bar.advance(_BLOCK, "design: checking")
        front = _pareto(prob, U, Q, MG, seed) if want_pareto else None
        bar.advance(_BLOCK, "design: done")

    return _result(prob, x_best, binding, detail, front,
                   dict(X=X, quantities=Q, violation=viol, min_margin=_min_margin(MG), method=method),
                   dict(seed=int(seed), n_coarse=len(X), n_starts=len(starts), coarse_method=method,
                        evaluations=int(prob.n_evaluations), scheduler=scheduler,
                        elapsed_s=round(time.perf_counter() - t_start, 3)))


def _int_in(name: str, v, lo: int, hi: int) -> int:
    if isinstance(v, bool) or not isinstance(v, int | np.integer) or not lo <= int(v) <= hi:
        raise InputError(f"{name} = {v!r} must be an integer in [{lo}, {hi}]")
    return int(v)


def _better(a: tuple[float, float], b: tuple[float, float]) -> bool:
    """(violation, objective) ``a`` better than ``b``: feasible beats infeasible, then objective, then violation."""
    fa, fb = a[0] <= _TOL * 0.1, b[0] <= _TOL * 0.1
    if fa != fb:
        return fa
    if fa:
        return a[1] > b[1] + 1e-9
    return a[0] < b[0] - 1e-12


def _min_margin(mg: np.ndarray) -> np.ndarray:
    if not mg.shape[1]:
        return np.full(len(mg), np.inf)
    return np.where(np.isnan(mg).any(axis=1), np.nan, np.nanmin(np.where(np.isnan(mg), np.inf, mg), axis=1))


def _coarse_grid(prob: _Problem, n_coarse: int, scheduler: str, report):
    """The coarse map as a factorial grid computed by :func:`bendpam.sweep` on a Dask cluster."""
    from bendpam.sweeps import sweep

    n = len(prob.variables)
    levels = max(2, round(n_coarse ** (1.0 / n)))
    g = np.linspace(0.0, 1.0, levels)
    grids: dict[str, Any] = {v.name: v.low + g * (v.high - v.low) for v in prob.variables}
    ds = sweep(prob.base, prob.P, prob.model, scheduler=scheduler, progress=report, **grids)
    U = np.array(np.meshgrid(*([g] * n), indexing="ij")).reshape(n, -1).T
    X = prob.x_of(U)
    r: dict[str, np.ndarray] = {}
    for name in ds.data_vars:
        a = np.asarray(ds[name].values, dtype=float)
        r[str(name)] = a.reshape(len(X), prob.P.size) if "pressure_kpa" in ds[name].dims else a.reshape(len(X))
    prob.n_evaluations += len(X)
    Q, MG = prob.assemble(X, r)
    return U, X, Q, MG


# ---- the finger's tip force ---------------------------------------------------------------------
def _tip_exact(act: Actuator, model: str, P: float) -> float:
    from bendpam.design.finger import Finger
    from bendpam.design.tip import blocked_tip_force

    try:
        res = blocked_tip_force(Finger(act, model), P)
    except BendpamError:
        return math.nan
    return res.magnitude_n if res.equilibrium else math.nan


def _tip_correction(prob: _Problem, x: np.ndarray, tip: list[int]) -> np.ndarray:
    """The factor (finger solve) / (closed form) of each tip-force target at ``x`` (1 where undefined)."""
    f = prob.tip_factor.copy()
    act = prob.actuator(x)
    M = np.abs(np.asarray(evaluate_cases(prob.base, prob.model, prob.values(x[None, :]), prob.P)
                          ["blocked_moment_nmm"][0]))
    for i in tip:
        P = float(prob.targets[i].pressure_kpa)  # type: ignore[arg-type]
        closed = 1.5 * M[prob.ip[P]] / act.L0_mm
        exact = _tip_exact(act, prob.model, P)
        f[i] = exact / closed if np.isfinite(exact) and closed > 0 else 1.0
    return f


def _settle_tip(prob: _Problem, u: np.ndarray, tip: list[int], sel: Sequence[int]) -> np.ndarray:
    """Stage A with the tip-force correction recomputed at the solution until it no longer changes."""
    for _ in range(8):
        f = _tip_correction(prob, prob.x_of(u), tip)
        change = float(np.max(np.abs(f[tip] / prob.tip_factor[tip] - 1.0)))
        prob.set_tip_factor(f)
        if change < 1e-9:
            break
        u = _least_squares(prob, u, sel)
    return u


# ---- infeasibility ------------------------------------------------------------------------------
def _diagnose(prob: _Problem, U, Q, MG, u_best) -> tuple[tuple[str, ...], str]:
    """Which targets (or limits) bind, in plain words."""
    tg = prob.targets
    nt = len(tg)

    def solve(sel: list[int], constraints: bool = True) -> tuple[np.ndarray, float]:
        sc = np.sum(prob.rows(Q, MG, sel, constraints) ** 2, axis=1)
        best_u, best_v = u_best, math.inf
        for i in _distinct(U, np.argsort(sc, kind="stable"), 2):
            u = _least_squares(prob, U[i], sel, constraints)
            q, mg, _ = prob.block(u)
            v = float(prob.violation(q[:1], mg[:1], sel, constraints)[0])
            if v < best_v:
                best_u, best_v = u, v
        return best_u, best_v

    # the safety limits alone
    if MG.shape[1]:
        u_c, v_c = solve([])
        if v_c > _TOL:
            q, mg, _ = prob.block(u_c)
            worst = prob.margin_names[int(np.argmin(prob.margin_miss(mg[:1])[0]))]
            return (f"min_margin={prob.min_margin:g}",), (
                f"No design within the ranges has every margin >= {prob.min_margin:g}"
                + (f" up to {prob.p_op:g} kPa" if prob.p_op else "")
                + f" (the best reaches {worst} = {_fmt_margin(float(mg[0, prob.margin_names.index(worst)]))}); "
                  "widen the ranges, lower the operating pressure or the required margin.")
    alone = []
    for i in range(nt):
        u_i, v_i = solve([i])
        if v_i > _TOL:
            q, _, _ = prob.block(u_i)
            best_q = _extreme(prob, U, Q, MG, i, float(q[0, i]))
            if abs(float(tg[i].miss(np.array([best_q]))[0])) > _TOL:
                alone.append((i, best_q))
    if alone:
        words = []
        for i, best_q in alone:
            t = tg[i]
            reach = "largest" if best_q < t.value else "smallest"
            words.append(f"{t.text} is out of reach even alone (the {reach} reachable value is {best_q:.4g} {t.unit}"
                         + (" with the margins met" if MG.shape[1] else "") + ")")
        return tuple(tg[i].text for i, _ in alone), "; ".join(words) + "."
    drop = []
    if nt > 1:
        for i in range(nt):
            _, v_i = solve([j for j in range(nt) if j != i])
            if v_i <= _TOL:
                drop.append(tg[i].text)
    limits_bind = bool(MG.shape[1]) and solve(list(range(nt)), constraints=False)[1] <= _TOL
    words = []
    if drop:
        which = drop[0] if len(drop) == 1 else "any one of " + ", ".join(drop)
        words.append(f"Dropping {which} lets the other targets be met")
    if limits_bind:
        words.append(f"the targets can be met together only with a margin below min_margin = {prob.min_margin:g}"
                     + (f" (up to {prob.p_op:g} kPa)" if prob.p_op else ""))
    binding = drop + ([f"min_margin={prob.min_margin:g}"] if limits_bind else [])
    if not binding:
        return tuple(t.text for t in tg), "The targets conflict: no single target can be dropped to meet the others."
    text = "; ".join(words) + "."
    return tuple(binding), text[0].upper() + text[1:]


def _extreme(prob: _Problem, U, Q, MG, i: int, q_local: float, rounds=(0.1, 0.03, 0.01), per_round: int = 256
             ) -> float:
    """The reachable extreme of target ``i``'s quantity with the margins met, toward its value.

    The local solve can stop at a jump of the margins (a fold born at a finite pressure); the
    extreme is also sought by drawing designs around the best ones (shrinking cubes clipped to
    the box) and the better of the two is returned.
    """
    t = prob.targets[i]
    up = q_local < t.value  # the target lies above what was reached
    sg = 1.0 if up else -1.0

    def score(Qs, Ms):
        ok = np.isfinite(Qs[:, i])
        if Ms.shape[1]:
            ok &= np.all(np.abs(prob.margin_miss(Ms)) <= _TOL, axis=1)
        return np.where(ok, sg * Qs[:, i], -np.inf)

    sc = score(Q, MG)
    if not np.any(np.isfinite(sc)):
        return q_local
    top = np.argsort(-sc, kind="stable")[:8]
    FU, best = U[top][np.isfinite(sc[top])], float(np.max(sc))
    n = U.shape[1]
    for r in rounds:
        NU = np.clip(FU[prob.rng.integers(0, len(FU), per_round)] + prob.rng.uniform(-r, r, (per_round, n)), 0, 1)
        parts = [prob.evaluate(prob.x_of(NU[s:s + _BLOCK])) for s in range(0, per_round, _BLOCK)]
        s_new = score(np.vstack([p[0] for p in parts]), np.vstack([p[1] for p in parts]))
        order = np.argsort(-s_new, kind="stable")[:8]
        if s_new[order[0]] > best:
            best = float(s_new[order[0]])
        FU = np.vstack([FU, NU[order[np.isfinite(s_new[order])]]])
    reached = sg * best
    return max(q_local, reached) if up else min(q_local, reached)


# ---- Pareto front -------------------------------------------------------------------------------
def _nondominated(G: np.ndarray) -> np.ndarray:
    """Indices of the non-dominated rows of ``G`` (N, 2), larger better in both (to 1e-9 relative)."""
    scale = np.maximum(np.max(np.abs(G), axis=0), 1e-300)
    Gr = np.round(G / scale, 9)
    order = np.lexsort((-Gr[:, 1], -Gr[:, 0]))
    keep = []
    best2 = -np.inf
    for i in order:
        if Gr[i, 1] > best2:
            keep.append(i)
            best2 = Gr[i, 1]
    return np.array(keep[::-1], dtype=int)


def _pareto(prob: _Problem, U, Q, MG, seed: int = 0, rounds=(0.15, 0.05, 0.015), per_round: int = 512
            ) -> ParetoFront | None:
    """Non-dominated designs in the two targets' quantities among the designs meeting every margin.

    The coarse map's front is refined by a few rounds of designs drawn around the front's
    designs (uniform in a shrinking cube, clipped to the box, so the box's faces, where fronts
    often lie, are sampled too), each round evaluated as blocks of the kernel.
    """
    t1, t2 = prob.targets
    sg = np.array([1.0 if t1.larger_is_better else -1.0, 1.0 if t2.larger_is_better else -1.0])

    def front(U, Q, MG):
        ok = np.all(np.isfinite(Q), axis=1)
        if MG.shape[1]:
            ok &= np.all(np.abs(prob.margin_miss(MG)) <= _TOL, axis=1)
        idx = np.flatnonzero(ok)
        return idx[_nondominated(Q[idx] * sg)] if idx.size else idx

    keep = front(U, Q, MG)
    if not keep.size:
        return None
    FU, FQ, FM = U[keep], Q[keep], MG[keep]
    rng = np.random.default_rng(seed)
    n = U.shape[1]
    for r in rounds:
        pick = rng.integers(0, len(FU), per_round)
        NU = np.clip(FU[pick] + rng.uniform(-r, r, (per_round, n)), 0.0, 1.0)
        parts = [prob.evaluate(prob.x_of(NU[s:s + _BLOCK])) for s in range(0, per_round, _BLOCK)]
        NQ, NM = np.vstack([p[0] for p in parts]), np.vstack([p[1] for p in parts])
        AU, AQ, AM = np.vstack([FU, NU]), np.vstack([FQ, NQ]), np.vstack([FM, NM])
        keep = front(AU, AQ, AM)
        FU, FQ, FM = AU[keep], AQ[keep], AM[keep]
    order = np.argsort(FQ[:, 0], kind="stable")
    return ParetoFront((t1, t2), FQ[order], prob.x_of(FU[order]), _min_margin(FM[order]),
                       tuple(v.name for v in prob.variables))


# ---- the result ---------------------------------------------------------------------------------
def _achieved(prob: _Problem, act: Actuator) -> np.ndarray:
    """Each target's magnitude from the public prediction functions (independent of the search)."""
    from bendpam import predict

    out = np.empty(len(prob.targets))
    for i, t in enumerate(prob.targets):
        P = t.pressure_kpa
        if t.quantity == "max_pressure_kpa":
            out[i] = predict.free_branch(act, prob.model).max_pressure_kpa
        elif t.quantity == "blocked_moment_nmm":
            out[i] = abs(float(predict.blocked_moment(act, P, prob.model)))
        elif t.quantity in ("free_curvature_per_mm", "free_angle_deg", "tangent_stiffness_nmm2"):
            fb = predict.free_curvature(act, P, prob.model)
            k = float(fb.curvature_per_mm)
            if t.quantity == "free_curvature_per_mm":
                out[i] = abs(k)
            elif t.quantity == "free_angle_deg":
                out[i] = abs(float(fb.angle_deg))
            else:
                out[i] = abs(float(predict.tangent_stiffness(act, P, k, prob.model))) if np.isfinite(k) else np.nan
        elif t.quantity == "blocked_stiffness_nmm2":
            out[i] = abs(float(predict.tangent_stiffness(act, P, 0.0, prob.model)))
        elif t.quantity == "blocked_tip_force_n":
            out[i] = _tip_exact(act, prob.model, float(P))  # type: ignore[arg-type]
        else:  # kernel-only quantities (frame stress)
            r = evaluate_cases(act, prob.model, {}, [P])
            out[i] = abs(float(np.asarray(r[t.quantity]).ravel()[0]))
    return out


def _sensitivities(prob: _Problem, x: np.ndarray) -> dict[str, dict[str, float]]:
    """``d ln q / d ln x`` of each target quantity (and the smallest margin) by central differences."""
    n = x.size
    d = np.where(x != 0, 1e-4 * np.abs(x), 1e-4 * (prob.hi - prob.lo))
    Xp = np.vstack([x + np.diag(d), x - np.diag(d)])
    try:
        q, mg = prob.evaluate(Xp)
    except InputError:  # a perturbation leaves the valid range: one-sided differences
        Xp = np.vstack([x + np.diag(d), np.tile(x, (n, 1))])
        q, mg = prob.evaluate(Xp)
    q0, mg0 = prob.evaluate(x[None, :])
    tip = [i for i, t in enumerate(prob.targets) if t.quantity == "blocked_tip_force_n"]
    for i in tip:  # the finger solve itself
        P = float(prob.targets[i].pressure_kpa)  # type: ignore[arg-type]
        for r in range(2 * n):
            try:
                q[r, i] = _tip_exact(prob.actuator(Xp[r]), prob.model, P)
            except InputError:
                q[r, i] = np.nan
        q0[0, i] = _tip_exact(prob.actuator(x), prob.model, P)
    step = Xp[:n] - Xp[n:]
    out: dict[str, dict[str, float]] = {}
    cols = [(t.key, q[:, i], q0[0, i]) for i, t in enumerate(prob.targets)]
    mm = _min_margin(mg)
    cols.append(("min_margin", mm, float(_min_margin(mg0)[0])))
    for key, col, c0 in cols:
        if key in out or not np.isfinite(c0) or c0 == 0:
            continue
        with np.errstate(invalid="ignore", divide="ignore"):
            dq = (col[:n] - col[n:]) / np.diag(step)
            e = dq * x / c0
        out[key] = {v.name: (float(e[j]) if np.isfinite(e[j]) else math.nan) for j, v in enumerate(prob.variables)}
    return out


def _result(prob: _Problem, x: np.ndarray, binding, detail: str, front, coarse, search) -> DesignResult:
    base_name = prob.base.name or prob.base.kind
    act = prob.actuator(x, name=f"designed from {base_name}")
    achieved = _achieved(prob, act)
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = achieved / np.array([t.value for t in prob.targets]) - 1.0
    met = np.array([abs(float(t.miss(np.array([a]))[0])) <= _TOL for t, a in zip(prob.targets, achieved, strict=True)])
    # margins of the final design, per pressure
    r = evaluate_cases(prob.base, prob.model, prob.values(x[None, :]), prob.P)
    _, mg = prob.assemble(x[None, :], r)
    margins = {k: float(v) for k, v in zip(prob.margin_names, mg[0], strict=True)}
    by_p: dict[float, dict[str, float]] = {}
    for j, P in enumerate(prob.P):
        if not prob.op_mask[j]:
            continue
        row = {}
        for k in prob.margin_names:
            if k == "pressure_margin":
                continue
            row[k] = float(np.asarray(r[k])[0, j])
        by_p[float(P)] = row
    mmin = float(_min_margin(mg)[0]) if mg.shape[1] else math.inf
    margins_ok = bool(np.all(np.abs(prob.margin_miss(mg)) <= _TOL)) if mg.shape[1] else True
    feasible = bool(np.all(met)) and margins_ok
    active = [t.text for t, a in zip(prob.targets, achieved, strict=True)
              if t.sense != "=" and np.isfinite(a) and abs(a / t.value - 1.0) <= _TOL]
    active += [f"{k} = {margins[k]:.4g}" for k in prob.margin_names
               if np.isfinite(margins[k]) and abs(margins[k] / prob.min_margin - 1.0) <= _TOL]
    if feasible:
        message = "Every target is met with every margin >= " f"{prob.min_margin:g}" + (
            f" up to {prob.p_op:g} kPa" if prob.p_op else "") + "; among such designs this one has the largest " \
            "smallest margin."
        if not prob.margin_names:
            message = ("Every target is met; no margin was checked (no target is taken at a pressure and no "
                       "operating pressure max_pressure_kpa was given).")
        binding = ()
    else:
        misses = ", ".join(f"{t.text} by {100 * e:+.2f} %" if np.isfinite(e) else f"{t.text} (no value)"
                           for t, e, m in zip(prob.targets, rel, met, strict=True) if not m)
        if not binding:
            binding = tuple(t.text for t, m in zip(prob.targets, met, strict=True) if not m) or (
                f"min_margin={prob.min_margin:g}",)
        message = ("The targets cannot be met together within the ranges. The closest design "
                   + (f"misses {misses}" if misses else "meets the targets only with a margin below the limit")
                   + (f" (smallest margin {_fmt_margin(mmin)})" if not margins_ok else "") + ". "
                   + (detail or f"Binding: {', '.join(binding)}."))
    values = {v.name: float(x[j]) for j, v in enumerate(prob.variables)}
    return DesignResult(
        actuator=act, model=prob.model, targets=prob.targets, variables=prob.variables, values=values,
        achieved=achieved, relative_error=rel, met=met, feasible=feasible, message=message, binding=tuple(binding),
        active=tuple(active), closest=None if feasible else dict(values), margins=margins, margins_by_pressure=by_p,
        min_margin=mmin, min_margin_required=prob.min_margin, max_pressure_kpa=prob.p_op,
        sensitivities=_sensitivities(prob, x), coarse=coarse, pareto=front, search=search)


# ------------------------------------------------------------------------------------------------
# figures
# ------------------------------------------------------------------------------------------------
def plot_coarse_map(result: DesignResult):
    """The coarse map in the first two variables (colour: largest relative miss), the design starred."""
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    c = result.coarse
    names = [v.name for v in result.variables]
    fig, ax = plt.subplots(figsize=(3.5, 2.9), layout="constrained")
    v = np.clip(np.nan_to_num(c["violation"], nan=_NAN_MISS), 1e-3, 3.0)
    x = c["X"][:, 0]
    y = c["X"][:, 1] if len(names) > 1 else v
    sc = ax.scatter(x, y, c=v, s=5, cmap="viridis_r", norm=LogNorm(1e-3, 3.0), linewidths=0)
    bx = result.values[names[0]]
    by = result.values[names[1]] if len(names) > 1 else max(1e-3, float(np.max(np.abs(result.relative_error))))
    ax.plot([bx], [by], marker="*", color="tab:red", ms=11, mec="k", mew=0.6, ls="none",
            label="design" if result.feasible else "closest design")
    ax.set_xlabel(names[0])
    ax.set_ylabel(names[1] if len(names) > 1 else "largest relative miss")
    if len(names) == 1:
        ax.set_yscale("log")
    cb = fig.colorbar(sc, ax=ax, pad=0.01)
    cb.set_label("largest relative miss", fontsize=8)
    ax.legend(fontsize=7, loc="best")
    ax.set_title(f"coarse map ({len(x)} designs, {c['method']})", fontsize=8)
    return fig


def plot_pareto(result: DesignResult):
    """The Pareto front of the two targets over the coarse map's designs that meet every margin."""
    import matplotlib.pyplot as plt

    pf = result.pareto
    if pf is None:
        raise InputError("this design has no Pareto front (it needs exactly two targets)")
    t1, t2 = pf.targets
    fig, ax = plt.subplots(figsize=(3.5, 2.8), layout="constrained")
    Q = result.coarse["quantities"]
    ok = np.isfinite(result.coarse["min_margin"]) & (result.coarse["min_margin"] >= result.min_margin_required * (
        1 - _TOL)) if np.any(np.isfinite(result.coarse["min_margin"])) else np.ones(len(Q), bool)
    ax.scatter(Q[ok, 0], Q[ok, 1], s=3, color="0.75", linewidths=0, label="designs (margins met)")
    ax.plot(pf.quantities[:, 0], pf.quantities[:, 1], "-o", color="tab:blue", ms=3, lw=1.2, label="Pareto front")
    ax.axvline(t1.value, color="k", ls="--", lw=0.7)
    ax.axhline(t2.value, color="k", ls="--", lw=0.7)
    ax.plot([result.achieved[0]], [result.achieved[1]], marker="*", color="tab:red", ms=11, mec="k", mew=0.6,
            ls="none", label="design" if result.feasible else "closest design")
    ax.set_xlabel(t1.label, fontsize=8)
    ax.set_ylabel(t2.label, fontsize=8)
    ax.legend(fontsize=6.5, loc="best")
    return fig
