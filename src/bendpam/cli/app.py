"""The ``bendpam`` Typer application and its entry point :func:`main`.

``main`` turns the library's :class:`~bendpam.errors.BendpamError` into one line
``bendpam: error: ...`` on stderr and exit status 2; SIGINT and SIGTERM into one line and 130/143:
``bendpam: interrupted; no outputs were changed`` before any output was committed,
``bendpam: interrupted after writing DIR`` after.  Any other exception is a bug: one line saying so
and where to report it, exit status 1 (``--debug`` prints the traceback).  A result beyond a
plausibility bound (:class:`~bendpam.errors.PlausibilityWarning`) is one ``bendpam: warning: ...``
line, like every other warning of a command.

Every output a command writes (through :func:`bendpam.cli.options.output_set` /
:func:`~bendpam.cli.options.output_file`, or :class:`~bendpam.infra.outputs.OutputSet` /
:class:`~bendpam.infra.outputs.OutputFile` directly) joins one
:class:`~bendpam.infra.outputs.OutputGroup`: the outputs of a command are committed together when
it returns with status 0, or all rolled back.
"""

# no ``from __future__ import annotations``: Typer reads the annotations of the commands as objects (start-up)

import os
import re
import sys
import traceback
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Annotated, Any, Optional

import typer

from bendpam.cli.options import FORCE_HELP, RUN_ARGS, RUN_COMMAND, RUN_FORCE, WROTE_LINES

__all__ = ["COMMANDS", "DECLARATION_HINT_CLI", "ISSUES_URL", "LazyTyper", "app", "cli_words", "main", "root_help"]

ISSUES_URL = "the bendpam issue tracker (include the command line and bendpam --version)"

#: Every command of ``bendpam`` in the order of its help: name -> (the module of :mod:`bendpam.cli` that registers
#: it, the first paragraph of its help on one line).  ``bendpam --help`` is built from this table without importing
#: the command modules, and a command runs with its own module imported only (:class:`LazyTyper`); a test checks
#: the table against the app's commands.
COMMANDS: dict[str, tuple[str, str]] = {
    "fit": ("identify", "Identify model parameters (alpha0, C10, C01, ...) from processed cyclic tests (section 3.4)."),
    "fit-material": ("identify", "Fit Mooney-Rivlin C10, C01 to a uniaxial tension test of the bladder material."),
    "design": ("inverse", "Inverse design: actuator parameters within ranges that meet targets at pressures, with "
               "safety margins."),
    "inspect": ("lab", "What the reader understood of each file (format, encoding, channels, units, values), before "
                "processing."),
    "process": ("lab", "Process raw four-point-bending cyclic tests into moment-curvature curves and Table 2 values."),
    "simulate-test": ("lab", "Write the raw files a testing machine would record for a model actuator (a virtual "
                      "test)."),
    "predict": ("predict", "Blocked moment and free bending curvature/angle at each pressure (and, with --cycle, the "
                "loop)."),
    "curve": ("predict", "Moment-curvature curves M(P, k') as CSV or a figure."),
    "stresses": ("predict", "Force-balance internal stresses around the cross-section (eq 37-48)."),
    "actuator": ("predict", "Show an actuator (TOML, derived values, lock-up limits) or save it as an editable TOML "
                 "file."),
    "demo": ("predict", "Predictions for the paper's BE-PAM and BC-PAM with both models, and a moment-curvature "
             "figure."),
    "sweep": ("sweep", "Design sweep: actuator parameters crossed with pressures (in-process or on Dask)."),
    "report": ("report", "Process raw cyclic tests, fit the models and write ONE self-contained HTML report."),
    "finger": ("design", "Equilibrium shape and tip pose of a finger under tip force, tip mass and self-weight."),
    "grasp": ("design", "Grip (pull-out) force of an N-finger gripper on spheres against diameter and pressure."),
    "wrist": ("design", "Bending angle of a four-actuator wrist per direction, and the load it holds horizontally."),
    "hand": ("hand", "Pose, reachable workspace and Kapandji test of the soft humanoid hand (BE-PAM fingers, "
             "two-segment thumb)."),
    "export": ("export", "Export an actuator's finger or gripper, or the soft hand, to a simulator (MuJoCo)."),
}


