"""Plugins through real entry points, a broken one beside them (issue 81, class 6).

The extending guide's own ``quadratic`` family (``docs/extending.md``, "A friction family": its code as the guide
shows it) is advertised under ``wbfriction.families`` by a distribution on the path (a ``dist-info`` folder, read by
``importlib.metadata`` as an installed package's), beside three that give no family: one whose module does not import,
one whose entry name is not its family's, one whose definition does not hold together. ``fit`` fits the guide's
family on a simulated log and compares it with the injected truth (a built-in family's, which has no ``F_q``);
``fit --model auto`` chooses among every family with the broken ones left out, each in one line naming it; naming a
broken one is that one line and a non-zero exit. The registry's rule behind it (:class:`~wbfriction.registry.Registry`)
is a property over every way an entry point can fail, anywhere among good ones.
"""

from __future__ import annotations

import json
import math
import re
import sys
import warnings
from pathlib import Path
from types import SimpleNamespace
from unittest.mock import patch

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from helpers import run_cli_printed, said
from wbfriction.friction.families.names import ENTRY_POINT_GROUP, FAMILIES
from wbfriction.registry import EntryPointError, PluginWarning, Registry

GUIDE = Path(__file__).resolve().parents[1] / "docs" / "extending.md"
DIST = "guide-friction 0.1"
"""The distribution that advertises the guide's family and the broken ones."""

BROKEN = {"needs-gone": "ModuleNotFoundError: No module named 'wbfriction_gone'",
          "quad": "its friction family is named 'quadratic', not 'quad'",
          "bad-bounds": "InvalidFamily: friction family 'bad-bounds': "}
"""The entry points that give no family, and the start of why (what their one line says)."""

ENTRIES = {"quadratic": "guide_friction.quadratic:Quadratic", "needs-gone": "guide_friction.gone:Gone",
           "quad": "guide_friction.quadratic:Quadratic", "bad-bounds": "guide_friction.invalid:BadBounds"}


def guide_family_code() -> str:
    """The guide's ``quadratic`` family as its page shows it: the section's first ``python`` block, up to its
    registration (the entry point takes the registration's place)."""
    text = GUIDE.read_text()
    section = text[text.index("## A friction family"):text.index("## A rig")]
    block = re.search(r"```python\n(.*?)```", section, re.S)
    assert block is not None
    code, registration, _ = block[1].partition("register_family(Quadratic())")
    assert registration and "class Quadratic(FrictionFamily)" in code
    return code


@pytest.fixture
def plugins(tmp_path, monkeypatch):
    """A distribution on the path advertising the guide's family and the three broken ones; the families' entry
    points read again before and after."""
    site = tmp_path / "site"
    package = site / "guide_friction"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "quadratic.py").write_text(guide_family_code())
    (package / "gone.py").write_text("import wbfriction_gone  # not installed\n")
    (package / "invalid.py").write_text(
        "import numpy as np\n\nfrom guide_friction.quadratic import Quadratic\n\n\n"
        "class BadBounds(Quadratic):\n    name = 'bad-bounds'\n    lower = np.zeros(3)  # 3 bounds, 4 parameters\n")
    dist = site / "guide_friction-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: guide-friction\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text(f"[{ENTRY_POINT_GROUP}]\n"
                                           + "".join(f"{n} = {v}\n" for n, v in ENTRIES.items()))
    monkeypatch.syspath_prepend(str(site))  # importlib's caches invalidated
    FAMILIES.reread()
    yield site
    FAMILIES.reread()
    for name in [m for m in sys.modules if m == "guide_friction" or m.startswith("guide_friction.")]:
        del sys.modules[name]


@pytest.fixture(scope="module")
def friction(tmp_path_factory) -> Path:
    """The friction table of a simulated Panda (2 s; the thesis's friction injected, its truth in the metadata)."""
    folder = tmp_path_factory.mktemp("arm")
    capsys = SimpleNamespace(readouterr=lambda: SimpleNamespace(out="", err=""))
    for args in (("simulate", "--robot", "panda", "--duration", "2", "-o", folder / "arm.parquet"),
                 ("estimate", folder / "arm.parquet", "--robot", "panda", "-o", folder / "friction.parquet")):
        code, _, err = run_cli_printed(capsys, *args)
        assert code == 0, err
    return folder / "friction.parquet"


def warning_lines(err: str) -> list[str]:
    return [line for line in said(err) if line.startswith("warning:")]


