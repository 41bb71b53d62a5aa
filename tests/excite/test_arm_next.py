"""What to record next on a fixed-base arm (:func:`wbfriction.excite.next.record_next_arm`, ``wbfriction excite
--after``): a Panda's log whose wrist (joints 5-7) held still leaves their friction undetermined; the motion proposed
moves them alone, and played with another noise it determines them, the injected friction recovered.

Cost: the first recording (10 s) simulated, estimated and fitted, about 12 s; the design of three joints and its
prediction (two identifications of 10 s), about 25 s; the motion played and identified, about 12 s."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

import wbfriction
from wbfriction.exceptions import InputError
from wbfriction.excite.design import ExciteOptions, design_excitation
from wbfriction.excite.predict_arm import REAL_ARM, identify_arm, sensor_noise
from wbfriction.fit.params_file import read_params
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.setpoint_table import read_setpoint_table
from wbfriction.logs.tables import write_table
from wbfriction.model.loading import RobotSpec
from wbfriction.pipeline.estimate_step import estimate_file
from wbfriction.pipeline.fit_step import fit_file
from wbfriction.sim.arm import ExcitationOptions, default_arm_friction, excitation_trajectory, simulate_arm
from wbfriction.walking.fourier import FourierTrajectory

WRIST = ("panda_joint5", "panda_joint6", "panda_joint7")
DURATION = 10.0


@pytest.fixture(scope="module")
def first(tmp_path_factory):
    """The Panda, the friction injected (the wrist's off the simulator's default, the design's prior for a joint
    without a fit it can take: F_c 1.2 times, F_v 0.8 times), and the parameters JSON of a 10 s log (a real arm's
    sensors) whose wrist held still at the middle of its range."""
    folder = tmp_path_factory.mktemp("arm_next")
    panda = wbfriction.load_robot("panda")
    truth = {j: dataclasses.replace(p, F_c=1.2 * p.F_c, F_v=0.8 * p.F_v) if j in WRIST else p
             for j, p in default_arm_friction(panda).items()}
    lower, upper = panda.angle_limits
    moved = ~np.isin(panda.actuated, WRIST)
    trajectory = excitation_trajectory(lower, upper, panda.model.velocityLimit[panda.act_v_index],
                                       ExcitationOptions(range_share=0.9, velocity_share=0.8, seed=1), moved)
    sim = simulate_arm(panda, truth, options=dataclasses.replace(REAL_ARM, duration=DURATION, seed=3),
                       trajectory=trajectory)
    write_table(sim.table, folder / "first.parquet")
    estimate_file(RobotSpec.given("panda"), folder / "first.parquet", folder / "friction.parquet",
                  EstimateOptions(), robot=panda)
    fit_file(folder / "friction.parquet", folder / "params.json")
    return panda, truth, folder


@pytest.mark.slow
@pytest.mark.xdist_group("excite_arm_next")
def test_the_wrist_held_still_is_recorded_next_and_determined(first, cli, tmp_path):
    panda, truth, folder = first
    fits = read_params(folder / "params.json")
    undetermined = {j for j, f in fits.items() if not f.verdict().ok}
    assert undetermined == set(WRIST), {j: f.verdict() for j, f in fits.items()}
    assert {fits[j].verdict().status for j in WRIST} == {"not excited"}

    out = " ".join(cli("excite", "--robot", "panda", "--after", folder / "params.json", "--duration", DURATION,
                       "--period", DURATION, "-o", tmp_path / "next.csv", "--json", tmp_path / "next.json",
                       "--figure", tmp_path / "next.png").split())
    assert "held at their posture (their fits ok): panda_joint1, panda_joint2, panda_joint3, panda_joint4" in out
    assert "prior friction from the fit on 4 joints" in out  # the shoulder's and elbow's fits: ok, their priors
    doc = json.loads((tmp_path / "next.json").read_text())
    after = doc["after"]
    assert after["moving"] == list(WRIST) and set(after["logged"]) == set(WRIST)
    assert {after["logged"][j]["status"] for j in WRIST} == {"not excited"}
    assert set(doc["predicted"]) == set(WRIST) and min(doc["margins"][j]["torque"] for j in panda.actuated) >= 0.2

    assert (tmp_path / "next.png").stat().st_size > 10_000
    table = read_setpoint_table(tmp_path / "next.csv", panda)
    still = [panda.actuated.index(j) for j in panda.actuated if j not in WRIST]
    assert np.ptp(table.q_des[:, still], axis=0).max() == 0.0
    assert np.ptp(table.q_des[:, [panda.actuated.index(j) for j in WRIST]], axis=0).min() > 1.0
    f = table.fourier
    assert f is not None
    played = FourierTrajectory(np.asarray(f["center"]), np.asarray(f["a"]), np.asarray(f["b"]), float(f["omega"]))
    _, again = identify_arm(panda, truth, played, dataclasses.replace(REAL_ARM, duration=DURATION, seed=9),
                            joints=WRIST)
    for fit in again:
        assert fit.verdict().status == "ok", (fit.joint, fit.verdict())
        read = fit.read_stderr()
        for name in ("F_c", "F_v"):
            error = abs(getattr(fit.params, name) - getattr(truth[fit.joint], name))
            assert error < 2 * read[name], (fit.joint, name, error, read[name])


def test_a_design_holds_the_joints_it_does_not_move():
    """The held joints' series are constants at the middle of their range, their velocity margin whole; the bounds
    and shares are the moving joint's alone; a joint the robot does not have, or none, is refused."""
    panda = wbfriction.load_robot("panda")
    prior, noise = default_arm_friction(panda), sensor_noise(panda)
    options = ExciteOptions(duration=2.0, period=2.0, starts=1)
    design = design_excitation(panda, prior, noise, options, moving=["panda_joint7"])
    lower, upper = panda.angle_limits
    t = design.trajectory
    np.testing.assert_array_equal(t.center[:6], 0.5 * (lower + upper)[:6])
    assert not np.any(t.a[:6]) and not np.any(t.b[:6]) and np.any(t.a[6])
    assert design.moving == ("panda_joint7",) and set(design.shares) == set(design.bound) == {"panda_joint7"}
    np.testing.assert_array_equal(design.margins.velocity[:6], 1.0)
    assert design.margins.torque.min() >= 1.0 - options.torque_share  # the held joints' gravity within the limit
    with pytest.raises(InputError, match="robot 'panda': no actuated joint 'elbow' to move"):
        design_excitation(panda, prior, noise, options, moving=["elbow"])
    with pytest.raises(InputError, match="robot 'panda': no joint to move"):
        design_excitation(panda, prior, noise, options, moving=[])
