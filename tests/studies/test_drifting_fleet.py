"""The simulated fleet's ground truth (issue 25): the drifts' schedule and the scoring of flags."""

from __future__ import annotations

import pytest

from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.studies.drifting_fleet import Drift, FleetPlan, friction_of, score_flags


def test_a_drift_ramps_from_its_onset_to_its_full_change():
    d = Drift("robot-1", "leg_right_4_joint", "F_c", 0.30, 10)
    assert d.onset(25) == 15
    assert [d.factor(i, 25) for i in (0, 14)] == [1.0, 1.0]
    assert d.factor(15, 25) == pytest.approx(1.03) and d.factor(24, 25) == pytest.approx(1.30)


def test_only_the_drifted_joint_of_the_drifted_robot_changes(talos):
    plan = FleetPlan()
    knee, ankle = THESIS_TARGETS["knee"], THESIS_TARGETS["ankle_pitch"]
    last = friction_of(talos, plan, "robot-1", 24)
    assert last["leg_right_4_joint"].F_c == pytest.approx(1.3 * knee.F_c)
    assert last["leg_right_4_joint"].F_v == knee.F_v and last["leg_left_4_joint"] == knee
    assert friction_of(talos, plan, "robot-2", 24)["leg_left_5_joint"].F_v == pytest.approx(1.5 * ankle.F_v)
    assert friction_of(talos, plan, "robot-0", 24) == friction_of(talos, plan, "robot-0", 0)
    assert friction_of(talos, plan, "robot-1", 14) == friction_of(talos, plan, "robot-0", 0)


def test_flags_are_scored_against_the_drifts():
    plan = FleetPlan()
    score = score_flags({("robot-1", "leg_right_4_joint"): 16, ("robot-3", "leg_left_2_joint"): 20}, plan, 120)
    assert score.found == {("robot-1", "leg_right_4_joint"): 1}
    assert score.missed == [("robot-2", "leg_left_5_joint")]
    assert score.false_alarms == [("robot-3", "leg_left_2_joint")] and not score.exact
