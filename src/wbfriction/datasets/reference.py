"""The published friction (or the peer's held-out error) of each real dataset, shipped as data.

Each dataset's reference is a TOML file of the package (``wbfriction/data/references/<dataset>.toml``) holding the
numbers as their authors published them, its source, and its ``kind``, which names the :class:`Reference` class
that reads it (:data:`KINDS`):

* ``coulomb-viscous`` (:class:`CoulombViscous`, the UR10e): ``f(qd) = F_v qd + F_c sgn(qd) + offset``;
* ``sigmoid`` (:class:`Sigmoid`, the Panda): ``f(qd) = A / (1 + exp(-alpha (qd + s))) - A / (1 + exp(-alpha s))``;
* ``held-out-rms`` (:class:`HeldOutRms`, the KUKA LWR4+): no published friction; the peer's method's torque RMS
  on the held-out log, per joint [N·m];
* ``peer-parameters`` (:class:`PeerParameters`, the Unitree Aliengo): the peer's identified parameters, in the
  dataset's own files; their held-out torque RMS computed at run time.

Sign convention: wbfriction's (README): ``f`` is the friction torque's opposite, ``f(qd) > 0`` for ``qd > 0`` when
friction dissipates; both papers add their ``f`` to the rigid-body torque in the measured torque, as
wbfriction's ``-tau_f``, so their ``f`` is wbfriction's. A curve is compared by its odd part,
``(f(qd) - f(-qd)) / 2`` (:meth:`Reference.odd`): free of a torque offset, which the references hold or not.
"""

from __future__ import annotations

import math
import tomllib
from abc import ABC, abstractmethod
from dataclasses import dataclass
from importlib import resources
from typing import Any, ClassVar

import numpy as np

from wbfriction.exceptions import InputError


@dataclass(frozen=True)
class Reference(ABC):
    """A dataset's reference (module docstring).

    Attributes:
        dataset: the dataset's name (``wbfriction dataset NAME``).
        source: where the numbers come from (paper, repository, file), one line.
        joints: the joints it covers, in order.
        min_speed: curves are compared over ``|qd|`` at least this [rad/s] (0: no curve).
    """

    kind: ClassVar[str]
    dataset: str
    source: str
    joints: tuple[str, ...]
    min_speed: float

    @property
    def has_curve(self) -> bool:
        """Whether it holds a friction curve (:meth:`odd`), not only the peer's held-out error."""
        return True

    def odd(self, joint: str, qd: np.ndarray) -> np.ndarray:
        """The published curve's odd part ``(f(qd) - f(-qd)) / 2`` [N·m] at ``qd`` [rad/s] (any shape).

        Raises:
            InputError: a joint the reference does not hold, or a reference without a curve.
        """
        qd = np.asarray(qd, dtype=float)
        return 0.5 * (self.f(joint, qd) - self.f(joint, -qd))

    @abstractmethod
    def f(self, joint: str, qd: np.ndarray) -> np.ndarray:
        """The published friction ``f(qd)`` [N·m] (wbfriction's sign convention)."""

    @classmethod
    @abstractmethod
    def from_joints(cls, head: dict[str, Any], joints: dict[str, dict[str, float]]) -> Reference:
        """The reference of a TOML file's ``head`` (dataset, source, min_speed) and ``[joints.<name>]`` tables."""

    def _index(self, joint: str) -> int:
        if joint not in self.joints:
            raise InputError(f"the {self.dataset} reference holds no joint '{joint}' ({', '.join(self.joints)})")
        return self.joints.index(joint)


def _per_joint(joints: dict[str, dict[str, float]], key: str) -> tuple[float, ...]:
    return tuple(float(values[key]) for values in joints.values())


@dataclass(frozen=True)
class CoulombViscous(Reference):
    """``f(qd) = F_v qd + F_c sgn(qd) + offset`` per joint (F_v [N·m·s/rad], F_c and offset [N·m])."""

    kind = "coulomb-viscous"
    F_v: tuple[float, ...] = ()
    F_c: tuple[float, ...] = ()
    offset: tuple[float, ...] = ()

    def f(self, joint: str, qd: np.ndarray) -> np.ndarray:
        k = self._index(joint)
        qd = np.asarray(qd, dtype=float)
        return self.F_v[k] * qd + self.F_c[k] * np.sign(qd) + self.offset[k]

    @classmethod
    def from_joints(cls, head: dict[str, Any], joints: dict[str, dict[str, float]]) -> CoulombViscous:
        return cls(**head, joints=tuple(joints), F_v=_per_joint(joints, "F_v"), F_c=_per_joint(joints, "F_c"),
                   offset=_per_joint(joints, "offset"))


