"""Each leg joint of a study is scored against its own target, the friction that was injected on it.

The studies' simulators and estimator are replaced by an exact estimate: every torque-controlled joint
moves at its own velocity profile and its estimated friction is (3.5) of the parameters the study asked
the simulator to inject on it (none on the others). Every leg joint's fit then recovers its own
parameters, so each scored error must be ~0 and each row's target must be that joint's injected friction;
a joint scored against another joint's target (e.g. every leg joint against the knee's: F_c 1.0 against
0.8 or 0.1) shows errors of 25 % and more.
"""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np
import pytest

from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.friction.estimate import FrictionEstimate
from wbfriction.friction.models import FrictionParams
from wbfriction.studies import filters, realistic, simulation
from wbfriction.studies.common import leg_joints
from wbfriction.studies.thesis import TABLE_6_1, TABLE_6_2

N = 3000
DT = 1e-3


def exact_estimate(robot, friction: dict[str, FrictionParams]) -> FrictionEstimate:
    """An estimate whose friction is exactly (3.5) of ``friction`` at each joint's own velocity, written
    out: ``tau_f = -(F_v qd + F_c (1 + S exp(-(qd / v_s)^2)) tanh(a qd) + tau_os)``."""
    t = np.arange(N) * DT
    joints = robot.torque_controlled
    i = np.arange(len(joints))
    qd = (0.6 + 0.05 * i) * np.sin(2 * np.pi * (0.5 + 0.07 * i) * t[:, None] + 0.3 * i)
    tau_f = np.zeros_like(qd)
    for j, p in friction.items():
        v = qd[:, joints.index(j)]
        tau_f[:, joints.index(j)] = -(p.F_v * v + p.F_c * (1 + p.S * np.exp(-(v / p.v_s) ** 2)) * np.tanh(p.a * v)
                                      + p.tau_os)
    contact = np.zeros((N, 2), dtype=bool)
    contact[:, 0] = (t % 1.0) < 0.5
    contact[:, 1] = ~contact[:, 0]
    return FrictionEstimate(joints=joints, time=t, qd=qd, tau_f=tau_f, valid=np.ones_like(qd, dtype=bool),
                            phase=np.full(N, "single"), unique=np.ones(N, dtype=bool), contact=contact,
                            contact_frames=robot.contact_frames, tau_f_true=tau_f.copy())


def _own_targets(robot) -> dict[str, FrictionParams]:
    return {j: THESIS_TARGETS[g] for j, _, g in leg_joints(robot)}


def _no_file(*args, **kwargs) -> None:
    """A figure or log writer that writes nothing (the test is about the scores)."""


class _FrictionLog(dict):
    """The friction injected, standing in for the simulated log (no sensors logged)."""

    wrench = None


def test_realistic_study_scores_each_leg_joint_against_its_own_friction(talos, tmp_path, monkeypatch):
    # the simulator hands the friction it was asked to inject to the estimator, which returns it exactly
    monkeypatch.setattr(realistic, "build_mujoco_robot", lambda robot: None)
    monkeypatch.setattr(realistic, "_simulate", lambda robot, mjr, gait, friction, options:
                        SimpleNamespace(log=_FrictionLog(friction)))
    monkeypatch.setattr(realistic, "estimate_log", lambda robot, friction, options: exact_estimate(robot, friction))
    for name in ("write_log", "velocity_panels_figure", "friction_curves_figure"):
        monkeypatch.setattr(realistic, name, _no_file)
    result = realistic.run_realistic_study(talos, tmp_path, steps=1, knee_steps=1)
    own = _own_targets(talos)
    assert [c.name for c in result.cases] == ["model", "mujoco", "noisy"]
    for case in result.cases:
        assert len(case.rows) == 12
        for row in case.rows:
            injected = own[row.joint]
            if case.name == "mujoco":  # MuJoCo's own friction: no Stribeck term, no offset
                injected = dataclasses.replace(injected, S=0.0, tau_os=0.0)
            assert row.fit.target == injected, (case.name, row.joint)
            errors = row.fit.error_percent()
            assert max(errors[n] for n in case.scored) < 0.5, (case.name, row.joint, errors)
        assert max(realistic.worst_scored(case).values()) < 0.5
    assert result.knee_rms["swing only"] == 0.0


def test_demo_scores_each_leg_joint_against_its_own_friction(talos, tmp_path, monkeypatch):
    """``wbfriction demo``'s identification table (Tables 6.1, 6.2)."""
    monkeypatch.setattr(simulation, "_simulate", lambda robot, gait, friction, label="", steps=None:
                        SimpleNamespace(log=friction, pulls=lambda: []))
    monkeypatch.setattr(simulation, "estimate_log", lambda robot, friction, options, companion=False:
                        exact_estimate(robot, friction))
    for name in ("write_log", "write_table", "write_report", "make_report", "support_phases_figure",
                 "derivative_schemes_figure", "friction_curves_figure"):
        monkeypatch.setattr(simulation, name, _no_file)
    result = simulation.run_study(talos, tmp_path, steps=1, knee_steps=1)
    own = _own_targets(talos)
    assert len(result.rows) == 12
    for row in result.rows:
        assert row.fit.target == own[row.joint], row.joint
        # beside it, the thesis's errors for that same joint (its side and group)
        assert row.group == talos.group_of(row.joint) and row.side in row.joint
        assert (row.thesis_6_1, row.thesis_6_2) == (TABLE_6_1[(row.side, row.group)], TABLE_6_2[(row.side, row.group)])
        errors = row.fit.error_percent()
        assert max(errors[n] for n in ("F_v", "F_c", "tau_os")) < 0.5, (row.joint, errors)
    assert result.truth_max_error == 0.0


def test_filter_study_scores_each_leg_joint_against_its_own_friction(talos, tmp_path, monkeypatch):
    monkeypatch.setattr(filters, "walking_reference", lambda robot, gait: None)
    monkeypatch.setattr(filters, "simulate_ideal", lambda robot, ref, friction, options:
                        SimpleNamespace(log=friction))
    monkeypatch.setattr(filters, "estimate_log", lambda robot, friction, options: exact_estimate(robot, friction))
    monkeypatch.setattr(filters, "filter_curves_figure", _no_file)
    scheme = filters.Scheme("central", "central")
    result = filters.run_filter_study(talos, tmp_path, steps=1, levels=(None,), schemes=(scheme,), workers=1)
    (row,) = result.rows
    assert row.rms_error == 0.0
    assert row.score < 0.5, row.worst  # the worst of F_v, F_c and tau_os over the 12 leg joints


@pytest.mark.parametrize("group", ["hip_pitch", "ankle_roll", "ankle_pitch"])
def test_the_knee_target_is_not_another_groups(group):
    """The premise: scored against the knee's target, these groups' exact fits would be far off."""
    own, knee = THESIS_TARGETS[group], THESIS_TARGETS["knee"]
    assert abs(own.F_c - knee.F_c) / knee.F_c > 0.19
