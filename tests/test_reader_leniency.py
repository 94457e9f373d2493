"""What labs write and the reader reads, with a warning: pauses, resets, repeats, padding (issue 22).

Small files written here, numbers derived by hand.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

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
    t = raw.data["time_s"].to_numpy()
    # the run 0.4, 0.4 (lines 6-7) is spread between its neighbours' stamps: centres at rows 3, 4.5, 6
    assert np.all(np.diff(t) > 0) and t[4] == pytest.approx(0.4 - 0.1 / 3) and t[5] == pytest.approx(0.4 + 0.1 / 3)


def test_packet_time_stamps_are_spread_and_the_curves_do_not_change(tmp_path):
    """Samples sent in packets of five, each row stamped with its packet's arrival (its last row's time): the
    reader spreads each run evenly, says so, and processing gives what the evenly stamped file gives."""
    from bendpam.lab.processing import process_tests
    from bendpam.lab.simulate import SimulationSettings, simulate_test
    from bendpam.physics import presets

    df, _ = simulate_test(presets.be_pam(), 150.0, settings=SimulationSettings(cycles=2, rate_hz=10.0, seed=3))
    plain = tmp_path / "plain.csv"
    df.to_csv(plain, index=False)
    t = df["time_s"].to_numpy()
    packed = df.copy()
    packed["time_s"] = t[np.minimum((np.arange(t.size) // 5) * 5 + 4, t.size - 1)]
    p = tmp_path / "packets.csv"
    packed.to_csv(p, index=False)
    raw = read_test(p, pressure_kpa=150.0)
    (w,) = [w for w in raw.warnings if "repeats" in w]
    assert "packets" in w and "(up to 5)" in w
    tr = raw.data["time_s"].to_numpy()
    assert np.all(np.diff(tr) > 0) and np.ptp(tr - t) < 5 * 0.1 + 1e-9  # s: one packet at most, a constant
    a, b = (process_tests([read_test(f, pressure_kpa=150.0)], keep_series=False).results[0] for f in (plain, p))
    assert b.blocked_moment == pytest.approx(a.blocked_moment, rel=2e-3)  # N*mm
    assert b.free_curvature == pytest.approx(a.free_curvature, rel=2e-3)


def test_a_run_of_repeated_stamps_before_a_pause_keeps_to_its_side():
    from bendpam.lab.checks import spread_repeats

    t = np.r_[np.repeat(np.arange(0.0, 2.0, 0.5), 5), 60.0 + np.repeat(np.arange(0.0, 2.0, 0.5), 5)]  # s: a pause
    out, longest = spread_repeats(t)
    assert longest == 5 and np.all(np.diff(out) > 0)
    assert np.allclose(np.diff(out[:20]), 0.1) and np.allclose(np.diff(out[20:]), 0.1)  # s: 0.5 s per 5 samples
    assert out[19] < 2.0 < 60.0 - 0.5 < out[20]  # no sample placed inside the pause


def test_a_row_that_repeats_the_previous_row_exactly_is_kept_and_spread(tmp_path):
    """A coarse clock during a hold with a quantised force writes rows equal in every column: they are samples, kept
    (leaving them out would space the run's other samples wrongly)."""
    body = _ramp(0.0, 5) + "0.4,0.04,3.0\n" + _ramp(0.5, 5)  # line 7 = line 6
    raw = read_test(_write(tmp_path, body))
    assert len(raw) == 11 and np.all(np.diff(raw.data["time_s"].to_numpy()) > 0)
    assert any("repeats the previous sample's value at 1 sample(s), line(s) 7" in w for w in raw.warnings)


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


def test_rows_sent_twice_are_dropped_and_a_restart_is_kept(tmp_path):
    """A logger's buffer sent again: time goes back three rows and those rows repeat exactly; they are dropped and
    named.  Rows after time goes back that differ are a restart of the clock, kept as a segment."""
    rows = _ramp(0.0, 8).splitlines(keepends=True)
    raw = read_test(_write(tmp_path, "".join(rows[:6] + rows[3:6] + rows[6:])))  # lines 8-10 repeat lines 5-7
    assert len(raw) == 8 and raw.segments == [(0, 8)]
    assert np.allclose(raw.data["time_s"], np.arange(8) * 0.1)
    assert any("dropped 3 row(s) sent twice" in w and "line(s) 8, 9, 10" in w for w in raw.warnings)
    moved = [*rows[3:5], "0.5,0.06,9.9\n"]  # the third differs: not a copy
    raw = read_test(_write(tmp_path, "".join(rows[:6] + moved + rows[6:]), name="u.csv"))
    assert len(raw) == 11 and len(raw.segments) == 2 and not any("sent twice" in w for w in raw.warnings)


@settings(max_examples=200, deadline=None)
@given(step=st.floats(1e-3, 0.1), per=st.integers(2, 10), n=st.integers(30, 400), start=st.floats(0.0, 100.0),
       coarse=st.floats(0.5, 1.5))
def test_spread_stamps_increase_and_stay_within_one_clock_step_of_the_truth(step, per, n, start, coarse):
    """Evenly taken samples (``step`` s apart) stamped by a clock that ticks every ``per * step * coarse`` s
    (truncated): the spread times increase strictly and differ from the true ones by a constant within less than
    one tick."""
    from bendpam.lab.checks import spread_repeats

    truth = start + np.arange(n) * step
    tick = per * step * coarse
    stamped = np.floor(truth / tick) * tick
    out, longest = spread_repeats(stamped)
    assert np.all(np.diff(out) > 0) and longest >= 1
    assert np.ptp(out - truth) < tick * (1.0 + 1e-9)
