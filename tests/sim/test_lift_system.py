"""The simulator's lift system (sim/lift.py) on the sim clock, with stand-in cabins (no
pybullet): call delays from the seed, doors and rides, full cabins that ride off, and the
robot carried to the same place in the next level's cabin."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pytest

from pmnav_bt.lift_timing import BED_LIFT as T
from pmnav_bt.seams import LiftDoor, LiftMotion, Pose2D
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.lift import LiftError, SimLift


@dataclass
class StandInCabin:
    """A cabin's doors, cart and floor, as ``sim.scene.lifts.Cabin`` has them."""

    frame: Pose2D
    is_open: bool = False
    cart: int | None = None
    doors: list[bool] = field(default_factory=list)

    def set_door(self, is_open: bool) -> None:
        self.is_open = is_open
        self.doors.append(is_open)

    def fill(self) -> None:
        self.cart = 1

    def empty(self) -> None:
        self.cart = None

    def holds(self, x: float, y: float) -> bool:
        return math.dist((x, y), (self.frame.x, self.frame.y)) < 0.8


@dataclass
class Robot:
    level: str
    pose: Pose2D
    carried: list[tuple[str, Pose2D]] = field(default_factory=list)

    def world_pose(self) -> Pose2D:
        return self.pose

    def carry(self, level: str, pose: Pose2D) -> None:
        self.level, self.pose = level, pose
        self.carried.append((level, pose))


def system(robot: Robot, full_p: float = 0.0, seed: int = 0):
    clock = SimClock(tick=0.1)
    cabins = {
        "L1": StandInCabin(Pose2D(10.0, -2.0, -math.pi / 2)),
        "L2": StandInCabin(Pose2D(40.0, 5.0, 0.0)),  # another place in L2's map frame
        "L3": StandInCabin(Pose2D(10.0, -2.0, -math.pi / 2)),
    }
    lift = SimLift(clock, robot, np.random.default_rng(seed), full_p)
    lift.add("lift1", "Lift A", cabins, "L3")
    return clock, lift, cabins


def wait_open(clock, lift, level: str, limit: float = 200.0) -> float:
    t0 = clock.now()
    while clock.now() - t0 < limit:
        st = lift.state("lift1")
        if st.current_level == level and st.door == LiftDoor.OPEN:
            return clock.now() - t0
        clock.wait(0.5)
    raise AssertionError(f"not open at {level} after {limit} s: {lift.state('lift1')}")


def test_a_call_is_answered_after_a_seeded_delay_the_ride_and_the_door():
    waits = []
    for seed in (1, 1, 2):
        clock, lift, cabins = system(Robot("L1", Pose2D(10.0, 0.0, 0.0)), seed=seed)
        lift.request("lift1", "L1", "s")
        st = lift.state("lift1")
        assert st.session == "s" and st.door == LiftDoor.CLOSED
        waits.append(wait_open(clock, lift, "L1"))
        assert cabins["L1"].is_open and not cabins["L3"].is_open
    assert waits[0] == waits[1] != waits[2]  # the seed decides the call's delay
    ride = 2 * T.ride_s_per_level + T.door_s
    assert all(ride <= w <= ride + T.call_delay_s + 0.5 for w in waits)


def test_the_robot_in_the_cabin_rides_to_the_same_place_in_the_next_levels_cabin():
    robot = Robot("L1", Pose2D(10.0, 0.0, 0.0))
    clock, lift, cabins = system(robot)
    lift.request("lift1", "L1", "s")
    wait_open(clock, lift, "L1")
    robot.pose = Pose2D(10.3, -2.0, math.pi / 2)  # drove in, turned round to face out
    lift.request("lift1", "L2", "s")
    assert lift.state("lift1").door == LiftDoor.MOVING
    clock.wait(T.door_s + 0.5)
    assert lift.state("lift1").motion == LiftMotion.UP
    took = wait_open(clock, lift, "L2")
    ride = T.ride_s_per_level
    assert ride <= took <= ride + T.door_s + 1.0  # no call delay from inside
    assert robot.level == "L2" and len(robot.carried) == 1
    # 0.3 m left of L1's cabin's middle (looking into it), facing out; in L2's the same.
    assert robot.pose.x == pytest.approx(40.0) and robot.pose.y == pytest.approx(5.0 + 0.3)
    assert robot.pose.yaw == pytest.approx(math.pi)
    lift.release("lift1", "s")
    clock.wait(10.0)
    assert lift.state("lift1").session == "" and not cabins["L2"].is_open


