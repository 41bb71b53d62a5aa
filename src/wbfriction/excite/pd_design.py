"""The design of a hung PD-driven robot's excitation: the set-points whose identification
(:func:`~wbfriction.actuator.identify_actuators`) is predicted to report every parameter furthest inside its status's
limit.

**The criterion** is the worst share of its ``ok`` limit that a parameter's *predicted reported* standard error comes to
(:meth:`~.predict.ActuatorPrediction.worst`: an offset's limit is
:data:`~wbfriction.actuator.identification.OFFSET_WEAK`, the others' :data:`~wbfriction.fit.status.WEAK` times their
value): E-optimality's worst parameter, on the scale the status reads, so that below 1 every parameter is predicted
``ok``. Not the Cramér-Rao bound alone, nor D-optimality: on a hung Go2 (30 s, a real driver's noise) the bound's
worst share hardly moves between motions (0.25-0.34), while what the identification reports moves 25-fold (0.27 on
wide ramps, 6.9 on wide chirps, whose delay's form the balance cannot tell; ``excite_design`` notes). The standard
error reported is mostly model error (the sandwich on the balance's residual, the Coulomb nuisance's slope, the
delay's form), which the prediction (:func:`~.predict.predict_pd`) takes from the identification itself on the motion
simulated without noise, with the identification's own Fisher information for the noise.

**The family** is triangle ramps (:func:`~wbfriction.sim.hung.setpoints`, ``kind="ramps"``): each joint between
random levels in the far half of its band about the robot's posture, reversing after a random time in ``reversal``.
A triangle wave is the Fourier series of odd harmonics falling as ``1/k^2``, the field's parameterisation (Swevers et
al. 1997) pushed to short reversals at constant speed: smooth series of five harmonics dwell near zero speed, where
the Coulomb nuisance's slope is model error, and reverse slowly (worst share 2.8-4.4 on the hung Go2, the calves'
offsets ``weak``), and the random levels give each joint a spread of speeds, so that F_v and F_c are not collinear as
they are on ramps at one speed. The ramps span the band (``amplitude``, a share of half the range) for the offsets,
whose information is the gravity torque's slope across it.

**The search** (:func:`design_pd`): the amplitudes of :attr:`PdExciteOptions.amplitudes` at the first reversal
range, then the reversal ranges at the best amplitude, each candidate scored by the prediction (two simulations and
two identifications, 5-10 s for 30 s of a quadruped); a candidate whose motion leaves a position or velocity limit or
asks more than :attr:`PdExciteOptions.torque_share` of a driver's torque limit is refused; the lowest worst share
kept. Derivative-free on a grid: the score of random levels is not smooth in these variables.

**A candidate is scored, never raised.** Its motion is simulated without noise first; one that passes a position
limit by more than a log may (:data:`~wbfriction.logs.options.LIMIT_MARGIN`: its log would be refused as read,
so it has no identification to predict) is dropped, its reason kept (:attr:`Candidate.dropped`), as is one whose
simulated log the log's checks refuse; the search goes on without it. Only when no candidate is left does the design
fail, in one line saying why (issue 81: a hung Go2's 10 s design stopped on one fast candidate's overshoot, blaming
the units).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Collection, Mapping
from dataclasses import dataclass

import numpy as np

from wbfriction.actuator.identification import OFFSET_WEAK
from wbfriction.actuator.options import ActuatorOptions
from wbfriction.exceptions import ColumnError, InputError
from wbfriction.excite.limits import JointLimits, Margins, margins
from wbfriction.excite.options import PdExciteOptions
from wbfriction.excite.predict import ActuatorPrediction, predict_pd, worst_share
from wbfriction.fit.status import WEAK
from wbfriction.friction.models import ModelParams
from wbfriction.logs.options import LIMIT_MARGIN
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress
from wbfriction.sim.hung import setpoint_band, setpoints, simulate_hung
from wbfriction.sim.pd_options import DriverNoise, HungOptions

SHARE_LIMITS = {"offset": OFFSET_WEAK}
"""The status's absolute limits (the others: :data:`~wbfriction.fit.status.WEAK` times the value)."""


@dataclass(frozen=True)
class Candidate:
    """One candidate of the search: its ``amplitude``, ``reversal`` [s], the parameter predicted worst ``worst``
    (joint, name, share of its limit; a dropped candidate's: ``("", "", inf)``), its motion's
    :class:`~.limits.Margins` ``margins``, whether it was within the limits (``within``), and why it was dropped
    unscored (``dropped``: its motion passes a position limit further than a log may, or its simulated log is
    refused; None: scored)."""

    amplitude: float
    reversal: tuple[float, float]
    worst: tuple[str, str, float]
    margins: Margins
    within: bool
    dropped: str | None = None


