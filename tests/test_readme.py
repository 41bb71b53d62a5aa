"""The README's commands run as written (issue 24, item 5): every line of its "Commands" block, in order, from a
copy of the checkout's layout (``examples/`` beside the outputs), each exiting 0 and writing what its ``-o``
names, no two lines writing the same file; then its Python API block."""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

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


@pytest.mark.slow
def test_the_readme_commands_run_as_written(tmp_path):
    (tmp_path / "examples").symlink_to(REPO / "examples")
    bin_dir = str(Path(sys.executable).parent)
    env = dict(os.environ, PATH=bin_dir + os.pathsep + os.environ.get("PATH", ""), MPLBACKEND="Agg")
    for command in readme_commands():
        assert command.split()[0] in ("wbfriction", "python"), command
        argv = shlex.split(command)
        argv[0] = os.path.join(bin_dir, "wbfriction") if argv[0] == "wbfriction" else sys.executable
        res = subprocess.run(argv, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=900)
        assert res.returncode == 0, f"{command}\n{res.stderr[-2000:]}"
        for out in outputs(command):
            assert (tmp_path / out).exists(), f"{command}: wrote no {out}"
    # then the Python API block, in the same folder (it reads walk.parquet)
    res = subprocess.run([sys.executable, "-c", readme_python()], cwd=tmp_path, env=env, capture_output=True,
                         text=True, timeout=900)
    assert res.returncode == 0, res.stderr[-2000:]
    assert "leg_right_4_joint: F_c" in res.stdout and (tmp_path / "api_params.json").exists()
