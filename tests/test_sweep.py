"""Design sweeps: equal to direct evaluation, identical on a local Dask cluster, robust to a lost worker."""

import os
import signal
import time

import numpy as np
import pytest
import xarray as xr
from numpy.testing import assert_allclose

import bendpam
from bendpam import presets
from bendpam.cli import main
from bendpam.errors import InputError
from bendpam.sweeps import SWEEP_PARAMETERS, build_cases, evaluate_cases


def direct(base, model, P_kpa, **changes):
    a = base.replace(**changes)
    fb = bendpam.free_curvature(a, np.asarray(P_kpa), model)
    return a, fb


@pytest.mark.parametrize("name,model", [("be-pam", "energy"), ("bc-pam", "energy"), ("bc-pam", "force_balance")])
def test_sweep_equals_direct_evaluation(name, model):
    base = presets.get(name, model)
    a0 = base.alpha0_deg + np.array([-2.0, 0.0, 1.5])
    C01 = base.C01_kpa * np.array([0.9, 1.0])
    P = np.array([40.0, 90.0, 140.0, 200.0])
    ds = bendpam.sweep(base, P, model, alpha0_deg=a0, C01_kpa=C01)
    assert ds.free_curvature_per_mm.dims == ("alpha0_deg", "C01_kpa", "pressure_kpa")
    assert ds.max_pressure_kpa.dims == ("alpha0_deg", "C01_kpa")
    for i, a in enumerate(a0):
        for j, c in enumerate(C01):
            act, fb = direct(base, model, P, alpha0_deg=a, C01_kpa=c)
            k = ds.free_curvature_per_mm.values[i, j]
            assert np.array_equal(np.isnan(k), np.isnan(fb.curvature_per_mm))
            ok = np.isfinite(k)
            assert_allclose(k[ok], fb.curvature_per_mm[ok], rtol=1e-10, atol=1e-15)
            assert_allclose(ds.free_angle_deg.values[i, j][ok], fb.angle_deg[ok], rtol=1e-10, atol=1e-12)
            assert_allclose(ds.blocked_moment_nmm.values[i, j], bendpam.blocked_moment(act, P, model),
                            rtol=1e-12, atol=1e-9)
            br = bendpam.free_branch(act, model)
            mp = float(ds.max_pressure_kpa.values[i, j])
            if np.isfinite(br.max_pressure_kpa):
                assert mp == pytest.approx(br.max_pressure_kpa, rel=1e-9)
            else:
                assert mp == np.inf
            # the limits are bendpam.physics.limits of the same actuator (the margins: safety factors; a fold's
            # curvature, which sets the BC-PAM's lock-up margin, is found to about 1e-8 on a flat maximum)
            lim = bendpam.limits(act, P, model)
            for name in ("frame_axial_force_n", "frame_stress_mpa", "buckling_margin", "lockup_margin",
                         "bladder_stretch_max", "min_margin"):
                assert_allclose(ds[name].values[i, j], getattr(lim, name), rtol=1e-7, err_msg=name)
            if br.kind == "lock-up":  # on the branch: k'_lock / |k'_free|
                lk = bendpam.curvature_limits(act)
                k_lim = lk.k_max if act.bend_sign > 0 else lk.k_min
                assert_allclose(ds.lockup_margin.values[i, j][ok], abs(k_lim) / np.abs(k[ok]), rtol=1e-9)
    assert ds.free_curvature_per_mm.attrs["units"] == "1/mm"
    assert ds.frame_stress_mpa.attrs["units"] == "MPa" and ds.buckling_margin.attrs["units"] == "1"


def test_every_parameter_can_be_swept():
    base = presets.be_pam()
    for name in SWEEP_PARAMETERS:
        v = getattr(base, name)
        vals = [v, v * 1.02] if name != "P_start_kpa" else [60.0, 70.0]
        ds = bendpam.sweep(base, [150.0], **{name: vals})
        for i, val in enumerate(vals):
            act = base.replace(**{name: val}) if name != "R0_mm" else base.replace(
                R0_mm=val, R0_start_mm=val * base.R0_start_mm / base.R0_mm)
            ref = bendpam.free_curvature(act, 150.0).curvature_per_mm
            assert float(ds.free_curvature_per_mm.values[i, 0]) == pytest.approx(float(ref), rel=1e-10), name


