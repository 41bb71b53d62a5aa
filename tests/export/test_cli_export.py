"""`wbfriction export` on the command line (issue 37): the Panda MJCF export works and carries the fitted
numbers of the fits that qualify; the joints left out one line per status; bad --include and nothing to
export: one line, exit 2, nothing written."""

from __future__ import annotations

import json

import mujoco
import pytest

from helpers import run, run_cli, said
from wbfriction.fit.params_file import write_params

PREVIOUS = b"the previous output"


@pytest.fixture()
def panda_params(tmp_path, fit_of):
    """Fits of the Panda's joints as `fit` writes them: A1, A2, A4-A6 ok (each its own numbers), A3 weak, A7 not
    in the file."""
    joints = [f"panda_joint{i}" for i in range(1, 7)]
    fits = [fit_of(j, "weak" if j == "panda_joint3" else "ok", F_v=0.1 * i, F_c=0.3 * i)
            for i, j in enumerate(joints, 1)]
    path = tmp_path / "p.json"
    write_params(path, fits, {"provenance": {"robot": "panda"}})
    return path


def lines(err: str) -> list[str]:
    return said(err)


def test_panda_mjcf_export(panda_params, tmp_path, capsys):
    """Issue 37: 'unknown element panda_finger_joint2 in equality constraint'. The file loads in MuJoCo with
    the arm's 7 joints and no constraint; the exported joints carry the JSON's F_v and F_c as damping and
    frictionloss, the others none; the terminal says what was left out, one line per status."""
    out = tmp_path / "p.xml"
    code, err = run_cli(capsys, "export", panda_params, "--robot", "panda", "-o", out)
    assert code == 0, err
    assert lines(err) == ["exported the friction of 5 joints (5 ok)", "not exported, weak: panda_joint3",
                          "not exported, not fitted: panda_joint7", f"wrote {out} (mjcf)"]
    truth = json.loads(panda_params.read_text())["joints"]
    mj = mujoco.MjModel.from_xml_path(str(out))
    assert mj.neq == 0 and mj.nv == 7
    for i in range(1, 8):
        j = f"panda_joint{i}"
        dof = mj.joint(j).dofadr[0]
        want = (truth[j]["params"]["F_v"], truth[j]["params"]["F_c"]) if j in truth and i != 3 else (0.0, 0.0)
        assert (mj.dof_damping[dof], mj.dof_frictionloss[dof]) == want, j
    assert "<!-- wbfriction fit of panda_joint1: ok -->" in out.read_text()

    code, err = run_cli(capsys, "export", panda_params, "--robot", "panda", "-o", out, "--include", "weak, at-bound")
    assert code == 0, err
    assert lines(err)[:2] == ["exported the friction of 6 joints (5 ok, 1 weak)",
                              "not exported, not fitted: panda_joint7"]
    mj = mujoco.MjModel.from_xml_path(str(out))
    assert mj.dof_damping[mj.joint("panda_joint3").dofadr[0]] == truth["panda_joint3"]["params"]["F_v"]


@pytest.mark.parametrize("case", ["include", "nothing", "empty"])
def test_refused_in_one_line_nothing_written(panda_params, tmp_path, capsys, case):
    """An --include that is not a choice, a file whose fits all fall short, one without joints: one line,
    exit 2, the previous output left byte for byte."""
    args, needle = ["--include", "weak,failed"], ("--include: 'failed' is not one of weak, at-bound, routes-disagree, "
                                                  "does-not-predict: a fit that is "
                                                  "not excited, failed or not fitted has no numbers the data carry, "
                                                  "never exported")
    if case == "nothing":
        doc = json.loads(panda_params.read_text())
        doc["joints"] = {j: d for j, d in doc["joints"].items() if j == "panda_joint3"}
        panda_params.write_text(json.dumps(doc))
        args, needle = [], f"{panda_params}: no fit qualifies for export (1 weak): --include weak exports those"
    elif case == "empty":
        panda_params.write_text('{"joints": {}}')
        args, needle = [], f"{panda_params}: no joints: nothing to export"
    out = tmp_path / "p.xml"
    out.write_bytes(PREVIOUS)
    code, err = run_cli(capsys, "export", panda_params, "--robot", "panda", "-o", out, "-o", tmp_path / "p.yaml",
                        *args)
    assert code == 2 and lines(err) == [f"error: {needle}"], err
    assert out.read_bytes() == PREVIOUS and sorted(p.name for p in tmp_path.iterdir()) == ["p.json", "p.xml"]


@pytest.mark.slow
def test_panda_from_a_simulated_log_to_mujoco(tmp_path):
    """The issue's repro as the user ran it: simulate, estimate, fit, export --robot panda -o p.xml. The MJCF
    loads in MuJoCo and each joint whose status in the parameters JSON is ok carries its F_v and F_c as
    damping and frictionloss; the others none."""
    steps = [("simulate", "--robot", "panda", "-o", "arm.parquet", "--duration", "6"),
             ("estimate", "arm.parquet", "--robot", "panda", "-o", "arm_friction.parquet"),
             ("fit", "arm_friction.parquet", "-o", "p.json"),
             ("export", "p.json", "--robot", "panda", "-o", "p.xml")]
    for args in steps:
        res = run(*args, cwd=tmp_path)
        assert res.returncode == 0, f"{args}: {res.stderr[-2000:]}"
    truth = json.loads((tmp_path / "p.json").read_text())["joints"]
    ok = {j: d["params"] for j, d in truth.items() if d["status"] == "ok"}
    assert ok
    mj = mujoco.MjModel.from_xml_path(str(tmp_path / "p.xml"))
    assert mj.neq == 0 and mj.nv == 7
    for i in range(1, 8):
        j = f"panda_joint{i}"
        dof = mj.joint(j).dofadr[0]
        want = (ok[j]["F_v"], ok[j]["F_c"]) if j in ok else (0.0, 0.0)
        assert (mj.dof_damping[dof], mj.dof_frictionloss[dof]) == want, j


@pytest.mark.parametrize("suffix", [".urdf", ".xml", ".yaml"])
def test_an_export_on_a_full_disk_is_one_line_and_keeps_the_previous_file(panda_params, tmp_path, suffix):
    """Issue 53: on a full disk (here ``ulimit -f``, 1 kB) ``export -o x.urdf`` ended in lxml's SerialisationError
    traceback while .xml and .yaml gave the one line of every writer: now all three do, status 1, the previous file
    byte for byte and no temporary file left."""
    import os
    import resource
    import subprocess
    import sys

    out = tmp_path / f"robot{suffix}"
    out.write_bytes(PREVIOUS)
    before = sorted(p.name for p in tmp_path.iterdir())

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (1024, 1024))

    res = subprocess.run([sys.executable, "-m", "wbfriction", "export", str(panda_params), "--robot", "panda", "-o",
                          str(out)], capture_output=True, text=True, preexec_fn=limit,
                         env=dict(os.environ, COLUMNS="200", PYTHONDONTWRITEBYTECODE="1"))
    assert res.returncode == 1 and lines(res.stderr) == [
        f"error: {out}: cannot be written: [Errno 27] File too large (the previous file is kept)"], res.stderr
    assert out.read_bytes() == PREVIOUS and sorted(p.name for p in tmp_path.iterdir()) == before
