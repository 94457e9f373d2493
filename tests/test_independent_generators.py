"""The independent held-out generators (tools/holdout6_generator.py, holdout7_generator.py, holdout8_generator.py,
holdout9_generator.py, holdout10_generator.py), checked alone.

The sixth set's machine: its fixture against a bracketed root of eq 6 and its clean machine (no loop, noise or
fault) against the truth's moment.  The seventh to tenth sets' loop laws (on that machine): each dissipates on every
cycle; the ninth and tenth sets' loops are 2-6 % of the blocked moment.  All: deterministic, and every file read by
bendpam with the pressure and sample count written (the ninth and tenth sets' also processed; the tenth set's
re-sent and reduced rows are counted in the rows written).
"""

import hashlib
import sys
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

import holdout6_generator as gen6  # noqa: E402
import holdout7_generator as gen7  # noqa: E402
import holdout8_generator as gen8  # noqa: E402
import holdout9_generator as gen9  # noqa: E402
import holdout10_generator as gen10  # noqa: E402

from bendpam.lab import read_test  # noqa: E402
from bendpam.lab.processing import process_tests  # noqa: E402
from bendpam.physics.fixture import Fixture  # noqa: E402


def test_the_sixth_sets_fixture_solves_eq_6():
    assert gen6.check_fixture(400) < 1e-9  # rad


@pytest.mark.parametrize("name", list(gen6.CASES))
def test_the_sixth_sets_clean_machine_gives_the_truths_moment(name):
    assert gen6.check_clean_machine(gen6.CASES[name]) < 1e-6  # of the blocked moment


@pytest.mark.parametrize("gen", [gen7, gen8, gen9, gen10])
def test_every_seventh_to_tenth_set_law_dissipates_on_every_cycle(gen):
    for law, found in gen.check_laws().items():
        assert min(found["areas"]) > 0.0, law  # loop area over max |z|: positive, each cycle


@pytest.mark.parametrize("gen", [gen9, gen10])
def test_the_ninth_and_tenth_sets_loops_are_two_to_six_percent_of_the_blocked_moment(gen):
    for law, found in gen.check_laws(points=500).items():
        assert found["dissipates"] and 0.02 <= found["half_width_mean"] <= 0.06, law


def _digest(folder: Path) -> str:
    h = hashlib.sha256()
    for p in sorted(folder.iterdir()):
        h.update(p.name.encode() + p.read_bytes())
    return h.hexdigest()


@pytest.mark.parametrize(("gen", "name"), [(gen6, "h6-chaboche-drift"), (gen6, "h6-ja-gauge"),
                                           (gen7, "h7-eyring-drift"), (gen7, "h7-dupont-ep"),
                                           (gen8, "h8-maxwellslip-tare"), (gen8, "h8-preisach-quant"),
                                           (gen8, "h8-boucwen-zero"), (gen9, "h9-gms-clock"),
                                           (gen9, "h9-bodner-spikes"), (gen9, "h9-romasing-clamp"),
                                           (gen10, "h10-moore-packets"), (gen10, "h10-bliman-dups"),
                                           (gen10, "h10-mullins-supply"), (gen10, "h10-kraus-reduction")])
def test_it_is_deterministic_and_bendpam_reads_every_file(gen, name, tmp_path):
    case = gen.CASES[name]
    truth = gen.generate_set(case, 1, tmp_path / "a")
    gen.generate_set(case, 1, tmp_path / "b")
    assert _digest(tmp_path / "a") == _digest(tmp_path / "b")
    assert len(truth["files"]) == len(case.pressures_kpa)
    raws = []
    for fname, test in zip(truth["files"], truth["tests"], strict=True):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            rt = read_test(tmp_path / "a" / fname)
        assert rt.pressure_kpa == pytest.approx(test["pressure_kpa"], rel=1e-6)
        resent = "dup-rows" in getattr(case, "faults", ())  # rows sent twice are dropped: the machine's samples
        assert len(rt) == (test["machine_samples"] if resent else test["samples"])
        raws.append(rt)
    if gen in (gen9, gen10):  # read and processed (not fitted): the faults leave the files usable
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            done = process_tests(raws, fixture=Fixture(d_mm=35.0, r_mm=2.5, t_mm=4.0, L0_mm=truth["fixture_L0_mm"]),
                                 keep_series=False)
        assert done.pressures_kpa.tolist() == [t["pressure_kpa"] for t in truth["tests"]]


def test_their_command_lines_write_a_seed_of_every_case(tmp_path, capsys):
    assert gen7.main([]) == 2 and "usage" in capsys.readouterr().out
    assert gen7.main([str(tmp_path), "3"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([*gen7.CASES, "truth.json"])
