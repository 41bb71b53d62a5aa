"""The ideal simulator of a walking quadruped (issue 56): point feet welded while they stand, friction injected.

The robot (the built-in ``go2_walking``: any floating-base robot with four point feet) follows a
:class:`~wbfriction.walking.quadruped.QuadrupedReference`. Each physics step (``physics_dt``) solves the constrained
forward dynamics with ``pin.constraintDynamics``: every foot in contact is a point (``CONTACT_3D``, its frame's origin
welded at its planned footprint, ``LOCAL_WORLD_ALIGNED``, Baumgarte correction):

.. math::

    M(q)\\,\\dot v + h(q, v) = S^T (\\tau + \\tau_f) + \\sum_c J_c^T \\lambda_c, \\qquad J_c \\dot v + \\dot J_c v = 0,
    \\qquad \\tau_f = -f(\\dot q)

with ``M`` holding the robot's armature, ``lambda_c`` (3,) the ground's force on foot ``c`` in world axes [N] and
the friction of each joint its own (:func:`default_quadruped_friction`), from the velocity at the step's start. At
touch-down the landing foot is anchored at its planned footprint and the configuration projected onto the anchors
(the least motion that puts the feet there: it snaps by its tracking error at that sample); at every logged sample
the velocity is projected onto the contacts (``pin.impulseDynamics``: the plastic impact at touch-down, the
integration's drift otherwise), so that the logged state satisfies ``J_c v = 0`` exactly. Semi-implicit Euler:
``v+ = v + h a``, ``q+ = q (+) h v+``.

**The controller** runs at the log rate, on the true state: the balance controller of
:mod:`wbfriction.sim.quadruped_control` (whole-body inverse dynamics: the base's pose, the swing feet, the posture;
two point feet exert no moment about the line between them, so that a feed-forward of the reference's inverse
dynamics plus joint PD lets a trot tip over), plus the friction of the reference's velocities (the controller
knows its robot's friction model; ``compensate``). Two drives:

* ``torque``: the motors apply ``tau = tau_c + kp (q_des - q) + kd (qd_des - qd)`` held over the period (``tau_c``
  the controller's torque, ``q_des``, ``qd_des`` its joint set-points: the reference's on a stance leg, on a swing
  leg those that put the foot on its reference from where the base is,
  :meth:`~wbfriction.sim.quadruped_control.BalanceController.leg_setpoints`; the log's ``tau``: the joint torque
  sensors sit before the friction: the command). With more than one physics step per period, the first step of
  each period (the switch at ``t_k``) takes the mean of the previous and the new command (the trapezoid rule), so
  that the command acts over ``[t_k, t_k+1)`` as a real robot's zero-order hold (the log's ``torque_alignment =
  "zoh"``, exact to O(h^2)): semi-implicit Euler kicks the velocity at a step's start, and a command applied from the
  period's first step to its last acted over ``[t_k - h/2, t_k+1 - h/2)`` as the positions see it, half a physics
  step early, which put the hips' F_v 3-17 % high on noise-free logs once differentiated (issue 63: an error of
  about ``M omega^2 h / 2`` in F_v). The sample's truth (acceleration, forces) is that of the command itself;
* ``pd``: the robot's motor drivers (``[pd]``, :mod:`wbfriction.model.pd`) are sent the controller's ``q_des`` (in
  the encoder's coordinates), ``qd_des`` and ``tau_ff`` (its torque, their PD on top) at the samples; at every
  physics step they apply the PD law on the encoder's angle and the velocity, clipped at their limits, with each
  set-point as :func:`~wbfriction.model.pd.pd_torque` takes it
  (``setpoints = "model"``: the linear interpolation of the commands at ``t - T/2 - delay``, the box average over
  one period of the held commands, held at the last command arrived where it would need a later one: a driver
  cannot know the next command), so that the law on the logged set-points gives the torque applied at the samples
  exactly (where the delay leaves every command it needs arrived: ``delay mod T <= T/2``, e.g. none); or held from
  their sample and delayed (``setpoints = "held"``, the hung robot's drivers,
  :func:`~wbfriction.sim.pd_robot.step_setpoints`). The log then
  has no ``tau.*`` but ``q_des.*``, ``qd_des.*``, ``tau_ff.*`` and the drivers' velocity ``qd.*``.

**The log** (the project's format, one row per sample, the physics step starting at it): ``q.*``, the torques (per
the drive), ``contact.*`` (the planned flags), the base pose ``base.*`` with its true twist and acceleration
(Pinocchio's free-flyer ``v[:6]``, ``a[:6]``, base frame), the IMU's readings (``imu.*``, if the robot has one:
:func:`~wbfriction.model.imu.imu_readings`), ``tau_f_true.*``, ``qd_true.*`` and ``qdd_true.*`` (the constrained
dynamics' acceleration without its Baumgarte term: the stance feet's acceleration is then zero, as the estimator
assumes), the feet's forces where asked (``force.<frame>.x|y|z``, or the normal ``force.<frame>``: zero in the
air); metadata: the generator, its options, the gait, ``friction_true``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from typing import Any, Literal, get_args

import numpy as np
import pinocchio as pin

from wbfriction.exceptions import InputError, OptionError, SimulationError
from wbfriction.friction.models import FrictionParams, ModelParams
from wbfriction.logs.log import Log
from wbfriction.logs.pd import PdSetpoints
from wbfriction.model.imu import imu_readings
from wbfriction.model.pd import PdDriver, pd_torque
from wbfriction.model.robot import Robot
from wbfriction.progress import Progress, counted
from wbfriction.sim.common import InjectedFriction, injected_friction, require_point_feet
from wbfriction.sim.options import SensorNoise
from wbfriction.sim.pd_robot import joint_values, step_setpoints
from wbfriction.sim.quadruped_control import BalanceController, BalanceGains
from wbfriction.sim.sensors import apply_sensor_noise
from wbfriction.walking.quadruped import QuadrupedReference

GENERATOR = "wbfriction.sim.quadruped.simulate_quadruped"
LWA = pin.LOCAL_WORLD_ALIGNED
Drive = Literal["torque", "pd"]
DRIVES: tuple[Drive, ...] = get_args(Drive)
FootForces = Literal["none", "normal", "3d"]
FOOT_FORCES: tuple[FootForces, ...] = get_args(FootForces)
Setpoints = Literal["model", "held"]
SETPOINTS: tuple[Setpoints, ...] = get_args(Setpoints)
Contacts = Literal["soft", "firm"]
CONTACTS: tuple[Contacts, ...] = get_args(Contacts)


@dataclass(frozen=True)
class QuadrupedOptions:
    """Options of :func:`simulate_quadruped` (module docstring).

    Attributes:
        physics_dt: the physics step [s]; the reference's period must be a whole number of them.
        drive: :data:`Drive`: ``torque`` (torque-controlled motors, torque sensors) or ``pd`` (the robot's motor
            drivers, its ``[pd]``).
        friction: parameters per joint name (joints not named: none); None: :func:`default_quadruped_friction`.
        armature: the drives' reflected inertia per joint [kg·m^2] (joints not named: 0); None: the robot's own.
        noise: the sensors' noise on the logged angles and torques (torque drive only); None: exact.
        foot_forces: :data:`FootForces`: the feet's force columns logged: none, the normal, all three components.
        kp, kd: the torque drive's joint PD gains [N·m/rad, N·m·s/rad] on the controller's torque.
        gains: the balance controller's gains (:class:`~wbfriction.sim.quadruped_control.BalanceGains`).
        baumgarte: (Kp [1/s^2], Kd [1/s]) of the contact constraints.
        setpoints: :data:`Setpoints`: how the PD drivers apply their set-points within a period.
        compensate: the feed-forward holds the friction of the reference's velocities.
        imu: log the IMU's readings (if the robot has an ``[imu]``).
        contacts: :data:`Contacts`: a soft-contact engine's feet on the ground: ``soft`` (the model's own: MuJoCo's
            default, a stance foot creeps about 1.5 cm/s) or ``firm`` (feet that hold:
            :func:`~wbfriction.sim.quadruped_mjcf.firm_contacts`); the ideal simulator's feet are welded (neither).
        seed: recorded (the noise has its own).

    Raises:
        OptionError: a value out of its choices or range.
    """

    physics_dt: float = 0.0005
    drive: Drive = "torque"
    friction: Mapping[str, ModelParams] | None = field(default=None, compare=False)
    armature: Mapping[str, float] | None = None
    noise: SensorNoise | None = None
    foot_forces: FootForces = "none"
    kp: float = 40.0
    kd: float = 1.0
    gains: BalanceGains = BalanceGains()
    baumgarte: tuple[float, float] = (400.0, 40.0)
    setpoints: Setpoints = "model"
    compensate: bool = True
    imu: bool = True
    contacts: Contacts = "soft"
    seed: int = 0

    def __post_init__(self) -> None:
        for name, value, choices in (("--drive", self.drive, DRIVES), ("--foot-forces", self.foot_forces,
                                                                         FOOT_FORCES),
                                     ("--setpoints", self.setpoints, SETPOINTS), ("--contacts", self.contacts,
                                                                                  CONTACTS)):
            if value not in choices:
                raise OptionError(name, value, f"one of {', '.join(choices)}")
        if not self.physics_dt > 0:
            raise OptionError("--physics-dt", self.physics_dt, "> 0 [s]")
        if self.kp < 0 or self.kd < 0:
            raise OptionError("--kp" if self.kp < 0 else "--kd", self.kp if self.kp < 0 else self.kd, ">= 0")
        if self.noise is not None and self.noise.active and self.drive == "pd":
            raise OptionError("--noise", asdict(self.noise), "none with --drive pd (the drivers' noise is not "
                              "simulated yet)")

    def metadata(self) -> dict:
        """The options as the log's metadata records them (the friction apart: ``friction_true``)."""
        out = {k: v for k, v in asdict(self).items() if k != "friction"}
        if self.contacts == "soft":  # the logs written before the option existed: the same bytes
            del out["contacts"]
        out["armature"] = None if self.armature is None else dict(self.armature)
        return out


