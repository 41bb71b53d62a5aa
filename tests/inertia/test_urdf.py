"""The corrected URDF: written identified bodies read back by Pinocchio, the structure kept."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.inertia.regressor import body_parameters
from wbfriction.inertia.sensitivity import scaled_robot
from wbfriction.inertia.urdf import body_links, inertia_changes, write_urdf
from wbfriction.model.loading import load_robot


def _same_structure(a: pin.Model, b: pin.Model) -> None:
    assert list(a.names) == list(b.names)
    assert [f.name for f in a.frames] == [f.name for f in b.frames]
    for j in range(a.njoints):
        assert a.jointPlacements[j].isApprox(b.jointPlacements[j], 1e-12)
    assert np.array_equal(a.lowerPositionLimit, b.lowerPositionLimit)
    assert np.array_equal(a.upperPositionLimit, b.upperPositionLimit)
    assert np.array_equal(a.armature, b.armature)


def test_written_urdf_reads_back_as_the_wrong_model(talos, tmp_path):
    """Every body changed (principal moments x1.1, mass x1.05): Pinocchio reading the written
    URDF gets the bodies back, joints, frames and limits unchanged."""
    wrong = scaled_robot(scaled_robot(talos, 1.1, "rotational"), 1.05, "mass")
    pi = body_parameters(wrong.model)
    assert write_urdf(talos, pi, tmp_path / "wrong.urdf") == ()
    back = load_robot("talos", urdf=tmp_path / "wrong.urdf")
    assert np.allclose(body_parameters(back.model), pi, rtol=1e-12, atol=1e-12)
    _same_structure(talos.model, back.model)


def test_unchanged_bodies_keep_their_urdf_text(talos, tmp_path):
    write_urdf(talos, body_parameters(talos.model), tmp_path / "same.urdf")
    text, original = (tmp_path / "same.urdf").read_text(), talos.urdf.read_text()
    assert text.count("<inertial>") == original.count("<inertial>")
    assert np.array_equal(body_parameters(load_robot("talos", urdf=tmp_path / "same.urdf").model),
                          body_parameters(talos.model))


def _box(values) -> np.ndarray:
    m, a, b, c, x, y, z, rx, ry, rz = values
    return pin.SE3(pin.rpy.rpyToMatrix(rx, ry, rz), np.array([x, y, z])).act(pin.Inertia.FromBox(m, a, b, c)) \
        .toDynamicParameters()


@settings(max_examples=15, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(body=st.integers(0, 200), values=st.tuples(st.floats(0.05, 20), *[st.floats(0.02, 0.5)] * 3,
                                                  *[st.floats(-0.3, 0.3)] * 3, *[st.floats(-3, 3)] * 3))
def test_any_physical_body_round_trips(talos, tmp_path_factory, body, values):
    """A body replaced by any rigid box, heavier or lighter than the links merged into it
    (then it goes to the child link whole): read back to 1e-9."""
    pi = body_parameters(talos.model)
    b = body % len(pi)
    pi[b] = _box(values)
    path = tmp_path_factory.mktemp("urdf") / "one.urdf"
    moved = write_urdf(talos, pi, path)
    links = body_links(talos)[b]
    assert set(moved) <= {links.joint} and (not moved or len(links.placements) > 1)
    back = body_parameters(load_robot("talos", urdf=path).model)
    assert np.allclose(back, pi, rtol=1e-9, atol=1e-9)


def test_a_body_lighter_than_its_other_links_goes_to_its_child_link_whole(talos, tmp_path):
    pi = body_parameters(talos.model)
    head = talos.model.getJointId("head_2_joint") - 1
    pi[head] *= 0.05  # lighter than the camera links merged into the head
    assert write_urdf(talos, pi, tmp_path / "light.urdf") == ("head_2_joint",)
    assert np.allclose(body_parameters(load_robot("talos", urdf=tmp_path / "light.urdf").model), pi, atol=1e-12)


def test_merged_links(talos):
    """Pinocchio merges links attached by fixed joints: the sole into the ankle, the gripper into the wrist."""
    links = {b.joint: b for b in body_links(talos)}
    assert links["root_joint"].child == "base_link"
    assert set(links["leg_left_6_joint"].placements) == {"leg_left_6_link", "left_sole_link"}
    assert len(links["arm_left_7_joint"].placements) == 10
    assert np.allclose(links["leg_left_6_joint"].placements["left_sole_link"].translation, [0, 0, -0.107])


def test_changes_table_is_the_scaling(talos):
    """Mass x1.05 and principal moments x1.1 about the centre of mass read back as such, the
    centres of mass unmoved."""
    wrong = scaled_robot(scaled_robot(talos, 1.1, "rotational"), 1.05, "mass")
    changes = inertia_changes(talos.model.names[1:], body_parameters(talos.model), body_parameters(wrong.model))
    massive = [c for c in changes if c.mass_given > 0]
    assert massive and all(abs(c.mass_change - 0.05) < 1e-12 for c in massive)
    assert all(c.com_shift < 1e-12 for c in changes)
    assert all(np.allclose(c.moments_change[c.moments_given > 1e-9], 0.1, atol=1e-9) for c in massive)


def test_unreadable_urdf_is_an_input_error(talos, tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'>")
    robot = dataclasses.replace(talos, urdf=bad, cache={})
    with pytest.raises(InputError, match="bad.urdf"):
        write_urdf(robot, body_parameters(talos.model), tmp_path / "out.urdf")
    assert not (tmp_path / "out.urdf").exists()


def test_a_massless_body_gives_its_changes_not_a_linalg_error():
    """Issue 53: ``identify`` with a URDF link of zero mass and inertia ended, after its work, in ``LinAlgError:
    Eigenvalues did not converge`` (its centre of mass ``h / m`` NaN). A massless body's centre of mass is its frame's
    origin: the identified body's shift is its own centre of mass, its moments those about it."""

    from wbfriction.inertia.urdf import inertia_changes

    identified = pin.Inertia(2.0, np.array([0.0, 0.3, 0.4]), np.diag([0.1, 0.2, 0.3]))
    massless = np.zeros(10)
    (change,) = inertia_changes(["link"], massless[None], identified.toDynamicParameters()[None])
    assert change.mass_given == 0.0 and change.mass == pytest.approx(2.0)
    assert change.com_shift == pytest.approx(0.5) and np.isnan(change.mass_change)
    assert np.allclose(change.moments, [0.1, 0.2, 0.3]) and np.allclose(change.moments_given, 0.0)
