"""The report of the real-arm tutorial (docs/tutorials/real-arm.md): the KUKA LWR4+'s runs 1 and 2, two recordings
29 min apart stamped in Unix epoch seconds, estimated with the given URDF and fitted as the tutorial does (issue 67).
Its figures as drawn and its page in headless Chromium (:mod:`report_checks`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from helpers import KUKA_CONFIG, KUKA_URDF, kuka_table, needs_kuka
from report_checks import (
    CHROMIUM_MISSING,
    check_figures,
    check_fits_drawn_in_their_samples,
    check_page,
    off_samples,
    render_in_chromium,
)
from wbfriction.fit.predict import predicted_friction
from wbfriction.pipeline.estimate_step import RobotSpec, estimate_file
from wbfriction.pipeline.fit_step import fit_file
from wbfriction.report.build import Report, make_report
from wbfriction.report.friction_figures import drawn_fit
from wbfriction.report.html import report_figure, write_report
from wbfriction.report.timeaxis import log_runs

pytestmark = [needs_kuka, pytest.mark.slow, pytest.mark.xdist_group("report_kuka")]  # its fixture: 40-60 s


@pytest.fixture(scope="module")
def kuka_report(tmp_path_factory) -> tuple[Report, Path]:
    """The real-arm tutorial's report (docs/tutorials/real-arm.md): the KUKA's runs 1 and 2 (two recordings 29 min
    apart, stamped in Unix epoch seconds) estimated with the given URDF, fitted, reported. About 40 s."""
    out = tmp_path_factory.mktemp("kuka_report")
    log, table, params = out / "runs12.parquet", out / "kuka_friction.parquet", out / "kuka_params.json"
    pq.write_table(kuka_table(1, 2), log)
    estimate_file(RobotSpec(None, str(KUKA_URDF), str(KUKA_CONFIG)), log, table)
    fit_file(table, params)
    report = make_report(table, params)
    write_report(report, out / "kuka_report.html")
    return report, out / "kuka_report.html"


def test_kuka_report_figures_read_right(kuka_report):
    """Issue 67, the real-arm tutorial's report: two runs 29 min apart, stamped in epoch seconds, each its own
    panel from 0 s; each joint's legend names its fit's family and terms (lwr_6: thesis + ripple); every ``ok``
    fit drawn inside its samples; no overlapping text. The check has teeth: lwr_6's velocity curve alone, without
    the ripple its fit kept, lies about 2 N·m above its samples (what the report drew before)."""
    report, _ = kuka_report
    est = report.est
    assert [r.rows.stop - r.rows.start for r in log_runs(est.time)] == [5027, 5027]
    assert check_fits_drawn_in_their_samples(report)  # lwr_5 at least
    i, fit = est.joints.index("lwr_6_joint"), report.fits["lwr_6_joint"]
    assert fit.kept_terms is not None and "ripple" in fit.kept_terms.kept
    assert not off_samples(est, i, drawn_fit(est, i, fit))
    m = est.valid[:, i]
    velocity_only = ("curve", est.qd[m, i], fit.params.torque(est.qd[m, i]))
    assert off_samples(est, i, velocity_only)
    # the tutorial's numbers: about 2 N·m above its samples; the ripple's arc 2.5 rad, under half its first
    # harmonic's period, its mean there about -2 N·m, which the offset balances
    assert 1.5 < np.median(velocity_only[2] - est.tau_f[m, i]) < 2.5
    low, high = fit.kept_terms.q_range
    assert 2.4 < high - low < 2.6 < np.pi
    ripple = predicted_friction(est, i, fit.kept_terms, m)[m] - velocity_only[2]
    assert -2.5 < ripple.mean() < -1.5
    overview = report_figure(report, None)
    legends = {ax.get_title(): [t.get_text() for t in ax.get_legend().get_texts()] for ax in overview.axes
               if ax.get_visible() and ax.get_legend() is not None}
    for joint in report.moved:
        f = report.fits[joint]
        terms = "" if f.kept_terms is None else " + " + " + ".join(f.kept_terms.kept)
        assert " ".join(legends[report.label(joint)]).replace("\n", " ") == f"fit: {f.model}{terms}", joint
    check_figures(report)


@CHROMIUM_MISSING
def test_kuka_report_renders_in_headless_chromium(kuka_report, tmp_path):
    """Issue 67: the real-arm tutorial's page at 1400 px in headless Chromium (:func:`check_page`): its seven
    joints' figures and the overview; the page says the log's two runs."""
    report, path = kuka_report
    images = check_page(render_in_chromium(path, tmp_path), 200)
    assert {"overview", *(f"fig-joint-lwr-{k}-joint" for k in range(7))} <= set(images)
    assert "in 2 runs over" in path.read_text()
