"""One self-contained HTML report of a friction estimate: ``wbfriction report``.

Everything a person needs to judge a friction table at a glance, in one file that opens
offline (figures embedded as PNG, no script, no network):

* a summary with the energy-consistency warnings (:mod:`wbfriction.energy`, eq. 7.9);
* the friction clouds of every joint as small multiples on shared axes, with the fitted
  model (3.5) and the target where known;
* the identified parameters with their standard errors (6.2.2), and the errors against the
  targets of a simulated log;
* the energy-consistency table (share of power-generating samples, zero crossings of
  ``Delta qdd`` against those of the velocity, Fig. 7.4);
* per joint: the cloud, ``tau_f`` over time by support phase, Fig. 7.4 with and without
  filtering, and the spectrum of the estimated acceleration (Fig. 7.1);
* the provenance: input files with their SHA-256, robot, options, package versions.

The same inputs give the same bytes (no timestamps).
"""

from __future__ import annotations

import base64
import html
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import __version__
from .energy import DEFAULT_THRESHOLD, DEFAULT_TOLERANCE, JointEnergy, energy_consistency
from .estimate import FrictionEstimate, estimate_from_table
from .exceptions import InputError
from .filters import amplitude_spectrum, finite_runs, suggest_cutoff
from .friction import PARAM_NAMES
from .identify import FitResult, fit_table_estimate, fitted_offsets
from .log import file_sha256, read_table, write_atomic
from .plots import friction_overview_figure, joint_figure, png_bytes

MIN_SPECTRUM_SAMPLES = 64


