"""The ``bendpam`` Typer application and its entry point :func:`main`.

``main`` turns the library's :class:`~bendpam.errors.BendpamError` into one line
``bendpam: error: ...`` on stderr and exit status 2; SIGINT and SIGTERM into
``bendpam: interrupted; no outputs were changed`` and 130/143.  Any other exception is a bug: one
line saying so and where to report it, exit status 1 (``--debug`` prints the traceback).
"""

from __future__ import annotations

import sys
import traceback
from typing import Annotated, Any, Optional

import typer

__all__ = ["ISSUES_URL", "app", "main"]

ISSUES_URL = "the bendpam issue tracker (include the command line and bendpam --version)"

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,
    help="bendpam: models, tests and design tools for bending pneumatic artificial muscles. "
         "Units: pressure kPa, lengths mm, force N, moments N·mm, curvature 1/mm, angles deg.",
)


def _version(value: bool) -> None:
    if value:
        from importlib.metadata import PackageNotFoundError, version

        try:
            v = version("bendpam")
        except PackageNotFoundError:  # pragma: no cover - running from a source tree
            from bendpam.version import __version__ as v
        typer.echo(f"bendpam {v}")
        raise typer.Exit(0)


@app.callback()
def _root(
    version: Annotated[Optional[bool], typer.Option("--version", callback=_version, is_eager=True,
                                                    help="Print the version and exit.")] = None,
    debug: Annotated[bool, typer.Option("--debug", help="Print the traceback of an internal error.")] = False,
) -> None:
    """bendpam: models, tests and design tools for bending pneumatic artificial muscles."""


# Typer >= 0.20 vendors click; find its exception base class without importing click directly.
# Typed as type[Any]: the class is found at run time, so its attributes (format_message) are not known statically.
_ClickException: type[Any] = next(c for c in typer.BadParameter.__mro__ if c.__name__ == "ClickException")


def _one_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def main(argv: list[str] | None = None) -> int:
    """Entry point: run the app; user errors are one line and exit code 2, bugs exit code 1.

    >>> main(["--version"])
    bendpam ...
    0
    >>> main(["predict", "--preset", "xx-pam", "--pressure-kpa", "100"])   # one line on stderr
    2
    """
    from bendpam.errors import BendpamError

    args = list(sys.argv[1:] if argv is None else argv)
    if not args:
        args = ["--help"]
    debug = "--debug" in args
    from bendpam.infra.outputs import Interrupted, interrupts

    try:
        with interrupts():
            rv = app(args=args, prog_name="bendpam", standalone_mode=False)
        if isinstance(rv, int) and not isinstance(rv, bool):  # typer.Exit(code) inside a command
            return rv
    except Interrupted as exc:
        typer.echo("bendpam: interrupted; no outputs were changed", err=True)
        return exc.exit_code
    except typer.Exit as exc:
        return exc.exit_code
    except (typer.Abort, KeyboardInterrupt):
        typer.echo("bendpam: interrupted; no outputs were changed", err=True)
        return 130
    except _ClickException as exc:
        typer.echo(f"bendpam: error: {exc.format_message()}", err=True)
        return 2
    except BendpamError as exc:
        typer.echo(f"bendpam: error: {_one_line(exc)}", err=True)
        return 2
    except (FileNotFoundError, PermissionError, IsADirectoryError, NotADirectoryError, FileExistsError) as exc:
        where = f": {exc.filename}" if exc.filename else ""
        typer.echo(f"bendpam: error: {exc.strerror or _one_line(exc)}{where}", err=True)
        return 2
    except OSError as exc:
        where = f": {exc.filename}" if exc.filename else ""
        typer.echo(f"bendpam: error: {exc.strerror or _one_line(exc)}{where}", err=True)
        return 2
    except BaseException as exc:
        if isinstance(exc, SystemExit):
            raise
        if debug:
            traceback.print_exc()
        typer.echo(f"bendpam: internal error ({type(exc).__name__}: {_one_line(exc)}); this is a bug in bendpam, "
                   f"please report it to {ISSUES_URL}" + ("" if debug else "; --debug shows the traceback"),
                   err=True)
        return 1
    return 0
