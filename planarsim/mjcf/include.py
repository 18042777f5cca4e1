"""MJCF ``<include file="...">``: the included file's top-level ``<mujoco>`` children take the
include element's place, wherever it stands (as MuJoCo does).

Where an included file is looked for, in order:

* ``assets`` (a dict: name -> bytes or str, as ``mujoco.MjModel.from_xml_string(xml,
  assets)`` takes it): the name as given, then joined to the including asset's directory;
  names compare after normalisation ("./common/skybox.xml" and "common/skybox.xml" are one
  name);
* on disk: next to the main file (for XML text given as a string: the current directory),
  then next to the including file. This is MuJoCo's order (checked with MuJoCo 4.0): where
  both directories hold the name, the main file's directory wins.

Included files may include others (a file that includes itself, directly or not, is a
ModelError naming the chain). Every node read from an included file remembers it
(``node.file``): error messages and the load report name it. Which of the included
elements carry physics is the loader's business: ``<asset>``, ``<visual>`` and the like are
ignored and reported as for the main file.
"""
from __future__ import annotations

import os
import posixpath
from pathlib import Path

from ..errors import ModelError

MAX_DEPTH = 32      # includes within includes; deeper is a cycle MuJoCo would refuse too


def _norm(name: str) -> str:
    return posixpath.normpath(str(name).replace("\\", "/"))


def decode(data, what) -> str:
    """UTF-8 bytes -> str (a byte order mark, as some editors write, dropped), or a
    ModelError naming what they are."""
    try:
        return bytes(data).decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise ModelError(f"{what} is not UTF-8 text: {e}") from None


def _text(data, name) -> str:
    if isinstance(data, (bytes, bytearray)):
        return decode(data, f"included file {name!r} (from assets)")
    if isinstance(data, str):
        return data
    raise ModelError(f"assets[{name!r}] must be bytes or str, got {type(data).__name__}")


def origin(node) -> str:
    """' in FILE' for a node read from an included file, else ''."""
    f = getattr(node, "file", None)
    return f" in {f}" if f else ""


def _walk(node, parent=None):
    yield node, parent
    for c in node.children:
        yield from _walk(c, node)


def resolve_includes(root, source: str, base_dir, assets, parse):
    """Replace every <include file=...> under ``root`` by the included file's top-level
    children, recursively. source: the main file's name for messages; base_dir: its
    directory (None: XML text, includes then resolve against the current directory);
    assets: None or dict name -> bytes | str; parse(text, name) -> root node."""
    if assets is not None and not isinstance(assets, dict):
        raise ModelError(f"load_mjcf: assets must be a dict (file name -> bytes or str), got "
                         f"{type(assets).__name__}")
    norm_assets = {}
    for k, v in (assets or {}).items():
        norm_assets.setdefault(_norm(k), (k, v))
    main_dir = Path(base_dir) if base_dir is not None else Path.cwd()
    _expand(root, source, None, main_dir, norm_assets, parse, (source,))
    return root


def _expand(root, source, own_dir, main_dir, assets, parse, chain):
    """own_dir: the including file's directory on disk, or for an asset its name's
    directory (a str); None for the main file."""
    if len(chain) > MAX_DEPTH:
        raise ModelError(f"includes nest deeper than {MAX_DEPTH}: {' -> '.join(chain)}")
    for node, parent in list(_walk(root)):
        if node.tag != "include":
            continue
        where = f"{source}:{node.line}: <include> (line {node.line})"
        extra = sorted(set(node.attrib) - {"file"})
        if extra:
            raise ModelError(f"{where}: attribute(s) {extra} not supported (only file=)")
        if node.children:
            raise ModelError(f"{where}: an <include> has no child elements")
        if parent is None:
            raise ModelError(f"{where}: the root element cannot be an <include>")
        fname = node.attrib.get("file", "").strip()
        if not fname:
            raise ModelError(f"{where}: file= is required (the file to include)")
        text, name, sub_dir = _find(fname, source, own_dir, main_dir, assets, where)
        if name in chain:
            raise ModelError(f"{where}: file={fname!r} includes itself: "
                             f"{' -> '.join(chain + (name,))}")
        sub = parse(text, name)
        if sub.tag != "mujoco":
            raise ModelError(f"{name}:{sub.line}: <{sub.tag}> (line {sub.line}): an included "
                             f"file's root element must be <mujoco> (included by {where})")
        extra = sorted(set(sub.attrib) - {"model"})
        if extra:
            raise ModelError(f"{name}:{sub.line}: <mujoco> (line {sub.line}): attribute(s) "
                             f"{extra} not supported in an included file")
        for n, _ in _walk(sub):
            if getattr(n, "file", None) is None:
                n.file = name
        _expand(sub, name, sub_dir, main_dir, assets, parse, chain + (name,))
        k = next(i for i, c in enumerate(parent.children) if c is node)
        parent.children[k:k + 1] = sub.children


def _find(fname, source, own_dir, main_dir, assets, where):
    """(text, name for messages, directory for its own includes) of an included file."""
    tried = []
    if assets:
        keys = [_norm(fname)]
        if isinstance(own_dir, str):
            keys.append(_norm(posixpath.join(own_dir, fname)))
        for key in keys:
            if key in assets:
                orig, data = assets[key]
                return _text(data, orig), orig, posixpath.dirname(key)
        tried.append(f"assets {sorted(set(keys))} (assets has {sorted(k for k, _ in assets.values())})")
    dirs = [d for d in (main_dir, own_dir if isinstance(own_dir, Path) else None) if d is not None]
    for d in dict.fromkeys(dirs):
        path = Path(d) / fname if not os.path.isabs(fname) else Path(fname)
        tried.append(str(path))
        if path.is_file():
            try:
                return path.read_text(), str(path), path.parent
            except OSError as e:
                raise ModelError(f"{where}: cannot read included file {str(path)!r}: "
                                 f"{e.strerror}") from None
    raise ModelError(f"{where}: included file {fname!r} not found (included by {source}; "
                     f"looked in: {'; '.join(tried)})")
