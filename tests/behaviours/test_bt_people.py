"""A drive among walking people in the simulator: a person who walks towards the robot is
waited for and never touched; the robot tells them from the building by depth alone (no
labels are read: the person moves between watch frames)."""

from __future__ import annotations

import math

import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.motion import DriveTo
from pmnav_bt.config import WorldConfig
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.seams import Pose2D
from pmnav_bt.sim.scene.people import PERSON_RADIUS_M

pytestmark = [pytest.mark.world, pytest.mark.timeout(300)]


@pytest.fixture(scope="module")
def building():
    return load_building("straight_office")  # one corridor along x from 0 to 54 m


@pytest.fixture(scope="module")
def world(building):
    from pmnav_bt.sim.world import SimWorld

    # walking people only, none pausing: 2-3 in the corridor
    scene = WorldConfig(
        preset="realistic", clutter_per_10m=0.0, people_per_100m=5.0, people_pausing=0.0
    )
    w = SimWorld(building, scene=scene, seed=4)
    yield w
    w.close()


class DriveToPoint(DriveTo):
    goal_xy = (0.0, 0.0)

    def goal(self) -> tuple[float, float]:
        return self.goal_xy


def coming(world, distance: float):
    """A person walking along the corridor with room ahead, and the pose ``distance`` m
    ahead of them, facing them."""
    for q in world.people.people:
        ahead = (50.0 - q.x) if math.cos(q.yaw) > 0 else q.x - 4.0
        if ahead > distance + 8.0:
            u = (math.cos(q.yaw), math.sin(q.yaw))
            return q, Pose2D(q.x + distance * u[0], 0.0, q.yaw + math.pi)
    raise AssertionError("no person with room ahead")


def test_a_person_walking_towards_the_robot_is_waited_for_and_never_touched(make_rig, world):
    q, there = coming(world, 6.0)
    rig = make_rig(there)
    drive = DriveToPoint("Drive", rig.ctx)
    # on past where the person walks: 8 m along the corridor, straight through them
    drive.goal_xy = (there.x + 8.0 * math.cos(there.yaw), 0.0)
    gaps = []

    def gap() -> bool:
        r = rig.true_pose()
        gaps.append(math.hypot(q.x - r.x, q.y - r.y) - PERSON_RADIUS_M - rig.body.radius)
        return False

    seen = rig.run(drive, max_ticks=1500, until=gap)
    assert seen[-1] == Status.SUCCESS, rig.failure
    assert world.people.contacts == 0 and rig.body.stats.collisions == 0
    assert min(gaps) > 0.2
    stops = [e for e in rig.ctx.trace if e.kind == "obstacle"]
    assert stops and stops[0].data["moving"]  # seen to move: a person, not clutter
    assert [e for e in rig.ctx.trace if e.kind == "way_clear"]  # waited, then went on
