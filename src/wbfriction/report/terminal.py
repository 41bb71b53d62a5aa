"""The fit as the terminal shows it (issue 39): tables that fit the terminal's width and notes one line per
family; joints named by their names, as the log, the URDF and every command name them.

:func:`fit_tables` gives the friction table of ``wbfriction fit`` (and of ``identify``'s friction): by default
one row per joint that moved with its model, its status, F_c and F_v (value ± standard error,
:func:`~wbfriction.report.numbers.with_error`) and their Cramér-Rao bounds below; the offset tau_os and the
Stribeck terms (S, v_s, a, for the models that have them) of the fitted joints in a second table; and on
simulated logs the errors against the truth in a third: three tables that fit 100 columns, every parameter's
column headed by its unit (:func:`header`). The joints that were not excited carry no information: no row, one
line of :func:`fit_notes` names them all (:func:`compact_names`: ``arm_left_{1..7}_joint``). ``wide=True`` gives
every joint and every parameter in one table, as wide as it takes. :func:`fit_notes` says what the statuses and
the model choice mean: one line per family of joints that share a status or a chosen model, each joint's own
reason with ``verbose``.
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Callable, Iterable, Mapping, Sequence
from functools import partial

from rich.table import Table
from rich.text import Text

from wbfriction.fit.energy import JointEnergy
from wbfriction.fit.result import FitResult
from wbfriction.fit.status import ZERO
from wbfriction.fit.terms import NOT_TRIED, TERM_COEFFICIENTS, TermFit
from wbfriction.friction.models import ALL_PARAM_NAMES
from wbfriction.friction.point_contacts import DeterminedShares
from wbfriction.inertia.document import Identification
from wbfriction.report.numbers import bound_text, with_error

MAIN = ("F_c", "F_v")
"""The parameters of the main table: the friction every model has."""
OTHERS = ("tau_os", "S", "v_s", "a")
"""The offset (every model) and the Stribeck terms (the models that have them), in a second table."""
CAPTION = ("value ± standard error (the residuals' autocorrelation-consistent sandwich, raised to the "
           "Cramér-Rao bound where that is larger; for F_c and F_v of a model chosen automatically, with the "
           "model error the candidate families show, in quadrature); Cramér-Rao: the standard deviation no "
           "unbiased estimator from these data goes below")
MARKS = {"n.i.": "n.i.: not identifiable", "(b)": "(b): at a bound of the fit, the bound's value, not the data's",
         "step": "step: a tanh slope beyond what the data resolve (Coulomb friction, sgn)",
         "dim": "dim: not to be used (status)", "*": "*: refitted with its terms beyond velocity (the terms' table)"}
"""What each mark of the friction table means: the caption explains those the table shows."""
NAMES_SHOWN = 6
"""Joints (or groups of joints, :func:`compact_names`) named in a note before "and N more"."""
UNITS = {"F_c": "N·m", "F_s": "N·m", "tau_os": "N·m", "F_s-F_c": "N·m", "F_v": "N·m·s/rad", "v_s": "rad/s",
         "a": "s/rad", "S": "-", "delta_s": "-"}
"""The unit of each built-in family's parameter, as a column's header gives it (``-``: a ratio)."""


def header(name: str) -> str:
    """A parameter's column header: its name and unit, ``F_v [N·m·s/rad]`` (a registered family's parameter
    without a known unit: its name)."""
    return f"{name} [{UNITS[name]}]" if name in UNITS else name


def _cell(r: FitResult, name: str) -> str:
    if r.params is None or name not in r.params.names:
        return ""
    if name in r.steps():
        return "step"
    return with_error(getattr(r.params, name), r.read_stderr().get(name)) + (" (b)" if r.at_bound.get(name) else "")


def _table(title: str, first: Sequence[str], names: Sequence[str], caption: str | None = None,
           units: bool = True) -> Table:
    table = Table(title=title, caption=caption, box=None, title_justify="left", caption_justify="left",
                  pad_edge=False)
    for col in first:
        table.add_column(col, no_wrap=col != "status", justify="right" if col == "N" else "left")
    for name in names:
        # a Text, not markup: Rich would take "[rad/s]" for a tag and drop it
        table.add_column(Text(header(name) if units else name), justify="right", no_wrap=True)
    return table


def fit_tables(results: Sequence[FitResult], wide: bool = False,
               labels: Mapping[str, str] | None = None) -> list[Table]:
    """The fitted friction of ``results`` as tables (module docstring): a fit that is not ``ok`` dimmed, its
    numbers not to be used; ``wide``: one table with every parameter and the sample counts; ``labels``: joint ->
    what a person reads (the robot TOML's ``[labels]``, recorded in the friction table), shown for the joint."""
    label = _labeller(labels)
    results = [r.reported() for r in results]  # with terms, the refitted model the status is about
    fitted = [r for r in results if r.params is not None]
    routes = ", ".join(sorted({r.route for r in results}))
    title = f"Friction per joint: f(qd) fitted to -tau_f ({routes} route)"
    if wide:
        names = [n for n in ALL_PARAM_NAMES if any(n in r.params.names for r in fitted if r.params is not None)]
        return [_rows(_table(title, ("joint", "model", "status", "N"), names, _caption(results, names)), results,
                      names, label, True)]
    # the joints that did not move carry no information: folded into one line (fit_notes), --wide shows them
    shown = [r for r in results if not _folded(r)]
    tables = [_rows(_table(title, ("joint", "model", "status"), MAIN, _caption(shown, MAIN)), shown, MAIN, label,
                    False)]
    others = [n for n in OTHERS if any(n in r.params.names for r in fitted if r.params is not None)]
    tables.append(_rows(_table("Offset and Stribeck terms", ("joint",), others),
                        [r for r in fitted if not _folded(r)], others, label, False, short=True))
    truth = [r for r in fitted if r.error_percent() is not None]
    still = [r.joint for r in truth if r.verdict().status == "not excited"]
    if truth:
        # the joints not excited left out: the line of fit_notes names them
        table = _table("Against the simulator's friction: error [%]", ("joint", "model"), [*MAIN, *OTHERS, "RMS"],
                       units=False)
        for r in truth:
            if r.joint in still:
                continue
            err = r.error_percent() or {}
            rms = "" if r.rms_error_vs_true is None else f"{r.rms_error_vs_true:.2g}"
            cells = [f"{err[n]:.2f}" if n in err else "" for n in (*MAIN, *OTHERS)]
            table.add_row(label(r.joint), r.model, *cells, rms, style=None if r.verdict().ok else "dim")
        tables.append(table)
    terms = terms_table(results, label)
    return [t for t in [*tables, terms] if t is not None and t.row_count]


def _caption(results: Sequence[FitResult], names: Sequence[str]) -> str:
    """The friction table's caption: :data:`CAPTION` and what each mark the table shows means (:data:`MARKS`)."""
    cells = [_cell(r, n) for r in results for n in names]
    bounds = [bound_text(r.crb.get(n)) for r in results for n in names if r.params is not None]
    shown = {"n.i.": any("n.i." in c for c in [*cells, *bounds]), "(b)": any(c.endswith("(b)") for c in cells),
             "step": "step" in cells, "dim": any(not r.verdict().ok for r in results),
             "*": any(r.params is not None and r.kept_terms is not None for r in results)}
    return "; ".join([CAPTION, *(MARKS[m] for m, there in shown.items() if there)])


def _folded(r: FitResult) -> bool:
    """Whether a fit's rows are folded into the line of the joints not excited (:func:`fit_notes`)."""
    return r.verdict().status == "not excited"


def terms_table(results: Sequence[FitResult], label: Callable[[str], str] = str) -> Table | None:
    """The terms beyond velocity (:mod:`~wbfriction.fit.terms`) of the joints whose fit kept some, one row per
    term (a narrow table whatever the terms): its status (:meth:`~wbfriction.fit.terms.TermFit.verdicts`) and
    its coefficients ± standard errors, after a row of F_c and F_v refitted with the terms (at zero load and the
    reference temperature, the ones exports write); None when no fit kept one."""
    kept = [r for r in results if r.kept_terms is not None]
    if not kept:
        return None
    table = Table(title="Terms beyond velocity", box=None, title_justify="left", caption_justify="left",
                  pad_edge=False, caption="ripple: a torque of the angle, not friction (left out of the energy check "
                                          "and the exports); the velocity row: F_c, F_v refitted with the terms")
    for col in ("joint", "term", "status", "values"):
        table.add_column(col, no_wrap=col != "values")
    for r in kept:
        terms = r.kept_terms
        assert terms is not None
        shown = partial(_term_value, terms)
        table.add_row(label(r.joint), "velocity", "",
                      f"{shown('F_c')}, {shown('F_v')} at {terms.reference_conditions()}")
        for term, verdict in terms.verdicts().items():
            if term == "ripple":
                text = (f"size {with_error(terms.derived['ripple_rms'], terms.stderr.get('ripple_rms'))} N·m, "
                        f"{terms.harmonics} harmonic{'s' if terms.harmonics > 1 else ''}")
            else:
                text = ", ".join(shown(n) for n in TERM_COEFFICIENTS[term]
                                 + (("rate_T",) if term == "temperature" and terms.temperature_rate else ()))
            table.add_row("", term, verdict.status, text, style=None if verdict.ok else "dim")
    return table


def _term_value(terms: TermFit, name: str) -> str:
    """``name value ± standard error`` of a coefficient of ``terms`` (``(b)``: held at a bound)."""
    values = {**terms.coefficients, **terms.derived, **terms.params.to_dict()}
    return f"{name} {with_error(values[name], terms.stderr.get(name))}" + (" (b)" if name in terms.at_bound else "")


def terms_notes(results: Sequence[FitResult], verbose: bool = False,
                labels: Mapping[str, str] | None = None) -> list[str]:
    """Why each term was kept or not: every joint's reasons with ``verbose``, else each term that is not ``ok``
    with its reason and one line on where the reasons are."""
    label = _labeller(labels)
    lines = []
    for r in results:
        if r.terms is None:
            continue
        for term, verdict in r.terms.verdicts().items():
            if not verdict.ok:
                lines.append(f"{label(r.joint)}: {term} {verdict}")
        if verbose:
            lines += [f"{label(r.joint)}: {term} {why}" for term, why in r.terms.reasons.items()]
    if verbose:
        return lines
    untried: dict[tuple[str, str], list[str]] = {}  # the joints per term and why it was not tried
    for r in results:
        for name, why in ({} if r.terms is None else r.terms.reasons).items():
            if why.startswith(NOT_TRIED):
                untried.setdefault((name, why.removeprefix(f"{NOT_TRIED}: ")), []).append(label(r.joint))
    for (name, why), joints in untried.items():
        lines.append(f"{name} not tried on {len(joints)} joint{'s' if len(joints) > 1 else ''} ({_joints(joints)}): "
                     f"{why}")
    none = [label(r.joint) for r in results if r.terms is not None and not r.terms.kept
            and any(not why.startswith(NOT_TRIED) for why in r.terms.reasons.values())]
    if none:
        lines.append(f"no term beyond velocity kept on {len(none)} joint{'s' if len(none) > 1 else ''} "
                     f"({_joints(none)}): those tried do not improve held-out samples; --verbose gives each joint's "
                     "reasons")
    return lines


def _rows(table: Table, results: Sequence[FitResult], names: Sequence[str], label: Callable[[str], str],
          wide: bool, short: bool = False) -> Table:
    """``results`` as rows of ``table``: value ± standard error, the Cramér-Rao bounds in a dimmed row below
    (not for a joint that did not move: nothing to bound); ``short``: the joint alone before the values."""
    for r in results:
        verdict = r.verdict()
        model = "—" if r.params is None else r.model + ("*" if r.kept_terms is not None else "")
        first = [label(r.joint)] + ([] if short else [model, verdict.status])
        count = [f"{r.n_samples}" + (f" (-{r.n_screened} screened)" if r.n_screened else "")] if wide else []
        table.add_row(*first, *count, *[_cell(r, n) for n in names], style=None if verdict.ok else "dim")
        if r.params is not None and verdict.status != "not excited" and any(n in r.crb for n in names):
            table.add_row("  Cramér-Rao", *[""] * (len(first) + len(count) - 1),
                          *[bound_text(r.crb.get(n)) for n in names], style="dim")
    return table


def _labeller(labels: Mapping[str, str] | None) -> Callable[[str], str]:
    """A joint's text in a table or a note: its label when ``labels`` give one, else its name."""
    return lambda joint: (labels or {}).get(joint) or joint


def compact_names(names: Sequence[str]) -> list[str]:
    """Joint names that differ by one number written once, bash's way: ``arm_left_{1..7}_joint`` for seven
    (a run of three or more), ``torso_{1,2}_joint``; the others as they are; in the order of their first name."""
    groups: dict[str | tuple[str, str], list[str]] = {}  # (prefix, suffix) of a numbered name, else the name
    for name in names:
        m = _NUMBERED.match(name)
        groups.setdefault((m.group(1), m.group(3)) if m else name, []).append(name)
    shown = []
    for key, members in groups.items():
        if isinstance(key, str) or len(set(members)) == 1:
            shown.append(members[0])
            continue
        runs: list[list[int]] = []
        for n in sorted({int(_NUMBERED.match(m).group(2)) for m in members}):  # type: ignore[union-attr]
            if runs and n == runs[-1][-1] + 1:
                runs[-1].append(n)
            else:
                runs.append([n])
        inner = ",".join(f"{r[0]}..{r[-1]}" if len(r) > 2 else ",".join(map(str, r)) for r in runs)
        shown.append(f"{key[0]}{{{inner}}}{key[1]}")
    return shown


_NUMBERED = re.compile(r"^(.*?)(\d+)(\D*)$")


def _joints(names: Sequence[str], everyone: bool = False) -> str:
    """Joints as a note names them (:func:`compact_names`): the first :data:`NAMES_SHOWN` and "and N more"
    (``everyone``: all of them)."""
    groups = compact_names(names)
    shown = groups if everyone else groups[:NAMES_SHOWN]
    return ", ".join(shown) + (f" and {len(groups) - len(shown)} more" if len(groups) > len(shown) else "")


def fit_notes(results: Sequence[FitResult], verbose: bool = False,
              labels: Mapping[str, str] | None = None, wide: bool = False) -> list[str]:
    """What the table's statuses and models mean, one line each: the joints not excited, whose rows
    :func:`fit_tables` folds, on one line that names them all (``wide``: their rows are in the table; the line
    says so); every other fit that is not ``ok`` with its reason; the model chosen on held-out data (``--model
    auto``), one line per model. ``verbose``: each joint's own line for both. Joints by their ``labels``."""
    label = _labeller(labels)
    lines = []
    folded = [label(r.reported().joint) for r in results if _folded(r.reported())]
    still = [label(r.joint) for r in results if r.verdict().status == "not excited" and r.params is not None
             and r.speed is not None]
    if folded:
        why = "hardly moved" if len(still) == len(folded) else "not determined by this log"
        lines.append(f"{len(folded)} joint{'s' if len(folded) > 1 else ''} not excited ({why}; "
                     + ("their rows above" if wide else "no rows: --wide shows them")
                     + ("" if verbose else ", --verbose why") + f"): {_joints(folded, everyone=True)}")
    for r in results:
        verdict = r.verdict()
        if not verdict.ok and (verbose or label(r.joint) not in still):
            lines.append(f"{label(r.joint)}: {verdict}")
    chosen: dict[str, list[str]] = defaultdict(list)
    for r in results:
        if r.selection is not None:
            if verbose:
                lines.append(f"{label(r.joint)}: {r.selection.reason}")
            chosen[r.model].append(label(r.joint))
    if chosen and not verbose:
        lines.append("model chosen on held-out data (--verbose gives each joint's reason):")
        lines += [f"  {model}: {_joints(joints)}" for model, joints in chosen.items()]
    return lines


def energy_notes(energy: Iterable[JointEnergy], verbose: bool = False,
                 labels: Mapping[str, str] | None = None) -> list[str]:
    """The energy check's warnings (eq. 7.9): the joints whose friction generates power on more than the
    threshold's share of their valid samples, on one line with each one's share, and what is likely off
    (thesis 7.2); ``verbose``: one line per joint (:meth:`~wbfriction.fit.energy.JointEnergy.warning`).
    Empty when no joint is flagged."""
    label = _labeller(labels)
    flagged = sorted((e for e in energy if e.flagged), key=lambda e: -e.generating_share)
    if verbose or not flagged:
        return [f"{label(e.joint)}{(e.warning() or '')[len(e.joint):]}" for e in flagged]
    shares = [f"{label(e.joint)} {100 * e.generating_share:.0f} %" for e in flagged]
    return [f"friction generates power on {len(flagged)} joint{'s' if len(flagged) > 1 else ''} (eq. 7.9; share "
            f"of valid samples, threshold {100 * flagged[0].threshold:.0f} %): {_joints(shares)}: the inertia model, "
            "a torque-sensor offset or the filtering is likely off (thesis 7.2)"]


CHANGED = 1e-4
"""A body whose mass, centre of mass [m] or principal moments changed by less than this (relative; absolute
for the centre of mass) is as given: left out of the bodies' table."""


def _g(x: float | None) -> str:
    """A friction parameter without a standard error, in three significant digits ("—": none; "0": a magnitude
    below :data:`~wbfriction.fit.status.ZERO`, at its floor of zero, not ``2.18e-67``: the solver's rounding)."""
    return "—" if x is None else "0" if abs(x) < ZERO else f"{x:.3g}"


def _change(x: float | None, digits: int) -> str:
    """A relative change as a signed percentage; ``new`` for a body the given model had none of."""
    return "new" if x is None else f"{100 * x:+.{digits}f}"


def _stacked(name: str) -> Text:
    """A column's header with the unit of its parameter (``accel. F_v``: F_v's) below its name."""
    unit = UNITS.get(name.removeprefix("accel. "))
    return Text(name if unit is None else f"{name}\n[{unit}]")


def identification_tables(result: Identification, wide: bool = False) -> tuple[list[Table], list[str]]:
    """The tables of ``wbfriction identify`` (:class:`~wbfriction.inertia.document.Identification`)
    and the notes that stand for the rows left out: the bodies that changed (``wide``: every body with mass),
    the friction of the joints whose acceleration-route fit moved (both routes, the status of the
    acceleration route's fit, the power-generating share), and their held-out torques."""
    notes: list[str] = []
    # Text, not markup, wherever a unit is in brackets: Rich would take "[kg]" or "[mm]" for a tag and drop it
    bodies = Table(title="Inertia model: given -> written", box=None, title_justify="left", caption_justify="left",
                   caption=Text("COM: shift [mm]; I1-I3: principal moments about the centre of mass, ascending, "
                                "change [%]; kept: the identified body predicted held-out torques better (else as "
                                "given)"))
    for col in ("body", "mass [kg]", "mass [%]", "COM [mm]", "I1 [%]", "I2 [%]", "I3 [%]", "kept"):
        bodies.add_column(Text(col), justify="left" if col == "body" else "right", no_wrap=True)
    massive = [b for b in result.bodies if b.has_mass]
    changed = [b for b in massive if wide or b.kept or b.mass_change is None
               or abs(b.mass_change) >= CHANGED or b.com_shift >= CHANGED
               or any(x is None or abs(x) >= CHANGED for x in b.moments_change)]
    for b in changed:
        bodies.add_row(b.body, f"{b.mass_given:.4g} -> {b.mass:.4g}", _change(b.mass_change, 2),
                       f"{1e3 * b.com_shift:.2f}", *[_change(x, 1) for x in b.moments_change],
                       "—" if b.kept is None else "yes" if b.kept else "no")
    if len(changed) < len(massive):
        notes.append(f"{len(massive) - len(changed)} of {len(massive)} bodies with mass written as given "
                     "(--wide lists them)")
    odd = [(b.body, b.implausible()) for b in massive if b.implausible()]
    if odd:
        notes.append(f"implausible bodies written ({len(odd)}): " + "; ".join(f"{b}: {why}" for b, why in odd)
                     + ": the log determines combinations of the bodies (what the held-out torques confirm), not "
                       "each body: read no link's own inertia off them")
    joints = result.joints
    moved = [j for j, v in joints.items() if wide or v.acceleration_route.verdict().status != "not excited"]
    names = result.friction_names
    friction = Table(title="Friction: this route (torques, the inertias written) and the acceleration route (5.10)",
                     box=None, title_justify="left", caption_justify="left",
                     caption=Text("status: of the acceleration route's fit; accel.: its parameters; gen: share of "
                                  "valid samples whose friction generates power (eq. 7.9) [%], given model -> "
                                  "identified; target: the simulator's; 0: at its floor of zero"))
    friction.add_column("joint", no_wrap=True)
    friction.add_column("status")  # wraps, where the terminal is narrow: the numbers never do
    for n in (*names, "accel. F_v", "accel. F_c", "gen [%]"):  # each unit below its name: narrow columns
        friction.add_column(_stacked(n), justify="right", no_wrap=True)
    pct = lambda x: "—" if x is None else f"{100 * x:.1f}"  # noqa: E731
    for joint in moved:
        j = joints[joint]
        accel = j.acceleration_route
        params = {} if accel.params is None else accel.params.to_dict()
        status = accel.verdict().status
        friction.add_row(joint, status, *[_g(j.identified[n]) for n in names],
                         *[_g(params.get(n)) for n in ("F_v", "F_c")],
                         f"{pct(j.generating_share_given_model)}->{pct(j.generating_share)}",
                         style=None if status == "ok" else "dim")
        if accel.target is not None:
            target = accel.target.to_dict()
            f_s = {"F_s-F_c": target.get("S", 0.0) * target["F_c"]}
            friction.add_row("  target", "", *[_g(target.get(n, f_s.get(n))) for n in names],
                             *[_g(target.get(n)) for n in ("F_v", "F_c")], "", style="dim")
    if len(moved) < len(joints):
        still = [j for j in joints if j not in moved]
        notes.append(f"not excited by this log, friction and held-out torques left out: {len(still)} joints "
                     f"({', '.join(still[:NAMES_SHOWN])}{' and more' if len(still) > NAMES_SHOWN else ''}); --wide "
                     "lists them")
    rms = Table(title=f"Held-out torques ({result.holdout_samples} samples at the end of the log, free of the contact "
                      "forces): RMS of measured - predicted [N·m]", box=None, title_justify="left")
    for col in ("joint", "given model", "given + its friction", "identified", "written"):
        rms.add_column(col, justify="left" if col == "joint" else "right", no_wrap=True)
    for joint in moved:
        h = joints[joint].holdout_rms
        rms.add_row(joint, f"{h.given:.4f}", f"{h.given_with_friction:.4f}", f"{h.identified:.4f}",
                    "—" if h.validated is None else f"{h.validated:.4f}")
    return [t for t in (bodies, friction, rms) if t.row_count], notes


def determination_table(shares: DeterminedShares, labels: Mapping[str, str] | None = None) -> Table:
    """The share of samples that determine each joint's friction, by contact pattern (issue 56): one row per joint,
    one column per pattern (its feet, the contact frames' common suffix left out, and its samples), the most frequent
    first, then every sample's; a pattern's share is of its samples whose dynamics were evaluated
    (:func:`~wbfriction.friction.point_contacts.determined_shares`)."""
    label = _labeller(labels)
    suffix = _common_suffix([f for p in shares.patterns if p != "flight" for f in p.split("+")])
    table = _table("determined: share of samples, by feet on the ground", ["joint"], [], caption=(
        "where the equations of motion leave a joint's friction unique\n(the rank of [S^T J^T], the logged foot "
        "forces counted;\nsamples within the switches' margins not counted)"))
    for pattern, n in zip(shares.patterns, shares.samples):
        name = "+".join(f.removesuffix(suffix) for f in pattern.split("+")) if pattern != "flight" else pattern
        table.add_column(f"{name}\n({n})", justify="right", no_wrap=True)
    table.add_column(f"all\n({int(shares.samples.sum())})", justify="right", no_wrap=True)
    for i, joint in enumerate(shares.joints):
        table.add_row(label(joint), *(f"{100 * s:.0f} %" for s in shares.share[:, i]),
                      f"{100 * shares.overall[i]:.0f} %")
    return table


def _common_suffix(names: Sequence[str]) -> str:
    """The longest suffix every name has, from its last ``_`` (``"_foot"``), or ""."""
    if not names:
        return ""
    tail = names[0][names[0].rfind("_"):] if "_" in names[0] else ""
    return tail if tail and all(n.endswith(tail) and n != tail for n in names) else ""
