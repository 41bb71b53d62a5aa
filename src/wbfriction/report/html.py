"""The report rendered: one self-contained HTML page (figures embedded as PNG, no script, no network).

The same report gives the same bytes (its one date is :func:`~wbfriction.pipeline.provenance.output_date`,
fixed by ``SOURCE_DATE_EPOCH``). What it shows is gathered by :mod:`wbfriction.report.build`. Figures are
static images sized for reading (:data:`~wbfriction.report.figures.READABLE`): a page that opens anywhere,
offline, in a mail or an archive, without a script library inside it.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from wbfriction.fit.energy import JointEnergy
from wbfriction.fit.result import FitResult
from wbfriction.fit.status import MIN_SPEED, FitVerdict
from wbfriction.friction.cross_check import LARGE, MIN_SAMPLES, cross_check
from wbfriction.friction.models import ALL_PARAM_NAMES, ModelParams
from wbfriction.friction.point_contacts import determined_shares
from wbfriction.inertia.document import Identification
from wbfriction.logs.tables import write_atomic
from wbfriction.report.build import Report, acceleration_spectra
from wbfriction.report.figures import png_bytes
from wbfriction.report.friction_figures import FIT_DRAWN, friction_overview_figure, joint_figure
from wbfriction.report.numbers import bound_text, duration_text, with_error
from wbfriction.report.terms import terms_section
from wbfriction.workers import process_pool

if TYPE_CHECKING:
    from matplotlib.figure import Figure

PAGE_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", sans-serif; margin: 0 auto; max-width: 1480px;
       padding: 0 24px 48px; color: #1d232a; font-size: 15px; line-height: 1.45; }
h1 { font-size: 1.6rem; margin: 24px 0 4px; } h2 { font-size: 1.25rem; margin-top: 36px;
     border-bottom: 1px solid #d5dae0; padding-bottom: 4px; } h3 { font-size: 1.05rem; margin: 26px 0 6px; }
.sub { color: #4f5a65; margin: 0 0 14px; max-width: 75em; }
.box { padding: 10px 14px; border-radius: 6px; margin: 12px 0; }
.warn { background: #fff4e5; border: 1px solid #f0b35a; } .ok { background: #eef8ef; border: 1px solid #8cc79a; }
.scroll { overflow-x: auto; max-width: 100%; }
table { border-collapse: collapse; font-size: 0.9rem; font-variant-numeric: tabular-nums; }
th, td { padding: 4px 6px; text-align: right; border-bottom: 1px solid #eceff2; white-space: nowrap;
         vertical-align: top; }
th { background: #f5f7f9; white-space: normal; max-width: 8em; vertical-align: bottom; }
td:first-child, th:first-child, th.text { text-align: left; }
tr.flag td { background: #fff1f0; } tr.target td, tr.err td { color: #5f6b76; }
tr.notok td { color: #8c96a0; } td.status, td.verdict { text-align: left; white-space: normal; min-width: 8em; }
tr.notok td.status, td.verdict.bad { color: #a4520a; } td.verdict.good, td.pass { color: #1f7a35; }
td.fail { color: #b3261e; font-weight: 600; }
.name { color: #6b7580; font-size: 0.8rem; }
img { max-width: 100%; height: auto; display: block; }
nav#contents ol { columns: 2; max-width: 48em; margin: 6px 0 0; padding-left: 1.4em; }
nav.joints { display: flex; flex-wrap: wrap; gap: 4px 14px; }
table.provenance td { text-align: left; white-space: normal; overflow-wrap: anywhere; max-width: 70em; }
table.provenance td:first-child { color: #4f5a65; white-space: nowrap; }
section.joint { margin-top: 22px; }
details.still { margin: 14px 0; } details.still summary { cursor: pointer; }
"""


