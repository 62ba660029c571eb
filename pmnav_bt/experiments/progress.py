"""Progress of a long run: a rich bar with rate and ETA on a terminal, timed lines in a log.

Rate and ETA count only the runs of this session (resumed ones are done already).
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import TextIO

LOG_INTERVAL_S = 30.0


def _duration(seconds: float) -> str:
    s = int(round(seconds))
    h, rem = divmod(s, 3600)
    m, s = divmod(rem, 60)
    return f"{h}h{m:02d}m" if h else f"{m}m{s:02d}s"


class LogProgress:
    """One line per finished run while runs are slow, at most one per ``interval``
    seconds otherwise, and always the last: done/total, rate per hour, ETA."""

    def __init__(
        self,
        total: int,
        already: int = 0,
        what: str = "episodes",
        interval: float = LOG_INTERVAL_S,
        stream: TextIO | None = None,
        clock: Callable[[], float] = time.monotonic,
    ):
        self.total, self.already, self.what = total, already, what
        self.interval, self.clock = interval, clock
        self.stream = stream or sys.stderr
        self.t0 = self.last = clock()
        self.last_done = already

    def line(self, done: int, note: str = "") -> str:
        elapsed = max(self.clock() - self.t0, 1e-9)
        new = done - self.already
        text = f"{done}/{self.total} {self.what}"
        if new > 0:
            rate = new / elapsed
            eta = (self.total - done) / rate
            text += f"; {rate * 3600:.0f}/h; ETA {_duration(eta)}"
        return text + (f" ({note})" if note else "")

    def __call__(self, done: int, note: str = "") -> None:
        now = self.clock()
        slow = now - self.last >= self.interval
        per_run = (now - self.last) / max(1, done - self.last_done)
        if slow or per_run >= self.interval / 10 or done >= self.total or done == self.already + 1:
            print(self.line(done, note), file=self.stream, flush=True)
            self.last, self.last_done = now, done


def bar_columns():
    """The rich progress bar's columns: description, bar, done/total, rate, elapsed, ETA."""
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        TaskProgressColumn,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    return (
        TextColumn("[progress.description]{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TaskProgressColumn(),
        TextColumn("{task.fields[rate]}"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
    )
