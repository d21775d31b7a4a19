"""A one-line progress bar on stderr for runs longer than a couple of seconds.

It stays silent when disabled (``--quiet``), when stderr is not a terminal, and during the first
``delay`` seconds, so short runs and logs/CI print nothing."""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import TextIO


class ProgressBar:
    def __init__(self, label: str, *, enabled: bool = True, stream: TextIO | None = None,
                 delay: float = 2.0, width: int = 30):
        self.stream = stream or sys.stderr
        self.enabled = enabled and hasattr(self.stream, "isatty") and self.stream.isatty()
        self.label, self.delay, self.width = label, delay, width
        self.started = time.monotonic()
        self.last_drawn = 0.0
        self.drawn = False
        self.length = 0

    def __call__(self, fraction: float) -> None:
        if not self.enabled:
            return
        now = time.monotonic()
        elapsed = now - self.started
        if elapsed < self.delay or (now - self.last_drawn < 0.2 and fraction < 1.0):
            return
        self.last_drawn = now
        filled = int(self.width * fraction)
        remaining = elapsed * (1.0 - fraction) / fraction if fraction > 0 else float("nan")
        line = (f"{self.label} [{'#' * filled}{'.' * (self.width - filled)}] {100 * fraction:5.1f}% "
                f"{elapsed:6.1f} s, ~{remaining:5.1f} s left")
        self.stream.write("\r" + line)
        self.stream.flush()
        self.drawn = True
        self.length = len(line)

    def clear(self) -> None:
        """Take the bar off its line (before another line is printed; the next call draws it again)."""
        if self.drawn:
            self.stream.write("\r" + " " * self.length + "\r")
            self.stream.flush()
            self.drawn = False
            self.last_drawn = 0.0

    def close(self) -> None:
        if self.drawn:
            self.stream.write("\n")
            self.stream.flush()


class Stages:
    """One progress callback over ``total`` stages of equal weight (the runs of a job):
    ``stage(k)`` is the callback of stage ``k`` (0-based), telling ``progress`` (k + f) / total."""

    def __init__(self, progress: Callable[[float], None] | None, total: int):
        self.progress, self.total = progress, max(1, total)

    def stage(self, k: int) -> Callable[[float], None] | None:
        if self.progress is None:
            return None
        progress, total = self.progress, self.total
        return lambda fraction: progress(min(1.0, (k + fraction) / total))
