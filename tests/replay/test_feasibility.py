"""Issue 81, class 2: a replay scores only what it can replay. The actuators' history against the timestep (the
limit measured on MuJoCo itself), the timestep and the window against the log period, PACE's torque delay against
the window, a log's gaps (replayed run by run, as its runs replayed on their own), the file's robot and encoder
offsets against the TOML's: each refused in one line before any replay, by ``rollout`` and ``refine`` alike."""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers import hung_go2_toml, hung_truth_mjcf, run_cli_printed, said
from wbfriction.export.mjcf import write_mjcf
from wbfriction.model.loading import load_robot
from wbfriction.replay.feasibility import ReplayInfeasible, check_history, exported_offsets, log_runs
from wbfriction.replay.mjcf import Replay, replay_mjcf
from wbfriction.replay.refine import refine_mjcf
from wbfriction.replay.rollout import ActuatorParams, rollout

PERIOD = 0.005
"""The hung simulator's log period [s] (200 Hz)."""
ROWS = (0, 120)
"""The stretch the properties replay: 0.6 s, five times the drivers' 12 ms delay and more."""
FEW = settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


@pytest.fixture(scope="module")
def hung(go2, mjr, tmp_path_factory):
    """1.5 s of the hung Go2, noise-free, its friction MuJoCo's own, and the MJCF of its true parameters (its
    actuators' history: 25 set-points, a 12 ms delay down to 0.48 ms)."""
    folder = tmp_path_factory.mktemp("feasibility")
    sim, robot, truth, log = hung_truth_mjcf(go2, mjr, folder, 1.5)
    ample = folder / "ample.xml"  # the same file, its history ten times as long: the delay held at any step here
    text = truth.read_text()
    assert text.count('nsample="25"') == 12
    ample.write_text(text.replace('nsample="25"', 'nsample="250"'))
    return sim, robot, truth, ample, log


def step_response_delay(h: float, delay: float, nsample: int) -> int:
    """The steps MuJoCo 4 delays a step of an actuator's control by (zero-order hold, ``delay`` [s], ``nsample``
    samples, timestep ``h`` [s]): the steps from the control's step to the force's."""
    xml = (f'<mujoco><option timestep="{h!r}"/><worldbody><body><joint name="j"/><geom size="0.1" mass="1"/></body>'
           f'</worldbody><actuator><general name="a" joint="j" biastype="affine" delay="{delay!r}" '
           f'nsample="{nsample}" interp="zoh"/></actuator></mujoco>')
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    switch = 5 + math.ceil(delay / h)
    for k in range(switch + 3 * nsample + 10):
        d.ctrl[0] = 1.0 if k >= switch else 0.0
        mujoco.mj_step(m, d)
        if d.actuator_force[0] > 0.5:
            return k - switch
    raise AssertionError("the control never arrived")


@settings(max_examples=60, deadline=None)
@given(h=st.floats(1e-4, 3e-3), nsample=st.integers(1, 30), steps=st.floats(0.05, 40.0))
def test_the_history_limit_is_mujocos(h, nsample, steps):
    """The limit :func:`check_history` refuses at is MuJoCo's own: a delay is applied whole (``ceil(delay / h)``
    steps) if and only if the check lets the timestep through; otherwise MuJoCo reads its oldest sample, a shorter
    delay (the delay kept off the hold's edge, as the export writes it)."""
    delay = h * steps
    if abs(steps - round(steps)) < 1e-6:
        delay -= 1e-9  # the export's HOLD_EDGE: never on a step's edge
    m = mujoco.MjModel.from_xml_string(
        f'<mujoco><option timestep="{h!r}"/><worldbody><body><joint name="j"/><geom size="0.1" mass="1"/></body>'
        f'</worldbody><actuator><general name="a" joint="j" delay="{delay!r}" nsample="{nsample}" interp="zoh"/>'
        '</actuator></mujoco>')
    exact = step_response_delay(h, delay, nsample) == math.ceil(delay / h)
    try:
        check_history("m.xml", m, np.array([0]), ["a"])
        refused = False
    except ReplayInfeasible as err:
        refused = True
        assert err.option == "--timestep" and "actuator 'a'" in str(err) and f"holds {nsample} set-points" in str(err)
    assert refused != exact


