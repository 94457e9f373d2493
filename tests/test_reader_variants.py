"""Synthesised variants of real export layouts: languages, encodings, units, quirks, checks.

Each file keeps the layout of a real export family (see tests/data/real and the comments) with
invented names and numbers.
"""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from bendpam.errors import FileFormatError, InputError
from bendpam.lab import ReadError, inspect_file, read_test, read_tests

LBF = 4.4482216152605


def _series(n: int = 40) -> np.ndarray:
    """time (s), stroke (mm), force (N): a smooth triangle-ish cycle."""
    t = np.arange(n) * 0.5
    s = 5.0 * np.abs(np.sin(np.pi * t / t[-1]))
    f = 2.0 - 0.3 * s
    return np.column_stack([t, s, f])


def _rows(arr: np.ndarray, sep: str, decimal: str = ".", quote: bool = False,
          fmt: str = "{:.5f}", lead: str = "", trail: str = "") -> list[str]:  # fmt: skip
    out = []
    for row in arr:
        cells = [fmt.format(v) for v in row]
        if decimal == ",":
            cells = [c.replace(".", ",") for c in cells]
        if quote:
            cells = [f'"{c}"' for c in cells]
        out.append(lead + sep.join(cells) + trail)
    return out


def _write(path: Path, lines: list[str], encoding: str = "utf-8", nl: str = "\r\n") -> Path:
    path.write_bytes((nl.join(lines) + nl).encode(encoding))
    return path


def _check(raw, arr, sources, rtol=1e-6):
    assert [raw.channels[r]["source"] for r in ("time", "stroke", "force")] == list(sources)
    assert_allclose(raw.data.to_numpy(), arr, rtol=rtol, atol=1e-4)  # 4-5 printed decimals


# ------------------------------------------------------------------------------------------------
# languages and encodings
# ------------------------------------------------------------------------------------------------
def test_polish_bluehill_cp1250(tmp_path):
    arr = _series()
    lines = ["Nazwa próbki : BE-PAM-07", "Operator : Łukasz Żółć", "",
             "Czas;Przemieszczenie;Obciążenie", "(s);(mm);(N)"]  # fmt: skip
    lines += _rows(arr, ";", ",")
    raw = read_test(_write(tmp_path / "pl_200kPa.csv", lines, "cp1250"))
    assert raw.encoding == "cp1250"
    assert raw.decimal == "," and raw.delimiter == ";"
    assert raw.dialect == "bluehill"
    assert raw.metadata["Operator"] == "Łukasz Żółć"
    _check(raw, arr, ("Czas", "Przemieszczenie", "Obciążenie"))
    assert raw.pressure_kpa == 200


def test_polish_godzina_variant(tmp_path):
    arr = _series()
    lines = ["Godzina;Przemieszczenie;Obciążenie", "(s);(mm);(kN)"]
    lines += _rows(arr / [1, 1, 1000], ";", ",", fmt="{:.8f}")
    raw = read_test(_write(tmp_path / "pl.csv", lines, "cp1250"))
    _check(raw, arr, ("Godzina", "Przemieszczenie", "Obciążenie"))
    assert raw.source_units["force_n"] == "kN"


def test_chinese_gb18030(tmp_path):
    arr = _series()
    lines = ['"试样标签 : A1"', '"操作员 : 张三"', "", '"时间","位移","载荷"', '"(s)","(mm)","(kN)"']
    lines += _rows(arr / [1, 1, 1000], ",", quote=True, fmt="{:.8f}")
    raw = read_test(_write(tmp_path / "zh.csv", lines, "gb18030"))
    assert raw.encoding == "gb18030"
    assert raw.metadata["操作员"] == "张三"
    _check(raw, arr, ("时间", "位移", "载荷"))


def test_chinese_unquoted_utf8_with_cycle_counter(tmp_path):
    arr = _series(60)
    counter = np.floor(np.arange(60) / 20)
    lines = ["时间,位移,载荷,循环计数", "s,mm,N,"]
    lines += [f"{a:.3f},{b:.5f},{c:.5f},{int(k)}" for (a, b, c), k in zip(arr, counter, strict=True)]
    raw = read_test(_write(tmp_path / "zh.csv", lines))
    assert raw.cycle_counter_source == "循环计数"
    assert raw.cycle_counter is not None and raw.cycle_counter.max() == 2


