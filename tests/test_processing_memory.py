"""Processing in bounded memory gives the numbers the whole-array steps gave.

The memory-saving forms of the steps (segments filtered into one array, eq 6-8 in blocks, the
series labelled without copies, Figure 4 (a) thinned past a number of samples) are checked
against the plain forms they replace.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import signal

import bendpam.present.figures.lab as figlab
from bendpam import presets
from bendpam.lab.processing import PAPER_FIXTURE, _convert, _segment_lowpass, process_tests
from bendpam.lab.rawtest import RawTest
from bendpam.lab.simulate import SimulationSettings, simulate_test


def _segment_lowpass_reference(x, tp, fs, cutoff, order, fallback):
    """The accumulate-and-count form (three arrays of the record's length)."""
    sos = signal.butter(order, cutoff, btype="low", fs=fs, output="sos")
    edges = np.unique(np.concatenate([tp, [x.size - 1]]))
    out = fallback.copy()
    acc = np.zeros(x.size)
    cnt = np.zeros(x.size)
    need = 3 * (2 * sos.shape[0] + 1)
    for a, b in itertools.pairwise(edges):
        seg = x[a: b + 1]
        if seg.size <= need:
            continue
        y = signal.sosfiltfilt(sos, seg, padtype="odd", padlen=min(seg.size - 1, max(need, int(3 * fs / cutoff))))
        acc[a: b + 1] += y
        cnt[a: b + 1] += 1
    done = cnt > 0
    out[done] = acc[done] / cnt[done]
    return out


@settings(max_examples=40, deadline=None)
@given(cuts=st.lists(st.integers(1, 399), max_size=12, unique=True), seed=st.integers(0, 2**16))
def test_segment_lowpass_equals_the_accumulating_form(cuts, seed):
    rng = np.random.default_rng(seed)
    x = np.cumsum(rng.normal(size=400))
    tp = np.array([0, *sorted(cuts)])
    fallback = rng.normal(size=400)
    got = _segment_lowpass(x, tp, 20.0, 1.0, 4, fallback)
    np.testing.assert_array_equal(got, _segment_lowpass_reference(x, tp, 20.0, 1.0, 4, fallback))


def test_convert_in_blocks_equals_one_call():
    rng = np.random.default_rng(3)
    s = rng.uniform(0.0, 20.0, 10_001)  # mm
    f = rng.uniform(0.0, 30.0, 10_001)  # N
    whole = PAPER_FIXTURE.convert(s, f, 0.5)
    for got, want in zip(_convert(PAPER_FIXTURE, s, f, 0.5, block=777), whole, strict=True):
        np.testing.assert_array_equal(got, want)


@pytest.fixture(scope="module")
def processed():
    data, _ = simulate_test(presets.be_pam(), 150.0, settings=SimulationSettings(cycles=3, rate_hz=10.0, seed=4))
    return process_tests([RawTest(data, "be_150kPa.csv", "csv", pressure_kpa=150.0)])


def test_series_labels_every_sample_of_a_cycle(processed):
    r = processed.results[0]
    ser = r.series
    cyc, branch = ser["cycle"].to_numpy(), ser["branch"].astype(str).to_numpy()
    assert set(np.unique(cyc)) <= {-1, 1, 2, 3} and (cyc > 0).any()
    assert set(branch[cyc > 0]) == {"unloading", "loading"} and set(branch[cyc < 0]) <= {""}
    assert (ser["branch"] == "loading").sum() > 0


def test_figure4_draws_a_long_test_every_nth_sample(processed, monkeypatch):
    n_cycle = int((processed.results[0].series["cycle"] > 0).sum())
    monkeypatch.setattr(figlab, "_LOOP_POINTS", 100)
    fig = figlab.figure4(processed)
    loops = fig.axes[0].get_lines()[0]  # drawn first, before the dashed mean curve
    assert len(loops.get_xdata()) == len(range(0, n_cycle, -(-n_cycle // 100))) <= 100
    monkeypatch.setattr(figlab, "_LOOP_POINTS", 10**9)
    fig = figlab.figure4(processed)
    assert len(fig.axes[0].get_lines()[0].get_xdata()) == n_cycle