def test_the_guides_family_through_its_entry_point_is_fitted_and_compared_with_a_truth_without_its_parameter(
        plugins, friction, tmp_path, capsys):
    """``fit --model quadratic`` on a simulated log whose truth is the thesis's: each joint fitted, each of the
    family's parameters that the truth has compared with it, ``F_q`` (which it has not) not."""
    out = tmp_path / "params.json"
    code, printed, err = run_cli_printed(capsys, "fit", friction, "--model", "quadratic", "--terms", "none", "-o", out)
    assert code == 0, err
    assert warning_lines(err) == []  # naming the guide's family loads it alone: nothing to leave out
    joints = json.loads(out.read_text())["joints"]
    assert len(joints) == 7
    for fit in joints.values():
        assert fit["model"] == "quadratic" and fit["target"]["model"] == "thesis"
        assert set(fit["error_percent"]) == {"F_v", "F_c", "tau_os"}  # no truth for F_q, none made up
        truth = fit["target"]
        for name, error in fit["error_percent"].items():
            assert error == pytest.approx(100 * abs(fit["params"][name] - truth[name]) / abs(truth[name]))
    assert "Against the simulator's friction" in printed


def test_auto_leaves_each_broken_plugin_out_in_one_line_and_chooses_among_the_others(plugins, friction, tmp_path,
                                                                                      capsys):
    out = tmp_path / "params.json"
    code, _, err = run_cli_printed(capsys, "fit", friction, "--model", "auto", "--terms", "none", "-o", out)
    assert code == 0, err
    lines = warning_lines(err)
    assert len(lines) == len(BROKEN), err
    for (name, why), line in zip(BROKEN.items(), lines):
        assert line.startswith(f"warning: friction family '{name}' left out: the entry point "
                               f"'{name} = {ENTRIES[name]}' of {DIST} does not load: {why}"), line
    assert "Traceback" not in err
    for fit in json.loads(out.read_text())["joints"].values():
        scored = [s["model"] for s in fit["selection"]["scores"]]
        assert scored == ["coulomb-viscous", "quadratic", "stribeck", "thesis"], scored  # simplest first
        assert set(fit["error_percent"]) <= set(fit["params"]) and "F_q" not in fit["error_percent"]


@pytest.mark.parametrize("name", BROKEN)
def test_naming_a_broken_plugin_is_its_one_line_before_any_work(plugins, friction, tmp_path, capsys, name):
    out = tmp_path / "params.json"
    code, _, err = run_cli_printed(capsys, "fit", friction, "--model", name, "-o", out)
    assert code == 1 and not out.exists()
    lines = said(err)
    assert len(lines) == 1 and lines[0].startswith(f"error: the entry point '{name} = {ENTRIES[name]}' of {DIST} "
                                                   f"does not load: {BROKEN[name]}"), err
    assert "reading" not in err  # refused before the table is read


# the registry's rule, for every registry with an entry-point group

class Kind:
    def __init__(self, name: str, precedence: float = 0.0):
        self.name, self.precedence = name, precedence


FAILURES = {
    "import": lambda name: ImportError(f"cannot import name '{name}'\nfrom a module"),
    "raises": lambda name: RuntimeError(f"{name} blew up"),
    "misnamed": lambda name: Kind(f"{name}-other"),
    "nameless": lambda name: object(),
    "refused": lambda name: Kind(f"{name}"),  # the registry's check refuses it
}
"""Every way an entry point gives no kind: an exception on loading, a kind of another name, an object without a
name, a kind the registry's check refuses."""


def entry_point(name: str, loads: object) -> SimpleNamespace:
    def load():
        if isinstance(loads, Exception):
            raise loads
        return loads

    return SimpleNamespace(name=name, value=f"toys:{name}", group="toys",
                           dist=SimpleNamespace(name="toy-kinds", version="0.1"), load=load)


def refuse(kind: Kind) -> None:
    if kind.name.startswith("bad"):
        raise ValueError(f"kind '{kind.name}' is not what the registry holds")


plans = st.lists(st.one_of(st.just("good"), st.sampled_from(sorted(FAILURES))), min_size=1, max_size=7)


