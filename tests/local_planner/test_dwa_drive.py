"""The local planner drives DriveTo in a pybullet world (fig2's 2 m corridor from room1 to
room4): round a box on the centre line to the goal without touching it, within the
Create 3's limits, and stopped before a box that shuts the corridor."""

from __future__ import annotations

import math

import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.motion import Approach
from pmnav_bt.failures import FailureCode
from pmnav_bt.seams import CREATE3_MAX_ANGULAR, CREATE3_MAX_LINEAR, Pose2D

pytestmark = pytest.mark.world

SOUTH = math.radians(-90)
DWA = ("tree.local_planner=dwa",)


def room4_step(rig):
    plan = rig.plan("room1", "room4")
    return next(s for s in plan.steps if s.landmark == "room4")


def record_commands(base) -> list[tuple[float, float]]:
    """Every velocity command ``base`` is sent from now on (a list that fills)."""
    sent: list[tuple[float, float]] = []
    inner = base.set_velocity

    def record(v, w):
        sent.append((v, w))
        inner(v, w)

    base.set_velocity = record
    return sent


@pytest.mark.parametrize("size", [0.4, 0.8])
def test_dwa_drives_round_a_box_on_the_centre_line_to_the_goal(make_rig, size):
    """The box is seen from 5 m, with the floor beside it (the camera sees the floor from
    3.7 m on), and is driven round as it comes: never held."""
    rig = make_rig(Pose2D(0.0, 29.5, SOUTH), overrides=DWA)
    rig.add_obstacle(0.0, 24.5, size=size, height=1.0)
    rig.set(target=room4_step(rig))
    sent = record_commands(rig.body)
    seen = rig.run(Approach("Approach", rig.ctx), max_ticks=900)
    rig.expect(seen, Status.SUCCESS)
    assert rig.body.stats.collisions == 0
    assert rig.true_pose().y < 24.5 - size / 2  # past it, not stopped at it
    assert "obstacle" not in [e.kind for e in rig.ctx.trace]  # never held
    # Within the Create 3's limits, forward only, and the speed changing no faster than
    # its wheels accelerate (0.9 m/s^2: 0.09 m/s a 0.1 s tick), but for the stop at the
    # goal (the body brakes by itself).
    assert all(0.0 <= v <= CREATE3_MAX_LINEAR + 1e-9 for v, _ in sent)
    assert all(abs(w) <= CREATE3_MAX_ANGULAR + 1e-9 for _, w in sent)
    moving = [v for v, _ in sent if v > 0.0]
    assert max(moving) > 0.9 * CREATE3_MAX_LINEAR  # and it did drive at speed
    steps = [abs(b[0] - a[0]) for a, b in zip(sent, sent[1:], strict=False) if b != (0.0, 0.0)]
    assert max(steps) <= 0.09 + 1e-6


def test_dwa_stops_before_a_box_that_shuts_the_corridor(make_rig):
    rig = make_rig(Pose2D(0.0, 29.5, SOUTH), overrides=DWA)
    rig.add_obstacle(0.0, 24.5, size=1.6, height=1.9)  # 0.4 m left either side
    rig.set(target=room4_step(rig))
    seen = rig.run(Approach("Approach", rig.ctx), max_ticks=600)
    rig.expect(seen, Status.FAILURE)
    assert rig.failure.code == FailureCode.BLOCKED
    assert "blocked for" in rig.failure.message
    assert rig.body.stats.collisions == 0
    assert rig.true_pose().y > 25.3 + 0.17  # short of the box
    assert rig.stopped()
