"""The realistic-simulator study (thesis 6.2) on a short MuJoCo walk: the knee's swing-phase estimate beats its
whole-step one (Fig. 6.4), its three identification cases and their files."""

from __future__ import annotations

import pytest

from wbfriction.fit.params_file import read_params
from wbfriction.studies.realistic import run_realistic_study, worst_scored

# module fixtures of 30-55 s (the quick subset: -m "not slow")
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("studies_realistic")]


@pytest.fixture(scope="module")
def study(talos, tmp_path_factory):
    out = tmp_path_factory.mktemp("realistic")
    return out, run_realistic_study(talos, out, steps=2, knee_steps=2)


def test_the_swing_phase_is_where_the_estimate_holds(study):
    """Fig. 6.4: with soft contacts, the knee's estimate is far better while its leg swings."""
    _, result = study
    assert result.knee_rms["swing only"] < 0.2 * result.knee_rms["whole step"]


def test_three_cases_of_twelve_leg_joints_and_their_files(study):
    out, result = study
    assert [c.name for c in result.cases] == ["model", "mujoco", "noisy"]
    for case in result.cases:
        assert [r.number for r in case.rows] == list(range(1, 13))
        params = read_params(out / f"mujoco_{case.name}_params.json")
        assert list(params) == [r.joint for r in case.rows]
        assert set(worst_scored(case)) == set(case.scored)
    mujoco = result.cases[1]  # MuJoCo's own friction has no Stribeck term or offset: those are held, not fitted
    assert all(r.fit.params.S == 0.0 and r.fit.params.tau_os == 0.0 and r.fit.stderr["S"] == 0.0 for r in mujoco.rows)
    assert all(f.stat().st_size > 1000 for f in result.files)
