"""A scenario's files (:func:`write_scenario`): the log simulated with its truth, the URDF the tool is given (the
simulated one's inertial parameters perturbed) and the robot TOML naming it, in one folder.

**Arms** (:func:`simulate_arm_mujoco`): the URDF (a Panda's, its fingers fixed, or a random chain's) loaded in
MuJoCo as :func:`~wbfriction.model.mjspec.urdf_spec` reads it (the root welded to the world, no contact, no joint
limit), the drawn armature in ``dof_armature``, MuJoCo's semi-implicit Euler at ``rate x substeps`` (10 kHz, as
:mod:`wbfriction.sim.arm`: at 2 kHz the explicit friction chattered about its reversals within a sample, and a
200 Hz log's F_v came out twice the law's on a light joint). The arm tracks
:func:`~wbfriction.sim.arm.excitation_trajectory`'s Fourier series by computed torque (Pinocchio's ``rnea`` on the
simulated model, armature included, no friction compensation) plus a joint PD of 8 Hz (critically damped, gains
from each joint's apparent inertia ``1 / (M + diag(armature))^-1_jj``, its least along the reference: stable at
200 Hz), the torque held over each sample; the friction
(:class:`~wbfriction.studies.generalise.laws.LawState`: any law, of the state at each physics step) and the motor
torque are applied as ``qfrc_applied``. The log (:mod:`wbfriction.sim.arm`'s columns): ``time`` (stamps late by up
to the clock's jitter), ``q.<joint>`` (the encoder: noise, then rounding), ``current.<joint>`` (the motor torque plus
noise over the true torque constant; the TOML's is ``k_t_error`` off) or ``tau.<joint>`` (a torque sensor), logged
``torque_delay`` late, and the truth ``tau_f_true``, ``qd_true``, ``qdd_true``.

**Hung PD-driven robots**: :func:`~wbfriction.sim.hung.simulate_hung` on the built-in Go2 with the drawn gains,
delay (and what it holds back), armature, encoder offsets and friction (a velocity law: the hung simulator's
friction is of the velocity alone), its drivers' noise; the TOML the tool is given has the perturbed URDF, the
gains ``gain_error`` off, the given delay, no armature and no encoder offset.

The metadata (``wbfriction`` key) has, beside the simulator's, ``friction_true`` (the truth:
:func:`~wbfriction.studies.generalise.laws.truth_from_log`), ``friction_law`` (each joint's law), ``scenario`` (the
draw) and ``given`` (what the TOML holds: armature, offsets, delay).

**Walking robots** (:func:`_write_walk`): ``wbfriction simulate --simulator mujoco`` run as a user runs it (its own
process), the built-in ``go2_walking`` crawling (``--gait walk``, or ``stand`` for an almost still log) for the
drawn seconds or TALOS walking forward the drawn steps, with the drawn friction (a ``--friction`` TOML of (3.5)
parameters per joint: velocity laws), encoder bits, torque noise and noise seed; the given TOML is the built-in
one naming the perturbed URDF. The log is the command's with the truth put in its metadata.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa

from wbfriction.friction.families.coulomb_viscous import CoulombViscousParams
from wbfriction.friction.families.thesis import FrictionParams
from wbfriction.logs.metadata import read_metadata, with_metadata
from wbfriction.logs.tables import write_table
from wbfriction.studies.generalise.laws import EXACT_LAWS, JointLaw, LawState, truth_from_log
from wbfriction.studies.generalise.scenario import Scenario
from wbfriction.studies.generalise.urdf import chain_urdf, fixed_joints, perturbed_urdf

GENERATOR = "wbfriction.studies.generalise.simulate"
BANDWIDTH = 8.0
"""The arm's joint PD bandwidth [Hz]."""
LOG, GIVEN_URDF, GIVEN_TOML, TRUE_URDF, TRUE_TOML = ("log.parquet", "given.urdf", "given.toml", "simulated.urdf",
                                                     "simulated.toml")
