"""Shared options and parsing for the ``bendpam`` commands (parsing only; no numerics here).

Multi-valued numbers (``--pressure-kpa``, ``--param``) take separate tokens, comma lists or ranges
``start:stop:count`` (count values from start to stop inclusive: ``100:200:5`` is 100, 125, 150,
175, 200).
"""

from __future__ import annotations

import contextvars
import math
import os
import sys
from collections.abc import Iterable
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Optional

import typer
from typer.core import TyperCommand

from bendpam.errors import InputError
from bendpam.infra.budgets import MAX_OPTION_VALUES, value_limit
from bendpam.validate import file_format

if TYPE_CHECKING:
    from bendpam.infra.outputs import OutputFile, OutputSet
    from bendpam.physics.actuator import Actuator

__all__ = [
    "FIGURE_FORMATS",
    "MULTI_VALUE_OPTIONS",
    "RANGE_HELP",
    "RUN_ARGS",
    "RUN_COMMAND",
    "RUN_FORCE",
    "WROTE_LINES",
    "ActuatorOpt",
    "FigureFormat",
    "FigureFormatOpt",
    "Format",
    "Model",
    "ModelOpt",
    "MultiValueCommand",
    "Preset",
    "PresetOpt",
    "PressureOpt",
    "QuietOpt",
    "UserError",
    "as_given",
    "collect_raw_files",
    "command_inputs",
    "command_line",
    "echo",
    "echo_wrote",
    "figure_format",
    "fmt_num",
    "format_prediction_table",
    "load_actuator",
    "model_for",
    "model_name",
    "output_file",
    "output_format",
    "output_set",
    "parse_values",
    "positive",
    "pressure_kpa",
    "pressures_kpa",
]

#: The largest number of values one option may expand to in any command (a range like 100:200:30000000 is
#: refused); each command has its own, smaller limit (:data:`bendpam.infra.budgets.VALUE_LIMITS`).
MAX_VALUES = MAX_OPTION_VALUES


class UserError(InputError):
    """A command line that cannot be acted on (a missing option, inconsistent options).

    >>> issubclass(UserError, InputError)
    True
    """


class Model(str, Enum):
    """The moment model of ``--model``.

    >>> Model("force-balance").name
    'force_balance'
    """

    energy = "energy"
    force_balance = "force-balance"


class Preset(str, Enum):
    """The paper's actuators of ``--preset``.

    >>> [p.value for p in Preset]
    ['be-pam', 'bc-pam']
    """

    be_pam = "be-pam"
    bc_pam = "bc-pam"


class Format(str, Enum):
    """The export dialects of ``simulate-test --format``.

    >>> Format("mts").value
    'mts'
    """

    csv = "csv"
    testxpert = "testxpert"
    bluehill = "bluehill"
    mts = "mts"


RANGE_HELP = "values '100 150 200', '100,150' or a range start:stop:count ('100:200:5' = 100, 125, ..., 200)"
PresetOpt = Annotated[Optional[Preset], typer.Option("--preset", help="Built-in actuator from the paper.")]
ActuatorOpt = Annotated[
    Optional[Path], typer.Option("--actuator", help="Actuator TOML file (see `bendpam actuator --preset be-pam`).")
]
ModelOpt = Annotated[Optional[Model], typer.Option(
    "--model", help="Moment model (default: the actuator's own, the model its constants were identified with; "
    "energy for a preset).", show_default=False)]
PressureOpt = Annotated[
    Optional[list[str]],
    typer.Option("--pressure-kpa", metavar="KPA...", help=f"Gauge pressure(s) in kPa: {RANGE_HELP}."),
]
#: options whose space-separated values are all collected (rewritten as repeated options)
MULTI_VALUE_OPTIONS = ("--pressure-kpa", "--diameter-mm", "--direction-deg")


