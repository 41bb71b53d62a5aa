"""Friction from foot force-torque sensors and a measured base motion (issue 23), on the ideal simulator's
exact data: every joint in every phase with the wrenches, every joint in single support with the base."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np
import pyarrow.parquet as pq
import pytest
from tests.helpers import run_cli

from wbfriction.exceptions import ColumnError
from wbfriction.fit.targets import THESIS_TARGETS
from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.measured import impacts
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.log import write_log
from wbfriction.logs.source import read_log
from wbfriction.sim import IdealOptions, simulate_ideal
from wbfriction.studies.common import SIMULATOR, leg_joints
from wbfriction.walking import GaitOptions, walking_reference

EXACT = 1e-6  # [N·m], the bound; the routes reach about 1e-12


@pytest.fixture(scope="module")
def ft_walk(talos):
    """Two forward steps, Table 6.1 friction on every leg joint, the force-torque sensors and the IMU logged."""
    friction = {j: THESIS_TARGETS[g] for j, _, g in leg_joints(talos)}
    ref = walking_reference(talos, GaitOptions(gait="forward", steps=2))
    options = IdealOptions(substeps=SIMULATOR.substeps, force_torque=True, imu=True)
    return simulate_ideal(talos, ref, friction, options).log


def _errors(est, rows):
    return np.abs(est.tau_f[rows] - est.tau_f_true[rows])


@pytest.mark.parametrize("base_motion", ["contact", "logged", "imu"])
def test_with_wrenches_every_joint_is_exact_in_every_phase(talos, ft_walk, base_motion):
    est = estimate_log(talos, ft_walk, EstimateOptions(diff="true", base_motion=base_motion))
    single, double = est.phase == "single", est.phase == "double"
    assert single.sum() > 1000 and double.sum() > 300
    assert np.all(est.route == "wrench") and np.all(est.unique) and np.all(est.valid)
    for rows in (single, double):
        assert _errors(est, rows).max() < EXACT  # the stance leg and double support included
    stance_leg = talos.limb_mask[0] & (est.contact[:, 0] & single)[:, None]  # left leg while it stands
    assert stance_leg.sum() > 4000 and np.abs(est.tau_f - est.tau_f_true)[stance_leg].max() < EXACT


def test_with_the_base_measured_every_joint_is_exact_in_single_support(talos, ft_walk):
    est = estimate_log(talos, ft_walk, EstimateOptions(diff="true", base_motion="logged", wrenches=False))
    base = est.route == "base"
    assert np.array_equal(base, est.unique & (est.phase == "single")) and base.sum() > 1000
    assert _errors(est, base).max() < EXACT  # every joint's, not only the swing leg's
    assert not est.valid[est.phase == "double"].any()  # twelve unknowns, six equations
    contact = estimate_log(talos, ft_walk, EstimateOptions(diff="true", base_motion="contact", wrenches=False))
    assert np.all(contact.route[contact.unique] == "contact")
    np.testing.assert_allclose(est.tau_f[base], contact.tau_f[base], atol=EXACT)  # two routes agree


def test_auto_takes_the_imu_and_the_wrenches_and_says_so(talos, ft_walk):
    est = estimate_log(talos, ft_walk, EstimateOptions(diff="true"))
    assert est.metadata["base_motion"] == {"base": "imu", "wrenches": True}
    no_imu = estimate_log(talos, dataclasses.replace(ft_walk, imu=None), EstimateOptions(diff="true"))
    assert no_imu.metadata["base_motion"] == {"base": "logged", "wrenches": True}
    bare = dataclasses.replace(ft_walk, imu=None, wrench=None)
    assert estimate_log(talos, bare, EstimateOptions(diff="true")).metadata["base_motion"]["base"] == "contact"


def test_central_differences_with_the_wrenches_beat_the_rigid_route(talos):
    """The ideal walk (one physics step per period: the sensors' instant is the period's) through central
    differences: the wrench route, every joint in every phase but the touch-downs, against the rigid-contact
    route's swing samples (measured: max 6e-3 N·m against 8e-3, RMS 5.7e-4 against 1.8e-3)."""
    friction = {j: THESIS_TARGETS[g] for j, _, g in leg_joints(talos)}
    ref = walking_reference(talos, GaitOptions(gait="forward", steps=2))
    log = simulate_ideal(talos, ref, friction, IdealOptions(force_torque=True)).log
    legs = [talos.torque_controlled.index(j) for j, _, _ in leg_joints(talos)]
    wrench = estimate_log(talos, log, EstimateOptions(diff="central"))
    rigid = estimate_log(talos, log, EstimateOptions(diff="central", base_motion="contact", wrenches=False))
    def rms(est):
        valid = est.valid[:, legs]
        return float(np.sqrt(np.mean((est.tau_f - est.tau_f_true)[:, legs][valid] ** 2)))
    assert wrench.valid[:, legs].mean() > 0.95 > 0.3 > rigid.valid[:, legs].mean()
    assert rms(wrench) < 0.5 * rms(rigid) < 1e-3


