"""The ``bendpam report`` command: raw test files -> one self-contained HTML report.

``register(app)`` adds the command to the ``bendpam`` Typer app.  Like the other commands it only
parses and prints; the work is :func:`bendpam.present.report.build_report`.

(No ``from __future__ import annotations`` here: the command is defined inside ``register`` and
Typer reads its annotations as objects.)
"""

import warnings
from pathlib import Path
from typing import Annotated, Optional

import typer

__all__ = ["register"]


def register(app: typer.Typer) -> None:
    """Add the ``report`` command to ``app`` (does nothing if it has one already).

    >>> app = typer.Typer()
    >>> register(app)
    >>> register(app)
    >>> [c.name for c in app.registered_commands]
    ['report']
    """
    if any(getattr(c, "name", None) == "report" for c in app.registered_commands):
        return
    from bendpam.cli.options import (
        RANGE_HELP,
        ActuatorOpt,
        ColumnsOpt,
        DriftMethod,
        DriftOpt,
        ForceUncertaintyOpt,
        FormatFileOpt,
        PresetOpt,
        PressureForceUncertaintyOpt,
        PressureUncertaintyOpt,
        QuietOpt,
        RateOpt,
        RepairOpt,
        ZeroUncertaintyOpt,
    )

    @app.command("report")
    def report(
        inputs: Annotated[list[Path], typer.Argument(help="Raw test files, or a folder of them.", show_default=False)],
        preset: PresetOpt = None,
        actuator: ActuatorOpt = None,
        out: Annotated[Optional[Path], typer.Option("--out", help="The HTML report to write (report.html).")] = None,
        pressure_kpa: Annotated[
            Optional[list[str]],
            typer.Option("--pressure-kpa", help=f"Pressure of each file in kPa, in file order: {RANGE_HELP} "
                         "(default: each file's metadata or filename)."),
        ] = None,
        l0_mm: Annotated[
            Optional[float],
            typer.Option("--l0-mm", help="Active length L0 for k' = 2 beta / L0 (mm); default: the actuator's."),
        ] = None,
        fixture: Annotated[str, typer.Option("--fixture", help="Fixture geometry d,r,t in mm.")] = "35,2.5,4",
        free: Annotated[
            str, typer.Option("--free", help="Parameters to identify, of alpha0, C10, C01, P_start, E_f, R0_start: "
                              "'alpha0 C10 C01' or 'alpha0,C10,C01'.")
        ] = "alpha0,C10,C01",
        model: Annotated[
            Optional[list[str]],
            typer.Option("--model", help="Model(s) to fit: energy, force-balance ('energy force-balance', "
                         "'energy,force-balance' or repeated; default both)."),
        ] = None,
        force_uncertainty_pct: ForceUncertaintyOpt = 0.0,
        pressure_uncertainty_kpa: PressureUncertaintyOpt = 0.0,
        zero_uncertainty_n: ZeroUncertaintyOpt = None,
        pressure_force_uncertainty_n_per_kpa: PressureForceUncertaintyOpt = None,
        columns: ColumnsOpt = None,
        rate_hz: RateOpt = None,
        repair: RepairOpt = False,
        format_file: FormatFileOpt = None,
        drift: DriftOpt = DriftMethod.none,
        quiet: QuietOpt = False,
        as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object (Table 2, the deadband, each "
                                              "model's parameters and NRMSEs, the warnings) instead of lines.")]
        = False,
        progress: Annotated[bool, typer.Option("--progress/--no-progress", hidden=True,
                                               help="Same as --quiet (--no-progress).")] = True,
    ):
        """Process raw cyclic tests, fit the models and write ONE self-contained HTML report.

        The page warns at the top when a fit is poor or the data do not match the actuator, and
        prints cleanly to PDF from a browser.
        """
        read = {"columns": columns, "rate_hz": rate_hz, "repair": repair, "format_file": format_file}
        _report(inputs, preset, actuator, out, pressure_kpa, l0_mm, fixture, free, model, progress and not quiet,
                as_json, (force_uncertainty_pct, pressure_uncertainty_kpa, zero_uncertainty_n,
                          pressure_force_uncertainty_n_per_kpa), read, DriftMethod(drift).value)


