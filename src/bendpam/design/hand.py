r"""A soft humanoid hand of bending PAMs (the paper's section 4.2, Figure 9): description and kinematics.

The hand
--------
Four fingers and the palm are BE-PAMs; the thumb has two BE-PAM segments whose bending planes meet
at ``thumb_plane_deg`` (60 deg in the paper), mounted on a palm segment that rolls the thumb about
an axis parallel to the index finger.  The thumb tip has three freedoms: the two thumb pressures and
the palm's.  Each part has its own actuator (default: the paper's BE-PAM, :func:`bendpam.physics.presets.be_pam`,
with the part's length as ``L0_mm``) or one read from an actuator TOML.

Frame: origin at the middle of the wrist crease, ``x`` toward the thumb (radial), ``y`` along the
fingers (distal), ``z = x cross y`` toward the palm side (palmar), in mm.  The fingers lie straight
along ``+y`` from their bases on the knuckle line and curl toward ``+z``.  A left hand is the mirror
image (bendpam models the one with the thumb toward ``+x``).

Kinematics (no load)
--------------------
Each unloaded segment is a circular arc of its free-bending curvature at its pressure,
``k'(P)`` from :meth:`bendpam.MomentLaw.free_curvature_array` (the paper's model; the pressures are
sampled only through :class:`~bendpam.MomentLaw`), bending angle ``theta = k' L``.  In the frame
``(t, n)`` of its base (tangent, bending direction) an arc of length ``L`` ends at
``(L sin(theta)/theta) t + (L (1 - cos theta)/theta) n`` with its frame turned by ``theta`` about
``t x n``.

* **Fingers**: base at ``(base_x_mm, base_y_mm, 0)``, ``t = +y``, ``n = +z``.
* **Palm roll**: the palm's BE-PAM (length ``roll_length_mm``) rolls the thumb about the index
  finger's axis (the line ``x = base_x_mm`` of the index, ``z = 0``) by its own bend angle ``phi``,
  turning ``+x`` toward ``+z``: the palm segment acts as a hinge around the index metacarpal.
* **Thumb**: unrolled (``phi = 0``) its base is at ``thumb_base_mm`` in the palm plane, it points at
  ``thumb_direction_deg`` from ``+y`` toward ``+x`` and bends toward ``+z`` (in front of the palm);
  rolled by 90 deg its base is in front of the index and it bends across the palm toward the
  little finger.  The distal segment's bending plane is the proximal one's turned by
  ``thumb_plane_deg`` about the tangent, toward the palm.

Assumptions (the paper gives no dimensions of its hand)
-------------------------------------------------------
* Dimensions of a large adult hand with the paper's BE-PAM tubes (17 mm across, about a finger's
  width): knuckle line 105 mm from the wrist, fingers 20 mm apart, index 95, middle 105, ring 100
  and little 80 mm long; thumb base 22 mm radial of the index axis, 45 mm from the wrist, thumb
  at 35 deg from the index (radial abduction at rest), segments 70 + 70 mm; palm roll segment 70 mm.
* ``max_pressure_kpa`` = 300 kPa.  With the paper's BE-PAM constants a 70 mm segment bends 90 deg at
  about 285 kPa (96 deg at 300 kPa); the paper's characterisation went to 200 kPa, where the same
  segment bends 54 deg, so 90 deg per thumb segment with human proportions needs the model
  beyond its tested range (an extrapolation, stated).  Give another ``max_pressure_kpa`` or longer
  segments in the hand file.
* The parts are arcs of their free curvature: gravity and fingertip loads are not in these
  kinematics, and the parts do not collide (the thumb may pass through a finger or the palm).

Units: mm, kPa, degrees (names end in ``_mm``, ``_kpa``, ``_deg``).  Bad input raises
:class:`bendpam.InputError` naming the key and its allowed range.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from bendpam.design.parts import json_number
from bendpam.errors import InputError
from bendpam.infra.accessors import figure
from bendpam.infra.atomic import atomic_write_text
from bendpam.infra.budgets import read_toml_file
from bendpam.infra.outputs import to_json
from bendpam.physics import presets
from bendpam.physics.actuator import Actuator
from bendpam.physics.law import MomentLaw
from bendpam.physics.models import normalise_model
from bendpam.validate import did_you_mean, number

__all__ = [
    "FINGERS",
    "PARTS",
    "Hand",
    "HandPart",
    "HandPose",
    "arc_frames",
    "default_hand",
    "finger_frame",
    "hand_pose",
    "save_result",
    "thumb_base",
    "thumb_chain",
]

#: the four fingers, radial to ulnar
FINGERS = ("index", "middle", "ring", "little")
#: every actuated part of the hand (the order of :attr:`Hand.parts`)
PARTS = (*FINGERS, "thumb_proximal", "thumb_distal", "palm_roll")

#: default finger bases (x, y) and lengths, mm (see the module docstring)
_FINGER_DEFAULTS = {"index": (30.0, 105.0, 95.0), "middle": (10.0, 108.0, 105.0),
                    "ring": (-10.0, 105.0, 100.0), "little": (-30.0, 98.0, 80.0)}
_HAND_KEYS = {"max_pressure_kpa", "contact_tolerance_mm", "radius_mm", "model", "actuator"}
_FINGER_KEYS = {"base_x_mm", "base_y_mm", "length_mm", "actuator"}
_THUMB_KEYS = {"base_x_mm", "base_y_mm", "proximal_mm", "distal_mm", "plane_deg", "direction_deg", "actuator"}
_PALM_KEYS = {"roll_length_mm", "actuator"}
_TABLES = {"hand": _HAND_KEYS, **{f: _FINGER_KEYS for f in FINGERS}, "thumb": _THUMB_KEYS, "palm": _PALM_KEYS}
#: pressures tabulated per part to map bend angles back to pressures (kPa grid points)
_TABLE_POINTS = 3001


@dataclass(frozen=True)
class HandPart:
    """One BE-PAM part of the hand: a name, its active length (mm) and its actuator (``L0_mm`` = the length).

    Examples
    --------
    >>> part = HandPart("index", 95.0, presets.be_pam())
    >>> part.actuator.L0_mm, round(float(part.angle_deg(200.0)), 1)     # mm, deg at 200 kPa
    (95.0, 73.6)
    """

    name: str
    length_mm: float
    actuator: Actuator
    model: str = "energy"

    def __post_init__(self):
        s = object.__setattr__
        s(self, "length_mm", number(f"{self.name}.length_mm", self.length_mm, 1.0, 1000.0, unit="mm"))
        if not isinstance(self.actuator, Actuator):
            raise TypeError(f"actuator must be a bendpam.Actuator, got {type(self.actuator).__name__}")
        if self.actuator.bend_sign == 0:
            raise InputError(f"{self.name}: the actuator has the neutral braid angle (54.74 deg): it does not bend")
        s(self, "actuator", self.actuator.replace(L0_mm=self.length_mm))
        s(self, "_tables", {})  # angle tables by maximum pressure (not a field: no part of eq or repr)

    @property
    def law(self) -> MomentLaw:
        """The part's moment law (:meth:`bendpam.MomentLaw.of`)."""
        return MomentLaw.of(self.actuator, self.model)

    def angle_deg(self, pressure_kpa) -> np.ndarray:
        """Free bending angle (deg) at the pressures (kPa): ``|k'(P)| L``; NaN where there is no equilibrium."""
        k = self.law.free_curvature_array(np.asarray(pressure_kpa, dtype=float))
        return np.degrees(np.abs(k) * self.length_mm)

    def angle_table(self, max_pressure_kpa: float) -> tuple[np.ndarray, np.ndarray]:
        """Pressures (kPa) from 0 to ``max_pressure_kpa`` and the free bending angles there (deg), up to the
        first pressure without an equilibrium (the angle rises with the pressure beyond ``P_start``)."""
        key = float(max_pressure_kpa)
        if key not in self._tables:  # type: ignore[attr-defined]
            P = np.linspace(0.0, key, _TABLE_POINTS)
            a = self.angle_deg(P)
            bad = ~np.isfinite(a)
            if bad.any():
                n = int(np.argmax(bad))
                P, a = P[:n], a[:n]
            self._tables[key] = (P, a)  # type: ignore[attr-defined]
        return self._tables[key]  # type: ignore[attr-defined]

    def pressure_for_angle(self, angle_deg, max_pressure_kpa: float) -> np.ndarray:
        """The pressure (kPa) at which the part bends ``angle_deg`` freely (interpolated in :meth:`angle_table`);
        0 for 0 deg, NaN beyond the largest angle up to ``max_pressure_kpa``."""
        P, a = self.angle_table(max_pressure_kpa)
        ang = np.asarray(angle_deg, dtype=float)
        start = int(np.searchsorted(a, 1e-12, side="right"))  # the last pressure of the deadband (angle 0)
        lo = max(start - 1, 0)
        out = np.interp(ang, a[lo:], P[lo:], right=np.nan)
        return np.where(ang <= 0.0, 0.0, out)


