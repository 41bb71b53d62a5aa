"""The hung PD-driven quadruped (Go2) on MuJoCo: its drivers' torque against the lead's PD law recomputed from the
logged columns, its limits and delay, the friction and armature against an independent inverse dynamics
(Pinocchio), its noise, its bytes, its set-points and the command line."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from tests.helpers import run_cli
from tests.toys.toy_family import FixedSlopeParams

from helpers import said
from wbfriction.exceptions import InputError
from wbfriction.friction.families.names import UnknownFamilyError
from wbfriction.friction.models import CoulombViscousParams, StribeckParams, target_from_dict
from wbfriction.logs.tables import read_metadata, read_table, write_table
from wbfriction.model.loading import load_robot
from wbfriction.model.pd import PdDriver, pd_torque
from wbfriction.sim.arm import arm_model
from wbfriction.sim.hung import setpoint_band, setpoints, simulate_hung
from wbfriction.sim.pd_options import REAL_DRIVER, DriverNoise, HungOptions, SetpointOptions
from wbfriction.sim.pd_robot import Commands, PdRun, build_pd_robot, step_setpoints

T = 0.005  # the log's period at 200 Hz


def columns(table, prefix, robot):
    return np.column_stack([table[f"{prefix}.{j}"].to_numpy() for j in robot.actuated])


@pytest.fixture(scope="module")
def staircase(go2, mjr):
    """Set-points held 5 samples (as the real Aliengo's), a real driver's noise, the TOML's 12 ms delay."""
    options = HungOptions(duration=2.0, setpoints=SetpointOptions(hold=5, seed=3), noise=REAL_DRIVER)
    return simulate_hung(go2, options, mjr=mjr)


def constant_over_periods(q_des: np.ndarray, time: np.ndarray, delay: float) -> np.ndarray:
    """(N, n): whether no commanded change of the set-point, applied ``delay`` late, falls within the sample's
    period [t_i - T/2, t_i + T/2] (by brute force over the switches)."""
    out = np.ones(q_des.shape, dtype=bool)
    for j in range(q_des.shape[1]):
        switches = time[1:][np.diff(q_des[:, j]) != 0] + delay
        inside = np.abs(time[:, None] - switches[None, :]) <= T / 2 + 1e-9
        out[:, j] = ~inside.any(axis=1)
    return out


@settings(max_examples=40, deadline=None)
@given(delay_steps=st.floats(0.0, 20.0), substeps=st.integers(1, 6), seed=st.integers(0, 2**16))
def test_a_step_applies_the_held_setpoints_mean_over_it(delay_steps, substeps, seed):
    """Each physics step's set-point is the mean over the step of the commanded samples held and delayed (a brute
    force over a fine grid); a delay of whole steps gives the held values themselves, bit for bit."""
    values = np.random.default_rng(seed).normal(size=(12, 2))
    n_steps = 12 * substeps
    got = step_setpoints(values, substeps, delay_steps, 0, n_steps)
    fine = (np.arange(2000) + 0.5) / 2000
    for s in range(n_steps):
        k = np.clip(np.floor((s + fine - delay_steps) / substeps).astype(int), 0, 11)
        np.testing.assert_allclose(got[s], values[k].mean(axis=0), atol=3e-3)
    whole = step_setpoints(values, substeps, float(round(delay_steps)), 0, n_steps)
    k = np.clip((np.arange(n_steps) - round(delay_steps)) // substeps, 0, 11)
    assert np.array_equal(whole, values[k])


def test_the_applied_torque_is_the_pd_law_of_the_logged_columns(go2, staircase):
    """Where the delayed set-point is constant over a sample's period, the torque the driver applied
    (``tau_true``) is the lead's ``pd_torque`` of the logged encoder angles, driver velocities and set-points,
    noise included, to rounding; where a switch falls inside the period it is not (the check sees the delay), and
    with the delay one physics step off it fails on the samples that then hold a switch."""
    table, driver = staircase.table, staircase.driver
    time = table["time"].to_numpy()
    q, qd, q_des, qd_des = (columns(table, p, go2) for p in ("q", "qd", "q_des", "qd_des"))
    tau_true = columns(table, "tau_true", go2)
    law = pd_torque(driver, time, q, qd, q_des, qd_des)
    constant = constant_over_periods(q_des, time, driver.delay)
    assert 0.6 < constant.mean() < 0.95  # both kinds of samples, many of each
    np.testing.assert_allclose(tau_true[constant], law[constant], rtol=0, atol=1e-12)
    switched = ~constant & (time[:, None] > driver.delay + T)
    assert np.all(np.abs(tau_true - law)[switched] > 1e-6)
    late = pd_torque(driver, time, q, qd, q_des, qd_des, delay=driver.delay + 0.001)
    off = constant & ~constant_over_periods(q_des, time, driver.delay + 0.001)
    assert off.sum() > 50 and np.all(np.abs(tau_true - late)[off] > 1e-6)


def test_the_torque_limits_clip(go2):
    """With a 1.5 N·m limit the drivers' torque stays within it and sits on it where the PD law asks for more: the
    law with the limit matches the applied torque, the law without exceeds the limit there."""
    pd = go2.pd
    tight = dataclasses.replace(go2, pd=PdDriver(pd.joints, pd.kp, pd.kd, pd.delay, np.full(12, 1.5)))
    sim = simulate_hung(tight, HungOptions(duration=2.0, setpoints=SetpointOptions(hold=5)))
    table = sim.table
    time = table["time"].to_numpy()
    q, qd, q_des, qd_des = (columns(table, p, go2) for p in ("q", "qd", "q_des", "qd_des"))
    tau = columns(table, "tau_true", go2)
    assert np.abs(tau).max() == 1.5
    at_limit = np.abs(tau) == 1.5
    assert at_limit.mean() > 0.05
    constant = constant_over_periods(q_des, time, pd.delay)
    np.testing.assert_allclose(tau[constant], pd_torque(tight.pd, time, q, qd, q_des, qd_des)[constant], atol=1e-12)
    free = pd_torque(pd.with_delay(pd.delay), time, q, qd, q_des, qd_des)  # the URDF's 23.7/45.4 N·m: not reached
    assert np.all(np.abs(free[constant & at_limit]) > 1.5)


@pytest.mark.parametrize("delay, jumps", [(0.012, {112: 1.0}), (0.0124, {112: 0.6, 113: 0.4})])
def test_a_step_setpoint_reaches_the_torque_after_the_delay(go2, mjr, delay, jumps):
    """A set-point step commanded at sample 100 of a 1 kHz log (one physics step per sample) changes the torque by
    kp x step at 100 + delay: at one step for a delay of whole steps, shared by the two steps around it
    (0.6 and 0.4 of it for 12.4 ms) otherwise; no other step moves the torque by a tenth of that."""
    n, step = 200, 0.1
    posture, _, _ = setpoint_band(go2, 0.25)
    q_des = np.tile(posture, (n, 1))
    q_des[100:] += step
    run = PdRun(mjr, 1e-3, 1, go2.pd.with_delay(delay), np.full(12, 0.015), np.zeros(12), {})
    tau = run.run(Commands(q_des, np.zeros_like(q_des), np.zeros_like(q_des)), 0, n, posture, np.zeros(12)).tau
    change = np.diff(tau, axis=0)  # change[k]: from step k to k + 1
    kp = go2.pd.kp
    for k, share in jumps.items():
        np.testing.assert_allclose(change[k - 1], share * kp * step, rtol=0.04)
    others = np.delete(change, [k - 1 for k in jumps], axis=0)
    assert np.abs(others).max() < 0.1 * kp[0] * step


def mixed_friction(robot) -> dict:
    """Stribeck on the hips, Coulomb-viscous elsewhere, each joint its own."""
    return {j: (StribeckParams(F_v=0.2 + 0.01 * i, F_c=0.3, F_s=0.45, v_s=0.1) if "hip" in j
                else CoulombViscousParams(F_v=0.25 + 0.01 * i, F_c=0.35 + 0.02 * i, tau_os=0.02))
            for i, j in enumerate(robot.actuated)}


def momentum_residual(robot, table, armature: np.ndarray) -> np.ndarray:
    """(M(q) + diag(armature)) qdd + h(q, qd) - tau - tau_f at every sample, from the logged truth (Pinocchio's
    RNEA on the fixed-base model, the model angle = the noise-free logged angle less the encoder offset)."""
    model = arm_model(robot)
    model.armature = np.asarray(armature, dtype=float)
    data = model.createData()
    meta = read_metadata(table)
    offset = np.array([meta["encoder_offset_true"][j] for j in robot.actuated])
    q = columns(table, "q", robot) - offset
    qd, qdd = columns(table, "qd_true", robot), columns(table, "qdd_true", robot)
    tau = columns(table, "tau_true", robot) + columns(table, "tau_f_true", robot)
    return np.array([pin.rnea(model, data, q[k], qd[k], qdd[k]) for k in range(len(q))]) - tau


@pytest.mark.parametrize("mode", ["model", "mujoco"])
def test_the_logged_friction_and_armature_close_the_dynamics(go2, mjr, mode):
    """The logged truth closes the fixed-base dynamics with the armature injected, on Pinocchio (independent of
    MuJoCo), to 1e-9 N·m; twice the armature leaves a residual of tenths of N·m. With the ``model`` friction the
    logged friction is each joint's ``-f(qd_true)`` of its family (Stribeck on the hips); with MuJoCo's own
    (Coulomb-viscous) it is the friction-loss constraint's force plus the damper's."""
    friction = mixed_friction(go2) if mode == "model" else None  # MuJoCo's: the default Coulomb-viscous
    sim = simulate_hung(go2, HungOptions(duration=1.5, friction=mode), friction, mjr=mjr)
    table = sim.table
    residual = momentum_residual(go2, table, sim.armature)
    assert np.abs(residual).max() < 1e-9
    assert np.abs(momentum_residual(go2, table, 2 * sim.armature)).max() > 0.1
    qd_true, tau_f = columns(table, "qd_true", go2), columns(table, "tau_f_true", go2)
    if mode == "model":
        for j, p in sim.friction.items():
            i = go2.actuated.index(j)
            np.testing.assert_allclose(tau_f[:, i], p.torque(qd_true[:, i]), rtol=1e-12, atol=1e-12)
    else:
        moving = np.abs(qd_true) > 0.05  # sliding: Coulomb's level plus the damper, against the velocity
        expected = -np.array([[p.F_c, p.F_v] for p in sim.friction.values()])
        slide = expected[:, 0] * np.sign(qd_true) + expected[:, 1] * qd_true
        assert np.abs(tau_f - slide)[moving].max() < 0.05 * np.abs(slide[moving]).max()
    meta = read_metadata(table)
    assert {j: target_from_dict(d) for j, d in meta["friction_true"].items()} == sim.friction


def test_noise_free_is_exactly_noise_free_and_the_real_drivers_noise_is_as_measured(go2, mjr, staircase):
    """Without noise the logged angle is the model's plus the offset and the driver's velocity the true one, bit for
    bit; with a real driver's, the angles lie on the encoders' lattice within half a step of the truth and the
    velocities' noise has the measured 0.08 rad/s."""
    exact = simulate_hung(go2, HungOptions(duration=1.0), mjr=mjr)
    table, tr = exact.table, exact.trajectory
    assert np.array_equal(columns(table, "q", go2), tr.q + exact.encoder_offset)
    assert np.array_equal(columns(table, "qd", go2), columns(table, "qd_true", go2))
    assert read_metadata(table)["driver_noise"]["encoder_resolution"] is None
    noisy, tr = staircase.table, staircase.trajectory
    q = columns(noisy, "q", go2)
    resolution = np.array([read_metadata(noisy)["driver_noise"]["encoder_resolution"][j] for j in go2.actuated])
    assert resolution[2] == pytest.approx(3.835e-5, rel=1e-3) and resolution[0] == pytest.approx(1.198e-5, rel=1e-3)
    steps = q / resolution
    assert np.abs(steps - np.round(steps)).max() < 1e-6
    assert np.abs(q - (tr.q + staircase.encoder_offset)).max() <= resolution.max() / 2 * (1 + 1e-9)
    velocity_error = columns(noisy, "qd", go2) - columns(noisy, "qd_true", go2)
    assert np.std(velocity_error, axis=0) == pytest.approx(np.full(12, 0.08), rel=0.1)


def test_a_seed_gives_the_same_bytes(go2, mjr, tmp_path):
    """The same options write the same file, byte for byte; another noise seed or set-point seed another."""
    def written(name: str, options: HungOptions) -> bytes:
        path = tmp_path / f"{name}.parquet"
        write_table(simulate_hung(go2, options, mjr=mjr).table, path)
        return path.read_bytes()

    options = HungOptions(duration=0.5, noise=dataclasses.replace(REAL_DRIVER, seed=3))
    first = written("a", options)
    assert written("b", options) == first
    assert written("c", dataclasses.replace(options, noise=REAL_DRIVER)) != first
    assert written("d", dataclasses.replace(options, setpoints=SetpointOptions(seed=1))) != first


@pytest.mark.parametrize("kind", ["ramps", "chirps", "both"])
def test_the_setpoints_stay_in_their_band_and_reverse_as_the_real_logs(go2, kind):
    """The set-points start at the standing posture, stay in each joint's band inside its limits, their slope is
    their derivative; the ramps reverse every 0.2-1.5 s (the last one back to the posture: up to 1.7 s), the
    chirps sweep, ``both`` is continuous where the chirps begin; a hold makes a staircase."""
    time = np.arange(int(20.0 / T)) * T
    options = SetpointOptions(kind=kind, seed=7)
    q, qd = setpoints(go2, time, options)
    posture, low, high = setpoint_band(go2, options.amplitude)
    lo, hi = go2.angle_limits
    assert np.allclose(q[0], posture) and np.all(low >= lo) and np.all(high <= hi)
    assert np.all(q >= low - 1e-12) and np.all(q <= high + 1e-12)
    smooth = np.abs(np.diff(qd, axis=0)).max(axis=1) < 0.2  # no reversal within the step
    np.testing.assert_allclose(np.diff(q, axis=0)[smooth], (qd[:-1][smooth] + qd[1:][smooth]) / 2 * T,
                               atol=2e-4 if kind != "ramps" else 1e-12)
    ramps = {"ramps": 20.0, "chirps": 0.0, "both": 10.0}[kind]
    for j in range(go2.n_act):
        ramp = time < ramps
        if ramp.any():
            sign = np.sign(qd[ramp, j])
            reversals = time[ramp][1:][np.diff(sign) != 0]
            gaps = np.diff(np.r_[0.0, reversals])
            assert gaps.min() >= 0.2 - 1e-9 and gaps.max() <= 1.7 + 1e-9 and len(gaps) >= ramps / 1.7
    staircase, _ = setpoints(go2, time, dataclasses.replace(options, hold=5))
    blocks = staircase.reshape(-1, 5, go2.n_act)
    assert np.array_equal(blocks, np.repeat(blocks[:, :1], 5, axis=1))


def test_the_metadata_names_the_truth(go2, mjr):
    """The metadata holds what was injected: gains, limits, delay (the one given), armature and offsets (the robot's
    TOML), friction, the physics step."""
    sim = simulate_hung(go2, HungOptions(duration=0.3, delay=0.0131), mjr=mjr)
    meta = read_metadata(sim.table)
    assert meta["delay_true"] == 0.0131 and meta["pd_true"]["delay"] == 0.0131
    assert meta["physics_step"] == pytest.approx(1e-3)
    assert meta["pd_true"]["kp"]["FL_calf_joint"] == 25.0 and meta["pd_true"]["kd"]["RR_hip_joint"] == 0.5
    assert meta["pd_true"]["torque_limit"]["FL_calf_joint"] == pytest.approx(45.43)
    assert meta["armature_true"]["RL_calf_joint"] == 0.0215
    assert meta["encoder_offset_true"] == go2.encoder_offset
    assert meta["actuator"] == "pd"
    assert set(sim.table.column_names) >= {f"{p}.FL_hip_joint" for p in
                                           ("q", "qd", "q_des", "qd_des", "tau_true", "tau_f_true", "qd_true",
                                            "qdd_true")}


def test_robots_it_does_not_simulate(go2):
    """A floating base, a robot without [pd], a noise level naming no joint or group, friction of a family the
    registry does not know (any it knows is simulated: ``test_injected_families.py``): one clear error each."""
    with pytest.raises(InputError, match="floating base"):
        build_pd_robot(load_robot("talos"))
    with pytest.raises(InputError, match="not PD-driven"):
        build_pd_robot(load_robot("panda"))
    with pytest.raises(InputError, match="'knee' is neither"):
        simulate_hung(go2, HungOptions(duration=0.1, noise=DriverNoise(velocity_std={"knee": 0.1})))
    with pytest.raises(UnknownFamilyError, match="fixed-slope"):  # the toy, not registered: not dropped in silence
        simulate_hung(go2, HungOptions(duration=0.1), {"FL_hip_joint": FixedSlopeParams(F_c=0.3)})


def test_the_command_line_simulates_a_hung_go2(capsys, tmp_path):
    """``wbfriction simulate --robot go2 --actuator pd`` writes the hung log; --delay [ms] and --driver-noise none are
    the simulation's; a floating-base robot is refused in one line."""
    out = tmp_path / "hung.parquet"
    code, err = run_cli(capsys, "simulate", "--robot", "go2", "--actuator", "pd", "-o", out, "--duration", "0.5",
                        "--delay", "10", "--driver-noise", "none")
    assert code == 0, err
    table = read_table(out)
    meta = read_metadata(table)
    assert meta["delay_true"] == pytest.approx(0.01) and table.num_rows == 100
    robot = load_robot("go2")
    assert np.array_equal(columns(table, "qd", robot), columns(table, "qd_true", robot))
    code, err = run_cli(capsys, "simulate", "--robot", "talos", "--actuator", "pd", "-o", tmp_path / "x.parquet")
    assert code != 0 and "floating base" in err and len(said(err)) == 1