@dataclass
class QuadrupedRun:
    """A simulated quadruped.

    Attributes:
        log: the log (module docstring).
        reference: the gait followed.
        force: the ground's true force on each foot (N, 4, 3) in world axes [N] (zero in the air), the one that goes
            with the log's true accelerations (Baumgarte term taken off).
        q: the true configurations (N, nq); v: velocities (N, nv); a: accelerations (N, nv) (the log's truth).
        tau_motor: the torque the motors applied at each sample's physics step (N, n_act) [N·m].
        tau_f: the friction applied there (N, n_act) [N·m].
        snap: how far each landing foot was from its footprint at touch-down (the configuration's projection) [m],
            one per touch-down.
    """

    log: Log
    reference: QuadrupedReference
    force: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    tau_motor: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    tau_f: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    snap: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def min_normal_force(self) -> float:
        """The least normal force of a foot in contact [N] (negative: a welded foot pulled on the ground)."""
        normal = self.force[..., 2][self.log.contact]
        return float(normal.min()) if normal.size else float("nan")


def default_quadruped_friction(robot: Robot) -> dict[str, ModelParams]:
    """Friction :func:`simulate_quadruped` injects by default: the thesis's (3.5) without Stribeck effect or offset
    (``F_v qd + F_c tanh(40 qd)``), every joint its own, made up and illustrative (joint ``i`` of ``n``:
    ``F_c = 0.2 + 0.4 ((7 i) mod n) / (n - 1)`` [N·m], ``F_v = 0.05 + 0.25 ((5 i) mod n) / (n - 1)`` [N·m·s/rad]:
    0.2-0.6 and 0.05-0.3, the two orders unlike each other and the joints', so that a joint mixed up with another
    shows); on a robot of another size than the Go2 the same share of its torques, F_c times its torque ratio and F_v
    times its damping ratio (:func:`~wbfriction.walking.scale.robot_scale`: dynamic similarity; the Go2's 1)."""
    from wbfriction.walking.scale import robot_scale

    n = robot.n_act
    span = max(n - 1, 1)
    scale = robot_scale(robot) if robot.floating_base and robot.contact_frames else None
    torque, damping = (1.0, 1.0) if scale is None else (scale.torque, scale.damping)
    return {j: FrictionParams(F_v=round((0.05 + 0.25 * ((5 * i) % n) / span) * damping, 4),
                              F_c=round((0.2 + 0.4 * ((7 * i) % n) / span) * torque, 4), S=0.0, v_s=0.1, tau_os=0.0,
                              a=40.0)
            for i, j in enumerate(robot.actuated)}