"""The files of a scenario's folder."""
PANDA_FINGERS = ("panda_finger_joint1", "panda_finger_joint2")
PANDA_K_T = (8.7, 8.7, 8.7, 8.7, 1.2, 1.2, 1.2)
"""The built-in Panda's torque constants [N·m/A] (its TOML's), the ones the given TOML holds."""


@dataclass(frozen=True)
class Written:
    """A scenario's folder: the log, the TOML the tool is given, the joints (in the robot's order)."""

    folder: Path
    log: Path
    config: Path
    joints: tuple[str, ...]


def _truth_params(law: JointLaw, truth: dict[str, float]) -> dict:
    """The ``friction_true`` entry of a joint: the law's family for the exact laws, else Coulomb-viscous."""
    if law.law in EXACT_LAWS:
        return FrictionParams(F_v=truth["F_v"], F_c=truth["F_c"], S=law.S, v_s=law.v_s, a=law.a).to_target()
    return CoulombViscousParams(F_v=truth["F_v"], F_c=truth["F_c"], tau_os=truth.get("tau_os", 0.0)).to_target()


def _jittered(time: np.ndarray, jitter: float, rng: np.random.Generator) -> np.ndarray:
    """Receive-time stamps: each ``time`` late by a uniform share of ``jitter`` [s] (kept increasing)."""
    if jitter <= 0:
        return time
    return time + rng.uniform(0.0, jitter, time.shape)


def _arm_urdfs(sc: Scenario) -> tuple[str, tuple[str, ...]]:
    """The simulated arm's URDF text and joints: the Panda's with its fingers fixed, or a random chain."""
    if sc.robot == "panda":
        from wbfriction.model.loading import load_robot
        robot = load_robot("panda")
        return fixed_joints(Path(robot.urdf).read_text(), PANDA_FINGERS), tuple(robot.actuated)
    return chain_urdf(np.random.default_rng(sc.chain_seed), sc.n_joints)


def _excitation(sc: Scenario):
    from wbfriction.sim.arm import ExcitationOptions
    if sc.excitation == "good":
        return ExcitationOptions(period=min(10.0, sc.duration / 2), harmonics=5, range_share=0.6, velocity_share=0.6,
                                 seed=sc.excitation_seed)
    if sc.excitation == "poor":
        return ExcitationOptions(period=sc.duration, harmonics=2, range_share=0.3, velocity_share=0.15,
                                 seed=sc.excitation_seed)
    return ExcitationOptions(period=sc.duration, harmonics=2, range_share=0.02, velocity_share=0.02,
                             seed=sc.excitation_seed)


