"""``wbfriction batch`` and ``trends``: a fleet's logs on Dask and the drifts of their friction."""

from __future__ import annotations

import time
from pathlib import Path
from typing import TYPE_CHECKING, Optional, cast

import typer
from rich.markup import escape

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: each command imports the rest of the library when it runs.
from wbfriction.fit.options import FitOptions, ModelChoice, model_choices
from wbfriction.fleet.options import SHAPES, Shape
from wbfriction.friction.options import EstimateOptions, TemperatureLaw
from wbfriction.logs.formats.catalog import table_formats
from wbfriction.pipeline.paths import check_paths
from wbfriction.signals.options import DiffOption

if TYPE_CHECKING:
    pass

from wbfriction.cli.common import (
    ESTIMATE,
    FIT,
    ConfigOpt,
    MaxHarmonicOpt,
    MinSamplesOpt,
    ReferenceTemperatureOpt,
    RobotOpt,
    TemperatureLawOpt,
    TermsOpt,
    UrdfOpt,
    app,
    console,
    stages,
    term_options,
)
from wbfriction.cli.helpformat import FLEETS
from wbfriction.cli.outputs import suffixes, written_as


@app.command(rich_help_panel=FLEETS)
def batch(source: Path = typer.Argument(..., metavar="MANIFEST",
                                        help="Manifest (a CSV or Parquet table: its columns hold text; columns "
                                             "log, robot_id, start_time [ISO 8601 with zone], robot or urdf/config, "
                                             "optional diff and model), or a folder of <robot_id>/<log> files (with "
                                             f"--robot or --urdf/--config), each log a {table_formats()} file."),
          output: Path = typer.Option(..., "-o", "--output", help="Results folder: a Parquet dataset, a folder per "
                                                                  "robot; logs whose results are there are "
                                                                  "skipped, results of a log listed with anything "
                                                                  "changed are replaced. Failures go beside it "
                                                                  "(RESULTS-failed)."),
          robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
          workers: Optional[int] = typer.Option(None, min=1, help="Worker processes of the local Dask cluster "
                                                                  "[default: 2]."),
          scheduler: Optional[str] = typer.Option(None, help="Address of a running Dask scheduler "
                                                             "(tcp://host:8786) instead of a local cluster; its "
                                                             "workers must see the logs and the results."),
          serial: bool = typer.Option(False, "--serial", help="One log after the other in this process, without "
                                                              "Dask (the reference the cluster's results equal)."),
          tables: Optional[Path] = typer.Option(None, "--tables",
                                                help="Also keep each log's friction table in this folder "
                                                     "(TABLES/<robot_id>/<key>.parquet)."),
          diff: DiffOption = typer.Option(ESTIMATE.diff, help="Differentiation, as 'wbfriction estimate --diff' (a "
                                                        "manifest's diff column overrides it per log)."),
          model: str = typer.Option(FIT.model, metavar=f"[{'|'.join(model_choices())}]",
                                    help="Friction model, as 'wbfriction fit --model' (a manifest's model column "
                                         "overrides it per log)."),
          min_samples: int = MinSamplesOpt, terms: str = TermsOpt, max_harmonic: int = MaxHarmonicOpt,
          reference_temperature: Optional[float] = ReferenceTemperatureOpt,
        temperature_law: TemperatureLaw = TemperatureLawOpt) -> None:
    """Estimate, fit and check every log of a fleet on Dask, into one results dataset (exit status 1 when a log
    failed: it is listed, the others are done)."""
    from wbfriction.fleet.batch import check_outputs, quiet_dask_logs, run_batch
    from wbfriction.fleet.manifest import read_manifest, scan_folder
    from wbfriction.fleet.options import BatchOptions
    from wbfriction.fleet.results import failures_folder
    from wbfriction.pipeline.estimate_step import RobotSpec

    check_paths({"MANIFEST": source}, {})
    options = BatchOptions(estimate=EstimateOptions(diff=diff), fit=FitOptions(  # refused before any log is read
        model=cast(ModelChoice, model), min_samples=min_samples,
        terms=term_options(terms, max_harmonic, reference_temperature, temperature_law)))
    check_outputs(output, tables)
    quiet_dask_logs()  # its faults are said here, one line each
    start = time.perf_counter()
    if source.is_dir():
        scan = scan_folder(source, RobotSpec.given(robot, urdf, config),
                           exclude=[p for p in (output, failures_folder(output), tables) if p is not None])
        for skipped in scan.skipped:
            console.print(f"[yellow]skipped:[/] {escape(str(skipped))}", highlight=False, soft_wrap=True)
        entries = scan.entries
    else:
        entries = read_manifest(source)
    with stages() as status:
        advance = status.steps("batch", len(entries), "logs")
        summary = run_batch(entries, output, options, engine="serial" if serial else "dask", workers=workers,
                            scheduler=scheduler, tables=tables, progress=lambda outcome: advance(1))
    for a, b in summary.copies:
        console.print(f"[yellow]note:[/] {escape(b.where)} has the same bytes as {escape(a.where)}: two results",
                      highlight=False, soft_wrap=True)
    for note in (*summary.stale, *summary.foreign):
        console.print(f"[yellow]note:[/] {escape(str(note))}", highlight=False, soft_wrap=True)
    for _, error in summary.failed:
        console.print(f"[bold red]failed:[/] {escape(error)}", highlight=False, soft_wrap=True)
    why = "".join(f"; {n} {reason}" for reason, n in sorted(summary.reasons.items()) if reason != "new")
    kept = f", {summary.kept} of logs not listed kept" if summary.kept else ""
    console.print(f"{summary.processed} logs processed ({len(summary.failed)} failed{why}), {summary.skipped} already "
                  f"done{kept}; results in {output} ({time.perf_counter() - start:.1f} s)", highlight=False,
                  soft_wrap=True)
    if summary.failed:
        console.print(f"failures recorded in {failures_folder(output)}", highlight=False, soft_wrap=True)
        raise typer.Exit(1)


