"""The seventh held-out set's generator (tools/holdout7_generator.py): its loop laws dissipate, its files read.

It reuses the sixth set's machine (tests/test_holdout6_generator.py) with eight loop laws of its own.
"""

import hashlib
import sys
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import holdout7_generator as gen7  # noqa: E402

from bendpam.lab import read_test  # noqa: E402


def test_every_law_dissipates_on_every_cycle():
    for law, found in gen7.check_laws().items():
        assert min(found["areas"]) > 0.0, law  # loop area over max |z|: positive, each cycle


def _digest(folder: Path) -> str:
    h = hashlib.sha256()
    for p in sorted(folder.iterdir()):
        h.update(p.name.encode() + p.read_bytes())
    return h.hexdigest()


@pytest.mark.parametrize("name", ["h7-eyring-drift", "h7-dupont-ep"])
def test_it_is_deterministic_and_bendpam_reads_every_file(name, tmp_path):
    case = gen7.CASES[name]
    truth = gen7.generate_set(case, 1, tmp_path / "a")
    gen7.generate_set(case, 1, tmp_path / "b")
    assert _digest(tmp_path / "a") == _digest(tmp_path / "b")
    assert len(truth["files"]) == len(case.pressures_kpa)
    for fname, test in zip(truth["files"], truth["tests"], strict=True):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rt = read_test(tmp_path / "a" / fname)
        assert rt.pressure_kpa == pytest.approx(test["pressure_kpa"], rel=1e-6)
        assert len(rt) == test["samples"]
