"""Write the command-line reference of bendpam as Markdown, from the Typer app itself.

Walks the click command tree of ``bendpam.cli.app`` (``typer.main.get_command``) and writes, for
every command, its usage line, its help text and a table of its arguments and options with the
same option strings, defaults and ranges as ``bendpam COMMAND --help``.  The documentation build
runs it (tools/docs_hooks.py), so the page cannot drift from the app.

    python tools/gen_cli_reference.py            # Markdown to stdout
    python tools/gen_cli_reference.py cli.md     # or to a file
"""

from __future__ import annotations

import inspect
import sys
from pathlib import Path
from typing import Any

# Sections of the reference: the module that defines a command -> (title, blurb).  A command from
# a module not listed here goes to "Other commands", so a new command never disappears.
SECTIONS: dict[str, tuple[str, str]] = {
    "bendpam.cli.predict": ("Predictions", "The models of the paper for one actuator (section 3)."),
    "bendpam.cli.lab": ("Cyclic tests", "Raw four-point-bending tests: simulate, inspect, process (section 2.2)."),
    "bendpam.cli.identify": ("Identification", "Fit the models to processed tests and the bladder to a tension test "
                             "(section 3.4)."),
    "bendpam.cli.report": ("Report", "From raw files to one HTML page."),
    "bendpam.cli.sweep": ("Design sweeps", "Parameters crossed with pressures."),
    "bendpam.cli.design": ("Fingers, grippers and wrists", "Section 4 of the paper."),
    "bendpam.cli.inverse": ("Inverse design", "Actuator parameters that meet design targets."),
}
OTHER = ("Other commands", "")


def _cell(text: Any) -> str:
    """Text for one Markdown table cell: one line, pipes escaped."""
    return " ".join(str(text).split()).replace("|", "\\|")


def _command_tree():
    import typer.main

    from bendpam.cli import app

    root = typer.main.get_command(app)
    ctx = root.make_context("bendpam", [], resilient_parsing=True)
    return root, ctx


def _params_table(cmd, ctx) -> list[str]:
    rows = []
    for param in cmd.params:
        if getattr(param, "hidden", False):
            continue
        record = param.get_help_record(ctx)
        if record is None:
            continue
        names, help_text = record
        kind = "argument" if param.param_type_name == "argument" else "option"
        if kind == "argument":
            help_text = getattr(param, "help", None) or help_text
            if param.required:
                help_text = f"{help_text} [required]"
        names = " ".join(str(names).split())  # in a code span: pipes stay cell content
        rows.append(f"| `{names}` | {_cell(help_text)} |")
    if not rows:
        return []
    return ["| Argument or option | Description |", "|---|---|", *rows]


def _section_of(cmd) -> str:
    callback = getattr(cmd, "callback", None)
    module = inspect.getmodule(callback) if callback is not None else None
    return module.__name__ if module is not None else ""


def render() -> str:
    """The whole reference as Markdown (a title, the global options, one section per command)."""
    root, ctx = _command_tree()
    out = [
        "# Command-line reference",
        "",
        "This page is generated from the `bendpam` Typer app by `tools/gen_cli_reference.py` each time the",
        "documentation is built; `bendpam COMMAND --help` prints the same text. Every value you type uses",
        "the [one unit rule](units.md): pressure in kPa, lengths in mm, force in N, moments in N·mm,",
        "curvature in 1/mm, angles in degrees. A bad value is one line `bendpam: error: ...` on stderr and",
        "exit status 2.",
        "",
        "## bendpam",
        "",
        "```text",
        root.get_usage(ctx),
        "```",
        "",
        inspect.cleandoc(root.help or ""),
        "",
        *_params_table(root, ctx),
        "",
    ]
    names = root.list_commands(ctx)
    grouped: dict[tuple[str, str], list[str]] = {}
    order = [*SECTIONS.values(), OTHER]
    for name in names:
        cmd = root.get_command(ctx, name)
        if cmd is None or getattr(cmd, "hidden", False):
            continue
        grouped.setdefault(SECTIONS.get(_section_of(cmd), OTHER), []).append(name)
    for section in order:
        if section not in grouped:
            continue
        title, blurb = section
        out += [f"## {title}", ""]
        if blurb:
            out += [blurb, ""]
        for name in grouped[section]:
            cmd = root.get_command(ctx, name)
            sub = cmd.make_context(name, [], parent=ctx, resilient_parsing=True)
            out += [
                f"### bendpam {name}",
                "",
                "```text",
                cmd.get_usage(sub),
                "```",
                "",
                inspect.cleandoc(cmd.help or ""),
                "",
                *_params_table(cmd, sub),
                "",
            ]
    return "\n".join(out).rstrip() + "\n"


def command_names() -> list[str]:
    """Every visible command of the app, as ``bendpam --help`` lists them."""
    root, ctx = _command_tree()
    return [n for n in root.list_commands(ctx) if not getattr(root.get_command(ctx, n), "hidden", False)]


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    text = render()
    if args:
        Path(args[0]).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
