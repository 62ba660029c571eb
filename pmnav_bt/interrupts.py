"""Stopping a long run cleanly: SIGTERM like Ctrl-C, quiet pool workers, results kept.

``stop_signals()`` turns SIGINT and SIGTERM in the main process into ``Interrupted``;
``quiet_worker()`` (a pool initializer) makes workers ignore both, so only the parent
decides, terminates the pool and keeps what finished, and makes them end with a parent
that was killed outright. ``JsonlAppender`` writes one line per finished result,
flushed and synced, so a kill loses at most the running episodes.
"""

from __future__ import annotations

import json
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

EXIT_CODES = {"SIGINT": 130, "SIGTERM": 143}


class Interrupted(BaseException):
    """The run was stopped by SIGINT (Ctrl-C) or SIGTERM.

    A BaseException, like KeyboardInterrupt, so no ``except Exception`` on the way up
    (an episode's crash guard, for one) turns it into a result."""

    def __init__(self, signame: str):
        self.signame = signame
        super().__init__(f"stopped by {signame}")

    @property
    def exit_code(self) -> int:
        return EXIT_CODES.get(self.signame, 1)


_deferring = 0  # > 0 inside signals_deferred()
_pending: list[str] = []  # a stop that arrived while deferring


@contextmanager
def stop_signals() -> Iterator[None]:
    """Within the block, SIGINT and SIGTERM raise Interrupted in the main thread."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, _frame):
        # Once is enough: a second signal while cleaning up must not break the cleanup.
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        name = signal.Signals(signum).name
        if _deferring:
            _pending.append(name)
            return
        raise Interrupted(name)

    old = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, h)


@contextmanager
def signals_deferred() -> Iterator[None]:
    """Within the block, a stop from ``stop_signals`` waits and is raised as the block
    ends: a result row is written and counted whole, or not at all."""
    global _deferring
    _deferring += 1
    try:
        yield
    finally:
        _deferring -= 1
    if not _deferring and _pending:
        name = _pending.pop()
        _pending.clear()
        raise Interrupted(name)


def quiet_worker(parent: int) -> None:
    """Pool initializer: a worker ignores SIGINT/SIGTERM from the terminal's process group
    (the parent stops it with terminate()), and ends with its ``parent``: a parent killed
    outright (SIGKILL) can stop nothing, and its workers would run their episode on and
    die on the broken pipe with a traceback."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    end_with_parent(parent)


PARENT_POLL_S = 0.5  # where the kernel cannot tell us, how often a worker looks


def end_with_parent(parent: int) -> None:
    """End this process, quietly (no cleanup, no traceback), as soon as ``parent`` has gone.

    On Linux the kernel sends SIGKILL the moment the parent dies (``PR_SET_PDEATHSIG``);
    elsewhere a daemon thread compares ``os.getppid()`` with ``parent`` every
    PARENT_POLL_S. A parent gone before this call (the worker is then the child of
    init) is caught by the same comparison, made once here."""
    if not _death_signal(signal.SIGKILL):
        def watch() -> None:
            while os.getppid() == parent:
                time.sleep(PARENT_POLL_S)
            os._exit(0)

        threading.Thread(target=watch, name="pmnav-parent-watch", daemon=True).start()
    if os.getppid() != parent:
        os._exit(0)


def _death_signal(sig: int) -> bool:
    """Ask the kernel for ``sig`` when the parent dies; False where it cannot (not Linux)."""
    if not sys.platform.startswith("linux"):
        return False
    import ctypes

    pr_set_pdeathsig = 1  # <linux/prctl.h>
    libc = ctypes.CDLL(None, use_errno=True)
    return libc.prctl(pr_set_pdeathsig, int(sig), 0, 0, 0) == 0


class JsonlAppender:
    """Append one JSON object per line to a file, each line flushed and synced."""

    def __init__(self, path: str | Path, mode: str = "w"):
        self.path = Path(path)
        self._f = open(self.path, mode, encoding="utf-8")  # noqa: SIM115 - closed in close()
        self.count = 0

    def write(self, record: dict[str, Any]) -> None:
        self._f.write(json.dumps(record) + "\n")
        self._f.flush()
        os.fsync(self._f.fileno())
        self.count += 1

    def close(self) -> None:
        self._f.close()

    def __enter__(self) -> JsonlAppender:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
