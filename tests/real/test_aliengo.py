"""A real PD-driven robot (issue 55): the iit-DLSLab's Unitree Aliengo, hung, every joint tracking ramps under its
drivers' PD law at 200 Hz, no torque sensor (../shared/real-data/unitree_aliengo).

No ground truth: what must hold is what a model of a real robot must do, predict data it was not fitted on. The
route a user takes (``wbfriction dataset aliengo``; ``identify --actuator pd`` on the first 60 %, its TOML; the
friction estimated and fitted on the same 60 %, the momentum route on both halves) predicts the last 40 %'s torque
better than the same lab's identification (PACE-style, CMA-ES over Isaac Lab rollouts; its delay holding back the
whole torque, as PACE's actuator does), both through the same estimate and prediction
(:mod:`wbfriction.studies.pd_peer`: the momentum route for both), and finds the drivers' delay near theirs. Measured
at issue 55's close: better on 10 of 12 joints (ours 0.075-0.155 N·m, mean 0.107, the peer's 0.080-0.291, mean 0.185;
not the front left calf, 0.089 against 0.080, nor the rear right calf, 0.155 against 0.092): the issue's "every
joint" not reached. Issue 63 (second session) lowered it to 9 of 12: a transition is a candidate only with samples
where it has settled, and the rear left calf's (3.5) curve, whose Stribeck velocity of 1.3 rad/s lies beyond the
joint's speeds (nothing above 2.6 rad/s; its F_c ±3993 %), predicted the last 40 % to 0.083 N·m; the Coulomb-viscous
fit now chosen predicts it to 0.101, the peer 0.097 (the rear right calf gained: 0.155 -> 0.124).

What the log cannot tell (issue 63, third session): the drivers' delay holding back the set-points or the whole
torque closes the balance alike (squared residual ratio 1.00), and on the ramps the two differ by a viscous torque
``kp delay qd`` (0.28 N·m·s/rad), which F_v takes up: F_v 0 on ten joints with the set-points held back, 0.14-0.61
with the torque (the peer's 0.24-0.31), 0.33 higher on the two hips where both are interior. No F_v is then
``ok``, and the friction fitted afterwards carries ``kp delay`` in F_v's standard error.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from helpers import REAL_DATA, needs_data
from wbfriction import datasets
from wbfriction.actuator import ActuatorOptions, identify_actuators
from wbfriction.datasets.aliengo import aliengo_peer
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.source import read_log
from wbfriction.model import load_robot
from wbfriction.model.loading import RobotSpec
from wbfriction.pipeline.actuator_step import identify_actuator_file, write_actuator_config
from wbfriction.pipeline.estimate_step import estimate_file
from wbfriction.pipeline.fit_step import fit_file
from wbfriction.pipeline.predict_step import predict_file
from wbfriction.studies.pd_peer import peer_held_out

pytestmark = [needs_data("unitree_aliengo"), pytest.mark.slow, pytest.mark.xdist_group("real_aliengo")]


@pytest.fixture(scope="module")
def route(tmp_path_factory):
    """The dataset written, its actuators identified on the first 60 %, the friction fitted there."""
    folder = tmp_path_factory.mktemp("aliengo")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv(datasets.DATA_ENV, str(REAL_DATA))
        written = datasets.write_dataset("aliengo", folder / "data")
        peer = aliengo_peer()
    config = written.config
    robot = load_robot(None, config=config)
    identified = identify_actuator_file(robot, written.logs["train"], folder / "actuator.json", ActuatorOptions())
    toml = folder / "identified.toml"
    write_actuator_config(config.read_text(), config.parent, robot.urdf, toml, identified)
    ours = load_robot(None, config=toml)
    spec = RobotSpec.given("", config=toml)
    for role in ("train", "held_out"):  # as the dataset's printed commands: the momentum route on both halves
        estimate_file(spec, written.logs[role], folder / f"{role}_friction.parquet", EstimateOptions(route="momentum"),
                      robot=ours)
    fit_file(folder / "train_friction.parquet", folder / "params.json")
    return written, peer, identified, ours, folder


def test_the_held_out_torque_predicted_better_than_the_peers_on_every_joint(route):
    written, peer, _, _, folder = route
    mine = predict_file(folder / "held_out_friction.parquet", folder / "params.json")
    theirs = peer_held_out(written.config, written.config.parent / "peer.toml", peer, Path(written.logs["held_out"]))
    better = [j for i, j in enumerate(mine.joints) if mine.rms[i] < theirs[j]]
    assert len(better) >= 9, sorted(set(mine.joints) - set(better))  # module docstring
    assert sum(mine.rms) < 0.7 * sum(theirs.values())
    assert max(mine.rms) < 0.2


def test_the_delay_near_the_peers(route):
    _, peer, identified, _, _ = route
    assert identified.delay.status == "ok"
    # the peer: 2.64 steps of 5 ms (13.2 ms; its simulator truncates it to 10 ms); ours 11.3 ms ± 0.2
    assert peer.applied_delay - 0.001 <= identified.delay.value <= peer.delay + 0.001


def test_the_identified_toml_writes_the_held_out_choice_and_predicts_better_than_the_given(route):
    """What ``--config-output`` wrote is the choice on held-out blocks of the training log
    (:mod:`wbfriction.actuator.written`), and the TOML so written predicts the held-out 40 %'s torque better than the
    TOML as the dataset gives it (no armature, no offsets, no delay), joint by joint, through the same route. Measured
    at issue 79: 0.061-0.131 N·m against 0.182-0.375 (means 0.100, 0.267)."""
    written, _, identified, ours, folder = route
    assert identified.written is not None
    for v in identified.written.values:
        if v.kind == "armature":
            assert ours.model.armature[ours.act_v_index[ours.actuated.index(v.joint)]] == pytest.approx(v.written)
        else:
            assert ours.encoder_offset.get(v.joint, 0.0) == pytest.approx(v.written)
    assert identified.written.written_delay == pytest.approx(ours.pd.delay)
    given = load_robot(None, config=written.config)
    spec = RobotSpec.given("", config=written.config)
    for role in ("train", "held_out"):
        estimate_file(spec, written.logs[role], folder / f"given_{role}.parquet", EstimateOptions(route="momentum"),
                      robot=given)
    fit_file(folder / "given_train.parquet", folder / "given_params.json")
    theirs = predict_file(folder / "given_held_out.parquet", folder / "given_params.json")
    mine = predict_file(folder / "held_out_friction.parquet", folder / "params.json")
    assert mine.joints == theirs.joints
    worse = [j for j, a, b in zip(mine.joints, mine.rms, theirs.rms) if not a <= b]
    assert worse == []


def test_the_log_does_not_tell_what_the_delay_holds_back(route):
    """The set-points or the whole torque held back close the balance alike: no F_v is ``ok``, the TOML written
    says so, and the friction fitted on it carries ``kp delay`` in F_v's standard error."""
    _, _, identified, ours, folder = route
    assert not identified.delayed_known and "does not tell what the delay holds back" in identified.velocity_reason
    assert all(j.F_v.status != "ok" for j in identified.joints)
    assert ours.pd is not None and not ours.pd.delayed_known
    kp_delay = 25.0 * identified.delay.value
    joints = json.loads((folder / "params.json").read_text())["joints"]
    for name, d in joints.items():
        assert d["model_spread"]["F_v"] >= kp_delay - 1e-12, name
        assert d["status"] != "ok", (name, d["status"])


