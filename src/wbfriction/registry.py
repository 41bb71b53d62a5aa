"""A registry of named kinds of one sort: what every place where a new kind plugs in keeps (the friction families,
the export targets, the log formats, the torque sources, the contact models, the simulators; ``docs/extending.md``).

A kind is an object with a ``name``. Every registry works alike: :meth:`Registry.register` adds a kind (refusing a
name taken, or replacing its kind where the registry says so, and, kept in precedence order, a precedence taken: the
kind of lowest precedence that claims a thing takes it), :meth:`~Registry.unregister` (or :meth:`~Registry.discard`)
takes one off, :meth:`~Registry.get` finds one by name, :meth:`~Registry.kinds` and :meth:`~Registry.names` list them
in the order they are asked in (precedence, or registration), and every error names what the registry holds.

What differs from one registry to the next is given when it is made: what its kinds must be (``check``), what
follows a registration (``on_register``, ``on_unregister``: a catalogue the help reads), and where kinds come from
besides the calls: built-in kinds whose modules are imported when first named (``builtins``), and kinds installed
packages advertise under an entry-point group (``entry_points``), read once, the first time the registry is asked,
and each loaded when first named. An entry point that does not give a valid kind of its name (its module missing or
broken, its object another name's or refused by ``check``) is one line naming it and its distribution
(:class:`EntryPointError`): raised where it is named, and, where every kind is asked for (:meth:`Registry.kinds`: a
model chosen among every family), left out with that line as a :class:`PluginWarning` (said once; the command line
prints it as its ``warning:`` line, :func:`one_line_warnings`), the others used. A kind looked up by something other
than its name (a file's suffix: :meth:`Registry.first`) loads the entry points only past the kinds registered.
"""

from __future__ import annotations

import copy
import importlib
import warnings
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from typing import TYPE_CHECKING, Any, Generic, Protocol, TypeVar

from wbfriction.exceptions import WbfrictionError

if TYPE_CHECKING:
    from importlib.metadata import EntryPoint


class Named(Protocol):
    """A kind a :class:`Registry` holds: its name."""

    @property
    def name(self) -> str:
        """The kind's name, unique in its registry."""


K = TypeVar("K", bound=Named)


class EntryPointError(WbfrictionError):
    """An entry point an installed package advertises that does not give a kind of its name (its module missing or
    broken, its object missing or not callable without arguments, its kind another name's or not what the registry
    holds): the environment, not the input.

    Attributes:
        entry_point: the entry point as its package declares it, ``name = module:object``.
        distribution: the package that advertises it (its name and version), or ``an unknown distribution``.
        problem: what loading it raised, in one line (``ModuleNotFoundError: No module named 'x'``, ``its friction
            family is named 'quadratic', not 'quad'``).
    """

    exit_status = 1

    def __init__(self, entry_point: str, distribution: str, problem: str):
        self.entry_point, self.distribution, self.problem = entry_point, distribution, problem
        super().__init__(f"the entry point '{entry_point}' of {distribution} does not load: {problem}")

    def __reduce__(self):  # picklable across worker processes, with its data
        return (type(self), (self.entry_point, self.distribution, self.problem))


class PluginWarning(UserWarning):
    """An entry point left out where every kind of its registry is asked for (:meth:`Registry.kinds`): its
    :class:`EntryPointError`, one line, after the kind's name (``friction family 'quad' left out: the entry point
    ...``)."""


@contextmanager
def one_line_warnings(say: Callable[[str], None]) -> Iterator[None]:
    """Within it, each :class:`PluginWarning` is said by ``say`` as its one line (the command line's ``warning:``),
    each time one is warned (the registry warns once per entry point); other warnings are shown as before."""
    with warnings.catch_warnings():
        warnings.simplefilter("always", PluginWarning)
        shown = warnings.showwarning

        def show(message, category, filename, lineno, file=None, line=None):
            if issubclass(category, PluginWarning):
                say(str(message))
            else:
                shown(message, category, filename, lineno, file, line)

        warnings.showwarning = show
        yield