class MultiValueCommand(TyperCommand):
    """A command in which ``--opt a b c`` means ``--opt a --opt b --opt c`` for the options above.

    >>> "--pressure-kpa" in MultiValueCommand.multi_value_options
    True
    """

    multi_value_options = MULTI_VALUE_OPTIONS

    def parse_args(self, ctx, args: list[str]) -> list[str]:
        out: list[str] = []
        current = None  # the multi-value option whose values are being read
        expecting = False  # its own first value comes next (it may start with '-')
        for i, tok in enumerate(args):
            if tok == "--":
                out.extend(args[i:])
                break
            if expecting:
                out.append(tok)
                expecting = False
            elif tok.startswith("-"):
                name = tok.split("=", 1)[0]
                current = name if name in self.multi_value_options else None
                expecting = current is not None and "=" not in tok
                out.append(tok)
            elif current is not None:
                out.extend([current, tok])
            else:
                out.append(tok)
        return super().parse_args(ctx, out)




def echo(text: str = "", err: bool = False) -> None:
    """Print one line (to stderr with ``err``).

    >>> echo("wrote out/")
    wrote out/
    """
    typer.echo(text, err=err)


def _too_many(name: str, what: str, limit: int) -> UserError:
    command = RUN_COMMAND.get()
    who = f"bendpam {command}" if command else "an option"
    return UserError(f"{name}: {what}; {who} takes at most {limit} values per option (about a minute of work or "
                     "less): give fewer values")


def parse_values(tokens: list[str] | None, name: str, *, max_values: int | None = None) -> list[float]:
    """Parse numbers given as separate tokens, comma lists or ranges ``start:stop:count``.

    ``max_values`` defaults to the running command's limit (:func:`bendpam.infra.budgets.value_limit`);
    a range is checked against it before it is expanded.

    >>> parse_values(["100,150", "200:300:3"], "--pressure-kpa")
    [100.0, 150.0, 200.0, 250.0, 300.0]
    >>> parse_values(["100:200:999999"], "--pressure-kpa")
    Traceback (most recent call last):
    ...
    bendpam.cli.options.UserError: --pressure-kpa: range '100:200:999999' gives 999999 values; an option takes ...
    """
    limit = value_limit(RUN_COMMAND.get()) if max_values is None else int(max_values)
    out: list[float] = []
    for tok in tokens or []:
        for part in str(tok).replace(",", " ").split():
            if ":" in part:
                bits = part.split(":")
                if len(bits) != 3:
                    raise UserError(f"{name}: range {part!r} must be start:stop:count")
                try:
                    a, b, n = float(bits[0]), float(bits[1]), int(bits[2])
                except ValueError:
                    raise UserError(f"{name}: range {part!r} must be start:stop:count with numbers") from None
                if not (math.isfinite(a) and math.isfinite(b)):
                    raise UserError(f"{name}: range {part!r} must have finite ends")
                if n < 1:
                    raise UserError(f"{name}: range {part!r} needs a count >= 1")
                if len(out) + n > limit:
                    raise _too_many(name, f"range {part!r} gives {n} values" + (f" after {len(out)}" if out else ""),
                                    limit)
                out.extend(a + (b - a) * i / (n - 1) if n > 1 else a for i in range(n))
            else:
                try:
                    v = float(part)
                except ValueError:
                    raise UserError(f"{name}: {part!r} is not a number") from None
                if not math.isfinite(v):
                    raise UserError(f"{name}: {part!r} is not finite")
                out.append(v)
                if len(out) > limit:
                    raise _too_many(name, f"more than {limit} values", limit)
    return out


def pressure_kpa(value: float, name: str = "--pressure-kpa") -> float:
    """One pressure option in kPa, with the same checks as :func:`pressures_kpa`.

    >>> pressure_kpa(150)
    150.0
    """
    return pressures_kpa([repr(float(value))], None, name)[0]


