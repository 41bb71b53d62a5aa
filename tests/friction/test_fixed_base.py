"""Friction of a fixed-base robot: the thesis's (5.13) with the base welded, ``tau_f = M qdd + h - tau``.

Ground truth: a Panda arm (example-robot-data) moved along known sinusoids; its torques are made
by an independent route, a fixed-base Pinocchio model of the whole URDF (fingers included, held
still), from a known friction. The estimator must give that friction back at every sample.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pyarrow as pa
import pytest

from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.models import coulomb_viscous_stribeck
from wbfriction.friction.options import EstimateOptions
from wbfriction.logs.log import log_from_table
from wbfriction.model import load_robot
from wbfriction.model.loading import example_robot_data_dir

PANDA = "panda_description/urdf/panda.urdf"
JOINTS = tuple(f"panda_joint{i}" for i in range(1, 8))
FINGERS = ("panda_finger_joint1", "panda_finger_joint2")
ARMATURE = np.array([0.3, 0.3, 0.2, 0.2, 0.1, 0.1, 0.05])
K_T = np.array([10.0, 10.0, 8.0, 8.0, 4.0, 4.0, 2.0])  # N·m/A


def config(tmp_path: Path, *, lock: bool = True, currents: bool = False) -> Path:
    text = 'name = "panda"\nfloating_base = false\n[armature]\n'
    text += "".join(f"{j} = {a}\n" for j, a in zip(JOINTS, ARMATURE))
    if lock:
        text += "[locked_joints]\n" + "".join(f"{f} = 0.02\n" for f in FINGERS)
    if currents:
        text += "[torque_constants]\n" + "".join(f"{j} = {k}\n" for j, k in zip(JOINTS, K_T))
    path = tmp_path / f"panda_{lock}_{currents}.toml"
    path.write_text(text)
    return path


def motion(n: int = 1500, dt: float = 1e-3, seed: int = 0):
    """Sinusoids per joint: q, qd, qdd (n, 7) [rad, rad/s, rad/s^2], analytic."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * dt
    amp, freq, phase = rng.uniform(0.2, 0.6, 7), rng.uniform(0.3, 1.2, 7), rng.uniform(0, 2 * np.pi, 7)
    center = np.array([0.0, 0.0, 0.0, -1.5, 0.0, 1.5, 0.0])
    w = 2 * np.pi * freq
    q = center + amp * np.sin(w * t[:, None] + phase)
    qd = amp * w * np.cos(w * t[:, None] + phase)
    qdd = -amp * w**2 * np.sin(w * t[:, None] + phase)
    return t, q, qd, qdd


def friction_truth(qd: np.ndarray) -> np.ndarray:
    """tau_f = -f(qd), model (3.5), different per joint [N·m]."""
    F_v, F_c = np.linspace(0.5, 0.1, 7), np.linspace(2.0, 0.4, 7)
    return -coulomb_viscous_stribeck(qd, F_v, F_c, 0.5, 0.05, 0.0, 50.0)


def torques(q, qd, qdd, tau_f) -> np.ndarray:
    """The joint torques that move the whole Panda (fixed base, fingers still at 0.02 m) along the
    motion against ``tau_f``: ``tau = (M + diag(armature)) qdd + h - tau_f``."""
    full = pin.buildModelFromUrdf(str(example_robot_data_dir() / PANDA))
    data = full.createData()
    tau = np.empty_like(q)
    for k in range(len(q)):
        qq = np.r_[q[k], 0.02, 0.02]
        tau[k] = pin.rnea(full, data, qq, np.r_[qd[k], 0, 0], np.r_[qdd[k], 0, 0])[:7] + ARMATURE * qdd[k]
    return tau - tau_f


@pytest.fixture(scope="module")
def panda_log():
    t, q, qd, qdd = motion()
    tau_f = friction_truth(qd)
    return t, q, qd, qdd, tau_f, torques(q, qd, qdd, tau_f)


def table(t, q, qd, qdd, tau, *, currents: bool = False, fingers: bool = False) -> pa.Table:
    cols = {"time": t}
    cols.update({f"q.{j}": q[:, i] for i, j in enumerate(JOINTS)})
    if currents:
        cols.update({f"current.{j}": tau[:, i] / K_T[i] for i, j in enumerate(JOINTS)})
    else:
        cols.update({f"tau.{j}": tau[:, i] for i, j in enumerate(JOINTS)})
    cols.update({f"qd_true.{j}": qd[:, i] for i, j in enumerate(JOINTS)})
    cols.update({f"qdd_true.{j}": qdd[:, i] for i, j in enumerate(JOINTS)})
    if fingers:
        n = len(t)
        for f in FINGERS:
            cols.update({f"q.{f}": np.full(n, 0.02), f"tau.{f}": np.zeros(n), f"qd_true.{f}": np.zeros(n),
                         f"qdd_true.{f}": np.zeros(n)})
    return pa.table(cols)


