"""The documentation: examples in the docstrings, the site's generated pages and its checks.

* Every public function and class (``bendpam.__all__``, the ``__all__`` of the subpackages and of
  the modules ``bendpam`` exports) carries a ``>>>`` example, except the short list
  :data:`EXEMPT`, each with its reason.
* The examples pass under ``pytest --doctest-modules`` (the README's test command collects them
  from src/bendpam, pyproject.toml) and write no file into the folder they run in (each runs in
  an empty folder that must stay empty: the root conftest.py).
* The tutorial (docs/tutorial.md) shows the commands of examples/walkthrough.sh in order; the CLI
  reference names every command and option of the app; the nav tolerates pages added later; the
  Markdown pages' own ``>>>`` examples pass.

The site itself is built by ``.ci/run`` (``mkdocs build --strict``).
"""

from __future__ import annotations

import doctest
import importlib
import inspect
import os
import re
import subprocess
import sys
import types
from pathlib import Path

import pytest

import bendpam

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
SRC = ROOT / "src" / "bendpam"
sys.path.insert(0, str(ROOT / "tools"))

import docs_figures  # noqa: E402

#: Public callables allowed without a ``>>>`` example: name -> reason.
EXEMPT: dict[str, str] = {}


def public_modules() -> list[types.ModuleType]:
    """Every module of the package (aliases of moved modules and private modules aside): issue 20 asks
    for an example on every public name of every module's ``__all__``, not only ``bendpam.__all__``."""
    names = ["bendpam"]
    for path in sorted(SRC.rglob("*.py")):
        rel = path.relative_to(SRC.parent).with_suffix("")
        parts = list(rel.parts[:-1] if rel.name == "__init__" else rel.parts)
        alias = "alias_module(__name__" in path.read_text(encoding="utf-8")
        if alias or any(part.startswith("_") for part in parts[1:]):
            continue
        names.append(".".join(parts))
    return [importlib.import_module(name) for name in dict.fromkeys(names)]


def public_callables() -> dict[str, object]:
    """``module.qualname`` of the defining module -> object, for every exported function and class."""
    found: dict[str, object] = {}
    for mod in public_modules():
        for name in getattr(mod, "__all__", ()):
            obj = getattr(mod, name)
            if inspect.isfunction(obj) or inspect.isclass(obj):
                found.setdefault(f"{obj.__module__}.{obj.__qualname__}", obj)
    return found


def has_example(obj: object) -> bool:
    return ">>>" in (obj.__doc__ or "")


def test_public_api_is_found():
    names = public_callables()
    for expected in ("bendpam.predict.blocked_moment", "bendpam.physics.actuator.Actuator",
                     "bendpam.design.finger.solve_finger", "bendpam.lab.readers.read_test",
                     "bendpam.physics.models.energy.coefficients", "bendpam.physics.presets.be_pam"):
        assert expected in names


def test_every_public_callable_has_an_example():
    missing = sorted(n for n, obj in public_callables().items() if not has_example(obj) and n not in EXEMPT)
    assert not missing, "public functions and classes without a >>> example:\n  " + "\n  ".join(missing)


def test_exemptions_are_current():
    names = public_callables()
    stale = [n for n in EXEMPT if n not in names or has_example(names[n])]
    assert not stale, f"remove from EXEMPT (gone or now with an example): {stale}"
    assert all(reason.strip() for reason in EXEMPT.values())


def test_pytest_collects_the_docstring_examples():
    import tomllib

    ini = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["pytest"]["ini_options"]
    assert "src/bendpam" in ini["testpaths"]
    assert "--doctest-modules" in ini["addopts"].split()


