"""The eleventh independent held-out generator (tools/holdout11_generator.py), checked alone.

Its loop laws alone: each dissipates on every cycle, its half-width on the reference triangle in hold-out 10's band
(2.8-4.0 % of the blocked moment); on the clean machine every logged cycle dissipates.  Its sets: deterministic, the
truth with hold-out 10's keys, every file read by bendpam with the pressure and the rows written, and read files
processed (not fitted): the faults leave the files usable.  Nothing here fits.
"""

import hashlib
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import holdout11_generator as gen11  # noqa: E402

from bendpam.lab import read_test  # noqa: E402
from bendpam.lab.processing import process_tests  # noqa: E402
from bendpam.physics.fixture import Fixture  # noqa: E402

TRUTH_KEYS = {"case", "seed", "alpha0_deg", "shear_modulus_kpa", "shape", "files", "fixture_L0_mm", "tests", "loop",
              "loop_source", "faults", "fault_params", "fault_sources"}  # hold-out 10's


def test_every_case_has_its_own_sourced_law_and_at_most_one_sourced_fault():
    assert set(gen11._LAWS) == set(gen11.SOURCES) == {c.loop for c in gen11.CASES.values()}
    assert len(gen11.CASES) == 8
    faults = [f for c in gen11.CASES.values() for f in c.faults]
    assert len(faults) == len(set(faults)) and set(faults) == set(gen11.FAULT_SOURCES)
    for case in gen11.CASES.values():
        assert len(case.faults) <= 1 and 3 <= len(case.pressures_kpa) <= 6, case.name
        assert 0.005 <= case.noise_fraction <= 0.03, case.name


def test_every_law_dissipates_on_every_cycle_with_hold_out_10s_half_width():
    for law, found in gen11.check_laws(points=500).items():
        assert found["dissipates"] and min(found["areas"]) > 0.0, law  # loop area over max |z|, each cycle
        assert 0.028 <= found["half_width_mean"] <= 0.040 and found["half_width_ok"], law


@pytest.mark.parametrize("name", [n for n in gen11.CASES if n != "h11-bk-regulator"])  # its law is the slow one
def test_the_clean_machines_loops_dissipate_on_every_logged_cycle(name):
    for P, found in gen11.check_machine(gen11.CASES[name]).items():
        assert found["half_widths"], P
        assert all(0.015 < hw < 0.06 for hw in found["half_widths"]), (P, found["half_widths"])
        assert 0.85 < found["detected_over_free"] < 1.05, P


def _digest(folder: Path) -> str:
    h = hashlib.sha256()
    for p in sorted(folder.iterdir()):
        h.update(p.name.encode() + p.read_bytes())
    return h.hexdigest()


def _read_and_process(folder: Path, truth: dict):
    raws = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for fname, test in zip(truth["files"], truth["tests"]):
            rt = read_test(folder / fname)
            assert rt.pressure_kpa == pytest.approx(test["pressure_kpa"], rel=1e-6)
            assert len(rt) == test["samples"]
            raws.append(rt)
        return process_tests(raws, fixture=Fixture(d_mm=35.0, r_mm=2.5, t_mm=4.0, L0_mm=truth["fixture_L0_mm"]),
                             keep_series=False)


@pytest.mark.parametrize("name", ["h11-lk-pause", "h11-huntcrossley-results", "h11-liangrogers-thermal",
                                  "h11-grosch-speed", "h11-schallamach-hyst"])
def test_it_is_deterministic_and_bendpam_reads_and_processes_every_file(name, tmp_path):
    case = gen11.CASES[name]
    truth = gen11.generate_set(case, 1, tmp_path / "a")
    gen11.generate_set(case, 1, tmp_path / "b")
    assert _digest(tmp_path / "a") == _digest(tmp_path / "b")
    assert set(truth) == TRUTH_KEYS and truth["loop"] == case.loop and truth["faults"] == list(case.faults)
    assert len(truth["files"]) == len(case.pressures_kpa)
    done = _read_and_process(tmp_path / "a", truth)
    assert done.pressures_kpa.tolist() == [t["pressure_kpa"] for t in truth["tests"]]


def test_the_handling_faults_show_in_the_files(tmp_path):
    truth = gen11.generate_set(gen11.CASES["h11-huntcrossley-results"], 0, tmp_path / "r")
    text = (tmp_path / "r" / truth["files"][0]).read_text(encoding="utf-8").splitlines()
    assert "Results" in text and len(text) - text.index("Results") - 3 == truth["tests"][0]["results_rows"] == 3
    truth = gen11.generate_set(gen11.CASES["h11-grosch-speed"], 0, tmp_path / "s")
    head = (tmp_path / "s" / truth["files"][0]).read_text(encoding="utf-8").splitlines()[1]
    assert head == "Rate:\t50\tmm/min" and truth["tests"][0]["real_speed_mm_min"] == 40.0
    truth = gen11.generate_set(gen11.CASES["h11-lk-pause"], 0, tmp_path / "p")
    test = truth["tests"][0]
    t, x = np.loadtxt(tmp_path / "p" / truth["files"][0], delimiter=",", comments="#", skiprows=3, unpack=True)[:2]
    held = x[(t > test["pause_start_s"] + 0.1) & (t < test["pause_start_s"] + test["pause_s"] - 0.1)]
    assert held.size > 1000 and np.ptp(held) < 0.02 and abs(np.mean(held) - test["pause_stroke_mm"]) < 1e-3


def test_its_command_line_prints_its_usage():
    assert gen11.main([]) == 2
