"""A body with hazard sensors (the Create 3's bumper, cliff sensors): the failure its
motion ends with names what it felt, on the doubles (a kinematic body in fig2_hospital)."""

from __future__ import annotations

import math

import numpy as np
from py_trees.common import Status

from pmnav_bt.behaviours.monitor import Monitor
from pmnav_bt.behaviours.motion import MoveToward
from pmnav_bt.failures import FailureCode
from pmnav_bt.hazards import HazardKind, place
from pmnav_bt.local_planner.steering import LocalPlannerSteering
from pmnav_bt.seams import Pose2D

SOUTH_AT_28 = Pose2D(0.0, 28.0, math.radians(-90))


def _feel(body, hazard) -> None:
    """Give the double the hooks of a body with hazard sensors (hardware/create3.py)."""
    body.hazards = lambda since=-math.inf: [hazard]
    body.blocked_by = lambda: hazard


def test_a_drive_stopped_by_a_bump_fails_blocked_naming_the_bump(make_rig):
    rig = make_rig(SOUTH_AT_28)
    step = next(s for s in rig.plan("0,28,-90", "room3").steps if s.landmark == "room5")
    rig.set(target=step)
    bump = place(HazardKind.BUMP, "bump_front_left", rig.true_pose(), 1.0)
    _feel(rig.body, bump)
    rig.body.blocked = True  # the bumper is pressed: every forward command refused
    seen = rig.run(MoveToward("MoveOn", rig.ctx, keep=1.0), max_ticks=50)
    rig.expect(seen, Status.FAILURE)
    assert rig.failure.code == FailureCode.BLOCKED
    at = f"({bump.point[0]:.2f}, {bump.point[1]:.2f})"
    assert rig.failure.message == f"3 collisions on the way: bumped front left at {at}"
    assert rig.stopped()


def test_a_cliff_ends_the_mission_naming_the_cliff(make_rig):
    rig = make_rig(SOUTH_AT_28)
    _feel(rig.body, place(HazardKind.CLIFF, "cliff_front_right", rig.true_pose(), 1.0))
    rig.body.faulted = True  # a cliff felt: the body's status is FAULT
    monitor = Monitor("Monitor", rig.ctx)
    assert rig.tick(monitor) == Status.FAILURE
    assert rig.failure.code == FailureCode.BASE_FAULT
    assert rig.failure.message.startswith("the base reports a fault: cliff front right at (")
    # Only the body's motion failures name it: a spent budget is not the cliff's doing.
    rig.body.faulted = False
    rig.ctx.budget_actions = -1
    assert rig.tick(monitor) == Status.FAILURE
    assert rig.failure.message == "0 actions used of -1"


def test_a_bump_felt_while_driving_is_marked_in_the_local_costmap(make_rig):
    """Under the local planner, what the bumper touched stays in the costmap: the drive
    plans round it though the camera never saw it (a low step, glass)."""
    rig = make_rig(SOUTH_AT_28)
    step = next(s for s in rig.plan("0,28,-90", "room3").steps if s.landmark == "room5")
    rig.set(target=step)
    steer = LocalPlannerSteering()
    rig.ctx.steering = steer
    bump = place(HazardKind.BUMP, "bump_front_left", rig.true_pose(), 1.0)
    stall = place(HazardKind.STALL, "left_wheel", rig.true_pose(), 1.0)
    rig.body.hazards = lambda since=-math.inf: [bump, stall]
    rig.body.blocked_by = lambda: None  # felt, but nothing stopped the drive
    rig.run(MoveToward("MoveOn", rig.ctx, keep=1.0), max_ticks=15)
    grid = steer.costmap.snapshot()
    xs, ys = zip(bump.point, stall.point, strict=True)
    at = grid.clearance(np.array(xs), np.array(ys))
    assert at[0] == 0.0  # the bump is an obstacle
    assert at[1] > 0.0  # a stall is felt at the wheels, not where anything stands
