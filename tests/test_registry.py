"""The registry every pluggable kind is kept in (:class:`wbfriction.registry.Registry`): names unique, precedences
unique where it keeps their order, the order kinds are asked in, errors that name what is registered."""

from __future__ import annotations

from dataclasses import dataclass

import pytest
from hypothesis import given
from hypothesis import strategies as st

from wbfriction.exceptions import InputError
from wbfriction.registry import Registry


@dataclass(frozen=True)
class Kind:
    name: str
    precedence: float = 0.0


@given(st.lists(st.integers(-1000, 1000), unique=True, max_size=12))
def test_kinds_are_asked_in_precedence_order_whatever_the_order_registered(precedences):
    registry: Registry[Kind] = Registry("kind", precedence=lambda k: k.precedence)
    for p in precedences:
        registry.add(Kind(f"k{p}", p))
    assert [k.precedence for k in registry] == sorted(precedences)
    assert registry.names() == tuple(f"k{p}" for p in sorted(precedences))


@given(st.lists(st.text("abc", min_size=1, max_size=3), unique=True, max_size=8))
def test_without_precedence_kinds_keep_the_order_registered(names):
    registry: Registry[Kind] = Registry("kind")
    for n in names:
        registry.add(Kind(n))
    assert registry.names() == tuple(names) and len(registry) == len(names)
    for n in names[::2]:
        registry.remove(n)
    assert registry.names() == tuple(names[1::2])


def test_a_name_or_precedence_taken_and_an_unknown_name_are_refused_naming_what_is_there():
    registry: Registry[Kind] = Registry("widget", precedence=lambda k: k.precedence, unknown=InputError)
    registry.add(Kind("a", 1))
    with pytest.raises(ValueError, match="a widget named 'a' is registered already"):
        registry.add(Kind("a", 2))
    with pytest.raises(ValueError, match="widget 'b' has the precedence 1 of 'a'"):
        registry.add(Kind("b", 1))
    with pytest.raises(InputError, match="unknown widget 'c': choose one of a"):
        registry.get("c")
    with pytest.raises(ValueError, match=r"no widget named 'c' \(registered: a\)"):
        registry.remove("c")
    assert registry.get("a") == Kind("a", 1) and "a" in registry and "b" not in registry
