"""The report rendered: one self-contained HTML page (figures embedded as PNG, no script, no network).

The same report gives the same bytes (no timestamps). What it shows is gathered by
:mod:`wbfriction.report.build`.
"""

from __future__ import annotations

import base64
import html
from pathlib import Path

import numpy as np

from wbfriction.friction.cross_check import LARGE, MIN_SAMPLES, cross_check
from wbfriction.friction.energy import JointEnergy
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.fit import FitResult
from wbfriction.friction.models import ALL_PARAM_NAMES, FrictionParams
from wbfriction.logs.tables import write_atomic
from wbfriction.report.build import Report, acceleration_spectra
from wbfriction.report.figures import friction_overview_figure, joint_figure, png_bytes
from wbfriction.workers import process_pool

_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", sans-serif; margin: 0 auto; max-width: 1480px;
       padding: 0 24px 48px; color: #1d232a; }
h1 { font-size: 1.5rem; margin: 24px 0 4px; } h2 { font-size: 1.15rem; margin-top: 32px;
     border-bottom: 1px solid #d5dae0; padding-bottom: 4px; } h3 { font-size: 1rem; margin: 24px 0 6px; }
.sub { color: #5a6570; margin: 0 0 16px; }
.box { padding: 10px 14px; border-radius: 6px; margin: 12px 0; }
.warn { background: #fff4e5; border: 1px solid #f0b35a; } .ok { background: #eef8ef; border: 1px solid #8cc79a; }
table { border-collapse: collapse; font-size: 0.82rem; font-variant-numeric: tabular-nums; }
th, td { padding: 3px 8px; text-align: right; border-bottom: 1px solid #eceff2; white-space: nowrap; }
th { background: #f5f7f9; } td:first-child, th:first-child { text-align: left; }
tr.flag td { background: #fff1f0; } tr.target td, tr.err td { color: #6b7580; }
tr.notok td { color: #9aa3ad; } tr.notok td.status { color: #a4520a; white-space: normal; text-align: left; }
td.status { text-align: left; }
img { max-width: 100%; height: auto; display: block; }
nav { display: flex; flex-wrap: wrap; gap: 4px 12px; font-size: 0.85rem; }
dl { display: grid; grid-template-columns: max-content 1fr; gap: 2px 16px; font-size: 0.82rem; }
dt { color: #5a6570; } dd { margin: 0; word-break: break-all; font-family: ui-monospace, monospace; }
section.joint { margin-top: 18px; }
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


def _fmt(value: float | None, se: float | None = None) -> str:
    if value is None or not np.isfinite(value):
        return "—"
    if se is None:
        return f"{value:.4g}"
    return f"{value:.4g} ± {'n.i.' if not np.isfinite(se) else f'{se:.2g}'}"


def _params_table(joints: list[str], fits: dict[str, FitResult]) -> str:
    """Each joint's model, its fit's status and parameters (value ±standard error; "(bound)": at a bound of
    the fit); blank where a parameter is not one of the joint's model. A fit that is not ``ok``
    (:mod:`~wbfriction.friction.status`) is greyed, its status cell giving the reason."""
    names = [n for n in ALL_PARAM_NAMES if any(f.params is not None and n in f.params.names for f in fits.values())]
    head = "".join(f"<th>{n}</th>" for n in names)
    rows = []

    def cell(fit: FitResult, n: str) -> str:
        if fit.params is None or n not in fit.params.names:
            return "<td></td>"
        bound = " (bound)" if fit.at_bound.get(n) else ""
        return f"<td>{_fmt(getattr(fit.params, n), fit.stderr.get(n))}{bound}</td>"

    for j in joints:
        fit = fits.get(j)
        if fit is None:
            rows.append(f'<tr class="notok"><td>{html.escape(j)}</td><td>—</td><td class="status">not fitted</td>'
                        "<td>—</td>" + "<td></td>" * (len(names) + 1) + "</tr>")
            continue
        verdict = fit.verdict()
        status = f'<td class="status">{html.escape(str(verdict))}</td>'
        if fit.params is None:  # said, not printed as parameters
            rows.append(f'<tr class="notok"><td>{html.escape(j)}</td><td>—</td>{status}<td>{fit.n_samples}</td>'
                        + "<td></td>" * (len(names) + 1) + "</tr>")
            continue
        cells = "".join(cell(fit, n) for n in names)
        screened = f" (−{fit.n_screened} screened)" if fit.n_screened else ""
        tr = "<tr>" if verdict.ok else '<tr class="notok">'
        rows.append(f"{tr}<td>{html.escape(j)}</td>"
                    f"<td>{html.escape(fit.model)}</td>{status}<td>{fit.n_samples}{screened}</td>{cells}"
                    f"<td>{_fmt(fit.rms_residual)}</td></tr>")
        err = fit.error_percent()
        if err is not None and fit.target is not None:
            target = fit.target.values_in(fit.model)
            rows.append('<tr class="target"><td>&nbsp;&nbsp;target</td><td></td><td></td><td></td>'
                        + "".join(f"<td>{_fmt(target[n]) if n in target else ''}</td>" for n in names)
                        + "<td></td></tr>")
            rows.append('<tr class="err"><td>&nbsp;&nbsp;error [%]</td><td></td><td></td><td></td>'
                        + "".join(f"<td>{f'{err[n]:.2f}' if n in err else ''}</td>" for n in names) + "<td></td></tr>")
    return (f'<table id="parameters"><tr><th>joint</th><th>model</th><th>status</th><th>N</th>{head}'
            '<th>RMS residual [N·m]</th></tr>'
            + "".join(rows) + "</table>")


def _identification_section(doc: dict) -> str:
    """The inertia-model identification: held-out torque RMS, both routes' friction, body changes."""
    passes = "; ".join(f"v_s {p.get('stribeck_velocity')}: {p.get('samples')} samples, {p.get('base_parameters')} "
                       f"base parameters of {p.get('parameters')}, condition {p.get('condition')}, prior "
                       f"{p.get('prior')}" for p in doc["passes"])
    rms = "".join(f"<tr><td>{html.escape(j)}</td>" + "".join(
        f"<td>{d['holdout_rms'][k]:.4f}</td>" for k in ("given", "given_with_friction", "identified"))
        + "</tr>" for j, d in doc["joints"].items())
    names = list(next(iter(doc["joints"].values()))["identified"])
    accel = ("F_v", "F_c", "tau_os")
    rows = []
    for j, d in doc["joints"].items():
        route = ((d.get("acceleration_route") or {}).get("params")) or {}
        rows.append(f"<tr><td>{html.escape(j)}</td>" + "".join(f"<td>{_fmt(d['identified'][n])}</td>" for n in names)
                    + "".join(f"<td>{_fmt(route.get(n))}</td>" for n in accel) + "</tr>")
    bodies = []
    for b in doc["bodies"]:
        if max(b["mass_given"], b["mass"]) <= 0:
            continue
        change = "new" if b.get("mass_change") is None else f"{100 * b['mass_change']:+.2f}"
        bodies.append(f"<tr><td>{html.escape(b['body'])}</td><td>{b['mass_given']:.4f}</td><td>{b['mass']:.4f}</td>"
                      f"<td>{change}</td><td>{1e3 * b['com_shift']:.2f}</td></tr>")
    return f"""<h2>Inertia model identified from the torques (thesis 2.4, ch. 8)</h2>
<p class="sub">{html.escape(passes)}. Held out: the last {doc['holdout_samples']} single-support samples of the log,
not used to identify.</p>
<h3>Held-out joint torques: RMS of measured − predicted [N·m]</h3>
<table id="holdout-rms"><tr><th>joint</th><th>given model</th><th>given + its best friction</th><th>identified</th></tr>
{rms}</table>
<h3>Friction of this route and of the acceleration route with the identified model</h3>
<table id="identified-friction"><tr><th>joint</th>{''.join(f"<th>{html.escape(n)}</th>" for n in names)}
{''.join(f"<th>accel. {n}</th>" for n in accel)}</tr>{''.join(rows)}</table>
<h3>Bodies: given → identified</h3>
<table id="inertia-changes"><tr><th>body</th><th>mass given [kg]</th><th>mass [kg]</th><th>change [%]</th>
<th>COM shift [mm]</th></tr>{''.join(bodies)}</table>
"""


def _energy_row(e: JointEnergy) -> str:
    pct = lambda x: "—" if x is None or not np.isfinite(x) else f"{100 * x:.2f}"  # noqa: E731
    lag = "—" if not np.isfinite(e.median_lag) else f"{1e3 * e.median_lag:.1f}"
    return (f'<tr class="{"flag" if e.flagged else ""}"><td>{html.escape(e.joint)}</td><td>{e.n_samples}</td>'
            f"<td>{pct(e.generating_share)}</td><td>{e.tau_os:.3g}</td><td>{e.velocity_crossings}</td>"
            f"<td>{'—' if e.delta_crossings is None else e.delta_crossings}</td><td>{lag}</td>"
            f"<td>{pct(e.opposite_share)}</td><td>{'over threshold' if e.flagged else ''}</td></tr>")


def _energy_table(joints: list[str], energy: dict[str, JointEnergy]) -> str:
    return ('<table id="energy"><tr><th>joint</th><th>valid samples</th><th>power-generating [%]</th>'
            "<th>τ_os removed [N·m]</th><th>qd zero crossings</th><th>Δqdd zero crossings</th>"
            "<th>median lag [ms]</th><th>Δqdd, qd opposite [%]</th><th></th></tr>"
            + "".join(_energy_row(energy[j]) for j in joints) + "</table>")


def _routes_section(est: FrictionEstimate) -> str:
    """The measured route against the rigid-contact one where both estimated a sample
    (:func:`~wbfriction.friction.cross_check.cross_check`); "" without a measured route."""
    if est.disagreement is None:
        return ""
    checks = [c for c in cross_check(est.joints, est.disagreement, est.tau_f, est.qdd) if c.samples >= MIN_SAMPLES]
    if not checks:
        return ""
    rows = "".join(f'<tr class="{"flag" if c.cause else ""}"><td>{html.escape(c.joint)}</td><td>{c.samples}</td>'
                   f"<td>{c.rms:.3g}</td><td>{c.mean:.3g}</td><td>{100 * c.share:.1f}</td>"
                   f"<td>{html.escape(c.cause)}</td></tr>" for c in checks)
    return ("<h2>Routes cross-checked: the sensors' route against the rigid contact</h2>"
            '<p class="sub">Single-support samples estimated by both routes: τ_f(measured) − τ_f(rigid contact). '
            f"A disagreement above {100 * LARGE:g} % of the friction's RMS is given its likely cause.</p>"
            '<table id="routes"><tr><th>joint</th><th>samples</th><th>RMS [N·m]</th><th>mean [N·m]</th>'
            f"<th>share of τ_f [%]</th><th>likely cause</th></tr>{rows}</table>")


def _summary_box(r: Report, n_joints: int) -> str:
    """The box atop the report: the joints whose friction generates power, or the worst one's share."""
    flagged = r.flagged
    if flagged:
        items = "".join(f"<li>{html.escape(e.warning() or '')}</li>" for e in flagged)
        return (f'<div class="box warn" id="energy-warning"><b>{len(flagged)} of {n_joints} joints generate '
                f"power</b> in more than {100 * r.threshold:g} % of their valid samples (eq. 7.9). Friction "
                f"dissipates energy; estimates that generate it point at the inertia model (try "
                f"<code>wbfriction sensitivity</code>), a torque-sensor offset or the filtering "
                f"(thesis 7.2).<ul>{items}</ul></div>")
    worst = max(r.energy.values(), key=lambda e: e.generating_share if np.isfinite(e.generating_share) else -1)
    return (f'<div class="box ok" id="energy-ok">Every joint\'s friction dissipates energy: at most '
            f"{100 * worst.generating_share:.2f} % of a joint's valid samples generate power "
            f"({html.escape(worst.joint)}; threshold {100 * r.threshold:g} %).</div>")


def _figures(r: Report, joints: list[str], targets: dict[str, FrictionParams],
             spectra: dict[str, tuple[np.ndarray, np.ndarray, float]], workers: int = 1) -> list[str]:
    """The overview figure's ``<img>``, then each joint's (:func:`~wbfriction.report.figures.joint_figure`),
    rendered on ``workers`` processes (forked: they read the report from memory), the overview first."""
    _FIGURE_INPUTS.update(r=r, targets=targets, spectra=spectra)
    keys: list[str | None] = [None, *joints]
    try:
        if workers > 1:
            with process_pool(min(workers, len(keys)), "fork") as pool:
                return list(pool.map(_figure_image, keys))
        return [_figure_image(k) for k in keys]
    finally:
        _FIGURE_INPUTS.clear()


_FIGURE_INPUTS: dict = {}
"""What :func:`_figure_image` draws from: set by :func:`_figures` before its workers fork."""


def _figure_image(joint: str | None) -> str:
    """The ``<img>`` of the overview figure (``joint`` None) or of one joint's figure."""
    r, targets, spectra = (_FIGURE_INPUTS[k] for k in ("r", "targets", "spectra"))
    if joint is None:
        flagged = {e.joint for e in r.flagged}
        return _img(friction_overview_figure(r.est, list(r.est.joints), r.fits, targets, flagged),
                    "friction of every joint over velocity", "overview", "overview-figure")
    fig = joint_figure(r.est, joint, r.fits.get(joint), targets.get(joint), spectra.get(joint))
    return _img(fig, joint, "fig-" + _anchor(joint), "joint-figure")


def _joint_section(r: Report, joint: str, image: str) -> str:
    """One joint's section: its energy note and its figure."""
    e = r.energy[joint]
    note = (f"{e.n_samples} valid samples; {100 * e.generating_share:.2f} % generate power"
            if np.isfinite(e.generating_share) else "no valid sample")
    return (f'<section class="joint" id="{_anchor(joint)}"><h3>{html.escape(joint)}</h3>'
            f'<p class="sub">{note}</p>{image}</section>')


def _page(r: Report, joints: list[str], summary: str, overview: str, sections: list[str]) -> str:
    """The page around the summary box, the overview figure and the joints' sections."""
    est = r.est
    robot = dict(r.provenance).get("robot", "?")
    nav = "".join(f'<a href="#{_anchor(j)}">{html.escape(j)}</a>' for j in joints)
    prov = "".join(f"<dt>{html.escape(k)}</dt><dd>{html.escape(v)}</dd>" for k, v in r.provenance)
    n_valid = int(est.valid.any(axis=1).sum())
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><meta name="viewport" content="width=device-width, initial-scale=1">
<title>wbfriction report: {html.escape(robot)}</title><style>{_CSS}</style></head>
<body>
<h1>Joint friction report: {html.escape(robot)}</h1>
<p class="sub">{len(est.time)} samples, {est.time[-1] - est.time[0]:.1f} s, {int(est.unique.sum())} in single support,
{n_valid} with a valid joint; {len(joints)} torque-controlled joints. Sign convention: τ_f is the torque friction
exerts on the joint (dissipative: qd·τ_f ≤ 0); the model f(qd) of eq. (3.5) is fitted to −τ_f.</p>
{summary}
<h2>Friction over velocity</h2>
{overview}
<h2>Identified parameters (3.5), value ± standard error</h2>
<p class="sub">Units: F_v N·m·s/rad, F_c and τ_os N·m, v_s rad/s, a s/rad. n.i.: not identifiable from these data.</p>
{_params_table(joints, r.fits)}
<h2>Energy consistency (eq. 7.9, Fig. 7.4)</h2>
<p class="sub">{_ENERGY_NOTE}</p>
{_energy_table(joints, r.energy)}
{_routes_section(est)}
{"" if r.identification is None else _identification_section(r.identification)}
<h2>Joints</h2>
<nav>{nav}</nav>
{''.join(sections)}
<h2>Provenance</h2>
<dl id="provenance">{prov}</dl>
</body></html>
"""


def render_html(r: Report, workers: int = 1) -> str:
    """The report as one self-contained HTML page, its per-joint figures rendered on ``workers``
    processes (the same bytes for any number)."""
    est = r.est
    joints = list(est.joints)
    targets = {j: f.target for j, f in r.fits.items() if f.target is not None}
    summary = _summary_box(r, len(joints))
    overview, *images = _figures(r, joints, targets, acceleration_spectra(est), workers)
    return _page(r, joints, summary, overview, [_joint_section(r, j, im) for j, im in zip(joints, images)])


def write_report(report: Report, output: str | Path, workers: int = 1) -> None:
    """Write the report's HTML (:func:`render_html` on ``workers`` processes), whole or not at all."""
    text = render_html(report, workers)
    write_atomic(output, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


