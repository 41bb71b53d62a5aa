"""The design of an excitation: each joint's Fourier series (:mod:`.trajectory`) chosen to minimise the worst share of
its status's limit that a parameter's Cramér-Rao bound comes to (:mod:`.information`), within the joint's position
and velocity limits (:mod:`.limits`), then checked against its torque limit.

**Torque-measured joints** (an arm). A joint's friction information depends on its own velocities only
(:func:`~.information.torque_bound`), so each joint is designed alone: minimise ``s`` over its ``2 L - 1`` variables
``z`` and ``s`` subject to ``s >= log rho_p(z)`` for every parameter ``p`` asked for, ``q(t) >= lower + m``,
``q(t) <= upper - m`` and ``|qd(t)| <= share x velocity limit`` on a grid of :data:`GRID` points per period
(SciPy's SLSQP; the epigraph makes the largest ``rho`` smooth), from :attr:`ExciteOptions.starts` seeded starts, the
best kept. The torque the whole motion asks (:func:`~.limits.inverse_dynamics`) is checked afterwards: where it
passes :attr:`ExciteOptions.torque_share` of a limit, every joint's velocity share is lowered and the design redone.

**Held joints.** A design may move some joints only (``moving``: what a log left undetermined,
:mod:`wbfriction.excite.next`): the others are held at the middle of their range (their series a constant), the
torque check reads every joint (a held joint's gravity and the moving ones' reaction included), and the bounds and
shares are the moving joints' alone.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass, field

import numpy as np

from wbfriction.exceptions import InputError
from wbfriction.excite.information import FRICTION_READ, limit_shares, torque_bound
from wbfriction.excite.limits import JointLimits, Margins, inverse_dynamics, margins
from wbfriction.excite.options import ARM_PERIOD, ARM_RATE
from wbfriction.excite.trajectory import FourierSpace, joint_series
from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.friction.noise import NoiseModel
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress
from wbfriction.walking.fourier import FourierTrajectory

GRID = 400
"""Points per period the limits are held at during the design (checked at every sample afterwards)."""
MAX_ITER = 80
"""SLSQP's iterations per start (the epigraph's ``s`` settles within a few tens)."""
SHRINK = 0.8
"""What the velocity share is multiplied by when a design asks more torque than allowed."""


@dataclass(frozen=True)
class ExciteOptions:
    """What ``excite`` designs (module docstring).

    Attributes:
        duration: the recording [s]; rate: its samples per second [Hz] (the noise's bandwidth).
        period: the Fourier series' period [s] (the recording holds ``duration / period`` of them, whole).
        harmonics: ``L`` per joint.
        range_share: share of each joint's position range the motion may use, centred (1: up to the limits).
        velocity_share: share of each joint's velocity limit it may reach.
        torque_share: share of each joint's torque limit the motion may ask.
        asked: the parameters each joint's motion must determine (a family's names, ``tau_os``).
        starts: seeded starts of each joint's design; seed: their seed.
    """

    duration: float = 30.0
    rate: float = ARM_RATE
    period: float = ARM_PERIOD
    harmonics: int = 6
    range_share: float = 0.9
    velocity_share: float = 0.8
    torque_share: float = 0.8
    asked: tuple[str, ...] = FRICTION_READ
    starts: int = 2
    seed: int = 0

    def __post_init__(self) -> None:
        if not self.rate > 0:
            raise InputError(f"--rate {self.rate:g}: a rate is > 0 Hz")
        if not self.period * self.rate > 2 * self.harmonics:  # a NaN too
            raise InputError(f"--period {self.period:g}: its series' highest harmonic ({self.harmonics} per period) "
                             f"must lie below half the rate ({self.rate:g} Hz): a period over "
                             f"{2 * self.harmonics / self.rate:g} s")
        cycles = self.duration / self.period if self.period > 0 else np.nan
        if not (np.isfinite(cycles) and cycles >= 1 and abs(cycles - round(cycles)) < 1e-9):
            raise InputError(f"--period {self.period:g}: the recording of {self.duration:g} s must hold a whole "
                             "number of periods (at least one), so that it ends at rest where it started")
        for name in ("range_share", "velocity_share", "torque_share"):
            if not 0 < getattr(self, name) <= 1:
                raise InputError(f"--{name.replace('_', '-')} {getattr(self, name)!r} is not a share in (0, 1]")

    @property
    def omega(self) -> float:
        """The fundamental [rad/s]."""
        return 2.0 * np.pi / self.period

    def times(self) -> np.ndarray:
        """The recording's sample times (N,) [s]."""
        return np.arange(int(round(self.duration * self.rate))) / self.rate


