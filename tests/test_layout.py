"""The package's layout, read from the source (no code run): subpackages along the data flow, each importing
only those before it, no circle between modules, no private name used outside its module, and the manual's
file map (``docs/explanation/layout.md``) naming what is there."""

from __future__ import annotations

import ast
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "wbfriction"

LAYERS = [
    {"version", "exceptions", "choices", "progress", "config", "workers", "quantities", "registry", "options"},
    {"model"},
    {"logs"},
    {"datasets"},
    {"signals"},
    {"friction"},
    {"fit"},
    {"actuator"},
    {"inertia"},
    {"walking"},
    {"sim"},
    {"export"},
    {"pipeline"},
    {"replay"},
    {"excite"},
    {"fleet"},
    {"report"},
    {"studies"},
    {"rigs"},
    {"cli", "__main__", "__init__", "entry"},
]
"""The top-level modules and subpackages in data-flow order: each may import only from its own layer
or earlier ones (the package's ``__init__`` re-exports, so it sits last)."""


def module_name(package: Path, path: Path) -> str:
    parts = list(path.relative_to(package.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports_of(package: Path, path: Path) -> set[str]:
    """Every package module a file imports, at any depth (function-level imports included)."""
    me = module_name(package, path).split(".")
    here = me if path.name == "__init__.py" else me[:-1]
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names if a.name.split(".")[0] == package.name}
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(here[: len(here) - node.level + 1] + ([base] if base else []))
            if base.split(".")[0] != package.name:
                continue
            for alias in node.names:  # "from wbfriction.x import y": y may be a module
                candidate = f"{base}.{alias.name}"
                out.add(candidate if is_module(package, candidate) else base)
    return out


def is_module(package: Path, name: str) -> bool:
    rel = Path(*name.split(".")[1:])
    return (package / rel).with_suffix(".py").is_file() or (package / rel / "__init__.py").is_file()


def import_graph(package: Path) -> dict[str, set[str]]:
    return {module_name(package, p): imports_of(package, p) for p in sorted(package.rglob("*.py"))}


def layer(module: str) -> int:
    top = module.split(".")[1] if "." in module else "__init__"
    return next(i for i, names in enumerate(LAYERS) if top in names)


def layer_breaches(package: Path) -> list[str]:
    """Imports of a later stage than the importer's."""
    return [f"{m} imports {i}" for m, deps in import_graph(package).items() for i in sorted(deps)
            if layer(i) > layer(m)]


def import_cycle(package: Path) -> list[str]:
    """One circle of module imports (empty if there is none); a package's ``__init__`` importing its
    own modules is how it re-exports, not a circle."""
    g = import_graph(package)
    g = {m: {d for d in deps if d in g and d != m and not d.startswith(m + ".")} for m, deps in g.items()}
    state: dict[str, int] = {}

    def visit(m: str, path: list[str]) -> list[str]:
        state[m] = 1
        for d in sorted(g[m]):
            if state.get(d) == 1:
                return path[path.index(d):] + [d]
            if d not in state and (found := visit(d, path + [d])):
                return found
        state[m] = 2
        return []

    for m in sorted(g):
        if m not in state and (found := visit(m, [m])):
            return found
    return []


def test_every_module_sits_in_a_layer():
    for module in import_graph(PACKAGE):
        layer(module)  # StopIteration for a module outside the layout


def test_no_module_imports_a_later_stage():
    assert not (bad := layer_breaches(PACKAGE)), "\n".join(bad)


def test_no_import_circle():
    assert not (cycle := import_cycle(PACKAGE)), " -> ".join(cycle)


def test_the_checks_see_a_circle_and_a_later_stage(tmp_path):
    """The two checks can fail: a made-up package with a circle (one import inside a function) and a
    model module importing the report."""
    pkg = tmp_path / "wbfriction"
    (pkg / "model").mkdir(parents=True)
    for f in ("__init__.py", "model/__init__.py", "report.py"):
        (pkg / f).write_text("")
    (pkg / "model" / "a.py").write_text("from wbfriction.model.b import x\n")
    (pkg / "model" / "b.py").write_text("from wbfriction.report import z\n\n\ndef f():\n    from .a import y\n")
    assert layer_breaches(pkg) == ["wbfriction.model.b imports wbfriction.report"]
    assert import_cycle(pkg) == ["wbfriction.model.a", "wbfriction.model.b", "wbfriction.model.a"]


def test_no_private_name_crosses_a_module():
    """``from wbfriction.x import _y`` nowhere: not in the package, the tests, the benchmarks, the examples."""
    bad = []
    for folder in ("src", "tests", "benchmarks", "examples"):
        for path in (ROOT / folder).rglob("*.py"):
            for node in ast.walk(ast.parse(path.read_text())):
                if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("wbfriction"):
                    bad += [f"{path.relative_to(ROOT)}: {node.module}.{a.name}" for a in node.names
                            if a.name.startswith("_") and not a.name.startswith("__")]
    assert not bad, "\n".join(bad)


FILE_MAP = ROOT / "docs" / "explanation" / "layout.md"
"""The manual's page holding the package's file map (moved there from the README, issue 54)."""


def test_file_map_matches_the_code():
    """The manual's file map (``docs/explanation/layout.md``) lists every subpackage and top-level module of the
    package, and nothing else."""
    text = FILE_MAP.read_text()
    block = re.search(r"<!-- file map -->\n```text\n(.*?)```", text, re.S)
    assert block, f"{FILE_MAP.relative_to(ROOT)}: no file map block"
    named = set(re.findall(r"^[│├└─ ]*([a-z_]+(?:/|\.py))\s", block.group(1), re.M))
    present = {p.name + "/" for p in PACKAGE.iterdir() if (p / "__init__.py").exists()}
    present |= {p.name for p in PACKAGE.glob("*.py") if p.name not in ("__init__.py", "__main__.py")}
    assert named == present, (f"{FILE_MAP.relative_to(ROOT)} lists {sorted(named - present)} that the code has "
                              f"not; misses {sorted(present - named)}")


MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 80
"""Issue 54's limits: a module over 600 lines holds several concepts, a function over 80 several jobs."""
MODULE_MARGIN = 20
"""Lines a module must stay below :data:`MAX_MODULE_LINES`: at most 580."""

LONG_FUNCTIONS: dict[str, str] = {}
"""Functions allowed over :data:`MAX_FUNCTION_LINES`, each with why (``module:function``)."""


def sizes(package: Path) -> tuple[dict[str, int], dict[str, int]]:
    """Lines per module, and per function or method (``module:qualified name``; nested functions count in their
    parent's lines, as they are part of its job)."""
    modules: dict[str, int] = {}
    functions: dict[str, int] = {}

    def visit(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.ClassDef):
                visit(child, f"{prefix}{child.name}.")
            elif isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                functions[f"{prefix}{child.name}"] = child.end_lineno - child.lineno + 1

    for path in sorted(package.rglob("*.py")):
        text = path.read_text()
        modules[name := module_name(package, path)] = len(text.splitlines())
        visit(ast.parse(text), f"{name}:")
    return modules, functions


def test_no_module_over_or_near_600_lines():
    """No module over :data:`MAX_MODULE_LINES`, nor within :data:`MODULE_MARGIN` lines of it: a module near the limit
    is one edit from over it, and splitting it then, to land that edit, is rushed; split it by concept now."""
    modules, _ = sizes(PACKAGE)
    limit = MAX_MODULE_LINES - MODULE_MARGIN
    assert not (long := {m: n for m, n in modules.items() if n > limit}), (
        f"modules over {limit} lines ({MAX_MODULE_LINES} less a margin of {MODULE_MARGIN}): {long}")


def test_no_function_over_80_lines():
    _, functions = sizes(PACKAGE)
    long = {f: n for f, n in functions.items() if n > MAX_FUNCTION_LINES and f not in LONG_FUNCTIONS}
    assert not long, long
    assert not (stale := [f for f in LONG_FUNCTIONS if functions.get(f, 0) <= MAX_FUNCTION_LINES]), (
        f"exceptions no longer needed: {stale}")


def test_the_size_checks_see_a_long_function(tmp_path):
    pkg = tmp_path / "wbfriction"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("")
    (pkg / "big.py").write_text("class A:\n    def f(self):\n" + "        x = 1\n" * 90)
    modules, functions = sizes(pkg)
    assert functions["wbfriction.big:A.f"] == 91 and modules["wbfriction.big"] == 92


KINDS = {"rig": (PACKAGE / "rigs", ("quadruped", "hung", "arm", "biped")),
         "engine": (PACKAGE / "sim" / "engines", ("ideal", "mujoco"))}
"""Each registry whose kinds' names nothing outside its folder may decide by: its folder and its built-in names."""
CHOOSERS = re.compile(r"(simulator|engine|rig)s?$")
"""What a variable, attribute or parameter that holds a rig's or an engine's name is called."""


def named(node: ast.AST) -> str:
    """The identifier a node ends in (``case.simulator``: ``simulator``), or ``""``."""
    return node.id if isinstance(node, ast.Name) else node.attr if isinstance(node, ast.Attribute) else ""


def kind_names_decided(package: Path) -> list[str]:
    """Where a module outside a registry's folder decides by one of its kinds' names: a comparison of a variable
    named like a choice of them (``simulator == "mujoco"``, ``rig.name in ("arm", ...)``) with the name, a default
    of such a parameter or field, or a ``Literal`` that lists the engines."""
    found = []
    for what, (folder, names) in KINDS.items():
        for path in sorted(package.rglob("*.py")):
            if folder in path.parents:
                continue
            rel = path.relative_to(package.parent)
            for node in ast.walk(ast.parse(path.read_text())):
                consts: list[ast.AST] = []
                if isinstance(node, ast.Compare):
                    sides = [node.left, *node.comparators]
                    if any(CHOOSERS.search(named(s)) or named(s) == "name" for s in sides):
                        consts = [c for s in sides for c in ast.walk(s) if isinstance(c, ast.Constant)]
                elif isinstance(node, ast.arguments):
                    args = [*node.posonlyargs, *node.args][-len(node.defaults):] if node.defaults else []
                    consts = [c for a, d in zip(args, node.defaults, strict=True) if CHOOSERS.search(a.arg)
                              for c in ast.walk(d) if isinstance(c, ast.Constant)]
                    consts += [c for a, d in zip(node.kwonlyargs, node.kw_defaults, strict=True)
                               if d is not None and CHOOSERS.search(a.arg) for c in ast.walk(d)
                               if isinstance(c, ast.Constant)]
                elif isinstance(node, ast.AnnAssign) and node.value is not None and CHOOSERS.search(named(node.target)):
                    consts = [c for c in ast.walk(node.value) if isinstance(c, ast.Constant)]
                elif isinstance(node, ast.Subscript) and named(node.value) == "Literal" and what == "engine":
                    listed = {c.value for c in ast.walk(node.slice) if isinstance(c, ast.Constant)}
                    consts = [node] if set(names) <= listed else []
                found += [f"{rel}:{c.lineno}: {what} name" for c in consts
                          if not isinstance(c, ast.Constant) or c.value in names]
    return found


def test_no_rig_or_engine_name_outside_its_registrys_folder():
    """Nothing outside ``rigs/`` decides by a rig's name, nor outside ``sim/engines/`` by an engine's: they ask the
    registry (``rig_for``, ``engine_of``) and the kind's own properties."""
    assert not (bad := kind_names_decided(PACKAGE)), "\n".join(bad)


def test_the_name_check_sees_a_decision_by_name(tmp_path):
    pkg = tmp_path / "wbfriction"
    (pkg / "studies").mkdir(parents=True)
    (pkg / "studies" / "a.py").write_text(
        'from typing import Literal\nS = Literal["ideal", "mujoco"]\n\n\ndef f(simulator="ideal"):\n'
        '    return simulator == "mujoco" or rig.name in ("arm", "x")\n')
    assert kind_names_decided(pkg) == [f"wbfriction/studies/a.py:{n}: {what} name"
                                       for n, what in ((6, "rig"), (2, "engine"), (5, "engine"), (6, "engine"))]


def test_no_options_read_by_name_in_sim():
    """The simulators take typed options: no ``Mapping[str, Any]`` of options in ``sim/``."""
    bad = [f"{p.relative_to(ROOT)}" for p in sorted((PACKAGE / "sim").rglob("*.py"))
           if re.search(r"Mapping\[str, Any\]", p.read_text())]
    assert not bad, bad
