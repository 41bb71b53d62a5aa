"""A new contact model is one file and one registry entry (issue 65): a toy contact model (``toys/toy_contact.py``:
a point foot written in the frame's own axes), registered with one call, reaches every command that takes a robot's
contact model (run in this process, as ``docs/extending.md`` says registration reaches).

* A Go2 trot simulated with the built-in ``point`` feet (``go2_walking``), then read with a copy of its TOML whose
  ``contact_model`` is the toy's: ``estimate`` (both routes) gives the point model's friction and determination,
  ``fit``, ``predict`` and ``report`` read it, ``identify`` identifies the inertias and friction from it.
* ``simulate`` refuses the toy robot in one line naming the model: the quadruped simulators model point feet only.
* The registry refuses a second model of a name, and a TOML naming a model nobody registered is one line naming the
  file and the registered models.
"""

from __future__ import annotations

import json

import numpy as np
import pinocchio as pin
import pytest

from helpers import run_cli_printed, said
from toys.toy_contact import NAME, LocalPoint
from wbfriction.cli.common import config_text
from wbfriction.exceptions import InputError
from wbfriction.logs.tables import read_table
from wbfriction.model.contacts import (
    Point,
    contact_model_of,
    contact_models,
    register_contact_model,
    unregister_contact_model,
)
from wbfriction.model.determination import contact_jacobian, measured_components
from wbfriction.model.loading import load_robot


@pytest.fixture
def local_point():
    """The toy contact model registered (one call), and forgotten after the test."""
    kind = register_contact_model(LocalPoint())
    yield kind
    unregister_contact_model(kind.name)


def toy_toml(path, kind: str = NAME):
    """The built-in ``go2_walking``'s TOML (no foot radius) with ``contact_model = kind``, named ``go2_toy``."""
    text, _ = config_text("go2_walking", None)
    assert 'contact_model = "point"' in text and "foot_radius" not in text
    path.write_text(text.replace('contact_model = "point"', f'contact_model = "{kind}"')
                    .replace('name = "go2_walking"', 'name = "go2_toy"'))
    return path


def test_a_toy_contact_model_runs_every_command_that_takes_the_robot(local_point, tmp_path, cli, capsys):
    """The trot of the point-footed Go2 estimated with the toy robot: the same friction (to 1e-8 N·m) on the same
    determined samples as the point model's, by either route; then fitted, predicted, reported and identified with
    the toy robot; and its simulation refused in one line naming the toy model."""
    log, toml = tmp_path / "trot.parquet", toy_toml(tmp_path / "toy.toml")
    cli("simulate", "--robot", "go2_walking", "--duration", "2", "-o", log)
    toy = load_robot(config=toml)
    assert toy.contact_kinds == (NAME,) * 4 and toy.contact_dims == (3,) * 4 and toy.partial_contacts
    assert toy.stands_on == LocalPoint.plural

    for route in ("momentum", "acceleration"):
        point_out, toy_out = tmp_path / f"point_{route}.parquet", tmp_path / f"toy_{route}.parquet"
        printed: dict[str, str] = {}
        runs = (("point", ("--robot", "go2_walking"), point_out), ("toy", ("--config", toml), toy_out))
        for name, given, out in runs:
            code, _, err = run_cli_printed(capsys, "estimate", log, *given, "--route", route, "-o", out)
            assert code == 0, err
            printed[name] = "\n".join(said(err)).replace(str(out), "OUT")  # the stages' lines hold their times
        assert "determined" in printed["toy"] and printed["toy"] == printed["point"]  # the same shares, as for points
        point, other = read_table(point_out), read_table(toy_out)
        for joint in toy.torque_controlled:
            flags = other[f"determined.{joint}"].to_numpy()
            np.testing.assert_array_equal(flags, point[f"determined.{joint}"].to_numpy())
            a, b = point[f"tau_f.{joint}"].to_numpy(), other[f"tau_f.{joint}"].to_numpy()
            np.testing.assert_array_equal(np.isnan(a), np.isnan(b))
            np.testing.assert_allclose(b, a, rtol=0, atol=1e-8, equal_nan=True)
        assert 0 < np.mean([other[f"determined.{j}"].to_numpy().mean() for j in toy.torque_controlled]) < 1

    friction, params = tmp_path / "toy_momentum.parquet", tmp_path / "params.json"
    cli("fit", friction, "--terms", "none", "-o", params)
    fits = json.loads(params.read_text())["joints"]
    assert set(fits) == set(toy.torque_controlled)
    cli("predict", friction, "--params", params)
    cli("report", friction, "--params", params, "-o", tmp_path / "report.html")
    assert (tmp_path / "report.html").stat().st_size > 0
    cli("identify", log, "--config", toml, "--passes", "1", "--holdout", "0.3", "-o", tmp_path / "identified.urdf")
    assert pin.buildModelFromUrdf(str(tmp_path / "identified.urdf")).nv == toy.model.nv - 6

    code, _, err = run_cli_printed(capsys, "simulate", "--config", toml, "--duration", "1",
                                   "-o", tmp_path / "never.parquet")
    lines = said(err)
    assert code == 2 and len(lines) == 1, err
    assert f"not contact model '{NAME}' of 'FL_foot': {LocalPoint.what}" in lines[0] and "point feet only" in lines[0]
    assert not (tmp_path / "never.parquet").exists()


