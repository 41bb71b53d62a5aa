"""Exports of PD-driven robots (issue 55, item 4): every field written is the robot's or the fit's value, read back
from the file; MuJoCo's compiled actuators apply the driver's law (the PD law of :mod:`wbfriction.model.pd` on a
hand-set state, the set-points delayed as the driver delays them); the delay in Isaac Lab's physics steps; the fits'
statuses as in every export.

The robot: the built-in Panda given drivers (a ``[pd]`` and ``[encoder_offset]`` as a robot TOML gives them), its
armature the TOML's; random gains, limits and offsets (seeded)."""

from __future__ import annotations

import dataclasses
import math
import re

import mujoco
import numpy as np
import pytest
from lxml import etree as ET

from helpers import load_yaml, run_cli
from wbfriction.exceptions import InputError
from wbfriction.export.drive import DEFAULT_PHYSICS_DT, HOLD_EDGE, SMALLEST_TIMESTEP, delay_steps, history_samples
from wbfriction.export.isaac import NO_FRICTION
from wbfriction.fit.params_file import write_params
from wbfriction.model import load_robot
from wbfriction.model.pd import PdDriver, pd_torque
from wbfriction.pipeline.export_step import export_files

DELAY = 0.013
"""The drivers' delay [s]: 2.6 steps of Isaac Lab's 0.005 s, 6.5 of MuJoCo's default 0.002 s (not whole)."""


@pytest.fixture(scope="module")
def panda():
    return load_robot("panda")


@pytest.fixture(scope="module")
def robot(panda):
    """The Panda with PD drivers on its 7 joints: random gains, a torque limit on each but the last, an encoder
    offset on joints 2, 4 and 5 (one negative), the set-points delayed by :data:`DELAY`."""
    rng = np.random.default_rng(55)
    n = len(panda.actuated)
    limit = rng.uniform(5.0, 90.0, n)
    limit[-1] = np.inf
    driver = PdDriver(panda.actuated, rng.uniform(10.0, 200.0, n), rng.uniform(0.2, 5.0, n), DELAY, limit)
    offsets = {"panda_joint2": 0.0312, "panda_joint4": -0.0207, "panda_joint5": 0.0049}
    return dataclasses.replace(panda, pd=driver, encoder_offset=offsets, cache={})


@pytest.fixture()
def params(tmp_path, fit_of):
    """Fits as `fit` writes them: joints 1, 2, 4 ok (each its own numbers), 3 weak, 5 failed, 6 and 7 not fitted;
    fitted for the built-in panda (its URDF: the PD TOMLs below use it too)."""
    status = {1: "ok", 2: "ok", 3: "weak", 4: "ok", 5: "failed"}
    fits = [fit_of(f"panda_joint{i}", s, F_v=0.07 * i, F_c=0.21 * i) for i, s in status.items()]
    path = tmp_path / "p.json"
    write_params(path, fits, {"provenance": {"robot": "panda", "urdf": str(load_robot("panda").urdf)}})
    return path, {f.joint: f for f in fits}




def by_joint(mapping: dict, joints) -> dict[str, float]:
    """A field's ``{regex: value}`` as ``{joint: value}``, each key matching its joint in full."""
    return {n: v for k, v in mapping.items() for n in joints if re.fullmatch(k, n)}


def header_offsets(text: str) -> dict[str, float]:
    """The encoder offsets a file's comment lists after its line about them, ``"<joint>": <rad>`` one per line."""
    lines = text.splitlines()
    start = next(i for i, line in enumerate(lines) if "encoder offset" in line)
    found: dict[str, float] = {}
    for line in lines[start:]:
        m = re.fullmatch(r'[#\s]*"([^"]+)": (\S+)', line)
        if m:
            found[m[1]] = float(m[2])
        elif found:
            break
    return found


def setpoint_offsets(text: str) -> dict[str, float]:
    """The set-point offsets a file's comment lists, ``"<joint>": <rad> (tau_os <N·m> N·m)`` one per line."""
    return {m[1]: float(m[2]) for m in re.finditer(r'"([^"]+)": (\S+) \(tau_os \S+ N·m\)', text)}


