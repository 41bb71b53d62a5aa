"""The decision constants' reference page (docs/reference/decision-constants.md) is the code's, and complete.

(a) every row names a constant (or an options class's default) that exists with the value the page states, and says
how it was chosen; (b) every upper-case module-level number or tuple of the decision packages is on the page or in
:data:`EXCLUDED` below with its reason: a new threshold without a documented choice fails here."""

from __future__ import annotations

import ast
import importlib
import math
import numbers
import pkgutil
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "reference" / "decision-constants.md"

DECISION_PACKAGES = ("fit", "actuator", "friction", "signals", "export", "fleet", "pipeline", "inertia")
"""The packages of ``wbfriction`` whose modules are checked for completeness (every module in them, walked)."""

CHOSEN = ("a priori", "a test level", "tuned on data")
"""How a value was chosen: what the page's column starts with."""

# Constants of the decision packages that decide no verdict, each with its reason. Keys relative to ``wbfriction``.
NAMES = "names: the choices or parameters it lists decide nothing by their value"
DERIVED = "derived from constants on the page"
NUMERICAL = "numerical: a size, batch, grid or pass count of a computation, no verdict"
FORMAT = "a file format's or an export target's convention"
PHYSICS = "a mathematical or unit constant"
EXCLUDED: dict[str, str] = {
    # actuator
    "actuator.written.WRITABLE": NAMES + " (the per-joint quantities a robot TOML holds)",
    # fit
    "fit.bound.BATCH": NUMERICAL + " (the torque noise's batch means)",
    "fit.options.MODEL_CHOICES": NAMES + " (the families, simplest first: their parameter count)",
    "fit.projection.GRID": NUMERICAL + " (the variable projection's start grid)",
    "fit.projection.BASINS": NUMERICAL + " (local minima refined)",
    "fit.regression.MAX_DENSE": NUMERICAL + " (memory of the autocorrelation's FFT)",
    "fit.smoothing.LOCAL": NAMES + " (smoother classes)",
    "fit.solve.EDGE_ROWS": NUMERICAL + " (rows a velocity's rate is measured over)",
    "fit.status.FIT_STATUSES": NAMES + " (the statuses)",
    "fit.targets.TERM_KEYS": FORMAT + " (a friction TOML's keys)",
    # actuator
    "actuator.options.PASSES": NUMERICAL + " (the offsets' linearisation passes)",
    "actuator.options.VELOCITIES": NAMES,
    "actuator.solve.KINDS": NAMES + " (the unknowns' kinds, in column order)",
    # friction
    "friction.decision.FILTER_SPAN": NUMERICAL + " (memory: rows a filter's response is computed for)",
    "friction.estimate.CHUNK": NUMERICAL,
    "friction.families.coulomb_viscous.COULOMB_VISCOUS_NAMES": NAMES,
    "friction.families.gaussian.TANH_ERF": PHYSICS + " (tanh as a sum of erf, fitted to 2e-7)",
    "friction.families.gaussian.SMALL": PHYSICS + " (a noise below 1e-12 rad/s is none)",
    "friction.families.gaussian.HERMITE": NUMERICAL + " (the Gauss-Hermite rule)",
    "friction.families.gaussian.ERF_ONE": PHYSICS + " (erf is 1.0 in double precision)",
    "friction.families.gaussian.TWO_OVER_ROOT_PI": PHYSICS,
    "friction.families.names.BUILTIN_NAMES": NAMES,
    "friction.families.params.ALL_PARAM_NAMES": NAMES,
    "friction.families.stribeck.STRIBECK_NAMES": NAMES,
    "friction.families.thesis.PARAM_NAMES": NAMES,
    "friction.force_sampling.READINGS": NAMES + " (the foot forces' readings tried)",
    "friction.force_sampling.KNOTS": NUMERICAL + " (the comparison's piecewise-linear basis)",
    "friction.models.MODEL_NAMES": NAMES,
    "friction.momentum.VELOCITY_ORDER": NUMERICAL + " (a Savitzky-Golay polynomial order)",
    "friction.noise.INERTIA_SAMPLES": NUMERICAL + " (configurations an effective inertia's median is over)",
    "friction.options.BASE_MOTIONS": NAMES,
    "friction.options.ROUTES": NAMES,
    "friction.options.ROUTE_OPTIONS": NAMES,
    "friction.options.METHODS": NAMES,
    "friction.options.TERMS": NAMES,
    "friction.options.TEMPERATURE_LAWS": NAMES,
    # signals
    "pipeline.raw_log.IMU_ORIENTATION": NAMES + " (the IMU orientation's columns)",
    "signals.choice.PREFERENCES": NAMES,
    "signals.leg_odometry.GATE_ROUNDS": NUMERICAL + " (rounds of the feet's gate)",
    "signals.leg_odometry.JERK_GRID": NUMERICAL + " (the decades the jerk density's likelihood is searched over)",
    "signals.contact_inference.CUES": NAMES + " (the contact cues)",
    "signals.contact_inference.ROBUST_SCALE": PHYSICS + " (the standard normal's upper quartile)",
    "signals.content.SEGMENT": NUMERICAL + " (the spectrum's segment length)",
    "signals.content.MIN_SEGMENT": NUMERICAL,
    "signals.content.MIN_SEGMENTS": NUMERICAL + " (NOISE_MARGIN's level assumes it)",
    "signals.content.FRAME": NUMERICAL + " (the position noise's frames)",
    "signals.choice.MOMENTUM_ORDER": NUMERICAL + " (a Savitzky-Golay polynomial order)",
    "signals.filters.TAIL": NUMERICAL + " (an IIR filter's half-width)",
    "signals.nonuniform.BLOCK": NUMERICAL,
    "signals.nonuniform.CACHE": NUMERICAL,
    "signals.options.SCHEMES": NAMES,
    "signals.options.FILTERING_SCHEMES": NAMES,
    "signals.options.DIFFS": NAMES,
    "signals.options.DIFF_OPTIONS": NAMES,
    "signals.options.TORQUE_ALIGNMENTS": NAMES,
    "signals.options.ALIGNMENT_OPTIONS": NAMES,
    "signals.options.VELOCITIES": NAMES,
    "signals.options.MASKS": NAMES,
    "signals.options.WEIGHTS": NAMES,
    "signals.spectrum.MIN_SAMPLES": NUMERICAL + " (fewest samples of a spectrum)",
    # export
    "export.catalog.BUILTIN": NAMES + " (the export targets)",
    "export.drive.DEFAULT_PHYSICS_DT": FORMAT + " (Isaac Lab's locomotion physics step)",
    "export.drive.WHOLE_STEP": NUMERICAL + " (floating-point division's rounding)",
    "export.drive.HOLD_EDGE": FORMAT + " (MuJoCo's zero-order hold's edge)",
    "export.drive.SMALLEST_TIMESTEP": FORMAT + " (an exported MuJoCo actuator's history)",
    "export.isaac.ISAAC_FIELDS": FORMAT,
    "export.isaac.PD_FIELDS": FORMAT,
    "export.mapping.INCLUDE_CHOICES": NAMES + " (INCLUDED_STATUS, on the page, maps them)",
    # fleet
    "fleet.batch.LOCAL_WORKERS": NUMERICAL + " (worker processes)",
    "fleet.batch.CONNECT_TIMEOUT": NUMERICAL + " (seconds waited for a scheduler)",
    "fleet.change_point.DAY": PHYSICS + " (seconds per day)",
    "fleet.change_point.BLOCK": NUMERICAL + " (noise series drawn at a time)",
    "fleet.manifest.REQUIRED": FORMAT + " (a manifest's columns)",
    "fleet.manifest.OPTIONAL": FORMAT + " (a manifest's columns)",
    "fleet.options.SHAPES": NAMES + " (the change's shapes)",
    "fleet.trends.QUANTITIES": DERIVED + " (TREND_PARAMS and REFERENCE_SPEEDS)",
    # pipeline
    "pipeline.chunks.CONTEXT": NUMERICAL + " (rows of context at a cut)",
    "pipeline.chunks.CHUNKS_PER_WORKER": NUMERICAL + " (when to start workers)",
    "pipeline.identify_step.MOVED_PATHS": FORMAT + " (a robot TOML's path keys)",
    "pipeline.paths.OUTPUT_OPTIONS": NAMES + " (command-line options)",
    "pipeline.provenance.DEPENDENCIES": NAMES + " (distributions named in provenance)",
    # inertia
    "inertia.consistency.FRICTION": NAMES,
    "inertia.consistency.PHYSICAL": NAMES,
    "inertia.options.ARMATURE_MODES": NAMES,
    "inertia.options.PARTS": NAMES,
    "inertia.regressor.PARAMS": NAMES,
}


