"""One grammar for every command (issue 25): lists, --json, --force and readable help.

Every option that takes a list accepts several tokens (``100 150 200``), a comma list
(``100,150,200``) and a range ``start:stop:count`` (``100:200:3``), on every command, and the
values reach the computation (checked in each command's output, not in the parser alone).
"""

import json
import re

import pandas as pd
import pytest
import typer

from bendpam.cli import app, main
from bendpam.cli.options import join_list_values, parse_values

#: The three spellings of the same list, as command-line tokens.
FORMS = {"tokens": ["100", "150", "200"], "commas": ["100,150,200"], "range": ["100:200:3"]}
EXPECTED = [100.0, 150.0, 200.0]


def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def strict(text: str):
    """JSON that has no NaN/Infinity tokens (they are not JSON)."""
    def refuse(token):
        raise AssertionError(f"non-JSON token {token}")

    return json.loads(text, parse_constant=refuse)


def test_free_takes_several_names(capsys, tmp_path):
    # the names join the option; the folder after them stays the argument (here one that does not exist)
    code, _, err = run(capsys, "fit", "--free", "alpha0", "C10", "C01", tmp_path / "nothing", "--preset", "be-pam",
                       "--out", tmp_path / "f")
    assert code == 2 and "nothing" in err and "unexpected extra argument" not in err, err
    assert join_list_values(["--free", "alpha0", "C10,C01", "proc"], {"--free": frozenset({"alpha0", "C10", "C01"})}) \
        == ["--free", "alpha0,C10,C01", "proc"]


def test_join_list_values_stops_at_files_and_options():
    rules = {"--pressure-kpa": None, "--model": frozenset({"energy", "force-balance"})}
    assert join_list_values(["--pressure-kpa", "100", "-5", "1e2", "raw", "x.csv"], rules) == \
        ["--pressure-kpa", "100,-5,1e2", "raw", "x.csv"]
    assert join_list_values(["--model", "energy", "force-balance", "raw"], rules) == \
        ["--model", "energy,force-balance", "raw"]
    # after '--' nothing is joined; a value of another option is never taken
    assert join_list_values(["--pressure-kpa", "100", "--", "150"], rules) == ["--pressure-kpa", "100", "--", "150"]
    assert join_list_values(["--l0-mm", "145", "150"], rules) == ["--l0-mm", "145", "150"]
    for form in FORMS.values():
        assert parse_values(join_list_values(["--p", *form], {"--p": None})[1:], "--p") == EXPECTED


@pytest.mark.parametrize("form", FORMS)
def test_predict_all_forms(capsys, form):
    code, out, err = run(capsys, "predict", "--preset", "be-pam", "--pressure-kpa", *FORMS[form], "--json")
    assert code == 0, err
    assert [r["pressure_kpa"] for r in strict(out)["results"]] == EXPECTED


@pytest.mark.parametrize("form", FORMS)
def test_curve_all_forms(capsys, tmp_path, form):
    f = tmp_path / "c.csv"
    code, _, err = run(capsys, "curve", "--preset", "be-pam", "--pressure-kpa", *FORMS[form], "--out", f,
                       "--points", "3")
    assert code == 0, err
    assert sorted(set(pd.read_csv(f).pressure_kpa)) == EXPECTED


@pytest.mark.parametrize("form", FORMS)
def test_simulate_test_all_forms(capsys, tmp_path, form):
    code, out, err = run(capsys, "simulate-test", "--preset", "be-pam", "--pressure-kpa", *FORMS[form], "--out",
                         tmp_path / "raw", "--cycles", "1", "--rate-hz", "5", "--json")
    assert code == 0, err
    truth = strict(out)
    assert [t["pressure_kpa"] for t in truth["pressures"]] == EXPECTED
    assert json.loads((tmp_path / "raw" / "truth.json").read_text())["pressures"] == truth["pressures"]


@pytest.fixture(scope="module")
def raw_files(tmp_path_factory):
    d = tmp_path_factory.mktemp("raw")
    assert main(["simulate-test", "--preset", "be-pam", "--pressure-kpa", "100,150,200", "--out", str(d / "raw"),
                 "--cycles", "1", "--rate-hz", "5", "--seed", "1"]) == 0
    return sorted(str(p) for p in (d / "raw").glob("*.csv"))


@pytest.mark.parametrize("form", FORMS)
def test_process_all_forms_before_the_files(capsys, tmp_path, raw_files, form):
    # the list ends at the first token that is not a value: the files after it stay files
    code, out, err = run(capsys, "process", "--pressure-kpa", *FORMS[form], *raw_files, "--out", tmp_path / "p",
                         "--no-figure", "--json", "-q")
    assert code == 0, err
    assert [r["pressure_kpa"] for r in strict(out)["pressures"]] == EXPECTED