def test_isaac_fields_are_the_robots_and_the_fits(robot, params, tmp_path):
    """The YAML (read by YAML 1.2 and 1.1) is a DelayedPDActuatorCfg of every PD-driven joint: stiffness = kp,
    damping = kd, armature the TOML's, the frictions of the ok fits only, the finite torque limits, the delay in
    whole physics steps; the encoder offsets listed in the header, and the ok fits' constant tau_os as set-point
    offsets offset + tau_os / kp; each joint's status beside its name."""
    path, fits = params
    out = tmp_path / "a.yaml"
    done = export_files(robot, path, [out])
    text = out.read_text()
    doc = load_yaml(text)
    assert load_yaml(text, (1, 1)) == doc
    joints, pd = robot.actuated, robot.pd
    assert [re.fullmatch(k, n) is not None for k, n in zip(doc["joint_names_expr"], joints)] == [True] * 7
    assert list(doc) == ["joint_names_expr", "stiffness", "damping", "armature", "friction", "dynamic_friction",
                         "viscous_friction", "actuator_effort_limit", "min_delay", "max_delay"]
    assert by_joint(doc["stiffness"], joints) == dict(zip(joints, pd.kp))
    assert by_joint(doc["damping"], joints) == dict(zip(joints, pd.kd))
    assert by_joint(doc["armature"], joints) == {j: robot.model.armature[robot.model.idx_vs[robot.model.getJointId(j)]]
                                                 for j in joints}
    assert by_joint(doc["armature"], joints)["panda_joint1"] == 0.30  # the TOML's [armature]
    ok = ["panda_joint1", "panda_joint2", "panda_joint4"]
    for j in ok:
        p = fits[j].params
        assert by_joint(doc["friction"], joints)[j] == (1 + p.S) * p.F_c
        assert by_joint(doc["dynamic_friction"], joints)[j] == p.F_c
        assert by_joint(doc["viscous_friction"], joints)[j] == p.F_v
    assert set(by_joint(doc["viscous_friction"], joints)) == set(ok)  # weak, failed, not fitted: none
    assert by_joint(doc["actuator_effort_limit"], joints) == dict(zip(joints[:6], pd.torque_limit[:6]))
    steps = math.floor(DELAY / DEFAULT_PHYSICS_DT + 0.5)
    assert doc["min_delay"] == doc["max_delay"] == steps == 3  # 2.6 steps rounded
    assert header_offsets(text) == robot.encoder_offset
    assert "encoder_bias = -offset" in text
    kp = dict(zip(joints, pd.kp))  # the ok fits' tau_os as set-point offsets, in the header and in the result
    assert setpoint_offsets(text) == {j: robot.encoder_offset.get(j, 0.0) + fits[j].params.tau_os / kp[j] for j in ok}
    assert done.drive is not None and done.drive.torque_offset == {j: fits[j].params.tau_os for j in ok}
    notes = dict(re.findall(r'^  - "([^"]+)"  # (.*)$', text, re.M))
    assert notes["panda_joint1"] == "wbfriction fit of panda_joint1: ok"
    assert notes["panda_joint3"] == notes["panda_joint5"] == notes["panda_joint7"] == NO_FRICTION
    assert done.reports[0].warnings == (delay_steps(DELAY).warning,)
    assert "2.600 physics steps of 0.005 s" in done.reports[0].warnings[0]


def test_isaac_included_weak_fit_carries_its_status(robot, params, tmp_path):
    """--include weak: the weak fit's numbers go in, its note says weak and why; the failed one never does."""
    path, fits = params
    out = tmp_path / "a.yaml"
    export_files(robot, path, [out], include=["weak", "at-bound"])
    text = out.read_text()
    doc = load_yaml(text)
    assert by_joint(doc["viscous_friction"], robot.actuated)["panda_joint3"] == fits["panda_joint3"].params.F_v
    assert re.search(r'^  - "panda_joint3"  # wbfriction fit of panda_joint3: weak \(.+\)$', text, re.M)
    assert "panda_joint5" not in by_joint(doc["viscous_friction"], robot.actuated)


@pytest.mark.parametrize("physics_dt, steps, whole", [(0.005, 3, False), (0.0065, 2, True), (0.001, 13, True),
                                                       (0.002, 7, False), (0.0026, 5, True), (0.02, 1, False)])
