"""How well a model describes processed tests: the metrics of eq 53-55, with or without its loop.

:func:`score` gives the paper's metrics of any actuator against processed tests, without fitting;
:func:`branch_nrmse` the cycle metric of both branches against a loop model, and
:func:`predicted_loss_ratios` the energy-loss ratio of each test, measured and predicted.
"""

from __future__ import annotations

import math

import numpy as np

from bendpam.identify.data import fit_data
from bendpam.identify.result import Metrics
from bendpam.physics.actuator import Actuator
from bendpam.physics.braid import DEFAULT_ORDER
from bendpam.physics.law import MomentLaw
from bendpam.physics.models import resolve_model

__all__ = ["branch_nrmse", "predicted_loss_ratios", "score"]

def score(
    processed, actuator: Actuator, model: str | None = None, *, loop=None, order: int = DEFAULT_ORDER,
    eq19_factor: bool = True,
) -> Metrics:
    """Metrics of eq 53-55 (and plain RMSEs) of ``actuator`` against processed data, without fitting.

    * eq 53: ``NRMSE_cycles = sqrt(sum_i (RMSE_i / M_max,i)^2 K_max,i / sum_i K_max,i)`` with
      ``M_max,i`` the test's blocked moment and ``K_max,i`` its free curvature; ``RMSE_i`` over the
      mean curve (no ``loop``), or over both mean branches against the loop model on the test's own
      path, blocked state to its measured free curvature (``loop`` given);
    * eq 54: ``NRMSE_BM = RMSE_BM / max_i BM_i``: the model's blocked moment, with a loop the
      largest moment of the predicted free cycle (:func:`bendpam.physics.hysteresis.predict_cycles`);
    * eq 55: ``NRMSE_FBC = RMSE_FBC / max_i FBC_i``: the model's free curvature, with a loop where
      the predicted cycle's unloading branch reaches zero moment; over the pressures where there is
      one (the others are listed in ``no_equilibrium_kpa``).

    Examples
    --------
    Virtual tests of the paper's BE-PAM (without a loop) against the actuator they were made with:

    >>> from pathlib import Path
    >>> import bendpam
    >>> from bendpam.lab import RawTest
    >>> from bendpam.lab.processing import ProcessingOptions
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> be = bendpam.physics.presets.be_pam()
    >>> settings = SimulationSettings(cycles=1, rate_hz=2.0, hysteresis=0.0, seed=1)
    >>> raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv", pressure_kpa=p)
    ...         for p in (100.0, 200.0)]
    >>> processed = bendpam.process_tests(raws, keep_series=False, options=ProcessingOptions(grid_points=21))
    >>> m = score(processed, be)
    >>> m.nrmse_cycles < 0.05, m.no_equilibrium_kpa
    (True, [])
    """
    model = resolve_model(actuator, model)
    d = fit_data(processed, "all")
    s = actuator.bend_sign or 1
    if loop is None:
        law = MomentLaw(actuator, model, order=order, eq19_factor=eq19_factor)
        A, B = law.coefficients(s * d.kc)
        pa = np.maximum(d.Pc - actuator.P_start_kpa, 0.0)
        sq = (s * (pa * A - B) - d.Mc) ** 2
        seg = d.seg
        bm_model = np.abs(law.blocked_moment(d.P))
        kf_model = np.abs(law.free_curvature_array(d.P))
    else:
        from bendpam.physics.hysteresis import loop_branches, predict_cycles

        res = processed.results
        k = np.concatenate([np.asarray(r.curvature_grid, float) for r in res])
        n = [np.asarray(r.curvature_grid).size for r in res]
        Pp = np.repeat(d.P, n)
        up, low = loop_branches(actuator, loop, Pp, np.repeat(d.K, n), k, model, order=order,
                                eq19_factor=eq19_factor)
        ld = np.concatenate([np.asarray(r.mean_loading, float) for r in res])
        ul = np.concatenate([np.asarray(r.mean_unloading, float) for r in res])
        sq = np.concatenate([(up - ld) ** 2, (low - ul) ** 2])
        seg = np.tile(np.repeat(np.arange(len(res)), n), 2)
        cycles = predict_cycles(actuator, loop, d.P, model, order=order, eq19_factor=eq19_factor)
        bm_model = np.array([c.blocked_moment_nmm for c in cycles])
        kf_model = np.array([c.free_curvature_per_mm for c in cycles])
    rm = np.sqrt(np.bincount(seg, sq, d.P.size) / np.bincount(seg, None, d.P.size))
    nrmse_c = math.sqrt(float(np.sum((rm / d.BM) ** 2 * d.K) / np.sum(d.K)))
    rmse_bm = math.sqrt(float(np.mean((bm_model - d.BM) ** 2)))
    ok = np.isfinite(kf_model)
    rmse_fbc = math.sqrt(float(np.mean((kf_model[ok] - d.K[ok]) ** 2))) if ok.any() else math.nan
    per = [{"pressure_kpa": float(d.P[i]), "rmse_cycle_nmm": float(rm[i]), "M_max_nmm": float(d.BM[i]),
            "K_max_per_mm": float(d.K[i]), "blocked_moment_model_nmm": float(bm_model[i]),
            "free_curvature_model_per_mm": float(kf_model[i]) if ok[i] else None} for i in range(d.P.size)]
    return Metrics(
        nrmse_cycles=nrmse_c,
        nrmse_blocked_moment=rmse_bm / float(d.BM.max()),
        nrmse_free_curvature=rmse_fbc / float(d.K.max()) if ok.any() else math.nan,
        rmse_cycles=math.sqrt(float(np.mean(sq))),
        rmse_blocked_moment=rmse_bm,
        rmse_free_curvature=rmse_fbc,
        per_pressure=per,
        no_equilibrium_kpa=[float(p) for p in d.P[~ok]],
        curves="mean curves" if loop is None else "loop",
    )




