"""Writing output files so that an interrupted run leaves nothing half-written behind.

A file is written under a temporary name in the system's temporary folder (staging_file),
then moved onto its final name in one step (publish): an error, Ctrl-C or even SIGKILL
while writing leaves no file at the target and none beside it. Where the temporary folder
is on another file system, the finished file is copied beside the target under a hidden
name (.NAME.PID.xxxx.part) and renamed from there; a process killed during that copy leaves
that file, and the next write to the same target (or to the temporary folder) removes the
temporary files of processes that are no longer running.
"""
from __future__ import annotations

import errno
import os
import re
import shutil
import tempfile
from pathlib import Path

_STAGING_PREFIX = "planarsim-"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:     # someone else's process: alive
        return True
    return True


def _remove_dead(folder: Path, pattern: re.Pattern) -> None:
    """Delete files in `folder` whose name matches `pattern` (group 1: the writer's pid)
    and whose writer is no longer running."""
    try:
        names = os.listdir(folder)
    except OSError:
        return
    for name in names:
        found = pattern.fullmatch(name)
        if found and not _alive(int(found.group(1))):
            try:
                os.unlink(folder / name)
            except OSError:
                pass


def remove_stale(path) -> None:
    """Remove temporary files of dead processes left beside `path` or in the staging folder."""
    path = Path(path)
    _remove_dead(path.parent if str(path.parent) else Path("."),
                 re.compile(rf"\.{re.escape(path.name)}\.(\d+)\..*\.part.*"))
    _remove_dead(Path(tempfile.gettempdir()), re.compile(rf"{_STAGING_PREFIX}(\d+)-.*\.part.*"))


def staging_file(path, suffix: str = "") -> str:
    """A new empty temporary file to write `path`'s content into (ending in `suffix`, for
    writers that go by the extension); stale ones of dead processes are removed first."""
    remove_stale(path)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f"{_STAGING_PREFIX}{os.getpid()}-",
                                   suffix=f".part{suffix}")
    except OSError:             # no usable temporary folder: stage beside the target
        fd, tmp = _beside(Path(path), suffix)
    os.close(fd)
    return tmp


def _beside(path: Path, suffix: str = ""):
    parent = path.parent if str(path.parent) else Path(".")
    return tempfile.mkstemp(prefix=f".{path.name}.{os.getpid()}.", suffix=f".part{suffix}",
                            dir=parent)


def folder_refuses(path) -> str | None:
    """Why no file can be made in `path`'s folder now (the system's words), or None: a
    temporary file is made there and removed at once. os.access says yes to root almost
    everywhere (in /proc too), so an export found out only after minutes of work."""
    try:
        fd, probe = _beside(Path(path), ".probe")
    except OSError as e:
        return e.strerror or str(e)
    os.close(fd)
    discard(probe)
    return None


def file_mode() -> int:
    """rw for everyone the umask allows (mkstemp creates files readable by the owner only)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def publish(tmp: str, path) -> None:
    """Move the finished temporary file `tmp` onto `path` in one step; an OSError names
    `path` (not the temporary file) and why it cannot be written there."""
    path = Path(path)
    os.chmod(tmp, file_mode())
    try:
        os.replace(tmp, path)
        return
    except OSError as e:
        if e.errno != errno.EXDEV:
            raise _cannot_write(path, e) from None
    try:
        fd, near = _beside(path)
    except OSError as e:        # a folder no file can be made in (/proc, a read-only mount)
        raise _cannot_write(path, e) from None
    os.close(fd)
    try:
        shutil.copyfile(tmp, near)
        os.chmod(near, file_mode())
        os.replace(near, path)
    except OSError as e:
        discard(near)
        raise _cannot_write(path, e) from None
    except BaseException:
        discard(near)
        raise
    discard(tmp)


def _cannot_write(path: Path, e: OSError) -> OSError:
    """The OSError of a file that could not be put at `path`, naming it (the error of the
    temporary file's move or copy names that file, which the caller never gave)."""
    return OSError(f"cannot write {str(path)!r}: {e.strerror or e}")


def discard(tmp) -> None:
    """Remove a temporary file (no error if it is gone)."""
    try:
        os.unlink(tmp)
    except OSError:
        pass
