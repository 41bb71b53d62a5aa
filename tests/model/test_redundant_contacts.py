"""Contacts whose constraints are redundant at every posture (issue 81, class 9): a point-foot robot whose TOML says
``contact_model = "sole"`` ended ``estimate`` with ``LinAlgError: Singular matrix`` on a trot. The stacked constraint
Jacobian's rank at a generic posture tells such a pattern of contacts (:func:`~wbfriction.model.dynamics.
redundant_contacts`); a log with one is refused in one line naming the key before any work."""

from __future__ import annotations

import itertools
from importlib import resources

import numpy as np
import pinocchio as pin
import pytest

from helpers import run_cli, said
from wbfriction.exceptions import InputError
from wbfriction.friction.estimate import estimate_log
from wbfriction.model.dynamics import check_contact_patterns, redundant_contacts
from wbfriction.model.loading import load_robot


def _sole_toml(path):
    """The walking Go2's TOML with ``contact_model = "sole"``: four point feet said to be soles."""
    text = resources.files("wbfriction.model.robots").joinpath("go2_walking.toml").read_text()
    assert 'contact_model = "point"' in text
    path.write_text(text.replace('contact_model = "point"', 'contact_model = "sole"')
                    .replace('name = "go2_walking"', 'name = "go2_soles"'))
    return path


@pytest.fixture(scope="module")
def soles(tmp_path_factory):
    return load_robot(None, config=_sole_toml(tmp_path_factory.mktemp("soles") / "go2_soles.toml"))


def _patterns(n: int):
    return [np.array(p, dtype=bool) for p in itertools.product([False, True], repeat=n) if any(p)]


def _kkt_rank(robot, flags, angles) -> tuple[int, int]:
    """The rank and size of ``J_c M^-1 J_c^T``, the matrix (5.10) solves with, at ``angles`` (the soles' LOCAL
    Jacobians)."""
    model, data = robot.model, robot.model.createData()
    q = robot.configuration(angles)
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    J = np.vstack([pin.getFrameJacobian(model, data, robot.contact_frame_ids[c], pin.LOCAL)
                   for c in np.flatnonzero(flags)])
    G = J @ np.linalg.solve(pin.crba(model, data, q), J.T)
    return int(np.linalg.matrix_rank(G)), G.shape[0]


def test_soles_on_a_quadrupeds_3_dof_legs_are_redundant(soles):
    """Six constraints per foot on legs of three joints: k feet down are 6k constraints on 6 + 3k degrees of
    freedom, redundant from k = 3 (18 on 15; 24 on 18); two feet of one side too (their hips' axes in one line); and
    ``J_c M^-1 J_c^T`` is then singular at the log's postures as at the check's, which is what ``estimate`` met. A
    trot's diagonal pair, and one foot, are not: the system solves."""
    rng = np.random.default_rng(1)
    for flags in _patterns(4):
        k = int(flags.sum())
        found = redundant_contacts(soles, flags)
        if k >= 3:
            assert found is not None and (found.constraints, found.rank, found.models) == (6 * k, 6 + 3 * k,
                                                                                          ("sole",) * k)
        for _ in range(3):  # postures about standing, none the check's
            rank, size = _kkt_rank(soles, flags, soles.reference_angles + rng.normal(0, 0.2, soles.n_act))
            assert (rank < size) == (found is not None), (flags, rank, size)
    assert redundant_contacts(soles, np.array([True, False, False, True])) is None  # a trot's pair
    assert redundant_contacts(soles, np.array([True, True, False, False])) is None  # the front pair


@pytest.mark.parametrize("name", ["talos", "toro", "go2_walking"])
def test_no_pattern_of_the_built_in_robots_is_redundant(name):
    """A humanoid's soles on legs of six joints (both down: 12 constraints on 18), a quadruped's point feet (all four:
    12 on 18): nothing refused."""
    robot = load_robot(name)
    assert all(redundant_contacts(robot, flags) is None for flags in _patterns(len(robot.contact_frames)))
    check_contact_patterns(robot, np.ones((3, len(robot.contact_frames)), dtype=bool), "log.parquet")


def test_a_trot_on_soles_is_one_line_naming_the_key(soles, capsys, tmp_path):
    """Round 4's last case: the walking Go2 simulated trotting, estimated with its feet said to be soles. Before:
    ``LinAlgError: Singular matrix`` after the differentiation; now one line naming the log, the row, the feet and
    ``contact_model``, and nothing written."""
    log = tmp_path / "trot.parquet"
    code, err = run_cli(capsys, "simulate", "--robot", "go2_walking", "--gait", "trot", "--duration", "1", "-o", log)
    assert code == 0, err
    config = _sole_toml(tmp_path / "go2_soles.toml")
    out = tmp_path / "friction.parquet"
    code, err = run_cli(capsys, "estimate", log, "--config", config, "-o", out)
    lines = said(err)
    assert code == 2 and len(lines) == 1, err
    assert f"{log}: row 0 has FL_foot, FR_foot, RL_foot, RR_foot on the ground: robot 'go2_soles''s contact_model " \
           "(sole) makes them 24 constraints of rank 18 at any posture" in lines[0], err
    assert not out.exists()
    from wbfriction.logs.source import read_log
    with pytest.raises(InputError, match="contact_model \\(sole\\) makes them 24 constraints of rank 18"):
        estimate_log(soles, read_log(log, soles))