def _command_name(info: Any) -> str:
    """The name of a registered command (Typer's name for it: the function's, with dashes)."""
    return info.name or typer.main.get_command_name(getattr(info.callback, "__name__", ""))


class LazyTyper(typer.Typer):
    """A Typer app whose command modules (:data:`COMMANDS`) are imported when its commands are first read.

    Reading :attr:`registered_commands` or :attr:`registered_groups` -- Typer does when it builds
    the command line, and so do ``typer.main.get_command(app)`` and the CLI reference -- imports
    every command module, in the order of :data:`COMMANDS`, and orders the commands as that table.
    Inside :meth:`only` they are what the modules imported so far registered: :func:`main` runs a
    command with its own module imported only (start-up).

    >>> from bendpam.cli.app import app
    >>> [_command_name(c) for c in app.registered_commands][:3]
    ['fit', 'fit-material', 'design']
    """

    def __init__(self, **kwargs: Any) -> None:
        self._pending: list[str] = []
        self._loading = self._partial = False
        self._commands: list[Any] = []
        self._groups: list[Any] = []
        super().__init__(**kwargs)
        self._pending = list(dict.fromkeys(module for module, _ in COMMANDS.values()))

    @property  # type: ignore[override]
    def registered_commands(self) -> list[Any]:
        self._load_all()
        return self._commands

    @registered_commands.setter
    def registered_commands(self, value: list[Any]) -> None:
        self._commands = value

    @property  # type: ignore[override]
    def registered_groups(self) -> list[Any]:
        self._load_all()
        return self._groups

    @registered_groups.setter
    def registered_groups(self, value: list[Any]) -> None:
        self._groups = value

    def _load_all(self) -> None:
        if self._pending and not (self._loading or self._partial):
            self.load(list(self._pending))
            order = {name: i for i, name in enumerate(COMMANDS)}
            for infos in (self._commands, self._groups):
                infos.sort(key=lambda info: order.get(_command_name(info), len(order)))

    def load(self, modules: list[str]) -> None:
        """Import these command modules of :mod:`bendpam.cli` (once each) and register their commands."""
        import importlib

        from bendpam.cli.options import use_bendpam_commands

        self._loading = True
        try:
            for name in modules:
                if name in self._pending:
                    self._pending.remove(name)
                    register = getattr(importlib.import_module(f"bendpam.cli.{name}"), "register", None)
                    if register is not None:
                        register(self)
            use_bendpam_commands(self)  # one grammar for lists, --force where a command writes, readable help
        finally:
            self._loading = False

    @contextmanager
    def only(self, name: str | None) -> Iterator[None]:
        """Within this block the app has the commands of ``name``'s module only (all for another name)."""
        if name not in COMMANDS:
            yield
            return
        self.load([COMMANDS[name][0]])
        self._partial = True
        try:
            yield
        finally:
            self._partial = False


app = LazyTyper(
    add_completion=True,  # --install-completion / --show-completion (README "Command line")
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
    help="bendpam: models, tests and design tools for bending pneumatic artificial muscles. "
         "Units: pressure kPa, lengths mm, force N, moments N·mm, curvature 1/mm, angles deg.",
)


def _version(value: bool) -> None:
    if value:
        from bendpam.infra.manifest import bendpam_version  # (bendpam_entry answers a lone --version the same way)

        typer.echo(f"bendpam {bendpam_version()}")
        raise typer.Exit(0)


@app.callback()
def _root(
    ctx: typer.Context,
    version: Annotated[Optional[bool], typer.Option("--version", callback=_version, is_eager=True,
                                                    help="Print the version and exit.")] = None,
    debug: Annotated[bool, typer.Option("--debug", help="Print the traceback of an internal error.")] = False,
    force: Annotated[bool, typer.Option("--force", help=FORCE_HELP + "  Every command that writes also takes it "
                                        "after its name (see its --help).")] = False,
) -> None:
    """bendpam: models, tests and design tools for bending pneumatic artificial muscles."""
    RUN_COMMAND.set(ctx.invoked_subcommand)
    RUN_FORCE.set(force)