def _trapezium(arr1, arr2) -> list[str]:
    # Shimadzu Trapezium text export: quoted cells, metadata, one block per specimen
    lines = ['"試験名","曲げ試験"', '"試験日","2024/03/14"', '"バッチ名","BE-PAM"', ""]
    for k, arr in enumerate((arr1, arr2), start=1):
        lines += [f'"試験片{k}"', '"時間","試験力","ストローク"', '"sec","N","mm"']
        lines += _rows(arr[:, [0, 2, 1]], ",", quote=True)
        lines.append("")
    return lines


def test_japanese_trapezium_shift_jis_two_specimens(tmp_path):
    # issue 22: two blocks with one header each whose time restarts are two tests (read_tests), not
    # "the first block read and the second listed"
    a1, a2 = _series(30), _series(25) * [1, 2, 1]
    path = _write(tmp_path / "jp.csv", _trapezium(a1, a2), "shift_jis")
    with pytest.raises(ReadError, match="holds 2 tests in separate blocks"):
        read_test(path)
    raw, raw2 = read_tests(path)
    assert raw.encoding == "shift_jis"
    assert raw.dialect == "trapezium"
    _check(raw, a1, ("時間", "ストローク", "試験力"))
    _check(raw2, a2, ("時間", "ストローク", "試験力"))
    assert (raw.block, raw2.block) == (1, 2)
    assert raw.metadata["試験名"] == "曲げ試験"
    assert len(raw.blocks) == 2 and raw.blocks[0]["read"] and raw.blocks[1]["read"]
    assert any("2 data blocks" in w for w in raw.warnings)


def test_italian_testsuite_decimal_comma(tmp_path):
    arr = _series()
    lines = ["Nome test:\tBE-PAM", "Pressione:\t0,2\tMPa", "",
             "_Time \t_Extension \t_Load ", "s\tmm\tkN"]  # fmt: skip
    lines += _rows(arr / [1, 1, 1000], "\t", ",", fmt="{:.8f}")
    raw = read_test(_write(tmp_path / "it.txt", lines, "cp1252"))
    assert raw.decimal == ","
    assert raw.dialect == "mts"
    _check(raw, arr, ("_Time", "_Extension", "_Load"))
    assert raw.pressure_kpa == pytest.approx(200) and raw.pressure_source == "metadata"


def test_french_cp1252(tmp_path):
    arr = _series()
    lines = ["Opérateur;Hélène", "Temps (s);Déplacement (mm);Force (N)"]
    lines += _rows(arr, ";", ",")
    raw = read_test(_write(tmp_path / "fr.csv", lines, "cp1252"))
    assert raw.encoding == "cp1252"
    assert raw.metadata["Opérateur"] == "Hélène"
    _check(raw, arr, ("Temps (s)", "Déplacement (mm)", "Force (N)"))


def test_spanish_utf8_bom(tmp_path):
    arr = _series()
    rows = _rows(arr / [1, 1, 1000], ",", fmt="{:.8f}")
    lines = ["Tiempo (s),Desplazamiento (mm),Fuerza (kN)", *rows]
    raw = read_test(_write(tmp_path / "es.csv", lines, "utf-8-sig"))
    assert raw.encoding == "utf-8-sig"
    _check(raw, arr, ("Tiempo (s)", "Desplazamiento (mm)", "Fuerza (kN)"))


def test_utf16_bluehill(tmp_path):
    arr = _series()
    lines = ['"Time","Extension","Load"', '"(s)","(mm)","(N)"', *_rows(arr, ",", quote=True)]
    raw = read_test(_write(tmp_path / "u16.csv", lines, "utf-16"))
    assert raw.encoding == "utf-16"
    _check(raw, arr, ("Time", "Extension", "Load"))


def test_german_in_units_and_exponents(tmp_path):
    arr = _series()
    lines = ["Zeit;Weg;Kraft", "in s;in mm;in kN"]
    lines += [f"{a:.3f};{b:.6e};{c / 1000:.6e}".replace(".", ",").replace("e-0", "e-00")
              for a, b, c in arr]  # fmt: skip
    raw = read_test(_write(tmp_path / "de.csv", lines, "cp1252"))
    assert raw.source_units == {"time_s": "s", "stroke_mm": "mm", "force_n": "kN"}
    _check(raw, arr, ("Zeit", "Weg", "Kraft"), rtol=1e-5)


def test_imperial_units(tmp_path):
    arr = _series()
    lines = ["Time (min),Crosshead (in),Load (lbf)"]
    lines += _rows(arr / [60, 25.4, LBF], ",", fmt="{:.10f}")
    raw = read_test(_write(tmp_path / "us.csv", lines))
    _check(raw, arr, ("Time (min)", "Crosshead (in)", "Load (lbf)"), rtol=1e-6)
    assert raw.source_units == {"time_s": "min", "stroke_mm": "in", "force_n": "lbf"}