@dataclass(frozen=True)
class ExcitationDesign:
    """A designed excitation and what it is predicted to determine.

    Attributes:
        robot: the robot's name; joints: the joints designed (the robot's actuated order).
        trajectory: each joint's series (n joints).
        options: what was designed.
        bound: per joint, each parameter's Cramér-Rao bound [its unit] on the designed motion.
        shares: per joint, each asked parameter's ``rho`` (:func:`~.information.limit_shares`): below 1, ``ok``
            at best.
        margins: how far inside its limits the motion stays (a held joint's: 1 for its velocity, its posture's
            distance to its limits for its position).
        prior: per joint, the friction the bounds are taken at.
        moving: the joints the design moves (``bound`` and ``shares`` are theirs); the others are held.
    """

    robot: str
    joints: tuple[str, ...]
    trajectory: FourierTrajectory
    options: ExciteOptions
    bound: dict[str, dict[str, float]]
    shares: dict[str, dict[str, float]]
    margins: Margins
    prior: dict[str, ModelParamsBase] = field(repr=False)
    moving: tuple[str, ...] = ()

    def worst(self) -> float:
        """The largest ``rho`` of any joint and parameter asked."""
        return max(max(s.values()) for s in self.shares.values())


def _grid(options: ExciteOptions) -> np.ndarray:
    return np.linspace(0.0, options.period, GRID, endpoint=False)


def _joint_objective(space: FourierSpace, options: ExciteOptions, params: ModelParamsBase, noise: NoiseModel):
    """``log rho`` of the asked parameters for a joint's variables: the information of one period times the
    periods recorded (the motion repeats: the bound falls as the square root of their number)."""
    t = np.arange(int(round(options.period * options.rate))) / options.rate
    periods = options.duration / options.period

    def log_shares(z: np.ndarray) -> np.ndarray:
        _, qd, _ = joint_series(space, z, t)
        bound = {n: b / np.sqrt(periods) for n, b in torque_bound(params, qd, noise).items()}
        rho = limit_shares(bound, params, options.asked)
        return np.log(np.where(np.isfinite(rho), rho, 1e12))
    return log_shares


def design_joint(space: FourierSpace, options: ExciteOptions, lower: float, upper: float, velocity: float,
                 params: ModelParamsBase, noise: NoiseModel, rng: np.random.Generator) -> np.ndarray:
    """One torque-measured joint's free variables (2 L - 1,) (module docstring): within ``[lower, upper]`` [rad]
    (its range's :attr:`~ExciteOptions.range_share`, centred) and ``velocity`` [rad/s] (the share of its limit)."""
    from scipy.optimize import minimize

    grid = _grid(options)
    log_shares = _joint_objective(space, options, params, noise)
    middle, half = 0.5 * (lower + upper), 0.5 * (upper - lower)

    def limits(y: np.ndarray) -> np.ndarray:
        q, qd, _ = joint_series(space, y[:-1], grid)
        return np.concatenate([q - lower, upper - q, velocity - np.abs(qd)])

    constraints = [{"type": "ineq", "fun": lambda y: y[-1] - log_shares(y[:-1])}, {"type": "ineq", "fun": limits}]
    best = None
    for _ in range(options.starts):
        z0 = np.concatenate([[middle], rng.normal(scale=0.3 * velocity / space.harmonics,
                                                  size=space.per_joint - 1)])
        z0 = _inside(space, z0, middle, half, velocity, grid)
        y0 = np.concatenate([z0, [float(np.max(log_shares(z0)))]])
        res = minimize(lambda y: y[-1], y0, constraints=constraints, method="SLSQP",
                       options={"maxiter": MAX_ITER, "ftol": 1e-4})
        y = res.x if np.all(limits(res.x) >= -1e-6) else y0
        score = float(np.max(log_shares(y[:-1])))
        if best is None or score < best[0]:
            best = (score, y[:-1])
    assert best is not None
    return best[1]


def _inside(space: FourierSpace, z: np.ndarray, middle: float, half: float, velocity: float,
            grid: np.ndarray) -> np.ndarray:
    """``z`` scaled about its centre ``middle`` so that its motion stays within ``middle +- half`` and
    ``velocity``."""
    q, qd, _ = joint_series(space, z, grid)
    scale = min(1.0, half / max(np.abs(q - z[0]).max() + abs(z[0] - middle), 1e-12),
                velocity / max(np.abs(qd).max(), 1e-12))
    return np.concatenate([[middle], z[1:] * scale])