def simulate_arm_mujoco(urdf: Path, joints: tuple[str, ...], sc: Scenario, k_true: np.ndarray) -> pa.Table:
    """The arm's log (module docstring) simulated from the URDF file ``urdf`` whose joints are ``joints``;
    ``k_true``: the true torque constants (n,) [N·m/A].

    Raises:
        SimulationError: the simulation diverged.
    """
    import mujoco
    import pinocchio as pin

    from wbfriction.exceptions import SimulationError
    from wbfriction.model.mjspec import urdf_spec
    from wbfriction.sim.arm import excitation_trajectory
    from wbfriction.sim.mujoco_model import route_mujoco_warnings

    model = pin.buildModelFromUrdf(str(urdf))
    if tuple(model.names[1:]) != joints:
        raise ValueError(f"{urdf}: joints {tuple(model.names[1:])}, expected {joints}")
    armature = np.array(sc.armature)
    model.armature = armature
    data = model.createData()
    traj = excitation_trajectory(model.lowerPositionLimit, model.upperPositionLimit, model.velocityLimit,
                                 _excitation(sc))
    dt = 1.0 / sc.rate
    n, nv = int(round(sc.duration * sc.rate)), model.nv
    time = np.arange(n) * dt
    q_ref, qd_ref, qdd_ref = traj(time)
    ff = np.array([pin.rnea(model, data, q_ref[k], qd_ref[k], qdd_ref[k]) for k in range(n)])
    # each joint's apparent inertia (the others free), its least along the reference: what the gains and the
    # bristles are kept stable on
    inertia = np.min([1.0 / np.diag(np.linalg.inv(pin.crba(model, data, q_ref[k])))
                      for k in range(0, n, max(1, n // 64))], axis=0)
    w = 2.0 * np.pi * BANDWIDTH
    kp, kd = inertia * w**2, 2.0 * w * inertia

    route_mujoco_warnings()
    spec = urdf_spec(urdf, free_joint=False)
    h = dt / sc.substeps
    spec.option.timestep = h
    spec.option.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    for joint in spec.joints:
        joint.limited = mujoco.mjtLimited.mjLIMITED_FALSE
    mj = spec.compile()
    ids = [mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, j) for j in joints]
    qadr, dadr = np.array(mj.jnt_qposadr[ids]), np.array(mj.jnt_dofadr[ids])
    mj.dof_armature[dadr] = armature
    md = mujoco.MjData(mj)
    md.qpos[qadr], md.qvel[dadr] = q_ref[0], qd_ref[0]
    laws = stable_laws(sc.laws, inertia, h)
    state = LawState(laws, sc.warm_up, sc.duration)
    Q, V, A, T, F = (np.empty((n, nv)) for _ in range(5))
    tau_f = np.zeros(nv)
    for k in range(n):
        q, v = md.qpos[qadr].copy(), md.qvel[dadr].copy()
        tau = ff[k] + kp * (q_ref[k] - q) + kd * (qd_ref[k] - v)
        for s in range(sc.substeps):
            q, v = md.qpos[qadr], md.qvel[dadr]
            tau_f = -state.f(v, q, tau + tau_f, (k * sc.substeps + s) * h, h)
            md.qfrc_applied[dadr] = tau + tau_f
            if s == 0:
                Q[k], V[k], T[k], F[k] = q, v, tau, tau_f
            mujoco.mj_step(mj, md)
            if s == 0:
                A[k] = md.qacc[dadr]
        if not np.isfinite(md.qvel).all() or md.warning[mujoco.mjtWarning.mjWARN_BADQACC].number:
            raise SimulationError(f"the arm's MuJoCo simulation diverged at sample {k}")
    return _arm_log(sc, joints, time, (Q, V, A, T, F), laws, state, k_true)


def _arm_log(sc: Scenario, joints: tuple[str, ...], time: np.ndarray, states: tuple[np.ndarray, ...],
             laws: tuple[JointLaw, ...], state: LawState, k_true: np.ndarray) -> pa.Table:
    """The arm's log table with its truth in the metadata, from the simulated samples ``states``: angles, velocities,
    accelerations, motor torques and friction (N, n) [rad, rad/s, rad/s², N·m, N·m] at the samples ``time`` (N,) [s]:
    the sensors' noise, rounding, delay and clock jitter applied (module docstring)."""
    from wbfriction.sim.options import SensorNoise

    Q, V, A, T, F = states
    n, nv = Q.shape
    armature = np.array(sc.armature)
    rng = np.random.default_rng(sc.noise_seed)
    noise = SensorNoise(position_std=sc.position_std, encoder_bits=sc.encoder_bits, torque_std=sc.torque_std,
                        seed=sc.noise_seed)
    eps_q, eps_tau = noise.draw(n, nv, nv)
    q_log = noise.encoder(Q + eps_q)
    lag = int(round(sc.torque_delay * sc.rate))
    measured = T + eps_tau
    if lag:
        measured = np.vstack([np.repeat(measured[:1], lag, axis=0), measured[:-lag]])
    torque = ("current", measured / k_true) if sc.sensor == "current" else ("tau", measured)
    cols: dict[str, np.ndarray] = {"time": _jittered(time, sc.clock_jitter, rng)}
    for prefix, x in (("q", q_log), torque, ("tau_f_true", F), ("qd_true", V), ("qdd_true", A)):
        cols.update({f"{prefix}.{j}": x[:, i] for i, j in enumerate(joints)})
    truth = truth_from_log(laws, V, F, state.temperature_factor(time))
    meta = {"generator": GENERATOR, "robot": sc.robot, "urdf": TRUE_URDF, "torque_alignment": "zoh",
            "dynamics": "(M(q) + diag(armature)) qdd + h(q, qd) = tau_motor + tau_f; tau_f = -f(qd, q, load, T)",
            "friction_true": {j: _truth_params(law, t) for j, law, t in zip(joints, laws, truth)},
            "friction_law": {j: law.to_dict() for j, law in zip(joints, laws)},
            "armature_true": dict(zip(joints, map(float, armature))),
            "torque_constants": dict(zip(joints, map(float, k_true))), "sensor_noise": dataclasses.asdict(noise)}
    return with_metadata(pa.table(cols), meta)


BRISTLE_STEP = 0.5
"""The most ``h sqrt(sigma_0 / I)`` a LuGre bristle is simulated at (``I`` the joint's apparent inertia ``1 /
(M^-1)_jj``, the other joints free, its least along the reference, armature included; ``h`` the physics step):
MuJoCo's explicit coupling of the bristle's spring to the joint is stable below 2."""


def stable_laws(laws: tuple[JointLaw, ...], inertia: np.ndarray, h: float) -> tuple[JointLaw, ...]:
    """``laws`` with each LuGre bristle's stiffness at most :data:`BRISTLE_STEP` ``^2 I / h^2`` (``inertia`` (n,):
    each joint's apparent inertia [kg·m²], ``h`` [s]): what the log's ``friction_law`` then records."""
    return tuple(dataclasses.replace(law, sigma0=min(law.sigma0, BRISTLE_STEP**2 * float(i) / h**2))
                 if law.sigma0 > 0 else law for law, i in zip(laws, inertia))


def _toml_value(x) -> str:
    if isinstance(x, str):
        return f'"{x}"'
    return repr(float(x))


def _toml(top: dict, tables: dict[str, dict]) -> str:
    lines = [f"{k} = {_toml_value(v) if not isinstance(v, bool) else str(v).lower()}" for k, v in top.items()]
    for name, table in tables.items():
        lines += ["", f"[{name}]"] + [f"{k} = {_toml_value(v)}" for k, v in table.items()]
    return "\n".join(lines) + "\n"


def _write_arm(sc: Scenario, folder: Path) -> Written:
    text, joints = _arm_urdfs(sc)
    (folder / TRUE_URDF).write_text(text)
    given, _ = perturbed_urdf(text, sc.perturbation, np.random.default_rng([sc.seed, 1]))
    (folder / GIVEN_URDF).write_text(given)
    k_given = np.array(PANDA_K_T) if sc.robot == "panda" else np.full(len(joints), 5.0)
    k_true = k_given / (1.0 + sc.k_t_error)
    tables = {"torque_constants": dict(zip(joints, k_given))} if sc.sensor == "current" else {}
    (folder / GIVEN_TOML).write_text(_toml({"name": sc.robot, "urdf": GIVEN_URDF, "floating_base": False}, tables))
    table = simulate_arm_mujoco(folder / TRUE_URDF, joints, sc, k_true)
    return _finish(sc, folder, table, joints, {"armature": {j: 0.0 for j in joints}})


GO2_TOP = {"srdf": "example-robot-data:go2_description/srdf/go2.srdf", "reference_configuration": "standing",
           "floating_base": False}
GO2_GROUPS = ("[groups]\nhip = [\"FL_hip_joint\", \"FR_hip_joint\", \"RL_hip_joint\", \"RR_hip_joint\"]\n"
              "thigh = [\"FL_thigh_joint\", \"FR_thigh_joint\", \"RL_thigh_joint\", \"RR_thigh_joint\"]\n"
              "calf = [\"FL_calf_joint\", \"FR_calf_joint\", \"RL_calf_joint\", \"RR_calf_joint\"]\n")


def hung_friction(law: JointLaw) -> FrictionParams:
    """A velocity law as the hung simulator's (3.5) parameters: the Coulomb asymmetry as ``tau_os`` (so an
    asymmetric law's ``F_v`` is its positive one)."""
    return FrictionParams(F_v=law.F_v, F_c=0.5 * (law.F_c + law.F_c_neg), S=law.S, v_s=law.v_s,
                          tau_os=0.5 * (law.F_c - law.F_c_neg), a=law.a)


def _write_pd(sc: Scenario, folder: Path) -> Written:
    from wbfriction.model.loading import load_robot
    from wbfriction.sim.hung import simulate_hung
    from wbfriction.sim.pd_options import DriverNoise, HungOptions, SetpointOptions

    original = load_robot("go2")
    joints = tuple(original.actuated)
    text = Path(original.urdf).read_text()
    (folder / TRUE_URDF).write_text(text)
    given, _ = perturbed_urdf(text, sc.perturbation, np.random.default_rng([sc.seed, 1]))
    (folder / GIVEN_URDF).write_text(given)
    # the mesh paths of the URDF (package://) resolve from the package's tree: the simulated robot loads the original
    (folder / TRUE_TOML).write_text(_toml({"name": "go2", "urdf": str(original.urdf), **GO2_TOP}, {
        "pd": {"kp": sc.kp, "kd": sc.kd, "delay": sc.delay, "delayed": sc.delayed}}) + GO2_GROUPS)
    (folder / GIVEN_TOML).write_text(_toml({"name": "go2", "urdf": GIVEN_URDF, **GO2_TOP}, {
        "pd": {"kp": sc.kp * (1 + sc.gain_error), "kd": sc.kd * (1 + sc.gain_error), "delay": sc.given_delay}})
        + GO2_GROUPS)
    robot = load_robot(None, config=folder / TRUE_TOML)
    setpoints = {"good": SetpointOptions(kind="both", amplitude=0.3, seed=sc.excitation_seed),
                 "poor": SetpointOptions(kind="ramps", amplitude=0.1, reversal=(1.5, 3.0), seed=sc.excitation_seed),
                 "still": SetpointOptions(kind="ramps", amplitude=0.01, seed=sc.excitation_seed)}[sc.excitation]
    resolution = None if sc.encoder_bits is None else 2.0 * np.pi / 2.0**sc.encoder_bits
    options = HungOptions(duration=sc.duration, rate=sc.rate, substeps=sc.substeps, setpoints=setpoints,
                          noise=DriverNoise(encoder_resolution=resolution, velocity_std=sc.velocity_std,
                                            seed=sc.noise_seed),
                          delay=sc.delay, armature=dict(zip(joints, sc.armature)),
                          encoder_offset=dict(zip(joints, sc.encoder_offset)))
    sim = simulate_hung(robot, options, friction={j: hung_friction(law) for j, law in zip(joints, sc.laws)})
    table = sim.table
    if sc.clock_jitter > 0:
        rng = np.random.default_rng([sc.noise_seed, 1])
        table = table.set_column(0, "time", pa.array(_jittered(sim.time, sc.clock_jitter, rng)))
    tr = sim.trajectory
    truth = truth_from_log(sc.laws, tr.qd, tr.tau_f)
    meta = read_metadata(table)
    meta["friction_true"] = {j: _truth_params(law, t) for j, law, t in zip(joints, sc.laws, truth)}
    table = with_metadata(table, meta)
    given_values = {"armature": {j: 0.0 for j in joints}, "offset": {j: 0.0 for j in joints},
                    "delay": sc.given_delay}
    return _finish(sc, folder, table, joints, given_values)


def absolute_pythonpath() -> dict[str, str]:
    """This process's environment with ``PYTHONPATH``'s entries made absolute: the commands run in a scenario's
    folder, where a relative entry (``PYTHONPATH=src``) would name nothing and the commands would run another
    installed ``wbfriction``."""
    import os

    env = dict(os.environ)
    if env.get("PYTHONPATH"):
        env["PYTHONPATH"] = os.pathsep.join(str(Path(p).resolve()) if p else p
                                            for p in env["PYTHONPATH"].split(os.pathsep))
    return env


def walking_joints(robot) -> tuple[str, ...]:
    """The joints a walking scenario injects friction on: a quadruped's every torque-controlled joint, a humanoid's
    legs (``leg_*``)."""
    joints = tuple(robot.torque_controlled)
    legs = tuple(j for j in joints if j.startswith("leg_"))
    return legs or joints


def _walk_command(sc: Scenario) -> str:
    """The ``wbfriction simulate`` line of a walking scenario (module docstring)."""
    if sc.robot_class == "crawl":
        gait = "stand" if sc.excitation == "still" else "walk"
        what = f"--robot {sc.robot} --gait {gait} --duration {sc.duration:g}"
    else:
        what = f"--robot {sc.robot} --gait forward --steps {int(sc.duration)}"
    noise = (f" --encoder-bits {sc.encoder_bits}" if sc.encoder_bits is not None else "") + (
        f" --torque-noise {sc.torque_std:g}" if sc.torque_std > 0 else "")
    return (f"wbfriction simulate {what} --simulator mujoco --friction {WALK_FRICTION}{noise} "
            f"--noise-seed {sc.noise_seed} -o {WALK_LOG}")


WALK_FRICTION, WALK_LOG = "friction.toml", "simulated.parquet"


def _write_walk(sc: Scenario, folder: Path) -> Written:
    """A crawl or a humanoid's walk by ``wbfriction simulate --simulator mujoco`` (its own process: the documented
    simulator as a user runs it), with the drawn friction, sensors and the given model perturbed."""
    import re

    import pyarrow.parquet as pq

    from wbfriction.model.loading import load_robot
    from wbfriction.model.robots import __file__ as robots_init
    from wbfriction.studies.real_data import run_route

    robot = load_robot(sc.robot)
    joints = walking_joints(robot)
    text = Path(robot.urdf).read_text()
    given, _ = perturbed_urdf(text, sc.perturbation, np.random.default_rng([sc.seed, 1]))
    (folder / GIVEN_URDF).write_text(given)
    toml = (Path(robots_init).parent / f"{sc.robot}.toml").read_text()
    (folder / GIVEN_TOML).write_text(re.sub(r'(?m)^urdf = .*$', f'urdf = "{GIVEN_URDF}"', toml, count=1))
    tables = {f"friction.{j}": {k: getattr(p, k) for k in ("F_v", "F_c", "S", "v_s", "tau_os", "a")}
              for j, p in ((j, hung_friction(law)) for j, law in zip(joints, sc.laws))}
    (folder / WALK_FRICTION).write_text(_toml({}, tables))
    run_route([_walk_command(sc)], folder, env=absolute_pythonpath())
    table = pq.read_table(folder / WALK_LOG)
    (folder / WALK_LOG).unlink()
    qd = np.column_stack([table.column(f"qd_true.{j}").to_numpy() for j in joints])
    tau_f = np.column_stack([table.column(f"tau_f_true.{j}").to_numpy() for j in joints])
    meta = read_metadata(table)
    truth = truth_from_log(sc.laws, qd, tau_f)
    meta["friction_true"] = {j: _truth_params(law, t) for j, law, t in zip(joints, sc.laws, truth)}
    return _finish(sc, folder, with_metadata(table, meta), joints, {})


def _finish(sc: Scenario, folder: Path, table: pa.Table, joints: tuple[str, ...], given: dict) -> Written:
    meta = read_metadata(table)
    meta.setdefault("friction_law", {j: law.to_dict() for j, law in zip(joints, sc.laws)})
    meta.update(scenario=dataclasses.asdict(sc) | {"laws": None}, given=given)
    write_table(with_metadata(table, meta), folder / LOG)
    return Written(folder, folder / LOG, folder / GIVEN_TOML, joints)


def write_scenario(sc: Scenario, folder: str | Path) -> Written:
    """Simulate ``sc`` and write its files into ``folder`` (made if missing; module docstring): ``log.parquet``,
    ``given.urdf`` and ``given.toml`` (what the tool is given), ``simulated.urdf`` (and ``simulated.toml`` for a
    PD-driven robot).

    Raises:
        SimulationError: a simulation that diverged.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    write = {"arm": _write_arm, "pd": _write_pd}.get(sc.robot_class, _write_walk)
    return write(sc, folder)