_ENERGY_NOTE = ("Share of valid samples with qd·(τ_f + τ_os) &gt; 0 and |τ_f + τ_os| above the tolerance (the\n"
                "identified offset τ_os is a sensor offset, not friction); zero crossings of the acceleration "
                "difference Δqdd against those of the velocity within valid stretches,\n"
                "and the median time from each velocity crossing to the nearest Δqdd crossing.")
"""The energy section's introduction (HTML)."""


def _img(fig, alt: str, id_: str, cls: str) -> str:
    data = base64.b64encode(png_bytes(fig)).decode("ascii")
    return f'<img id="{html.escape(id_)}" class="{cls}" alt="{html.escape(alt)}" src="data:image/png;base64,{data}">'


def _anchor(joint: str) -> str:
    return "joint-" + "".join(c if c.isalnum() else "-" for c in joint)


def _joint_cell(r: Report, joint: str) -> str:
    """A joint's first cell: its label, linked to its section, and its name when that differs."""
    label = r.label(joint)
    name = "" if label == joint else f'<br><span class="name">{html.escape(joint)}</span>'
    return f'<td><a href="#{_anchor(joint)}">{html.escape(label)}</a>{name}</td>'


def _fmt(value: float | None, se: float | None = None, digits: int = 4) -> str:
    """``value ± se`` to the digits ``se`` supports (:func:`~wbfriction.report.numbers.with_error`, the terminal's
    format), ``value`` alone to ``digits`` significant digits without ``se``; "—" for none."""
    if value is None or not np.isfinite(value):
        return "—"
    if se is None:
        return f"{value:.{digits}g}"
    return with_error(value, se)


def _params_table(r: Report, joints: list[str], fits: dict[str, FitResult]) -> str:
    """Each joint's model, its fit's status and parameters (value ±standard error; "at a bound": at a bound of
    the fit), under them their Cramér-Rao bounds and the same model on the other route; blank where a parameter is
    not one of the joint's model. A fit that is not ``ok`` (:mod:`~wbfriction.fit.status`) is greyed, its
    status cell giving the reason."""
    names = [n for n in ALL_PARAM_NAMES if any(f.params is not None and n in f.params.names for f in fits.values())]
    head = "".join(f"<th>{n}</th>" for n in names)
    rows = []

    def cell(fit: FitResult, n: str) -> str:
        if fit.params is None or n not in fit.params.names:
            return "<td></td>"
        if n in fit.steps():
            return '<td>step<br><span class="name">sharper than the data resolve: Coulomb</span></td>'
        bound = '<br><span class="name">at a bound</span>' if fit.at_bound.get(n) else ""
        return f"<td>{_fmt(getattr(fit.params, n), fit.read_stderr().get(n))}{bound}</td>"

    for j in joints:
        fit = fits.get(j)
        if fit is None:
            rows.append(f'<tr class="notok">{_joint_cell(r, j)}<td>—</td><td class="status">not fitted</td>'
                        "<td>—</td>" + "<td></td>" * (len(names) + 1) + "</tr>")
            continue
        verdict = fit.verdict()
        status = f'<td class="status">{html.escape(str(verdict))}</td>'
        if fit.params is None:  # said, not printed as parameters
            rows.append(f'<tr class="notok">{_joint_cell(r, j)}<td>—</td>{status}<td>{fit.n_samples}</td>'
                        + "<td></td>" * (len(names) + 1) + "</tr>")
            continue
        cells = "".join(cell(fit, n) for n in names)
        screened = f'<br><span class="name">−{fit.n_screened} screened</span>' if fit.n_screened else ""
        tr = "<tr>" if verdict.ok else '<tr class="notok">'
        rows.append(f"{tr}{_joint_cell(r, j)}"
                    f"<td>{html.escape(fit.model)}</td>{status}<td>{fit.n_samples}{screened}</td>{cells}"
                    f"<td>{_fmt(fit.rms_residual)}</td></tr>")
        if fit.crb:
            rows.append('<tr class="target"><td>&nbsp;&nbsp;Cramér-Rao bound</td><td></td><td></td><td></td>'
                        + "".join(f"<td>{bound_text(fit.crb.get(n))}</td>" for n in names) + "<td></td></tr>")
        check = fit.route_check
        if check is not None and check.params is not None:
            rows.append(f'<tr class="target"><td>&nbsp;&nbsp;{html.escape(check.route)} route</td><td></td><td></td>'
                        "<td></td>" + "".join(f"<td>{_fmt(check.params[n], check.stderr.get(n))}</td>"
                                              if n in check.params else "<td></td>" for n in names) + "<td></td></tr>")
        err = fit.error_percent()
        if err is not None and fit.target is not None:
            target = fit.target.values_in(fit.model)
            rows.append('<tr class="target"><td>&nbsp;&nbsp;target</td><td></td><td></td><td></td>'
                        + "".join(f"<td>{_fmt(target[n]) if n in target else ''}</td>" for n in names)
                        + "<td></td></tr>")
            rows.append('<tr class="err"><td>&nbsp;&nbsp;error [%]</td><td></td><td></td><td></td>'
                        + "".join(f"<td>{f'{err[n]:.2f}' if n in err else ''}</td>" for n in names) + "<td></td></tr>")
    return ('<div class="scroll"><table id="parameters"><tr><th>joint</th><th class="text">model</th>'
            f'<th class="text">status</th><th>N</th>'
            f'{head}<th>RMS residual [N·m]</th></tr>' + "".join(rows) + "</table></div>")


