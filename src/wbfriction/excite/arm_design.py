"""The design of a fixed-base arm's excitation, as ``wbfriction excite`` runs it: each joint's Fourier series designed
on its friction's Cramér-Rao bound (:func:`~.design.design_excitation`), then what ``estimate`` and ``fit`` are
predicted to report on it (:func:`~.predict_arm.predict_arm`: the identification run on the motion simulated with a
real arm's sensors).

The design's criterion is the bound's (E-optimality's worst parameter on the ``weak`` status's scale,
:mod:`.design`): on an arm measured by torque sensors the estimate's information is the joint's own velocities', so
each joint is designed alone, in seconds. The bound is not what the fit reports: on a Panda the fit's standard
errors are 2-16 times it (:mod:`.predict_arm`), so the prediction printed and written is the identification's own.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass, replace

import numpy as np

from wbfriction.excite.design import ExcitationDesign, ExciteOptions, design_excitation
from wbfriction.excite.predict_arm import REAL_ARM, ArmPrediction, predict_arm, sensor_noise
from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress
from wbfriction.sim.arm import ArmOptions, default_arm_friction


@dataclass(frozen=True)
class ArmDesign:
    """A fixed-base arm's designed excitation and what its identification is predicted to report.

    Attributes:
        design: the design (its trajectory, bounds, shares and margins).
        prediction: the prediction (:class:`~.predict_arm.ArmPrediction`).
        time: the samples' times (N,) [s]; q_des, qd_des: the trajectory's angles and velocities there (N, n)
            [rad, rad/s], the model's (an arm's encoders read them less its ``[encoder_offset]``, 0 unless given).
        recording: the sensors the prediction took.

    A design that holds joints (:attr:`moving`) predicts the moving joints' identification only.
    """

    design: ExcitationDesign
    prediction: ArmPrediction
    time: np.ndarray
    q_des: np.ndarray
    qd_des: np.ndarray
    recording: ArmOptions

    def fourier(self) -> dict[str, object]:
        """The trajectory's coefficients (the model's angles), as the set-points table holds them
        (:mod:`wbfriction.logs.setpoint_table`)."""
        t = self.design.trajectory
        return {"center": t.center, "a": t.a, "b": t.b, "omega": t.omega}

    @property
    def joints(self) -> tuple[str, ...]:
        """The joints of the design (the robot's actuated order)."""
        return self.design.joints

    @property
    def moving(self) -> tuple[str, ...]:
        """The joints it moves (the others held at the middle of their range)."""
        return self.design.moving


def design_arm(robot: Robot, options: ExciteOptions = ExciteOptions(),
               prior: Mapping[str, ModelParamsBase] | None = None, recording: ArmOptions = REAL_ARM,
               progress: Progress | None = None, moving: Collection[str] | None = None) -> ArmDesign:
    """Design a fixed-base arm's excitation and predict its identification (module docstring).

    Args:
        robot: a fixed-base robot with torque-measured joints and finite limits.
        options: the design's (:class:`~.design.ExciteOptions`: duration, rate, period, harmonics, shares).
        prior: the friction expected per joint (None: :func:`~wbfriction.sim.arm.default_arm_friction`).
        recording: the sensors the prediction simulates (:data:`~.predict_arm.REAL_ARM`), at the design's duration
            and rate.
        progress: told of each joint designed.
        moving: the joints to move (None: every one); the others are held at the middle of their range
            (:func:`~.design.design_excitation`), and only the moving joints' identification is predicted.

    Raises:
        InputError: what :func:`~.design.design_excitation` and :func:`~.predict_arm.predict_arm` raise.
    """
    prior = dict(default_arm_friction(robot) if prior is None else prior)
    recording = replace(recording, duration=options.duration, rate=options.rate)
    design = design_excitation(robot, prior, sensor_noise(robot, recording), options, progress, moving)
    prediction = predict_arm(robot, prior, design.trajectory, recording,  # type: ignore[arg-type]
                             joints=None if moving is None else design.moving)
    time = options.times()
    q, qd, _ = design.trajectory(time)
    return ArmDesign(design, prediction, time, q, qd, recording)