def split_row(line: str) -> list[str]:
    """A Markdown table row's cells (``\\|`` is a bar inside a cell)."""
    return [c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]


def page_rows() -> list[list[str]]:
    """The rows of the page's table of constants (the one whose header starts ``| constant |``)."""
    rows, inside = [], False
    for line in PAGE.read_text().splitlines():
        if line.startswith("| constant |"):
            inside = True
            continue
        if inside:
            if not line.startswith("|"):
                break
            if not line.startswith("|---"):
                rows.append(split_row(line))
    return rows


def code(cell: str) -> str:
    m = re.fullmatch(r"`([^`]+)`", cell)
    assert m, f"not one code span: {cell!r}"
    return m.group(1)


def resolve(name: str):
    """The object ``wbfriction.<name>``: a module's constant, or ``Class.field`` (a dataclass default)."""
    parts = name.split(".")
    for k in range(len(parts) - 1, 0, -1):
        try:
            obj = importlib.import_module("wbfriction." + ".".join(parts[:k]))
        except ModuleNotFoundError:
            continue
        for attr in parts[k:]:
            obj = getattr(obj, attr)
        return obj
    raise ModuleNotFoundError(name)


def literal(text: str):
    return eval(text, {"__builtins__": {}, "inf": math.inf})  # the page's values: Python literals and inf


