"""What every family's parameters share (:class:`ModelParamsBase`): one joint's values, by name, in the fit's order,
with the characteristic ``f(qd)`` they give, the torque ``tau_f = -f(qd)`` and the conversions to vectors and
mappings (sign convention and units: :mod:`wbfriction.friction.models`)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, fields
from typing import ClassVar, TypeVar, cast

import numpy as np
from numpy.typing import ArrayLike

from wbfriction.exceptions import InputError
from wbfriction.friction.families.names import FAMILIES

ALL_PARAM_NAMES = ("F_v", "F_c", "F_s", "S", "v_s", "tau_os", "a")
"""Every built-in family's parameter names, in one order (e.g. the columns of a table of several families): the keys
of :meth:`ModelParamsBase.quantities`."""

ParamLike = float | np.ndarray
"""A model parameter: one value, or an array of them broadcastable to ``qd`` (e.g. one per joint)."""

ParamsT = TypeVar("ParamsT", bound="ModelParamsBase")
"""Any family's parameter class."""


@dataclass(frozen=True)
class ModelParamsBase:
    """What the parameter sets of the families share: their family's name, their fitted parameters' names (in the
    fit's order), ``f``, ``torque`` and conversions. A family's parameters are a frozen dataclass of floats deriving
    from this one, one field per name of :attr:`names` (and fixed ones such as the Stribeck exponent ``delta_s``)."""

    model: ClassVar[str]
    names: ClassVar[tuple[str, ...]]

    def f(self, qd: ArrayLike) -> np.ndarray:
        """Friction characteristic ``f(qd)`` [N·m] (``qd`` [rad/s], any shape)."""
        raise NotImplementedError

    def f_at(self, qd: float) -> float:
        """:meth:`f` of one velocity [rad/s], in plain floats (a simulator's physics step): the same number."""
        return float(self.f(qd))

    def quantities(self) -> dict[str, float]:
        """Every built-in family's parameters in this family's terms (:data:`ALL_PARAM_NAMES`): what a fit of any
        family is compared with (:meth:`values_in`), what the exports read (the static level ``F_s``, the Coulomb
        level ``F_c``); a quantity this family does not have is NaN (a Stribeck velocity without a Stribeck effect),
        a jump it makes is a tanh slope ``a = inf``."""
        raise NotImplementedError

    def values_in(self, model: str) -> dict[str, float]:
        """These parameters under the names of ``model``'s, e.g. an injected friction of one family against a fit of
        another: of this family, its own values; of another, those of its names that :meth:`quantities` has (a
        parameter only ``model`` has, such as a plugin's ``F_q``, has no counterpart here and is left out: no truth
        for it, rather than one made up).

        Raises:
            UnknownFamilyError: no family named ``model``.
        """
        if model == self.model:
            return {n: getattr(self, n) for n in self.names}
        q = self.quantities()
        return {n: q[n] for n in FAMILIES.get(model).names if n in q}

    def to_target(self) -> dict[str, float | str]:
        """These parameters and their family's name, as a simulator's ``friction_true`` metadata holds them
        (:func:`~wbfriction.friction.models.target_from_dict` reads them back)."""
        return {"model": self.model, **self.to_dict()}

    def torque(self, qd: ArrayLike) -> np.ndarray:
        """Torque friction exerts on the joint, ``tau_f = -f(qd)`` [N·m]."""
        return -self.f(qd)

    def as_vector(self) -> np.ndarray:
        """The fitted parameters in :attr:`names` order."""
        return np.array([getattr(self, n) for n in self.names])

    @classmethod
    def from_vector(cls: type[ParamsT], x: Iterable[float], delta_s: float = 2.0) -> ParamsT:
        """Parameters from the fitted values in :attr:`names` order (and the Stribeck exponent
        ``delta_s``, for the families that have one)."""
        values = dict(zip(cls.names, map(float, x), strict=True))
        if "delta_s" in {f.name for f in fields(cls)}:
            values["delta_s"] = float(delta_s)
        return cls(**values)

    def to_dict(self) -> dict[str, float]:
        """Every parameter by name (the inverse of :meth:`from_dict`)."""
        return asdict(self)

    @classmethod
    def from_dict(cls: type[ParamsT], d: Mapping[str, object]) -> ParamsT:
        """Parameters from a mapping of their names (missing ones take the defaults).

        Raises:
            InputError: an unknown name, or a value that is not a number.
        """
        names = {f.name for f in fields(cls)}
        unknown = set(d) - names
        if unknown:
            raise InputError(f"unknown friction parameter(s) of the {cls.model} model: {', '.join(sorted(unknown))}")
        try:
            return cls(**{k: float(cast(float, v)) for k, v in d.items()})
        except (TypeError, ValueError) as exc:
            raise InputError(str(exc)) from None
