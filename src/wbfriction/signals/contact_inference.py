"""Contacts from the log: each foot's contact state per sample, with its confidence, from what a walking robot writes
(issue 82, item 1).

A raw quadruped log has no contact flags and often no foot forces. The state of each foot is inferred from cues that
the joints' angles, velocities and torques, and the base's orientation (an IMU's), hold:

* **kinematics** (``"kinematics"``): each foot's contact point (the foot frame's origin less ``robot.foot_radius``
  along the vertical) in a gravity-aligned frame at the base, its height above the ground the lowest half of the
  feet stand on (the mean of their heights: at least half of the feet are down in a walk or a trot). Stance reads
  ``N(0, sigma_h^2)`` with ``sigma_h`` the noise measured in the log (the spread between the two lowest feet, both on
  the ground: their heights' difference, robust scale); swing reads anywhere between the ground and the foot's
  highest (its 99th percentile): a uniform density.
* **torques** (``"torque"``): the ground's force each leg's torques imply, ``f = -(J_leg^T)^-1 (tau_leg - g_leg)``
  (the leg's rows of the floating-base dynamics, quasi-static: the leg's own gravity torque with the base's
  orientation; the generalized-momentum residual of contact detection, Bledt et al. 2018, De Luca's observer,
  without its inertial terms, which the base's unknown acceleration would need), its world-vertical component.
  Swing reads ``N(0, sigma_f^2)`` with ``sigma_f`` measured on the samples the kinematics call swing with
  confidence (the leg's inertia, the drive's friction and rotor inertia in a current-based torque, the noise);
  stance reads any share of the robot's weight: uniform on ``[0, m g]``.
* **counts** (``"counts"``): raw foot-force sensor counts, calibrated in the log itself
  (:func:`calibrate_counts`: the offset is what the swing phases read, the scales make the feet's total average to
  the weight), then read as the torques' force is.
* **periodicity** (``"periodicity"``): the gait's period from the autocorrelation of the feet's heights
  (:func:`gait_period`); the two-state hidden Markov model of each foot switches twice a period
  (``p = 2 dt / period``), which regularises isolated flips. Without a period, the switches the kinematics see
  (counted on a first pass) set it.

Each foot is a two-state hidden Markov model (swing, stance) whose emission is the product of its cues' densities
(independent given the state); the forward-backward posterior of the state is the **confidence** of the best guess
(``max(p, 1 - p)``), and a sample whose confidence is below ``options.level`` is not confident (the integrator
leaves it out of the friction and counts it).

A swing the chain finds whose foot never rises above the stance feet's noise (:data:`LIFT_SIGMAS` of it) is not a
swing (:func:`unlifted_swings`): the foot is on the ground, its load near nothing (a walk's foot diagonal to the
swinging one, the other three carrying the robot). Its samples are called stance with a confidence of 0.5 (not
confident: the torques' force cannot tell a foot grazing the ground from one just above it). With foot counts, which
measure the load itself, the chain's swings are kept (on the Go2's 4 s walk the rule would turn 100 % into
99.3 %). On Solo-12's MuJoCo walk such a foot carries 0.3-3 N of the 24.5 N weight for about 40 ms each gait cycle,
1.1-1.7 mm above the loaded feet (which sink into the soft ground): both cues read it as swing, and each foot had one
such false swing a cycle (95.5 % agreement; 98.6 % now). On the Go2's 4 s walks (``go2_walking``) agreement rises
from 97.8-97.9 to 98.7-98.8 %.

A log where no foot swings is refused (:func:`check_swings`): a foot swings where it is lifted and unloaded
(:func:`lifted_unloaded`) for a run of consecutive samples at least :func:`least_swing` long, the run that noise
alone on a standing robot makes with a probability below :data:`SWING_LEVEL`; isolated samples that cross the
thresholds (a stance foot's load near them, a bounce on a soft ground) are not a swing. Nothing is determined on a
standing log without foot forces.

The foot's velocity relative to the base against the stance group's (stance feet move together relative to the
base) is not a cue here: on the MuJoCo Go2, whose spherical feet roll, it lowered the trot's agreement from 98 % to
93 % (the rolling sphere's centre moves while the foot stands).

Measured on the MuJoCo twin (``tests/signals/test_contact_inference.py``): trot and walk, clean and with a Unitree's
noise, the best guess agrees with the simulator's contacts (normal force > 0) on 98-99 % of the samples.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError, OptionError
from wbfriction.logs.contacts import OFF_SHARE
from wbfriction.model.robot import Robot
from wbfriction.signals.phases import true_runs

CUES = ("torque", "kinematics", "counts", "periodicity")
"""The cues, as :attr:`InferredContacts.cues` names them."""

LIFT_SIGMAS = 5.0
"""A sample has its foot lifted and unloaded where the foot's height exceeds this many of the stance feet's height
noise (``sigma_h``) and, with the torque cue, the force its leg's torques imply is below the contact flags' own off
threshold (:data:`~wbfriction.logs.contacts.OFF_SHARE` of the weight): a standing robot on a soft ground sinks a
foot by millimetres as its load shifts (2.1 mm against 5 sigma = 1.9 mm on the MuJoCo twin). A foot leaves the
ground only where such samples make a run of :func:`least_swing` (:func:`check_swings`)."""

SWING_LEVEL = 0.00135
"""The test level of the standing refusal (:func:`least_swing`): the probability that noise alone on a standing
robot makes a run of lifted-and-unloaded samples as long as a swing needs, anywhere in the log (one-sided 3
standard deviations, 0.13 %)."""

MIN_SAMPLES = 100
"""Fewer samples: too short for the inference (the noise, the feet's highest and the period measured on them)."""

SWING_CEILING = 99.0
"""The percentile of a foot's height taken as its highest in swing (the uniform swing density's top)."""

ROBUST_SCALE = 0.6744897501960817
"""The standard normal's upper quartile: a median absolute deviation over it estimates a standard deviation."""


@dataclass(frozen=True)
class ContactOptions:
    """How contacts are inferred (module docstring).

    Attributes:
        level: the confidence [0.5, 1) a sample's state needs to count as confident (posterior probability of the
            best guess).
        torque: use the torques' implied ground force as a cue.
        periodicity: use the gait's period for the state's switching rate.

    Raises:
        OptionError: a level outside [0.5, 1), a cue option that is not a bool.
    """

    level: float = 0.95
    torque: bool = True
    periodicity: bool = True

    def __post_init__(self) -> None:
        if not (isinstance(self.level, (int, float)) and 0.5 <= float(self.level) < 1.0):
            raise OptionError("--contact-level", self.level, "a probability in [0.5, 1)")
        for name in ("torque", "periodicity"):
            if not isinstance(getattr(self, name), bool):
                raise OptionError(f"--contact-{name}", getattr(self, name), "true or false")


@dataclass(frozen=True)
class InferredContacts:
    """Each foot's contact state per sample, inferred (:func:`infer_contacts`).

    Attributes:
        contact: (N, n_c) bool, the best guess per foot (``robot.contact_frames`` order): True on the ground.
        confidence: (N, n_c) float in [0.5, 1]: the posterior probability that the guess is right; 0.5 on a swing
            the foot never lifted in (:func:`unlifted_swings`: called stance, undetermined).
        confident: (N, n_c) bool: ``confidence >= options.level``.
        cues: the cues used (of :data:`CUES`).
        gait_period: the gait's period [s] from the periodicity, None if not periodic (or the cue is off).
    """

    contact: np.ndarray
    confidence: np.ndarray
    confident: np.ndarray
    cues: tuple[str, ...]
    gait_period: float | None

    def unconfident_rows(self) -> np.ndarray:
        """(N,) bool: the samples where any foot's state is not confident."""
        return np.asarray(~self.confident.all(axis=1), dtype=bool)


def _legs(robot: Robot) -> list[np.ndarray]:
    """Each contact frame's leg: its joints' positions in ``robot.actuated``."""
    return [np.array([robot.actuated.index(j) for j in robot.limb(f)], dtype=int) for f in robot.contact_frames]


def _rotations(rotation: np.ndarray | None, n: int, source: str) -> np.ndarray:
    if rotation is None:
        return np.broadcast_to(np.eye(3), (n, 3, 3))
    rotation = np.asarray(rotation, dtype=float)
    if rotation.shape != (n, 3, 3) or not np.all(np.isfinite(rotation)):
        raise InputError(f"{source}: the base's rotation must be (N, 3, 3) finite, got {rotation.shape}")
    return rotation


def feet_kinematics(robot: Robot, q: np.ndarray, tau: np.ndarray | None, rotation: np.ndarray | None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Each foot's contact point relative to the base and the ground force its leg's torques imply.

    Args:
        robot: a floating-base robot with contact frames, each on a leg of as many joints as force components (3).
        q: (N, n_act) joint angles [rad] in ``robot.actuated`` order (the model's angles).
        tau: (N, n_act) joint torques [N·m], or None (no forces computed).
        rotation: (N, 3, 3) the base's world rotation, or None (the base level: identity).

    Returns:
        ``(points, forces)``: (N, n_c, 3) [m] each foot's contact point (foot frame's origin less
        ``robot.foot_radius`` along the world vertical) from the base's origin, world axes; (N, n_c, 3) [N] the
        ground's force on each foot, world axes, ``f = -(J_leg^T)^-1 (tau_leg - g_leg)`` with ``g`` the generalized
        gravity (the leg's inertial terms left out), NaN without torques.
    """
    model = robot.model
    data = model.createData()
    n, nc = len(q), len(robot.contact_frames)
    R = _rotations(rotation, n, "<log>")
    legs, iv = _legs(robot), robot.act_v_index
    offset = np.array([0.0, 0.0, -robot.foot_radius])
    points, forces = np.zeros((n, nc, 3)), np.full((n, nc, 3), np.nan)
    for k in range(n):
        qf = robot.configuration(q[k], np.r_[0.0, 0.0, 0.0, pin.Quaternion(R[k]).coeffs()])
        pin.computeJointJacobians(model, data, qf)
        pin.updateFramePlacements(model, data)
        g = pin.computeGeneralizedGravity(model, data, qf) if tau is not None else None
        for c, fid in enumerate(robot.contact_frame_ids):
            points[k, c] = data.oMf[fid].translation + offset
            if g is not None and tau is not None:
                J = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
                cols = iv[legs[c]]
                Jl = (J[:3] - pin.skew(offset) @ J[3:])[:, cols]
                forces[k, c] = np.linalg.solve(Jl.T, g[cols] - tau[k, legs[c]])
    return points, forces


def weight(robot: Robot) -> float:
    """The robot's weight ``m g`` [N] (its model's total mass, the model's gravity)."""
    return float(pin.computeTotalMass(robot.model) * np.linalg.norm(robot.model.gravity.linear))


def calibrate_counts(counts: np.ndarray, stance: np.ndarray, swing: np.ndarray, weight_n: float, source: str = "<log>"
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Raw foot-force counts' offset and scale, found in the log: ``force = (counts - offset) / scale``.

    The offset of each foot is what it reads in swing (its median over ``swing``); the scales are those for which
    the feet's forces add up to the weight on average over the samples where every foot's state is known
    (``stance | swing``): least squares of ``sum_c (counts_c - offset_c) / scale_c = m g`` (the base's vertical
    acceleration averages out over a gait).

    Args:
        counts: (N, n_c) raw counts.
        stance, swing: (N, n_c) bool, samples known on the ground, in the air.
        weight_n: the robot's weight [N].

    Returns:
        ``(offset, scale)``, each (n_c,) [counts], [counts/N].

    Raises:
        InputError: a foot never seen in swing, or scales the log does not determine (no foot alternating).
    """
    counts = np.asarray(counts, dtype=float)
    nc = counts.shape[1]
    if not swing.any(axis=0).all():
        raise InputError(f"{source}: foot-force counts of a foot never seen in swing: no offset found")
    offset = np.array([np.median(counts[swing[:, c], c]) for c in range(nc)])
    known = (stance | swing).all(axis=1)
    A = np.where(stance, counts - offset, 0.0)[known]
    if len(A) < nc or np.linalg.matrix_rank(A) < nc:
        raise InputError(f"{source}: the foot-force counts' scales are not determined by the log")
    inv, *_ = np.linalg.lstsq(A, np.full(len(A), weight_n), rcond=None)
    return offset, 1.0 / inv


def gait_period(signal: np.ndarray, dt: float) -> float | None:
    """The gait's period [s]: the lag of the autocorrelation's highest peak after its first zero crossing, summed over
    the feet's (N, n_c) ``signal``; None when that peak is not above the white-noise band (``3 / sqrt(N)``, a test
    level of 0.13 % one-sided) or the log holds no crossing."""
    x = signal - signal.mean(axis=0)
    n = len(x)
    spec = np.fft.rfft(x, 2 * n, axis=0)
    ac = np.fft.irfft(np.abs(spec) ** 2, axis=0)[:n].sum(axis=1)
    if not ac[0] > 0:
        return None
    ac = ac / ac[0]
    below = np.flatnonzero(ac[: n // 2] < 0)
    if not len(below):
        return None
    lag = below[0] + int(np.argmax(ac[below[0]: n // 2]))
    return lag * dt if ac[lag] > 3.0 / np.sqrt(n) else None


def _posterior(logb: np.ndarray, p: float) -> np.ndarray:
    """The two-state chain's (0 swing, 1 stance; switching with probability ``p`` per sample, even start) posterior
    probability of stance (N,), from the emissions' log densities (N, 2): scaled forward-backward."""
    n = len(logb)
    b = np.exp(logb - logb.max(axis=1, keepdims=True))
    A = np.array([[1 - p, p], [p, 1 - p]])
    alpha = np.empty((n, 2))
    a = 0.5 * b[0]
    alpha[0] = a / a.sum()
    for k in range(1, n):
        a = (alpha[k - 1] @ A) * b[k]
        alpha[k] = a / a.sum()
    beta = np.ones(2)
    post = np.empty(n)
    post[-1] = alpha[-1, 1]
    for k in range(n - 2, -1, -1):
        beta = A @ (b[k + 1] * beta)
        beta /= beta.sum()
        g = alpha[k] * beta
        post[k] = g[1] / g.sum()
    return post


def _height_densities(h: np.ndarray, sigma: float) -> np.ndarray:
    """(N, n_c, 2) log densities of the heights [m]: swing uniform between the ground and the foot's highest (below
    the ground as stance does), stance ``N(0, sigma^2)``."""
    top = np.maximum(np.percentile(h, SWING_CEILING, axis=0), LIFT_SIGMAS * sigma)
    stance = -0.5 * (h / sigma) ** 2 - np.log(sigma * np.sqrt(2 * np.pi))
    swing = -np.log(top) + np.where(h < 0, -0.5 * (h / sigma) ** 2, 0.0)
    return np.stack([swing, stance], axis=-1)


def _force_densities(f: np.ndarray, swing: np.ndarray, weight_n: float) -> np.ndarray:
    """(N, n_c, 2) log densities of the feet's vertical forces [N]: swing ``N(0, sigma_f^2)`` with ``sigma_f`` each
    foot's RMS over ``swing`` (its samples known in the air), stance uniform on ``[0, m g]`` (below zero as swing
    falls off)."""
    out = np.zeros(f.shape + (2,))
    for c in range(f.shape[1]):
        x = f[:, c]
        sigma = float(np.sqrt(np.mean(x[swing[:, c]] ** 2))) if swing[:, c].any() else weight_n / f.shape[1]
        sigma = max(sigma, 1e-9 * weight_n)
        out[:, c, 0] = -0.5 * (x / sigma) ** 2 - np.log(sigma * np.sqrt(2 * np.pi))
        out[:, c, 1] = -np.log(weight_n) + np.where(x < 0, -0.5 * (x / sigma) ** 2, 0.0)
    return out


def lifted_unloaded(h: np.ndarray, sigma: float, fz: np.ndarray | None, weight_n: float) -> np.ndarray:
    """(N, n_c) bool: the samples whose foot is lifted (its height ``h`` [m] above :data:`LIFT_SIGMAS` times the
    stance feet's height noise ``sigma`` [m]) and unloaded (the vertical force ``fz`` [N] its leg's torques imply
    below :data:`~wbfriction.logs.contacts.OFF_SHARE` of the weight ``weight_n`` [N]; ``fz`` None: lifted alone)."""
    lifted = np.asarray(h) > LIFT_SIGMAS * sigma
    return lifted if fz is None else lifted & (np.asarray(fz) < OFF_SHARE * weight_n)


def least_swing(runs: int) -> int:
    """The fewest consecutive samples of a foot lifted and unloaded that make a swing, given the log's ``runs`` of
    such samples (every foot's, counted by :func:`run_count`): ``1 + ceil(log2(runs / SWING_LEVEL))``.

    A foot that stands has its mean height and load on the stance side of both thresholds
    (:func:`lifted_unloaded`), so noise symmetric about them lifts and unloads it on each sample with a probability
    ``p <= 1/2``; on independent samples (the repeats merged) a run once started goes on ``k - 1`` more samples with a
    probability ``p^(k-1) <= 2^-(k-1)``, and one of the log's ``runs`` does with at most ``runs * 2^-(k-1)``. The
    least ``k`` that keeps this below :data:`SWING_LEVEL` follows: 18 samples for 100 runs, 21 for 1,000. It follows
    from the test level and the runs the log holds, not from a gait: a swing is at least this long lifted and
    unloaded, or noise alone could have made it. The runs are counted, not the samples: a log twice as long needs one
    sample more only if it holds twice the runs (counting every sample as a start asked 27 samples of a minute's log
    at 2 ms, more than a Solo-12's swings hold, 19-21). A swing that holds its foot lifted and unloaded for fewer
    samples (a log sampled coarsely) is not told from noise, and the log is refused.

    The thesis's lift-off and touch-down margins (0.15 s together) are longer than what a swing holds lifted and
    unloaded: on the MuJoCo Go2 the leg's inertia, left out of the torques' force, reads as load over a swing's second
    half, and a foot's longest run in its walks and trots lasts 54-104 ms of 0.2-0.25 s swings (27-52 samples at
    2 ms). The standing twin's noise makes runs of 2-6 samples.
    """
    return 1 + int(np.ceil(np.log2(max(int(runs), 1) / SWING_LEVEL)))


def run_count(mask: np.ndarray) -> int:
    """The runs of consecutive True in the (N, n_c) bool ``mask``, every column's together."""
    mask = np.asarray(mask, dtype=bool)
    return sum(len(true_runs(mask[:, c])) for c in range(mask.shape[1]))


def longest_runs(mask: np.ndarray) -> np.ndarray:
    """(n_c,) int: each column's longest run of consecutive True in the (N, n_c) bool ``mask`` (0 for none)."""
    mask = np.asarray(mask, dtype=bool)
    return np.array([max((b - a for a, b in true_runs(mask[:, c])), default=0) for c in range(mask.shape[1])],
                    dtype=int)


def unlifted_swings(contact: np.ndarray, h: np.ndarray, sigma: float) -> np.ndarray:
    """(N, n_c) bool: the samples of the swings (runs of ``~contact`` per foot, (N, n_c) bool) in which the foot is
    never lifted: no sample's height ``h`` [m] above :data:`LIFT_SIGMAS` times the stance feet's height noise
    ``sigma`` [m] (:func:`lifted_unloaded`'s height test).

    A swing lifts its foot; a foot that stays within the stance feet's noise while its load falls to near nothing is
    a foot grazing the ground (a walk's foot diagonal to the swinging one, whose load the other three carry: 0.3-3 N of
    Solo-12's 24.5 N on its MuJoCo twin, 1-1.7 mm above the loaded feet, which sink into the soft ground), not a
    swing, whatever its load's cue says.
    """
    contact, h = np.asarray(contact, dtype=bool), np.asarray(h, dtype=float)
    lifted = h > LIFT_SIGMAS * sigma
    out = np.zeros(contact.shape, dtype=bool)
    for c in range(contact.shape[1]):
        for a, b in true_runs(~contact[:, c]):
            out[a:b, c] = not lifted[a:b, c].any()
    return out


def check_swings(lifted: np.ndarray, dt: float, frames: tuple[str, ...], source: str = "<log>") -> np.ndarray:
    """Refuse a log where no foot swings: no run of lifted-and-unloaded samples (``lifted``, (N, n_c) bool, from
    :func:`lifted_unloaded`) as long as :func:`least_swing` (isolated samples are noise: a stance foot near the
    thresholds, a bounce on a soft ground).

    Args:
        lifted: (N, n_c) bool, the samples whose foot is lifted and unloaded, feet in ``frames`` order.
        dt: the sample period [s] (the message's durations).
        frames: the feet's names.
        source: the log's name, for the message.

    Returns:
        (n_c,) int: each foot's longest run [samples].

    Raises:
        InputError: no foot's longest run reaches :func:`least_swing`: one line with the longest run found (samples,
            milliseconds, the foot) against the run a swing needs.
    """
    count = run_count(lifted)
    runs, need = longest_runs(lifted), least_swing(count)
    if runs.max() < need:
        c = int(np.argmax(runs))
        run = f"{runs[c]} ({runs[c] * dt * 1e3:.3g} ms, {frames[c]})"
        found = f"the longest run of samples with a foot lifted and unloaded is {run}" if runs[c] else \
            "no sample has a foot lifted and unloaded"
        raise InputError(f"{source}: no foot ever leaves the ground (a standing log): {found}, against the "
                         f"{need} ({need * dt * 1e3:.3g} ms) a swing needs among the log's {count} runs (noise alone "
                         f"makes one as long with a probability below {SWING_LEVEL:g}); contacts cannot be inferred "
                         "without foot forces")
    return runs


def _check(robot: Robot, arrays: dict[str, np.ndarray], dt: float, source: str) -> int:
    n = len(arrays["q"])
    for name, x in arrays.items():
        if x.ndim != 2 or len(x) != n or not np.all(np.isfinite(x)):
            raise InputError(f"{source}: {name} must be (N, k) and finite for contact inference, got {x.shape}")
    for name in ("q", "tau"):
        if arrays[name].shape[1] != robot.n_act:
            raise InputError(f"{source}: {name} has {arrays[name].shape[1]} joints, the robot {robot.n_act}")
    if "foot_counts" in arrays and arrays["foot_counts"].shape[1] != len(robot.contact_frames):
        raise InputError(f"{source}: foot counts for {arrays['foot_counts'].shape[1]} feet, the robot has "
                         f"{len(robot.contact_frames)}")
    if not (np.isfinite(dt) and dt > 0):
        raise OptionError("--dt", dt, "a sample period > 0 [s]")
    if not robot.floating_base or len(robot.contact_frames) < 2:
        raise InputError(f"robot '{robot.name}': contact inference needs a floating base on two or more feet")
    if n < MIN_SAMPLES:
        raise InputError(f"{source}: {n} samples are too short for contact inference (at least {MIN_SAMPLES})")
    return n


def infer_contacts(robot: Robot, q: np.ndarray, qd: np.ndarray, tau: np.ndarray, rotation: np.ndarray | None,
                   dt: float, foot_counts: np.ndarray | None = None, options: ContactOptions = ContactOptions(),
                   source: str = "<log>") -> InferredContacts:
    """Each foot's contact state per sample with its confidence, from the log's joints, torques and base orientation
    (module docstring).

    Args:
        robot: a floating-base robot on point feet (``robot.contact_frames``), each foot on a three-joint leg.
        q: (N, n_act) joint angles [rad], ``robot.actuated`` order (the model's angles).
        qd: (N, n_act) the drives' joint velocities [rad/s] (checked; the velocity cue is not used, module
            docstring).
        tau: (N, n_act) joint torques [N·m] (a torque sensor's, or the motors' from currents).
        rotation: (N, 3, 3) the base's world rotation (an IMU's orientation), or None: the base taken as level.
        dt: the sample period [s].
        foot_counts: (N, n_c) raw foot-force sensor counts (any offset and scale), or None.
        options: :class:`ContactOptions`.
        source: the log's name, for messages.

    Returns:
        :class:`InferredContacts`.

    Raises:
        InputError: arrays of the wrong shape or not finite, fewer than :data:`MIN_SAMPLES` samples, a log where no
            foot ever leaves the ground (a standing robot: nothing determined without foot forces): no foot lifted
            and unloaded for a run of :func:`least_swing` samples (:func:`check_swings`).
        OptionError: ``dt`` not > 0.
    """
    arrays = {"q": np.asarray(q, float), "qd": np.asarray(qd, float), "tau": np.asarray(tau, float)}
    if foot_counts is not None:
        arrays["foot_counts"] = np.asarray(foot_counts, float)
    n = _check(robot, arrays, dt, source)
    R = _rotations(rotation, n, source)
    points, forces = feet_kinematics(robot, arrays["q"], arrays["tau"] if options.torque else None, R)
    z = points[..., 2]
    nc = z.shape[1]
    low = np.sort(z, axis=1)
    h = z - low[:, : max(1, nc // 2)].mean(axis=1, keepdims=True)
    sigma = max(float(np.median(low[:, 1] - low[:, 0])) / ROBUST_SCALE, 1e-6)
    # lifted and unloaded (a stance foot sinks into a soft ground by millimetres as its load shifts) for a run
    check_swings(lifted_unloaded(h, sigma, forces[..., 2] if options.torque else None, weight(robot)), dt,
                 robot.contact_frames, source)
    cues = ["kinematics"]
    logh = _height_densities(h, sigma)
    first = np.stack([_posterior(logh[:, c], 2.0 / n) for c in range(nc)], axis=1)
    period = gait_period(h, dt) if options.periodicity else None
    if period is not None:
        cues.append("periodicity")
        p = min(0.5, 2.0 * dt / period)
    else:
        p = min(0.5, max(1.0, float(np.abs(np.diff(first > 0.5, axis=0)).sum()) / nc) / n)
    swing, stance = first < 1 - options.level, first > options.level
    logb = logh.copy()
    w = weight(robot)
    if options.torque:
        cues.insert(0, "torque")
        logb += _force_densities(forces[..., 2], swing, w)
    if foot_counts is not None:
        cues.append("counts")
        offset, scale = calibrate_counts(arrays["foot_counts"], stance, swing, w, source)
        logb += _force_densities((arrays["foot_counts"] - offset) / scale, swing, w)
    post = np.stack([_posterior(logb[:, c], p) for c in range(nc)], axis=1)
    contact = post > 0.5
    # on the ground, its load near nothing: undetermined (foot counts measure the load: a run they call swing is)
    grazing = unlifted_swings(contact, h, sigma) if foot_counts is None else np.zeros_like(contact)
    contact |= grazing
    confidence = np.where(grazing, 0.5, np.where(contact, post, 1.0 - post))
    return InferredContacts(contact, confidence, confidence >= options.level, tuple(c for c in CUES if c in cues),
                            period)
