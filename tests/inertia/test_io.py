"""The identification JSON: what is written reads back as the same typed result; the reader refuses what
its writer would not have written, naming the key."""

from __future__ import annotations

import json

import pytest

from wbfriction.exceptions import InputError
from wbfriction.inertia.document import Identification
from wbfriction.inertia.io import read_identification, write_identification

DOC = {
    "passes": [{"stribeck_velocity": 0.2, "samples": 100,
                "not_excited": [{"parameter": "hand.m", "information": 0.0, "partners": {"wrist.c_z": -0.3}}]}],
    "holdout_samples": 20,
    "bodies": [{"body": "root_joint", "mass_given": 10.0, "mass": 9.5, "com_shift": 0.001}],
    "joints": {"knee": {"holdout_rms": {"given": 1.0, "given_with_friction": 0.5, "identified": 0.01},
                        "identified": {"F_v": 0.2, "F_c": 1.0, "tau_os": 0.9},
                        "armature": {"given": 0.0, "identified": 0.3}}},
}


def test_what_is_written_reads_back(tmp_path):
    """A minimal document reads as the typed result, and that result writes back the same values and
    reads again to an equal result."""
    (tmp_path / "i.json").write_text(json.dumps(DOC))
    result = read_identification(tmp_path / "i.json")
    assert result.joints["knee"].identified == DOC["joints"]["knee"]["identified"]
    assert result.joints["knee"].armature == 0.3 and result.joints["knee"].holdout_rms.validated is None
    assert result.passes[0].not_excited[0].partners == {"wrist.c_z": -0.3}
    assert result.bodies[0].mass_change is None and result.bodies[0].kept is None
    write_identification(tmp_path / "j.json", result)
    again = read_identification(tmp_path / "j.json")
    assert again == result and isinstance(again, Identification)
    written = json.loads((tmp_path / "j.json").read_text())
    for path in (("holdout_samples",), ("joints", "knee", "holdout_rms"), ("joints", "knee", "identified"),
                 ("bodies", 0, "mass"), ("passes", 0, "not_excited", 0, "partners")):
        a, b = DOC, written
        for k in path:
            a, b = a[k], b[k]
        assert a == b, path


@pytest.mark.parametrize(("damage", "key"), [
    (lambda d: d.pop("joints"), "joints"),
    (lambda d: d["joints"]["knee"]["holdout_rms"].pop("identified"), "joints.knee.holdout_rms"),
    (lambda d: d["joints"]["knee"]["identified"].update(F_v="x"), "joints.knee.identified"),
    (lambda d: d["bodies"][0].pop("mass"), "bodies"),
    (lambda d: d.update(passes=[]), "passes"),
    (lambda d: d.update(holdout_samples=1.5), "holdout_samples"),
    (lambda d: d["joints"]["knee"]["armature"].pop("identified"), "joints.knee.armature"),
    (lambda d: d["passes"][0]["not_excited"][0].update(partners=None), r"passes\[0\].not_excited"),
    (lambda d: d["passes"][0].pop("samples"), r"passes\[0\].samples"),
    (lambda d: d["joints"]["knee"].update(acceleration_route={"model": "no such model"}),
     "joints.knee.acceleration_route"),
])
def test_a_damaged_document_names_its_key(tmp_path, damage, key):
    doc = json.loads(json.dumps(DOC))
    damage(doc)
    (tmp_path / "i.json").write_text(json.dumps(doc))
    with pytest.raises(InputError, match=f"'{key}' is missing or malformed"):
        read_identification(tmp_path / "i.json")


def test_not_json_at_all(tmp_path):
    (tmp_path / "i.json").write_bytes(b"\xff\xfe")
    with pytest.raises(InputError, match="not an identification written by 'wbfriction identify --json'"):
        read_identification(tmp_path / "i.json")



def test_an_identification_with_numbers_not_finite_writes_null(tmp_path):
    """Issue 63: a value that is not finite (a friction parameter not determined) is written ``null``, not ``NaN``."""
    import dataclasses

    from helpers import strict_json

    (tmp_path / "i.json").write_text(json.dumps(DOC))
    result = read_identification(tmp_path / "i.json")
    knee = result.joints["knee"]
    joints = {"knee": dataclasses.replace(knee, identified={**knee.identified, "F_c": float("nan")})}
    write_identification(tmp_path / "n.json", dataclasses.replace(result, joints=joints))
    assert strict_json(tmp_path / "n.json")["joints"]["knee"]["identified"]["F_c"] is None
