"""A declared calibration of the rig (GUM type B): the load cell's and the pressure gauge's standard uncertainties,
and its zero and any force in proportion to the pressure, when the lab knows them.

The curves cannot show a force reading a fixed fraction high or a pressure a few kPa off (every test moves
alike); declared, each adds what it would move the fitted parameters by.  Checked against actual refits of
the same raw tests read by a load cell 1 % high and at pressures 2 kPa off, 50 mN off zero, and with a force of
0.5 mN/kPa reaching it.  A declared offset also leaves out the ensemble's members that fit it (checked on the
calibration study's stiction case, where they take weight on clean data).
"""

import json
import warnings
from pathlib import Path

import numpy as np
import pytest

from bendpam import presets
from bendpam.cli import main
from bendpam.errors import InputError
from bendpam.identify.fitting import fit
from bendpam.identify.result import FitResult
from bendpam.identify.uncertainty import Instrument
from bendpam.lab import RawTest
from bendpam.lab.processed import write_processed
from bendpam.lab.processing import process_tests
from bendpam.lab.simulate import SimulationSettings, simulate_test

BE = presets.be_pam()
PRESSURES = (100.0, 150.0, 200.0)


def raws(force_scale: float = 1.0, pressure_offset_kpa: float = 0.0, zero_n: float = 0.0,
         force_per_kpa: float = 0.0) -> list[RawTest]:
    """The same simulated tests (two cycles, a loop), read with a force scaled and pressures said off, off zero by
    ``zero_n`` and with ``force_per_kpa`` times the pressure on the load cell."""
    out = []
    for p in PRESSURES:
        data, _ = simulate_test(BE, p, settings=SimulationSettings(cycles=2, rate_hz=5.0, seed=int(p)))
        data = data.assign(force_n=data["force_n"] * force_scale + zero_n + force_per_kpa * p)
        out.append(RawTest(data, Path(f"be_{p:g}kPa.csv"), "csv", pressure_kpa=p + pressure_offset_kpa))
    return out


def fitted(force_scale=1.0, pressure_offset_kpa=0.0, instrument=None, zero_n=0.0, force_per_kpa=0.0):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ps = process_tests(raws(force_scale, pressure_offset_kpa, zero_n, force_per_kpa), keep_series=False)
        return fit(ps, BE, profile_points=0, law_uncertainty=False, instrument=instrument)


@pytest.fixture(scope="module")
def base():
    return fitted(instrument=Instrument(force_uncertainty_pct=1.0, pressure_uncertainty_kpa=2.0))


def test_the_declared_parts_are_what_refits_with_the_errors_move(base):
    b = base.uncertainty
    assert set(b.instrument) >= {"alpha0_deg", "shear_modulus_kpa"}
    # the load cell 1 % high: one standard uncertainty of the declared 1 %
    high = fitted(force_scale=1.01)
    for key, moved in (("alpha0_deg", high.actuator.alpha0_deg - base.actuator.alpha0_deg),
                       ("shear_modulus_kpa", high.material.shear_modulus_kpa - base.material.shear_modulus_kpa)):
        alone = Instrument(force_uncertainty_pct=1.0)
        part = fitted(instrument=alone).uncertainty.instrument[key]
        assert part == pytest.approx(abs(moved), rel=0.15), key
    # the pressures 2 kPa off: one standard uncertainty of the declared 2 kPa
    off = fitted(pressure_offset_kpa=2.0)
    part = fitted(instrument=Instrument(pressure_uncertainty_kpa=2.0)).uncertainty.instrument["alpha0_deg"]
    assert part == pytest.approx(abs(off.actuator.alpha0_deg - base.actuator.alpha0_deg), rel=0.15)


@pytest.mark.parametrize(("declared", "moved"), [(Instrument(zero_uncertainty_n=0.05), {"zero_n": 0.05}),
                                                 (Instrument(pressure_force_uncertainty_n_per_kpa=5e-4),
                                                  {"force_per_kpa": 5e-4})])