def load_params(path: str | Path) -> dict[str, FitResult]:
    """Fitted parameters written by ``wbfriction fit`` (or the demo), by joint name.

    Raises:
        InputError: a file that is not such JSON (named with the key at fault).
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: file not found")
    try:
        doc = json.loads(path.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: not JSON: {exc}") from None
    joints = doc.get("joints") if isinstance(doc, dict) else None
    if not isinstance(joints, dict):
        raise InputError(f"{path}: no 'joints' object: not a parameter file from 'wbfriction fit'")
    out = {}
    for joint, d in joints.items():
        try:
            out[joint] = FitResult.from_dict(joint, d)
        except (ValueError, TypeError, AttributeError) as exc:
            raise InputError(f"{path}: joint '{joint}': {exc}") from None
    return out


def acceleration_spectra(est: FrictionEstimate, tail: float = 0.01) -> dict[str, tuple[np.ndarray, np.ndarray, float]]:
    """Spectrum of the estimated acceleration ``qdd_est = qdd - Delta qdd`` (5.10) of every joint
    over the longest stretch where it is defined for all joints, and its suggested cutoff
    (Fig. 7.1, :func:`~wbfriction.filters.suggest_cutoff`); {} when the table lacks the columns
    or the stretch is shorter than 64 samples."""
    if est.qdd is None or est.delta_qdd is None:
        return {}
    qdd_est = est.qdd - est.delta_qdd
    runs = finite_runs(np.where(np.isfinite(qdd_est).all(axis=1), 0.0, np.nan))
    if not runs:
        return {}
    a, b = max(runs, key=lambda r: r[1] - r[0])
    if b - a < MIN_SPECTRUM_SAMPLES:
        return {}
    freq, amp = amplitude_spectrum(qdd_est[a:b], float(np.median(np.diff(est.time))))
    return {j: (freq, amp[:, i], suggest_cutoff(freq, amp[:, i], tail)) for i, j in enumerate(est.joints)}


def load_identification(path: str | Path) -> dict:
    """What ``wbfriction identify --json`` wrote (:func:`wbfriction.closed_loop.loop_document`).

    Raises:
        InputError: a file that is not such JSON (named with the key at fault).
    """
    path = Path(path)
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{path}: not an identification written by 'wbfriction identify --json' ({exc})") from None

    def need(ok: bool, key: str) -> None:
        if not ok:
            raise InputError(f"{path}: '{key}' is missing or malformed (not written by 'wbfriction identify --json'?)")

    need(isinstance(doc, dict) and isinstance(doc.get("joints"), dict) and doc["joints"], "joints")
    for joint, j in doc["joints"].items():
        need(isinstance(j, dict) and isinstance(j.get("holdout_rms"), dict)
             and all(isinstance(j["holdout_rms"].get(k), (int, float))
                     for k in ("given", "given_with_friction", "identified")), f"joints.{joint}.holdout_rms")
        need(isinstance(j.get("identified"), dict)
             and all(isinstance(v, (int, float)) for v in j["identified"].values()), f"joints.{joint}.identified")
    need(isinstance(doc.get("bodies"), list) and all(
        isinstance(b, dict) and isinstance(b.get("body"), str)
        and all(isinstance(b.get(k), (int, float)) for k in ("mass_given", "mass", "com_shift"))
        for b in doc["bodies"]), "bodies")
    need(isinstance(doc.get("passes"), list) and doc["passes"] and all(isinstance(p, dict) for p in doc["passes"]),
         "passes")
    need(isinstance(doc.get("holdout_samples"), int), "holdout_samples")
    return doc


@dataclass
class Report:
    """What a report shows, computed; :meth:`html` renders it.

    Attributes:
        est: the estimate read from the friction table.
        fits: fitted parameters by joint (from ``--params`` or fitted here).
        energy: energy consistency by joint.
        provenance: (label, value) pairs.
        threshold: share of power-generating samples above which a joint is flagged.
        identification: what ``wbfriction identify --json`` wrote, or None.
    """

    est: FrictionEstimate
    fits: dict[str, FitResult]
    energy: dict[str, JointEnergy]
    provenance: list[tuple[str, str]]
    threshold: float
    identification: dict | None = None

    @property
    def flagged(self) -> list[JointEnergy]:
        return [e for e in self.energy.values() if e.flagged]

    def html(self) -> str:
        return _render(self)


def make_report(friction: str | Path, params: str | Path | None = None,
                threshold: float = DEFAULT_THRESHOLD, tolerance: float = DEFAULT_TOLERANCE,
                identification: str | Path | None = None) -> Report:
    """Read a friction table (and parameters, else fit them; and an identification of the
    inertia model, :func:`load_identification`) and compute the report.

    Raises:
        InputError: unreadable inputs.
    """
    friction = Path(friction)
    ident = None if identification is None else load_identification(identification)
    est = estimate_from_table(read_table(friction), str(friction))
    if params is not None:
        fits = load_params(params)
    else:
        fits = {f.joint: f for f in fit_table_estimate(est)}
    energy = {e.joint: e for e in energy_consistency(est, fitted_offsets(fits.values()), threshold, tolerance)}
    meta = est.metadata
    prov: list[tuple[str, str]] = [("friction table", f"{friction} (sha256 {file_sha256(friction)})")]
    if params is not None:
        prov.append(("parameters", f"{params} (sha256 {file_sha256(params)})"))
    else:
        prov.append(("parameters", "fitted by the report (no --params given)"))
    source = dict(meta.get("provenance", {}))
    if source.get("log"):
        prov.append(("log", f"{source['log']} (sha256 {source.get('log_sha256', '?')})"))
    elif meta.get("source"):
        prov.append(("log", str(meta["source"])))
    prov.append(("robot", str(source.get("robot") or meta.get("robot", "?"))))
    if source.get("urdf"):
        prov.append(("URDF", str(source["urdf"])))
    if "estimate_options" in meta:
        prov.append(("estimate options", json.dumps(meta["estimate_options"], sort_keys=True)))
    if est.companion_diff:
        prov.append(("companion scheme (Fig. 7.4)", est.companion_diff))
    if source.get("wbfriction"):
        prov.append(("estimated with", f"wbfriction {source['wbfriction']}"))
    prov.append(("report", f"wbfriction {__version__}; energy threshold {100 * threshold:g} %, "
                               f"tolerance {tolerance:g} N·m"))
    if identification is not None:
        prov.append(("inertia identification", f"{identification} (sha256 {file_sha256(identification)})"))
    return Report(est, fits, energy, prov, threshold, ident)


def write_report(report: Report, output: str | Path) -> None:
    """Write the report's HTML, whole or not at all."""
    text = report.html()
    write_atomic(output, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


# --------------------------------------------------------------------- rendering
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
img { max-width: 100%; height: auto; display: block; }
nav { display: flex; flex-wrap: wrap; gap: 4px 12px; font-size: 0.85rem; }
dl { display: grid; grid-template-columns: max-content 1fr; gap: 2px 16px; font-size: 0.82rem; }
dt { color: #5a6570; } dd { margin: 0; word-break: break-all; font-family: ui-monospace, monospace; }
section.joint { margin-top: 18px; }
"""


def _img(fig, alt: str, id_: str, cls: str) -> str:
    data = base64.b64encode(png_bytes(fig)).decode("ascii")
    return f'<img id="{html.escape(id_)}" class="{cls}" alt="{html.escape(alt)}" src="data:image/png;base64,{data}">'


def _anchor(joint: str) -> str:
    return "joint-" + "".join(c if c.isalnum() else "-" for c in joint)


def _fmt(value: float, se: float | None = None) -> str:
    if value is None or not np.isfinite(value):
        return "—"
    if se is None:
        return f"{value:.4g}"
    return f"{value:.4g} ± {'n.i.' if not np.isfinite(se) else f'{se:.2g}'}"


def _params_table(joints: list[str], fits: dict[str, FitResult]) -> str:
    head = "".join(f"<th>{n}</th>" for n in PARAM_NAMES)
    rows = []
    for j in joints:
        fit = fits.get(j)
        if fit is None or fit.params is None:
            n = "—" if fit is None else str(fit.n_samples)
            rows.append(f"<tr><td>{html.escape(j)}</td><td>{n}</td>" + "<td>—</td>" * (len(PARAM_NAMES) + 1)
                        + "</tr>")
            continue
        cells = "".join(f"<td>{_fmt(getattr(fit.params, n), fit.stderr.get(n))}</td>" for n in PARAM_NAMES)
        rows.append(f"<tr><td>{html.escape(j)}</td><td>{fit.n_samples}</td>{cells}"
                    f"<td>{_fmt(fit.rms_residual)}</td></tr>")
        err = fit.error_percent()
        if err is not None:
            rows.append('<tr class="target"><td>&nbsp;&nbsp;target</td><td></td>'
                        + "".join(f"<td>{_fmt(getattr(fit.target, n))}</td>" for n in PARAM_NAMES) + "<td></td></tr>")
            rows.append('<tr class="err"><td>&nbsp;&nbsp;error [%]</td><td></td>'
                        + "".join(f"<td>{err[n]:.2f}</td>" for n in PARAM_NAMES) + "<td></td></tr>")
    return (f'<table id="parameters"><tr><th>joint</th><th>N</th>{head}<th>RMS residual [N·m]</th></tr>'
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


def _render(r: Report) -> str:
    est = r.est
    joints = list(est.joints)
    targets = {j: f.target for j, f in r.fits.items() if f.target is not None}
    flagged = r.flagged
    robot = dict(r.provenance).get("robot", "?")
    if flagged:
        items = "".join(f"<li>{html.escape(e.warning())}</li>" for e in flagged)
        summary = (f'<div class="box warn" id="energy-warning"><b>{len(flagged)} of {len(joints)} joints generate '
                   f"power</b> in more than {100 * r.threshold:g} % of their valid samples (eq. 7.9). Friction "
                   f"dissipates energy; estimates that generate it point at the inertia model (try "
                   f"<code>wbfriction sensitivity</code>), a torque-sensor offset or the filtering "
                   f"(thesis 7.2).<ul>{items}</ul></div>")
    else:
        worst = max(r.energy.values(), key=lambda e: e.generating_share if np.isfinite(e.generating_share) else -1)
        summary = (f'<div class="box ok" id="energy-ok">Every joint\'s friction dissipates energy: at most '
                   f"{100 * worst.generating_share:.2f} % of a joint's valid samples generate power "
                   f"({html.escape(worst.joint)}; threshold {100 * r.threshold:g} %).</div>")
    spectra = acceleration_spectra(est)
    overview = _img(friction_overview_figure(est, joints, r.fits, targets, {e.joint for e in flagged}),
                    "friction of every joint over velocity", "overview", "overview-figure")
    sections = []
    for j in joints:
        e = r.energy[j]
        fig = joint_figure(est, j, r.fits.get(j), targets.get(j), spectra.get(j))
        note = (f"{e.n_samples} valid samples; {100 * e.generating_share:.2f} % generate power"
                if np.isfinite(e.generating_share) else "no valid sample")
        sections.append(f'<section class="joint" id="{_anchor(j)}"><h3>{html.escape(j)}</h3>'
                        f'<p class="sub">{note}</p>{_img(fig, j, "fig-" + _anchor(j), "joint-figure")}</section>')
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
<p class="sub">Share of valid samples with qd·(τ_f + τ_os) &gt; 0 and |τ_f + τ_os| above the tolerance (the
identified offset τ_os is a sensor offset, not friction); zero crossings of the acceleration difference Δqdd against those of the velocity within valid stretches,
and the median time from each velocity crossing to the nearest Δqdd crossing.</p>
{_energy_table(joints, r.energy)}
{"" if r.identification is None else _identification_section(r.identification)}
<h2>Joints</h2>
<nav>{nav}</nav>
{''.join(sections)}
<h2>Provenance</h2>
<dl id="provenance">{prov}</dl>
</body></html>
"""
