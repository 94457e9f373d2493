"""The weighted least-squares problem of a fit (variable projection): residuals for given free parameters.

:class:`Problem` holds the data, the model and the free parameters of one fit of
:func:`bendpam.identify.fitting.fit`: the model's columns at the data's curvatures (the kinematics on
:data:`CHEB_NODES` Chebyshev nodes, interpolated), the linear parameters in the internal coordinates that
keep the admissible cone a box (``S_lo``, ``S_hi``: the weights of the two bounding shapes), the loop's
columns (:func:`bendpam.identify.ensemble.steady_z`), and the weighted residuals.  :class:`Tension` is a
tension test's rows of a joint fit.  The search, the uncertainty and the result are
:mod:`bendpam.identify.fitting`'s.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from bendpam.errors import InputError
from bendpam.identify.data import FitData
from bendpam.identify.ensemble import TWO_BRANCH, played_path, steady_z
from bendpam.identify.numerics import bounded_lstsq, chebyshev_interpolation, halfline
from bendpam.identify.result import PARAMETERS
from bendpam.physics.actuator import Actuator
from bendpam.physics.law import MomentLaw

__all__ = ["CHEB_NODES", "NONLINEAR", "Problem", "Tension"]

#: The kinematic parameters (searched; the others are solved exactly for each of their trials).
NONLINEAR = ("alpha0", "R0_start")
#: Chebyshev nodes on which the kinematics are sampled (then interpolated to the data).
CHEB_NODES = 32


@dataclass
class Tension:
    """Tension-test rows of a joint fit: stretches, nominal stresses (kPa) and their weight.

    >>> Tension(np.array([1.0, 1.2, 1.4]), np.array([0.0, 95.0, 170.0]), 0.5).stretch.size
    3
    """

    stretch: np.ndarray
    stress_kpa: np.ndarray
    weight: float


class Problem:
    """Residuals of the weighted problem for a given set of free parameters (variable projection).

    ``Problem(actuator, data, model, free, bounds, order, eq19_factor, law, shape_bounds)``: the nominal
    actuator, the curves (:class:`~bendpam.identify.data.FitData`), the model, the free parameters, their
    bounds, the braid's series order, eq 19's factor, the loop law (None: mean curves) and the admissible
    shapes.  :meth:`project` solves the linear parameters exactly for the nonlinear ones.

    Examples
    --------
    Two virtual tests of the paper's BE-PAM; with alpha0 at its nominal value, the constants that fit best:

    >>> import warnings
    >>> from pathlib import Path
    >>> import bendpam
    >>> from bendpam.identify.data import fit_data
    >>> from bendpam.lab import RawTest
    >>> from bendpam.lab.processing import process_tests
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> be = bendpam.physics.presets.be_pam()
    >>> raws = [RawTest(simulate_test(be, p, settings=SimulationSettings(cycles=1, rate_hz=2.0, hysteresis=0.0,
    ...                                                                  seed=1))[0], Path(f"{p}.csv"), "csv",
    ...                 pressure_kpa=p) for p in (100.0, 200.0)]
    >>> with warnings.catch_warnings():
    ...     warnings.simplefilter("ignore")
    ...     d = fit_data(process_tests(raws, keep_series=False))
    >>> prob = Problem(be, d, "energy", ["alpha0", "C10", "C01"], {"C10": (-5e3, 5e3), "C01": (-5e3, 5e3)}, 8,
    ...                True, None, (0.0, 1.0))
    >>> r, lin = prob.project({"alpha0": be.alpha0_deg})
    >>> prob.nonlin, prob.int_names, round(prob.to_user({"alpha0": be.alpha0_deg}, lin)["C01"])   # kPa
    (['alpha0'], ['S_lo', 'S_hi'], 185)
    """

    def __init__(self, actuator: Actuator, data: FitData, model: str, free: list[str], bounds, order: int,
                 eq19_factor: bool, law: str | None, shape_bounds: tuple[float, float], *,
                 shape_fixed: float | None = None, tension: Tension | None = None):
        self.base = actuator
        self.d = data
        self.model = model
        self.order = order
        self.eq19 = eq19_factor
        self.law = law
        self.bounds = bounds
        self.shape_bounds = shape_bounds
        self.shape_fixed = shape_fixed
        self.tension = tension
        self.sign = actuator.bend_sign or 1
        self.set_free([*free, "theta_h", "a0", "a1"] if law else list(free))
        w, y, grp = data.w, data.Mc, data.group
        if tension is not None:
            n = tension.stretch.size
            w = np.concatenate([w, np.full(n, tension.weight)])
            y = np.concatenate([y, tension.stress_kpa])
            grp = np.concatenate([grp, np.full(n, int(grp.max()) + 1)])
        self.w, self.y, self.groups = w, y, grp
        self.W: np.ndarray | None
        self.nodes, self.W = chebyshev_interpolation(data.kc, float(data.kc.max()) or 1e-9, CHEB_NODES)
        self._qs_cache: dict = {}
        self._z_cache: dict = {}
        if not self._interpolation_ok():
            self.W = None

    def set_free(self, free: list[str]) -> None:
        """The varied parameters: the nonlinear ones (searched) and the linear ones (projected)."""
        self.free = list(free)
        self.nonlin = [p for p in self.free if p in NONLINEAR or p in ("theta_h", "theta_2", "gap", "ratio")]
        self.lin = [p for p in self.free if p not in self.nonlin]
        self.cone = "C10" in self.lin and "C01" in self.lin
        self.int_names, self.T, self.lo, self.hi = self._internal()

    # -- linear parameters: internal coordinates -> user values (user = T @ internal) ---------
    def _internal(self):
        blocks = []  # (internal name, {user name: coefficient}, lo, hi)
        hiS = max(self.bounds["C10"][1] + self.bounds["C01"][1], 1.0)
        for p in self.lin:
            if p == "C01" and self.cone:
                continue
            if p == "C10" and self.cone:
                if self.shape_fixed is not None:
                    b = self.shape_fixed
                    blocks.append(("S", {"C10": 1.0 - b, "C01": b}, 0.0, hiS))
                else:
                    b_lo, b_hi = self.shape_bounds
                    blocks.append(("S_lo", {"C10": 1.0 - b_lo, "C01": b_lo}, 0.0, hiS))
                    blocks.append(("S_hi", {"C10": 1.0 - b_hi, "C01": b_hi}, 0.0, hiS))
            elif p in ("C10", "C01"):
                blocks.append((p, {p: 1.0}, *self._single_constant_bounds(p)))
            else:
                blocks.append((p, {p: 1.0}, *self.bounds[p]))
        T = np.zeros((len(self.lin), len(blocks)))
        for j, (_, coef, _, _) in enumerate(blocks):
            for name, c in coef.items():
                T[self.lin.index(name), j] = c
        return [b[0] for b in blocks], T, np.array([b[2] for b in blocks]), np.array([b[3] for b in blocks])

    def _single_constant_bounds(self, p: str) -> tuple[float, float]:
        """Bounds of one free constant with the other fixed: its box, C10 + C01 >= 1 kPa, the cone."""
        b_lo, b_hi = self.shape_bounds if self.shape_fixed is None else (self.shape_fixed, self.shape_fixed)
        other = "C01" if p == "C10" else "C10"
        c = float(getattr(self.base, PARAMETERS[other][0]))
        if p == "C10":  # x = C10: C01 - b_lo S >= 0, b_hi S - C01 >= 0
            conds = [(-b_lo, -(1.0 - b_lo) * c), (b_hi, -(b_hi - 1.0) * c), (1.0, 1.0 - c)]
        else:  # x = C01
            conds = [(1.0 - b_lo, b_lo * c), (b_hi - 1.0, -b_hi * c), (1.0, 1.0 - c)]
        lo, hi = self.bounds[p]
        for a, b in conds:
            l_, h_ = halfline(a, b)
            lo, hi = max(lo, l_), min(hi, h_)
        if not lo <= hi:
            raise InputError(
                f"with {PARAMETERS[other][0]} = {c:g} kPa held fixed no {PARAMETERS[p][0]} gives an admissible "
                f"material (shape C01/(C10 + C01) in [{b_lo:.4g}, {b_hi:.4g}]); free both constants")
        return lo, hi

    def actuator(self, values: dict[str, float]) -> Actuator:
        ch = {PARAMETERS[p][0]: v for p, v in values.items() if p in PARAMETERS}
        return self.base.replace(**ch)

    # -- the model's columns --------------------------------------------------------------------
    def _interpolation_ok(self) -> bool:
        if self.W is None or self.d.kc.size <= 3 * CHEB_NODES:
            return False
        law = MomentLaw(self.base, self.model, eq19_factor=self.eq19, order=self.order)
        k = float(self.d.kc.max()) * np.array([1.0, 0.37, 0.81])
        idx = [int(np.argmin(np.abs(self.d.kc - x))) for x in k]
        nodes = np.column_stack(law.basis(self.sign * self.nodes))
        approx = self.W[idx] @ nodes
        exact = np.column_stack(law.basis(self.sign * self.d.kc[idx]))
        scale = np.maximum(np.abs(exact).max(axis=0), 1e-300)
        return bool(np.all(np.abs(approx - exact) <= 1e-9 * scale))

    def _qs(self, nl: dict[str, float]):
        """The actuator, ``(A, b10, b01)`` (per kPa) and the frame's curvature column at the data's curvatures
        for the kinematics in ``nl`` (with a ``gap``: at the played curvatures, as the fixture converts them)."""
        gap = float(nl.get("gap", 0.0))
        key = (tuple(sorted((p, float(v)) for p, v in nl.items() if p in PARAMETERS)), gap)
        hit = self._qs_cache.get(key)
        if hit is None:
            if len(self._qs_cache) > 256:
                self._qs_cache.clear()
            a = self.base.replace(**{PARAMETERS[p][0]: v for p, v in key[0]})
            law = MomentLaw(a, self.model, eq19_factor=self.eq19, order=self.order)
            kq, fac = (self.d.kc, 1.0) if gap <= 0 else self._played(gap)[:2]
            if self.W is not None:
                W = self.W if gap <= 0 else chebyshev_interpolation(kq, float(self.d.kc.max()) or 1e-9, CHEB_NODES)[1]
                cols = W @ np.column_stack(law.basis(self.sign * self.nodes))
                hit = (a, cols[:, 0] * fac, cols[:, 1] * fac, cols[:, 2] * fac, kq * fac)
            else:
                A, b10, b01 = law.basis(self.sign * kq)
                hit = (a, A * fac, b10 * fac, b01 * fac, kq * fac)
            self._qs_cache[key] = hit
        return hit

    def _played(self, gap: float):
        if ("played", gap) not in self._z_cache:
            self._z_cache[("played", gap)] = played_path(self.d, gap)
        return self._z_cache[("played", gap)]

    def _z(self, theta_deg: float, gap: float = 0.0, ratio: float | None = None, law: str | None = None,
           theta_2: float | None = None):
        law = law or self.law
        key = (law, theta_deg, gap, ratio, theta_2)  # the cache is shared by the ensemble's members
        z = self._z_cache.get(key)
        if z is None:
            if len(self._z_cache) > 512:
                self._z_cache.clear()
            assert law is not None, "a loop fit has a law"
            if law in TWO_BRANCH:  # two columns of other laws' z (each cached), at their angles
                angle = {"theta": theta_deg, "theta_2": float(theta_2 or 1.0), None: 0.0}
                z = np.column_stack([self._z(angle[a], law=part).reshape(self.d.kc.size, -1)[:, 0]
                                     for part, a in TWO_BRANCH[law]])
            else:
                z = steady_z(law, theta_deg, self.d if gap <= 0 else self._played(gap)[2], ratio)
            self._z_cache[key] = z
        return z

    def design(self, nl: dict[str, float]):
        """Fixed part ``c0`` and columns ``X`` (per internal linear unit) of every row of the model."""
        a, A, b10, b01, k_frame = self._qs(nl)
        s, d = self.sign, self.d
        cols = {"C10": -s * b10, "C01": -s * b01, "P_start": -s * A, "E_f": -a.frame_inertia_mm4 * k_frame}
        c0 = s * d.Pc * A
        fixed = {"C10": a.C10_kpa, "C01": a.C01_kpa, "P_start": a.P_start_kpa, "E_f": a.frame_modulus_mpa}
        for p, col in cols.items():
            if p not in self.lin:
                c0 = c0 + col * fixed[p]
        if "F_off" in self.lin or "F_P" in self.lin:  # an offset force: its moment at each row is eq 7's lever times it
            assert d.lever is not None, "an offset is fitted only where the fixture's lever is known"
            cols["F_off"] = d.lever  # a load-cell zero offset (N)
            cols["F_P"] = d.lever * d.Pc  # a force in proportion to the pressure (N/kPa)
        if self.law:
            z = self._z(float(nl["theta_h"]), float(nl.get("gap", 0.0)), nl.get("ratio"),
                        theta_2=nl.get("theta_2")).reshape(d.kc.size, -1)
            pa = np.maximum(d.Pc - a.P_start_kpa, 0.0)
            for j, (n0, n1) in enumerate((("a0", "a1"), ("a0_2", "a1_2"))[: z.shape[1]]):
                cols[n0], cols[n1] = -z[:, j], -z[:, j] * pa
        X = np.column_stack([cols[p] for p in self.lin]) if self.lin else np.zeros((c0.size, 0))
        if self.tension is not None:
            lam = self.tension.stretch
            g1 = lam - lam**-2
            tcols = {"C10": 2.0 * g1, "C01": 2.0 * g1 / lam}
            ct = np.zeros(lam.size)
            for p, col in tcols.items():
                if p not in self.lin:
                    ct = ct + col * fixed[p]
            Xt = np.column_stack([tcols.get(p, np.zeros(lam.size)) for p in self.lin])
            c0 = np.concatenate([c0, ct])
            X = np.vstack([X, Xt])
        return c0, X @ self.T

    def to_user(self, nl: dict[str, float], lin_int: np.ndarray) -> dict[str, float]:
        out = {p: float(v) for p, v in nl.items()}
        out.update({p: float(v) for p, v in zip(self.lin, self.T @ lin_int, strict=True)})
        return out

    def project(self, nl: dict[str, float]):
        """Best linear parameters for the nonlinear ones; returns (weighted residuals, internal linear values)."""
        c0, X = self.design(nl)
        Aw = self.w[:, None] * X
        yw = self.w * (self.y - c0)
        x = bounded_lstsq(Aw, yw, self.lo, self.hi)
        return Aw @ x - yw, x

    def residual_full(self, x_int: np.ndarray) -> np.ndarray:
        nl = dict(zip(self.nonlin, x_int[: len(self.nonlin)], strict=True))
        c0, X = self.design(nl)
        return self.w * (c0 + X @ x_int[len(self.nonlin):] - self.y)
