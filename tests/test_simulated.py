"""End to end on a log of the constrained forward dynamics with known friction."""

from __future__ import annotations

import numpy as np
import pytest

from wbfriction.estimate import EstimateOptions, estimate_log
from wbfriction.friction import FrictionParams
from wbfriction.identify import fit_estimate
from wbfriction.simulate import FixedFootScenario, simulate_fixed_foot

SWING_LEG = [f"leg_right_{i}_joint" for i in range(1, 7)]


@pytest.fixture(scope="module")
def sim_log(talos):
    return simulate_fixed_foot(talos, FixedFootScenario(duration=3.0, double_support=0.4, seed=3))


def _rms(est, joints):
    idx = [est.joints.index(j) for j in joints]
    err = (est.tau_f - est.tau_f_true)[:, idx]
    return np.sqrt(np.nanmean(np.where(est.valid[:, idx], err, np.nan) ** 2, axis=0))


def test_swing_leg_friction_is_recovered(talos, sim_log):
    est = estimate_log(talos, sim_log)
    rms = _rms(est, SWING_LEG)
    peak = np.nanmax(np.abs(est.tau_f_true[:, [est.joints.index(j) for j in SWING_LEG]]), axis=0)
    assert np.all(rms < 0.02 * peak), (rms, peak)
    # stance leg never valid under the swing mask; every other joint valid in single support
    stance_leg = [est.joints.index(f"leg_left_{i}_joint") for i in range(1, 7)]
    assert not est.valid[:, stance_leg].any()
    assert est.valid[:, est.joints.index("arm_left_4_joint")].sum() > 2000


def test_zoh_torque_alignment_reduces_the_error(talos, sim_log):
    """The simulator holds each torque command for 1 ms: aligning on the mean matters."""
    zoh = _rms(estimate_log(talos, sim_log, EstimateOptions(torque_alignment="zoh")), SWING_LEG)
    sample = _rms(estimate_log(talos, sim_log, EstimateOptions(torque_alignment="sample")), SWING_LEG)
    print("RMS error [N·m] zoh:", np.round(zoh, 4), "sample:", np.round(sample, 4))
    assert np.all(zoh < sample / 3)


def test_backward_differences_are_worse_without_compensation(talos, sim_log):
    central = _rms(estimate_log(talos, sim_log, EstimateOptions(diff="central")), SWING_LEG)
    comp = _rms(estimate_log(talos, sim_log, EstimateOptions(diff="backward")), SWING_LEG)
    raw = _rms(estimate_log(talos, sim_log, EstimateOptions(diff="backward", compensate_delay=False)), SWING_LEG)
    print("RMS central", np.round(central, 4), "backward compensated", np.round(comp, 4), "raw", np.round(raw, 4))
    assert np.all(central <= comp * 1.001) and np.all(comp < raw)


def test_reconstructed_base_equals_logged_base(talos):
    log = simulate_fixed_foot(talos, FixedFootScenario(duration=0.8, double_support=0.2, log_base=True, seed=1))
    with_base = estimate_log(talos, log)
    log.base = None
    without = estimate_log(talos, log)
    m = with_base.unique
    assert np.abs(with_base.tau_f[m] - without.tau_f[m]).max() < 1e-6


def test_fit_recovers_thesis_targets_on_swing_leg(talos, sim_log):
    est = estimate_log(talos, sim_log)
    targets = {j: FrictionParams(**p) for j, p in sim_log.metadata["friction_true"].items()}
    results = {r.joint: r for r in fit_estimate(est.joints, est.qd, est.tau_f, est.valid, targets=targets,
                                                tau_f_true=est.tau_f_true)}
    for j in SWING_LEG:
        r = results[j]
        err = r.error_percent()
        assert err["F_c"] < 5 and err["tau_os"] < 5 and err["F_v"] < 10, (j, err)
        assert r.rms_model_vs_true < 0.02
