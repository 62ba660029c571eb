"""A plate seen near the target but not read: the tree drives where it reads and reads it;
a plate never read is tried ``tree.active_reads`` times, then the search moves on."""

from __future__ import annotations

import math

import pytest

from pmnav_bt.failures import FailureCode
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.seams import Pose2D
from pmnav_bt.testing.doubles import ScriptedGrounder

START = Pose2D(4.0, 0.0, 0.0)  # straight_office, facing east down the corridor
KITCHEN_DOOR = (48.5, 1.1)  # room13, 1.1 m off the corridor's centre line
MAX_TICKS = 20_000
# A reading model (not the oracle's): the reading pose comes from its plate ranges.
OCR = "grounder.backend=ocr"


@pytest.fixture(scope="module")
def building():
    return load_building("straight_office")


def kitchen_read_within(pm, metres: float) -> ScriptedGrounder:
    """The goal's sign read only from nearer than ``metres``; farther, an unread plate."""
    return ScriptedGrounder(pm, readable_within={"room13": metres})


def reads(rig) -> list:
    return [e for e in rig.ctx.trace if e.kind == "active_read" and e.label == "room13"]


def test_an_unread_plate_is_read_from_nearer_and_the_goal_reached(make_rig, pm):
    # From the centre line the door is 1.1 m off at best: read from 1.0 m, never from there.
    rig = make_rig(START, grounder=kitchen_read_within(pm, 1.0), overrides=(OCR,))
    out = rig.mission("Kitchen", max_ticks=MAX_TICKS)
    assert out.success, out.failure
    went = reads(rig)
    assert 1 <= len(went) <= rig.ctx.config.tree.active_reads
    assert went[-1].data["distance_m"] <= 1.0  # the last try stood where it reads
    done = [e.data["read"] for e in rig.ctx.trace if e.kind == "active_read_done"]
    assert done[-1] is True and done.count(True) == 1
    p = rig.true_pose()
    assert math.dist((p.x, p.y), KITCHEN_DOOR) < 1.0


def test_without_active_reading_the_same_plate_is_never_read(make_rig, pm):
    grounder = kitchen_read_within(pm, 1.0)
    rig = make_rig(START, grounder=grounder, overrides=(OCR, "tree.active_reads=0"))
    out = rig.mission("Kitchen", max_ticks=MAX_TICKS)
    assert not out.success and not reads(rig)
    assert FailureCode.TARGET_NOT_FOUND in (out.failure.code, getattr(out.cause, "code", None))


def test_a_plate_never_read_is_tried_n_times_then_the_search_moves_on(make_rig, pm):
    rig = make_rig(START, grounder=kitchen_read_within(pm, 0.0), overrides=(OCR,))
    out = rig.mission("Kitchen", max_ticks=MAX_TICKS)
    assert not out.success
    assert len(reads(rig)) == rig.ctx.config.tree.active_reads
    assert not any(e.data["read"] for e in rig.ctx.trace if e.kind == "active_read_done")
    # each try stood nearer than where the plate was last seen unread
    assert all(e.data["distance_m"] < e.data["seen_m"] for e in reads(rig))
    assert FailureCode.TARGET_NOT_FOUND in (out.failure.code, getattr(out.cause, "code", None))
