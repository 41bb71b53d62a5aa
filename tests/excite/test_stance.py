"""TALOS standing on its left foot while its right leg follows a designed excitation (issue 66,
:mod:`wbfriction.excite.stance`): the reference keeps the stance sole still and its ZMP inside the sole, and, played
in the ideal simulator and in MuJoCo with friction injected on the swing leg, the project's estimate and fit recover
each swing joint's injected F_c and F_v within 2 %.

The friction injected is not the design's prior (the thesis's Table 6.1): F_c 1.25 times and F_v 0.75 times it, so
that the prior is not the answer. The ideal simulator runs its physics at 40 kHz (:data:`IDEAL`), not the studies'
10 kHz (:data:`~wbfriction.studies.common.SIMULATOR`): at 10 kHz semi-implicit Euler's O(h) bias between the logged
state and the position differences the estimator reads leaves the hip pitch's F_v 2.1 % off (its estimate's error
correlates with the velocity where the swing leg is fast: 1.8e-3 N·m RMS above 0.5 rad/s, 1.9e-4 at 100 kHz), and
the worst F_v error halves each time the physics rate doubles (measured, default options: 2.12 % at 10 substeps,
1.07 % at 20, 0.54 % at 40, 0.22 % at 100; F_c at most 0.2 % throughout): the simulator's integration, not the
excitation or the estimator. MuJoCo (its default options): worst F_c 0.04 %, F_v 0.28 %. The test prints the table
of its run.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pinocchio as pin
import pytest

from wbfriction.exceptions import InputError
from wbfriction.excite.stance import StanceOptions, stance_reference, support_margin, swing_band
from wbfriction.fit.joints import fit_joints
from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.options import EstimateOptions
from wbfriction.sim.ideal import simulate_ideal
from wbfriction.sim.mujoco_sim import simulate_mujoco
from wbfriction.sim.options import MujocoOptions
from wbfriction.studies.common import SIMULATOR

pytestmark = pytest.mark.slow  # the design and the IK: about 15 s; the ideal simulator 10-15 s, MuJoCo 1-2 s

TOLERANCE = 2.0
"""The issue's: each swing joint's F_c and F_v within 2 % [%]."""
IDEAL = dataclasses.replace(SIMULATOR, substeps=40)
"""The ideal simulator with its physics at 40 kHz under the 1 kHz controller (module docstring)."""


@pytest.fixture(scope="module")
def excitation(talos):
    return stance_reference(talos, StanceOptions())


def truth(talos, joints) -> dict:
    """The friction injected on the swing leg: Table 6.1's, F_c x 1.25 and F_v x 0.75."""
    out = {}
    for j in joints:
        p = THESIS_TARGETS[talos.group_of(j)]
        out[j] = dataclasses.replace(p, F_c=1.25 * p.F_c, F_v=0.75 * p.F_v)
    return out


def test_the_stance_sole_stays_put_and_the_zmp_inside_it(talos, excitation):
    ref = excitation.reference
    assert ref.contact[:, 0].all() and not ref.contact[:, 1].any()  # single support on the left, throughout
    model, data = talos.model, talos.model.createData()
    fid = talos.contact_frame_ids[0]
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
    assert support_margin(talos, 0, ref.zmp) > 0.01 and excitation.zmp_margin > 0.01
    assert excitation.clearance > 0.02
    angles = talos.angles(ref.q)[:, [talos.actuated.index(j) for j in excitation.joints]]
    assert np.all(angles >= excitation.lower - 1e-9) and np.all(angles <= excitation.upper + 1e-9)
    assert np.ptp(angles, axis=0).min() > 0.1  # every swing joint moves
    speed = np.abs(ref.v[:, talos.act_v_index[[talos.actuated.index(j) for j in excitation.joints]]])
    assert speed.max() <= StanceOptions().velocity


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
        StanceOptions(stance="both")


@pytest.mark.parametrize("simulator", ["ideal", "mujoco"])
def test_each_swing_joint_friction_recovered_within_two_percent(talos, excitation, simulator):
    friction = truth(talos, excitation.joints)
    start = time.perf_counter()
    if simulator == "ideal":
        sim = simulate_ideal(talos, excitation.reference, friction, IDEAL)
    else:
        sim = simulate_mujoco(talos, excitation.reference, friction, MujocoOptions())
    simulated = time.perf_counter() - start
    log = sim.log
    assert log.contact[:, 0].all() and not log.contact[:, 1].any()  # measured on MuJoCo: never a second foot
    est = estimate_log(talos, log, EstimateOptions())
    idx = [est.joints.index(j) for j in excitation.joints]
    assert est.unique.mean() > 0.95  # single support: every sample but the ends
    fits = fit_joints(list(excitation.joints), est.qd[:, idx], est.tau_f[:, idx], est.valid[:, idx],
                      smoother=est.smoother)
    print(f"\n{simulator}: simulated {len(log.time)} samples in {simulated:.1f} s, estimated and fitted in "
          f"{time.perf_counter() - start - simulated:.1f} s")
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
