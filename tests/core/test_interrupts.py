"""Signals during a result write: the row and its count go together, the stop comes after."""

import os
import signal

import pytest

from pmnav_bt.experiments.runstore import Expected, ResultStore
from pmnav_bt.interrupts import Interrupted, signals_deferred, stop_signals


def test_a_stop_inside_a_deferred_block_arrives_after_it():
    steps = []
    with pytest.raises(Interrupted) as got, stop_signals():
        with signals_deferred():
            os.kill(os.getpid(), signal.SIGINT)
            steps.append("after the kill, still inside")
        steps.append("never: the stop arrives as the block ends")
    assert got.value.signame == "SIGINT"
    assert steps == ["after the kill, still inside"]


def test_a_stop_during_a_row_write_keeps_row_and_count_together(tmp_path, monkeypatch):
    store = ResultStore(tmp_path / "results.jsonl", [Expected("v/e0", "v", "i", "c")], False)
    real_fsync = os.fsync

    def fsync_then_stop(fd):  # the signal lands between the line and its bookkeeping
        real_fsync(fd)
        os.kill(os.getpid(), signal.SIGTERM)

    monkeypatch.setattr(os, "fsync", fsync_then_stop)
    with pytest.raises(Interrupted), stop_signals():
        store.write("v/e0", {"episode_id": "e0"})
    monkeypatch.setattr(os, "fsync", real_fsync)
    store.close()
    lines = (tmp_path / "results.jsonl").read_text().splitlines()
    assert len(lines) == 1 and store.count == 1 and "v/e0" in store.done