def predicted_loss_ratios(processed, actuator: Actuator, loop, model: str | None = None, *, order: int = DEFAULT_ORDER,
                          eq19_factor: bool = True) -> list[dict]:
    """Energy-loss ratio of each test, measured (processing) and predicted (the loop's free cycle).

    The prediction is :func:`bendpam.physics.hysteresis.predict_cycles`, exactly what ``bendpam predict
    --cycle`` prints: the cycle between the blocked state and the free state the model reaches on
    unloading.

    Examples
    --------
    >>> from types import SimpleNamespace as NS
    >>> import bendpam
    >>> from bendpam.physics.hysteresis import LoopModel
    >>> tests = NS(results=[NS(pressure_kpa=150.0, energy_loss_ratio=0.2)])
    >>> loop = LoopModel(law="pi", theta_h_deg=5.0, a0_nmm=0.0, a1_nmm_per_kpa=0.25)
    >>> r = predicted_loss_ratios(tests, bendpam.physics.presets.be_pam(), loop)
    >>> r[0]["measured"], 0.0 < r[0]["predicted"] < 1.0
    (0.2, True)
    """
    from bendpam.physics.hysteresis import predict_cycles

    cycles = predict_cycles(actuator, loop, [r.pressure_kpa for r in processed.results], model, order=order,
                            eq19_factor=eq19_factor)
    return [{"pressure_kpa": float(r.pressure_kpa), "measured": float(r.energy_loss_ratio),
             "predicted": c.energy_loss_ratio} for r, c in zip(processed.results, cycles, strict=True)]


def branch_nrmse(processed, actuator: Actuator, loop, model: str | None = None, *, order: int = DEFAULT_ORDER,
                 eq19_factor: bool = True) -> float:
    """eq-53-style NRMSE of both branches (loading and unloading) against the loop model (:func:`score`).

    Examples
    --------
    Virtual tests of the paper's BE-PAM with a friction loop, against a loop model (not fitted):

    >>> from pathlib import Path
    >>> import bendpam
    >>> from bendpam.lab import RawTest
    >>> from bendpam.lab.processing import ProcessingOptions
    >>> from bendpam.lab.simulate import SimulationSettings, simulate_test
    >>> be = bendpam.physics.presets.be_pam()
    >>> settings = SimulationSettings(cycles=1, rate_hz=2.0, hysteresis=0.2, seed=1)
    >>> raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv", pressure_kpa=p)
    ...         for p in (100.0, 200.0)]
    >>> processed = bendpam.process_tests(raws, keep_series=False, options=ProcessingOptions(grid_points=21))
    >>> from bendpam.physics.hysteresis import LoopModel
    >>> loop = LoopModel(law="pi", theta_h_deg=5.0, a0_nmm=0.0, a1_nmm_per_kpa=0.25)
    >>> 0.0 < branch_nrmse(processed, be, loop) < 1.0
    True
    """
    return score(processed, actuator, model, loop=loop, order=order, eq19_factor=eq19_factor).nrmse_cycles
