"""The one decorator every kernel uses, and the guard against stale numba caches.

cache=True: compiled once per machine, loaded from disk afterwards.
fastmath=False: fastmath lets LLVM assume no NaNs and would remove the isfinite guards.
_nrt=False: kernels never allocate; without the runtime's reference counting, passing the
model/state/workspace NamedTuples (dozens of arrays) between stages costs nothing, where
with it every call increments and decrements every array (about 1 us per call).

Numba checks a cached function against its own file only; a kernel that calls into another
file would keep stale machine code after that file changes. ``_drop_stale_caches`` hashes all
kernel sources and clears the numba caches of planarsim and walkers when the hash changes.
"""
import hashlib
import os
from pathlib import Path

from numba import njit

_OPTIONS = dict(cache=True, fastmath=False, nogil=True, error_model="numpy", _nrt=False)

jit = njit(**_OPTIONS)
jit_inline = njit(inline="always", **_OPTIONS)


def _drop_stale_caches():
    here = Path(__file__).resolve().parent
    roots = [here.parent, here.parent.parent / "walkers"]
    digest = hashlib.blake2b(digest_size=16)
    for root in roots:
        if not root.is_dir():
            continue
        for path in sorted(root.rglob("*.py")):
            digest.update(str(path.relative_to(root)).encode())
            digest.update(path.read_bytes())
    stamp = here / "__pycache__" / "kernel_sources.hash"
    new = digest.hexdigest()
    try:
        if stamp.exists() and stamp.read_text() == new:
            return
        for root in roots:
            if root.is_dir():
                for pattern in ("*.nbi", "*.nbc"):
                    for f in root.rglob(pattern):
                        f.unlink(missing_ok=True)
        stamp.parent.mkdir(exist_ok=True)
        tmp = stamp.with_suffix(f".{os.getpid()}.tmp")
        tmp.write_text(new)
        os.replace(tmp, stamp)
    except OSError:
        pass  # read-only install: sources cannot change there either


_drop_stale_caches()
