"""The friction families' names, and the families kept under them, in a module that imports nothing heavy: the
command line lists the names in its help and :class:`~wbfriction.fit.options.FitOptions` checks one
(:func:`check_family`) without loading NumPy or any family (:mod:`wbfriction.fit.options` adds ``auto``).

A built-in family's module (``stribeck`` -> :mod:`.stribeck`) is imported when the family is first used
(:func:`load`), and registers it; so is a family an installed package advertises under the entry-point group
:data:`ENTRY_POINT_GROUP`. :mod:`.registry` is the typed interface to what is kept here
(:func:`~.registry.register_family`, :func:`~.registry.family`, :func:`~.registry.families`).
"""

from __future__ import annotations

import functools
import importlib
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Literal, get_args

from wbfriction.exceptions import OptionError

if TYPE_CHECKING:
    from importlib.metadata import EntryPoint

BuiltinName = Literal["coulomb-viscous", "stribeck", "thesis"]
"""A built-in friction family: Coulomb-viscous (3.1 + 3.2, :mod:`.coulomb_viscous`), Coulomb-Stribeck-viscous
(3.3 + 3.2, :mod:`.stribeck`), or the thesis's smooth model (3.5, :mod:`.thesis`); each with an offset ``tau_os``
(3.4)."""

BUILTIN_NAMES: tuple[BuiltinName, ...] = get_args(BuiltinName)
"""The built-in families, simplest (fewest parameters) first."""

ENTRY_POINT_GROUP = "wbfriction.families"
"""The entry-point group under which an installed package advertises its families: each entry's name is the family's
and its object a :class:`~wbfriction.friction.families.base.FrictionFamily` (an instance, or a class called without
arguments), loaded when the family is first used (:func:`load`)."""

REGISTERED: dict[str, Any] = {}
"""Name -> family (a :class:`~wbfriction.friction.families.base.FrictionFamily`), in the order registered (the
built-in ones as they are first used): :func:`~wbfriction.friction.families.registry.register_family` adds one."""


class InvalidFamily(ValueError):
    """A family whose definition does not hold together
    (:meth:`~wbfriction.friction.families.base.FrictionFamily.validate`).

    Attributes:
        family: the family's name.
        problem: what does not hold, e.g. ``lower has 5 bounds for 6 parameters``.
    """

    def __init__(self, family: str, problem: str):
        self.family, self.problem = family, problem
        super().__init__(f"friction family '{family}': {problem}")

    def __reduce__(self):  # picklable across worker processes, with its data
        return (type(self), (self.family, self.problem))


class UnknownFamilyError(OptionError):
    """A friction family's name that no family has.

    Attributes:
        name: the name given.
        known: the names the option takes (:func:`family_names`, after ``auto`` where the option takes it).
        option: the option or key that named it, e.g. ``--model`` or ``selection.chosen``.
    """

    def __init__(self, name: str, known: Sequence[str], option: str = "model"):
        self.name = name
        self.known = tuple(known)
        super().__init__(option, name, f"one of {', '.join(self.known)}")

    def __reduce__(self):  # picklable across worker processes, with its data
        return (type(self), (self.name, self.known, self.option))


def module_of(name: str) -> str:
    """The module of the built-in family ``name`` (``coulomb-viscous`` ->
    ``wbfriction.friction.families.coulomb_viscous``)."""
    return f"{__name__.rpartition('.')[0]}.{name.replace('-', '_')}"


@functools.cache
def advertised() -> dict[str, EntryPoint]:
    """The families installed packages advertise (entry-point group :data:`ENTRY_POINT_GROUP`), by name, not loaded;
    read once per process."""
    from importlib.metadata import entry_points

    return {ep.name: ep for ep in entry_points(group=ENTRY_POINT_GROUP)}


def family_names() -> tuple[str, ...]:
    """Every family's name, none loaded: the built-in ones (simplest first), then those registered, then those
    installed packages advertise."""
    return tuple(dict.fromkeys((*BUILTIN_NAMES, *REGISTERED, *advertised())))


def check_family(name: str, option: str = "model", also: Sequence[str] = ()) -> str:
    """``name`` if it is a family's (or one of ``also``, e.g. ``auto``), without loading the family.

    Raises:
        UnknownFamilyError: naming ``option``, the name and those known (``also`` first).
    """
    if name in also or name in BUILTIN_NAMES or name in REGISTERED or name in advertised():
        return name
    raise UnknownFamilyError(name, (*also, *family_names()), option)


def keep(fam: Any) -> Any:
    """Keep ``fam`` under its name, once its definition is checked (``fam.validate()``); returns it. A family of the
    same name is replaced (a module reloaded).

    Raises:
        InvalidFamily: a definition that does not hold together; nothing kept.
    """
    fam.validate()
    REGISTERED.pop(fam.name, None)
    REGISTERED[fam.name] = fam
    return fam


def load(name: str) -> Any:
    """The family ``name``, loaded on first use: a built-in family's module imported (it registers the family), an
    installed package's entry point loaded (and kept).

    Raises:
        UnknownFamilyError: no family has that name (the message names the families known).
        InvalidFamily: an entry point's family of another name, or one that does not hold together.
    """
    fam = REGISTERED.get(name)
    if fam is not None:
        return fam
    if name in BUILTIN_NAMES:
        importlib.import_module(module_of(name))
        return REGISTERED[name]
    ep = advertised().get(name)
    if ep is None:
        raise UnknownFamilyError(name, family_names())
    loaded = ep.load()
    fam = loaded() if isinstance(loaded, type) else loaded
    if fam.name != name:
        raise InvalidFamily(fam.name, f"advertised as '{name}' by the entry point {ep.value}")
    return keep(fam)
