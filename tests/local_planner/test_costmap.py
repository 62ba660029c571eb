"""The rolling costmap: marks what depth shows standing on the floor, clears it where the
floor is seen again, remembers what is out of view, forgets stale marks, moves with the
robot, and inflates by the body's radius."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.local_planner.costmap import DECAY_S, LETHAL_PAD_M, LocalCostmap
from pmnav_bt.seams import CREATE3_RADIUS_M, Pose2D

SOUTH = math.radians(-90)


def occupied_near(cm: LocalCostmap, x: float, y: float, r: float) -> int:
    """How many occupied cells have their centre within ``r`` of odometry (x, y)."""
    occ = cm.occupied()
    i, j = np.nonzero(occ)
    cx = cm.origin[0] + (j + 0.5) * cm.resolution
    cy = cm.origin[1] + (i + 0.5) * cm.resolution
    return int(np.count_nonzero(np.hypot(cx - x, cy - y) <= r))


@pytest.mark.world
def test_a_box_seen_is_marked_and_cleared_once_seen_gone(make_rig):
    rig = make_rig(Pose2D(0.0, 29.5, SOUTH), width=320, height=240)
    # Its near face 3.8 m ahead, where the camera (1.6 m up, 47 deg vertical field) sees
    # the floor: nearer, a box and its floor are both below the view.
    box = rig.add_obstacle(0.0, 25.4, size=0.6, height=1.0)
    cm = LocalCostmap()
    cm.add_depth(rig.base.observe(), now=0.0)
    assert occupied_near(cm, 0.0, 25.7, 0.3) >= 5  # its near face
    assert occupied_near(cm, 0.0, 27.0, 0.4) == 0  # the floor before it
    grid = cm.snapshot()
    face = np.array([0.0]), np.array([25.7])
    assert grid.clearance(*face)[0] < grid.lethal_m
    rig.world.remove_obstacle(box)
    rig.obstacles.remove(box)
    cm.add_depth(rig.base.observe(), now=1.0)
    assert occupied_near(cm, 0.0, 25.7, 0.3) == 0  # its floor seen bare: cleared
    assert cm.snapshot().clearance(*face)[0] > grid.lethal_m  # no longer in the way


@pytest.mark.world
def test_what_the_camera_cannot_see_is_remembered_until_it_decays(make_rig):
    rig = make_rig(Pose2D(0.0, 29.5, SOUTH), width=320, height=240)
    cm = LocalCostmap()
    cm.recentre(0.0, 29.5)
    cm.mark([(0.0, 30.0), (0.0, 28.5)], now=0.0)  # a bump behind, one 1 m ahead (blind)
    cm.add_depth(rig.base.observe(), now=1.0)
    assert occupied_near(cm, 0.0, 30.0, 0.05) == 1
    assert occupied_near(cm, 0.0, 28.5, 0.05) == 1  # under the camera's view
    cm.add_depth(rig.base.observe(), now=DECAY_S + 0.5)
    assert occupied_near(cm, 0.0, 30.0, 0.05) == 0
    assert occupied_near(cm, 0.0, 28.5, 0.05) == 0


def test_the_window_moves_with_the_robot_and_forgets_what_it_leaves():
    cm = LocalCostmap(size=6.0)  # 3 m round the robot
    cm.mark([(1.0, 1.0)], now=0.0)
    cm.recentre(1.5, -0.7)
    assert occupied_near(cm, 1.0, 1.0, 0.05) == 1
    assert cm.snapshot().clearance(np.array([1.0]), np.array([1.0]))[0] == 0.0
    cm.recentre(10.0, 0.0)
    assert occupied_near(cm, 1.0, 1.0, 0.05) == 0


def test_inflation_by_the_body_radius_and_a_falling_cost_beyond():
    cm = LocalCostmap()
    cm.mark([(1.0, 0.0)], now=0.0)
    grid = cm.snapshot()
    assert grid.lethal_m == pytest.approx(CREATE3_RADIUS_M + LETHAL_PAD_M)
    xs = np.array([1.0 - CREATE3_RADIUS_M, 1.0 - grid.lethal_m - 0.1, 1.0 - 1.0])
    clear = grid.clearance(xs, np.zeros(3))
    assert clear[0] < grid.lethal_m < clear[1]
    cost = grid.cost(clear)
    assert cost[0] == 1.0 and 0.0 < cost[1] < 1.0 and cost[2] == 0.0


def test_a_costmap_that_is_not_sensible_is_refused():
    with pytest.raises(ValueError, match="not sensible"):
        LocalCostmap(size=6.0, resolution=0.0)


@pytest.mark.world
def test_a_person_seen_gone_up_close_is_cleared_a_low_box_below_the_view_is_kept(make_rig):
    """Within 3.7 m the camera sees no floor, so only the height of a mark tells: a
    person-high mark 1.75 m ahead whose column the next frame's rays pass through is seen
    gone; a low box seen from afar and now below the view stays marked as the robot
    comes near."""
    rig = make_rig(Pose2D(0.0, 29.5, SOUTH), width=320, height=240)
    person = rig.add_obstacle(0.0, 27.5, size=0.5, height=1.7)
    rig.add_obstacle(0.6, 24.0, size=0.4, height=0.4)  # low, beside the way, 5.3 m off
    cm = LocalCostmap()
    cm.add_depth(rig.base.observe(), now=0.0)
    assert occupied_near(cm, 0.0, 27.75, 0.3) >= 3
    rig.world.remove_obstacle(person)
    rig.obstacles.remove(person)
    cm.add_depth(rig.base.observe(), now=1.0)
    assert occupied_near(cm, 0.0, 27.75, 0.3) == 0  # walked on: the rays pass through
    rig.body.set_pose(Pose2D(0.0, 28.2, SOUTH))  # the low box 4 m off: seen
    cm.add_depth(rig.base.observe(), now=2.0)
    assert occupied_near(cm, 0.6, 24.2, 0.3) >= 3
    rig.body.set_pose(Pose2D(0.0, 26.0, SOUTH))  # 1.8 m off: below the view
    cm.add_depth(rig.base.observe(), now=3.0)
    assert occupied_near(cm, 0.6, 24.2, 0.3) >= 3
