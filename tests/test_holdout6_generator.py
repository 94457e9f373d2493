"""The sixth held-out set's generator (tools/holdout6_generator.py): an independent machine, checked on its own.

Its fixture against a bracketed root of eq 6, its clean machine (no loop, noise or fault) against the truth's
moment, its determinism, and every file read by bendpam with the pressure and sample count it wrote.
"""

import hashlib
import sys
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import holdout6_generator as gen6  # noqa: E402

from bendpam.lab import read_test  # noqa: E402


def test_its_fixture_solves_eq_6():
    assert gen6.check_fixture(400) < 1e-9  # rad


@pytest.mark.parametrize("name", list(gen6.CASES))
def test_its_clean_machine_gives_the_truths_moment(name):
    assert gen6.check_clean_machine(gen6.CASES[name]) < 1e-6  # of the blocked moment


def _digest(folder: Path) -> str:
    h = hashlib.sha256()
    for p in sorted(folder.iterdir()):
        h.update(p.name.encode() + p.read_bytes())
    return h.hexdigest()


@pytest.mark.parametrize("name", ["h6-chaboche-drift", "h6-ja-gauge"])
def test_it_is_deterministic_and_bendpam_reads_every_file(name, tmp_path):
    case = gen6.CASES[name]
    truth = gen6.generate_set(case, 1, tmp_path / "a")
    gen6.generate_set(case, 1, tmp_path / "b")
    assert _digest(tmp_path / "a") == _digest(tmp_path / "b")
    assert len(truth["files"]) == len(case.pressures_kpa)
    for fname, test in zip(truth["files"], truth["tests"], strict=True):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rt = read_test(tmp_path / "a" / fname)
        assert rt.pressure_kpa == pytest.approx(test["pressure_kpa"], rel=1e-6)
        assert len(rt) == test["samples"]
