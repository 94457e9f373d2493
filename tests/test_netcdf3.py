"""bendpam's NetCDF-3 reader (:mod:`bendpam.infra.netcdf3`) against SciPy's and the files' own bytes.

Files are written by xarray's SciPy backend (what bendpam writes) in both NetCDF-3 formats, with
and without an unlimited (record) dimension, and read back by both readers: the same variables,
values, shapes and attributes.  A header is also built by hand from the format specification, so
the reader is checked against the raw bytes and not only against SciPy.
"""

import struct

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

from bendpam.errors import FileFormatError
from bendpam.infra.netcdf3 import read_netcdf3


def scipy_read(path):
    from scipy.io import netcdf_file

    with netcdf_file(path, "r", mmap=False) as f:
        values = {k: np.array(v.data) for k, v in f.variables.items()}
        attrs = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in f._attributes.items()}
    return values, attrs


def assert_same(path):
    values, attrs = read_netcdf3(path)
    ref_values, ref_attrs = scipy_read(path)
    assert list(values) == list(ref_values)
    for k, v in values.items():
        ref = ref_values[k]
        assert v.shape == ref.shape and v.dtype == ref.dtype.newbyteorder("="), k
        assert np.array_equal(v, ref, equal_nan=v.dtype.kind == "f"), k
    assert list(attrs) == list(ref_attrs)
    for k, a in attrs.items():
        same = np.array_equal(a, ref_attrs[k], equal_nan=np.asarray(a).dtype.kind == "f")
        assert type(a) is type(ref_attrs[k]) and same, k


@settings(max_examples=30, deadline=None)
@given(n_t=st.integers(0, 6), n_x=st.integers(1, 4), kinds=st.lists(st.sampled_from(["f8", "f4", "i4", "i2", "i1"]),
                                                                     min_size=1, max_size=4),
       fmt=st.sampled_from(["NETCDF3_CLASSIC", "NETCDF3_64BIT"]), unlimited=st.booleans(), seed=st.integers(0, 99))
def test_same_as_scipy(tmp_path_factory, n_t, n_x, kinds, fmt, unlimited, seed):
    rng = np.random.default_rng(seed)
    data = {f"v{i}": (("t", "x")[: 1 + i % 2], (rng.normal(size=(n_t, n_x)[: 1 + i % 2]) * 50).astype(k))
            for i, k in enumerate(kinds)}
    data["label"] = ("x", np.array(["a", "bc", "def", "g"][:n_x]))
    if n_t:
        data["v0"][1].flat[0] = np.nan if data["v0"][1].dtype.kind == "f" else data["v0"][1].flat[0]
    ds = xr.Dataset(data, attrs={"text": "kPa ° ok", "one": 2.5, "many": np.array([1, 2, 3], "i4")})
    path = tmp_path_factory.mktemp("nc") / "x.nc"
    ds.to_netcdf(path, engine="scipy", format=fmt, unlimited_dims=["t"] if unlimited else None,
                 encoding={f"v{i}": {"dtype": k} for i, k in enumerate(kinds)})
    assert_same(path)


def _name(s: bytes) -> bytes:
    return struct.pack(">I", len(s)) + s + b"\0" * (-len(s) % 4)


def test_a_header_built_by_hand():
    """CDF-1: one dimension 'p' = 3, a text attribute, one double variable at a given offset."""
    values = np.array([100.0, 150.0, np.nan])
    header = (b"CDF\x01" + struct.pack(">I", 0)
              + struct.pack(">II", 10, 1) + _name(b"p") + struct.pack(">I", 3)
              + struct.pack(">II", 12, 1) + _name(b"units") + struct.pack(">II", 2, 3) + b"kPa\0")
    var = _name(b"pressure_kpa") + struct.pack(">II", 1, 0) + struct.pack(">II", 0, 0) + struct.pack(">II", 6, 24)
    begin = len(header) + 8 + len(var) + 4
    blob = header + struct.pack(">II", 11, 1) + var + struct.pack(">I", begin) + values.astype(">f8").tobytes()
    import tempfile
    from pathlib import Path

    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "hand.nc"
        f.write_bytes(blob)
        got, attrs = read_netcdf3(f)
        assert attrs == {"units": "kPa"}
        assert got["pressure_kpa"].dtype == np.float64
        assert np.array_equal(got["pressure_kpa"], values, equal_nan=True)
        assert_same(f)


def test_bad_files_are_one_line_errors(tmp_path):
    good = tmp_path / "good.nc"
    xr.Dataset({"m": ("p", np.arange(50.0))}).to_netcdf(good, engine="scipy")
    blob = good.read_bytes()
    for i, bad in enumerate([b"", b"CDF", b"CDF\x05" + blob[4:], b"\x89HDF\r\n", blob[:30], blob[:-8]]):
        f = tmp_path / f"bad{i}.nc"
        f.write_bytes(bad)
        with pytest.raises(FileFormatError, match=f"^{f}: ") as e:
            read_netcdf3(f)
        assert "\n" not in str(e.value)


def test_processed_set_reads_without_scipy_io_the_same(tmp_path):
    """A processed set bendpam wrote comes back through this reader as it did through SciPy's."""
    import bendpam
    from bendpam.lab import RawTest
    from bendpam.lab.processing import load_processed, process_tests, write_processed
    from bendpam.lab.simulate import SimulationSettings, simulate_test

    be, cfg = bendpam.physics.presets.be_pam(), SimulationSettings(cycles=2, rate_hz=5.0, seed=3)
    from pathlib import Path

    raws = [RawTest(simulate_test(be, p, settings=cfg)[0], Path(f"be_{p:g}kPa.csv"), "csv", pressure_kpa=p)
            for p in (100.0, 180.0)]
    ps = process_tests(raws, keep_series=False)
    write_processed(ps, tmp_path, figure=False)
    assert_same(tmp_path / "curves.nc")
    back = load_processed(tmp_path)
    assert back.pressures_kpa.tolist() == [100.0, 180.0]
    for a, b in zip(back.results, ps.results, strict=True):
        assert np.array_equal(a.blocked_moment, b.blocked_moment, equal_nan=True)
