"""The Go2 standing on three point feet while its fourth leg follows a designed excitation (issue 66,
:mod:`wbfriction.excite.tripod`): the reference keeps the three stance feet still, its centre of mass and ZMP inside
their triangle and the swing foot off the ground, and, played in the ideal quadruped simulator and in MuJoCo's with
friction injected, the project's estimate (point feet) and fit recover each swing joint's injected F_c and F_v
within 2 %.

The friction injected is not the design's prior (the quadruped simulators' default): F_c 1.25 times and F_v 0.75
times it, on every joint. Both simulators run their physics at 4 kHz (:data:`PHYSICS`), not their default 2 kHz: at
2 kHz their explicit integration of the Coulomb term ``-F_c tanh(40 qd)`` is near its stability bound on the light
calf (``F_c a h / I`` about 3 for the front right calf, the largest F_c injected, 0.75 N·m, I about
0.005 kg·m^2; an explicit step is stable below 2): its velocity chatters through zero (21 sign changes against the
reference's 15, measured; 15 at 4 kHz), which put the front right calf's F_v 4.5 % low (4.2 % on MuJoCo; its hip's
1.6 %), the simulator's integration, not the excitation or the estimator (the other three legs: within 0.6 % at
2 kHz too, ideal). At 4 kHz (measured, the default estimate): worst F_c 0.13 % and F_v 0.62 % over the four legs,
on either simulator (the front right calf's F_v 0.54 % ideal, 0.59 % MuJoCo; the rear left's joints within
0.10 %). MuJoCo's stance feet move by their soft contacts' give (2.5-2.6 mm). The test prints the table of its run.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pinocchio as pin
import pytest

from wbfriction.exceptions import InputError, ModelError
from wbfriction.excite.design import ExciteOptions
from wbfriction.excite.tripod import SWING_BAND, TripodOptions, swing_band, swing_foot, tripod_reference
from wbfriction.fit.joints import fit_estimate
from wbfriction.fit.options import FitOptions
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions
from wbfriction.model import load_robot
from wbfriction.sim.quadruped import QuadrupedOptions, default_quadruped_friction, simulate_quadruped
from wbfriction.walking.quadruped import FOOT_RADIUS

# the design and the IK: about 6 s per leg; the ideal simulator about 4 s, MuJoCo about 8 s; one module fixture
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("excite_tripod")]

LWA = pin.LOCAL_WORLD_ALIGNED
TOLERANCE = 2.0
"""The issue's: each swing joint's F_c and F_v within 2 % [%]."""
PHYSICS = 0.00025
"""Both simulators' physics step [s] (4 kHz under the 500 Hz controller: the module docstring)."""


@pytest.fixture(scope="module")
def go2():
    """The built-in ``go2_walking``: a Go2 on four point feet."""
    return load_robot("go2_walking")


@pytest.fixture(scope="module")
def excitations(go2):
    """The reference with each leg swung, built once (about 6 s each)."""
    cache: dict[str, object] = {}

    def get(leg: str):
        if leg not in cache:
            cache[leg] = tripod_reference(go2, TripodOptions(swing=leg))
        return cache[leg]
    return get


def zmp_margin(robot, q, v, a, triangle) -> float:
    """The least distance [m] of the ZMP on the ground to the triangle's edges (3, 2), the ZMP from the base's rows of
    the inverse dynamics (the wrench the ground must give a robot that no motor holds up: Newton-Euler of the whole
    body), computed here apart from the module's centroidal one."""
    model, data = robot.model, robot.model.createData()
    out = []
    for k in range(0, len(q), 10):
        wrench = pin.rnea(model, data, q[k], v[k], a[k])[:6]  # at the base's origin, in its frame
        R, p = pin.Quaternion(q[k, 3:7]).toRotationMatrix(), q[k, :3]  # the base's placement
        force, moment = R @ wrench[:3], R @ wrench[3:]
        moment = moment + np.cross(p, force)  # about the world's origin
        out.append([-moment[1] / force[2], moment[0] / force[2]])
    return edge_distance(np.array(out), triangle)


