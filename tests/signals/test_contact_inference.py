"""Contacts from the log (issue 82, item 1): on the MuJoCo twin (trot and walk, clean and with a Unitree's noise) the
best guess agrees with the simulator's contacts (normal force > 0) on at least 97 % of the samples from the joints,
torques and the base's rotation alone, and with raw foot-force counts of an unknown offset and scale; a standing log
is refused; a leg's known force is recovered from its torques; counts' offset and scale are found for any drawn."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError, OptionError
from wbfriction.logs.contacts import OFF_SHARE
from wbfriction.model.loading import load_robot
from wbfriction.signals.contact_inference import (
    LIFT_SIGMAS,
    ROBUST_SCALE,
    ContactOptions,
    calibrate_counts,
    check_swings,
    feet_kinematics,
    infer_contacts,
    least_swing,
    lifted_unloaded,
    run_count,
    unlifted_swings,
    weight,
)
from wbfriction.sim.logger import ORIENTATION_STD
from wbfriction.sim.quadruped import QuadrupedOptions
from wbfriction.sim.quadruped_mjcf import build_quadruped_model
from wbfriction.sim.quadruped_mujoco import UNITREE_NOISE, simulate_quadruped_mujoco
from wbfriction.walking.quadruped import GaitOptions, quadruped_reference

COUNTS_SCALE, COUNTS_OFFSET = 37.0, 512.0
"""The raw counts made from the simulator's normal forces: ``counts = 37 F + 512``, the inference not told."""


@pytest.fixture(scope="module")
def robot():
    """The built-in ``go2_walking`` with MuJoCo's spherical feet (``foot_radius = 0.023``, the quadrupeds how-to)."""
    return dataclasses.replace(load_robot("go2_walking"), foot_radius=0.023)


@pytest.fixture(scope="module")
def mjr(robot):
    return build_quadruped_model(robot)


@pytest.fixture(scope="module")
def runs(robot, mjr):
    """4 s runs, made once per module on first use: (gait, noisy) -> the run."""
    cache: dict = {}

    def get(gait: str, noisy: bool):
        if (gait, noisy) not in cache:
            reference = quadruped_reference(robot, GaitOptions(gait, duration=4.0))
            cache[gait, noisy] = simulate_quadruped_mujoco(robot, reference, QuadrupedOptions(foot_forces="normal"),
                                                           noise=UNITREE_NOISE if noisy else None, mjr=mjr)
        return cache[gait, noisy]
    return get


def rotations(base: np.ndarray) -> np.ndarray:
    return np.array([pin.Quaternion(b[3:]).matrix() for b in base])


@pytest.mark.parametrize("counts", [False, True], ids=["no-counts", "counts"])
@pytest.mark.parametrize("noisy", [False, True], ids=["clean", "noisy"])
@pytest.mark.parametrize("gait", ["trot", "walk"])
def test_the_twins_contacts_are_recovered(robot, runs, gait, noisy, counts):
    """At least 97 % of the samples (all of them, the best guess) agree with the simulator's contacts (measured:
    97.8-98.8 % without counts, the walk's feet grazing the ground, never lifted, called stance; 97.2-100 % with
    them); the confident samples agree at least as well; at least 95 % of the feet's samples are confident (measured
    96-100 %), and the gait's period is the reference's."""
    run = runs(gait, noisy)
    log = run.log
    truth = run.force[..., 2] > 0  # the true normal force, noise off
    foot_counts = COUNTS_SCALE * log.foot_force[..., 2] + COUNTS_OFFSET if counts else None
    inferred = infer_contacts(robot, log.q, log.qd_logged, log.tau, rotations(log.base), run.reference.dt,
                              foot_counts=foot_counts, source=f"{gait}.parquet")
    agree = inferred.contact == truth
    assert agree.mean() >= 0.97, agree.mean(axis=0)
    assert agree[inferred.confident].mean() >= agree.mean()
    assert inferred.confident.mean() >= 0.95
    assert inferred.unconfident_rows().shape == (len(log.q),)
    assert np.all((inferred.confidence >= 0.5) & (inferred.confidence <= 1.0))
    assert inferred.gait_period == pytest.approx(run.reference.options.period, rel=0.02)
    assert inferred.cues == (("torque", "kinematics", "counts", "periodicity") if counts
                             else ("torque", "kinematics", "periodicity"))


def test_a_standing_log_is_refused(robot, mjr):
    """Feet that never leave the ground: nothing is determined without foot forces, one line naming the log."""
    reference = quadruped_reference(robot, GaitOptions("stand", duration=1.0))
    log = simulate_quadruped_mujoco(robot, reference, mjr=mjr).log
    with pytest.raises(InputError, match=r"^stand.parquet: no foot ever leaves the ground"):
        infer_contacts(robot, log.q, log.qd_logged, log.tau, rotations(log.base), reference.dt,
                       source="stand.parquet")


