"""Start-up (issue 24, item 6): what the short commands import, checked in fresh interpreters.

``bendpam --help`` and ``--version`` import no NumPy (nor pandas, pyplot, ``scipy.io``);
``bendpam predict`` prints its few rows without pandas; ``bendpam fit`` imports no pyplot (no
matplotlib at all without a figure) and no ``scipy.io``: it reads the processed set's ``curves.npz``
with NumPy (``curves.nc`` stays the file of record; tests/test_processing_npz.py).  ``--help`` imports
none of the command modules, a command its own module only.
Each command runs through the console script's entry (:func:`bendpam_entry.main`) in a new
process, which then lists ``sys.modules``.  No timings here: ``benchmarks/bench_startup.py``
measures them.
"""

import json
import subprocess
import sys
from pathlib import Path

import pytest

RUN = """
import json, sys
sys.argv = ["bendpam", *json.loads(sys.argv[1])]
import bendpam_entry
rc = bendpam_entry.main()
with open({out!r}, "w") as f:
    json.dump({{"rc": rc, "modules": sorted(sys.modules)}}, f)
"""


def modules_after(args: list[str], tmp_path: Path, cwd: Path | None = None) -> tuple[set[str], str]:
    """The modules loaded once ``bendpam ARGS`` has run in a fresh interpreter, and its stdout."""
    out = tmp_path / f"modules-{len(list(tmp_path.glob('modules-*')))}.json"
    r = subprocess.run([sys.executable, "-c", RUN.format(out=str(out)), json.dumps(args)], capture_output=True,
                       text=True, cwd=cwd or tmp_path, timeout=300)
    assert r.returncode == 0, r.stderr
    got = json.loads(out.read_text())
    assert got["rc"] == 0, r.stderr
    return set(got["modules"]), r.stdout


def loaded(modules: set[str], name: str) -> list[str]:
    return sorted(m for m in modules if m == name or m.startswith(name + "."))


NOT_AT_START = ["numpy", "pandas", "matplotlib", "scipy", "xarray", "dask"]


@pytest.mark.parametrize("args", [["--help"], ["--version"], ["predict", "--help"]])
def test_help_and_version_import_no_numpy(args, tmp_path):
    modules, stdout = modules_after(args, tmp_path)
    assert "bendpam" in modules
    for heavy in NOT_AT_START:
        assert loaded(modules, heavy) == [], f"`bendpam {' '.join(args)}` imports {heavy}"
    assert stdout.startswith("bendpam 0.") if args == ["--version"] else "Usage: bendpam" in stdout


def test_import_bendpam_alone_imports_no_numpy(tmp_path):
    code = "import json, sys, bendpam; print(json.dumps(sorted(sys.modules)))"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert loaded(set(json.loads(r.stdout)), "numpy") == []


def test_the_lazy_facade_still_gives_every_name():
    import bendpam

    for name in bendpam.__all__:
        assert getattr(bendpam, name) is not None, name
    assert bendpam.MomentLaw is __import__("bendpam.physics.law", fromlist=["MomentLaw"]).MomentLaw
    assert set(bendpam.__all__) <= set(dir(bendpam))
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        _ = bendpam.no_such_name


def test_predict_prints_without_pandas(tmp_path):
    modules, stdout = modules_after(["predict", "--preset", "be-pam", "--pressure-kpa", "150"], tmp_path)
    assert "numpy" in modules and "bendpam.physics.law" in modules  # it did compute
    for heavy in ("pandas", "matplotlib", "xarray", "dask", "scipy.io"):
        assert loaded(modules, heavy) == [], f"`bendpam predict` imports {heavy}"
    row = next(line for line in stdout.splitlines() if line.strip().startswith("150 "))
    assert len(row.split()) >= 4  # P, blocked moment, free curvature, free angle


def test_predict_table_is_the_dataframe_table():
    """The CLI's table from the columns equals the one from the DataFrame (the same numbers, rows, text)."""
    import bendpam
    from bendpam.cli.options import format_prediction_table, table_rows
    from bendpam.predict import prediction_columns

    a = bendpam.physics.presets.be_pam()
    P = [0.0, 100.0, 150.0, 250.0]  # 0 kPa: below the deadband, no bending (a note)
    cols, df = prediction_columns(a, P), bendpam.prediction_table(a, P)
    assert list(cols) == df.columns.tolist()
    assert format_prediction_table(cols, "t") == format_prediction_table(df, "t")
    rows = table_rows(cols)
    assert [r.pressure_kpa for r in rows] == P
    assert [r.note for r in rows] == df["note"].tolist() and [r.limit_note for r in rows] == df["limit_note"].tolist()