def test_doctests_run_in_an_empty_folder_that_must_stay_empty(tmp_path):
    """The root conftest.py runs each docstring example in an empty folder and fails one that writes there.

    (The examples themselves run once, collected by ``--doctest-modules``.)
    """
    (tmp_path / "writes.py").write_text('def f():\n    """\n    >>> open("left.txt", "w").write("x")\n    1\n    """\n')
    (tmp_path / "clean.py").write_text('def g():\n    """\n    >>> 1 + 1\n    2\n    """\n')
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "conftest", "--doctest-modules",
           "-c", os.devnull, "--rootdir", str(tmp_path), "writes.py", "clean.py"]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    r = subprocess.run(cmd, cwd=tmp_path, capture_output=True, text=True, timeout=120, env=env)
    assert r.returncode == 1, r.stdout[-3000:] + r.stderr[-2000:]
    assert "the example wrote into the folder it ran in: left.txt" in r.stdout
    assert re.search(r"2 passed, 1 error", r.stdout), r.stdout[-2000:]
    assert sorted(p.name for p in tmp_path.iterdir() if p.suffix != ".py" and p.name != "__pycache__") == []


def test_markdown_pages_examples_pass():
    """The ``>>>`` examples in ```pycon blocks of docs/*.md (index, units)."""
    parser, runner = doctest.DocTestParser(), doctest.DocTestRunner(optionflags=doctest.ELLIPSIS)
    ran = 0
    for page in sorted(DOCS.glob("*.md")):
        for i, block in enumerate(re.findall(r"^```pycon\n(.*?)^```", page.read_text(encoding="utf-8"),
                                              re.MULTILINE | re.DOTALL)):
            test = parser.get_doctest(block, {}, f"{page.name}[{i}]", str(page), 0)
            result = runner.run(test, clear_globs=True)
            assert result.failed == 0, f"{page.name}: example {i} fails"
            ran += result.attempted
    assert ran >= 4


# ------------------------------------------------------------------------------------------------
# the tutorial and the walkthrough
# ------------------------------------------------------------------------------------------------
def test_walkthrough_parses_into_steps():
    steps = docs_figures.walkthrough_steps()
    assert len(steps) == 10
    assert all(title and cmds for title, cmds in steps)
    assert all(c.startswith("bendpam ") and "\\" not in c and "  " not in c for _, cmds in steps for c in cmds)
    assert docs_figures.walkthrough_commands()[0] == "bendpam predict --preset be-pam --pressure-kpa 100 150 200"


def test_tutorial_shows_the_walkthrough_in_order():
    text = (DOCS / "tutorial.md").read_text(encoding="utf-8")
    assert docs_figures.check_tutorial(text) == []
    steps = re.findall(r"^## (\d+)\. ", text, re.MULTILINE)
    assert steps == [str(i + 1) for i in range(len(docs_figures.walkthrough_steps()))]
    for name in docs_figures.FIGURES:
        assert f"figures/{name}" in text, name


def test_readme_shows_the_walkthrough():
    readme = (DOCS.parent / "README.md").read_text(encoding="utf-8")
    section = readme[readme.index("## Walkthrough"):readme.index("## Command line")]
    assert docs_figures.tutorial_commands(section) == docs_figures.walkthrough_commands()


def test_tutorial_check_finds_a_difference():
    text = (DOCS / "tutorial.md").read_text(encoding="utf-8")
    changed = text.replace("--seed 1", "--seed 7", 1)
    assert changed != text
    assert docs_figures.check_tutorial(changed)
    dropped = text.replace("bendpam inspect raw-be\n", "", 1)
    assert docs_figures.check_tutorial(dropped)


def test_block_commands_joins_continuations():
    body = "bendpam a --x 1 \\\n    --y 2\n# comment\nbendpam  b\nls\n"
    assert docs_figures.block_commands(body) == ["bendpam a --x 1 --y 2", "bendpam b"]


# ------------------------------------------------------------------------------------------------
# the command-line reference
# ------------------------------------------------------------------------------------------------
def test_cli_reference_names_every_command_and_option():
    import gen_cli_reference
    import typer.main

    from bendpam.cli import app

    text = gen_cli_reference.render()
    root = typer.main.get_command(app)
    ctx = root.make_context("bendpam", [], resilient_parsing=True)
    names = gen_cli_reference.command_names()
    assert {"predict", "process", "inspect", "fit", "report", "sweep", "finger"} <= set(names)
    for name in names:
        assert f"### bendpam {name}\n" in text, name
        section = text.split(f"### bendpam {name}\n", 1)[1].split("\n### ", 1)[0]
        for param in root.get_command(ctx, name).params:
            if not getattr(param, "hidden", False):
                for opt in param.opts:  # an argument is shown by its metavar (FILES..., PROCESSED_DIR)
                    shown = param.metavar if param.param_type_name == "argument" and param.metavar else opt
                    assert shown in section, (name, shown)
    assert text.count("### bendpam ") == len(names)


