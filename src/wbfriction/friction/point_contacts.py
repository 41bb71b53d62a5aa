"""Friction of a robot on point feet (a quadruped), wherever the contacts leave it determined (issue 56).

The thesis's route (:mod:`wbfriction.friction.estimate`) welds a sole and re-roots the robot at it; a point foot
turns about its contact point and gives no such tree. Here the base's motion is measured (its logged pose
differentiated, or the IMU's rates with the logged orientation: :func:`~wbfriction.friction.measured.base_state`),
every acceleration is known, and each sample's equation of motion is solved for the joint torques and the contact
forces not measured. Which joints that determines is decided per sample by the rank of ``[S^T  J_u^T]``
(:mod:`wbfriction.model.determination`), never by a phase's name: a swinging leg always, a stance leg where the
feet's forces are measured (``force.<frame>.x`` ... ``.z``, :mod:`wbfriction.logs.foot_forces`). A joint not
determined at a sample is NaN there, not valid, never guessed.

The thesis's margins (6.2.1) apply around every foot's switch (:func:`~wbfriction.signals.phases.settled`).

Sign convention: ``tau_f = tau_joint - tau``, the torque friction exerts on the joint.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.friction.estimated import FrictionEstimate, no_single_support
from wbfriction.friction.measured import base_state, finite_base, measured_base
from wbfriction.friction.options import EstimateOptions
from wbfriction.model.determination import Determination, joint_torques
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress
from wbfriction.signals.kinematics import MeasuredKinematics
from wbfriction.signals.phases import segment, settled


def contacts_route(robot: Robot, kin: MeasuredKinematics, rows: np.ndarray, progress: Progress | None = None
                   ) -> tuple[np.ndarray, Determination]:
    """The friction of the torque-controlled joints on the rows ``rows`` (N,) of ``kin`` whose base motion is
    measured and finite, where the contacts leave it determined (module docstring).

    Returns:
        ``(tau_f, determination)``: (N, n_tc) [N·m], NaN where not estimated or not determined, and the
        :class:`~wbfriction.model.determination.Determination` of every row (not determined off ``rows``).

    Raises:
        InputError: the base's motion not measured (no base pose columns, or ``--base-motion contact``).
    """
    if measured_base(kin) == "contact":
        source = kin.metadata.get("source", "the log")
        raise InputError(f"{source}: a robot on {robot.stands_on} needs the base's measured motion: the base pose "
                         "columns base.x ... base.qw (with --base-motion logged or auto), or them and the IMU's imu.* "
                         "(--base-motion imu)")
    n, tc = len(kin.time), robot.tc_index
    ok = rows & finite_base(kin)
    r = np.flatnonzero(ok)
    q, v, a_b = base_state(robot, kin, r)
    assert a_b is not None  # a measured base
    a = np.zeros_like(v)
    a[:, :6], a[:, robot.act_v_index] = a_b, kin.qdd[r]
    feet = None if kin.foot_force is None else kin.foot_force[r]
    solution = joint_torques(robot, q, v, a, kin.contact[r], feet, progress)
    tau_f = np.full((n, tc.size), np.nan)
    tau_f[r] = solution.tau[:, tc] - kin.tau[r]
    d = solution.determination
    out = Determination(np.zeros((n, robot.n_act), dtype=bool), np.zeros(n, dtype=int), np.full(n, np.nan),
                        np.full((n, 6), np.nan))
    out.determined[r], out.nullity[r], out.cond[r], out.residual[r] = d.determined, d.nullity, d.cond, d.residual
    return tau_f, out


def point_contact_estimate(robot: Robot, kin: MeasuredKinematics, options: EstimateOptions,
                           progress: Progress | None = None, require_determined: bool = True) -> FrictionEstimate:
    """:func:`~wbfriction.friction.estimate.estimate_friction` for a robot on point feet (module docstring).

    The estimate's ``valid`` is (N, n_tc): determined, the derivatives defined, outside the switches' margins;
    ``unique`` (N,) a sample that determines some joint; ``cond`` the conditioning of the contact forces
    (:class:`~wbfriction.model.determination.Determination`); ``route`` ``"base"``.
    ``determined`` is the rank decision of every evaluated sample (:func:`determined_shares` counts it by contact
    pattern).

    Raises:
        InputError: what :func:`contacts_route` raises; with ``require_determined``, no sample determining a joint.
    """
    assert kin.valid is not None  # set by MeasuredKinematics.__post_init__
    usable = kin.valid & settled(kin.time, kin.contact, options.lift_off_skip, options.touch_down_skip)
    tau_f, det = contacts_route(robot, kin, usable, progress)
    tc = robot.tc_index
    valid = det.determined[:, tc] & usable[:, None] & np.isfinite(tau_f)
    if require_determined and not valid.any():
        raise no_single_support(robot, kin.metadata.get("source", "the log"))
    tau_f = np.where(valid, tau_f, np.nan)
    metadata = dict(kin.metadata)
    metadata["estimate_options"] = asdict(options)
    metadata["joint_labels"] = {j: robot.label(j) for j in robot.torque_controlled}
    return FrictionEstimate(
        joints=robot.torque_controlled, time=kin.time, qd=kin.qd[:, tc], tau_f=tau_f, valid=valid,
        phase=segment(kin.time, kin.contact).labels(), unique=valid.any(axis=1), contact=kin.contact,
        contact_frames=robot.contact_frames, qdd=kin.qdd[:, tc], delta_qdd=np.full_like(tau_f, np.nan),
        cond=det.cond, tau_f_true=kin.tau_f_true, metadata=metadata, smoother=kin.smoother,
        route=np.where(valid.any(axis=1), "base", "none").astype("<U7"), determined=det.determined[:, tc])


def contact_pattern(frames: tuple[str, ...], flags: np.ndarray) -> str:
    """A contact pattern's name: the frames on the ground joined by ``+`` (``"FL_foot+RR_foot"``), ``"flight"``."""
    down = [f for f, on in zip(frames, flags) if on]
    return "+".join(down) if down else "flight"


