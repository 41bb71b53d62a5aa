"""The command line's shared parts: the app, its two consoles (messages on standard error, one line each;
results on standard output, as wide as the terminal), the options several commands take with the library's
defaults, the robot from --robot/--urdf/--config/--mjcf, the refusal of the options a command's mode does not read
(:func:`refuse_options`), the progress of its stages (:func:`stages`) and the entry point :func:`main`."""

from __future__ import annotations

import sys
from collections.abc import Collection, Mapping
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Optional, cast

import typer
from rich.console import Console
from rich.markup import escape

# Loading this module (what `wbfriction --help` and every command pay before they start) imports only the
# options, whose defaults the help shows: each command imports the rest of the library when it runs.
from wbfriction.cli.helpformat import MAX_WIDTH, SectionedGroup
from wbfriction.cli.stages import Stages
from wbfriction.exceptions import InputError, OptionError, WbfrictionError
from wbfriction.fit.options import DEFAULT_THRESHOLD, DEFAULT_TOLERANCE, FitOptions, TermOptions
from wbfriction.friction.options import TERMS, EstimateOptions, TemperatureLaw, Term
from wbfriction.inertia.options import InertialOptions
from wbfriction.logs.formats.catalog import table_formats
from wbfriction.logs.options import LIMIT_MARGIN, MAX_GAP, MAX_GAP_LEAST
from wbfriction.model.robots import BUILTIN_ROBOTS
from wbfriction.registry import one_line_warnings
from wbfriction.signals.options import NOISE_TARGET, FilterOptions
from wbfriction.sim.options import IdealOptions, MujocoOptions
from wbfriction.version import __version__
from wbfriction.walking.options import GaitOptions

if TYPE_CHECKING:
    from wbfriction.model.robot import Robot

# rich_markup_mode=None: click's plain help, so that units in brackets ([m], [rad/s], [friction.<group>]) are
# printed as written (Rich markup would take them for tags and delete them); the commands in sections, the help as
# wide as the terminal up to MAX_WIDTH (click's default stops at 80)
app = typer.Typer(add_completion=False, rich_markup_mode=None, cls=SectionedGroup,
                  context_settings={"max_content_width": MAX_WIDTH})
console = Console(stderr=True, soft_wrap=True)  # a message is one line, wrapped by the terminal, not cut into lines
out = Console()  # as wide as the terminal (COLUMNS); tables fit it (--wide: every column)

WideOpt = typer.Option(False, "--wide", help="Every column in one table, as wide as it takes (default: tables that "
                                            "fit the terminal).")
VerboseOpt = typer.Option(False, "--verbose", help="Each joint's own line for the notes shared by several.")
RobotOpt = typer.Option("talos", "--robot", help=f"Built-in robot: {', '.join(BUILTIN_ROBOTS)}; or a robot TOML "
                                                  "(a path ending in .toml, as --config).")
# the help names the log formats registered as it is loaded (their catalogue: no pyarrow imported)
LogArg = typer.Argument(..., metavar="LOG", help=f"Log in the wbfriction format: {table_formats()}.")
FrictionArg = typer.Argument(..., metavar="FRICTION", help="Friction table written by 'wbfriction estimate'.")
EnergyThresholdOpt = typer.Option(DEFAULT_THRESHOLD, min=0.0, max=1.0,
                                  help="Share of power-generating samples (eq. 7.9) above which a joint is flagged.")
EnergyToleranceOpt = typer.Option(DEFAULT_TOLERANCE, min=0.0,
                                  help="Smallest friction torque that counts as generating power [N·m] (the torque "
                                       "sensor's resolution).")
UrdfOpt = typer.Option(None, "--urdf", help="URDF of another robot (with --config), or another URDF of the "
                                             "built-in --robot (e.g. identified inertias).")
ConfigOpt = typer.Option(None, "--config", help="Robot TOML: urdf or mjcf (else give --urdf or --mjcf), "
                                                  "contact_frames, position_controlled, groups.")
