"""MkDocs hooks of the bendpam documentation (``hooks:`` in mkdocs.yml).

At build time, without writing anything into the source tree:

* ``cli.md`` is generated from the Typer app (tools/gen_cli_reference.py);
* the walkthrough is run (tools/docs_figures.py, in a subprocess, cached in the temporary folder
  by a hash of the sources); its figures and report are published under ``figures/`` and the
  output of each command is shown under the matching command of docs/tutorial.md.  The commands of
  the tutorial must be those of examples/walkthrough.sh, in order (plus the extra commands
  docs_figures.py runs); a difference is a warning, so ``mkdocs build --strict`` fails;
* pages of docs/ that the ``nav`` of mkdocs.yml does not list (pages added later, such as
  limits.md, grasp.md or design.md) are added to the navigation, so a new page never breaks the
  build and never goes missing.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import re
import shutil
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path
from typing import Any

from mkdocs.structure.files import File, Files

ROOT = Path(__file__).resolve().parent.parent
TOOLS = ROOT / "tools"
if str(TOOLS) not in sys.path:
    sys.path.insert(0, str(TOOLS))

import docs_figures  # noqa: E402
import gen_cli_reference  # noqa: E402

log = logging.getLogger("mkdocs.hooks.bendpam")

#: Pages other work adds to docs/: where they go in the navigation, with their titles.  Any other
#: unlisted page goes before the changelog under its own first heading.
OPTIONAL_PAGES: tuple[tuple[str, str], ...] = (
    ("Limits of the models", "limits.md"),
    ("Grasping", "grasp.md"),
    ("Design notes", "design.md"),
)
GENERATED_PAGES = ("cli.md",)
FIGURES_DIR = "figures"


# ------------------------------------------------------------------------------------------------
# navigation
# ------------------------------------------------------------------------------------------------
def _nav_files(nav: Any) -> set[str]:
    found: set[str] = set()
    if isinstance(nav, str):
        found.add(nav)
    elif isinstance(nav, dict):
        for v in nav.values():
            found |= _nav_files(v)
    elif isinstance(nav, list):
        for v in nav:
            found |= _nav_files(v)
    return found


def _title(path: Path) -> str:
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.startswith("# "):
            return line[2:].strip()
    return path.stem.replace("-", " ").capitalize()


def on_config(config, **kwargs):
    nav = config.get("nav")
    if not nav:
        return config
    docs = Path(config["docs_dir"])
    listed = _nav_files(nav)
    extra: list[dict[str, str]] = []
    for title, page in OPTIONAL_PAGES:
        if page not in listed and (docs / page).is_file():
            extra.append({title: page})
            listed.add(page)
    for path in sorted(docs.glob("*.md")):
        if path.name not in listed and path.name not in GENERATED_PAGES:
            extra.append({_title(path): path.name})
    if extra:
        at = next((i for i, item in enumerate(nav) if "changelog.md" in _nav_files(item)), len(nav))
        nav[at:at] = extra
    return config


# ------------------------------------------------------------------------------------------------
# generated files
# ------------------------------------------------------------------------------------------------
def _sources_key() -> str:
    h = hashlib.sha256()
    paths = sorted((ROOT / "src").rglob("*.py"))
    paths += [docs_figures.SCRIPT, Path(docs_figures.__file__), *docs_figures.PAGE_FIGURES]
    for p in paths:
        h.update(str(p.relative_to(ROOT)).encode())
        h.update(p.read_bytes())
    h.update(sys.version.encode())
    return h.hexdigest()[:16]


def walkthrough_outputs() -> Path:
    """The folder of tools/docs_figures.py's results, made once per state of the sources."""
    cache = Path(tempfile.gettempdir()) / f"bendpam-docs-{_sources_key()}"
    if (cache / "outputs.json").is_file() and not os.environ.get("BENDPAM_DOCS_REFRESH"):
        return cache
    staging = Path(tempfile.mkdtemp(prefix="bendpam-docs-tmp-"))
    try:
        env = dict(os.environ, MPLBACKEND="Agg")
        r = subprocess.run([sys.executable, str(Path(docs_figures.__file__)), str(staging)], env=env,
                           capture_output=True, text=True, timeout=600)
        if r.returncode != 0:
            raise RuntimeError(f"tools/docs_figures.py failed:\n{r.stderr[-3000:]}")
        log.info(r.stdout.strip())
        shutil.rmtree(cache, ignore_errors=True)
        os.replace(staging, cache)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    for old in cache.parent.glob("bendpam-docs-*"):  # results of earlier states of the sources, over a day old
        if old != cache and old.is_dir() and time.time() - old.stat().st_mtime > 86400:
            shutil.rmtree(old, ignore_errors=True)
    return cache


