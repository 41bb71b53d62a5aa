"""Which fits are exported (issue 37): status ok by default, weak and at bound on request, not excited and
failed never; each exported joint's status beside it in every format; nothing written when nothing qualifies."""

from __future__ import annotations

import re

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lxml import etree as ET
from ruamel.yaml import YAML

from wbfriction.exceptions import InputError
from wbfriction.export.mapping import (
    INCLUDE_CHOICES,
    NOT_FITTED,
    JointExport,
    check_include,
    joint_export,
    select_fits,
    status_note,
)
from wbfriction.export.mjcf import write_mjcf
from wbfriction.fit.params_file import write_params
from wbfriction.fit.result import FitResult
from wbfriction.fit.status import FitVerdict
from wbfriction.friction.models import FrictionParams
from wbfriction.model import load_robot
from wbfriction.pipeline.export_step import export_files

STATUSES = ("ok", "weak", "at bound", "not excited", "failed")


@pytest.fixture(scope="module")
def panda():
    return load_robot("panda")


def test_by_default_only_ok_fits_are_exported(panda, fit_of):
    """Every status once: ok exported; the others and the joints without a fit listed by status, in the
    robot's joint order."""
    j = panda.actuated
    fits = {j[0]: fit_of(j[0], "ok"), j[1]: fit_of(j[1], "weak"), j[2]: fit_of(j[2], "at bound"),
            j[3]: fit_of(j[3], "not excited"), j[4]: fit_of(j[4], "failed"), j[5]: fit_of(j[5], "ok"),
            j[6]: FitResult(j[6], 3, message="not fitted: 3 valid samples")}
    sel = select_fits(fits, panda)
    assert list(sel.exported) == [j[0], j[5]] and sel.exported_statuses == {"ok": 2}
    assert dict(sel.left_out) == {"weak": (j[1],), "at bound": (j[2],), "not excited": (j[3], j[6]),
                                  "failed": (j[4],)}
    del fits[j[6]]
    assert select_fits(fits, panda).left_out[NOT_FITTED] == (j[6],)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(statuses=st.lists(st.sampled_from((*STATUSES, NOT_FITTED)), min_size=7, max_size=7),
       include=st.lists(st.sampled_from(INCLUDE_CHOICES), max_size=3))
def test_selection_partitions_the_joints_and_never_exports_what_the_data_do_not_carry(panda, fit_of, statuses,
                                                                                      include):
    """Over any mix of statuses and choices: every actuated joint is either exported or left out under its
    status, once; exported are exactly the ok ones and those included; not excited and failed never."""
    fits = {j: fit_of(j, s) for j, s in zip(panda.actuated, statuses) if s != NOT_FITTED}
    wanted = {"ok", *(c.replace("-", " ") for c in include)}
    expected = [j for j, s in zip(panda.actuated, statuses) if s in wanted]
    if not expected:
        with pytest.raises(InputError, match="^p.json: no fit qualifies for export"):
            select_fits(fits, panda, include, "p.json") if fits else select_fits({}, panda, include, "p.json")
        return
    sel = select_fits(fits, panda, include)
    assert list(sel.exported) == expected
    assert sum(sel.exported_statuses.values()) == len(expected) and set(sel.exported_statuses) <= wanted
    left = [j for joints in sel.left_out.values() for j in joints]
    assert sorted(left + expected) == sorted(panda.actuated) and len(set(left)) == len(left)
    for status, joints in sel.left_out.items():
        assert [s for j, s in zip(panda.actuated, statuses) if j in joints] == [status] * len(joints)
    assert not {"not excited", "failed"} & {f.verdict().status for f in sel.exported.values()}


def test_include_is_checked_where_it_is_defined():
    assert check_include(["at-bound", "weak", "weak"]) == ("at-bound", "weak")
    assert check_include([]) == ()
    with pytest.raises(InputError,
                       match="^--include: 'strong' is not one of weak, at-bound, routes-disagree, does-not-predict$"):
        check_include(["weak", "strong"])
    for never in ("not-excited", "failed", "not-fitted", "not excited"):
        with pytest.raises(InputError, match=f"^--include: '{never}' .*has no numbers the data carry"):
            check_include([never])
    with pytest.raises(InputError, match="^--include: 'ok' .*always exported$"):
        check_include(["ok"])
    with pytest.raises(InputError, match="^--include: 'at bound' is not one of"):
        check_include(["at bound"])  # the option's spelling is at-bound