@FEW
@given(h=st.floats(1e-4, 3 * PERIOD))
def test_a_timestep_is_refused_unless_it_replays_the_files_delay_and_holds_the_set_points(hung, h):
    """Timesteps across the range against the file's delay (12 ms, a history of 25 set-points) and the log period
    (5 ms): below 0.48 ms the history would shorten the delay and above 5 ms set-points would be skipped, and both
    are refused naming ``--timestep``; any other replays exactly as the same file with an ample history does (the
    whole delay applied: what was silently 1.1 -> 10.8 mrad at 0.2 ms)."""
    sim, robot, truth, ample, _ = hung
    replay = Replay(timestep=h, horizon=0.25)
    expected = replay_mjcf(ample, robot, sim.table, replay, rows=ROWS) if h <= PERIOD else None
    short = math.ceil((0.012 - 1e-9) / h - 1e-12) > 25
    if short or h > PERIOD:
        with pytest.raises(ReplayInfeasible, match=r"\(--timestep") as err:
            replay_mjcf(truth, robot, sim.table, replay, rows=ROWS)
        assert err.value.option == "--timestep" and err.value.value == h
        assert ("actuator 'FL_hip_joint' holds 25 set-points" in str(err.value)) == short
    else:
        assert expected is not None
        np.testing.assert_array_equal(replay_mjcf(truth, robot, sim.table, replay, rows=ROWS).q_sim, expected.q_sim)


@FEW
@given(scale=st.floats(0.5, 4.0), samples=st.floats(0.2, 4.0))
def test_a_window_shorter_than_two_samples_is_refused_and_any_other_simulates(hung, go2, mjr, scale, samples):
    """Windows against log periods (the log's time stretched: periods of 2.5-20 ms): a window of fewer than two
    samples (``round(window / period) < 2``) restarted from the log at every row and scored every model 0.00, one
    without friction too; it is refused naming ``--window``, by the file's replay and by the project's rollout. Any
    other replays something: every joint's error is above zero."""
    sim, robot, truth, _, _ = hung
    table = sim.table.set_column(0, "time", pa.array(sim.table["time"].to_numpy() * scale))
    period, window = PERIOD * scale, PERIOD * scale * samples
    bare = ActuatorParams({}, label="no friction")
    runs = [lambda: replay_mjcf(truth, robot, table, Replay(horizon=window), rows=ROWS),
            lambda: rollout(go2, table, bare, rows=ROWS, horizon=window, mjr=mjr)]
    for run in runs:
        if round(window / period) < 2:
            with pytest.raises(ReplayInfeasible, match=r"\(--window\)") as err:
                run()
            assert err.value.option == "--window" and err.value.value == window
        else:
            assert np.all(run().rms > 0)


def cut(table: pa.Table, gaps: list[tuple[int, int]]) -> tuple[pa.Table, list[pa.Table]]:
    """``table`` with rows removed at each gap (``(row, how many)``, rows sorted and apart), and its runs as tables
    of their own."""
    keep = np.ones(table.num_rows, dtype=bool)
    for row, n in gaps:
        keep[row:row + n] = False
    kept = np.flatnonzero(keep)
    starts = [0] + [int(np.searchsorted(kept, row + n)) for row, n in gaps]
    bounds = list(zip(starts, starts[1:] + [len(kept)]))
    return table.take(pa.array(kept)), [table.take(pa.array(kept[a:b])) for a, b in bounds]


