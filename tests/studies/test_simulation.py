"""The thesis's simulation study (ch. 6) on a short walk: exact with the true accelerations (Fig. 6.1), the
derivative schemes ordered as the thesis found them (Fig. 6.2, 6.3), and its files."""

from __future__ import annotations

import pytest

from wbfriction.fit.params_file import read_params
from wbfriction.studies.simulation import run_study

# module fixtures of 30-55 s (the quick subset: -m "not slow")
pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("studies_simulation")]


@pytest.fixture(scope="module")
def study(talos, tmp_path_factory):
    out = tmp_path_factory.mktemp("study")
    return out, run_study(talos, out, steps=2, knee_steps=2)


def test_true_accelerations_recover_the_friction_exactly(study):
    _, result = study
    assert result.truth_max_error < 1e-8
    assert max(result.knee_rms["true acceleration"]) < 1e-8


def test_delay_compensation_and_the_swing_leg(study):
    """Fig. 6.2/6.3: an uncompensated delay costs most; every scheme is worse with the leg in stance."""
    _, result = study
    rms = result.knee_rms
    assert rms["backward, not compensated"][0] > 3 * rms["backward, delay compensated"][0]
    for label in ("central (6.2)", "backward, delay compensated", "backward, not compensated"):
        swing, stance = rms[label]
        assert swing < stance


def test_the_parameters_file_reads_back_as_the_table(study):
    out, result = study
    params = read_params(out / "walk_params.json")
    assert [r.joint for r in result.rows] == list(params)
    for row in result.rows:
        assert params[row.joint].params == row.fit.params
        if row.group in ("knee", "ankle_pitch"):  # the joints a 2-step walk moves most
            assert max(row.fit.error_percent()[n] for n in ("F_v", "F_c", "tau_os")) < 5.0
    assert {f.name for f in result.files} >= {"fig6_1_support_phases.png", "walk_friction.parquet", "report.html"}
    assert all(f.stat().st_size > 1000 for f in result.files)
