"""A plate read as the target before the search, not seen by it, is read again from where
it reads (pybullet, the real reader): a flag sign hangs 2.3 m up, and from under it the
search's level views pass below it; the tree backs off to where its text is in view."""

from __future__ import annotations

import math

import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.active_read import read_from_where_read
from pmnav_bt.behaviours.capture import CaptureViews, search_yaws
from pmnav_bt.behaviours.search import target_entity
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.signage import Signage, SignStyleSpec
from pmnav_bt.perception.unread_plates import UnreadPlate
from pmnav_bt.seams import Entity, Pose2D
from pmnav_bt.trees.active_read import read_closer_subtree

pytestmark = pytest.mark.world

FLAGS = SignStyleSpec(
    plate_width=0.3,
    cap_height=0.06,
    font="dejavu_sans",
    text_rgb=(255, 255, 255),
    plate_rgb=(22, 52, 112),
    mounting="flag",
    layout="number_only",
    height=2.3,
)


@pytest.fixture(scope="module")
def building():
    return load_building("fig2_hospital").model_copy(update={"signage": Signage(style=FLAGS)})


def _search(rig) -> list:
    cap = CaptureViews("SearchViews", rig.ctx, lambda b: search_yaws(None), target_entity)
    rig.expect(rig.run(cap, max_ticks=300), Status.SUCCESS)
    return [d for v in rig.get("views") for d in v.detections or ()]


def test_a_flag_read_before_but_not_seen_from_under_it_is_read_again(make_rig, world):
    flag = world.signs["room4"]  # room4's flag, in fig2_hospital's first corridor
    read_from = Pose2D(0.0, flag.centre[1] + 3.0, -math.pi / 2)
    rig = make_rig(
        read_from, width=320, height=240, reading_width=640, overrides=("grounder.backend=ocr",)
    )
    step = next(s for s in rig.plan("0,29,-90", "room3").steps if s.landmark == "room4")
    rig.set(target=step, map_T_odom=(0.0, 0.0, 0.0))
    assert any(d.entity == Entity.room("room4") for d in _search(rig))  # read from 3 m
    assert rig.ctx.grounder.plate_named(Entity.room("room4")) is not None

    rig.body.set_pose(Pose2D(0.0, flag.centre[1] + 1.0, -math.pi / 2))  # under it
    assert not _search(rig)  # above every view

    rig.expect(rig.run(read_closer_subtree(rig.ctx), max_ticks=3000), Status.SUCCESS)
    assert rig.get("sighting").entity == Entity.room("room4")
    (went,) = [e for e in rig.ctx.trace if e.kind == "active_read"]
    assert went.data["read"]  # the plate read before, not an unread one
    p = rig.true_pose()
    assert math.dist((p.x, p.y), flag.centre) > 1.5  # backed off to see it


def test_a_flag_read_before_is_read_again_from_the_side_it_was_read_from():
    # A flag across the corridor, read from 4 m down it: depth gave its wall's normal
    # (+x), from which its text is seen edge-on; it is read again from down the corridor.
    flag = UnreadPlate((0.0, 0.0), (1.0, 0.0), 2.3, 2.35, 0.06, 0.3, 5.0, (1.0, 4.0), "135")
    again = read_from_where_read(flag)
    assert again.normal == pytest.approx((1.0 / math.hypot(1, 4), 4.0 / math.hypot(1, 4)))
    assert again.xy == flag.xy and again.read == "135"