_OUTPUTS: dict[str, Any] = {}


def on_files(files: Files, config, **kwargs) -> Files:
    files.append(File.generated(config, "cli.md", content=gen_cli_reference.render()))
    folder = walkthrough_outputs()
    record = json.loads((folder / "outputs.json").read_text(encoding="utf-8"))
    _OUTPUTS.clear()
    _OUTPUTS.update(record)
    for name in record["files"]:
        files.append(File.generated(config, f"{FIGURES_DIR}/{name}", abs_src_path=str(folder / name)))
    return files


# ------------------------------------------------------------------------------------------------
# the tutorial: commands checked against the walkthrough (docs_figures.check_tutorial), outputs inserted
# ------------------------------------------------------------------------------------------------
def _output_block(commands: list[str], outputs: dict[str, dict]) -> str:
    parts = []
    for c in commands:
        run = outputs.get(c)
        if run is None:
            continue
        text = (run["stdout"] + run["stderr"]).rstrip()
        if text:
            parts.append(f"$ {c}\n{text}")
    if not parts:
        return ""
    body = textwrap.indent("```text\n" + "\n\n".join(parts) + "\n```", "    ")
    return f'\n??? example "Output"\n\n{body}\n\n'


# ------------------------------------------------------------------------------------------------
# the table of bendpam.__all__ on api/bendpam.md
# ------------------------------------------------------------------------------------------------
EXPORTS_MARKER = "<!-- bendpam-exports -->"


def api_pages(docs_dir: Path) -> dict[str, str]:
    """``module name -> page`` (relative to ``api/``) from the ``::: module`` lines of docs/api."""
    pages = {}
    for page in sorted((docs_dir / "api").glob("*.md")):
        for name in re.findall(r"^::: (\S+)", page.read_text(encoding="utf-8"), re.MULTILINE):
            pages.setdefault(name, page.name)
    return pages


def exports_table(docs_dir: Path) -> str:
    """A Markdown table of ``bendpam.__all__``: name (linked to its documentation), kind, summary, page."""
    import importlib
    import inspect
    import types

    import bendpam

    pages = api_pages(docs_dir)
    rows = ["| Name | Kind | Summary | Page |", "|---|---|---|---|"]
    for name in bendpam.__all__:
        obj = getattr(bendpam, name)
        if isinstance(obj, types.ModuleType):
            kind, ident, home = "module", obj.__name__, obj.__name__
        elif inspect.isclass(obj) or inspect.isfunction(obj):
            kind = "class" if inspect.isclass(obj) else "function"
            ident, home = f"{obj.__module__}.{obj.__qualname__}", obj.__module__
        else:  # a constant (no anchor of its own): the documented module that exports it
            kind, ident = "constant", ""
            home = next(m for m in pages if m != "bendpam" and obj is getattr(importlib.import_module(m), name, None)
                        and name in getattr(importlib.import_module(m), "__all__", ()))
        doc = inspect.getdoc(obj) if kind != "constant" else ""
        summary = (doc or "").strip().split("\n\n")[0].replace("\n", " ")
        summary = re.sub(r":[a-z]+:`~?([^`]+)`", r"`\1`", summary).replace("|", "\\|")
        link = f"[`{name}`][{ident}]" if ident else f"`{name}`"
        rows.append(f"| {link} | {kind} | {summary} | [{home}]({pages.get(home, '')}) |")
    return "\n".join(rows) + "\n"


def on_page_markdown(markdown: str, page, config, files, **kwargs) -> str:
    if page.file.src_uri == "api/bendpam.md" and EXPORTS_MARKER in markdown:
        return markdown.replace(EXPORTS_MARKER, exports_table(Path(config["docs_dir"])))
    if page.file.src_uri != "tutorial.md":
        return markdown
    for problem in docs_figures.check_tutorial(markdown):
        log.warning(f"docs/tutorial.md: {problem}")
    outputs = {run["command"]: run for run in _OUTPUTS.get("commands", [])}

    def add_output(m: re.Match) -> str:
        return m.group(0) + _output_block(docs_figures.block_commands(m.group(1)), outputs)

    return docs_figures.BASH_BLOCK.sub(add_output, markdown)