def test_build_cases_is_a_block_of_model_params():
    """``build_cases`` (which replaced ``CaseArrays``) gives the numerics' view of every case at once."""
    base = presets.be_pam()
    a0 = np.array([62.0, 68.0, 74.0])
    cs = build_cases(base, {"alpha0_deg": a0})
    assert isinstance(cs, bendpam.ModelParams) and cs.shape == (3,)
    assert_allclose(cs.alpha0, np.radians(a0), rtol=1e-15)
    for i, a in enumerate(a0):
        one = base.replace(alpha0_deg=a).params
        for f in ("alpha0", "R0_start", "t0_start", "bladder_area", "frame_stiffness", "C10", "C01", "P_start", "L0"):
            assert float(np.asarray(getattr(cs, f))[i]) == pytest.approx(float(getattr(one, f)), rel=1e-15), f
    # R0_mm swept alone: R0_start keeps the base ratio, t0_start follows eq 52
    cs = build_cases(base, {"R0_mm": np.array([8.0, 9.0])})
    assert_allclose(cs.R0_start, np.array([8.0, 9.0]) * base.R0_start_mm / base.R0_mm, rtol=1e-15)
    ref = base.replace(R0_mm=9.0, R0_start_mm=9.0 * base.R0_start_mm / base.R0_mm)
    assert float(cs.t0_start[1]) == pytest.approx(ref.t0_start_mm, rel=1e-14)
    with pytest.raises(InputError, match="alpha0_deg"):
        build_cases(base, {"alpha0_deg": np.array([60.0, 95.0])})


def test_bad_sweeps():
    base = presets.be_pam()
    with pytest.raises(ValueError, match="cannot sweep"):
        bendpam.sweep(base, [100.0], alpha=[1, 2])
    with pytest.raises(ValueError, match="t0_mm"):
        bendpam.sweep(base, [100.0], t0_mm=[2.0, 9.0])
    with pytest.raises(ValueError, match="C10_kpa \\+ C01_kpa"):
        bendpam.sweep(base, [100.0], C10_kpa=[-600.0])
    with pytest.raises(ValueError, match="pressure"):
        bendpam.sweep(base, [-5.0], alpha0_deg=[70.0])


def test_lazy_sweep_is_chunked_and_bounded(tmp_path):
    base = presets.be_pam()
    ds = bendpam.sweep(base, np.linspace(80, 250, 5), alpha0_deg=np.linspace(62, 78, 9), t0_mm=[2.0, 2.5, 3.0],
                       compute=False, chunk_cases=4)
    for v in ds.data_vars.values():
        assert v.chunks is not None
        case_dims = [i for i, d in enumerate(v.dims) if d != "pressure_kpa"]
        sizes = [np.prod([v.chunks[i][j] for i, j in zip(case_dims, idx)])
                 for idx in np.ndindex(*[len(v.chunks[i]) for i in case_dims])]
        assert max(sizes) <= 4  # never more than one block of chunk_cases cases at once
    eager = bendpam.sweep(base, np.linspace(80, 250, 5), alpha0_deg=np.linspace(62, 78, 9), t0_mm=[2.0, 2.5, 3.0],
                          chunk_cases=4)
    ds.to_netcdf(tmp_path / "s.nc")
    back = xr.open_dataset(tmp_path / "s.nc")
    assert_allclose(back.free_curvature_per_mm.values, eager.free_curvature_per_mm.values, equal_nan=True, rtol=0)
    back.close()


def _bits(ds):
    return {k: np.ascontiguousarray(v.values, dtype=float).view(np.int64) for k, v in ds.data_vars.items()}


def test_local_cluster_equals_in_process_bit_for_bit():
    pytest.importorskip("distributed")
    base = presets.bc_pam()
    kw = dict(alpha0_deg=np.linspace(34, 39, 6), t0_mm=[2.0, 2.5], chunk_cases=3)
    P = np.array([40.0, 80.0, 120.0, 160.0])
    local = bendpam.sweep(base, P, **kw)
    cluster = bendpam.sweep(base, P, workers=2, **kw)
    a, b = _bits(local), _bits(cluster)
    for k in a:
        assert np.array_equal(a[k], b[k]), k