# ------------------------------------------------------------------------------------------------
# the site's configuration
# ------------------------------------------------------------------------------------------------
def _nav_pages(nav) -> set[str]:
    if isinstance(nav, str):
        return {nav}
    items = nav.values() if isinstance(nav, dict) else nav
    return set().union(*(_nav_pages(v) for v in items))


def test_nav_pages_exist():
    yaml = pytest.importorskip("yaml")

    class Loader(yaml.SafeLoader):
        pass

    Loader.add_multi_constructor("", lambda loader, suffix, node: None)  # mkdocs' !ENV and friends
    config = yaml.load((ROOT / "mkdocs.yml").read_text(encoding="utf-8"), Loader=Loader)
    pages = _nav_pages(config["nav"])
    generated = {"cli.md"}
    assert pages - generated and all((DOCS / p).is_file() for p in pages - generated)
    for page in (DOCS / "api").glob("*.md"):
        assert f"api/{page.name}" in pages, page.name


def is_alias(name: str) -> bool:
    """A module kept only as an alias of its new home (``bendpam.law``), read as text, not imported."""
    parts = name.split(".")[1:]
    for i in range(1, len(parts) + 1):  # the module or a package above it
        rel = Path(*parts[:i])
        for path in (SRC / rel.with_suffix(".py"), SRC / rel / "__init__.py"):
            if path.is_file() and "alias_module(__name__" in path.read_text(encoding="utf-8"):
                return True
    return False


def test_every_module_has_an_api_page():
    """Each module of the package (the command line aside) is rendered by a ``::: module`` line."""
    import pkgutil

    modules = {m.name for m in pkgutil.walk_packages(bendpam.__path__, "bendpam.", onerror=lambda name: None)
               if not m.name.startswith("bendpam.cli") and not m.name.rpartition(".")[2].startswith("_")
               and not is_alias(m.name)}
    shown = set()
    for page in (DOCS / "api").glob("*.md"):
        shown |= set(re.findall(r"^::: (\S+)", page.read_text(encoding="utf-8"), re.MULTILINE))
    assert not modules - shown, f"add to a page of docs/api/: {sorted(modules - shown)}"
    assert not shown - modules - {"bendpam"}, sorted(shown - modules)


def test_nav_adds_pages_written_later(tmp_path):
    pytest.importorskip("mkdocs")
    import docs_hooks

    (tmp_path / "limits.md").write_text("# Limits\n")
    (tmp_path / "notes-on-x.md").write_text("Intro.\n\n# Notes on X\n")
    (tmp_path / "index.md").write_text("# Home\n")
    nav = [{"Home": "index.md"}, {"Python API": ["api/index.md"]}, {"Changelog": "changelog.md"}]
    config = docs_hooks.on_config({"nav": nav, "docs_dir": str(tmp_path)})
    assert config["nav"] == [{"Home": "index.md"}, {"Python API": ["api/index.md"]},
                             {"Limits of the models": "limits.md"}, {"Notes on X": "notes-on-x.md"},
                             {"Changelog": "changelog.md"}]


def test_griffe_extension_makes_rst_readable():
    pytest.importorskip("griffe")
    import docs_griffe

    text = ("See :func:`~bendpam.predict.moment` and :class:`bendpam.Actuator`, in N*mm (`a*b`).  Quick start::\n\n"
            "    x = 2*y\n\n>>> 1 + 1\n2\n\nExamples\n--------\n>>> 2 + 2\n4")
    out = docs_griffe.markdown_docstring(text)
    assert "See `moment` and `bendpam.Actuator`, in N\\*mm (`a*b`).  Quick start:\n\n    x = 2*y\n" in out
    assert "```pycon\n>>> 1 + 1\n2\n```" in out
    assert out.endswith("Examples\n--------\n>>> 2 + 2\n4")  # the Examples section is Griffe's own
