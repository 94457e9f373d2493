"""What labs write and the reader reads, with a warning: pauses, resets, repeats, padding (issue 22).

Small files written here, numbers derived by hand.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bendpam.lab import ReadError, read_test, read_tests

HEADER = "time_s,stroke_mm,force_n\n"


def _write(tmp_path: Path, body: str, name: str = "t.csv") -> Path:
    p = tmp_path / name
    p.write_text(HEADER + body)
    return p


def _ramp(t0: float, n: int, dt: float = 0.1) -> str:
    # time t0 + k*dt s, stroke k*0.01 mm, force 1 + k*0.5 N
    return "".join(f"{t0 + k * dt:.1f},{k * 0.01:.2f},{1 + k * 0.5:.1f}\n" for k in range(n))


def test_pause_is_read_and_splits_segments(tmp_path):
    # 10 samples at 0.1 s, then a 19 s pause: time 0.0..0.9 then 19.9..20.8
    p = _write(tmp_path, _ramp(0.0, 10) + _ramp(19.9, 10))
    raw = read_test(p)
    assert len(raw) == 20 and raw.segments == [(0, 10), (10, 20)]
    (w,) = [w for w in raw.warnings if "gap" in w]
    assert "19 s between line 11 and line 12" in w  # lines: header is line 1, sample k at line k+2


def test_time_reset_is_read_as_a_new_segment(tmp_path):
    # the clock restarts at 0 after 8 samples and runs on for 6
    p = _write(tmp_path, _ramp(0.0, 8) + _ramp(0.0, 6))
    raw = read_test(p)
    assert len(raw) == 14 and raw.segments == [(0, 8), (8, 14)]
    assert any("restarts 1 time(s), at line(s) 10" in w for w in raw.warnings)
    assert raw.data["time_s"].iat[8] == 0.0


def test_a_sample_out_of_order_is_refused_with_its_line(tmp_path):
    # 0.0 0.1 0.2 0.3 | 0.05 | 0.5 ...: the 5th sample's time is out of order (a wrong number), line 6
    lines = _ramp(0.0, 10).splitlines()
    lines[4] = "0.05,0.04,3.0"
    body = "\n".join(lines) + "\n"
    p = _write(tmp_path, body)
    with pytest.raises(ReadError, match="out of order") as info:
        read_test(p)
    assert info.value.line == 6 and str(p) in str(info.value)
    raw = read_test(p, repair=True)
    assert len(raw) == 9 and np.all(np.diff(raw.data["time_s"]) > 0)


def test_repeated_time_is_kept_and_reported(tmp_path):
    body = _ramp(0.0, 5) + "0.4,0.05,3.5\n" + _ramp(0.5, 5)
    raw = read_test(_write(tmp_path, body))
    assert len(raw) == 11 and raw.segments == [(0, 11)]
    assert any("repeats" in w and "line(s) 7" in w for w in raw.warnings)


def test_padding_rows_at_the_end_are_dropped(tmp_path):
    # two rows of zeros after the data (a logger's padding)
    raw = read_test(_write(tmp_path, _ramp(0.1, 12) + "0,0,0\n0,0,0\n"))
    assert len(raw) == 12 and raw.data["time_s"].iat[-1] == pytest.approx(1.2)
    assert any("padding" in w and "14, 15" in w for w in raw.warnings)


def test_end_record_with_time_back_to_zero_is_dropped(tmp_path):
    # time 0.0 in the first and the last row: the last is an end record, not a sample
    raw = read_test(_write(tmp_path, _ramp(0.0, 12) + "0.0,0.5,0.1\n"))
    assert len(raw) == 12 and raw.data["force_n"].iat[-1] == pytest.approx(6.5)
    assert raw.data["time_s"].iat[0] == 0.0
    assert any("padding" in w for w in raw.warnings)


def test_trailing_delimiters_are_read(tmp_path):
    body = "".join(line + ",\n" for line in _ramp(0.0, 6).splitlines())
    p = tmp_path / "t.csv"
    p.write_text("time_s,stroke_mm,force_n,\n" + body)
    raw = read_test(p)
    assert len(raw) == 6 and raw.data["force_n"].tolist() == [1.0, 1.5, 2.0, 2.5, 3.0, 3.5]


def test_time_that_never_advances_is_refused(tmp_path):
    # an aborted test: three samples, all at time 0
    p = _write(tmp_path, "0,0.1,1\n0,0.1,2\n0,0.1,3\n")
    with pytest.raises(ReadError, match="time does not advance") as info:
        read_test(p)
    assert info.value.line == 2


def test_read_tests_of_a_single_test_file(tmp_path):
    (raw,) = read_tests(_write(tmp_path, _ramp(0.0, 6)))
    assert raw.specimen is None and raw.block is None and len(raw) == 6 and raw.segments == [(0, 6)]


def test_two_end_records_back_at_time_zero_are_dropped(tmp_path):
    raw = read_test(_write(tmp_path, _ramp(0.0, 30) + "0.0,0.5,0.1\n0.0,0.6,0.2\n"))
    assert len(raw) == 30 and raw.data["time_s"].iat[-1] == pytest.approx(2.9)
    assert any("padding" in w and "32, 33" in w for w in raw.warnings)