def test_a_declared_offset_is_what_a_refit_with_it_moves(base, declared, moved):
    """50 mN off zero moves alpha0 by about 0.07 deg here; 0.5 mN/kPa (0.1 N at 200 kPa) by about 0.13 deg."""
    shifted = fitted(**moved)
    part = fitted(instrument=declared).uncertainty
    assert abs(shifted.actuator.alpha0_deg - base.actuator.alpha0_deg) > 0.05  # the offset matters here
    for key, now, then in (("alpha0_deg", shifted.actuator.alpha0_deg, base.actuator.alpha0_deg),
                           ("shear_modulus_kpa", shifted.material.shear_modulus_kpa, base.material.shear_modulus_kpa)):
        assert part.instrument[key] == pytest.approx(abs(now - then), rel=0.15), key
    assert part.declared.startswith("the load cell's zero to 0.05 N" if "zero_n" in moved
                                    else "a force in proportion to the pressure to 0.0005 N/kPa")


def test_the_total_and_the_parameters_include_it(base):
    b = base.uncertainty
    plain = fitted()
    assert plain.uncertainty.instrument == {}
    for key in ("alpha0_deg", "shear_modulus_kpa"):
        assert b.total[key] == pytest.approx(np.sqrt(b.statistical[key] ** 2 + b.systematic.get(key, 0.0) ** 2
                                                     + b.instrument[key] ** 2))
        assert b.total[key] > plain.uncertainty.total[key]
    assert base.parameters["alpha0"].stderr == pytest.approx(b.total["alpha0_deg"], rel=1e-6)
    assert base.material.se_shear_modulus_kpa == pytest.approx(b.total["shear_modulus_kpa"], rel=1e-6)
    assert "the force reading to 1 %" in b.declared and "2 kPa" in b.declared and "declared" not in b.resampling
    assert "/ instrument" in str(base) and b.declared in str(base)


def test_it_survives_the_saved_fit(base, tmp_path):
    base.save(tmp_path / "fit")
    back = FitResult.load(tmp_path / "fit")
    assert back.uncertainty.instrument == pytest.approx(base.uncertainty.instrument)
    assert "instrument" in json.loads((tmp_path / "fit" / "fit.json").read_text(encoding="utf-8"))["uncertainty"]


def test_bad_declarations_are_refused():
    with pytest.raises(InputError, match="force_uncertainty_pct"):
        Instrument(force_uncertainty_pct=-1.0)
    with pytest.raises(InputError, match="pressure_uncertainty_kpa"):
        Instrument(pressure_uncertainty_kpa=float("nan"))
    with pytest.raises(InputError, match="zero_uncertainty_n"):
        Instrument(zero_uncertainty_n=-0.01)
    with pytest.raises(InputError, match="pressure_force_uncertainty_n_per_kpa"):
        Instrument(pressure_force_uncertainty_n_per_kpa=float("inf"))
    assert Instrument(zero_uncertainty_n=0.0).declared and Instrument(zero_uncertainty_n=0.0).offsets_declared == (
        "F_off",)


@pytest.fixture(scope="module")
def stiction(study_case):
    """The calibration study's stiction case (seed 0): clean data on which the offset members take weight."""
    return study_case("stiction", 0)


def offset_laws(result) -> set[str]:
    return {m.law.split("+", 1)[1] for m in result.uncertainty.ensemble if "+" in m.law}


