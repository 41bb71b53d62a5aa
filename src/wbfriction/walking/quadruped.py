"""A quadruped's gait reference: contact pattern, base motion, swing feet and leg IK (issue 56).

Four gaits (:data:`Gait`), the feet in :attr:`Robot.contact_frames <wbfriction.model.robot.Robot.contact_frames>`
order, each leg told front/rear and left/right by its foot's place in the base frame at the robot's reference
configuration:

* ``stand``: four feet down, the base swaying in height, roll, pitch and sideways, each motion a chirp of its own
  (slow to fast), so that every joint moves both ways at speeds from zero to several rad/s;
* ``step``: a trot in place, diagonal pairs alternating (front left with rear right);
* ``trot``: the same, moving forward at ``speed``;
* ``walk``: a crawl, one leg swinging at a time (rear left, front left, rear right, front right), three feet down
  (four between swings), the base swaying sideways away from the swinging side so that the zero-moment point stays
  inside the triangle of the stance feet (crossing the middle while four feet are down).

The gaits start with every foot down for half a period, the forward speed ramping up (minimum jerk) over the first
period of swings. A swing runs from the foot's last footprint to the next (under its hip at the middle of the
next stance, the nominal path's, without the sway), horizontally by a minimum-snap profile, vertically by a bump
``h 256 s^4 (1 - s)^4`` (zero velocity, acceleration and jerk at lift-off and touch-down), with a sideways bump of its
own; each swing's height and sideways bump are drawn from ``seed`` (0.6-1.4 times ``step_height``, -0.02 to
0.03 m outwards) so that no two steps move the joints alike. The base sways in every gait (height, roll, pitch;
sums of sines of their own frequencies, phases from ``seed``).

The feet start at their places in the robot's reference configuration, moved together along the base so that
their centre (the diagonals' crossing) lies under the centre of mass. A foot's planned position is its contact
frame's origin (a foot sphere's centre), at the robot's ``foot_radius`` (:func:`foot_sphere`; the Go2's
:data:`FOOT_RADIUS` where its TOML gives none) above the ground while it stands. A stance foot does not move, and
the base pose is planned; the leg joints follow by inverse kinematics (Newton iterations per sample, from the
previous sample's angles), their velocities from ``J v = pd`` and accelerations from ``J a = pdd - Jd v``
(Pinocchio's ``LOCAL_WORLD_ALIGNED`` Jacobians of the feet), all analytic: the reference ``(q, v, a)`` keeps every
stance foot still to machine precision at the acceleration level.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, get_args

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError, ModelError, OptionError
from wbfriction.model.robot import Robot

Gait = Literal["stand", "step", "trot", "walk"]
"""The gaits :func:`quadruped_reference` plans (module docstring)."""
GAITS: tuple[Gait, ...] = get_args(Gait)
FOOT_RADIUS = 0.023
"""Height of a standing foot's contact frame above the ground [m]: the Go2's foot sphere's radius (its collision
mesh reaches 0.0229 m below the frame; the SRDF's standing posture puts the frames 0.0226 m up)."""
LWA = pin.LOCAL_WORLD_ALIGNED


def foot_sphere(robot: Robot) -> float:
    """A standing foot's contact frame's height above the ground [m]: the robot's ``foot_radius`` where its TOML
    gives one, else :data:`FOOT_RADIUS` (the Go2's, the built-in ``go2_walking``'s)."""
    return robot.foot_radius or FOOT_RADIUS


_PERIOD = {"stand": 0.5, "step": 0.5, "trot": 0.5, "walk": 1.2}
_SPEED = {"stand": 0.0, "step": 0.0, "trot": 0.2, "walk": 0.1}
_CRAWL = (("rear", "left"), ("front", "left"), ("rear", "right"), ("front", "right"))
"""The crawl's swing order."""