# Typer >= 0.20 vendors click; find its exception base class without importing click directly.
# Typed as type[Any]: the class is found at run time, so its attributes (format_message) are not known statically.
_ClickException: type[Any] = next(c for c in typer.BadParameter.__mro__ if c.__name__ == "ClickException")


def _one_line(exc: BaseException) -> str:
    from bendpam.infra.targets import OutputRefused

    if isinstance(exc, OutputRefused) and exc.forceable:
        kind = next((k for k in ("folder", "file") if exc.reason.startswith(f"output {k}")), "")
        moved = f" (the old {kind} is then moved aside, not deleted)" if kind else ""
        return f"{exc.reason}; choose another place, or add --force{moved}"
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """``warnings.showwarning`` while a command runs: bendpam's warnings are one ``bendpam: warning:`` line each.

    So is a ``UserWarning`` located in bendpam's own code (a library function warning its caller,
    here a command: ``curves.npz`` not used, and why).

    A :class:`~bendpam.errors.ModelMismatchWarning` or
    :class:`~bendpam.errors.OutsideTestedRangeWarning` is printed once per command, however many
    computations of the command raise it.
    """
    from bendpam.errors import ModelMismatchWarning, OutsideTestedRangeWarning, PlausibilityWarning

    if issubclass(category, PlausibilityWarning | ModelMismatchWarning | OutsideTestedRangeWarning):
        text = _one_line(message) if isinstance(message, BaseException) else str(message).strip().splitlines()[0]
        if "max_pressure_kpa" in text:
            text += _MAX_PRESSURE_HINT
        if not issubclass(category, PlausibilityWarning):
            shown = _SHOWN.get()
            if text in shown:
                return
            _SHOWN.set(shown | {text})
        typer.echo(f"bendpam: warning: {text}", err=True)
    elif issubclass(category, UserWarning) and str(filename).startswith(_PACKAGE):  # raised for bendpam's own code
        typer.echo(f"bendpam: warning: {str(message).strip().splitlines()[0]}", err=True)
    else:
        _SHOW_WARNING(message, category, filename, lineno, file, line)


#: The folder of the bendpam package: a warning located in it is about bendpam's own call (one line too).
_PACKAGE = os.path.dirname(os.path.dirname(os.path.abspath(__file__))) + os.sep


#: The once-per-command warnings already printed by the running command.
_SHOWN: ContextVar[frozenset[str]] = ContextVar("bendpam_shown_warnings", default=frozenset())
_SHOW_WARNING = warnings.showwarning
#: Where a command-line user sets the burst limit (added to a message that names it).
_MAX_PRESSURE_HINT = (" (max_pressure_kpa is a key of the [actuator] table of an --actuator file; "
                      "`bendpam actuator --preset NAME --out FILE.toml` writes one to edit)")


def _lift_force(args: list[str]) -> list[str]:
    """``--force`` after a command that has no such option of its own goes to the root options."""
    end = args.index("--") if "--" in args else len(args)
    if "--force" not in args[:end]:
        return args
    name = next((a for a in args[:end] if not a.startswith("-")), None)
    group = typer.main.get_command(app)
    cmd = getattr(group, "commands", {}).get(name) if name else None
    if cmd is not None and any("--force" in getattr(p, "opts", ()) for p in cmd.params):
        return args
    rest = list(args)
    rest.remove("--force")
    return ["--force", *rest]


def _command_of(args: list[str]) -> str | None:
    """The command a command line runs: its first word that is not an option (the root options take no value).

    >>> _command_of(["--force", "fit", "proc", "--out", "f"]), _command_of(["--install-completion"])
    ('fit', None)
    """
    return next((a for a in args if not a.startswith("-")), None)