def test_mts793_english_decimal_point(tmp_path):
    arr = _series()
    lines = ["MTS793|MPT|ENU|1|2|.|/|:|1|0|0|A", "",
             "Data Acquisition\t\t\t\t\t\tTime:\t10.0\tSec\t3/29/2016 1:54:32 PM",
             "Running Time\tAxial Displacement\tAxial Load\tAxial Command", "Sec\tmm\tkN\tkN"]  # fmt: skip
    lines += [f"{a:.4f}\t{b:.6f}\t{c / 1000:.8f}\t0" for a, b, c in arr]
    raw = read_test(_write(tmp_path / "mts.dat", lines))
    assert raw.dialect == "mts793" and raw.decimal == "." and raw.delimiter == "\t"
    _check(raw, arr, ("Running Time", "Axial Displacement", "Axial Load"))
    assert "Axial Command" in raw.other_columns


def test_damaged_text_still_reads(tmp_path):
    arr = _series()
    lines = ["Pr\ufffdfer;A. M\ufffdller", "Pr\ufffdfzeit;Standardweg;Standardkraft", "s;mm;N"]
    lines += _rows(arr, ";", ",")
    raw = read_test(_write(tmp_path / "damaged.txt", lines))
    _check(raw, arr, ("Pr\ufffdfzeit", "Standardweg", "Standardkraft"))
    assert any("U+FFFD" in w for w in raw.warnings)


def test_leading_blank_line_trailing_columns_and_index(tmp_path):
    arr = _series()
    lines = ["", "1;Time;Extension;Load;;", ";(s);(mm);(N);;"]
    lines += _rows(arr, ";", lead=";", trail=";;")
    raw = read_test(_write(tmp_path / "x.csv", lines))
    _check(raw, arr, ("Time", "Extension", "Load"))
    assert raw.header_line == 2


# ------------------------------------------------------------------------------------------------
# thousands separators, rates, refusals
# ------------------------------------------------------------------------------------------------
def test_thousands_separator_collision_is_refused(tmp_path):
    lines = ['"Time","Extension","Load"', '"(s)","(mm)","(N)"',
             '"0,10","0,500","12,5"', '"0,20","1,000","1,000,292"', '"0,30","1,500","12,7"']  # fmt: skip
    p = _write(tmp_path / "eu.csv", lines)
    with pytest.raises(ReadError) as info:
        read_test(p)
    assert info.value.line == 4
    msg = str(info.value)
    assert "'1,000,292'" in msg and "thousands separator" in msg and "decimal comma" in msg


def test_unambiguous_grouping_is_read(tmp_path):
    lines = ['"Time","Extension","Load"', '"(s)","(mm)","(N)"',
             '"0.10","0.500","1,012.5"', '"0.20","1.000","1,013.5"', '"0.30","1.500","1,014.5"']  # fmt: skip
    raw = read_test(_write(tmp_path / "us.csv", lines))
    assert_allclose(raw.data["force_n"], [1012.5, 1013.5, 1014.5])


def test_no_time_column_with_rate_in_metadata(tmp_path):
    arr = _series()
    lines = ["Sample rate: 2 Hz", "Extension (mm);Load (N)", *_rows(arr[:, 1:], ";")]
    raw = read_test(_write(tmp_path / "rate.csv", lines))
    assert raw.sample_rate_hz == 2.0
    assert raw.channels["time"]["source"] is None and "2 Hz" in raw.channels["time"]["why"]
    _check(raw, arr, (None, "Extension (mm)", "Load (N)"))
    info = inspect_file(tmp_path / "rate.csv")
    assert info["columns"]["time"] == {"source": None, "unit": "s", "candidates": []}


def test_no_time_column_with_rate_option_or_error(tmp_path):
    arr = _series()
    p = _write(tmp_path / "norate.csv", ["Extension (mm);Load (N)", *_rows(arr[:, 1:], ";")])
    plain = read_test(p)  # read, and said: the sample number stands for the time
    assert plain.channels["time"]["source"] is None and plain.source_units["time_s"] == "sample"
    np.testing.assert_array_equal(plain.data["time_s"].to_numpy(), np.arange(len(arr), dtype=float))
    np.testing.assert_allclose(plain.data[["stroke_mm", "force_n"]].to_numpy(), arr[:, 1:], atol=1e-5)
    assert any("no time column and no sampling rate" in w for w in plain.warnings)
    raw = read_test(p, rate_hz=2)
    _check(raw, arr, (None, "Extension (mm)", "Load (N)"))
    with pytest.raises(InputError, match="rate_hz"):
        read_test(p, rate_hz=-1)