def test_the_toy_jacobian_spans_the_point_constraint(local_point, tmp_path):
    """At a configuration of the walking Go2, the toy's rows are the point foot's (no radius) in the frame's axes,
    ``R^T J_point``; foot sensors' world-axes columns are not read for it (its force is in other axes)."""
    toy, point = load_robot(config=toy_toml(tmp_path / "toy.toml")), load_robot("go2_walking")
    q = pin.randomConfiguration(point.model, -np.ones(point.model.nq), np.ones(point.model.nq))
    q[3:7] /= np.linalg.norm(q[3:7])
    data_toy, data_point = toy.model.createData(), point.model.createData()
    for robot, data in ((toy, data_toy), (point, data_point)):
        pin.computeJointJacobians(robot.model, data, q)
        pin.updateFramePlacements(robot.model, data)
    for c, fid in enumerate(point.contact_frame_ids):
        R = data_point.oMf[fid].rotation
        np.testing.assert_allclose(contact_jacobian(toy, data_toy, c), R.T @ contact_jacobian(point, data_point, c),
                                   atol=1e-12)
    forces = np.zeros((5, 4, 3))
    assert measured_components(point, forces).all() and not measured_components(toy, forces).any()


def test_the_registry_refuses_a_second_model_of_a_name(local_point):
    """A name is registered once (built-in or not), a model unknown is named with the registered ones."""
    assert [m.name for m in contact_models()][:2] == ["sole", "point"] and contact_model_of(NAME) is local_point
    with pytest.raises(ValueError, match=f"a contact model named '{NAME}' is registered already"):
        register_contact_model(LocalPoint())
    with pytest.raises(ValueError, match="a contact model named 'point' is registered already"):
        register_contact_model(Point())
    with pytest.raises(InputError, match="unknown contact model 'ball': choose one of sole, point, local-point"):
        contact_model_of("ball")
    with pytest.raises(ValueError, match="no contact model named 'ball'"):
        unregister_contact_model("ball")


def test_an_unknown_contact_model_in_a_toml_is_one_line_naming_the_file(tmp_path, capsys):
    """The toy's TOML read where the toy is not registered: one line naming the file, the frame and the registered
    models, before any work."""
    toml = toy_toml(tmp_path / "toy.toml")
    with pytest.raises(InputError) as caught:
        load_robot(config=toml)
    assert "\n" not in str(caught.value)
    assert str(caught.value).startswith(str(toml)), caught.value
    assert f"contact_model of 'FL_foot' is '{NAME}': choose one of the registered contact models, sole, point" \
        in str(caught.value)
    code, _, err = run_cli_printed(capsys, "simulate", "--config", toml, "-o", tmp_path / "never.parquet")
    lines = said(err)
    assert code == 2 and len(lines) == 1 and str(toml.name) in lines[0], err
