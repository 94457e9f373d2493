"""A clock that restarts inside one raw test (issue 22 item 3): read with a warning, processed as one test."""

from __future__ import annotations

import numpy as np

import bendpam
from bendpam.lab import read_test
from bendpam.lab.processing import continuous_time, process_tests
from bendpam.lab.simulate import SimulationSettings, simulate_test


def _write(path, t, s, f):
    lines = ["time_s,stroke_mm,force_n"] + [f"{a:.4f},{b:.6f},{c:.6f}" for a, b, c in zip(t, s, f, strict=True)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")


def test_a_restarted_clock_is_read_and_processed_like_the_continuous_test(tmp_path):
    be = bendpam.physics.presets.be_pam()
    data, _truth = simulate_test(be, 150.0, settings=SimulationSettings(cycles=2, seed=3))
    t, s, f = (data[c].to_numpy() for c in ("time_s", "stroke_mm", "force_n"))
    n = t.size // 2
    restarted = t.copy()
    restarted[n:] -= restarted[n]  # the machine's clock starts again from 0 s half-way through
    _write(tmp_path / "plain_150kPa.csv", t, s, f)
    _write(tmp_path / "restart_150kPa.csv", restarted, s, f)
    plain = read_test(tmp_path / "plain_150kPa.csv")
    raw = read_test(tmp_path / "restart_150kPa.csv")
    assert len(raw) == len(plain) and len(raw.segments) == 2 and raw.segments[1][0] == n
    assert any("restart" in w or "back" in w for w in raw.warnings), raw.warnings
    a = process_tests([plain]).results[0]
    b = process_tests([raw]).results[0]
    assert b.n_cycles == a.n_cycles == 2
    np.testing.assert_array_equal(b.blocked_moments, a.blocked_moments)
    np.testing.assert_array_equal(b.free_curvatures, a.free_curvatures)
    assert any("clock restarts 1 time" in note for note in b.notes)


def test_continuous_time_keeps_gaps_and_shifts_restarts():
    t = np.array([0.0, 0.5, 1.0, 5.0, 5.5, 0.0, 0.5])  # a 4 s gap, then a restart
    out, k = continuous_time(t, [(0, 3), (3, 5), (5, 7)])
    assert k == 1
    np.testing.assert_allclose(out, [0.0, 0.5, 1.0, 5.0, 5.5, 6.0, 6.5])
    same, k0 = continuous_time(t[:5], [(0, 3), (3, 5)])
    assert k0 == 0 and same is not None and np.array_equal(same, t[:5])
