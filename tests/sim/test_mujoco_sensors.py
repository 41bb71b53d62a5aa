"""MuJoCo's ankle force-torque sensors: the plate split off its link changes nothing of the robot, the
wrenches follow the project's convention, and with them the estimate is exact on soft contacts."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions
from wbfriction.sim import MujocoOptions, simulate_mujoco
from wbfriction.sim.mujoco_model import build_mujoco_robot
from wbfriction.sim.mujoco_sim import MatchedMeans, matched_weights
from wbfriction.studies.common import leg_joints
from wbfriction.walking import GaitOptions, walking_reference


def test_the_plates_change_neither_the_mass_nor_the_contacts(talos):
    plain = build_mujoco_robot(dataclasses.replace(talos, ft_sensors=(), cache={}))
    split = build_mujoco_robot(talos)
    assert split.model.body_mass.sum() == pytest.approx(pin.computeTotalMass(talos.model), abs=1e-9)
    assert split.model.body_mass.sum() == pytest.approx(plain.model.body_mass.sum(), abs=1e-9)
    for s in talos.ft_sensors:
        plate = mujoco.mj_name2id(split.model, mujoco.mjtObj.mjOBJ_BODY, f"ft_{s.name}")
        assert split.model.body_mass[plate] == pytest.approx(0.4)
        link = split.model.body_parentid[plate]
        np.testing.assert_array_equal(split.model.body_invweight0[plate], split.model.body_invweight0[link])
    # the soles where they were, on the plates
    d_plain, d_split = mujoco.MjData(plain.model), mujoco.MjData(split.model)
    d_plain.qpos[:], d_split.qpos[:] = plain.qpos(talos.q_reference), split.qpos(talos.q_reference)
    mujoco.mj_forward(plain.model, d_plain)
    mujoco.mj_forward(split.model, d_split)
    for g_plain, g_split in zip(plain.sole_geoms, split.sole_geoms):
        np.testing.assert_allclose(d_split.geom_xpos[g_split], d_plain.geom_xpos[g_plain], atol=1e-12)
        np.testing.assert_allclose(d_split.geom_xmat[g_split], d_plain.geom_xmat[g_plain], atol=1e-12)


@pytest.fixture(scope="module")
def mujoco_walk(talos):
    """Two forward steps on MuJoCo's soft contacts, Table 6.1 friction on every leg joint, sensors logged;
    one physics step per period, so that the sensors' mean over the period is their reading at the instant
    the true accelerations are logged at."""
    friction = {j: THESIS_TARGETS[g] for j, _, g in leg_joints(talos)}
    ref = walking_reference(talos, GaitOptions(gait="forward", steps=2))
    return simulate_mujoco(talos, ref, friction, MujocoOptions(substeps=1)).log


@pytest.fixture(scope="module")
def mujoco_walk_4(talos):
    """The first 0.6 s of a forward walk with the default four physics steps per period, noise off."""
    ref = walking_reference(talos, GaitOptions(gait="forward", steps=1))
    ref = dataclasses.replace(ref, **{f: getattr(ref, f)[:600] for f in ("time", "q", "v", "a", "contact", "feet",
                                                                          "com", "zmp")})
    return simulate_mujoco(talos, ref, None, MujocoOptions())


def test_standing_the_ankles_read_the_weight_above_the_plates(talos, mujoco_walk):
    """Sign and scale: from 0.2 to 0.5 s, both feet down and the robot nearly still (in the first 0.2 s it
    settles on its soft soles), the two sensors' fz add up to the weight of everything above the plates
    (+: the plates push the robot up)."""
    above = (pin.computeTotalMass(talos.model) - 0.8) * 9.81
    assert mujoco_walk.contact[200:500].all()
    fz = mujoco_walk.wrench[200:500, :, 2].sum(axis=1)
    assert np.all(np.abs(fz - above) < 0.005 * above)


def test_with_the_sensors_every_leg_joint_is_exact_on_soft_contacts(talos, mujoco_walk):
    """True derivatives: the wrench route recovers the friction applied at every leg joint in every phase
    (MuJoCo's solver tolerance aside), where the rigid-contact route, whose welded sole MuJoCo's soft
    contact is not, misses it by up to newton-metres."""
    legs = [talos.torque_controlled.index(j) for j, _, _ in leg_joints(talos)]
    wrench = estimate_log(talos, mujoco_walk, EstimateOptions(diff="true", base_motion="logged"))
    contact = estimate_log(talos, mujoco_walk, EstimateOptions(diff="true", base_motion="contact", wrenches=False))
    err_w = np.abs(wrench.tau_f - wrench.tau_f_true)[:, legs]
    err_c = np.abs(contact.tau_f - contact.tau_f_true)[:, legs]
    assert wrench.valid[:, legs].all()
    assert np.median(err_w) < 1e-9 and err_w.max() < 1e-2
    assert np.nanmax(np.where(contact.valid[:, legs], err_c, np.nan)) > 20 * err_w.max()


def _error_share(robot, log, options) -> float:
    """RMS of the leg joints' friction error over their valid samples, as a share of the true friction's RMS."""
    legs = [robot.torque_controlled.index(j) for j, _, _ in leg_joints(robot)]
    est = estimate_log(robot, log, options)
    valid = est.valid[:, legs]
    err = (est.tau_f - est.tau_f_true)[:, legs][valid]
    return float(np.sqrt(np.mean(err**2)) / np.sqrt(np.mean(est.tau_f_true[:, legs][valid] ** 2)))


def test_a_compliant_sole_leaves_the_measured_route_and_degrades_the_rigid_one(talos):
    """MuJoCo's default soles, then soles twice as soft (contact time constant 0.04 s): with the ankle
    wrenches and the logged base (central differences, noise off) the error changes by less than 2 % of
    the friction; the rigid-contact route's grows (measured 0.10 -> 0.13 % against 7.6 -> 14.5 %)."""
    friction = {j: THESIS_TARGETS[g] for j, _, g in leg_joints(talos)}
    ref = walking_reference(talos, GaitOptions(gait="forward", steps=4))
    measured = EstimateOptions(diff="central", base_motion="logged")
    rigid = EstimateOptions(diff="central", base_motion="contact", wrenches=False)
    shares = {}
    for timeconst in (None, 0.04):
        log = simulate_mujoco(talos, ref, friction, MujocoOptions(sole_timeconst=timeconst)).log
        shares[timeconst] = (_error_share(talos, log, measured), _error_share(talos, log, rigid))
    (m_stiff, r_stiff), (m_soft, r_soft) = shares[None], shares[0.04]
    assert abs(m_soft - m_stiff) < 0.02 and m_soft < 0.01
    assert r_soft > r_stiff + 0.04 and r_soft > 2 * m_soft


def test_imperfections_are_off_by_default_and_drawn_from_the_seed():
    from wbfriction.sim import SensorNoise
    drift, offset = MujocoOptions().imperfections(100, 1e-3, 4, 2)
    assert not drift.any() and not offset.any()
    options = MujocoOptions(torque_drift=0.01, ft_offset=(5.0, 0.5), sensors=SensorNoise(seed=3))
    drift, offset = options.imperfections(1001, 1e-3, 4, 2)
    np.testing.assert_allclose(np.abs(drift[-1]), 0.01)  # 1 s at 0.01 N·m/s
    assert np.array_equal(offset, options.imperfections(1001, 1e-3, 4, 2)[1])
    assert 0.5 < np.std(offset[:, :3]) / 5.0 < 2 and 0.5 < np.std(offset[:, 3:]) / 0.5 < 2


@settings(max_examples=50, deadline=None)
@given(n=st.integers(1, 8), seed=st.integers(0, 2**32 - 1))
def test_matched_weights_are_what_the_central_second_difference_sees(n, seed):
    """Semi-implicit Euler (MuJoCo's position update) with ``n`` steps per period and arbitrary accelerations:
    the central second difference of the positions at the periods' first steps equals the accelerations
    weighed by :func:`matched_weights` (step ``s`` of period ``k`` counts ``w[s, 0]`` in sample ``k`` and
    ``w[s, 1]`` in sample ``k + 1``), and the weights of a sample sum to one."""
    rng = np.random.default_rng(seed)
    h, periods = 1e-3 / n, 4
    a = rng.normal(size=n * periods)
    x, v = np.zeros(n * periods + 1), rng.normal()
    for i, ai in enumerate(a):  # v_{i+1} = v_i + h a_i, x_{i+1} = x_i + h v_{i+1}
        v += h * ai
        x[i + 1] = x[i] + h * v
    w = matched_weights(n)
    sample = np.zeros(periods + 1)
    for i, ai in enumerate(a):
        k, s = divmod(i, n)
        sample[k] += w[s, 0] * ai
        sample[k + 1] += w[s, 1] * ai
    q, dt = x[::n], n * h
    central = (q[2:] - 2 * q[1:-1] + q[:-2]) / dt**2
    np.testing.assert_allclose(central, sample[1:periods], rtol=1e-9, atol=1e-9)
    assert w[:, 0].sum() + w[:, 1].sum() == pytest.approx(1.0)


@settings(max_examples=50, deadline=None)
@given(n=st.integers(1, 40), substeps=st.integers(1, 6), block=st.integers(1, 9), seed=st.integers(0, 2**32 - 1))
def test_matched_means_are_the_running_sums_bit_for_bit(n, substeps, block, seed):
    """:class:`MatchedMeans`, reduced in blocks, gives the very numbers of a running sum over the physics steps
    (each step's ``weight * reading`` added to its sample and the next as it comes), for any block size."""
    rng = np.random.default_rng(seed)
    readings = rng.normal(size=(n, substeps, 3)) * 10.0 ** rng.integers(-3, 4, size=(n, substeps, 3))
    w = matched_weights(substeps)
    running = np.zeros((n, 3))
    for k in range(n):
        for s in range(substeps):
            running[k] += w[s, 0] * readings[k, s]
            if k + 1 < n:
                running[k + 1] += w[s, 1] * readings[k, s]
    means = MatchedMeans(n, substeps, 3, block=block)
    for k in range(n):
        means.period(k)[:] = readings[k]
        means.done(k)
    assert np.array_equal(means.out, running)


def test_the_logged_torque_is_the_matched_mean_of_the_motors(talos, mujoco_walk_4):
    """Noise off, ``n`` = 4 physics steps per period: the torque sensor reads the motors' torque held over
    the periods as ``(n - 1) / 2n`` of the last period's and ``(n + 1) / 2n`` of this one's."""
    res, n = mujoco_walk_4, MujocoOptions().substeps
    tau, motor = res.log.tau, res.tau_motor
    np.testing.assert_allclose(tau[1:], (n - 1) / (2 * n) * motor[:-1] + (n + 1) / (2 * n) * motor[1:],
                               rtol=0, atol=1e-9)
    assert res.log.metadata["torque_alignment"] == "sample"