def test_delay_in_physics_steps(robot, params, tmp_path, physics_dt, steps, whole):
    """min_delay = max_delay = round(delay / physics_dt) (halves up); a warning exactly when not whole."""
    out = tmp_path / "a.yaml"
    done = export_files(robot, params[0], [out], physics_dt=physics_dt)
    doc = load_yaml(out.read_text())
    assert doc["min_delay"] == doc["max_delay"] == steps == math.floor(DELAY / physics_dt + 0.5)
    assert (done.reports[0].warnings == ()) == whole


def test_delay_steps_rounding():
    """Nearest whole step, halves up; a quotient that is whole but for floating point is whole."""
    assert [delay_steps(d * 0.01, 0.01).steps for d in (2.4, 2.5, 2.6, 0.49)] == [2, 3, 3, 0]
    exact = delay_steps(0.3, 0.1)
    assert exact.exact != 3 and exact.steps == 3 and exact.whole and exact.warning is None
    assert not delay_steps(0.0125, 0.005).whole
    for bad in (0.0, -0.005, math.inf, math.nan):
        with pytest.raises(InputError, match="--physics-dt"):
            delay_steps(0.01, bad)


def test_isaac_refuses_friction_of_a_joint_not_pd_driven(robot, params, tmp_path):
    """One actuator group, one drive model: a fitted joint outside [pd] joints is refused, nothing written."""
    partial = dataclasses.replace(robot, pd=PdDriver(robot.actuated[2:], robot.pd.kp[2:], robot.pd.kd[2:], DELAY),
                                  cache={})
    out = tmp_path / "a.yaml"
    with pytest.raises(InputError, match="joint 'panda_joint1' has friction to export but is not PD-driven"):
        export_files(partial, params[0], [out])
    assert not out.exists()


@pytest.fixture()
def mjcf(robot, params, tmp_path):
    """The MJCF of the PD-driven Panda (written by export_files), its text, its compiled model and the fits."""
    path, fits = params
    out = tmp_path / "a.xml"
    export_files(robot, path, [out])
    return out.read_text(), mujoco.MjModel.from_xml_path(str(out)), fits


def test_mjcf_fields_are_the_robots_and_the_fits(robot, mjcf):
    """Read back from the file and from MuJoCo's compiled model: one position actuator per PD-driven joint, named
    as it: gain kp, bias [-kp offset - tau_os, -kp, -kd] (tau_os the exported fit's, none without), force range the
    torque limit (none without), the delay (less 1 ns, the hold's edge), zero-order hold, a history long enough down
    to 0.5 ms; joints' armature, damping = F_v, frictionloss = F_c of the ok fits only; the comment lists the encoder
    offsets and the set-point offsets offset + tau_os / kp."""
    text, m, fits = mjcf
    pd = robot.pd
    root = ET.fromstring(text.encode())
    acts = root.find("actuator").findall("general")
    assert [a.get("name") for a in acts] == [a.get("joint") for a in acts] == list(robot.actuated)
    assert m.nu == 7
    for i, j in enumerate(robot.actuated):
        a, dof = m.actuator(j).id, m.joint(j).dofadr[0]
        kp, kd, off = pd.kp[i], pd.kd[i], robot.encoder_offset.get(j, 0.0)
        exported = j in ("panda_joint1", "panda_joint2", "panda_joint4")
        tau_os = fits[j].params.tau_os if exported else 0.0
        assert m.actuator_trnid[a, 0] == m.joint(j).id
        assert m.actuator_gainprm[a, 0] == kp and not np.any(m.actuator_gainprm[a, 1:])
        assert m.actuator_biasprm[a, 0] == pytest.approx(-kp * off - tau_os, rel=1e-15, abs=1e-15)
        assert list(m.actuator_biasprm[a, 1:3]) == [-kp, -kd] and not np.any(m.actuator_biasprm[a, 3:])
        assert m.actuator_gaintype[a] == mujoco.mjtGain.mjGAIN_FIXED
        assert m.actuator_biastype[a] == mujoco.mjtBias.mjBIAS_AFFINE
        xml = acts[i]
        assert [float(x) for x in xml.get("gainprm").split()] == [kp]
        assert [float(x) for x in xml.get("biasprm").split()] == list(m.actuator_biasprm[a, :3])
        if np.isfinite(pd.torque_limit[i]):
            assert list(m.actuator_forcerange[a]) == [-pd.torque_limit[i], pd.torque_limit[i]]
            assert m.actuator_forcelimited[a] == 1
        else:
            assert m.actuator_forcelimited[a] == 0 and "forcerange" not in xml.attrib
        assert m.actuator_delay[a] == float(xml.get("delay")) == DELAY - HOLD_EDGE  # the hold's edge: 1 ns
        samples = m.actuator_history[a, 0]
        assert samples == history_samples(DELAY, m.opt.timestep) >= math.ceil(DELAY / SMALLEST_TIMESTEP)
        assert xml.get("interp", "zoh") == "zoh"
        armature = robot.model.armature[robot.model.idx_vs[robot.model.getJointId(j)]]
        assert m.dof_armature[dof] == armature
        want = (fits[j].params.F_v, fits[j].params.F_c) if exported else (0.0, 0.0)
        assert (m.dof_damping[dof], m.dof_frictionloss[dof]) == want, j
    assert "<!-- wbfriction fit of panda_joint1: ok -->" in text
    assert header_offsets(text) == robot.encoder_offset
    kp = dict(zip(robot.actuated, pd.kp))
    assert setpoint_offsets(text) == {j: pytest.approx(robot.encoder_offset.get(j, 0.0) + 0.01 / kp[j], rel=1e-15)
                                      for j in ("panda_joint1", "panda_joint2", "panda_joint4")}


