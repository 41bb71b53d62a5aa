"""The fixed-base arm simulator: its excitation trajectory against its own derivatives, its log against an
independent inverse dynamics (armature and friction included), the encoders and the current columns."""

from __future__ import annotations

from importlib import resources

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.friction.models import FrictionParams, coulomb_viscous_stribeck
from wbfriction.logs.log import log_from_table
from wbfriction.logs.tables import read_metadata
from wbfriction.model.loading import example_robot_data_dir, load_robot
from wbfriction.sim.arm import ArmOptions, ExcitationOptions, excitation_trajectory, simulate_arm

PANDA_URDF = "panda_description/urdf/panda.urdf"


@pytest.fixture(scope="module")
def panda():
    config = resources.files("wbfriction.model.robots").joinpath("panda.toml")
    return load_robot(urdf=example_robot_data_dir() / PANDA_URDF, config=str(config))


def friction_of(robot) -> dict[str, FrictionParams]:
    return {j: FrictionParams(F_v=0.5 - 0.05 * i, F_c=1.0 - 0.1 * i, S=0.3, v_s=0.05, tau_os=0.1, a=40.0)
            for i, j in enumerate(robot.actuated)}


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), harmonics=st.integers(2, 8), period=st.floats(1.0, 20.0),
       range_share=st.floats(0.1, 1.0), velocity_share=st.floats(0.1, 1.0))
def test_excitation_starts_at_rest_within_limits(seed, harmonics, period, range_share, velocity_share):
    """The Fourier series' velocity and acceleration are the derivatives of its position (central
    differences), it starts at rest, spans at most its share of the range inside the limits and keeps
    its speed within its share of the limit; a joint not excited stays in the middle."""
    lower, upper = np.array([-2.0, -0.5, 0.1]), np.array([2.5, 0.5, 3.0])
    vmax = np.array([2.0, 1.0, 0.5])
    opts = ExcitationOptions(period=period, harmonics=harmonics, range_share=range_share,
                             velocity_share=velocity_share, seed=seed)
    traj = excitation_trajectory(lower, upper, vmax, opts, excited=np.array([True, True, False]))
    t = np.linspace(0.0, 2 * period, 4001)
    q, qd, qdd = traj(t)
    h = 1e-5
    qp, qdp, _ = traj(t + h)
    qm, qdm, _ = traj(t - h)
    assert np.allclose((qp - qm) / (2 * h), qd, atol=1e-6 * (1 + np.abs(qd).max()))
    assert np.allclose((qdp - qdm) / (2 * h), qdd, atol=1e-5 * (1 + np.abs(qdd).max()))
    q0, qd0, qdd0 = traj(np.zeros(1))
    assert np.abs(qd0).max() < 1e-12 and np.abs(qdd0).max() < 1e-9 * (1 + np.abs(qdd).max())
    assert np.all(q >= lower - 1e-9) and np.all(q <= upper + 1e-9)
    assert np.all(q.max(axis=0) - q.min(axis=0) <= range_share * (upper - lower) * (1 + 1e-3))
    assert np.all(np.abs(qd).max(axis=0) <= velocity_share * vmax * (1 + 1e-3))
    assert np.allclose(q[:, 2], 0.5 * (lower[2] + upper[2])) and np.abs(qd[:, 2]).max() == 0.0


