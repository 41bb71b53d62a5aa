"""The walking quadruped's gait reference and ideal simulator (issue 56): what the log says is the truth.

The checks hold by construction of the physics, not by the code's own numbers: the equation of motion with the
log's true arrays and the feet's forces, the stance feet still, the planned contact pattern of each gait, the
robot upright, the drivers' law on the logged set-points, the friction the log says was injected.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from helpers import said
from wbfriction.exceptions import InputError, OptionError
from wbfriction.logs.log import log_from_table
from wbfriction.model import load_robot
from wbfriction.model.pd import pd_torque
from wbfriction.sim.quadruped import QuadrupedOptions, default_quadruped_friction, simulate_quadruped
from wbfriction.walking.quadruped import FOOT_RADIUS, GAITS, GaitOptions, quadruped_reference

LWA = pin.LOCAL_WORLD_ALIGNED
DURATION = {"stand": 1.5, "step": 2.0, "trot": 2.0, "walk": 3.0}


@pytest.fixture(scope="module")
def robot():
    """The built-in ``go2_walking``: a Go2 on four point feet."""
    return load_robot("go2_walking")


@pytest.fixture(scope="module")
def references(robot):
    """Each gait, short."""
    return {g: quadruped_reference(robot, GaitOptions(gait=g, duration=DURATION[g])) for g in GAITS}


@pytest.fixture(scope="module")
def runs(robot, references):
    """Each gait simulated, torque-driven, the feet's 3-D forces logged."""
    return {g: simulate_quadruped(robot, references[g], QuadrupedOptions(foot_forces="3d")) for g in GAITS}


@pytest.fixture(scope="module")
def pd_run(robot, references):
    """The trot, PD-driven (the robot's drivers, its [pd])."""
    return simulate_quadruped(robot, references["trot"], QuadrupedOptions(drive="pd", foot_forces="normal"))


def full_state(robot, log):
    """Configurations, velocities and accelerations (N, nq), (N, nv) from the log's true columns alone."""
    q = robot.configuration(log.q, log.base)
    v = np.hstack([log.base_qd_true, log.qd_true])
    a = np.hstack([log.base_qdd_true, log.qdd_true])
    order = np.concatenate([np.arange(6), robot.act_v_index])
    out_v, out_a = np.empty_like(v), np.empty_like(a)
    out_v[:, order], out_a[:, order] = v, a
    return q, out_v, out_a


def equation_residuals(robot, log, tau_motor, force, every=5):
    """Per checked sample: the largest residual of ``M a + h = S^T (tau + tau_f) + sum J_c^T lambda`` relative to
    ``|M a + h|``, and the largest stance-foot velocity [m/s] and acceleration [m/s^2], from the log's arrays, the
    motors' torque and the feet's forces ``force`` (N, 4, 3)."""
    model, data = robot.model, robot.model.createData()
    q, v, a = full_state(robot, log)
    eom, still = [], []
    for k in range(0, len(log), every):
        lhs = pin.rnea(model, data, q[k], v[k], a[k]).copy()
        rhs = np.zeros(model.nv)
        rhs[robot.act_v_index] = tau_motor[k] + log.tau_f_true[k]
        pin.computeJointJacobians(model, data, q[k])
        pin.forwardKinematics(model, data, q[k], v[k], a[k])
        pin.updateFramePlacements(model, data)
        for c, f in enumerate(robot.contact_frame_ids):
            if log.contact[k, c]:
                rhs += pin.getFrameJacobian(model, data, f, LWA)[:3].T @ force[k, c]
                still.append(max(np.abs(pin.getFrameVelocity(model, data, f, LWA).linear).max(),
                                 np.abs(pin.getFrameClassicalAcceleration(model, data, f, LWA).linear).max()))
        eom.append(np.abs(lhs - rhs).max() / np.abs(lhs).max())
    return np.array(eom), np.array(still)


@pytest.mark.parametrize("gait", GAITS)
def test_the_log_holds_the_equation_of_motion(robot, runs, gait):
    """The log's true state, torques, friction and feet's forces satisfy the equation of motion at every sample
    checked, and its stance feet neither move nor accelerate: an estimator fed with the truth is exact."""
    run = runs[gait]
    eom, still = equation_residuals(robot, run.log, run.log.tau, run.log.foot_force)
    assert eom.max() < 1e-8
    assert still.max() < 1e-8


def test_the_pd_driven_log_holds_it_with_the_drivers_torque(robot, pd_run):
    """PD-driven: the same with the torque the drivers applied; the law of :func:`pd_torque` on the logged
    set-points, encoder angles and driver velocities gives that torque to rounding, and so does the log's torque
    read back from its table (the lead's reader: no ``tau`` column, ``q_des``, ``qd_des``, ``tau_ff``)."""
    log = pd_run.log
    sp = log.setpoints
    assert log.torque_source == "pd" and sp is not None
    law = pd_torque(robot.pd, log.time, log.q + robot.offset_vector, sp.qd, sp.q_des, sp.qd_des, sp.tau_ff)
    np.testing.assert_allclose(law, pd_run.tau_motor, rtol=0, atol=1e-9)
    eom, _ = equation_residuals(robot, log, pd_run.tau_motor, pd_run.force)
    assert eom.max() < 1e-8
    table = log.to_table(robot)
    assert not any(c.startswith("tau.") for c in table.column_names)
    assert {f"force.{f}" for f in robot.contact_frames} <= set(table.column_names)
    read = log_from_table(table, robot)
    np.testing.assert_allclose(read.tau, pd_run.tau_motor, rtol=0, atol=1e-9)
    np.testing.assert_allclose(read.foot_force[..., 2], pd_run.force[..., 2], rtol=0, atol=1e-12)
    assert np.isnan(read.foot_force[..., :2]).all()


