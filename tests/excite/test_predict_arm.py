"""The prediction of what a fixed-base arm's identification reports (:mod:`wbfriction.excite.predict_arm`), against
what ``estimate`` and ``fit`` report on the motion recorded with another noise: a Panda, 10 s, a real arm's sensors,
on the motion ``excite`` designs and on a random Fourier excitation within the same limits (the how-to's run,
:mod:`tests.test_readme`, holds the issue's 30 s).

Cost: the design about 11 s (one start per joint), six identifications (the fit most of each): at 20 s the fixture
took 216 s of a loaded 2-core machine, at 10 s (one period: the same truths hold) about half; computed once per
worker."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from wbfriction.excite.design import ExciteOptions, design_excitation
from wbfriction.excite.predict import Predicted
from wbfriction.excite.predict_arm import REAL_ARM, ArmPrediction, identify_arm, predict_arm, sensor_noise
from wbfriction.fit.result import FitResult
from wbfriction.model.loading import load_robot
from wbfriction.sim.arm import ExcitationOptions, default_arm_friction, excitation_trajectory

pytestmark = pytest.mark.xdist_group("excite_arm")  # one module fixture, one worker

DURATION = 10.0
"""The recordings' duration [s]: one of the design's periods (the how-to's run holds the issue's 30 s)."""
STATISTICAL = ("F_c", "F_v", "tau_os")
"""The parameters whose statistical standard error one noisy simulation predicts (module docstring of
:mod:`~wbfriction.excite.predict_arm`)."""


@pytest.fixture(scope="module")
def runs() -> dict[str, tuple[ArmPrediction, list[FitResult]]]:
    """Per motion (``designed``, ``random``): the prediction (noise seed 0) and the fits of the motion recorded with
    noise seed 7."""
    robot = load_robot("panda")
    prior = default_arm_friction(robot)
    options = ExciteOptions(duration=DURATION, starts=1)
    designed = design_excitation(robot, prior, sensor_noise(robot), options).trajectory
    lower, upper = robot.angle_limits
    random = excitation_trajectory(lower, upper, robot.model.velocityLimit[robot.act_v_index],
                                   ExcitationOptions(period=options.period, range_share=options.range_share,
                                                     velocity_share=options.velocity_share, seed=1))
    recorded = dataclasses.replace(REAL_ARM, duration=DURATION, seed=7)
    predicted = dataclasses.replace(REAL_ARM, duration=DURATION)
    return {name: (predict_arm(robot, prior, trajectory, predicted),
                   identify_arm(robot, prior, trajectory, recorded)[1])
            for name, trajectory in (("designed", designed), ("random", random))}


def ratios(prediction: ArmPrediction, fits: list[FitResult], statistical: bool) -> np.ndarray:
    """Reported over predicted standard error of each parameter both fits have."""
    out = []
    for fit in fits:
        reported = fit.stderr if statistical else fit.read_stderr()
        for name, p in prediction.joints[fit.joint].items():
            if name in reported and (name in STATISTICAL or not statistical):
                out.append(reported[name] / (prediction.statistical[fit.joint][name] if statistical else p.se))
    return np.array(out)


@pytest.mark.slow
def test_the_statistical_standard_errors_are_those_predicted_within_a_factor_1_5(runs):
    """F_c's, F_v's and tau_os's standard errors (without the family spread) reported on another noise's recording,
    on either motion."""
    for motion, (prediction, fits) in runs.items():
        r = ratios(prediction, fits, statistical=True)
        assert len(r) == 21
        assert np.mean((r > 1 / 1.5) & (r < 1.5)) >= 0.9, (motion, np.sort(r))
        assert 0.8 < np.median(r) < 1.25, (motion, np.sort(r))


@pytest.mark.xfail(strict=True, reason="the standard error a user reads holds the family spread and the Stribeck and "
                   "transition parameters' (S, v_s, a), which the noise sets anew in each recording: measured on "
                   "30 s: 72 % (designed) and 56 % (random) of the parameters within 1.5x, medians 1.07 and 0.98, "
                   "ratios 0.2-3.7")
@pytest.mark.slow
def test_every_read_standard_error_is_that_predicted_within_a_factor_1_5(runs):
    for motion, (prediction, fits) in runs.items():
        r = ratios(prediction, fits, statistical=False)
        assert np.mean((r > 1 / 1.5) & (r < 1.5)) >= 0.9, (motion, np.sort(r))
        assert 0.8 < np.median(r) < 1.25, (motion, np.sort(r))


@pytest.mark.slow
def test_the_designed_motion_determines_every_parameter_asked(runs):
    """On the designed motion every joint is predicted ``ok`` with F_c and F_v well inside the ``weak`` limit, and
    the recording is ``ok`` with F_c and F_v within 2 reported standard errors of the friction injected."""
    prediction, fits = runs["designed"]
    truth = default_arm_friction(load_robot("panda"))
    assert {p.status for params in prediction.joints.values() for p in params.values()} == {"ok"}
    assert prediction.worst(0.25)[2] < 1.0
    for fit in fits:
        assert fit.verdict().status == "ok", (fit.joint, fit.verdict())
        read = fit.read_stderr()
        for name in ("F_c", "F_v"):
            error = abs(getattr(fit.params, name) - getattr(truth[fit.joint], name))
            assert error < 2 * read[name], (fit.joint, name, error, read[name])


def test_the_worst_share_is_the_largest_of_the_magnitudes_read():
    """``worst``: the largest predicted standard error over ``weak`` times its value among F_c and F_v (an offset,
    however loose, is not one of them unless asked for); a magnitude at zero is infinitely weak."""
    def p(value: float, se: float) -> Predicted:
        return Predicted(value, 0.0, 0.0, se, "ok", "")

    prediction = ArmPrediction({"a": {"F_c": p(1.0, 0.05), "F_v": p(0.5, 0.05), "tau_os": p(0.1, 1.0)},
                                "b": {"F_c": p(2.0, 0.2), "F_v": p(0.2, 0.01)}}, {}, {})
    joint, name, share = prediction.worst(0.25)
    assert (joint, name) == ("a", "F_v") and share == pytest.approx(0.05 / (0.25 * 0.5))
    assert prediction.worst(0.25, ("tau_os",))[2] == pytest.approx(1.0 / (0.25 * 0.1))
    prediction.joints["b"]["F_v"] = p(0.0, 0.01)
    assert prediction.worst(0.25) == ("b", "F_v", np.inf)
