"""At home in notebooks (issue 25 item 3): short summaries, and paths where a processed set is expected."""

from pathlib import Path

import numpy as np
import pytest

import bendpam
from bendpam.errors import InputError
from bendpam.infra.display import MAX_ROWS, summary_text
from bendpam.lab import RawTest, processing, simulate
from bendpam.lab.processed import write_processed

BE = bendpam.physics.presets.be_pam()


def check_short(obj, *, max_lines=16):
    """A repr of a few lines without any array; an HTML fragment with the same title."""
    text = repr(obj)
    assert 1 <= len(text.splitlines()) <= max_lines, text
    assert "array(" not in text and "\n\n" not in text
    html = obj._repr_html_()
    assert html.startswith("<div><b>") and html.endswith("</div>") and len(html) < 4000
    assert text.splitlines()[0].split(" ")[0] in html
    return text, html


@pytest.fixture(scope="module")
def processed():
    settings = simulate.SimulationSettings(cycles=1, rate_hz=2.0, hysteresis=0.0, seed=1)
    raws = [RawTest(simulate.simulate_test(BE, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv",
                    pressure_kpa=p) for p in (100.0, 150.0, 200.0)]
    return processing.process_tests(raws, keep_series=False, options=processing.ProcessingOptions(grid_points=21))


@pytest.fixture(scope="module")
def folder(processed, tmp_path_factory):
    d = tmp_path_factory.mktemp("proc") / "proc"
    d.mkdir()
    write_processed(processed, d)
    return d


def test_actuator_summary():
    text, html = check_short(BE)
    assert text.splitlines()[0] == "Actuator BE-PAM (paper, energy constants)"
    assert "alpha0_deg: 69.7" in text and "<li>braid angle alpha0_deg: 69.7</li>" in html
    assert BE == bendpam.physics.presets.be_pam()  # repr changes nothing else


def test_moment_law_summary():
    law = bendpam.MomentLaw.of(BE)
    assert repr(law).startswith("MomentLaw(")
    html = law._repr_html_()
    assert "<b>MomentLaw of BE-PAM" in html and "model: energy" in html


def test_processed_set_summary(processed):
    text, html = check_short(processed)
    lines = text.splitlines()
    assert lines[0].startswith("ProcessedSet: 3 pressure(s)")
    # one row per pressure, the values of Table 2 (blocked moment: the cycles' mean)
    rows = [ln.split() for ln in lines[3:]]
    assert [float(r[0]) for r in rows] == [100.0, 150.0, 200.0]
    for r, res in zip(rows, processed.results, strict=True):
        assert float(r[2]) == pytest.approx(float(np.mean(res.blocked_moments)), rel=1e-3)
    assert html.count("<tr>") == 4


def test_long_tables_are_cut():
    rows = [[i, float(i)] for i in range(100)]
    text = summary_text("t", [], ["i", "x"], rows)
    assert len(text.splitlines()) == 1 + 1 + MAX_ROWS + 1 and text.endswith(f"... {100 - MAX_ROWS} more rows")


def test_fit_takes_a_folder_and_summarises(folder, processed):
    res = bendpam.fit(str(folder), BE)  # a path where a processed set is expected
    assert res.converged and abs(res.actuator.alpha0_deg - 69.7) < 0.5
    same = bendpam.fit(folder, BE)
    assert same.actuator.alpha0_deg == pytest.approx(res.actuator.alpha0_deg, rel=1e-9)
    text, html = check_short(res)
    assert text.splitlines()[0].startswith("FitResult: energy model (converged")
    assert "curves fitted: mean curves" in text and "alpha0_deg" in html
    fig = res.plot(folder)  # the figure takes the folder too
    assert fig.axes


def test_type_comparison_takes_a_folder(folder):
    from bendpam.identify.compare import type_comparison

    with pytest.raises(InputError, match=r"no such|curves\.nc"):
        type_comparison(folder / "missing", BE)


def test_not_a_processed_set_is_one_line():
    with pytest.raises(InputError, match=r"expected a processed test set .* got int"):
        bendpam.fit(3, BE)


def test_design_and_finger_summaries():
    from bendpam.design import Finger, solve_finger
    from bendpam.design.inverse import design_actuator

    shape = solve_finger(Finger(BE), 150.0)
    text, _ = check_short(shape)
    assert text.splitlines()[0] == "FingerShape at 150 kPa (equilibrium)"
    assert "bend_angle_deg: 67.78" in text and "base_moment_nmm: 0" in text
    res = design_actuator(BE, ["blocked_moment_nmm=400@200"], ["alpha0_deg=60:80"], n_coarse=64, n_starts=1)
    text, html = check_short(res)
    assert text.splitlines()[0] == "DesignResult: feasible (energy model)"
    assert "target blocked_moment_nmm=400@200: 400 (met)" in text and "<td>alpha0_deg</td>" in html
