"""Velocity control and the action odometer."""

from __future__ import annotations

import math

import pytest

from pmnav_bt.control import Limits, Odometer, goto_command, rotate_command
from pmnav_bt.seams import Pose2D

LIM = Limits()


def simulate(pose: Pose2D, goal, steps=2000, dt=0.05):
    for _ in range(steps):
        v, w, done = goto_command(pose, *goal, LIM)
        if done:
            return pose, True
        assert abs(v) <= LIM.linear + 1e-9 and abs(w) <= LIM.angular + 1e-9 and v >= 0
        pose = Pose2D(
            pose.x + v * math.cos(pose.yaw) * dt,
            pose.y + v * math.sin(pose.yaw) * dt,
            pose.yaw + w * dt,
        )
    return pose, False


@pytest.mark.parametrize("goal", [(5, 0), (-3, 2), (0, -4), (0.1, 0.05)])
def test_goto_reaches_the_goal_within_limits(goal):
    pose, done = simulate(Pose2D(0, 0, 0.3), goal)
    assert done and math.dist((pose.x, pose.y), goal) <= 0.15


def test_rotate_turns_in_place_the_short_way():
    v, w, done = rotate_command(Pose2D(0, 0, math.radians(170)), math.radians(-170), LIM)
    assert v == 0 and w > 0 and not done
    assert rotate_command(Pose2D(0, 0, 1.0), 1.01, LIM)[2]


def test_odometer_counts_action_equivalents():
    odo = Odometer()
    for p in (Pose2D(0, 0, 0), Pose2D(1.0, 0, 0), Pose2D(1.0, 0, math.pi / 2)):
        odo.update(p)
    assert odo.actions == 4 + 3  # 1 m = 4 forward steps, 90 deg = 3 turns
