"""Sweeps as NetCDF, CSV or Parquet (issue 16), and their progress reports.

The tidy tables hold one row per (case, pressure) with unit-named columns and round-trip to the
NetCDF values exactly; ``bendpam sweep`` picks the format from ``--out``'s suffix or ``--format``
and reports progress on stderr (silenced by ``--quiet``).
"""

import sys

import numpy as np
import pandas as pd
import pytest
import xarray as xr

import bendpam
from bendpam import presets
from bendpam.cli import main
from bendpam.errors import InputError
from bendpam.sweeps import sweep, sweep_format, to_table, write_sweep

ARGS = ["sweep", "--preset", "be-pam", "--param", "alpha0_deg=66,70,74", "--param", "t0_mm=2,2.5",
        "--pressure-kpa", "100:250:4"]


@pytest.fixture(scope="module")
def ds():
    # 150 kPa is above the BC-PAM's fold: NaN outputs must survive the round trip too
    return sweep(presets.get("bc-pam"), [40.0, 100.0, 150.0], alpha0_deg=[34.0, 36.57], t0_mm=[2.2, 2.6, 3.0])


def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def test_table_is_tidy_with_unit_named_columns(ds):
    t = to_table(ds)
    assert len(t) == 2 * 3 * 3
    assert list(t.columns[:3]) == ["alpha0_deg", "t0_mm", "pressure_kpa"]
    assert set(t.columns[3:]) == set(ds.data_vars)
    # one row per (case, pressure): the grid in C order with pressures innermost
    assert t["pressure_kpa"].tolist()[:3] == [40.0, 100.0, 150.0]
    assert t[["alpha0_deg", "t0_mm", "pressure_kpa"]].drop_duplicates().shape[0] == len(t)
    row = t[(t.alpha0_deg == 36.57) & (t.t0_mm == 2.6) & (t.pressure_kpa == 100.0)].iloc[0]
    point = ds.sel(alpha0_deg=36.57, t0_mm=2.6, pressure_kpa=100.0)
    for name in ds.data_vars:
        assert row[name] == pytest.approx(float(point[name]), nan_ok=True)
    # per-case outputs repeat on every pressure of their case
    per_case = t.groupby(["alpha0_deg", "t0_mm"])["max_pressure_kpa"].nunique()
    assert (per_case == 1).all()
    assert t.attrs["units"]["blocked_moment_nmm"] == "N*mm" and t.attrs["units"]["pressure_kpa"] == "kPa"
    assert t["branch_end"].dtype == np.int8


def test_table_without_swept_parameters():
    d = sweep(presets.get("be-pam"), [100.0, 200.0])
    t = to_table(d)
    assert list(t.columns[:1]) == ["pressure_kpa"] and len(t) == 2
    np.testing.assert_array_equal(t["blocked_moment_nmm"], d["blocked_moment_nmm"].values)


def frame_from_nc(path):
    with xr.open_dataset(path) as d:
        return to_table(d.load())


@pytest.mark.parametrize("fmt", ["csv", "parquet"])
def test_round_trip_equals_netcdf(ds, tmp_path, fmt):
    if fmt == "parquet":
        pytest.importorskip("pyarrow")
    nc = write_sweep(ds, tmp_path / "s.nc")
    path = write_sweep(ds, tmp_path / f"s.{fmt}")
    back = pd.read_csv(path) if fmt == "csv" else pd.read_parquet(path)
    ref = frame_from_nc(nc)
    assert list(back.columns) == list(ref.columns)
    for col in ref.columns:
        a, b = ref[col].to_numpy(dtype=float), back[col].to_numpy(dtype=float)
        np.testing.assert_array_equal(a, b)  # bit for bit, NaN and inf included
    assert np.isnan(back["free_curvature_per_mm"]).any()  # the NaN cases were there to round-trip


def test_parquet_keeps_types_and_metadata(ds, tmp_path):
    pq = pytest.importorskip("pyarrow.parquet")
    import json

    path = write_sweep(ds, tmp_path / "s.parquet")
    meta = json.loads(pq.read_schema(path).metadata[b"bendpam"])
    assert meta["units"]["frame_stress_mpa"] == "MPa" and meta["model"] == "energy"
    assert "alpha0_deg" in meta["base_actuator"]
    assert pd.read_parquet(path)["branch_end"].dtype == np.int8


def test_sweep_format_from_suffix_or_argument():
    assert sweep_format("a.NC") == "nc" and sweep_format("a.pq") == "parquet"
    assert sweep_format("a", "csv") == "csv"
    with pytest.raises(InputError, match="format"):
        sweep_format("a.csv", "parquet")
    with pytest.raises(InputError, match=r"\.txt"):
        sweep_format("a.txt")
    with pytest.raises(InputError, match="xlsx"):
        sweep_format("a", "xlsx")