def pressures_kpa(first: list[str] | None, more: list[str] | None = None, name: str = "--pressure-kpa") -> list[float]:
    """Pressures (kPa) from the option's values (``more``: values that followed it, if any).

    >>> pressures_kpa(["100:200:3"])
    [100.0, 150.0, 200.0]
    >>> pressures_kpa(["0.2"])
    Traceback (most recent call last):
    ...
    bendpam.cli.options.UserError: --pressure-kpa: every pressure is below 5 kPa (largest 0.2); ...
    """
    values = parse_values((first or []) + (more or []), name)
    if not values:
        raise UserError(f"give at least one pressure with {name} (kPa), e.g. {name} 100 150 200")
    for v in values:
        if v < 0:
            raise UserError(f"{name}: {v:g} kPa is below zero; pressures are gauge pressures >= 0 kPa")
    nz = [v for v in values if v > 0]
    if nz and max(nz) < 5.0:
        raise UserError(f"{name}: every pressure is below 5 kPa (largest {max(nz):g}); pressures are in kPa "
                        "(0.2 MPa = 200 kPa)")
    return values


def model_name(model: Model | None) -> str | None:
    """The library's name of a ``--model`` choice (None when not given: the actuator's own model).

    >>> model_name(Model.force_balance), model_name(None)
    ('force_balance', None)
    """
    from bendpam.physics.models import normalise_model

    return None if model is None else normalise_model(model.value)


def model_for(act: Actuator, model: Model | None) -> str:
    """The model a command evaluates ``act`` with: ``--model``, else the actuator's own (energy when unknown).

    A ``--model`` other than the one the actuator's constants were identified with warns once
    (``bendpam: warning: ...``); the name returned is handed to the library, which does not warn again.

    >>> from bendpam.physics import presets
    >>> model_for(presets.be_pam("force_balance"), None), model_for(presets.be_pam(), Model.energy)
    ('force_balance', 'energy')
    """
    from bendpam.physics.models import resolve_model

    return resolve_model(act, model_name(model))


def load_actuator(preset: Preset | None, actuator: Path | None, model: Model | None) -> Actuator:
    """The actuator of ``--preset`` (with ``--model``'s Table 3 constants, energy by default) or ``--actuator``.

    Exactly one of them.  Use :func:`model_for` for the model to evaluate it with.

    >>> load_actuator(Preset.be_pam, None, None).alpha0_deg
    69.7
    """
    if preset is not None and actuator is not None:
        raise UserError("give either --preset or --actuator, not both")
    if preset is None and actuator is None:
        raise UserError("give an actuator: --preset be-pam|bc-pam or --actuator FILE.toml")
    from bendpam.physics import presets
    from bendpam.physics.actuator import Actuator

    if preset is not None:
        return presets.get(preset.value, model_name(model) or "energy")
    assert actuator is not None  # exactly one of preset and actuator was checked above
    return Actuator.from_toml(actuator)


def fmt_num(x, fmt: str) -> str:
    """``format(x, fmt)``, or a dash of the same width for None/NaN/inf.

    >>> fmt_num(1.23456, "6.2f"), fmt_num(float("nan"), "6.2f")
    ('  1.23', '     —')
    """
    width = fmt.split(".")[0]
    try:
        ok = x is not None and math.isfinite(float(x))
    except (TypeError, ValueError):
        ok = False
    return format(float(x), fmt) if ok else "—".rjust(int(width) if width else 1)


def format_prediction_table(df, title: str) -> str:
    """The text table of ``predict``.

    >>> import pandas as pd
    >>> row = dict(pressure_kpa=150.0, blocked_moment_nmm=200.0, free_curvature_per_mm=0.01, free_angle_deg=30.0,
    ...            note="")
    >>> print(format_prediction_table(pd.DataFrame([row]), "BE-PAM").splitlines()[-1])
         150            200.00        0.01000         30.00
    """
    lines = [title, f"{'P (kPa)':>8}  {'M_blocked (N·mm)':>16}  {'k_free (1/mm)':>13}  {'θ_free (deg)':>12}  note"]
    for r in df.itertuples():
        lines.append(
            f"{r.pressure_kpa:8.4g}  {fmt_num(r.blocked_moment_nmm, '16.2f')}  "
            f"{fmt_num(r.free_curvature_per_mm, '13.5f')}  {fmt_num(r.free_angle_deg, '12.2f')}  {r.note}"
        )
    return "\n".join(lines)


