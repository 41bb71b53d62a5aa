"""The rollout check: the hung Go2's log replayed with the true parameters tracks it (to rounding noise-free, to the
drivers' noise with it), with wrong ones (armature x2, friction x0.5, the delay one physics step off either way)
clearly worse; the stretch, the delayed history before it, the restarts, the parameter files and the table."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np
import pytest

from wbfriction.exceptions import ColumnError, InputError
from wbfriction.fit.params_file import write_params
from wbfriction.fit.result import FitResult
from wbfriction.replay.rollout import ActuatorParams, read_log_setpoints, rollout, rollout_table
from wbfriction.sim.hung import simulate_hung
from wbfriction.sim.pd_options import REAL_DRIVER, HungOptions
from wbfriction.sim.pd_robot import Commands, PdRun

EXACT = 1e-10
"""Replaying a noise-free log with its true parameters: measured at most 4e-15 rad RMS (1e-14 at worst) over 25 s of
ramps or chirps. The replay runs the simulator's own steps; the one difference is the initial angle, the logged one
less the offset (``(q + b) - b``, a rounding of 1e-16), so the tolerance is rounding amplified a million times."""
NOISY = 1e-3
"""Replaying a log with a real driver's noise (encoder steps, 0.08 rad/s on the driver's velocity) noise-free:
measured 2.3e-4 rad RMS at worst over 25 s (the noise's torque, kd x 0.08 rad/s, moves the robot; the replay's
does not), 2.0e-4 to 4.0e-4 over this file's 7 s (three noise seeds)."""


@pytest.fixture(scope="module")
def logs(go2, mjr):
    """8 s of the hung Go2 (ramps, then chirps), noise-free and with a real driver's noise."""
    return {kind: simulate_hung(go2, HungOptions(duration=8.0, noise=noise), mjr=mjr)
            for kind, noise in (("exact", HungOptions().noise), ("noisy", REAL_DRIVER))}


def truth(sim, **changes) -> ActuatorParams:
    return dataclasses.replace(ActuatorParams(sim.friction, label="truth"), **changes)


@pytest.mark.parametrize("kind", ["exact", "noisy"])
def test_the_true_parameters_track_the_log_and_wrong_ones_do_not(go2, mjr, logs, kind):
    """With the truth (the robot TOML's armature, offsets and delay, the injected friction) the replay tracks the log
    to rounding (noise-free) or within the drivers' noise; twice the armature or half the friction are off by ten
    times as much on every joint (measured with the noise: 14-18 times, three noise seeds), the delay one physics
    step (1 ms) early or late by twice as much (measured: 2.9-3.2 times), and by 5e-4 rad at least."""
    sim = logs[kind]
    rows = (200, 1600)  # 1-8 s
    ours = rollout(go2, sim.table, truth(sim), rows=rows, mjr=mjr)
    assert ours.rms.max() < (EXACT if kind == "exact" else NOISY)
    wrong = {"armature x2": truth(sim, armature={j: 2 * a for j, a in zip(go2.actuated, sim.armature)}),
             "friction x0.5": truth(sim, friction={j: dataclasses.replace(p, F_c=0.5 * p.F_c, F_v=0.5 * p.F_v)
                                                   for j, p in sim.friction.items()}),
             "delay + 1 ms": truth(sim, delay=sim.driver.delay + 0.001),
             "delay - 1 ms": truth(sim, delay=sim.driver.delay - 0.001)}
    for label, params in wrong.items():
        off = rollout(go2, sim.table, dataclasses.replace(params, label=label), rows=rows, mjr=mjr)
        factor = 2.0 if label.startswith("delay") else 10.0
        assert np.all(off.rms > np.maximum(factor * ours.rms, 5e-4)), (label, off.rms, ours.rms)


def test_the_delay_before_the_stretch_comes_from_the_log(go2, mjr, logs):
    """A stretch from the middle of the log replays the set-points commanded before it (the delay's history): the
    truth tracks from its first sample, and restarting from the log's state every 0.5 s changes nothing
    noise-free."""
    sim = logs["exact"]
    one = rollout(go2, sim.table, truth(sim), times=(3.0, 5.0), mjr=mjr)
    assert one.rows == (600, 1000) and np.abs(one.error).max() < EXACT
    shots = rollout(go2, sim.table, truth(sim), rows=(600, 1000), horizon=0.5, mjr=mjr)
    assert np.abs(shots.error).max() < EXACT and shots.horizon == 0.5


def test_restarts_take_the_logs_state(go2, mjr, logs):
    """With a wrong armature, each restart of a 0.5 s horizon begins at the log's angle (no error at the restarts'
    samples, the noisy log's) and the error grows again from there."""
    sim = logs["noisy"]
    params = truth(sim, armature={j: 2 * a for j, a in zip(go2.actuated, sim.armature)})
    res = rollout(go2, sim.table, params, rows=(200, 1000), horizon=0.5, mjr=mjr)
    starts = np.arange(0, 800, 100)
    assert np.abs(res.error[starts]).max() < 1e-12
    assert np.abs(res.error).max() > 1e-3