@pytest.fixture(scope="module")
def processed_dir(tmp_path_factory):
    """A small processed set (2 pressures, 2 cycles) written by bendpam."""
    import bendpam
    from bendpam.lab import RawTest
    from bendpam.lab.processing import process_tests, write_processed
    from bendpam.lab.simulate import SimulationSettings, simulate_test

    be, settings = bendpam.physics.presets.be_pam(), SimulationSettings(cycles=2, rate_hz=5.0, seed=1)
    raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv", pressure_kpa=p)
            for p in (100.0, 200.0)]
    folder = tmp_path_factory.mktemp("startup") / "proc"
    write_processed(process_tests(raws, keep_series=False), folder, figure=False)
    return folder


@pytest.mark.slow
def test_fit_without_a_figure_imports_no_matplotlib(processed_dir, tmp_path):
    modules, _ = modules_after(["fit", str(processed_dir), "--preset", "be-pam", "--out", str(tmp_path / "fit"),
                                "--no-figure", "--quiet"], tmp_path)
    assert (tmp_path / "fit" / "fit.json").is_file()
    assert loaded(modules, "matplotlib") == [], "`bendpam fit --no-figure` imports matplotlib"
    assert loaded(modules, "scipy.io") == [] and loaded(modules, "xarray") == []  # curves.npz, read by NumPy


@pytest.mark.slow
def test_fit_with_its_figure_imports_no_pyplot(processed_dir, tmp_path):
    modules, _ = modules_after(["fit", str(processed_dir), "--preset", "be-pam", "--out", str(tmp_path / "fit"),
                                "--quiet"], tmp_path)
    assert (tmp_path / "fit" / "figure7.png").is_file()
    assert "matplotlib" in modules
    assert loaded(modules, "matplotlib.pyplot") == []
    assert loaded(modules, "bendpam.design") == []  # one figure does not load the design layer (issue 24 item 6)
    assert loaded(modules, "bendpam.present.figures") == ["bendpam.present.figures", "bendpam.present.figures.lab",
                                                          "bendpam.present.figures.style"]  # the lab figure only


@pytest.mark.parametrize("columns", ["80", "60", "200"])
def test_root_help_is_typers_own_text(columns, monkeypatch):
    """``bendpam --help`` (built from option-less copies of the commands) is exactly what Typer prints."""
    import typer.main

    from bendpam.cli import app
    from bendpam.cli.app import root_help

    monkeypatch.setenv("COLUMNS", columns)
    light = root_help()
    group = typer.main.get_command(app)  # built after root_help(): the app is left as it was
    assert light == group.get_help(typer.Context(group, info_name="bendpam"))
    assert all(len(group.commands[c].params) > 3 for c in ("predict", "fit", "sweep"))


def test_no_arguments_and_help_print_the_root_help(capsys):
    from bendpam.cli.app import main, root_help

    for argv in ([], ["--help"]):
        assert main(argv) == 0
        assert capsys.readouterr().out == root_help() + "\n"


@pytest.mark.skipif(not Path("/dev/full").exists(), reason="needs /dev/full")
@pytest.mark.parametrize("args", [["--help"], ["--version"], []])
def test_a_full_stdout_is_one_error_line(args, tmp_path):
    """The short paths (root help, the entry's --version) keep the command line's error handling."""
    code = "import sys, bendpam_entry; sys.argv = ['bendpam', *sys.argv[1:]]; sys.exit(bendpam_entry.main())"
    with open("/dev/full", "w", encoding="utf-8") as full:
        r = subprocess.run([sys.executable, "-c", code, *args], stdout=full, stderr=subprocess.PIPE, text=True,
                           cwd=tmp_path, timeout=120)
    assert r.returncode == 2 and r.stderr == "bendpam: error: No space left on device\n", r.stderr


def test_the_command_table_is_the_apps():
    """``COMMANDS`` (what ``bendpam --help`` is built from) names every command of the app, in its order, with the
    module that registers it and the first paragraph of its help."""
    import typer.main

    from bendpam.cli import app
    from bendpam.cli.app import COMMANDS

    group = typer.main.get_command(app)
    assert list(group.commands) == list(COMMANDS)
    for name, cmd in group.commands.items():
        module, first = COMMANDS[name]
        assert " ".join((cmd.help or "").split("\n\n")[0].split()) == first, name
        assert not (cmd.hidden or cmd.deprecated or cmd.short_help), name
        where = cmd.callback.__module__ if cmd.callback is not None else f"bendpam.cli.{module}"
        assert where == f"bendpam.cli.{module}", name


def test_a_command_imports_its_own_module_only(tmp_path):
    modules, stdout = modules_after(["fit", "--help"], tmp_path)
    assert "--no-figure" in stdout
    assert sorted(m for m in modules if m.startswith("bendpam.cli")) == [
        "bendpam.cli", "bendpam.cli.app", "bendpam.cli.identify", "bendpam.cli.options"]
    modules, _ = modules_after(["--help"], tmp_path)
    assert sorted(m for m in modules if m.startswith("bendpam.cli")) == ["bendpam.cli", "bendpam.cli.app",
                                                                         "bendpam.cli.options"]


