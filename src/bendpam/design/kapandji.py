r"""The Kapandji opposition test of the soft hand, and the reachable workspace of its tips.

Kapandji's test (Kapandji, *Ann. Chir. Main* 5(1), 67-73, 1986) scores the thumb's opposition by
the points of the other fingers its tip reaches.  The paper's hand (section 4.2) is tested on
eight points; bendpam defines them after Kapandji's ten, on the hand with the fingers straight
(their pressures as given, 0 kPa by default):

====  ===========================================================================================
 1    radial side of the index finger's proximal phalanx (at 22 % of its length)
 2    radial side of the index finger's middle phalanx (at 59 % of its length)
 3    index fingertip (pulp: the palmar side of the tip)
 4    middle fingertip
 5    ring fingertip
 6    little fingertip
 7    the little finger's proximal interphalangeal crease (palmar side, at 45 % of its length)
 8    the distal palmar crease at the little finger's ray (palm surface, 15 mm proximal of its base)
====  ===========================================================================================

Points 1-7 are Kapandji's 1-7 (his 8 and 9, the little finger's other creases, are left out),
point 8 his 10.  The phalanx fractions are the adult proportions of the proximal, middle and
distal phalanges (about 45 : 28 : 27 of the finger's length).  Every target is on a tube's surface:
the finger's centreline moved by the hand's ``radius_mm`` toward the side the thumb touches; the
palm surface is at ``z = radius_mm``.

For each point, a bounded multi-start optimisation (:func:`scipy.optimize.minimize`, L-BFGS-B,
started from the best points of a vectorised grid of poses) finds the thumb's bend angles and the
palm roll that bring the thumb tip closest; the angles are then turned into pressures through each
part's free-bending law (:meth:`bendpam.design.hand.HandPart.pressure_for_angle`) and the distance
is evaluated again at those pressures.  ``touched_by`` is ``"tip"`` when the thumb tip (the end of
its centreline) comes within ``contact_tolerance_mm`` of the point; else ``"thumb"`` when some
other point of the thumb's centreline does (a second optimisation over the pose and the place
along the thumb); else ``"none"``.  Collisions are not modelled: the thumb may pass through a finger.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from bendpam.design.hand import FINGERS, Hand, arc_frames, finger_frame, hand_pose, save_result, thumb_chain
from bendpam.design.parts import json_number
from bendpam.errors import InputError
from bendpam.infra.accessors import figure
from bendpam.validate import integer

__all__ = [
    "KAPANDJI_POINTS",
    "HandWorkspace",
    "KapandjiPoint",
    "KapandjiResult",
    "hand_workspace",
    "kapandji",
    "kapandji_targets",
]

#: the eight points: (number, description, finger, fraction of its length, side) - side "radial",
#: "palmar" (a finger's palmar surface) or "palm" (the palm surface near the finger's base)
KAPANDJI_POINTS = (
    (1, "index, proximal phalanx, radial side", "index", 0.22, "radial"),
    (2, "index, middle phalanx, radial side", "index", 0.59, "radial"),
    (3, "index fingertip", "index", 1.0, "palmar"),
    (4, "middle fingertip", "middle", 1.0, "palmar"),
    (5, "ring fingertip", "ring", 1.0, "palmar"),
    (6, "little fingertip", "little", 1.0, "palmar"),
    (7, "little finger, proximal interphalangeal crease", "little", 0.45, "palmar"),
    (8, "distal palmar crease at the little finger", "little", -15.0, "palm"),
)
_THUMB = ("thumb_proximal", "thumb_distal", "palm_roll")


def _targets(hand: Hand, number: int, finger_rad) -> np.ndarray:
    """Point ``number`` (mm, (..., 3)) with its finger bent by ``finger_rad`` (rad, array)."""
    _n, _d, f, frac, side = KAPANDJI_POINTS[number - 1]
    R, p = finger_frame(hand, f)
    a = np.asarray(finger_rad, dtype=float)
    if side == "palm":
        return np.broadcast_to(p + np.array([0.0, frac, hand.radius_mm]), (*a.shape, 3))
    _, Re, pe = arc_frames(np.broadcast_to(R, (*a.shape, 3, 3)), p, a * frac, frac * hand.part(f).length_mm)
    return pe + hand.radius_mm * (Re[..., :, 2] if side == "radial" else Re[..., :, 1])


def kapandji_targets(hand: Hand, finger_pressures_kpa: dict | None = None) -> np.ndarray:
    """The eight target points (8, 3), mm, with the fingers at ``finger_pressures_kpa`` (default straight).

    Examples
    --------
    >>> from bendpam.design.hand import default_hand
    >>> t = kapandji_targets(default_hand())
    >>> np.round(t[2], 1).tolist(), np.round(t[7], 1).tolist()      # index pulp, palm crease (mm)
    ([30.0, 200.0, 8.5], [-30.0, 83.0, 8.5])
    """
    given = _finger_pressures(finger_pressures_kpa)
    pose = hand_pose(hand, given)
    return np.stack([_targets(hand, i, math.radians(pose.angles_deg[KAPANDJI_POINTS[i - 1][2]]))
                     for i in range(1, 9)])


def _finger_pressures(finger_pressures_kpa) -> dict:
    given = dict(finger_pressures_kpa or {})
    for k in given:
        if k not in FINGERS:
            raise InputError(f"finger_pressures_kpa: {k!r} is not a finger; the fingers are {', '.join(FINGERS)}")
    return given


def _max_rad(hand: Hand, name: str) -> float:
    a = hand.reach_deg()[name]
    if not math.isfinite(a):  # the largest angle before the law has no equilibrium
        a = float(hand.part(name).angle_table(hand.max_pressure_kpa)[1][-1])
    return math.radians(a)


def _tip_distance(hand: Hand, number: int, x: np.ndarray) -> np.ndarray:
    """Thumb-tip distance (mm) to point ``number`` for rows ``x`` (N, 4) = (proximal, distal, roll, finger), rad."""
    _, tip, _ = thumb_chain(hand, x[:, 0], x[:, 1], x[:, 2])
    return np.linalg.norm(tip - _targets(hand, number, x[:, 3]), axis=-1)


def _body_distance(hand: Hand, number: int, x: np.ndarray) -> np.ndarray:
    """Distance (mm) from point ``number`` to the point at arc length ``x[:, 4]`` (mm) along the thumb."""
    pts, _, _ = thumb_chain(hand, x[:, 0], x[:, 1], x[:, 2], s_mm=x[:, 4:5])
    return np.linalg.norm(pts[:, 0] - _targets(hand, number, x[:, 3]), axis=-1)


def _minimise(fun, grid: np.ndarray, bounds: np.ndarray, starts: int) -> tuple[np.ndarray, float]:
    """The smallest of ``fun`` over a box: the ``starts`` best grid points polished by L-BFGS-B."""
    from scipy.optimize import minimize

    values = fun(grid)
    best = np.argsort(values)[:starts]
    x_best, f_best = grid[best[0]], float(values[best[0]])
    box = [(float(lo), float(hi)) for lo, hi in bounds]
    k = grid.shape[1]
    steps = np.vstack([np.zeros(k), 1e-6 * np.eye(k), -1e-6 * np.eye(k)])

    def value_and_gradient(z):  # one vectorised call: the value and central differences
        v = fun(z[None, :] + steps)
        return float(v[0]), (v[1:k + 1] - v[k + 1:]) / 2e-6

    for i in best:
        res = minimize(value_and_gradient, grid[i], jac=True, method="L-BFGS-B", bounds=box)
        if float(res.fun) < f_best:
            x_best, f_best = np.clip(res.x, bounds[:, 0], bounds[:, 1]), float(res.fun)
    return x_best, f_best


def _grid(bounds: np.ndarray, n: int) -> np.ndarray:
    """A grid of ``n`` points per free variable (one where its bounds are equal) over the box ``bounds`` (k, 2)."""
    axes = [np.linspace(lo, hi, n) if hi > lo else np.array([lo]) for lo, hi in bounds]
    return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, len(bounds))


@dataclass(frozen=True)
class KapandjiPoint:
    """One point of the test: where it is and how close the thumb comes.

    Attributes
    ----------
    number, description : the point (1-8, :data:`KAPANDJI_POINTS`).
    target_mm : the point (3,), mm.
    distance_mm : the thumb tip's closest distance, mm (at ``pressures_kpa``).
    touched_by : ``"tip"``, ``"thumb"`` (another point of the thumb within the tolerance) or ``"none"``.
    pressures_kpa : dict of the pressures of the closest tip pose, kPa: thumb_proximal, thumb_distal,
        palm_roll and (when it moves) the finger that carries the point.
    roll_deg : the palm roll there, deg.
    thumb_distance_mm : the closest distance of any point of the thumb, mm (the tip's when it touches).
    tip_mm : the tip position at the closest pose, mm.

    Examples
    --------
    >>> from bendpam.design.hand import default_hand
    >>> p = kapandji(default_hand(), points=(5,), grid=5, starts=1).points[0]
    >>> p.description, p.touched, sorted(p.to_dict())[:4]
    ('ring fingertip', True, ['description', 'distance_mm', 'number', 'pressures_kpa'])
    """

    number: int
    description: str
    target_mm: tuple
    distance_mm: float
    touched_by: str
    pressures_kpa: dict
    roll_deg: float
    thumb_distance_mm: float
    tip_mm: tuple

    @property
    def touched(self) -> bool:
        """Touched by the thumb (tip or body)."""
        return self.touched_by != "none"

    def to_dict(self) -> dict[str, Any]:
        """The point as a JSON-ready dict (units in the key names)."""
        return {"number": self.number, "description": self.description,
                "target_mm": [float(v) for v in self.target_mm], "distance_mm": json_number(self.distance_mm),
                "touched": self.touched, "touched_by": self.touched_by,
                "pressures_kpa": {k: json_number(v) for k, v in self.pressures_kpa.items()},
                "roll_deg": json_number(self.roll_deg), "thumb_distance_mm": json_number(self.thumb_distance_mm),
                "tip_mm": [float(v) for v in self.tip_mm]}


@dataclass(frozen=True)
class KapandjiResult:
    """The Kapandji test of a hand: eight :class:`KapandjiPoint` and the hand.

    Examples
    --------
    >>> from bendpam.design.hand import default_hand
    >>> res = kapandji(default_hand(), points=(4,))
    >>> p = res.points[0]
    >>> p.number, p.touched_by, p.distance_mm < 8.5
    (4, 'tip', True)
    """

    hand: Hand
    points: tuple
    finger_pressures_kpa: dict

    @property
    def score(self) -> int:
        """Kapandji's score: the number of the last point of the unbroken run 1, 2, ... touched by the tip."""
        n = 0
        for p in sorted(self.points, key=lambda q: q.number):
            if p.number != n + 1 or p.touched_by != "tip":
                break
            n = p.number
        return n

    def to_dict(self) -> dict[str, Any]:
        """The test as a JSON-ready dict: ``points`` (each with ``distance_mm``, ``touched``, ``touched_by``)."""
        return {"contact_tolerance_mm": self.hand.contact_tolerance_mm, "score": self.score,
                "touched_by_tip": [p.number for p in self.points if p.touched_by == "tip"],
                "touched_by_thumb_only": [p.number for p in self.points if p.touched_by == "thumb"],
                "finger_pressures_kpa": {k: float(v) for k, v in self.finger_pressures_kpa.items()},
                "points": [p.to_dict() for p in self.points]}

    def plot(self, ax=None, title: str | None = None):
        """A 3-D figure of the thumb's closest pose for every point
        (:func:`~bendpam.present.figures.hand.plot_kapandji`).

        >>> from bendpam.design.hand import default_hand
        >>> fig = kapandji(default_hand(), points=(3,)).plot()
        >>> len(fig.axes)
        1
        """
        return figure("kapandji")(self, ax=ax, title=title)

    def save(self, out_dir, *, figure_format: str = "png") -> dict[str, str]:
        """Write ``kapandji.json`` and ``kapandji.<format>`` into ``out_dir`` (each atomically); ``{name: path}``."""
        return save_result(out_dir, "kapandji", self.to_dict(), lambda: self.plot(), figure_format)


def _pressures(hand: Hand, names: tuple, x: np.ndarray) -> dict[str, float]:
    """The pressures (kPa) that bend the named parts by the angles ``x`` (rad)."""
    return {n: float(hand.part(n).pressure_for_angle(math.degrees(a), hand.max_pressure_kpa))
            for n, a in zip(names, x, strict=True)}


def _point(hand: Hand, number: int, finger_rad: float | None, grid: int, starts: int) -> KapandjiPoint:
    """Closest tip pose, and the closest thumb body when the tip does not touch, for one point.

    ``finger_rad``: the bend of the point's finger, fixed (rad), or None to optimise it too."""
    finger = KAPANDJI_POINTS[number - 1][2]
    moves = finger_rad is None and KAPANDJI_POINTS[number - 1][4] != "palm"
    fb = (0.0, _max_rad(hand, finger)) if moves else (finger_rad or 0.0,) * 2
    bounds = np.array([(0.0, _max_rad(hand, n)) for n in _THUMB] + [fb])
    x, _ = _minimise(lambda z: _tip_distance(hand, number, z) ** 2, _grid(bounds, grid), bounds, starts)
    names = _THUMB + ((finger,) if moves else ())
    P = _pressures(hand, names, x[: len(names)])
    pose = hand_pose(hand, P)  # at those pressures, through the moment law
    x_at = np.array([[math.radians(pose.angles_deg[n]) for n in _THUMB] + [x[3]]])
    if moves:
        x_at[0, 3] = math.radians(pose.angles_deg[finger])
    target = _targets(hand, number, x_at[:, 3])[0]
    tip = pose.tips_mm["thumb"]
    d = float(np.linalg.norm(tip - target))
    tol = hand.contact_tolerance_mm
    body = d
    if d > tol:
        Lt = hand.part("thumb_proximal").length_mm + hand.part("thumb_distal").length_mm
        b5 = np.vstack([bounds, [0.0, Lt]])
        g5 = _grid(b5, max(3, grid // 2 + 1))
        _, f = _minimise(lambda z: _body_distance(hand, number, z) ** 2, g5, b5, starts)
        body = min(d, math.sqrt(max(f, 0.0)))
    by = "tip" if d <= tol else ("thumb" if body <= tol else "none")
    return KapandjiPoint(number, KAPANDJI_POINTS[number - 1][1], tuple(target), d, by, P,
                         pose.angles_deg["palm_roll"], body, tuple(tip))


def kapandji(hand: Hand, *, finger_pressures_kpa: dict | None = None, points=None, grid: int = 9,
             starts: int = 3) -> KapandjiResult:
    """The Kapandji test (module docstring): for each point the closest thumb pose, its pressures and distance.

    Parameters
    ----------
    hand : :class:`~bendpam.design.hand.Hand`
    finger_pressures_kpa : dict, optional
        Fixed pressures of the fingers (kPa).  Default: the finger that carries a point flexes to meet
        the thumb (its pressure is optimised with the thumb's, as in the clinical test).
    points : iterable of int, optional
        Which of the points 1-8 (default all).
    grid : int
        Grid points per freedom of the starting grid (3 to 21; up to ``grid ** 4`` poses, vectorised).
    starts : int
        Local optimisations from the best grid points (1 to 20).

    Examples
    --------
    >>> from bendpam.design.hand import default_hand
    >>> res = kapandji(default_hand(), points=(3, 7), grid=7)
    >>> [(p.number, p.touched_by) for p in res.points]
    [(3, 'tip'), (7, 'none')]
    """
    if not isinstance(hand, Hand):
        raise TypeError(f"hand must be a bendpam.design.hand.Hand, got {type(hand).__name__}")
    n = integer("grid", grid, 3, 21)
    k = integer("starts", starts, 1, 20)
    wanted = tuple(range(1, 9)) if points is None else tuple(integer("points", p, 1, 8) for p in points)
    given = _finger_pressures(finger_pressures_kpa)
    fixed: dict[str, float | None] = {f: None for f in FINGERS}
    if given:
        pose = hand_pose(hand, given)
        fixed = {f: math.radians(pose.angles_deg[f]) for f in FINGERS}
    pts = tuple(_point(hand, i, fixed[KAPANDJI_POINTS[i - 1][2]], n, k) for i in wanted)
    return KapandjiResult(hand, pts, given)


# ---- reachable workspace ----------------------------------------------------------------------
@dataclass(frozen=True)
class HandWorkspace:
    """Tip positions over a grid of pressures: each finger's tip path and the thumb tip's 3-D cloud.

    Attributes
    ----------
    hand : the hand.
    pressures_kpa : the pressure grid of every part (kPa, ``n`` values from 0 to ``max_pressure_kpa``).
    finger_tips_mm : per finger, tips (n, 3), mm.
    thumb_tips_mm : (n**3, 3), mm, for (thumb_proximal, thumb_distal, palm_roll) on the grid (C order).

    Examples
    --------
    >>> from bendpam.design.hand import default_hand
    >>> ws = hand_workspace(default_hand(), n=5)
    >>> ws.thumb_tips_mm.shape, ws.finger_tips_mm["index"].shape
    ((125, 3), (5, 3))
    """

    hand: Hand
    pressures_kpa: np.ndarray
    finger_tips_mm: dict
    thumb_tips_mm: np.ndarray

    def to_dict(self) -> dict[str, Any]:
        """Extent of every tip's workspace (box, mm; the thumb's convex-hull volume, cm^3) as a JSON-ready dict."""
        from scipy.spatial import ConvexHull, QhullError

        def box(t):
            return {"min_mm": [float(v) for v in t.min(axis=0)], "max_mm": [float(v) for v in t.max(axis=0)]}

        try:
            vol = ConvexHull(np.unique(self.thumb_tips_mm.round(9), axis=0)).volume / 1e3
        except (QhullError, ValueError):
            vol = 0.0
        return {"pressures_kpa": [float(p) for p in self.pressures_kpa],
                "fingers": {f: box(t) for f, t in self.finger_tips_mm.items()},
                "thumb": {**box(self.thumb_tips_mm), "hull_volume_cm3": float(vol),
                          "points": len(self.thumb_tips_mm)}}

    def plot(self, ax=None, title: str | None = None):
        """A 3-D scatter of the tips (:func:`bendpam.present.figures.hand.plot_hand_workspace`)."""
        return figure("hand_workspace")(self, ax=ax, title=title)

    def save(self, out_dir, *, figure_format: str = "png") -> dict[str, str]:
        """Write ``workspace.json`` (:meth:`to_dict`) and ``workspace.<format>`` into ``out_dir``; ``{name: path}``."""
        return save_result(out_dir, "workspace", self.to_dict(), lambda: self.plot(), figure_format)


def hand_workspace(hand: Hand, n: int = 15) -> HandWorkspace:
    """The reachable tip positions over ``n`` pressures per part from 0 to ``max_pressure_kpa`` (vectorised).

    >>> from bendpam.design.hand import default_hand
    >>> ws = hand_workspace(default_hand(), n=3)
    >>> np.round(ws.finger_tips_mm["middle"][0], 1).tolist()          # unpressurised: straight, mm
    [10.0, 213.0, 0.0]
    """
    if not isinstance(hand, Hand):
        raise TypeError(f"hand must be a bendpam.design.hand.Hand, got {type(hand).__name__}")
    m = integer("n", n, 2, 60)
    P = np.linspace(0.0, hand.max_pressure_kpa, m)
    fingers = {}
    for f in FINGERS:
        part = hand.part(f)
        a = np.radians(part.angle_deg(P))
        R, p = finger_frame(hand, f)
        fingers[f] = arc_frames(np.broadcast_to(R, (*a.shape, 3, 3)), p, a, part.length_mm)[2]
    ang = [np.radians(hand.part(nm).angle_deg(P)) for nm in _THUMB]
    A = np.meshgrid(*ang, indexing="ij")
    _, tips, _ = thumb_chain(hand, *(a.ravel() for a in A))
    return HandWorkspace(hand, P, fingers, tips)
