"""The registry every pluggable kind is kept in (:class:`wbfriction.registry.Registry`): names unique, precedences
unique where it keeps their order, the order kinds are asked in, errors that name what is registered."""

from __future__ import annotations

import importlib
import pickle
from dataclasses import dataclass
from types import ModuleType, SimpleNamespace
from unittest.mock import patch

import pytest
from hypothesis import given
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.registry import EntryPointError, Registry


@dataclass(frozen=True)
class Kind:
    name: str
    precedence: float = 0.0


@given(st.lists(st.integers(-1000, 1000), unique=True, max_size=12))
def test_kinds_are_asked_in_precedence_order_whatever_the_order_registered(precedences):
    registry: Registry[Kind] = Registry("kind", precedence=lambda k: k.precedence)
    for p in precedences:
        registry.register(Kind(f"k{p}", p))
    assert [k.precedence for k in registry] == sorted(precedences)
    assert registry.names() == tuple(f"k{p}" for p in sorted(precedences))


@given(st.lists(st.text("abc", min_size=1, max_size=3), unique=True, max_size=8))
def test_without_precedence_kinds_keep_the_order_registered(names):
    registry: Registry[Kind] = Registry("kind")
    for n in names:
        registry.register(Kind(n))
    assert registry.names() == tuple(names) and len(registry) == len(names)
    for n in names[::2]:
        registry.unregister(n)
    assert registry.names() == tuple(names[1::2])


def test_a_name_or_precedence_taken_and_an_unknown_name_are_refused_naming_what_is_there():
    registry: Registry[Kind] = Registry("widget", precedence=lambda k: k.precedence, unknown=InputError)
    registry.register(Kind("a", 1))
    with pytest.raises(ValueError, match="a widget named 'a' is registered already"):
        registry.register(Kind("a", 2))
    with pytest.raises(ValueError, match="widget 'b' has the precedence 1 of 'a'"):
        registry.register(Kind("b", 1))
    with pytest.raises(InputError, match="unknown widget 'c': choose one of a"):
        registry.get("c")
    with pytest.raises(ValueError, match=r"no widget named 'c' \(registered: a\)"):
        registry.unregister("c")
    assert registry.get("a") == Kind("a", 1) and "a" in registry and "b" not in registry


# every registry works alike: the calls, the rules given when it is made, the entry points

@dataclass(frozen=True)
class Sized(Kind):
    size: int = 1


def refuse_empty(kind: Sized) -> None:
    if kind.size < 1:
        raise ValueError(f"kind '{kind.name}' is empty")


def test_the_rules_given_when_made_replace_check_and_follow_a_registration():
    """``check`` refuses before anything is registered (before a name taken); ``replace`` puts the kind of a name
    taken last; ``on_register``/``on_unregister`` follow each change; ``discard`` forgets a name if it is there."""
    seen: list[str] = []
    registry: Registry[Sized] = Registry("sized", replace=True, check=refuse_empty,
                                         on_register=lambda k: seen.append(f"+{k.name}"),
                                         on_unregister=lambda n: seen.append(f"-{n}"))
    registry.register(Sized("a"))
    registry.register(Sized("b"))
    with pytest.raises(ValueError, match="kind 'a' is empty"):
        registry.register(Sized("a", size=0))
    assert registry.register(Sized("a", size=2)) is registry.get("a") and registry.names() == ("b", "a")
    assert registry.unregister("b") == Sized("b")
    registry.discard("b")  # none: a no-op
    registry.discard("a")
    assert seen == ["+a", "+b", "+a", "-b", "-a"] and len(registry) == 0 and registry.kinds() == ()


def test_the_old_names_of_the_calls_still_work_and_a_copy_changes_on_its_own():
    registry: Registry[Kind] = Registry("kind")
    assert registry.register(Kind("a")) == Kind("a") and list(registry) == [Kind("a")]
    twin = registry.copy()
    twin.register(Kind("b"))
    assert registry.names() == ("a",) and twin.names() == ("a", "b")
    assert registry.unregister("a") == Kind("a") and "a" not in registry and "a" in twin


def test_an_unknown_name_raises_the_registrys_own_error_naming_what_there_is():
    missing: list[tuple[str, tuple[str, ...]]] = []

    def unknown(name: str, known: tuple[str, ...]) -> Exception:
        missing.append((name, known))
        return KeyError(name)

    registry: Registry[Kind] = Registry("kind", missing=unknown)
    registry.register(Kind("a"))
    with pytest.raises(KeyError):
        registry.get("z")
    with pytest.raises(KeyError):
        registry.unregister("y")
    assert missing == [("z", ("a",)), ("y", ("a",))]