def test_a_full_cabin_comes_with_its_cart_and_rides_off_with_it_when_let_go():
    robot = Robot("L1", Pose2D(10.0, 0.0, 0.0))
    clock, lift, cabins = system(robot, full_p=1.0)
    lift.request("lift1", "L1", "s")
    wait_open(clock, lift, "L1")
    assert cabins["L1"].cart is not None
    lift.release("lift1", "s")
    clock.wait(T.door_s * 2 + 10.0)
    st = lift.state("lift1")
    assert cabins["L1"].cart is None  # it left, cart and all, for another level
    assert st.current_level != "L1" or st.motion != LiftMotion.STOPPED
    assert robot.level == "L1" and not robot.carried  # the robot stayed in the lobby


def test_calls_after_a_full_cabin_has_shut_its_doors_are_independent_arrivals():
    """The tree lets a full cabin go and calls again once its doors have shut
    (``SeeItLeave``): each such call is a new arrival, full with probability p whatever
    the last one was (three full ones in a row are p cubed, not p)."""
    p, after_full = 0.3, []
    for seed in range(150):
        robot = Robot("L1", Pose2D(10.0, 0.0, 0.0))
        clock, lift, cabins = system(robot, full_p=p, seed=seed)
        was_full = None
        for _ in range(4):
            lift.request("lift1", "L1", "s")
            wait_open(clock, lift, "L1")
            full = cabins["L1"].cart is not None
            if was_full:
                after_full.append(full)
            was_full = full
            lift.release("lift1", "s")
            while lift.state("lift1").door != LiftDoor.CLOSED:
                clock.wait(0.5)
    assert len(after_full) > 100
    assert abs(np.mean(after_full) - p) < 0.1


def test_a_call_before_a_full_cabins_doors_shut_opens_them_on_it_again():
    robot = Robot("L1", Pose2D(10.0, 0.0, 0.0))
    clock, lift, cabins = system(robot, full_p=1.0)
    lift.request("lift1", "L1", "s")
    wait_open(clock, lift, "L1")
    assert cabins["L1"].cart is not None
    lift.full_p = 0.0  # were the next call a new arrival, it would come empty
    lift.release("lift1", "s")
    clock.wait(T.dwell_s + 1.0)  # its doors closing
    lift.request("lift1", "L1", "s")
    assert wait_open(clock, lift, "L1") <= T.door_s + 0.5  # at once: no call delay
    assert cabins["L1"].cart is not None and lift.full_calls == 1
    lift.release("lift1", "s")  # let go again: now it leaves, cart and all
    clock.wait(T.dwell_s + 2 * T.door_s + 1.0)
    assert cabins["L1"].cart is None and lift.state("lift1").current_level == "L1"
    assert lift.state("lift1").motion != LiftMotion.STOPPED


def test_a_robot_left_in_the_lobby_is_not_carried():
    robot = Robot("L1", Pose2D(10.0, 0.0, 0.0))
    clock, lift, _ = system(robot)
    lift.request("lift1", "L1", "s")
    wait_open(clock, lift, "L1")
    lift.request("lift1", "L2", "s")
    wait_open(clock, lift, "L2")
    assert robot.level == "L1" and not robot.carried


def test_an_unknown_lift_or_level_is_refused_in_one_line():
    clock, lift, _ = system(Robot("L1", Pose2D(0.0, 0.0, 0.0)))
    with pytest.raises(LiftError, match="no lift 'lift9'"):
        lift.request("lift9", "L1", "s")
    with pytest.raises(LiftError, match="Lift A does not serve level 'L7'"):
        lift.request("lift1", "L7", "s")
