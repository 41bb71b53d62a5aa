"""The friction families' names, and the families kept under them, in a module that imports nothing heavy: the
command line lists the names in its help and :class:`~wbfriction.fit.options.FitOptions` checks one
(:func:`check_family`) without loading NumPy or any family (:mod:`wbfriction.fit.options` adds ``auto``).

The families are kept in :data:`FAMILIES` (a :class:`~wbfriction.registry.Registry`, as every registered kind): a
built-in family's module (``stribeck`` -> :mod:`.stribeck`) is imported when the family is first used, and registers
it; a family an installed package advertises under the entry-point group :data:`ENTRY_POINT_GROUP` is loaded when
first named. :mod:`.registry` is the typed interface to it (:func:`~.registry.register_family`,
:func:`~.registry.family`, :func:`~.registry.families`).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, Literal, get_args

from wbfriction.exceptions import OptionError
from wbfriction.registry import Registry

BuiltinName = Literal["coulomb-viscous", "stribeck", "thesis"]
"""A built-in friction family: Coulomb-viscous (3.1 + 3.2, :mod:`.coulomb_viscous`), Coulomb-Stribeck-viscous
(3.3 + 3.2, :mod:`.stribeck`), or the thesis's smooth model (3.5, :mod:`.thesis`); each with an offset ``tau_os``
(3.4)."""

BUILTIN_NAMES: tuple[BuiltinName, ...] = get_args(BuiltinName)
"""The built-in families, simplest (fewest parameters) first."""

ENTRY_POINT_GROUP = "wbfriction.families"
"""The entry-point group under which an installed package advertises its families: each entry's name is the family's
and its object a :class:`~wbfriction.friction.families.base.FrictionFamily` (an instance, or a class called without
arguments), loaded when the family is first named (:data:`FAMILIES`)."""


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


def validate(fam: Any) -> None:
    """Refuse a family whose definition does not hold together (``fam.validate()``)."""
    fam.validate()


FAMILIES: Registry[Any] = Registry(
    "friction family", replace=True, check=validate, builtins={n: module_of(n) for n in BUILTIN_NAMES},
    entry_points=ENTRY_POINT_GROUP, missing=UnknownFamilyError)
"""The friction families (each a :class:`~wbfriction.friction.families.base.FrictionFamily`) by name: the built-in
ones (simplest first, each loaded when first used), those registered
(:func:`~wbfriction.friction.families.registry.register_family`: a family of the same name replaced, a definition
that does not hold together refused), those installed packages advertise (each loaded when first named; one that
gives no valid family of its name is one line, :class:`~wbfriction.registry.EntryPointError`, left out of ``auto``'s
candidates with that line as a warning)."""


def family_names() -> tuple[str, ...]:
    """Every family's name, none loaded: the built-in ones (simplest first), then those registered, then those
    installed packages advertise."""
    return FAMILIES.names()


def check_family(name: str, option: str = "model", also: Sequence[str] = ()) -> str:
    """``name`` if it is a family's (or one of ``also``, e.g. ``auto``), without loading a built-in family; a family
    an installed package advertises is loaded (what it needs imported), so that one that does not load fails here,
    before any work.

    Raises:
        UnknownFamilyError: naming ``option``, the name and those known (``also`` first).
        EntryPointError: the entry point of that name gives no valid family of its name
            (:class:`~wbfriction.registry.EntryPointError`: one line naming it and its package).
    """
    if name in also or name in FAMILIES.builtins or name in FAMILIES.loaded():
        return name
    if name in FAMILIES:
        FAMILIES.get(name)  # an entry point's family
        return name
    raise UnknownFamilyError(name, (*also, *family_names()), option)
