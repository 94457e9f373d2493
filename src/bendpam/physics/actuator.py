"""The :class:`Actuator`: an immutable, validated description of one bending PAM.

Field names carry their units (``alpha0_deg``, ``R0_mm``, ``C10_kpa`` ...) because that is how a
user writes them down.  Properties without a unit suffix (``alpha0``, ``C10``, ``P_start`` ...) give
the same values in the package's internal units: mm, MPa (N/mm^2), N*mm, radians.

The deadband and prestrain corrections of section 3.3 are part of the description: the bladder is
stress-free at ``P_start`` with outer radius ``R0_start`` and thickness ``t0_start`` given by eq 51-52
(constant bladder cross-section area, constant length).  Both models use ``R0_start`` and
``t0_start`` in place of ``R0`` and ``t0`` everywhere (docs/paper-reading.md item 13).
"""

from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import tomli_w

from bendpam.errors import InputError, OutsideTestedRangeWarning, warn_user
from bendpam.infra.atomic import atomic_write_text
from bendpam.infra.budgets import read_toml_file
from bendpam.infra.display import summary_html, summary_text
from bendpam.physics.material import MooneyRivlin
from bendpam.validate import DEFAULT_MAX_PRESSURE_KPA, PLAUSIBLE, did_you_mean, float_array, number, plausible

__all__ = ["NEUTRAL_ANGLE_DEG", "Actuator", "FitIdentity", "ModelParams", "bladder_area_mm2", "frame_inertia_mm4",
           "outside_tested_range", "t0_start_mm"]

#: The braid angle at which a McKibben sleeve has maximum volume, arctan(sqrt 2) = 54.7356 deg.
NEUTRAL_ANGLE_DEG = math.degrees(math.atan(math.sqrt(2.0)))


def _numeric(**values) -> None:
    """One InputError line for a value that is not a number or an array of numbers (mm)."""
    for name, value in values.items():
        float_array(name, value, "mm")


def t0_start_mm(R0_mm, t0_mm, R0_start_mm):
    """Bladder wall thickness at P_start (mm), eq 52: constant wall area (eq 51); scalars or arrays.

    >>> round(float(t0_start_mm(8.5, 2.5, 10.1)), 4)     # the paper's BE-PAM: 2.5 mm stretched to 10.1 mm
    1.9907
    """
    _numeric(R0_mm=R0_mm, t0_mm=t0_mm, R0_start_mm=R0_start_mm)
    return R0_start_mm - np.sqrt(R0_start_mm * R0_start_mm - 2.0 * R0_mm * t0_mm + t0_mm * t0_mm)


def bladder_area_mm2(R0_mm, t0_mm):
    """Bladder wall cross-section area (mm^2), invariant under the prestrain (eq 51).

    >>> round(float(bladder_area_mm2(8.5, 2.5)), 2)
    113.88
    """
    _numeric(R0_mm=R0_mm, t0_mm=t0_mm)
    return np.pi * (2.0 * R0_mm * t0_mm - t0_mm * t0_mm)


def frame_inertia_mm4(width_mm, thickness_mm):
    """Second moment of area of the frame strip, ``I_f = w h^3 / 12`` (mm^4), eq 16 and 27.

    >>> frame_inertia_mm4(5.0, 0.5)                      # Table 1: 5 mm x 0.5 mm
    0.052083...
    """
    _numeric(width_mm=width_mm, thickness_mm=thickness_mm)
    return width_mm * thickness_mm**3 / 12.0


#: Actuator fields that are not inputs of the models (labels and the limits of :mod:`bendpam.physics.limits`).
_NOT_MODEL_PARAMS = ("name", "model", "frame_strength_mpa", "bladder_stretch_limit", "tested_pressure_kpa",
                     "fit_identity")