def point_constraints(robot: Robot, model: pin.Model, data: pin.Data, active: np.ndarray,
                      anchors: Mapping[int, np.ndarray], baumgarte: tuple[float, float]
                      ) -> tuple[pin.StdVec_RigidConstraintModel, pin.StdVec_RigidConstraintData]:
    """Point contacts (``CONTACT_3D``, ``LOCAL_WORLD_ALIGNED``) holding the ``active`` feet's frame origins at their
    anchors (world positions (3,) [m]), initialised in ``data``."""
    models = pin.StdVec_RigidConstraintModel()
    for c in active:
        fr = model.frames[robot.contact_frame_ids[c]]
        cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, fr.parentJoint, fr.placement, 0,
                                      pin.SE3(np.eye(3), np.asarray(anchors[int(c)], dtype=float)), LWA)
        cm.setBaumgarteCorrectorParameters(pin.BaumgarteCorrectorParameters(*baumgarte))
        models.append(cm)
    datas = pin.StdVec_RigidConstraintData()
    for cm in models:
        datas.append(cm.createData())
    pin.initConstraintDynamics(model, data, models, datas)
    return models, datas


def project_feet(robot: Robot, model: pin.Model, data: pin.Data, q: np.ndarray, active: np.ndarray,
                 anchors: Mapping[int, np.ndarray], iterations: int = 4) -> np.ndarray:
    """``q`` moved by the least motion (base and joints) that puts the ``active`` feet on their anchors
    (Gauss-Newton on the position errors)."""
    ids = [robot.contact_frame_ids[c] for c in active]
    for _ in range(iterations):
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        e = np.concatenate([data.oMf[f].translation - anchors[int(c)] for c, f in zip(active, ids)])
        if np.abs(e).max() < 1e-13:
            break
        J = np.vstack([pin.getFrameJacobian(model, data, f, LWA)[:3] for f in ids])
        q = pin.integrate(model, q, -np.linalg.lstsq(J, e, rcond=None)[0])
    return q


