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
from wbfriction.fit.status import MIN_REVERSE, reverse_share
from wbfriction.friction.estimate import resolve_differentiation
from wbfriction.friction.measured import finite_base, log_base_motion
from wbfriction.friction.options import EstimateOptions
from wbfriction.inertia.options import InertialOptions
from wbfriction.logs.log import Log
from wbfriction.model.determination import free_rows
from wbfriction.model.robot import Robot
from wbfriction.signals.kinematics import MeasuredKinematics, measure
from wbfriction.signals.phases import segment, settled


@dataclass
class Part:
    """A log part's kinematics and stance, its single-support rows usable for the regression
    (``use``), and among them the training, validation and held-out rows (N,) (:func:`split_log`).

    Attributes:
        kin: the part's kinematics (:func:`~wbfriction.signals.kinematics.measure`).
        stance: per sample, its row group (:func:`~wbfriction.inertia.regressor.row_groups`), -1 if none: the index
            of the stance contact frame (:attr:`Robot.contact_frames`) in single support
            (:func:`~wbfriction.signals.phases.segment`); on point feet 0 wherever some joint's row holds.
        use: the samples with valid kinematics, impacts left out, in single support or, on point feet, outside the
            switches' margins with the base's motion measured and some joint's row free of unknown contact forces
            (N,) bool.
        train, validation, held: the training, validation and held-out rows among ``use`` (N,) bool.
        rows: on point feet, where each torque-controlled joint's row holds (N, n_tc) bool
            (:func:`~wbfriction.model.determination.free_rows`); None: every joint's, wherever ``use``.
    """

    kin: MeasuredKinematics
    stance: np.ndarray
    use: np.ndarray
    train: np.ndarray
    validation: np.ndarray
    held: np.ndarray
    rows: np.ndarray | None = None

    def holds(self, r: np.ndarray) -> np.ndarray | None:
        """Where each joint's row holds on the samples ``r`` (len(r), n_tc) bool; None: everywhere."""
        return None if self.rows is None else self.rows[r]


def usable_samples(robot: Robot) -> str:
    """What a sample the identification learns from is, in the robot's words: a humanoid's single-support sample, or
    on point feet (contacts that leave the base undetermined alone) one with a joint free of unknown contact forces
    (messages)."""
    if robot.partial_contacts:
        sensed = any(m.world_force for m in robot.contact_models)
        return "sample with a joint free of unknown contact forces (a leg in the air" + \
            (", or feet with 3-D force columns)" if sensed else ")")
    return "single-support sample"


def split_log(robot: Robot, log: Log, est: EstimateOptions, opts: InertialOptions) -> list[Part]:
    """Per log part: its kinematics, stance, and the training, validation and held-out
    single-support rows (module docstring); a part too short for the differentiation is left out."""
    est, _ = resolve_differentiation(est, log)  # diff "auto": chosen once for the whole log
    assert est.diff != "auto"
    # the shares count recorded time, not the gaps between segments (a log made of several runs)
    active = active_time(log)
    cut = (1.0 - opts.holdout) * active[-1]
    cut_validation = (1.0 - opts.holdout) * (1.0 - opts.validation) * active[-1]
    base_motion = log_base_motion(robot, log, est.base_motion, False)[1] if robot.partial_contacts else "contact"
    if base_motion == "contact" and robot.partial_contacts:
        raise InputError(f"{log.source}: robot '{robot.name}' stands on {robot.stands_on}: its identification "
                         "needs the base's measured motion, the base pose columns base.x ... base.qw (and the IMU's "
                         "imu.*)")
    out = []
    for (a, b), part in zip(log.segments or [(0, len(log))], log.parts()):
        t_active = active[a:b]
        try:
            kin = measure(part, est.diff, compensate_delay=est.compensate_delay,
                          torque_alignment=est.torque_alignment, filtering=est.filtering, velocity=est.velocity,
                          base_motion=base_motion == "logged", imu=base_motion == "imu")
        except InputError:
            continue  # too short for the scheme: nothing to learn from it
        assert kin.valid is not None  # set by MeasuredKinematics.__post_init__
        rows = None
        if robot.partial_contacts:
            rows = free_rows(robot, kin.contact, kin.foot_force)
            use = (kin.valid & settled(kin.time, kin.contact, est.lift_off_skip, est.touch_down_skip)
                   & finite_base(kin) & rows.any(axis=1))
            stance = np.where(use, 0, -1)
        else:
            phases = segment(kin.time, kin.contact, est.lift_off_skip, est.touch_down_skip)
            use, stance = kin.valid & phases.keep, phases.stance
        train = np.zeros_like(use)
        idx = np.flatnonzero(use & (t_active < cut))
        train[idx[:: opts.stride]] = True
        held = use & (t_active >= cut)
        validation = train & (t_active >= cut_validation)
        out.append(Part(kin, stance, use, train & ~validation, validation, held, rows))
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


def one_way_joints(robot: Robot, parts: list[Part]) -> tuple[str, ...]:
    """The torque-controlled joints whose regression rows (training and validation, where each joint's row holds)
    move the other way on fewer than :data:`~wbfriction.fit.status.MIN_REVERSE` of them
    (:attr:`~wbfriction.inertia.options.InertialOptions.one_way_joints`)."""
    qd: list[list[np.ndarray]] = [[] for _ in robot.torque_controlled]
    for part in parts:
        rows = np.flatnonzero((part.train | part.validation) & (part.stance >= 0))
        held = part.holds(rows)
        for i, column in enumerate(part.kin.qd[rows][:, robot.tc_index].T):
            qd[i].append(column if held is None else column[held[:, i]])
    moved = [np.concatenate(v) if v else np.zeros(0) for v in qd]
    return tuple(j for j, v in zip(robot.torque_controlled, moved) if v.size and reverse_share(v) < MIN_REVERSE)


def torque_rms(robot: Robot, parts: list[Part]) -> np.ndarray:
    """RMS measured torque of each torque-controlled joint over the regression's samples (the training and
    validation rows of ``parts``) (n_tc,) [N·m]."""
    sq, count = np.zeros(len(robot.torque_controlled)), np.zeros(len(robot.torque_controlled))
    for part in parts:
        rows = part.train | part.validation
        held = part.holds(rows)
        tau = part.kin.tau[rows] if held is None else np.where(held, part.kin.tau[rows], 0.0)
        sq += np.sum(tau ** 2, axis=0)
        count += rows.sum() if held is None else held.sum(axis=0)
    return np.sqrt(sq / np.maximum(count, 1))
