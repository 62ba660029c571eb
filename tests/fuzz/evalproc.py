"""A real ``pmnav sim eval`` in a child process of its own session, for the tests that
stop it mid-run (SIGINT, SIGTERM) and resume it: start it, wait for finished rows, read
``results.jsonl`` as it grows (a torn last line is skipped), and never leave it running."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path


def eval_argv(out: Path, n: int, jobs: int, *more: str) -> list[str]:
    """``pmnav sim eval`` of ``n`` easy straight_office episodes with the oracle grounder
    (fast episodes: these tests are about stopping and resuming, not perception)."""
    return [
        sys.executable, "-m", "pmnav_bt.experiments.cli", "sim", "eval",
        "--building", "straight_office", "--tier", "easy", "-n", str(n),
        "--variants", "pmnav", "--worlds", "clean", "--set", "grounder.backend=sim_gt",
        "--jobs", str(jobs), "--out", str(out), *more,
    ]  # fmt: skip


def rows(path: Path) -> list[dict]:
    """The finished rows of a results.jsonl, without a torn last line."""
    try:
        text = path.read_text()
    except OSError:
        return []
    found = []
    for line in text.splitlines():
        with contextlib.suppress(ValueError):
            found.append(json.loads(line))
    return found


@contextlib.contextmanager
def running(argv: list[str]) -> Iterator[subprocess.Popen]:
    """The child in its own session (its process group holds every worker it starts);
    killed with its group on the way out if it is still running."""
    proc = subprocess.Popen(
        argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True
    )
    try:
        yield proc
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.communicate()


def wait_for_rows(proc: subprocess.Popen, path: Path, count: int, timeout: float = 120) -> None:
    """Poll until ``count`` rows are finished; fail if the child ends or time runs out."""
    deadline = time.monotonic() + timeout
    while len(rows(path)) < count and time.monotonic() < deadline:
        assert proc.poll() is None, proc.communicate()
        time.sleep(0.1)
    assert len(rows(path)) >= count, f"fewer than {count} episodes finished in {timeout:g} s"