def _identification_section(r: Report, ident: Identification) -> str:
    """The inertia-model identification: each pass's verdict (what the held-out gate kept,
    :mod:`~wbfriction.inertia.validation`) and solver outcome, held-out torque RMS, both routes' friction,
    the bodies as written (kept or given)."""
    passes = []
    for k, p in enumerate(ident.passes, start=1):
        solver = (p.solver or {}).get("meaning") or p.message
        verdict = p.verdict or f"pass {k}"
        passes.append(f"<li><b>{html.escape(verdict)}</b><br>v_s {_fmt(p.stribeck_velocity)} rad/s, "
                      f"{p.samples} samples, {p.base_parameters} base parameters of "
                      f"{p.parameters}, condition number {_fmt(p.condition)}, prior "
                      f"{p.prior:g}; {html.escape(solver)}</li>")
    validated = any(d.holdout_rms.validated is not None for d in ident.joints.values())
    rms = "".join(f"<tr>{_joint_cell(r, j)}" + "".join(
        "<td>—</td>" if x is None else f"<td>{x:.4f}</td>"
        for x in (d.holdout_rms.given, d.holdout_rms.given_with_friction, d.holdout_rms.identified,
                  *((d.holdout_rms.validated,) if validated else ())))
        + "</tr>" for j, d in ident.joints.items())
    names = ident.friction_names
    accel = ("F_v", "F_c", "tau_os")
    rows = []
    for j, d in ident.joints.items():
        route = {} if d.acceleration_route.params is None else d.acceleration_route.params.to_dict()
        rows.append(f"<tr>{_joint_cell(r, j)}" + "".join(f"<td>{_fmt(d.identified[n])}</td>" for n in names)
                    + "".join(f"<td>{_fmt(route.get(n))}</td>" for n in accel) + "</tr>")
    bodies = []
    for b in ident.bodies:
        if not b.has_mass:
            continue
        change = "new" if b.mass_change is None else f"{100 * b.mass_change:+.2f}"
        kept = "" if b.kept is None else f"<td>{'kept' if b.kept else 'given'} ({html.escape(str(b.limb))})</td>"
        bodies.append(f"<tr><td>{html.escape(b.body)}</td>{kept}<td>{b.mass_given:.4f}</td>"
                      f"<td>{b.mass:.4f}</td><td>{change}</td><td>{1e3 * b.com_shift:.2f}</td></tr>")
    kept_head = '<th class="text">written (limb)</th>' if any(b.kept is not None for b in ident.bodies) else ""
    heads = "".join(f"<th>{html.escape(n)}</th>" for n in names) + "".join(f"<th>accel. {n}</th>" for n in accel)
    rms_heads = "<th>given model</th><th>given + its best friction</th><th>identified</th>" + (
        "<th>written (kept where it helps)</th>" if validated else "")
    return f"""<h2 id="identification">Inertia model identified from the torques (thesis 2.4, ch. 8)</h2>
<ul class="sub">{''.join(passes)}</ul>
<p class="sub">Held out: the last {ident.holdout_samples} samples of the log whose equations are free of the contact
forces (single support; on point feet, each joint's where no foot with an unknown force is down on its leg), not
used to identify.
The identified inertias are written only for the limbs where they predict these samples better than the given
model with its best friction; the other limbs stay as given.</p>
<h3>Held-out joint torques: RMS of measured − predicted [N·m]</h3>
<div class="scroll"><table id="holdout-rms"><tr><th>joint</th>{rms_heads}</tr>{rms}</table></div>
<h3>Friction of this route (the model written) and of the acceleration route</h3>
<div class="scroll"><table id="identified-friction"><tr><th>joint</th>{heads}</tr>{''.join(rows)}</table></div>
<h3>Bodies: given → written</h3>
<div class="scroll"><table id="inertia-changes"><tr><th>body</th>{kept_head}<th>mass given [kg]</th>
<th>mass written [kg]</th><th>change [%]</th><th>COM shift [mm]</th></tr>{''.join(bodies)}</table></div>
"""


