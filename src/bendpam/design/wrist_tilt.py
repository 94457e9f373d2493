r"""The wrist in three dimensions: the tilt of the hand for every pressure combination, under gravity.

Extends :mod:`bendpam.design.wrist` (four actuators around a column, one uniform arc of curvature
vector ``b``; read its model first) with

* a **3-D load**: the hand's mass and a payload at their levers beyond the end plate, under
  gravity for a forearm held horizontal (one actuator on top), vertical with the hand up, or
  vertical with the hand hanging down;
* the **orientation map**: the tilt (``theta = |b| L``) and its direction ``psi`` for a block of
  pressure combinations, solved together (vectorised continuation in pressure);
* the **inverse**: the pressures that hold a target tilt and direction (closed form, the moment
  law being affine in the active pressure), checked by the forward solve;
* **frame-buckling margins** of each actuator along the way (the compressed BC-PAM frames are what
  buckles), from :func:`bendpam.physics.limits.section_limits`.

Load model
----------
The wrist's axis is ``z`` (toward the hand), its cross-section ``(x, y)`` with the actuators at
``positions_deg``.  A mass ``m`` at ``lever`` beyond the end plate sits, for the uniform arc, at::

    p(b) = b G(s) + A(s) e_z,    s = |b|^2,
    G = L^2 (1 - cos x)/x^2 + lever L sin(x)/x,    A = L sin(x)/x + lever cos(x),    x = |b| L

(``G`` and ``A`` are even power series in ``x``, evaluated as such: exact at the straight wrist).
With ``g`` the unit vector of gravity in this frame, virtual work adds the generalised moment
``(m g_n / L) grad_b (g . p)`` (N*mm; ``g_n`` = 9.80665e-3 N/g) to the wrist's moment, and its
Hessian to the Jacobian.  For the horizontal forearm and a bend toward the top actuator this is
exactly :func:`bendpam.design.wrist.wrist_hold`'s load.

Assumptions
-----------
* Defaults (the paper gives neither): the hand's mass 300 g (seven BE-PAMs of about 35 g and a
  palm) with its centre 80 mm beyond the end plate; the payload at 100 mm
  (:data:`bendpam.design.wrist.DEFAULT_LEVER_MM`).  The paper's example payload is a 550 g bottle.
* The actuators slide axially at the end plate (as in :mod:`~bendpam.design.wrist`): the weight's
  axial component goes to the column, the actuators' frames carry no external axial force.
* Each actuator must stay where its law falls with curvature (``dM/dk' < 0``) and inside its lock-up
  limits, and the wrist's 2x2 stiffness must be negative definite; the map refuses (``equilibrium
  = False``) a combination whose continuation from the straight wrist leaves that region.
* The buckling margin is :func:`~bendpam.physics.limits.section_limits`'s (Hetenyi's beam on the
  bladder's elastic foundation, conservative by about 25 % against the paper's blocked test) at
  each actuator's pressure and frame curvature; ``inf`` where the frame is in tension.

Units: kPa, mm, N*mm, g, degrees (names end in ``_kpa``, ``_mm``, ``_g``, ``_deg``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from bendpam.design.hand import save_result
from bendpam.design.parts import G_N_PER_G, checked_pressure_kpa, checked_pressures_kpa, json_number
from bendpam.design.rod import newton_batch
from bendpam.design.wrist import DEFAULT_LEVER_MM, Wrist
from bendpam.errors import InputError
from bendpam.infra.accessors import figure
from bendpam.physics.limits import section_limits
from bendpam.validate import integer, number

__all__ = [
    "DEFAULT_HAND_LEVER_MM",
    "DEFAULT_HAND_MASS_G",
    "FOREARM",
    "WristLoad",
    "WristMap",
    "WristTarget",
    "wrist_directions",
    "wrist_map",
    "wrist_target",
]

#: default mass of the hand carried by the wrist, g (an assumption: see the module docstring)
DEFAULT_HAND_MASS_G = 300.0
#: default lever of the hand's centre of mass beyond the end plate, mm
DEFAULT_HAND_LEVER_MM = 80.0
#: forearm orientations: horizontal (the actuator at ``up_deg`` on top), vertical with the hand up or down
FOREARM = ("horizontal", "up", "down")
_TERMS = 14  # terms of the even power series, used for |b| L < 1 rad (closed forms above)
_STEPS = 8   # continuation steps in pressure from the straight wrist
_TABLE_TOL = 1e-8  # the moment table's tolerance: the one of MomentLaw.stable_branch (the planar wrist's)


def _even_series_coefficients() -> np.ndarray:
    """Taylor coefficients in ``y = x^2`` of c0 = cos x, c1 = (1 - cos x)/x^2, c2 = sin(x)/x (rows), ``_TERMS`` each."""
    return np.array([[(-1.0) ** i / math.factorial(2 * i + shift) for i in range(_TERMS)] for shift in (0, 2, 1)])


_COEF = _even_series_coefficients()
_DCOEF = [_COEF, _COEF[:, 1:] * np.arange(1, _TERMS), _COEF[:, 2:] * (np.arange(2, _TERMS) * np.arange(1, _TERMS - 1))]


def _c012(y: np.ndarray) -> list[np.ndarray]:
    """c0, c1, c2 (module docstring: cos x, (1 - cos x)/x^2, sin(x)/x) and their first two derivatives in
    ``y = x^2 >= 0``: ``[values, first, second]``, each (3, N).  Closed forms for ``y >= 1``, the series below."""
    y = np.asarray(y, dtype=float)
    small = [np.stack([np.polynomial.polynomial.polyval(y, c) for c in D]) for D in _DCOEF]
    ys = np.maximum(y, 1.0)
    x = np.sqrt(ys)
    c0, c2 = np.cos(x), np.sin(x) / x
    c1 = (1.0 - c0) / ys
    d2 = (c0 - c2) / (2.0 * ys)
    d0 = -c2 / 2.0
    d1 = (-d0 - c1) / ys
    e2 = (d0 - d2) / (2.0 * ys) - d2 / ys
    e0 = -d2 / 2.0
    e1 = (-e0 - 2.0 * d1) / ys
    big = [np.stack([c0, c1, c2]), np.stack([d0, d1, d2]), np.stack([e0, e1, e2])]
    return [np.where(y < 1.0, a, b) for a, b in zip(small, big, strict=True)]


@dataclass(frozen=True)
class WristLoad:
    """What the wrist carries: the hand and a payload under gravity (validated, immutable).

    Parameters
    ----------
    hand_mass_g, hand_lever_mm : the hand's mass (g) and its centre's distance beyond the end plate (mm).
    payload_g, payload_lever_mm : the payload (g) and its distance beyond the end plate (mm).
    forearm : {"horizontal", "up", "down"}
        Horizontal forearm with the actuator at ``up_deg`` on top, or vertical with the hand above
        (``"up"``) or hanging below (``"down"``) the wrist.
    up_deg : float
        For a horizontal forearm: the direction in the cross-section that points up (deg).

    Examples
    --------
    >>> load = WristLoad(payload_g=550.0)
    >>> load.gravity().round(6).tolist(), load.total_g
    ([-0.0, -1.0, 0.0], 850.0)
    """

    hand_mass_g: float = DEFAULT_HAND_MASS_G
    hand_lever_mm: float = DEFAULT_HAND_LEVER_MM
    payload_g: float = 0.0
    payload_lever_mm: float = DEFAULT_LEVER_MM
    forearm: str = "horizontal"
    up_deg: float = 90.0

    def __post_init__(self):
        s = object.__setattr__
        for name, unit in (("hand_mass_g", "g"), ("hand_lever_mm", "mm"), ("payload_g", "g"),
                           ("payload_lever_mm", "mm")):
            s(self, name, number(name, getattr(self, name), 0.0, 1e5, unit=unit))
        if self.forearm not in FOREARM:
            raise InputError(f"forearm = {self.forearm!r} is not allowed; choose one of {', '.join(FOREARM)}")
        s(self, "up_deg", number("up_deg", self.up_deg, -360.0, 360.0, unit="deg"))

    @property
    def total_g(self) -> float:
        """Hand and payload, g."""
        return self.hand_mass_g + self.payload_g

    def gravity(self) -> np.ndarray:
        """The unit vector of gravity in the wrist's frame (x, y cross-section; z toward the hand)."""
        if self.forearm == "up":
            return np.array([0.0, 0.0, -1.0])
        if self.forearm == "down":
            return np.array([0.0, 0.0, 1.0])
        u = math.radians(self.up_deg)
        return np.array([-math.cos(u), -math.sin(u), 0.0])

    def moment(self, b: np.ndarray, length_mm: float) -> tuple[np.ndarray, np.ndarray]:
        """The generalised moment of the load (N*mm, (N, 2)) and its Jacobian (N*mm^2, (N, 2, 2)) at curvatures
        ``b`` (1/mm, (N, 2)) of a wrist of length ``length_mm`` (module docstring)."""
        b = np.atleast_2d(np.asarray(b, dtype=float))
        L = float(length_mm)
        g = self.gravity()
        gxy, gz = g[:2], g[2]
        s = np.einsum("ij,ij->i", b, b)
        y = s * L * L
        m = np.zeros_like(b)
        J = np.zeros((*b.shape, 2))
        eye = np.eye(2)
        c = _c012(y)
        for mass, lev in ((self.hand_mass_g, self.hand_lever_mm), (self.payload_g, self.payload_lever_mm)):
            if mass == 0.0:
                continue
            W = mass * G_N_PER_G / L
            G = [(L * L * c[d][1] + lev * L * c[d][2]) * L ** (2 * d) for d in range(3)]
            A = [(L * c[d][2] + lev * c[d][0]) * L ** (2 * d) for d in range(3)]
            gb = b @ gxy
            m += W * (gxy[None, :] * G[0][:, None] + 2.0 * (gb * G[1] + gz * A[1])[:, None] * b)
            bb = np.einsum("ni,nj->nij", b, b)
            J += W * (2.0 * G[1][:, None, None] * (np.einsum("i,nj->nij", gxy, b) + np.einsum("ni,j->nij", b, gxy))
                      + 2.0 * (gb * G[1] + gz * A[1])[:, None, None] * eye
                      + 4.0 * (gb * G[2] + gz * A[2])[:, None, None] * bb)
        return m, J

    def to_dict(self) -> dict[str, Any]:
        """The load case as a JSON-ready dict."""
        return {"hand_mass_g": self.hand_mass_g, "hand_lever_mm": self.hand_lever_mm, "payload_g": self.payload_g,
                "payload_lever_mm": self.payload_lever_mm, "forearm": self.forearm, "up_deg": self.up_deg}