def collect_raw_files(paths: list[Path]) -> list[Path]:
    """Expand folders into their raw test files (see :func:`bendpam.lab.files.collect_raw_files`).

    >>> collect_raw_files([Path("no-such-folder")])
    Traceback (most recent call last):
    ...
    bendpam.errors.InputError: no-such-folder: no such file or folder
    """
    from bendpam.lab.files import collect_raw_files as collect

    return collect(paths)


#: The arguments of the running command line (set by :func:`bendpam.cli.app.main`).
RUN_ARGS: contextvars.ContextVar[list[str] | None] = contextvars.ContextVar("bendpam_run_args", default=None)
#: The name of the running command (``"process"``): the producer recorded in its output sets.
RUN_COMMAND: contextvars.ContextVar[str | None] = contextvars.ContextVar("bendpam_run_command", default=None)
#: The ``wrote ...`` lines of the running command, printed once its outputs are committed (:func:`echo_wrote`).
WROTE_LINES: contextvars.ContextVar[list[str] | None] = contextvars.ContextVar("bendpam_wrote_lines", default=None)


def echo_wrote(text: str) -> None:
    """Say that an output was written -- after the command's outputs are committed, so the line is true.

    Inside a command run by :func:`bendpam.cli.app.main` the line waits until every output of the
    command is in place (a signal or an error before then rolls them back, and the line is never
    printed); elsewhere it is printed at once.

    >>> echo_wrote("wrote out/")
    wrote out/
    """
    pending = WROTE_LINES.get()
    if pending is None:
        typer.echo(text)
    else:
        pending.append(text)


#: ``bendpam --force``: replace outputs that bendpam did not write, moving them aside.
RUN_FORCE: contextvars.ContextVar[bool] = contextvars.ContextVar("bendpam_run_force", default=False)
#: Parameters of a command that name its outputs (every other path parameter is an input).
OUTPUT_PARAMS = ("out", "plot")


def command_line() -> list[str]:
    """The command line, for the manifests of output sets.

    >>> command_line()[0]
    'bendpam'
    """
    args = RUN_ARGS.get()
    return ["bendpam", *(sys.argv[1:] if args is None else args)]


def _click_context() -> Any:
    """The running command's click context (Typer may vendor click), or None."""
    base = next((c for c in typer.Context.__mro__[1:] if c.__name__ == "Context"), None)
    core = sys.modules.get(base.__module__) if base is not None else None
    push = getattr(core, "push_context", None)
    get = getattr(sys.modules.get(getattr(push, "__module__", "") or ""), "get_current_context", None)
    return get(silent=True) if callable(get) else None


def command_inputs() -> list[Path]:
    """The existing paths among the running command's parameters, outputs (``--out``, ``--plot``) aside.

    Every output is checked against them: an output equal to, inside or containing an input
    folder given on the command line is refused for every command, whatever inputs the
    command itself passes.

    >>> command_inputs()      # outside a command
    []
    """
    ctx = _click_context()
    if ctx is None:
        return []
    found: list[Path] = []
    for name, value in (getattr(ctx, "params", None) or {}).items():
        if name in OUTPUT_PARAMS:
            continue
        for v in value if isinstance(value, list | tuple) else [value]:
            if isinstance(v, os.PathLike) and os.path.exists(v):
                found.append(Path(v))
    return found


def _inputs(inputs: Iterable[Path | None]) -> list[Path]:
    out: list[Path] = []
    for p in [*inputs, *command_inputs()]:
        if p is not None and Path(p) not in out:
            out.append(Path(p))
    return out


def as_given(out: Path) -> Path | str:
    """``out`` as typed: Typer's ``Path("./~")`` is ``Path("~")``; only a ``~`` typed first means home.

    >>> str(as_given(Path("data")))
    'data'
    """
    text = str(out)
    if not text.startswith("~"):
        return out
    values = [a.split("=", 1)[1] if a.startswith("--") and "=" in a else a for a in RUN_ARGS.get() or []]
    typed = [v for v in values if v and Path(v) == out]
    if typed and not any(v.startswith("~") for v in typed):
        return os.path.join(".", text)  # typed as ./~ : a folder named ~ here
    return text


