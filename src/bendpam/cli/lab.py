"""``bendpam process`` and ``bendpam simulate-test``: raw cyclic tests in and out."""

# no ``from __future__ import annotations``: Typer reads the annotations of the commands as objects (start-up)

import re
from pathlib import Path
from typing import Annotated, Optional

import typer

from bendpam.cli.app import app, cli_words
from bendpam.cli.options import (
    ActuatorOpt,
    ColumnsOpt,
    DriftMethod,
    DriftOpt,
    FigureFormatOpt,
    Format,
    FormatFileOpt,
    ModelOpt,
    MultiValueCommand,
    PresetOpt,
    PressureOpt,
    QuietOpt,
    RateOpt,
    RepairOpt,
    UserError,
    collect_raw_files,
    deprecated_format,
    echo_wrote,
    fmt_num,
    load_actuator,
    model_for,
    output_set,
    parse_values,
    pressures_kpa,
    print_json,
)
from bendpam.errors import InputError, ProcessingError

FixtureOpt = Annotated[str, typer.Option("--fixture", help="Fixture geometry d,r,t in mm.")]

#: SimulationSettings as named in the library's messages -> the options of ``simulate-test``.
_FLAGS = {"rate_hz": "--rate-hz", "fewer cycles": "fewer --cycles", "dwell_s": "--dwell-s",
          "speed_mm_min": "--speed-mm-min"}  # fmt: skip
_SETTING_FLAGS = re.compile(r"(?<![\w-])(?:rate_hz|fewer cycles|dwell_s|speed_mm_min)(?![\w-])")


def _check_l0(l0_mm: float) -> None:
    """--l0-mm: a positive length in the plausible range of an actuator's (docs/plausibility.md)."""
    import math

    from bendpam.validate import plausible

    if not (math.isfinite(l0_mm) and l0_mm > 0):
        raise UserError(f"--l0-mm: {l0_mm:g} mm must be a positive length")
    plausible("L0_mm", l0_mm, label="--l0-mm")


@app.command()
def inspect(
    files: Annotated[list[Path], typer.Argument(help="Raw test files (or folders of them).", show_default=False)],
    pressure_kpa: Annotated[Optional[float], typer.Option("--pressure-kpa", help="Pressure (kPa) to report.")] = None,
    columns: ColumnsOpt = None,
    rate_hz: RateOpt = None,
    repair: RepairOpt = False,
    format_file: FormatFileOpt = None,
    suggest: Annotated[bool, typer.Option(
        "--suggest", help="Print a format declaration that reads each file (what detection found, or the best "
                          "guesses from its head), to save, edit and give with --format-file.")] = False,
    as_json: Annotated[bool, typer.Option("--json", help="Print a JSON list, one object per file.")] = False,
):
    """What the reader understood of each file (format, encoding, channels, units, values), before processing."""
    from bendpam.lab import format_inspection, inspect_file

    paths = collect_raw_files(files)
    if suggest:
        _print_suggestions(paths, as_json)
        return
    if format_file is not None:
        from bendpam.lab import load_declaration

        load_declaration(format_file)  # a bad declaration is one error, not one per file
    infos = [inspect_file(p, pressure_kpa=pressure_kpa, columns=columns, rate_hz=rate_hz, repair=repair,
                          format_file=format_file) for p in paths]
    for info in infos:
        if "error" in info:
            info["error"] = cli_words(info["error"])
    if as_json:
        print_json(infos)
    else:
        for info in infos:
            typer.echo(format_inspection(info))
            typer.echo("")
    bad = [i for i in infos if "error" in i]
    if bad:
        for i in bad:
            typer.echo(f"bendpam: error: {i['error']}", err=True)
        raise typer.Exit(2)


def _print_suggestions(paths: list[Path], as_json: bool) -> None:
    """``inspect --suggest``: a declaration per file (TOML text, or a JSON list of {file, declaration})."""
    import json

    from bendpam.lab import suggest_declaration

    drafts = [(p, suggest_declaration(p)) for p in paths]
    if as_json:
        typer.echo(json.dumps([{"file": str(p), "declaration": d} for p, d in drafts], indent=2, ensure_ascii=False))
        return
    for i, (_p, d) in enumerate(drafts):
        typer.echo(("\n" if i else "") + d, nl=False)


