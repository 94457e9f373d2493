"""Channels sampled at different rates in one table, and end records after the samples (issue 22 follow-up).

Small synthetic variants of what real exports write (an HBM catman sheet with a slow rate group,
blank cells between a slower channel's values, a column that ends first, end records with text or
with fewer numbers, a metadata count of the samples).  The channels are linear in time, so the
interpolated values are known exactly by hand.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from bendpam.lab.declared import read_declared
from bendpam.lab.read_error import ReadError
from bendpam.lab.readers import read_test

N = 40  # rows of the fast clock, 0.05 s apart


def _write(tmp_path, name: str, text: str):
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _force(t):
    return 10.0 + 100.0 * t  # N, linear in time: interpolation is exact


def _stroke(t):
    return 2.0 * t  # mm


def _two_clocks(n_slow: int) -> str:
    """A catman-like table: a fast clock (20 Hz) with the stroke, a slow clock (10 Hz) with the load."""
    rows = ["Time  1 - default sample rate,Time  1 - slow sample rate,Load,Extenso", "s,s,N,mm"]
    for i in range(N):
        t = 0.05 * i
        slow = f"{0.1 * i:.6g},{_force(0.1 * i):.6g}" if i < n_slow else ","
        rows.append(f"{t:.6g},{slow},{_stroke(t):.6g}")
    return "\n".join(rows) + "\n"


def _every(m: float, n: int = N, phase: int = 0, tail: int = 0) -> str:
    """Force written on the rows round(phase + k m) only (a slower channel on the same clock)."""
    have = {round(phase + k * m) for k in range(n) if round(phase + k * m) < n - tail}
    rows = ["time_s,stroke_mm,force_n"]
    for i in range(n):
        t = 0.05 * i
        rows.append(f"{t:.6g},{_stroke(t):.6g}," + (f"{_force(t):.6g}" if i in have else ""))
    return "\n".join(rows) + "\n"


# ---- a column on its own clock (catman rate groups) ------------------------------------------------------------
def test_a_slow_rate_group_is_interpolated_to_the_fast_clock(tmp_path):
    raw = read_test(_write(tmp_path, "catman.csv", _two_clocks(N // 2)))
    t = 0.05 * np.arange(N)
    assert len(raw.data) == N  # the slow clock ends at 1.9 s; the last fast row (1.95 s) is within its period
    assert_allclose(raw.data["time_s"], t)
    assert_allclose(raw.data["force_n"], _force(np.minimum(t, 1.9)), rtol=1e-9)  # its last value holds
    assert_allclose(raw.data["stroke_mm"], _stroke(t))
    (note,) = [w for w in raw.warnings if "own clock" in w]
    assert "'Load'" in note and "'Time  1 - slow sample rate'" in note and "every 0.1 s" in note
    assert "line 42 within one period" in note and "further out dropped" not in note


def test_rows_further_than_a_period_past_the_slow_clock_are_dropped(tmp_path):
    raw = read_test(_write(tmp_path, "catman_short.csv", _two_clocks(N // 2 - 1)))
    assert len(raw.data) == N - 1  # the slow clock ends at 1.8 s: rows to 1.9 s kept, 1.95 s dropped
    assert any("line 42 further out dropped" in w for w in raw.warnings)


# ---- blank cells between a slower channel's values -------------------------------------------------------------
@pytest.mark.parametrize("m", [2, 3, 5, 20 / 7])
def test_blank_cells_between_values_are_interpolated(tmp_path, m):
    raw = read_test(_write(tmp_path, "slow.csv", _every(m)))
    t = 0.05 * np.arange(N)
    last = max(round(k * m) for k in range(N) if round(k * m) < N)
    keep = np.arange(N) < last + m  # rows within one period past the last value hold it
    assert len(raw.data) == keep.sum()
    assert_allclose(raw.data["force_n"], _force(np.minimum(t[keep], 0.05 * last)), rtol=1e-9)
    assert any("rows (sampled slower): its" in w for w in raw.warnings)


def test_three_rates_in_one_table(tmp_path):
    rows = ["time_s,stroke_mm,force_n"]
    for i in range(N):
        t = 0.05 * i
        rows.append(f"{t:.6g}," + (f"{_stroke(t):.6g}" if i % 2 == 0 else "") + ","
                    + (f"{_force(t):.6g}" if i % 5 == 0 else ""))
    raw = read_test(_write(tmp_path, "three.csv", "\n".join(rows) + "\n"))
    t = 0.05 * np.arange(len(raw.data))
    assert len(raw.data) == N  # force's last value at row 35 holds for 4 rows (< 5), stroke's at 38 for 1
    assert_allclose(raw.data["stroke_mm"], _stroke(np.minimum(t, 0.05 * 38)))
    assert_allclose(raw.data["force_n"], _force(np.minimum(t, 0.05 * 35)), rtol=1e-9)
    assert sum("sampled slower" in w for w in raw.warnings) == 2


@settings(max_examples=15, deadline=None)
@given(m=st.floats(1.5, 6.0), phase=st.integers(0, 1))
def test_any_even_pattern_reads_the_line_exactly(tmp_path_factory, m, phase):
    path = _write(tmp_path_factory.mktemp("p"), "p.csv", _every(m, n=60, phase=phase))
    raw = read_test(path)
    t = raw.data["time_s"].to_numpy()
    have = sorted({round(phase + k * m) for k in range(60) if round(phase + k * m) < 60})
    assert_allclose(raw.data["force_n"], _force(np.clip(t, 0.05 * have[0], 0.05 * have[-1])), rtol=1e-9)


# ---- refusals kept -----------------------------------------------------------------------------------------------
def test_an_empty_cell_here_and_there_is_still_refused(tmp_path):
    text = _every(1).splitlines()
    text[10] = text[10].rsplit(",", 1)[0] + ","
    path = _write(tmp_path, "hole.csv", "\n".join(text) + "\n")
    with pytest.raises(ReadError) as err:
        read_test(path)
    assert str(err.value).startswith(f"{path}:11: ") and "an empty cell in column 'force_n'" in str(err.value)
    raw = read_test(path, repair=True)
    assert len(raw.data) == N - 1 and any("dropped 1 row(s) with a non-finite or empty value at line(s) 11" in w
                                          for w in raw.warnings)


def test_a_long_empty_tail_without_a_clock_is_refused(tmp_path):
    path = _write(tmp_path, "half.csv", _every(1, tail=N // 2))
    with pytest.raises(ReadError) as err:
        read_test(path)
    assert f":{N // 2 + 2}: " in str(err.value) and "'force_n'" in str(err.value) and "\n" not in str(err.value)


def test_a_text_line_amid_the_samples_is_still_refused(tmp_path):
    text = _every(1).splitlines()
    text.insert(20, "End,0,0")
    with pytest.raises(ReadError, match=r":21: .*'End'"):
        read_test(_write(tmp_path, "mid.csv", "\n".join(text) + "\n"))


# ---- end records after the samples -------------------------------------------------------------------------------
@pytest.mark.parametrize("record, what", [
    ("End,0,0", "no number in column 'time_s'"),
    ("Mean,1.5,40.2\nMax,3.9,205", "no number in column 'time_s'"),
])
def test_an_end_record_with_text_is_left_out_and_said(tmp_path, record, what):
    raw = read_test(_write(tmp_path, "end.csv", _every(1) + record + "\n"))
    assert len(raw.data) == N
    (note,) = [w for w in raw.warnings if "end or summary record" in w]
    assert note.startswith(f"line {N + 2}: {record.count(chr(10)) + 1} end or summary record(s)") and what in note


def test_an_end_record_with_fewer_numbers_is_dropped_and_said(tmp_path):
    raw = read_test(_write(tmp_path, "short_end.csv", _every(1) + "1.95,1\n"))
    assert len(raw.data) == N
    assert any(w.startswith(f"line {N + 2}: column 'force_n' is empty") and "1 row(s) dropped" in w
               for w in raw.warnings)


def test_rows_past_the_declared_number_of_points_are_end_records(tmp_path):
    body = _every(1).splitlines()
    text = f'"Number of points : {N}"\n' + "\n".join(body) + "\n2.0,0,0\n"
    raw = read_test(_write(tmp_path, "counted.csv", text))
    assert len(raw.data) == N and raw.data["force_n"].iloc[-1] == pytest.approx(_force(0.05 * (N - 1)))
    assert any(f"the metadata count {N} samples (line 1: 'Number of points : {N}')" in w for w in raw.warnings)
    far = read_test(_write(tmp_path, "far.csv", text.replace(f": {N}", ": 5")))  # not a few rows off: not used
    assert len(far.data) == N + 1


# ---- declarations ------------------------------------------------------------------------------------------------
def test_a_declaration_reads_a_slow_rate_group_with_clock(tmp_path):
    data = _write(tmp_path, "catman.csv", _two_clocks(N // 2))
    decl = _write(tmp_path, "catman.toml", 'header_line = 1\nunits_line = 2\nfirst_data_line = 3\ndelimiter = ","\n'
                  '[time]\ncolumn = 1\n[stroke]\ncolumn = "Extenso"\n'
                  '[force]\ncolumn = "Load"\nclock = "Time  1 - slow sample rate"\n')
    (raw,) = read_declared(data, decl)
    assert_allclose(raw.data.to_numpy(), read_test(data).data.to_numpy())
    with pytest.raises(ReadError, match=r"catman\.csv:23: an empty cell: '' in the force column 'Load'"):
        read_declared(data, _write(tmp_path, "catman.toml", decl.read_text().replace('clock = "Time  1 - slow '
                                                                                      'sample rate"\n', "")))


def test_clock_is_refused_for_time(tmp_path):
    decl = _write(tmp_path, "bad.toml", 'header_line = 1\nfirst_data_line = 2\ndelimiter = ","\n'
                  '[time]\ncolumn = 1\nclock = 2\n[stroke]\ncolumn = 2\n[force]\ncolumn = 3\n')
    with pytest.raises(ReadError, match=r"time\.clock: 2 is not allowed; expected the name or 1-based position"):
        read_declared(_write(tmp_path, "x.csv", _every(1)), decl)


def test_an_empty_time_cell_reads_only_at_the_end(tmp_path):
    rows = ["time_s,stroke_mm,force_n"] + [f"{0.1 * i:.3g},{0.01 * i:.3g},{i:.1f}" for i in range(30)]
    raw = read_test(_write(tmp_path, "tail.csv", "\n".join([*rows, ",0.31,31"]) + "\n"))
    assert len(raw.data) == 30 and any(w.startswith("line 32: the time column 'time_s' is empty") for w in raw.warnings)
    rows[11] = ",0.1,10"
    with pytest.raises(ReadError, match=r"tail2\.csv:12: .*an empty cell in column 'time_s'"):
        read_test(_write(tmp_path, "tail2.csv", "\n".join(rows) + "\n"))


def test_a_broken_pattern_is_refused_at_the_row_that_breaks_it(tmp_path):
    text = _every(2, n=200).splitlines()
    text[101] = text[101].rsplit(",", 1)[0] + ","  # row 100 (line 102) should hold a value
    path = _write(tmp_path, "broken.csv", "\n".join(text) + "\n")
    with pytest.raises(ReadError) as err:
        read_test(path)
    assert str(err.value) == (f"{path}:102: an empty cell in column 'force_n' breaks its pattern (a value every 2 "
                              "rows up to line 100); expected a value every 2 rows, as sampled at one rate")


def test_a_long_table_with_a_slower_channel_reads_in_blocks(tmp_path):
    n = 30_000  # more than a piece of lines: the rows after the first empty cell go through the C parser
    text = _every(3, n=n)
    raw = read_test(_write(tmp_path, "long.csv", text))
    t = raw.data["time_s"].to_numpy()
    assert len(raw.data) == n
    assert_allclose(raw.data["force_n"], _force(np.minimum(t, 0.05 * (n - 1 - (n - 1) % 3))), rtol=1e-9)
