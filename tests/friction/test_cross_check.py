"""The measured route against the rigid-contact one: the disagreement's summary and its likely cause."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.friction.cross_check import MIN_SAMPLES, cross_check, likely_cause
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions
from wbfriction.sim import IdealOptions, MujocoOptions, simulate_ideal, simulate_mujoco
from wbfriction.walking import GaitOptions, walking_reference


@settings(max_examples=50, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), size=st.floats(0.1, 10.0))
def test_each_kind_of_disagreement_is_named(seed, size):
    rng = np.random.default_rng(seed)
    qdd = rng.normal(size=500) * 5
    assert likely_cause(size + 0.1 * size * rng.normal(size=500), qdd).startswith("an offset")
    assert likely_cause(size * qdd / 5 + 0.1 * size * rng.normal(size=500), qdd).startswith("a wrong inertia")
    assert likely_cause(size * rng.normal(size=500), qdd).startswith("neither a constant nor following")


def test_exact_routes_agree_and_no_cause_is_given(talos):
    """Ideal simulator, true derivatives: both routes are exact, their disagreement is round-off."""
    ref = walking_reference(talos, GaitOptions(gait="forward", steps=2))
    log = simulate_ideal(talos, ref, None, IdealOptions(force_torque=True)).log
    est = estimate_log(talos, log, EstimateOptions(diff="true", base_motion="logged"))
    assert est.disagreement is not None
    checks = cross_check(est.joints, est.disagreement, est.tau_f, est.qdd)
    legs = [c for c in checks if "leg" in c.joint]
    assert all(c.samples >= MIN_SAMPLES for c in legs)
    assert max(c.rms for c in legs) < 1e-9 and not any(c.cause for c in legs)


@pytest.mark.parametrize(("options", "cause", "at_least"), [
    (MujocoOptions(sole_timeconst=0.08), "neither a constant nor following the acceleration: a stance foot", 9),
    (MujocoOptions(ft_offset=(20.0, 2.0)), "an offset", 6),
])
def test_mujoco_imperfections_are_named(talos, options, cause, at_least):
    """A compliant sole makes the rigid route's stance foot move: a disagreement neither constant nor following the
    acceleration, the foot named first among its possible causes, not blamed alone; a force-torque offset shifts the
    sensors' route by a constant (measured: 10 and 8 of the 12 leg joints)."""
    from wbfriction.fit.targets import THESIS_TARGETS
    from wbfriction.studies.common import leg_joints
    friction = {j: THESIS_TARGETS[g] for j, _, g in leg_joints(talos)}
    ref = walking_reference(talos, GaitOptions(gait="forward", steps=2))
    log = simulate_mujoco(talos, ref, friction, options).log
    est = estimate_log(talos, log, EstimateOptions(diff="central", base_motion="logged"))
    legs = {j for j, _, _ in leg_joints(talos)}
    checks = [c for c in cross_check(est.joints, est.disagreement, est.tau_f, est.qdd) if c.joint in legs]
    assert sum(c.cause.startswith(cause) for c in checks) >= at_least


@pytest.mark.slow
def test_the_report_shows_the_routes_cross_checked(talos, tmp_path):
    from wbfriction.friction.io import friction_table
    from wbfriction.logs.tables import write_table
    from wbfriction.report.build import make_report
    from wbfriction.report.html import render_html

    ref = walking_reference(talos, GaitOptions(gait="forward", steps=1))
    log = simulate_mujoco(talos, ref, None, MujocoOptions(ft_offset=(20.0, 2.0))).log
    est = estimate_log(talos, log, EstimateOptions(diff="central", base_motion="logged"))
    write_table(friction_table(est), tmp_path / "f.parquet")
    page = render_html(make_report(tmp_path / "f.parquet"))
    assert 'id="routes"' in page and "an offset" in page


def test_the_file_and_the_command_give_the_same_check(talos, tmp_path):
    """The table file's cross-check (three columns per joint) equals the in-memory one; ``estimate`` prints the
    joints whose routes disagree, one line per likely cause (a 20 N / 2 N·m force-torque offset: "an offset")."""
    from helpers import run
    from wbfriction.friction.cross_check import cross_check_file
    from wbfriction.friction.io import friction_table
    from wbfriction.logs.log import write_log
    from wbfriction.logs.tables import write_table

    ref = walking_reference(talos, GaitOptions(gait="forward", steps=1))
    log = simulate_mujoco(talos, ref, None, MujocoOptions(ft_offset=(20.0, 2.0))).log
    est = estimate_log(talos, log, EstimateOptions(diff="central", base_motion="logged"))
    write_table(friction_table(est), tmp_path / "f.parquet")
    assert cross_check_file(tmp_path / "f.parquet") == cross_check(est.joints, est.disagreement, est.tau_f, est.qdd)
    write_log(log, talos, tmp_path / "log.parquet")
    res = run("estimate", tmp_path / "log.parquet", "-o", tmp_path / "cli.parquet", "--base-motion", "logged")
    assert res.returncode == 0, res.stderr
    assert "routes cross-checked on" in res.stderr and "likely an offset" in res.stderr
    causes = [line for line in res.stderr.splitlines() if line.startswith("  likely ")]
    assert len(causes) == len(set(causes)) and len(causes) <= 3, res.stderr  # one line per cause, not per joint