def _part(name: str, length: float, act: Actuator | None, model: str) -> HandPart:
    return HandPart(name, length, act if act is not None else presets.be_pam(model), model)


@dataclass(frozen=True)
class Hand:
    """The hand: its seven BE-PAM parts and their placement (validated, immutable).

    Build it with :func:`default_hand` or :meth:`from_toml`.  ``finger_bases_mm`` maps each finger to
    its base ``(x, y)`` on the knuckle line (mm).  See the module docstring for the frame and the
    default dimensions (assumptions).

    Examples
    --------
    >>> hand = default_hand()
    >>> [p.name for p in hand.parts][4:], hand.thumb_plane_deg, hand.max_pressure_kpa
    (['thumb_proximal', 'thumb_distal', 'palm_roll'], 60.0, 300.0)
    """

    parts: tuple
    finger_bases_mm: dict = field(default_factory=dict)
    thumb_plane_deg: float = 60.0
    thumb_direction_deg: float = 35.0
    thumb_base_mm: tuple = (52.0, 45.0)
    max_pressure_kpa: float = 300.0
    contact_tolerance_mm: float = 8.5
    radius_mm: float = 8.5
    model: str = "energy"

    def __post_init__(self):
        s = object.__setattr__
        names = tuple(getattr(p, "name", None) for p in self.parts)
        if names != PARTS:
            raise InputError(f"a hand has the parts {', '.join(PARTS)} in that order; got {names}")
        s(self, "thumb_plane_deg", number("thumb.plane_deg", self.thumb_plane_deg, 0.0, 180.0, unit="deg"))
        s(self, "thumb_direction_deg",
          number("thumb.direction_deg", self.thumb_direction_deg, -90.0, 90.0, unit="deg"))
        s(self, "max_pressure_kpa", number("hand.max_pressure_kpa", self.max_pressure_kpa, 0.0, 2000.0,
                                           lo_open=True, unit="kPa"))
        s(self, "contact_tolerance_mm",
          number("hand.contact_tolerance_mm", self.contact_tolerance_mm, 0.0, 100.0, lo_open=True, unit="mm"))
        s(self, "radius_mm", number("hand.radius_mm", self.radius_mm, 0.0, 100.0, lo_open=True, unit="mm"))
        bases = {}
        for f in FINGERS:
            xy = self.finger_bases_mm.get(f, _FINGER_DEFAULTS[f][:2])
            bases[f] = (number(f"{f}.base_x_mm", xy[0], -500.0, 500.0, unit="mm"),
                        number(f"{f}.base_y_mm", xy[1], -500.0, 500.0, unit="mm"))
        s(self, "finger_bases_mm", bases)
        s(self, "thumb_base_mm", (number("thumb.base_x_mm", self.thumb_base_mm[0], -500.0, 500.0, unit="mm"),
                                  number("thumb.base_y_mm", self.thumb_base_mm[1], -500.0, 500.0, unit="mm")))

    def part(self, name: str) -> HandPart:
        """The part called ``name`` (one of :data:`PARTS`)."""
        if name not in PARTS:
            raise InputError(f"no hand part {name!r}{did_you_mean(name, PARTS)}; the parts are {', '.join(PARTS)}")
        return self.parts[PARTS.index(name)]

    def reach_deg(self) -> dict[str, float]:
        """Each part's free bending angle at ``max_pressure_kpa`` (deg; NaN: no equilibrium there).

        >>> {k: round(v) for k, v in default_hand().reach_deg().items()}["thumb_distal"]
        96
        """
        if "_reach" not in self.__dict__:
            object.__setattr__(self, "_reach", {p.name: float(p.angle_deg(self.max_pressure_kpa)) for p in self.parts})
        return dict(self.__dict__["_reach"])

    def to_dict(self) -> dict[str, Any]:
        """The hand's description as a JSON-ready dict (units in the key names).

        >>> d = default_hand().to_dict()
        >>> d["parts"]["index"]["length_mm"], d["thumb_plane_deg"]
        (95.0, 60.0)
        """
        reach = self.reach_deg()
        parts = {p.name: {"length_mm": p.length_mm, "actuator": p.actuator.name or p.actuator.kind,
                          "angle_at_max_pressure_deg": json_number(reach[p.name])} for p in self.parts}
        for f in FINGERS:
            parts[f]["base_mm"] = list(self.finger_bases_mm[f])
        parts["thumb_proximal"]["base_mm"] = list(self.thumb_base_mm)
        return {"parts": parts, "thumb_plane_deg": self.thumb_plane_deg,
                "thumb_direction_deg": self.thumb_direction_deg, "max_pressure_kpa": self.max_pressure_kpa,
                "contact_tolerance_mm": self.contact_tolerance_mm, "radius_mm": self.radius_mm, "model": self.model}

    @classmethod
    def from_toml(cls, path) -> Hand:
        """Read a hand description (TOML; every key optional, the defaults of :func:`default_hand`).

        Tables ``[hand]`` (``max_pressure_kpa``, ``contact_tolerance_mm``, ``radius_mm``, ``model``,
        ``actuator``), ``[index]``, ``[middle]``, ``[ring]``, ``[little]`` (``base_x_mm``, ``base_y_mm``,
        ``length_mm``, ``actuator``), ``[thumb]`` (``proximal_mm``, ``distal_mm``, ``plane_deg``,
        ``direction_deg``, ``base_x_mm``, ``base_y_mm``, ``actuator``) and ``[palm]`` (``roll_length_mm``,
        ``actuator``).  ``actuator`` is the path of an actuator TOML, relative to the hand file; the
        ``[hand]`` one is the default of every part.  docs/hand.md has an example.

        >>> import tempfile, pathlib
        >>> with tempfile.TemporaryDirectory() as d:
        ...     f = pathlib.Path(d) / "hand.toml"
        ...     _ = f.write_text("[thumb]\\nplane_deg = 45\\n")
        ...     Hand.from_toml(f).thumb_plane_deg
        45.0
        """
        p = Path(path)
        return _hand_from_dict(read_toml_file(p, "hand file"), p)