@pytest.mark.parametrize(
    "lines, what",
    [
        (["Width (mm);Thickness (mm);Length (mm)", "20;2;100", "21;2;101", "20;2;99"], "Width"),
        (["Specimen;Fmax (N);E-Modul (MPa)", "1;12,5;1100", "2;12,9;1120", "3;12,2;1090"], "Fmax"),
    ],
)
def test_sidecars_and_results_tables_are_refused(tmp_path, lines, what):
    p = _write(tmp_path / "side.csv", lines)
    with pytest.raises(ReadError) as info:
        read_test(p)
    msg = str(info.value)
    assert "summary" in msg and what in msg and info.value.line == 1


def test_broken_zs2_is_refused(tmp_path):
    pytest.importorskip("zs2decode")  # native Zwick files are read with it (tests/test_zwick.py)
    p = tmp_path / "test.zs2"
    p.write_bytes(b"\x1f\x8b\x08\x00" + bytes(40))
    with pytest.raises(ReadError, match=r"native Zwick \.zs2 file with a broken gzip stream"):
        read_test(p)


# ------------------------------------------------------------------------------------------------
# values: spikes, time, gaps, pressures
# ------------------------------------------------------------------------------------------------
def _zwick_like(tmp_path, arr, name="z.txt", extra=None) -> Path:
    lines = ['"Probe"\t"3"', '"Prüfzeit"\t"Standardweg"\t"Standardkraft"', '"s"\t"mm"\t"N"']
    body = _rows(arr, "\t", ",", fmt="{:.4f}")
    if extra:
        for k, text in extra.items():
            body[k] = text
    return _write(tmp_path / name, lines + body, "cp1252")


def test_spike_refused_with_line_and_repaired(tmp_path):
    arr = _series()
    arr[:, 2] = 2.45 + 0.01 * np.sin(arr[:, 0])
    p = _zwick_like(tmp_path, arr, extra={10: "5,0000\t2,5000\t2,451502E9"})
    with pytest.raises(ReadError) as info:
        read_test(p)
    assert info.value.line == 14 and "spike" in str(info.value) and "Standardkraft" in str(info.value)
    raw = read_test(p, repair=True)
    assert len(raw) == len(arr) - 1
    assert raw.data["force_n"].max() < 3
    assert any("spike" in w and "14" in w for w in raw.warnings)


def test_time_backwards_refused_and_repaired(tmp_path):
    arr = _series()
    p = _zwick_like(tmp_path, arr, extra={20: "1,0000\t2,5000\t1,0000"})
    with pytest.raises(ReadError, match="time does not increase") as info:
        read_test(p)
    assert info.value.line == 24
    raw = read_test(p, repair=True)
    assert len(raw) == len(arr) - 1 and np.all(np.diff(raw.data["time_s"]) > 0)


def test_gap_read_and_reported(tmp_path):
    # issue 22: a pause in the sampling is what labs write; it is read, reported and splits the series
    arr = _series()
    arr[25:, 0] += 300.0
    p = _zwick_like(tmp_path, arr)
    for repair in (False, True):
        raw = read_test(p, repair=repair)
        assert len(raw) == len(arr) and raw.segments == [(0, 25), (25, len(arr))]
        assert any("gap" in w and "line 29" in w for w in raw.warnings)


def test_nonfinite_rows_dropped_with_repair(tmp_path):
    arr = _series()
    p = _zwick_like(tmp_path, arr, extra={5: "2,5000\t1,0000\tnan"})
    with pytest.raises(ReadError, match="non-finite"):
        read_test(p)
    raw = read_test(p, repair=True)
    assert len(raw) == len(arr) - 1 and any("line(s) 9" in w for w in raw.warnings)


@pytest.mark.parametrize("value", ["-50;kPa", "20000;kPa", "2e9;Pa"])
def test_absurd_pressure_in_header_is_refused(tmp_path, value):
    arr = _series()
    lines = [f"Druck;{value}", "Prüfzeit;Standardweg;Standardkraft", "s;mm;N"]
    p = _write(tmp_path / "p.txt", lines + _rows(arr, ";", ","), "cp1252")
    with pytest.raises(ReadError, match="out of range; expected 0 to 10 000 kPa") as info:
        read_test(p)
    assert info.value.line == 1


@pytest.mark.parametrize("name", ["be_-50kPa.csv", "be_20000kPa.csv"])
def test_absurd_pressure_in_filename_is_refused(tmp_path, name):
    arr = _series()
    p = _write(tmp_path / name, ["time_s,stroke_mm,force_n", *_rows(arr, ",")])
    with pytest.raises(ReadError, match="file name is out of range"):
        read_test(p)