ONE_JOINT = """<mujoco model="pendulum">
  <worldbody>
    <body name="base">
      <inertial pos="0 0 0" mass="1" diaginertia="0.01 0.01 0.01"/>
      <body name="arm" pos="0 0 -0.1">
        <joint name="hinge" axis="0 1 0" damping="0.7"/>
        <inertial pos="0 0 -0.2" mass="2" diaginertia="0.02 0.02 0.002"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="torque" joint="hinge" gear="3"/>
  </actuator>
</mujoco>
"""


def test_one_joint_position_actuator(tmp_path, fit_of):
    """A one-joint robot from an MJCF with its own motor on the joint: the export replaces the motor by the
    driver's actuator, whose torque on hand-set states is kp (q_des - q_enc) - kd qd - tau_os with q_enc = qpos +
    offset and tau_os the fit's."""
    (tmp_path / "pendulum.xml").write_text(ONE_JOINT)
    config = tmp_path / "pendulum.toml"
    config.write_text('name = "pendulum"\nmjcf = "pendulum.xml"\nfloating_base = false\n'
                      "[pd]\nkp = 30.0\nkd = 0.8\ndelay = 0.004\n[encoder_offset]\nhinge = -0.05\n")
    robot = load_robot(config=config)
    params = tmp_path / "p.json"
    write_params(params, [fit_of("hinge", "ok", F_v=0.11, F_c=0.33)], {"provenance": {"robot": "pendulum"}})
    out = tmp_path / "out.xml"
    export_files(robot, params, [out])
    m = mujoco.MjModel.from_xml_path(str(out))
    assert m.nu == 1 and m.actuator(0).name == "hinge" and m.actuator_gear[0, 0] == 1.0
    assert (m.dof_damping[0], m.dof_frictionloss[0]) == (0.11, 0.33)
    for q, qd, q_des in [(0.3, -1.2, 0.1), (-0.7, 0.4, 0.2), (0.0, 0.0, 0.0)]:
        d = mujoco.MjData(m)
        d.qpos[0], d.qvel[0], d.ctrl[0] = q, qd, q_des
        mujoco.mj_initCtrlHistory(m, d, 0, None, np.full((int(m.actuator_history[0, 0]), 1), q_des))
        mujoco.mj_forward(m, d)
        # the fit's tau_os (0.01 N·m) as a set-point offset: the joint gets -tau_os
        assert d.qfrc_actuator[0] == pytest.approx(30.0 * (q_des - (q - 0.05)) - 0.8 * qd - 0.01, abs=1e-12)