def _hand_from_dict(data: dict, path: Path) -> Hand:
    """A :class:`Hand` from a parsed hand file (unknown tables and keys refused in one line)."""
    for table, value in data.items():
        if table not in _TABLES:
            raise InputError(f"{path}: unknown table [{table}]{did_you_mean(table, _TABLES)}; "
                             f"the tables are {', '.join(f'[{t}]' for t in _TABLES)}")
        if not isinstance(value, dict):
            raise InputError(f"{path}: {table} must be a table [{table}]")
        for key in value:
            if key not in _TABLES[table]:
                raise InputError(f"{path}: [{table}] has an unknown key {key!r}{did_you_mean(key, _TABLES[table])}; "
                                 f"allowed: {', '.join(sorted(_TABLES[table]))}")
    h, _th, _pa = data.get("hand", {}), data.get("thumb", {}), data.get("palm", {})
    model = h.get("model", "energy")
    if not isinstance(model, str):
        raise InputError(f"{path}: [hand] model = {model!r} must be 'energy' or 'force_balance'")
    model = normalise_model(model)

    def actuator(table: dict, where: str, default: Actuator | None) -> Actuator | None:
        if "actuator" not in table:
            return default
        if not isinstance(table["actuator"], str):
            raise InputError(f"{path}: [{where}] actuator must be the path of an actuator TOML file")
        return Actuator.from_toml(path.parent / table["actuator"])

    def num(table: dict, where: str, key: str, default: float) -> float:
        return number(f"{path}: [{where}] {key}", table.get(key, default))

    try:
        return _build_hand(data, path, model, actuator, num)
    except InputError as exc:
        if str(path) in str(exc):
            raise
        raise InputError(f"{path}: {exc}") from None


