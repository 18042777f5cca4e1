"""A griffe extension for the API reference: planarsim's docstrings are plain text laid out
by hand (aligned `name : meaning` tables, indented continuations, `>>>` sessions), not Markdown.
Rendered as Markdown their line breaks would be lost and `>>>` would read as a quotation, so
each paragraph that is laid out is kept as it stands, in a text block (a `>>>` session in a
Python console block); paragraphs of running prose, and section titles underlined with dashes,
stay Markdown. mkdocs.yml loads it (plugins: mkdocstrings: ... extensions)."""
from __future__ import annotations

import re

import griffe

_ALIGNED = re.compile(r"\S {2,}\S")               # columns: two or more spaces inside a line
_NAMED = re.compile(r"^\s*[\w.*,()\[\] ]+ : ")       # `name : meaning`
_RULE = re.compile(r"^\s*-{3,}\s*$")


def _laid_out(lines):
    if len(lines) < 2:
        return bool(lines) and bool(_NAMED.match(lines[0]) or _ALIGNED.search(lines[0].strip()))
    first = len(lines[0]) - len(lines[0].lstrip())
    return any(len(l) - len(l.lstrip()) > first for l in lines[1:]) or \
        any(_ALIGNED.search(l.strip()) or _NAMED.match(l) for l in lines)


def _fence(lines, lang):
    indent = min(len(l) - len(l.lstrip()) for l in lines if l.strip())
    return [f"```{lang}"] + [l[indent:] for l in lines] + ["```"]


def to_markdown(text: str) -> str:
    """The docstring `text` as Markdown that shows it as its author laid it out."""
    out = []
    for para in re.split(r"\n\s*\n", text.strip("\n")):
        lines = para.split("\n")
        if len(lines) >= 2 and _RULE.match(lines[1]):      # "Parameters\n----------"
            out.append(f"**{lines[0].strip()}**")
            lines = lines[2:]
            if not lines:
                continue
        if any(l.lstrip().startswith(">>>") for l in lines):
            out.append("\n".join(_fence(lines, "pycon")))
        elif _laid_out(lines):
            out.append("\n".join(_fence(lines, "text")))
        else:
            out.append("\n".join(l.strip() for l in lines))
    return "\n\n".join(out)


class PlainDocstrings(griffe.Extension):
    def on_instance(self, *, obj, **kwargs) -> None:
        if obj.docstring is not None:
            obj.docstring.value = to_markdown(obj.docstring.value)
