"""Detection that generalises (issue 22): blocks, specimens side by side, header rows, channels by values.

Small files written here in the layouts labs use, numbers derived by hand.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bendpam.lab import ReadError, inspect_file, read_test, read_tests


def _write(path: Path, lines: list[str]) -> Path:
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_blocks_that_continue_one_test_are_concatenated(tmp_path):
    # an MTS MPT fatigue export: 3 blocks of 5 rows, each with a title and its own header; time continues
    lines = ["MTS793|MPT|ENU|1|2|\t|.|:|49|1|1|A"]
    for b in range(3):
        lines += [f"Data Acquisition {b + 1}", "Time\tDisplacement\tForce", "s\tmm\tN"]
        lines += [f"{0.5 * (5 * b + k):.1f}\t{0.01 * (5 * b + k):.2f}\t{2.0 * (5 * b + k):.1f}" for k in range(5)]
    raw = read_test(_write(tmp_path / "mpt.dat", lines))
    assert len(raw) == 15 and raw.block is None
    assert raw.data["time_s"].tolist() == [0.5 * i for i in range(15)]
    assert raw.data["force_n"].iat[-1] == 28.0  # 2 N x sample 14
    assert [b["rows"] for b in raw.blocks] == [5, 5, 5] and all(b["continues"] for b in raw.blocks)
    assert any("3 data blocks with the same columns" in w for w in raw.warnings)
    assert raw.segments == [(0, 15)]


def test_blocks_that_restart_time_are_separate_tests(tmp_path):
    lines = []
    for b in range(2):
        lines += ["Time,Stroke,Force", "s,mm,N"] + [f"{0.1 * k:.1f},{0.2 * k:.1f},{b + 1}.{k}" for k in range(6)]
    path = _write(tmp_path / "two.csv", lines)
    with pytest.raises(ReadError, match="holds 2 tests in separate blocks") as info:
        read_test(path)
    assert info.value.line == 9  # the second header
    first, second = read_tests(path)
    assert (first.block, second.block, len(first), len(second)) == (1, 2, 6, 6)
    assert second.data["force_n"].tolist() == [2.0, 2.1, 2.2, 2.3, 2.4, 2.5]
    assert second.data_lines == (11, 16)


def test_specimens_side_by_side_with_repeated_names_and_unequal_length(tmp_path):
    # Shimadzu-like: a row of specimen names, names repeated per group, units; specimen B is 2 rows shorter
    lines = ['"A",,,"B",,', "Time,Force,Stroke,Time,Force,Stroke", "sec,N,mm,sec,N,mm"]
    for k in range(8):
        b = f"{0.1 * k:.1f},{10 * k},{0.5 * k:.1f}" if k < 6 else ",,"
        lines.append(f"{0.1 * k:.1f},{5 * k},{0.25 * k:.2f},{b}")
    path = _write(tmp_path / "flex.csv", lines)
    with pytest.raises(ReadError, match="holds 2 specimens side by side"):
        read_test(path)
    a, b = read_tests(path)
    assert (a.specimen, b.specimen, len(a), len(b)) == ("A", "B", 8, 6)
    assert a.data["force_n"].iat[-1] == 35.0 and b.data["force_n"].iat[-1] == 50.0
    assert b.data["stroke_mm"].iat[-1] == 2.5 and b.channels["force"]["source"] == "Force"


def test_specimens_named_above_the_first_group_only(tmp_path):
    # Mecmesin-like: names and units above the first group, specimen names after the units row
    lines = ["Force,Distance,Time,,,", "N,mm,min,,,", "Sample 1,,,Sample 2,,", ",,,,,"]
    lines += [f"{k},{0.1 * k:.1f},{0.01 * k:.2f},{2 * k},{0.2 * k:.1f},{0.01 * k:.2f}" for k in range(5)]
    s1, s2 = read_tests(_write(tmp_path / "emperor.csv", lines))
    assert (s1.specimen, s2.specimen) == ("Sample 1", "Sample 2")
    assert s2.data["time_s"].iat[-1] == pytest.approx(2.4)  # 0.04 min
    assert s2.data["force_n"].tolist() == [0.0, 2.0, 4.0, 6.0, 8.0]


def test_header_above_rows_of_channel_metadata(tmp_path):
    # HBM catman: names, units, then rows of one cell per channel, empty rows, then data
    lines = ["File comment:\t\t", "Time  1 - default sample rate\tLoad\tExtenso", "s\tkN\tmm",
             "\t\t", "50.00 ms (20 Hz)\t50.00 ms (20 Hz)\t50.00 ms (20 Hz)",
             "Sensor:\tSensor: DC 10 V\tSensor: DC 10 V", "Zero: 0 s\tZero: 0 kN\tZero: 0 mm", "\t\t"]
    lines += [f"{0.05 * k:.2f}\t{0.001 * k:.3f}\t{0.002 * k:.3f}" for k in range(6)]
    raw = read_test(_write(tmp_path / "catman.txt", lines))
    assert raw.header_line == 2 and len(raw) == 6
    assert raw.data["force_n"].iat[-1] == pytest.approx(5.0)  # 0.005 kN
    assert [raw.channels[r]["source"] for r in ("time", "stroke", "force")] == [
        "Time  1 - default sample rate", "Extenso", "Load"]


def test_point_time_without_units_row(tmp_path):
    # Deben Microtest: quoted metadata, 'Point' holds the time, no units row, an end record
    lines = ['"Sample : Default"', '"Number of points : 4"', '"Point","Elongation","Force","Position","Code"']
    lines += [".1,.001,-.0009,0,2", ".2,.004,-.0012,.0004,0", ".3,.007,-.001,.0008,0", ".4,.009,-.0011,.0031,0",
              "0,0,0,0,1"]
    raw = read_test(_write(tmp_path / "d.MTR", lines))
    assert len(raw) == 4 and raw.channels["time"]["source"] == "Point"
    assert raw.channels["stroke"]["source"] == "Position" and raw.data["stroke_mm"].iat[-1] == 0.0031


def test_german_bluehill_names(tmp_path):
    lines = ["Probe : 3", "Zeit;Traversenweg;Standardkraft", "(s);(mm);(N)"]
    lines += [f"{k},{0.5 * k:.1f},{3 * k}".replace(",", ";") for k in range(5)]
    raw = read_test(_write(tmp_path / "de.csv", lines))
    assert [raw.channels[r]["source"] for r in ("time", "stroke", "force")] == ["Zeit", "Traversenweg",
                                                                               "Standardkraft"]


def test_machine_displacement_preferred_over_clip_gauge(tmp_path):
    lines = ["Zeit [s]\tClip-Gauge [mm]\tMaschine [mm]\tKraft [N]"]
    lines += [f"{k}\t{0.001 * k:.3f}\t{0.1 * k:.1f}\t{5 * k}" for k in range(6)]
    raw = read_test(_write(tmp_path / "hbm.txt", lines))
    assert raw.channels["stroke"]["source"] == "Maschine [mm]"


def test_dead_force_channel_is_never_chosen(tmp_path):
    # the load cell named first reads noise (+-0.2 N); the machine force reaches 373 N
    rng = np.random.default_rng(1)
    n = 200
    noise = np.round(0.2 * rng.uniform(-1, 1, n), 3)
    force = np.round(np.linspace(0, 373, n), 3)
    lines = ["Time (s)\tStroke (mm)\tLoad cell (N)\tForce machine (N)"]
    lines += [f"{0.1 * k:.1f}\t{0.01 * k:.2f}\t{noise[k]}\t{force[k]}" for k in range(n)]
    raw = read_test(_write(tmp_path / "dead.txt", lines))
    assert raw.channels["force"]["source"] == "Force machine (N)"
    assert raw.data["force_n"].iat[-1] == 373.0
    assert any("looks dead" in w for w in raw.warnings)


def test_inspect_reports_header_candidates(tmp_path):
    lines = ["Operator: A", "Time,Stroke,Force", "s,mm,N"] + [f"{k},{k},{k}" for k in range(4)]
    info = inspect_file(_write(tmp_path / "c.csv", lines))
    cands = info["header"]["candidates"]
    assert cands[0]["line"] == 2 and "units row at line 3" in cands[0]["reasons"]


def test_space_aligned_names_with_single_spaces(tmp_path):
    # MTS BasicTestWare: names hold single spaces and are separated by two or more; numbers right-aligned
    lines = ["Test: BE-1", "", "Ch 1 Displacement  Ch 1 Force  Time", "mm                 kN          sec"]
    lines += [f"{0.01 * k:>17.3f}  {0.002 * k:>10.4f}  {0.5 * k:>5.1f}" for k in range(6)]
    raw = read_test(_write(tmp_path / "btw.dat", lines))
    assert [raw.channels[r]["source"] for r in ("time", "stroke", "force")] == ["Time", "Ch 1 Displacement",
                                                                               "Ch 1 Force"]
    assert raw.delimiter == " " and len(raw) == 6
    assert raw.data["force_n"].iat[-1] == pytest.approx(10.0)  # 0.01 kN
    assert raw.data["time_s"].iat[-1] == 2.5


def test_a_numeric_metadata_row_between_names_and_data(tmp_path):
    # catman ASCII: a row of zeros among the channel-metadata rows is not a data block
    lines = ["Zeit  2 - Standardmessrate\tKraft Maschine\tWeg Maschine", "s\tN\tmm",
             "Sensor: -\tSensor: 1 kN\tSensor: 100 mm", "0\t0\t0", "Tarawert: 0 s\tTarawert: 0 N\tTarawert: 0 mm"]
    lines += [f"{0.01 * k:.2f}\t{1.5 * k:.1f}\t{0.02 * k:.2f}" for k in range(5)]
    raw = read_test(_write(tmp_path / "catman.asc", lines))
    assert raw.header_line == 1 and len(raw) == 5 and raw.data["force_n"].iat[-1] == 6.0


def test_a_time_named_with_its_sampling_rate_group_is_the_time(tmp_path):
    # catman ASCII names the time of a rate group 'Time DEVICE_1 (Sample rate 1) CH=1': the note on the sampling is
    # not a rate channel, so the time is read (20 ms apart), not made from the sample index (first seen on a real
    # export from a public repository, round 5 of the corpus)
    lines = ["HBM_CATMAN_DATAFILE_40", "", "CHANNELS: 3", "",
             "Time DEVICE_1 (Sample rate 1) CH=1\tLoad CH=2\tStroke CH=3", "s\tkN\tmm",
             "T0 =10.11.17 16:53:58\tT0 =10.11.17 16:53:58\tT0 =10.11.17 16:53:58", "dt =20 ms\tdt =20 ms\tdt =20 ms"]
    lines += [f"{0.02 * k:.2f}\t{0.5 * k:.1f}\t{0.1 * k:.1f}" for k in range(6)]
    raw = read_test(_write(tmp_path / "catman.asc", lines))
    assert raw.channels["time"]["source"] == "Time DEVICE_1 (Sample rate 1) CH=1"
    assert len(raw) == 6 and raw.data["time_s"].iat[-1] == pytest.approx(0.1)
    assert raw.data["force_n"].iat[-1] == pytest.approx(2500.0)  # 2.5 kN


def test_specimen_groups_separated_by_an_empty_column(tmp_path):
    lines = ['"C1",,,,"C2",,', '"Temps","Force","Course","","Temps","Force","Course"',
             '"sec","N","mm","","sec","N","mm"']
    lines += [f'"{0.1 * k:.1f}","{k}","{0.01 * k:.2f}","","{0.1 * k:.1f}","{3 * k}","{0.02 * k:.2f}"' for k in range(5)]
    c1, c2 = read_tests(_write(tmp_path / "ms.csv", lines))
    assert (c1.specimen, c2.specimen) == ("C1", "C2")
    assert c2.data["force_n"].tolist() == [0.0, 3.0, 6.0, 9.0, 12.0] and c2.data["stroke_mm"].iat[-1] == 0.08


def test_space_separated_names_without_inner_spaces(tmp_path):
    lines = ["Time Stroke Force", "0.0 0.00 1.0", "0.1 0.05 1.5", "0.2 0.10 2.0"]
    raw = read_test(_write(tmp_path / "ws.txt", lines))
    assert raw.data["force_n"].tolist() == [1.0, 1.5, 2.0]


def test_time_that_restarts_each_cycle_gives_way_to_one_that_runs_through(tmp_path):
    # 'Prüfzeit' (the better time name) restarts every 4 samples; 'Zeit' runs through
    lines = ["Prüfzeit (s)\tZeit (s)\tWeg (mm)\tKraft (N)"]
    lines += [f"{0.1 * (k % 4):.1f}\t{0.1 * k:.1f}\t{0.01 * k:.2f}\t{k}" for k in range(12)]
    raw = read_test(_write(tmp_path / "cyc.txt", lines))
    assert raw.channels["time"]["source"] == "Zeit (s)" and raw.segments == [(0, 12)]
    assert any("restarts or pauses" in w for w in raw.warnings)


def test_time_with_a_sample_out_of_order_gives_way_to_another_time(tmp_path):
    times = [0.0, 0.1, 0.2, 0.05, 0.4, 0.5, 0.6, 0.7]
    lines = ["Time (s)\tTest time (s)\tStroke (mm)\tForce (N)"]
    lines += [f"{t}\t{0.1 * k:.1f}\t{0.01 * k:.2f}\t{k}" for k, t in enumerate(times)]
    raw = read_test(_write(tmp_path / "ooo.txt", lines))
    assert raw.channels["time"]["source"] == "Test time (s)" and len(raw) == 8


def test_quiet_force_channel_gives_way_to_one_that_moves_100_times_more(tmp_path):
    # a smooth +-0.2 N drift on the load cell (not noise-like) while the machine force reaches 373 N
    n = 200
    quiet = np.round(0.2 * np.sin(np.linspace(0, 3, n)), 4)
    force = np.round(np.linspace(0, 373, n), 3)
    lines = ["Zeit [s]\tWeg Maschine [mm]\tWägezelle-200 N [N]\tKraft Maschine [N]"]
    lines += [f"{0.1 * k:.1f}\t{0.01 * k:.2f}\t{quiet[k]}\t{force[k]}" for k in range(n)]
    raw = read_test(_write(tmp_path / "catman.txt", lines))
    assert raw.channels["force"]["source"] == "Kraft Maschine [N]"
    assert any("looks dead" in w and "Wägezelle" in w for w in raw.warnings)


def test_names_written_over_two_rows(tmp_path):
    lines = ["Ch 1\t\tTime", "Displacement\tForce\t", "mm\tkN\ts"]
    lines += [f"{0.01 * k:.2f}\t{0.002 * k:.3f}\t{0.5 * k:.1f}" for k in range(6)]
    raw = read_test(_write(tmp_path / "two.txt", lines))
    assert [raw.channels[r]["source"] for r in ("time", "stroke", "force")] == ["Time", "Ch 1 Displacement",
                                                                               "Ch 1 Force"]
    assert raw.data["force_n"].iat[-1] == pytest.approx(10.0) and raw.data["time_s"].iat[-1] == 2.5


def test_one_test_per_values_sheet_of_a_workbook(tmp_path, monkeypatch):
    # testXpert workbooks hold a 'Values <specimen>' sheet per specimen; the sheets are given here
    # through the workbook reader (no workbook writer in the dependencies)
    import bendpam.lab.excel as excel

    def values(k: int) -> list[str]:
        return ["Test time\tStandard travel\tStandard force", "s\tmm\tN"] + [
            f"{0.1 * i:.1f}\t{0.01 * i:.2f}\t{k * i}" for i in range(5)]

    sheets = [excel.Sheet("Results", ["Specimen\tFmax", "\tN", "A\t12"]),
              excel.Sheet("Values A", values(1)), excel.Sheet("Values B", values(3))]
    monkeypatch.setattr(excel, "workbook_sheets", lambda path: sheets)
    path = tmp_path / "tx.xlsx"
    path.write_bytes(b"PK\x03\x04" + bytes(60))
    with pytest.raises(ReadError, match="holds 2 tests on the sheets 'Values A', 'Values B'"):
        read_test(path)
    a, b = read_tests(path)
    assert (a.specimen, b.specimen) == ("Values A", "Values B")
    assert b.data["force_n"].tolist() == [0.0, 3.0, 6.0, 9.0, 12.0]


def test_sheets_that_continue_one_test_are_that_test(tmp_path, monkeypatch):
    # TA Instruments TRIOS writes a sheet per step of the procedure (a ramp, a hold, a ramp...), time running on
    # from sheet to sheet: one test of its sheets' samples, each sheet a block (a sheet per specimen, whose time
    # starts again, stays a test of its own; the test above)
    import bendpam.lab.excel as excel

    def step(k: int, n: int = 4) -> list[str]:
        return ["Step time\tTime\tDisplacement\tForce", "s\ts\tmm\tN"] + [
            f"{0.5 * i:.1f}\t{10.0 * k + 0.5 * i:.1f}\t{0.1 * (k + i):.1f}\t{k + 0.25 * i:.2f}" for i in range(n)]

    sheets = [excel.Sheet("Details", ["Procedure\tramp, hold", "Operator\tX"]), excel.Sheet("Ramp - 1", step(0)),
              excel.Sheet("Hold - 2", step(1)), excel.Sheet("Ramp - 3", step(2, 3))]
    monkeypatch.setattr(excel, "workbook_sheets", lambda path: sheets)
    path = tmp_path / "trios.xlsx"
    path.write_bytes(b"PK\x03\x04" + bytes(60))
    tests = read_tests(path)
    assert len(tests) == 1 and tests[0].specimen is None
    raw = read_test(path)
    assert len(raw) == 11 and raw.data["time_s"].tolist()[3:6] == [1.5, 10.0, 10.5]
    assert [b["sheet"] for b in raw.blocks] == ["Ramp - 1", "Hold - 2", "Ramp - 3"]
    assert [b["start"] for b in raw.blocks] == [0, 4, 8] and raw.metadata["sheets"] == "Ramp - 1; Hold - 2; Ramp - 3"
    assert any("continue one test" in w for w in raw.warnings)
    assert raw.data["force_n"].iat[-1] == 2.5


def test_channels_found_by_their_units_when_no_name_is_known(tmp_path):
    lines = ["Kanal A (s);Kanal B (mm);Kanal C (kN)"]
    lines += [f"{k};{0.5 * k};{0.25 * k}".replace(".", ",") for k in range(5)]
    raw = read_test(_write(tmp_path / "units.csv", lines))
    assert [raw.channels[r]["source"] for r in ("time", "stroke", "force")] == ["Kanal A (s)", "Kanal B (mm)",
                                                                               "Kanal C (kN)"]
    assert raw.data["force_n"].iat[-1] == 1000.0 and "only column in kN" in raw.channels["force"]["why"]


def test_german_bluehill_extension_named_dehnung_in_mm(tmp_path):
    lines = ["Zeit;Dehnung;Standardkraft", "(s);(mm);(N)"] + [f"{k};{k},5;{3 * k}" for k in range(5)]
    raw = read_test(_write(tmp_path / "dehnung.csv", lines))
    assert raw.channels["stroke"]["source"] == "Dehnung" and raw.data["stroke_mm"].iat[-1] == 4.5


def test_strain_in_percent_is_not_a_stroke(tmp_path):
    lines = ["Zeit;Dehnung;Standardkraft", "(s);(%);(N)"] + [f"{k};{k},5;{3 * k}" for k in range(5)]
    with pytest.raises(ReadError, match="no stroke column"):
        read_test(_write(tmp_path / "pct.csv", lines))


def test_digits_grouped_by_spaces(tmp_path):
    # a French-locale spreadsheet export: '1 234,5' with a no-break space
    lines = ["Temps (s);Déplacement (mm);Force (N)"]
    lines += [f"{k},0;{k},25;{1000 + 250 * k:,.1f}".replace(",", "\u00a0").replace(".", ",").replace(
        "\u00a00;", ",0;").replace("\u00a025;", ",25;") for k in range(5)]
    raw = read_test(_write(tmp_path / "fr.csv", lines))
    assert raw.data["force_n"].tolist() == [1000.0, 1250.0, 1500.0, 1750.0, 2000.0]
    assert raw.data["stroke_mm"].iat[-1] == 4.25


def test_extensometer_removed_mid_test_gives_way_to_the_crosshead(tmp_path):
    # the chosen stroke ('Extension', first of two generic displacements) has empty cells once the
    # extensometer is removed (line 8 on); the other displacement channel runs through and is read
    lines = ["Time (s),Extension (mm),Deflection (mm),Load (N)"]
    lines += [f"{0.1 * k:.1f},{'' if k > 5 else f'{0.001 * k:.3f}'},{0.01 * k:.2f},{k}" for k in range(10)]
    raw = read_test(_write(tmp_path / "ext.csv", lines))
    assert raw.channels["stroke"]["source"] == "Deflection (mm)" and len(raw) == 10
    assert any("stroke column 'Extension (mm)' not used (line 8" in w for w in raw.warnings)


def test_a_stroke_stuck_at_saturation_gives_way_to_one_that_moves(tmp_path):
    # the clip gauge (chosen first of two generic displacements) saturates at 2.0 mm from sample 20 of 40
    lines = ["Time (s)\tExtension (mm)\tDisplacement (mm)\tForce (N)"]
    lines += [f"{0.1 * k:.1f}\t{min(0.1 * k, 2.0):.2f}\t{0.2 * k:.2f}\t{k}" for k in range(40)]
    raw = read_test(_write(tmp_path / "sat.txt", lines))
    assert raw.channels["stroke"]["source"] == "Displacement (mm)" and raw.data["stroke_mm"].iat[-1] == 7.8
    assert any("stuck" in w for w in raw.warnings)


def test_fixed_width_columns_with_blanks_in_names_and_a_column_without_unit(tmp_path):
    # a dilatometer/testing-machine ASCII export (TA DIL 805 style): right-aligned columns, a names
    # row whose names hold two blanks ('Phi  (D)'), and a units row with no unit over 'No.'
    lines = [
        r" C:\WinTA100\DIL805.PRO\Data\test_1.asc",
        "     No.          Time        DL     Force    Phi  (D)        Poti",
        "                     s        um         N                      mm",
        "      19      0.002099    -93.72      -0.7      0.0316     11.2011",
        "      20      0.002220    -95.12      -4.2      0.0023     11.2010",
        "      21      0.002323    -94.84      -2.8     -0.0108     11.2009",
    ]
    path = tmp_path / "dil_150kPa.asc"
    path.write_text("\r\n".join(lines) + "\r\n", encoding="latin-1")
    raw = read_test(path)
    assert [raw.channels[r]["source"] for r in ("time", "stroke", "force")] == ["Time", "DL", "Force"]
    # first row: 0.002099 s, -93.72 um = -0.09372 mm, -0.7 N; last: 0.002323 s, -0.09484 mm, -2.8 N
    np.testing.assert_allclose(raw.data.iloc[0].to_numpy(), [0.002099, -0.09372, -0.7])
    np.testing.assert_allclose(raw.data.iloc[-1].to_numpy(), [0.002323, -0.09484, -2.8])
