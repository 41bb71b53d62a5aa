"""Griffe extensions for the API reference: the package read as it is written, src/ not edited for the manual.

:class:`LazyStubExports`: a package whose names are loaded on first use exports what its stub re-exports (or, for a
package with a module ``__getattr__``, what it imports for type checkers).
``wbfriction`` and its subpackages bind ``__getattr__, __dir__, __all__ = lazy_loader.attach_stub(__name__,
__file__)``: the names a user imports are those of the ``__init__.pyi`` stub beside (``from .x import Y as Y``), which
griffe merges into the package but cannot read ``__all__`` from (a call's result). Without ``__all__`` those
re-exports count as imports, not the package's API, and the manual would show none of them. This extension sets
each such package's exports to the stub's names, so that ``::: wbfriction.friction`` documents what
``from wbfriction.friction import ...`` gives, whatever module a name lives in today (the layout moves; the stub
follows it).

:class:`ContinuedItems`: in a Google-style section (``Args:``, ``Raises:``, ...), a line at an item's indentation
that does not start a new item (``name: text``) continues the item above, as its author meant
(``InputError: ...; ModelError: soles not flat in the reference`` / ``posture, or a step out of reach``): it is
indented one level more, so that griffe pairs it instead of warning. Every other docstring warning stays on (the
manual is built with ``--strict``).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import griffe

SECTION = re.compile(r"^(\s*)(Args|Arguments|Parameters|Raises|Exceptions|Returns|Yields|Attributes|Other Parameters|"
                     r"Warns|Warnings|Receives|Keyword Args|Keyword Arguments|Methods|Functions|Classes|Modules):\s*$")
ITEM = re.compile(r"^[\w.*\[\], |]+(\s*\([^)]*\))?:(\s|$)")


def _lazy(module: griffe.Module) -> bool:
    """Whether the package's ``__init__.py`` loads its names on first use: from its stub (``lazy_loader``), or
    through a module ``__getattr__`` over names imported for type checkers."""
    init = module.filepath
    if not isinstance(init, Path) or init.suffix != ".py":
        return False
    text = init.read_text(encoding="utf-8")
    return "lazy_loader.attach_stub" in text or "\ndef __getattr__(" in text


class LazyStubExports(griffe.Extension):
    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:
        todo = [pkg]
        while todo:
            module = todo.pop()
            todo.extend(m for m in module.modules.values() if not m.is_alias)
            if not module.exports and module.is_init_module and _lazy(module):  # None, or [] (unevaluated)
                module.exports = [name for name, member in module.members.items()
                                  if member.is_alias and member.target_path.startswith(pkg.name + ".")]


def continue_items(text: str) -> str:
    """``text`` with each section line at an item's indentation that starts no item indented one level more."""
    lines = text.split("\n")
    section_indent: int | None = None
    item_indent: int | None = None
    for i, line in enumerate(lines):
        if (header := SECTION.match(line)) is not None:
            section_indent, item_indent = len(header.group(1)), None
            continue
        if section_indent is None or not line.strip():
            continue
        indent = len(line) - len(line.lstrip())
        if indent <= section_indent:  # the section ended
            section_indent = item_indent = None
            continue
        if item_indent is None:
            item_indent = indent
        if indent == item_indent and not ITEM.match(line.lstrip()):
            lines[i] = "    " + line
    return "\n".join(lines)


class ContinuedItems(griffe.Extension):
    def on_package(self, *, pkg: griffe.Module, **kwargs: Any) -> None:
        todo: list[griffe.Object] = [pkg]
        while todo:
            obj = todo.pop()
            if obj.docstring is not None:
                obj.docstring.value = continue_items(obj.docstring.value)
            todo.extend(m for m in obj.members.values() if not m.is_alias)
