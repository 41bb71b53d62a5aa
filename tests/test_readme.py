"""The README's commands run as written (issue 24, item 5): every line of its "Commands" block, in order, from a
copy of the checkout's layout (``examples/`` beside the outputs), each exiting 0 and writing what its ``-o``
names, no two lines writing the same file; then its Python API block."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from pathlib import Path

import pytest

from helpers import REAL_DATA

REPO = Path(__file__).resolve().parents[1]


def readme_commands() -> list[str]:
    """The lines of the README's "Commands" bash block, comments dropped."""
    text = (REPO / "README.md").read_text()
    block = re.search(r"## Commands\n.*?```bash\n(.*?)```", text, re.S)
    assert block, "no bash block under '## Commands'"
    lines = [line.split("  #")[0].strip() for line in block.group(1).splitlines()]
    return [line for line in lines if line and not line.startswith("#")]


def readme_python() -> str:
    """The README's Python block under "## The library"."""
    text = (REPO / "README.md").read_text()
    block = re.search(r"## The library\n.*?```python\n(.*?)```", text, re.S)
    assert block, "no python block under '## The library'"
    return block.group(1)


def outputs(command: str) -> list[str]:
    """What a command line says it writes: the values of its ``-o`` options and of ``--json``/``--write``."""
    words = shlex.split(command)
    return [words[i + 1] for i, w in enumerate(words[:-1]) if w in ("-o", "--output", "--output-dir", "--json",
                                                                     "--write")]


def test_every_output_is_its_own():
    written = [o for c in readme_commands() for o in outputs(c)]
    assert written and len(written) == len(set(written)), sorted(w for w in written if written.count(w) > 1)


def needs(commands: list[str]) -> list[set[int]]:
    """For each command, the earlier ones it reads the outputs of: an argument that is an earlier command's
    output, or a path inside one (``fleet/manifest.csv`` inside ``fleet``). The README's order is kept
    between a command and what it reads; the others may run side by side."""
    made = [outputs(c) for c in commands]
    deps = []
    for i, command in enumerate(commands):
        words = shlex.split(command)
        deps.append({j for j in range(i) for out in made[j]
                     if any(w == out or w.startswith(out.rstrip("/") + "/") for w in words)})
    return deps


def test_a_command_waits_for_what_it_reads():
    commands = readme_commands()
    deps = needs(commands)
    index = {c.split(" -o ")[0]: i for i, c in enumerate(commands)}
    fit = index["wbfriction fit walk_friction.parquet"]
    assert deps[fit] == {index["wbfriction estimate walk.parquet --robot talos"]}
    predict = next(i for i, c in enumerate(commands) if c.startswith("wbfriction predict"))
    assert {commands[j].split()[-1] for j in deps[predict]} == {"noisy_friction.parquet", "walk_params.json"}
    batch = next(i for i, c in enumerate(commands) if c.startswith("wbfriction batch"))
    assert [commands[j] for j in deps[batch]] == ["python examples/fleet_trends.py --output fleet"]


EXPECTED = {
    "python examples/fleet_trends.py --output fleet": [  # arm 1's joint 4 alone, from the day its wear began
        r"^24 logs processed on Dask, 0 already done$",
        r"^drift: arm-1 panda_joint4 \S+ \+\d+ % from 2026-01-1[0-4]$",  # worn from the 8th log, Jan 12
        r"1 of 14 tested robot joints drifted.*; wrote fleet/trends\.html$",  # that joint alone
    ],
}
"""What a command must print (regular expressions, each found in its output, multi-line): the examples the
README runs are checked here, once (``tests/test_examples.py`` runs the others)."""


def _run(command: str, cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess:
    bin_dir = str(Path(sys.executable).parent)
    argv = shlex.split(command)
    argv[0] = os.path.join(bin_dir, "wbfriction") if argv[0] == "wbfriction" else sys.executable
    return subprocess.run(argv, cwd=cwd, env=env, capture_output=True, text=True, timeout=900)


@pytest.mark.slow
def test_the_readme_commands_run_as_written(tmp_path):
    """Each command once what it reads is written, two at a time (the machine's two cores)."""
    (tmp_path / "examples").symlink_to(REPO / "examples")
    bin_dir = str(Path(sys.executable).parent)
    env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ.get("PATH", ""), MPLBACKEND="Agg")
    if REAL_DATA.is_dir():  # 'wbfriction dataset' offline: the local copy, checked against the same SHA-256
        env.setdefault("WBFRICTION_DATA", str(REAL_DATA))
    commands = readme_commands()
    assert all(c.split()[0] in ("wbfriction", "python") for c in commands)
    deps = needs(commands)
    done: set[int] = set()
    with ThreadPoolExecutor(2) as pool:
        running: dict[Future, int] = {}
        while len(done) < len(commands):
            for i in range(len(commands)):
                if i not in done and i not in running.values() and deps[i] <= done and len(running) < 2:
                    running[pool.submit(_run, commands[i], tmp_path, env)] = i
            finished, _ = wait(running, return_when=FIRST_COMPLETED)
            for future in finished:
                i = running.pop(future)
                command, res = commands[i], future.result()
                assert res.returncode == 0, f"{command}\n{res.stderr[-2000:]}"
                for out in outputs(command):
                    assert (tmp_path / out).exists(), f"{command}: wrote no {out}"
                for pattern in EXPECTED.get(command, []):
                    assert re.search(pattern, res.stdout, re.M), f"{command}: {pattern!r} not in\n{res.stdout}"
                done.add(i)
    # then the Python API block, in the same folder (it reads walk.parquet)
    res = subprocess.run([sys.executable, "-c", readme_python()], cwd=tmp_path, env=env, capture_output=True,
                         text=True, timeout=900)
    assert res.returncode == 0, res.stderr[-2000:]
    assert "leg_right_4_joint: F_c" in res.stdout and (tmp_path / "api_params.json").exists()