def test_the_two_structures_f_v_differ_by_kp_delay(route):
    """Two routes to one number: the identification under the whole torque held back against under the set-points
    held back puts F_v higher by about ``kp delay`` (the analytic difference on steady motion), where both are
    interior (the hips; elsewhere the set-points' F_v sits at its floor of zero)."""
    written, _, identified, _, _ = route
    robot = load_robot(None, config=written.config)
    log = read_log(written.logs["train"], robot)
    torque = identify_actuators(robot, log, ActuatorOptions(delayed="torque"))
    kp_delay = 25.0 * identified.delay.value
    interior = [(j.joint, t.F_v.value - j.F_v.value) for j, t in zip(identified.joints, torque.joints)
                if j.F_v.value > 1e-6 and t.F_v.value > 1e-6]
    assert interior, "no joint with both F_v interior"
    for joint, difference in interior:
        assert difference == pytest.approx(kp_delay, rel=0.25), joint
    assert all(t.F_v.value > j.F_v.value for j, t in zip(identified.joints, torque.joints))


def test_the_exported_simulator_tracks_the_held_out_stretch_better_than_the_peers(route, tmp_path):
    """Issue 64: the MJCF the route exports (the default fits, weak and at-bound included as the dataset's command
    does; where the model chosen is not ok, its Coulomb-viscous fit), replayed under the last 40 %'s set-points as
    MuJoCo runs it, tracks the logged angles better on average than the peer's parameters simulated as PACE
    simulates them (its torque held back 2 periods, the law once a period), and on the hips and thighs; the fits'
    tau_os exported as set-point offsets is what takes it there: without them the same file is worse than the
    peer's. Measured: 4.77 mrad mean against the peer's 7.05 (9 of 12 joints; the front left, rear left and rear
    right calves not: 3.7, 3.3, 5.5 against 3.1, 2.7, 3.6); 9.5 without tau_os."""
    import mujoco
    import numpy as np

    from wbfriction.pipeline.export_step import export_files
    from wbfriction.replay.mjcf import Replay, replay_mjcf
    from wbfriction.studies.pd_peer import peer_rollouts

    written, peer, _, ours, folder = route
    mjcf = tmp_path / "aliengo.xml"
    export_files(ours, folder / "params.json", [mjcf], include=("weak", "at-bound"))
    table = peer_rollouts(written.config, written.config.parent / "peer.toml", peer, folder / "identified.toml",
                          mjcf, written.logs["held_out"]).to_pydict()
    mine, theirs = np.array(table["rms.ours"]), np.array(table["rms.peer"])
    assert mine.mean() < 0.8 * theirs.mean(), (mine, theirs)
    legs = [i for i, j in enumerate(table["joint"]) if "calf" not in j]
    assert np.all(mine[legs] < theirs[legs]), (mine, theirs)
    spec = mujoco.MjSpec.from_file(str(mjcf))  # the same file without the fits' constant torques
    for j in ours.actuated:
        bias = np.array(spec.actuator(j).biasprm, dtype=float)
        bias[0] = -25.0 * ours.encoder_offset.get(j, 0.0)
        spec.actuator(j).biasprm = bias
    bare = tmp_path / "no_tau_os.xml"
    bare.write_text(spec.to_xml())
    without = replay_mjcf(bare, ours, written.logs["held_out"], Replay()).rms
    assert without.mean() > theirs.mean() > mine.mean()