def edge_distance(points, triangle) -> float:
    """The least signed distance [m] of the points (N, 2) to the triangle's (3, 2) edges (positive inside): the
    barycentric way (each edge's distance is the point's barycentric weight of the opposite vertex times that
    vertex's height)."""
    a, b, c = triangle
    T = np.column_stack([b - a, c - a])
    lam = np.linalg.solve(T, (points - a).T).T  # weights of b and c
    weights = np.column_stack([1 - lam.sum(axis=1), lam])
    area2 = abs(np.linalg.det(T))
    heights = np.array([area2 / np.linalg.norm(triangle[(i + 1) % 3] - triangle[(i + 2) % 3]) for i in range(3)])
    return float((weights * heights).min())


@pytest.mark.parametrize("leg", ["FR", "RL"])
def test_the_stance_feet_stay_put_and_the_com_and_zmp_inside_them(go2, excitations, leg):
    excitation = excitations(leg)
    options = TripodOptions()
    s = excitation.swing
    assert go2.contact_frames[s] == f"{leg}_foot" and excitation.stance == tuple(c for c in range(4) if c != s)
    ref = excitation.reference
    assert len(ref) == 4000 and ref.dt == 0.002
    assert ref.contact[:, list(excitation.stance)].all() and not ref.contact[:, s].any()  # three feet, throughout
    assert excitation.joints == go2.limb(go2.contact_frames[s])
    q, v, a = ref.full(go2)
    model, data = go2.model, go2.model.createData()
    triangle = excitation.triangle
    coms, swing_z = [], []
    for k in range(0, len(ref), 10):
        pin.forwardKinematics(model, data, q[k], v[k], a[k])
        pin.updateFramePlacements(model, data)
        for i, c in enumerate(excitation.stance):
            f = go2.contact_frame_ids[c]
            np.testing.assert_allclose(data.oMf[f].translation, [*triangle[i], FOOT_RADIUS], atol=1e-9)
            assert np.abs(pin.getFrameVelocity(model, data, f, LWA).linear).max() < 1e-9
            assert np.abs(pin.getFrameClassicalAcceleration(model, data, f, LWA).linear).max() < 1e-7
        swing_z.append(data.oMf[go2.contact_frame_ids[s]].translation[2])
        np.testing.assert_allclose(ref.feet[k, s], data.oMf[go2.contact_frame_ids[s]].translation, atol=1e-12)
        assert data.oMi[1].rotation[2, 2] > 1 - 1e-12  # upright
        coms.append(pin.centerOfMass(model, data, q[k])[:2])
    assert edge_distance(np.array(coms), triangle) > options.com_margin
    assert zmp_margin(go2, q, v, a, triangle) > options.zmp_margin
    assert min(swing_z) - FOOT_RADIUS > options.clearance and excitation.clearance > options.clearance
    assert excitation.spacing > options.spacing
    angles = go2.angles(q)[:, [go2.actuated.index(j) for j in excitation.joints]]
    assert np.all(angles >= excitation.lower - 1e-9) and np.all(angles <= excitation.upper + 1e-9)
    assert np.ptp(angles, axis=0).min() > 0.3  # every swing joint moves
    speed = np.abs(v[:, go2.act_v_index[[go2.actuated.index(j) for j in excitation.joints]]])
    assert speed.max() <= options.velocity and speed.max(axis=0).min() > 1.0
    assert np.abs(v[0]).max() < 1e-12 and np.abs(v[-1]).max() < 1e-3  # at rest at both ends (the last sample: T - dt)


def test_the_swing_leg_is_named_and_the_options_checked(go2):
    assert [swing_foot(go2, x) for x in ("FL", "FR_foot", 2, "RR")] == [0, 1, 2, 3]
    for bad in ("XX", 4, True):
        with pytest.raises(InputError, match="--swing"):
            swing_foot(go2, bad) if not isinstance(bad, bool) else TripodOptions(swing=bad)
    lo_r, hi_r = swing_band(go2, go2.limb("FR_foot"), False, 0.05)
    lo_l, hi_l = swing_band(go2, go2.limb("FL_foot"), True, 0.05)
    np.testing.assert_allclose([lo_l[0], hi_l[0]], [-hi_r[0], -lo_r[0]])  # the hip mirrored
    np.testing.assert_allclose([lo_l[1:], hi_l[1:]], [lo_r[1:], hi_r[1:]])
    assert (lo_r, hi_r)[0][2] == SWING_BAND["calf"][0]
    with pytest.raises(InputError, match="--velocity"):
        TripodOptions(velocity=0.0)
    with pytest.raises(ModelError, match="--com-margin"):  # the Go2's triangles' inradius is about 0.10 m
        tripod_reference(go2, TripodOptions(com_margin=0.2))
    short = ExciteOptions(duration=1.0, rate=500.0, period=1.0, harmonics=2, starts=1, range_share=1.0)
    with pytest.raises(ModelError, match="ZMP .* lower --velocity"):
        tripod_reference(go2, TripodOptions(design=short, zmp_margin=0.2))


