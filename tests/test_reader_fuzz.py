"""Mutated real and synthetic exports through the whole pipeline: read, then process.

Every outcome must be a clean result or a one-line :class:`bendpam.errors.BendpamError` that
names the file (and the line where one applies); no NaN or absurd number in a result, no other
exception type.
"""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from bendpam import presets
from bendpam.errors import BendpamError, PlausibilityWarning
from bendpam.lab import RawTest, inspect_file, read_test, write_test
from bendpam.lab.processing import process_tests
from bendpam.lab.simulate import simulate_test

REAL = Path(__file__).parent / "data" / "real"
FUZZ = settings(
    max_examples=40,
    deadline=None,
    suppress_health_check=[
        HealthCheck.too_slow,
        HealthCheck.function_scoped_fixture,
        HealthCheck.data_too_large,
    ],
)


def _head(path: Path, n_lines: int) -> bytes:
    return b"".join(path.read_bytes().splitlines(keepends=True)[:n_lines])


def _synthetic() -> dict[str, bytes]:
    data, _truth = simulate_test(presets.be_pam("energy"), 200.0)
    data = data.iloc[::4].reset_index(drop=True)
    out: dict[str, bytes] = {}
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        for dialect in ("csv", "testxpert", "bluehill", "mts"):
            p = Path(d) / f"sim_{dialect}.txt"
            write_test(p, data, dialect, pressure_kpa=200, language="de")
            out[f"sim_{dialect}.txt"] = p.read_bytes()
    # a Polish (cp1250) and a Chinese (GB18030) variant of the Bluehill layout
    rows = [f"{t:.4f};{s:.5f};{f:.5f}".replace(".", ",") for t, s, f in data.to_numpy()]
    pl = ["Ciśnienie : 200 kPa", "Czas;Przemieszczenie;Obciążenie", "(s);(mm);(N)", *rows]
    out["sim_pl.csv"] = ("\r\n".join(pl) + "\r\n").encode("cp1250")
    rows = [f"{t:.4f},{s:.5f},{f:.5f}" for t, s, f in data.to_numpy()]
    zh = ["时间,位移,载荷", "s,mm,N", *rows]
    out["sim_zh.csv"] = ("\r\n".join(zh) + "\r\n").encode("gb18030")
    return out


CORPUS: dict[str, bytes] = {
    **_synthetic(),
    "bluehill2.csv": _head(REAL / "bluer_Bluehill2_ccyclic_Specimen_RawData_6.csv", 3000),
    "wavematrix.csv": (REAL / "whiterabbit_WaveMatrix_silicone10A_Test7.steps.tracking.csv").read_bytes(),
    "mts793.dat": (REAL / "lebedigital_MTS793_MPT_DEU_ansi_cyclic_Emodul_BALosMV4.dat").read_bytes(),
    "instron8852.csv": (REAL / "pmd_42CrMoS4_Instron8852_46NT71.csv").read_bytes(),
    "zwick.TRA": _head(REAL / "matolab_Zugversuch_ETFE_Groesseneffekt7.TRA", 2000),
    "trends.csv": (REAL / "whiterabbit_WaveMatrix_latexglove_Test6.steps.trends.csv").read_bytes(),
}  # fmt: skip
NAMES = sorted(CORPUS)
ENCODINGS = ["utf-8", "cp1252", "cp1250", "gb18030", "shift_jis", "utf-16", "latin-1"]


def _decode(raw: bytes) -> str:
    for enc in ("utf-8-sig", "gb18030", "cp1250"):
        try:
            return raw.decode(enc)
        except UnicodeDecodeError:
            continue
    return raw.decode("latin-1")