MjcfOpt = typer.Option(None, "--mjcf", help="MuJoCo MJCF of the robot instead of its URDF (with --config, or the "
                                             "built-in --robot's configuration); not with --urdf.")
FitWorkersOpt = typer.Option(2, min=1, help="Processes fitting joints side by side.")
RouteOpt = typer.Option("auto", "--route", help="How the friction is reached: momentum (positions "
                                                "differentiated once, generalized momentum), acceleration (twice, "
                                                "the thesis's) or auto (chosen from the positions' noise, printed); "
                                                "the other route is estimated too, as a check.")
NoiseTargetOpt = typer.Option(NOISE_TARGET, "--noise-target",
                              help="diff and route auto: the most RMS noise of the positions a scheme may leave in "
                                   "the acceleration [rad/s^2].")
VelocityWindowOpt = typer.Option(None, "--velocity-window", help="momentum: the velocity's Savitzky-Golay window "
                                                                 "(odd, at least 7) [samples]; default: chosen from "
                                                                 "the noise.")
MomentumWindowOpt = typer.Option(None, "--momentum-window", help="momentum: the window the friction is averaged "
                                                                 "over (odd, at least 3) [samples]; default: chosen "
                                                                 "from the noise.")
TimeUnitOpt = typer.Option(None, help="Unit of a numeric time column: s, ms, us or ns (needed for integer stamps; "
                                      "float stamps are seconds unless said otherwise; timestamps carry theirs).")
MapOpt = typer.Option(None, "--map", help="Topic map TOML of a ROS 2 bag log (see 'wbfriction convert'); with a "
                                           "table log: its [joint_states] rename and [[contacts]] column, threshold.")


MaxGapOpt = typer.Option(MAX_GAP, min=MAX_GAP_LEAST, help="Time steps of at least this many local median steps "
                                                            "split the log into segments, estimated apart.")
TimeBaseOpt = typer.Option("auto", help="Time base the positions are differentiated on: auto (decided from the "
                                         "data and printed), recorded (the stamps as they are: a clock that "
                                         "skips samples) or regularised (a uniform clock fitted to "
                                         "receive-time stamps).")
RepeatsOpt = typer.Option("merge", help="Rows that repeat the previous sample in every joint column (a logger faster "
                                          "than the drives): merge (one row per sample, at its re-estimated time, "
                                          "when a drive clock slower than the logger explains them) or keep.")
RateOpt = typer.Option(None, "--rate", min=0.0, help="The logger's nominal rate [Hz] of a log without a time "
                                                      "column: its rows are stamped k / rate.")
LimitMarginOpt = typer.Option(LIMIT_MARGIN, min=0.0,
                              help="Positions beyond the URDF limits by more than this [rad] are refused (wrong "
                                   "units).")


def stages() -> Stages:
    """A command's progress on standard error, stage by stage (:class:`~wbfriction.cli.stages.Stages`: bars on a
    terminal, one line per stage ended elsewhere); a context manager around the command's work."""
    return Stages(console)


@contextmanager
def progress_bar(total: int, label: str, unit: str = "samples"):
    """One stage of ``total`` items of ``unit`` (:func:`stages`); yields the callable told of the items done."""
    with stages() as stage:
        yield stage.steps(label, total, unit)


def robot_of(robot: str, urdf: Optional[Path], config: Optional[Path], mjcf: Optional[Path] = None) -> Robot:
    """The robot ``--robot``, ``--urdf``, ``--config`` and ``--mjcf`` name, loaded
    (:meth:`RobotSpec.given <wbfriction.model.loading.RobotSpec.given>`, the one way they name a robot).

    Raises:
        InputError: what :func:`~wbfriction.model.loading.load_robot` raises.
    """
    from wbfriction.model.loading import RobotSpec

    return RobotSpec.given(robot, urdf, config, mjcf).load()


