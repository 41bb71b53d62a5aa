"""Start-up (issue 22): the command line imports only what a command uses. Loading the CLI (what
``wbfriction --help`` and every command pay before they start) imports the options modules (whose defaults
the help shows) and none of NumPy, Pinocchio, pyarrow, SciPy, MuJoCo or matplotlib: each command imports
them when it runs."""

from __future__ import annotations

import json
import subprocess
import sys

HEAVY = ("numpy", "pinocchio", "pyarrow", "scipy", "mujoco", "matplotlib")


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


def test_every_subpackage_name_resolves_on_first_use():
    """The subpackages load their names on first use (``lazy_loader`` stubs, ``__init__.pyi``): each name
    the stub declares resolves, from the module the stub says."""
    import importlib

    for pkg in ("export", "friction", "inertia", "logs", "model", "pipeline", "signals", "sim", "walking"):
        module = importlib.import_module(f"wbfriction.{pkg}")
        assert module.__all__, pkg
        assert [n for n in module.__all__ if getattr(module, n, None) is None] == [], pkg


def test_the_options_modules_code_uses_only_names_they_define():
    """The options modules import NumPy only for type checking (their methods import it when they run): no
    function or method of theirs reads a global name the module does not define at run time."""
    import builtins
    import dis
    import importlib
    import types

    def code_objects(obj):
        if isinstance(obj, types.FunctionType):
            yield obj.__code__
        elif isinstance(obj, property) and obj.fget is not None:
            yield obj.fget.__code__
        elif isinstance(obj, type):
            for value in vars(obj).values():
                yield from code_objects(value)

    missing = []
    for stage in ("signals", "friction", "walking", "sim", "inertia", "logs"):
        module = importlib.import_module(f"wbfriction.{stage}.options")
        for obj in vars(module).values():
            if getattr(obj, "__module__", None) != module.__name__:
                continue
            stack = list(code_objects(obj))
            while stack:
                code = stack.pop()
                stack += [c for c in code.co_consts if isinstance(c, types.CodeType)]
                names = {i.argval for i in dis.get_instructions(code) if i.opname == "LOAD_GLOBAL"}
                missing += [(stage, code.co_qualname, n) for n in names
                            if n not in vars(module) and not hasattr(builtins, n) and code.co_name != "wrapper"]
    assert missing == []


def test_estimate_imports_scipy_signal_only_for_a_butterworth_filter(talos, combined_walk, tmp_path):
    """Issue 41: ``scipy.signal`` costs about 0.5 s of a process's start; the Savitzky-Golay route (its own
    weighted fit, FFT overlap-add by ``scipy.fft``), the momentum route and the noise measurement of
    ``--diff auto`` do without it; a Butterworth filter imports it."""
    import pyarrow.parquet as pq

    log = tmp_path / "walk.parquet"
    pq.write_table(combined_walk.log.to_table(talos).slice(0, 4000), log)
    runs = {("--diff", "savgol", "--route", "acceleration"): False, ("--route", "momentum"): False,
            ("--diff", "auto",): False, ("--diff", "butterworth", "--route", "acceleration"): True}
    for k, (args, imported) in enumerate(runs.items()):
        code = ("import sys\nfrom wbfriction.cli.common import main\n"
                f"sys.argv = ['wbfriction', 'estimate', {str(log)!r}, '-o', {str(tmp_path / f'{k}.parquet')!r}, "
                f"'--workers', '1', *{args!r}]\n"
                "try:\n    main()\nexcept SystemExit as exc:\n    assert not exc.code, exc.code")
        assert ("scipy.signal" in _modules_after(code)) is imported, args
