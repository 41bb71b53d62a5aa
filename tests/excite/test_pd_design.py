"""Issue 66 on a hung Go2 (:mod:`wbfriction.excite.pd_design`): a designed 30 s excitation, played by the hung PD
simulator with a real driver's noise of another seed, identified as ``identify --actuator pd`` does, from no offset.

Measured when written (seeds 7 and 8): every one of the 48 parameters and the delay ``ok``; the standard errors
reported within 1.5x of those predicted on 47 and 48 of 48 (median ratio 0.95 and 0.97). Within two standard errors
of the truth: 36 and 34 of 48. The rest are off by the simulator's discretisation (1 ms physics steps), not by noise.
The standard errors there are 0.1-0.5 %, while F_v is 0.5-1 % high on the hips and thighs, and the delay is 0.58 ms
short against a standard error of 0.01 ms. On 0.25 ms steps the delay is 0.15 ms short and F_v is within two
standard errors (:mod:`tests.actuator.test_hung_truth` has the same bias with its own set-points). So "within two
standard errors of the truth" holds on the share above only. Every parameter is within that bias, which this test
holds.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import wbfriction
from wbfriction.actuator import identify_actuators
from wbfriction.excite.options import PdExciteOptions
from wbfriction.excite.pd_design import design_pd, play_options
from wbfriction.logs.log import log_from_table
from wbfriction.sim.hung import simulate_hung
from wbfriction.sim.pd_options import REAL_DRIVER

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("excite_pd_design")]  # one module fixture, one worker
DISCRETISATION = {"armature": 0.02, "F_v": 0.015, "F_c": 0.015}
"""The relative error the simulator's 1 ms physics steps leave (module docstring; measured up to 0.9 %)."""
OFFSET_ERROR = {"hip": 0.006, "thigh": 0.006, "calf": 0.025}
"""The offsets' error [rad] the simulator leaves with any motion (:mod:`tests.actuator.test_hung_truth`)."""


@pytest.fixture(scope="module")
def played():
    robot = wbfriction.load_robot("go2")
    # the search's choice (the how-to's run searches the whole default grid: tests/test_readme.py), predicted once
    design = design_pd(robot, PdExciteOptions(duration=30.0, amplitudes=(0.95,), reversals=((0.2, 1.5),)))
    sim = simulate_hung(robot, play_options(design, replace(REAL_DRIVER, seed=7)),
                        reference=(design.q_des - robot.offset_vector, design.qd_des))
    blind = replace(robot, encoder_offset={})  # the TOML's offsets are the truth, not the identification's guess
    return robot, design, sim, identify_actuators(blind, log_from_table(sim.table, blind, "played.parquet"))


def test_the_design_stays_within_the_limits(played):
    robot, design, sim, _ = played
    lower, upper = robot.angle_limits
    q = design.q_des - robot.offset_vector
    assert np.all(q >= lower) and np.all(q <= upper)
    assert np.all(np.abs(sim.trajectory.qd) < robot.model.velocityLimit[robot.act_v_index])
    assert design.margins.least() > 0 and design.margins.torque.min() >= 1 - design.options.torque_share
    assert design.chosen.within and design.worst()[2] < 1.0


def test_every_parameter_is_ok_and_its_standard_error_as_predicted(played):
    _, design, _, result = played
    assert result.delay.status == "ok"
    assert all(p.status == "ok" for j in result.joints for p in j.parameters().values())
    ratios = np.array([p.se / design.prediction.joints[j.joint][name].se
                       for j in result.joints for name, p in j.parameters().items()])
    assert len(ratios) == 48
    # both standard errors carry a ten-block jackknife (actuator.solve.block_grown), each estimated to about 24 %
    # (1 / sqrt(2 x 9)): their ratio to about 35 %, so within a factor 2 nine times in ten
    assert np.mean((ratios > 1 / 2) & (ratios < 2)) >= 0.9, np.sort(ratios)
    assert 0.8 < np.median(ratios) < 1.25
    assert 1 / 1.5 < result.delay.se / design.prediction.delay.se < 1.5


def test_the_truth_within_two_standard_errors_or_the_simulators_discretisation(played):
    _, _, sim, result = played
    within = []
    for i, j in enumerate(result.joints):
        friction = sim.friction[j.joint]
        truth = {"armature": sim.armature[i], "F_v": friction.F_v, "F_c": friction.F_c,
                 "offset": sim.encoder_offset[i]}
        for name, p in j.parameters().items():
            error = abs(p.value - truth[name])
            within.append(error <= 2 * p.se)
            tolerance = OFFSET_ERROR[j.joint.split("_")[1]] if name == "offset" else DISCRETISATION[name] * truth[name]
            assert error <= max(2 * p.se, tolerance), (j.joint, name, p.value, truth[name], p.se)
    assert np.mean(within) >= 2 / 3  # module docstring: 36 of 48
    assert abs(result.delay.value - sim.driver.delay) < sim.physics_step