def _report(inputs, preset, actuator, out, pressure_kpa, l0_mm, fixture, free, model, progress,
            as_json=False, instrument=(0.0, 0.0, None, None), read=None, drift="none") -> None:
    from bendpam.cli.options import (
        Model,
        UserError,
        collect_raw_files,
        echo_wrote,
        load_actuator,
        output_file,
        parse_values,
    )
    from bendpam.errors import PlausibilityWarning
    from bendpam.identify.uncertainty import Instrument
    from bendpam.physics.fixture import Fixture
    from bendpam.present.report import build_report, fmt_value

    if out is None:
        raise UserError("give the report to write with --out report.html")
    if out.suffix.lower() not in {".html", ".htm"}:
        raise UserError(f"--out {str(out)!r}: the report is HTML; give a file name ending in .html")
    if out.is_dir():
        raise UserError(f"--out {str(out)!r} is a folder; give the HTML file to write, e.g. report.html")
    models = []
    for tok in model or ["energy", "force-balance"]:
        for part in tok.replace(",", " ").split():
            try:
                m = Model(part.strip().lower().replace("_", "-"))
            except ValueError:
                raise UserError(f"--model {part!r} is not known; choose energy or force-balance") from None
            if m not in models:
                models.append(m)
    if not models:
        raise UserError("--model: give energy, force-balance or both")
    # the nominal actuator: a preset takes the first model's Table 3 constants (start values only)
    act = load_actuator(preset, actuator, models[0])
    files = collect_raw_files(inputs)
    pressures = parse_values(pressure_kpa, "--pressure-kpa") if pressure_kpa else None
    if pressures is not None and len(pressures) != len(files):
        raise UserError(
            f"--pressure-kpa: got {len(pressures)} pressure(s) for {len(files)} file(s); give one per file, in order"
        )
    fx = Fixture.from_string(fixture, L0_mm=act.L0_mm if l0_mm is None else l0_mm, name="--fixture")
    declared = (read or {}).get("format_file")
    if declared is not None:
        from bendpam.lab import load_declaration

        load_declaration(declared)  # refused before any file is read
    with output_file(out, [*files, actuator, declared]) as f, warnings.catch_warnings(record=True) as found:
        warnings.simplefilter("always", PlausibilityWarning)
        res = build_report(files, act, f.path, models=[m.value for m in models], free=free, pressure_kpa=pressures,
                           fixture=fx, progress=progress, shown_as=str(out), instrument=Instrument(*instrument),
                           processing_options={"drift": drift}, read_options=read)
    _rewarn(found, res.warnings)

    summ = res.summary
    if as_json:
        _print_json(res, out)
        return
    for row in res.table2:
        typer.echo(f"{row['pressure_kpa']:>6} kPa  {row['cycles']} cycles  blocked moment (N·mm) "
                   f"{row['blocked_moment_nmm']}  free curvature (1/mm) {row['free_curvature_per_mm']}  "
                   f"energy loss (%) {row['energy_loss_percent']}")
    typer.echo(f"deadband: {fmt_value(summ['deadband_kpa'], summ['deadband_se_kpa'], 'kPa')}")
    for row in res.table3:
        typer.echo(f"{row['model']}: α₀ (°) {row['alpha0']}, C₁₀ (kPa) {row['C10']}, C₀₁ (kPa) {row['C01']}, "
                   f"μ (kPa) {row['mu']}; NRMSE (%) cycles {row['nrmse_cycles']}, blocked moment "
                   f"{row['nrmse_blocked_moment']}, free curvature {row['nrmse_free_curvature']}")
    for w in res.warnings:
        typer.echo(f"bendpam: {w.severity}: {w.title}", err=True)
    for note in res.notes:
        typer.echo(f"bendpam: warning: {note}", err=True)
    n_w = sum(w.severity == "warning" for w in res.warnings)
    box = f", {n_w} warning(s) and {len(res.warnings) - n_w} caution(s) at the top" if res.warnings else ""
    echo_wrote(f"wrote {out} ({res.bytes / 1024:.0f} KiB, {len(res.figures)} figures{box})")


def _rewarn(found, boxed) -> None:
    """The warnings raised while the report was built, again, but those the page's warning box repeats (a test's
    plausibility finding is both; the command prints the box's titles): each once."""
    from bendpam.errors import PlausibilityWarning

    titles = [w.title for w in boxed]
    for w in found:
        text = str(w.message).strip()
        if issubclass(w.category, PlausibilityWarning) and any(text[:100] in t for t in titles):
            continue
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def _print_json(res, out) -> None:
    """``report --json``: the report's numbers as one JSON object."""
    from bendpam.cli.options import print_json

    fits = {m: {k: d[k] for k in ("model", "parameters", "nrmse", "converged", "flags") if k in d}
            for m, d in ((m, f.to_dict()) for m, f in res.fits.items())}
    print_json({"report": str(out), "table2": res.summary, "fits": fits, "failed": dict(res.failed),
                "warnings": [{"severity": w.severity, "kind": w.kind, "title": w.title} for w in res.warnings],
                "notes": list(res.notes)})
