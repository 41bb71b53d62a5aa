"""A log generator: the constrained forward dynamics with known friction (thesis 6.1).

TALOS (or any robot) stands on both feet, then lifts one foot and swings that leg, the
arms and the torso through multi-sine references, the stance foot welded to the ground.
The contacts are rigid (``pin.constraintDynamics`` with 6D contacts), the controller
runs at the log rate ``1/dt`` and holds its torque over each period (zero-order hold),
and the physics integrates with semi-implicit Euler at ``dt / substeps``. Friction
(3.5) acts on the chosen joints at every physics step: ``tau_f = -f(qd)``.

The controller: feed-forward inverse dynamics of the reference on the stance-rooted
model (exact in single support), plus joint PD with gains set from each joint's
effective inertia. Position-controlled joints get a stiff PD whose torque is not logged.

The log carries the commanded torques, the contact flags of the plan, the true
friction at every sample (``tau_f_true``) and, in its metadata, the injected parameters.
This is the testbed until the walking simulator lands; the estimator never sees the
model of the world beyond the log.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import pinocchio as pin

from .exceptions import InputError
from .friction import FrictionParams, friction_by_group, smooth, stack_params
from .log import Log
from .robot import Robot


@dataclass(frozen=True)
class FixedFootScenario:
    """Parameters of :func:`simulate_fixed_foot`.

    Attributes:
        duration: total length [s].
        double_support: initial double-support time [s] (arms and torso move, legs hold).
        dt: log and control period [s].
        substeps: physics steps per control period.
        stance: index of the stance contact frame (the other one lifts off).
        amplitude: scale of the reference motion (1 = about 0.3 rad on the swing leg).
        frequency: base frequency of the multi-sine references [Hz].
        bandwidth: closed-loop bandwidth of the joint PD [Hz].
        log_base: write the base pose to the log.
        seed: random seed of the reference phases.
    """

    duration: float = 6.0
    double_support: float = 0.5
    dt: float = 1e-3
    substeps: int = 10
    stance: int = 0
    amplitude: float = 1.0
    frequency: float = 0.6
    bandwidth: float = 8.0
    log_base: bool = False
    seed: int = 0


def _amplitudes(robot: Robot, swing: set[str], amplitude: float) -> tuple[np.ndarray, np.ndarray]:
    """Reference amplitudes [rad] in single and double support, per actuated joint."""
    ss, ds = np.zeros(robot.n_act), np.zeros(robot.n_act)
    lo, hi = robot.angle_limits
    q0 = robot.reference_angles
    room = np.minimum(np.maximum(np.minimum(hi - q0, q0 - lo), 0.0), np.pi)
    pc = set(robot.position_controlled)
    legs = set().union(*(robot.limb(f) for f in robot.contact_frames))
    for i, name in enumerate(robot.actuated):
        if name in swing:
            ss[i] = 0.3
        elif name in pc:
            ss[i] = ds[i] = 0.15
        elif name not in legs:
            ss[i] = ds[i] = 0.25
    scale = amplitude * np.ones(robot.n_act)
    return np.minimum(ss * scale, 0.45 * room), np.minimum(ds * scale, 0.45 * room)


class _Reference:
    """Multi-sine joint references with a smooth amplitude ramp at each phase start."""

    def __init__(self, robot: Robot, scenario: FixedFootScenario, swing: set[str]):
        rng = np.random.default_rng(scenario.seed)
        self.q0 = robot.reference_angles
        self.amp_ss, self.amp_ds = _amplitudes(robot, swing, scenario.amplitude)
        n = robot.n_act
        f0 = scenario.frequency
        self.freq = np.stack([f0 * rng.uniform(0.8, 1.6, n), f0 * rng.uniform(1.8, 3.0, n)]) * 2 * np.pi
        self.phase = rng.uniform(0, 2 * np.pi, (2, n))
        self.t_ds = scenario.double_support

    @staticmethod
    def _ramp(t: float, t0: float, length: float = 0.5) -> tuple[float, float, float]:
        """Quintic smooth step from 0 at t0 to 1 at t0 + length, and its derivatives."""
        s = np.clip((t - t0) / length, 0.0, 1.0)
        if s <= 0.0 or s >= 1.0:
            return float(s >= 1.0), 0.0, 0.0
        return (10 * s**3 - 15 * s**4 + 6 * s**5, (30 * s**2 - 60 * s**3 + 30 * s**4) / length,
                (60 * s - 180 * s**2 + 120 * s**3) / length**2)

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        w, ph = self.freq, self.phase
        # sines start at zero value: sin(w t + ph) - sin(ph)
        s = (np.sin(w * t + ph) - np.sin(ph)).sum(0) / 2
        ds = (w * np.cos(w * t + ph)).sum(0) / 2
        dds = (-w**2 * np.sin(w * t + ph)).sum(0) / 2
        r_ds, dr_ds, ddr_ds = self._ramp(t, 0.0)
        r_ss, dr_ss, ddr_ss = self._ramp(t, self.t_ds)
        amp = self.amp_ds * r_ds + (self.amp_ss - self.amp_ds) * r_ss
        damp = self.amp_ds * dr_ds + (self.amp_ss - self.amp_ds) * dr_ss
        ddamp = self.amp_ds * ddr_ds + (self.amp_ss - self.amp_ds) * ddr_ss
        q = self.q0 + amp * s
        qd = damp * s + amp * ds
        qdd = ddamp * s + 2 * damp * ds + amp * dds
        return q, qd, qdd


def _contact_models(robot: Robot, data: pin.Data, active: list[int], placements: dict[int, pin.SE3]):
    models = []
    for c in active:
        fr = robot.model.frames[robot.contact_frame_ids[c]]
        cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_6D, robot.model, fr.parentJoint, fr.placement,
                                      0, placements[c], pin.LOCAL)
        cm.setBaumgarteCorrectorParameters(pin.BaumgarteCorrectorParameters(400.0, 40.0))
        models.append(cm)
    datas = [cm.createData() for cm in models]
    pin.initConstraintDynamics(robot.model, data, models, datas)
    return models, datas


def simulate_fixed_foot(robot: Robot, scenario: FixedFootScenario = FixedFootScenario(),
                        friction: dict[str, FrictionParams] | None = None, progress=None) -> Log:
    """Simulate the fixed-foot scenario and return its log (module docstring).

    Args:
        robot: the robot; needs at least two contact frames and a reference configuration
            in which they are flat on the ground (TALOS: ``half_sitting``).
        scenario: :class:`FixedFootScenario`.
        friction: parameters per torque-controlled joint name; default: the thesis's
            targets (Table 6.1) on the leg joint groups, none elsewhere.
        progress: optional callable receiving numbers of samples done.

    Raises:
        InputError: unknown joint in ``friction``, fewer than two contact frames.
    """
    if len(robot.contact_frames) < 2:
        raise InputError(f"robot '{robot.name}': the fixed-foot scenario needs two contact frames")
    from .estimate import stance_model  # stance-rooted model, shared with the estimator

    friction = friction_by_group(robot.groups) if friction is None else friction
    for joint in friction:
        if joint not in robot.torque_controlled:
            raise InputError(f"friction given for '{joint}', which is not a torque-controlled joint")
    model = robot.model
    data = model.createData()
    stance_c = scenario.stance
    swing_c = 1 - stance_c if stance_c in (0, 1) else 0
    swing = set(robot.limb(robot.contact_frames[swing_c]))
    ref = _Reference(robot, scenario, swing)
    rooted = stance_model(robot, stance_c)
    rooted_data = rooted.model.createData()

    # initial state: reference posture with the stance sole flat at the origin
    q = robot.configuration(ref.q0)  # base at the identity
    pin.framesForwardKinematics(model, data, q)
    q[:7] = pin.SE3ToXYZQUAT(data.oMf[robot.contact_frame_ids[stance_c]].inverse())
    pin.framesForwardKinematics(model, data, q)
    anchors = {c: data.oMf[robot.contact_frame_ids[c]].copy() for c in range(len(robot.contact_frames))}
    for c in anchors:  # weld the feet flat, at their height
        anchors[c].rotation = np.eye(3) if c == stance_c else anchors[c].rotation
    v = np.zeros(model.nv)

    # PD gains from each joint's effective inertia in single support with every other
    # joint free, 1 / (M^-1)_jj on the stance-rooted model: conservative for the
    # decentralised PD (a joint between two light links sees a small inertia)
    q_r = rooted.layout.configuration(ref.q0, None, rooted.sign)
    M_r = pin.crba(rooted.model, rooted_data, q_r)
    M_r = np.triu(M_r) + np.triu(M_r, 1).T
    M_j = M_r[np.ix_(rooted.v_index, rooted.v_index)]
    inertia = 1.0 / np.diag(np.linalg.inv(M_j))
    w = 2 * np.pi * scenario.bandwidth
    kp, kd = inertia * w**2, inertia * 2 * 0.9 * w
    pc = robot.pc_index
    kp[pc], kd[pc] = kp[pc] * 4, kd[pc] * 2

    tc = robot.tc_index
    iv = robot.act_v_index
    joints_f = [robot.torque_controlled.index(j) for j in friction]
    params_f = stack_params(list(friction.values()))
    iv_f = iv[tc][joints_f]
    n = int(round(scenario.duration / scenario.dt))
    h = scenario.dt / scenario.substeps
    settings = pin.ProximalSettings(1e-12, 1e-10, 50)
    rows = {k: np.empty((n, m)) for k, m in (("q", robot.n_act), ("tau", len(tc)), ("tau_f", len(tc)),
                                              ("contact", len(robot.contact_frames)), ("base", 7))}
    active = None
    for k in range(n):
        t = k * scenario.dt
        now = list(range(len(robot.contact_frames))) if t < scenario.double_support else [stance_c]
        if now != active:
            active = now
            cmodels, cdatas = _contact_models(robot, data, active, anchors)
        q_ref, qd_ref, qdd_ref = ref(t)
        angles, qd = q[iv + 1], v[iv]
        pose = np.array([0, 0, 0, 0, 0, 0, 1.0])
        tau_ff, _ = rooted.inverse_dynamics(pose[None], q_ref[None], qd_ref[None], qdd_ref[None])
        tau_cmd = tau_ff[0] + kp * (q_ref - angles) + kd * (qd_ref - qd)
        tau_f = np.zeros(len(tc))
        if joints_f:
            tau_f[joints_f] = -smooth(v[iv_f], **params_f)
        rows["q"][k], rows["tau"][k], rows["tau_f"][k] = angles, tau_cmd[tc], tau_f
        rows["contact"][k] = [c in active for c in range(len(robot.contact_frames))]
        rows["base"][k] = q[:7]
        tau_full = np.zeros(model.nv)
        for _ in range(scenario.substeps):
            tau_full[iv] = tau_cmd
            if joints_f:
                tau_full[iv_f] -= smooth(v[iv_f], **params_f)
            a = pin.constraintDynamics(model, data, q, v, tau_full, cmodels, cdatas, settings)
            v = v + a * h
            q = pin.integrate(model, q, v * h)
        if progress is not None and (k + 1) % 100 == 0:
            progress(100)
    if progress is not None and n % 100:
        progress(n % 100)
    metadata = {
        "generator": "wbfriction.simulate.simulate_fixed_foot",
        "scenario": asdict(scenario),
        "friction_true": {j: p.to_dict() for j, p in friction.items()},
    }
    time = np.arange(n) * scenario.dt
    return Log(time, rows["q"], rows["tau"], rows["contact"].astype(bool),
               rows["base"] if scenario.log_base else None, rows["tau_f"], metadata, source="simulate_fixed_foot")
