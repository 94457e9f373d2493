"""Native Zwick ``.zs2`` files (bendpam.lab.zwick): round trips through an independent encoder, refusals.

The files are built by ``tests/zs2_writer.py``, an encoder written from the published format
description; zs2decode (the reader's decoder) is also asked for its own XML dump of them, so the
encoder is checked against the reference decoder and not only against bendpam.
"""

from __future__ import annotations

import sys
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import zs2_writer as w
from bendpam.lab import inspect_file, read_test, read_tests
from bendpam.lab.read_error import ReadError
from bendpam.lab.zwick import read_zs2

zs2decode = pytest.importorskip("zs2decode")

NAMES = {1: "Prüfzeit", 2: "Standardkraft", 3: "Traversenweg absolut", 4: "Standardweg", 5: "Dehnung"}


def _write(tmp_path, data: bytes, name: str = "series_150kPa.zs2"):
    path = tmp_path / name
    path.write_bytes(data)
    return path


def _hand_series():
    t = np.array([0.0, 0.5, 1.0, 1.5, 2.0])
    travel_m = np.array([0.0, 0.00025, 0.0005, 0.00075, 0.001])  # 0 .. 1 mm
    force = np.array([0.0, 2.5, 5.0, 7.5, 10.0])
    a = w.specimen("Probe 1", [(1, t), (2, force), (3, travel_m + 0.2), (4, travel_m), (5, travel_m * 10)],
                   double=True)
    b = w.specimen("Probe 2", [(1, t), (2, force * 2), (4, travel_m * 3)], double=True)
    untested = w.specimen("Probe 3", [])
    return w.series(NAMES, [a, untested, b])


def test_reference_decoder_reads_the_encoder():
    """zs2decode's own XML dump of an encoded series has the paths its example script reads."""
    from zs2decode import parser, util

    stream = w.series(NAMES, [w.specimen("P1", [(1, np.arange(3.0)), (2, np.ones(3))])])
    import gzip

    chunks = parser.parse_chunks(parser.data_stream_to_chunks(bytearray(gzip.decompress(stream))))
    root = ET.fromstring(util.chunks_to_XML(chunks))
    chans = root.findall("./Body/batch/SeriesDef/TestTaskDefs/Elem0/ChannelManager/ChannelManager/")
    assert [c.find("./Name/Text").attrib["value"] for c in chans if c.tag.startswith("Elem")] == \
        [NAMES[k] for k in sorted(NAMES)]
    sample = root.find("./Body/batch/Series/SeriesElements/Elem0")
    block = sample.find("./SeriesElements/Elem0/RealTimeCapture/Trs/SingleGroupDataBlock")
    assert block.find("IndexTimeChannel").attrib["value"] == "0"
    arr = block.find("./DataChannels/Elem1/DataArray")
    assert arr.attrib["type"] == "EE04" and arr.attrib["value"] == "[1.0, 1.0, 1.0]"
    param = sample.find("./EvalContext/ParamContext/ParameterListe/Elem0")
    assert param.find("ID").attrib["value"] == str(w.SPECIMEN_NAME_ID)
    assert "P1" in param.find("QS_TextPar").attrib["value"]


def test_series_reads_one_test_per_tested_specimen(tmp_path):
    path = _write(tmp_path, _hand_series())
    tests = read_tests(path)
    assert [t.specimen for t in tests] == ["Probe 1", "Probe 2"]  # Probe 3 has no data
    first, second = tests
    assert first.dialect == "zs2" and first.pressure_kpa == 150.0
    assert first.source_units == {"time_s": "s", "stroke_mm": "m", "force_n": "N"}
    # hand-derived: travel 0.00025 m per step is 0.25 mm; the relative travel, not the absolute one
    np.testing.assert_allclose(first.data["stroke_mm"], [0.0, 0.25, 0.5, 0.75, 1.0], rtol=1e-12)
    np.testing.assert_array_equal(first.data["time_s"], [0.0, 0.5, 1.0, 1.5, 2.0])
    np.testing.assert_array_equal(first.data["force_n"], [0.0, 2.5, 5.0, 7.5, 10.0])
    np.testing.assert_allclose(second.data["stroke_mm"], [0.0, 0.75, 1.5, 2.25, 3.0], rtol=1e-12)
    np.testing.assert_array_equal(second.data["force_n"], [0.0, 5.0, 10.0, 15.0, 20.0])
    assert "Probe 3" in first.metadata["Note"]
    assert first.metadata["Specimen"] == "Probe 1"


