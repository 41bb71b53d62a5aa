"""Start-up (issue 22): the command line imports only what a command uses. Loading the CLI (what
``wbfriction --help`` and every command pay before they start) imports neither SciPy, MuJoCo nor
matplotlib; they are imported inside the functions that use them."""

from __future__ import annotations

import json
import subprocess
import sys

HEAVY = ("scipy", "mujoco", "matplotlib")


def _modules_after(code: str) -> list[str]:
    probe = f"import sys, json\n{code}\nprint(json.dumps(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    return json.loads(out.splitlines()[-1])


def test_loading_the_command_line_imports_no_heavy_library():
    loaded = _modules_after("import wbfriction.cli")
    assert [m for m in loaded if m.split(".")[0] in HEAVY] == []


def test_help_of_every_command_imports_no_heavy_library():
    code = ("from wbfriction.cli import app\nimport typer.testing\n"
            "for c in (None, 'estimate', 'fit', 'report', 'simulate', 'identify'):\n"
            "    r = typer.testing.CliRunner().invoke(app, ([c] if c else []) + ['--help'])\n"
            "    assert r.exit_code == 0, (c, r.output)")
    loaded = _modules_after(code)
    assert [m for m in loaded if m.split(".")[0] in HEAVY] == []


def test_import_loads_nothing_heavy_and_every_public_name_resolves():
    """``import wbfriction`` loads no NumPy or Pinocchio; each name of ``__all__`` (the estimator, the fit and
    its verdict, saving and loading parameters, the simulators) is reachable from the package."""
    assert not [m for m in _modules_after("import wbfriction") if m.split(".")[0] in ("numpy", "pinocchio")]
    import wbfriction
    assert [n for n in wbfriction.__all__ if getattr(wbfriction, n, None) is None] == []