@app.command()
def process(
    inputs: Annotated[list[Path], typer.Argument(help="Raw test files, or a folder of them.", show_default=False)],
    out: Annotated[Optional[Path], typer.Option("--out", help="Output folder.")] = None,
    pressure_kpa: PressureOpt = None,
    l0_mm: Annotated[float, typer.Option("--l0-mm", help="Active length L0 for k' = 2 beta / L0 (mm).")] = 145.0,
    fixture: FixtureOpt = "35,2.5,4",
    cutoff_hz: Annotated[
        Optional[float],
        typer.Option("--cutoff-hz", help="Low-pass cutoff (Hz); default 1 Hz (max 40% of Nyquist); 0 = off."),
    ] = None,
    tare_n: Annotated[float, typer.Option("--tare-n", help="Force tare for self-weight (N).")] = 0.0,
    reversal_fraction: Annotated[
        float, typer.Option("--reversal-fraction", help="Stroke-reversal threshold, fraction of the stroke range.")
    ] = 0.05,
    grid_points: Annotated[int, typer.Option("--grid-points", min=5, max=100000,
                                             help="Points of the common curvature grid.")] = 101,
    figure: Annotated[bool, typer.Option("--figure/--no-figure", help="Write figure4.png (or .pdf/.svg).")] = True,
    fig_format: FigureFormatOpt = None,
    columns: ColumnsOpt = None,
    rate_hz: RateOpt = None,
    repair: RepairOpt = False,
    format_file: FormatFileOpt = None,
    drift: DriftOpt = DriftMethod.none,
    despike_sigmas: Annotated[float, typer.Option(
        "--despike-sigmas", help="Replace isolated spikes of 1-2 samples this many noise SDs off both neighbours "
                                 "(noted per test); 0 = keep them; else 4 to 1e6.")] = 8.0,
    as_json: Annotated[bool, typer.Option("--json", help="Print summary.json to stdout.")] = False,
    keep_going: Annotated[bool, typer.Option(
        "--keep-going", help="Skip the files that cannot be read or processed (each reported) instead of refusing.")]
    = False,
    quiet: QuietOpt = False,
):
    """Process raw four-point-bending cyclic tests into moment-curvature curves and Table 2 values.

    Every file is reported (read, or skipped and why); several tests at one pressure are replicates.
    """
    from bendpam.lab.batch import FilesRefused, file_line, process_files
    from bendpam.lab.processed import ProcessingOptions
    from bendpam.physics.fixture import Fixture

    out = _check_process_inputs(out, l0_mm, format_file)
    files = collect_raw_files(inputs)
    pressures = _file_pressures(pressure_kpa, files)
    fx = Fixture.from_string(fixture, L0_mm=l0_mm, name="--fixture")
    try:
        opts = ProcessingOptions(cutoff_hz=cutoff_hz, reversal_fraction=reversal_fraction, grid_points=grid_points,
                                 tare_n=tare_n, drift=DriftMethod(drift).value, despike_sigmas=despike_sigmas)
    except InputError as exc:  # the API's words name the field: the CLI's handler names the option (option_words)
        raise UserError(str(exc)) from None
    fig_name = f"figure4.{fig_format.value if fig_format is not None else 'png'}"
    if fig_format is not None and not figure:
        raise UserError(f"--format {fig_format.value}: there is no figure with --no-figure")

    from bendpam.infra.progress import Progress

    read_kw = {"columns": columns, "rate_hz": rate_hz, "repair": repair, "format_file": format_file}
    per_file = (pressures * len(files) if len(pressures) == 1 else pressures) if pressures else None
    try:
        # the output target is checked (and locked) before any work; a refusal inside leaves it unchanged
        with output_set(out, inputs) as o, Progress(len(files) + 1, "process", quiet=quiet) as bar:
            processed = process_files(files, pressures_kpa=per_file, fixture=fx, options=opts, keep_going=keep_going,
                                      read_options=read_kw, on_file=lambda _f: bar.advance())
            bar.advance(0, description="process: writing")
            processed.save(o.staging, figure=False)
            if figure:
                from bendpam.present.figures import save_figure

                save_figure(processed.plot(), o.path(fig_name))
            bar.advance()
    except FilesRefused as exc:  # every bad file, one line each; raised before anything is written
        _refused(exc.problems, len(files))
    except ProcessingError as exc:
        raise UserError(_flags(str(exc))) from None
    if as_json:
        typer.echo((out / "summary.json").read_text(encoding="utf-8"))
        return
    for info in processed.files:
        typer.echo(_flags(file_line(info)))
    _print_table2(processed.summary())
    echo_wrote(f"wrote {out}/ (curves.nc, curves.npz, curves.csv, summary.json{', ' + fig_name if figure else ''})")