def _kinematics(talos, normal: np.ndarray, contact: np.ndarray) -> SimpleNamespace:
    """What :func:`impacts` reads of measured kinematics: 1 kHz rows, the flags, wrenches whose soles' normal
    forces are ``normal`` (N, 2) [N]."""
    model, wrench = talos.model, np.zeros((len(normal), len(talos.ft_sensors), 6))
    for s, sensor in enumerate(talos.ft_sensors):
        contact_frame = model.frames[model.getFrameId(sensor.contact)].placement
        axis = (contact_frame.rotation.T @ sensor.placement.rotation)[2]  # the sole's normal in sensor axes
        wrench[:, s, :3] = normal[:, [talos.contact_frames.index(sensor.contact)]] * axis
    return SimpleNamespace(time=np.arange(len(normal)) * 1e-3, contact=contact, wrench=wrench)


def test_an_impact_starts_at_the_first_touch_and_a_flag_drop_is_none(talos):
    """A sole touching 100 ms before its flag rises: its impact from two rows before the touch to 20 ms after
    it (at least to the flag's rise). A standing sole whose flag drops for one row (a lift-off's force
    chattering about the threshold) rises again without a touch-down: no impact, not the stance before it."""
    n = 1000
    normal, contact = np.full((n, 2), 400.0), np.ones((n, 2), dtype=bool)
    normal[300:500, 1], contact[300:600, 1] = -4.0, False  # right foot: in the air, then a light touch
    normal[500:600, 1] = 20.0
    contact[800, 0] = False  # left foot: its flag drops for one row, the sole loaded
    out = impacts(talos, _kinematics(talos, normal, contact))
    assert np.array_equal(np.flatnonzero(out), np.arange(498, 601))


def test_rows_the_wrench_route_leaves_out_are_not_the_rigid_routes(talos, ft_walk):
    """Central differences leave a touch-down's stencil and impact out of the wrench route; those rows are
    then not valid at all, not estimated by the rigid-contact route, which knows nothing of a sole touching
    the ground before its flag rises. A flag dropping for one row mid-stance (the sole still loaded) costs
    the rows whose stencil spans it, not the stance before it."""
    contact = ft_walk.contact.copy()
    k = int(np.flatnonzero(contact[:, 0] & ~contact[:, 1])[300])  # the left foot standing, the right swinging
    contact[k, 0] = False
    est = estimate_log(talos, dataclasses.replace(ft_walk, contact=contact), EstimateOptions(diff="central"))
    assert np.all(est.route[est.valid.any(axis=1)] == "wrench")
    assert est.valid[k - 200:k - 1].all() and not est.valid[k - 1:k + 2].any()


def test_the_wrenches_make_every_sample_usable(talos, ft_walk):
    """The share of samples giving a valid estimate per joint: swing-only single support before, all after."""
    rigid = EstimateOptions(diff="true", base_motion="contact", wrenches=False)
    before = estimate_log(talos, ft_walk, rigid).valid.mean(axis=0)
    after = estimate_log(talos, ft_walk, EstimateOptions(diff="true")).valid.mean(axis=0)
    legs = talos.limb_mask.any(axis=0)
    assert np.all(before[legs] < 0.3) and np.all(after == 1.0)


def test_wrench_columns_round_trip_and_a_missing_sensor_is_named(talos, ft_walk, tmp_path):
    path = tmp_path / "walk.parquet"
    write_log(ft_walk, talos, path)
    back = read_log(path, talos)
    np.testing.assert_array_equal(back.wrench, ft_walk.wrench)
    np.testing.assert_array_equal(back.base_qdd_true, ft_walk.base_qdd_true)
    table = pq.read_table(path)
    pq.write_table(table.drop(["wrench.right_ankle.fx", "wrench.right_ankle.fy", "wrench.right_ankle.fz",
                               "wrench.right_ankle.tx", "wrench.right_ankle.ty", "wrench.right_ankle.tz"]),
                   tmp_path / "one.parquet")
    with pytest.raises(ColumnError, match="missing column 'wrench.right_ankle.fx'.*sensor 'right_ankle'"):
        read_log(tmp_path / "one.parquet", talos)
    pq.write_table(table.drop(["wrench.left_ankle.tz"]), tmp_path / "partial.parquet")
    with pytest.raises(ColumnError, match="wrench of sensor 'left_ankle' is partial: missing column "
                                          "'wrench.left_ankle.tz'"):
        read_log(tmp_path / "partial.parquet", talos)
    pq.write_table(table.append_column("wrench.hand.fx", table.column("time")), tmp_path / "hand.parquet")
    with pytest.raises(ColumnError, match="'wrench.hand.fx' names an unknown force-torque sensor"):
        read_log(tmp_path / "hand.parquet", talos)


def test_estimate_says_which_base_motion_it_used(talos, ft_walk, tmp_path, capsys):
    write_log(ft_walk, talos, tmp_path / "walk.parquet")
    code, err = run_cli(capsys, "estimate", tmp_path / "walk.parquet", "-o", tmp_path / "f.parquet", "--diff",
                        "true")
    assert code == 0 and "base motion: imu; wrenches: every joint in every phase" in err
    routes = pq.read_table(tmp_path / "f.parquet", columns=["route"]).column("route").to_pylist()
    assert set(routes) == {"wrench"}
    code, err = run_cli(capsys, "estimate", tmp_path / "walk.parquet", "-o", tmp_path / "g.parquet",
                        "--base-motion", "gps")
    assert code == 2 and "'--base-motion'" in err and "'gps'" in err and not (tmp_path / "g.parquet").exists()