@dataclass(frozen=True)
class GaitOptions:
    """A quadruped's gait (module docstring).

    Attributes:
        gait: :data:`Gait`.
        duration: [s].
        dt: the reference's (and the log's) sample period [s].
        period: the gait cycle [s]; None: 0.5 (stand, step, trot) or 1.2 (walk). Set after construction.
        step_height: a swing's mean height [m].
        speed: forward speed [m/s]; None: 0.2 (trot), 0.1 (walk), 0 (stand, step). Set after construction.
        base_height: the base (root joint) origin's mean height above the ground [m] (a Go2 stands at ~0.30).
        seed: the swings' heights and bumps and the sway's phases.
        scale: the robot's length scale against the Go2's (:mod:`wbfriction.walking.scale`): the sway's and the
            swings' sideways amplitudes [m] are the Go2's times it (``simulate`` sets it with the heights).

    Raises:
        OptionError: an unknown gait, a duration shorter than two samples, a period, dt or height not > 0, a
            ``step`` or ``stand`` with a forward speed.
    """

    gait: Gait = "trot"
    duration: float = 8.0
    dt: float = 0.002
    period: float = field(default=None)  # type: ignore[assignment]
    step_height: float = 0.06
    speed: float = field(default=None)  # type: ignore[assignment]
    base_height: float = 0.30
    seed: int = 0
    scale: float = 1.0

    def __post_init__(self) -> None:
        if self.gait not in GAITS:
            raise OptionError("--gait", self.gait, f"one of {', '.join(GAITS)}")
        if self.period is None:
            object.__setattr__(self, "period", _PERIOD[self.gait])
        if self.speed is None:
            object.__setattr__(self, "speed", _SPEED[self.gait])
        for name in ("dt", "period", "base_height", "duration", "scale"):
            if not float(getattr(self, name)) > 0:
                raise OptionError(f"--{name.replace('_', '-')}", getattr(self, name), "> 0")
        if self.step_height < 0:
            raise OptionError("--step-height", self.step_height, ">= 0 [m]")
        if self.gait in ("stand", "step") and self.speed != 0:
            raise OptionError("--speed", self.speed, f"0 for the gait '{self.gait}' (it stays in place)")
        if round(self.duration / self.dt) < 2:
            raise OptionError("--duration", self.duration, f"at least two samples of {self.dt:g} s")