#: The hard limits of the numeric fields (the models' domain): (lo, hi, lo open, hi open, unit); ``t0_mm``
#: and ``R0_start_mm`` are bounded by ``R0_mm``.  The plausible ranges inside them: :data:`bendpam.validate.PLAUSIBLE`.
_HARD = {
    "alpha0_deg": (0.0, 90.0, True, True, "deg"),
    "R0_mm": (0.0, None, True, False, "mm"),
    "L0_mm": (0.0, None, True, False, "mm"),
    "frame_thickness_mm": (0.0, None, True, False, "mm"),
    "frame_width_mm": (0.0, None, True, False, "mm"),
    "frame_modulus_mpa": (0.0, None, True, False, "MPa"),
    "C10_kpa": (None, None, False, False, "kPa"),
    "C01_kpa": (None, None, False, False, "kPa"),
    "P_start_kpa": (0.0, None, False, False, "kPa"),
    "braid_thickness_mm": (0.0, None, True, False, "mm"),
    "max_pressure_kpa": (0.0, None, True, False, "kPa"),
}


def _suggest(key: str, known) -> str:
    """``'alpha_deg' (did you mean 'alpha0_deg'?); known: ...`` for an unknown key."""
    return f"{key!r}{did_you_mean(key, known)}; known: {', '.join(known)}"


@dataclass(frozen=True)
class FitIdentity:
    """Where a fitted actuator's constants came from: the fit that wrote it.

    Attributes
    ----------
    fit_json_sha256 : SHA-256 (hex) of the ``fit.json`` written beside the actuator ("" before it is saved).
    processed : the processed test set the fit was made on (the folder's name; "" when unknown).
    date : when the fit was made, ISO 8601 UTC (``2026-11-25T18:30:00Z``).
    version : the bendpam version that made it.

    >>> ident = FitIdentity(processed="be-tests", date="2026-11-25T18:30:00Z", version="0.4.0")
    >>> FitIdentity.from_dict(ident.to_dict()) == ident, ident.describe()
    (True, "fit of 'be-tests' on 2026-11-25T18:30:00Z (bendpam 0.4.0)")
    """

    fit_json_sha256: str = ""
    processed: str = ""
    date: str = ""
    version: str = ""

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            if not isinstance(getattr(self, f.name), str):
                raise InputError(f"fit_identity.{f.name} = {getattr(self, f.name)!r} must be a string")

    def to_dict(self) -> dict[str, str]:
        """The fields as a plain dict (the ``[actuator.fit_identity]`` table of an actuator file)."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, data: Any, source: str = "fit_identity") -> FitIdentity:
        """From :meth:`to_dict`'s dict; an unknown key or a value that is not a string is one InputError line."""
        if isinstance(data, FitIdentity):
            return data
        if not isinstance(data, dict):
            raise InputError(f"{source}: expected a table (fit_json_sha256, processed, date, version), "
                             f"got {type(data).__name__}")
        known = [f.name for f in dataclasses.fields(cls)]
        unknown = [k for k in data if k not in known]
        if unknown:
            raise InputError(f"{source}: unknown key {_suggest(unknown[0], known)}")
        return cls(**data)

    def describe(self) -> str:
        """One line for messages: what was fitted, when, by which version."""
        what = f"fit of {self.processed!r}" if self.processed else "fit"
        when = f" on {self.date}" if self.date else ""
        ver = f" (bendpam {self.version})" if self.version else ""
        sha = f", fit.json sha256 {self.fit_json_sha256[:12]}" if self.fit_json_sha256 else ""
        return f"{what}{when}{ver}{sha}"


def _tested_pair(value: Any) -> tuple[float, float] | None:
    """``tested_pressure_kpa`` checked: None, or two finite pressures ``0 <= lo <= hi`` (kPa)."""
    if value is None:
        return None
    msg = f"tested_pressure_kpa = {value!r} must be two pressures [lowest, highest] in kPa with 0 <= lowest <= highest"
    if isinstance(value, str | bytes | dict) or not hasattr(value, "__len__") or len(value) != 2:
        raise InputError(msg)
    lo = number("tested_pressure_kpa[0]", value[0], 0.0, unit="kPa")
    hi = number("tested_pressure_kpa[1]", value[1], 0.0, unit="kPa")
    if lo > hi:
        raise InputError(msg)
    return (lo, hi)