def _energy_row(r: Report, e: JointEnergy) -> str:
    pct = lambda x: "—" if x is None or not np.isfinite(x) else f"{100 * x:.2f}"  # noqa: E731
    lag = "—" if not np.isfinite(e.median_lag) else f"{1e3 * e.median_lag:.1f}"
    check = '<td class="fail">fail</td>' if e.flagged else '<td class="pass">pass</td>'
    return (f'<tr class="{"flag" if e.flagged else ""}">{_joint_cell(r, e.joint)}<td>{e.n_samples}</td>'
            f"<td>{pct(e.generating_share)}</td>{check}<td>{e.tau_os:.3g}</td><td>{e.velocity_crossings}</td>"
            f"<td>{'—' if e.delta_crossings is None else e.delta_crossings}</td><td>{lag}</td>"
            f"<td>{pct(e.opposite_share)}</td></tr>")


def _energy_table(r: Report, joints: list[str]) -> str:
    return (f'<div class="scroll"><table id="energy"><tr><th>joint</th><th>valid samples</th>'
            f"<th>power-generating [%]</th><th>≤ {100 * r.threshold:g} %</th>"
            "<th>τ_os removed [N·m]</th><th>qd zero crossings</th><th>Δqdd zero crossings</th>"
            "<th>median lag [ms]</th><th>Δqdd, qd opposite [%]</th></tr>"
            + "".join(_energy_row(r, r.energy[j]) for j in joints) + "</table></div>")


def _routes_section(r: Report) -> str:
    """The measured route against the rigid-contact one where both estimated a sample
    (:func:`~wbfriction.friction.cross_check.cross_check`); "" without a measured route."""
    est = r.est
    if est.disagreement is None:
        return ""
    checks = [c for c in cross_check(est.joints, est.disagreement, est.tau_f, est.qdd) if c.samples >= MIN_SAMPLES]
    if not checks:
        return ""
    rows = "".join(f'<tr class="{"flag" if c.cause else ""}">{_joint_cell(r, c.joint)}<td>{c.samples}</td>'
                   f"<td>{c.rms:.3g}</td><td>{c.mean:.3g}</td><td>{100 * c.share:.1f}</td>"
                   f'<td class="verdict">{html.escape(c.cause)}</td></tr>' for c in checks)
    return ('<h2 id="routes">Routes cross-checked: the sensors\' route against the rigid contact</h2>'
            '<p class="sub">Single-support samples estimated by both routes: τ_f(measured) − τ_f(rigid contact). '
            f"A disagreement above {100 * LARGE:g} % of the friction's RMS is given its likely cause.</p>"
            '<div class="scroll"><table id="routes"><tr><th>joint</th><th>samples</th><th>RMS [N·m]</th>'
            f'<th>mean [N·m]</th><th>share of τ_f [%]</th><th class="text">likely cause</th></tr>{rows}</table></div>')