# ---- the vectorised wrist ---------------------------------------------------------------------
class _Wrist4:
    """The wrist's moment for blocks of pressures (N, 4) and curvature vectors (N, 2), from the law's table."""

    def __init__(self, wrist: Wrist, load: WristLoad | None):
        law = wrist.law
        self.w, self.load, self.L = wrist, load, wrist._length_mm
        self.table = law.tabulated(_TABLE_TOL)
        self.k_lo, self.k_hi = float(law.limits.k_min), float(law.limits.k_max)
        self.P_start = float(law.P_start_kpa)
        self.s = wrist._actuator.bend_sign
        self.e = wrist.directions
        self.ep = np.stack([-self.e[:, 1], self.e[:, 0]], axis=1)
        self.fixed = (wrist.lateral_stiffness_nmm2 * (self.ep.T @ self.ep)
                      + wrist.column_stiffness_nmm2 * np.eye(2))  # the linear part, N*mm^2

    def kprime(self, b: np.ndarray) -> np.ndarray:
        return self.s * (b @ self.e.T)

    def actuators(self, P: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each actuator's moment ``M`` (N*mm) and ``dM/dk'`` (N*mm^2), (N, 4), at its frame curvature."""
        kc = np.clip(self.kprime(b), 0.999 * self.k_lo, 0.999 * self.k_hi)  # inside; admissible() refuses outside
        A, B, dA, dB = self.table.derivatives(kc)
        pa = np.maximum(P - self.P_start, 0.0)
        return pa * A - B, pa * dA - dB

    def moment(self, P: np.ndarray, b: np.ndarray, t: float = 1.0):
        """Total moment (N*mm, (N, 2)), Jacobian (N, 2, 2) and the actuators' ``dM/dk'`` (N, 4), load scaled by t."""
        M, dM = self.actuators(P, b)
        m = self.s * (M @ self.e) - b @ self.fixed
        J = np.einsum("ni,ij,ik->njk", dM, self.e, self.e) - self.fixed
        if self.load is not None and self.load.total_g > 0:
            ml, Jl = self.load.moment(b, self.L)
            m, J = m + t * ml, J + t * Jl
        return m, J, dM

    def admissible(self, P: np.ndarray, b: np.ndarray) -> np.ndarray:
        kp = self.kprime(b)
        inside = np.all((kp > self.k_lo) & (kp < self.k_hi), axis=1)
        _, dM = self.actuators(P, b)
        return inside & np.all(dM < 0.0, axis=1)

    def stable(self, P: np.ndarray, b: np.ndarray, t: float) -> np.ndarray:
        _, J, _ = self.moment(P, b, t)
        ev = np.linalg.eigvalsh(0.5 * (J + np.swapaxes(J, 1, 2)))
        return self.admissible(P, b) & np.all(ev < 0.0, axis=1)


def _continue(model: _Wrist4, P: np.ndarray, steps: int) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """Continuation in pressure and load from the straight wrist, all rows together: final curvatures (N, 2),
    whether each row stayed on a stable equilibrium, and the curvature after every step."""
    n = len(P)
    b = np.zeros((n, 2))
    ok = np.ones(n, dtype=bool)
    path = []
    scale = max(1.0, float(np.max(np.abs(model.table.moment(np.max(P, initial=0.0), 0.0)))))
    for t in np.linspace(1.0 / steps, 1.0, steps):
        Pt = t * P

        live = np.flatnonzero(ok)
        Pl = Pt[live]

        def fun(rows, U, Pl=Pl, t=t):
            return np.stack([model.moment(Pl[rows], U[:, j], t)[0] for j in range(U.shape[1])], axis=1) / scale

        def jac(rows, u, Pl=Pl, t=t):
            return model.moment(Pl[rows], u, t)[1] / scale

        def adm(rows, u, Pl=Pl):
            return model.admissible(Pl[rows], u)

        if live.size:
            u, conv, _ = newton_batch(fun, b[live], -np.inf, np.inf, maxit=50, jac=jac, admissible=adm)
            good = conv & model.stable(Pt[live], u, t)
            b[live] = u
            ok[live] = good
        path.append(np.where(ok[:, None], b, np.nan))
    return np.where(ok[:, None], b, np.nan), ok, path


def _margins(wrist: Wrist, model: _Wrist4, P: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Frame-buckling margins (N, 4) of the actuators at pressures P (N, 4) and curvatures b (N, 2); NaN where b is."""
    kp = model.kprime(np.nan_to_num(b))
    out = np.full(P.shape, np.nan)
    good = np.all(np.isfinite(b), axis=1)
    act = wrist._actuator
    for i in range(P.shape[1]):
        for p in np.unique(P[good, i]):
            rows = good & (P[:, i] == p)
            out[rows, i] = section_limits(act, float(p), kp[rows, i])["buckling_margin"]
    return out


def _orientation(b: np.ndarray, L: float) -> tuple[np.ndarray, np.ndarray]:
    """Tilt (deg) and its direction (deg in [0, 360); NaN when straight) of curvature vectors b (N, 2)."""
    kap = np.hypot(b[:, 0], b[:, 1])
    psi = np.degrees(np.arctan2(b[:, 1], b[:, 0])) % 360.0
    psi = np.where(psi > 360.0 - 1e-6, 0.0, psi)
    return np.degrees(kap * L), np.where(kap > 1e-12, psi, np.nan)


@dataclass(frozen=True)
class WristMap:
    """Orientation of the loaded wrist for a block of pressure combinations.

    Attributes
    ----------
    pressures_kpa : (N, 4), kPa.
    tilt_deg, direction_deg : (N,), deg: the tilt ``|b| L`` and its direction (NaN: straight or no equilibrium).
    equilibrium : (N,) bool: a stable equilibrium reached by continuation from the straight wrist.
    buckling_margin : (N, 4): each actuator's frame-buckling margin there (inf: frame in tension).
    load : the :class:`WristLoad` (None: unloaded).

    Examples
    --------
    >>> m = wrist_map(Wrist(), [[0.0, 150.0, 0.0, 0.0], [150.0, 0.0, 0.0, 0.0]])
    >>> m.tilt_deg.round(1).tolist(), m.direction_deg.round(1).tolist()     # as wrist_bend: 22.3 deg
    ([22.3, 22.3], [90.0, 0.0])
    """

    pressures_kpa: np.ndarray
    tilt_deg: np.ndarray
    direction_deg: np.ndarray
    equilibrium: np.ndarray
    buckling_margin: np.ndarray
    load: WristLoad | None

    def to_dataframe(self):
        """One row per combination: ``p0_kpa``..``p3_kpa``, ``tilt_deg``, ``direction_deg``, ``equilibrium``,
        ``buckling_margin_0``..``3``, ``min_buckling_margin`` (a :class:`pandas.DataFrame`)."""
        import pandas as pd

        cols: dict[str, Any] = {f"p{i}_kpa": self.pressures_kpa[:, i] for i in range(4)}
        cols.update(tilt_deg=self.tilt_deg, direction_deg=self.direction_deg, equilibrium=self.equilibrium)
        cols.update({f"buckling_margin_{i}": self.buckling_margin[:, i] for i in range(4)})
        cols["min_buckling_margin"] = np.min(self.buckling_margin, axis=1)
        return pd.DataFrame(cols)

    def to_dict(self) -> dict[str, Any]:
        """The map as a JSON-ready dict (lists per column; null where not defined)."""
        df = self.to_dataframe()
        return {"load": None if self.load is None else self.load.to_dict(),
                "columns": {c: [json_number(v) if c != "equilibrium" else bool(v) for v in df[c]] for c in df}}

    def plot(self, ax=None, title: str | None = None):
        """The tilts in the plane of the actuators, coloured by the buckling margin
        (:func:`~bendpam.present.figures.hand.plot_wrist_map`).

        >>> fig = wrist_map(Wrist(), [[0.0, 150.0, 0.0, 0.0]]).plot()
        >>> fig.axes[0].get_xlabel()
        'tilt toward 0 deg (deg)'
        """
        return figure("wrist_map")(self, ax=ax, title=title)

    def save(self, out_dir, *, figure_format: str = "png") -> dict[str, str]:
        """Write ``wrist_map.json`` (:meth:`to_dict`) and ``wrist_map.<format>`` into ``out_dir``; ``{name: path}``.

        >>> import tempfile
        >>> with tempfile.TemporaryDirectory() as d:
        ...     sorted(wrist_map(Wrist(), [[0.0, 150.0, 0.0, 0.0]]).save(d))
        ['wrist_map.json', 'wrist_map.png']
        """
        return save_result(out_dir, "wrist_map", self.to_dict(), lambda: self.plot(), figure_format)


def _pressure_block(wrist: Wrist, pressures_kpa) -> np.ndarray:
    P = np.asarray(pressures_kpa, dtype=float)
    if P.ndim != 2 or P.shape[1] != 4 or P.shape[0] == 0:
        raise InputError(f"pressures_kpa has shape {P.shape}; give rows of 4 pressures (kPa), one per actuator")
    flat = checked_pressures_kpa(P.ravel(), "pressures_kpa", actuator=wrist._actuator)
    return flat.reshape(P.shape)


def wrist_map(wrist: Wrist, pressures_kpa, load: WristLoad | None = None, *, steps: int = _STEPS) -> WristMap:
    """Tilt and direction of the wrist (with ``load``) for every row of four pressures (kPa), solved together.

    ``pressures_kpa``: (N, 4) rows; :func:`numpy.meshgrid` of per-actuator values gives a full map.
    ``steps``: continuation steps in pressure (and load) from the straight wrist (2 to 64).

    Examples
    --------
    The hand (300 g at 80 mm) and a 550 g bottle, forearm horizontal, top actuator inflated: the hand droops
    by 25.9 deg (toward 270 deg, down):

    >>> m = wrist_map(Wrist(), [[0.0, 140.0, 0.0, 0.0]], WristLoad(payload_g=550.0))
    >>> bool(m.equilibrium[0]), round(float(m.tilt_deg[0]), 1), round(float(m.direction_deg[0]), 1)
    (True, 25.9, 270.0)
    """
    if not isinstance(wrist, Wrist):
        raise TypeError(f"wrist must be a bendpam.design.Wrist, got {type(wrist).__name__}")
    if load is not None and not isinstance(load, WristLoad):
        raise TypeError(f"load must be a WristLoad or None, got {type(load).__name__}")
    n = integer("steps", steps, 2, 64)
    P = _pressure_block(wrist, pressures_kpa)
    model = _Wrist4(wrist, load)
    b, ok, _ = _continue(model, P, n)
    tilt, psi = _orientation(np.nan_to_num(b), wrist._length_mm)
    tilt, psi = np.where(ok, tilt, np.nan), np.where(ok, psi, np.nan)
    return WristMap(P, tilt, psi, ok, _margins(wrist, model, P, b), load)


# ---- the inverse: pressures for a target orientation ------------------------------------------
@dataclass(frozen=True)
class WristTarget:
    """The pressures that hold the wrist at a target tilt and direction, and whether it gets there.

    Attributes
    ----------
    tilt_deg, direction_deg : the target, deg.
    pressures_kpa : the four pressures (kPa; NaN where no pair of neighbouring actuators can hold it).
    reached : the forward solve at those pressures (continuation from the straight wrist) ends at the
        target (within 0.05 deg) on a stable equilibrium.
    tilt_reached_deg, direction_reached_deg : where the forward solve ends, deg.
    min_buckling_margin : per actuator, the smallest frame-buckling margin along the pressure ramp.
    note : why not, else empty.

    Examples
    --------
    >>> t = wrist_target(Wrist(), 20.0, 45.0)              # between two actuators: both inflated
    >>> [round(p) for p in t.pressures_kpa], t.reached
    ([104, 104, 0, 0], True)
    """

    tilt_deg: float
    direction_deg: float
    pressures_kpa: tuple
    reached: bool
    tilt_reached_deg: float
    direction_reached_deg: float
    min_buckling_margin: tuple
    note: str

    def to_dict(self) -> dict[str, Any]:
        """The target and its pressures as a JSON-ready dict."""
        return {"tilt_deg": self.tilt_deg, "direction_deg": self.direction_deg,
                "pressures_kpa": [json_number(p) for p in self.pressures_kpa], "reached": bool(self.reached),
                "tilt_reached_deg": json_number(self.tilt_reached_deg),
                "direction_reached_deg": json_number(self.direction_reached_deg),
                "min_buckling_margin": [json_number(m) for m in self.min_buckling_margin],
                "note": self.note or None}


def _needed_pressures(model: _Wrist4, b: np.ndarray) -> tuple[np.ndarray, str]:
    """Pressures (kPa, (4,)) of two neighbouring actuators that balance the wrist at curvature ``b`` (the law is
    affine in the active pressure, ``M = P_a A - B``: a 2x2 linear system); the smallest feasible pair."""
    kp = model.kprime(b[None, :])[0]
    if np.any(kp <= model.k_lo) or np.any(kp >= model.k_hi):
        return np.full(4, np.nan), "the target bends an actuator beyond its lock-up limit"
    A, _B, _dA, _dB = model.table.derivatives(kp)
    m0, _, _ = model.moment(np.zeros((1, 4)), b[None, :])  # every actuator at P_a = 0, with the load
    best, best_max = None, math.inf
    for i in range(4):
        j = (i + 1) % 4
        cols = np.column_stack([model.s * A[i] * model.e[i], model.s * A[j] * model.e[j]])
        if abs(np.linalg.det(cols)) < 1e-12:
            continue
        pa = np.linalg.solve(cols, -m0[0])
        if np.all(pa >= -1e-9) and pa.max() < best_max:
            best, best_max = (i, j, np.maximum(pa, 0.0)), float(pa.max())
    if best is None:
        return np.full(4, np.nan), "no two neighbouring actuators hold this orientation with positive pressures"
    P = np.zeros(4)
    i, j, pa = best
    for idx, a in ((i, pa[0]), (j, pa[1])):
        P[idx] = a + model.P_start if a > 1e-9 else 0.0
    return P, ""


def wrist_target(wrist: Wrist, tilt_deg: float, direction_deg: float, load: WristLoad | None = None, *,
                 steps: int = _STEPS) -> WristTarget:
    """The pressures (kPa) that hold the wrist (with ``load``) at ``tilt_deg`` toward ``direction_deg``.

    Solved in closed form at the target curvature, then checked by the forward solve from the
    straight wrist (:func:`wrist_map`), which also gives the buckling margins along the way.

    Examples
    --------
    >>> t = wrist_target(Wrist(), 30.0, 90.0)                 # unloaded: the actuator at 90 deg alone
    >>> [round(p) for p in t.pressures_kpa], t.reached, round(t.tilt_reached_deg, 2)
    ([0, 197, 0, 0], True, 30.0)
    """
    if not isinstance(wrist, Wrist):
        raise TypeError(f"wrist must be a bendpam.design.Wrist, got {type(wrist).__name__}")
    tilt = number("tilt_deg", tilt_deg, 0.0, 180.0, unit="deg")
    psi = number("direction_deg", direction_deg, -720.0, 720.0, unit="deg")
    n = integer("steps", steps, 2, 64)
    model = _Wrist4(wrist, load)
    kap = math.radians(tilt) / wrist._length_mm
    b = kap * np.array([math.cos(math.radians(psi)), math.sin(math.radians(psi))])
    P, note = _needed_pressures(model, b)
    nan4 = (math.nan,) * 4
    if note:
        return WristTarget(tilt, psi % 360.0, tuple(P), False, math.nan, math.nan, nan4, note)
    max_p = float(wrist._actuator.max_pressure_kpa)
    if P.max() > max_p:
        return WristTarget(tilt, psi % 360.0, tuple(P), False, math.nan, math.nan, nan4,
                           f"needs {P.max():.4g} kPa, above the actuator's burst limit {max_p:g} kPa")
    b_end, ok, path = _continue(model, P[None, :], n)
    margins = np.vstack([_margins(wrist, model, t * P[None, :], bt)
                         for t, bt in zip(np.linspace(1.0 / n, 1.0, n), path, strict=True)])
    mins = tuple(float(v) for v in np.nanmin(np.where(np.isnan(margins), np.inf, margins), axis=0))
    tr, pr = _orientation(np.nan_to_num(b_end), wrist._length_mm)
    if not ok[0]:
        return WristTarget(tilt, psi % 360.0, tuple(P), False, math.nan, math.nan, mins,
                           "no equilibrium on the way: the wrist snaps through (an actuator leaves the falling part "
                           "of its moment law) before these pressures")
    off = abs((float(pr[0]) - psi + 180.0) % 360.0 - 180.0) if tilt > 0.05 else 0.0
    hit = abs(float(tr[0]) - tilt) < 0.05 and off < 0.05
    why = "" if hit else (f"the forward solve ends at {float(tr[0]):.2f} deg toward {float(pr[0]):.1f} deg "
                          "(another equilibrium branch)")
    return WristTarget(tilt, psi % 360.0, tuple(P), hit, float(tr[0]), float(pr[0]), mins, why)


def wrist_directions(wrist: Wrist, pressure_kpa: float, load: WristLoad | None = None, *,
                     target_tilt_deg: float = 30.0, directions_deg=(0.0, 90.0, 180.0, 270.0)) -> list[dict[str, Any]]:
    """Per direction: the tilt reached with the actuator of that direction at ``pressure_kpa`` (kPa), carrying
    ``load``; the pressures needed for ``target_tilt_deg``; and the buckling margins on the way.

    Returns one JSON-ready dict per direction: ``direction_deg``, ``pressure_kpa``, ``tilt_deg``,
    ``tilt_direction_deg``, ``equilibrium``, ``reaches_target``, ``min_buckling_margin`` (per
    actuator, along the pressure ramp), ``target`` (:meth:`WristTarget.to_dict`) and ``note``.

    Examples
    --------
    >>> rows = wrist_directions(Wrist(), 200.0)               # unloaded: the four directions alike
    >>> [round(r["tilt_deg"], 1) for r in rows], [r["reaches_target"] for r in rows]
    ([30.4, 30.4, 30.4, 30.4], [True, True, True, True])
    """
    from bendpam.design.wrist import wrist_pressures

    P0 = checked_pressure_kpa(pressure_kpa, actuator=wrist._actuator)
    target = number("target_tilt_deg", target_tilt_deg, 0.0, 180.0, unit="deg")
    rows = []
    for d in directions_deg:
        P = np.array(wrist_pressures(d, P0, wrist.positions_deg))
        model = _Wrist4(wrist, load)
        b, ok, path = _continue(model, P[None, :], _STEPS)
        margins = np.vstack([_margins(wrist, model, t * P[None, :], bt)
                             for t, bt in zip(np.linspace(1.0 / _STEPS, 1.0, _STEPS), path, strict=True)])
        mins = np.nanmin(np.where(np.isnan(margins), np.inf, margins), axis=0)
        tilt, psi = _orientation(np.nan_to_num(b), wrist._length_mm)
        tgt = wrist_target(wrist, target, d, load)
        along = float(tilt[0] * math.cos(math.radians(psi[0] - d))) if ok[0] and tilt[0] > 1e-9 else 0.0
        reached = bool(ok[0] and along >= target - 1e-9)
        rows.append(_direction_row(d, P0, ok[0], tilt[0], psi[0], along, reached, mins, tgt, target))
    return rows


def _direction_row(d, P0, ok, tilt, psi, along, reached, mins, tgt: WristTarget, target: float) -> dict[str, Any]:
    """One direction of :func:`wrist_directions` as a JSON-ready dict, with the note that says why not."""
    need = (f"{np.nanmax(tgt.pressures_kpa):.4g} kPa" + ("" if np.count_nonzero(tgt.pressures_kpa) < 2 else
                                                          f" ({', '.join(f'{p:.4g}' for p in tgt.pressures_kpa)})")
            if tgt.reached else f"more than the model gives ({tgt.note})")
    weak = [i for i, m in enumerate(tgt.min_buckling_margin) if m < 1.0]
    if tgt.reached and weak:
        need += (f", where the frame of actuator {weak[0]} buckles first (margin "
                 f"{tgt.min_buckling_margin[weak[0]]:.2f})")
    if reached:
        note = ""
    elif not ok:
        note = f"no equilibrium at {P0:g} kPa: the wrist snaps through on the way; {target:g} deg needs {need}"
    else:
        note = f"{along:.1f} deg toward {d % 360.0:g} deg at {P0:g} kPa"
        if tilt > 1e-9 and abs((psi - d + 180.0) % 360.0 - 180.0) > 0.5:
            note += f" (it tilts {tilt:.1f} deg toward {psi:.0f} deg under the load)"
        note += f"; {target:g} deg needs {need}"
    return {"direction_deg": float(d) % 360.0, "pressure_kpa": P0, "tilt_deg": json_number(tilt) if ok else None,
            "tilt_direction_deg": json_number(psi) if ok else None,
            "tilt_along_deg": json_number(along) if ok else None,
            "equilibrium": bool(ok), "reaches_target": reached,
            "min_buckling_margin": [json_number(m) for m in mins], "target": tgt.to_dict(), "note": note or None}
