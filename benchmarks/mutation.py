"""Mutation testing of the estimator's core with mutmut 3: the share of mutants the tests kill.

mutmut changes the code (an operator, a constant, an argument: one mutant at a time) and runs the tests
that reach the changed function; a mutant the tests pass with has *survived*: a change of the code no
test notices. The run happens on a copy of the repository in a temporary folder (mutmut rewrites the
sources it mutates, in its ``mutants/`` folder: never run it in the checkout), configured there through
the copy's ``pyproject.toml`` (``[tool.mutmut]``); the checkout is not touched. The copy's tests import
the mutated sources: mutmut puts ``mutants/src`` first on its own ``sys.path`` (its forced-fail run stops
it when the tests do not see the mutants), and ``PYTHONPATH`` points there too, so that a test's
subprocess (``python -m wbfriction``) does not import an editable install's sources instead.

mutmut is not a dependency of the package: ``pip install mutmut`` (3.x). It is CPU-heavy (each mutant
reruns the tests that reach it): on a shared machine run it niced, one module at a time, with a budget::

    nice -n 19 python benchmarks/mutation.py --module signals/choice.py --max-children 1 --timeout 3600

Prints, per module, the mutants killed, survived, timed out, without tests, those that **change no number**
(:func:`no_number`: the text of a message or an error raised anyway, a progress callback, a function that
only formats text) and the share killed of the others: killed and timed out over the number-changing
mutants checked (a mutant no test reaches counts as a survivor); then every survivor, those that change a
number with their diff (``--all-diffs``: the others' too). ``--json FILE`` writes every mutant's record;
``--keep DIR`` keeps the copy (then ``cd DIR && mutmut results`` / ``mutmut show NAME``), and
``--rerun DIR`` tests that copy's survivors again with the checkout's tests (new truth tests), and the
mutants its budget left unchecked, printing the tallies before and after.
"""

from __future__ import annotations

import argparse
import ast
import importlib.util
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
from collections import Counter
from collections.abc import Iterator, Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

TESTS: dict[str, tuple[str, ...]] = {
    "friction/estimate.py": ("tests/friction/test_estimate.py", "tests/friction/test_double_support.py",
                             "tests/friction/test_condition_number.py", "tests/friction/test_fixed_base.py"),
    "model/dynamics.py": ("tests/model/test_dynamics.py", "tests/friction/test_double_support.py",
                          "tests/friction/test_condition_number.py"),
    "model/rerooted.py": ("tests/model/test_rerooted.py", "tests/friction/test_estimate.py"),
    "signals/kinematics.py": ("tests/signals/test_kinematics.py", "tests/signals/test_filter_wiring.py",
                              "tests/signals/test_filters.py"),
    "signals/filters.py": ("tests/signals/test_filters.py", "tests/signals/test_weighted_savgol.py",
                           "tests/signals/test_filter_wiring.py", "tests/signals/test_nonuniform.py"),
    "fit/solve.py": ("tests/fit/test_fit.py",),
    "fit/selection.py": ("tests/fit/test_fit.py",),
    "fit/joints.py": ("tests/fit/test_fit.py",),
    "fit/status.py": ("tests/fit/test_status.py",),
    "logs/clock.py": ("tests/logs/test_clock.py", "tests/logs/test_log.py"),
    "signals/choice.py": ("tests/signals/test_choice.py",),
    "signals/content.py": ("tests/signals/test_choice.py",),
    "fleet/trends.py": ("tests/fleet/test_trends.py", "tests/fleet/test_trends_truth.py"),
    "fleet/change_point.py": ("tests/fleet/test_trends_truth.py", "tests/fleet/test_change_point.py"),
    "fleet/batch.py": ("tests/fleet/test_batch_truth.py", "tests/fleet/test_results.py"),
    "fleet/task.py": ("tests/fleet/test_task.py", "tests/fleet/test_task_truth.py"),
}
"""The modules mutated (under ``src/wbfriction``) and the fast tests run against each one's mutants (mutmut
needs them all green on the unmutated code: it refuses to start otherwise). Tests marked ``slow`` are left out."""