@FEW
@given(data=st.data())
def test_a_log_with_gaps_is_replayed_as_its_runs_on_their_own(hung, go2, mjr, data):
    """Gaps anywhere in a log (1-3 of them, 1-40 rows missing each): the replay restarts at each run and takes no
    set-point across a gap: its simulated angles are those of each run replayed as a log of its own (a 0.5 s gap
    was replayed as if evenly sampled: 1.9 mrad became 16.4). The file's replay in windows and in one shot, and the
    project's rollout."""
    sim, robot, truth, _, _ = hung
    base = sim.table.slice(0, 160)
    rows = sorted(data.draw(st.lists(st.integers(3, 150), min_size=1, max_size=3, unique=True)))
    gaps = [(row, data.draw(st.integers(1, min(40, base.num_rows - row - 2)))) for row in rows]
    gaps = [(row, n) for k, (row, n) in enumerate(gaps) if k == 0 or row > gaps[k - 1][0] + gaps[k - 1][1] + 1]
    gapped, pieces = cut(base, gaps)
    assert len(log_runs(gapped["time"].to_numpy())) == len(pieces)
    params = ActuatorParams(sim.friction, label="truth")

    def run(t: pa.Table, replay: str) -> np.ndarray:
        if replay == "rollout":
            return rollout(go2, t, params, horizon=0.1, mjr=mjr).q_sim
        return replay_mjcf(truth, robot, t, Replay(horizon=0.1 if replay == "windows" else None)).q_sim

    for replay in ("windows", "whole", "rollout"):
        np.testing.assert_allclose(run(gapped, replay), np.vstack([run(p, replay) for p in pieces]), rtol=0,
                                   atol=1e-12, err_msg=replay)


def test_runs_split_at_a_sample_missing_not_at_jitter_nor_drift():
    """A run goes on while each row's step rounds to one period: a sample late by 0.4 period, or an hour at 200 Hz
    its times stored in float32 (steps quantised, their median off their mean: a grid from the start is half a
    period off by row 513), are one run; a sample missing, a time that repeats or goes back, starts a new one."""
    t = np.arange(20) * 0.005
    assert log_runs(t) == ((0, 20),)
    late = t.copy()
    late[5] += 0.002
    assert log_runs(late) == ((0, 20),)
    hour = np.linspace(0.0, 3600.0, 200 * 3600 + 1).astype(np.float32).astype(float)
    assert log_runs(hour) == ((0, hour.size),)
    assert log_runs(np.delete(t, 7)) == ((0, 7), (7, 19))
    assert log_runs(np.concatenate([t[:10], t[:10]])) == ((0, 10), (10, 20))  # two logs read one after the other
    repeat = np.insert(t, 4, t[3])
    assert log_runs(repeat) == ((0, 4), (4, 21))
    with pytest.raises(ReplayInfeasible, match="no period"):
        log_runs(np.zeros(5))


def test_absurd_timestep_and_torque_delay_are_refused(hung):
    """A timestep of ten log periods and PACE's torque delay of 10^5 periods replayed at 23-26 mrad with exit 0;
    both are refused naming the option and the limit. A torque delay within a window replays."""
    sim, robot, truth, _, _ = hung
    with pytest.raises(ReplayInfeasible, match=r"of 0.05 s is longer than <table>'s period 0.005 s"):
        replay_mjcf(truth, robot, sim.table, Replay(timestep=10 * PERIOD))
    with pytest.raises(ReplayInfeasible, match=r"--torque-delay\) of 100000 periods .* at most 198") as err:
        replay_mjcf(truth, robot, sim.table, Replay(torque_delay=100_000))
    assert err.value.option == "--torque-delay" and err.value.limit == "at most 198 periods"
    with pytest.raises(ReplayInfeasible, match="at most 18 periods"):
        replay_mjcf(truth, robot, sim.table, Replay(torque_delay=19, horizon=0.1))
    assert replay_mjcf(truth, robot, sim.table, Replay(torque_delay=18, horizon=0.1)).rms.max() > 0


A1_TOML = """name = "a1"
urdf = "example-robot-data:a1_description/urdf/a1.urdf"
floating_base = false
[pd]
kp = 25.0
kd = 0.5
delay = 0.012
"""


