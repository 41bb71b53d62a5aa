"""A log's samples for the inertia identification: each part's kinematics and stance, and its single-support
rows split in time into training, validation and held-out rows (:mod:`wbfriction.inertia.identification`).

The shares count recorded time, not the gaps between a log's segments (a log made of several runs): the
held-out rows are the last :attr:`~wbfriction.inertia.options.InertialOptions.holdout` of it, never used to
identify (:mod:`~wbfriction.inertia.validation` decides on them); the validation rows the last
:attr:`~wbfriction.inertia.options.InertialOptions.validation` of the rest (the prior's weight is chosen on
them, :mod:`~wbfriction.inertia.prior`); the training rows every
:attr:`~wbfriction.inertia.options.InertialOptions.stride`-th usable sample before them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.friction.estimate import resolve_differentiation
from wbfriction.friction.options import EstimateOptions
from wbfriction.inertia.options import InertialOptions
from wbfriction.logs.log import Log
from wbfriction.model.robot import Robot
from wbfriction.signals.kinematics import MeasuredKinematics, measure
from wbfriction.signals.phases import segment


@dataclass
class Part:
    """A log part's kinematics and stance, its single-support rows usable for the regression
    (``use``), and among them the training, validation and held-out rows (N,) (:func:`split_log`).

    Attributes:
        kin: the part's kinematics (:func:`~wbfriction.signals.kinematics.measure`).
        stance: per sample, the index of the stance contact frame (:attr:`Robot.contact_frames`) in single
            support, -1 otherwise (N,) (:func:`~wbfriction.signals.phases.segment`).
        use: single-support samples with valid kinematics, impacts left out (N,) bool.
        train, validation, held: the training, validation and held-out rows among ``use`` (N,) bool.
    """

    kin: MeasuredKinematics
    stance: np.ndarray
    use: np.ndarray
    train: np.ndarray
    validation: np.ndarray
    held: np.ndarray


def split_log(robot: Robot, log: Log, est: EstimateOptions, opts: InertialOptions) -> list[Part]:
    """Per log part: its kinematics, stance, and the training, validation and held-out
    single-support rows (module docstring); a part too short for the differentiation is left out."""
    est, _ = resolve_differentiation(est, log)  # diff "auto": chosen once for the whole log
    assert est.diff != "auto"
    # the shares count recorded time, not the gaps between segments (a log made of several runs)
    active = active_time(log)
    cut = (1.0 - opts.holdout) * active[-1]
    cut_validation = (1.0 - opts.holdout) * (1.0 - opts.validation) * active[-1]
    out = []
    for (a, b), part in zip(log.segments or [(0, len(log))], log.parts()):
        t_active = active[a:b]
        try:
            kin = measure(part, est.diff, compensate_delay=est.compensate_delay,
                          torque_alignment=est.torque_alignment, filtering=est.filtering, velocity=est.velocity)
        except InputError:
            continue  # too short for the scheme: nothing to learn from it
        phases = segment(kin.time, kin.contact, est.lift_off_skip, est.touch_down_skip)
        assert kin.valid is not None  # set by MeasuredKinematics.__post_init__
        use = kin.valid & phases.keep
        train = np.zeros_like(use)
        idx = np.flatnonzero(use & (t_active < cut))
        train[idx[:: opts.stride]] = True
        held = use & (t_active >= cut)
        validation = train & (t_active >= cut_validation)
        out.append(Part(kin, phases.stance, use, train & ~validation, validation, held))
    return out


def active_time(log: Log) -> np.ndarray:
    """Time since the log's start without its gaps (N,) [s]: each segment continues where the last ended."""
    active = np.empty(len(log))
    start = 0.0
    for a, b in log.segments or [(0, len(log))]:
        active[a:b] = start + (log.time[a:b] - log.time[a])
        start = active[b - 1] + log.dt
    return active


@dataclass
class LogSamples:
    """What the identifications of one log with one given model share (the closed loop's passes differ
    only in the Stribeck term): the log's kinematics and its training, validation and held-out samples
    (:func:`split_log`), made once by :func:`log_samples`. (The regressor rows are not kept: a long log's
    would need memory of the size of the data, which the compressed least squares avoids.)

    Attributes:
        robot: the given model.
        log: the log.
        key: the options the parts were split with (differentiation, holdout, validation, stride).
        parts: :func:`split_log`'s parts.
    """

    robot: Robot
    log: Log
    key: tuple
    parts: list[Part]

    def matches(self, robot: Robot, log: Log, estimate_options: EstimateOptions, options: InertialOptions) -> bool:
        """Whether these are the samples :func:`log_samples` would split from these arguments."""
        return self.robot is robot and self.log is log and self.key == split_key(estimate_options, options)


def split_key(estimate_options: EstimateOptions, options: InertialOptions) -> tuple:
    """The options :func:`split_log` depends on."""
    return estimate_options, options.holdout, options.validation, options.stride


def log_samples(robot: Robot, log: Log, estimate_options: EstimateOptions = EstimateOptions(),
                options: InertialOptions = InertialOptions()) -> LogSamples:
    """The samples several :func:`~wbfriction.inertia.identification.identify_inertia` calls on ``log`` with the
    given model ``robot`` share (:class:`LogSamples`); ``options``' Stribeck term may differ between the calls,
    not its holdout, validation or stride."""
    return LogSamples(robot, log, split_key(estimate_options, options),
                      split_log(robot, log, estimate_options, options))


def torque_rms(robot: Robot, parts: list[Part]) -> np.ndarray:
    """RMS measured torque of each torque-controlled joint over the regression's samples (the training and
    validation rows of ``parts``) (n_tc,) [N·m]."""
    sq, count = np.zeros(len(robot.torque_controlled)), 0
    for part in parts:
        rows = part.train | part.validation
        sq += np.sum(part.kin.tau[rows] ** 2, axis=0)
        count += int(rows.sum())
    return np.sqrt(sq / max(count, 1))
