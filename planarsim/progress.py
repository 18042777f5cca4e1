"""Progress bars on stderr for work that takes longer than a second (no heavy imports here).

``TextProgress(total, label)(done)`` redraws one line ``[#####.....] 30/60 frames``;
``progress_for(progress, total, label)`` turns the usual ``progress=`` argument (True, False,
or a callable(done, total)) into a callable(done).
"""
from __future__ import annotations

import sys


class TextProgress:
    """A one-line text progress bar on stderr: ``[#####.....] 30/60 frames``."""

    def __init__(self, total: int, label: str = "frames", stream=None, width: int = 30):
        self.total, self.label, self.width = int(total), label, width
        self.stream = stream if stream is not None else sys.stderr
        self._last = -1

    def __call__(self, done: int) -> None:
        filled = int(self.width * done / max(1, self.total))
        if filled == self._last and done < self.total:
            return
        self._last = filled
        bar = "#" * filled + "." * (self.width - filled)
        end = "\n" if done >= self.total else ""
        self.stream.write(f"\r[{bar}] {done}/{self.total} {self.label}{end}")
        self.stream.flush()


def progress_for(progress, total: int, label: str):
    """callable(done) for `progress`: True a TextProgress, a callable(done, total), or a no-op."""
    if progress is True:
        return TextProgress(total, label)
    if callable(progress):
        return lambda done: progress(done, total)
    return lambda done: None


def stderr_is_terminal() -> bool:
    """Whether stderr is an interactive terminal (where a redrawn bar makes sense)."""
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False
