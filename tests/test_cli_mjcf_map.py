"""The command line with a robot from MJCF (--mjcf) and a table log read through a map (--map): the same
friction table as with the URDF and the log as written."""

from __future__ import annotations

import numpy as np
import pyarrow.parquet as pq
import pytest

from helpers import assert_one_line_error, mapped_copy, run
from wbfriction.export.mjcf import write_mjcf
from wbfriction.logs.log import write_log


@pytest.fixture(scope="module")
def walk(talos, tmp_path_factory):
    """A one-step walk of the ideal simulator, TALOS's MJCF (written at test time) and a robot TOML."""
    from wbfriction.sim import simulate_ideal
    from wbfriction.walking import GaitOptions, walking_reference

    out = tmp_path_factory.mktemp("mjcf_map")
    sim = simulate_ideal(talos, walking_reference(talos, GaitOptions(gait="forward", steps=1)))
    write_log(sim.log, talos, out / "walk.parquet")
    write_mjcf(talos, {}, out / "talos.xml")
    (out / "robot.toml").write_text('name = "mine"\nposition_controlled = ["head_1_joint", "head_2_joint"]\n'
                                    'contact_frames = ["left_sole_link", "right_sole_link"]\n')
    res = run("estimate", out / "walk.parquet", "--urdf", talos.urdf, "--config", out / "robot.toml",
              "-o", out / "urdf.parquet")
    assert res.returncode == 0, res.stderr
    return out


def assert_same_table(a, b, exact: bool = True):
    """The same columns, the same flags, phases and routes, and the same numbers (to rounding unless ``exact``:
    the MJCF's inertias are MuJoCo's principal axes of the URDF's, equal to about 1e-16 relative)."""
    ta, tb = pq.read_table(a), pq.read_table(b)
    assert ta.column_names == tb.column_names
    for name in ta.column_names:
        x, y = ta.column(name).to_numpy(), tb.column(name).to_numpy()
        if exact or x.dtype.kind != "f":
            np.testing.assert_array_equal(x, y, err_msg=name)
        else:
            np.testing.assert_allclose(x, y, rtol=1e-9, atol=1e-9, err_msg=name)


def test_estimate_with_mjcf_gives_the_urdf_table(talos, walk, tmp_path):
    res = run("estimate", walk / "walk.parquet", "--mjcf", walk / "talos.xml", "--config", walk / "robot.toml",
              "-o", tmp_path / "mjcf.parquet")
    assert res.returncode == 0, res.stderr
    assert_same_table(walk / "urdf.parquet", tmp_path / "mjcf.parquet", exact=False)
    assert_one_line_error(run("estimate", walk / "walk.parquet", "--mjcf", walk / "talos.xml", "--urdf", talos.urdf,
                              "-o", tmp_path / "x.parquet"), "--urdf or its --mjcf, not both")
    assert_one_line_error(run("identify", walk / "walk.parquet", "--mjcf", walk / "talos.xml",
                              "-o", tmp_path / "x.urdf"), "identify (it writes the corrected URDF) needs")


def test_estimate_through_a_map_gives_the_logs_table(talos, walk, tmp_path):
    table = pq.read_table(walk / "walk.parquet")
    mapped, toml = mapped_copy(table, talos.contact_frames)
    pq.write_table(mapped, tmp_path / "renamed.parquet")
    (tmp_path / "map.toml").write_text(toml)
    res = run("estimate", tmp_path / "renamed.parquet", "--map", tmp_path / "map.toml", "--config",
              walk / "robot.toml", "--urdf", talos.urdf, "-o", tmp_path / "mapped.parquet")
    assert res.returncode == 0, res.stderr
    assert_same_table(walk / "urdf.parquet", tmp_path / "mapped.parquet")
    (tmp_path / "map.toml").write_text(toml.replace('"leg_left_4_joint"', '"knee"'))
    assert_one_line_error(run("convert", tmp_path / "renamed.parquet", "--map", tmp_path / "map.toml",
                              "-o", tmp_path / "x.parquet"), "rename LLeg_knee = 'knee': not a joint of robot 'talos'")