@pytest.mark.parametrize("form", FORMS)
def test_report_all_forms_reach_the_report(capsys, tmp_path, raw_files, monkeypatch, form):
    import bendpam.present.report as rep
    from bendpam.errors import InputError

    seen = {}

    def fake(files, act, path, *, models, pressure_kpa, **kw):
        seen.update(models=models, pressure_kpa=pressure_kpa)
        raise InputError("stop here")  # the fits themselves are tests/test_report.py's

    monkeypatch.setattr(rep, "build_report", fake)
    models = {"tokens": ["energy", "force-balance"], "commas": ["energy,force-balance"],
              "range": ["energy", "--model", "force-balance"]}[form]
    code, _, err = run(capsys, "report", *raw_files, "--preset", "be-pam", "--pressure-kpa", *FORMS[form],
                       "--model", *models, "--out", tmp_path / "r.html")
    assert code == 2 and "stop here" in err
    assert seen == {"models": ["energy", "force-balance"], "pressure_kpa": EXPECTED}


@pytest.mark.parametrize("form", FORMS)
def test_sweep_all_forms(capsys, tmp_path, form):
    f = tmp_path / "s.csv"
    param = {"tokens": ["alpha0_deg=60", "65", "70"], "commas": ["alpha0_deg=60,65,70"],
             "range": ["alpha0_deg=60:70:3"]}[form]
    code, _, err = run(capsys, "sweep", "--preset", "be-pam", "--param", *param, "--pressure-kpa", *FORMS[form],
                       "--out", f, "-q")
    assert code == 0, err
    df = pd.read_csv(f)
    assert sorted(set(df.pressure_kpa)) == EXPECTED and sorted(set(df.alpha0_deg)) == [60.0, 65.0, 70.0]


@pytest.mark.parametrize("form", FORMS)
def test_finger_all_forms(capsys, form):
    code, out, err = run(capsys, "finger", "--preset", "be-pam", "--pressure-kpa", *FORMS[form], "--json")
    assert code == 0, err
    assert [r["pressure_kpa"] for r in strict(out)["results"]] == EXPECTED


@pytest.mark.parametrize("form", FORMS)
def test_wrist_all_forms(capsys, form):
    dirs = {"tokens": ["0", "90", "180"], "commas": ["0,90,180"], "range": ["0:180:3"]}[form]
    code, out, err = run(capsys, "wrist", "--preset", "be-pam", "--pressure-kpa", *FORMS[form], "--direction-deg",
                         *dirs, "--json")
    assert code == 0, err
    rows = strict(out)["results"]
    assert sorted({r["pressure_kpa"] for r in rows}) == EXPECTED
    assert sorted({r["direction_deg"] for r in rows}) == [0.0, 90.0, 180.0]


@pytest.mark.parametrize("form", FORMS)
def test_grasp_all_forms(capsys, form):
    dia = {"tokens": ["100", "140"], "commas": ["100,140"], "range": ["100:140:2"]}[form]
    code, out, err = run(capsys, "grasp", "--preset", "be-pam", "--diameter-mm", *dia, "--pressure-kpa", "200",
                         "--json")
    assert code == 0, err
    rows = strict(out)["results"]
    assert sorted({r["diameter_mm"] for r in rows}) == [100.0, 140.0]
    assert {r["pressure_kpa"] for r in rows} == {200.0}


# ---- --json: strict, "inf" for infinity, null for missing ----------------------------------------
def test_json_infinity_is_a_string_and_null_is_missing(capsys):
    code, out, err = run(capsys, "predict", "--preset", "be-pam", "--pressure-kpa", "150", "--json")
    assert code == 0, err
    obj = strict(out)
    row = obj["results"][0]
    # the paper's BE-PAM has no frame strength: no limit, an infinite margin -- never null
    assert obj["actuator"]["frame_strength_mpa"] is None  # missing
    assert row["frame_strength_margin"] == "inf" and float(row["frame_strength_margin"]) == float("inf")
    assert obj["max_equilibrium_pressure_kpa"] == "inf"  # the free-bending branch never ends
    assert row["note"] is None


def test_finger_limits_margin_without_demand_is_inf(capsys):
    code, out, err = run(capsys, "finger", "--preset", "be-pam", "--pressure-kpa", "150", "--json")
    assert code == 0, err
    lim = strict(out)["results"][0]["limits"]
    assert lim["buckling_margin"] == "inf"  # no compressive demand on the frame
    assert isinstance(lim["lockup_margin"], float)


def _commands():
    group = typer.main.get_command(app)
    return group, sorted(group.commands)


#: Commands that print results (a table, values, a summary): each has --json.
PRINTING = {"actuator", "demo", "design", "finger", "fit", "fit-material", "grasp", "inspect", "predict",
            "process", "report", "simulate-test", "wrist", "hand"}