def outside_tested_range(tested_kpa: tuple[float, float] | None, pressure_kpa, label: str = "") -> np.ndarray:
    """Which pressures lie outside the tested range ``tested_kpa`` (kPa); warns once if any do.

    The one check of a fitted actuator (or a fit) used where it was not tested: an
    :class:`~bendpam.errors.OutsideTestedRangeWarning` line names the first such pressure and the range.
    ``tested_kpa`` None (or not finite): nothing is outside.  A tolerance of 1e-9 kPa absorbs round-off.

    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     outside_tested_range((100.0, 200.0), [150.0, 250.0], "my PAM").tolist()
    [False, True]
    >>> str(caught[0].message)
    'pressure 250 kPa is outside the tested range [100, 200] kPa of my PAM (the prediction is an extrapolation)'
    """
    P = np.asarray(pressure_kpa, dtype=float)
    out = np.zeros(P.shape, dtype=bool)
    if tested_kpa is None or not all(math.isfinite(v) for v in tested_kpa):
        return out
    lo, hi = tested_kpa
    out = (P < lo - 1e-9) | (P > hi + 1e-9)
    if np.any(out):
        of = f" of {label}" if label else ""
        warn_user(f"pressure {float(P[out].flat[0]):g} kPa is outside the tested range [{lo:g}, {hi:g}] kPa{of} "
                  "(the prediction is an extrapolation)", OutsideTestedRangeWarning)
    return out