def test_the_log_obeys_the_arm_dynamics(panda):
    """Two routes: the true columns of the log satisfy ``(M + diag(armature)) qdd + h = k i + tau_f``
    by ``pin.rnea`` of a fixed-base model built here; ``tau_f_true = -f(qd_true)`` of (3.5); the
    positions are those of 19-bit encoders; the metadata names what was injected; the arm tracks
    its reference; the log reads back as motor currents on a fixed base."""
    friction = friction_of(panda)
    armature = {j: 0.1 + 0.02 * i for i, j in enumerate(panda.actuated)}
    sim = simulate_arm(panda, friction, armature, ArmOptions(duration=1.0, excitation=ExcitationOptions(period=2.0)))
    table = sim.table
    assert not [c for c in table.column_names if c.startswith(("contact.", "base.", "tau."))]
    col = lambda prefix: np.column_stack([table[f"{prefix}.{j}"].to_numpy() for j in panda.actuated])  # noqa: E731
    q_true, qd, qdd, tau_f, current = sim.q, col("qd_true"), col("qdd_true"), col("tau_f_true"), col("current")

    model = pin.buildModelFromUrdf(str(example_robot_data_dir() / PANDA_URDF))
    fingers = [model.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    model = pin.buildReducedModel(model, fingers, pin.neutral(model))
    model.armature = np.array([armature[j] for j in panda.actuated])
    data = model.createData()
    k = np.array([panda.torque_constants[j] for j in panda.actuated])
    lhs = np.array([pin.rnea(model, data, q_true[i], qd[i], qdd[i]) for i in range(len(qd))])
    assert np.abs(lhs - (current * k + tau_f)).max() < 1e-9 * np.abs(lhs).max()

    p = {n: np.array([getattr(friction[j], n) for j in panda.actuated]) for n in ("F_v", "F_c", "S", "v_s", "tau_os",
                                                                                  "a")}
    assert np.allclose(tau_f, -coulomb_viscous_stribeck(qd, **p), atol=1e-12)
    step = 2 * np.pi / 2**19
    q_log = col("q")
    assert np.allclose(q_log / step, np.round(q_log / step), atol=1e-6) and np.abs(q_log - q_true).max() <= step / 2
    assert np.abs(q_true - sim.trajectory(table["time"].to_numpy())[0]).max() < 0.01

    meta = read_metadata(table)
    assert meta["armature_true"] == pytest.approx(armature) and meta["torque_constants"] == panda.torque_constants
    assert meta["friction_true"]["panda_joint3"]["F_c"] == friction["panda_joint3"].F_c
    log = log_from_table(table, panda)
    assert log.torque_source == "current" and np.allclose(log.tau, current * k) and log.contact.all()


def test_torque_noise_and_the_robots_own_armature(panda):
    """Without an armature given the robot's ``[armature]`` is the truth; the torque noise is the
    one asked for (seeded), and the same seed gives the same log."""
    opts = ArmOptions(duration=0.3, torque_std=0.2, seed=3, excitation=ExcitationOptions(period=2.0))
    a, b = (simulate_arm(panda, {}, options=opts) for _ in range(2))
    meta = read_metadata(a.table)
    assert meta["armature_true"] == pytest.approx(dict(zip(panda.actuated, panda.model.armature[panda.act_v_index])))
    k = np.array([panda.torque_constants[j] for j in panda.actuated])
    current = np.column_stack([a.table[f"current.{j}"].to_numpy() for j in panda.actuated])
    noise = current * k - a.tau_motor
    assert 0.17 < noise.std() < 0.23 and abs(noise.mean()) < 0.02
    assert a.table.equals(b.table)


def test_what_the_simulator_refuses(panda, talos):
    with pytest.raises(InputError, match="floating base"):
        simulate_arm(talos, {})
    with pytest.raises(InputError, match="'knee'"):
        simulate_arm(panda, {"knee": FrictionParams()})
    with pytest.raises(InputError, match=">= 0"):
        simulate_arm(panda, {}, {"panda_joint1": -0.1})
    with pytest.raises(InputError, match="duration"):
        ArmOptions(duration=0.0)
    with pytest.raises(InputError, match="harmonics >= 2"):
        ExcitationOptions(harmonics=1)


def test_a_trajectory_given_is_the_one_tracked(panda):
    """A trajectory given replaces the random excitation: the arm tracks it (its true positions within 0.01 rad of
    it, the same dynamics as with its own: the random series given back gives the same samples), it is recorded in
    the metadata, and one of the wrong shape is refused."""
    opts = ArmOptions(duration=1.0, excitation=ExcitationOptions(period=2.0, seed=4))
    model = panda.model
    lower, upper = panda.angle_limits
    velocity = model.velocityLimit[panda.act_v_index]
    own = excitation_trajectory(lower, upper, velocity, ExcitationOptions(period=2.0, seed=9))
    given = simulate_arm(panda, friction_of(panda), options=opts, trajectory=own)
    t = given.table["time"].to_numpy()
    assert np.abs(given.q - own(t)[0]).max() < 0.01
    assert read_metadata(given.table)["trajectory"]["a"] == own.a.tolist()
    random = simulate_arm(panda, friction_of(panda), options=opts)
    assert np.abs(random.q - own(t)[0]).max() > 0.05  # not the one given: another seed
    mirrored = excitation_trajectory(lower, upper, velocity, ExcitationOptions(period=2.0, seed=4))
    again = simulate_arm(panda, friction_of(panda), options=opts, trajectory=mirrored)
    np.testing.assert_array_equal(again.q, random.q)
    with pytest.raises(InputError, match="trajectory given"):
        simulate_arm(panda, {}, options=opts, trajectory=lambda t: (np.zeros((len(t), 3)),) * 3)
