"""A registry of named kinds of one sort: what every place where a new kind plugs in keeps (the log formats, the torque
sources, the contact models, the simulators; ``docs/extending.md``).

A kind is an object with a ``name``. The registry refuses a name taken (and, kept in precedence order, a precedence
taken: the kind of lowest precedence that claims a thing takes it), names what it holds in its errors, and gives its
kinds in the order they are asked in: precedence, or registration.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Generic, Protocol, TypeVar


class Named(Protocol):
    """A kind a :class:`Registry` holds: its name."""

    @property
    def name(self) -> str:
        """The kind's name, unique in its registry."""


K = TypeVar("K", bound=Named)


class Registry(Generic[K]):
    """The registered kinds of one sort, by name, in the order they are asked in.

    Args:
        what: what one kind is, for errors (``"torque source"``).
        precedence: each kind's precedence (``lambda k: k.precedence``): kept in that order, two kinds may not
            share one; None: in the order registered.
        unknown: the exception :meth:`get` raises for a name not registered (``ValueError`` by default; the
            user-facing ones: :class:`~wbfriction.exceptions.InputError`), built from the message.
    """

    def __init__(self, what: str, precedence: Callable[[K], float] | None = None,
                 unknown: Callable[[str], Exception] = ValueError) -> None:
        self.what, self.precedence, self.unknown = what, precedence, unknown
        self._kinds: dict[str, K] = {}

    def add(self, kind: K) -> K:
        """Register ``kind``; returns it.

        Raises:
            ValueError: a kind of that name, or of that precedence, registered already (naming it).
        """
        if kind.name in self._kinds:
            raise ValueError(f"a {self.what} named '{kind.name}' is registered already ({self._kinds[kind.name]!r})")
        order = self.precedence
        if order is not None:
            tied = next((k for k in self._kinds.values() if order(k) == order(kind)), None)
            if tied is not None:
                raise ValueError(f"{self.what} '{kind.name}' has the precedence {order(kind):g} of '{tied.name}'")
        self._kinds[kind.name] = kind
        if order is not None:
            self._kinds = {k.name: k for k in sorted(self._kinds.values(), key=order)}
        return kind

    def remove(self, name: str) -> K:
        """Unregister the kind named ``name``; returns it.

        Raises:
            ValueError: none of that name (naming those registered).
        """
        if name not in self._kinds:
            raise ValueError(f"no {self.what} named '{name}' (registered: {self.listed()})")
        return self._kinds.pop(name)

    def get(self, name: str) -> K:
        """The kind named ``name``.

        Raises:
            the registry's ``unknown`` exception: none of that name (naming those registered).
        """
        if name not in self._kinds:
            raise self.unknown(f"unknown {self.what} {name!r}: choose one of {self.listed()}")
        return self._kinds[name]

    def kinds(self) -> tuple[K, ...]:
        """The registered kinds, in the order they are asked in."""
        return tuple(self._kinds.values())

    def names(self) -> tuple[str, ...]:
        """The registered kinds' names, in order."""
        return tuple(self._kinds)

    def listed(self) -> str:
        """The names as messages list them: ``a, b, c``."""
        return ", ".join(self._kinds)

    def __contains__(self, name: object) -> bool:
        return name in self._kinds

    def __iter__(self) -> Iterator[K]:
        return iter(tuple(self._kinds.values()))

    def __len__(self) -> int:
        return len(self._kinds)