def _run(args: list[str]) -> Any:
    """Run the app with every output of the command in one group (committed when it returns 0)."""
    from bendpam.infra.outputs import OutputGroup

    group = OutputGroup()
    wrote: list[str] = []
    token = WROTE_LINES.set(wrote)
    try:
        with group:
            rv = app(args=args, prog_name="bendpam", standalone_mode=False)
            if isinstance(rv, int) and not isinstance(rv, bool) and rv != 0:
                group.abort()  # a command that fails keeps no outputs
                wrote.clear()
    finally:
        WROTE_LINES.reset(token)
    for line in wrote:  # only now is every output in place
        typer.echo(line)
    for m in group.members:
        if m.moved_aside is not None:
            typer.echo(f"bendpam: warning: the old content of {m.shown} was moved to {m.moved_aside}", err=True)
    return rv


#: What the command line says where the library says how to get a format declaration.
DECLARATION_HINT_CLI = (
    "describe the file's layout in a format declaration and give it with --format-file "
    "('bendpam inspect FILE --suggest' drafts one)"
)


def option_words(text: str, args: list[str]) -> str:
    """A library refusal that opens with the field it checked (``rate_hz = -5.0 is outside ...``) in the command
    line's words, when the user gave that field as an option: ``--rate-hz -5.0 is outside ...``.

    >>> option_words("rate_hz = -5.0 is outside the allowed range [0.001, 1e+06]", ["simulate-test", "--rate-hz=-5"])
    '--rate-hz -5.0 is outside the allowed range [0.001, 1e+06]'
    >>> option_words("rate_hz = -5.0 is outside the allowed range [0.001, 1e+06]", ["simulate-test"])
    'rate_hz = -5.0 is outside the allowed range [0.001, 1e+06]'
    """
    m = re.match(r"([a-z][a-z0-9_]*) = ", text)
    if m is None:
        return text
    option = "--" + m.group(1).replace("_", "-")
    given = any(a == option or a.startswith(option + "=") for a in args)
    return f"{option} {text[m.end():]}" if given else text


def cli_words(text: str) -> str:
    """A library message in the command line's words (its options instead of the library's functions).

    >>> from bendpam.lab.declaration import DECLARATION_HINT
    >>> cli_words(f"x.csv:3: no header row; or {DECLARATION_HINT}")
    "x.csv:3: no header row; or describe the file's layout in a format declaration and give it with --format-file ..."
    >>> cli_words("x.csv:503: time does not increase ... (read with repair=True to drop such samples)")
    'x.csv:503: time does not increase ... (read with --repair to drop such samples)'
    """
    from bendpam.lab.declaration import DECLARATION_HINT

    return text.replace(DECLARATION_HINT, DECLARATION_HINT_CLI).replace("read with repair=True", "read with --repair")


def root_help() -> str:
    """The text of ``bendpam --help``, built from :data:`COMMANDS` without importing the commands.

    Typer builds every command's options from its signature before it shows the root help, which
    lists only the commands' names and first lines.  This builds the root help of a copy of the app
    whose commands have the names and first paragraphs of :data:`COMMANDS` but no options: the same
    text (a test compares them) in a fraction of the start-up.

    >>> root_help().splitlines()[0]
    'Usage: bendpam [OPTIONS] COMMAND [ARGS]...'
    """
    import copy

    from typer.models import CommandInfo

    light = copy.copy(app)
    light._pending, light._groups, light._commands = [], [], []
    for name, (_, text) in COMMANDS.items():

        def nothing() -> None:
            """(a command without options)"""

        nothing.__doc__ = text
        light._commands.append(CommandInfo(name=name, callback=nothing))
    group = typer.main.get_command(light)
    return group.get_help(typer.Context(group, info_name="bendpam"))


def _print_root_help() -> int:
    """Print :func:`root_help`; a full disk or a closed pipe is one line and exit status 2, as in :func:`main`."""
    try:
        typer.echo(root_help())
    except OSError as exc:
        typer.echo(f"bendpam: error: {exc.strerror or _one_line(exc)}", err=True)
        return 2
    return 0


