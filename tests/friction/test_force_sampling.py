"""Which period a logged foot force stands for (wbfriction.friction.force_sampling, issue 63): on constructed
impulses whose friction is a function of the velocity and whose force's integral is known in closed form, each
reading is recognised; on the ideal simulator's crawl with 3-D foot forces, the log as written fits the convention
and one shifted a step is named in one line."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from wbfriction.friction.estimate import estimate_log
from wbfriction.friction.force_sampling import READINGS, check_force_sampling, force_integrals
from wbfriction.friction.options import EstimateOptions
from wbfriction.model import load_robot
from wbfriction.pipeline.estimate_step import force_sampling_warnings
from wbfriction.signals.window import MomentumWindow
from wbfriction.sim.quadruped import QuadrupedOptions, simulate_quadruped
from wbfriction.walking.quadruped import GaitOptions, quadruped_reference

DT = 0.002
OMEGA = 2 * np.pi * np.array([1.3, 3.1])
AMP = np.array([20.0, 6.0])  # [N·m]: a stance leg's J^T f, tens of times its friction


def _e_integral(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The closed form of ``int_a^b e dt``, ``e = sum AMP sin(OMEGA t)``."""
    return np.sum(AMP / OMEGA * (np.cos(OMEGA * a[:, None]) - np.cos(OMEGA * b[:, None])), axis=1)


@pytest.mark.parametrize("logged", READINGS)
def test_each_reading_recognised(logged):
    """The force logged as the mean over [t_k, t_k+1), at the instants, or as the mean over [t_k-1, t_k): the reading
    that matches it leaves the least residual, and a warning names it whenever the route used another."""
    n = 3000
    t = np.arange(n) * DT
    qd = (0.8 * np.sin(2 * np.pi * 0.9 * t) + 0.3 * np.sin(2 * np.pi * 2.3 * t + 1.0))[:, None]
    tau_f = -(0.3 * np.tanh(qd / 0.02) + 0.15 * qd)
    impulses = 0.5 * (tau_f[1:] + tau_f[:-1]) * DT + _e_integral(t[:-1], t[1:])[:, None]  # int (tau_f + e)
    e = {"held": _e_integral(t, t + DT) / DT, "instants": np.sum(AMP * np.sin(OMEGA * t[:, None]), axis=1),
         "held before": _e_integral(t - DT, t) / DT}[logged][:, None]
    window = MomentumWindow(10, DT)
    rows = np.ones((n, 1), dtype=bool)
    for used in ("held", "instants"):
        found = check_force_sampling(impulses, e, qd, rows, window, used)
        assert found.joints == 1 and found.best == logged, found
        assert bool(found.warning("x.parquet")) == (logged != used)
    if logged == "held before":
        assert "held over [t_k-1, t_k)" in check_force_sampling(impulses, e, qd, rows, window, "held").warning("x")


def test_force_integrals_of_a_line():
    """``e`` linear in time: the trapezoid is exact, the held readings are off by half a step's change either way."""
    e = np.arange(5.0)[:, None]
    dt = np.full(4, 0.5)
    np.testing.assert_allclose(force_integrals(e, dt, "instants")[:, 0], (np.arange(4) + 0.5) * 0.5)
    np.testing.assert_allclose(force_integrals(e, dt, "held")[:, 0], np.arange(4) * 0.5)
    np.testing.assert_allclose(force_integrals(e, dt, "held before")[:, 0], (np.arange(4) + 1) * 0.5)


@pytest.fixture(scope="module")
def crawl():
    robot = load_robot("go2_walking")
    reference = quadruped_reference(robot, GaitOptions(gait="walk", duration=3.0))
    return robot, simulate_quadruped(robot, reference, QuadrupedOptions(foot_forces="3d")).log


def test_the_crawl_as_logged_and_shifted(crawl):
    """The ideal simulator's foot forces are those of each period's first physics step, its torques held (zoh): the
    momentum route's reading (held over [t_k, t_k+1)) fits best and nothing is said; the same forces one row late
    (a logger writing the mean over the period before the stamp) are named, through the command's warnings."""
    robot, log = crawl
    options = EstimateOptions(diff="true", base_motion="logged", route="momentum", check_route=False)
    found = estimate_log(robot, log, options).metadata["foot_force_sampling"]
    assert found["used"] == found["best"] == "held" and not found["warning"] and found["joints"] == 12
    late = log.foot_force.copy()
    late[1:] = late[:-1]
    found = estimate_log(robot, replace(log, foot_force=late), options).metadata["foot_force_sampling"]
    assert found["best"] == "held before" and found["rss"]["held"] > 2 * found["rss"]["held before"]
    (line,) = force_sampling_warnings({"route_check": {"foot_force_sampling": found}})
    assert "held over [t_k-1, t_k)" in line and "one row earlier" in line
