"""The numbers are read in blocks of text: where the blocks end never changes what is read or refused.

The parser hands the C parser large blocks of lines and reads a block that has odd lines
(blank lines, text after the data, a bad cell, a second table) in pieces, only the odd piece line
by line.  Here the block and piece sizes are made tiny, so that their ends fall everywhere, and
the result is checked against the rows written (values, line numbers, warnings, refusals).
"""

from __future__ import annotations

import io

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy import ndimage

import bendpam.lab.parser as parser_mod
from bendpam.lab import ReadError, read_test
from bendpam.lab.checks import SPIKE_FACTOR, find_spikes
from bendpam.lab.layout import LineReader

HEADER = "time_s,stroke_mm,force_n"


def _rows(n: int, t0: float = 0.0) -> list[str]:
    return [f"{t0 + 0.05 * i:.2f},{5 + np.sin(i / 7):.5f},{20 + np.cos(i / 7):.4f}" for i in range(n)]


def _expected(lines: list[str]) -> tuple[np.ndarray, list[int]]:
    """The numbers of the data rows among ``lines`` (file lines from 1) and their line numbers."""
    vals, lnos = [], []
    for k, line in enumerate(lines, start=1):
        cells = line.split(",")
        if len(cells) == 3:
            try:
                vals.append([float(c) for c in cells])
                lnos.append(k)
            except ValueError:
                pass
    return np.array(vals), lnos


@pytest.fixture
def tiny_chunks(monkeypatch):
    def set_sizes(chars: int, piece: int) -> None:
        monkeypatch.setattr(parser_mod, "_CHUNK_CHARS", chars)
        monkeypatch.setattr(parser_mod, "_PIECE_LINES", piece)
    return set_sizes


def _write(tmp_path, name: str, lines: list[str], newline: str = "\n", final: bool = True):
    path = tmp_path / name
    path.write_bytes((newline.join(lines) + (newline if final else "")).encode())
    return path


@pytest.mark.parametrize("chars", [7, 20, 33, 64, 150, 1000])
@pytest.mark.parametrize("piece", [1, 3, 7, 2000])
def test_blank_lines_and_text_after_the_data_at_every_block_end(tmp_path, tiny_chunks, chars, piece):
    lines = [HEADER, *_rows(40), "", "", *_rows(10, t0=2.0), "", "", "End of test", "Operator: x"]
    path = _write(tmp_path, "be_150kPa.csv", lines)
    tiny_chunks(chars, piece)
    raw = read_test(path)
    want, lnos = _expected(lines)
    np.testing.assert_array_equal(raw.data.to_numpy(), want)
    assert raw.data_lines == (lnos[0], lnos[-1]) == (2, 53)
    assert any("text line(s) after the data" in w and "line 56" in w for w in raw.warnings), raw.warnings


@pytest.mark.parametrize("chars", [9, 25, 64, 4096])
@pytest.mark.parametrize("piece", [2, 5, 2000])
def test_a_second_table_after_blank_lines_ends_the_block(tmp_path, tiny_chunks, chars, piece):
    lines = [HEADER, *_rows(30), "", "Results", HEADER, *_rows(12, t0=50.0)]
    path = _write(tmp_path, "be_150kPa.csv", lines)
    tiny_chunks(chars, piece)
    raw = read_test(path)
    # the second table repeats the header and its time continues (50 s on): one test of both blocks
    # (issue 22 item 3), the gap between them a segment boundary; wherever the chunks end
    first, _ = _expected(lines[:31])
    second, _ = _expected([HEADER, *lines[34:]])
    np.testing.assert_array_equal(raw.data.to_numpy(), np.vstack([first, second]))
    assert raw.segments == [(0, 30), (30, 42)]
    assert any("2 data blocks" in w for w in raw.warnings), raw.warnings


@pytest.mark.parametrize("chars", [11, 40, 333, 1 << 21])
@pytest.mark.parametrize("piece", [1, 4, 2000])
def test_a_bad_cell_is_named_at_its_line_wherever_the_blocks_end(tmp_path, tiny_chunks, chars, piece):
    lines = [HEADER, *_rows(60)]
    lines[47] = "2.30,abc,20.1"  # line 48
    path = _write(tmp_path, "be_150kPa.csv", lines)
    tiny_chunks(chars, piece)
    with pytest.raises(ReadError) as err:
        read_test(path)
    assert str(err.value).startswith(f"{path}:48: ") and "'abc'" in str(err.value)


