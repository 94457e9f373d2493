"""Shared options and parsing for the ``bendpam`` commands (parsing only; no numerics here).

Multi-valued numbers (``--pressure-kpa``, ``--param``) take separate tokens, comma lists or ranges
``start:stop:count`` (count values from start to stop inclusive: ``100:200:5`` is 100, 125, 150,
175, 200).
"""

from __future__ import annotations

import contextvars
import math
import os
import re
import sys
from collections.abc import Iterable
from enum import Enum
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any, Optional

import typer
from typer.core import TyperArgument, TyperCommand

from bendpam.errors import InputError
from bendpam.infra.budgets import MAX_OPTION_VALUES, value_limit

if TYPE_CHECKING:
    from bendpam.infra.outputs import OutputFile, OutputSet
    from bendpam.physics.actuator import Actuator

__all__ = [
    "FIGURE_FORMATS",
    "FORCE_HELP",
    "LIST_OPTIONS",
    "METAVARS",
    "MULTI_VALUE_OPTIONS",
    "RANGE_HELP",
    "RUN_ARGS",
    "RUN_COMMAND",
    "RUN_FORCE",
    "WROTE_LINES",
    "ActuatorOpt",
    "BendpamCommand",
    "ColumnsOpt",
    "DriftMethod",
    "DriftOpt",
    "FigureFormat",
    "FigureFormatOpt",
    "ForceUncertaintyOpt",
    "Format",
    "FormatFileOpt",
    "Model",
    "ModelOpt",
    "MultiValueCommand",
    "Preset",
    "PresetOpt",
    "PressureForceUncertaintyOpt",
    "PressureOpt",
    "PressureUncertaintyOpt",
    "QuietOpt",
    "RateOpt",
    "RepairOpt",
    "UserError",
    "ZeroUncertaintyOpt",
    "as_given",
    "collect_raw_files",
    "command_inputs",
    "command_line",
    "deprecated_format",
    "echo",
    "echo_wrote",
    "figure_format",
    "fmt_num",
    "format_prediction_table",
    "join_list_values",
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
    "print_json",
    "table_rows",
    "use_bendpam_commands",
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
    """The export dialects of ``simulate-test --table-format``.

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
#: The options that take a list: ``--opt a b c`` (several tokens), ``--opt a,b`` and ranges are one grammar
#: (:func:`parse_values`).  Value: what a following token must look like to be one more value of the option
#: (``None``: a number, a comma list or a range; else the names it may be).
LIST_OPTIONS: dict[str, frozenset[str] | None] = {
    "--pressure-kpa": None,
    "--diameter-mm": None,
    "--direction-deg": None,
    "--param": None,
    "--model": frozenset({"energy", "force-balance", "force_balance"}),
    "--free": frozenset({"alpha0", "C10", "C01", "P_start", "E_f", "R0_start"}),  # identify.result.PARAMETERS
}
#: List options whose one value is a comma list (the values that follow join it with commas).
COMMA_LIST_OPTIONS = ("--free",)
#: Kept for older imports: the options of :data:`LIST_OPTIONS`.
MULTI_VALUE_OPTIONS = tuple(LIST_OPTIONS)
_NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
_VALUES = re.compile(rf"{_NUMBER}(?:[,:]{_NUMBER})*,?")
#: Metavars of options whose values have a shape of their own (every other one is derived from its type).
METAVARS = {"--fixture": "D,R,T", "--tip-force-n": "FX,FY", "--free": "NAMES...", "--scheduler": "ADDRESS",
            "--fit-range": "developed|all", "--loop-law": "pi|dahl", "--hysteresis-law": "pi|dahl",
            "--bend": "ccw|cw", "--plot-var": "NAME", "--plot-x": "NAME", "--plot-y": "NAME",
            "--pressure-kpa": "KPA...", "--diameter-mm": "MM...", "--direction-deg": "DEG...", "--model": "MODEL...",
            "--columns": "time=NAME,stroke=NAME,force=NAME", "--curvature": "PER_MM", "--k-max": "PER_MM"}
#: The unit ending a float option's name -> its metavar (``--l0-mm MM``).
_UNIT_METAVARS = {"mm": "MM", "kpa": "KPA", "deg": "DEG", "hz": "HZ", "s": "SECONDS", "n": "NEWTONS", "g": "GRAMS",
                  "nmm": "NMM", "gib": "GIB", "minutes": "MINUTES", "mm2": "MM2", "nmm2": "NMM2", "mpa": "MPA",
                  "min": "MM_PER_MIN"}
#: Parameters of a command that name its outputs (every other path parameter is an input).
OUTPUT_PARAMS = ("out", "plot")
FORCE_HELP = ("Replace an output that bendpam did not write, or that another bendpam command wrote: the old "
              "file or folder is moved aside to NAME.moved-aside-TIME, never deleted (the home folder, the current "
              "folder and the inputs are refused all the same).")


def _list_rules(param: Any) -> dict[str, frozenset[str] | None]:
    """``{option: continuation rule}`` of ``param`` if it is a list option of its command, else ``{}``."""
    names = [o for o in getattr(param, "opts", ()) if o in LIST_OPTIONS]
    listed = getattr(param, "multiple", False) or getattr(param, "nargs", 1) == -1
    if not names or not (listed or names[0] in COMMA_LIST_OPTIONS):
        return {}
    return {o: LIST_OPTIONS[names[0]] for o in param.opts}


def _continues(token: str, rule: frozenset[str] | None) -> bool:
    """Whether ``token`` is one more value of a list option with the continuation ``rule``."""
    if rule is None:
        return bool(_VALUES.fullmatch(token))
    names = {r.lower() for r in rule}
    return all(part in names for part in token.lower().split(",") if part) and token.strip(",") != ""


def join_list_values(args: list[str], rules: dict[str, frozenset[str] | None]) -> list[str]:
    """``--opt a b c`` -> ``--opt a,b,c`` for the list options ``rules`` (option -> continuation rule).

    A value joins the option before it while it looks like one (a number, comma list or range, or
    one of the option's names); anything else (a file, another option, ``--``) ends the list.

    >>> join_list_values(["raw", "--pressure-kpa", "100", "125", "150:200:3", "more"], {"--pressure-kpa": None})
    ['raw', '--pressure-kpa', '100,125,150:200:3', 'more']
    >>> join_list_values(["--param", "alpha0_deg=60", "70", "--pressure-kpa=100", "150"],
    ...                  {"--param": None, "--pressure-kpa": None})
    ['--param', 'alpha0_deg=60,70', '--pressure-kpa=100,150']
    """
    out: list[str] = []
    rule: frozenset[str] | None = None
    current = False  # the last token is a list option's value (more may follow)
    expecting = False  # a list option's own first value comes next (it may start with '-')
    for i, tok in enumerate(args):
        if tok == "--":
            out.extend(args[i:])
            break
        if expecting:
            out.append(tok)
            expecting, current = False, True
        elif current and _continues(tok, rule):
            out[-1] = f"{out[-1].rstrip(',')},{tok}"
        elif tok.startswith("-") and tok.split("=", 1)[0] in rules:
            rule = rules[tok.split("=", 1)[0]]
            expecting, current = "=" not in tok, "=" in tok
            out.append(tok)
        else:
            current = False
            out.append(tok)
    return out


def _readable_metavar(param: Any) -> str | None:
    """A metavar a person reads for ``param`` (``KPA...``, ``PATH``, ``N``), or None for a flag."""
    desc = getattr(param, "type_descriptor", None)
    opts = [o for o in getattr(param, "opts", ()) if o.startswith("--")]
    if getattr(param, "is_flag", False) or desc is None:
        return None
    if opts and opts[0] in METAVARS and (opts[0] not in LIST_OPTIONS or desc.is_list):
        return METAVARS[opts[0]]
    if desc.is_choice and desc.choices:
        return "[" + "|".join(str(getattr(c, "value", c)) for c in desc.choices) + "]"
    if desc.is_tuple:
        return "LO HI" if "range" in (param.name or "") else " ".join(["X"] * max(param.nargs, 1))
    if desc.is_path or (desc.is_list and "Path" in str(desc.annotation)):
        return "FILES..." if param.nargs != 1 else (param.name or "path").upper() \
            if param.param_type_name == "argument" else "PATH"
    if desc.annotation is int:
        return "N"
    if desc.annotation is float:
        words = opts[0].lstrip("-").split("-") if opts else [param.name or ""]
        return "NUMBER" if "per" in words else _UNIT_METAVARS.get(words[-1], "NUMBER")
    return "TEXT..." if desc.is_list else "TEXT"


def _force_option() -> Any:
    """A ``--force`` option for a command (the same as ``bendpam --force``), built by Typer itself."""
    probe = typer.Typer()

    @probe.command()
    def _f(force: Annotated[bool, typer.Option("--force", help=FORCE_HELP)] = False) -> None:  # pragma: no cover
        pass

    param = typer.main.get_command(probe).params[0]
    param.expose_value = False
    param.callback = lambda ctx, p, value: RUN_FORCE.set(True) if value else None
    return param


class BendpamCommand(TyperCommand):
    """Every ``bendpam`` command: one grammar for lists, ``--force`` where it writes, readable metavars.

    * a list option (:data:`LIST_OPTIONS`) takes several tokens: ``--pressure-kpa 100 150 200`` is
      ``--pressure-kpa 100,150,200`` (:func:`join_list_values`; the values are parsed by :func:`parse_values`);
    * a command that writes (an ``--out`` or ``--plot`` option) shows and takes ``--force``;
    * the help names values as a person reads them (``KPA...``, ``PATH``, ``N``, ``FILES...``), never types.

    >>> "--pressure-kpa" in LIST_OPTIONS
    True
    """

    multi_value_options = MULTI_VALUE_OPTIONS

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        names = {p.name for p in self.params}
        if names & set(OUTPUT_PARAMS) and not any("--force" in getattr(p, "opts", ()) for p in self.params):
            at = next((i for i, p in enumerate(self.params) if getattr(p, "opts", None) == ["--help"]),
                      len(self.params))
            self.params.insert(at, _force_option())
        for p in self.params:
            if p.metavar is None:
                p.metavar = _readable_metavar(p)
            if p.param_type_name == "argument" and p.metavar is not None:
                p.__class__ = _ReadableArgument

    def parse_args(self, ctx, args: list[str]) -> list[str]:
        rules: dict[str, frozenset[str] | None] = {}
        for p in self.params:
            rules.update(_list_rules(p))
        return super().parse_args(ctx, join_list_values(args, rules) if rules else args)


class _ReadableArgument(TyperArgument):
    """An argument shown by its metavar alone (``FILES...``), without Typer's ``{name}`` and ``<type>``."""

    def display_type_rich(self, ctx) -> str | None:
        return None

    def _rich_display_name(self) -> str:
        return str(self.metavar)

    def _usage_display_name(self) -> str:
        return str(self.metavar) if self.required else f"[{self.metavar}]"


#: Kept for older imports: every command is a :class:`BendpamCommand`.
MultiValueCommand = BendpamCommand


def use_bendpam_commands(app: typer.Typer) -> None:
    """Make every command of ``app`` a :class:`BendpamCommand` (one grammar, ``--force``, readable help).

    >>> t = typer.Typer()
    >>> _ = t.command("x")(lambda: None)
    >>> use_bendpam_commands(t)
    >>> t.registered_commands[0].cls is BendpamCommand
    True
    """
    for info in app.registered_commands:
        if info.cls is None or info.cls is TyperCommand:
            info.cls = BendpamCommand


def echo(text: str = "", err: bool = False) -> None:
    """Print one line (to stderr with ``err``).

    >>> echo("wrote out/")
    wrote out/
    """
    typer.echo(text, err=err)


def print_json(obj: Any) -> None:
    """Print ``obj`` as strict JSON: infinity is the string ``"inf"`` (``"-inf"``), ``null`` means missing.

    >>> print_json({"margin": float("inf"), "angle_deg": float("nan"), "n": 2})
    {
      "margin": "inf",
      "angle_deg": null,
      "n": 2
    }
    """
    import json

    from bendpam.infra.atomic import json_safe

    typer.echo(json.dumps(json_safe(obj), indent=2, allow_nan=False, ensure_ascii=False))


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


def table_rows(table) -> list[Any]:
    """The rows of a table of columns (a dict of equal-length sequences, or a DataFrame), each with the
    columns as attributes.

    >>> [r.b for r in table_rows({"a": [1, 2], "b": ["x", "y"]})]
    ['x', 'y']
    """
    from types import SimpleNamespace

    columns = {str(k): list(table[k]) for k in table}
    n = len(next(iter(columns.values()), []))
    return [SimpleNamespace(**{k: v[i] for k, v in columns.items()}) for i in range(n)]


def format_prediction_table(table, title: str) -> str:
    """The text table of ``predict``, from the columns of :func:`bendpam.predict.prediction_columns`
    (or the DataFrame of :func:`~bendpam.predict.prediction_table`).

    >>> cols = dict(pressure_kpa=[150.0], blocked_moment_nmm=[200.0], free_curvature_per_mm=[0.01],
    ...             free_angle_deg=[30.0], note=[""])
    >>> print(format_prediction_table(cols, "BE-PAM").splitlines()[-1])
         150            200.00        0.01000         30.00
    """
    lines = [title, f"{'P (kPa)':>8}  {'M_blocked (N·mm)':>16}  {'k_free (1/mm)':>13}  {'θ_free (deg)':>12}  note"]
    for r in table_rows(table):
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
#: ``--force`` (of the command or of ``bendpam``): replace outputs that bendpam did not write, moving them aside.
RUN_FORCE: contextvars.ContextVar[bool] = contextvars.ContextVar("bendpam_run_force", default=False)


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
ForceUncertaintyOpt = Annotated[float, typer.Option(
    "--force-uncertainty-pct", min=0.0, max=20.0, help="The load cell's calibration, a standard uncertainty in % of "
    "the reading (ISO 7500-1 class 1: 0.58): added to the error bars as the instrument's part.")]
PressureUncertaintyOpt = Annotated[float, typer.Option(
    "--pressure-uncertainty-kpa", min=0.0, max=100.0,
    help="The pressure gauge's calibration, a standard uncertainty in kPa common to every test.")]
ZeroUncertaintyOpt = Annotated[Optional[float], typer.Option(
    "--zero-uncertainty-n", min=0.0, max=1e4,
    help="The load cell's zero is known (a tare with the fixture as tested): its standard uncertainty in N, 0 for "
    "exactly. The fit's members with a zero offset are left out and this doubt takes their place.")]
PressureForceUncertaintyOpt = Annotated[Optional[float], typer.Option(
    "--pressure-force-uncertainty-n-per-kpa", min=0.0, max=10.0,
    help="No force in proportion to the pressure (a supply hose, a fitting's thrust) reaches the load cell beyond "
    "this standard uncertainty in N/kPa, 0 for none. The fit's members with such a force are left out.")]
QuietOpt = Annotated[
    bool, typer.Option("--quiet", "-q", help="No progress on stderr (neither the bar nor the progress lines).")
]

#: The reader's options (``process``, ``inspect``, ``report``).
ColumnsOpt = Annotated[Optional[str], typer.Option(
    "--columns", metavar="time=NAME,stroke=NAME,force=NAME",
    help="Choose the file's channels by name (any of time, stroke, force); "
         "default: chosen and reported by the reader.")]
RateOpt = Annotated[Optional[float], typer.Option(
    "--rate-hz", help="Sampling rate (Hz) for a file without a time column (default: from its metadata).")]
FormatFileOpt = Annotated[Optional[Path], typer.Option(
    "--format-file", metavar="PATH",
    help="Read the files by this format declaration (TOML; docs/formats.md), with no detection; "
         "'bendpam inspect FILE --suggest' drafts one.")]
RepairOpt = Annotated[bool, typer.Option(
    "--repair", help="Remove isolated spikes and non-increasing samples (reported) instead of refusing the file.")]


class DriftMethod(str, Enum):
    """``--drift``: the load-cell offset drift correction (:data:`bendpam.lab.drift.DRIFT_METHODS`).

    >>> DriftMethod("linear").value
    'linear'
    """

    none = "none"
    linear = "linear"


DriftOpt = Annotated[DriftMethod, typer.Option(
    "--drift", help="Load-cell offset drift: none = estimate and report it; linear = also subtract the fitted "
                    "linear offset before processing.")]


def deprecated_format(old: Any, new: Any, command: str, *, new_name: str = "--table-format") -> Any:
    """The value of ``new_name``, or of the old ``--format`` spelling with a one-line note on stderr.

    ``--format`` means the figure format on every command; where it meant a table's format it is
    still accepted for one release (0.4) with this note.

    >>> deprecated_format(None, "csv", "sweep")
    'csv'
    """
    if old is None:
        return new
    value = getattr(old, "value", old)
    if new is not None and getattr(new, "value", new) != value:
        raise UserError(f"give either {new_name} {getattr(new, 'value', new)} or --format {value}, not both")
    echo(f"bendpam: warning: {command} --format {value} is deprecated (--format is the figure format); use "
         f"{new_name} {value}", err=True)
    return old


def output_format(path: Path | None, fmt: str | Enum | None, formats: tuple[str, ...], *, option: str = "--out",
                  default: str | None = None, format_option: str = "--format") -> str | None:
    """The format of an output file from ``--format`` or the suffix of ``path`` (:func:`bendpam.validate.file_format`).

    Returns None when ``path`` is None.

    >>> output_format(Path("sweep.csv"), None, ("nc", "csv"))
    'csv'
    """
    if path is None:
        return None
    from bendpam.validate import file_format  # (validate imports NumPy: not at start-up)

    return file_format(path, fmt, formats, option=option, format_option=format_option, default=default)


def figure_format(path: Path | None, fmt: str | Enum | None, option: str = "--out") -> str | None:
    """:func:`output_format` for a figure (png, pdf or svg; png when neither the name nor --format says).

    >>> figure_format(Path("fig.svg"), None), figure_format(Path("fig"), None)
    ('svg', 'png')
    """
    return output_format(path, fmt, FIGURE_FORMATS, option=option, default="png")