def design_excitation(robot: Robot, prior: Mapping[str, ModelParamsBase], noise: Mapping[str, NoiseModel],
                      options: ExciteOptions = ExciteOptions(), progress: Progress | None = None,
                      moving: Collection[str] | None = None) -> ExcitationDesign:
    """The excitation of every actuated joint of a fixed-base robot whose torque is measured (module docstring).

    Args:
        robot: a fixed-base robot.
        prior: per joint, the friction expected (the bounds' point: a fit, or a guess).
        noise: per joint, its friction estimate's noise (the torque's and the positions', its inertia, the period).
        options: :class:`ExciteOptions`.
        progress: told of each joint designed (once: a design shrunk to fit the torque limits is not told again).
        moving: the joints to move (None: every one); the others are held at the middle of their range (module
            docstring).

    Raises:
        InputError: a floating-base robot, a joint without prior or noise, or without limits
            (:meth:`~.limits.JointLimits.of`); a parameter asked for that its prior's family has not; ``moving``
            empty or naming a joint the robot does not actuate.
    """
    if robot.floating_base:
        raise InputError(f"robot '{robot.name}' has a floating base: excite designs a fixed-base robot's motion here")
    missing = [j for j in robot.actuated if j not in prior or j not in noise]
    if missing:
        raise InputError(f"no prior friction or noise for joint '{missing[0]}' of robot '{robot.name}'")
    for j in robot.actuated:
        unknown = [p for p in options.asked if p != "tau_os" and p not in type(prior[j]).names]
        if unknown:
            raise InputError(f"--asked {unknown[0]}: not a parameter of joint '{j}''s {prior[j].model} prior")
    moved = robot.actuated if moving is None else tuple(j for j in robot.actuated if j in set(moving))
    unknown = sorted(set(moving or ()) - set(robot.actuated))
    if unknown or not moved:
        raise InputError(f"robot '{robot.name}': " + (f"no actuated joint '{unknown[0]}' to move" if unknown
                                                       else "no joint to move"))
    limits = JointLimits.of(robot)
    space = FourierSpace(1, options.harmonics, options.omega)
    share = options.velocity_share
    for attempt in range(4):  # a design shrunk to fit the torque limits is designed again, its joints not told again
        design = _design(robot, prior, noise, options, limits, space, share, progress if attempt == 0 else None,
                         moved)
        if design.margins.torque.min() >= 1.0 - options.torque_share:
            return design
        share *= SHRINK
    raise InputError(f"the design asks more than {options.torque_share:.0%} of a torque limit even at "
                     f"{share / SHRINK:.0%} of the velocity limits: lower --velocity-share or --range-share")


def _design(robot: Robot, prior: Mapping[str, ModelParamsBase], noise: Mapping[str, NoiseModel],
            options: ExciteOptions, limits: JointLimits, space: FourierSpace, share: float,
            progress: Progress | None, moving: tuple[str, ...]) -> ExcitationDesign:
    rng = np.random.default_rng(options.seed)
    middle, half = 0.5 * (limits.lower + limits.upper), 0.5 * (limits.upper - limits.lower) * options.range_share
    z = []
    for i, joint in enumerate(robot.actuated):
        if joint not in moving:  # held at the middle of its range: a constant series
            z.append(np.concatenate([[middle[i]], np.zeros(space.per_joint - 1)]))
            continue
        z.append(design_joint(space, options, middle[i] - half[i], middle[i] + half[i], share * limits.velocity[i],
                              prior[joint], noise[joint], rng))
        if progress is not None:
            progress(1)
    full = FourierSpace(len(robot.actuated), options.harmonics, options.omega)
    trajectory = full.trajectory(np.concatenate(z))
    q, qd, qdd = trajectory(options.times())
    tau = inverse_dynamics(robot, q, qd, qdd, prior)
    bound = {j: torque_bound(prior[j], qd[:, i], noise[j]) for i, j in enumerate(robot.actuated) if j in moving}
    shares = {j: dict(zip(options.asked, map(float, limit_shares(bound[j], prior[j], options.asked))))
              for j in moving}
    return ExcitationDesign(robot.name, robot.actuated, trajectory, options, bound, shares,
                            margins(limits, q, qd, tau), dict(prior), moving)