def test_another_robots_file_and_other_offsets_are_refused(hung, tmp_path):
    """An A1's export (the Go2's joints' names) replayed for the Go2 is refused naming both robots; the Go2's own
    file with a TOML whose encoder offsets differ from those exported (in the actuators' bias) is refused naming the
    joint and both offsets (both replayed at 23-26 mrad with exit 0); the refinement refuses them alike, before any
    replay. The offsets the export records read back exactly."""
    sim, robot, truth, _, _ = hung
    config = tmp_path / "a1.toml"
    config.write_text(A1_TOML)
    other = tmp_path / "a1.xml"
    write_mjcf(load_robot(None, config=config), {}, other)
    for run in (lambda p, r: replay_mjcf(p, r, sim.table), lambda p, r: refine_mjcf(p, r, sim.table)):
        with pytest.raises(ReplayInfeasible, match=r"a model of 'a1' .* not of robot 'go2' \(its model "
                                                   r"'go2_description'\)") as err:
            run(other, robot)
        assert err.value.option == "<mujoco model>"
        moved = dict(robot.encoder_offset, FR_calf_joint=robot.encoder_offset["FR_calf_joint"] + 1e-3)
        with pytest.raises(ReplayInfeasible, match=r"encoder offset 0.035 rad for 'FR_calf_joint' .* gives "
                                                   r"0.036000000000000004") as err:
            run(truth, dataclasses.replace(robot, encoder_offset=moved, cache={}))
        assert err.value.option == "[encoder_offset]"
    assert exported_offsets(truth) == robot.encoder_offset
    odd = dataclasses.replace(robot, encoder_offset={j: (k + 1) / 3e3 * (-1) ** k for k, j in
                                                     enumerate(robot.actuated)}, cache={})
    write_mjcf(odd, {}, tmp_path / "odd.xml")
    assert exported_offsets(tmp_path / "odd.xml") == odd.encoder_offset


def test_cli_refuses_in_one_line_and_writes_nothing(hung, tmp_path, capsys):
    """``rollout --window`` below two samples wrote a table of zeros; ``--timestep`` below the history, ten periods,
    ``--torque-delay`` 10^5: each is one line naming the option, exit 2, no table written; ``refine --window``, and a
    held-out log sampled faster than the file's timestep, refused before the refinement's minute. A log with a gap
    is replayed, the table's caption saying where its runs start."""
    sim, robot, truth, _, log = hung
    config = hung_go2_toml(tmp_path / "go2.toml", robot, sim.driver.delay)
    table = tmp_path / "r.parquet"
    for option, value in (("--window", "0.003"), ("--timestep", "0.0002"), ("--timestep", "0.05"),
                          ("--torque-delay", "100000")):
        code, _, err = run_cli_printed(capsys, "rollout", log, truth, "--config", config, option, value, "-o", table)
        assert code == 2 and len(said(err)) == 1 and f"({option}" in err, (option, err)
        assert not table.exists()
    gapped = tmp_path / "gapped.parquet"
    pq.write_table(cut(sim.table, [(100, 20)])[0], gapped)
    code, printed, err = run_cli_printed(capsys, "rollout", gapped, truth, "--config", config, "-o", table)
    assert code == 0, err
    assert "the log's gaps cut it into 2 evenly sampled runs, each replayed on its own (restarted at rows 100)" \
        in " ".join(printed.split())
    refined = tmp_path / "refined.xml"
    code, _, err = run_cli_printed(capsys, "refine", log, truth, "--config", config, "--window", "0.003", "-o", refined)
    assert code == 2 and len(said(err)) == 1 and "(--window)" in err and not refined.exists()
    held = tmp_path / "held.parquet"  # its period 0.5 ms, the file's timestep 2 ms
    pq.write_table(sim.table.set_column(0, "time", pa.array(sim.table["time"].to_numpy() / 10)), held)
    code, _, err = run_cli_printed(capsys, "refine", log, truth, "--config", config, "--held-out", held, "-o", refined)
    assert code == 2 and len(said(err)) == 1 and "0.002 s is longer than held.parquet's period 0.0005 s" in err
    assert "refining" not in err and not refined.exists()