def is_checked(value) -> bool:
    return (isinstance(value, numbers.Real) and not isinstance(value, bool)) or isinstance(value, tuple)


def module_constants() -> dict[str, object]:
    """Every upper-case name assigned at a decision module's top level (not imported), whose value is a number or
    a tuple, keyed relative to ``wbfriction``."""
    out = {}
    for sub in DECISION_PACKAGES:
        pkg = importlib.import_module(f"wbfriction.{sub}")
        names = [pkg.__name__] + [m.name for m in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + ".")]
        for modname in names:
            mod = importlib.import_module(modname)
            for node in ast.parse(Path(mod.__file__).read_text()).body:
                targets = (node.targets if isinstance(node, ast.Assign)
                           else [node.target] if isinstance(node, ast.AnnAssign) else [])
                for t in targets:
                    if isinstance(t, ast.Name) and re.fullmatch(r"[A-Z][A-Z0-9_]*", t.id):
                        value = getattr(mod, t.id)
                        if is_checked(value):
                            out[f"{modname.removeprefix('wbfriction.')}.{t.id}"] = value
    return out


ROWS = page_rows()


def test_the_page_has_its_table():
    assert len(ROWS) > 50
    names = [code(r[0]) for r in ROWS]
    assert len(names) == len(set(names)), "a constant listed twice"


@pytest.mark.parametrize("row", ROWS, ids=lambda r: r[0].strip("`"))
def test_each_row_is_the_codes(row):
    assert len(row) == 5, row
    name, value = code(row[0]), literal(code(row[1]))
    actual = resolve(name)
    if isinstance(actual, float) and math.isinf(actual):
        assert actual == value
    else:
        assert actual == value and type(actual) is type(value), f"{name}: the code has {actual!r}, the page {value!r}"
    assert row[2], f"{name}: what it decides"
    assert row[3].startswith(CHOSEN), f"{name}: how chosen must start with one of {CHOSEN}: {row[3]!r}"
    assert row[4], f"{name}: supported by (– for none)"


def test_every_decision_constant_is_listed_or_excluded():
    listed = {code(r[0]) for r in ROWS}
    found = module_constants()
    missing = sorted(set(found) - listed - set(EXCLUDED))
    assert not missing, (f"constants neither on {PAGE.relative_to(ROOT)} (with how each was chosen) nor in "
                         f"EXCLUDED with a reason: {missing}")
    stale = sorted(set(EXCLUDED) - set(found))
    assert not stale, f"EXCLUDED names no longer in the code: {stale}"
    both = sorted(set(EXCLUDED) & listed)
    assert not both, f"both listed and excluded: {both}"
    assert all(reason for reason in EXCLUDED.values())


def test_the_page_is_in_the_nav_and_linked():
    nav = (ROOT / "mkdocs.yml").read_text()
    assert "reference/decision-constants.md" in nav
    assert "../reference/decision-constants.md" in (ROOT / "docs" / "explanation" / "statuses.md").read_text()
