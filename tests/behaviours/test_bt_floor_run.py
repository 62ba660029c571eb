"""How far the map's floor runs out of a waypoint, as the turn check expects depth to show.

An open floor annotated as 4 m wide legs (as an imported RMF office's lanes are): from a
branch the plan goes north past the corner of a room block standing 0.5 m east of the
leg's line. The waypoint itself has the floor open to the far wall; a robot that believes
it stands 0.7 m east of it has the block's corner 2 m ahead, and the check must expect 2 m
there (that wall is the way going on past the corner, not a sign that it is lost).
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from pmnav_bt.behaviours.motion import floor_run
from pmnav_bt.map.building import building_from_data
from pmnav_bt.map.floorplan import FREE, OCCUPIED, FloorPlanImage, fill_world_polygons
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.pose.evidence.floor_model import wall_source
from pmnav_bt.seams import Pose2D

NORTH = math.pi / 2.0
BRANCH = (6.0, 0.0)


def _box(x0, y0, x1, y1):
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], float)


@pytest.fixture(scope="module")
def ctx():
    data = {
        "schema_version": 1,
        "name": "open_floor",
        "corridor_width": 4.0,
        "waypoints": [
            {"id": "start", "kind": "start", "pos": [0.0, 0.0]},
            {"id": "branch1", "kind": "branch", "pos": list(BRANCH)},
            {"id": "end1", "kind": "end", "pos": [6.0, 6.0]},
            {"id": "end2", "kind": "end", "pos": [12.0, 0.0]},
        ],
        "edges": [["start", "branch1"], ["branch1", "end1"], ["branch1", "end2"]],
    }
    pm = parse_building(building_from_data(data))
    plan = FloorPlanImage(np.full((240, 400), OCCUPIED, np.uint8), 0.05, (-3.0, -3.0, 0.0))
    fill_world_polygons(plan, [_box(-2.0, -2.0, 14.0, 8.0)], FREE)  # the open floor
    fill_world_polygons(plan, [_box(6.5, 2.0, 14.5, 8.5)], OCCUPIED)  # a room block
    return SimpleNamespace(pm=pm, walls=wall_source("grid", plan))


def test_the_run_is_measured_from_where_the_robot_believes_it_stands(ctx):
    at_waypoint = floor_run(ctx, BRANCH, NORTH, Pose2D(*BRANCH, NORTH))
    beside = floor_run(ctx, BRANCH, NORTH, Pose2D(6.7, 0.0, NORTH))
    assert at_waypoint == pytest.approx(8.0, abs=0.15)  # the far wall
    assert beside == pytest.approx(2.0, abs=0.15)  # the block's corner
    # Short of the waypoint, the run counts from level with the estimate.
    short = floor_run(ctx, BRANCH, NORTH, Pose2D(6.0, -1.0, NORTH))
    assert short == pytest.approx(9.0, abs=0.15)


def test_an_estimate_outside_every_corridor_measures_from_the_waypoint(ctx):
    # 3.5 m east of the north leg's line (half its width is 2 m), inside the room block:
    # the robot is lost, not beside the lane; the map's run is the waypoint's, counted
    # from level with the estimate (4 m on), not the block's none.
    lost = floor_run(ctx, BRANCH, NORTH, Pose2D(9.5, 4.0, NORTH))
    assert lost == pytest.approx(8.0 - 4.0, abs=0.15)
