from __future__ import annotations

import dataclasses
import os

# One BLAS/OpenMP thread per test process (set before NumPy loads; the pages' commands inherit it): the suite runs
# two xdist workers on two cores, and OpenBLAS's spinning threads on the project's small dense problems cost CPU
# time and give none back (tests/inertia, 120 tests on a loaded 2-core machine: 128 s of user time on two threads
# per process, 88 s on one). An exported value wins: `OPENBLAS_NUM_THREADS=2 python -m pytest` runs them on two.
for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import settings

from helpers import run_cli_printed
from wbfriction.model.loading import load_robot
from wbfriction.model.robot import Robot
from wbfriction.signals.kinematics import MeasuredKinematics

# The property tests draw the same examples on every run (a seed from each test's own code, no example database):
# the suite's verdict is reproducible, and a red CI is a defect, not a draw. `HYPOTHESIS_PROFILE=explore` draws new
# examples each run (and replays the failures it saved) to look for defects; pin what it finds with `@example`.
settings.register_profile("repeatable", derandomize=True, database=None)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The slow tests first (their order kept): on two workers the longest start early, and the run does not end
    on one worker running a long test while the other idles (longest-first scheduling)."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)


@pytest.fixture(scope="module")
def go2() -> Robot:
    """The built-in ``go2``: hung, PD-driven (the hung simulator's and the replays' tests; a module of its own may
    name another robot so)."""
    return load_robot("go2")


@pytest.fixture(scope="module")
def mjr(go2):
    """Its MuJoCo model (:func:`~wbfriction.sim.pd_robot.build_pd_robot`), built once a module."""
    from wbfriction.sim.pd_robot import build_pd_robot

    return build_pd_robot(go2)


@pytest.fixture(scope="session")
def talos() -> Robot:
    return load_robot("talos")


@pytest.fixture(scope="session")
def toro() -> Robot:
    return load_robot("toro")


@pytest.fixture(scope="session")
def talos_tilted_sole(talos) -> Robot:
    """TALOS with its right contact frame's axes turned against its joint's (same point), as
    in URDFs whose sole frames follow another axis convention; the soles stay flat."""
    model = pin.Model(talos.model)
    fid = model.getFrameId(talos.contact_frames[1])
    fr = model.frames[fid]
    turn = pin.SE3(pin.rpy.rpyToMatrix(np.pi / 2, 0.3, -np.pi / 2), np.zeros(3))
    model.addFrame(pin.Frame("tilted_sole", fr.parentJoint, fid, fr.placement * turn, pin.FrameType.OP_FRAME))
    return dataclasses.replace(talos, model=model, contact_frames=(talos.contact_frames[0], "tilted_sole"), cache={})


def random_state(robot: Robot, rng: np.random.Generator, active: list[int], base_random: bool):
    """A random configuration (within limits), base pose and a velocity with J v = 0."""
    model = robot.model
    data = model.createData()
    angles = rng.uniform(*robot.angle_limits)
    q = robot.configuration(angles)
    if base_random:
        q[:7] = pin.SE3ToXYZQUAT(pin.SE3(pin.Quaternion(rng.standard_normal(4)).normalized().matrix(),
                                         rng.standard_normal(3)))
    else:  # stance contact frame flat at the origin, as the estimator reconstructs it
        pin.framesForwardKinematics(model, data, q)
        q[:7] = pin.SE3ToXYZQUAT(data.oMf[robot.contact_frame_ids[active[0]]].inverse())
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    J = np.vstack([pin.getFrameJacobian(model, data, robot.contact_frame_ids[c], pin.LOCAL) for c in active])
    v = rng.standard_normal(model.nv)
    v -= np.linalg.pinv(J) @ (J @ v)  # project onto the constraint J v = 0
    return q, v