def test_the_app_read_after_one_command_has_every_command_in_order(tmp_path):
    """A command run in this process loads its module only; reading the app afterwards loads the rest, in order."""
    code = ("import json, sys, typer.main\n"
            "from bendpam.cli import app, main\n"
            "rc = main(['actuator', '--preset', 'be-pam'])\n"
            "print(json.dumps([rc, list(typer.main.get_command(app).commands)]))\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    from bendpam.cli.app import COMMANDS

    rc, names = json.loads(r.stdout.strip().splitlines()[-1])
    assert rc == 0 and names == list(COMMANDS), r.stderr


def test_the_figures_registered_on_first_use_are_the_modules_own(tmp_path):
    """``bendpam.present.figures`` registers each figure's name before its module is imported; the table it uses
    is what the modules register, and the first use of a name draws with the module's own function."""
    code = """
import importlib, json, sys
import bendpam.infra.accessors as acc
seen = {}
real = acc.register
def spy(name):
    def deco(fn):
        seen[name] = fn.__module__.rsplit(".", 1)[-1]
        return real(name)(fn)
    return deco
acc.register = spy
import bendpam.present.figures as figs
stand_ins = dict(seen)
seen.clear()
before = sorted(m for m in sys.modules if m.startswith("matplotlib"))
for module in sorted(set(figs._REGISTERED.values())):
    importlib.import_module("bendpam.present.figures." + module)
print(json.dumps([figs._REGISTERED, seen, before, acc.figure("figure7").__module__]))
"""
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, timeout=300)
    assert r.returncode == 0, r.stderr
    table, registered, matplotlib_before, figure7_home = json.loads(r.stdout.strip().splitlines()[-1])
    assert registered == table
    assert matplotlib_before == []
    assert figure7_home == "bendpam.present.figures.lab"



@pytest.fixture(scope="module")
def fine_fit(tmp_path_factory):
    """A processed set on a fine curvature grid (2000 points) and its fit with a loop."""
    import bendpam
    from bendpam.identify.fitting import fit
    from bendpam.lab import RawTest
    from bendpam.lab.processing import ProcessingOptions, process_tests
    from bendpam.lab.simulate import SimulationSettings, simulate_test

    be, settings = bendpam.physics.presets.be_pam(), SimulationSettings(cycles=2, rate_hz=5.0, seed=2)
    raws = [RawTest(simulate_test(be, p, settings=settings)[0], Path(f"be_{p:g}kPa.csv"), "csv", pressure_kpa=p)
            for p in (100.0, 200.0)]
    processed = process_tests(raws, keep_series=False, options=ProcessingOptions(grid_points=2000))
    return processed, fit(processed, be, free=("alpha0",))


def test_figure7_draws_a_fine_grid_with_what_its_pixels_show(fine_fit):
    """Figure 7 (a) draws each line with at most about 512 points and 26 markers per pressure, the last point kept;
    the model's loop is computed on the points drawn (the same values as on the whole grid)."""
    import numpy as np

    from bendpam.physics.hysteresis import loop_branches
    from bendpam.present.figures import figure7

    processed, res = fine_fit
    assert res.loop is not None
    ax = figure7(processed, res).axes[0]
    thin, thick = ax.collections[0].get_segments(), ax.collections[1].get_segments()
    markers = ax.collections[2].get_offsets()
    assert len(thin) == len(thick) == 2 * len(processed.results)
    assert all(500 <= len(seg) <= 512 for seg in thin + thick)
    assert len(markers) <= 26 * len(processed.results)
    r = processed.results[0]
    assert thin[0][-1].tolist() == [r.curvature_grid[-1], r.mean_loading[-1]]  # the end of the branch is drawn
    up, _ = loop_branches(res.actuator, res.loop, r.pressure_kpa, float(r.free_curvature[0]), r.curvature_grid,
                          res.model)
    drawn = np.searchsorted(r.curvature_grid, thick[0][:, 0])
    np.testing.assert_allclose(thick[0][:, 1], up[drawn], rtol=1e-12, atol=1e-9)


def test_shell_completion_completes_the_commands(tmp_path):
    """Typer's shell completion (``_BENDPAM_COMPLETE`` set, no arguments) answers with the commands, not the help."""
    import os

    code = "import sys, bendpam_entry; sys.argv = ['bendpam']; sys.exit(bendpam_entry.main())"
    env = {**os.environ, "_BENDPAM_COMPLETE": "complete_bash", "COMP_WORDS": "bendpam fi", "COMP_CWORD": "1"}
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path, env=env,
                       timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ["fit", "fit-material", "finger"]