@dataclass
class QuadrupedReference:
    """A quadruped's planned gait sampled every ``options.dt`` (module docstring).

    Attributes:
        options: the gait's options.
        time: sample times (N,) [s], from 0.
        contact: planned contact flags (N, 4) bool, feet in ``robot.contact_frames`` order (True: on the ground).
        base: planned base pose (N, 7): position [m] and orientation quaternion (x, y, z, qx, qy, qz, qw), world.
        feet: planned foot (contact frame origin) positions (N, 4, 3) [m], world; a stance foot's is its footprint.
        q: joint angles (N, n_act) [rad], :attr:`Robot.actuated` order.
        qd: joint velocities (N, n_act) [rad/s].
        qdd: joint accelerations (N, n_act) [rad/s^2].
        base_v: the base's twist (N, 6), Pinocchio's free-flyer velocity ``v[:6]`` (linear, angular; base frame)
            [m/s, rad/s].
        base_a: its derivative (N, 6), the free-flyer's ``a[:6]`` [m/s^2, rad/s^2].
        feet_v, feet_a: the feet's planned velocities [m/s] and accelerations [m/s^2] (N, 4, 3), world.
    """

    options: GaitOptions
    time: np.ndarray
    contact: np.ndarray
    base: np.ndarray
    feet: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    base_v: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))
    base_a: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))
    feet_v: np.ndarray = field(default_factory=lambda: np.zeros((0, 4, 3)))
    feet_a: np.ndarray = field(default_factory=lambda: np.zeros((0, 4, 3)))

    def __len__(self) -> int:
        return len(self.time)

    @property
    def dt(self) -> float:
        """The sample period [s]."""
        return self.options.dt

    def full(self, robot: Robot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The whole-body reference of ``robot``: configurations (N, nq), velocities and accelerations (N, nv)."""
        q = robot.configuration(self.q, self.base)
        v = np.zeros((len(self), robot.model.nv))
        a = np.zeros_like(v)
        v[:, :6], a[:, :6] = self.base_v, self.base_a
        v[:, robot.act_v_index], a[:, robot.act_v_index] = self.qd, self.qdd
        return q, v, a


# ------------------------------------------------------------------ analytic pieces: value, rate, its rate
def _wave(t: np.ndarray, amplitude: float, f0: float, f1: float, phase: float, span: float
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``amplitude sin(phi)``, its first and second time derivatives, ``phi`` a linear chirp from ``f0`` to ``f1``
    [Hz] over ``span`` [s] starting at ``phase``."""
    w0, dw = 2.0 * np.pi * f0, 2.0 * np.pi * (f1 - f0) / span
    phi = phase + w0 * t + 0.5 * dw * t**2
    rate = w0 + dw * t
    s, c = np.sin(phi), np.cos(phi)
    return amplitude * s, amplitude * c * rate, amplitude * (c * dw - s * rate**2)


def _min_jerk(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``10 s^3 - 15 s^4 + 6 s^5`` on [0, 1] (0 before, 1 after) and its derivatives in ``s``."""
    s = np.clip(s, 0.0, 1.0)
    return (s**3 * (10 - 15 * s + 6 * s**2), 30 * s**2 * (1 - s) ** 2, 60 * s * (1 - s) * (1 - 2 * s))


def _min_snap(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``35 s^4 - 84 s^5 + 70 s^6 - 20 s^7`` on [0, 1] (0 before, 1 after; zero velocity, acceleration and jerk at
    both ends) and its derivatives in ``s``."""
    s = np.clip(s, 0.0, 1.0)
    u = 1 - s
    return s**4 * (35 - 84 * s + 70 * s**2 - 20 * s**3), 140 * s**3 * u**3, 420 * s**2 * u**2 * (u - s)


def _bump(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``256 s^4 (1 - s)^4`` (1 at s = 1/2, 0 outside [0, 1]; zero velocity, acceleration and jerk at both ends)
    and its derivatives in ``s``."""
    s = np.clip(s, 0.0, 1.0)
    u = 1 - s
    return 256 * s**4 * u**4, 1024 * s**3 * u**3 * (u - s), 1024 * s**2 * u**2 * (3 * (u - s) ** 2 - 2 * s * u)


def _ramp_path(t: np.ndarray, speed: float, start: float, length: float
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distance, speed and acceleration of a start at rest ramping (minimum jerk) to ``speed`` over
    ``[start, start + length]``."""
    s = np.clip((t - start) / length, 0.0, 1.0)
    r, dr, _ = _min_jerk(s)
    integral = length * s**4 * (2.5 - 3 * s + s**2) + np.maximum(t - start - length, 0.0)
    return speed * integral, speed * r, speed * dr / length


# ------------------------------------------------------------------ the plan
@dataclass
class _Swing:
    leg: int
    start: float
    end: float
    height: float
    bump: float  # sideways, outwards [m]


def _legs(robot: Robot) -> tuple[np.ndarray, list[tuple[str, str]]]:
    """Each foot's home in the base frame (4, 3): its position at the reference configuration, all four moved
    forwards or backwards together so that their centre lies under the centre of mass; and its (front|rear,
    left|right).

    Raises:
        ModelError: a robot without four contact frames, one on each corner.
    """
    if len(robot.contact_frames) != 4 or not robot.floating_base:
        raise ModelError(f"robot '{robot.name}': a quadruped's gait needs a floating base and four contact frames, "
                         f"got {len(robot.contact_frames)}")
    q = robot.configuration(robot.reference_angles)
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    base = np.array([data.oMf[f].translation for f in robot.contact_frame_ids]) - q[:3]
    # the footprints centred under the centre of mass: the diagonals cross beneath it (a trot's balance)
    base[:, 0] += pin.centerOfMass(robot.model, data, q)[0] - q[0] - base[:, 0].mean()
    corners = [("front" if x > 0 else "rear", "left" if y > 0 else "right") for x, y, _ in base]
    if len(set(corners)) != 4:
        raise ModelError(f"robot '{robot.name}': its four feet are not one on each corner of the base: {corners}")
    return base, corners


def _swings(options: GaitOptions, corners: list[tuple[str, str]], rng: np.random.Generator) -> list[_Swing]:
    """The swings of the gait, in time order (module docstring)."""
    if options.gait == "stand":
        return []
    T, start = options.period, 0.5 * options.period
    if options.gait == "walk":
        groups = [[corners.index(c)] for c in _CRAWL]
        # four feet down for T/12 where the base crosses from one side to the other, T/60 between the two swings
        # of a side
        length, gap, cross = 0.2 * T, T / 60, T / 12
        offsets = [0.5 * cross, 0.5 * cross + length + gap, 0.5 * (T + cross), 0.5 * (T + cross) + length + gap]
    else:  # diagonal pairs: front left with rear right, then front right with rear left
        groups = [[corners.index(("front", "left")), corners.index(("rear", "right"))],
                  [corners.index(("front", "right")), corners.index(("rear", "left"))]]
        length = T / 2
        offsets = [0.0, T / 2]
    out: list[_Swing] = []
    cycle = 0
    end = options.duration - 0.5 * T  # every foot down for the last half period
    while True:
        for group, offset in zip(groups, offsets):
            t0 = start + cycle * T + offset
            if t0 + length > end:
                return out
            for leg in group:
                out.append(_Swing(leg, t0, t0 + length, options.step_height * rng.uniform(0.6, 1.4),
                                  rng.uniform(-0.02 * options.scale, 0.03 * options.scale)))
        cycle += 1


def _base_motion(t: np.ndarray, options: GaitOptions, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """The base's position (3, N, 3) and roll-pitch (3, N, 2) [m, rad], each value, rate and its rate (module
    docstring); the nominal path (no sway) is the position's x."""
    T, D = options.period, options.duration
    pos, rp = np.zeros((3, len(t), 3)), np.zeros((3, len(t), 2))
    pos[:, :, 0] = np.array(_ramp_path(t, options.speed, 0.5 * T, T))
    pos[0, :, 2] = options.base_height
    if options.gait == "stand":  # chirps, each axis its own frequencies [m or rad, Hz, Hz]
        waves = [(pos, 2, 0.035, 0.15, 1.3), (pos, 1, 0.03, 0.1, 1.3), (pos, 0, 0.03, 0.12, 1.1),
                 (rp, 0, 0.15, 0.13, 1.6), (rp, 1, 0.12, 0.11, 1.0)]
    else:
        waves = [(pos, 2, 0.012, 0.71, 0.71), (rp, 0, 0.05, 0.43, 0.43), (rp, 1, 0.04, 0.57, 0.57)]
        if options.gait != "walk":
            waves.append((pos, 1, 0.01, 0.31, 0.31))
    for arr, axis, amplitude, f0, f1 in waves:  # lengths the Go2's times the scale, angles as they are
        amplitude *= options.scale if arr is pos else 1.0
        arr[:, :, axis] += np.array(_wave(t, amplitude, f0, f1, rng.uniform(0, 2 * np.pi), D))
    if options.gait == "walk":
        pos[:, :, 1] += _crawl_shift(t, T, 0.06 * options.scale)
    return pos, rp


def _crawl_shift(t: np.ndarray, T: float, amplitude: float) -> np.ndarray:
    """The crawl's sideways shift of the base (3, N) [m] (value, rate, its rate): ``-A sin(2 pi (t - T/2) / T)``,
    right while the left legs swing (the first half of each cycle), left while the right ones do, crossing the middle
    while four feet are down; faded in over the first half period. A sine: its zero-moment point moves with it,
    ``1 + (2 pi / T)^2 z / g`` times as far (a higher harmonic's would move against it)."""
    out = np.array(_wave(t, -amplitude, 1 / T, 1 / T, -np.pi, 1.0))
    fade = np.array(_min_jerk((t - 0.1 * T) / (0.4 * T)))
    fade[1:] /= np.array([[0.4 * T], [(0.4 * T) ** 2]])
    return np.array([out[0] * fade[0], out[1] * fade[0] + out[0] * fade[1],
                     out[2] * fade[0] + 2 * out[1] * fade[1] + out[0] * fade[2]])


def _orientation(rp: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rotation matrices (N, 3, 3) of roll-pitch (yaw 0: ``R = Ry(pitch) Rx(roll)``), world angular velocities and
    accelerations (N, 3), from ``rp`` (3, N, 2): value, rate, its rate."""
    (r, p), (dr, dp), (ddr, ddp) = rp[0].T, rp[1].T, rp[2].T
    cr, sr, cp, sp = np.cos(r), np.sin(r), np.cos(p), np.sin(p)
    zero = np.zeros_like(r)
    R = np.stack([np.stack([cp, sp * sr, sp * cr], -1), np.stack([zero, cr, -sr], -1),
                  np.stack([-sp, cp * sr, cp * cr], -1)], -2)
    omega = np.stack([dr * cp, dp, -dr * sp], -1)
    domega = np.stack([ddr * cp - dr * dp * sp, ddp, -ddr * sp - dr * dp * cp], -1)
    return R, omega, domega


def _feet(t: np.ndarray, options: GaitOptions, swings: list[_Swing], home: np.ndarray, nominal_x: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray]:
    """The feet's planned positions (3, N, 4, 3) (value, rate, its rate) and contact flags (N, 4), from each
    foot's home (4, 3) (its footprint at the start, the base at the origin) and the nominal path's x (N,)."""
    feet = np.zeros((3, len(t), 4, 3))
    feet[0] = home
    contact = np.ones((len(t), 4), dtype=bool)
    footprint = home.copy()
    stance = options.period - (swings[0].end - swings[0].start) if swings else 0.0
    for sw in swings:  # in time order: each swing writes the samples after its lift-off
        target = home[sw.leg] + [float(np.interp(sw.end + 0.5 * stance, t, nominal_x)), 0.0, 0.0]
        contact[(t > sw.start) & (t < sw.end), sw.leg] = False
        after = t > sw.start
        L = sw.end - sw.start
        s = (t[after] - sw.start) / L
        m, b = np.array(_min_snap(s)), np.array(_bump(s))  # (3, n): value, d/ds, d2/ds2
        scale = np.array([1.0, 1.0 / L, 1.0 / L**2])[:, None]
        path = (target - footprint[sw.leg])[None, None, :] * (m * scale)[:, :, None]
        path[0] += footprint[sw.leg]
        path[:, :, 2] += sw.height * b * scale
        path[:, :, 1] += np.sign(home[sw.leg, 1]) * sw.bump * b * scale
        feet[:, after, sw.leg] = path
        footprint[sw.leg] = target
    return feet, contact


def quadruped_reference(robot: Robot, options: GaitOptions = GaitOptions()) -> QuadrupedReference:
    """Plan a quadruped's gait (module docstring).

    Args:
        robot: a floating-base robot with four contact frames (feet), one on each corner of its base, and a
            reference configuration (the IK's first guess: its knees' bend is kept).
        options: :class:`GaitOptions`.

    Returns:
        :class:`QuadrupedReference` of ``round(duration / dt)`` samples.

    Raises:
        ModelError: a robot that is not such a quadruped.
        InputError: a foot out of its leg's reach (the IK does not converge).
    """
    n = int(round(options.duration / options.dt))
    t = np.arange(n) * options.dt
    rng = np.random.default_rng(options.seed)
    offsets, corners = _legs(robot)
    home = offsets.copy()
    home[:, 2] = foot_sphere(robot)
    swings = _swings(options, corners, rng)
    pos, rp = _base_motion(t, options, rng)
    R, omega, domega = _orientation(rp)
    feet, contact = _feet(t, options, swings, home, pos[0, :, 0])
    base = np.empty((n, 7))
    base[:, :3] = pos[0]
    base[:, 3:] = [pin.Quaternion(r).coeffs() for r in R]
    # Pinocchio's free-flyer velocity and acceleration: the base frame's twist and its derivative
    base_v, base_a = np.empty((n, 6)), np.empty((n, 6))
    base_v[:, :3] = np.einsum("nji,nj->ni", R, pos[1])
    base_v[:, 3:] = np.einsum("nji,nj->ni", R, omega)
    base_a[:, :3] = np.einsum("nji,nj->ni", R, pos[2]) - np.cross(base_v[:, 3:], base_v[:, :3])
    base_a[:, 3:] = np.einsum("nji,nj->ni", R, domega)
    q, qd, qdd = _leg_ik(robot, base, base_v, base_a, feet, _reach_remedy(options))
    return QuadrupedReference(options, t, contact, base, feet[0].copy(), q, qd, qdd, base_v, base_a, feet[1].copy(),
                              feet[2].copy())


def _reach_remedy(options: GaitOptions) -> str:
    """What to change when the gait puts a foot out of its leg's reach, as the error says it: the speed (the command
    line's --speed), the heights where not the defaults (fields of :class:`GaitOptions` alone), else the robot."""
    remedies = [f"lower --speed ({options.speed:g} m/s)"] if options.speed > 0 else []
    if (options.base_height, options.step_height) != (GaitOptions.base_height, GaitOptions.step_height):
        remedies.append(f"lower base_height ({options.base_height:g} m) or step_height ({options.step_height:g} m)")
    return " or ".join(remedies) or (f"its legs do not reach the ground {options.base_height:g} m below its base with "
                                     f"swings {options.step_height:g} m high")


def _leg_ik(robot: Robot, base: np.ndarray, base_v: np.ndarray, base_a: np.ndarray, feet: np.ndarray, remedy: str,
            iterations: int = 20, tol: float = 1e-12) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The leg joints' angles, velocities and accelerations (N, n_act) putting the feet at ``feet`` (3, N, 4, 3)
    with the base at ``base`` (N, 7), moving by ``base_v``, ``base_a`` (N, 6) (module docstring); ``remedy``: what
    the error says to change where a foot is out of reach."""
    model, data = robot.model, robot.model.createData()
    n = len(base)
    legs = [np.array([robot.model.idx_vs[robot.model.getJointId(j)] for j in robot.limb(f)])
            for f in robot.contact_frames]
    if any(len(cols) != 3 for cols in legs):
        raise ModelError(f"robot '{robot.name}': each leg needs three joints between the base and its foot")
    iq, iv = robot.act_q_index, robot.act_v_index
    q = robot.configuration(robot.reference_angles)
    Q, V, A = np.empty((n, model.nq)), np.zeros((n, model.nv)), np.zeros((n, model.nv))
    zero = np.zeros(model.nv)
    for k in range(n):
        q[:7] = base[k]
        for _ in range(iterations):
            pin.computeJointJacobians(model, data, q)
            pin.updateFramePlacements(model, data)
            err = [feet[0, k, c] - data.oMf[f].translation for c, f in enumerate(robot.contact_frame_ids)]
            if max(np.abs(e).max() for e in err) < tol:
                break
            dq = np.zeros(model.nv)
            for c, f in enumerate(robot.contact_frame_ids):
                J = pin.getFrameJacobian(model, data, f, LWA)[:3, legs[c]]
                dq[legs[c]] = np.linalg.solve(J, err[c])
            q = pin.integrate(model, q, dq)
        else:
            raise InputError(f"the gait puts a foot of robot '{robot.name}' out of its leg's reach at "
                             f"sample {k}: {remedy}")
        v, a = zero.copy(), zero.copy()
        v[:6], a[:6] = base_v[k], base_a[k]
        pin.forwardKinematics(model, data, q, v, a)  # the base's motion alone: the legs' share below
        for c, f in enumerate(robot.contact_frame_ids):
            J = pin.getFrameJacobian(model, data, f, LWA)[:3]
            v[legs[c]] = np.linalg.solve(J[:, legs[c]], feet[1, k, c] - J[:, :6] @ base_v[k])
        pin.forwardKinematics(model, data, q, v, a)
        for c, f in enumerate(robot.contact_frame_ids):
            J = pin.getFrameJacobian(model, data, f, LWA)[:3]
            drift = pin.getFrameClassicalAcceleration(model, data, f, LWA).linear  # J a + Jd v, legs' a = 0
            a[legs[c]] = np.linalg.solve(J[:, legs[c]], feet[2, k, c] - drift)
        Q[k], V[k], A[k] = q, v, a
    return Q[:, iq], V[:, iv], A[:, iv]
