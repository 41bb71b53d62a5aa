"""Issue 65, class 5: what the terminal says is what was done, in the robot's own terms.

Before: a log holding both measured torques and set-points said nothing of where its torque came from; the momentum
route said ``--window 15 not used`` of a filter the user never gave (the differentiation choice's); contact flags
that flicker printed numpy's ``Mean of empty slice`` (tests/signals/test_choice.py)."""

from __future__ import annotations

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from helpers import run_cli
from wbfriction.model import load_robot


@pytest.fixture(scope="module")
def hung(tmp_path_factory):
    """3 s of the hung Go2 (PD drivers)."""
    from wbfriction.sim.hung import simulate_hung
    from wbfriction.sim.pd_options import HungOptions

    path = tmp_path_factory.mktemp("hung") / "hung.parquet"
    pq.write_table(simulate_hung(load_robot("go2"), HungOptions(duration=3.0)).table, path)
    return path


def _line(err: str, prefix: str) -> str:
    return next((ln for ln in err.splitlines() if ln.startswith(prefix)), "")


def test_measured_torques_beside_set_points_say_which_is_used(hung, tmp_path, capsys):
    table = pq.read_table(hung)
    for j in load_robot("go2").actuated:
        table = table.append_column(f"tau.{j}", pa.array(np.zeros(table.num_rows)))
    both = tmp_path / "both.parquet"
    pq.write_table(table, both)
    code, err = run_cli(capsys, "estimate", both, "--robot", "go2", "-o", tmp_path / "f.parquet")
    assert code == 0, err
    assert _line(err, "torque:") == "torque: joint torque sensors (tau.<joint>); the set-points q_des.<joint> not used"
    code, err = run_cli(capsys, "estimate", hung, "--robot", "go2", "-o", tmp_path / "g.parquet")
    assert code == 0 and _line(err, "torque:").startswith("torque: the drivers' PD law on q_des.<joint>"), err


def test_the_route_names_only_the_options_the_user_gave_as_unused(hung, tmp_path, capsys):
    code, err = run_cli(capsys, "estimate", hung, "--robot", "go2", "-o", tmp_path / "f.parquet", "--route", "momentum")
    route = _line(err, "route:")
    assert code == 0 and route.startswith("route: momentum") and "not used" not in route, err
    code, err = run_cli(capsys, "estimate", hung, "--robot", "go2", "-o", tmp_path / "f.parquet", "--route", "momentum",
                        "--diff", "savgol", "--window", "21")
    assert code == 0 and _line(err, "route:").endswith("; --window 21 not used (the acceleration route's filter; "
                                                       "--route acceleration keeps it)"), err
