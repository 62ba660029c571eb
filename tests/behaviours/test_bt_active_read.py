"""The active read in pybullet with the real reader: a small plate (30 mm capitals, a
realistic signage style) seen 2.2 m off is not read; the tree drives square to it, within
the range its text size allows, and reads it there."""

from __future__ import annotations

import math

import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.capture import CaptureViews, search_yaws
from pmnav_bt.behaviours.search import target_entity
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.signage import Signage, SignStyleSpec
from pmnav_bt.seams import Entity, Pose2D
from pmnav_bt.trees.active_read import read_closer_subtree

pytestmark = pytest.mark.world

# fig2_hospital's first corridor, facing south, 1.9 m short of level with room4's sign.
SEEN_FROM = Pose2D(0.0, 23.0, -math.pi / 2)
SMALL_PLATES = SignStyleSpec(
    plate_width=0.3,
    cap_height=0.03,
    font="dejavu_sans",
    text_rgb=(255, 255, 255),
    plate_rgb=(22, 52, 112),
    mounting="beside",
    layout="number_and_name",
    height=1.5,
)


@pytest.fixture(scope="module")
def building():
    return load_building("fig2_hospital").model_copy(
        update={"signage": Signage(style=SMALL_PLATES)}
    )


def test_a_small_plate_is_read_after_moving_closer(make_rig, world):
    rig = make_rig(
        SEEN_FROM, width=320, height=240, reading_width=640, overrides=("grounder.backend=ocr",)
    )
    step = next(s for s in rig.plan("0,29,-90", "room3").steps if s.landmark == "room4")
    rig.set(target=step, map_T_odom=(0.0, 0.0, 0.0))
    sign = world.signs["room4"]
    cap = CaptureViews("SearchViews", rig.ctx, lambda b: search_yaws(None), target_entity)
    rig.expect(rig.run(cap, max_ticks=300), Status.SUCCESS)
    assert not any(v.detections for v in rig.get("views"))  # too small to read from here
    unread = rig.ctx.grounder.unread_plates(0.0)
    (plate,) = [p for p in unread if math.dist(p.xy, sign.centre) < 0.3]
    seen = math.dist(plate.seen_from, sign.centre)

    rig.expect(rig.run(read_closer_subtree(rig.ctx), max_ticks=3000), Status.SUCCESS)
    assert rig.get("sighting").entity == Entity.room("room4")
    (went,) = [e for e in rig.ctx.trace if e.kind == "active_read"]
    p = rig.true_pose()
    here = math.dist((p.x, p.y), sign.centre)
    assert here <= min(seen - 0.5, went.data["read_range_m"]) + 0.2  # nearer, within range
    off = math.atan2(p.y - sign.centre[1], p.x - sign.centre[0]) - math.atan2(*sign.normal[::-1])
    assert abs(math.degrees(math.remainder(off, math.tau))) < 20.0  # square to it
