"""MJCF text to a tree of elements that remember their lines, and errors that name them."""
from __future__ import annotations

from dataclasses import dataclass, field
from xml.parsers import expat

from ..errors import ModelError


@dataclass
class Node:
    """One XML element with the line it starts on (and the included file it was read from,
    include.py, or None)."""
    tag: str
    attrib: dict
    line: int
    children: list = field(default_factory=list)
    file: str | None = None


def parse_xml(text: str, source: str = "<string>") -> Node:
    """Parse XML into Nodes that remember their line numbers (expat)."""
    parser = expat.ParserCreate()
    stack, root = [], []

    def start(tag, attrs):
        node = Node(tag, dict(attrs), parser.CurrentLineNumber)
        (stack[-1].children if stack else root).append(node)
        stack.append(node)

    def end(tag):
        stack.pop()

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    try:
        parser.Parse(text, True)
    except expat.ExpatError as e:
        raise ModelError(f"{source}:{e.lineno}: malformed XML: {expat.ErrorString(e.code)} "
                         f"(line {e.lineno}, column {e.offset})") from None
    return root[0]


def element_error(source: str, node: Node, msg: str) -> ModelError:
    """A ModelError naming the file (the included one for a node read from an included
    file), the element (its tag and name) and its line."""
    src = getattr(node, "file", None) or source
    return ModelError(f"{src}:{node.line}: <{node.tag}"
                      f"{' name=' + repr(node.attrib['name']) if 'name' in node.attrib else ''}> "
                      f"(line {node.line}): {msg}")