def _build_hand(data: dict, path: Path, model: str, actuator, num) -> Hand:
    """The :class:`Hand` of a checked hand file (``actuator`` and ``num`` read its values)."""
    h, th, pa = data.get("hand", {}), data.get("thumb", {}), data.get("palm", {})
    base = actuator(h, "hand", None)
    parts, bases = [], {}
    for f in FINGERS:
        t = data.get(f, {})
        x, y, L = _FINGER_DEFAULTS[f]
        bases[f] = (num(t, f, "base_x_mm", x), num(t, f, "base_y_mm", y))
        parts.append(_part(f, num(t, f, "length_mm", L), actuator(t, f, base), model))
    tact = actuator(th, "thumb", base)
    parts += [_part("thumb_proximal", num(th, "thumb", "proximal_mm", 70.0), tact, model),
              _part("thumb_distal", num(th, "thumb", "distal_mm", 70.0), tact, model),
              _part("palm_roll", num(pa, "palm", "roll_length_mm", 70.0), actuator(pa, "palm", base), model)]
    return Hand(tuple(parts), bases, thumb_plane_deg=num(th, "thumb", "plane_deg", 60.0),
                thumb_direction_deg=num(th, "thumb", "direction_deg", 35.0),
                thumb_base_mm=(num(th, "thumb", "base_x_mm", 52.0), num(th, "thumb", "base_y_mm", 45.0)),
                max_pressure_kpa=num(h, "hand", "max_pressure_kpa", 300.0),
                contact_tolerance_mm=num(h, "hand", "contact_tolerance_mm", 8.5),
                radius_mm=num(h, "hand", "radius_mm", 8.5), model=model)


