"""The actuators of a hung PD-driven robot identified (issue 55): armature, friction, encoder offsets and delay
recovered from a log simulated with them, the same log read back through the PD columns.

The ground truth is simulated here by Pinocchio, independently of the identification's momentum balance: a Go2
(example-robot-data) on a fixed base, its joints' accelerations from ABA with the armature in the model, the
drivers' PD law at every 0.5 ms physics step on the encoder's reading (the true angle plus its offset), the set-points
of a 200 Hz log held and applied ``delay`` late, a smooth Coulomb-viscous friction; semi-implicit Euler.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pyarrow as pa
import pytest

import wbfriction
from wbfriction.actuator import ActuatorOptions, identify_actuators
from wbfriction.exceptions import InputError
from wbfriction.logs.log import log_from_table
from wbfriction.model.loading import example_robot_data_dir
from wbfriction.model.pd import pd_torque

T = 0.005
SUBSTEPS = 10
TRUTH = {"armature": 0.012, "F_v": 0.2, "F_c": 0.35, "delay": 0.0125}
OFFSETS = np.array([0.03, -0.04, 0.05] * 4)


def go2_toml(folder, offsets: bool = False) -> str:
    path = folder / "go2_hung.toml"
    text = (f'name = "go2-hung"\nurdf = "{example_robot_data_dir() / "go2_description/urdf/go2.urdf"}"\n'
            "floating_base = false\n[pd]\nkp = 25.0\nkd = 0.5\n")
    path.write_text(text)
    return str(path)


def triangles(n: int, joints: int, seed: int) -> np.ndarray:
    """Triangle ramps about a standing leg's posture, each joint its own reversal periods (0.2-0.8 s)."""
    rng = np.random.default_rng(seed)
    centre = np.array([0.0, 0.8, -1.5] * 4)
    t = np.arange(n) * T
    out = np.empty((n, joints))
    for j in range(joints):
        period = rng.uniform(0.4, 1.6)
        phase = rng.uniform(0, period)
        saw = 2 * np.abs(((t + phase) / period) % 1.0 - 0.5)  # 0..1..0
        out[:, j] = centre[j] + 0.3 * (saw - 0.5)
    return out


def simulate(robot, n: int, offsets: np.ndarray, seed: int = 0) -> pa.Table:
    """The hung robot driven through ``n`` log samples (module docstring); the log's columns."""
    model = pin.buildModelFromUrdf(str(robot.urdf))
    assert tuple(model.names[1:]) == robot.actuated
    model.armature[:] = TRUTH["armature"]
    data = model.createData()
    q_des = triangles(n, model.nv, seed)
    q, v = q_des[0].copy(), np.zeros(model.nv)
    h = T / SUBSTEPS
    Q, V = np.empty((n, model.nv)), np.empty((n, model.nv))
    for i in range(n):
        Q[i], V[i] = q + offsets, v
        for s in range(SUBSTEPS):
            k = max(int(np.floor((i * T + s * h - TRUTH["delay"]) / T + 1e-9)), 0)
            tau = 25.0 * (q_des[k] - (q + offsets)) - 0.5 * v
            tau_f = -(TRUTH["F_v"] * v + TRUTH["F_c"] * np.tanh(100.0 * v))
            v = v + h * pin.aba(model, data, q, v, tau + tau_f)
            q = q + h * v
    cols = {"time": np.arange(n) * T}
    for j, name in enumerate(robot.actuated):
        cols |= {f"q.{name}": Q[:, j], f"qd.{name}": V[:, j], f"q_des.{name}": q_des[:, j]}
    return pa.table(cols)


@pytest.fixture(scope="module")
def hung(tmp_path_factory):
    folder = tmp_path_factory.mktemp("hung")
    robot = wbfriction.load_robot(None, config=go2_toml(folder))
    return robot, simulate(robot, 1200, OFFSETS)


def test_the_log_reads_as_the_pd_law(hung):
    robot, table = hung
    log = log_from_table(table, robot, "hung.parquet")
    assert log.torque_source == "pd" and log.metadata["torque_alignment"] == "sample"
    q = np.column_stack([table[f"q.{j}"].to_numpy() for j in robot.actuated])
    expected = pd_torque(robot.pd, log.time, q, log.qd_logged,
                         np.column_stack([table[f"q_des.{j}"].to_numpy() for j in robot.actuated]))
    np.testing.assert_array_equal(log.tau, expected)


def test_the_delay_and_offsets_recovered_noise_free(hung):
    """A second simulator (Pinocchio's ABA, its own integration; the MuJoCo hung Go2 is tests/actuator/
    test_hung_truth.py's): the delay within one of its physics steps, every offset within 3 mrad, every armature within
    5 %; its sharp triangle reversals at 200 Hz leave the friction's split between F_c and F_v to the MuJoCo test."""
    robot, table = hung
    result = identify_actuators(robot, log_from_table(table, robot, "hung.parquet"))
    assert abs(result.delay.value - TRUTH["delay"]) < T / SUBSTEPS
    assert result.delay.status == "ok"
    for i, joint in enumerate(result.joints):
        assert joint.armature.value == pytest.approx(TRUTH["armature"], rel=0.05), joint.joint
        assert joint.offset is not None
        assert joint.offset.value == pytest.approx(OFFSETS[i], abs=0.003), joint.joint
        assert joint.armature.status == "ok"


def test_a_known_delay_and_no_offsets_are_taken_as_given(hung, tmp_path):
    robot, table = hung
    result = identify_actuators(robot, log_from_table(table, robot, "hung.parquet"),
                                ActuatorOptions(delay=TRUTH["delay"], offset_bound=0.0))
    assert result.delay.value == TRUTH["delay"] and result.delay.reason == "given (--delay)"
    assert all(j.offset is None for j in result.joints)


def test_a_torque_from_a_sensor_is_refused(hung):
    robot, table = hung
    with_tau = table.append_column(f"tau_est.{robot.actuated[0]}", table[f"q.{robot.actuated[0]}"])
    for j in robot.actuated[1:]:
        with_tau = with_tau.append_column(f"tau_est.{j}", table[f"q.{j}"])
    log = log_from_table(with_tau, robot, "est.parquet")
    assert log.torque_source == "driver"  # the drivers' estimate is measured: it comes first
    with pytest.raises(InputError, match="not the PD law"):
        identify_actuators(robot, log)