@dataclass(frozen=True)
class ModelParams:
    """An actuator (or an array of actuator cases) in the models' internal units: mm, MPa, rad.

    This is the numerics' view of an :class:`Actuator`; users never build one by hand.  Every
    field is a float for one actuator, or an array of one shape for a block of cases (sweeps,
    design searches), so the kinematics and both models evaluate many actuators at once.  The
    derived values of eq 51-52 are computed here and nowhere else (:meth:`build`).

    Attributes
    ----------
    alpha0 : initial braid angle, rad.
    R0_start, t0_start : bladder outer radius and wall thickness at P_start, mm (eq 51-52).
    bladder_area : bladder wall cross-section area, mm^2 (eq 51).
    frame_stiffness : E_f I_f, N*mm^2 (eq 16, 27).
    frame_modulus : E_f, MPa.  frame_thickness : h_f, mm.
    C10, C01 : Mooney-Rivlin constants, MPa.
    P_start : threshold pressure, MPa (eq 50); ``P_start_kpa`` the same in kPa, exactly as given.
    L0 : active length, mm.  braid_thickness : t_br, mm.
    R0 : outer radius of the as-made (unstressed) bladder, mm, for the stretches of
        :mod:`bendpam.physics.limits`; ``None`` (a hand-made block) means no prestrain, ``R0 = R0_start``.
    max_pressure_kpa : the burst limit, kPa (the actuator's; default 2000): the law of these cases
        refuses pressures above it.

    Examples
    --------
    >>> import bendpam
    >>> p = bendpam.physics.presets.be_pam().params
    >>> round(float(p.C10), 4), p.P_start, round(float(p.frame_stiffness), 2)    # MPa, MPa, N*mm^2
    (-0.3189, 0.068, 353.96)
    """

    alpha0: Any
    R0_start: Any
    t0_start: Any
    bladder_area: Any
    frame_stiffness: Any
    frame_modulus: Any
    frame_thickness: Any
    C10: Any
    C01: Any
    P_start: Any
    L0: Any
    braid_thickness: Any
    P_start_kpa: Any = 0.0
    R0: Any = None
    max_pressure_kpa: Any = DEFAULT_MAX_PRESSURE_KPA

    @classmethod
    def build(cls, *, alpha0_deg, R0_mm, t0_mm, L0_mm, frame_thickness_mm, frame_width_mm, frame_modulus_mpa,
              C10_kpa, C01_kpa, P_start_kpa, R0_start_mm, braid_thickness_mm=0.3,
              max_pressure_kpa=DEFAULT_MAX_PRESSURE_KPA) -> ModelParams:
        """From user units (the :class:`Actuator` field names); scalars or arrays that broadcast."""
        return cls(
            alpha0=np.radians(alpha0_deg), R0_start=R0_start_mm * 1.0,
            t0_start=t0_start_mm(R0_mm, t0_mm, R0_start_mm), bladder_area=bladder_area_mm2(R0_mm, t0_mm),
            frame_stiffness=frame_modulus_mpa * frame_inertia_mm4(frame_width_mm, frame_thickness_mm),
            frame_modulus=frame_modulus_mpa * 1.0, frame_thickness=frame_thickness_mm * 1.0,
            C10=C10_kpa * 1e-3, C01=C01_kpa * 1e-3, P_start=P_start_kpa * 1e-3, L0=L0_mm * 1.0,
            braid_thickness=braid_thickness_mm * 1.0, P_start_kpa=P_start_kpa * 1.0, R0=R0_mm * 1.0,
            max_pressure_kpa=max_pressure_kpa * 1.0,
        )

    @property
    def shape(self) -> tuple[int, ...]:
        """Broadcast shape of the fields: ``()`` for one actuator."""
        return np.broadcast_shapes(*(np.shape(v) for v in self.__dict__.values()))

    def broadcast(self) -> ModelParams:
        """Every field as a float array of :attr:`shape` (one entry per case)."""
        shp = self.shape
        return ModelParams(**{k: np.array(np.broadcast_to(v, shp), dtype=float) for k, v in self.__dict__.items()})

    def take(self, index) -> ModelParams:
        """The cases at ``index`` (array fields only; scalars stay)."""
        return ModelParams(**{k: (np.asarray(v)[index] if np.ndim(v) else v) for k, v in self.__dict__.items()})

    def rows(self, index) -> Any:
        """The cases at ``index`` as a view that gathers a field only when it is read (once).

        The same values as :meth:`take`, for the hot loops of the root solvers and the margins, which
        read a few of the fields of many cases.

        Examples
        --------
        >>> import numpy as np, bendpam
        >>> p = bendpam.physics.presets.be_pam().params
        >>> q = ModelParams(**{k: np.full(3, v, dtype=float) if v is not None else None for k, v in p.__dict__.items()})
        >>> bool(q.rows(np.array([0, 2])).alpha0.tolist() == q.take(np.array([0, 2])).alpha0.tolist())
        True
        """
        return _Rows(self, index)

    def col(self) -> ModelParams:
        """The same cases with a trailing axis, to broadcast against per-case samples."""
        return ModelParams(**{k: (np.asarray(v)[..., None] if np.ndim(v) else v) for k, v in self.__dict__.items()})

    @property
    def bend_sign(self):
        """+1 (BE-PAM, bends toward the frame), -1 (BC-PAM) or 0 (neutral braid angle), per case."""
        return np.sign(np.round(np.degrees(self.alpha0) - NEUTRAL_ANGLE_DEG, 9)).astype(int)


class _Rows:
    """:meth:`ModelParams.rows`: the fields of some cases, each gathered on its first read."""

    def __init__(self, params: ModelParams, index):
        self._params, self._index = params, index

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_"):
            raise AttributeError(name)
        v = getattr(self._params, name)
        v = np.asarray(v)[self._index] if np.ndim(v) else v
        setattr(self, name, v)
        return v