def default_hand(model: str = "energy", actuator: Actuator | None = None) -> Hand:
    """The documented default hand (module docstring): the paper's BE-PAM in every part unless ``actuator``.

    >>> hand = default_hand()
    >>> hand.part("middle").length_mm, hand.finger_bases_mm["index"]          # mm
    (105.0, (30.0, 105.0))
    """
    model = normalise_model(model)
    parts = [_part(f, _FINGER_DEFAULTS[f][2], actuator, model) for f in FINGERS]
    parts += [_part(n, 70.0, actuator, model) for n in ("thumb_proximal", "thumb_distal", "palm_roll")]
    return Hand(tuple(parts), {f: _FINGER_DEFAULTS[f][:2] for f in FINGERS}, model=model)


# ---- kinematics (vectorised over poses) ----------------------------------------------------------
def _rot(axis: np.ndarray, angle) -> np.ndarray:
    """Rotation matrices (..., 3, 3) about the unit vectors ``axis`` (..., 3) by ``angle`` (rad) (Rodrigues)."""
    a = np.asarray(axis, dtype=float)
    th = np.asarray(angle, dtype=float)[..., None, None]
    K = np.zeros((*a.shape[:-1], 3, 3))
    K[..., 0, 1], K[..., 0, 2], K[..., 1, 2] = -a[..., 2], a[..., 1], -a[..., 0]
    K = K - np.swapaxes(K, -1, -2)
    eye = np.broadcast_to(np.eye(3), K.shape)
    return eye + np.sin(th) * K + (1.0 - np.cos(th)) * (K @ K)


