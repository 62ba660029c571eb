"""Background work for behaviours: a tick submits, later ticks poll, terminate() cancels.

DESIGN.md: a tick never blocks. Anything slower than a few milliseconds (rendering a
panorama, OCR, a network call) runs here. A job gets a ``cancelled`` event it may
check between stages; cancelling a job that has not started drops it.
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from typing import Any


class Job:
    """One piece of background work."""

    def __init__(self, future: Future, cancelled: threading.Event):
        self._future = future
        self.cancelled = cancelled

    def done(self) -> bool:
        return self._future.done()

    def result(self) -> Any:
        """The result (raises the job's exception). Call only when done()."""
        return self._future.result(timeout=0)

    def cancel(self) -> None:
        self.cancelled.set()
        self._future.cancel()

    def wait(self, timeout: float | None = None) -> None:
        """Block until the job ends (runners and tests only; never from a tick)."""
        # A cancelled or timed-out job has nothing more to wait for.
        with contextlib.suppress(Exception):
            self._future.exception(timeout=timeout)


class Worker:
    """A small pool shared by a tree's behaviours."""

    def __init__(self, threads: int = 1):
        self._pool = ThreadPoolExecutor(max_workers=threads, thread_name_prefix="pmnav-worker")
        self._jobs: set[Job] = set()
        self._lock = threading.Lock()

    def submit(self, fn: Callable[[threading.Event], Any]) -> Job:
        """Run ``fn(cancelled_event)`` in the background."""
        cancelled = threading.Event()
        job = Job(self._pool.submit(fn, cancelled), cancelled)
        with self._lock:
            self._jobs = {j for j in self._jobs if not j.done()}
            self._jobs.add(job)
        return job

    def busy(self) -> bool:
        with self._lock:
            return any(not j.done() for j in self._jobs)

    def drain(self, timeout: float | None = None) -> None:
        """Wait for every job in flight (the simulation runner does this to stay repeatable)."""
        with self._lock:
            jobs = list(self._jobs)
        for j in jobs:
            j.wait(timeout)

    def shutdown(self) -> None:
        with self._lock:
            for j in self._jobs:
                j.cancel()
        self._pool.shutdown(wait=True, cancel_futures=True)
