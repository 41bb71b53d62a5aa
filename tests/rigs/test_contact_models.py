"""Issue 81, class 10 (second item): ``excite`` took any robot on four feet that do not fix its base for a
quadruped, without asking the contact model. A Go2 whose TOML says its feet are the toy contact model
(``toys/toy_contact.py``: three constraints, no single one fixing the base) is now refused in one line naming the
model, before the design; the built-in point feet still design."""

from __future__ import annotations

import pytest

from helpers import run_cli_printed, said
from toys.toy_contact import NAME, LocalPoint
from wbfriction.cli.common import config_text
from wbfriction.exceptions import InputError
from wbfriction.model.contacts import register_contact_model, unregister_contact_model
from wbfriction.model.loading import load_robot
from wbfriction.rigs import rig_for
from wbfriction.rigs.standing import require_feet

STANCE = "a quadruped's stance on three of four point feet"


@pytest.fixture
def toy_robot(tmp_path):
    """The built-in ``go2_walking``'s TOML with the toy contact model on its four feet (registered for the test)."""
    kind = register_contact_model(LocalPoint())
    text, _ = config_text("go2_walking", None)
    toml = tmp_path / "toy.toml"
    toml.write_text(text.replace('contact_model = "point"', f'contact_model = "{NAME}"')
                    .replace('name = "go2_walking"', 'name = "go2_toy"'))
    yield toml
    unregister_contact_model(kind.name)


def test_four_feet_of_another_model_are_not_a_quadrupeds(toy_robot):
    robot = load_robot(config=toy_robot)
    assert len(robot.contact_frames) == 4 and robot.partial_contacts  # what was counted
    with pytest.raises(InputError, match=rf"^robot 'go2_toy' stands on contact model '{NAME}' at 'FL_foot' "):
        require_feet(robot, 4, STANCE, model="point")
    require_feet(load_robot("go2_walking"), 4, STANCE, model="point")


def test_excite_refuses_them_in_one_line_before_the_design(toy_robot, capsys, tmp_path, monkeypatch):
    import wbfriction.excite.tripod as tripod

    def never(*args, **kwargs):
        raise AssertionError("the stance designed")

    monkeypatch.setattr(tripod, "tripod_reference", never)
    assert rig_for(load_robot(config=toy_robot)).name == "quadruped"  # its simulation refuses them likewise
    code, _, err = run_cli_printed(capsys, "excite", "--config", toy_robot, "-o", tmp_path / "d.parquet")
    lines = said(err)
    assert code == 2 and len(lines) == 1, err
    assert f"contact model '{NAME}' at 'FL_foot' ({LocalPoint.what}), not 'point': excite designs {STANCE}" in lines[0]
    assert not (tmp_path / "d.parquet").exists()
