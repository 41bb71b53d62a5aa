"""``identify --config-output``: the robot's configuration rewritten for the identified model, everything else kept."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from wbfriction.exceptions import InputError
from wbfriction.pipeline.identify_step import identified_config

GIVEN = """\
# my arm
name = "arm"
urdf = "robots/arm.urdf"   # the given model
srdf = "robots/arm.srdf"
floating_base = false

[torque_constants]   # N·m/A
j1 = 10.0

[armature]
j1 = 0.5
j2 = 0.1

[labels]
j1 = "shoulder"
"""


def test_the_urdf_and_the_armature_are_replaced_and_the_rest_kept(tmp_path):
    source, out = tmp_path / "in", tmp_path / "out" / "arm_identified.toml"
    text = identified_config(GIVEN, source, tmp_path / "out" / "arm_identified.urdf", out, {"j1": 0.25, "j2": 0.125})
    doc = tomllib.loads(text)
    assert doc["urdf"] == "arm_identified.urdf" and doc["armature"] == {"j1": 0.25, "j2": 0.125}
    assert doc["srdf"] == "../in/robots/arm.srdf"  # relative to the new file's folder, the same file
    assert (out.parent / doc["srdf"]).resolve() == (source / "robots" / "arm.srdf").resolve()
    given = tomllib.loads(GIVEN)
    assert {k: v for k, v in doc.items() if k not in ("urdf", "srdf", "armature")} == {
        k: v for k, v in given.items() if k not in ("urdf", "srdf", "armature")}
    assert "# my arm" in text and "[torque_constants]   # N·m/A" in text  # comments kept


def test_without_an_identified_armature_the_given_one_stays(tmp_path):
    text = identified_config(GIVEN, tmp_path, tmp_path / "id.urdf", tmp_path / "id.toml", None)
    assert tomllib.loads(text)["armature"] == {"j1": 0.5, "j2": 0.1}


def test_a_configuration_it_cannot_rewrite_is_refused(tmp_path):
    dotted = GIVEN.replace("[armature]\nj1 = 0.5\nj2 = 0.1\n", "").replace("floating_base = false\n",
                                                                           "floating_base = false\narmature.j1 = 0.5\n")
    assert tomllib.loads(dotted)["armature"] == {"j1": 0.5}
    with pytest.raises(InputError, match="id.toml: the robot's configuration could not be rewritten"):
        identified_config(dotted, tmp_path, tmp_path / "id.urdf", tmp_path / "id.toml", {"j1": 0.2})


def test_a_built_in_configuration_keeps_its_package_paths(tmp_path):
    from importlib import resources

    text = resources.files("wbfriction.model.robots").joinpath("talos.toml").read_text()
    doc = tomllib.loads(identified_config(text, Path("."), tmp_path / "talos_id.urdf", tmp_path / "talos.toml", None))
    assert doc["srdf"].startswith("example-robot-data:") and doc["urdf"] == "talos_id.urdf"
