"""The examples run as a user runs them (a fresh process, the public API), and print what they promise."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from helpers import KUKA, KUKA_CONFIG, KUKA_URDF, needs_kuka
from wbfriction.logs.source import read_log
from wbfriction.model import load_robot

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run_example(name: str, *args: str) -> str:
    res = subprocess.run([sys.executable, str(EXAMPLES / name), *args], capture_output=True, text=True,
                         env=dict(os.environ, MPLBACKEND="Agg"), timeout=900)
    assert res.returncode == 0, res.stderr
    return res.stdout


def numbers(pattern: str, text: str) -> list[float]:
    found = re.search(pattern, text)
    assert found, f"{pattern!r} not in:\n{text}"
    return [float(x) for x in found.groups()]


def test_every_example_is_run_here_or_by_the_readme():
    """Each example is run here, or among the README's commands with what it prints checked there
    (``tests/test_readme.py``: ``fleet_trends.py``, whose 24 logs would otherwise run twice)."""
    from test_readme import EXPECTED

    tested = set(re.findall(r'run_example\("([a-z0-9_]+\.py)"', Path(__file__).read_text()))
    by_readme = {Path(c.split()[1]).name for c in EXPECTED if c.startswith("python examples/")}
    assert tested | by_readme == {p.name for p in EXAMPLES.glob("*.py")} and not tested & by_readme


@pytest.mark.slow
def test_estimate_a_log():
    out = run_example("estimate_a_log.py", "--steps", "2")
    F_v, F_c, tau_os = numbers(r"leg_right_4_joint +\d+ +([\d.]+) ± +\S+ +([\d.]+) ± +\S+ +([\d.]+)", out)
    assert F_v == pytest.approx(0.2, rel=0.05) and F_c == pytest.approx(1.0, rel=0.02)  # Table 6.1's knee
    assert tau_os == pytest.approx(1.0, rel=0.02)


def test_your_own_robot():
    out = run_example("your_own_robot.py", "--steps", "2")
    assert "16 torque-controlled joints, 16 position-controlled" in out
    for side in ("left", "right"):
        F_v, F_c = numbers(rf"leg_{side}_4_joint: F_v ([\d.]+) \(true 0.3\), F_c ([\d.]+)", out)
        assert F_v == pytest.approx(0.3, rel=0.05) and F_c == pytest.approx(1.2, rel=0.03)


def test_ros2_bag():
    out = run_example("ros2_bag.py", "--steps", "2")
    assert ": a bag log" in out
    (diff,) = numbers(r"largest difference to the log's own estimate: (\S+) N·m", out)
    assert diff < 1e-9  # the bag carries the log's samples: the same estimate


@pytest.mark.slow
def test_identify_inertia():
    out = run_example("identify_inertia.py", "--steps", "2")
    given, with_friction, identified = numbers(r"given model ([\d.]+), given \+ its best friction ([\d.]+), "
                                               r"identified ([\d.]+)", out)
    assert identified < 0.1 * with_friction < given
    true, _, ident = numbers(r"true ([\d.]+), given ([\d.]+), identified ([\d.]+)", out)
    assert ident == pytest.approx(true, rel=0.01)
    assert "wrote" in out and Path(out.split("wrote ")[1].split(" ")[0]).is_file()


@needs_kuka
def test_kuka_lwr4_convert(tmp_path):
    """The real KUKA LWR4+ recordings into the log format, stamps untouched; the log then reads."""
    out = tmp_path / "runs12.parquet"
    text = run_example("kuka_lwr4_convert.py", str(KUKA / "measurements_1.npz"), str(KUKA / "measurements_2.npz"),
                       "-o", str(out))
    assert "10054 rows from 2 recording(s), 7 joints" in text and "stamps kept as recorded" in text
    robot = load_robot(urdf=KUKA_URDF, config=KUKA_CONFIG)
    log = read_log(out, robot)
    assert log.segments == [(0, 5027), (5027, 10054)]  # the half hour between the runs is a gap
    assert log.clock is not None and log.clock.kind == "jittered"


def test_quadruped_walk():
    """Three feet down: the swinging leg alone determined, every leg with the feet's forces, and then exact."""
    plain = run_example("quadruped_walk.py")
    three = re.findall(r"^(\w+_foot\+\w+_foot\+\w+_foot) \(\d+ samples\): determined (.*)$", plain, re.M)
    assert len(three) == 4
    for pattern, legs in three:
        swinging = {"FL", "FR", "RL", "RR"} - {f[:2] for f in pattern.split("+")}
        assert set(legs.split(", ")) == swinging
    forces = run_example("quadruped_walk.py", "--foot-forces", "3d")
    assert all(legs == "FL, FR, RL, RR" for legs in re.findall(r"\): determined (.*)$", forces, re.M))
    errors = [float(x) for x in re.findall(r"\(([\d.]+) % off\)", forces)]
    assert len(errors) == 24 and max(errors) < 1.0
