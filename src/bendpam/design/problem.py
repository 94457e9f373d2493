"""The inverse-design problem: targets, variables and margins, and blocks of designs evaluated at once.

:class:`DesignProblem` maps the unit box of the variables to actuators, evaluates blocks of designs
with the vectorised sweep kernel (:func:`bendpam.sweeps.evaluate_cases`) at the target and
operating pressures, and turns the outputs into the targets' magnitudes, the safety margins and
the residuals of the searches of :mod:`bendpam.design.inverse`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from bendpam.design.targets import NAN_MISS, Target, Variable
from bendpam.errors import BendpamError, InputError
from bendpam.physics.actuator import Actuator
from bendpam.physics.law import MomentLaw
from bendpam.sweeps import build_cases, evaluate_cases

__all__ = [
    "MARGIN_CAP",
    "DesignProblem",
]

#: margins above this count as "no demand" in the max-min objective
MARGIN_CAP = 1e3

_KERNEL_2D = ("blocked_moment_nmm", "free_curvature_per_mm", "free_angle_deg", "frame_stress_mpa")
_STIFFNESS = ("tangent_stiffness_nmm2", "blocked_stiffness_nmm2")
_FD_STEP = 1e-6  # forward-difference step in the unit box
_W_CONSTRAINT = 30.0  # weight of the margins' misses in the least squares (the closest design keeps them)


class DesignProblem:
    """Targets, variables and margins of one design problem; evaluates blocks of designs.

    The designs are points ``u`` of the unit box of the variables (:meth:`x_of` maps them to the
    variables' values); :meth:`evaluate` gives, for a block of designs, the targets' magnitudes and
    the smallest margin of each kind over the operating pressures (``margin_names``).

    Examples
    --------
    >>> import numpy as np
    >>> from bendpam.physics.presets import be_pam
    >>> from bendpam.design.targets import parse_targets, parse_variables
    >>> base = be_pam()
    >>> prob = DesignProblem(base, "energy", parse_targets(["blocked_moment_nmm=400@200"]),
    ...                      parse_variables(base, ["alpha0_deg=60:80"]), None, 1.0)
    >>> q, margins = prob.evaluate(prob.x_of(np.array([[0.0], [1.0]])))     # alpha0 = 60 and 80 deg
    >>> q[:, 0].round(1).tolist(), margins.shape == (2, len(prob.margin_names))
    ([142.4, 400.7], True)
    """

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
        return np.where(np.isnan(mg), -NAN_MISS, r)

    def violation(self, q: np.ndarray, mg: np.ndarray, sel: Sequence[int], constraints: bool = True) -> np.ndarray:
        """The largest relative miss of a target or margin, per design."""
        parts = [np.abs(self.targets[i].miss(q[:, i])) for i in sel]
        if constraints and mg.shape[1]:
            parts.extend(np.abs(self.margin_miss(mg)).T)
        return np.max(np.vstack(parts), axis=0) if parts else np.zeros(len(q))

    def log_margin(self, mg: np.ndarray) -> np.ndarray:
        """``ln(min(margin, cap) / min_margin)`` per margin (NaN: no equilibrium -> very negative)."""
        m = np.where(np.isnan(mg), 1e-6, np.clip(mg, 1e-6, MARGIN_CAP))
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