def config_text(robot: str, config: Optional[Path]) -> tuple[str, Path]:
    """The robot's configuration as text and the folder its relative paths start from: ``config``'s, else the
    built-in ``robot``'s packaged TOML (its paths name the installed example-robot-data)."""
    from importlib import resources

    if config is not None:
        return config.read_text(encoding="utf-8"), config.parent
    if robot not in BUILTIN_ROBOTS:
        raise InputError(f"unknown robot '{robot}': built-in robots are {', '.join(BUILTIN_ROBOTS)}")
    return resources.files("wbfriction.model.robots").joinpath(f"{robot}.toml").read_text(), Path(".")


def print_whole(renderable) -> None:
    """Print ``renderable`` as wide as it takes, nothing cut or wrapped (``--wide``; the terminal wraps its
    lines): a console of that width on the same output (``Console.print`` stays within its console's)."""
    from rich.measure import Measurement

    width = max(out.width, Measurement.get(out, out.options.update(width=10_000), renderable).maximum)
    Console(width=width, file=out.file, force_terminal=out.is_terminal, no_color=out.no_color).print(renderable)


def warn(warnings) -> None:
    """Print warnings, one line each."""
    for w in warnings:
        console.print(f"[yellow]warning:[/] {escape(w)}", highlight=False, soft_wrap=True)


def warn_energy(energy, verbose: bool = False, labels: Mapping[str, str] | None = None) -> None:
    """Print the energy-consistency warnings (eq. 7.9) of the flagged joints: one line (``verbose``: one per
    joint; :func:`~wbfriction.report.terminal.energy_notes`)."""
    from wbfriction.report.terminal import energy_notes

    for line in energy_notes(energy, verbose, labels):
        console.print(f"[yellow]warning:[/] {escape(line)}", highlight=False, soft_wrap=True)


def joint_list(r: Robot, joints: Optional[str]) -> list[str]:
    """``--joints`` as a list (checked), or by default the legs' torque-controlled joints, else all of them."""
    if joints is None:
        legs = [j for f in r.contact_frames for j in r.limb(f) if j in r.torque_controlled]
        return legs or list(r.torque_controlled)
    names = [j.strip() for j in joints.split(",") if j.strip()]
    unknown = [j for j in names if j not in r.torque_controlled]
    if unknown or not names:
        bad = unknown[0] if unknown else joints
        raise InputError(f"--joints: '{bad}' is not a torque-controlled joint of {r.name}")
    return names


GIVEN = ("COMMANDLINE", "ENVIRONMENT")
"""Where an option's value comes from when the user gave it (click's ``ParameterSource``, named so that typer's own
copy of click answers the same): not its default, whatever the default is."""


def given_options(ctx: typer.Context) -> list[str]:
    """The names of the parameters the command line (or the environment) gave the command, in its order."""
    return [p.name for p in ctx.command.params
            if p.name is not None and getattr(ctx.get_parameter_source(p.name), "name", None) in GIVEN]


def option_flag(param) -> str:
    """An option as the command line spells it, every spelling: ``--gait``, ``-o/--output``,
    ``--log-base/--no-log-base``."""
    return "/".join([*param.opts, *getattr(param, "secondary_opts", ())])


def refuse_options(ctx: typer.Context, mode: str, takes: Collection[str], shared: Collection[str] = ()) -> None:
    """Refuse, before any work, the first option the user gave (:func:`given_options`) that the way the command
    runs does not read: an option of another mode, which would be dropped without a word.

    Args:
        ctx: the command's context.
        mode: the way it runs, as the message says it, e.g. ``robot 'go2' is a hung PD-driven robot (fixed base,
            [pd])``.
        takes: the names of the parameters that mode reads (the command's, e.g. ``excitation_seed``), listed in the
            message in the command's order.
        shared: those every mode of the command reads that name what runs (the robot, the log, the mode): not
            listed.

    Raises:
        InputError: ``--gait: robot 'go2' is ...: it takes --duration, ...; not --gait``.
    """
    params = {p.name: p for p in ctx.command.params}
    for name in given_options(ctx):
        if name not in takes and name not in shared:
            flag = option_flag(params[name])
            listed = ", ".join(option_flag(p) for n, p in params.items() if n in takes)
            raise InputError(f"{flag}: {mode}: it takes {listed}; not {flag}")


