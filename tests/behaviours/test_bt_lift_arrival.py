"""Where the robot is on the far level of a lift ride (``behaviours/lift.arrival_pose``):
the lift carries the cabin and the robot in it, so the robot's heading in the cabin is
the one it had there on the level left."""

from __future__ import annotations

import math

import pytest

from pmnav_bt.behaviours.lift import Ride, arrival_pose
from pmnav_bt.geometry import wrap_angle
from pmnav_bt.map.lift_doorway import Doorway
from pmnav_bt.seams import Pose2D

# Lift doors on a wall facing +y on the first level; on the second the same shaft's doors
# open to -x (another corridor runs past it there).
BOARD = Doorway((10.0, 1.2), (0.0, 1.0), 1.6, (10.0, 0.0))
ALIGHT = Doorway((-1.2, 5.0), (-1.0, 0.0), 1.6, (0.0, 5.0))
RIDE = Ride("lift1", "Lift A", "L1", "L2", BOARD, ALIGHT)


@pytest.mark.parametrize("aside_deg", [0.0, 25.0, -25.0])
def test_the_heading_in_the_cabin_rides_along(aside_deg):
    """The robot drove in 25 deg aside and turned round: on arrival it faces the doors
    25 deg aside too, and stands in the cabin's middle."""
    aside = math.radians(aside_deg)
    odom_yaw = 0.4  # anything: the old estimate turns it into the map
    old_tf = (3.0, -1.0, wrap_angle(-math.pi / 2 + aside - odom_yaw))  # facing out, aside
    p = arrival_pose(RIDE, old_tf, Pose2D(7.0, 7.0, odom_yaw))
    out = ALIGHT.cabin_pose()
    assert math.dist((p.x, p.y), (out.x, out.y)) < 1e-9
    assert abs(wrap_angle(p.yaw - (out.yaw + aside))) < 1e-9


def test_without_an_estimate_the_robot_faces_the_doors():
    assert arrival_pose(RIDE, None, Pose2D(0.0, 0.0, 1.0)) == ALIGHT.cabin_pose()