@dataclass(frozen=True)
class Sigmoid(Reference):
    """``f(qd) = A / (1 + exp(-alpha (qd + s))) - A / (1 + exp(-alpha s))`` per joint (A [N·m], alpha [s/rad],
    s [rad/s]): zero at rest, ``A`` from the fastest backwards to the fastest forwards."""

    kind = "sigmoid"
    A: tuple[float, ...] = ()
    alpha: tuple[float, ...] = ()
    s: tuple[float, ...] = ()

    def f(self, joint: str, qd: np.ndarray) -> np.ndarray:
        k = self._index(joint)
        qd = np.asarray(qd, dtype=float)
        a, alpha, s = self.A[k], self.alpha[k], self.s[k]
        return a / (1.0 + np.exp(-alpha * (qd + s))) - a / (1.0 + math.exp(-alpha * s))

    @classmethod
    def from_joints(cls, head: dict[str, Any], joints: dict[str, dict[str, float]]) -> Sigmoid:
        return cls(**head, joints=tuple(joints), A=_per_joint(joints, "A"), alpha=_per_joint(joints, "alpha"),
                   s=_per_joint(joints, "s"))


@dataclass(frozen=True)
class HeldOutRms(Reference):
    """No curve: the peer's torque RMS on the dataset's held-out log, per joint [N·m] (``rms``)."""

    kind = "held-out-rms"
    rms: tuple[float, ...] = ()

    @property
    def has_curve(self) -> bool:
        return False

    def f(self, joint: str, qd: np.ndarray) -> np.ndarray:
        raise InputError(f"the {self.dataset} reference holds no friction curve, only the peer's held-out error")

    def held_out(self, joint: str) -> float:
        """The peer's held-out torque RMS of ``joint`` [N·m]."""
        return self.rms[self._index(joint)]

    @classmethod
    def from_joints(cls, head: dict[str, Any], joints: dict[str, dict[str, float]]) -> HeldOutRms:
        return cls(**head, joints=tuple(joints), rms=_per_joint(joints, "rms"))


@dataclass(frozen=True)
class PeerParameters(Reference):
    """No curve and no number shipped: the peer published its parameters (a PD-driven robot's armature, friction,
    encoder offsets and delay), read from the dataset's files at run time; its held-out torque RMS is computed
    through the same estimate and prediction as wbfriction's (:mod:`wbfriction.studies.pd_peer`)."""

    kind = "peer-parameters"

    @property
    def has_curve(self) -> bool:
        return False

    def f(self, joint: str, qd: np.ndarray) -> np.ndarray:
        raise InputError(f"the {self.dataset} reference holds no friction curve, only the peer's parameters")

    @classmethod
    def from_joints(cls, head: dict[str, Any], joints: dict[str, dict[str, float]]) -> PeerParameters:
        return cls(**head, joints=tuple(joints))


KINDS: dict[str, type[Reference]] = {cls.kind: cls for cls in (CoulombViscous, Sigmoid, HeldOutRms,
                                                                 PeerParameters)}
"""A reference file's ``kind`` -> the class that reads it."""


def reference(dataset: str) -> Reference:
    """The reference shipped for ``dataset`` (``wbfriction/data/references/<dataset>.toml``).

    Raises:
        InputError: no reference for that dataset, or a file whose kind or keys are not known (naming it).
    """
    name = f"{dataset}.toml"
    path = resources.files("wbfriction").joinpath("data").joinpath("references").joinpath(name)
    if not path.is_file():
        raise InputError(f"no published reference for the dataset '{dataset}'")
    doc = tomllib.loads(path.read_text(encoding="utf-8"))
    try:
        cls = KINDS[doc["kind"]]
        head = {"dataset": str(doc["dataset"]), "source": str(doc["source"]),
                "min_speed": float(doc.get("min_speed", 0.0))}
        return cls.from_joints(head, doc["joints"])
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(f"references/{name}: {type(exc).__name__} {exc} (kinds: {', '.join(KINDS)})") from None
