"""The friction fitted on the swings checked on the stances: a self-consistency measure where no truth exists.

A robot on point feet without foot forces determines a joint's friction only while its leg swings
(:mod:`wbfriction.model.determination`). In a stance the leg's three joint rows of the floating-base equations of
motion hold three more unknowns, its foot's force ``f_c``:

.. math:: (M a + h)_{leg} = \\tau_{leg} + \\tau_{f,leg} + J_{c,leg}^T f_c

so, given a friction model, the stance feet's forces follow from their legs' rows (least squares where the legs hold
more rows than the forces have components), and the base's six rows must then balance:

.. math:: r = (M a + h)_{base} - \\sum_c J_{c,base}^T f_c = 0.

Their residual ``r`` (a force [N] and a moment [N·m], base frame) carries every error of the model, the
measurements and the friction. The friction fitted on the swings, predicted on the stances' velocities, should
leave less of it than no friction at all, and about as little as any better friction: that is the check
(:func:`stance_check`), on data the fit never saw (no stance sample enters the fit). It needs the base's motion
(its pose logged, or made from the IMU and the legs: :mod:`wbfriction.pipeline.raw_log`).

Sign convention: ``tau_f = -f(qd)``, the torque friction exerts on the joint (the README's).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError
from wbfriction.fit.predict import FrictionCurve
from wbfriction.fit.result import FitResult
from wbfriction.logs.log import Log
from wbfriction.model.robot import Robot
from wbfriction.signals.kinematics import MeasuredKinematics


@dataclass(frozen=True)
class StanceCheck:
    """The base's balance on the stance samples (module docstring), without friction and with the friction given.

    Attributes:
        samples: the stance samples checked (a foot down, every signal defined, the contact flags sure).
        force_without, moment_without: RMS of the residual's force [N] and moment [N·m] components with no friction.
        force_with, moment_with: the same with the friction given.
        joints: the joints whose friction was given (the others have none in either residual).
    """

    samples: int
    force_without: float
    moment_without: float
    force_with: float
    moment_with: float
    joints: tuple[str, ...] = ()

    def line(self) -> str:
        """One line: the residuals without and with the friction."""
        return (f"the base's balance on {self.samples} stance samples: RMS residual {self.force_without:.3g} N, "
                f"{self.moment_without:.3g} N·m without friction; {self.force_with:.3g} N, {self.moment_with:.3g} "
                f"N·m with the friction of {len(self.joints)} joints fitted on the swings")


def trusted_friction(fits: Mapping[str, FitResult], include: Sequence[str] = ("ok",)) -> dict[str, FrictionCurve]:
    """The friction models of ``fits`` (``read_params``) whose status is in ``include``: a ``weak`` fit may be off
    by several times its value, and would make the check say more of it than the data do."""
    return {j: f.params for j, f in fits.items() if f.params is not None and f.verdict().status in include}


def base_residuals(robot: Robot, kin: MeasuredKinematics, tau_fs: Sequence[np.ndarray], rows: np.ndarray
                   ) -> list[np.ndarray]:
    """Per friction of ``tau_fs``, (len(rows), 6) the base's residual (module docstring) at ``rows``: force [N] then
    moment [N·m], base frame; each row's dynamics and Jacobians computed once for every friction.

    Args:
        robot: a floating-base robot on point feet.
        kin: the log's kinematics with the base's motion (``kin.base``, ``base_qd``, ``base_qdd``).
        tau_fs: each (N, n_act), the friction torque of every actuated joint [N·m] (0 for a joint without a model).
        rows: the stance rows (a foot down at each).
    """
    model, data = robot.model, robot.model.createData()
    frames = [model.getFrameId(f) for f in robot.contact_frames]
    assert kin.base is not None and kin.base_qd is not None and kin.base_qdd is not None
    out = [np.empty((len(rows), 6)) for _ in tau_fs]
    tau = np.zeros(model.nv)
    joints = robot.act_v_index[robot.tc_index]
    for i, k in enumerate(rows):
        q = np.concatenate([kin.base[k], kin.q[k]])
        v = np.concatenate([kin.base_qd[k], kin.qd[k]])
        rhs = pin.rnea(model, data, q, v, np.concatenate([kin.base_qdd[k], kin.qdd[k]]))  # M a + h
        pin.computeJointJacobians(model, data, q)
        J = np.vstack([pin.getFrameJacobian(model, data, frames[c], pin.LOCAL_WORLD_ALIGNED)[:3]
                       for c in np.flatnonzero(kin.contact[k])])
        legs = np.flatnonzero(np.abs(J[:, 6:]).sum(axis=0) > 0) + 6
        for residual, tau_f in zip(out, tau_fs):
            tau[joints] = kin.tau[k] + tau_f[k, robot.tc_index]
            f = np.linalg.lstsq(J[:, legs].T, (rhs - tau)[legs], rcond=None)[0]
            residual[i] = (rhs - tau - J.T @ f)[:6]
    return out


def stance_check(robot: Robot, kin: MeasuredKinematics, friction: Mapping[str, FrictionCurve]) -> StanceCheck:
    """The base's balance on every stance sample of ``kin`` (module docstring) without friction and with ``friction``.

    Args:
        robot: a floating-base robot on point feet.
        kin: the log's kinematics with the base's motion.
        friction: a friction model per joint name (``wbfriction fit``'s parameters: ``read_params``; the ``ok`` ones
            only, :func:`trusted_friction`, to check what a user would export). A joint without one has no friction
            in either residual, so the two differ by the friction given alone.

    Raises:
        InputError: a robot that is not on point feet, kinematics without the base's motion, no friction given, or
            no stance sample.
    """
    return stance_checks(robot, kin, [friction])[0]


def stance_checks(robot: Robot, kin: MeasuredKinematics, frictions: Sequence[Mapping[str, FrictionCurve]]
                  ) -> list[StanceCheck]:
    """:func:`stance_check` of each friction of ``frictions`` on the same samples, each row's dynamics computed once.

    Raises:
        InputError: what :func:`stance_check` raises, for any of them.
    """
    if not (robot.floating_base and robot.partial_contacts):
        raise InputError(f"robot '{robot.name}': the stance check is for a floating base on point feet")
    if kin.base is None or kin.base_qd is None or kin.base_qdd is None:
        raise InputError(f"robot '{robot.name}': the stance check needs the base's motion (its pose, or the IMU's)")
    if not all(any(j in friction for j in robot.actuated) for friction in frictions):
        raise InputError(f"robot '{robot.name}': no friction model of any of its joints to check")
    tau_fs = [np.zeros((len(kin.time), robot.n_act)) for _ in frictions]
    for tau_f, friction in zip(tau_fs, frictions):
        for i, joint in enumerate(robot.actuated):
            if joint in friction:
                tau_f[:, i] = -np.asarray(friction[joint].f(kin.qd[:, i]))
    assert kin.valid is not None
    finite = np.isfinite(kin.base_qdd).all(axis=1) & np.isfinite(kin.base_qd).all(axis=1)
    rows = np.flatnonzero(kin.valid & finite & kin.contact.any(axis=1))
    if rows.size == 0:
        raise InputError(f"robot '{robot.name}': no stance sample to check (a foot down, the base's motion known)")
    without, *with_models = base_residuals(robot, kin, (np.zeros((len(kin.time), robot.n_act)), *tau_fs), rows)
    rms = lambda r: float(np.sqrt(np.mean(r ** 2)))  # noqa: E731
    return [StanceCheck(int(rows.size), rms(without[:, :3]), rms(without[:, 3:]), rms(with_model[:, :3]),
                        rms(with_model[:, 3:]), tuple(j for j in robot.actuated if j in friction))
            for with_model, friction in zip(with_models, frictions)]


def log_stance_check(robot: Robot, log: Log, friction: Mapping[str, FrictionCurve]) -> StanceCheck:
    """:func:`stance_check` on a log: its kinematics measured as ``estimate``'s acceleration route measures them (the
    scheme and window its decision takes on the log's noise, :func:`~wbfriction.friction.decision.decide_log`), the
    base's motion from its logged pose.

    Raises:
        InputError: a log without the base's pose; what :func:`stance_check` raises.
    """
    return log_stance_checks(robot, log, [friction])[0]


def log_stance_checks(robot: Robot, log: Log, frictions: Sequence[Mapping[str, FrictionCurve]]
                      ) -> list[StanceCheck]:
    """:func:`log_stance_check` of each friction of ``frictions``, the log measured once (:func:`stance_checks`).

    Raises:
        InputError: what :func:`log_stance_check` raises.
    """
    from wbfriction.friction.decision import decide_log
    from wbfriction.friction.options import EstimateOptions
    from wbfriction.signals.kinematics import measure
    from wbfriction.signals.options import SCHEMES, Diff

    if log.base is None:
        raise InputError(f"{log.source}: the stance check needs the base's pose (base.x ... base.qw)")
    options = decide_log(robot, EstimateOptions(route="acceleration"), log.q, log.dt, segments=log.segments,
                         rows=len(log), source=log.source).options
    diff = cast(Diff, options.diff if options.diff in SCHEMES else "central")  # decided: no longer "auto"
    return stance_checks(robot, measure(log, diff, filtering=options.filtering, base_motion=True), frictions)