def arc_frames(R, p, angle_rad, length_mm, s_mm=None):
    """Positions (and frames) along circular arcs: the segment kinematics of the hand.

    Parameters
    ----------
    R : array (..., 3, 3)
        Base frames, columns ``(t, n, b)``: tangent, bending direction, ``t x n``.
    p : array (..., 3)
        Base positions, mm.
    angle_rad : array (...)
        Bending angles ``theta = k' L``, rad (0: straight).
    length_mm : float
        Segment length ``L``, mm.
    s_mm : array (m,) or (..., m), optional
        Arc lengths at which to return points, the same for every arc or per arc (default: none).

    Returns
    -------
    (points, R_end, p_end)
        ``points`` (..., m, 3) at ``s_mm`` (or None), the end frames (..., 3, 3) and positions (..., 3).

    Examples
    --------
    A 90-deg arc of length 100 mm along x bending toward y ends at (2L/pi, 2L/pi) pointing along y:

    >>> pts, R1, p1 = arc_frames(np.eye(3), np.zeros(3), np.pi / 2, 100.0)
    >>> np.round(p1, 3).tolist(), np.round(R1[:, 0], 6).tolist()
    ([63.662, 63.662, 0.0], [0.0, 1.0, 0.0])
    """
    R = np.asarray(R, dtype=float)
    p = np.asarray(p, dtype=float)
    th = np.asarray(angle_rad, dtype=float)

    def local(s):  # (..., m) arc lengths -> tangent and normal offsets, exact as theta -> 0
        a = th[..., None] * s / length_mm
        return s * np.sinc(a / np.pi), s * a / 2.0 * np.sinc(a / (2.0 * np.pi)) ** 2

    def place(s):
        u, v = local(s)
        return p[..., None, :] + u[..., None] * R[..., None, :, 0] + v[..., None] * R[..., None, :, 1]

    p_end = place(np.full((*th.shape, 1), float(length_mm)))[..., 0, :]
    R_end = _rot(R[..., :, 2], th) @ R
    pts = None
    if s_mm is not None:  # (m,) for every arc, or one row per arc (..., m)
        s = np.asarray(s_mm, dtype=float)
        pts = place(np.broadcast_to(s, th.shape + s.shape[-1:]))
    return pts, R_end, p_end


def finger_frame(hand: Hand, name: str) -> tuple[np.ndarray, np.ndarray]:
    """A finger's base frame (columns t = +y, n = +z, b = +x) and base position (mm).

    >>> R, p = finger_frame(default_hand(), "ring")
    >>> R[:, 0].tolist(), p.tolist()                      # along +y, from the knuckle line
    ([0.0, 1.0, 0.0], [-10.0, 105.0, 0.0])
    """
    x, y = hand.finger_bases_mm[name]
    return np.column_stack([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]), np.array([x, y, 0.0])


def thumb_base(hand: Hand, roll_rad) -> tuple[np.ndarray, np.ndarray]:
    """The thumb's base position (..., 3), mm, and frame (..., 3, 3; columns t, n, b) at palm rolls ``roll_rad``.

    >>> p, R = thumb_base(default_hand(), np.pi / 2)                 # rolled in front of the index
    >>> np.round(p, 6).tolist(), np.round(R[:, 1], 6).tolist()       # it bends toward -x (the little finger)
    ([30.0, 45.0, 22.0], [-1.0, 0.0, 0.0])
    """
    phi = np.asarray(roll_rad, dtype=float)
    roll = _rot(np.broadcast_to([0.0, -1.0, 0.0], (*phi.shape, 3)), phi)  # about the index axis: +x -> +z
    axis = np.array([hand.finger_bases_mm["index"][0], 0.0, 0.0])
    pbase = axis + roll @ (np.array([*hand.thumb_base_mm, 0.0]) - axis)
    d = math.radians(hand.thumb_direction_deg)
    t0 = np.array([math.sin(d), math.cos(d), 0.0])
    n0 = np.array([0.0, 0.0, 1.0])
    return pbase, roll @ np.column_stack([t0, n0, np.cross(t0, n0)])