def entry_point(name: str, value: str, loads: object = None, dist: str | None = "toy-kinds") -> SimpleNamespace:
    """An entry point of the group ``toys`` (what ``importlib.metadata.entry_points`` gives), ``loads`` its object
    (an exception: raised)."""

    def load():
        if isinstance(loads, Exception):
            raise loads
        return loads

    package = None if dist is None else SimpleNamespace(name=dist, version="0.1")
    return SimpleNamespace(name=name, value=value, group="toys", dist=package, load=load)


class Toy:
    name = "toy"


def test_entry_points_are_read_once_and_each_loaded_when_first_named():
    """The group is read the first time the registry is asked (not when made), once; its names are listed without
    loading; an entry point's object is loaded (a class: called) and registered when named, and again once
    unregistered."""
    advertised = [entry_point("toy", "toys:Toy", loads=Toy), entry_point("other", "toys:OTHER", loads=Kind("other"))]
    with patch("importlib.metadata.entry_points", return_value=advertised) as read:
        registry: Registry[Kind] = Registry("kind", entry_points="toys")
        registry.register(Kind("a"))
        assert read.call_count == 0
        assert registry.names() == ("a", "toy", "other") and "toy" in registry and "b" not in registry
        assert registry.loaded() == ("a",)
        assert isinstance(registry.get("toy"), Toy) and registry.get("toy") is registry.get("toy")
        assert registry.loaded() == ("a", "toy") and [k.name for k in registry] == ["a", "toy", "other"]
        registry.unregister("toy")
        assert registry.names() == ("a", "other", "toy") and registry.get("toy").name == "toy"
        with pytest.raises(ValueError, match="unknown kind 'zed': choose one of a, other, toy"):
            registry.get("zed")
    read.assert_called_once_with(group="toys")


def test_a_broken_entry_point_fails_in_one_line_naming_it_and_its_package():
    broken = [entry_point("bad", "toys.gone:Bad", loads=ModuleNotFoundError("No module named 'toys.gone'\n(hint)")),
              entry_point("lost", "toys:Lost", loads=AttributeError("no Lost"), dist=None),
              entry_point("liar", "toys:Toy", loads=Toy)]
    with patch("importlib.metadata.entry_points", return_value=broken):
        registry: Registry[Kind] = Registry("kind", entry_points="toys")
        with pytest.raises(EntryPointError) as info:
            registry.get("bad")
        assert str(info.value) == ("the entry point 'bad = toys.gone:Bad' of toy-kinds 0.1 does not load: "
                                   "ModuleNotFoundError: No module named 'toys.gone' (hint)")
        assert info.value.exit_status == 1 and isinstance(info.value.__cause__, ModuleNotFoundError)
        again = pickle.loads(pickle.dumps(info.value))
        assert (str(again), again.distribution) == (str(info.value), "toy-kinds 0.1")
        with pytest.raises(EntryPointError, match="^the entry point 'lost = toys:Lost' of an unknown distribution "
                                                  "does not load: AttributeError: no Lost$"):
            registry.get("lost")
        with pytest.raises(EntryPointError, match="^the entry point 'liar = toys:Toy' of toy-kinds 0.1 does not load: "
                                                  "its kind is named 'toy', not 'liar'$"):
            registry.get("liar")
        assert registry.loaded() == ()


def test_built_in_kinds_are_listed_first_loaded_when_named_and_never_unregistered(monkeypatch):
    """A built-in kind's module is imported the first time it is named (here: one that registers it)."""
    registry: Registry[Kind] = Registry("kind", builtins={"b": "toy_builtin_kind"})
    module = ModuleType("toy_builtin_kind")
    imported: list[str] = []

    def import_module(name: str):
        imported.append(name)
        registry.register(Kind("b"))
        return module

    monkeypatch.setattr(importlib, "import_module", import_module)
    registry.register(Kind("a"))
    assert registry.names() == ("b", "a") and registry.loaded() == ("a",) and "b" in registry
    assert registry.get("b") == Kind("b") and registry.get("b") == Kind("b") and imported == ["toy_builtin_kind"]
    with pytest.raises(ValueError, match="^the built-in kind 'b' cannot be unregistered$"):
        registry.unregister("b")
    with pytest.raises(ValueError, match=r"^no kind named 'c' \(registered: a\)$"):
        registry.unregister("c")


@pytest.mark.parametrize("module, registry", [
    ("wbfriction.model.contacts", "MODELS"), ("wbfriction.logs.torque", "SOURCES"),
    ("wbfriction.logs.formats.registry", "FORMATS"), ("wbfriction.export.registry", "TARGETS"),
    ("wbfriction.friction.families.names", "FAMILIES")])
def test_every_registered_kind_is_kept_in_one(module, registry):
    """The five registries of kinds are each a :class:`Registry` (the simulators' too: theirs is being replaced)."""
    held = getattr(importlib.import_module(module), registry)
    assert isinstance(held, Registry) and len(held) == len(held.kinds()) > 0