def output_set(out: Path, inputs: Iterable[Path | None] = (), *, force: bool | None = None) -> OutputSet:
    """An :class:`~bendpam.infra.outputs.OutputSet` for a command's output folder (whole set or nothing).

    The producer recorded is the command's name; ``force`` defaults to ``bendpam --force``;
    the inputs are ``inputs`` and every path parameter of the command but its outputs.

    >>> import tempfile
    >>> with tempfile.TemporaryDirectory() as d:
    ...     with output_set(Path(d) / "out") as o:
    ...         _ = o.write_text("a.txt", "a")
    ...     print(sorted(p.name for p in (Path(d) / "out").iterdir()))
    ['a.txt', 'manifest.json']
    """
    from bendpam.infra.outputs import OutputSet

    return OutputSet(as_given(out), inputs=_inputs(inputs), command=command_line(),
                     force=RUN_FORCE.get() if force is None else force, producer=RUN_COMMAND.get())


def output_file(out: Path, inputs: Iterable[Path | None] = (), *, force: bool | None = None) -> OutputFile:
    """An :class:`~bendpam.infra.outputs.OutputFile` for a command's single output file.

    >>> output_file(Path("no-such-folder") / "x.csv")
    Traceback (most recent call last):
    ...
    bendpam.cli.options.UserError: --out 'no-such-folder/x.csv': the folder 'no-such-folder' does not exist
    """
    from bendpam.infra.outputs import OutputFile

    typed = as_given(out)
    given = Path(os.path.expanduser(typed) if isinstance(typed, str) and typed.startswith("~") else typed)
    if not given.parent.is_dir():
        raise UserError(f"--out {str(out)!r}: the folder {str(given.parent)!r} does not exist")
    return OutputFile(typed, inputs=_inputs(inputs), command=command_line(),
                      force=RUN_FORCE.get() if force is None else force)


def positive(name: str, value: float | None, unit: str) -> float | None:
    """A numeric option that must be > 0 (None passes).

    >>> positive("--width-mm", 2.0, "mm"), positive("--width-mm", None, "mm")
    (2.0, None)
    """
    if value is None:
        return None
    if not (math.isfinite(value) and value > 0):
        raise UserError(f"{name}: {value:g} {unit} must be > 0")
    return value


# ---- figure formats and progress (issue 16) -------------------------------------------------
class FigureFormat(str, Enum):
    """The figure formats of ``--format``.

    >>> FIGURE_FORMATS
    ('png', 'pdf', 'svg')
    """

    png = "png"
    pdf = "pdf"
    svg = "svg"


#: The figure formats every figure-writing command accepts.
FIGURE_FORMATS = tuple(f.value for f in FigureFormat)
FigureFormatOpt = Annotated[
    Optional[FigureFormat],
    typer.Option("--format", help="Figure format: png, pdf or svg (default: from the file name, else png)."),
]
QuietOpt = Annotated[
    bool, typer.Option("--quiet", "-q", help="No progress on stderr (neither the bar nor the progress lines).")
]

def output_format(path: Path | None, fmt: str | Enum | None, formats: tuple[str, ...], *, option: str = "--out",
                  default: str | None = None) -> str | None:
    """The format of an output file from ``--format`` or the suffix of ``path`` (:func:`bendpam.validate.file_format`).

    Returns None when ``path`` is None.

    >>> output_format(Path("sweep.csv"), None, ("nc", "csv"))
    'csv'
    """
    if path is None:
        return None
    return file_format(path, fmt, formats, option=option, format_option="--format", default=default)


def figure_format(path: Path | None, fmt: str | Enum | None, option: str = "--out") -> str | None:
    """:func:`output_format` for a figure (png, pdf or svg; png when neither the name nor --format says).

    >>> figure_format(Path("fig.svg"), None), figure_format(Path("fig"), None)
    ('svg', 'png')
    """
    return output_format(path, fmt, FIGURE_FORMATS, option=option, default="png")
