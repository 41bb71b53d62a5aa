"""The same input gives the same output bytes, before and after a change of the code's layout (issue 54).

Three scenarios run the command line as a user does: a walk (TALOS in the ideal simulator: estimate, fit,
predict, report, export), an arm (4 s of a simulated Panda: estimate, fit, identify, export) and a fleet (two
simulated Panda logs, one per robot, one drifted, batched on Dask, then their trends: every output kind at the least
cost; the trends, too few logs to test, say so). Every file they write and every line they print is hashed (SHA-256)
and compared with ``tests/golden/same_bytes.json``, recorded before issue 54 moved the fitting into its own
stage (commit ``1390c40``; the arm's and the fleet's re-recorded when they were shortened, after the files of the
longer ones were checked unmoved). A refactoring that moves one bit of one output fails here.

Bytes depend on the libraries that compute them (a SciPy release may round differently; PyArrow writes its
version into every Parquet file), so the comparison holds where the stack is the one recorded: Python, NumPy,
SciPy, Pinocchio, MuJoCo, PyArrow, the machine's architecture, and the processor's instructions that NumPy's
kernels and OpenBLAS's core choose at run time (an AVX-512 machine sums in another order than an AVX2 one). On
another stack the recorded bytes cannot be compared: the scenario then runs twice, in two folders, and the two
runs must give the same bytes (the promise on any machine); ``WBFRICTION_RECORD_SAME_BYTES=1`` records the stack
at hand (after checking on the recorded stack that nothing moved).
"""

from __future__ import annotations

import fcntl
import hashlib
import json
import os
import platform
import sys
from pathlib import Path

import pytest

from helpers import run
from wbfriction.model.loading import example_robot_data_dir

GOLDEN = Path(__file__).resolve().parent / "golden" / "same_bytes.json"
RECORD = os.environ.get("WBFRICTION_RECORD_SAME_BYTES") == "1"

FLEET = """
from pathlib import Path
from wbfriction.studies.drifting_fleet import Drift, simulate_arm_fleet
Path("fleet").mkdir()
simulate_arm_fleet(Path("fleet"), robots=2, logs=1, seconds=2.0,
                   drifts=(Drift("arm-1", "panda_joint4", "F_c", 0.40, 1),))
"""

SCENARIOS: dict[str, list[list[str]]] = {
    "walk": [
        ["simulate", "-o", "walk.parquet", "--gait", "combined", "--steps", "1"],
        ["estimate", "walk.parquet", "--robot", "talos", "-o", "friction.parquet"],
        ["fit", "friction.parquet", "-o", "params.json"],
        ["fit", "friction.parquet", "--model", "thesis", "-o", "thesis.json"],
        ["predict", "friction.parquet", "--params", "params.json"],
        ["report", "friction.parquet", "--params", "params.json", "-o", "report.html"],
        ["export", "params.json", "--robot", "talos", "--include", "weak,at-bound",
         "-o", "talos.xml", "-o", "talos.yaml", "-o", "talos.urdf"],
    ],
    "arm": [
        ["simulate", "--robot", "panda", "-o", "arm.parquet", "--duration", "4"],
        ["estimate", "arm.parquet", "--robot", "panda", "-o", "friction.parquet"],
        ["fit", "friction.parquet", "-o", "params.json"],
        ["fit", "friction.parquet", "--model", "stribeck", "-o", "stribeck.json"],
        ["estimate", "arm.parquet", "--robot", "panda", "--route", "momentum", "-o", "momentum.parquet"],
        ["identify", "arm.parquet", "--robot", "panda", "--armature", "identify", "-o", "identified.urdf",
         "--json", "identified.json"],
        ["export", "params.json", "--robot", "panda", "-o", "panda.xml", "-o", "panda.yaml", "-o", "panda.urdf"],
    ],
    "fleet": [
        ["python", "-c", FLEET],
        ["batch", "fleet/manifest.csv", "-o", "fleet/results"],
        ["trends", "fleet/results", "-o", "trends.html", "--table", "trends.csv"],
    ],
}
"""Each scenario's command lines (``wbfriction`` ARGS, or ``python -c``), in order, in a folder of their own."""

