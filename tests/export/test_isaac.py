"""The Isaac Lab actuator YAML: read back by YAML 1.2 and 1.1 readers to the same floats, mapped as documented."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import load_yaml as load
from wbfriction.exceptions import InputError
from wbfriction.export.isaac import ISAAC_FIELDS, isaac_actuator_dict, write_isaac_yaml, yaml_float
from wbfriction.fit.result import FitResult
from wbfriction.friction.models import FrictionParams

YAML_1_1_FLOAT = re.compile(r"^[-+]?([0-9][0-9_]*)?\.[0-9.]*([eE][-+][0-9]+)?$")
"""The float of the YAML 1.1 type repository (yaml.org/type/float.html), what PyYAML resolves as a float."""




def test_round_trip_and_mapping(tmp_path, random_friction):
    """Written, read back (YAML 1.2 and 1.1): the document is isaac_actuator_dict's, every key
    matches its joint in full, and the values are (1 + S) F_c, F_c, F_v and the armature."""
    rng = np.random.default_rng(8)
    joints = ["lwr_0_joint", "lwr_1_joint", "wrist.roll-1"]
    friction = {n: FitResult(n, 100, params=p, success=True) for n, p in random_friction(joints[:2], rng).items()}
    friction["wrist.roll-1"] = FitResult("wrist.roll-1", 3)  # no parameters: armature only
    armature = {"lwr_1_joint": 1e-5 / 3, "wrist.roll-1": 0.02}
    path = tmp_path / "actuators.yaml"
    write_isaac_yaml(path, friction, armature)
    text = path.read_text()
    doc = isaac_actuator_dict(friction, armature)
    assert load(text) == load(text, (1, 1)) == doc
    assert [re.fullmatch(k, n) is not None for k, n in zip(doc["joint_names_expr"], joints)] == [True] * 3
    assert re.fullmatch(doc["joint_names_expr"][2], "wristXroll-1") is None  # the dot is not a wildcard
    by_joint = {f: {n: v for k, v in doc[f].items() for n in joints if re.fullmatch(k, n)} for f in ISAAC_FIELDS}
    for n in joints[:2]:
        p = friction[n].params
        assert by_joint["friction"][n] == (1 + p.S) * p.F_c
        assert by_joint["dynamic_friction"][n] == p.F_c
        assert by_joint["viscous_friction"][n] == p.F_v
        assert by_joint["dynamic_friction"][n] <= by_joint["friction"][n]  # PhysX: dynamic <= static
    assert by_joint["armature"] == {"lwr_1_joint": 1e-5 / 3, "wrist.roll-1": 0.02}
    assert "wrist.roll-1" not in by_joint["friction"]


def test_fields_without_values_are_left_out():
    doc = isaac_actuator_dict({"knee": FrictionParams(F_v=1.0, F_c=2.0)})
    assert list(doc) == ["joint_names_expr", "friction", "dynamic_friction", "viscous_friction"]


@settings(max_examples=200, deadline=None, derandomize=True)
@given(x=st.floats(0.0, 1e300) | st.floats(0.0, 1e-3) | st.integers(0, 10**6).map(float))
def test_yaml_float_is_read_back_exactly_by_yaml_1_1_and_1_2(x):
    text = yaml_float(x)
    assert YAML_1_1_FLOAT.match(text), text
    assert load(f"v: {text}")["v"] == load(f"v: {text}", (1, 1))["v"] == x


def test_refused_input(tmp_path):
    """(d) non-dissipative friction, and S < 0 (static friction below Coulomb: PhysX refuses it)."""
    path = tmp_path / "a.yaml"
    with pytest.raises(InputError, match="joint 'knee': F_c = -1 N·m < 0"):
        write_isaac_yaml(path, {"knee": FrictionParams(F_v=1.0, F_c=-1.0)})
    with pytest.raises(InputError, match="joint 'knee': static friction F_s = 0.8 N·m below the Coulomb friction"):
        write_isaac_yaml(path, {"knee": FrictionParams(F_v=1.0, F_c=1.0, S=-0.2)})
    assert not path.exists()
