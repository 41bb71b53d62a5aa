"""The hung, PD-driven Go2 the replays' tests share (built once a module)."""

from __future__ import annotations

import pytest

from wbfriction.model import load_robot
from wbfriction.sim.pd_robot import build_pd_robot


@pytest.fixture(scope="module")
def go2():
    """The built-in ``go2``: hung, PD-driven."""
    return load_robot("go2")


@pytest.fixture(scope="module")
def mjr(go2):
    """Its MuJoCo model (:func:`~wbfriction.sim.pd_robot.build_pd_robot`)."""
    return build_pd_robot(go2)