def test_hyphen_is_no_minus_sign(tmp_path):
    arr = _series()
    p = _write(tmp_path / "BE-200kPa.csv", ["time_s,stroke_mm,force_n", *_rows(arr, ",")])
    assert read_test(p).pressure_kpa == 200


def test_pressure_option_range():
    with pytest.raises(InputError, match="out of range"):
        read_test("whatever.csv", pressure_kpa=-1)


# ------------------------------------------------------------------------------------------------
# workbooks
# ------------------------------------------------------------------------------------------------
def _xlsx(path: Path, rows: list[list[object]]) -> Path:
    """A minimal .xlsx (inline strings), enough for a reader."""

    def cell(ref: str, v: object) -> str:
        if isinstance(v, str):
            return f'<c r="{ref}" t="inlineStr"><is><t>{v}</t></is></c>'
        return f'<c r="{ref}"><v>{v!r}</v></c>'

    def col(i: int) -> str:
        return chr(ord("A") + i)

    body = "".join(
        f'<row r="{r + 1}">' + "".join(cell(f"{col(i)}{r + 1}", v) for i, v in enumerate(row))
        + "</row>"
        for r, row in enumerate(rows)
    )
    ns = "http://schemas.openxmlformats.org/spreadsheetml/2006/main"
    rel = "http://schemas.openxmlformats.org/officeDocument/2006/relationships"
    pkg = "http://schemas.openxmlformats.org/package/2006"
    office = "application/vnd.openxmlformats-officedocument.spreadsheetml"
    head = '<?xml version="1.0" encoding="UTF-8"?>'
    parts = {
        "[Content_Types].xml": (
            f'{head}<Types xmlns="{pkg}/content-types">'
            '<Default Extension="rels" ContentType="application/vnd.openxmlformats-package.relationships+xml"/>'
            '<Default Extension="xml" ContentType="application/xml"/>'
            f'<Override PartName="/xl/workbook.xml" ContentType="{office}.sheet.main+xml"/>'
            f'<Override PartName="/xl/worksheets/sheet1.xml" ContentType="{office}.worksheet+xml"/>'
            "</Types>"
        ),
        "_rels/.rels": (
            f'{head}<Relationships xmlns="{pkg}/relationships">'
            f'<Relationship Id="rId1" Type="{rel}/officeDocument" Target="xl/workbook.xml"/>'
            "</Relationships>"
        ),
        "xl/workbook.xml": (
            f'{head}<workbook xmlns="{ns}" xmlns:r="{rel}">'
            '<sheets><sheet name="Probe 1" sheetId="1" r:id="rId1"/></sheets></workbook>'
        ),
        "xl/_rels/workbook.xml.rels": (
            f'{head}<Relationships xmlns="{pkg}/relationships">'
            f'<Relationship Id="rId1" Type="{rel}/worksheet" Target="worksheets/sheet1.xml"/>'
            "</Relationships>"
        ),
        "xl/worksheets/sheet1.xml": (
            f'{head}<worksheet xmlns="{ns}"><sheetData>{body}</sheetData></worksheet>'
        ),
    }
    with zipfile.ZipFile(path, "w") as z:
        for name, text in parts.items():
            z.writestr(name, text)
    return path


def test_xlsx_workbook(tmp_path):
    pytest.importorskip("python_calamine")
    arr = _series()
    rows: list[list[object]] = [["Pressure", 150, "kPa"], [], ["Time", "Extension", "Load"],
                                ["s", "mm", "kN"]]  # fmt: skip
    rows += [[float(a), float(b), float(c) / 1000] for a, b, c in arr]
    raw = read_test(_xlsx(tmp_path / "book.xlsx", rows))
    assert raw.dialect == "excel" and raw.encoding == "xlsx"
    assert raw.pressure_kpa == 150 and raw.metadata["sheet"] == "Probe 1"
    _check(raw, arr, ("Time", "Extension", "Load"))


def test_xlsx_without_calamine_names_the_extra(tmp_path, monkeypatch):
    import builtins

    real_import = builtins.__import__

    def no_calamine(name, *args, **kwargs):
        if name == "python_calamine":
            raise ImportError(name)
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_calamine)
    p = tmp_path / "book.xlsx"
    p.write_bytes(b"PK\x03\x04" + bytes(60))
    with pytest.raises(FileFormatError) as info:
        read_test(p)
    msg = str(info.value)
    assert "\n" not in msg and "bendpam[excel]" in msg and "binary" in msg