def _determination_section(r: Report) -> str:
    """A robot on point feet: the share of samples that determine each joint's friction, by feet on the ground
    (:func:`~wbfriction.friction.point_contacts.determined_shares`); "" otherwise."""
    shares = determined_shares(r.est)
    if shares is None:
        return ""
    head = "".join(f"<th>{html.escape(p)} ({n})</th>" for p, n in zip(shares.patterns, shares.samples))
    rows = "".join(f"<tr>{_joint_cell(r, j)}" + "".join(f"<td>{100 * s:.0f}</td>" for s in shares.share[:, i])
                   + f"<td>{100 * shares.overall[i]:.0f}</td></tr>" for i, j in enumerate(shares.joints))
    return ('<h2 id="determined">Where each joint\'s friction is determined</h2>'
            '<p class="sub">Share of samples [%], by the feet on the ground: a joint is determined where the '
            "equations of motion leave its friction unique (the rank of [Sᵀ Jᵀ], the logged foot forces counted), "
            "never guessed elsewhere. Samples within the switches' margins are not counted.</p>"
            f'<div class="scroll"><table id="determined"><tr><th>joint</th>{head}<th>all ({int(shares.samples.sum())})'
            f"</th></tr>{rows}</table></div>")


def _summary_box(r: Report) -> str:
    """The box atop the report: the joints whose friction generates power, or the worst one's share."""
    flagged = r.flagged
    n = len(r.moved)
    if flagged:
        items = "".join(f"<li>{html.escape(r.label(e.joint))}: {html.escape(e.warning() or '')}</li>"
                        for e in flagged)
        return (f'<div class="box warn" id="energy-warning"><b>{len(flagged)} of {n} joints that moved generate '
                f"power</b> in more than {100 * r.threshold:g} % of their valid samples (eq. 7.9). Friction "
                f"dissipates energy; estimates that generate it point at the inertia model (try "
                f"<code>wbfriction sensitivity</code>), a torque-sensor offset or the filtering "
                f"(thesis 7.2).<ul>{items}</ul></div>")
    shares = [r.energy[j] for j in r.moved if np.isfinite(r.energy[j].generating_share)]
    if not shares:
        return '<div class="box warn" id="energy-none">No joint moved in a valid sample: nothing to judge.</div>'
    worst = max(shares, key=lambda e: e.generating_share)
    return (f'<div class="box ok" id="energy-ok">Every joint\'s friction dissipates energy: at most '
            f"{100 * worst.generating_share:.2f} % of a joint's valid samples generate power "
            f"({html.escape(r.label(worst.joint))}; threshold {100 * r.threshold:g} %).</div>")


def joint_verdict(verdict: FitVerdict, energy: JointEnergy | None) -> tuple[str, bool]:
    """What a reader does with a joint's numbers, in one phrase, and whether they can be used: the fit's
    status (:mod:`~wbfriction.fit.status`) and the energy check (eq. 7.9) together."""
    if verdict.status in ("ok", "weak") and energy is not None and energy.flagged:
        return (f"check the inertia model: friction generates power in {100 * energy.generating_share:.1f} % "
                "of the samples", False)
    if verdict.ok:
        return "usable", True
    if verdict.status == "weak":
        return f"use with care: {verdict.reason}", False
    return f"not usable: {verdict.reason}", False


