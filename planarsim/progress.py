"""Progress bars on stderr for work that takes longer than a second (no heavy imports here).

``TextProgress(total, label)(done)`` redraws one line ``[#####.....] 30/60 frames`` (on a
terminal only: nothing goes into a pipe or a log);
``progress_for(progress, total, label)`` turns the usual ``progress=`` argument (True, False,
or a callable(done, total)) into a callable(done); ``Elapsed(label)`` shows the seconds spent
on work that has no count (a compiled simulation call) once it passes a second.
"""
from __future__ import annotations

import sys


class TextProgress:
    """A one-line text progress bar on stderr: ``[#####.....] 30/60 frames``.

    On stderr (no `stream` given) the bar is drawn only when stderr is a terminal: a pipe or
    a log gets no carriage returns. A `stream` given is drawn on as asked."""

    def __init__(self, total: int, label: str = "frames", stream=None, width: int = 30):
        self.total, self.label, self.width = int(total), label, width
        self.enabled = stream is not None or stderr_is_terminal()
        self.stream = stream if stream is not None else sys.stderr
        self._last = -1

    def __call__(self, done: int) -> None:
        if not self.enabled:
            return
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


class Elapsed:
    """A context manager that, once the work inside has taken `delay` seconds, shows
    ``label ... 2.3 s`` on stderr, updated every `every` seconds by a background thread (for
    work with no count to show, a simulation in one compiled call, say), and ends the line
    when the work ends. Nothing is written for work that ends within `delay`."""

    def __init__(self, label: str, enabled: bool = True, delay: float = 1.0, every: float = 0.1,
                 stream=None):
        self.label, self.enabled, self.delay, self.every = label, bool(enabled), float(delay), float(every)
        self.stream = stream if stream is not None else sys.stderr
        self.shown = False

    def __enter__(self):
        import threading
        import time
        self._clock = time.perf_counter
        self._start = self._clock()
        self._stop = threading.Event()
        self._thread = None
        if self.enabled:
            self._thread = threading.Thread(target=self._run, name="planarsim-elapsed", daemon=True)
            self._thread.start()
        return self

    def _write(self, end=""):
        self.stream.write(f"\r{self.label} ... {self._clock() - self._start:.1f} s{end}")
        self.stream.flush()
        self.shown = True

    def _run(self):
        if self._stop.wait(self.delay):
            return
        while not self._stop.wait(self.every):
            self._write()

    def __exit__(self, *exc):
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            if self.shown:
                self._write("\n")
        return False