@pytest.mark.slow  # a LocalCluster with a killed worker, about 5 s
def test_killed_worker_loses_no_results():
    distributed = pytest.importorskip("distributed")
    base = presets.be_pam()
    kw = dict(alpha0_deg=np.linspace(60, 80, 48), t0_mm=[1.8, 2.5], chunk_cases=2)
    P = np.linspace(80, 250, 6)
    expected = bendpam.sweep(base, P, **kw)
    lazy = bendpam.sweep(base, P, compute=False, **kw)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster, distributed.Client(cluster) as client:
        futures = client.compute(lazy)
        # wait until a worker holds a task, then kill that worker's process abruptly (its nanny
        # restarts it): the kill follows an event, not a delay
        t0 = time.monotonic()
        while not any(client.processing().values()):
            assert time.monotonic() - t0 < 60
            time.sleep(0.01)
        busy = next(addr for addr, tasks in client.processing().items() if tasks)
        assert not futures.done(), "the sweep finished before the worker could be killed"
        nanny = next(n for n in cluster.workers.values() if n.worker_address == busy)
        os.kill(nanny.process.process.pid, signal.SIGKILL)  # the worker process dies mid-task
        result = futures.result(timeout=300)
        assert sum(len(v) for v in client.processing().values()) == 0
    a, b = _bits(expected), _bits(result)
    for k in a:
        assert np.array_equal(a[k], b[k]), k


def test_kernel_handles_folds_and_deadband():
    base = presets.bc_pam("energy")
    out = evaluate_cases(base, "energy", {"alpha0_deg": np.array([36.57])}, [20.0, 32.0, 100.0, 150.0])
    k = out["free_curvature_per_mm"][0]
    assert k[0] == 0.0 and k[1] == 0.0  # deadband: straight
    assert k[2] < 0 and np.isnan(k[3])  # BC-PAM bends away; above the 134 kPa fold there is no equilibrium
    assert out["branch_end"][0] == 1
    assert 130 < out["max_pressure_kpa"][0] < 138


def test_cli_sweep(tmp_path, capsys):
    out = tmp_path / "s.nc"
    png = tmp_path / "s.png"
    code = main(["sweep", "--preset", "be-pam", "--param", "alpha0_deg=64:76:4", "--param", "t0_mm=2,3",
                 "--pressure-kpa", "100:200:3", "--out", str(out), "--plot", str(png), "--plot-y", "pressure_kpa"])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    ds = xr.open_dataset(out)
    assert dict(ds.sizes) == {"alpha0_deg": 4, "t0_mm": 2, "pressure_kpa": 3}
    assert ds.free_angle_deg.attrs["units"] == "deg"
    ds.close()
    assert png.read_bytes()[:4] == b"\x89PNG"
    for args, word in [(["--param", "alpha=1:2:3"], "cannot sweep"), (["--param", "alpha0_deg"], "NAME="),
                       (["--out", str(tmp_path / "x.txt")], ".nc"), (["--plot-var", "nope"], "nope")]:
        base_args = ["sweep", "--preset", "be-pam", "--pressure-kpa", "150"]
        if "--out" not in args:
            base_args += ["--out", str(tmp_path / "y.nc")]
        if "--param" not in args:
            base_args += ["--param", "alpha0_deg=65,70"]
        if args[0] == "--plot-var":
            base_args += ["--plot", str(tmp_path / "p.png")]
        code = main(base_args + args)
        err = capsys.readouterr().err
        assert code == 2 and word in err and err.count("\n") == 1, err


def test_sweep_plot_single_pressure_and_at(tmp_path, capsys):
    from bendpam.cli import main

    assert main(["sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:5", "--pressure-kpa", "150",
                 "--plot", str(tmp_path / "one.png")]) == 0
    assert (tmp_path / "one.png").stat().st_size > 1000
    assert main(["sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:5", "--param", "t0_mm=2,2.5",
                 "--pressure-kpa", "100:200:3", "--plot", str(tmp_path / "at.png"), "--at", "pressure_kpa=150"]) == 0
    capsys.readouterr()
    assert main(["sweep", "--preset", "be-pam", "--param", "alpha0_deg=60:80:5", "--pressure-kpa", "150",
                 "--plot", str(tmp_path / "x.png"), "--at", "nope=1"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nope" in err


def test_sweep_figure_fixes_the_requested_slice():
    import numpy as np

    import bendpam
    from bendpam.present.figures import sweep_figure

    ds = bendpam.sweep(bendpam.physics.presets.be_pam(), [100.0, 150.0, 200.0], alpha0_deg=np.linspace(60, 80, 4),
                       t0_mm=[2.0, 2.5])
    fig = sweep_figure(ds, at={"pressure_kpa": 151.0})
    assert "pressure_kpa = 150" in fig.axes[0].get_title()