def test_parameters_from_fits_and_a_parameters_file_side_by_side(go2, mjr, logs, tmp_path):
    """Friction given as fits (``.params``) or as the parameters JSON ``wbfriction fit`` writes replays as the
    parameters themselves; a fit without parameters replays without friction (named); two sets tabulate side by
    side."""
    sim = logs["exact"]
    rows = (200, 600)
    direct = rollout(go2, sim.table, truth(sim), rows=rows, mjr=mjr)
    fits = {j: SimpleNamespace(params=p) for j, p in sim.friction.items()}
    assert np.array_equal(rollout(go2, sim.table, truth(sim, friction=fits), rows=rows, mjr=mjr).q_sim, direct.q_sim)
    path = tmp_path / "params.json"
    write_params(path, [FitResult(j, 100, p, model=p.model, success=True) for j, p in sim.friction.items()])
    from_file = rollout(go2, sim.table, truth(sim, friction=str(path), label="file"), rows=rows, mjr=mjr)
    assert np.abs(from_file.q_sim - direct.q_sim).max() < 1e-9  # the JSON's 17 digits
    fits["FL_hip_joint"] = SimpleNamespace(params=None)
    bare = rollout(go2, sim.table, truth(sim, friction=fits, label="no hip"), rows=rows, mjr=mjr)
    assert bare.no_friction == ("FL_hip_joint",) and bare.by_joint()["FL_hip_joint"] > 1e-3
    table = rollout_table([direct, bare])
    assert table.column_names == ["joint", "rms.truth", "rms.no hip"]
    assert table["joint"].to_pylist() == list(go2.actuated)
    with pytest.raises(InputError, match="labels must differ"):
        rollout_table([direct, direct])


def test_what_a_rollout_refuses(go2, mjr, logs):
    """A log without set-points, a stretch outside the log, a horizon <= 0, friction of an unknown joint: one clear
    error each."""
    sim = logs["exact"]
    with pytest.raises(ColumnError, match="q_des.FL_hip_joint"):
        read_log_setpoints(go2, sim.table.drop_columns(["q_des.FL_hip_joint"]))
    with pytest.raises(InputError, match="stretch"):
        rollout(go2, sim.table, truth(sim), rows=(1500, 1700), mjr=mjr)
    with pytest.raises(InputError, match="horizon"):
        rollout(go2, sim.table, truth(sim), rows=(0, 10), horizon=0.0, mjr=mjr)
    with pytest.raises(InputError, match="knee"):
        rollout(go2, sim.table, truth(sim, friction={"knee": sim.friction["FL_hip_joint"]}), rows=(0, 10), mjr=mjr)


def test_a_parameters_file_of_another_robot_is_refused(go2, mjr, logs, tmp_path):
    """Issue 65, class 1: a Go2 and an Aliengo share their joints' names, so a parameters file fitted for the other
    robot would replay silently: the file's recorded robot must be the one replayed, named in one line."""
    sim = logs["exact"]
    path = tmp_path / "params.json"
    write_params(path, [FitResult(j, 100, p, model=p.model, success=True) for j, p in sim.friction.items()],
                 {"provenance": {"robot": "aliengo"}})
    refusal = r"params.json: parameters of robot 'aliengo' \(its model file not recorded\), not of 'go2' "
    with pytest.raises(InputError, match=refusal):
        rollout(go2, sim.table, truth(sim, friction=str(path)), rows=(0, 10), mjr=mjr)


def test_a_peers_torque_delay_holds_back_the_whole_law(go2, mjr):
    """PACE's delay (a peer's model, ``torque_delay``): the torque applied at each physics step is the PD law of the
    readings and set-points of 12 steps before (feedback delayed too), bit for bit; before that, the first step's."""
    n, lag = 300, 12
    q_des = np.tile(go2.reference_angles, (n, 1))
    q_des[100:] += 0.1
    run = PdRun(mjr, 1e-3, 1, go2.pd.with_delay(0.012), np.full(12, 0.015), np.zeros(12), {}, torque_delay=True)
    tr = run.run(Commands(q_des, np.zeros_like(q_des), np.zeros_like(q_des)), 0, n, go2.reference_angles,
                 np.zeros(12))
    law = np.clip(go2.pd.kp * (q_des - tr.q_encoder) - go2.pd.kd * tr.qd_driver, -go2.pd.torque_limit,
                  go2.pd.torque_limit)
    assert np.array_equal(tr.tau[lag:], law[:-lag])
    assert np.array_equal(tr.tau[:lag], np.repeat(law[:1], lag, axis=0))
