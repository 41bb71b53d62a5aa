"""The PD driver's law (model/pd.py): the delayed zero-order-held set-points, the torque, the TOML's ``[pd]``."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.model.pd import PdDriver, delayed, parse_pd, pd_torque

T = 0.005


def held_mean(commanded: np.ndarray, time: np.ndarray, delay: float, start: float, end: float,
              fine: int = 20_000) -> float:
    """The mean over [start, end] of the zero-order-held set-point applied ``delay`` late, by brute force."""
    t = np.linspace(start, end, fine, endpoint=False) + (end - start) / fine / 2
    k = np.searchsorted(time + delay, t, side="right") - 1
    return float(np.mean(commanded[np.clip(k, 0, len(time) - 1)]))


@settings(max_examples=40, deadline=None)
@given(delay_steps=st.floats(0.0, 6.0), seed=st.integers(0, 2**16))
def test_delayed_is_the_held_setpoints_mean_over_each_period(delay_steps, seed):
    time = np.arange(40) * T
    commanded = np.random.default_rng(seed).normal(size=40)
    d = delay_steps * T
    got = delayed(commanded, time, d)
    for i in range(10, 40):
        assert got[i] == pytest.approx(held_mean(commanded, time, d, time[i] - T / 2, time[i] + T / 2), abs=2e-3)


def test_a_step_applied_after_the_delay():
    time = np.arange(20) * T
    q_des = np.where(np.arange(20) >= 5, 1.0, 0.0)[:, None]
    driver = PdDriver(("j",), np.array([10.0]), np.array([0.0]), delay=2 * T)
    tau = pd_torque(driver, time, np.zeros((20, 1)), np.zeros((20, 1)), q_des)[:, 0]
    # commanded at t_5, applied from t_7: sample 7's period [t_7 - T/2, t_7 + T/2] holds it half the time
    np.testing.assert_allclose(tau, 10.0 * np.clip(np.arange(20) - 6.5, 0.0, 1.0))


def test_the_law_its_signs_and_its_limit():
    time = np.arange(4) * T
    driver = PdDriver(("a", "b"), np.array([20.0, 30.0]), np.array([0.5, 1.0]), torque_limit=np.array([np.inf, 5.0]))
    q = np.full((4, 2), 0.1)
    qd = np.full((4, 2), 2.0)
    q_des = np.full((4, 2), 0.3)
    tau_ff = np.full((4, 2), 0.25)
    tau = pd_torque(driver, time, q, qd, q_des, np.full((4, 2), 1.0), tau_ff)
    np.testing.assert_allclose(tau[:, 0], 20.0 * 0.2 + 0.5 * (1.0 - 2.0) + 0.25)
    np.testing.assert_allclose(tau[:, 1], 5.0)  # 30 * 0.2 - 1 + 0.25 = 5.25, clipped
    logged = pd_torque(driver, time, q, qd, q_des, kp=np.full((4, 2), 10.0), kd=np.zeros((4, 2)))
    np.testing.assert_allclose(logged, 2.0)


def test_parse_pd_per_joint_group_and_default_limits():
    actuated = ["a", "b", "c"]
    groups = {"leg": ("a", "b")}
    driver = parse_pd({"kp": {"leg": 20.0, "c": 5.0}, "kd": 0.5, "delay": 0.01}, actuated, groups,
                      np.array([10.0, 0.0, 3.0]), "r.toml")
    assert driver.joints == ("a", "b", "c")
    np.testing.assert_array_equal(driver.kp, [20.0, 20.0, 5.0])
    np.testing.assert_array_equal(driver.torque_limit, [10.0, np.inf, 3.0])
    assert driver.delay == 0.01
    only = parse_pd({"kp": 1.0, "kd": 0.0, "joints": ["c", "a"]}, actuated, groups, np.zeros(3), "r.toml")
    assert only.joints == ("a", "c")


@pytest.mark.parametrize(("table", "message"), [
    ({"kd": 0.5}, "needs 'kp'"),
    ({"kp": {"a": 1.0}, "kd": 0.5}, "no value for 'b'"),
    ({"kp": -1.0, "kd": 0.5}, re.escape("[pd] kp of 'a': -1 N·m/rad is outside [0, 100000] N·m/rad")),
    ({"kp": 1.0, "kd": 0.5, "delay": -0.1}, re.escape("[pd] delay: -0.1 s is outside [0, 0.5] s")),
    ({"kp": 1.0, "kd": 0.5, "delay": 20.0}, re.escape("[pd] delay: 20 s is outside [0, 0.5] s")),
    ({"kp": 1.0, "kd": 0.5, "gain": 2}, "no key 'gain'"),
    ({"kp": {"leg": 1.0, "x": 2.0}, "kd": 0.5}, "'x' is neither"),
    ({"kp": 1.0, "kd": 0.5, "torque_limit": 0.0},
     re.escape("[pd] torque_limit of 'a': 0 N·m is outside (0, 100000] N·m")),
])
def test_parse_pd_refuses_naming_the_file_and_key(table, message):
    with pytest.raises(InputError, match=message) as err:
        parse_pd(table, ["a", "b"], {"leg": ("a", "b")}, np.zeros(2), "robot.toml")
    assert str(err.value).startswith("robot.toml: ")
