"""Friction families: each friction model as an object (:class:`~.base.FrictionFamily`: its parameters, bounds, fit
coordinates, variable-projection design, characteristic and expectation under a velocity noise), found by name in a
registry (:mod:`.registry`: :func:`~.registry.register_family`, :func:`~.registry.family`,
:func:`~.registry.families`). The built-in families, simplest first: :mod:`.coulomb_viscous` (3.1 + 3.2),
:mod:`.stribeck` (3.3 + 3.2), :mod:`.thesis` (3.5). Their names (:mod:`.names`) and the registry load no NumPy (the
command line's help lists the names); the names below are imported on first use."""

from __future__ import annotations

from typing import TYPE_CHECKING

import lazy_loader

if TYPE_CHECKING:
    from .base import FrictionFamily as FrictionFamily
    from .coulomb_viscous import CoulombViscous as CoulombViscous
    from .coulomb_viscous import CoulombViscousParams as CoulombViscousParams
    from .names import BUILTIN_NAMES as BUILTIN_NAMES
    from .names import BuiltinName as BuiltinName
    from .names import InvalidFamily as InvalidFamily
    from .names import UnknownFamilyError as UnknownFamilyError
    from .names import check_family as check_family
    from .names import family_names as family_names
    from .params import ALL_PARAM_NAMES as ALL_PARAM_NAMES
    from .params import ModelParamsBase as ModelParamsBase
    from .registry import families as families
    from .registry import family as family
    from .registry import register_family as register_family
    from .registry import unregister_family as unregister_family
    from .stribeck import Stribeck as Stribeck
    from .stribeck import StribeckParams as StribeckParams
    from .thesis import FrictionParams as FrictionParams
    from .thesis import Thesis as Thesis

MODULES = {
    "FrictionFamily": "base", "InvalidFamily": "names",
    "CoulombViscous": "coulomb_viscous", "CoulombViscousParams": "coulomb_viscous",
    "BUILTIN_NAMES": "names", "BuiltinName": "names",
    "ALL_PARAM_NAMES": "params", "ModelParamsBase": "params",
    "UnknownFamilyError": "names", "check_family": "names", "families": "registry", "family": "registry",
    "family_names": "names", "register_family": "registry", "unregister_family": "registry",
    "Stribeck": "stribeck", "StribeckParams": "stribeck",
    "FrictionParams": "thesis", "Thesis": "thesis",
}
"""Each public name and the module (of this package) that defines it."""

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__, submod_attrs={module: [n for n, m in MODULES.items() if m == module] for module in set(MODULES.values())})
