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
"""

from __future__ import annotations

from pathlib import Path

import pytest

from helpers import REAL_DATA, needs_data
from wbfriction import datasets
from wbfriction.actuator import ActuatorOptions
from wbfriction.datasets.aliengo import aliengo_peer
from wbfriction.friction.options import EstimateOptions
from wbfriction.model import load_robot
from wbfriction.model.loading import RobotSpec
from wbfriction.pipeline.actuator_step import identify_actuator_file, write_actuator_config
from wbfriction.pipeline.estimate_step import estimate_file
from wbfriction.pipeline.fit_step import fit_file
from wbfriction.pipeline.predict_step import predict_file
from wbfriction.studies.pd_peer import peer_held_out

pytestmark = [needs_data("unitree_aliengo"), pytest.mark.slow]


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


def test_the_identified_toml_holds_only_what_the_data_determine(route):
    _, _, identified, ours, _ = route
    for joint in identified.joints:
        written = ours.model.armature[ours.act_v_index[ours.actuated.index(joint.joint)]]
        if joint.armature.status == "ok":
            assert written == pytest.approx(joint.armature.value)
        else:
            assert written == 0.0  # aliengo.toml has none: a value not ok (weak, at a bound) is not written