def test_a_declared_tare_leaves_out_the_offset_members_and_says_why_they_were_wide(stiction):
    ps, act, truth = stiction
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plain = fit(ps, act, profile_points=0)
        zero = fit(ps, act, profile_points=0, instrument=Instrument(zero_uncertainty_n=0.005))
        tared = fit(ps, act, profile_points=0, instrument=Instrument(zero_uncertainty_n=0.005,
                                                                      pressure_force_uncertainty_n_per_kpa=0.0))
    assert offset_laws(plain) == {"offset", "pressure_offset", "both_offsets"}
    assert offset_laws(zero) == {"pressure_offset"}  # the members with a zero offset are out
    assert offset_laws(tared) == set()
    said = [f for f in plain.flags if "offset members take" in f]
    assert len(said) == 1 and "--zero-uncertainty-n" in said[0]
    assert not any("offset members take" in f for f in tared.flags)
    se_plain, se_tared = plain.parameters["alpha0"].stderr, tared.parameters["alpha0"].stderr
    assert se_tared < 0.6 * se_plain  # the offset members' doubt is most of the bar on these data
    assert tared.uncertainty.instrument["alpha0_deg"] > 0.0  # 5 mN of zero, counted
    assert abs(tared.parameters["alpha0"].value - truth["alpha0_deg"]) <= 2.0 * se_tared


def test_the_command_line_declares_it(tmp_path, capsys):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        write_processed(process_tests(raws(), keep_series=False), tmp_path / "proc", figure=False)
    assert main(["fit", str(tmp_path / "proc"), "--preset", "be-pam", "--out", str(tmp_path / "fit"), "--no-figure",
                 "--force-uncertainty-pct", "0.58", "--pressure-uncertainty-kpa", "1.7", "--json"]) == 0
    unc = json.loads(capsys.readouterr().out)["uncertainty"]
    assert unc["instrument"]["alpha0_deg"] > 0
    assert main(["fit", str(tmp_path / "proc"), "--preset", "be-pam", "--out", str(tmp_path / "fit2"),
                 "--force-uncertainty-pct", "-1"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--force-uncertainty-pct" in err[0]
    assert main(["fit", str(tmp_path / "proc"), "--preset", "be-pam", "--out", str(tmp_path / "fit3"), "--no-figure",
                 "--zero-uncertainty-n", "0.01", "--pressure-force-uncertainty-n-per-kpa", "0", "--json"]) == 0
    unc = json.loads(capsys.readouterr().out)["uncertainty"]
    assert "the load cell's zero to 0.01 N and no force in proportion to the pressure" in unc["declared"]
    assert unc["instrument"]["alpha0_deg"] > 0
    assert main(["fit", str(tmp_path / "proc"), "--preset", "be-pam", "--out", str(tmp_path / "fit4"),
                 "--zero-uncertainty-n", "-0.01"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--zero-uncertainty-n" in err[0]


def test_the_report_declares_it_too(tmp_path):
    from bendpam.lab.simulate import simulate_tests
    from bendpam.present.report import build_report

    raw = simulate_tests(BE, [100, 200], tmp_path / "raw", settings=SimulationSettings(cycles=2, rate_hz=2.0, seed=3))
    rep = build_report(tmp_path / "raw", BE, tmp_path / "report.html", models=["energy"], progress=False,
                       processing_options={"grid_points": 21}, instrument=Instrument(force_uncertainty_pct=0.58))
    assert raw and "Instrument (declared)" in (tmp_path / "report.html").read_text(encoding="utf-8")
    assert rep.html.name == "report.html"


def test_the_report_names_the_declaration(tmp_path):
    from bendpam.lab.simulate import SimulationSettings, simulate_tests
    from bendpam.present.report import build_report

    simulate_tests(BE, [100, 200], tmp_path / "raw", settings=SimulationSettings(cycles=1, rate_hz=2.0, hysteresis=0.0,
                                                                                  seed=1))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        build_report(tmp_path / "raw", BE, tmp_path / "r.html", models=["energy"], progress=False,
                     processing_options={"grid_points": 21}, instrument=Instrument(force_uncertainty_pct=0.5))
    page = (tmp_path / "r.html").read_text(encoding="utf-8")
    assert "Instrument (declared)" in page
    assert "its declared calibration: the force reading to 0.5 %" in page
    assert "statistical (" in page and "calibration: the force reading to 0.5 %)" not in page


def test_without_a_declaration_the_fit_says_what_its_bars_leave_out():
    text = str(fitted())
    assert "not included: the rig's calibration" in text and "--force-uncertainty-pct" in text