def test_a_standing_log_with_noisy_feet_is_refused(robot, mjr):
    """The twin standing 8 s with a Unitree's noise, its base's rotation read from an IMU of the noisy raw twin's
    orientation noise (sim.logger.ORIENTATION_STD, white): near the end a foot's load falls to a few per cent of the
    weight and isolated samples (runs of 1-2, measured; 1-8 with other seeds of the IMU's noise) are lifted and
    unloaded. Before, any such sample passed the check and each foot was called off the ground on 43-49 % of the
    samples, on a robot that never swings; now a swing needs a run of least_swing samples (for the runs the log holds),
    and the message says what was found."""
    reference = quadruped_reference(robot, GaitOptions("stand", duration=8.0))
    log = simulate_quadruped_mujoco(robot, reference, noise=UNITREE_NOISE, mjr=mjr).log
    rng = np.random.default_rng(0)
    imu = np.array([R @ pin.exp3(rng.normal(0.0, ORIENTATION_STD, 3)) for R in rotations(log.base)])
    points, forces = feet_kinematics(robot, log.q, log.tau, imu)
    z = points[..., 2]
    low = np.sort(z, axis=1)
    h = z - low[:, :2].mean(axis=1, keepdims=True)
    sigma = float(np.median(low[:, 1] - low[:, 0])) / ROBUST_SCALE
    assert lifted_unloaded(h, sigma, forces[..., 2], weight(robot)).any()  # what passed before
    with pytest.raises(InputError, match=r"^stand.parquet: no foot ever leaves the ground \(a standing log\): the "
                       r"longest run of samples with a foot lifted and unloaded is \d+ \(\d+ ms, \w+_foot\), "
                       r"against the \d+ \(\d+ ms\) a swing needs among the log's \d+ runs") as refused:
        infer_contacts(robot, log.q, log.qd_logged, log.tau, imu, reference.dt, source="stand.parquet")
    assert "\n" not in str(refused.value)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(100, 3000), nc=st.integers(2, 4),
       share=st.floats(0.0, 0.3), torque=st.booleans())
def test_isolated_lifted_samples_never_make_a_swing_and_one_run_does(seed, n, nc, share, torque):
    """Synthetic feet standing (heights within their noise, loads above the off threshold), with runs of lifted and
    unloaded samples each shorter than the least any log needs, separated by one standing sample or more, on up to
    ``share`` of the samples: refused. One run as long as least_swing of the runs then held added on a foot:
    accepted, that foot's longest run is it."""
    rng = np.random.default_rng(seed)
    sigma, w = 1e-3, 150.0
    shortest = least_swing(1)  # what a swing needs whatever the runs: noise runs shorter are refused
    h = rng.normal(0.0, sigma, (n, nc)).clip(-3 * sigma, 3 * sigma)
    fz = rng.uniform(OFF_SHARE * w * 1.01, w, (n, nc))
    for c in range(nc):
        k = 0
        while k < n:
            length = int(rng.integers(1, shortest))
            if rng.random() < share:
                h[k: k + length, c] = rng.uniform(LIFT_SIGMAS * sigma * 1.01, 0.1, len(h[k: k + length]))
                fz[k: k + length, c] = rng.uniform(-0.2 * w, OFF_SHARE * w * 0.99, len(h[k: k + length]))
            k += length + 1  # the next run after a standing sample
    frames = tuple(f"foot{c}" for c in range(nc))
    before = lifted_unloaded(h, sigma, fz if torque else None, w)
    with pytest.raises(InputError, match="no foot ever leaves the ground"):
        check_swings(before, 0.002, frames)
    need = least_swing(run_count(before) + 2)  # the run added, and one it may split in two
    c, start = int(rng.integers(nc)), int(rng.integers(0, max(n - need, 0) + 1))
    h[start: start + need, c], fz[start: start + need, c] = 0.05, 0.0
    for k in (start - 1, start + need):  # standing on either side: the run is exactly ``need`` long
        if 0 <= k < n:
            h[k, c], fz[k, c] = 0.0, w
    after = lifted_unloaded(h, sigma, fz if torque else None, w)
    runs = check_swings(after, 0.002, frames)
    assert least_swing(run_count(after)) <= need and runs[c] == min(need, n) and runs.max() == min(need, n)


def test_the_run_a_swing_needs_grows_with_the_log_s_runs_not_its_samples():
    """One more sample per doubling of the runs; the samples do not count (a minute's walk at 2 ms asked 27 samples
    when every sample counted as a start, more than a Solo-12's swings hold)."""
    assert least_swing(1) == 11 and least_swing(100) == 18 and least_swing(200) == 19
    lifted = np.zeros((30_000, 4), dtype=bool)
    lifted[100:121, 0] = True  # one run of 21 samples in a minute's log at 2 ms
    assert run_count(lifted) == 1 and check_swings(lifted, 0.002, ("a", "b", "c", "d"))[0] == 21