class _Run:
    """One run of :func:`simulate_quadruped`: the model, the commands, the contacts, the state and the buffers."""

    def __init__(self, robot: Robot, reference: QuadrupedReference, options: QuadrupedOptions) -> None:
        self.robot, self.ref, self.options = robot, reference, options
        self.model = robot.model
        if options.armature is not None:  # the robot's model is not changed
            self.model = pin.Model(robot.model)
            self.model.armature[robot.act_v_index] = joint_values(robot, options.armature, {}, "armature")
        self.data = self.model.createData()
        n, dt = len(reference), reference.dt
        self.substeps = int(round(dt / options.physics_dt))
        if self.substeps < 1 or abs(self.substeps * options.physics_dt - dt) > 1e-9 * dt:
            raise OptionError("--physics-dt", options.physics_dt, f"a whole fraction of the log's period {dt:g} s")
        self.h = dt / self.substeps
        friction = default_quadruped_friction(robot) if options.friction is None else options.friction
        self.injected: InjectedFriction = injected_friction(robot, friction, joints=robot.actuated)
        self.iv, self.iq = robot.act_v_index, robot.act_q_index
        self.iv_f = self.iv[self.injected.joints]
        self.controller = BalanceController(robot, self.model, reference, options.gains)
        self.compensation = np.zeros((n, robot.n_act))  # the motors' share against the reference's friction
        if options.compensate and self.injected.joints:
            self.compensation[:, self.injected.joints] = -self.injected.torque(reference.qd[:, self.injected.joints])
        self.Q, self.V, self.A = (np.empty((n, m)) for m in (self.model.nq, self.model.nv, self.model.nv))
        self.force = np.zeros((n, len(robot.contact_frames), 3))
        self.tau_motor, self.tau_f = np.zeros((n, robot.n_act)), np.zeros((n, robot.n_act))
        self.switches = np.flatnonzero(np.any(np.diff(reference.contact, axis=0, prepend=False), axis=1))
        self.active = np.zeros(0, dtype=int)
        self.anchors: dict[int, np.ndarray] = {}
        self.snaps: list[float] = []
        self.settings = pin.ProximalSettings(1e-12, 1e-10, 50)
        q_full, v_full, _ = reference.full(robot)
        self.q, self.v = q_full[0].copy(), v_full[0].copy()
        self.driver: PdDriver | None = None
        self.held: np.ndarray | None = None  # the torque drive's command of the sample
        if options.drive == "pd":
            self._setup_drivers()

    def _setup_drivers(self) -> None:
        """The PD drivers and the buffers of their commands (filled sample by sample)."""
        robot, n = self.robot, len(self.ref)
        if robot.pd is None or robot.pd.joints != robot.actuated:
            raise InputError(f"robot '{robot.name}': --drive pd needs a [pd] table driving every joint "
                             "(wbfriction.model.pd)")
        self.driver = driver = robot.pd
        if driver.delayed == "torque" and driver.delay > 0:
            raise InputError(f"robot '{robot.name}': a driver delaying its whole torque ([pd] delayed = torque) is "
                             "not simulated here yet")
        self.offset = joint_values(robot, None, robot.encoder_offset, "encoder offset")
        self.commands = (self.ref.q + self.offset, self.ref.qd.copy(), np.zeros((n, robot.n_act)))

    def applied_setpoints(self, k: int) -> list[np.ndarray]:
        """The set-points (q_des, qd_des, tau_ff) the drivers apply at the physics steps of sample ``k`` (substeps,
        n_act) each, from the commands of samples up to ``k`` (module docstring): ``held``, the hung robot's drivers'
        (:func:`~wbfriction.sim.pd_robot.step_setpoints`); ``model``, the linear interpolation of the commands at
        ``t - T/2 - delay`` (:func:`~wbfriction.model.pd.delayed`), held at the last command arrived where it would
        need a later one."""
        d, T, S, time = self.driver.delay, self.ref.dt, self.substeps, self.ref.time  # type: ignore[union-attr]
        if self.options.setpoints == "held":
            return [step_setpoints(x[:k + 1], S, d / self.h, k * S, (k + 1) * S) for x in self.commands]
        steps = time[k] + np.arange(S) * self.h
        u = (steps - 0.5 * T - d - time[0]) / T
        arrived = np.floor((steps - d - time[0]) / T + 1e-9).astype(int)
        j0 = np.clip(np.floor(u).astype(int), 0, k)
        j1 = np.minimum(j0 + 1, np.maximum(arrived, 0))
        w = np.where(j1 > j0, np.clip(u - j0, 0.0, 1.0), 0.0)[:, None]
        out = []
        for x in self.commands:  # np.interp's arithmetic: x0 + (x1 - x0) * w, on the samples' time axis
            at = steps - 0.5 * T - d
            exact = np.column_stack([np.interp(at, time[:k + 1], x[:k + 1, j]) for j in range(x.shape[1])])
            out.append(np.where(w > 0, exact, x[np.maximum(j1, 0)]) if k else np.broadcast_to(x[0], exact.shape))
        return out

    def switch_contacts(self, k: int) -> None:
        """Anchor the feet landing at sample ``k`` at their footprints, project onto them, rebuild the contacts."""
        contact = self.ref.contact[k]
        landing = [c for c in np.flatnonzero(contact) if c not in self.active]
        for c in landing:
            self.anchors[int(c)] = self.ref.feet[k, c].copy()
        self.active = np.flatnonzero(contact)
        if landing:
            pin.framesForwardKinematics(self.model, self.data, self.q)
            self.snaps += [float(np.linalg.norm(self.data.oMf[self.robot.contact_frame_ids[c]].translation
                                                - self.anchors[int(c)])) for c in landing]
            self.q = project_feet(self.robot, self.model, self.data, self.q, self.active, self.anchors)
        self.cmodels, self.cdatas = point_constraints(self.robot, self.model, self.data, self.active, self.anchors,
                                                      self.options.baumgarte)
        self.n_lam = 3 * len(self.active)

    def motor_torque(self, k: int, s: int, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The torque the motors apply at physics step ``s`` of sample ``k`` (module docstring: the drive)."""
        if s == 0:  # the controller, at the log rate
            tau = self.controller.torque(k, q, v, self.active) + self.compensation[k]
            q_des, qd_des = self.controller.setpoints
            if self.driver is None:
                o = self.options
                previous, self.held = self.held, tau + o.kp * (q_des - q[self.iq]) + o.kd * (qd_des - v[self.iv])
                if previous is not None and self.substeps > 1:  # the switch at t_k: the trapezoid's half step
                    return 0.5 * (previous + self.held)
            else:  # the drivers' set-points and feed-forward, their PD on top (as the torque drive's)
                self.commands[0][k], self.commands[1][k], self.commands[2][k] = q_des + self.offset, qd_des, tau
                self.step_commands = self.applied_setpoints(k)
        if self.driver is None:
            assert self.held is not None  # set at every sample's first step
            return self.held
        d = self.driver
        q_des, qd_des, tau_ff = (x[s] for x in self.step_commands)
        tau = d.kp * (q_des - (q[self.iq] + self.offset)) - d.kd * v[self.iv]  # pd_torque's order
        return np.clip(tau + d.kd * qd_des + tau_ff, -d.torque_limit, d.torque_limit)

    def run(self, progress: Progress | None = None) -> None:
        """Every sample: contact changes, the velocity's projection, the physics steps, the log (module docstring)."""
        model, data, settings, h = self.model, self.data, self.settings, self.h
        switches = set(self.switches.tolist())
        tau = np.zeros(model.nv)
        for k in counted(len(self.ref), progress):
            if k in switches:
                self.switch_contacts(k)
            q, v = self.q, self.v
            if len(self.active):
                v = pin.impulseDynamics(model, data, q, v, self.cmodels, self.cdatas, 0.0, settings).copy()
            for s in range(self.substeps):
                tau_m = self.motor_torque(k, s, q, v)
                tau_f = self.injected.torque(v[self.iv_f])
                tau[self.iv] = tau_m
                tau[self.iv_f] += tau_f
                a = pin.constraintDynamics(model, data, q, v, tau, self.cmodels, self.cdatas, settings)
                if s == 0:
                    commanded = self.held if self.driver is None and self.held is not None else tau_m
                    self.record(k, q, v, a, commanded, tau_m, tau_f)
                v = v + h * a
                q = pin.integrate(model, q, h * v)
            if not np.isfinite(v).all():
                raise SimulationError(f"the quadruped's simulation diverged at sample {k}")
            self.q, self.v = q, v

    def record(self, k: int, q: np.ndarray, v: np.ndarray, a: np.ndarray, tau_m: np.ndarray, applied: np.ndarray,
               tau_f: np.ndarray) -> None:
        """Log sample ``k``: the state, the true acceleration and forces under the motor torque ``tau_m`` of the
        sample (the Baumgarte term and the switch's half step, ``applied - tau_m``, taken off both: one more solve
        with the KKT factorisation of the step), the torques."""
        n_lam, data = self.n_lam, self.data
        lam = data.lambda_c.copy()
        a = a.copy()
        rhs = np.zeros(n_lam + self.model.nv)
        if n_lam:
            rhs[:n_lam] = -np.concatenate([cd.contact_acceleration_error.linear for cd in self.cdatas])
        rhs[n_lam + self.iv] = tau_m - applied
        if rhs.any():
            X = data.constraint_chol.solve(rhs)
            a += X[n_lam:]
            lam -= X[:n_lam]
        self.Q[k], self.V[k], self.A[k] = q, v, a
        self.force[k, self.active] = lam.reshape(-1, 3)
        self.tau_motor[k] = tau_m
        self.tau_f[k, self.injected.joints] = tau_f

    def result(self) -> QuadrupedRun:
        """The log (module docstring) and the run around it."""
        robot, ref, options = self.robot, self.ref, self.options
        iq, iv = self.iq, self.iv
        Q, V, A = self.Q, self.V, self.A
        meta = {"generator": GENERATOR, "robot": robot.name, "options": options.metadata(),
                "gait": asdict(ref.options), "drive": options.drive,
                "friction_true": {j: p.to_target() for j, p in self.injected.params.items()},
                "armature_true": dict(zip(robot.actuated, self.model.armature[iv].tolist())),
                "physics_step": self.h}
        imu = imu_readings(self.model, robot.imu, Q, V, A) if options.imu and robot.imu is not None else None
        foot_force = None
        if options.foot_forces != "none":
            foot_force = self.force.copy()
            if options.foot_forces == "normal":
                foot_force[..., :2] = np.nan
        common: dict[str, Any] = dict(
            base=Q[:, :7].copy(), tau_f_true=self.tau_f.copy(), source=GENERATOR.rsplit(".", 1)[-1],
            qd_true=V[:, iv].copy(), qdd_true=A[:, iv].copy(), base_qd_true=V[:, :6].copy(),
            base_qdd_true=A[:, :6].copy(), imu=imu, foot_force=foot_force)
        if self.driver is None:
            meta["torque_alignment"] = "sample" if self.substeps == 1 else "zoh"
            log = Log(ref.time.copy(), Q[:, iq].copy(), self.tau_motor.copy(), ref.contact.copy(), metadata=meta,
                      **common)
            if options.noise is not None and options.noise.active:
                log = apply_sensor_noise(log, options.noise)
        else:
            meta["torque_alignment"] = "sample"
            meta["encoder_offset_true"] = dict(zip(robot.actuated, self.offset.tolist()))
            meta["pd_true"] = {"kp": self.driver.kp.tolist(), "kd": self.driver.kd.tolist(),
                               "delay": self.driver.delay, "setpoints": options.setpoints}
            qd = V[:, iv].copy()
            setpoints = PdSetpoints(self.commands[0], qd, self.commands[1], self.commands[2])
            tau = pd_torque(self.driver, ref.time, Q[:, iq] + self.offset, qd, *self.commands)
            log = Log(ref.time.copy(), Q[:, iq].copy(), tau, ref.contact.copy(), metadata=meta, qd_logged=qd,
                      torque_source="pd", setpoints=setpoints, **common)
        return QuadrupedRun(log, ref, self.force, Q, V, A, self.tau_motor, self.tau_f, np.array(self.snaps))


def simulate_quadruped(robot: Robot, reference: QuadrupedReference,
                       options: QuadrupedOptions = QuadrupedOptions(), progress: Progress | None = None
                       ) -> QuadrupedRun:
    """Simulate a quadruped following ``reference`` in the ideal simulator (module docstring).

    Args:
        robot: a floating-base robot with four point feet (``contact_model = "point"``), every joint actuated
            (torque-controlled for ``drive = "torque"``; PD-driven by its ``[pd]`` for ``"pd"``), e.g. the built-in
            ``go2_walking``.
        reference: :func:`~wbfriction.walking.quadruped.quadruped_reference` of the robot.
        options: :class:`QuadrupedOptions`.
        progress: optional callable receiving numbers of samples done.

    Returns:
        :class:`QuadrupedRun` with one log row per reference sample.

    Raises:
        InputError: a robot that is not such a quadruped, friction for a joint it does not have.
        OptionError: a physics step that does not divide the reference's period.
        SimulationError: the state diverged.
    """
    if not robot.floating_base or len(robot.contact_frames) != 4:
        raise InputError(f"robot '{robot.name}': the quadruped simulator needs a floating base and four point feet "
                         "(contact_model = \"point\")")
    require_point_feet(robot, "the quadruped simulator")
    if robot.torque_controlled != robot.actuated:
        raise InputError(f"robot '{robot.name}': the quadruped simulator drives every joint: none may be "
                         "position-controlled")
    run = _Run(robot, reference, options)
    run.run(progress)
    return run.result()
