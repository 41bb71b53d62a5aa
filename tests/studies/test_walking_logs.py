"""A walking robot's raw log against the twin's truth (:mod:`wbfriction.studies.walking_logs`), on the firm twin's
clean trot: every step of the raw route scored as ``bench_walking_logs.py --contacts firm`` scores it."""

from __future__ import annotations

import json

import numpy as np
import pyarrow.parquet as pq
import pytest


@pytest.mark.slow
def test_the_firm_trots_raw_route_against_its_truth(tmp_path):
    """The repeats found exactly; no sample whose inferred contact differs from the simulator's is one a fit used
    (the feet grazing the ground near lift-off and touch-down lie in the margins); the base's velocity within 5 % of
    its speed (measured 3.0 %); every ``ok`` fit's F_c and F_v within two of the standard errors it reads of the
    injected friction, the torque constants' stated 1.73 % in them (measured: within one; before the scale's spread,
    F_c 4.5 % off at a read error of 1.7 %); and where the given flags and pose and the raw route are both ``ok``,
    within 2 % of each other (measured 0.7 %)."""
    from wbfriction.fit.params_file import read_params
    from wbfriction.studies.walking_logs import WalkingCase, score_case

    case = WalkingCase("trot", False, "firm")
    score = score_case(case, tmp_path)
    assert score.repeats_exact and score.fitted_disagreement == 0 and score.velocity_error < 0.05
    truth = json.loads(pq.read_schema(tmp_path / f"{case.name}_raw.parquet").metadata[b"wbfriction"])
    fits = read_params(tmp_path / f"{case.name}_params.json")
    ok = [f for f in fits.values() if f.verdict().status == "ok"]
    assert ok, {j: f.verdict().status for j, f in fits.items()}
    for f in ok:
        true, read = truth["friction_true"][f.joint], f.read_stderr()
        for n in ("F_c", "F_v"):
            assert abs(getattr(f.params, n) - true[n]) <= 2 * read[n], (f.joint, n, getattr(f.params, n), true[n])
    assert np.isnan(score.given_gap) or score.given_gap <= 0.02