def _unexpected(exc: BaseException, debug: bool) -> int:
    """An exception no other branch of :func:`main` took: an interrupt behind it (a signal during a module's import
    comes back wrapped, :func:`~bendpam.infra.signals.interrupt_behind`), or a bug (exit 1, one line)."""
    from bendpam.infra.signals import Interrupted, interrupt_behind, interrupted_line

    cause = interrupt_behind(exc)
    if cause is not None:
        typer.echo(interrupted_line(), err=True)
        return cause.exit_code if isinstance(cause, Interrupted) else 130
    if debug:
        traceback.print_exc()
    typer.echo(f"bendpam: internal error ({type(exc).__name__}: {_one_line(exc)}); this is a bug in bendpam, "
               f"please report it to {ISSUES_URL}" + ("" if debug else "; --debug shows the traceback"), err=True)
    return 1


def main(argv: list[str] | None = None) -> int:
    """Entry point: run the app; user errors are one line and exit code 2, bugs exit code 1.

    >>> main(["--version"])
    bendpam ...
    0
    >>> main(["predict", "--preset", "xx-pam", "--pressure-kpa", "100"])   # one line on stderr
    2
    """
    args = list(sys.argv[1:] if argv is None else argv)
    from bendpam.infra.console import plain_streams

    plain_streams()  # a pipe on Windows is cp1252: write what it lacks (theta, mu, <=) in ASCII words, not a crash
    if (not args or args == ["--help"]) and "_BENDPAM_COMPLETE" not in os.environ:  # (shell completion: Typer's)
        return _print_root_help()  # nothing runs: no output group, no signal handling (start-up)
    from bendpam.errors import BendpamError
    from bendpam.infra.signals import Interrupted, forget_written, interrupted_line, interrupts, quiet_logging

    debug = "--debug" in args
    forget_written()
    tokens = (RUN_ARGS.set(list(args)), RUN_COMMAND.set(None), RUN_FORCE.set(False))
    shown = _SHOWN.set(frozenset())
    try:
        with app.only(_command_of(args)):  # only the command's own module is imported (start-up)
            args = _lift_force(args)
            with interrupts(on_signal=quiet_logging), warnings.catch_warnings():
                warnings.showwarning = _show_warning
                rv = _run(args)
        if isinstance(rv, int) and not isinstance(rv, bool):  # typer.Exit(code) inside a command
            return rv
    except Interrupted as exc:
        typer.echo(interrupted_line(), err=True)
        return exc.exit_code
    except typer.Exit as exc:
        return exc.exit_code
    except (typer.Abort, KeyboardInterrupt):
        typer.echo(interrupted_line(), err=True)
        return 130
    except _ClickException as exc:
        typer.echo(f"bendpam: error: {exc.format_message()}", err=True)
        return 2
    except BendpamError as exc:  # in the command line's words: its options (given), not the library's fields
        text = option_words(cli_words(_one_line(exc)), args)
        typer.echo(f"bendpam: error: {text}{_MAX_PRESSURE_HINT if 'max_pressure_kpa to go higher' in text else ''}",
                   err=True)
        return 2
    except (FileNotFoundError, PermissionError, IsADirectoryError, NotADirectoryError, FileExistsError) as exc:
        where = f": {exc.filename}" if exc.filename else ""
        typer.echo(f"bendpam: error: {exc.strerror or _one_line(exc)}{where}", err=True)
        return 2
    except OSError as exc:
        where = f": {exc.filename}" if exc.filename else ""
        typer.echo(f"bendpam: error: {exc.strerror or _one_line(exc)}{where}", err=True)
        return 2
    except MemoryError:
        typer.echo("bendpam: error: out of memory: the machine could not hold this run's data; give fewer values "
                   "or smaller inputs (docs/budgets.md: the memory budgets)", err=True)
        return 2
    except BaseException as exc:
        if isinstance(exc, SystemExit):
            raise
        return _unexpected(exc, debug)
    finally:
        import logging

        logging.disable(logging.NOTSET)  # (quiet_logging after a signal)
        RUN_ARGS.reset(tokens[0])
        RUN_COMMAND.reset(tokens[1])
        RUN_FORCE.reset(tokens[2])
        _SHOWN.reset(shown)
    return 0
