"""Inertia-model sensitivity (thesis 7.2, Fig. 7.5, 7.6): the scaling, and the direction of its
effect on the friction estimate of a simulated walk."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.friction.options import EstimateOptions
from wbfriction.inertia.sensitivity import inertia_sensitivity, parse_factors, scale_inertia, scaled_robot
from wbfriction.studies.common import leg_joints


def _random_inertia(seed: int) -> pin.Inertia:
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((3, 3))
    return pin.Inertia(rng.uniform(0.1, 20.0), rng.normal(0.0, 0.3, 3), A @ A.T + 0.01 * np.eye(3))


def _about_com(inertia: pin.Inertia) -> np.ndarray:
    """The 6x6 spatial inertia expressed at the centre of mass (axes of the body frame)."""
    return pin.SE3(np.eye(3), np.asarray(inertia.lever)).actInv(inertia).matrix()


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**20), factor=st.floats(0.5, 2.0))
def test_scaling_all_scales_the_spatial_inertia_in_any_frame(seed, factor):
    body = _random_inertia(seed)
    np.testing.assert_allclose(scale_inertia(body, factor, "all").matrix(), factor * body.matrix(), atol=1e-10)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**20), factor=st.floats(0.5, 2.0))
def test_mass_and_rotational_scale_their_own_eigenvalues(seed, factor):
    """About the centre of mass the eigenvalues are m (x3) and the principal moments: each
    part scales its own three, leaves the other three and the centre of mass alone."""
    body = _random_inertia(seed)
    eig = np.sort(np.linalg.eigvalsh(_about_com(body)))
    moments = np.sort(np.linalg.eigvalsh(np.asarray(body.inertia)))
    np.testing.assert_allclose(eig, np.sort(np.r_[[body.mass] * 3, moments]), rtol=1e-9)
    for part, expected in (("mass", np.r_[[factor * body.mass] * 3, moments]),
                           ("rotational", np.r_[[body.mass] * 3, factor * moments])):
        scaled = scale_inertia(body, factor, part)
        np.testing.assert_allclose(np.asarray(scaled.lever), np.asarray(body.lever), atol=1e-12)
        np.testing.assert_allclose(np.sort(np.linalg.eigvalsh(_about_com(scaled))), np.sort(expected),
                                   rtol=1e-9, atol=1e-12)
        # the principal axes are kept: the rotational blocks commute
        I0, I1 = np.asarray(body.inertia), np.asarray(scaled.inertia)
        np.testing.assert_allclose(I0 @ I1, I1 @ I0, atol=1e-9 * np.abs(I0).max() ** 2)


def test_scaled_robot_total_mass(talos):
    m = pin.computeTotalMass(talos.model)
    assert pin.computeTotalMass(scaled_robot(talos, 1.1, "all").model) == pytest.approx(1.1 * m)
    assert pin.computeTotalMass(scaled_robot(talos, 1.1, "mass").model) == pytest.approx(1.1 * m)
    assert pin.computeTotalMass(scaled_robot(talos, 1.1, "rotational").model) == pytest.approx(m)
    assert pin.computeTotalMass(talos.model) == pytest.approx(m)  # the original is untouched


def test_bad_parts_and_factors_are_input_errors():
    with pytest.raises(InputError, match="part"):
        scale_inertia(_random_inertia(0), 1.1, "inertia")
    with pytest.raises(InputError, match="> 0"):
        scale_inertia(_random_inertia(0), -1.0)
    assert parse_factors("0.9, 1.1,") == (0.9, 1.1)
    for bad in ("", "0.9,x", "0.9,-1"):
        with pytest.raises(InputError, match="--factors"):
            parse_factors(bad)


@pytest.fixture(scope="module")
def sensitivities(talos, combined_walk):
    opts = EstimateOptions(diff="central", route="acceleration")
    return {part: inertia_sensitivity(talos, combined_walk.log, [0.9, 1.1], part, opts) for part in ("mass",
                                                                                                     "rotational")}


def test_mass_error_shifts_the_knee_curve_up_for_more_mass(talos, sensitivities):
    """Fig. 7.5 (right knee): lower inertia shifts the curve down, higher inertia up. In swing the
    model's torque to hold the flexed shank and foot against gravity grows with their mass. The
    shift dominates the branch separation."""
    for knee in ("leg_right_4_joint", "leg_left_4_joint"):
        low, high = sensitivities["mass"].joint(knee)
        print(knee, low, high)
        assert high.shift > 0.3 and low.shift < -0.3
        assert high.shift == pytest.approx(-low.shift, rel=0.1)  # linear in the error
        assert abs(high.shift) > 5 * abs(high.split)


def test_rotational_error_splits_the_branches_without_shifting(talos, sensitivities):
    """Fig. 7.6: with the principal moments scaled the shift is gone and the branches for rising
    and falling velocity separate: the error is the extra inertial torque, (f - 1) I qdd, so the
    rising branch (qdd > 0) moves up for f > 1 and down for f < 1, on every leg joint that moves."""
    legs = [j for j, _, _ in leg_joints(talos)]
    mass = {j: sensitivities["mass"].joint(j)[1] for j in legs}
    for j in legs:
        low, high = sensitivities["rotational"].joint(j)
        print(j, f"shift {high.shift:.4f} split {high.split:.4f} (mass x1.1: shift {mass[j].shift:.4f})")
        if j.endswith(("_5_joint", "_6_joint")):  # ankles: the foot's rotational inertia is negligible
            assert abs(high.split) < 0.01
            continue
        assert high.split > 0 > low.split
        assert abs(high.shift) < high.split
        assert abs(high.shift) < 0.1 * abs(mass[j].shift)
        if not j.endswith("_1_joint"):  # hip roll, hip pitch, knee (the hip yaw moves little in swing)
            assert high.split > 0.02 and abs(high.shift) < 0.5 * high.split
