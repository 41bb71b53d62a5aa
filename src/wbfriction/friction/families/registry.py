"""The friction families by name: :func:`register_family` adds one, :func:`family` finds one, :func:`families` lists
them simplest first.

Every stage that depends on a family (the fit's bounds and coordinates, its variable projection, its expectation
under the velocity noise, the model choice of ``--model auto``, the exports' static level) asks it here, by the name a
fit records (:attr:`~wbfriction.fit.result.FitResult.model`). The built-in families
(:data:`~.names.BUILTIN_NAMES`) are loaded on first use; so is a family an installed package advertises under the
entry-point group :data:`~.names.ENTRY_POINT_GROUP`, which makes it a choice of ``wbfriction fit --model`` and a
candidate of ``--model auto``. A family defined in a program takes one call::

    register_family(ViscousOnly())  # a FrictionFamily subclass (wbfriction.friction.families.base)

This module imports nothing heavy (the families are kept in :data:`.names.FAMILIES`, a
:class:`~wbfriction.registry.Registry` as every registered kind): checking a name (:func:`check_family`,
what :class:`~wbfriction.fit.options.FitOptions` does) loads no family.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from wbfriction.friction.families.names import FAMILIES, UnknownFamilyError, check_family, family_names

if TYPE_CHECKING:
    from wbfriction.friction.families.base import FrictionFamily

__all__ = ["UnknownFamilyError", "check_family", "families", "family", "family_names", "register_family",
           "unregister_family"]


def register_family(fam: FrictionFamily) -> FrictionFamily:
    """Make ``fam`` a family of its :attr:`~FrictionFamily.name` (a choice of ``--model``, a candidate of
    ``--model auto``); returns it. Registering a family of the same name again replaces it (a module reloaded).

    Raises:
        InvalidFamily: a definition that does not hold together (:meth:`FrictionFamily.validate`); nothing
            registered.
    """
    return FAMILIES.register(fam)


def unregister_family(name: str) -> None:
    """Forget the family ``name`` (registered by a program or loaded from an entry point: it is loaded again when
    named).

    Raises:
        ValueError: a built-in family (:data:`~.names.BUILTIN_NAMES`).
        UnknownFamilyError: a name no family registered has.
    """
    FAMILIES.unregister(name)


def family(name: str) -> FrictionFamily:
    """The family ``name``, loaded on first use (a built-in module, an installed package's entry point).

    Raises:
        UnknownFamilyError: no family has that name (the message names the families known).
        InvalidFamily: an entry point's family that does not hold together, or is another name's.
        EntryPointError: an entry point that does not load (:class:`wbfriction.registry.EntryPointError`: one line
            naming it and its package).
    """
    return FAMILIES.get(name)


def families() -> tuple[FrictionFamily, ...]:
    """Every family (each loaded), simplest (fewest parameters) first, in the order of :func:`family_names` among
    those of as many parameters: what ``--model auto`` chooses among."""
    return tuple(sorted(FAMILIES.kinds(), key=lambda f: len(f.names)))