def test_nothing_to_export_is_one_line(panda, fit_of):
    """A file without joints, or without a fit that qualifies: one line that counts the statuses and says
    which --include would export some."""
    with pytest.raises(InputError, match="^p.json: no joints: nothing to export$"):
        select_fits({}, panda, (), "p.json")
    j = panda.actuated
    fits = {j[0]: fit_of(j[0], "not excited"), j[1]: fit_of(j[1], "weak"), j[2]: fit_of(j[2], "weak"),
            j[3]: fit_of(j[3], "failed")}
    with pytest.raises(InputError, match=r"^p.json: no fit qualifies for export \(1 not excited, 2 weak, 1 failed\): "
                                         r"--include weak exports those$"):
        select_fits(fits, panda, (), "p.json")
    del fits[j[1]], fits[j[2]]
    with pytest.raises(InputError, match=r"^p.json: no fit qualifies for export \(1 not excited, 1 failed\)$"):
        select_fits(fits, panda, ["weak"], "p.json")
    with pytest.raises(InputError, match="'elbow' is not an actuated joint of robot 'panda'"):
        select_fits({"elbow": fit_of("elbow", "not excited")}, panda)


def test_a_fit_whose_numbers_are_not_the_datas_is_refused_at_the_mapping(fit_of):
    """Whoever calls the writers: a not excited or failed fit with parameters is refused, naming the joint;
    a fit without parameters exports no friction; bare parameters have no status."""
    for status in ("not excited", "failed"):
        with pytest.raises(InputError, match=f"^joint 'hip': its fit is {status}: "):
            joint_export("hip", fit_of("hip", status, F_v=38.8))
    for status in ("ok", "weak", "at bound"):
        exp = joint_export("hip", fit_of("hip", status))
        assert exp.verdict is not None and exp.verdict.status == status and exp.viscous == 0.2
    assert joint_export("hip", FitResult("hip", 3)).has_friction is False
    assert joint_export("hip", FrictionParams(F_v=0.2, F_c=1.0)).verdict is None


@settings(max_examples=200, deadline=None, derandomize=True)
@given(status=st.sampled_from(STATUSES), reason=st.text(alphabet=st.characters(blacklist_categories=("Cs", "Cc"))
                                                       | st.sampled_from(["-", "\n", "\t", "\r"]), max_size=40))
def test_the_status_note_is_one_line_that_xml_and_yaml_read_as_a_comment(status, reason):
    """Whatever the reason says (dashes, line breaks, quotes, '#'): one line, a valid XML comment, a YAML
    comment that leaves the document as it is, with the status and the reason's words."""
    note = status_note(JointExport("knee", 0.2, 1.0, 1.3, verdict=FitVerdict(status, reason)))
    assert note is not None and "\n" not in note and "\r" not in note
    assert note.startswith(f"wbfriction fit of knee: {status}")
    assert re.sub(r"[\s-]", "", note).endswith(re.sub(r"[\s-]", "", reason) + (")" if reason.strip() else ""))
    xml = ET.fromstring(f"<joint><!-- {note} --><dynamics/></joint>".encode())
    assert xml[0].tag is ET.Comment and xml[1].tag == "dynamics"
    assert YAML(typ="safe", pure=True).load(f'joint_names_expr:\n  - "knee"  # {note}\n') == {
        "joint_names_expr": ["knee"]}
    assert status_note(JointExport("knee", 0.2, 1.0, 1.3)) is None  # bare parameters: no status
    assert status_note(JointExport("knee", armature=0.1, verdict=FitVerdict(status))) is None  # no friction


def write_fits(path, fits: dict[str, FitResult]) -> None:
    write_params(path, fits.values(), {"provenance": {"robot": "talos"}})


def talos_fits(talos, fit_of) -> dict[str, FitResult]:
    """The issue's TALOS walk as `fit` judged it: the hip yaws did not move (F_v 38.8 from the solver against
    the walk's 0.2), nor did the torso and arms (20 joints with tiny numbers); the other leg joints are ok,
    the left knee weak; the head has no fit."""
    fits = {}
    for j in talos.torque_controlled:
        if j in ("leg_left_1_joint", "leg_right_1_joint"):
            fits[j] = fit_of(j, "not excited", F_v=38.8, F_c=0.9)
        elif j.startswith("leg_"):
            fits[j] = fit_of(j, "weak" if j == "leg_left_4_joint" else "ok", F_v=0.2 + 0.01 * len(fits))
        else:
            fits[j] = fit_of(j, "not excited", F_v=0.01, F_c=0.003)
    return fits


def comments_before(root: ET._Element, tag: str) -> dict[str, str]:
    """Joint name -> the comment right before its ``tag`` element (``<joint>`` in MJCF, ``<dynamics>`` in a
    URDF's joint)."""
    out = {}
    for e in root.iter(tag):
        prev = e.getprevious()
        if prev is not None and prev.tag is ET.Comment:
            name = e.get("name") if tag == "joint" else e.getparent().get("name")
            out[name] = prev.text.strip()
    return out


