"""A Griffe extension that lets bendpam's reStructuredText habits render as Markdown.

bendpam's docstrings are NumPy style, written for ``help()`` and Sphinx habits: ``:func:`name```
roles, ``Text::`` before a literal block and ``>>>`` examples outside an ``Examples`` section.
MkDocs renders docstrings as Markdown, where a role shows its colons, ``::`` stays and ``>>>`` is a
nested quote.  On every docstring, before it is parsed (mkdocs.yml, mkdocstrings ``extensions``):

* ``:func:`~a.b.c``` becomes ```c```, ``:class:`a.b``` becomes ```a.b``` (any role);
* a line ending in ``::`` ends in ``:`` (the indented block after it is a code block already);
* in prose, a ``*`` between two words (``N*mm``) is escaped, so that it is not read as emphasis;
* a run of ``>>>`` lines with their continuation and output lines, outside an ``Examples``
  section, is fenced as a ``pycon`` code block.

The docstrings themselves are not changed (``help()`` and the doctests see them as written).
"""

from __future__ import annotations

import re
from typing import Any

import griffe

_ROLE = re.compile(r":(?:py:)?[a-z]+:`(~?)([^`<>]+?)`")
_SECTION_RULE = re.compile(r"^\s*-{3,}\s*$")
_EXAMPLE_TITLES = {"examples", "example"}
_STAR = re.compile(r"(?<=[\w)])\*(?=[\w(])")


def _escape_stars(line: str) -> str:
    parts = line.split("`")
    return "`".join(p if i % 2 else _STAR.sub(r"\\*", p) for i, p in enumerate(parts))


def _role(m: re.Match[str]) -> str:
    target = m.group(2).strip()
    if m.group(1):
        target = target.rsplit(".", 1)[-1]
    return f"`{target}`"


def markdown_docstring(text: str) -> str:
    """The Markdown-friendly form of one docstring (see the module docstring)."""
    text = _ROLE.sub(_role, text)
    lines = text.split("\n")
    out: list[str] = []
    section = ""
    literal: int | None = None  # indentation of the line that opened an RST literal block
    fenced = False
    i = 0
    while i < len(lines):
        line = lines[i]
        if i + 1 < len(lines) and line.strip() and _SECTION_RULE.match(lines[i + 1]):
            section = line.strip().lower()
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if literal is not None and stripped and indent <= literal:
            literal = None
        if stripped.startswith("```"):
            fenced = not fenced
        code = fenced or literal is not None or section in _EXAMPLE_TITLES or stripped.startswith(("```", "..."))
        if stripped.startswith(">>>") and section not in _EXAMPLE_TITLES:
            pad = line[:indent]
            block = []
            while i < len(lines) and lines[i].strip():
                block.append(lines[i][len(pad):] if lines[i].startswith(pad) else lines[i].strip())
                i += 1
            out += [f"{pad}```pycon", *(f"{pad}{b}" for b in block), f"{pad}```"]
            continue
        if not code and stripped:
            line = _escape_stars(line)
        if line.rstrip().endswith("::") and not stripped.startswith(("..", ">>>")):
            literal = indent
            line = line.rstrip()[:-2].rstrip()
            line = line + ":" if line and not line.endswith(":") else line
        out.append(line)
        i += 1
    return "\n".join(out)


class ReadableDocstrings(griffe.Extension):
    """Rewrite each docstring with :func:`markdown_docstring` when Griffe creates the object."""

    def on_instance(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = markdown_docstring(obj.docstring.value)