def test_inspect_names_format_channels_and_specimens(tmp_path):
    info = inspect_file(_write(tmp_path, _hand_series()))
    assert info["format"] == "zs2"
    assert info["columns"]["stroke"]["source"] == "Standardweg"
    assert info["columns"]["force"]["source"] == "Standardkraft"
    assert info["columns"]["time"]["source"] == "Prüfzeit"
    assert [t["specimen"] for t in info["tests"]] == ["Probe 1", "Probe 2"]
    assert info["tests"][1]["last"] == {"time_s": 2.0, "stroke_mm": pytest.approx(3.0), "force_n": 20.0}


def test_read_test_refuses_a_series_of_several_specimens(tmp_path):
    path = _write(tmp_path, _hand_series())
    with pytest.raises(ReadError, match="holds 2 tests on the specimens of the series 'Probe 1', 'Probe 2'"):
        read_test(path)


def test_unnamed_specimens_and_time_by_index(tmp_path):
    """No name parameter: 'specimen k'; the IndexTimeChannel marks the time even under an unknown name."""
    t = np.linspace(0.0, 1.0, 4)
    spec = w.specimen(None, [(7, np.array([0.0, 1.0, 2.0, 3.0])), (2, t * 3), (4, t / 1000)], time_index=1)
    names = {2: "Zeitachse X", 4: "Standardweg", 7: "Standardkraft"}
    (test,) = read_tests(_write(tmp_path, w.series(names, [spec]), "unnamed.zp2"))
    assert test.specimen == "specimen 1"
    np.testing.assert_allclose(test.data["time_s"], t * 3)
    np.testing.assert_array_equal(test.data["force_n"], [0.0, 1.0, 2.0, 3.0])


@settings(max_examples=15, deadline=None)
@given(
    n=st.integers(min_value=20, max_value=60),
    double=st.booleans(),
    seed=st.integers(min_value=0, max_value=2**31 - 1),
    n_spec=st.integers(min_value=1, max_value=3),
)
def test_round_trip_values_exact(tmp_path_factory, n, double, seed, n_spec):
    rng = np.random.default_rng(seed)
    specs, expected = [], []
    for k in range(n_spec):
        t = np.cumsum(rng.uniform(0.05, 0.1, n))
        phase = 2 * np.pi * t / (t[-1] * rng.uniform(2.0, 4.0))  # smooth signals: nothing for the reader to repair
        travel = rng.uniform(1e-4, 1e-2) * np.sin(phase) + rng.uniform(-0.01, 0.01)
        force = rng.uniform(1.0, 500.0) * np.cos(phase) + rng.uniform(-50.0, 50.0)
        specs.append(w.specimen(f"S{k}", [(1, t), (4, travel), (2, force)], double=double))
        expected.append((t, travel, force))
    path = _write(tmp_path_factory.mktemp("zs2"), w.series(NAMES, specs), "rt.zs2")
    tests = read_tests(path)
    assert [t.specimen for t in tests] == [f"S{k}" for k in range(n_spec)]
    for test, (t, travel, force) in zip(tests, expected):
        dtype = np.float64 if double else np.float32
        stored = [np.asarray(x, dtype=dtype) for x in (t, travel, force)]
        assert len(test) == n
        # every value reads back to the stored one: a single float to the same single, a double exactly
        np.testing.assert_array_equal(test.data["time_s"].to_numpy().astype(dtype), stored[0])
        np.testing.assert_array_equal(test.data["force_n"].to_numpy().astype(dtype), stored[2])
        np.testing.assert_allclose(test.data["stroke_mm"], stored[1].astype(np.float64) * 1000.0,
                                   rtol=1e-12 if double else 1e-8, atol=0)