def test_missing_pyarrow_is_one_line_naming_the_extra(ds, tmp_path, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "pyarrow", None)  # import pyarrow now raises ImportError
    with pytest.raises(InputError, match=r'pip install "bendpam\[parquet\]"'):
        write_sweep(ds, tmp_path / "s.parquet")
    code, out, err = run(capsys, *ARGS, "--out", tmp_path / "s.parquet")
    assert code == 2 and err.count("\n") == 1 and 'pip install "bendpam[parquet]"' in err
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------------------------------------
# the command
# ------------------------------------------------------------------------------------------------
def test_cli_writes_every_format_with_the_same_values(tmp_path, capsys):
    for name in ("s.nc", "s.csv", "s.parquet", "table"):
        extra = ["--table-format", "csv"] if name == "table" else []
        code, out, err = run(capsys, *ARGS, "--out", tmp_path / name, *extra, "-q")
        assert code == 0, err
        assert err == ""  # --quiet
    ref = frame_from_nc(tmp_path / "s.nc")
    assert "24 rows" in out
    for back in (pd.read_csv(tmp_path / "s.csv"), pd.read_parquet(tmp_path / "s.parquet"),
                 pd.read_csv(tmp_path / "table")):
        assert list(back.columns) == list(ref.columns)
        np.testing.assert_array_equal(back.to_numpy(dtype=float), ref.to_numpy(dtype=float))


@pytest.mark.parametrize("extra,word", [
    (["--out", "s.csv", "--table-format", "parquet"], "--table-format"),  # suffix and --table-format disagree
    (["--out", "s.xlsx"], ".xlsx"),                          # not a sweep format
    (["--out", "s.png"], ".png"),                            # a figure is --plot
    (["--out", "s.nc", "--format", "pdf"], "--plot"),         # a figure format without --plot
    (["--plot", "p.png", "--table-format", "csv"], "--out"),  # a data format without --out
    (["--out", "s"], "--table-format"),                      # no format at all
])
def test_cli_format_errors_exit_2(tmp_path, capsys, monkeypatch, extra, word):
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, *ARGS, *extra)
    assert code == 2 and word in err and err.count("\n") == 1, err
    assert list(tmp_path.iterdir()) == []


def test_cli_old_format_spelling_still_works_with_a_note(tmp_path, capsys):
    code, out, err = run(capsys, *ARGS, "--out", tmp_path / "table", "--format", "csv", "-q")
    assert code == 0, err
    assert err.splitlines() == ["bendpam: warning: sweep --format csv is deprecated (--format is the figure format); "
                                "use --table-format csv"]
    assert len(pd.read_csv(tmp_path / "table")) == 24


def test_cli_progress_lines_on_stderr_unless_quiet(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("BENDPAM_PROGRESS_INTERVAL_S", "0")  # a line per block
    args = [*ARGS, "--chunk-cases", "2", "--out", tmp_path / "s.nc"]
    code, out, err = run(capsys, *args)
    assert code == 0
    lines = err.splitlines()
    assert lines[0].startswith("bendpam: sweep: 2/6 (33 %)")
    assert lines[-1].startswith("bendpam: sweep: 6/6 (100 %), finished in")
    assert "wrote" in out and "bendpam:" not in out  # progress only on stderr
    for flag in ("--quiet", "-q", "--no-progress"):
        code, out, err = run(capsys, *args, flag)
        assert code == 0 and err == ""


def test_short_sweep_is_silent_by_default(tmp_path, capsys, monkeypatch):
    monkeypatch.delenv("BENDPAM_PROGRESS_INTERVAL_S", raising=False)
    code, out, err = run(capsys, *ARGS, "--out", tmp_path / "s.nc")
    assert code == 0 and err == ""  # done within the first 5 s: nothing to report


# ------------------------------------------------------------------------------------------------
# the progress callback of the library
# ------------------------------------------------------------------------------------------------
def counted_sweep(**kw):
    counts = []
    d = bendpam.sweep(presets.get("be-pam"), [100.0, 200.0], alpha0_deg=[64, 66, 68, 70, 72], t0_mm=[2.0, 2.5],
                      chunk_cases=3, progress=counts.append, **kw)
    return d, counts


def test_progress_callback_counts_every_case_once():
    d, counts = counted_sweep()
    # blocks of at most 3 cases: the t0_mm dimension (2) whole, alpha0_deg one value at a time
    assert sorted(counts) == [2] * 5


def test_progress_callback_without_dask(monkeypatch):
    ref, _ = counted_sweep()
    monkeypatch.setitem(sys.modules, "dask.array", None)  # the loop path
    d, counts = counted_sweep()
    assert sorted(counts) == [2] * 5
    xr.testing.assert_identical(d, ref)


def test_progress_true_reports_on_stderr(capsys, monkeypatch):
    monkeypatch.setenv("BENDPAM_PROGRESS_INTERVAL_S", "0")
    bendpam.sweep(presets.get("be-pam"), [150.0], alpha0_deg=[66, 70], chunk_cases=1, progress=True)
    err = capsys.readouterr().err
    assert err.splitlines()[-1].startswith("bendpam: sweep: 2/2 (100 %), finished")
