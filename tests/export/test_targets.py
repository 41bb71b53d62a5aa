"""Export targets by suffix (issue 54): a format plugs in with one class and one call, and `export_files` writes it
as it writes the built-in ones; a suffix no target writes is refused, naming the file and the formats known."""

from __future__ import annotations

import csv
import re
from pathlib import Path

import pytest

from toys.toy_target import FrictionCsv
from wbfriction.exceptions import InputError
from wbfriction.export import catalog, registry
from wbfriction.export.isaac import IsaacTarget
from wbfriction.export.mjcf import MjcfTarget
from wbfriction.export.registry import SuffixTaken, UnknownExportFormat, register_target, target_for
from wbfriction.export.urdf import UrdfTarget
from wbfriction.fit.params_file import write_params
from wbfriction.model import load_robot
from wbfriction.pipeline.export_step import export_files


@pytest.fixture()
def targets(monkeypatch):
    """The registry as it is, restored after the test."""
    monkeypatch.setattr(registry, "TARGETS", registry.TARGETS.copy())
    monkeypatch.setattr(catalog, "KINDS", dict(catalog.KINDS))  # what the help and errors name
    return registry.TARGETS


@pytest.fixture(scope="module")
def panda():
    return load_robot("panda")


@pytest.fixture()
def params(tmp_path, fit_of):
    """Fits of the Panda as `fit` writes them: A1, A2, A4-A6 ok (each its own numbers), A3 weak, A7 not fitted."""
    fits = [fit_of(f"panda_joint{i}", "weak" if i == 3 else "ok", F_v=0.1 * i, F_c=0.3 * i) for i in range(1, 7)]
    path = tmp_path / "p.json"
    write_params(path, fits, {"provenance": {"robot": "panda"}})
    return path, {f.joint: f for f in fits}


def test_a_registered_target_writes_the_fitted_values(targets, panda, params, tmp_path):
    """One call registers the toy target; `export_files` picks it by suffix (any case), beside a built-in one, and
    its file holds the fitted F_c and F_v of the fits that qualify, in the robot's order, exactly."""
    register_target(FrictionCsv())
    path, fits = params
    outs = [tmp_path / "friction.CSV", tmp_path / "panda.yaml"]
    done = export_files(panda, path, outs)
    assert done.outputs == ((outs[0], FrictionCsv.name), (outs[1], "isaac"))
    ok = [f"panda_joint{i}" for i in (1, 2, 4, 5, 6)]
    assert [r.joints for r in done.reports] == [tuple(ok)] * 2
    with outs[0].open(newline="") as f:
        rows = list(csv.DictReader(f))
    assert [r["joint"] for r in rows] == ok
    for row in rows:
        params_of = fits[row["joint"]].params
        assert (float(row["F_c"]), float(row["F_v"])) == (params_of.F_c, params_of.F_v)

    export_files(panda, path, [outs[0]], include=["weak"])
    with outs[0].open(newline="") as f:
        assert [r["joint"] for r in csv.DictReader(f)] == [f"panda_joint{i}" for i in range(1, 7)]


def test_an_unknown_suffix_is_refused_naming_the_file(targets, panda, params, tmp_path):
    """Before the toy target is registered, a .csv output is refused before anything is written (one line: the
    file and the formats known); the built-in formats by their first suffix, the new one once registered."""
    path, _ = params
    out = tmp_path / "friction.csv"
    with pytest.raises(UnknownExportFormat) as info:
        export_files(panda, path, [tmp_path / "panda.xml", out])
    assert str(info.value) == (f"{out}: unknown export format: name it .urdf (URDF <dynamics damping "
                               "friction>), .xml (MuJoCo MJCF: damping, frictionloss, armature) or .yaml (Isaac Lab "
                               "actuators)")
    assert isinstance(info.value, InputError) and (info.value.path, info.value.suffix) == (out, ".csv")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.json"]
    register_target(FrictionCsv())
    with pytest.raises(InputError, match=re.escape("or .csv (joint, F_c, F_v)")):
        target_for(tmp_path / "friction.txt")
    with pytest.raises(InputError, match=r"^export: give at least one output \(-o FILE.urdf, .xml, .yaml or .csv\)$"):
        export_files(panda, path, [])


def test_the_built_in_targets_by_suffix(targets):
    """Each suffix the export wrote before the registry, by the same target; a suffix taken is refused."""
    by_suffix = {s: type(target_for(Path(f"x{s}"))) for s in (".urdf", ".xml", ".mjcf", ".yaml", ".yml", ".URDF")}
    assert by_suffix == {".urdf": UrdfTarget, ".xml": MjcfTarget, ".mjcf": MjcfTarget, ".yaml": IsaacTarget,
                         ".yml": IsaacTarget, ".URDF": UrdfTarget}

    class Other(FrictionCsv):
        name = "other"
        suffixes = (".csv", ".xml")

    with pytest.raises(SuffixTaken, match="'other': .xml is written by the 'mjcf' target"):
        register_target(Other())
    assert "other" not in targets and ".csv" not in {s for t in targets for s in t.suffixes}


def test_the_catalogue_the_help_reads_is_the_registrys():
    """``export --help`` and the unknown-suffix error name the targets from their catalogue
    (:mod:`wbfriction.export.catalog`, which imports nothing heavy): it is the registry's, target by target, in order,
    and a built-in target's name, suffixes and description are its kind's (issue 65, class 7)."""
    assert catalog.known_targets() == tuple(f"{t.suffixes[0]} ({t.description})" for t in registry.targets())
    assert tuple(catalog.KINDS) == tuple(t.name for t in registry.targets())
    assert catalog.BUILTIN == tuple(catalog.TargetKind.of(t) for t in registry.targets()[:len(catalog.BUILTIN)])