def _check_process_inputs(out: Path | None, l0_mm: float, format_file: Path | None) -> Path:
    """``process``'s checks before any file is read: an output folder (returned), --l0-mm, --format-file."""
    if out is None:
        raise UserError("give an output folder with --out OUTDIR")
    _check_l0(l0_mm)
    if format_file is not None:
        from bendpam.lab import load_declaration

        load_declaration(format_file)  # refused before any file is read
    return out


def _refused(problems: list[str], n_files: int) -> None:
    """Every file that refused the set, one ``bendpam: error:`` line each, then exit 2 (nothing was written)."""
    for problem in problems:
        typer.echo(f"bendpam: error: {_flags(problem)}", err=True)
    if len(problems) > 1:
        typer.echo(f"bendpam: error: {len(problems)} of {n_files} file(s) cannot be processed; nothing "
                   "written (--keep-going skips them)", err=True)
    raise typer.Exit(2) from None


def _flags(message: str) -> str:
    """A library message in this command's words: --pressure-kpa, --format-file (:func:`cli_words`)."""
    return cli_words(message.replace("give pressure_kpa when reading it", "give --pressure-kpa"))


def _file_pressures(pressure_kpa: Optional[list[str]], files: list[Path]) -> list[float]:
    """The ``--pressure-kpa`` values of ``process``: none, or one per file (in kPa, not below zero)."""
    pressures = parse_values(pressure_kpa, "--pressure-kpa") if pressure_kpa else []
    if (pressures and len(pressures) not in (1, len(files))) or (len(pressures) == 1 and len(files) > 1):
        raise UserError(
            f"--pressure-kpa: got {len(pressures)} pressure(s) for {len(files)} file(s); give one per file, in order"
        )
    for v in pressures:
        if v < 0:
            raise UserError(f"--pressure-kpa: {v:g} kPa is below zero")
    return pressures


def _print_table2(summ: dict) -> None:
    """Table 2 of a processed set (its ``summary()``): a line per test, the replicates' mean ± std (n), the deadband.

    Tests at one pressure are replicates: each has its line (``#1``, ``#2``, ... and its file), then
    a ``mean`` line with the standard deviation over them and their number.  Plausibility warnings
    follow their test.
    """
    typer.echo(f"{'P (kPa)':>8} {'cycles':>6} {'M_blocked (N·mm)':>18} {'k_free (1/mm)':>20} {'loss ratio':>10}")
    groups = {float(g["pressure_kpa"]): g for g in summ.get("replicates", [])}
    tests = summ["pressures"]
    for k, r in enumerate(tests):
        group = groups.get(float(r["pressure_kpa"])) or {}
        several = int(group.get("n", 1)) > 1
        tag = f"  #{r.get('replicate', 1)} {r['source']}" if several else ""
        typer.echo(
            f"{r['pressure_kpa']:8.4g} {r['cycles']:6d} {r['blocked_moment_nmm']:9.2f} ± "
            f"{fmt_num(r['blocked_moment_se_nmm'], '6.2f')} {r['free_curvature_per_mm']:10.5f} ± "
            f"{fmt_num(r['free_curvature_se_per_mm'], '7.1e')} {100 * r['energy_loss_ratio']:9.2f}%{tag}"
        )
        for note in r["notes"]:
            typer.echo(f"         note: {note}")
        for warning in r.get("warnings", []):
            typer.echo(f"         warning: {warning}")
        if (r.get("drift") or {}).get("flagged") and not r["drift"].get("corrected"):
            typer.echo("         note: --drift linear subtracts the fitted offset")
        last = k + 1 == len(tests) or float(tests[k + 1]["pressure_kpa"]) != float(r["pressure_kpa"])
        if several and last:
            typer.echo(
                f"{'mean':>8} {'':6} {group['blocked_moment_nmm']:9.2f} ± "
                f"{fmt_num(group['blocked_moment_std_nmm'], '6.2f')} {group['free_curvature_per_mm']:10.5f} ± "
                f"{fmt_num(group['free_curvature_std_per_mm'], '7.1e')} {100 * group['energy_loss_ratio']:9.2f}%"
                f"  std over n = {group['n']} replicates"
            )
    typer.echo(f"deadband: {fmt_num(summ['deadband_kpa'], '.4g')} ± {fmt_num(summ['deadband_se_kpa'], '.2g')} kPa")