VOLATILE = ("fleet/results/",)
"""Outputs whose bytes are not the input's alone: the batch's results record when and where each log ran
(their numbers reach ``trends.csv``, which is compared)."""


def stack() -> dict[str, str]:
    """The libraries and machine the bytes depend on."""
    import mujoco
    import numpy
    import pinocchio
    import pyarrow
    import scipy
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    from threadpoolctl import threadpool_info

    blas = [f"{lib.get('internal_api')} {lib.get('version')} {lib.get('architecture')}"
            for lib in threadpool_info() if lib.get("user_api") == "blas"]
    return {"python": platform.python_version(), "machine": platform.machine(), "numpy": numpy.__version__,
            "scipy": scipy.__version__, "pinocchio": pinocchio.__version__, "mujoco": mujoco.__version__,
            "pyarrow": pyarrow.__version__,
            "numpy kernels": " ".join(t for t in __cpu_dispatch__ if __cpu_features__.get(t)),
            "blas": "; ".join(sorted(blas))}


def digest(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def run_scenario(name: str, folder: Path) -> dict[str, str]:
    """Run a scenario in ``folder``; the SHA-256 of each command's standard output and of every file written."""
    import subprocess

    hashes = {}
    for i, args in enumerate(SCENARIOS[name]):
        if args[0] == "python":
            res = subprocess.run([sys.executable, *args[1:]], cwd=folder, capture_output=True, text=True)
        else:
            res = run(*args, cwd=folder, columns=120)
        assert res.returncode == 0, f"{name}: {' '.join(args[:3])} exited {res.returncode}: {res.stderr[-2000:]}"
        hashes[f"stdout {i}: {' '.join(args[:2])}"] = digest(res.stdout.encode())
    robots = os.fsencode(example_robot_data_dir())
    for path in sorted(folder.rglob("*")):
        rel = path.relative_to(folder).as_posix()
        if path.is_file() and not rel.startswith(VOLATILE):
            # an exported MJCF names the robot's meshes where example-robot-data is installed: the same bytes
            # wherever that is
            hashes[rel] = digest(path.read_bytes().replace(robots, b"<example-robot-data>"))
    return hashes


@pytest.mark.slow
@pytest.mark.parametrize("name", list(SCENARIOS))
def test_outputs_are_the_bytes_recorded(name, tmp_path):
    if RECORD:
        hashes = run_scenario(name, tmp_path)
        GOLDEN.parent.mkdir(exist_ok=True)
        with open(GOLDEN.with_suffix(".lock"), "w") as lock:  # the scenarios record side by side (-n 2): one
            fcntl.flock(lock, fcntl.LOCK_EX)                  # read-modify-write at a time, none lost
            golden = json.loads(GOLDEN.read_text()) if GOLDEN.is_file() else {"stack": stack(), "scenarios": {}}
            golden["stack"] = stack()
            golden["scenarios"][name] = hashes
            GOLDEN.write_text(json.dumps(golden, indent=1, sort_keys=True) + "\n")
        return
    golden = json.loads(GOLDEN.read_text()) if GOLDEN.is_file() else {"stack": stack(), "scenarios": {}}
    differs = {k: (v, golden["stack"].get(k)) for k, v in stack().items() if golden["stack"].get(k) != v}
    hashes = run_scenario(name, _folder(tmp_path, "first"))
    if differs:
        expected = run_scenario(name, _folder(tmp_path, "second"))
        against = "a second run (the bytes were recorded on another stack: " + ", ".join(
            f"{k} {now} here, {then} recorded" for k, (now, then) in differs.items()) + ")"
    else:
        expected = golden["scenarios"][name]
        against = "the bytes recorded"
    assert sorted(hashes) == sorted(expected), f"the outputs written are not those of {against}"
    moved = [k for k in expected if hashes[k] != expected[k]]
    assert not moved, f"{name}: these outputs differ from {against}: {moved}"


def _folder(parent: Path, name: str) -> Path:
    folder = parent / name
    folder.mkdir()
    return folder
