"""Mutation testing of the estimator's core with mutmut 3: the share of mutants the tests kill.

mutmut changes the code (an operator, a constant, an argument: one mutant at a time) and runs the tests
that reach the changed function; a mutant the tests pass with has *survived*: a change of the code no
test notices. The run happens on a copy of the repository in a temporary folder (mutmut rewrites the
sources it mutates, in its ``mutants/`` folder: never run it in the checkout), configured there through
the copy's ``pyproject.toml`` (``[tool.mutmut]``); the checkout is not touched.

mutmut is not a dependency of the package: ``pip install mutmut`` (3.x). It is CPU-heavy (each mutant
reruns the tests that reach it): on a shared machine run it niced, one module at a time, with a budget::

    nice -n 19 python benchmarks/mutation.py --module signals/filters.py --max-children 1 --timeout 3600

Prints, per run, the mutants killed, survived, timed out, without tests, the share killed (killed and
timed out over the mutants checked: a mutant no test reaches counts as a survivor) and the wall time;
``--keep DIR`` keeps the copy (then ``cd DIR && mutmut results`` / ``mutmut show NAME`` list the survivors).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

TESTS: dict[str, tuple[str, ...]] = {
    "friction/estimate.py": ("tests/friction/test_estimate.py", "tests/friction/test_double_support.py",
                             "tests/friction/test_condition_number.py", "tests/friction/test_fixed_base.py"),
    "model/dynamics.py": ("tests/model/test_dynamics.py", "tests/friction/test_double_support.py",
                          "tests/friction/test_condition_number.py"),
    "model/stance.py": ("tests/model/test_stance.py", "tests/friction/test_estimate.py"),
    "signals/kinematics.py": ("tests/signals/test_kinematics.py", "tests/signals/test_filter_wiring.py",
                              "tests/signals/test_filters.py"),
    "signals/filters.py": ("tests/signals/test_filters.py", "tests/signals/test_weighted_savgol.py",
                           "tests/signals/test_filter_wiring.py", "tests/signals/test_nonuniform.py"),
    "friction/fit.py": ("tests/friction/test_fit.py",),
}
"""The modules mutated (under ``src/wbfriction``) and the fast tests run against each one's mutants (mutmut
needs them all green on the unmutated code: it refuses to start otherwise)."""

IGNORE = shutil.ignore_patterns(".git", "mutants", "__pycache__", ".pytest_cache", ".mypy_cache", ".ruff_cache",
                                ".hypothesis", "*.egg-info", "build", "dist")


def prepare(copy: Path, modules: list[str]) -> None:
    """Copy the repository to ``copy`` and configure mutmut there (the modules, their tests)."""
    shutil.copytree(REPO, copy, ignore=IGNORE)
    tests = sorted({t for m in modules for t in TESTS[m] if (copy / t).exists()})
    section = {
        "source_paths": ["src"],
        "only_mutate": [f"src/wbfriction/{m}" for m in modules],
        "pytest_add_cli_args_test_selection": tests,
        "pytest_add_cli_args": ["-p", "no:cacheprovider"],
        "also_copy": ["examples", "README.md"],
    }
    lines = ["", "[tool.mutmut]"] + [f"{k} = {json.dumps(v)}" for k, v in section.items()]
    with (copy / "pyproject.toml").open("a", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")


def counts(copy: Path) -> dict[str, int]:
    """mutmut's own tally of the run (``mutmut export-cicd-stats``)."""
    mutmut = [sys.executable, "-m", "mutmut"]
    subprocess.run([*mutmut, "export-cicd-stats"], cwd=copy, check=True, capture_output=True, text=True)
    return json.loads((copy / "mutants" / "mutmut-cicd-stats.json").read_text())


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--module", action="append", choices=sorted(TESTS),
                        help="a module to mutate (repeat; default: all of them)")
    parser.add_argument("--max-children", type=int, default=1, help="mutants tested side by side")
    parser.add_argument("--timeout", type=float, default=3600.0, help="wall-time budget of the run [s]")
    parser.add_argument("--keep", type=Path, help="make the copy here and keep it (default: a temporary folder)")
    args = parser.parse_args()
    modules = args.module or sorted(TESTS)
    if importlib.util.find_spec("mutmut") is None:
        print("mutmut is not installed: pip install mutmut", file=sys.stderr)
        return 2
    keep = args.keep is not None
    base = args.keep.resolve() if keep else Path(tempfile.mkdtemp(prefix="wbfriction-mutation-"))
    if keep and base.exists():
        print(f"{base} exists: give a new folder", file=sys.stderr)
        return 2
    copy = base if keep else base / "repo"
    try:
        prepare(copy, modules)
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        env.update(OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", PYTHONHASHSEED="0")
        start = time.monotonic()
        log = copy / "mutmut-run.log"
        with log.open("w") as out:  # its own session: a budget overrun ends mutmut and its workers together
            run = subprocess.Popen([sys.executable, "-m", "mutmut", "run", "--max-children", str(args.max_children)],
                                   cwd=copy, env=env, stdout=out, stderr=subprocess.STDOUT, start_new_session=True)
            try:
                finished = run.wait(timeout=args.timeout) == 0
                if not finished:
                    print(log.read_text()[-3000:], file=sys.stderr)
            except subprocess.TimeoutExpired:
                os.killpg(run.pid, signal.SIGTERM)
                try:
                    run.wait(timeout=30)
                except subprocess.TimeoutExpired:
                    os.killpg(run.pid, signal.SIGKILL)
                    run.wait()
                finished = False
                print(f"stopped after the budget of {args.timeout:g} s: the figures cover the mutants done",
                      file=sys.stderr)
        elapsed = time.monotonic() - start
        stats = counts(copy)
        killed = stats["killed"] + stats["timeout"]  # a mutant that hangs the tests is caught too
        checked = killed + stats["survived"] + stats["no_tests"] + stats["suspicious"] + stats["segfault"]
        share = 100.0 * killed / checked if checked else float("nan")
        print(f"modules: {', '.join(modules)}")
        print(f"mutants: {stats['total']}; killed {stats['killed']}, timed out {stats['timeout']}, survived "
              f"{stats['survived']}, no tests {stats['no_tests']}, suspicious {stats['suspicious']}, skipped "
              f"{stats['skipped']}, not reached in the budget {stats['total'] - checked - stats['skipped']}")
        print(f"killed: {share:.1f} % of the {checked} mutants checked ({'whole run' if finished else 'partial run'}, "
              f"{elapsed:.0f} s)")
        return 0
    finally:
        if not keep:
            shutil.rmtree(base, ignore_errors=True)


if __name__ == "__main__":
    raise SystemExit(main())
