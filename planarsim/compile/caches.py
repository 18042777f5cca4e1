"""Stale numba caches: numba checks a cached function against its own file only.

A kernel that calls into another file would keep stale machine code after that file changes.
``drop_stale_caches`` hashes all engine sources (kernels/ and compile/, and the mode) and
clears the numba caches of planarsim and walkers when the hash changes.
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

from .mode import FAST, MODE, PYTHON

_PLANARSIM = Path(__file__).resolve().parent.parent


def _sources_hash(folder: Path, extra: str = "") -> str:
    digest = hashlib.blake2b(extra.encode(), digest_size=16)
    for path in sorted(folder.rglob("*.py")):
        digest.update(str(path.relative_to(folder)).encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def _mode_tag() -> str:
    if MODE != FAST:
        return MODE
    from .fast import KERNEL_CALLS   # the kernels compile differently with it: a switch clears
    return "calls" if KERNEL_CALLS else ""


# the engine's compiled code changes with its kernels, this compiler layer and the mode
ENGINE_HASH = _sources_hash(_PLANARSIM / "compile",
                            _sources_hash(_PLANARSIM / "kernels", _mode_tag()))


def drop_stale_caches(folder, clear=None) -> None:
    """Clear the numba caches below `clear` (default `folder`) when the sources of `folder`
    or of planarsim's engine changed since the caches were written (nothing under
    NUMBA_DISABLE_JIT=1, which neither reads nor writes them).

    Walker packages call this on import with their own folder, since their rollout kernels
    link the engine's step and their controller files.
    """
    if MODE == PYTHON:
        return
    folder = Path(folder).resolve()
    clear = folder if clear is None else Path(clear).resolve()
    new = _sources_hash(folder, ENGINE_HASH)
    stamp = folder / "__pycache__" / "numba_sources.hash"
    try:
        if stamp.exists() and stamp.read_text() == new:
            return
        for pattern in ("*.nbi", "*.nbc"):
            for f in clear.rglob(pattern):
                f.unlink(missing_ok=True)
        stamp.parent.mkdir(exist_ok=True)
        tmp = stamp.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(new)
        os.replace(tmp, stamp)
    except OSError:
        pass  # read-only install: its sources cannot change either


drop_stale_caches(_PLANARSIM / "compile", clear=_PLANARSIM)