# ------------------------------------------------------------------------------------------------
# refusals: one line naming the file and what was missing
# ------------------------------------------------------------------------------------------------
def _one_line(exc: ReadError, path) -> str:
    msg = str(exc)
    assert "\n" not in msg and path.name in msg
    return msg


def test_refuses_a_file_without_channel_list(tmp_path):
    spec = w.specimen("P", [(1, np.arange(3.0)), (2, np.ones(3))])
    path = _write(tmp_path, w.series(NAMES, [spec], with_channels=False))
    with pytest.raises(ReadError) as info:
        read_tests(path)
    assert "ChannelManager" in _one_line(info.value, path)


def test_refuses_a_series_without_measured_data(tmp_path):
    path = _write(tmp_path, w.series(NAMES, [w.specimen("P", []), w.specimen("Q", [])]))
    with pytest.raises(ReadError) as info:
        read_tests(path)
    assert "no measured data" in _one_line(info.value, path) and "2 specimen" in str(info.value)


def test_refuses_channels_of_unequal_length(tmp_path):
    spec = w.specimen("P", [(1, np.arange(4.0)), (2, np.ones(3))])
    path = _write(tmp_path, w.series(NAMES, [spec]))
    with pytest.raises(ReadError) as info:
        read_zs2(path)
    assert "unequal lengths" in _one_line(info.value, path) and "'P'" in str(info.value)


def test_refuses_gzip_that_is_not_zs2_and_broken_gzip(tmp_path):
    import gzip

    path = _write(tmp_path, gzip.compress(b"time;force\n0;1\n"), "data.csv.gz")
    with pytest.raises(ReadError) as info:
        read_tests(path)
    assert "not a native Zwick" in _one_line(info.value, path)
    broken = _write(tmp_path, b"\x1f\x8b\x08\x00" + bytes(40), "broken.zs2")
    with pytest.raises(ReadError) as info:
        read_tests(broken)
    assert "broken gzip stream" in _one_line(info.value, broken)


def test_refuses_in_one_line_without_zs2decode(tmp_path, monkeypatch):
    path = _write(tmp_path, _hand_series(), "other.zs2")
    monkeypatch.setitem(sys.modules, "zs2decode", None)
    with pytest.raises(ReadError) as info:
        read_tests(path)
    assert "zs2decode" in _one_line(info.value, path) and "bendpam[zwick]" in str(info.value)


def test_process_folder_reads_a_series_as_replicates(tmp_path):
    """A simulated cyclic test stored as a .zs2 series (two specimens, travel in m, single floats) processes to
    the blocked moment its own numbers give, each specimen a replicate at the file's pressure."""
    import bendpam
    from bendpam.lab.batch import process_files
    from bendpam.lab.simulate import SimulationSettings, simulate_test

    data, truth = simulate_test(bendpam.physics.presets.be_pam(), 150.0,
                                settings=SimulationSettings(cycles=2, rate_hz=5.0, seed=1))
    t, s, f = (data[c].to_numpy() for c in ("time_s", "stroke_mm", "force_n"))
    specs = [w.specimen(name, [(1, t), (4, s / 1000.0), (2, f)]) for name in ("A", "B")]
    _write(tmp_path, w.series({1: "Prüfzeit", 2: "Standardkraft", 4: "Standardweg"}, specs), "be_150kPa.zs2")
    processed = process_files([tmp_path / "be_150kPa.zs2"], keep_series=False)
    assert processed.files[0]["status"] == "read" and processed.files[0]["tests"] == 2
    assert [(r.specimen, r.replicate, r.pressure_kpa) for r in processed.results] == [("A", 1, 150.0), ("B", 2, 150.0)]
    for r in processed.results:
        assert r.blocked_moment[0] == pytest.approx(truth["blocked_moment_nmm"], rel=0.02)
