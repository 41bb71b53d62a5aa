"""Any registered friction family through every simulator gives the truth it was given (issue 65, class 7): the toy
family (``toys/toy_family.py``, registered as ``docs/extending.md`` shows) and the built-in ones, one family on every
joint or several side by side, injected with F_c = 2 N·m on each of the six simulators that take a friction model
(the Panda arm, the walking humanoid ideal and on MuJoCo, the walking quadruped ideal and on MuJoCo, the hung
PD-driven Go2). The friction each logs (``tau_f_true``) is the family's own characteristic ``tau_f = -f(qd)`` of the
velocity it logs with it (``qd_true``: every simulator logs the friction of the sample's own physics step), on every
joint: never a zero, never uninitialised memory (a registered family's joints read 0.0, 5e-324, 1e-323 N·m before)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from toys.toy_family import NAME, FixedSlope
from wbfriction.friction.families.names import BUILTIN_NAMES
from wbfriction.friction.families.params import ModelParamsBase
from wbfriction.friction.families.registry import family, register_family, unregister_family
from wbfriction.model.loading import load_robot
from wbfriction.sim.arm import ArmOptions, simulate_arm
from wbfriction.sim.hung import simulate_hung
from wbfriction.sim.ideal import simulate_ideal
from wbfriction.sim.mujoco_model import build_mujoco_robot
from wbfriction.sim.mujoco_sim import simulate_mujoco
from wbfriction.sim.options import IdealOptions, MujocoOptions
from wbfriction.sim.pd_options import HungOptions
from wbfriction.sim.pd_robot import build_pd_robot
from wbfriction.sim.quadruped import QuadrupedOptions, simulate_quadruped
from wbfriction.sim.quadruped_mjcf import build_quadruped_model
from wbfriction.sim.quadruped_mujoco import simulate_quadruped_mujoco
from wbfriction.walking import GaitOptions, walking_reference
from wbfriction.walking.quadruped import GaitOptions as QuadrupedGait
from wbfriction.walking.quadruped import quadruped_reference

F_C = 2.0
"""The Coulomb level injected on every joint [N·m] (the issue's)."""
RANGES = {"F_v": (0.05, 1.0), "F_s": (2.0, 3.0), "S": (0.0, 1.0), "v_s": (0.02, 0.5), "tau_os": (-0.5, 0.5),
          "a": (5.0, 100.0)}
"""Where each other parameter is drawn, by name (a family's parameter of another name: in [0, 1])."""
FAMILIES = (*BUILTIN_NAMES, NAME)
"""The families registered while this module runs: the built-in ones and the toy."""
SAMPLES = 60
"""Samples simulated per run: a humanoid's reference cut to these, a quadruped's trot and the arm's log as long."""

Truth = tuple[np.ndarray, np.ndarray, tuple[str, ...]]
"""What a simulator logged: the true velocities (N, n) [rad/s], the true friction (N, n) [N·m], the joints' names."""


@pytest.fixture(scope="module", autouse=True)
def toy_registered():
    """The toy family registered (one call, as the guide's), forgotten after the module."""
    register_family(FixedSlope())
    yield
    unregister_family(NAME)


def drawn(name: str, delta_s: float, unit: list[float]) -> ModelParamsBase:
    """Parameters of the family ``name`` with F_c = :data:`F_C`, the others over :data:`RANGES` from ``unit`` (one
    number in [0, 1] per parameter), a Stribeck exponent ``delta_s`` where the family has one."""
    cls = family(name).params_class
    values = {n: F_C if n == "F_c" else RANGES.get(n, (0.0, 1.0))[0] + u * np.ptp(RANGES.get(n, (0.0, 1.0)))
              for n, u in zip(cls.names, unit)}
    if "delta_s" in {f.name for f in dataclasses.fields(cls)}:
        values["delta_s"] = delta_s
    return cls(**values)


def logged(table, prefix: str, joints: tuple[str, ...]) -> np.ndarray:
    """The columns ``prefix.<joint>`` of a log's table (N, n)."""
    return np.column_stack([table[f"{prefix}.{j}"].to_numpy() for j in joints])


@pytest.fixture(scope="module")
def simulators() -> dict[str, tuple[tuple[str, ...], Callable[[dict], Truth]]]:
    """Per simulator: the joints it injects friction on, and a run of it with friction per joint (a short one)."""
    panda, talos, walker, go2 = (load_robot(n) for n in ("panda", "talos", "go2_walking", "go2"))
    ref = walking_reference(talos, GaitOptions(gait="forward", steps=1, initial=0.2, final=0.2))
    ref = dataclasses.replace(ref, **{f: getattr(ref, f)[:SAMPLES]
                                      for f in ("time", "q", "v", "a", "contact", "feet", "com", "zmp")})
    trot = quadruped_reference(walker, QuadrupedGait("trot", duration=SAMPLES * 0.002))
    humanoid, quadruped, hung = build_mujoco_robot(talos), build_quadruped_model(walker), build_pd_robot(go2)
    tc = tuple(talos.torque_controlled)
    on_tc = [list(talos.actuated).index(j) for j in tc]

    def arm(friction: dict) -> Truth:
        table = simulate_arm(panda, friction, options=ArmOptions(duration=SAMPLES / 1000)).table
        return logged(table, "qd_true", panda.actuated), logged(table, "tau_f_true", panda.actuated), panda.actuated

    def walk(run) -> Callable[[dict], Truth]:
        return lambda friction: (lambda log: (log.qd_true[:, on_tc], log.tau_f_true, tc))(run(friction).log)

    def trotting(run) -> Callable[[dict], Truth]:
        return lambda friction: (lambda log: (log.qd_true, log.tau_f_true, walker.actuated))(
            run(walker, trot, QuadrupedOptions(friction=friction)).log)

    def hung_go2(friction: dict) -> Truth:
        table = simulate_hung(go2, HungOptions(duration=SAMPLES / 200), friction, mjr=hung).table
        return logged(table, "qd_true", go2.actuated), logged(table, "tau_f_true", go2.actuated), go2.actuated

    return {"arm": (panda.actuated, arm),
            "ideal": (tc, walk(lambda fr: simulate_ideal(talos, ref, fr, IdealOptions()))),
            "mujoco": (tc, walk(lambda fr: simulate_mujoco(talos, ref, fr, MujocoOptions(), mjr=humanoid))),
            "quadruped": (walker.actuated, trotting(simulate_quadruped)),
            "quadruped-mujoco": (walker.actuated, trotting(lambda *a: simulate_quadruped_mujoco(*a, mjr=quadruped))),
            "hung": (go2.actuated, hung_go2)}


@pytest.mark.parametrize("simulator", ["arm", "ideal", "mujoco", "quadruped", "quadruped-mujoco", "hung"])
@settings(max_examples=15, deadline=None)
@example(names=[NAME], unit=[0.5] * 8, delta_s=2.0)  # the issue's: the toy alone, F_c = 2 N·m
@example(names=["thesis", NAME, "stribeck"], unit=[0.3] * 8, delta_s=1.5)  # side by side
@given(names=st.lists(st.sampled_from(FAMILIES), min_size=1, max_size=3),
       unit=st.lists(st.floats(0.0, 1.0), min_size=8, max_size=8), delta_s=st.sampled_from([2.0, 1.5]))
def test_any_registered_family_through_every_simulator_gives_the_truth_it_was_given(simulators, simulator, names,
                                                                                     unit, delta_s):
    """Joint ``i`` has the family ``names[i % len(names)]`` (one family on every joint, or several side by side)."""
    joints, run = simulators[simulator]
    friction = {j: drawn(names[i % len(names)], delta_s, unit) for i, j in enumerate(joints)}
    qd, tau_f, logged_joints = run(friction)
    assert logged_joints == joints and np.isfinite(tau_f).all()
    assert not np.any((tau_f != 0) & (np.abs(tau_f) < np.finfo(float).tiny)), "subnormal friction: memory never set"
    for i, joint in enumerate(joints):
        truth = friction[joint].torque(qd[:, i])  # the family's own characteristic, tau_f = -f(qd)
        np.testing.assert_allclose(tau_f[:, i], truth, rtol=1e-12, atol=1e-12, err_msg=f"{simulator}: {joint}, "
                                   f"{friction[joint].model}")