def refuse_unread(ctx: typer.Context, mode: str, unread: Collection[str], what: str) -> None:
    """Refuse, before any work, the first option the user gave (:func:`given_options`) of those ``unread`` that the
    way the command runs does not read (where they are fewer than those it reads: :func:`refuse_options` lists
    those); ``what`` names them as a kind (``contact or base``), so the line stays short.

    Raises:
        InputError: ``--mask: robot 'panda' has a fixed base: it takes no contact or base option``.
    """
    params = {p.name: p for p in ctx.command.params}
    for name in given_options(ctx):
        if name in unread:
            raise InputError(f"{option_flag(params[name])}: {mode}: it takes no {what} option")


ESTIMATE = EstimateOptions()  # one source of defaults: the library's
BaseMotionOpt = typer.Option(ESTIMATE.base_motion, "--base-motion",
                             help="Base motion: contact (rigid stance foot, thesis 5.4), logged (the base.* pose "
                                  "differentiated like the joints), imu (the imu.* gyro and accelerometer, the base.q* "
                                  "orientation) or auto (imu, else logged with wrenches or point feet, else contact; "
                                  "printed).")
FILTER = FilterOptions()
GAIT = GaitOptions()
IDEAL = IdealOptions()
MUJOCO = MujocoOptions()
INERTIAL = InertialOptions()
FIT = FitOptions()
MinSamplesOpt = typer.Option(FIT.min_samples, min=1, help="Joints with fewer valid samples are not fitted.")
ModelOpt = typer.Option(FIT.model, "--model", help="Friction model per joint: auto (the simplest whose held-out RMS "
                                                    "is within --selection-tolerance of the best), coulomb-viscous "
                                                    "(3.1 + 3.2), stribeck (3.3 + 3.2) or thesis (3.5); each with "
                                                    "an offset tau_os.")
TermsOpt = typer.Option("auto", "--terms", help="Terms beyond velocity tried per joint, comma-separated, auto (every "
                                                "one the log's signals allow; all: the same) or none: load "
                                                "(Coulomb friction growing with the joint's rigid-body torque), "
                                                "direction (F_v by direction of motion), ripple (a torque periodic in "
                                                "the angle, not friction), temperature (needs temperature.<joint> in "
                                                "the log); each kept where it predicts the log's later samples.")
MaxHarmonicOpt = typer.Option(FIT.terms.max_harmonic, "--max-harmonic", help="The ripple's highest harmonic tried.")
ReferenceTemperatureOpt = typer.Option(None, "--reference-temperature",
                                       help="T_ref [°C] the temperature term's levels are stated at [default: each "
                                            "log's median].")
TemperatureLawOpt = typer.Option(FIT.terms.temperature_law, "--temperature-law",
                                 help="How the temperature term's levels follow the temperature: linear, exponential "
                                      "(Bittencourt's decrease) or auto (the exponential where held-out samples "
                                      "improve).")