def test_the_refined_simulator_tracks_the_held_out_stretch_better_than_the_export(route, tmp_path):
    """Issue 64, item 2: the route's MJCF refined on its own replay of the first 60 % (``wbfriction refine``) tracks
    the last 40 % better on average than the export it started from, and than the peer's (a cross-check on data it
    was not refined on). Measured (``--model coulomb-viscous --terms none``, the how-to's export): 4.24 mrad mean
    against 4.77 and the peer's 7.05; better than the export on the thighs and rear hips (6 of 12), worse on the
    calves and front hips (the front left 7.2 against 4.0); better than the peer's on 8 of 12 (not the calves: 4.1,
    3.8, 3.9, 5.8 against 3.1, 3.6, 2.7, 3.6); the set-points' delay 6 ms (three 2 ms steps) against the
    identification's 11.3. The default fits' export (this test's) is the same file (its fits not ok replaced by
    the Coulomb-viscous ones): the same numbers."""
    import numpy as np

    from wbfriction.pipeline.export_step import export_files
    from wbfriction.replay.refine import refine_mjcf, write_refined
    from wbfriction.studies.pd_peer import peer_rollouts

    written, peer, _, ours, folder = route
    mjcf, refined = tmp_path / "aliengo.xml", tmp_path / "refined.xml"
    export_files(ours, folder / "params.json", [mjcf], include=("weak", "at-bound"))
    result = refine_mjcf(mjcf, ours, written.logs["train"])
    write_refined(mjcf, result, ours, refined)
    assert result.rms.mean() < result.rms_start.mean()
    table = peer_rollouts(written.config, written.config.parent / "peer.toml", peer, folder / "identified.toml",
                          mjcf, written.logs["held_out"], others={"refined": refined}).to_pydict()
    export, better, theirs = (np.array(table[f"rms.{k}"]) for k in ("ours", "refined", "peer"))
    assert better.mean() < 0.95 * export.mean() and better.mean() < 0.7 * theirs.mean(), (better, export, theirs)


def test_refined_on_the_peers_training_data_the_simulator_tracks_better_than_the_peer(route, tmp_path):
    """Issue 64, on the peer's footing: the peer's parameters were fitted on the whole log (PACE's ``my_fit.py``
    replays all of ``traj_0.pt``), so its error on the last 40 % is on data it was fitted on, not held out. The
    route's export (identified on the first 60 %) refined on the same whole log tracks the last 40 % better than
    the peer on average and on at least 11 of 12 joints. Measured: 2.70 mrad mean against 7.05; every joint but the
    rear right calf (3.72 against 3.64); from the whole log's own identification, the same: 2.69, 3.70."""
    import numpy as np

    from wbfriction.pipeline.export_step import export_files
    from wbfriction.studies.pd_peer import peer_rollouts, refine_on_whole_log

    written, peer, _, ours, folder = route
    mjcf = tmp_path / "aliengo.xml"
    export_files(ours, folder / "params.json", [mjcf], include=("weak", "at-bound"))
    whole = refine_on_whole_log(folder / "identified.toml", mjcf, [written.logs["train"], written.logs["held_out"]],
                                tmp_path / "whole.xml")
    table = peer_rollouts(written.config, written.config.parent / "peer.toml", peer, folder / "identified.toml",
                          mjcf, written.logs["held_out"], others={"whole": whole}).to_pydict()
    mine, theirs = np.array(table["rms.whole"]), np.array(table["rms.peer"])
    assert mine.mean() < 0.5 * theirs.mean(), (mine, theirs)
    assert np.sum(mine <= theirs) >= 11 and np.all(mine < 1.1 * theirs), (mine, theirs)


def test_a_whole_log_whose_stretches_do_not_follow_on_is_refused(route, tmp_path):
    """The whole log is the stretches in time order: the held-out stretch before the training one is refused before
    any replay, naming the file."""
    from wbfriction.exceptions import InputError
    from wbfriction.studies.pd_peer import refine_on_whole_log

    written, _, _, _, folder = route
    with pytest.raises(InputError, match="train.parquet: its times do not follow"):
        refine_on_whole_log(folder / "identified.toml", tmp_path / "never_read.xml",
                            [written.logs["held_out"], written.logs["train"]], tmp_path / "whole.xml")
