"""The friction of a robot on point feet (wbfriction.friction.point_contacts) on exact data: equal to the true
friction to 1e-8 wherever the contacts leave it determined, not estimated elsewhere, every joint with 3-D foot
forces; the contact pattern's shares; what is refused."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest

from helpers import consistent_motion, run_cli, widest_line
from wbfriction.exceptions import InputError
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.io import friction_table, read_friction_file
from wbfriction.friction.options import EstimateOptions
from wbfriction.friction.point_contacts import determined_shares
from wbfriction.logs.log import Log, write_log
from wbfriction.logs.source import read_log
from wbfriction.logs.tables import write_table
from wbfriction.model.determination import contact_jacobian
from wbfriction.model.loading import load_robot

DT = 0.002
TROT = np.array([[1, 0, 0, 1], [0, 1, 1, 0]], dtype=bool)  # the diagonal pairs


@pytest.fixture(scope="module")
def go2():
    return load_robot("go2_walking")


def exact_log(robot, n: int = 600, forces: str = "none", seed: int = 0) -> Log:
    """A log whose every sample satisfies the equation of motion exactly: smooth joint motions, a trot's contact
    pattern (diagonal pairs, 0.25 s each, four feet down for 20 ms between), contact forces drawn, the base's
    acceleration solved from its six rows, the torques from the joints' rows less a known friction. The samples
    are not one trajectory (the base's pose does not integrate its acceleration): with the true derivatives
    (diff "true") the estimator reads each one alone."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * DT
    phase = 2 * np.pi * t / 0.5
    amp, off = rng.uniform(0.1, 0.3, robot.n_act), rng.uniform(0, 2 * np.pi, robot.n_act)
    angles = robot.reference_angles + amp * np.sin(phase[:, None] + off)
    qd = amp * 2 * np.pi / 0.5 * np.cos(phase[:, None] + off)
    qdd_j = -amp * (2 * np.pi / 0.5) ** 2 * np.sin(phase[:, None] + off)
    pair = (t // 0.25).astype(int) % 2
    contact = TROT[pair]
    contact[(t % 0.25) < 0.02] = True  # four feet down at each switch
    base = np.tile([0.0, 0.0, 0.3, 0.0, 0.0, 0.0, 1.0], (n, 1))
    base[:, 3] = 0.05 * np.sin(phase)  # a roll
    base[:, 3:] /= np.linalg.norm(base[:, 3:], axis=1, keepdims=True)
    v = np.zeros((n, robot.model.nv))
    v[:, :6] = rng.normal(0, 0.2, (n, 6))
    v[:, robot.act_v_index] = qd
    force = rng.normal(0, 15, (n, 4, 3)) + [0, 0, 50]
    tau_f = -(0.3 * np.tanh(50 * qd) + 0.1 * qd)
    a, tau = consistent_motion(robot, robot.configuration(angles, base), v, qdd_j, contact, force, tau_f)
    foot_force = None
    if forces != "none":
        foot_force = np.where(contact[..., None], force, 0.0)
        if forces == "normal":
            foot_force[..., :2] = np.nan
    return Log(t, angles, tau, contact, base, tau_f, {}, "exact.parquet", qd_true=qd, qdd_true=qdd_j,
               base_qd_true=v[:, :6], base_qdd_true=a[:, :6], foot_force=foot_force)


TRUE = EstimateOptions(diff="true")


def test_exact_where_determined(go2):
    est = estimate_log(go2, exact_log(go2), TRUE)
    truth = est.tau_f_true
    assert est.valid.any()
    err = np.abs(est.tau_f - truth)[est.valid]
    assert err.max() < 1e-8 * np.abs(truth).max()
    assert np.isnan(est.tau_f[~est.valid]).all()
    # the swinging pair is determined, the stance pair is not; never at four feet down
    legs = np.array([n[:2] for n in go2.torque_controlled])
    frames = [f[:2] for f in go2.contact_frames]
    for k in np.flatnonzero(est.valid.any(axis=1)):
        down = {f for f, on in zip(frames, est.contact[k]) if on}
        assert len(down) == 2
        assert (est.valid[k] == ~np.isin(legs, list(down))).all()
    shares = determined_shares(est).to_dict()
    by_pattern = {p["pattern"]: p for p in shares["patterns"]}
    assert by_pattern["FL_foot+RR_foot"]["share"]["FR_hip_joint"] == 1.0
    assert by_pattern["FL_foot+RR_foot"]["share"]["FL_hip_joint"] == 0.0
    assert set(by_pattern["FL_foot+FR_foot+RL_foot+RR_foot"]["share"].values()) == {0.0}  # standing: none
    assert sum(p["samples"] for p in shares["patterns"]) == np.isfinite(est.cond).sum()


def test_foot_forces_determine_every_joint(go2, tmp_path):
    """3-D foot forces: every joint in every settled sample, still exact; read back from a file, the same."""
    log = exact_log(go2, forces="3d")
    est = estimate_log(go2, log, TRUE)
    assert est.valid.any(axis=1).sum() == est.valid.all(axis=1).sum() > 0.3 * len(log.time)
    assert np.abs(est.tau_f - est.tau_f_true)[est.valid].max() < 1e-8 * np.abs(est.tau_f_true).max()
    path = tmp_path / "forces.parquet"
    write_log(log, go2, path)
    again = estimate_log(go2, read_log(path, go2), TRUE)
    assert np.array_equal(again.valid, est.valid)
    table = tmp_path / "friction.parquet"
    write_table(friction_table(est), table)
    back = read_friction_file(table)
    assert np.array_equal(back.determined, est.determined) and np.array_equal(back.cond, est.cond, equal_nan=True)
    assert np.allclose(again.tau_f[est.valid], est.tau_f[est.valid], rtol=0, atol=1e-12)


def test_normal_forces_only(go2):
    """Normal forces alone: the feet here are not on one level, so they may help; whatever they determine is
    exact, and at least the swing legs are determined."""
    est = estimate_log(go2, exact_log(go2, forces="normal"), TRUE)
    plain = estimate_log(go2, exact_log(go2), TRUE)
    assert (est.valid | ~plain.valid).all()
    assert np.abs(est.tau_f - est.tau_f_true)[est.valid].max() < 1e-7 * np.abs(est.tau_f_true).max()


def test_refusals(go2):
    """Point feet leave the base free to turn about them: without its measured motion, both routes refuse."""
    log = exact_log(go2, n=400)
    no_base = Log(log.time, log.q, log.tau, log.contact, None, log.tau_f_true, {}, "nobase.parquet",
                  qd_true=log.qd_true, qdd_true=log.qdd_true)
    for options in (TRUE, EstimateOptions(diff="central", route="momentum", check_route=False)):
        with pytest.raises(InputError, match="nobase.parquet: a robot on point feet needs the base's measured motion"):
            estimate_log(go2, no_base, options)


def test_estimate_prints_the_shares_by_feet_down(go2, tmp_path, capsys):
    """``wbfriction estimate`` on a robot on point feet prints, per joint, the share of samples that determine it by
    the feet on the ground, within 100 columns."""
    log = tmp_path / "trot.parquet"
    write_log(exact_log(go2), go2, log)
    code, text = run_cli(capsys, "estimate", str(log), "--robot", "go2_walking", "--diff", "true", "-o",
                         str(tmp_path / "f.parquet"))
    assert code == 0
    lines = text.splitlines()
    head = next(i for i, line in enumerate(lines) if line.startswith("determined: share of samples"))
    columns = lines[head + 1].split()
    assert sorted(columns) == ["FL+FR+RL+RR", "FL+RR", "FR+RL", "all"]
    # each joint by its name, as the log and every other command name it
    rows = {line.split()[0]: dict(zip(columns, line.split()[1:][::2])) for line in lines[head + 3:head + 15]}
    assert sorted(rows) == sorted(go2.actuated)
    assert rows["FL_hip_joint"] == {**rows["FL_hip_joint"], "FR+RL": "100", "FL+RR": "0", "FL+FR+RL+RR": "0"}
    assert rows["FR_hip_joint"] == {**rows["FR_hip_joint"], "FR+RL": "0", "FL+RR": "100", "FL+FR+RL+RR": "0"}
    assert widest_line("\n".join(lines[head:head + 18])) <= 100


def test_contact_point_below_a_spherical_foot(go2):
    """With ``foot_radius`` r, a point foot's Jacobian gives the velocity of the sphere's lowest point, ``v_o + w x
    (0, 0, -r)`` (the frame's velocity in world axes, Pinocchio's own)."""
    robot = replace(go2, foot_radius=0.023, cache={})
    model, data = robot.model, robot.model.createData()
    rng = np.random.default_rng(3)
    q = robot.configuration(robot.reference_angles + rng.normal(0, 0.2, robot.n_act), np.r_[0, 0, 0.3, 0, 0, 0, 1])
    v = rng.normal(0, 1, model.nv)
    pin.forwardKinematics(model, data, q, v)
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    for c, fid in enumerate(robot.contact_frame_ids):
        twist = pin.getFrameVelocity(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        expected = twist.linear + np.cross(twist.angular, [0.0, 0.0, -0.023])
        assert np.allclose(contact_jacobian(robot, data, c) @ v, expected, atol=1e-12)
        assert np.allclose(contact_jacobian(go2, data, c) @ v, twist.linear, atol=1e-12)
