"""The export targets by file-name suffix: which :class:`~wbfriction.export.target.ExportTarget` writes an output.

The built-in targets are registered here, in the order errors name them: ``.urdf`` (the URDF's ``<dynamics>``,
:class:`~wbfriction.export.urdf.UrdfTarget`), ``.xml``/``.mjcf`` (a MuJoCo MJCF,
:class:`~wbfriction.export.mjcf.MjcfTarget`), ``.yaml``/``.yml`` (Isaac Lab actuators,
:class:`~wbfriction.export.isaac.IsaacTarget`). Another format plugs in with :func:`register_target`
(:mod:`wbfriction.export.target`'s docstring has an example); :func:`target_for` then picks it for its suffixes,
in ``wbfriction.pipeline.export_step.export_files`` as for the built-in ones. An installed package advertises a target
under the entry-point group :data:`ENTRY_POINT_GROUP` (``wbfriction.export_targets``): read, and its targets loaded,
the first time an output's suffix is none of the targets registered so far, or every target is asked for.
"""

from __future__ import annotations

from pathlib import Path

from wbfriction.choices import spoken
from wbfriction.exceptions import InputError
from wbfriction.export import catalog
from wbfriction.export.isaac import IsaacTarget
from wbfriction.export.mjcf import MjcfTarget
from wbfriction.export.target import ExportTarget
from wbfriction.export.urdf import UrdfTarget
from wbfriction.registry import Registry


class SuffixTaken(ValueError):
    """A target registered for a suffix another target writes.

    Attributes:
        suffix: the suffix, e.g. ``.xml``.
        target: the name of the target registered.
        holder: the name of the target that writes it.
    """

    def __init__(self, suffix: str, target: str, holder: str):
        self.suffix, self.target, self.holder = suffix, target, holder
        super().__init__(f"export target '{target}': {suffix} is written by the '{holder}' target")


class UnknownExportFormat(InputError):
    """An output whose suffix no target writes.

    Attributes:
        path: the output as given.
        suffix: its suffix, lower case (empty for a name without one).
        known: the formats known, each as its first suffix and description
            (``.urdf (URDF <dynamics damping friction>)``).
    """

    def __init__(self, path: str | Path, suffix: str, known: tuple[str, ...]):
        self.path, self.suffix, self.known = path, suffix, known
        super().__init__(f"{path}: unknown export format: name it {spoken(known)}")

    def __reduce__(self):  # picklable across worker processes, with its data
        return (type(self), (self.path, self.suffix, self.known))


def check_suffixes(target: ExportTarget) -> None:
    """Refuse a target without suffixes, with one that is not lower case with its dot, or with one another target
    (by name) writes: what :func:`register_target` checks first.

    Raises:
        SuffixTaken: a suffix another target writes.
        ValueError: no suffix, or one not lower case with its dot.
    """
    if not target.suffixes:
        raise ValueError(f"export target '{target.name}': no suffix")
    for suffix in target.suffixes:
        if not suffix.startswith(".") or suffix != suffix.lower():
            raise ValueError(f"export target '{target.name}': suffix {suffix!r} is not lower case with its dot")
        holder = next((t for t in TARGETS.registered() if suffix in t.suffixes), None)  # no entry point loaded
        if holder is not None and holder.name != target.name:
            raise SuffixTaken(suffix, target.name, holder.name)


def catalogue(target: ExportTarget) -> None:
    """Put ``target``'s kind in the catalogue the command line's help reads (:mod:`~wbfriction.export.catalog`)."""
    catalog.KINDS[target.name] = catalog.TargetKind.of(target)


def uncatalogue(name: str) -> None:
    """Take the target ``name``'s kind off the catalogue the command line's help reads."""
    catalog.KINDS.pop(name, None)


ENTRY_POINT_GROUP = "wbfriction.export_targets"
"""The entry-point group under which an installed package advertises its export targets: each entry's name is the
target's and its object an :class:`~wbfriction.export.target.ExportTarget` (an instance, or a class called without
arguments)."""

TARGETS: Registry[ExportTarget] = Registry("export target", replace=True, check=check_suffixes,
                                           on_register=catalogue, on_unregister=uncatalogue,
                                           entry_points=ENTRY_POINT_GROUP)
"""The registered targets by name, in the order registered (a target registered again: last), then those installed
packages advertise (loaded when an output's suffix is none of the others', or every target is asked for: one that
does not load is left out with one :class:`~wbfriction.registry.PluginWarning` line); each writes the outputs named
with one of its suffixes (:func:`target_for`)."""


def register_target(target: ExportTarget) -> ExportTarget:
    """Make ``target`` write every output named with one of its :attr:`~ExportTarget.suffixes`; returns it.

    Registering a target of the same name again replaces it (a module reloaded): its suffixes are the new one's.

    Raises:
        SuffixTaken: a suffix another target (by name) writes; nothing registered.
        ValueError: a target without suffixes, or a suffix that is not lower case with its dot (``.csv``).
    """
    return TARGETS.register(target)


def unregister_target(name: str) -> None:
    """Forget the target named ``name`` (a no-op if none is): its suffixes are written by no target."""
    TARGETS.discard(name)


def targets() -> tuple[ExportTarget, ...]:
    """The targets registered, each once, in the order registered."""
    return TARGETS.kinds()


def known_formats() -> tuple[str, ...]:
    """Each target's first suffix and description, in the order registered
    (:func:`~wbfriction.export.catalog.known_targets`)."""
    return catalog.known_targets()


def target_for(path: str | Path) -> ExportTarget:
    """The target that writes ``path``, by its suffix (any case).

    Raises:
        UnknownExportFormat: a suffix no target writes, naming the file and the formats known.
    """
    suffix = Path(path).suffix.lower()
    target = TARGETS.first(lambda t: suffix in t.suffixes)
    if target is None:
        raise UnknownExportFormat(path, suffix, known_formats())
    return target


register_target(UrdfTarget())
register_target(MjcfTarget())
register_target(IsaacTarget())
