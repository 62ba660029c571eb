"""Something in the way of a drive, on the doubles: a person is waited for (never pushed,
never driven round before the patience is out), clutter is driven round, a way that
stays shut fails with where it is in the building's words, a closed fire door with its
own code. The fake body draws upright cylinders in depth (``FakeObstacle``)."""

from __future__ import annotations

import math

import pytest
from building_kit import with_landmark
from py_trees.common import Status

from pmnav_bt.behaviours.motion import DriveTo
from pmnav_bt.failures import FailureCode
from pmnav_bt.map.building import Landmark
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.seams import Pose2D
from pmnav_bt.testing.doubles import FakeObstacle
from pmnav_bt.way_ahead import PATIENCE_S, WayShut

START = Pose2D(4.0, 0.0, 0.0)  # straight_office, facing east down the corridor
GOAL = (12.0, 0.0)
PERIOD = 0.1


@pytest.fixture(scope="module")
def building():
    return load_building("straight_office")


class DriveToPoint(DriveTo):
    def goal(self) -> tuple[float, float]:
        return GOAL


def drive(rig, max_ticks=1500):
    """Run a drive to GOAL; the statuses, and the least gap to the obstacles over it."""
    gaps = []
    seen = rig.run(
        DriveToPoint("Drive", rig.ctx), max_ticks, until=lambda: gaps.append(rig.body.gap())
    )
    return seen, min(gaps)


def events(rig, kind):
    return [e for e in rig.ctx.trace if e.kind == kind]


def barrier(x: float, half_width: float = 1.1):
    """Standing cylinders across the corridor at ``x``, edge to edge (nothing to slip by)."""
    n = int(2 * half_width / 0.2) + 1
    return [FakeObstacle.standing(x, -half_width + 0.2 * i, 0.12) for i in range(n)]


def test_a_person_who_comes_towards_the_robot_is_waited_for_then_the_drive_goes_on(make_rig):
    rig = make_rig(START)
    # walks west towards the robot at 1 m/s, stops 1.4 m in front of it for 3 s (as people
    # in the simulator stop for it), then turns back
    rig.body.obstacles = [FakeObstacle(((0.0, 12.0, 0.0), (5.0, 7.0, 0.0), (8.0, 7.0, 0.0),
                                        (16.0, 20.0, 0.0)))]  # fmt: skip
    seen, gap = drive(rig)
    rig.expect(seen, Status.SUCCESS)
    assert gap > 0.3  # never closer than this to the person

    waited = events(rig, "way_clear")
    assert len(waited) == 1 and waited[0].data["waited"] >= 3.0  # stood until they left
    assert not events(rig, "detour")  # not driven round
    p = rig.true_pose()
    assert math.dist((p.x, p.y), GOAL) < 0.2


@pytest.mark.xfail(
    strict=True,
    reason="not met since every frame goes into the costmap (nocollide): the first hold "
    "sees the person move, later frames 1.1 s apart (the sway is 0.7 s) read them still, "
    "and the drive passes before the patience as for clutter; a hold's mover verdict must "
    "outlast aliased frames (issue 38)",
)
def test_someone_who_stays_in_the_way_is_passed_only_after_the_patience(make_rig):
    rig = make_rig(START)
    # stands right of the centre line 3 m ahead for a minute, talking, stepping to and fro
    sway = tuple((0.7 * i, 7.0 + 0.25 * (-1) ** i, -0.4) for i in range(90))
    rig.body.obstacles = [FakeObstacle(sway)]
    seen, gap = drive(rig)
    rig.expect(seen, Status.SUCCESS)
    stop, passed = events(rig, "obstacle")[0], events(rig, "detour")[0]
    assert passed.data["moving"] and passed.time - stop.time >= PATIENCE_S
    assert gap > 0.2


def test_clutter_that_stands_still_is_driven_round_without_waiting(
    make_rig, thumbnails_off_the_tick
):
    rig = make_rig(START)
    rig.body.obstacles = [FakeObstacle.standing(7.0, 0.0, 0.3)]
    seen, gap = drive(rig)
    rig.expect(seen, Status.SUCCESS)
    (stop,), (passed,) = events(rig, "obstacle"), events(rig, "detour")
    assert stop.frame is None and stop.thumbnail is not None  # shrunk in the worker
    assert not passed.data["moving"] and passed.time - stop.time < 3.0
    assert gap > 0.0


def test_a_way_that_stays_shut_fails_naming_the_corridor(make_rig):
    rig = make_rig(START)
    rig.body.obstacles = barrier(7.0)
    seen, gap = drive(rig)
    rig.expect(seen, Status.FAILURE)
    f = rig.failure
    assert f.code == FailureCode.BLOCKED
    shut = rig.get("way_shut")
    seconds = f"{shut.seconds:.0f} s"
    assert f.message.startswith(f"the corridor between room1 and room2 blocked for {seconds}")
    assert isinstance(shut, WayShut) and not shut.moving and shut.seconds >= PATIENCE_S
    assert 6.5 < shut.point[0] < 7.2 and rig.stopped() and gap > 0.0


def test_a_closed_fire_door_fails_with_its_own_code_and_place(make_rig, building):
    door = Landmark(id="firedoor1", kind="fire_door", name="FD-2", pos=(7.0, 0.0))
    rig = make_rig(START)
    rig.ctx.pm = parse_building(with_landmark(building, door))
    rig.body.obstacles = barrier(7.0)
    seen, _ = drive(rig)
    rig.expect(seen, Status.FAILURE)
    f = rig.failure
    assert f.code == FailureCode.DOOR_CLOSED
    assert f.message.startswith("fire door FD-2 at room1 closed"), f.message  # its node