def _pm(fit: FitResult, name: str, digits: int = 3) -> str:
    """``value ± se`` of one parameter of ``fit``, "—" when it is not in the fit's model."""
    if fit.params is None or name not in fit.params.names:
        return "—"
    value = getattr(fit.params, name)
    value = 0.0 if abs(value) < 1e-9 else value  # a magnitude at its floor of zero, not 2.4e-15
    return _fmt(value, fit.read_stderr().get(name), digits)


def _summary_table(r: Report) -> str:
    """One row per joint that moved: label, status, F_c, F_v, tau_os (± standard error), the power-generating
    share, valid samples and the verdict (:func:`joint_verdict`; with terms beyond velocity, the conditions its F_c,
    F_v hold at, :meth:`~wbfriction.fit.terms.TermFit.reference_conditions`); the joints that did not move in
    one line."""
    rows = []
    for j in r.moved:
        fit, e = r.fits.get(j), r.energy.get(j)
        share = "—" if e is None or not np.isfinite(e.generating_share) else f"{100 * e.generating_share:.1f}"
        cls = "" if e is None else (' class="fail"' if e.flagged else ' class="pass"')
        if fit is None:  # the parameters given cover other joints
            status, ok, values = "not fitted", False, "<td>—</td>" * 3
            text, good = "no parameters for this joint in the file given", False
        else:
            verdict = fit.verdict()
            status, ok = verdict.status, verdict.ok
            text, good = joint_verdict(verdict, e)
            terms = fit.kept_terms
            if terms is not None:  # its F_c, F_v are levels at the terms' reference conditions (issue 53)
                text += (f"; F_c, F_v at {terms.reference_conditions()} (terms beyond velocity: "
                         f"{', '.join(terms.kept)})")
            values = "".join(f"<td>{_pm(fit, n)}</td>" for n in ("F_c", "F_v", "tau_os"))
        rows.append(f'<tr{"" if ok else " class=notok"}>{_joint_cell(r, j)}'
                    f'<td class="status">{html.escape(status)}</td>{values}<td{cls}>{share}</td>'
                    f"<td>{0 if e is None else e.n_samples}</td>"
                    f'<td class="verdict {"good" if good else "bad"}">{html.escape(text)}</td></tr>')
    if r.still:
        names = ", ".join(html.escape(r.label(j)) for j in r.still)
        rows.append(f'<tr class="still"><td colspan="8" class="verdict">{len(r.still)} joints did not move '
                    f"(|qd| below {MIN_SPEED:g} rad/s on 95 % of their valid samples, or none valid): their "
                    f"friction is not in these data: {names}.</td></tr>")
    return ('<div class="scroll"><table id="summary"><tr><th>joint</th><th class="text">status</th>'
            "<th>F_c [N·m]</th><th>F_v [N·m·s/rad]</th><th>τ_os [N·m]</th><th>power-generating [%]</th>"
            f'<th>valid samples</th><th class="text">verdict</th></tr>{"".join(rows)}</table></div>')


def _figures(r: Report, joints: list[str], targets: Mapping[str, ModelParams],
             spectra: dict[str, tuple[np.ndarray, np.ndarray, float]], workers: int = 1) -> list[str]:
    """The overview figure's ``<img>`` (none without a joint), then each joint's
    (:func:`~wbfriction.report.friction_figures.joint_figure`), rendered on ``workers`` processes (forked: they read the
    report from memory), the overview first."""
    _FIGURE_INPUTS.update(r=r, targets=targets, spectra=spectra, joints=joints)
    keys: list[str | None] = [None, *joints] if joints else []
    try:
        if workers > 1 and len(keys) > 1:
            with process_pool(min(workers, len(keys)), "fork") as pool:
                images = list(pool.map(_figure_image, keys))
        else:
            images = [_figure_image(k) for k in keys]
        return images or [""]
    finally:
        _FIGURE_INPUTS.clear()


_FIGURE_INPUTS: dict = {}
"""What :func:`_figure_image` draws from: set by :func:`_figures` before its workers fork."""


