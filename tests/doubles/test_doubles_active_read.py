"""A plate seen near the target but not read: the tree drives where it reads and reads it;
a plate never read is tried ``tree.active_reads`` times, then the search moves on."""

from __future__ import annotations

import math

import pytest
from py_trees.common import Status

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


def test_the_plate_the_last_try_faced_is_a_candidate_of_the_next(make_rig, pm):
    # The first try faced the kitchen's plate and did not read it: the grounder saw it,
    # unread, from the reading pose. The search after it did not see it (a flag above its
    # views, a person before it): the next try still goes to it, from nearer.
    from pmnav_bt.behaviours.active_read import PlanReadingPose
    from pmnav_bt.perception.unread_plates import UnreadPlate
    from pmnav_bt.seams import View

    grounder = ScriptedGrounder(pm)
    rig = make_rig(Pose2D(45.5, 0.0, 0.0), grounder=grounder, overrides=(OCR,))
    plan = rig.ctx.planner.plan(pm, rig.ctx.base.pose(), "room13")
    rig.bb.set("target", plan.steps[-1])

    def seen_from(x: float) -> None:  # the plate, seen unread now from (x, 0)
        grounder.unread.seen(UnreadPlate(
            xy=KITCHEN_DOOR, normal=(0.0, -1.0), z=1.5, top=1.55, line_height=0.05,
            width=0.3, stamp=rig.ctx.now(), seen_from=(x, 0.0)))  # fmt: skip

    def search() -> None:  # a search's views: one frame, now
        rig.bb.set("views", [View(0.0, rig.ctx.base.observe())])

    plan_pose = PlanReadingPose("UnreadPlate", rig.ctx)
    plan_pose.setup_with_descendants()
    seen_from(45.5)
    search()
    assert rig.run(plan_pose)[-1] == Status.SUCCESS
    first = rig.get("reading_pose")
    rig.wait(2.0)
    seen_from(first.pose.x)  # faced from the reading pose, still not read
    rig.wait(2.0)
    search()  # the next search sees no plate
    assert rig.run(plan_pose)[-1] == Status.SUCCESS, plan_pose.feedback_message
    assert rig.get("reading_pose").pose.distance < first.pose.distance