@app.command(rich_help_panel=FLEETS)
def trends(results: Path = typer.Argument(..., metavar="RESULTS", help="Results folder written by 'wbfriction "
                                                                       "batch'."),
           output: Path = typer.Option(..., "-o", "--output", callback=written_as("html"),
                                       help=f"HTML page to write ({suffixes('html')})."),
           table: Optional[Path] = typer.Option(None, "--table", callback=written_as("text-table"),
                                                help=f"Also write the trends as a table ({suffixes('text-table')})."),
           alpha: float = typer.Option(1e-3, min=1e-6, max=0.5, help="False-alarm probability per joint."),
           replicates: Optional[int] = typer.Option(None, min=1, help="Noise series of the p-values' Monte Carlo "
                                                                      "[default: 20000, more for a small --alpha]."),
           min_change: float = typer.Option(0.10, min=0.0, help="Smallest change flagged, relative to the "
                                                                "baseline (0.1: 10 %)."),
           shapes: str = typer.Option(",".join(SHAPES), help="Shapes of change tested, comma-separated: "
                                                                   "hinge (a linear drift from an onset), step "
                                                                   "(a jump at it); the better one per series."),
           temperature: bool = typer.Option(True, help="Compare each series' values at one temperature where its "
                                                       "logs record theirs (temperature.<joint>) and they spread."),
           reference_temperature: Optional[float] = typer.Option(None, help="That temperature [°C] [default: each "
                                                                            "series' median]."),
           title: str = typer.Option("Friction trends", help="The page's title.")) -> None:
    """Friction over time per robot and joint, and the joints whose friction drifted (a hinge or step change
    detector weighted by the fits' standard errors), as one HTML page."""
    import math

    from wbfriction.fleet.results import read_results
    from wbfriction.fleet.trends import UNITS, TrendOptions, fleet_trends
    from wbfriction.logs.tables import write_table
    from wbfriction.report.numbers import p_value_text
    from wbfriction.report.trends import write_trends_html

    check_paths({"RESULTS": results}, {"-o": output, **({"--table": table} if table is not None else {})})
    options = TrendOptions(alpha=alpha, min_change=min_change, replicates=replicates,
                           shapes=tuple(cast("Shape", s.strip()) for s in shapes.split(",") if s.strip()),
                           temperature=temperature, reference_temperature=reference_temperature)
    with stages() as status:
        status(f"reading {results}")
        dataset = read_results(results)
        for note in dataset.notes():  # files left out, start times holding several logs
            label, _, text = note.partition(": ")
            console.print(f"[yellow]{label}:[/] {escape(text)}", highlight=False, soft_wrap=True)
        status(f"testing {dataset.table.num_rows} rows for drifts ({options.draws()} noise series per test)")
        found = fleet_trends(dataset.table, options)
        status(f"writing {output}")
        write_trends_html(found, output, title)
        if table is not None:
            write_table(found.to_table(), table)
    notes = found.temperature_notes()
    if notes:
        robot_id, joint, quantity, note = notes[0]
        joints = len({(r, j) for r, j, _, _ in notes})
        console.print(f"[yellow]note:[/] temperature left out of {len(notes)} series on {joints} joint"
                      f"{'s' if joints > 1 else ''} (first {escape(robot_id)} {escape(joint)} {quantity}: "
                      f"{note.removeprefix('temperature left out: ')}); --table writes each series' temperature_note",
                      highlight=False, soft_wrap=False)  # a note, not an error line: wrapped to the terminal
    for j in found.flagged:
        cp = j.drifts[0]
        size = (f"{100 * cp.relative:+.1f} %" if not math.isnan(cp.relative)
                else f"{cp.change:+.3g} {UNITS[cp.quantity]} from a baseline not told from zero")
        console.print(f"drift: {j.robot_id} {j.joint}: {cp.quantity} {size} ({cp.shape}) from {cp.onset_time:%Y-%m-%d} "
                      f"(p {p_value_text(cp.p_value)})", highlight=False)
    console.print(f"{found.summary()}; wrote {output}" + (f" and {table}" if table is not None else ""),
                  highlight=False)