def test_talos_not_excited_hip_yaw_is_not_exported(talos, fit_of, tmp_path):
    """Issue 37's repro: a hip yaw `fit` called not excited (F_v 38.8) and the 20 torso and arm joints that
    never moved are not exported by default; the joints not exported hold no friction in the MJCF and the URDF
    alike (issue 67: the URDF's <dynamics> set to 0; Isaac Lab: no entry); the exported
    ones carry the JSON's numbers and a comment with their status. With --include weak the weak knee is
    exported, with its reason; the same input gives the same bytes."""
    fits = talos_fits(talos, fit_of)
    params = tmp_path / "p.json"
    write_fits(params, fits)
    outs = [tmp_path / "t.xml", tmp_path / "t.urdf", tmp_path / "t.yaml"]
    export_files(talos, params, outs)
    ok = [j for j, f in fits.items() if f.verdict().ok]
    assert len(ok) == 9
    mj = mujoco.MjModel.from_xml_path(str(outs[0]))
    for j in talos.actuated:
        dof = mj.joint(j).dofadr[0]
        want = (fits[j].params.F_v, fits[j].params.F_c) if j in ok else (0.0, 0.0)
        assert (mj.dof_damping[dof], mj.dof_frictionloss[dof]) == want, j
    mjcf_notes = comments_before(ET.parse(str(outs[0])).getroot(), "joint")
    assert mjcf_notes == {j: f"wbfriction fit of {j}: ok" for j in ok}
    original = {j.get("name"): j.find("dynamics") for j in ET.parse(str(talos.urdf)).getroot().findall("joint")}
    urdf = ET.parse(str(outs[1])).getroot()
    for joint in urdf.findall("joint"):
        name, dyn = joint.get("name"), joint.find("dynamics")
        if name in ok:
            assert (float(dyn.get("damping")), float(dyn.get("friction"))) == (fits[name].params.F_v,
                                                                              fits[name].params.F_c)
        elif original[name] is None:
            assert dyn is None, name
        elif name in talos.actuated:
            assert (float(dyn.get("damping")), float(dyn.get("friction"))) == (0.0, 0.0), name
        else:
            assert dyn.attrib == original[name].attrib, name
    assert comments_before(urdf, "dynamics") == mjcf_notes
    yaml_text = outs[2].read_text()
    doc = YAML(typ="safe", pure=True).load(yaml_text)
    assert doc["joint_names_expr"] == ok and list(doc["viscous_friction"]) == ok
    assert [ln.split("# ", 1)[1] for ln in yaml_text.splitlines() if ln.startswith("  - ")] == list(mjcf_notes.values())

    first = [p.read_bytes() for p in outs]
    export_files(talos, params, outs)
    assert [p.read_bytes() for p in outs] == first

    export_files(talos, params, outs, include=["weak"])
    knee = "leg_left_4_joint"
    mj = mujoco.MjModel.from_xml_path(str(outs[0]))
    assert mj.dof_damping[mj.joint(knee).dofadr[0]] == fits[knee].params.F_v
    note = comments_before(ET.parse(str(outs[0])).getroot(), "joint")[knee]
    assert note == f"wbfriction fit of {knee}: weak ({fits[knee].verdict().reason})" and "F_v ±300 %" in note
    assert f'  - "{knee}"  # {note}\n' in outs[2].read_text()


@pytest.mark.parametrize("doc", ["empty", "not excited"])
def test_nothing_qualifies_nothing_written(talos, fit_of, tmp_path, doc):
    """A parameters file without joints, or whose fits are all not excited: one line, no file (the issue:
    a friction-free MJCF, exit 0)."""
    params = tmp_path / "p.json"
    if doc == "empty":
        params.write_text('{"joints": {}}')
    else:
        write_fits(params, {j: fit_of(j, "not excited", F_v=38.8) for j in talos.torque_controlled[:3]})
    outs = [tmp_path / "t.xml", tmp_path / "t.urdf", tmp_path / "t.yaml"]
    with pytest.raises(InputError, match=f"^{re.escape(str(params))}: no (joints|fit qualifies)"):
        export_files(talos, params, outs)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.json"]


def test_a_robot_from_an_mjcf_keeps_its_friction_where_nothing_is_exported(talos, fit_of, tmp_path):
    """The model file is an MJCF with friction on every leg joint: a joint not exported keeps the file's
    damping and frictionloss; an exported one gets the fit's."""
    legs = [j for j in talos.actuated if j.startswith("leg_")]
    source = tmp_path / "talos.xml"
    write_mjcf(talos, {j: FrictionParams(F_v=0.5, F_c=0.7) for j in legs}, source)
    robot = load_robot("talos", mjcf=source)
    params = tmp_path / "p.json"
    write_fits(params, {"leg_left_1_joint": fit_of("leg_left_1_joint", "not excited", F_v=38.8),
                        "leg_left_2_joint": fit_of("leg_left_2_joint", "ok", F_v=0.25, F_c=1.5)})
    export_files(robot, params, [tmp_path / "out.xml"])
    mj = mujoco.MjModel.from_xml_path(str(tmp_path / "out.xml"))
    got = {j: (mj.dof_damping[mj.joint(j).dofadr[0]], mj.dof_frictionloss[mj.joint(j).dofadr[0]]) for j in legs}
    assert got == {j: (0.25, 1.5) if j == "leg_left_2_joint" else (0.5, 0.7) for j in legs}
    assert np.all(mj.dof_damping[[mj.joint(j).dofadr[0] for j in talos.actuated if j not in legs]] == 0.0)
