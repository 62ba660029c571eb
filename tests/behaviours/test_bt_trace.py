"""The trace's frames (``behaviours/context.py``): a leaf logs the frame it saw in the tick,
and the worker shrinks it to the trace's thumbnail (a third of a millisecond: not in a
tick), on the test doubles."""

from __future__ import annotations

import math

import numpy as np

from pmnav_bt.behaviours.context import thumbnail
from pmnav_bt.seams import Pose2D

START = Pose2D(0.0, 28.0, math.radians(-90))


def frame(h: int = 480, w: int = 640) -> np.ndarray:
    """A frame whose thumbnail tells it from another: a gradient across it."""
    return np.broadcast_to(np.linspace(0, 255, w, dtype=np.uint8)[None, :, None], (h, w, 3)).copy()


def test_a_frame_logged_in_a_tick_is_shrunk_in_the_worker(make_rig, thumbnails_off_the_tick):
    rig = make_rig(START)
    rgb = frame()
    rig.ctx.log("fix", "2 signs", rgb, attempts=1)  # what a leaf does in its tick
    event = rig.ctx.trace[-1]
    assert thumbnails_off_the_tick == [] and event.frame is rgb  # nothing shrunk yet
    rig.wait()  # between ticks: the worker's jobs run
    assert len(thumbnails_off_the_tick) == 1
    assert thumbnails_off_the_tick[0].startswith("pmnav-worker")
    assert event.frame is None  # the full frame is not kept
    assert event.thumbnail.shape == (72, 96, 3)
    assert np.array_equal(event.thumbnail, thumbnail(rgb))
    assert len(thumbnails_off_the_tick) == 1  # read, not made again


def test_an_event_whose_shrinking_never_ran_is_shrunk_when_read(make_rig):
    rig = make_rig(START)
    rgb = frame(240, 320)
    rig.ctx.log("obstacle", "", rgb, free=0.8)  # the run's last tick: no drain after it
    rig.ctx.worker.shutdown()  # the shrinking job is dropped with the worker
    event = rig.ctx.trace[-1]
    assert event.frame is rgb
    assert np.array_equal(event.thumbnail, thumbnail(rgb)) and event.frame is None


def test_an_event_without_a_frame_has_no_thumbnail(make_rig):
    rig = make_rig(START)
    rig.ctx.log("plan", "room3", steps=[])
    rig.wait()
    assert rig.ctx.trace[-1].thumbnail is None