def report_figure(r: Report, joint: str | None, spectra: Mapping[str, tuple[np.ndarray, np.ndarray, float]]
                  | None = None) -> Figure:
    """A figure of the report as the page shows it: the overview (``joint`` None:
    :func:`~wbfriction.report.friction_figures.friction_overview_figure` of the joints that moved) or one joint's
    (:func:`~wbfriction.report.friction_figures.joint_figure`); ``spectra`` as
    :func:`~wbfriction.report.build.acceleration_spectra` gives them (computed when None)."""
    targets: dict[str, ModelParams] = {j: f.target for j, f in r.fits.items() if f.target is not None}
    if joint is None:
        joints = list(r.moved)
        return friction_overview_figure(r.est, joints, r.fits, targets, {e.joint for e in r.flagged},
                                        labels={j: r.label(j) for j in joints})
    spectra = acceleration_spectra(r.est) if spectra is None else spectra
    return joint_figure(r.est, joint, r.fits.get(joint), targets.get(joint), spectra.get(joint))


def _figure_image(joint: str | None) -> str:
    """The ``<img>`` of the overview figure (``joint`` None) or of one joint's figure."""
    r, spectra = _FIGURE_INPUTS["r"], _FIGURE_INPUTS["spectra"]
    if joint is None:
        return _img(report_figure(r, None), "friction of every joint that moved, over velocity", "overview",
                    "overview-figure")
    return _img(report_figure(r, joint, spectra), f"friction of {r.label(joint)}", "fig-" + _anchor(joint),
                "joint-figure")


def _joint_section(r: Report, joint: str, image: str) -> str:
    """One joint's section: its label and name, its fit's verdict and energy note, its figure."""
    e = r.energy[joint]
    note = (f"{e.n_samples} valid samples; {100 * e.generating_share:.2f} % generate power"
            if np.isfinite(e.generating_share) else "no valid sample")
    fit = r.fits.get(joint)
    if fit is not None:
        note = f"fit: {fit.verdict()}; " + note
    name = "" if r.label(joint) == joint else f' <span class="name">{html.escape(joint)}</span>'
    return (f'<section class="joint" id="{_anchor(joint)}"><h3>{html.escape(r.label(joint))}{name}</h3>'
            f'<p class="sub">{html.escape(note)}</p>{image}</section>')


def _terms_section(r: Report) -> str:
    """The terms beyond velocity of the joints that moved (:func:`~wbfriction.report.terms.terms_section`), "" when
    no fit kept one."""
    return terms_section(r.moved, r.fits, lambda joint: _joint_cell(r, joint))


def _provenance(r: Report) -> str:
    """Inputs, robot and options, then every dependency's version and the date, as a table."""
    rows = [*r.provenance, ("versions", ", ".join(f"{n} {v}" for n, v in r.versions)), ("date", r.date)]
    return ('<table id="provenance" class="provenance">'
            + "".join(f"<tr><td>{html.escape(k)}</td><td>{html.escape(v)}</td></tr>" for k, v in rows) + "</table>")


def _contents(r: Report) -> str:
    """The table of contents: the page's sections, in order."""
    items = [("summary", "Summary"), ("overview-section", "Friction over velocity"),
             ("parameters-section", "Identified parameters"), ("energy-section", "Energy consistency")]
    if _terms_section(r):
        items.append(("terms-section", "Terms beyond velocity"))
    if _routes_section(r):
        items.append(("routes", "Routes cross-checked"))
    if _determination_section(r):
        items.append(("determined", "Where each joint's friction is determined"))
    if r.identification is not None:
        items.append(("identification", "Inertia model identified"))
    items += [("joints", f"Joints that moved ({len(r.moved)})"), ("provenance-section", "Provenance")]
    return ('<nav id="contents"><b>Contents</b><ol>'
            + "".join(f'<li><a href="#{a}">{html.escape(t)}</a></li>' for a, t in items) + "</ol></nav>")


