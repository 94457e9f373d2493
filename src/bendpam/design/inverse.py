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
import time
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from bendpam.design.finger import Finger
from bendpam.design.parts import pressures_checked
from bendpam.design.problem import MARGIN_CAP, DesignProblem
from bendpam.design.result import DesignResult, ParetoFront, fmt_margin
from bendpam.design.targets import TOL, Target, parse_targets, parse_variables
from bendpam.design.tip import blocked_tip_force
from bendpam.errors import BendpamError, InputError
from bendpam.infra.accessors import figure
from bendpam.infra.progress import Progress
from bendpam.infra.scheduler import parse_scheduler_address, probe_scheduler
from bendpam.physics.actuator import Actuator
from bendpam.physics.models import resolve_model
from bendpam.predict import blocked_moment, free_branch, free_curvature, tangent_stiffness
from bendpam.sweeps import evaluate_cases, sweep

__all__ = [
    "design_actuator",
    "plot_coarse_map",
    "plot_pareto",
]

_BLOCK = 256  # designs per block of the coarse map


def _least_squares(prob: DesignProblem, u0: np.ndarray, sel: Sequence[int], constraints: bool = True,
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


def _max_margin(prob: DesignProblem, u0: np.ndarray) -> np.ndarray:
    """Stage B: SLSQP maximising the smallest log margin while every target stays met."""
    from scipy.optimize import minimize

    n = u0.size
    eq = [i for i, t in enumerate(prob.targets) if t.sense == "="]
    ineq = [i for i, t in enumerate(prob.targets) if t.sense != "="]
    s_max = math.log(MARGIN_CAP / prob.min_margin)

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


def _local(prob: DesignProblem, u0: np.ndarray, sel: Sequence[int], constraints: bool = True,
           maximise: bool = True) -> tuple[np.ndarray, float, float]:
    """Stage A, then (when feasible) stage B and a polish: ``(u, violation, objective)``."""
    u = _least_squares(prob, u0, sel, constraints)
    q, mg, _ = prob.block(u)
    viol = float(prob.violation(q[:1], mg[:1], sel, constraints)[0])
    obj = float(prob.objective(mg[:1])[0]) if constraints else 0.0
    if maximise and constraints and viol <= TOL * 0.1 and len(sel) == len(prob.targets):
        ub = _max_margin(prob, u)
        ub = _least_squares(prob, ub, sel, constraints, max_nfev=20)
        qb, mgb, _ = prob.block(ub)
        vb = float(prob.violation(qb[:1], mgb[:1], sel, constraints)[0])
        ob = float(prob.objective(mgb[:1])[0])
        if vb <= TOL * 0.1 and ob >= obj:
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
    return Progress(total, description, quiet=not show)


def design_actuator(base: Actuator, targets: Iterable[Target | str], vary, *, model: str | None = None,
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
    model : ``"energy"``, ``"force_balance"`` or None (default): the base actuator's own model (energy
        when unknown); another than the actuator's warns (:class:`~bendpam.errors.ModelMismatchWarning`).
    max_pressure_kpa : the operating pressure (kPa): every margin must hold up to it, and the
        fold or lock-up pressure must exceed it by ``min_margin``.  Default: the highest target
        pressure.
    min_margin : the safety factor required of every margin (>= 1).
    n_coarse : designs in the coarse map (rounded up to a power of 2; 16 to 2**20).
    n_starts : local searches from the best distinct designs of the map (1 to 64).
    pareto : compute the Pareto front of two targets (None: when there are exactly two).
    scheduler : a Dask scheduler address (or scheduler file): the coarse map (a grid) is computed
        there.  It must answer as a Dask scheduler within 10 s (:mod:`bendpam.infra.scheduler`).
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
    prob, n_coarse, n_starts, want_pareto, scheduler = _problem(base, targets, vary, model, max_pressure_kpa,
                                                                 min_margin, n_coarse, n_starts, pareto,
                                                                 scheduler, seed)
    tg, n = prob.targets, len(prob.variables)
    all_t = list(range(len(tg)))

    m = math.ceil(math.log2(n_coarse))
    n_map = (1 << m) if scheduler is None else max(2, round(n_coarse ** (1.0 / n))) ** n
    # progress in designs: the coarse map's, then _BLOCK per local search and per final stage
    with _progress(n_map + _BLOCK * (n_starts + 2), "design", progress) as bar, pressures_checked():
        # 1. the coarse map, ranked
        U, X, Q, MG, method = _coarse_map(prob, m, n_coarse, scheduler, seed, bar)
        tip = [i for i, t in enumerate(tg) if t.quantity == "blocked_tip_force_n"]
        viol, starts = _starts(prob, U, Q, MG, tip, n_starts)
        # 2-3. local searches
        u_best = _search(prob, U, X, starts, tip, bar)
        x_best = prob.x_of(u_best)
        q_b, mg_b = prob.evaluate(x_best[None, :])
        feasible_search = float(prob.violation(q_b, mg_b, all_t)[0]) <= TOL

        # diagnosis
        binding: tuple[str, ...] = ()
        detail = ""
        if not feasible_search:
            binding, detail = _diagnose(prob, U, Q, MG, u_best)
        bar.advance(_BLOCK, "design: checking")
        front = _pareto(prob, U, Q, MG, seed) if want_pareto else None
        bar.advance(_BLOCK, "design: done")

    with pressures_checked():  # checked above: the designs' own predictions do not warn again
        return _result(prob, x_best, binding, detail, front,
                       dict(X=X, quantities=Q, violation=viol, min_margin=_min_margin(MG), method=method),
                       dict(seed=int(seed), n_coarse=len(X), n_starts=len(starts), coarse_method=method,
                            evaluations=int(prob.n_evaluations), scheduler=scheduler,
                            elapsed_s=round(time.perf_counter() - t_start, 3)))


def _problem(base, targets, vary, model, max_pressure_kpa, min_margin, n_coarse, n_starts, pareto, scheduler,
             seed) -> tuple[DesignProblem, int, int, bool, Any]:
    """:func:`design_actuator`'s arguments checked: the problem, the search sizes, the Pareto flag, the scheduler.

    The model is the base actuator's unless ``model`` says otherwise (then it warns once); a target or
    operating pressure outside a fitted base actuator's tested range warns once here.
    """
    if not isinstance(base, Actuator):
        raise TypeError(f"base must be a bendpam.Actuator, got {type(base).__name__}")
    model = resolve_model(base, model)
    tg = parse_targets(targets)
    variables = parse_variables(base, vary)
    n_coarse, n_starts, want_pareto = _checked_search(tg, max_pressure_kpa, min_margin, n_coarse, n_starts, pareto)
    base.outside_tested([t.pressure_kpa for t in tg if t.pressure_kpa is not None]
                        + ([] if max_pressure_kpa is None else [max_pressure_kpa]))  # once, outside the tests
    scheduler = _checked_scheduler(scheduler)
    prob = DesignProblem(base, model, tg, variables, max_pressure_kpa, float(min_margin), int(seed))
    return prob, n_coarse, n_starts, want_pareto, scheduler


def _checked_search(tg: tuple[Target, ...], max_pressure_kpa, min_margin, n_coarse, n_starts,
                    pareto) -> tuple[int, int, bool]:
    """Check the search's arguments; returns ``(n_coarse, n_starts, want_pareto)``."""
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
    return n_coarse, n_starts, len(tg) == 2 if pareto is None else bool(pareto)


def _coarse_map(prob: DesignProblem, m: int, n_coarse: int, scheduler: str | None, seed: int, bar):
    """Stage 1: a scrambled Sobol sample of ``2**m`` designs (or, with ``scheduler``, a grid on that cluster).

    Returns ``(U, X, Q, MG, method)``: unit-box and actual designs, target quantities, margins.
    """
    n = len(prob.variables)
    if scheduler is not None:
        U, X, Q, MG = _coarse_grid(prob, n_coarse, scheduler, bar.advance)
        return U, X, Q, MG, "grid"
    from scipy.stats import qmc

    U = qmc.Sobol(n, scramble=True, rng=np.random.default_rng(seed)).random_base2(m)
    X = prob.x_of(U)
    qs, ms = [], []
    for s in range(0, len(X), _BLOCK):
        q, mg = prob.evaluate(X[s:s + _BLOCK])
        qs.append(q)
        ms.append(mg)
        bar.advance(len(q), "design: coarse map")
    return U, X, np.vstack(qs), np.vstack(ms), "sobol"


def _starts(prob: DesignProblem, U, Q, MG, tip: list[int], n_starts: int) -> tuple[np.ndarray, list[int]]:
    """The coarse map's violations and the ``n_starts`` best distinct designs to start the local searches from.

    The tip-force targets' closed form is first corrected at the centre of the box (``Q`` in place).
    """
    all_t = list(range(len(prob.targets)))
    if tip:
        f0 = _tip_correction(prob, prob.x_of(np.full(len(prob.variables), 0.5)), tip)
        Q[:, tip] *= f0[tip] / prob.tip_factor[tip]
        prob.set_tip_factor(f0)
    viol = prob.violation(Q, MG, all_t)
    score = np.sum(prob.rows(Q, MG, all_t) ** 2, axis=1)
    obj = prob.objective(MG)
    order = np.lexsort((-obj, np.round(score, 12)))
    return viol, _distinct(U, order, n_starts)


def _search(prob: DesignProblem, U, X, starts: list[int], tip: list[int], bar) -> np.ndarray:
    """Stages 2-3 from each start; the best design in the unit box (exactly on a bound where it is at one)."""
    all_t = list(range(len(prob.targets)))
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
    return np.where(u_best < 1e-8, 0.0, np.where(u_best > 1.0 - 1e-8, 1.0, u_best))  # on a bound: exactly


def _checked_scheduler(scheduler: str | None) -> str | None:
    """The scheduler's address, read and asked before any work (refused in one line, never a hang)."""
    if scheduler is None:
        return None
    address = parse_scheduler_address(scheduler)
    probe_scheduler(address)
    return address


def _int_in(name: str, v, lo: int, hi: int) -> int:
    if isinstance(v, bool) or not isinstance(v, int | np.integer) or not lo <= int(v) <= hi:
        raise InputError(f"{name} = {v!r} must be an integer in [{lo}, {hi}]")
    return int(v)


def _better(a: tuple[float, float], b: tuple[float, float]) -> bool:
    """(violation, objective) ``a`` better than ``b``: feasible beats infeasible, then objective, then violation."""
    fa, fb = a[0] <= TOL * 0.1, b[0] <= TOL * 0.1
    if fa != fb:
        return fa
    if fa:
        return a[1] > b[1] + 1e-9
    return a[0] < b[0] - 1e-12


def _min_margin(mg: np.ndarray) -> np.ndarray:
    if not mg.shape[1]:
        return np.full(len(mg), np.inf)
    return np.where(np.isnan(mg).any(axis=1), np.nan, np.nanmin(np.where(np.isnan(mg), np.inf, mg), axis=1))


def _coarse_grid(prob: DesignProblem, n_coarse: int, scheduler: str, report):
    """The coarse map as a factorial grid computed by :func:`bendpam.sweep` on a Dask cluster."""
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
    try:
        res = blocked_tip_force(Finger(act, model), P)
    except BendpamError:
        return math.nan
    return res.magnitude_n if res.equilibrium else math.nan


def _tip_correction(prob: DesignProblem, x: np.ndarray, tip: list[int]) -> np.ndarray:
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


def _settle_tip(prob: DesignProblem, u: np.ndarray, tip: list[int], sel: Sequence[int]) -> np.ndarray:
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
def _diagnose(prob: DesignProblem, U, Q, MG, u_best) -> tuple[tuple[str, ...], str]:
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
        if v_c > TOL:
            q, mg, _ = prob.block(u_c)
            worst = prob.margin_names[int(np.argmin(prob.margin_miss(mg[:1])[0]))]
            return (f"min_margin={prob.min_margin:g}",), (
                f"No design within the ranges has every margin >= {prob.min_margin:g}"
                + (f" up to {prob.p_op:g} kPa" if prob.p_op else "")
                + f" (the best reaches {worst} = {fmt_margin(float(mg[0, prob.margin_names.index(worst)]))}); "
                  "widen the ranges, lower the operating pressure or the required margin.")
    alone = []
    for i in range(nt):
        u_i, v_i = solve([i])
        if v_i > TOL:
            q, _, _ = prob.block(u_i)
            best_q = _extreme(prob, U, Q, MG, i, float(q[0, i]))
            if abs(float(tg[i].miss(np.array([best_q]))[0])) > TOL:
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
            if v_i <= TOL:
                drop.append(tg[i].text)
    limits_bind = bool(MG.shape[1]) and solve(list(range(nt)), constraints=False)[1] <= TOL
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


def _extreme(prob: DesignProblem, U, Q, MG, i: int, q_local: float, rounds=(0.1, 0.03, 0.01), per_round: int = 256
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
            ok &= np.all(np.abs(prob.margin_miss(Ms)) <= TOL, axis=1)
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


def _pareto(prob: DesignProblem, U, Q, MG, seed: int = 0, rounds=(0.15, 0.05, 0.015), per_round: int = 512
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
            ok &= np.all(np.abs(prob.margin_miss(MG)) <= TOL, axis=1)
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
def _achieved(prob: DesignProblem, act: Actuator) -> np.ndarray:
    """Each target's magnitude from the public prediction functions (independent of the search)."""
    out = np.empty(len(prob.targets))
    for i, t in enumerate(prob.targets):
        P = t.pressure_kpa
        if t.quantity == "max_pressure_kpa":
            out[i] = free_branch(act, prob.model).max_pressure_kpa
        elif t.quantity == "blocked_moment_nmm":
            out[i] = abs(float(blocked_moment(act, P, prob.model)))
        elif t.quantity in ("free_curvature_per_mm", "free_angle_deg", "tangent_stiffness_nmm2"):
            fb = free_curvature(act, P, prob.model)
            k = float(fb.curvature_per_mm)
            if t.quantity == "free_curvature_per_mm":
                out[i] = abs(k)
            elif t.quantity == "free_angle_deg":
                out[i] = abs(float(fb.angle_deg))
            else:
                out[i] = abs(float(tangent_stiffness(act, P, k, prob.model))) if np.isfinite(k) else np.nan
        elif t.quantity == "blocked_stiffness_nmm2":
            out[i] = abs(float(tangent_stiffness(act, P, 0.0, prob.model)))
        elif t.quantity == "blocked_tip_force_n":
            out[i] = _tip_exact(act, prob.model, float(P))  # type: ignore[arg-type]
        else:  # kernel-only quantities (frame stress)
            r = evaluate_cases(act, prob.model, {}, [P])
            out[i] = abs(float(np.asarray(r[t.quantity]).ravel()[0]))
    return out


#: The factors on P_start of the deadband study (:func:`_deadband`): the deadband moved by -20 % and +20 %.
DEADBAND_FACTORS = (0.8, 1.2)


def _deadband(prob: DesignProblem, act: Actuator) -> dict[str, Any]:
    """What the design delivers if its deadband ``P_start`` is not the one assumed (x 0.8 and x 1.2).

    The search keeps the base actuator's ``P_start`` (and its prestrain ratio ``R0_start / R0``) while it
    varies the geometry; the threshold of a real bladder moves with it (docs/design.md, "The deadband").
    Each target is recomputed with the public prediction functions at ``P_start * factor``.
    """
    import warnings

    values = np.array([t.value for t in prob.targets])
    rows: list[dict[str, Any]] = []
    for f in DEADBAND_FACTORS:
        row: dict[str, Any] = {"factor": f, "P_start_kpa": act.P_start_kpa * f}
        try:
            with warnings.catch_warnings():  # the design's own warnings were given once already
                warnings.simplefilter("ignore")
                ach = _achieved(prob, act.replace(P_start_kpa=act.P_start_kpa * f))
        except BendpamError as exc:
            rows.append({**row, "achieved": None, "relative_error": None, "met": None, "note": str(exc)})
            continue
        with np.errstate(invalid="ignore", divide="ignore"):
            rel = ach / values - 1.0
        met = [bool(abs(float(t.miss(np.array([a]))[0])) <= TOL) for t, a in zip(prob.targets, ach, strict=True)]
        rows.append({**row, "achieved": [float(a) for a in ach], "relative_error": [float(e) for e in rel],
                     "met": met, "note": ""})
    varied = any(v.name == "P_start_kpa" for v in prob.variables)
    return {"P_start_kpa": act.P_start_kpa, "R0_start_mm": act.R0_start_mm, "assumed": not varied,
            "meaning": ("P_start is a design variable; the rows show the targets if the built actuator's "
                        "threshold differs from it by -20 % / +20 %" if varied else
                        "P_start is the base actuator's and R0_start keeps its ratio R0_start / R0: both assumed, "
                        "not modelled from the bladder and sleeve geometry; the rows show the targets if the "
                        "deadband moves by -20 % / +20 %"),
            "moved": rows}


def _sensitivities(prob: DesignProblem, x: np.ndarray) -> dict[str, dict[str, float]]:
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


def _result(prob: DesignProblem, x: np.ndarray, binding, detail: str, front, coarse, search) -> DesignResult:
    base_name = prob.base.name or prob.base.kind
    act = prob.actuator(x, name=f"designed from {base_name}")
    achieved = _achieved(prob, act)
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = achieved / np.array([t.value for t in prob.targets]) - 1.0
    met = np.array([abs(float(t.miss(np.array([a]))[0])) <= TOL for t, a in zip(prob.targets, achieved, strict=True)])
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
    margins_ok = bool(np.all(np.abs(prob.margin_miss(mg)) <= TOL)) if mg.shape[1] else True
    feasible = bool(np.all(met)) and margins_ok
    active = [t.text for t, a in zip(prob.targets, achieved, strict=True)
              if t.sense != "=" and np.isfinite(a) and abs(a / t.value - 1.0) <= TOL]
    active += [f"{k} = {margins[k]:.4g}" for k in prob.margin_names
               if np.isfinite(margins[k]) and abs(margins[k] / prob.min_margin - 1.0) <= TOL]
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
                   + (f" (smallest margin {fmt_margin(mmin)})" if not margins_ok else "") + ". "
                   + (detail or f"Binding: {', '.join(binding)}."))
    values = {v.name: float(x[j]) for j, v in enumerate(prob.variables)}
    return DesignResult(
        actuator=act, model=prob.model, targets=prob.targets, variables=prob.variables, values=values,
        achieved=achieved, relative_error=rel, met=met, feasible=feasible, message=message, binding=tuple(binding),
        active=tuple(active), closest=None if feasible else dict(values), margins=margins, margins_by_pressure=by_p,
        min_margin=mmin, min_margin_required=prob.min_margin, max_pressure_kpa=prob.p_op,
        sensitivities=_sensitivities(prob, x), coarse=coarse, pareto=front, search=search,
        deadband=_deadband(prob, act))


# ------------------------------------------------------------------------------------------------
# figures (drawn by bendpam.present.figures.design, reached by name)
# ------------------------------------------------------------------------------------------------
def plot_coarse_map(result: DesignResult):
    """The coarse map in the first two variables (colour: largest relative miss), the design starred.

    The figure is :func:`bendpam.present.figures.design.plot_coarse_map`, loaded on first use.

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> from bendpam.physics.presets import be_pam
    >>> res = design_actuator(be_pam(), ["blocked_moment_nmm=400@200"], ["alpha0_deg=60:80"], n_coarse=16, n_starts=1)
    >>> fig = plot_coarse_map(res)
    >>> len(fig.axes)                                     # the map and its colour bar
    2
    >>> plt.close(fig)
    """
    return figure("coarse_map")(result)


def plot_pareto(result: DesignResult):
    """The Pareto front of the two targets over the coarse map's designs that meet every margin.

    The figure is :func:`bendpam.present.figures.design.plot_pareto`, loaded on first use.

    Examples
    --------
    >>> import matplotlib.pyplot as plt
    >>> from bendpam.physics.presets import be_pam
    >>> res = design_actuator(be_pam(), ["blocked_moment_nmm>=300@150", "free_angle_deg>=60@150"],
    ...                       ["alpha0_deg=60:80", "R0_mm=7:10"], n_coarse=16, n_starts=1)
    >>> fig = plot_pareto(res)
    >>> len(fig.axes)                                     # fig.savefig("pareto.png") to keep it
    1
    >>> plt.close(fig)
    """
    return figure("pareto")(result)