def test_every_command_has_readable_help_json_and_force(capsys):
    group, names = _commands()
    assert set(PRINTING) <= set(names)
    for name in names:
        code, out, err = run(capsys, name, "--help")
        assert code == 0, err
        for bad in ("<list", "{", "[str]", "<path>", "<float", "<int", "<str>", "[Path]"):
            assert bad not in out, f"bendpam {name} --help shows {bad!r}"
        cmd = group.commands[name]
        writes = any(p.name in ("out", "plot") for p in cmd.params)
        assert ("--force" in out) == writes, name
        if name in PRINTING:
            assert re.search(r"^\s+--json\b", out, re.M), f"bendpam {name} has no --json"


def test_force_after_the_command_replaces_a_foreign_file(capsys, tmp_path):
    f = tmp_path / "a.toml"
    f.write_text("hand-edited\n")
    code, _, err = run(capsys, "actuator", "--preset", "be-pam", "--out", f)
    assert code == 2 and "--force" in err and f.read_text() == "hand-edited\n"
    code, _, err = run(capsys, "actuator", "--preset", "be-pam", "--out", f, "--force")
    assert code == 0, err
    assert "alpha0_deg" in f.read_text()
    assert [p.read_text() for p in tmp_path.glob("a.toml.moved-aside-*")] == ["hand-edited\n"]
    # the root spelling still works
    f2 = tmp_path / "b.toml"
    f2.write_text("x\n")
    assert run(capsys, "--force", "actuator", "--preset", "be-pam", "--out", f2)[0] == 0


def test_shell_completion_is_available(capsys, monkeypatch):
    code, out, _ = run(capsys, "--help")
    assert code == 0 and "--install-completion" in out and "--show-completion" in out
    monkeypatch.setenv("_BENDPAM_COMPLETE", "complete_bash")
    monkeypatch.setenv("COMP_WORDS", "bendpam predict --pres")
    monkeypatch.setenv("COMP_CWORD", "2")
    with pytest.raises(SystemExit):
        main(["predict", "--pres"])
    assert {"--preset", "--pressure-kpa"} <= set(capsys.readouterr().out.split())


# ---- --format is the figure format; tables have --table-format ----------------------------------
def test_format_is_the_figure_format_on_every_command(capsys):
    group, names = _commands()
    for name in names:
        code, out, _ = run(capsys, name, "--help")
        for line in out.splitlines():
            if re.match(r"^\s+--format\s", line):
                assert line.split()[1] == "[png|pdf|svg]", (name, line)
    for name in ("sweep", "simulate-test"):
        assert "--table-format" in run(capsys, name, "--help")[1]
    assert "--format" in run(capsys, "design", "--help")[1]


def test_simulate_test_table_format_and_the_old_spelling(capsys, tmp_path):
    args = ["simulate-test", "--preset", "be-pam", "--pressure-kpa", "150", "--cycles", "1", "--rate-hz", "5"]
    code, _, err = run(capsys, *args, "--out", tmp_path / "a", "--table-format", "testxpert")
    assert code == 0 and err == "", err
    assert [p.name for p in (tmp_path / "a").glob("*.txt")] == ["be-pam_150kPa.txt"]
    code, _, err = run(capsys, *args, "--out", tmp_path / "b", "--format", "testxpert")
    assert code == 0
    assert err.splitlines() == ["bendpam: warning: simulate-test --format testxpert is deprecated (--format is the "
                                "figure format); use --table-format testxpert"]
    assert [p.name for p in (tmp_path / "b").glob("*.txt")] == ["be-pam_150kPa.txt"]
    code, _, err = run(capsys, *args, "--out", tmp_path / "c", "--format", "mts", "--table-format", "csv")
    assert code == 2 and "not both" in err


def test_design_figure_format(capsys, tmp_path):
    code, _, err = run(capsys, "design", "--preset", "be-pam", "--target", "blocked_moment_nmm=400@200", "--vary",
                       "alpha0_deg=60:80", "--n-coarse", "16", "--starts", "1", "--out", tmp_path / "d", "--format",
                       "svg", "--quiet")
    assert code == 0, err
    assert (tmp_path / "d" / "coarse_map.svg").read_text().lstrip().startswith(("<?xml", "<svg"))
    assert not (tmp_path / "d" / "coarse_map.png").exists()
    code, _, err = run(capsys, "design", "--preset", "be-pam", "--target", "blocked_moment_nmm=400@200", "--vary",
                       "alpha0_deg=60:80", "--format", "pdf")
    assert code == 2 and "--out" in err


@pytest.mark.slow
def test_report_json(capsys, tmp_path, raw_files):
    out = tmp_path / "r.html"
    code, text, err = run(capsys, "report", *raw_files, "--preset", "be-pam", "--model", "energy", "--out", out,
                          "--json", "-q")
    assert code == 0, err
    obj = strict(text)
    assert obj["report"] == str(out) and out.stat().st_size > 10_000
    assert [r["pressure_kpa"] for r in obj["table2"]["pressures"]] == EXPECTED
    assert set(obj["fits"]) == {"energy"} and obj["fits"]["energy"]["converged"] is True
    assert abs(obj["fits"]["energy"]["parameters"]["alpha0_deg"]["value"] - 69.7) < 1.0