@pytest.mark.parametrize("chars", [13, 64, 1 << 21])
def test_repair_drops_a_non_finite_row_by_its_line(tmp_path, tiny_chunks, chars):
    lines = [HEADER, *_rows(50)]
    lines[30] = "1.45,nan,20.3"  # line 31
    path = _write(tmp_path, "be_150kPa.csv", lines, newline="\r\n", final=False)
    tiny_chunks(chars, 3)
    raw = read_test(path, repair=True)
    assert len(raw.data) == 49
    assert "dropped 1 row(s) with a non-finite or empty value at line(s) 31" in raw.warnings


@pytest.mark.parametrize("chars", [10, 77, 1 << 21])
def test_a_bad_counter_cell_is_named_at_its_own_line(tmp_path, tiny_chunks, chars):
    rows = [f"{r},{i // 10}" for i, r in enumerate(_rows(80))]
    rows[63] = rows[63].rsplit(",", 1)[0] + ",x"  # line 65
    path = _write(tmp_path, "be_150kPa.csv", ["time_s,stroke_mm,force_n,cycle count", *rows])
    tiny_chunks(chars, 4)
    raw = read_test(path)
    assert len(raw.data) == 80 and raw.cycle_counter is None
    assert "cycle counter 'cycle count' has non-numeric cells (line 65); not used" in raw.warnings


def test_a_bad_line_far_into_a_big_file_is_named_exactly(tmp_path):
    n = 300_000  # several blocks of text of the default size
    i = np.arange(n)
    body = [f"{a:.2f},{b:.5f},{c:.4f}" for a, b, c in zip(i * 0.01, 5 + 5 * np.sin(i / 500), 20 + np.cos(i / 500),
                                                           strict=True)]
    body[249_998] = "2499.98,5.0;1,20.0"  # line 250 000: a stray ';'
    path = _write(tmp_path, "be_150kPa.csv", [HEADER, *body])
    with pytest.raises(ReadError) as err:
        read_test(path)
    assert str(err.value).startswith(f"{path}:250000: ")
    body[249_998] = "2499.98,5.0,20.0"
    path = _write(tmp_path, "be_150kPa.csv", [HEADER, *body, "", "End of test"])
    raw = read_test(path)
    assert len(raw.data) == n and raw.data_lines == (2, n + 1)
    assert raw.data["time_s"].iat[-1] == float(body[-1].split(",")[0])


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(parts=st.lists(st.sampled_from(["row", "row", "row", "blank", "crlf"]), min_size=3, max_size=60),
       chars=st.integers(1, 200))
def test_take_text_gives_the_lines_that_iteration_gives(parts, chars):
    pieces, k = [], 0
    for p in parts:
        pieces.append(f"{k},{k * 0.5}" if p == "row" else "")
        pieces.append("\r\n" if p == "crlf" else "\n")
        k += 1
    text = "".join(pieces)
    want = [line.rstrip("\r\n") for line in io.StringIO(text, newline=None)]
    reader = LineReader(io.StringIO(text, newline=None))
    first = reader.next()
    got = [first] if first is not None else []
    while (block := reader.take_text(chars)) is not None:
        lines = block[0].split("\n")
        assert len(lines) == block[1]
        got.extend(lines)
        assert reader.lineno == len(got)
    assert got == want


def _spikes_by_filter(x: np.ndarray) -> np.ndarray:
    """The definition: distance to the 5-sample median beyond SPIKE_FACTOR robust ranges (the full filter)."""
    n = x.size
    if n < 5:
        return np.empty(0, dtype=np.int64)
    k = max(2, int(np.ceil(0.005 * n)))
    part = np.partition(x, [k, n - 1 - k])
    scale = float(part[n - 1 - k] - part[k])
    scale = max(scale, max(1e-9 * max(float(np.median(np.abs(x))), 1.0), 1e-12))
    dev = np.abs(x - ndimage.median_filter(x, size=5, mode="nearest"))
    return np.flatnonzero(dev > SPIKE_FACTOR * scale)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.one_of(st.floats(-5, 5, allow_nan=False), st.sampled_from([0.0, 1.0, 2.5, 1e9, -1e7, 50.0])),
                min_size=0, max_size=80))
def test_find_spikes_equals_the_full_median_filter(values):
    x = np.array(values, dtype=float)
    np.testing.assert_array_equal(find_spikes(x), _spikes_by_filter(x))
