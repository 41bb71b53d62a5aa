"""The prediction of what a PD-driven robot's identification reports (:mod:`wbfriction.excite.predict`), against
what it reports on the motion recorded with another noise: a hung Go2, 20 s of ramps then chirps, a real driver's
noise."""

from __future__ import annotations

import dataclasses

import numpy as np

from wbfriction.actuator.identification import identify_actuators
from wbfriction.excite.predict import predict_pd
from wbfriction.logs.log import log_from_table
from wbfriction.model.loading import load_robot
from wbfriction.sim.hung import simulate_hung
from wbfriction.sim.pd_options import REAL_DRIVER, HungOptions, SetpointOptions


def test_the_standard_errors_reported_are_those_predicted_within_a_factor_1_5():
    robot = load_robot("go2")
    options = HungOptions(duration=20.0, setpoints=SetpointOptions(kind="both", amplitude=0.5), noise=REAL_DRIVER)
    predicted = predict_pd(robot, options)
    recorded = simulate_hung(robot, dataclasses.replace(options, noise=dataclasses.replace(REAL_DRIVER, seed=7)))
    reported = identify_actuators(robot, log_from_table(recorded.table, robot, "recorded"))
    ratios = np.array([p.parameters()[name].se / predicted.joints[p.joint][name].se
                       for p in reported.joints for name in predicted.joints[p.joint]])
    assert len(ratios) == 48
    assert np.mean((ratios > 1 / 1.5) & (ratios < 1.5)) >= 0.9, np.sort(ratios)
    assert 0.8 < np.median(ratios) < 1.25
    assert predicted.delay.se > 0 and 0.5 < reported.delay.se / predicted.delay.se < 2.0
