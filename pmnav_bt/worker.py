"""Background work for behaviours: a tick submits, later ticks poll, terminate() cancels.

docs/architecture.md: a tick never blocks. Anything slower than a few milliseconds (rendering a
panorama, OCR, a network call) runs here. A job gets a ``cancelled`` event it may
check between stages; cancelling a job that has not started drops it.

Two modes:
- immediate (on the robot): a job starts at once, in a pool thread;
- deferred (in simulation): a job starts only when the runner calls ``drain()``
  between ticks. The simulated world stands still during a tick anyway, a render
  cannot then hold the interpreter lock in the middle of a tick, and no job can end
  in the tick that submitted it, so a seed replays the same episode tick for tick.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any


class Job:
    """One piece of background work."""

    def __init__(self, fn: Callable[[threading.Event], Any]):
        self.fn = fn
        self.cancelled = threading.Event()
        self._future: Future | None = None

    def _start(self, pool: ThreadPoolExecutor) -> None:
        if self._future is None:
            self._future = pool.submit(self.fn, self.cancelled)
            if self.cancelled.is_set():
                self._future.cancel()

    def started(self) -> bool:
        return self._future is not None

    def done(self) -> bool:
        return self._future is not None and self._future.done()

    def result(self) -> Any:
        """The result (raises the job's exception). Call only when done()."""
        if self._future is None:
            raise RuntimeError("the job has not run yet")
        return self._future.result(timeout=0)

    def cancel(self) -> None:
        self.cancelled.set()
        if self._future is not None:
            self._future.cancel()

    def wait(self, timeout: float | None = None) -> None:
        """Block until the job ends (runners and tests only; never from a tick)."""
        if self._future is None:
            return
        # A cancelled or timed-out job has nothing more to wait for.
        with contextlib.suppress(Exception):
            self._future.exception(timeout=timeout)


class Worker:
    """A small pool shared by a tree's behaviours."""

    def __init__(self, threads: int = 1, deferred: bool = False):
        self._pool = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="pmnav-worker")
        self.deferred = deferred
        self._jobs: list[Job] = []
        self._lock = threading.Lock()

    def submit(self, fn: Callable[[threading.Event], Any]) -> Job:
        """Run ``fn(cancelled_event)`` in the background (now, or at the next drain)."""
        job = Job(fn)
        with self._lock:
            self._jobs = [j for j in self._jobs if not j.done()]
            self._jobs.append(job)
        if not self.deferred:
            job._start(self._pool)
        return job

    def busy(self) -> bool:
        with self._lock:
            return any(not j.done() and not j.cancelled.is_set() for j in self._jobs)

    def drain(self, timeout: float | None = None) -> None:
        """Start any deferred jobs and wait for every job in flight (between ticks only)."""
        with self._lock:
            jobs = list(self._jobs)
        for j in jobs:
            if not j.cancelled.is_set():
                j._start(self._pool)
        for j in jobs:
            j.wait(timeout)

    def shutdown(self) -> None:
        with self._lock:
            for j in self._jobs:
                j.cancel()
        self._pool.shutdown(wait=True, cancel_futures=True)