def thumb_chain(hand: Hand, proximal_rad, distal_rad, roll_rad, s_mm=None):
    """The thumb for bend angles (rad, arrays of one shape): points at arc lengths ``s_mm`` from its base
    (mm, 0 to ``L1 + L2``; (m,) or one row (..., m) per pose; None: none), tip positions (..., 3) and
    tip frames (..., 3, 3).

    >>> from bendpam.design.hand import default_hand
    >>> _, tip, _ = thumb_chain(default_hand(), 0.0, 0.0, 0.0)        # straight, unrolled
    >>> np.round(tip, 1).tolist()                                    # 140 mm at 35 deg from (52, 45, 0)
    [132.3, 159.7, 0.0]
    """
    th1, th2, phi = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (proximal_rad, distal_rad, roll_rad)))
    L1, L2 = hand.part("thumb_proximal").length_mm, hand.part("thumb_distal").length_mm
    pbase, R0 = thumb_base(hand, phi)
    s = None if s_mm is None else np.asarray(s_mm, dtype=float)
    pts1, R1, p1 = arc_frames(R0, pbase, th1, L1, None if s is None else np.clip(s, 0.0, L1))
    R1 = R1 @ _rot(np.array([1.0, 0.0, 0.0]), -math.radians(hand.thumb_plane_deg))  # distal plane, toward the palm
    pts2, R2, p2 = arc_frames(R1, p1, th2, L2, None if s is None else np.clip(s - L1, 0.0, L2))
    pts = None
    if s is not None and pts1 is not None and pts2 is not None:
        pts = np.where((s <= L1)[..., None], pts1, pts2)
    return pts, p2, R2


