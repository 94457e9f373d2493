"""`bendpam inspect` and the channel options of `bendpam process` on real machine exports."""

import json
import shutil
from pathlib import Path

import pytest

from bendpam.cli import main

REAL = Path(__file__).parent / "data" / "real"
ZWICK = REAL / "matolab_Zugversuch_ETFE_Groesseneffekt7.TRA"
SUMMARY = REAL / "whiterabbit_WaveMatrix_latexglove_Test6.steps.trends.csv"
MTS = REAL / "lebedigital_MTS793_MPT_DEU_ansi_cyclic_Emodul_BALosMV4.dat"


def strict_json(text):
    def bad(name):
        raise ValueError(f"non-standard JSON constant {name}")

    return json.loads(text, parse_constant=bad)


def test_inspect_json_shape_and_values(capsys):
    assert main(["inspect", str(ZWICK), str(MTS), "--json"]) == 0
    infos = strict_json(capsys.readouterr().out)
    assert [Path(i["file"]).name for i in infos] == [ZWICK.name, MTS.name]
    keys = {"file", "format", "encoding", "delimiter", "decimal", "header_line", "n_samples", "columns",
            "other_columns", "first", "last", "metadata", "pressure_kpa", "cycle_counter", "warnings"}
    for info in infos:
        assert keys <= set(info)
        assert set(info["columns"]) == {"time", "stroke", "force"}
        assert set(info["first"]) == {"time_s", "stroke_mm", "force_n"}
    z, m = infos
    assert z["format"] == "testxpert" and z["columns"]["stroke"]["source"] == "Standardweg"
    assert z["n_samples"] == 18876
    assert m["format"] == "mts793" and m["columns"]["force"]["unit"] == "kN"
    assert any("data blocks" in w for w in m["warnings"])


def test_inspect_text_and_refused_summary(capsys):
    code = main(["inspect", str(ZWICK), str(SUMMARY)])
    out, err = capsys.readouterr()
    assert code == 2
    assert "Standardweg" in out and "stroke" in out
    assert err.count("\n") == 1 and "per-cycle" in err and SUMMARY.name in err


def test_inspect_json_error_entry(capsys):
    assert main(["inspect", str(SUMMARY), "--json"]) == 2
    (info,) = strict_json(capsys.readouterr().out)
    assert set(info) == {"file", "error"} and "time series" in info["error"]


def test_columns_override_is_used_by_inspect(capsys):
    assert main(["inspect", str(ZWICK), "--json", "--columns", "stroke=Traverse abs."]) in (0, 2)
    (info,) = strict_json(capsys.readouterr().out)
    if "error" not in info:
        assert info["columns"]["stroke"]["source"] == "Traverse abs."


@pytest.mark.parametrize("columns", ["stroke=NoSuchChannel", "speed=Standardweg", "stroke"])
def test_bad_columns_are_one_line_errors(capsys, tmp_path, columns):
    f = tmp_path / ZWICK.name
    shutil.copy(ZWICK, f)
    code = main(["process", str(f), "--pressure-kpa", "100", "--out", str(tmp_path / "out"), "--columns", columns])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("bendpam: error:") and err.count("\n") == 1
    assert not (tmp_path / "out").exists()