@dataclass(frozen=True)
class PdDesign:
    """A hung PD-driven robot's designed excitation.

    Attributes:
        robot: the robot's name; joints: its PD-driven joints (its actuated order).
        time: the set-points' times (N,) [s] from the start, at the drivers' rate.
        q_des: the set-points (N, n) [rad], in the encoders' coordinates (the model's angle plus the robot's
            ``[encoder_offset]``), as the drivers take them.
        qd_des: the velocity set-points (N, n) [rad/s] (zeros unless :attr:`PdExciteOptions.velocity`).
        chosen: the candidate kept; candidates: every one scored, in the search's order.
        prediction: what the identification is predicted to report on it (:class:`~.predict.ActuatorPrediction`).
        margins: how far inside its limits its motion stays (noise-free, the prior's friction; a joint held still:
            1).
        options: what was designed.
        moving: the joints it excites (the others held at their posture).
    """

    robot: str
    joints: tuple[str, ...]
    time: np.ndarray
    q_des: np.ndarray
    qd_des: np.ndarray
    chosen: Candidate
    candidates: tuple[Candidate, ...]
    prediction: ActuatorPrediction
    margins: Margins
    options: PdExciteOptions
    moving: tuple[str, ...]

    def worst(self) -> tuple[str, str, float]:
        """The parameter predicted worst: (joint, name, share of its status's limit)."""
        return self.chosen.worst

    def dropped(self) -> tuple[Candidate, ...]:
        """The candidates dropped unscored (:attr:`Candidate.dropped`), in the search's order."""
        return tuple(c for c in self.candidates if c.dropped is not None)


def design_pd(robot: Robot, options: PdExciteOptions = PdExciteOptions(),
              prior: Mapping[str, ModelParams] | None = None,
              identification: ActuatorOptions = ActuatorOptions(), progress: Progress | None = None,
              moving: Collection[str] | None = None) -> PdDesign:
    """The excitation of a hung PD-driven robot (module docstring).

    Args:
        robot: a fixed-base robot whose joints are all PD-driven (``[pd]``), with finite position, velocity and
            torque limits; its ``[pd]`` delay, ``[armature]`` and ``[encoder_offset]`` are the prior's.
        options: :class:`PdExciteOptions`.
        prior: the friction expected per joint (a fit; None: the simulator's default,
            :func:`~wbfriction.sim.hung.default_hung_friction`).
        identification: how the recording will be identified.
        progress: told of each candidate scored.
        moving: the joints to excite (None: every one); the others are held at their posture, and the criterion
            reads the moving joints' parameters only (what a log already determines is not recorded again,
            :mod:`wbfriction.excite.next`).

    Raises:
        InputError: a robot the hung simulator does not take, a joint without limits
            (:meth:`~.limits.JointLimits.of`); no candidate within the limits (every one dropped: how many, and
            the first's reason).
    """
    limits = JointLimits.of(robot)
    still = np.zeros(robot.n_act, dtype=bool) if moving is None else ~np.isin(robot.actuated, tuple(moving))
    scored: dict[tuple[float, tuple[float, float]], tuple[Candidate, ActuatorPrediction | None]] = {}

    def score(amplitude: float, reversal: tuple[float, float]) -> Candidate:
        key = (amplitude, reversal)
        if key not in scored:
            scored[key] = scored_candidate(robot, limits, options, amplitude, reversal, still, prior, identification)
            if progress is not None:
                progress(1)
        return scored[key][0]

    def best(cands: list[Candidate]) -> Candidate | None:
        ok = [c for c in cands if c.within]
        return min(ok, key=lambda c: c.worst[2]) if ok else None

    first = best([score(a, options.reversals[0]) for a in options.amplitudes])
    amplitude = first.amplitude if first is not None else min(options.amplitudes)
    chosen = best([score(amplitude, r) for r in options.reversals])
    if chosen is None:
        raise InputError(none_left(robot.name, [c for c, _ in scored.values()], options.torque_share))
    prediction = scored[(chosen.amplitude, chosen.reversal)][1]
    assert prediction is not None and prediction.motion is not None  # within: scored
    commands = prediction.motion.commands
    return PdDesign(robot.name, robot.actuated, prediction.motion.time, commands.q_des, commands.qd_des, chosen,
                    tuple(c for c, _ in scored.values()), prediction, chosen.margins, options,
                    tuple(j for j, s in zip(robot.actuated, still) if not s))