def init_history(m: mujoco.MjModel, d: mujoco.MjData, ctrl: np.ndarray) -> None:
    """Every actuator's history filled with its ``ctrl`` (the set-point held since before the start)."""
    for a in range(m.nu):
        n = int(m.actuator_history[a, 0])
        mujoco.mj_initCtrlHistory(m, d, a, None, np.full((n, 1), ctrl[a]))


def exported_tau_os(robot, fits) -> np.ndarray:
    """The constant tau_os [N·m] of each joint's exported fit (the ok ones: joints 1, 2, 4), 0 elsewhere."""
    tau_os = np.array([fits[j].params.tau_os if fits.get(j) is not None and fits[j].verdict().ok else 0.0
                       for j in robot.actuated])
    assert np.count_nonzero(tau_os) == 3
    return tau_os


def test_mjcf_applies_the_drivers_law(robot, mjcf):
    """On hand-set states (the set-points held since before the start, so their delay does not show), MuJoCo's
    joint torque from the actuators is the driver's law of wbfriction.model.pd on the encoder's reading qpos +
    offset, with the exported fit's constant tau_os as a set-point offset tau_os / kp: kp (q_des - tau_os / kp - q_enc)
    - kd qd, clipped at the limit (some states drive past it)."""
    _, m, fits = mjcf
    rng = np.random.default_rng(4)
    order = [m.joint(j).qposadr[0] for j in robot.actuated]
    dofs = [m.joint(j).dofadr[0] for j in robot.actuated]
    acts = [m.actuator(j).id for j in robot.actuated]
    offset = robot.offset_vector
    tau_os = exported_tau_os(robot, fits)
    clipped = 0
    for _ in range(20):
        d = mujoco.MjData(m)
        q, qd, q_des = rng.uniform(-1, 1, 7), rng.uniform(-2, 2, 7), rng.uniform(-1, 1, 7)
        d.qpos[order], d.qvel[dofs] = q, qd
        ctrl = np.zeros(m.nu)
        ctrl[acts] = q_des
        d.ctrl[:] = ctrl
        init_history(m, d, ctrl)
        mujoco.mj_forward(m, d)
        time = np.array([0.0, 1.0])
        q_set = q_des - tau_os / robot.pd.kp
        want = pd_torque(robot.pd, time, np.tile(q + offset, (2, 1)), np.tile(qd, (2, 1)), np.tile(q_set, (2, 1)))[0]
        raw = robot.pd.kp * (q_set - q - offset) - robot.pd.kd * qd
        clipped += int(np.sum(np.abs(raw) > robot.pd.torque_limit))
        np.testing.assert_allclose(d.qfrc_actuator[dofs], want, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(d.actuator_force[acts], want, rtol=1e-12, atol=1e-12)
    assert clipped > 0


@pytest.mark.parametrize("timestep, lag", [(None, 7), (0.001, 13), (0.0005, 26), (0.0007, 19)])
def test_mjcf_delays_the_setpoints_as_the_driver(robot, mjcf, timestep, lag):
    """Stepped at its own timestep (0.002 s: 6.5 steps) or a smaller one, whole (13, 26 steps) or not, with
    set-points that change every step: the force at each step is the driver's law with the set-point commanded
    DELAY before, held (zero-order): ceil(DELAY / timestep) steps back, every step."""
    _, m, fits = mjcf
    tau_os = exported_tau_os(robot, fits)
    if timestep is not None:
        m.opt.timestep = timestep
    acts = [m.actuator(j).id for j in robot.actuated]
    dofs = [m.joint(j).dofadr[0] for j in robot.actuated]
    qadr = [m.joint(j).qposadr[0] for j in robot.actuated]
    assert lag == math.ceil(DELAY / m.opt.timestep - 1e-6)
    d = mujoco.MjData(m)
    rng = np.random.default_rng(7)
    commanded = rng.uniform(-0.05, 0.05, (120, 7))
    init_history(m, d, np.zeros(m.nu))
    for k in range(120):
        ctrl = np.zeros(m.nu)
        ctrl[acts] = commanded[k]
        d.ctrl[:] = ctrl
        q, qd = d.qpos[qadr].copy(), d.qvel[dofs].copy()
        mujoco.mj_step(m, d)
        applied = commanded[k - lag] if k >= lag else np.zeros(7)
        raw = robot.pd.kp * (applied - q - robot.offset_vector) - robot.pd.kd * qd - tau_os
        want = np.clip(raw, -robot.pd.torque_limit, robot.pd.torque_limit)
        np.testing.assert_allclose(d.actuator_force[acts], want, rtol=1e-12, atol=1e-9, err_msg=f"step {k}")


def held_lags(delay: float, timestep: float, nsample: int, steps: int = 12) -> set[int]:
    """How many steps back a one-joint MuJoCo position actuator with ``delay``, ``nsample`` and zero-order hold
    reads its control, over ``steps`` steps once its history is full (each step's control its index)."""
    spec = mujoco.MjSpec()
    spec.option.timestep, spec.option.gravity = timestep, [0, 0, 0]
    body = spec.worldbody.add_body()
    body.add_joint(name="j")
    body.add_geom(size=[0.1, 0, 0], mass=1e12, contype=0, conaffinity=0)
    act = spec.add_actuator(target="j", trntype=mujoco.mjtTrn.mjTRN_JOINT)
    act.set_to_position(kp=1.0, kv=0.0)
    act.delay, act.nsample, act.interp = delay, nsample, 0
    m = spec.compile()
    d = mujoco.MjData(m)
    lags = set()
    for k in range(steps):
        d.ctrl[0] = float(k)
        mujoco.mj_step(m, d)
        if k >= nsample + 1:
            lags.add(round(k - d.actuator_force[0] - d.qpos[0]))
    return lags


def test_mujoco_reads_a_short_history_as_a_shorter_delay():
    """Why nsample covers the delay (history_samples): MuJoCo 4 reads a buffer shorter than the delay at its oldest
    sample, silently. One joint, 0.013 s at 0.005 s: 3 steps with 3 samples or more, 2 with 2."""
    assert history_samples(0.013, 0.005) == 27  # enough down to 0.5 ms
    assert [held_lags(0.013, 0.005, n, 14) for n in (2, 3, 4, 8)] == [{2}, {3}, {3}, {3}]


def test_mujoco_hold_edge():
    """Why the delay is written 1 ns less (HOLD_EDGE): a delay of whole timesteps sits on the sample times, and
    MuJoCo's zero-order hold reads one step early or late as the floating-point time rounds; 1 ns less reads the
    driver's sample every step."""
    assert held_lags(0.013, 0.001, 20, 3000) == {13, 14}
    assert held_lags(0.013 - HOLD_EDGE, 0.001, 20, 3000) == {13}
    assert held_lags(0.012 - HOLD_EDGE, 0.002, 20, 3000) == {6}
    assert held_lags(0.013 - HOLD_EDGE, 0.002, 20, 3000) == {7}  # not whole: the hold as it was


def test_robot_without_drivers_has_no_actuators(panda, params, tmp_path):
    """No [pd]: a motor per joint (ctrl = the torque; issue 67), no gain, no delay."""
    outs = [tmp_path / "a.xml", tmp_path / "a.yaml"]
    done = export_files(panda, params[0], outs)
    mj = mujoco.MjModel.from_xml_path(str(outs[0]))
    assert mj.nu == 7 and np.all(mj.actuator_biastype == mujoco.mjtBias.mjBIAS_NONE)
    assert np.all(mj.actuator_gainprm[:, 0] == 1.0) and not np.any(mj.actuator_delay)
    assert list(load_yaml(outs[1].read_text())) == ["joint_names_expr", "friction", "dynamic_friction",
                                                    "viscous_friction"]
    assert all(r.warnings == () for r in done.reports)


PD_TOML = """name = "panda_pd"
urdf = "example-robot-data:panda_description/urdf/panda.urdf"
floating_base = false
[locked_joints]
panda_finger_joint1 = 0.0
panda_finger_joint2 = 0.0
[pd]
kp = 60.0
kd = {shoulder = 2.0, upper_arm = 1.5, panda_joint5 = 0.5, panda_joint6 = 0.5, panda_joint7 = 0.5}
delay = 0.013
torque_limit = 40.0
[encoder_offset]
panda_joint2 = 0.0312
[groups]
shoulder = ["panda_joint1", "panda_joint2"]
upper_arm = ["panda_joint3", "panda_joint4"]
"""


def test_cli_physics_dt(params, tmp_path, capsys):
    """From a robot TOML's [pd] on the command line: --physics-dt counts the delay; its rounding is a warning line;
    a step that is not > 0 is one line naming the option, exit 2, nothing written."""
    config = tmp_path / "panda_pd.toml"
    config.write_text(PD_TOML)
    out = tmp_path / "a.yaml"
    code, err = run_cli(capsys, "export", params[0], "--config", config, "-o", out)
    assert code == 0, err
    assert "warning: the drivers' delay 0.013 s is 2.600 physics steps of 0.005 s" in " ".join(err.split())
    doc = load_yaml(out.read_text())
    assert doc["min_delay"] == 3 and by_joint(doc["stiffness"], ["panda_joint7"]) == {"panda_joint7": 60.0}
    assert by_joint(doc["damping"], ["panda_joint2"]) == {"panda_joint2": 2.0}
    code, err = run_cli(capsys, "export", params[0], "--config", config, "-o", out, "--physics-dt", "0.0013")
    assert code == 0 and "warning" not in err
    assert load_yaml(out.read_text())["max_delay"] == 10
    other = tmp_path / "b.yaml"
    code, err = run_cli(capsys, "export", params[0], "--config", config, "-o", other, "--physics-dt", "0")
    assert code == 2 and "--physics-dt must be a number in [1e-05, 0.1] s" in err and not other.exists()


def test_a_physics_step_nothing_reads_is_refused(params, tmp_path, capsys):
    """``--physics-dt`` counts a PD driver's delay in an Isaac Lab file's physics steps: given with outputs none of
    which counts it (an MJCF, a URDF), or for a robot without PD drivers, it is refused in one line before anything is
    written, not ignored (issue 65, class 6)."""
    config = tmp_path / "panda_pd.toml"
    config.write_text(PD_TOML)
    outs = [tmp_path / "a.xml", tmp_path / "a.urdf"]
    code, err = run_cli(capsys, "export", params[0], "--config", config, *sum((["-o", o] for o in outs), []),
                        "--physics-dt", "0.002")
    assert code == 2 and err.strip() == "error: --physics-dt: only a .yaml output counts a delay in physics steps", err
    code, err = run_cli(capsys, "export", params[0], "--robot", "panda", "-o", tmp_path / "a.yaml",
                        "--physics-dt", "0.002")
    assert code == 2 and err.strip() == ("error: --physics-dt: robot 'panda' has no PD drivers ([pd]) whose delay it "
                                         "counts"), err
    assert not [p for p in tmp_path.iterdir() if p.suffix in (".xml", ".urdf", ".yaml")]
    code, err = run_cli(capsys, "export", params[0], "--config", config, "-o", outs[0], "-o", tmp_path / "a.yaml",
                        "--physics-dt", "0.002")
    assert code == 0, err  # one output counts it


def test_a_torque_held_back_whole_is_said_by_both_targets(tmp_path):
    """``[pd] delayed = "torque"`` (PACE's actuator): neither Isaac Lab's DelayedPDActuator nor MuJoCo's actuator
    delay holds it; the export says so in one line and writes the delay as a set-point delay."""
    import wbfriction
    from wbfriction.export.registry import target_for
    from wbfriction.model.loading import example_robot_data_dir

    config = tmp_path / "hung.toml"
    config.write_text(f'name = "hung"\nurdf = "{example_robot_data_dir() / "go2_description/urdf/go2.urdf"}"\n'
                      'floating_base = false\n[pd]\nkp = 25.0\nkd = 0.5\ndelay = 0.01\ndelayed = "torque"\n')
    robot = wbfriction.load_robot(None, config=config)
    for name in ("robot.yaml", "robot.xml"):
        report = target_for(tmp_path / name).write(tmp_path / name, robot, {})
        assert any("hold back their whole torque" in w for w in report.warnings), name