def distribution_of(ep: EntryPoint) -> str:
    """The package that advertises ``ep``: ``name version``, or ``an unknown distribution``."""
    dist = getattr(ep, "dist", None)
    return "an unknown distribution" if dist is None else f"{dist.name} {dist.version}"


class Registry(Generic[K]):
    """The registered kinds of one sort, by name, in the order they are asked in.

    Args:
        what: what one kind is, for errors (``"torque source"``).
        precedence: each kind's precedence (``lambda k: k.precedence``): kept in that order, two kinds may not
            share one; None: in the order registered (the built-in kinds' names first, the entry points' last).
        unknown: the exception :meth:`get` raises for a name not registered (``ValueError`` by default; the
            user-facing ones: :class:`~wbfriction.exceptions.InputError`), built from the message.
        replace: a kind registered under a name taken replaces the kind of that name (a module reloaded), rather
            than being refused.
        check: what a kind must be, before it is registered: it raises what is wrong (nothing registered).
        on_register: what follows a kind's registration (a catalogue the help reads, kept in step).
        on_unregister: what follows a kind's unregistration, given its name.
        builtins: the built-in kinds' names, each to the module that registers it when imported, the first time it
            is named: listed before they are loaded, and never unregistered.
        entry_points: the entry-point group installed packages advertise kinds under (each entry's name the kind's,
            its object the kind or a class called without arguments); None: none.
        missing: the exception for a name not registered, from the name and the names that could be given instead
            (:meth:`get`: every name; :meth:`unregister`: those registered but built in); None: ``unknown``'s
            (:meth:`get`) or ``ValueError``'s (:meth:`unregister`), built from the message.
    """

    def __init__(self, what: str, precedence: Callable[[K], float] | None = None,
                 unknown: Callable[[str], Exception] = ValueError, *, replace: bool = False,
                 check: Callable[[K], None] | None = None, on_register: Callable[[K], None] | None = None,
                 on_unregister: Callable[[str], None] | None = None, builtins: Mapping[str, str] | None = None,
                 entry_points: str | None = None,
                 missing: Callable[[str, tuple[str, ...]], Exception] | None = None) -> None:
        self.what, self.precedence, self.unknown, self.replace = what, precedence, unknown, replace
        self.check, self.on_register, self.on_unregister = check, on_register, on_unregister
        self.builtins: dict[str, str] = dict(builtins or {})
        self.entry_points, self.missing = entry_points, missing
        self._kinds: dict[str, K] = {}
        self._advertised: dict[str, EntryPoint] | None = None
        self._broken: dict[str, EntryPointError] = {}  # the entry points that gave no kind, by name
        self._plugins: set[str] = set()  # the names of the kinds loaded from entry points
        self._warned: set[str] = set()  # the entry points left out with a PluginWarning already

    def register(self, kind: K) -> K:
        """Register ``kind``; returns it.

        Raises:
            what the registry's ``check`` raises: a kind that is not what the registry holds; nothing registered.
            ValueError: a kind of that name (unless the registry replaces it), or of that precedence, registered
                already (naming it).
        """
        if self.check is not None:
            self.check(kind)
        taken = self._kinds.get(kind.name)
        if taken is not None and not self.replace:
            raise ValueError(f"a {self.what} named '{kind.name}' is registered already ({taken!r})")
        order = self.precedence
        if order is not None:
            tied = next((k for k in self._kinds.values() if k.name != kind.name and order(k) == order(kind)), None)
            if tied is not None:
                raise ValueError(f"{self.what} '{kind.name}' has the precedence {order(kind):g} of '{tied.name}'")
        self._kinds.pop(kind.name, None)
        self._kinds[kind.name] = kind
        if order is not None:
            ordered = sorted(self._kinds.values(), key=order)
            self._kinds.clear()
            self._kinds.update((k.name, k) for k in ordered)
        if self.on_register is not None:
            self.on_register(kind)
        return kind

    def unregister(self, name: str) -> K:
        """Unregister the kind named ``name``; returns it. A kind of an entry point is loaded again when named.

        Raises:
            ValueError: a built-in kind; none of that name registered (naming those registered), or the registry's
                ``missing`` exception.
        """
        if name in self.builtins:
            raise ValueError(f"the built-in {self.what} '{name}' cannot be unregistered")
        if name not in self._kinds:
            registered = tuple(n for n in self._kinds if n not in self.builtins)
            if self.missing is not None:
                raise self.missing(name, registered)
            raise ValueError(f"no {self.what} named '{name}' (registered: {', '.join(registered)})")
        kind = self._kinds.pop(name)
        self._plugins.discard(name)
        if self.on_unregister is not None:
            self.on_unregister(name)
        return kind

    def discard(self, name: str) -> None:
        """Unregister the kind named ``name`` if one is registered (a no-op if none is)."""
        if name in self._kinds:
            self.unregister(name)

    def get(self, name: str) -> K:
        """The kind named ``name``: a built-in one's module imported, an entry point's loaded, the first time.

        Raises:
            the registry's ``unknown`` (or ``missing``) exception: none of that name (naming those there are).
            EntryPointError: the entry point of that name gives no kind of that name (it does not load, its kind is
                another name's or refused by ``check``; each time it is named, loaded once).
        """
        kind = self._kinds.get(name)
        if kind is not None:
            return kind
        if name in self.builtins:
            importlib.import_module(self.builtins[name])
            return self._kinds[name]
        broken = self._broken.get(name)
        if broken is not None:  # raised anew from its data: one line, its traceback not grown by every ask
            raise EntryPointError(broken.entry_point, broken.distribution, broken.problem)
        ep = self.advertised().get(name)
        if ep is not None:
            return self._load(name, ep)
        if self.missing is not None:
            raise self.missing(name, self.names())
        raise self.unknown(f"unknown {self.what} {name!r}: choose one of {self.listed()}")

    def advertised(self) -> dict[str, EntryPoint]:
        """The kinds installed packages advertise under the registry's entry-point group, by name, not loaded: read
        once, the first time it is asked."""
        if self._advertised is None:
            self._advertised = {}
            if self.entry_points is not None:
                from importlib.metadata import entry_points

                self._advertised = {ep.name: ep for ep in entry_points(group=self.entry_points)}
        return self._advertised

    def _load(self, name: str, ep: EntryPoint) -> K:
        """The kind of the entry point ``ep``, advertised as ``name``, loaded and registered; one that gives none (an
        exception on the way, a kind of another name, one ``check`` or the registration refuses) kept aside
        (:meth:`broken`) and raised as :class:`EntryPointError`, nothing registered."""
        cause: Exception | None = None
        try:
            loaded: Any = ep.load()
            kind = loaded() if isinstance(loaded, type) else loaded
            named = getattr(kind, "name", None)
            if named == name:
                registered = self.register(kind)
                self._plugins.add(name)
                return registered
            problem = (f"its {self.what} is named {named!r}, not '{name}'" if isinstance(named, str)
                       else f"{type(kind).__name__} is no {self.what} (it has no name)")
        except Exception as exc:
            problem, cause = " ".join(f"{type(exc).__name__}: {exc}".split()), exc
        error = self._broken[name] = EntryPointError(f"{ep.name} = {ep.value}", distribution_of(ep), problem)
        raise error from cause

    def _usable(self, name: str) -> K | None:
        """The kind named ``name``, or None for an entry point that gives none: left out with one
        :class:`PluginWarning` (the first time), its error kept aside (:meth:`broken`)."""
        try:
            return self.get(name)
        except EntryPointError as exc:
            if name not in self._warned:
                self._warned.add(name)
                warnings.warn(PluginWarning(f"{self.what} '{name}' left out: {exc}"), stacklevel=3)
            return None

    def broken(self) -> dict[str, EntryPointError]:
        """The entry points tried so far that gave no kind (:class:`EntryPointError`), by name: the kinds
        :meth:`kinds` leaves out."""
        return dict(self._broken)

    def reread(self) -> None:
        """Read the entry points again the next time the registry is asked (a package installed or removed while the
        program runs): the kinds loaded from the former ones unregistered, those that gave none forgotten."""
        for name in self._plugins & set(self._kinds):
            self.unregister(name)
        self._plugins.clear()
        self._broken.clear()
        self._warned.clear()
        self._advertised = None

    def _lazy(self) -> bool:
        """Whether kinds may be named before they are loaded (built-in modules, entry points)."""
        return bool(self.builtins) or self.entry_points is not None

    def kinds(self) -> tuple[K, ...]:
        """The kinds, in the order they are asked in (each loaded): an entry point that gives none left out, with one
        :class:`PluginWarning` naming it and why (the first time)."""
        if self._lazy():
            return tuple(k for k in map(self._usable, self.names()) if k is not None)
        return tuple(self._kinds.values())

    def names(self) -> tuple[str, ...]:
        """The kinds' names, in order, none loaded (but in precedence order, which loads them, leaving out as
        :meth:`kinds` does an entry point that gives none): the built-in ones, those registered, those the entry
        points advertise."""
        if not self._lazy():
            return tuple(self._kinds)
        if self.precedence is not None:
            for n in (*self.builtins, *self.advertised()):
                self._usable(n)
            return tuple(self._kinds)
        return tuple(dict.fromkeys((*self.builtins, *self._kinds, *self.advertised())))

    def loaded(self) -> tuple[str, ...]:
        """The names of the kinds registered so far (the built-in ones and the entry points' once named), in
        order."""
        return tuple(self._kinds)

    def registered(self) -> tuple[K, ...]:
        """The kinds registered so far, in order, none loaded: what a kind being registered is checked against (a
        suffix another kind claims), and what help read as the program starts lists, without reading entry
        points."""
        return tuple(self._kinds.values())

    def first(self, test: Callable[[K], bool]) -> K | None:
        """The first kind, in the order they are asked in, that passes ``test`` (a format that reads a file, a
        target that writes a suffix, a rig that claims a robot), or None. Kept in registration order, the entry
        points are read, and loaded, only when no kind before them passes (the built-in ones first: a log in a
        built-in format reads no entry point); kept in precedence order, every kind is loaded (:meth:`kinds`),
        since one advertised may come first. An entry point that gives no kind is left out as :meth:`kinds` leaves
        it out, with one :class:`PluginWarning`."""
        if self.precedence is not None:
            return next((k for k in self.kinds() if test(k)), None)
        before = tuple(dict.fromkeys((*self.builtins, *self._kinds)))
        for name in before:
            kind = self.get(name)
            if test(kind):
                return kind
        for name in self.advertised():
            plugin = None if name in before else self._usable(name)
            if plugin is not None and test(plugin):
                return plugin
        return None

    def listed(self) -> str:
        """The names as messages list them: ``a, b, c``."""
        return ", ".join(self.names())

    def copy(self) -> Registry[K]:
        """A registry of the same rules and kinds, changed on its own (what a test registers in and throws away)."""
        twin = copy.copy(self)
        twin._kinds, twin._broken = dict(self._kinds), dict(self._broken)
        twin._plugins, twin._warned = set(self._plugins), set(self._warned)
        return twin

    def __contains__(self, name: object) -> bool:
        """Whether a kind is named ``name`` (registered, built in or advertised; none loaded)."""
        if name in self._kinds or name in self.builtins:
            return True
        return self.entry_points is not None and name in self.advertised()

    def __iter__(self) -> Iterator[K]:
        return iter(self.kinds())

    def __len__(self) -> int:
        return len(self.names())