@st.composite
def mutations(draw) -> tuple[str, bytes, str]:
    name = draw(st.sampled_from(NAMES))
    raw = CORPUS[name]
    kind = draw(st.sampled_from(["truncate", "flip", "encoding", "spike", "units", "lines"]))
    if kind == "truncate":
        raw = raw[: draw(st.integers(0, len(raw)))]
    elif kind == "flip":
        b = bytearray(raw)
        for _ in range(draw(st.integers(1, 6))):
            i = draw(st.integers(0, max(len(b) - 1, 0)))
            if b:
                b[i] ^= draw(st.integers(1, 255))
        raw = bytes(b)
    elif kind == "encoding":
        raw = _decode(raw).encode(draw(st.sampled_from(ENCODINGS)), errors="replace")
    elif kind == "spike":
        lines = raw.split(b"\n")
        i = draw(st.integers(len(lines) // 4, max(len(lines) - 2, len(lines) // 4)))
        big = draw(st.sampled_from([b"2451502E9", b"9999999999", b"-1e30", b"nan", b"1,000,292"]))
        lines[i] = re.sub(rb"\d+(?:[.,]\d+)?", big, lines[i], count=draw(st.integers(1, 2)))
        raw = b"\n".join(lines)
    elif kind == "units":
        text = _decode(raw)
        a, b = draw(st.sampled_from([("N", "kN"), ("mm", "in"), ("s", "ms"), ("kN", "N"),
                                     ("(s)", "(min)"), ("mm", "%")]))  # fmt: skip
        text = re.sub(rf"(?<![\w]){re.escape(a)}(?![\w])", b, text[:4000], count=3) + text[4000:]
        raw = text.encode("utf-8")
    else:
        lines = raw.split(b"\n")
        for _ in range(draw(st.integers(1, 3))):
            i = draw(st.integers(0, len(lines)))
            junk = draw(st.sampled_from([b"", b"End of data", b";;;", b"Time;Force", b"\x00\x01",
                                         b"Pressure;-5;bar", b"1;2", b'"']))  # fmt: skip
            lines.insert(i, junk)
        raw = b"\n".join(lines)
    return name, raw, kind


def _check_error(exc: BaseException, path: Path) -> None:
    assert isinstance(exc, BendpamError), f"{type(exc).__name__}: {exc}"
    msg = str(exc)
    assert "\n" not in msg and "\r" not in msg, msg
    assert path.name in msg, msg
    line = getattr(exc, "line", None)
    if line is not None:
        assert f"{path.name}:{line}: " in msg, msg


def _check_result(raw: RawTest) -> None:
    d = raw.data.to_numpy()
    assert np.isfinite(d).all()
    assert list(raw.data.columns) == ["time_s", "stroke_mm", "force_n"]
    assert np.all(np.diff(d[:, 0]) > 0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # a plausibility finding is a result, not a fault (mts793.dat is a concrete test: issue 22 item 7)
        warnings.simplefilter("ignore", PlausibilityWarning)
        ps = process_tests([raw], keep_series=False)
    for r in ps.results:
        for arr in (r.curvature_grid, r.branches, r.blocked_moments, r.free_curvatures):
            assert np.isfinite(arr).all()
            assert np.all(np.abs(arr) < 1e15)
        assert math.isfinite(r.sample_rate_hz) and r.sample_rate_hz > 0
        ratios = r.energy_loss_ratios
        assert np.isfinite(ratios).all() or any("energy-loss ratio undefined" in n for n in r.notes)


@FUZZ
@given(case=mutations(), repair=st.booleans())
def test_mutated_exports_through_the_pipeline(tmp_path_factory, case, repair):
    name, content, _kind = case
    path = tmp_path_factory.mktemp("mut") / name
    path.write_bytes(content)
    try:
        raw = read_test(path, pressure_kpa=200, repair=repair)
    except Exception as exc:
        _check_error(exc, path)
        info = inspect_file(path, pressure_kpa=200, repair=repair)
        assert set(info) == {"file", "error"}
        return
    try:
        _check_result(raw)
    except AssertionError:
        raise
    except Exception as exc:
        _check_error(exc, path)


@pytest.mark.parametrize("name", NAMES)
def test_unmutated_corpus(tmp_path, name):
    path = tmp_path / name
    path.write_bytes(CORPUS[name])
    try:
        raw = read_test(path, pressure_kpa=200)
    except BendpamError as exc:
        assert name == "trends.csv", str(exc)
        _check_error(exc, path)
        return
    assert name != "trends.csv"
    try:
        _check_result(raw)
    except BendpamError as exc:  # a tension test is no bending cycle: a clean refusal is fine
        _check_error(exc, path)
    if name.startswith("sim_"):
        ps = process_tests([raw])
        assert ps.results[0].n_cycles >= 2
