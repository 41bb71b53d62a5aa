"""The HTML report: its content from a simulated walk, its figures as drawn, and how it renders in a real browser
(headless Chromium, Debian's ``chromium`` and ``chromium-driver``, which ``.ci/run`` installs; :mod:`report_checks`).
The real arm's report: ``test_report_kuka.py``."""

from __future__ import annotations

import base64
import re

import numpy as np
import pytest

from report_checks import (
    CHROMIUM_MISSING,
    check_figures,
    check_fits_drawn_in_their_samples,
    check_page,
    render_in_chromium,
)
from wbfriction.exceptions import InputError
from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.params_file import fit_to_dict, read_params
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.io import friction_table
from wbfriction.friction.options import EstimateOptions
from wbfriction.inertia.sensitivity import inertia_sensitivity
from wbfriction.logs.tables import write_table
from wbfriction.report.build import acceleration_spectra, make_report
from wbfriction.report.html import render_html, write_report

pytestmark = [pytest.mark.slow,  # module fixtures of 30-55 s (the quick subset: -m "not slow")
              pytest.mark.xdist_group("report_walk")]  # computed once


@pytest.fixture(scope="module")
def tables(talos, combined_walk, tmp_path_factory):
    """The walk's friction table with the true model, and with every body's rotational inertia x 1.1."""
    out = tmp_path_factory.mktemp("report")
    est = estimate_log(talos, combined_walk.log, EstimateOptions(), companion=True)
    true_model = out / "friction.parquet"
    write_table(friction_table(est), true_model)
    scaled = inertia_sensitivity(talos, combined_walk.log, [1.1], "rotational",
                                 EstimateOptions(diff="central", route="acceleration")).estimates[1]
    scaled.metadata = est.metadata
    rotational = out / "friction_rot11.parquet"
    write_table(friction_table(scaled), rotational)
    return out, true_model, rotational


@pytest.fixture(scope="module")
def true_report(tables):
    return make_report(tables[1])


@pytest.fixture(scope="module")
def report_file(tables, true_report):
    path = tables[0] / "report.html"
    write_report(true_report, path)
    return path


def _images(text: str) -> dict[str, bytes]:
    return {m.group(1): base64.b64decode(m.group(2))
            for m in re.finditer(r'<img id="([^"]+)"[^>]*src="data:image/png;base64,([^"]+)"', text)}


def _walking_and_still(talos) -> tuple[list[str], list[str]]:
    """Joints that move in the walk (the legs but the hip yaws, which turn only in part of it) and joints the
    walking controller holds still (arms, grippers)."""
    legs = [j for j in talos.torque_controlled if j.startswith("leg_") and not j.endswith("_1_joint")]
    held = [j for j in talos.torque_controlled if j.startswith(("arm_", "gripper_"))]
    return legs, held


def test_report_is_self_contained_and_complete(talos, report_file):
    """Every joint that walks has its figure, every joint held still none (they are named in one line); labels
    from the robot TOML; nothing fetched from elsewhere."""
    text = report_file.read_text()
    images = _images(text)
    walking, held = _walking_and_still(talos)
    for joint in walking:
        assert images[f"fig-joint-{joint.replace('_', '-')}"].startswith(b"\x89PNG")
    assert not any(f"fig-joint-{joint.replace('_', '-')}" in images for joint in held)
    assert "overview" in images
    still = re.search(r'<tr class="still">(.*?)</tr>', text, re.S)
    assert still and all(talos.label(j) in still.group(1) for j in held)
    assert "right knee" in text and "left ankle roll" in text
    # nothing fetched from elsewhere: no external source, stylesheet or script
    assert not re.search(r'(src|href)="(?!data:|#)', text)
    assert "<script" not in text
    assert 'id="energy-ok"' in text and 'id="energy-warning"' not in text
    assert "sha256" in text and "estimate options" in text


