"""A PD-driven robot's log columns (logs/pd.py): the torque's source, the gains logged, the encoder offset, the
errors; the identified TOML written back (pipeline/actuator_step.py)."""

from __future__ import annotations

import tomllib

import numpy as np
import pyarrow as pa
import pytest

import wbfriction
from wbfriction.exceptions import ColumnError, InputError
from wbfriction.logs.log import log_from_table
from wbfriction.model.loading import example_robot_data_dir
from wbfriction.model.pd import delayed, pd_torque

N = 300
T = 0.005


def robot_toml(folder, extra: str = "") -> str:
    path = folder / "hung.toml"
    path.write_text(f'name = "hung"\nurdf = "{example_robot_data_dir() / "go2_description/urdf/go2.urdf"}"\n'
                    "floating_base = false\n[pd]\nkp = 20.0\nkd = 0.4\ndelay = 0.0075\n" + extra)
    return str(path)


@pytest.fixture
def robot(tmp_path):
    return wbfriction.load_robot(None, config=robot_toml(tmp_path, "[encoder_offset]\nFL_hip_joint = 0.05\n"))


def table(robot, **extra) -> pa.Table:
    rng = np.random.default_rng(3)
    t = np.arange(N) * T
    cols = {"time": t}
    lower, upper = robot.angle_limits
    for i, j in enumerate(robot.actuated):
        base = 0.5 * (lower[i] + upper[i])
        cols |= {f"q.{j}": base + 0.1 * np.sin(2 * t + i), f"qd.{j}": 0.2 * np.cos(2 * t + i),
                 f"q_des.{j}": base + 0.1 * np.sin(2 * t + i + 0.1) + 0.01 * rng.normal(size=N)}
    for prefix, value in extra.items():
        cols |= {f"{prefix}.{j}": np.full(N, value) for j in robot.actuated}
    return pa.table(cols)


def column(t: pa.Table, prefix: str, robot) -> np.ndarray:
    return np.column_stack([t[f"{prefix}.{j}"].to_numpy() for j in robot.actuated])


def test_the_pd_law_on_the_encoder_then_the_model_angle_less_its_offset(robot):
    t = table(robot)
    log = log_from_table(t, robot, "hung.parquet")
    q_logged = column(t, "q", robot)
    np.testing.assert_array_equal(log.tau, pd_torque(robot.pd, log.time, q_logged, column(t, "qd", robot),
                                                     column(t, "q_des", robot)))
    offset = np.zeros(robot.n_act)
    offset[robot.actuated.index("FL_hip_joint")] = 0.05
    np.testing.assert_allclose(log.q, q_logged - offset, atol=1e-15)
    back = log.to_table(robot)
    np.testing.assert_allclose(column(back, "q", robot), q_logged, atol=1e-15)  # the encoder's reading again
    np.testing.assert_array_equal(column(back, "q_des", robot), column(t, "q_des", robot))


def test_logged_gains_replace_the_tomls(robot):
    t = table(robot, kp=10.0, kd=0.0)
    log = log_from_table(t, robot, "hung.parquet")
    expected = 10.0 * (delayed(column(t, "q_des", robot), log.time, 0.0075) - column(t, "q", robot))
    np.testing.assert_allclose(log.tau, expected, atol=1e-12)


def test_the_drivers_estimate_comes_first_and_is_said(robot):
    log = log_from_table(table(robot, tau_est=1.5), robot, "hung.parquet")
    assert log.torque_source == "driver"
    np.testing.assert_array_equal(log.tau, 1.5)


@pytest.mark.parametrize(("prefix", "source"), [("tau", "sensor"), ("tau_est", "driver")])
def test_a_measured_torque_and_its_setpoints_are_written_back_both(robot, prefix, source):
    """A log of measured torques that also holds set-points is written back with both (it was written as its
    set-points alone, a PD law's log: its measured torque dropped, or with the drivers' estimates, its set-points):
    read again, the same source, torque and set-points."""
    log = log_from_table(table(robot, **{prefix: 1.5}), robot, "hung.parquet")
    assert log.torque_source == source
    back = log_from_table(log.to_table(robot), robot, "back.parquet")
    assert back.torque_source == source
    np.testing.assert_array_equal(back.tau, log.tau)
    np.testing.assert_array_equal(back.setpoints.q_des, log.setpoints.q_des)


@pytest.mark.parametrize(("change", "message"), [
    (lambda t: t.drop(["q_des.FL_hip_joint"]), r"or 'q_des.FL_hip_joint' with \[pd\] gains"),
    (lambda t: t.append_column("tau_est.FL_hip_joint", t["q.FL_hip_joint"]), "missing column 'tau_est.FL_thigh_joint'"),
    (lambda t: t.append_column("kp.FL_hip_joint", t["q.FL_hip_joint"]), "missing column 'kp.FL_thigh_joint'"),
    (lambda t: t.append_column("q_des.nope", t["q.FL_hip_joint"]), "unknown joint 'nope'"),
])
def test_bad_columns_are_refused_naming_the_file_and_column(robot, change, message):
    with pytest.raises(ColumnError, match=message) as err:
        log_from_table(change(table(robot)), robot, "hung.parquet")
    assert str(err.value).startswith("hung.parquet")


def test_setpoints_without_gains_are_refused(tmp_path, robot):
    plain = tmp_path / "plain.toml"
    plain.write_text(f'name = "plain"\nurdf = "{robot.urdf}"\nfloating_base = false\n')
    other = wbfriction.load_robot(None, config=plain)
    with pytest.raises(ColumnError, match=r"is a PD set-point, but robot 'plain' has no \[pd\] gains"):
        log_from_table(table(robot), other, "hung.parquet")


