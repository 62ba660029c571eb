"""The active read in pybullet with the real reader: a small plate (30 mm capitals, a
realistic signage style) seen 2.2 m off is not read; the tree drives square to it, within
the range its text size allows, and reads it there."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.active_read import _Planner
from pmnav_bt.behaviours.capture import CaptureViews, search_yaws
from pmnav_bt.behaviours.search import target_entity
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.signage import Signage, SignStyleSpec
from pmnav_bt.perception.read_range import plate_read_range
from pmnav_bt.perception.reading_pose import reading_pose
from pmnav_bt.perception.unread_plates import UnreadPlate
from pmnav_bt.seams import CREATE3_RADIUS_M, Entity, Pose2D
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


def test_a_reading_pose_is_not_taken_touching_clutter(make_rig, world):
    """A plant just beyond the spot a plate would be read from on bare floor (square to
    it, nearest the robot): depth shows it, and the pose chosen keeps the body clear of
    it by the pad, as does the way there (before, the spot was taken: the way to it was
    free, and the plant 2 cm from the body's edge)."""
    rig = make_rig(
        SEEN_FROM, width=320, height=240, reading_width=640, overrides=("grounder.backend=ocr",)
    )
    sign = world.signs["room4"]
    n = np.asarray(sign.normal, float)
    robot = (SEEN_FROM.x, SEEN_FROM.y)
    plate = UnreadPlate(
        xy=tuple(sign.centre), normal=tuple(n), z=1.5, top=1.52, line_height=0.03, width=0.3,
        stamp=0.0, seen_from=robot,
    )  # fmt: skip
    rng = plate_read_range(rig.ctx.config, plate.line_height)
    bare = reading_pose(plate.xy, plate.normal, rng, lambda p: True, seen_from=robot, robot=robot)
    half = 0.225
    away = np.array([bare.x, bare.y]) - robot
    gap = CREATE3_RADIUS_M + 0.02 + half  # 2 cm from the body's edge at that spot
    box = np.array([bare.x, bare.y]) + away / np.linalg.norm(away) * gap
    rig.add_obstacle(float(box[0]), float(box[1]), size=2 * half, height=1.0)
    step = next(s for s in rig.plan("0,29,-90", "room3").steps if s.landmark == "room4")
    rig.set(target=step, map_T_odom=(0.0, 0.0, 0.0))
    cap = CaptureViews("SearchViews", rig.ctx, lambda b: search_yaws(None), target_entity)
    rig.expect(rig.run(cap, max_ticks=300), Status.SUCCESS)
    views = rig.get("views")
    toward = math.atan2(sign.centre[1] - SEEN_FROM.y, sign.centre[0] - SEEN_FROM.x)
    seen_in = min(
        views, key=lambda v: abs(math.remainder(v.observation.pose.yaw - toward, math.tau))
    )
    plate = dataclasses.replace(plate, stamp=seen_in.observation.stamp)
    planner = _Planner(rig.ctx, Entity.room("room4"), (0.0, 0.0, 0.0), 3.0, views, robot)
    plan, why = planner([plate])
    assert plan is not None, why

    def to_box(x: float, y: float) -> float:  # from a point to the box's square
        dx, dy = max(abs(x - box[0]) - half, 0.0), max(abs(y - box[1]) - half, 0.0)
        return math.hypot(dx, dy)

    spot = (plan.pose.x, plan.pose.y)
    assert to_box(*spot) >= CREATE3_RADIUS_M + 0.05  # not touching it
    start = np.array(robot)
    way = [start + t * (np.asarray(spot) - start) for t in np.linspace(0.0, 1.0, 40)]
    assert min(to_box(*p) for p in way) >= CREATE3_RADIUS_M  # nor on the way there
