"""TALOS standing on one foot while its other leg follows a designed excitation (issue 66,
:mod:`wbfriction.excite.one_foot`): the reference keeps the stance sole still and its ZMP inside the sole, and, played
in the ideal simulator and in MuJoCo with friction injected on the swing leg, the project's estimate and fit recover
each swing joint's injected F_c and F_v within 2 %.

The friction injected is not the design's prior (the thesis's Table 6.1): F_c 1.25 times and F_v 0.75 times it, so
that the prior is not the answer. The ideal simulator runs its physics at 40 kHz (:data:`IDEAL`), not the studies'
10 kHz (:data:`~wbfriction.studies.common.SIMULATOR`): at 10 kHz semi-implicit Euler's O(h) bias between the logged
state and the position differences the estimator reads left the swing hip pitch's F_v 2.1 % off on the earlier
band (left stance; 3.6 % on a right stance), and the estimate's error and the worst F_v error halve each time the
physics rate doubles
(measured on the earlier band, left stance: worst F_v 2.07 % at 10 kHz, 1.04 % at 20 kHz, 0.52 % at 40 kHz; the hip
pitch's estimate off by 1.8e-3, 8.9e-4, 4.5e-4 N·m RMS where it turns faster than 0.5 rad/s; F_c at most 0.2 %
throughout): the simulator's integration, not the excitation or the estimator. On the band of ``SWING_BAND``, left
stance at 40 kHz: worst F_v 0.49 %; MuJoCo (its default options): worst F_c 0.05 % and F_v 0.42 % (left stance),
0.07 % and 0.54 % (right); the stance sole moved 1.3-1.9 mm. The test prints the table of its run.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pinocchio as pin
import pytest

from wbfriction.exceptions import InputError, ModelError
from wbfriction.excite import one_foot as one_foot_module
from wbfriction.excite.one_foot import OneFootOptions, band_clearance, one_foot_reference, support_margin, swing_band
from wbfriction.fit.joints import fit_joints
from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions
from wbfriction.sim.ideal import simulate_ideal
from wbfriction.sim.mujoco_sim import simulate_mujoco
from wbfriction.sim.options import MujocoOptions
from wbfriction.studies.common import SIMULATOR

# the design and the IK: about 15 s; the ideal simulator 10-15 s, MuJoCo 1-2 s; one module fixture, one worker
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("excite_one_foot")]

TOLERANCE = 2.0
"""The issue's: each swing joint's F_c and F_v within 2 % [%]."""
IDEAL = dataclasses.replace(SIMULATOR, substeps=40)
"""The ideal simulator with its physics at 40 kHz under the 1 kHz controller (module docstring)."""


@pytest.fixture(scope="module")
def excitations(talos):
    """The reference standing on each foot, built once (about 5-13 s each)."""
    cache: dict[str, object] = {}

    def get(stance: str):
        if stance not in cache:
            cache[stance] = one_foot_reference(talos, OneFootOptions(stance=stance))
        return cache[stance]
    return get


def truth(talos, joints) -> dict:
    """The friction injected on the swing leg: Table 6.1's, F_c x 1.25 and F_v x 0.75."""
    out = {}
    for j in joints:
        p = THESIS_TARGETS[talos.group_of(j)]
        out[j] = dataclasses.replace(p, F_c=1.25 * p.F_c, F_v=0.75 * p.F_v)
    return out


def sole_moved(talos, stance: int, q0: np.ndarray, q: np.ndarray) -> float:
    """The largest displacement [m] of the stance sole over the motion ``q`` (N, nq) (every 20th sample), from
    its placement at ``q0``, its rotation counted at 0.1 m per rad (a corner of the sole)."""
    model, data = talos.model, talos.model.createData()
    fid = talos.contact_frame_ids[stance]
    pin.framesForwardKinematics(model, data, q0)
    first = data.oMf[fid].copy()
    worst = 0.0
    for k in range(0, len(q), 20):
        pin.framesForwardKinematics(model, data, q[k])
        error = pin.log6(first.actInv(data.oMf[fid])).vector
        worst = max(worst, float(np.linalg.norm(error[:3]) + 0.1 * np.linalg.norm(error[3:])))
    return worst


@pytest.mark.parametrize("stance", ["left", "right"])
def test_the_stance_sole_stays_put_and_the_zmp_inside_it(talos, excitations, stance):
    excitation = excitations(stance)
    c = excitation.stance
    assert c == ("left", "right").index(stance)
    ref = excitation.reference
    assert ref.contact[:, c].all() and not ref.contact[:, 1 - c].any()  # single support, throughout
    assert all(j in talos.limb(talos.contact_frames[1 - c]) for j in excitation.joints)
    model, data = talos.model, talos.model.createData()
    fid = talos.contact_frame_ids[c]
    pin.framesForwardKinematics(model, data, ref.q[0])
    first = data.oMf[fid].copy()
    drift = 0.0
    for k in range(0, len(ref), 50):
        pin.forwardKinematics(model, data, ref.q[k], ref.v[k], ref.a[k])
        pin.updateFramePlacements(model, data)
        drift = max(drift, np.linalg.norm(pin.log6(first.actInv(data.oMf[fid])).vector))
        still = pin.getFrameClassicalAcceleration(model, data, fid, pin.LOCAL_WORLD_ALIGNED).vector
        assert np.abs(pin.getFrameVelocity(model, data, fid, pin.LOCAL_WORLD_ALIGNED).vector).max() < 1e-9
        assert np.abs(still).max() < 1e-7
    assert drift < 1e-9 and abs(first.translation[2]) < 1e-9 and first.rotation[2, 2] > 1 - 1e-12
    assert support_margin(talos, c, ref.zmp) > 0.01 and excitation.zmp_margin > 0.01
    assert excitation.clearance > 0.02
    angles = talos.angles(ref.q)[:, [talos.actuated.index(j) for j in excitation.joints]]
    assert np.all(angles >= excitation.lower - 1e-9) and np.all(angles <= excitation.upper + 1e-9)
    assert np.ptp(angles, axis=0).min() > 0.1  # every swing joint moves
    speed = np.abs(ref.v[:, talos.act_v_index[[talos.actuated.index(j) for j in excitation.joints]]])
    assert speed.max() <= OneFootOptions().velocity