@pytest.mark.parametrize("leg, simulator", [("FR", "ideal"), ("FR", "mujoco"), ("RL", "ideal"), ("RL", "mujoco")])
def test_each_swing_joint_friction_recovered_within_two_percent(go2, excitations, leg, simulator):
    excitation = excitations(leg)
    s = excitation.swing
    truth = {j: dataclasses.replace(p, F_c=1.25 * p.F_c, F_v=0.75 * p.F_v)
             for j, p in default_quadruped_friction(go2).items()}
    options = QuadrupedOptions(friction=truth, physics_dt=PHYSICS)
    start = time.perf_counter()
    robot = go2
    if simulator == "ideal":
        run = simulate_quadruped(go2, excitation.reference, options)
    else:
        from wbfriction.sim.quadruped_mujoco import simulate_quadruped_mujoco
        from wbfriction.studies.quadruped import QuadrupedCase, case_robot

        run = simulate_quadruped_mujoco(go2, excitation.reference, options)
        robot = case_robot(go2, QuadrupedCase(simulator="mujoco"))  # its feet spheres: the force at their bottom
    simulated = time.perf_counter() - start
    log = run.log
    assert (log.contact == excitation.reference.contact).mean() > 0.999  # measured on MuJoCo: three feet
    model, data = go2.model, go2.model.createData()
    moved = 0.0
    for k in range(0, len(log), 20):
        pin.framesForwardKinematics(model, data, run.q[k])
        for i, c in enumerate(excitation.stance):
            foot = data.oMf[go2.contact_frame_ids[c]].translation
            moved = max(moved, float(np.linalg.norm(foot - [*excitation.triangle[i], FOOT_RADIUS])))
    assert moved < 5e-3  # it stood: no slip, no tipping
    assert run.force[1:, list(excitation.stance), 2].min() > 0  # every stance foot pushes (MuJoCo: from its second)
    est = estimate_log(robot, log, EstimateOptions())
    fits = {f.joint: f for f in fit_estimate(est, FitOptions(model="thesis"), joints=excitation.joints,
                                             fixed={"S": 0.0, "v_s": 0.1})}
    print(f"\n{leg} swung, {simulator}: simulated {len(log)} samples in {simulated:.1f} s, estimated and fitted in "
          f"{time.perf_counter() - start - simulated:.1f} s, the stance feet moved {moved * 1e3:.2f} mm")
    errors = {}
    for joint in excitation.joints:
        fit = fits[joint]
        assert fit.params is not None, joint
        # three feet: every sample is estimated, and fitted but where the joint may stick (the fit's rule near zero
        # speed, :func:`~wbfriction.fit.solve.stuck_rows`: 0.7-2.6 % of the samples, as the design's series dwell
        # near a reversal; which design the optimiser finds moves with the processor's and BLAS's rounding)
        valid = int(est.valid[:, est.joints.index(joint)].sum())
        assert valid > 0.99 * len(log) and fit.n_screened == 0, joint
        assert fit.n_samples + fit.n_stuck == valid and fit.n_stuck < 0.05 * len(log), (joint, fit.n_stuck)
        for name in ("F_c", "F_v"):
            want, got = getattr(truth[joint], name), getattr(fit.params, name)
            errors[joint, name] = 100 * abs(got / want - 1)
            status = "ok" if errors[joint, name] < TOLERANCE else "FAIL"
            print(f"  {joint:15s} {name}: truth {want:.4f}, fitted {got:.5f}, {errors[joint, name]:.2f} % {status}")
    assert max(errors.values()) < TOLERANCE, errors
    assert s == swing_foot(go2, leg)
