"""Real testing-machine exports (tests/data/real, see ATTRIBUTION.md) read as checked by hand.

Every expected number below was read off the raw text of the file (the raw line is quoted in
the comment next to it) and converted by hand to s, mm and N.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from bendpam.lab import (
    FORMATS,
    RawTest,
    ReadError,
    check_cycle_count,
    detect_dialect,
    format_inspection,
    inspect_file,
    read_test,
)

REAL = Path(__file__).parent / "data" / "real"

# name: format, encoding, delimiter, decimal, header line, n samples,
#       (time source, unit), (stroke source, unit), (force source, unit),
#       first (s, mm, N), last (s, mm, N), counter (source, max) or None
EXPECTED = {
    "matolab_Zugversuch_ETFE_Groesseneffekt7.TRA": (
        "testxpert", "cp1252", "\t", ".", 17, 18876,  # data on lines 19..18894
        ("Prüfzeit", "s"), ("Standardweg", "mm"), ("Standardkraft", "N"),
        # line 19:    0.02<TAB>6.8902e-005<TAB>0.218446<TAB>8.61275e-005<TAB>785.175
        (0.02, 6.8902e-5, 0.218446),
        # line 18894: 386.35<TAB>247.389<TAB>51.4614<TAB>309.236<TAB>1032.56
        (386.35, 247.389, 51.4614),
        None,
    ),
    "bluer_Bluehill2_ccyclic_Specimen_RawData_6.csv": (
        "bluehill", "utf-8", ",", ".", 4, 18011,  # data on lines 6..18016
        ("Time", "sec"), ("Extension", "mm"), ("Load", "N"),
        # line 6:     0.00000,-2.04726,-4.31900,22476,0
        (0.0, -2.04726, -4.319),
        # line 18016: 360.06000,-2.04555,0.28068,22412,2
        (360.06, -2.04555, 0.28068),
        ("Total Cycle Count", 2.0),
    ),
    "whiterabbit_BluehillUniversal_silicone30a_20251029_145648_1.csv": (
        "bluehill", "utf-8", ",", ".", 1, 4041,  # data on lines 3..4043, line 4044 empty
        ("Time", "s"), ("Displacement", "mm"), ("Force", "kN"),
        # line 3:    "","0.0000","-0.0001","0.0005","0.0028","0.0000","0.0000"   (kN -> N)
        (0.0, -0.0001, 0.5),
        # line 4043: "","80.0604","-0.0003","0.0006","-0.0268","0.0000","10.0000"
        (80.0604, -0.0003, 0.6),
        ("Total cycle count", 10.0),
    ),
    "whiterabbit_WaveMatrix_silicone10A_Test7.steps.tracking.csv": (
        "wavematrix", "utf-8-sig", ",", ".", 1, 1942,  # data on lines 2..1943
        ("Total Time (s)", "s"), ("Position (mm)", "mm"), ("Force (kN)", "kN"),
        # line 2:    0,0,1,1,1,0,0,0.174042576,-0.018536563,...
        (0.0, 0.174042576, -18.536563),
        # line 1943: 15.602,5.273,51,1,0,50,10,-0.109943043,-0.018464829,...
        (15.602, -0.109943043, -18.464829),
        ("Total Cycles", 51.0),
    ),
    "pmd_42CrMoS4_Instron8852_46NT71.csv": (
        "instron", "utf-8", "\t", ".", 24, 768,  # data on lines 26..793
        ("Time", "s"), ("Machine Displacement", "mm"), ("Force", "kN"),
        # line 26:  0<TAB>0.0007143817674338952<TAB>0.117967<TAB>0<TAB>...
        (0.0, 0.0, 117.967),
        # line 793: 156.64<TAB>3.757264381767434<TAB>16.3491<TAB>4.66341<TAB>...
        (156.64, 4.66341, 16349.1),
        None,
    ),
    "lebedigital_MTS793_MPT_DEU_ansi_cyclic_Emodul_BALosMV4.dat": (
        "mts793", "cp1252", "\t", ",", 14, 669,  # block 1: data on lines 16..684
        ("Laufzeit", "s"), ("Ch 1 Weg", "mm"), ("Ch 1 Kraft", "kN"),
        # line 16:  41893<TAB>33,549805<TAB>-1<TAB>-1,0524206<TAB>-0,063988566<TAB>...
        (33.549805, -0.063988566, -1052.4206),
        # line 684: 41893<TAB>367,5498<TAB>0<TAB>0,093188137<TAB>0,30308366<TAB>...
        (367.5498, 0.30308366, 93.188137),
        None,
    ),
}  # fmt: skip
SUMMARY = "whiterabbit_WaveMatrix_latexglove_Test6.steps.trends.csv"


def test_all_real_files_are_covered():
    # the original seven files (the corpus of issue 22 lives in dev/ and holdout/ with its truth.toml)
    names = {p.name for p in REAL.iterdir() if p.is_file() and p.suffix not in (".md", ".toml")}
    assert names == set(EXPECTED) | {SUMMARY}


@pytest.fixture(scope="module")
def raws() -> dict[str, RawTest]:
    return {name: read_test(REAL / name) for name in EXPECTED}


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_real_file_reads_as_checked_by_hand(raws, name):
    fmt, enc, delim, dec, header, n, t, s, f, first, last, counter = EXPECTED[name]
    raw = raws[name]
    assert raw.dialect == fmt == raw.format
    assert raw.encoding == enc
    assert raw.delimiter == delim
    assert raw.decimal == dec
    assert raw.header_line == header
    assert len(raw) == n
    for role, (source, unit) in zip(("time", "stroke", "force"), (t, s, f), strict=True):
        assert raw.channels[role]["source"] == source, role
        assert raw.channels[role]["unit"] == unit, role
        assert raw.channels[role]["why"]
    assert list(raw.data.columns) == ["time_s", "stroke_mm", "force_n"]
    assert np.isfinite(raw.data.to_numpy()).all()
    np.testing.assert_allclose(raw.data.iloc[0].to_numpy(), first, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(raw.data.iloc[-1].to_numpy(), last, rtol=1e-9, atol=1e-12)
    assert np.all(np.diff(raw.data["time_s"].to_numpy()) > 0)
    if counter is None:
        assert raw.cycle_counter is None and raw.cycle_counter_source is None
    else:
        assert raw.cycle_counter_source == counter[0]
        assert raw.cycle_counter is not None and raw.cycle_counter.shape == (n,)
        assert raw.cycle_counter.max() == counter[1]
    assert raw.pressure_kpa is None and raw.pressure_source is None
    assert detect_dialect(REAL / name) == fmt


def test_zwick_choice_and_metadata(raws):
    raw = raws["matolab_Zugversuch_ETFE_Groesseneffekt7.TRA"]
    # relative crosshead travel beats the absolute crosshead position 'Traverse abs.'
    why = raw.channels["stroke"]["why"]
    assert "Traverse abs." in why and "relative" in why and "absolute" in why
    assert raw.other_columns == ["Dehnung", "Traverse abs."]
    # "EinspannlÃ¤nge"<TAB>832.756<TAB>"mm"  (cp1252 'ä')
    assert raw.metadata["Einspannlänge"] == "832.756 mm"
    assert raw.metadata["Prüfgeschwindigkeit"] == "150 mm/min"
    assert raw.metadata["Datum"] == "20.02.2008"
    assert raw.source_units == {"time_s": "s", "stroke_mm": "mm", "force_n": "N"}


def test_instron_8852_prefers_machine_displacement(raws):
    raw = raws["pmd_42CrMoS4_Instron8852_46NT71.csv"]
    # 'Displacement' is strain x gauge length (an extensometer value); the machine's own
    # displacement is the crosshead stroke the fixture needs
    assert "Displacement" in raw.other_columns
    assert "'Displacement'" in raw.channels["stroke"]["why"]
    assert raw.metadata["Machine type"] == "INSTRON 8852TT"
    assert raw.metadata["Gauge length"] == "25 mm"
    assert raw.source_units["force_n"] == "kN"


def test_mts793_blocks_and_setpoint(raws):
    raw = raws["lebedigital_MTS793_MPT_DEU_ansi_cyclic_Emodul_BALosMV4.dat"]
    # the force setpoint 'Ch 1 Kraft Sollwert' is never the force
    assert "Ch 1 Kraft Sollwert" in raw.other_columns
    assert [b["line"] for b in raw.blocks] == [14, 687]
    assert [b["rows"] for b in raw.blocks] == [669, 2]
    assert [b["read"] for b in raw.blocks] == [True, False]
    assert any("2 data blocks" in w and "687" in w for w in raw.warnings)
    # Prüfer : <TAB>Kh  (cp1252 'ü'), Masse :<TAB>5428,5
    assert raw.metadata["Prüfer"] == "Kh"
    assert raw.metadata["Masse"] == "5428,5"
    # unnamed transducers (serial numbers, mm) are listed, not chosen
    assert "1944 B" in raw.channels["stroke"]["why"]


def test_wavematrix_prefers_position_over_digital_position(raws):
    raw = raws["whiterabbit_WaveMatrix_silicone10A_Test7.steps.tracking.csv"]
    assert "Digital Position (mm)" in raw.channels["stroke"]["why"]
    assert "Cycle Elapsed Time (s)" in raw.other_columns  # resets every cycle: not the time


def test_summary_file_is_refused_with_the_reason():
    with pytest.raises(ReadError) as info:
        read_test(REAL / SUMMARY)
    msg = str(info.value)
    assert "\n" not in msg and SUMMARY in msg
    assert info.value.line == 1
    assert "summary" in msg and "not a time series" in msg and "Force:Maximum (kN)" in msg
    got = inspect_file(REAL / SUMMARY)
    assert set(got) == {"file", "error"} and "summary" in got["error"]


def test_cycle_counter_check(raws):
    raw = raws["bluer_Bluehill2_ccyclic_Specimen_RawData_6.csv"]
    # Total Cycle Count goes 0 -> 2 in the file: two cycles completed
    assert check_cycle_count(raw, 2) is None
    msg = check_cycle_count(raw, 3)
    assert msg is not None and "'Total Cycle Count'" in msg and "2" in msg and "3" in msg
    assert "\n" not in msg
    assert check_cycle_count(raws["pmd_42CrMoS4_Instron8852_46NT71.csv"], 5) is None
    uni = raws["whiterabbit_BluehillUniversal_silicone30a_20251029_145648_1.csv"]
    assert check_cycle_count(uni, 10) is None


def test_columns_override_on_a_real_file():
    raw = read_test(REAL / "matolab_Zugversuch_ETFE_Groesseneffekt7.TRA",
                    columns={"stroke": "Traverse abs."})  # fmt: skip
    assert raw.channels["stroke"]["source"] == "Traverse abs."
    assert "columns option" in raw.channels["stroke"]["why"]
    # line 19: ...<TAB>785.175 ; line 18894: ...<TAB>1032.56
    assert raw.data["stroke_mm"].iloc[0] == pytest.approx(785.175)
    assert raw.data["stroke_mm"].iloc[-1] == pytest.approx(1032.56)
    same = read_test(REAL / "matolab_Zugversuch_ETFE_Groesseneffekt7.TRA",
                     columns="stroke=Traverse abs.")  # fmt: skip
    assert same.channels == raw.channels
    with pytest.raises(ReadError, match="'Nope' named in the columns option"):
        read_test(REAL / "matolab_Zugversuch_ETFE_Groesseneffekt7.TRA", columns={"force": "Nope"})


def _no_nan(obj) -> bool:
    if isinstance(obj, float):
        return math.isfinite(obj)
    if isinstance(obj, dict):
        return all(_no_nan(v) for v in obj.values())
    if isinstance(obj, list):
        return all(_no_nan(v) for v in obj)
    return True


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_inspect_file_shape(name):
    info = inspect_file(REAL / name)
    assert list(info) == [
        "file", "format", "encoding", "delimiter", "decimal", "header_line", "n_samples",
        "columns", "other_columns", "first", "last", "metadata", "pressure_kpa", "cycle_counter",
        "warnings", "header", "specimen", "block", "segments",
    ]  # fmt: skip
    assert set(info["columns"]) == {"time", "stroke", "force"}
    # issue 22: every candidate column with its score (a time made from a rate has none)
    assert all(set(c) == {"source", "unit", "candidates"} for c in info["columns"].values())
    for c in info["columns"].values():
        assert c["source"] is None or c["candidates"][0]["column"] == c["source"]
    assert set(info["first"]) == set(info["last"]) == {"time_s", "stroke_mm", "force_n"}
    assert info["format"] in FORMATS
    assert _no_nan(info)
    json.dumps(info, allow_nan=False)
    text = format_inspection(info)
    assert name in text and "samples" in text and len(text.splitlines()) >= 6
    n, s, first, counter = (EXPECTED[name][i] for i in (5, 7, 9, 11))
    assert info["n_samples"] == n
    assert info["columns"]["stroke"]["source"] == s[0]
    assert info["first"]["force_n"] == pytest.approx(first[2])
    assert (info["cycle_counter"] is None) == (counter is None)


def test_format_inspection_of_an_error():
    text = format_inspection({"file": "x.csv", "error": "x.csv:3: bad"})
    assert text.splitlines() == ["x.csv", "  error: x.csv:3: bad"]