DESELECT: dict[str, tuple[str, ...]] = {
    "logs/clock.py": ("tests/logs/test_clock.py::test_friction_of_a_walk",),
}
"""Tests (node-id prefixes) left out of a module's run: each needs a simulated walk (40 s per mutant that
reaches it); the module's own truth tests reach the same functions in seconds."""

TEXT_FUNCTIONS: dict[str, tuple[str, ...]] = {
    "fit/status.py": ("FitVerdict.__str__", "solver_phrase"),
    "signals/choice.py": ("DiffChoice.__str__",),
}
"""Functions whose result is only text, no number formatted (a reason's joints): every mutant of theirs
changes no number."""
TEXT_CALLS = ("warn", "print", "echo", "progress")
"""Calls whose arguments are text or a progress report (so are those of ``*Error``, ``*Warning``)."""
TEXT_ARGS: dict[str, tuple[int, ...]] = {"FitVerdict": (1,), "DiffChoice": (2,), "fallback": (0,), "Clock": (6,)}
"""Positional arguments that are messages: a verdict's reason, a choice's, a clock's."""
TEXT_KEYWORDS = ("reason", "message", "label", "title", "source")
"""Keyword arguments that are messages or labels."""
TEXT_NAMES = ("reason", "rms", "span", "other", "word", "structure", "gaps", "asked", "on", "facts", "label",
              "why", "what", "weak")
"""Variables that hold (parts of) a message, or a list of message phrases (``weak``)."""

IGNORE = shutil.ignore_patterns(".git", "mutants", "__pycache__", ".pytest_cache", ".mypy_cache", ".ruff_cache",
                                ".hypothesis", "*.egg-info", "build", "dist")