def scored_candidate(robot: Robot, limits: JointLimits, options: PdExciteOptions, amplitude: float,
                     reversal: tuple[float, float], still: np.ndarray, prior: Mapping[str, ModelParams] | None,
                     identification: ActuatorOptions) -> tuple[Candidate, ActuatorPrediction | None]:
    """One candidate of :func:`design_pd` and its prediction (None: dropped unscored, module docstring): its motion
    simulated without noise, its margins (a joint ``still`` (n_act,): 1), then its identification predicted unless
    the motion passes a position limit further than a log may or its simulated log is refused."""
    hung = options.hung(amplitude, reversal)
    reference = held(robot, hung, still)
    motion = simulate_hung(robot, dataclasses.replace(hung, noise=DriverNoise()), prior, reference=reference)
    run = motion.trajectory
    m = margins(limits, run.q, run.qd, run.tau)
    m = Margins(np.where(still, 1.0, m.position), np.where(still, 1.0, m.velocity), m.torque)
    dropped = beyond_log(limits, run.q)
    prediction = None
    if dropped is None:
        try:
            prediction = predict_pd(robot, hung, prior, reference=reference, identification=identification,
                                    motion=motion)
        except ColumnError as e:  # the log's checks refuse its simulated log
            dropped = f"its simulated log is refused ({e})"
    if prediction is None:
        return Candidate(amplitude, reversal, ("", "", np.inf), m, False, dropped), None
    within = bool(min(m.position.min(), m.velocity.min()) > 0 and m.torque.min() >= 1.0 - options.torque_share)
    asked = {j: p for j, p in prediction.joints.items() if not still[robot.actuated.index(j)]}
    return Candidate(amplitude, reversal, worst_share(asked, SHARE_LIMITS, WEAK), m, within), prediction


def beyond_log(limits: JointLimits, q: np.ndarray) -> str | None:
    """Why a motion ``q`` (N, n) [rad, the model's angles] cannot be identified: it passes a joint's position limit
    by more than :data:`~wbfriction.logs.options.LIMIT_MARGIN`, past which a log is refused as read (its joint, by
    how much); None: it does not."""
    excess = np.maximum(limits.lower - q.min(axis=0), q.max(axis=0) - limits.upper)
    i = int(np.argmax(excess))
    if excess[i] <= LIMIT_MARGIN:
        return None
    return (f"its motion passes the position limit of joint '{limits.joints[i]}' by {excess[i]:.3g} rad, more than "
            f"a log may ({LIMIT_MARGIN:g} rad)")


def none_left(robot: str, candidates: list[Candidate], torque_share: float) -> str:
    """The one line of a search that kept no candidate: every one dropped (how many, and the first's reason), or those
    scored outside the limits (and how many dropped)."""
    dropped = [c.dropped for c in candidates if c.dropped is not None]
    if len(dropped) == len(candidates):
        return (f"robot '{robot}': no candidate motion can be scored: {len(dropped)} of {len(candidates)} dropped "
                f"(the first: amplitude {candidates[0].amplitude:g}, reversals {candidates[0].reversal[0]:g}-"
                f"{candidates[0].reversal[1]:g} s: {dropped[0]}): lower --amplitude")
    also = f" ({len(dropped)} of {len(candidates)} dropped unscored: {dropped[0]})" if dropped else ""
    return (f"robot '{robot}': every candidate passes a limit or {torque_share:.0%} of a torque limit{also}: lower "
            "--amplitude")


def held(robot: Robot, options: HungOptions, still: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The set-points of ``options`` (model angles and slopes (N, n_act)) with the joints ``still`` (n_act,) held at
    their posture; None where none is (the simulator's own)."""
    if not still.any():
        return None
    time = np.arange(int(round(options.duration * options.rate))) / options.rate
    q, slope = setpoints(robot, time, options.setpoints)
    posture = setpoint_band(robot, options.setpoints.amplitude)[0]
    q[:, still], slope[:, still] = posture[still], 0.0
    return q, slope


def play_options(design: PdDesign, noise: DriverNoise) -> HungOptions:
    """The hung simulation that plays ``design`` with the drivers' noise ``noise``."""
    return dataclasses.replace(design.options.hung(design.chosen.amplitude, design.chosen.reversal), noise=noise)