def test_the_log_reads_back(robot, runs):
    """Torque-driven: the table the log writes reads back to the same torques, friction, feet's forces (3-D) and
    planned contacts; the metadata names the friction injected, every joint its own."""
    log = runs["trot"].log
    read = log_from_table(log.to_table(robot), robot)
    np.testing.assert_array_equal(read.tau, log.tau)
    np.testing.assert_array_equal(read.tau_f_true, log.tau_f_true)
    np.testing.assert_array_equal(read.foot_force, log.foot_force)
    np.testing.assert_array_equal(read.contact, log.contact)
    truth = read.metadata["friction_true"]
    assert set(truth) == set(robot.actuated)
    assert len({round(t["F_c"], 6) for t in truth.values()}) == 12 == len({round(t["F_v"], 6) for t in truth.values()})


def test_friction_is_the_one_injected(robot, runs):
    """``tau_f_true = -f(qd_true)`` with the default friction's parameters (F_c 0.2-0.6 N·m, F_v 0.05-0.3
    N·m·s/rad, each joint its own)."""
    log = runs["walk"].log
    params = default_quadruped_friction(robot)
    for i, joint in enumerate(robot.actuated):
        p = params[joint]
        assert 0.2 <= p.F_c <= 0.6 and 0.05 <= p.F_v <= 0.3
        np.testing.assert_allclose(log.tau_f_true[:, i], -p.f(log.qd_true[:, i]), rtol=0, atol=1e-12)


def test_each_gait_has_its_contact_pattern(robot, references):
    """stand: four feet always; step and trot: a diagonal pair in the air, the other on the ground, four feet down
    only at the switches (single samples) and over the first and last half period; walk: one foot in the air at
    most, each in turn, the same order every cycle."""
    corners = [(f[0], f[1]) for f in robot.contact_frames]  # ('F' | 'R', 'L' | 'R')
    diagonals = [{corners.index(("F", "L")), corners.index(("R", "R"))},
                 {corners.index(("F", "R")), corners.index(("R", "L"))}]
    assert references["stand"].contact.all()
    for gait in ("step", "trot"):
        ref = references[gait]
        air = [set(np.flatnonzero(~row).tolist()) for row in ref.contact]
        assert all(a in (set(), *diagonals) for a in air)
        half = int(round(0.5 * ref.options.period / ref.dt))
        four = ref.contact.all(axis=1)
        assert four[:half].all() and four[-half:].all()
        inside = four[half + 1:-half - 1]
        assert inside.any() and not (inside[1:] & inside[:-1]).any()  # the switches: lone samples
        swings = [a for i, a in enumerate(air) if a and a != air[i - 1]]  # each swing once
        assert len(swings) > 4 and all(a != b for a, b in zip(swings, swings[1:]))  # the pairs alternate
    c = references["walk"].contact
    assert set(c.sum(axis=1).tolist()) == {3, 4}
    swinging = [int(np.flatnonzero(~row)[0]) for row in c if not row.all()]
    order = [swinging[0]] + [b for a, b in zip(swinging, swinging[1:]) if b != a]
    assert len(order) > 4 and sorted(order[:4]) == [0, 1, 2, 3] and order[4:] == order[:len(order) - 4]


@pytest.mark.parametrize("gait", GAITS)
def test_the_robot_stays_up_and_the_feet_push(robot, runs, references, gait):
    """The base stays within 2.5 cm of its planned position; a foot in contact pushes on the ground (its normal
    force > 0) but at a switch's sample, where a landing foot may pull a little (the impact, the joints' PD on four
    feet: under 15 N, a fifth of a stance foot's load), a foot in the air feels none; a landing foot is within 3 mm
    of its footprint (the configuration's projection at touch-down moves it no more)."""
    run, ref = runs[gait], references[gait]
    assert np.abs(run.log.base[:, :3] - ref.base[:, :3]).max() < 0.025
    stance = run.log.contact
    switch = np.r_[False, np.any(np.diff(stance, axis=0), axis=1)]
    normal = run.force[..., 2]
    assert normal[stance & ~switch[:, None]].min() > 0
    assert normal[stance].min() > -15.0
    assert np.all(run.force[~stance] == 0)
    assert gait == "stand" or 0 < run.snap.max() < 0.003