@app.command("simulate-test", cls=MultiValueCommand)
def simulate_test_cmd(
    preset: PresetOpt = None,
    actuator: ActuatorOpt = None,
    model: ModelOpt = None,
    pressure_kpa: PressureOpt = None,
    out: Annotated[
        Optional[Path], typer.Option("--out", help="Output folder for the raw files and truth.json.")] = None,
    table_fmt: Annotated[Optional[Format], typer.Option(
        "--table-format", help="Export dialect of the raw files: csv, testxpert, bluehill or mts (default csv).")]
    = None,
    fmt: Annotated[Optional[Format], typer.Option(
        "--format", hidden=True, help="Deprecated spelling of --table-format (--format is the figure format).")]
    = None,
    noise_n: Annotated[float, typer.Option("--noise-n", help="Force noise, standard deviation (N).")] = 0.05,
    noise_stroke_mm: Annotated[float, typer.Option("--noise-stroke-mm", help="Stroke noise, standard deviation (mm).")]
    = 0.002,
    hysteresis: Annotated[
        float,
        typer.Option("--hysteresis", help="Pressure part of the loop amplitude, as a fraction of the blocked moment."),
    ] = 0.06,
    hysteresis_angle_deg: Annotated[
        float, typer.Option("--hysteresis-angle-deg",
                            help="Loop angle (deg): saturation angle (pi) or characteristic angle (dahl).")
    ] = 5.0,
    hysteresis_law: Annotated[str, typer.Option("--hysteresis-law", help="Loop law: pi (Prandtl-Ishlinskii) or dahl.")]
    = "pi",
    hysteresis_offset_nmm: Annotated[
        float, typer.Option("--hysteresis-offset-nmm", help="Constant part of the loop amplitude (N·mm).")
    ] = 0.0,
    cycles: Annotated[int, typer.Option("--cycles", min=1, max=1000, help="Cycles per pressure.")] = 3,
    speed_mm_min: Annotated[float, typer.Option("--speed-mm-min", help="Crosshead speed (mm/min).")] = 30.0,
    rate_hz: Annotated[float, typer.Option("--rate-hz", help="Sampling rate (Hz).")] = 20.0,
    dwell_s: Annotated[float, typer.Option("--dwell-s", help="Dwell at each end of a stroke (s).")] = 0.0,
    stroke_offset_mm: Annotated[
        float, typer.Option("--stroke-offset-mm", help="Machine stroke at the blocked state (mm).")] = 0.0,
    fixture: FixtureOpt = "35,2.5,4",
    seed: Annotated[Optional[int], typer.Option("--seed", help="Random seed.")] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print truth.json (the true values) instead of one "
                                          "line per file.")] = False,
):
    """Write the raw files a testing machine would record for a model actuator (a virtual test)."""
    from bendpam.lab.simulate import SimulationSettings, simulate_tests
    from bendpam.physics.fixture import Fixture

    if out is None:
        raise UserError("give an output folder with --out DIR")
    dialect = deprecated_format(fmt, table_fmt, "simulate-test") or Format.csv
    act = load_actuator(preset, actuator, model)
    P = pressures_kpa(pressure_kpa)
    st = SimulationSettings(cycles=cycles, speed_mm_min=speed_mm_min, rate_hz=rate_hz, noise_n=noise_n,
                            noise_stroke_mm=noise_stroke_mm, hysteresis=hysteresis,
                            hysteresis_angle_deg=hysteresis_angle_deg, hysteresis_law=hysteresis_law,
                            hysteresis_offset_nmm=hysteresis_offset_nmm, dwell_s=dwell_s,
                            stroke_offset_mm=stroke_offset_mm, seed=seed)
    fx = Fixture.from_string(fixture, L0_mm=act.L0_mm, name="--fixture")
    with output_set(out, [actuator]) as o:
        try:
            truth = simulate_tests(act, P, o.staging, model_for(act, model), dialect=dialect.value, fixture=fx,
                                   settings=st)
        except InputError as exc:  # the library names the settings; this command's options say them as flags
            raise UserError(_SETTING_FLAGS.sub(lambda m: _FLAGS[m.group(0)], str(exc))) from None
    if as_json:
        print_json(truth)
        return
    for t in truth["pressures"]:
        typer.echo(
            f"{t['file']}: {t['samples']} samples, blocked {t['blocked_moment_nmm']:.2f} N·mm, "
            f"free k' {t['free_curvature_per_mm']:.5f} 1/mm, loss ratio {100 * t['energy_loss_ratio']:.1f}%"
        )
    echo_wrote(f"wrote {out}/ ({len(truth['files'])} files and truth.json)")
