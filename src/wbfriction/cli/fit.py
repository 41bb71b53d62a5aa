"""``wbfriction fit``, ``export``, ``predict`` and ``report``: the friction model of a friction table and where
it goes."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Optional, cast

import typer
from rich.markup import escape
from rich.table import Table

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: each command imports the rest of the library when it runs.
from wbfriction.exceptions import InputError
from wbfriction.export.catalog import targets_words
from wbfriction.fit.options import FitOptions, ModelChoice, model_choices
from wbfriction.friction.options import TemperatureLaw
from wbfriction.pipeline.paths import check_paths
from wbfriction.quantities import check_options

if TYPE_CHECKING:
    from wbfriction.fit.result import FitResult
    from wbfriction.model.robot import Robot

from wbfriction.cli.common import (
    FIT,
    ConfigOpt,
    EnergyThresholdOpt,
    EnergyToleranceOpt,
    FitWorkersOpt,
    FrictionArg,
    MaxHarmonicOpt,
    MinSamplesOpt,
    MjcfOpt,
    ModelOpt,
    ReferenceTemperatureOpt,
    RobotOpt,
    TemperatureLawOpt,
    TermsOpt,
    UrdfOpt,
    VerboseOpt,
    WideOpt,
    app,
    console,
    given_options,
    out,
    print_whole,
    robot_of,
    stages,
    term_options,
    warn,
    warn_energy,
)
from wbfriction.cli.helpformat import FRICTION
from wbfriction.cli.outputs import suffixes, written_as


def _print_fits(results: list[FitResult], wide: bool = False, verbose: bool = False) -> None:
    """The fitted friction's tables and notes (:mod:`~wbfriction.report.terminal`), as wide as the terminal,
    the joints by their names (as the log, the URDF and every other command name them)."""
    from wbfriction.report.terminal import fit_notes, fit_tables, terms_notes

    for table in fit_tables(results, wide):
        print_whole(table) if wide else out.print(table)
    for line in [*fit_notes(results, verbose, wide=wide), *terms_notes(results, verbose)]:
        out.print(escape(line), highlight=False)


def _run_fit(friction: Path, output: Path, options: FitOptions, threshold: float, tolerance: float,
             workers: int, wide: bool = False, verbose: bool = False) -> None:
    from wbfriction.pipeline.fit_step import fit_file

    with stages() as stage:
        stage(f"reading {friction.name}")
        fitted = fit_file(friction, output, options, threshold=threshold, tolerance=tolerance, workers=workers,
                          progress=stage.steps)
    _print_fits(fitted.fits, wide, verbose)
    warn_energy(fitted.energy, verbose)
    console.print(f"wrote {output}")


FitModelOpt = typer.Option(FIT.model, "--model", metavar=f"[{'|'.join(model_choices())}]",
                           help=f"{ModelOpt.help} Or a family a program registered, or an installed package "
                                "advertises (entry points 'wbfriction.families').")
"""``--model``: any family's name, checked once, by :class:`~wbfriction.fit.options.FitOptions` (its error names the
families known)."""


@app.command(rich_help_panel=FRICTION,
             short_help="Fit a friction model per joint, with standard errors and a status per fit")
def fit(friction: Path = FrictionArg,
        output: Path = typer.Option(..., "-o", "--output", callback=written_as("json"),
                                    help=f"Parameters to write (JSON, {suffixes('json')})."),
        min_samples: int = MinSamplesOpt,
        energy_threshold: float = EnergyThresholdOpt, energy_tolerance: float = EnergyToleranceOpt,
        workers: int = FitWorkersOpt, model: str = FitModelOpt,
        selection_tolerance: float = typer.Option(FIT.selection_tolerance, min=0.0,
                                                  help="With --model auto: relative excess of held-out RMS within "
                                                       "which the simpler model is chosen."),
        terms: str = TermsOpt, max_harmonic: int = MaxHarmonicOpt,
        reference_temperature: Optional[float] = ReferenceTemperatureOpt,
        temperature_law: TemperatureLaw = TemperatureLawOpt,
        pass_rows: float = typer.Option(FIT.pass_rows, min=0.0,
                                        help="A reversal crossing the speeds a joint may stick at within this many "
                                             "samples passes through zero and stays in the fit; a slower one may "
                                             "hold a stop and is left out with the filter's reach (inf: every "
                                             "reversal; 0: none)."),
        stick_floor: float = typer.Option(FIT.stick_floor, min=0.0,
                                          help="Speed [rad/s] below which a joint that lingers may stick or creep "
                                               "(a loaded stance leg), whatever its velocity's noise: those samples "
                                               "are left out of the fit."),
        wide: bool = WideOpt, verbose: bool = VerboseOpt) -> None:
    """Identify a friction model of every joint, with standard errors and the parameters left
    at a bound; warn about joints whose friction generates power (eq. 7.9)."""
    check_paths({"FRICTION": friction}, {"-o": output})
    _run_fit(friction, output, FitOptions(model=cast(ModelChoice, model), selection_tolerance=selection_tolerance,
                                          min_samples=min_samples, pass_rows=pass_rows, stick_floor=stick_floor,
                                          terms=term_options(terms, max_harmonic, reference_temperature,
                                                             temperature_law)),
             energy_threshold, energy_tolerance, workers, wide, verbose)


@app.command(rich_help_panel=FRICTION,
             short_help="Write the fitted friction where simulators read it (MJCF, URDF, Isaac Lab)")
def export(ctx: typer.Context,
           params: Path = typer.Argument(..., metavar="PARAMS", help="Parameters written by 'wbfriction fit'."),
           outputs: list[Path] = typer.Option(..., "-o", "--output", callback=written_as("export"),
                                              help=f"File to write, format by name: {targets_words()}; repeat -o "
                                                   "for several."),
           include: str = typer.Option("", "--include",
                                       help="Fit statuses exported besides ok, comma-separated: weak (large "
                                            "standard errors), at-bound (a parameter at a bound of the fit), "
                                            "routes-disagree (the two routes' fits differ: one is biased), "
                                            "does-not-predict (fitted on the first 70 % of its samples it "
                                            "mispredicts the rest). "
                                            "Fits not excited or failed are never exported."),
           physics_dt: float = typer.Option(0.005, "--physics-dt",
                                            help="Physics step [s] of the Isaac Lab simulation a PD-driven robot's "
                                                 "delay is counted in (.yaml: min_delay = max_delay = delay / "
                                                 "physics-dt, rounded to whole steps, with a warning): 0.005, Isaac "
                                                 "Lab's locomotion tasks (sim.dt 1/200, decimation 4)."),
           robot: str = RobotOpt, urdf: Optional[Path] = UrdfOpt, config: Optional[Path] = ConfigOpt,
           mjcf: Optional[Path] = MjcfOpt) -> None:
    """Write the fitted friction where simulators read it: the fits whose status is ok (and --include),
    each with its status in a comment; the other actuated joints hold no friction (.urdf: their <dynamics> set
    to 0; .xml: 0; from an MJCF model file: its own values). F_v -> damping,
    F_c -> Coulomb friction (MuJoCo frictionloss); the Stribeck bump and the tanh have no
    simulator field and are dropped. Inertias are the URDF's: give --urdf IDENTIFIED.urdf to export
    identified ones. A robot with PD-driven joints ([pd] in its TOML) gets its drivers: gains, torque limits, delay,
    encoder offsets and the fits' constant tau_os as a set-point offset tau_os/kp (MuJoCo position actuators; an
    Isaac Lab DelayedPDActuatorCfg); elsewhere tau_os, a torque sensor's offset, is dropped. The .xml is the whole
    MuJoCo model: the URDF's collision geometry (meshes by absolute path), a floor and free joint under a floating
    base, a motor per torque-controlled joint, the keyframe 'stance'."""
    from wbfriction.pipeline.export_step import export_files

    check_paths({"PARAMS": params, "--urdf": urdf, "--mjcf": mjcf, "--config": config},
                {f"-o {o}": o for o in outputs})
    check_options({"--physics-dt": ("physics_dt", physics_dt)})
    r = robot_of(robot, urdf, config, mjcf)
    if "physics_dt" in given_options(ctx):
        refuse_physics_dt(r, outputs)
    with stages() as stage:
        stage(f"exporting {params.name} to {len(outputs)} file{'s' if len(outputs) > 1 else ''}")
        result = export_files(r, params, outputs, include=[c.strip() for c in include.split(",") if c.strip()],
                              physics_dt=physics_dt)
    counts = result.selection.exported_statuses
    console.print(f"exported the friction of {sum(counts.values())} joints ("
                  + ", ".join(f"{n} {status}" for status, n in counts.items()) + ")", highlight=False)
    for status, joints in result.selection.left_out.items():
        console.print(f"not exported, {status}: {', '.join(joints)}", highlight=False, soft_wrap=True)
    instead = result.selection.instead
    if instead:
        console.print("the simplest family's fit (coulomb-viscous, no terms) exported in place of the model chosen, "
                      "not ok: " + ", ".join(f"{j} ({f.model}, {f.verdict().status})" for j, f in instead.items()),
                      highlight=False, soft_wrap=True)
    with_terms = {j: t.kept for j, f in result.selection.exported.items() if (t := f.kept_terms) is not None}
    if with_terms:
        console.print("no simulator holds the terms beyond velocity: dropped for "
                      + ", ".join(f"{j} ({', '.join(kept)})" for j, kept in with_terms.items())
                      + "; their F_c, F_v are at the reference conditions (zero load, T_ref), as each joint's note "
                        "says", highlight=False, soft_wrap=True)
    if result.drive is not None and result.drive.torque_offset:
        drive = result.drive
        shifts = [1e3 * (drive.setpoint_offset(j) - drive.offset(j)) for j in drive.torque_offset]
        console.print(f"PD drivers: the fits' constant tau_os written as set-point offsets tau_os/kp on "
                      f"{len(shifts)} joints ({min(shifts):.3g} to {max(shifts):.3g} mrad), where the drive applies "
                      "it (the URDF has no drive: there it is dropped)", highlight=False, soft_wrap=True)
    warn(dict.fromkeys(w for report in result.reports for w in report.warnings))
    for path, fmt in result.outputs:
        console.print(f"wrote {path} ({fmt})")


@app.command(rich_help_panel=FRICTION)
def predict(friction: Path = typer.Argument(..., metavar="FRICTION",
                                            help="Friction table of a held-out log ('wbfriction estimate' with the URDF"
                                                 " under test)."),
            params: Path = typer.Option(..., "--params", help="Parameters fitted on other logs estimated with "
                                                              "the same URDF ('wbfriction fit')."),
            table_file: Optional[Path] = typer.Option(None, "--table", callback=written_as("table"),
                                                 help=f"Also write the prediction table ({suffixes('table')}): per "
                                                      "sample and joint, time from the log's start [s], qd, "
                                                      "measured and predicted torque and friction, residual [N·m]; "
                                                      "each joint's RMS in its metadata."),
            figure: Optional[Path] = typer.Option(None, "--figure", callback=written_as("png"),
                                                  help="Also write a PNG: per joint, measured and predicted torque "
                                                       "over time (a panel per run) and friction against "
                                                       "velocity.")) -> None:
    """How well a model predicts torques it was not fitted on: per joint, the RMS of measured minus
    predicted torque, tau - (M qdd + h + f(qd)), with the friction model and without it; where the log leaves
    the angles, loads or temperatures the fit's terms were fitted on, it says so (well outside: status
    'outside fitted ranges'). --table and --figure write it sample by sample."""
    import numpy as np

    from wbfriction.fit.ranges import OUTSIDE
    from wbfriction.report.prediction import write_prediction

    check_paths({"FRICTION": friction, "--params": params}, {"--table": table_file, "--figure": figure})
    with stages() as stage:
        stage(f"predicting the torques of {friction.name}")
        pred = write_prediction(friction, params, table_file, figure)
    table = Table(title=f"Torque prediction on {friction.name}: RMS of measured - predicted [N·m]", box=None,
                  collapse_padding=True, caption_justify="left",
                  caption="rigid body: the inertia model alone; friction: with the friction model; moving: with it, "
                          "where the joint moves (not where it may stick: static friction); allowed: there, what the "
                          "log's noise and the fit's standard errors allow (its model refitted on this log); still: "
                          "the joint did not move in this log; (!): it does not predict it")
    numbers = ("samples", "rigid body", "friction", "moving", "allowed")
    for col in ("joint", *numbers, "fit"):  # the joint and the numbers never cut: the status wraps
        table.add_column(col, justify="right" if col in numbers else "left", no_wrap=col != "fit")
    statuses = pred.status or ("",) * len(pred.joints)
    checks = pred.checks or (None,) * len(pred.joints)
    for j, n, rigid, full, status, check in zip(pred.joints, pred.samples, pred.rms_rigid_body, pred.rms, statuses,
                                                checks):
        moving = "still" if check is None else f"{check.rms:.3g}"
        allowed = "" if check is None else f"{check.allowed:.3g}" + ("" if check.predicts else " (!)")
        table.add_row(j, str(n), f"{rigid:.3g}", "—" if not np.isfinite(full) else f"{full:.3g}", moving, allowed,
                      status, style=None if status in ("ok", "") else "dim")
    rigid, full = pred.overall(pred.rms_rigid_body), pred.overall(pred.rms)
    table.add_row("all joints", str(int(pred.samples.sum())), f"{rigid:.3g}",
                  "—" if not np.isfinite(full) else f"{full:.3g}", "", "", "", style="bold", end_section=True)
    out.print(table)
    for j, kept in zip(pred.joints, pred.terms or ()):
        if kept:
            out.print(f"with its terms beyond velocity, {j}: {', '.join(kept)}", highlight=False)
    for j, use in zip(pred.joints, pred.ranges or ()):  # a term used beyond what it was fitted on, said
        for sentence in [] if use is None else use.sentences():
            console.print(f"{escape(j)}: {escape(sentence)}", highlight=False, soft_wrap=True)
    for j, check in zip(pred.joints, checks):
        if check is not None and not check.predicts:
            console.print(f"{escape(j)}: does not predict this log: {escape(check.describe())}", highlight=False)
    if OUTSIDE in statuses:
        console.print(f"{OUTSIDE}: this log's signals are beyond the ranges the fit's terms were fitted on by more "
                      "than those ranges' widths: their laws are extrapolated there, which the fit's status does not "
                      "cover",
                      highlight=False, soft_wrap=True)
    if any(status not in ("ok", "", OUTSIDE) for status in statuses):
        console.print("a prediction by a fit that is not ok is no better than that fit: see 'fit' for the reason")
    for path in (table_file, figure):
        if path is not None:
            console.print(f"wrote {path}")


@app.command(rich_help_panel=FRICTION,
             short_help="One self-contained HTML report of the friction, its fits and their checks")
def report(friction: Path = FrictionArg,
           output: Path = typer.Option(Path("report.html"), "-o", "--output", callback=written_as("html"),
                                       help=f"HTML file to write ({suffixes('html')})."),
           params: Optional[Path] = typer.Option(None, help="Parameters written by 'wbfriction fit' (default: "
                                                            "fitted here)."),
           identification: Optional[Path] = typer.Option(None, help="JSON written by 'wbfriction identify --json': "
                                                                    "adds the held-out torque RMS, both routes' "
                                                                    "friction and the body changes."),
           energy_threshold: float = EnergyThresholdOpt, energy_tolerance: float = EnergyToleranceOpt,
           workers: int = typer.Option(2, min=1, help="Processes fitting the joints (without --params) and "
                                                     "rendering their figures (the same report for any "
                                                     "number).")) -> None:
    """One self-contained HTML report: friction clouds and fits, parameters, energy consistency,
    per-joint time series, Fig. 7.4, spectra, provenance."""
    from wbfriction.report.build import make_report
    from wbfriction.report.html import write_report

    check_paths({"FRICTION": friction, "--params": params, "--identification": identification}, {"-o": output})

    with stages() as stage:
        stage("building the report")
        rep = make_report(friction, params, energy_threshold, energy_tolerance, identification, workers)
        write_report(rep, output, workers)
    warn_energy(rep.energy.values())
    console.print(f"wrote {output} ({len(rep.est.joints)} joints, {len(rep.flagged)} flagged)")


def refuse_physics_dt(r: Robot, outputs: list[Path]) -> None:
    """``--physics-dt`` given where nothing reads it: no output's target counts a delay in physics steps
    (:attr:`~wbfriction.export.target.ExportTarget.reads`), or the robot has no PD drivers whose delay it counts.

    Raises:
        InputError: naming the option and why.
    """
    from wbfriction.export.registry import target_for, targets

    if not any("physics_dt" in target_for(o).reads for o in outputs):
        readers = " or ".join(t.suffixes[0] for t in targets() if "physics_dt" in t.reads)
        raise InputError(f"--physics-dt: only a {readers} output counts a delay in physics steps")
    if r.pd is None:
        raise InputError(f"--physics-dt: robot '{r.name}' has no PD drivers ([pd]) whose delay it counts")
