"""The :class:`Actuator`: an immutable, validated description of one bending PAM.

Field names carry their units (``alpha0_deg``, ``R0_mm``, ``C10_kpa`` ...) because that is how a
user writes them down.  Properties without a unit suffix (``alpha0``, ``C10``, ``P_start`` ...) give
the same values in the package's internal units: mm, MPa (N/mm^2), N*mm, radians.

The deadband and prestrain corrections of section 3.3 are part of the description: the bladder is
stress-free at ``P_start`` with outer radius ``R0_start`` and thickness ``t0_start`` given by eq 51-52
(constant bladder cross-section area, constant length).  Both models use ``R0_start`` and
``t0_start`` in place of ``R0`` and ``t0`` everywhere (NOTES.md item 11).
"""

from __future__ import annotations

import dataclasses
import math
import os
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import tomli_w

from ._io import atomic_write_text
from .material import MooneyRivlin

__all__ = ["Actuator", "NEUTRAL_ANGLE_DEG"]

#: The braid angle at which a McKibben sleeve has maximum volume, arctan(sqrt 2) = 54.7356 deg.
NEUTRAL_ANGLE_DEG = math.degrees(math.atan(math.sqrt(2.0)))


def _check(name: str, value: Any, lo: float | None, hi: float | None, *, lo_open=True, hi_open=True, unit=""):
    """Validate a scalar against an interval and return it as float; raise a clear ValueError."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {value!r} is not a number") from None
    lo_s = "(" if lo_open else "["
    hi_s = ")" if hi_open else "]"
    rng = f"{lo_s}{'-inf' if lo is None else f'{lo:g}'}, {'inf' if hi is None else f'{hi:g}'}{hi_s}"
    u = f" {unit}" if unit else ""
    if not math.isfinite(v):
        raise ValueError(f"{name} = {value!r}{u} is not finite; allowed range {rng}{u}")
    bad_lo = lo is not None and (v <= lo if lo_open else v < lo)
    bad_hi = hi is not None and (v >= hi if hi_open else v > hi)
    if bad_lo or bad_hi:
        raise ValueError(f"{name} = {v:g}{u} is outside the allowed range {rng}{u}")
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

    # derived, filled in __post_init__
    _material: MooneyRivlin = field(init=False, repr=False, compare=False, hash=False)

    def __post_init__(self) -> None:
        s = object.__setattr__
        s(self, "alpha0_deg", _check("alpha0_deg", self.alpha0_deg, 0.0, 90.0, unit="deg"))
        s(self, "R0_mm", _check("R0_mm", self.R0_mm, 0.0, None, unit="mm"))
        s(self, "t0_mm", _check("t0_mm", self.t0_mm, 0.0, self.R0_mm, unit="mm"))
        s(self, "L0_mm", _check("L0_mm", self.L0_mm, 0.0, None, unit="mm"))
        s(self, "frame_thickness_mm", _check("frame_thickness_mm", self.frame_thickness_mm, 0.0, None, unit="mm"))
        s(self, "frame_width_mm", _check("frame_width_mm", self.frame_width_mm, 0.0, None, unit="mm"))
        s(self, "frame_modulus_mpa", _check("frame_modulus_mpa", self.frame_modulus_mpa, 0.0, None, unit="MPa"))
        s(self, "C10_kpa", _check("C10_kpa", self.C10_kpa, None, None, unit="kPa"))
        s(self, "C01_kpa", _check("C01_kpa", self.C01_kpa, None, None, unit="kPa"))
        if self.C10_kpa + self.C01_kpa <= 0.0:
            raise ValueError(
                f"C10_kpa + C01_kpa = {self.C10_kpa + self.C01_kpa:g} kPa must be > 0 "
                "(the bladder's initial shear modulus 2(C10 + C01) must be positive); "
                f"got C10_kpa = {self.C10_kpa:g}, C01_kpa = {self.C01_kpa:g}"
            )
        s(self, "P_start_kpa", _check("P_start_kpa", self.P_start_kpa, 0.0, None, lo_open=False, unit="kPa"))
        if self.R0_start_mm is None:
            s(self, "R0_start_mm", self.R0_mm)
        else:
            s(
                self,
                "R0_start_mm",
                _check("R0_start_mm", self.R0_start_mm, self.R0_mm, None, lo_open=False, unit="mm"),
            )
        s(self, "braid_thickness_mm", _check("braid_thickness_mm", self.braid_thickness_mm, 0.0, None, unit="mm"))
        if not isinstance(self.name, str):
            raise ValueError(f"name = {self.name!r} must be a string")
        s(self, "_material", MooneyRivlin(self.C10, self.C01))

    # ---- internal units -------------------------------------------------------------------------
    @property
    def alpha0(self) -> float:
        """Initial braid angle, rad."""
        return math.radians(self.alpha0_deg)

    @property
    def R0(self) -> float:
        """Unpressurised bladder outer radius, mm."""
        return self.R0_mm

    @property
    def t0(self) -> float:
        """Unpressurised bladder wall thickness, mm."""
        return self.t0_mm

    @property
    def L0(self) -> float:
        """Active (frame) length, mm."""
        return self.L0_mm

    @property
    def C10(self) -> float:
        """Mooney-Rivlin C10, MPa."""
        return self.C10_kpa * 1e-3

    @property
    def C01(self) -> float:
        """Mooney-Rivlin C01, MPa."""
        return self.C01_kpa * 1e-3

    @property
    def P_start(self) -> float:
        """Threshold pressure P_start, MPa (eq 50)."""
        return self.P_start_kpa * 1e-3

    @property
    def material(self) -> MooneyRivlin:
        """The bladder's :class:`~bendpam.material.MooneyRivlin` law (constants in MPa)."""
        return self._material

    @property
    def R0_start(self) -> float:
        """Bladder outer radius at P_start, mm (Table 1)."""
        return float(self.R0_start_mm)

    @property
    def t0_start(self) -> float:
        """Bladder wall thickness at P_start, mm: eq 52, constant wall area (eq 51)."""
        R0s = self.R0_start
        return R0s - math.sqrt(R0s * R0s - 2.0 * self.R0 * self.t0 + self.t0 * self.t0)

    @property
    def bladder_area(self) -> float:
        """Bladder wall cross-section area, mm^2 (invariant, eq 51)."""
        return math.pi * (2.0 * self.R0 * self.t0 - self.t0 * self.t0)

    @property
    def frame_inertia(self) -> float:
        """Second moment of area of the frame strip, I_f = w h^3 / 12, mm^4."""
        return self.frame_width_mm * self.frame_thickness_mm**3 / 12.0

    @property
    def frame_stiffness(self) -> float:
        """Bending stiffness of the frame E_f I_f, N*mm^2 (eq 16, 27)."""
        return self.frame_modulus_mpa * self.frame_inertia

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
        unknown = set(changes) - set(self.field_names())
        if unknown:
            raise ValueError(
                f"unknown actuator parameter(s) {sorted(unknown)}; known: {', '.join(self.field_names())}"
            )
        return dataclasses.replace(self, **changes)

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in dataclasses.fields(cls) if f.init)

    def to_dict(self) -> dict[str, Any]:
        """The init fields as a plain dict (units in the names), plus derived values under ``derived``."""
        d = {n: getattr(self, n) for n in self.field_names()}
        return d

    def derived(self) -> dict[str, float]:
        """Derived quantities, units in the names."""
        return {
            "t0_start_mm": self.t0_start,
            "bladder_area_mm2": self.bladder_area,
            "frame_inertia_mm4": self.frame_inertia,
            "frame_stiffness_nmm2": self.frame_stiffness,
            "shear_modulus_kpa": 2.0 * (self.C10_kpa + self.C01_kpa),
        }

    @classmethod
    def from_dict(cls, data: dict[str, Any], *, source: str = "actuator") -> Actuator:
        """Build from a dict of init fields; unknown or missing keys raise a clear ValueError."""
        if not isinstance(data, dict):
            raise ValueError(f"{source}: expected a table of actuator parameters, got {type(data).__name__}")
        names = cls.field_names()
        unknown = [k for k in data if k not in names]
        if unknown:
            raise ValueError(f"{source}: unknown actuator parameter(s) {unknown}; known: {', '.join(names)}")
        required = [f.name for f in dataclasses.fields(cls) if f.init and f.default is dataclasses.MISSING]
        missing = [k for k in required if k not in data]
        if missing:
            raise ValueError(f"{source}: missing actuator parameter(s) {missing}")
        try:
            return cls(**data)
        except ValueError as exc:
            raise ValueError(f"{source}: {exc}") from None

    def to_toml(self, path: str | os.PathLike | None = None) -> str:
        """Serialise to TOML (an ``[actuator]`` table); write atomically to ``path`` if given."""
        d = {k: v for k, v in self.to_dict().items() if v is not None}
        text = "# bendpam actuator description (units in the key names)\n" + tomli_w.dumps({"actuator": d})
        if path is not None:
            atomic_write_text(path, text)
        return text

    @classmethod
    def from_toml(cls, path: str | os.PathLike) -> Actuator:
        """Read an actuator from a TOML file with an ``[actuator]`` table (or top-level keys)."""
        p = Path(path)
        try:
            raw = p.read_bytes()
        except FileNotFoundError:
            raise ValueError(f"{p}: actuator file not found") from None
        except OSError as exc:
            raise ValueError(f"{p}: cannot read actuator file ({exc.strerror})") from None
        try:
            data = tomllib.loads(raw.decode("utf-8"))
        except UnicodeDecodeError as exc:
            raise ValueError(f"{p}: not UTF-8 text (byte {exc.start})") from None
        except tomllib.TOMLDecodeError as exc:
            raise ValueError(f"{p}: invalid TOML: {exc}") from None
        table = data.get("actuator", data)
        return cls.from_dict(table, source=str(p))

    def summary(self) -> str:
        """A short human-readable description."""
        label = self.name or self.kind
        return (
            f"{label}: alpha0={self.alpha0_deg:g} deg, R0={self.R0_mm:g} mm, t0={self.t0_mm:g} mm, "
            f"L0={self.L0_mm:g} mm, frame {self.frame_thickness_mm:g}x{self.frame_width_mm:g} mm "
            f"E={self.frame_modulus_mpa:g} MPa, C10={self.C10_kpa:g} kPa, C01={self.C01_kpa:g} kPa, "
            f"P_start={self.P_start_kpa:g} kPa, R0_start={self.R0_start:g} mm (t0_start={self.t0_start:.4g} mm)"
        )