@pytest.mark.parametrize("gait", GAITS)
def test_the_joints_move_both_ways_fast_and_slow(robot, gait):
    """Over the gait's default 8 s every joint's velocity changes sign, passes near zero and exceeds 1.5 rad/s
    (2 rad/s in the gaits that step): friction is seen both ways over a range of speeds."""
    qd = quadruped_reference(robot, GaitOptions(gait=gait)).qd
    assert np.all((qd > 0.05).any(axis=0) & (qd < -0.05).any(axis=0))
    assert np.all(np.abs(qd).min(axis=0) < 0.01)
    assert np.all(np.abs(qd).max(axis=0) > (1.5 if gait == "stand" else 2.0))


def simpson_error(x, rate, dt):
    """The largest gap between ``x``'s change over two samples and Simpson's integral of ``rate`` over them."""
    return np.abs((x[2:] - x[:-2]) - dt / 3 * (rate[:-2] + 4 * rate[1:-1] + rate[2:])).max()


def test_the_reference_is_consistent(robot, references):
    """The reference's velocities and accelerations are the derivatives of its angles (Simpson's rule over two
    samples), its stance feet stand at their footprints, on the ground, and its step stays in place."""
    for gait in ("trot", "walk"):
        ref = references[gait]
        assert simpson_error(ref.q, ref.qd, ref.dt) < 1e-6
        assert simpson_error(ref.qd, ref.qdd, ref.dt) < 1e-3
        np.testing.assert_allclose(ref.feet[..., 2][ref.contact], FOOT_RADIUS, atol=1e-12)
    step = references["step"]
    assert np.abs(step.base[:, 0]).max() < 0.02
    assert references["trot"].base[-1, 0] > 0.2


def test_bad_options_say_so(robot, references):
    """An unknown gait or drive, a physics step that does not divide the log's period, a robot on soles: one line
    each, naming the option."""
    with pytest.raises(OptionError, match="--gait"):
        GaitOptions(gait="gallop")  # type: ignore[arg-type]
    with pytest.raises(OptionError, match="--drive"):
        QuadrupedOptions(drive="current")  # type: ignore[arg-type]
    with pytest.raises(OptionError, match="--physics-dt"):
        simulate_quadruped(robot, references["stand"], QuadrupedOptions(physics_dt=0.0003))
    with pytest.raises(InputError, match="point feet"):
        simulate_quadruped(load_robot("talos"), references["stand"])


def test_the_command_line_walks_a_quadruped(robot, tmp_path, capsys):
    """``simulate --robot go2_walking --gait walk --drive pd --foot-forces 3d`` writes a PD-driven crawl's log
    (set-points, no torque columns, the feet's 3-D forces, the planned contacts, three feet down or four); a
    humanoid's gait on point feet, and a quadruped's on a humanoid, are one-line errors naming --gait."""
    from helpers import run_cli
    from wbfriction.logs.source import read_log

    path = tmp_path / "crawl.parquet"
    code, err = run_cli(capsys, "simulate", "--robot", "go2_walking", "--gait", "walk", "--drive", "pd",
                        "--duration", "1.5", "--foot-forces", "3d", "-o", path)
    assert code == 0, err
    log = read_log(path, robot)
    assert log.torque_source == "pd" and len(log) == 750
    assert np.isfinite(log.foot_force).all()
    assert set(log.contact.sum(axis=1).tolist()) == {3, 4}
    assert log.metadata["gait"]["gait"] == "walk" and log.metadata["drive"] == "pd"
    code, err = run_cli(capsys, "simulate", "--robot", "go2_walking", "--gait", "forward", "-o", path)
    assert code == 2 and "--gait forward" in err and len(said(err)) == 1
    code, err = run_cli(capsys, "simulate", "--gait", "trot", "-o", path)
    assert code == 2 and "--gait trot" in err and len(said(err)) == 1


def test_the_held_torque_is_a_real_robots_zero_order_hold(robot, runs):
    """Torque-driven, the command ``tau[k]`` acts over ``[t_k, t_k+1)`` as on a real robot, so that positions
    differentiated at the log rate see the mean of the two torques around a sample (``torque_alignment = "zoh"``).
    With semi-implicit Euler and the command applied from the period's first physics step, the torque acted half a
    physics step early: the hips' F_v came out 3-16 % high on noise-free logs differentiated (issue 63). Central
    differences, every joint seen (3-D forces), 2 s: every hip's fitted F_v within 5 % of the injected one (3.0 %
    at worst; 19.9 % before)."""
    from wbfriction.fit.joints import fit_estimate
    from wbfriction.fit.options import FitOptions
    from wbfriction.friction.estimate import estimate_log
    from wbfriction.friction.options import EstimateOptions

    log = runs["trot"].log
    assert log.metadata["torque_alignment"] == "zoh"
    est = estimate_log(robot, log, EstimateOptions(diff="central", route="acceleration", base_motion="logged",
                                                   check_route=False))
    hips = [j for j in robot.actuated if "hip" in j]
    fits = {f.joint: f for f in fit_estimate(est, FitOptions(model="thesis"), fixed={"S": 0.0, "v_s": 0.1})}
    truth = default_quadruped_friction(robot)
    errors = {j: fits[j].params.F_v / truth[j].F_v - 1 for j in hips}
    assert max(abs(e) for e in errors.values()) < 0.05, errors
