"""The export targets as the command line's help names them, in a module that imports nothing heavy (no MuJoCo, no
Pinocchio): each registered target's name, suffixes and description (:class:`TargetKind`), in the order registered.

The built-in targets' kinds are declared here (:data:`BUILTIN`; each built-in class takes its own from it:
``class UrdfTarget(ExportTarget, kind=URDF)``), so ``export --help`` lists them without importing their modules;
:func:`~wbfriction.export.registry.register_target` adds the kind of every target it registers and
:func:`~wbfriction.export.registry.unregister_target` takes it off. What the help and the errors say of the targets
(:func:`known_targets`, :func:`targets_words`) is read from here: a registered target is in it, a hand-kept list
nowhere.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from wbfriction.choices import spoken


@dataclass(frozen=True)
class TargetKind:
    """What an export target is, without its code.

    Attributes:
        name: the target's one-word name (``mjcf``), what ``export`` prints after each file.
        suffixes: the output names' endings it writes, lower case with the dot (``.xml``, ``.mjcf``).
        description: what the file holds, as the help and errors name it (``MuJoCo MJCF: damping, ...``).
    """

    name: str
    suffixes: tuple[str, ...]
    description: str

    @classmethod
    def of(cls, target: Any) -> TargetKind:
        """The kind of an :class:`~wbfriction.export.target.ExportTarget` (its class attributes)."""
        return cls(target.name, tuple(target.suffixes), target.description)

    def words(self) -> str:
        """The target as the help names it: its first suffix and description, ``.urdf (URDF <dynamics ...>)``."""
        return f"{self.suffixes[0]} ({self.description})"


URDF = TargetKind("urdf", (".urdf",), "URDF <dynamics damping friction>")
MJCF = TargetKind("mjcf", (".xml", ".mjcf"), "MuJoCo MJCF: damping, frictionloss, armature")
ISAAC = TargetKind("isaac", (".yaml", ".yml"), "Isaac Lab actuators")
BUILTIN: tuple[TargetKind, ...] = (URDF, MJCF, ISAAC)
"""The built-in targets, in the order they are registered."""

KINDS: dict[str, TargetKind] = {kind.name: kind for kind in BUILTIN}
"""Name -> the kind of each registered target, in the order registered (kept by the registry)."""


def known_targets() -> tuple[str, ...]:
    """Each registered target's first suffix and description, in order: ``(".urdf (URDF <dynamics ...>)", ...)``."""
    return tuple(kind.words() for kind in KINDS.values())


def targets_words() -> str:
    """The registered targets as the help lists them: ``.urdf (...), .xml (...) or .yaml (...)``."""
    return spoken(known_targets())
