"""Issue 40: a fleet whose friction follows the joints' temperatures (tens of percent between its coldest and
warmest logs) and wears on some joints (steps and ramps of 15-30 %, random onsets): with the temperatures logged,
the trends flag exactly the worn joints, each onset within one log and each size within 5 %, over 10 seeds; without
them, what the same fleets give (printed, and worse)."""

from __future__ import annotations

import numpy as np
import pytest

from wbfriction.studies.temperature_fleet import (
    K_TC,
    TemperatureFleet,
    score_temperature_fleet,
    temperature_fleet,
)


def test_the_fleet_spans_tens_of_percent_of_friction_by_temperature():
    plan = TemperatureFleet(seed=0, robots=1, logs=12)
    results = temperature_fleet(plan)
    T = np.asarray(results.column("temperature").to_numpy(), dtype=float)
    assert np.isfinite(T).all() and abs(K_TC) * (T.max() - T.min()) > 0.2
    wear = plan.wear()
    assert len(wear) == 3 and len({(w.robot_id, w.joint) for w in wear}) == 3
    assert all(0.15 <= w.size <= 0.30 and plan.margin <= w.onset <= plan.logs - plan.margin for w in wear)


@pytest.mark.slow
def test_temperature_cannot_fool_the_trends():
    rows = []
    for seed in range(10):
        plan = TemperatureFleet(seed=seed)
        results = temperature_fleet(plan)
        with_t = score_temperature_fleet(plan, results)
        blind = score_temperature_fleet(plan, results, temperature=False)
        rows.append((with_t, blind))
        assert set(with_t.flagged) == set(with_t.worn), (seed, with_t.false_alarms, with_t.missed)
        assert all(abs(e) <= 1 for e in with_t.onset_error.values()), (seed, with_t.onset_error)
        assert all(abs(e) <= 0.05 for e in with_t.size_error.values()), (seed, with_t.size_error)
    for name, k in (("with temperatures", 0), ("without", 1)):
        scores = [r[k] for r in rows]
        onsets = [e for s in scores for e in s.onset_error.values()]
        sizes = [e for s in scores for e in s.size_error.values()]
        print(f"\n{name}: {sum(len(s.worn) for s in scores)} worn joints, missed {sum(len(s.missed) for s in scores)}, "
              f"false alarms {sum(len(s.false_alarms) for s in scores)}, onset within 1 log "
              f"{np.mean(np.abs(onsets) <= 1):.2f}, size error max {100 * np.max(np.abs(sizes)):.1f} % RMS "
              f"{100 * np.sqrt(np.mean(np.square(sizes))):.1f} %")
    blind = [r[1] for r in rows]
    worst_blind = max(abs(e) for s in blind for e in s.size_error.values())
    assert sum(len(s.missed) + len(s.false_alarms) for s in blind) > 0 or worst_blind > 0.05