def term_options(terms: str, max_harmonic: int, reference_temperature: float | None,
                 temperature_law: TemperatureLaw = "auto") -> TermOptions:
    """The terms' options of ``--terms`` (comma-separated, ``auto`` or ``all``: every term, ``none``),
    ``--max-harmonic``, ``--reference-temperature`` and ``--temperature-law``.

    Raises:
        OptionError: an unknown term (:class:`~wbfriction.fit.options.TermOptions`), a reference temperature
            no joint has, or an option of a term not tried (``--max-harmonic`` without the ripple,
            ``--reference-temperature`` or ``--temperature-law`` without the temperature term).
    """
    names = (TERMS if terms.strip() in ("all", "auto") else () if terms.strip() == "none"
             else tuple(t.strip() for t in terms.split(",") if t.strip()))
    # an option of a term not tried would be dropped without a word
    if max_harmonic != FIT.terms.max_harmonic and "ripple" not in names:
        raise OptionError("--max-harmonic", max_harmonic, f"left out without the ripple term (--terms {terms})")
    for option, value, default in (("--reference-temperature", reference_temperature, None),
                                   ("--temperature-law", temperature_law, FIT.terms.temperature_law)):
        if value != default and "temperature" not in names:
            raise OptionError(option, value, f"left out without the temperature term (--terms {terms})")
    return TermOptions(terms=cast(tuple[Term, ...], names), max_harmonic=max_harmonic,
                       reference_temperature=reference_temperature, temperature_law=temperature_law)


def _version(value: bool) -> None:
    if value:
        out.print(f"wbfriction {__version__}", highlight=False)
        raise typer.Exit()


@app.callback(invoke_without_command=True)
def overview(ctx: typer.Context,
             version: bool = typer.Option(False, "--version", callback=_version, is_eager=True,
                                          help="Print the version and exit.")) -> None:
    """Whole-body joint friction estimation for torque-controlled legged robots: estimate the friction torque of
    every joint from a log, fit a friction model, check it, export it. Run 'wbfriction demo' to see it on a
    simulated walk, 'wbfriction COMMAND --help' for a command."""
    if ctx.invoked_subcommand is None:  # 'wbfriction' alone: the overview, successfully
        out.print(ctx.get_help(), highlight=False, markup=False)
        raise typer.Exit()


def main() -> None:
    """Entry point: run the app, turning wbfriction errors into one line and their exit status (2 for
    the input, 1 for the environment: an output the system refused to write, a cluster gone, a plugin that does not
    load; :attr:`~wbfriction.exceptions.WbfrictionError.exit_status`), and a plugin left out (a
    :class:`~wbfriction.registry.PluginWarning`) into a ``warning:`` line. Interruptions (Ctrl-C, SIGTERM)
    are :mod:`wbfriction.entry`'s, which calls this."""
    try:
        from wbfriction.pipeline.paths import refuse_empty_outputs
        refuse_empty_outputs(sys.argv[1:])  # -o "": Path("") is the working folder
        with one_line_warnings(lambda line: warn([line])):  # a plugin left out: one line naming it
            status = app(standalone_mode=False)
    except WbfrictionError as exc:
        console.print(f"[bold red]error:[/] {escape(str(exc))}", highlight=False, soft_wrap=True)
        sys.exit(exc.exit_status)
    except typer.Exit as exc:  # pragma: no cover - typer control flow
        sys.exit(exc.exit_code)
    except (typer.Abort, KeyboardInterrupt):  # pragma: no cover
        sys.exit(130)
    except Exception as exc:  # usage errors: click's (typer vendors its own copy in newer releases)
        message, code = getattr(exc, "format_message", None), getattr(exc, "exit_code", None)
        if callable(message) and isinstance(code, int):  # one line, as every other error
            console.print(f"[bold red]error:[/] {escape(str(message()))}", highlight=False, soft_wrap=True)
            sys.exit(code)
        raise
    if isinstance(status, int) and status:
        sys.exit(status)


def print_items(items) -> None:
    """Print what an operation returned to print (:class:`~wbfriction.report.printed.Printed` items), in order, on
    standard output: a line without highlighting, a table fitted to the terminal or, ``whole``, as wide as it
    takes."""
    for p in items:
        if p.whole:
            print_whole(p.item)
        else:
            out.print(p.item, highlight=False, soft_wrap=p.soft_wrap)