def test_report_warns_when_rotational_inertia_is_off(tables, true_report):
    """With every principal moment of inertia 10 % too large the share of power-generating samples
    rises (on this walk a hip yaw, the joint with the smallest friction torques in swing, passes
    5 %), and the report says so."""
    before, after = true_report, make_report(tables[2])
    legs = [j for j in before.energy if j.startswith("leg_")]
    assert max(before.energy[j].generating_share for j in legs) < 0.01
    assert sum(after.energy[j].generating_share for j in legs) > 3 * sum(before.energy[j].generating_share
                                                                          for j in legs)
    flagged = {e.joint for e in after.flagged}
    assert flagged & {"leg_left_1_joint", "leg_right_1_joint"}  # a hip yaw
    text = render_html(after)
    assert 'id="energy-warning"' in text
    for joint in flagged:
        assert f"{joint}: " in text


def test_same_input_same_bytes(tables, report_file, tmp_path):
    """Built again from the same table, its joints fitted and its figures rendered on two processes instead of
    one: the same bytes."""
    _, true_model, _ = tables
    again = tmp_path / "again.html"
    write_report(make_report(true_model, workers=2), again, workers=2)
    assert again.read_bytes() == report_file.read_bytes()


def test_params_file_round_trip_and_errors(tables, tmp_path):
    """Parameters written by 'wbfriction fit' read back as they were fitted."""
    import json

    from wbfriction.friction.io import read_friction_table
    from wbfriction.logs.tables import read_table

    _, true_model, _ = tables
    fits = fit_estimate(read_friction_table(read_table(true_model)))
    path = tmp_path / "params.json"
    path.write_text(json.dumps({"joints": {f.joint: fit_to_dict(f) for f in fits}}))
    back = read_params(path)
    for f in fits:
        if f.params is not None:
            assert back[f.joint].params == f.params
            for name, se in f.stderr.items():
                assert back[f.joint].stderr[name] == pytest.approx(se) or not np.isfinite(se)
    bad = tmp_path / "bad.json"
    bad.write_text('{"joints": {"knee": {"params": {"F_x": 1}}}}')
    with pytest.raises(InputError, match="bad.json: joint 'knee'"):
        read_params(bad)
    bad.write_text("[1, 2]")
    with pytest.raises(InputError, match="no 'joints'"):
        read_params(bad)


def test_spectrum_is_that_of_the_estimated_acceleration(talos, combined_walk, tables):
    """qdd - delta_qdd is qdd_est of (5.10): the report's spectrum equals the spectrum command's
    (the constrained dynamics of the log) where both look at the same stretch."""
    from wbfriction.friction.io import read_friction_table
    from wbfriction.logs.tables import read_table
    from wbfriction.signals.spectrum import acceleration_spectrum

    _, true_model, _ = tables
    est = read_friction_table(read_table(true_model))
    dyn_spec = acceleration_spectrum(talos, combined_walk.log, ["leg_left_4_joint"])
    ours = acceleration_spectra(est)["leg_left_4_joint"]
    # both take the longest stretch with a foot on the ground and defined derivatives
    assert len(ours[0]) == len(dyn_spec.freq)
    np.testing.assert_allclose(ours[1], dyn_spec.amplitude[:, 0], rtol=1e-6, atol=1e-9)


def test_walk_report_figures_read_right(talos, true_report):
    """Issue 67, the simulated walk: every ``ok`` fit drawn inside its samples, no overlapping text in any figure
    (matplotlib's own text boxes), time in seconds from the walk's start."""
    assert len(check_fits_drawn_in_their_samples(true_report)) >= 8
    check_figures(true_report)


@CHROMIUM_MISSING
def test_report_renders_in_headless_chromium(talos, report_file, tmp_path):
    """At 1400 px in headless Chromium (:func:`check_page`): the simulated walk's page; a joint that moved has its
    figure, one that did not has none."""
    images = check_page(render_in_chromium(report_file, tmp_path), 500)
    walking, held = _walking_and_still(talos)
    assert all(f"fig-joint-{j.replace('_', '-')}" in images for j in walking)
    assert not any(f"fig-joint-{j.replace('_', '-')}" in images for j in held)
    assert "overview" in images