def test_every_sample_gives_the_friction_exactly(tmp_path, panda_log):
    t, q, qd, qdd, tau_f, tau = panda_log
    robot = load_robot(urdf=example_robot_data_dir() / PANDA, config=config(tmp_path))
    est = estimate_log(robot, log_from_table(table(t, q, qd, qdd, tau), robot), EstimateOptions(diff="true"))
    assert est.valid.all() and est.unique.all()  # no contact, no phase: every sample unique
    assert np.allclose(est.tau_f, tau_f, rtol=0, atol=1e-9)


def test_differentiated_positions_give_the_friction(tmp_path, panda_log):
    """The same from positions alone (central differences at 1 kHz, no noise): O(dt^2) errors."""
    t, q, qd, qdd, tau_f, tau = panda_log
    robot = load_robot(urdf=example_robot_data_dir() / PANDA, config=config(tmp_path))
    est = estimate_log(robot, log_from_table(table(t, q, qd, qdd, tau), robot),
                       EstimateOptions(diff="central", torque_alignment="sample"))
    inner = est.valid.all(axis=1)
    assert inner.sum() == len(t) - 2
    assert np.abs(est.tau_f[inner] - tau_f[inner]).max() < 1e-3


def test_currents_times_torque_constants_are_torques(tmp_path, panda_log):
    t, q, qd, qdd, tau_f, tau = panda_log
    robot = load_robot(urdf=example_robot_data_dir() / PANDA, config=config(tmp_path, currents=True))
    from_tau = log_from_table(table(t, q, qd, qdd, tau), robot)
    from_current = log_from_table(table(t, q, qd, qdd, tau, currents=True), robot)
    assert from_tau.torque_source == "sensor" and from_current.torque_source == "current"
    assert np.allclose(from_current.tau, tau, rtol=1e-14, atol=0)
    est = estimate_log(robot, from_current, EstimateOptions(diff="true"))
    assert np.allclose(est.tau_f, tau_f, rtol=0, atol=1e-9)


def test_locked_joints_change_nothing_for_the_joints_that_move(tmp_path, panda_log):
    t, q, qd, qdd, tau_f, tau = panda_log
    locked = load_robot(urdf=example_robot_data_dir() / PANDA, config=config(tmp_path))
    free = load_robot(urdf=example_robot_data_dir() / PANDA, config=config(tmp_path, lock=False))
    assert free.actuated == JOINTS + FINGERS
    est_locked = estimate_log(locked, log_from_table(table(t, q, qd, qdd, tau), locked),
                              EstimateOptions(diff="central"))
    est_free = estimate_log(free, log_from_table(table(t, q, qd, qdd, tau, fingers=True), free),
                            EstimateOptions(diff="central"))
    assert np.allclose(est_free.tau_f[:, :7], est_locked.tau_f, rtol=0, atol=1e-9, equal_nan=True)


def test_a_log_without_torque_or_current_names_the_column(tmp_path, panda_log):
    t, q, qd, qdd, tau_f, tau = panda_log
    robot = load_robot(urdf=example_robot_data_dir() / PANDA, config=config(tmp_path))
    tab = table(t, q, qd, qdd, tau).drop_columns(["tau.panda_joint3"])
    with pytest.raises(ValueError, match="missing column 'tau.panda_joint3' \\(or 'current.panda_joint3'"):
        log_from_table(tab, robot)
    tab = table(t, q, qd, qdd, tau, currents=True)
    with pytest.raises(ValueError, match="'current.panda_joint1' needs a torque constant"):
        log_from_table(tab, robot)


class _Truth:
    """The injected friction as a model: ``f(qd)`` of joint ``i``."""

    def __init__(self, i: int) -> None:
        self.i = i

    def f(self, qd):
        full = np.zeros((len(qd), 7))
        full[:, self.i] = qd
        return -friction_truth(full)[:, self.i]


def test_the_true_model_predicts_the_torques(tmp_path, panda_log):
    """Torque prediction (friction.predict): the injected friction predicts the torques exactly,
    the rigid-body model alone misses them by the friction's RMS."""
    from wbfriction.fit.predict import predict_torques

    t, q, qd, qdd, tau_f, tau = panda_log
    robot = load_robot(urdf=example_robot_data_dir() / PANDA, config=config(tmp_path))
    est = estimate_log(robot, log_from_table(table(t, q, qd, qdd, tau), robot), EstimateOptions(diff="true"))
    pred = predict_torques(est, {j: _Truth(i) for i, j in enumerate(JOINTS[:6])}, tau)
    assert np.all(pred.rms[:6] < 1e-9) and np.isnan(pred.rms[6])  # the last joint has no model
    assert np.allclose(pred.rms_rigid_body, np.sqrt(np.mean(tau_f**2, axis=0)), rtol=1e-9)
    assert np.allclose(pred.rms_torque, np.sqrt(np.mean(tau**2, axis=0)), rtol=1e-12)
    assert np.all(pred.samples == len(t))