@dataclass(frozen=True)
class DeterminedShares:
    """The share of samples that determine each joint's friction, by contact pattern (issue 56's table).

    Attributes:
        joints: the torque-controlled joints (n_tc,).
        patterns: the contact patterns (:func:`contact_pattern`), most frequent first (n_p,).
        samples: (n_p,) the samples of each pattern whose dynamics were evaluated (derivatives defined, outside the
            switches' margins).
        share: (n_p, n_tc) the fraction of them that determine the joint.
        overall: (n_tc,) the fraction over every evaluated sample.
    """

    joints: tuple[str, ...]
    patterns: tuple[str, ...]
    samples: np.ndarray
    share: np.ndarray
    overall: np.ndarray

    def to_dict(self) -> dict:
        """As JSON: ``{"patterns": [{"pattern", "samples", "share": {joint: fraction}}], "all": {joint: fraction}}``."""
        return {"patterns": [{"pattern": p, "samples": int(n), "share": dict(zip(self.joints, map(float, row)))}
                             for p, n, row in zip(self.patterns, self.samples, self.share)],
                "all": dict(zip(self.joints, map(float, self.overall)))}


def determined_shares(est: FrictionEstimate) -> DeterminedShares | None:
    """:class:`DeterminedShares` of an estimate of a robot on point feet (its ``determined`` flags, the samples
    counted those with a finite ``cond``); None for an estimate without them (the thesis's phases decided)."""
    if est.determined is None or est.cond is None:
        return None
    counted = np.isfinite(est.cond)
    patterns, of = np.unique(est.contact[counted].astype(bool), axis=0, return_inverse=True)
    of = of.ravel()
    det = est.determined[counted]
    samples = np.bincount(of, minlength=len(patterns))
    order = sorted(range(len(patterns)), key=lambda p: (-samples[p], contact_pattern(est.contact_frames, patterns[p])))
    share = np.array([det[of == p].mean(axis=0) for p in order]).reshape(len(order), len(est.joints))
    overall = det.mean(axis=0) if len(det) else np.zeros(len(est.joints))
    return DeterminedShares(est.joints, tuple(contact_pattern(est.contact_frames, patterns[p]) for p in order),
                            samples[order], share, overall)