@settings(max_examples=80, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 400), nc=st.integers(1, 4), share=st.floats(0.0, 1.0))
def test_a_swing_whose_foot_never_lifts_is_called_stance(seed, n, nc, share):
    """Random contact states and heights (within the stance noise, or lifted on ``share`` of the samples): exactly the
    samples of the swings (runs of False) holding no sample above LIFT_SIGMAS * sigma are found, whole runs, never a
    stance sample nor a swing that lifts. Before, every run the chain called swing was kept (Solo-12's walk: a foot
    grazing the ground with 0.3-3 N read as a 40 ms swing each gait cycle)."""
    rng = np.random.default_rng(seed)
    sigma = 1e-3
    contact = rng.random((n, nc)) < 0.5
    contact = np.repeat(contact, rng.integers(1, 30), axis=0)[:n] if n > 1 else contact
    h = rng.uniform(-3 * sigma, LIFT_SIGMAS * sigma, contact.shape)
    h[rng.random(contact.shape) < share * 0.1] = rng.uniform(LIFT_SIGMAS * sigma * 1.001, 0.1)
    found = unlifted_swings(contact, h, sigma)
    assert not (found & contact).any()
    for c in range(contact.shape[1]):
        edges = np.diff(np.r_[0, (~contact[:, c]).astype(np.int8), 0])
        for a, b in zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)):
            lifted = (h[a:b, c] > LIFT_SIGMAS * sigma).any()
            assert np.all(found[a:b, c] == (not lifted))


def test_a_short_log_and_bad_options_are_refused(robot):
    q = np.tile(robot.reference_angles, (50, 1))
    with pytest.raises(InputError, match=r"^short.csv: 50 samples are too short"):
        infer_contacts(robot, q, 0 * q, 0 * q, None, 0.002, source="short.csv")
    with pytest.raises(OptionError, match="--contact-level"):
        ContactOptions(level=1.0)


@pytest.mark.parametrize("radius", [0.0, 0.023])
def test_a_legs_known_force_is_recovered_from_its_torques(robot, radius):
    """Static balance of one leg, ``tau = g - J^T f`` (Pinocchio's gravity, the Jacobian at the contact point),
    on a tilted base: the force comes back to rounding, world axes, and the other feet read none."""
    robot = dataclasses.replace(robot, foot_radius=radius)
    model, data = robot.model, robot.model.createData()
    R = pin.rpy.rpyToMatrix(0.1, -0.2, 0.7)
    angles = robot.reference_angles
    qf = robot.configuration(angles, np.r_[0, 0, 0, pin.Quaternion(R).coeffs()])
    pin.computeJointJacobians(model, data, qf)
    pin.updateFramePlacements(model, data)
    g = pin.computeGeneralizedGravity(model, data, qf)[robot.act_v_index]
    c = robot.contact_frames.index("RL_foot")
    J = pin.getFrameJacobian(model, data, robot.contact_frame_ids[c], pin.LOCAL_WORLD_ALIGNED)
    J = J[:3] - pin.skew(np.array([0, 0, -radius])) @ J[3:]
    f = np.array([5.0, -8.0, 60.0])
    tau = g - J[:, robot.act_v_index].T @ f
    _, forces = feet_kinematics(robot, angles[None], tau[None], R[None])
    np.testing.assert_allclose(forces[0, c], f, atol=1e-9)
    np.testing.assert_allclose(np.delete(forces[0], c, axis=0), 0.0, atol=1e-9)


@settings(max_examples=50, deadline=None)
@given(seed=st.integers(0, 2**32 - 1),
       offset=st.lists(st.floats(-1e4, 1e4), min_size=4, max_size=4),
       scale=st.lists(st.floats(0.01, 1e3), min_size=4, max_size=4),
       sign=st.sampled_from([1.0, -1.0]))
def test_counts_offset_and_scale_are_found_in_the_log(seed, offset, scale, sign):
    """Any offset and scale (either sign): the offset is what swing reads, the scales those that make the stance
    feet's forces add up to the weight: both found to rounding."""
    rng = np.random.default_rng(seed)
    n, nc, w = 400, 4, 150.0
    stance = rng.random((n, nc)) < 0.6
    stance[~stance.any(axis=1), 0] = True
    share = rng.random((n, nc)) * stance
    force = w * share / share.sum(axis=1, keepdims=True)
    scale_true = sign * np.array(scale)
    counts = scale_true * force + np.array(offset)
    found_offset, found_scale = calibrate_counts(counts, stance, ~stance, w)
    np.testing.assert_allclose(found_offset, offset, atol=1e-9 * (1 + np.abs(offset).max()))
    np.testing.assert_allclose(found_scale, scale_true, rtol=1e-8)


def test_the_weight_is_the_models(robot):
    assert weight(robot) == pytest.approx(pin.computeTotalMass(robot.model) * 9.81, rel=1e-3)