def prepare(copy: Path, modules: list[str]) -> None:
    """Copy the repository to ``copy`` and configure mutmut there (the modules, their tests)."""
    shutil.copytree(REPO, copy, ignore=IGNORE)
    tests = sorted({t for m in modules for t in TESTS[m] if (copy / t).exists()})
    deselect = [f"--deselect={d}" for m in modules for d in DESELECT.get(m, ())]
    section = {
        "source_paths": ["src"],
        "only_mutate": [f"src/wbfriction/{m}" for m in modules],
        "pytest_add_cli_args_test_selection": tests,
        "pytest_add_cli_args": ["-p", "no:cacheprovider", "-m", "not slow", *deselect],
        "also_copy": ["examples", "README.md", "docs"],  # the manual: the file map (test_layout), its pages
    }
    lines = ["", "[tool.mutmut]"] + [f"{k} = {json.dumps(v)}" for k, v in section.items()]
    with (copy / "pyproject.toml").open("a", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    (copy / "mutants" / "src").mkdir(parents=True)  # on PYTHONPATH from the start; mutmut fills it


# ------------------------------------------------------------------------ what a mutant changes
Chain = tuple[tuple[ast.AST, str, int | None], ...]
"""Where a mutant differs: the nodes from the function down, each with the field (and list index) followed."""


def _diff_sites(a: object, b: object, chain: Chain = ()) -> Iterator[Chain]:
    """The places where two syntax trees differ (the deepest node whose fields differ)."""
    if type(a) is not type(b):
        yield chain
        return
    if not isinstance(a, ast.AST):
        if a != b:
            yield chain
        return
    for name in a._fields:
        x, y = getattr(a, name, None), getattr(b, name, None)
        if isinstance(x, list) and isinstance(y, list):
            if len(x) != len(y):
                if name == "keywords":  # a keyword argument removed: the place is that keyword
                    kept = {k.arg for k in (x if len(x) < len(y) else y)}
                    for i, k in enumerate(x if len(x) > len(y) else y):
                        if k.arg not in kept:
                            yield (*chain, (a, name, i), (k, "value", None))
                    continue
                yield (*chain, (a, name, None))
                continue
            for i, (u, v) in enumerate(zip(x, y)):
                yield from _diff_sites(u, v, (*chain, (a, name, i)))
        else:
            yield from _diff_sites(x, y, (*chain, (a, name, None)))


def _call_name(node: ast.Call) -> str:
    f = node.func
    return f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else ""


def _names(targets: Sequence[ast.expr]) -> list[str | None]:
    return [t.id if isinstance(t, ast.Name) else None for t in targets]


def _text_site(chain: Chain) -> str | None:
    """Why the change at ``chain`` changes no number, or None (:func:`no_number`)."""
    number = any(isinstance(n, ast.FormattedValue) and f == "value" for n, f, _ in chain)  # a number shown
    for k, (node, field, index) in enumerate(chain):
        if isinstance(node, ast.Raise):
            return "message of an error raised anyway"
        if isinstance(node, ast.Call) and field in ("args", "keywords"):
            name = _call_name(node)
            if name.endswith(("Error", "Exception", "Warning")):
                return f"message of {name}()"
            if name in TEXT_CALLS:
                return f"argument of {name}()"
            if number:
                continue
            if field == "args" and index in TEXT_ARGS.get(name, ()):
                return f"message argument of {name}()"
            if name == "append" and isinstance(node.func, ast.Attribute) and isinstance(node.func.value, ast.Name) \
                    and node.func.value.id in TEXT_NAMES:
                return "a message phrase"
        if number:
            continue
        if isinstance(node, ast.keyword) and node.arg in TEXT_KEYWORDS:
            return f"message keyword {node.arg}="
        if isinstance(node, ast.Assign | ast.AugAssign | ast.AnnAssign) and field == "value":
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            if all(n in TEXT_NAMES for n in _names(targets)):
                return "text of a message variable"
        if isinstance(node, ast.JoinedStr) and not any(
                isinstance(n, ast.Call) and _call_name(n) in ("float", "int") for n, _, _ in chain[:k]):
            data = [n for n, f, _ in chain[:k] if isinstance(n, ast.Subscript | ast.Compare)
                    or (isinstance(n, ast.Call) and f == "args")]
            if not data:
                return "formatted text"
    return None


def no_number(module: str, function: str, original: str, mutant: str) -> str | None:
    """Why a mutant changes no number (a short phrase), or None when it may change one.

    A mutant changes no number when every place where it differs from the original (compared as syntax
    trees) lies in text: a function listed in :data:`TEXT_FUNCTIONS`, an error raised anyway (its message,
    its class), the arguments of a message or progress call (:data:`TEXT_CALLS`, ``*Error``,
    ``*Warning``), or, outside the numbers a message shows (``{...}`` of an f-string), a message argument
    (:data:`TEXT_ARGS`, :data:`TEXT_KEYWORDS`), a message variable (:data:`TEXT_NAMES`), or an f-string
    that is not parsed as a number, used as an index or compared. Everything else counts: a changed
    constant, operator, argument or choice string, and a number a reason shows (a verdict's percentage).
    """
    if function in TEXT_FUNCTIONS.get(module, ()):
        return f"{function} only formats text"
    try:
        sites = list(_diff_sites(ast.parse(textwrap.dedent(original)), ast.parse(textwrap.dedent(mutant))))
    except SyntaxError:
        return None
    if not sites:
        return "the same syntax tree"
    reasons = [_text_site(c) for c in sites]
    return None if any(r is None for r in reasons) else reasons[0]


# --------------------------------------------------------------------------------- the records
@dataclass(frozen=True)
class Mutant:
    """One mutant: its name, module (under ``src/wbfriction``), function, mutmut's status, diff, and why
    it changes no number (None: it may change one)."""

    name: str
    module: str
    function: str
    status: str
    diff: str
    no_number: str | None

    @property
    def killed(self) -> bool:
        return self.status in ("killed", "timeout")

    @property
    def checked(self) -> bool:
        return self.status in ("killed", "timeout", "survived", "no tests", "suspicious", "segfault")


def _function_of(name: str) -> str:
    """``pkg.mod.x_func__mutmut_3`` -> ``func``; ``pkg.mod.xǁClassǁmethod__mutmut_3`` -> ``Class.method``."""
    short = name.rsplit(".", 1)[1].rsplit("__mutmut_", 1)[0]
    if short.startswith("x\u01c1"):
        return ".".join(p for p in short[2:].split("\u01c1") if p)
    return short[2:] if short.startswith("x_") else short


def dump_mutants(out: Path) -> None:
    """Run in the copy (its ``pyproject.toml`` configures mutmut): every mutant's name, status, original
    and mutated function, as mutmut's ``results --all`` and ``show`` read them, into ``out`` (JSON)."""
    import difflib

    import libcst as cst
    from mutmut.mutation.data import SourceFileMutationData
    from mutmut.mutation.diff_apply import read_mutant_function, read_mutants_module, read_original_function
    from mutmut.stats import status_by_exit_code
    from mutmut.utils.file_utils import walk_mutatable_files

    records = []
    for path in walk_mutatable_files():
        data = SourceFileMutationData(path=path)
        data.load()
        module = str(path).split("src/wbfriction/", 1)[-1]
        tree = read_mutants_module(path)  # parsed once: mutmut's ``show`` parses it for every mutant
        for name, code in data.exit_code_by_key.items():
            original, mutant = (cst.Module([f]).code.strip() for f in (read_original_function(tree, name),
                                                                       read_mutant_function(tree, name)))
            diff = "\n".join(difflib.unified_diff(original.split("\n"), mutant.split("\n"), fromfile=str(path),
                                                  tofile=str(path), lineterm=""))
            records.append(dict(name=name, module=module, status=status_by_exit_code[code], original=original,
                                mutant=mutant, diff=diff))
    out.write_text(json.dumps(records))


def read_mutants(copy: Path, env: dict[str, str]) -> list[Mutant]:
    """Every mutant of the run in ``copy``, classified (:func:`no_number`)."""
    out = copy / "mutants" / "wbfriction-mutants.json"
    subprocess.run([sys.executable, str(Path(__file__).resolve()), "--dump", str(out)], cwd=copy,
                   env=env, check=True)
    mutants = []
    for r in json.loads(out.read_text()):
        function = _function_of(r["name"])
        mutants.append(Mutant(r["name"], r["module"], function, r["status"], r["diff"],
                              no_number(r["module"], function, r["original"], r["mutant"])))
    return mutants


def summary(module: str, mutants: list[Mutant]) -> str:
    """One module's tally (module docstring)."""
    status = Counter(m.status for m in mutants)
    number = [m for m in mutants if m.no_number is None and m.checked]
    excluded = [m for m in mutants if m.no_number is not None and m.checked]
    killed = sum(m.killed for m in number)
    share = 100.0 * killed / len(number) if number else float("nan")
    tally = ", ".join(f"{k} {v}" for k, v in sorted(status.items()))
    return (f"{module}: {len(mutants)} mutants ({tally}); {len(excluded)} change no number "
            f"({sum(m.killed for m in excluded)} of them killed); of the {len(number)} that change a number "
            f"{killed} killed: {share:.1f} %")


def report(mutants: list[Mutant], all_diffs: bool) -> None:
    """Print the tallies per module, then the survivors (module docstring)."""
    modules = sorted({m.module for m in mutants})
    for module in modules:
        print(summary(module, [m for m in mutants if m.module == module]))
    survivors = [m for m in mutants if m.checked and not m.killed]
    number = [m for m in survivors if m.no_number is None]
    print(f"\n{len(number)} survivors that change a number:")
    for m in number:
        print(f"\n# {m.name}: {m.status}\n{m.diff}")
    print(f"\n{len(survivors) - len(number)} survivors that change no number:")
    for m in survivors:
        if m.no_number is not None:
            print(f"  {m.name}: {m.status}, {m.no_number}")
            if all_diffs:
                print(m.diff)


def run_mutmut(copy: Path, env: dict[str, str], max_children: int, timeout: float,
               names: Sequence[str] = ()) -> bool:
    """``mutmut run`` in ``copy`` (of the mutants ``names`` only, when given) within ``timeout`` seconds;
    whether it finished."""
    log = copy / "mutmut-run.log"
    command = [sys.executable, "-m", "mutmut", "run", "--max-children", str(max_children), *names]
    with log.open("w") as out:  # its own session: a budget overrun ends mutmut and its workers together
        run = subprocess.Popen(command, cwd=copy, env=env, stdout=out, stderr=subprocess.STDOUT,
                               start_new_session=True)
        try:
            finished = run.wait(timeout=timeout) == 0
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
            print(f"stopped after the budget of {timeout:g} s: the figures cover the mutants done", file=sys.stderr)
    return finished


def environment(copy: Path) -> dict[str, str]:
    """The environment mutmut runs in: one BLAS thread, hashes fixed, the mutated sources first on every
    Python's path (module docstring)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", PYTHONHASHSEED="0",
               PYTHONPATH=str(copy / "mutants" / "src"))
    return env


def rerun(copy: Path, max_children: int, timeout: float, all_diffs: bool) -> int:
    """Bring the checkout's tests into a kept copy and test again the mutants they did not kill, and those
    a budget left unchecked (the sources mutated must be unchanged); print the tallies before and after,
    and the survivors."""
    env = environment(copy)
    before = read_mutants(copy, env)
    for tests in (copy / "tests", copy / "mutants" / "tests"):
        shutil.copytree(REPO / "tests", tests, ignore=IGNORE, dirs_exist_ok=True)
    names = [m.name for m in before if not m.killed]
    start = time.monotonic()
    finished = run_mutmut(copy, env, max_children, timeout, names)
    elapsed = time.monotonic() - start
    after = read_mutants(copy, env)
    print("before:")
    for module in sorted({m.module for m in before}):
        print("  " + summary(module, [m for m in before if m.module == module]))
    print(f"after ({len(names)} mutants tested again, {'whole run' if finished else 'partial run'}, {elapsed:.0f} s):")
    report(after, all_diffs)
    return 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--module", action="append", choices=sorted(TESTS),
                        help="a module to mutate (repeat; default: all of them)")
    parser.add_argument("--max-children", type=int, default=1, help="mutants tested side by side")
    parser.add_argument("--timeout", type=float, default=3600.0, help="wall-time budget of the run [s]")
    parser.add_argument("--keep", type=Path, help="make the copy here and keep it (default: a temporary folder)")
    parser.add_argument("--json", type=Path, help="write every mutant's record here")
    parser.add_argument("--all-diffs", action="store_true", help="print the diffs of every survivor")
    parser.add_argument("--rerun", type=Path, metavar="DIR",
                        help="a copy kept by --keep: test its survivors (and unchecked mutants) again with the "
                             "checkout's tests")
    parser.add_argument("--dump", type=Path, help=argparse.SUPPRESS)  # run in the copy by read_mutants
    args = parser.parse_args()
    if args.dump is not None:
        dump_mutants(args.dump)
        return 0
    if args.rerun is not None:
        return rerun(args.rerun.resolve(), args.max_children, args.timeout, args.all_diffs)
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
        env = environment(copy)
        start = time.monotonic()
        finished = run_mutmut(copy, env, args.max_children, args.timeout)
        elapsed = time.monotonic() - start
        mutants = read_mutants(copy, env)
        if args.json is not None:
            args.json.write_text(json.dumps([asdict(m) for m in mutants], indent=1))
        print(f"modules: {', '.join(modules)} ({'whole run' if finished else 'partial run'}, {elapsed:.0f} s)")
        report(mutants, args.all_diffs)
        return 0
    finally:
        if not keep:
            shutil.rmtree(base, ignore_errors=True)


if __name__ == "__main__":
    raise SystemExit(main())