def _angles_rad(hand: Hand, pressures: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    out = {}
    for name, P in pressures.items():
        a = hand.part(name).angle_deg(P)
        if not np.all(np.isfinite(a)):
            bad = float(np.asarray(P)[~np.isfinite(a)].ravel()[0])
            raise InputError(f"{name}: no free-bending equilibrium at {bad:g} kPa (the actuator folds or locks up)")
        out[name] = np.radians(a)
    return out


@dataclass(frozen=True)
class HandPose:
    """The hand at one set of pressures: each part's pressure, angle, centreline and the tips.

    Attributes
    ----------
    hand : the :class:`Hand`.
    pressures_kpa, angles_deg : per part (dicts keyed by :data:`PARTS`).
    centrelines_mm : per finger, ``"thumb"`` and ``"palm_roll"``: points (m, 3) along the centreline, mm.
    tips_mm : per finger and ``"thumb"``: the tip position (3,), mm.

    Examples
    --------
    >>> pose = hand_pose(default_hand(), {"index": 200.0})
    >>> round(pose.angles_deg["index"], 1), np.round(pose.tips_mm["index"], 1).tolist()
    (73.6, [30.0, 175.9, 53.1])
    """

    hand: Hand
    pressures_kpa: dict
    angles_deg: dict
    centrelines_mm: dict
    tips_mm: dict

    def to_dict(self) -> dict[str, Any]:
        """The pose as a JSON-ready dict (units in the key names).

        >>> d = hand_pose(default_hand(), {"index": 200.0}).to_dict()
        >>> d["pressures_kpa"]["index"], sorted(d["tips_mm"])
        (200.0, ['index', 'little', 'middle', 'ring', 'thumb'])
        """
        return {"pressures_kpa": {k: float(v) for k, v in self.pressures_kpa.items()},
                "angles_deg": {k: json_number(v) for k, v in self.angles_deg.items()},
                "tips_mm": {k: [float(x) for x in v] for k, v in self.tips_mm.items()}}

    def plot(self, ax=None, title: str | None = None):
        """A 3-D figure of the pose (:func:`bendpam.present.figures.hand.plot_hand_pose`, reached by name).

        >>> fig = hand_pose(default_hand(), {"thumb_proximal": 250.0}).plot()
        >>> len(fig.axes)                                   # fig.savefig("hand.png") to keep it
        1
        """
        return figure("hand_pose")(self, ax=ax, title=title)

    def save(self, out_dir, *, figure_format: str = "png") -> dict[str, str]:
        """Write ``pose.json`` and ``pose.<format>`` into ``out_dir`` (atomically, each); ``{name: path}``.

        For a whole set use :class:`bendpam.infra.outputs.OutputSet`, as ``bendpam hand --out`` does.
        """
        return save_result(out_dir, "pose", self.to_dict(), lambda: self.plot(), figure_format)


def save_result(out_dir, stem: str, record: dict, draw, figure_format: str) -> dict[str, str]:
    """Write ``<stem>.json`` (``record``) and the figure ``draw()`` as ``<stem>.<figure_format>`` into ``out_dir``,
    each atomically; returns ``{file name: path}`` (the ``save()`` of the hand's results).

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     sorted(hand_pose(default_hand()).save(d))
    ['pose.json', 'pose.png']
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write_text(out / f"{stem}.json", to_json(record))
    target = out / f"{stem}.{figure_format}"
    figure("save_figure")(draw(), target, format=figure_format)
    return {f"{stem}.json": str(out / f"{stem}.json"), target.name: str(target)}


def hand_pose(hand: Hand, pressures_kpa: dict | None = None, *, samples: int = 25) -> HandPose:
    """Forward kinematics of the unloaded hand: every part an arc of its free curvature at its pressure.

    ``pressures_kpa`` maps part names (:data:`PARTS`) to gauge pressures (kPa, 0 to the hand's
    ``max_pressure_kpa``); parts not named are at 0 kPa (straight).

    Examples
    --------
    >>> pose = hand_pose(default_hand(), {"thumb_proximal": 300.0, "palm_roll": 300.0})
    >>> round(pose.angles_deg["thumb_proximal"], 1), round(pose.angles_deg["palm_roll"], 1)   # deg
    (95.9, 95.9)
    """
    if not isinstance(hand, Hand):
        raise TypeError(f"hand must be a bendpam.design.hand.Hand, got {type(hand).__name__}")
    given = dict(pressures_kpa or {})
    for name in given:
        if name not in PARTS:
            raise InputError(f"pressures_kpa: no hand part {name!r}{did_you_mean(name, PARTS)}; "
                             f"the parts are {', '.join(PARTS)}")
    P = {n: number(f"pressures_kpa[{n!r}]", given.get(n, 0.0), 0.0, hand.max_pressure_kpa, unit="kPa")
         for n in PARTS}
    ang = {n: float(a) for n, a in _angles_rad(hand, {n: np.asarray(P[n]) for n in PARTS}).items()}
    lines, tips = {}, {}
    for f in FINGERS:
        R, p = finger_frame(hand, f)
        L = hand.part(f).length_mm
        pts, _, tip = arc_frames(R, p, ang[f], L, np.linspace(0.0, L, samples))
        lines[f], tips[f] = pts, tip
    Lt = hand.part("thumb_proximal").length_mm + hand.part("thumb_distal").length_mm
    pts, tip, _ = thumb_chain(hand, ang["thumb_proximal"], ang["thumb_distal"], ang["palm_roll"],
                              np.linspace(0.0, Lt, 2 * samples))
    lines["thumb"], tips["thumb"] = pts, tip
    axis = np.array([hand.finger_bases_mm["index"][0], 0.0, 0.0])
    turns = _rot(np.broadcast_to([0.0, -1.0, 0.0], (samples, 3)), np.linspace(0.0, ang["palm_roll"], samples))
    lines["palm_roll"] = axis + turns @ (np.array([*hand.thumb_base_mm, 0.0]) - axis)  # the thumb base's path
    return HandPose(hand, P, {n: math.degrees(a) for n, a in ang.items()}, lines, tips)