def _page(r: Report, overview: str, sections: list[str]) -> str:
    """The page: title, contents, summary, overview figure, tables, the joints' sections, provenance."""
    est = r.est
    robot = dict(r.provenance).get("robot", "?")
    moved = list(r.moved)
    nav = "".join(f'<a href="#{_anchor(j)}">{html.escape(r.label(j))}</a>' for j in moved)
    n_valid = int(est.valid.any(axis=1).sum())
    support = f"{int(est.unique.sum())} in single support, " if est.contact_frames else "fixed base, "
    if est.determined is not None:
        support = f"{int(est.determined.any(axis=1).sum())} determining some joint, "
    still = ""
    if r.still:
        still = (f'<details class="still"><summary>{len(r.still)} joints did not move: no figure</summary>'
                 f'<p class="sub">{", ".join(html.escape(r.label(j)) for j in r.still)}</p></details>')
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>wbfriction report: {html.escape(robot)}</title><style>{PAGE_CSS}</style></head>
<body>
<h1>Joint friction report: {html.escape(robot)}</h1>
<p class="sub">{len(est.time)} samples, {duration_text(est.time)}, {support}{n_valid} with a valid joint;
{len(est.joints)} torque-controlled joints, {len(moved)} of which moved. Sign convention:
τ_f is the torque friction exerts on the joint (dissipative: qd·τ_f ≤ 0); the model f(qd) of eq. (3.5) is fitted to
−τ_f. Made {html.escape(r.date)}.</p>
{_contents(r)}
<h2 id="summary">Summary</h2>
{_summary_box(r)}
<p class="sub">Value ± standard error; status of the fit (ok, weak, at bound, not excited, failed); power-generating:
share of the valid samples where the friction estimate generates power (eq. 7.9).</p>
{_summary_table(r)}
<h2 id="overview-section">Friction over velocity</h2>
<p class="sub">Each joint's valid samples and {html.escape(FIT_DRAWN)}; its legend names the fit's model.</p>
{overview}
<h2 id="parameters-section">Identified parameters (3.5), value ± standard error</h2>
<p class="sub">Units: F_v N·m·s/rad, F_c and τ_os N·m, v_s rad/s, a s/rad. n.i.: not identifiable from these data.</p>
{_params_table(r, moved, r.fits)}
{_terms_section(r)}
<h2 id="energy-section">Energy consistency (eq. 7.9, Fig. 7.4)</h2>
<p class="sub">{_ENERGY_NOTE}</p>
{_energy_table(r, moved)}
{_routes_section(r)}
{_determination_section(r)}
{"" if r.identification is None else _identification_section(r, r.identification)}
<h2 id="joints">Joints that moved</h2>
<p class="sub">Each joint's figure: (a) its friction over velocity and its fit; (b) τ_f over time in seconds from the
log's start, a panel per run where gaps split it (each from its own start), by support phase (single dark blue,
double green, flight red; valid samples orange); (c) Fig. 7.4 over its widest valid stretch; (d) Fig. 7.1.</p>
<nav class="joints">{nav}</nav>
{''.join(sections)}
{still}
<h2 id="provenance-section">Provenance</h2>
{_provenance(r)}
</body></html>
"""


def render_html(r: Report, workers: int = 1) -> str:
    """The report as one self-contained HTML page, its figures rendered on ``workers`` processes (the same
    bytes for any number). Only the joints that moved get figures and table rows (:attr:`Report.moved`)."""
    moved = list(r.moved)
    targets = {j: f.target for j, f in r.fits.items() if f.target is not None}
    overview, *images = _figures(r, moved, targets, acceleration_spectra(r.est), workers)
    return _page(r, overview, [_joint_section(r, j, im) for j, im in zip(moved, images)])


def write_report(report: Report, output: str | Path, workers: int = 1) -> None:
    """Write the report's HTML (:func:`render_html` on ``workers`` processes), whole or not at all."""
    text = render_html(report, workers)
    write_atomic(output, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))
