"""The background worker: results, errors, cancellation."""

from __future__ import annotations

import threading
import time

import pytest

from pmnav_bt.worker import Worker


def test_result_and_error():
    w = Worker()
    ok = w.submit(lambda c: 41 + 1)
    bad = w.submit(lambda c: 1 / 0)
    w.drain(5)
    assert ok.done() and ok.result() == 42
    with pytest.raises(ZeroDivisionError):
        bad.result()
    w.shutdown()


def test_cancel_sets_the_event_of_a_running_job_and_drops_a_queued_one():
    w = Worker(threads=1)
    started = threading.Event()
    seen_cancel = threading.Event()

    def long(cancelled):
        started.set()
        while not cancelled.is_set():
            time.sleep(0.001)
        seen_cancel.set()
        return "stopped"

    running = w.submit(long)
    queued = w.submit(lambda c: "never")
    assert started.wait(5)
    assert w.busy()
    queued.cancel()
    running.cancel()
    assert seen_cancel.wait(5)
    w.drain(5)
    assert not w.busy()
    assert queued.cancelled.is_set()
    w.shutdown()
