"""Issue 42: ``pmnav sim eval``'s main process killed outright (SIGKILL: no handler runs,
nothing terminates the pool). Its pool workers used to run on for about 14 s and die on
the broken pipe with tracebacks; now they end with it, quietly, within a few seconds."""

from __future__ import annotations

import os
import signal
import sys
import time

import pytest
from evalproc import eval_argv, running
from fuzzkit import TRIED
from test_eval_interrupt import _session

pytestmark = [
    pytest.mark.timeout(180),
    pytest.mark.skipif(sys.platform != "linux", reason="reads /proc"),
]


def _workers(sid: int) -> list[int]:
    """The pool workers among the live processes of session ``sid`` (multiprocessing's
    spawn starts them as ``python -c 'from multiprocessing.spawn import spawn_main ...'``)."""
    found = []
    for pid in _session(sid):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                if b"spawn_main" in f.read():
                    found.append(pid)
        except OSError:
            continue
    return found


def test_pool_workers_end_with_a_killed_parent(tmp_path):
    TRIED["sim eval: parent killed (SIGKILL)"] += 1
    with running(eval_argv(tmp_path / "eval", 20, 2)) as proc:
        deadline = time.monotonic() + 90
        while len(_workers(proc.pid)) < 2 and time.monotonic() < deadline:
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.2)
        workers = _workers(proc.pid)
        assert len(workers) == 2, "the pool's workers never started"
        time.sleep(3)  # into their first episodes
        os.kill(proc.pid, signal.SIGKILL)  # the parent only, as the OOM killer would
        proc.wait(timeout=10)
        deadline = time.monotonic() + 5
        while any(p in _session(proc.pid) for p in workers) and time.monotonic() < deadline:
            time.sleep(0.1)
        left = [p for p in workers if p in _session(proc.pid)]
        _, err = proc.communicate(timeout=30)  # the pipes close when every writer is gone
    assert left == [], f"workers {left} outlived their parent by 5 s"
    assert "Traceback" not in err and "BrokenPipeError" not in err, err[-2000:]