@dataclass(frozen=True)
class Actuator:
    """Geometry and materials of a bending PAM (paper Table 1 and Table 3).

    Parameters
    ----------
    alpha0_deg : float
        Initial braid angle alpha_0, measured from the actuator axis, degrees, in (0, 90).  Above
        54.74 deg the actuator is a BE-PAM (bends toward the frame, k' > 0); below, a BC-PAM.
    R0_mm : float
        Outer radius of the unpressurised bladder tube, mm.
    t0_mm : float
        Wall thickness of the unpressurised bladder tube, mm, in (0, R0_mm).
    L0_mm : float
        Active length (length of the inextensible frame), mm.
    frame_thickness_mm, frame_width_mm : float
        Cross-section of the elastic frame (a thin strip), mm.  Its second moment of area is
        ``I_f = width * thickness^3 / 12`` (eq 16, 27).
    frame_modulus_mpa : float
        Young's modulus E_f of the frame, MPa (Table 1: 6.796 GPa = 6796 MPa).
    C10_kpa, C01_kpa : float
        Mooney-Rivlin constants of the bladder, kPa.  Either may be negative, but
        ``C10 + C01 > 0``.
    P_start_kpa : float
        Threshold (deadband) pressure P_start, kPa, >= 0 (eq 50).
    R0_start_mm : float, optional
        Outer bladder radius at P_start, mm, >= R0_mm.  Defaults to ``R0_mm`` (no prestrain).
        ``t0_start`` follows from eq 52.
    braid_thickness_mm : float
        Nominal braid-sleeve thickness t_br, mm.  It cancels out of the moment (eq 49) and is used
        only to turn the braid line tension into the nominal stress sigma_br (eq 31, 48).
    name : str
        A label for tables and figures.
    model : str
        The model whose identification gave these constants (``"energy"``, ``"force_balance"``) or
        ``""`` (unknown).  Table 3 gives different constants for each model; the command line warns
        when an actuator is used with the other model.
    frame_strength_mpa : float, optional
        Strength of the frame material, MPa, > 0 (for a glass-fibre epoxy strip a few hundred MPa).
        :func:`bendpam.physics.limits` compares the frame's largest combined axial and bending stress with
        it; ``None`` (default): no strength check.
    bladder_stretch_limit : float, optional
        Largest principal stretch the bladder may reach, dimensionless, > 1, counted from the
        as-made tube (``R0_mm``, ``t0_mm``: the prestrain of eq 51-52 included), e.g. 3.0 for a
        latex tube used well below its elongation at break.  :func:`bendpam.physics.limits` reports the
        margin in strain, ``(limit - 1) / (stretch - 1)``; ``None`` (default): no stretch check.
    max_pressure_kpa : float
        The burst limit, kPa (default 2000 = 2 MPa, more than any pneumatic PAM holds): every
        function that takes this actuator and pressures refuses a pressure above it.  Raise it for
        a hydraulic muscle (up to 100 MPa).
    tested_pressure_kpa : (float, float), optional
        The lowest and highest pressure (kPa) of the tests these constants were identified on
        (``bendpam fit`` writes it).  Predictions outside it warn
        (:class:`~bendpam.errors.OutsideTestedRangeWarning`); ``None`` (default): not a fitted actuator.
    fit_identity : FitIdentity, optional
        The fit that wrote these constants (``fit.json``'s SHA-256, the processed set, date, version);
        a dict of those keys is accepted.

    Notes
    -----
    Every numeric field must also lie in its physical plausibility range
    (:data:`bendpam.validate.PLAUSIBLE`, docs/plausibility.md): a braid angle of 10 to 88 deg,
    ``R0_start_mm`` at most 3 ``R0_mm``, a frame modulus from rubber to steel, and so on.

    Examples
    --------
    >>> import bendpam
    >>> a = bendpam.Actuator(alpha0_deg=70, R0_mm=8.5, t0_mm=2.5, L0_mm=145, frame_thickness_mm=0.5,
    ...                      frame_width_mm=5, frame_modulus_mpa=6796, C10_kpa=114, C01_kpa=300,
    ...                      P_start_kpa=68, R0_start_mm=10.1)
    >>> a.kind, a.bend_sign, round(a.t0_start_mm, 4)
    ('BE-PAM', 1, 1.9907)
    >>> a.replace(alpha0_deg=40).kind
    'BC-PAM'
    >>> print(a.to_toml().splitlines()[2])               # a.to_toml("a.toml") writes the file
    alpha0_deg = 70.0
    >>> bendpam.Actuator(**{**a.to_dict(), "t0_mm": 9.0})
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: t0_mm = 9 mm is outside the allowed range (0, 8.5) mm
    >>> a.replace(R0_start_mm=1e22)
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: R0_start_mm = 1e+22 mm is outside the plausible range [R0_mm, 3 R0_mm] = [8.5, 25.5] ...
    """

    alpha0_deg: float
    R0_mm: float
    t0_mm: float
    L0_mm: float
    frame_thickness_mm: float
    frame_width_mm: float
    frame_modulus_mpa: float
    C10_kpa: float
    C01_kpa: float
    P_start_kpa: float = 0.0
    R0_start_mm: float | None = None
    braid_thickness_mm: float = 0.3
    name: str = ""
    model: str = ""
    frame_strength_mpa: float | None = None
    bladder_stretch_limit: float | None = None
    max_pressure_kpa: float = DEFAULT_MAX_PRESSURE_KPA
    tested_pressure_kpa: tuple[float, float] | None = None
    fit_identity: FitIdentity | None = None

    # derived, filled in __post_init__
    _material: MooneyRivlin = field(init=False, repr=False, compare=False, hash=False)
    _params: ModelParams = field(init=False, repr=False, compare=False, hash=False)

    def __post_init__(self) -> None:
        s = object.__setattr__
        for name, (lo, hi, open_lo, open_hi, unit) in _HARD.items():
            s(self, name, number(name, getattr(self, name), lo, hi, lo_open=open_lo, hi_open=open_hi, unit=unit))
        s(self, "t0_mm", number("t0_mm", self.t0_mm, 0.0, self.R0_mm, lo_open=True, hi_open=True, unit="mm"))
        if self.C10_kpa + self.C01_kpa <= 0.0:
            raise InputError(
                f"C10_kpa + C01_kpa = {self.C10_kpa + self.C01_kpa:g} kPa must be > 0 "
                "(the bladder's initial shear modulus 2(C10 + C01) must be positive); "
                f"got C10_kpa = {self.C10_kpa:g}, C01_kpa = {self.C01_kpa:g}"
            )
        if self.R0_start_mm is None:
            s(self, "R0_start_mm", self.R0_mm)
        else:
            s(self, "R0_start_mm", number("R0_start_mm", self.R0_start_mm, self.R0_mm, unit="mm"))
        if type(self.model) is not str and isinstance(self.model, str):
            s(self, "model", str(self.model))  # a plain name (a resolved model name is a str subclass)
        if self.model not in ("", "energy", "force_balance"):
            raise InputError(f"model = {self.model!r}: the model the constants were identified with must be "
                             "'energy', 'force_balance' or '' (unknown)")
        if not isinstance(self.name, str):
            raise InputError(f"name = {self.name!r} must be a string")
        if self.frame_strength_mpa is not None:
            s(self, "frame_strength_mpa",
              number("frame_strength_mpa", self.frame_strength_mpa, 0.0, lo_open=True, unit="MPa"))
        if self.bladder_stretch_limit is not None:
            s(self, "bladder_stretch_limit",
              number("bladder_stretch_limit", self.bladder_stretch_limit, 1.0, lo_open=True))  # a stretch: no unit
        s(self, "tested_pressure_kpa", _tested_pair(self.tested_pressure_kpa))
        if self.fit_identity is not None:
            s(self, "fit_identity", FitIdentity.from_dict(self.fit_identity))
        values = {f: getattr(self, f) for f in PLAUSIBLE if getattr(self, f, None) is not None}
        for name, value in values.items():  # physical plausibility (docs/plausibility.md), after the hard limits
            plausible(name, value, values)
        s(self, "_material", MooneyRivlin(self.C10_kpa * 1e-3, self.C01_kpa * 1e-3))
        s(self, "_params", ModelParams.build(**{f: getattr(self, f) for f in self.field_names()
                                                     if f not in _NOT_MODEL_PARAMS}))

    # ---- derived values (units in the names) ---------------------------------------------------
    @property
    def params(self) -> ModelParams:
        """The numerics' view: the same actuator in mm, MPa and rad (see :class:`ModelParams`)."""
        return self._params

    @property
    def material(self) -> MooneyRivlin:
        """The bladder's :class:`~bendpam.physics.material.MooneyRivlin` law (constants in MPa, numerics only)."""
        return self._material

    @property
    def t0_start_mm(self) -> float:
        """Bladder wall thickness at P_start, mm: eq 52, constant wall area (eq 51)."""
        return float(self._params.t0_start)

    @property
    def bladder_area_mm2(self) -> float:
        """Bladder wall cross-section area, mm^2 (invariant, eq 51)."""
        return float(self._params.bladder_area)

    @property
    def frame_inertia_mm4(self) -> float:
        """Second moment of area of the frame strip, I_f = w h^3 / 12, mm^4."""
        return float(frame_inertia_mm4(self.frame_width_mm, self.frame_thickness_mm))

    @property
    def frame_stiffness_nmm2(self) -> float:
        """Bending stiffness of the frame E_f I_f, N*mm^2 (eq 16, 27)."""
        return float(self._params.frame_stiffness)

    def _summary(self) -> tuple[str, list[tuple[str, Any]], list[str], list[list[Any]]]:
        items: list[tuple[str, Any]] = [
            ("kind", self.kind), ("braid angle alpha0_deg", self.alpha0_deg),
            ("bladder R0_mm, t0_mm", f"{self.R0_mm:g}, {self.t0_mm:g}"), ("active length L0_mm", self.L0_mm),
            ("Mooney-Rivlin C10_kpa, C01_kpa", f"{self.C10_kpa:g}, {self.C01_kpa:g}"),
            ("threshold P_start_kpa", self.P_start_kpa)]
        if self.model:
            items.append(("identified with", self.model.replace("_", "-") + " model"))
        return f"Actuator {self.name or self.kind}", items, [], []

    def __repr__(self) -> str:
        """A few lines: the name, the kind and the main parameters (``to_toml()`` has them all).

        >>> from bendpam.physics.presets import be_pam
        >>> print(repr(be_pam()).splitlines()[:3])
        ['Actuator BE-PAM (paper, energy constants)', '  kind: BE-PAM', '  braid angle alpha0_deg: 69.7']
        """
        return summary_text(*self._summary())

    def _repr_html_(self) -> str:
        """The summary of :meth:`__repr__` for a notebook (HTML)."""
        return summary_html(*self._summary())

    @property
    def kind(self) -> str:
        """``"BE-PAM"`` above the neutral angle 54.74 deg, ``"BC-PAM"`` below, ``"neutral"`` at it."""
        if abs(self.alpha0_deg - NEUTRAL_ANGLE_DEG) < 1e-9:
            return "neutral"
        return "BE-PAM" if self.alpha0_deg > NEUTRAL_ANGLE_DEG else "BC-PAM"

    @property
    def bend_sign(self) -> int:
        """+1 if the actuator bends freely toward the frame (k' > 0), -1 away from it, 0 at 54.74 deg."""
        return {"BE-PAM": 1, "BC-PAM": -1, "neutral": 0}[self.kind]

    # ---- convenience ----------------------------------------------------------------------------
    def replace(self, **changes: Any) -> Actuator:
        """Return a copy with some fields changed (validated again)."""
        unknown = [k for k in changes if k not in self.field_names()]
        if unknown:
            raise InputError(f"unknown actuator parameter {_suggest(unknown[0], self.field_names())}")
        return dataclasses.replace(self, **changes)

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in dataclasses.fields(cls) if f.init)

    def to_dict(self) -> dict[str, Any]:
        """The init fields as a plain dict (units in the names): plain numbers, strings, lists and dicts."""
        d = {n: getattr(self, n) for n in self.field_names()}
        if self.tested_pressure_kpa is not None:
            d["tested_pressure_kpa"] = list(self.tested_pressure_kpa)
        if self.fit_identity is not None:
            d["fit_identity"] = self.fit_identity.to_dict()
        return d

    def outside_tested(self, pressure_kpa) -> np.ndarray:
        """Which of ``pressure_kpa`` lie outside :attr:`tested_pressure_kpa`; warns once if any do.

        >>> import bendpam
        >>> bendpam.physics.presets.be_pam().outside_tested([100.0, 300.0]).tolist()   # not fitted: no range
        [False, False]
        """
        return outside_tested_range(self.tested_pressure_kpa, pressure_kpa, self.name or self.kind)

    def derived(self) -> dict[str, float]:
        """Derived quantities, units in the names."""
        return {
            "t0_start_mm": self.t0_start_mm,
            "bladder_area_mm2": self.bladder_area_mm2,
            "frame_inertia_mm4": self.frame_inertia_mm4,
            "frame_stiffness_nmm2": self.frame_stiffness_nmm2,
            "shear_modulus_kpa": 2.0 * (self.C10_kpa + self.C01_kpa),
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any], *, source: str = "actuator") -> Actuator:
        """Build from a dict of init fields; unknown or missing keys raise a one-line InputError.

        Values are type-checked: a bool or a string is not a number.  An unknown key is reported
        with the nearest known one.
        """
        if not isinstance(data, dict):
            raise InputError(f"{source}: expected a table of actuator parameters, got {type(data).__name__}")
        names = cls.field_names()
        unknown = [k for k in data if k not in names]
        if unknown:
            raise InputError(f"{source}: unknown actuator parameter {_suggest(unknown[0], names)}")
        required = [f.name for f in dataclasses.fields(cls) if f.init and f.default is dataclasses.MISSING]
        missing = [k for k in required if k not in data]
        if missing:
            raise InputError(f"{source}: missing actuator parameter(s) {', '.join(missing)}")
        try:
            return cls(**data)
        except InputError as exc:
            raise InputError(f"{source}: {exc}") from None

    def to_toml(self, path: str | os.PathLike | None = None) -> str:
        """Serialise to TOML (an ``[actuator]`` table); write atomically to ``path`` if given."""
        d = {k: v for k, v in self.to_dict().items() if v is not None}
        text = "# bendpam actuator description (units in the key names)\n" + tomli_w.dumps({"actuator": d})
        if path is not None:
            atomic_write_text(path, text)
        return text

    @classmethod
    def from_toml(cls, path: str | os.PathLike) -> Actuator:
        """Read an actuator from a TOML file with an ``[actuator]`` table (or top-level keys).

        The file must be a regular file of at most 1 MiB with tables nested at most 3 deep
        (:mod:`bendpam.infra.budgets`); anything else is refused in one line before it is read.
        """
        p = Path(path)
        data = read_toml_file(p, "actuator file")
        if "actuator" in data:
            extra = [k for k in data if k not in ("actuator", "hysteresis")]
            if extra:
                raise InputError(f"{p}: unknown table or key {_suggest(extra[0], ('actuator', 'hysteresis'))}")
            return cls.from_dict(data["actuator"], source=str(p))
        return cls.from_dict({k: v for k, v in data.items() if k != "hysteresis"}, source=str(p))

    def summary(self) -> str:
        """A short human-readable description."""
        label = self.name or self.kind
        return (
            f"{label}: alpha0={self.alpha0_deg:g} deg, R0={self.R0_mm:g} mm, t0={self.t0_mm:g} mm, "
            f"L0={self.L0_mm:g} mm, frame {self.frame_thickness_mm:g}x{self.frame_width_mm:g} mm "
            f"E={self.frame_modulus_mpa:g} MPa, C10={self.C10_kpa:g} kPa, C01={self.C01_kpa:g} kPa, "
            f"P_start={self.P_start_kpa:g} kPa, R0_start={self.R0_start_mm:g} mm (t0_start={self.t0_start_mm:.4g} mm)"
        )

