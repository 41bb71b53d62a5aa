"""What a command's output is written as, by its file's suffix: the kinds of document the commands write (a table, a
friction table streamed, a MuJoCo model, parameters, a page, a figure, ...), each with the suffixes its writers read
from their own registries, so that an output whose suffix no writer of its kind writes is refused, before any work,
naming the option, the suffix and the suffixes its kind is written as.

The tables' suffixes are the registered log formats' (:mod:`~wbfriction.logs.formats.catalog`: a format registered is
a suffix accepted, and the help lists it), the models' and the exports' the registered export targets'
(:mod:`~wbfriction.export.catalog`); neither catalogue imports anything heavy, so the command line checks its outputs
as it parses its options (:mod:`wbfriction.cli.outputs`). A suffix none of those registered writes is checked again
after the formats (or targets) installed packages advertise are loaded (their entry points read then, not as the
command line starts). A new kind of document is one call::

    register_output(OutputKind("svg", "a vector figure", lambda: (".svg",)))

Every output option of every command is of one kind (:data:`OUTPUT_OPTIONS`; ``docs/reference/files.md``, "Output
names").
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from wbfriction.choices import spoken
from wbfriction.exceptions import OptionError
from wbfriction.export.catalog import KINDS as TARGET_KINDS
from wbfriction.logs.formats.catalog import written
from wbfriction.registry import Registry


@dataclass(frozen=True)
class OutputKind:
    """A kind of document a command writes, found by its file's suffix.

    Attributes:
        name: the kind's one-word name (``table``), what :func:`check_output` is given.
        what: the document as messages name it (``a table``).
        listed: the suffixes it is written as, lower case with the dot, the one to name first first: asked each time
            (read from the registry of its writers, e.g. the log formats', so that one registered there is one here).
        advertised: what loads the writers installed packages advertise (a registry's entry points), asked before a
            suffix not listed is refused; None: none.
    """

    name: str
    what: str
    listed: Callable[[], tuple[str, ...]]
    advertised: Callable[[], object] | None = None

    def suffixes(self) -> tuple[str, ...]:
        """The suffixes it is written as, now: ``(".parquet", ".pq", ".csv")``."""
        return tuple(self.listed())

    def words(self) -> str:
        """The suffixes as the help lists them: ``.parquet, .pq or .csv``."""
        return spoken(self.suffixes())


class OutputSuffixError(OptionError):
    """An output named with a suffix its kind of document is not written as: refused before any work.

    Attributes:
        option: the option as the command line spells it (``-o``, ``--table``).
        value: the path given, as a string.
        suffix: its suffix, lower case ('' without one).
        what: the document, as messages name it (``a table``).
        accepted: the suffixes it is written as.
    """

    def __init__(self, option: str, value: str, suffix: str, what: str, accepted: tuple[str, ...]):
        self.option, self.value, self.suffix, self.what, self.accepted = option, value, suffix, what, accepted
        self.expected = f"{what} named {spoken(accepted)}"
        said = f"not '{suffix}'" if suffix else f"and '{Path(value).name}' has no suffix"
        super(OptionError, self).__init__(f"{option} {value}: {what} is written as {spoken(accepted)}, {said}")

    def __reduce__(self):  # picklable across worker processes, with its data
        return (type(self), (self.option, self.value, self.suffix, self.what, self.accepted))


def _targets() -> tuple[str, ...]:
    """Every registered export target's suffixes, in order."""
    return tuple(s for kind in TARGET_KINDS.values() for s in kind.suffixes)


def _advertised_formats() -> object:
    """Every log format, those installed packages advertise loaded (their kinds catalogued)."""
    from wbfriction.logs.formats.registry import FORMATS

    return FORMATS.kinds()


def _advertised_targets() -> object:
    """Every export target, those installed packages advertise loaded (their kinds catalogued)."""
    from wbfriction.export.registry import TARGETS

    return TARGETS.kinds()


def _target(name: str) -> Callable[[], tuple[str, ...]]:
    """The suffixes of the registered export target ``name`` (none while it is not registered)."""
    return lambda: TARGET_KINDS[name].suffixes if name in TARGET_KINDS else ()


OUTPUTS: Registry[OutputKind] = Registry("output kind")
"""The kinds of document the commands write, by name."""
register_output = OUTPUTS.register
"""Add a kind of document (an :class:`OutputKind`); returns it (ValueError: a name registered already)."""
unregister_output = OUTPUTS.unregister
"""Remove the kind of document of a name; returns it (ValueError: none of that name)."""

for _builtin in (
        OutputKind("table", "a table", written, _advertised_formats),
        OutputKind("text-table", "a table with text columns", lambda: written(text=True), _advertised_formats),
        OutputKind("streamed-table", "a streamed table", lambda: written(streamed=True), _advertised_formats),
        OutputKind("export", "an export", _targets, _advertised_targets),
        OutputKind("mjcf", "a MuJoCo model", _target("mjcf")),
        OutputKind("urdf", "a URDF", _target("urdf")),
        OutputKind("json", "a JSON document", lambda: (".json",)),
        OutputKind("toml", "a robot's TOML", lambda: (".toml",)),
        OutputKind("png", "a figure", lambda: (".png",)),
        OutputKind("html", "a page", lambda: (".html", ".htm"))):
    register_output(_builtin)


def output_kind(name: str) -> OutputKind:
    """The registered kind of document named ``name`` (ValueError: none, naming those there are)."""
    return OUTPUTS.get(name)


def check_output(option: str, path: str | Path, kind: str) -> None:
    """Refuse an output whose suffix (any case) the kind of document ``kind`` is not written as, before any work.

    Args:
        option: the option that names it, as the command line spells it (``-o``).
        path: the file to write.
        kind: the registered kind of document it is (:data:`OUTPUTS`).

    Raises:
        OutputSuffixError: ``-o x.txt: a table is written as .parquet, .pq, ... or .npz, not '.txt'`` (a name without
            a suffix: ``..., and 'x' has no suffix``).
    """
    found = output_kind(kind)
    suffix = Path(path).suffix.lower()
    accepted = found.suffixes()
    if suffix not in accepted and found.advertised is not None:  # an installed package's writer, loaded now
        found.advertised()
        accepted = found.suffixes()
    if suffix not in accepted:
        raise OutputSuffixError(option, str(path), suffix, found.what, accepted)


OUTPUT_OPTIONS: dict[str, dict[str, str]] = {
    "simulate": {"-o": "table"},
    "convert": {"-o": "streamed-table"},
    "estimate": {"-o": "streamed-table"},
    "fit": {"-o": "json"},
    "export": {"-o": "export"},
    "predict": {"--table": "table", "--figure": "png"},
    "report": {"-o": "html"},
    "rollout": {"-o": "text-table", "--figure": "png"},
    "refine": {"-o": "mjcf", "--table": "text-table"},
    "identify": {"-o": "urdf", "--json": "json", "--config-output": "toml"},
    "excite": {"-o": "table", "--json": "json", "--figure": "png"},
    "sensitivity": {"-o": "png"},
    "spectrum": {"-o": "png"},
    "trends": {"-o": "html", "--table": "text-table"},
}
"""Each command's options that name a file it writes, to the kind of document it is (the folders a command writes
into, ``batch -o``, ``--tables``, ``dataset -o``, ``demo -o`` and the studies', have no suffix to check)."""
