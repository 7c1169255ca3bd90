"""A small XML writer for the exports: elements, text, CDATA, and chosen namespace prefixes.

``xml.etree`` names prefixes itself (``ns0``) and cannot write CDATA, which Moodle XML
carries HTML in; this writes exactly what it is given.  An element whose children include
text, or that holds text by its kind, is written on one line (whitespace there would be
content); the others are indented.
"""

from __future__ import annotations

import dataclasses
from xml.sax.saxutils import escape, quoteattr

# Elements whose content is text however it is made up (a paragraph holding only a
# <strong>): written on one line, since indentation there would be content.
TEXT_ELEMENTS = frozenset({"p", "h2", "h3", "strong", "pre", "code", "simpleChoice", "text",
                           "value"})


@dataclasses.dataclass(frozen=True)
class CData:
    """Text written as ``<![CDATA[...]]>`` (split where it holds ``]]>``)."""

    text: str


@dataclasses.dataclass
class El:
    """An element: its tag (with a prefix where needed), attributes and children."""

    tag: str
    attrs: dict[str, str] = dataclasses.field(default_factory=dict)
    children: list[El | str | CData] = dataclasses.field(default_factory=list)

    def add(self, *children: El | str | CData | None) -> El:
        self.children.extend(c for c in children if c is not None and c != "")
        return self


def el(tag: str, attrs: dict[str, str | None] | None = None,
       *children: El | str | CData | None) -> El:
    """An element; attributes whose value is None are left out."""
    kept = {k: v for k, v in (attrs or {}).items() if v is not None}
    return El(tag, kept).add(*children)


def _cdata(text: str) -> str:
    return "<![CDATA[" + text.replace("]]>", "]]]]><![CDATA[>") + "]]>"


def _write(node: El | str | CData, depth: int, out: list[str], indent: bool) -> None:
    pad = "\n" + "  " * depth if indent else ""
    if isinstance(node, str):
        out.append(escape(node))
        return
    if isinstance(node, CData):
        out.append(_cdata(node.text))
        return
    attrs = "".join(f" {k}={quoteattr(v)}" for k, v in node.attrs.items())
    out.append(f"{pad}<{node.tag}{attrs}")
    if not node.children:
        out.append("/>")
        return
    out.append(">")
    mixed = node.tag in TEXT_ELEMENTS or any(not isinstance(c, El) for c in node.children)
    for child in node.children:
        _write(child, depth + 1, out, indent and not mixed)
    if indent and not mixed:
        out.append(pad)
    out.append(f"</{node.tag}>")


def to_xml(root: El) -> str:
    """The document: an XML declaration, then ``root`` indented, UTF-8 text."""
    out = ['<?xml version="1.0" encoding="UTF-8"?>']
    _write(root, 0, out, True)
    return "".join(out) + "\n"