def test_the_identified_toml_keeps_the_rest_and_writes_what_was_chosen(tmp_path):
    from wbfriction.actuator.identification import ActuatorIdentification, Identified, JointActuator
    from wbfriction.actuator.written import WrittenChoice, WrittenValue
    from wbfriction.pipeline.actuator_step import actuator_config

    path = robot_toml(tmp_path, "[armature]   # given\nFL_hip_joint = 0.001\nFR_hip_joint = 0.002\n")
    ok, bound = Identified(0.011, 1e-4, 1e-4), Identified(0.0, 1e-3, 1e-3, "at bound", "armature at bound")
    joints = (JointActuator("FL_hip_joint", ok, ok, ok, Identified(0.02, 1e-3, 1e-3), 0.0, 0.0, 1),
              JointActuator("FR_hip_joint", bound, ok, ok, Identified(0.3, 1e-3, 1e-3, "at bound"), 0.0, 0.0, 1))
    nan2 = (np.nan, np.nan)

    def chosen(kind: str, joint: str, identified: float, given: float, source: str) -> WrittenValue:
        return WrittenValue(kind, joint, identified, given, source, nan2, np.nan, np.inf, "")  # type: ignore[arg-type]

    choice = WrittenChoice(chosen("delay", "", 0.012, 0.0, "identified"),
                           (chosen("armature", "FL_hip_joint", 0.011, 0.001, "identified"),
                            chosen("offset", "FL_hip_joint", 0.02, 0.0, "identified"),
                            chosen("armature", "FR_hip_joint", 0.0, 0.002, "given"),
                            chosen("offset", "FR_hip_joint", 0.3, 0.0, "given")), 10)
    result = ActuatorIdentification(joints, Identified(0.012, 1e-4, 1e-4), T, 0.04, np.empty((0, 2)), {}, {}, "x",
                                    written=choice)
    text = open(path).read()
    written = tomllib.loads(actuator_config(text, tmp_path, tmp_path / "go2.urdf", tmp_path / "out.toml", result))
    assert written["armature"] == {"FL_hip_joint": 0.011, "FR_hip_joint": 0.002}  # the TOML's kept where chosen
    assert written["encoder_offset"] == {"FL_hip_joint": 0.02}
    assert written["pd"] == {"kp": 20.0, "kd": 0.4, "delay": 0.012}  # what the delay holds back: not decided here
    assert written["name"] == "hung" and written["floating_base"] is False


def test_the_identification_refuses_a_log_whose_torque_is_not_the_pd_laws(robot):
    from wbfriction.actuator import identify_actuators

    with pytest.raises(InputError, match="not the PD law"):
        identify_actuators(robot, log_from_table(table(robot, tau_est=1.0), robot, "est.parquet"))
    talos = wbfriction.load_robot("talos")
    with pytest.raises(InputError, match="no \\[pd\\] gains"):
        identify_actuators(talos, log_from_table(table(robot), robot, "x"))


@pytest.mark.parametrize("wrap", ["(-pi, pi]", "[0, 2pi)"])
def test_a_continuous_joints_setpoint_is_read_on_its_angles_branch(tmp_path, wrap):
    """Issue 65, class 8: the Go2's front left thigh made continuous, swinging across where the logger wraps its angle
    (π in (−π, π], 0 in [0, 2π)), its angle and set-point wrapped alike, each on its own side of the wrap at times:
    the drivers' torque is the PD law on the unwrapped angle and set-point (written from their definitions). The
    set-point read as logged was a turn from the angle there: ``kp 2π`` = 126 N·m, clipped at the drive's limit."""
    urdf = tmp_path / "go2_continuous.urdf"
    text = (example_robot_data_dir() / "go2_description/urdf/go2.urdf").read_text()
    at = text.index('name="FL_thigh_joint"')
    urdf.write_text(text[:at] + text[at:].replace('type="revolute"', 'type="continuous"', 1))
    config = tmp_path / "continuous.toml"
    config.write_text(f'name = "hung"\nurdf = "{urdf}"\nfloating_base = false\n[pd]\nkp = 20.0\nkd = 0.4\n'
                      "delay = 0.0075\n")
    robot = wbfriction.load_robot(None, config=config)
    i = robot.actuated.index("FL_thigh_joint")
    assert list(robot.layout.q2_joint) == [i]
    t = table(wbfriction.load_robot(None, config=robot_toml(tmp_path)))  # the same joints, revolute
    time = t["time"].to_numpy()
    wraps_at = np.pi if wrap == "(-pi, pi]" else 0.0
    q, q_des = wraps_at + 0.3 * np.sin(4 * time), wraps_at + 0.3 * np.sin(4 * time + 0.1)  # the angles as they are
    reduce = ((lambda x: x - 2 * np.pi * np.ceil((x - np.pi) / (2 * np.pi))) if wrap == "(-pi, pi]"
              else (lambda x: np.mod(x, 2 * np.pi)))
    assert np.any(np.abs(reduce(q_des) - reduce(q)) > np.pi)  # a turn apart as logged
    for prefix, x in (("q", q), ("q_des", q_des)):
        t = t.set_column(t.column_names.index(f"{prefix}.FL_thigh_joint"), f"{prefix}.FL_thigh_joint",
                         pa.array(reduce(x)))
    log = log_from_table(t, robot, "hung.parquet")
    angles, setpoints = column(t, "q", robot), column(t, "q_des", robot)
    angles[:, i], setpoints[:, i] = q, q_des
    expected = pd_torque(robot.pd, log.time, angles, column(t, "qd", robot), setpoints)
    np.testing.assert_allclose(log.tau, expected, rtol=0, atol=1e-12)
    assert np.abs(log.tau[:, i]).max() < 3.0
