"""The exported simulator replayed (issue 64, item 3): the MJCF ``wbfriction export`` writes of the hung Go2's true
parameters, replayed under its log's set-points, tracks the log the project's simulator wrote with MuJoCo's own
friction (two routes to one motion); a wrong parameter in the file is seen; PACE's actuator (the torque held back
whole periods) is the peer's; and what a replay refuses."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pyarrow as pa
import pytest

from helpers import assert_stages, hung_go2_toml, hung_truth_mjcf, run_cli_printed, said
from wbfriction.exceptions import InputError
from wbfriction.export.mjcf import write_mjcf
from wbfriction.logs.tables import read_table
from wbfriction.replay.mjcf import Replay, replay_mjcf

AGREE = 1e-3
"""The truth's MJCF against the simulator that wrote the log, noise-free, the file stepped at the simulator's 1 ms:
measured 3.9e-4 rad RMS at worst over 6 s. The models are the same (masses, armature, friction loss and its
constraint's softness, gains, offsets, delay); MuJoCo integrates the position actuator's velocity gain within its
Euler step, where the simulator applies the drivers' torque as computed at the step's start."""


@pytest.fixture(scope="module")
def hung(go2, mjr, tmp_path_factory):
    """6 s of the hung Go2, noise-free, its friction MuJoCo's own (frictionloss, damping; the constraint's time
    constant MuJoCo's default, as an export leaves it), and the MJCF of its true parameters."""
    return hung_truth_mjcf(go2, mjr, tmp_path_factory.mktemp("replay"), 6.0)


def test_the_truths_file_tracks_the_simulators_log(hung):
    """Stepped at the simulator's 1 ms, the truth's file tracks the log within :data:`AGREE`, in 1 s windows and in
    one shot; at the file's own 2 ms within 3 mrad (measured 2.2)."""
    sim, robot, truth, log = hung
    for horizon in (1.0, None):
        r = replay_mjcf(truth, robot, sim.table, Replay(horizon=horizon, timestep=0.001))
        assert r.rms.max() < AGREE, (horizon, r.rms)
        assert r.rows == (0, sim.table.num_rows) and r.joints == robot.actuated
    assert replay_mjcf(truth, robot, log, Replay()).rms.max() < 3e-3


def test_a_wrong_file_is_seen(hung, tmp_path):
    """Half the friction, or the drivers' delay 5 ms short, in the file: every joint's tracking error is ten times
    the truth's at least (measured: 23-73 and 34-69 times)."""
    sim, robot, truth, _ = hung
    ours = replay_mjcf(truth, robot, sim.table, Replay(timestep=0.001))
    for change in ("friction", "delay"):
        spec = mujoco.MjSpec.from_file(str(truth))
        for j in robot.actuated:
            if change == "friction":
                spec.joint(j).frictionloss *= 0.5
            else:
                spec.actuator(j).delay -= 0.005
        path = tmp_path / f"{change}.xml"
        path.write_text(spec.to_xml())
        off = replay_mjcf(path, robot, sim.table, Replay(timestep=0.001))
        assert np.all(off.rms > 10 * ours.rms), (change, off.rms / ours.rms)


def test_pace_actuator_holds_the_torque_back_whole_periods(hung):
    """PACE's actuator: the law once a log period, its torque applied ``torque_delay`` periods later. It is another
    drive than the log's (set-points held back 12 ms, the law every 1 ms): 13-45 mrad off with no delay, and the later
    the torque the further (0 < 2 < 4 periods, every joint: measured 13-45, 14-50, 17-60 mrad), where the file's own
    actuators track within :data:`AGREE`."""
    sim, robot, truth, _ = hung
    errors = [replay_mjcf(truth, robot, sim.table, Replay(torque_delay=k)).rms for k in (0, 2, 4)]
    assert np.all(errors[0] < errors[1]) and np.all(errors[1] < errors[2])
    assert errors[0].min() > 10 * AGREE


def test_what_a_replay_refuses(hung, go2, tmp_path):
    sim, robot, truth, _ = hung
    bare = tmp_path / "bare.xml"  # the robot's model without its drivers' actuators: motors (issue 67)
    write_mjcf(dataclasses.replace(go2, pd=None, cache={}), {}, bare)
    with pytest.raises(InputError, match="no position actuator named 'FL_hip_joint'"):
        replay_mjcf(bare, robot, sim.table)
    with pytest.raises(InputError, match="MuJoCo cannot load it"):
        (tmp_path / "broken.xml").write_text("<mujoco><worldbody><body></mujoco>")
        replay_mjcf(tmp_path / "broken.xml", robot, sim.table)
    fed = sim.table.append_column("tau_ff.FL_hip_joint", pa.array(np.full(sim.table.num_rows, 0.1)))
    for j in robot.actuated[1:]:
        fed = fed.append_column(f"tau_ff.{j}", pa.array(np.zeros(sim.table.num_rows)))
    with pytest.raises(InputError, match="'tau_ff' columns are not zero"):
        replay_mjcf(truth, robot, fed)
    gains = sim.table
    for j in robot.actuated:
        gains = gains.append_column(f"kp.{j}", pa.array(np.full(sim.table.num_rows, 99.0)))
    with pytest.raises(InputError, match="'kp' differs from the file's"):
        replay_mjcf(truth, robot, gains)
    with pytest.raises(InputError, match="base floats"):
        replay_mjcf(truth, dataclasses.replace(robot, floating_base=True, cache={}), sim.table)
    with pytest.raises(InputError, match="horizon"):
        Replay(horizon=0.0)
    with pytest.raises(InputError, match="log's run from 0 to"):
        replay_mjcf(truth, robot, sim.table, times=(50.0, 60.0))


def test_cli(hung, tmp_path, capsys):
    """``wbfriction rollout``: the table per joint, the file and the figure; a bad option in one line."""
    sim, robot, truth, log = hung
    config = hung_go2_toml(tmp_path / "go2.toml", robot, sim.driver.delay)
    out, fig = tmp_path / "r.parquet", tmp_path / "r.png"
    code, printed, err = run_cli_printed(capsys, "rollout", log, truth, "--config", config, "--timestep", "0.001",
                                         "-o", out, "--figure", fig)
    assert code == 0, err
    assert_stages(err, "replaying")  # piped: its stage's line (issue 67)
    table = read_table(out)
    assert table.column_names == ["joint", "rms_windows", "rms_whole"]
    assert table.column("joint").to_pylist() == list(robot.actuated)
    assert max(table.column("rms_whole").to_pylist()) < AGREE
    assert fig.read_bytes()[:4] == b"\x89PNG"
    assert "mean" in printed and "[mrad]" in printed and f"wrote {out}" in err
    code, _, err = run_cli_printed(capsys, "rollout", log, truth, "--config", config, "--window", "0")
    assert code == 2 and "--window" in err and len(said(err)) == 1
