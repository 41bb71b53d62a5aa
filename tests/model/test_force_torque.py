"""Force-torque sensors: the TOML's tables, the robot above the sensors, what the sensors measure."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.model.force_torque import (
    ForceTorqueSensor,
    above_sensors_model,
    external_wrenches,
    parse_sensors,
    sensor_readings,
)

FRAMES = ["left_sole_link", "right_sole_link"]


def _spec(**kw):
    spec = {"link": "leg_left_6_link", "contact": "left_sole_link", "xyz": [0, 0, -0.08], "mass_below": 0.4,
            "com_below": [0, 0, -0.0135], "inertia_below": [5e-4, 1.36e-3, 1.81e-3, 0, 0, 0]}
    spec.update(kw)
    return spec


def _random_configuration(robot, rng) -> np.ndarray:
    """A finite configuration: the reference posture moved by up to 0.3 rad per joint, a tilted base."""
    base = np.r_[rng.normal(size=3), pin.Quaternion(pin.rpy.rpyToMatrix(*rng.uniform(-0.5, 0.5, 3))).coeffs()]
    return robot.configuration(robot.reference_angles + rng.uniform(-0.3, 0.3, robot.n_act), base)


def test_the_builtin_talos_has_one_sensor_per_ankle(talos):
    names = [s.name for s in talos.ft_sensors]
    assert names == ["left_ankle", "right_ankle"]
    assert [s.contact for s in talos.ft_sensors] == FRAMES
    assert talos.ft_sensors[0].columns() == [f"wrench.left_ankle.{a}" for a in ("fx", "fy", "fz", "tx", "ty", "tz")]


@pytest.mark.parametrize(("change", "needle"), [
    ({"link": "no_such_link"}, "link = 'no_such_link' is not a frame"),
    ({"contact": "nowhere"}, "contact = 'nowhere' is not one of the contact frames"),
    ({"contact": "right_sole_link"}, "is not on the link"),
    ({"xyz": [0, 0]}, "xyz must be 3 numbers"),
    ({"mass_below": -1.0}, "mass_below must be >= 0"),
    ({"inertia_below": [1, 1, 1, 5, 0, 0]}, "not positive semi-definite"),
    ({"colour": "red"}, "unknown key 'colour'"),
])
def test_a_bad_sensor_table_is_refused_in_one_line_naming_it(talos, change, needle):
    with pytest.raises(InputError, match=needle) as info:
        parse_sensors(talos.model, {"left": _spec(**change)}, FRAMES, "robot.toml")
    message = str(info.value)
    assert message.startswith("robot.toml: [force_torque.left]") and "\n" not in message


def test_two_sensors_on_one_contact_are_refused(talos):
    with pytest.raises(InputError, match="measures contact 'left_sole_link' as"):
        parse_sensors(talos.model, {"a": _spec(), "b": _spec()}, FRAMES, "robot.toml")


def test_the_robot_above_the_sensors_plus_the_parts_below_is_the_robot(talos):
    above = above_sensors_model(talos.model, talos.ft_sensors)
    for s in talos.ft_sensors:
        whole = above.inertias[s.joint] + s.below_in_joint
        np.testing.assert_allclose(whole.matrix(), talos.model.inertias[s.joint].matrix(), atol=1e-12)
        assert above.inertias[s.joint].mass == pytest.approx(talos.model.inertias[s.joint].mass - 0.4)
    untouched = set(range(talos.model.njoints)) - {s.joint for s in talos.ft_sensors}
    for j in untouched:
        np.testing.assert_array_equal(above.inertias[j].matrix(), talos.model.inertias[j].matrix())


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_a_massless_plate_at_the_sole_reads_the_contact_wrench(talos, seed):
    """Analytic case: nothing below the sensor and the sensor frame on the sole: f_s = lambda."""
    rng = np.random.default_rng(seed)
    sensor = parse_sensors(talos.model, {"s": {"link": "left_sole_link", "contact": "left_sole_link"}}, FRAMES,
                           "t")
    q = _random_configuration(talos, rng)[None]
    v, a = rng.normal(size=(1, talos.model.nv)), rng.normal(size=(1, talos.model.nv))
    lam = np.zeros((1, 2, 6))
    lam[0, 0] = rng.normal(size=6) * 100
    np.testing.assert_allclose(sensor_readings(talos.model, sensor, tuple(FRAMES), q, v, a, lam)[0, 0], lam[0, 0],
                               atol=1e-9)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**31 - 1))
def test_the_sensor_wrench_on_the_robot_above_balances_the_whole_robot(talos, seed):
    """Two routes: RNEA of the whole robot with the contact wrench as an external force, and RNEA of the
    robot above the sensors with the sensors' readings (:func:`sensor_readings`) as external forces,
    give the same torques at every joint and the same six base rows."""
    rng = np.random.default_rng(seed)
    model = talos.model
    q = _random_configuration(talos, rng)
    v, a = rng.normal(size=model.nv), rng.normal(size=model.nv)
    lam = rng.normal(size=(1, 2, 6)) * 200
    f_s = sensor_readings(model, talos.ft_sensors, talos.contact_frames, q[None], v[None], a[None], lam)[0]
    fext = [pin.Force.Zero() for _ in range(model.njoints)]
    for c, frame in enumerate(talos.contact_frames):
        fr = model.frames[model.getFrameId(frame)]
        fext[fr.parentJoint] = fext[fr.parentJoint] + fr.placement.act(pin.Force(lam[0, c]))
    whole = pin.rnea(model, model.createData(), q, v, a, fext)
    above = above_sensors_model(model, talos.ft_sensors)
    split = pin.rnea(above, above.createData(), q, v, a, external_wrenches(above, talos.ft_sensors, f_s))
    assert np.all(np.isfinite(whole))
    np.testing.assert_allclose(split, whole, atol=1e-8 * max(1.0, np.abs(whole).max()))


def test_a_standing_robot_reads_its_weight_less_the_plate(talos):
    """Static check: standing still on one foot, the sensor's fz is the weight above it (m_total - plate) g."""
    model = talos.model
    q = talos.q_reference.copy()
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    q[:7] = pin.SE3ToXYZQUAT(data.oMf[model.getFrameId("left_sole_link")].inverse())
    zeros = np.zeros((1, model.nv))
    total = pin.computeTotalMass(model)
    lam = np.zeros((1, 2, 6))
    lam[0, 0, 2] = total * 9.81
    pin.framesForwardKinematics(model, data, q)
    com = pin.centerOfMass(model, data, q)
    sole = data.oMf[model.getFrameId("left_sole_link")]
    lam[0, 0, 3:] = np.cross(sole.actInv(com) * [1, 1, 0], [0, 0, total * 9.81])  # the weight's moment at the sole
    f_s = sensor_readings(model, talos.ft_sensors, talos.contact_frames, q[None], zeros, zeros, lam)[0, 0]
    assert f_s[2] == pytest.approx((total - 0.4) * 9.81, rel=1e-9)
    assert isinstance(talos.ft_sensors[0], ForceTorqueSensor)