def constrained_forward(robot: Robot, q, v, tau_full, active: list[int], with_wrench: bool = False):
    """Ground truth: Pinocchio's proximal constrained dynamics with welded contacts; the
    acceleration (nv,), and with ``with_wrench`` also the contact wrenches (6 n_active,) in
    the contact frames (LOCAL)."""
    model = robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    models = []
    for c in active:
        fid = robot.contact_frame_ids[c]
        fr = model.frames[fid]
        models.append(pin.RigidConstraintModel(pin.ContactType.CONTACT_6D, model, fr.parentJoint, fr.placement,
                                               0, data.oMf[fid], pin.LOCAL))
    datas = [m.createData() for m in models]
    pin.initConstraintDynamics(model, data, models, datas)
    settings = pin.ProximalSettings(1e-14, 1e-12, 200)
    a = pin.constraintDynamics(model, data, q, v, tau_full, models, datas, settings).copy()
    return (a, data.lambda_c.copy()) if with_wrench else a


def truth_samples(robot: Robot, n: int, support: str, seed: int, friction_joints: list[str],
                  base_random: bool = False):
    """Random samples with friction injected through the constrained forward dynamics.

    Returns (kin, tau_f_true) where kin.qdd is the true joint acceleration.
    """
    rng = np.random.default_rng(seed)
    model = robot.model
    n_tc = len(robot.torque_controlled)
    inject = np.array([j in friction_joints for j in robot.torque_controlled])
    rows = dict(q=[], qd=[], qdd=[], tau=[], contact=[], base=[], tau_f=[])
    for _ in range(n):
        if support == "single":
            active = [int(rng.integers(len(robot.contact_frames)))]
        else:
            active = list(range(len(robot.contact_frames)))
        q, v = random_state(robot, rng, active, base_random)
        tau_tc = rng.normal(0.0, 20.0, n_tc)
        tau_f = np.where(inject, rng.normal(0.0, 2.0, n_tc), 0.0)
        tau_full = np.zeros(model.nv)
        tau_full[robot.act_v_index[robot.tc_index]] = tau_tc + tau_f
        tau_full[robot.act_v_index[robot.pc_index]] = rng.normal(0.0, 2.0, len(robot.pc_index))
        a = constrained_forward(robot, q, v, tau_full, active)
        contact = np.zeros(len(robot.contact_frames), dtype=bool)
        contact[active] = True
        angles = robot.angles(q)
        rows["q"].append(angles)
        rows["qd"].append(v[robot.act_v_index])
        rows["qdd"].append(a[robot.act_v_index])
        rows["tau"].append(tau_tc)
        rows["contact"].append(contact)
        rows["base"].append(q[:7])
        rows["tau_f"].append(tau_f)
    arr = {k: np.array(v) for k, v in rows.items()}
    kin = MeasuredKinematics(time=np.arange(n) * 1e-3, q=arr["q"], qd=arr["qd"], qdd=arr["qdd"], tau=arr["tau"],
                             contact=arr["contact"], base=arr["base"] if base_random else None)
    return kin, arr["tau_f"]


@pytest.fixture(scope="session")
def combined_walk(talos):
    """The demo's combined walk (forward, sideways, turning), 3 steps per direction, Table 6.1
    friction on every leg joint, the demo's simulator (physics at 10 kHz)."""
    from wbfriction.fit.targets import THESIS_TARGETS
    from wbfriction.sim import simulate_ideal
    from wbfriction.studies.common import SIMULATOR, leg_joints
    from wbfriction.walking import GaitOptions, walking_reference

    friction = {j: THESIS_TARGETS[g] for j, _, g in leg_joints(talos)}
    ref = walking_reference(talos, GaitOptions(gait="combined", steps=3))
    return simulate_ideal(talos, ref, friction, SIMULATOR)


@pytest.fixture
def cli(capsys):
    """``wbfriction ARGS`` in this process, which must succeed; its standard output."""
    def run(*args) -> str:
        code, out, err = run_cli_printed(capsys, *args)
        assert code == 0, (args[0], err)
        return out
    return run