@given(plans, st.booleans())
@settings(max_examples=40, deadline=None)
def test_every_registry_leaves_out_each_entry_point_that_gives_no_kind_in_one_warning(plan, ordered):
    """Entry points, each good or failing one way, anywhere: ``kinds()`` (and ``names()`` where kept in precedence
    order, which loads them) holds the built-in and the good ones in order; each failing one is one
    :class:`PluginWarning` line naming it and its package, once; naming it raises its one line, each time."""
    advertised, good, bad = [], [], []
    for k, how in enumerate(plan):
        name = f"good{k}" if how == "good" else f"bad{k}" if how == "refused" else f"plug{k}"
        advertised.append(entry_point(name, Kind(name, k + 1) if how == "good" else FAILURES[how](name)))
        (good if how == "good" else bad).append(name)
    with patch("importlib.metadata.entry_points", return_value=advertised):
        registry: Registry[Kind] = Registry("kind", (lambda k: k.precedence) if ordered else None, check=refuse,
                                            entry_points="toys")
        registry.register(Kind("own", 0.5))
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            assert [k.name for k in registry.kinds()] == ["own", *good]
            assert [k.name for k in registry] == ["own", *good]  # said once
            if ordered:
                assert registry.names() == ("own", *good)
    lines = [str(w.message) for w in caught]
    assert all(issubclass(w.category, PluginWarning) for w in caught) and len(lines) == len(bad)
    for name, line in zip(bad, lines):
        assert "\n" not in line and line.startswith(f"kind '{name}' left out: the entry point "
                                                    f"'{name} = toys:{name}' of toy-kinds 0.1 does not load: ")
    assert set(registry.broken()) == set(bad)
    for name in bad:
        with pytest.raises(EntryPointError) as info:
            registry.get(name)
        assert str(info.value) == str(registry.broken()[name]) and info.value.exit_status == 1


def test_reread_forgets_the_entry_points_loaded_and_broken():
    first = [entry_point("a", Kind("a")), entry_point("b", RuntimeError("no"))]
    registry: Registry[Kind] = Registry("kind", entry_points="toys")
    with patch("importlib.metadata.entry_points", return_value=first):
        with pytest.warns(PluginWarning, match="^kind 'b' left out: "):
            assert [k.name for k in registry.kinds()] == ["a"]
        registry.register(Kind("own"))
    with patch("importlib.metadata.entry_points", return_value=[entry_point("b", Kind("b"))]):
        registry.reread()
        assert registry.loaded() == ("own",) and registry.broken() == {}
        assert [k.name for k in registry.kinds()] == ["own", "b"]


def test_a_truth_is_compared_under_the_names_it_has(plugins):
    """A fit of the guide's family against a built-in family's truth: its ``F_q`` has no counterpart there (left
    out); against a truth of its own family, every parameter as it is; a built-in fit against the guide's truth,
    every name (the guide's ``quantities()`` gives them all)."""
    from guide_friction.quadratic import QuadraticParams

    from wbfriction.friction.models import FrictionParams

    guide = QuadraticParams(F_v=0.3, F_q=0.02, F_c=2.0, tau_os=0.1)
    thesis = FrictionParams(F_v=0.5, F_c=1.0, S=0.3, v_s=0.05, a=40.0, tau_os=0.1)
    assert thesis.values_in("quadratic") == {"F_v": 0.5, "F_c": 1.0, "tau_os": 0.1}
    assert guide.values_in("quadratic") == {"F_v": 0.3, "F_q": 0.02, "F_c": 2.0, "tau_os": 0.1}
    against = guide.values_in("thesis")
    assert math.isnan(against.pop("v_s")) and against == {"F_v": 0.3, "F_c": 2.0, "S": 0.0, "a": 50.0, "tau_os": 0.1}


@given(plans, st.booleans(), st.integers(0, 8))
@settings(max_examples=40, deadline=None)
def test_the_first_kind_that_passes_is_the_first_of_every_kind_and_reads_no_entry_point_before_it_must(plan, ordered,
                                                                                                        wanted):
    """:meth:`Registry.first` (a file's format, an output's target, a robot's rig): the first of :meth:`kinds`
    that passes, a failing entry point left out with its one warning; kept in registration order, the entry points
    are not read when a kind registered passes (a log in a built-in format reads none)."""
    advertised = [entry_point(f"good{k}" if how == "good" else f"plug{k}",
                              Kind(f"good{k}", k + 1) if how == "good" else FAILURES[how](f"plug{k}"))
                  for k, how in enumerate(plan) if how != "refused"]
    test = (lambda kind: kind.name == ("own" if wanted == 0 else f"good{wanted}"))
    with patch("importlib.metadata.entry_points", return_value=advertised) as read:
        registry: Registry[Kind] = Registry("kind", (lambda k: k.precedence) if ordered else None,
                                            entry_points="toys")
        registry.register(Kind("own", 0.5))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PluginWarning)
            found = registry.first(test)
            assert read.called == (ordered or wanted != 0)
            expected = next((k for k in registry.kinds() if test(k)), None)
    assert found is expected
    assert (found is None) == (wanted != 0 and (wanted >= len(plan) or plan[wanted] != "good"))