def test_the_band_is_mirrored_and_checked(talos):
    right = tuple(f"leg_right_{i}_joint" for i in range(1, 7))
    left = tuple(f"leg_left_{i}_joint" for i in range(1, 7))
    lo_r, hi_r = swing_band(talos, right, "right", 0.05)
    lo_l, hi_l = swing_band(talos, left, "left", 0.05)
    mirrored = np.array([0, 1, 5])  # hip yaw, hip roll, ankle roll
    np.testing.assert_allclose(lo_l[mirrored], -hi_r[mirrored])
    np.testing.assert_allclose(lo_l[2:5], lo_r[2:5])
    with pytest.raises(InputError, match="band"):
        swing_band(talos, ("arm_left_1_joint",), "left", 0.05)
    with pytest.raises(InputError, match="stance"):
        OneFootOptions(stance="both")


@pytest.mark.parametrize("stance", ["left", "right"])
def test_every_posture_of_the_band_keeps_the_swing_sole_clear(talos, stance):
    """The band's 64 corners, each with the base and stance leg solved: the swing sole stays above the clearance
    and beside the stance sole whatever the design's series combine (not only on the design one processor's rounding
    finds)."""
    c = ("left", "right").index(stance)
    joints = talos.limb(talos.contact_frames[1 - c])
    lower, upper = swing_band(talos, joints, ("left", "right")[1 - c], OneFootOptions().margin)
    low, beside = band_clearance(talos, c, joints, lower, upper)
    assert low > OneFootOptions().clearance and beside > 0.01


def test_a_band_that_lets_the_sole_cross_is_refused_before_the_design(talos, monkeypatch):
    """The earlier band (hip yaw -0.15..0.05, hip roll -0.4..-0.2, ankle roll -0.15..0.15) lets a corner come 44 mm
    across the stance sole (its corners solved one by one, right stance): refused in one line before the design."""
    monkeypatch.setitem(one_foot_module.SWING_BAND, "hip_yaw", (-0.15, 0.05))
    monkeypatch.setitem(one_foot_module.SWING_BAND, "hip_roll", (-0.4, -0.2))
    monkeypatch.setitem(one_foot_module.SWING_BAND, "ankle_roll", (-0.15, 0.15))

    def not_reached(*args, **kwargs):
        raise AssertionError("designed a band that is not admissible")
    monkeypatch.setattr(one_foot_module, "design_swing", not_reached)
    with pytest.raises(ModelError, match="posture band lets the swing sole come .* -4[0-9].[0-9] mm beside"):
        one_foot_reference(talos, OneFootOptions(stance="right"))


@pytest.mark.parametrize("stance, simulator", [("left", "ideal"), ("left", "mujoco"), ("right", "mujoco")])
def test_each_swing_joint_friction_recovered_within_two_percent(talos, excitations, stance, simulator):
    excitation = excitations(stance)
    c = excitation.stance
    friction = truth(talos, excitation.joints)
    start = time.perf_counter()
    if simulator == "ideal":
        sim = simulate_ideal(talos, excitation.reference, friction, IDEAL)
    else:
        sim = simulate_mujoco(talos, excitation.reference, friction, MujocoOptions())
    simulated = time.perf_counter() - start
    log = sim.log
    assert log.contact[:, c].all() and not log.contact[:, 1 - c].any()  # measured on MuJoCo: never a second foot
    moved = sole_moved(talos, c, excitation.reference.q[0], sim.q)
    assert moved < 5e-3  # it stood: no slip, no tipping (measured on MuJoCo: 0.9 mm left, 1.3 mm right)
    est = estimate_log(talos, log, EstimateOptions())
    idx = [est.joints.index(j) for j in excitation.joints]
    assert est.unique.mean() > 0.95  # single support: every sample but the ends
    fits = fit_joints(list(excitation.joints), est.qd[:, idx], est.tau_f[:, idx], est.valid[:, idx],
                      smoother=est.smoother)
    print(f"\n{stance} foot, {simulator}: simulated {len(log.time)} samples in {simulated:.1f} s, estimated and "
          f"fitted in {time.perf_counter() - start - simulated:.1f} s, the stance sole moved {moved * 1e3:.2f} mm")
    errors = {}
    for fit in fits:
        assert fit.params is not None, fit.joint
        for name in ("F_c", "F_v"):
            want, got = getattr(friction[fit.joint], name), getattr(fit.params, name)
            errors[fit.joint, name] = 100 * abs(got / want - 1)
            status = "ok" if errors[fit.joint, name] < TOLERANCE else "FAIL"
            print(f"  {fit.joint:18s} {name}: truth {want:.4f}, fitted {got:.5f}, "
                  f"{errors[fit.joint, name]:.2f} % {status}")
    assert max(errors.values()) < TOLERANCE, errors
