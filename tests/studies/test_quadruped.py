"""What each gait gives a walking quadruped (wbfriction.studies.quadruped, issue 56), against the friction the
simulators injected: the ideal trot exact, torque- and PD-driven; a walk's stance legs not determined without foot
forces and exact with them; MuJoCo's soft contacts within 5 %; what the rank decision reports per contact pattern."""

from __future__ import annotations

import numpy as np
import pytest

from wbfriction.exceptions import OptionError
from wbfriction.model.loading import load_robot
from wbfriction.studies.quadruped import QuadrupedCase, case_robot, run_quadruped

LEGS = ("FL", "FR", "RL", "RR")


@pytest.fixture(scope="module")
def go2():
    return load_robot("go2_walking")


def errors(study) -> np.ndarray:
    """(n_joints, 2) the fitted F_c and F_v errors against the truth [%], NaN for a joint not fitted."""
    return np.array([[(f.error_percent() or {}).get(p, np.nan) for p in ("F_c", "F_v")] for f in study.fits])


def share(study, pattern: str, leg: str) -> float:
    """The share of ``pattern``'s samples that determine the joints of ``leg`` (the same for its three joints)."""
    s = study.shares
    values = {s.share[s.patterns.index(pattern), i] for i, j in enumerate(s.joints) if j.startswith(leg + "_")}
    assert len(values) == 1
    return values.pop()


@pytest.mark.parametrize("drive", ["torque", "pd"])
def test_ideal_trot_is_exact_on_every_joint(go2, drive):
    """The ideal trot, noise-free: every joint's F_c and F_v within 1 % (the issue's target), from its swing phases
    alone (the stance pair is never determined: two point feet may squeeze along their diagonal)."""
    study = run_quadruped(go2, QuadrupedCase(gait="trot", drive=drive, duration=4.0))
    assert np.nanmax(errors(study)) < 1.0 and not np.isnan(errors(study)).any()
    for pair, swinging in (("FL_foot+RR_foot", ("FR", "RL")), ("FR_foot+RL_foot", ("FL", "RR"))):
        for leg in LEGS:
            assert share(study, pair, leg) == (1.0 if leg in swinging else 0.0)
    assert study.shares.share[study.shares.patterns.index("FL_foot+FR_foot+RL_foot+RR_foot")].max() == 0.0


def test_walk_needs_foot_forces_for_its_stance_legs(go2):
    """A walk (three feet down): the stance legs not determined without the feet's forces, the swinging leg is;
    with 3-D foot forces every leg in every pattern, and still exact."""
    plain = run_quadruped(go2, QuadrupedCase(gait="walk", duration=4.0))
    three = [p for p in plain.shares.patterns if p.count("+") == 2]
    assert len(three) == 4
    for pattern in three:
        for leg in LEGS:
            assert share(plain, pattern, leg) == (0.0 if f"{leg}_foot" in pattern else 1.0)
    forces = run_quadruped(go2, QuadrupedCase(gait="walk", duration=4.0, foot_forces="3d"))
    assert (forces.shares.share == 1.0).all()
    assert np.nanmax(errors(forces)) < 1.0 and not np.isnan(errors(forces)).any()
    n_plain = np.array([f.n_samples for f in plain.fits])
    assert (np.array([f.n_samples for f in forces.fits]) > 3 * n_plain).all()


@pytest.mark.slow
@pytest.mark.parametrize("foot_forces", ["none", "3d"])
def test_mujoco_trot_within_five_percent(go2, foot_forces):
    """MuJoCo's soft contacts and sphere feet (the force at the sphere's lowest point: the robot's foot_radius),
    noise-free: every joint's F_c and F_v within 5 % (the issue's target), or weak because the joint moved one way
    where it was determined (a thigh seen only in swing: its Coulomb friction and offset are one column)."""
    case = QuadrupedCase(simulator="mujoco", gait="trot", duration=4.0, foot_forces=foot_forces)
    assert case_robot(go2, case).foot_radius > 0
    study = run_quadruped(go2, case)
    err = errors(study)
    verdicts = [f.verdict() for f in study.fits]
    good = np.array([v.ok for v in verdicts])
    assert good.sum() >= 8 and not np.isnan(err).any()
    assert err[good].max() < 5.0
    for v, e in zip(verdicts, err):
        if not v.ok and e.max() >= 5.0:
            assert "moved one way" in v.reason


def test_bad_case_is_refused_before_simulating():
    with pytest.raises(OptionError, match="--simulator"):
        QuadrupedCase(simulator="gazebo")  # type: ignore[arg-type]
    with pytest.raises(OptionError, match="--gait"):
        QuadrupedCase(gait="gallop")  # type: ignore[arg-type]
    with pytest.raises(OptionError, match="--foot-forces"):
        QuadrupedCase(foot_forces="6d")  # type: ignore[arg-type]
