"""The simulated body's bumper: which zone of it is pressed, if any.

The body is a kinematic cylinder that stops where it would touch a wall, a door, an
obstacle or a person (``sim/robot.py`` cuts the motion within 0.1 mm of the contact), so
"touching" is a clearance under ``TOUCH_M``. Which way the contact lies is where the
clearance falls fastest: its gradient, from four probes ``PROBE_M`` round the body's
centre (one contact, or the nearer of two in a corner). The bearing of the contact from
the heading picks the Create 3's bumper zone (``pmnav_bt.hazards.bump_zone``); a contact
behind the wheels presses no bumper. The bumper is a spring: it is pressed while the
body drives into what it touches, and lets go when the body stops, turns on the spot or
backs off (a body left touching a wall it has turned along would otherwise feel a bump
for ever, and never be let drive on).
"""

from __future__ import annotations

import math

from pmnav_bt.geometry import wrap_angle
from pmnav_bt.hazards import bump_zone
from pmnav_bt.seams import Pose2D
from pmnav_bt.sim.world import SimWorld

TOUCH_M = 0.002  # clearer than this is not touching (a stopped body rests 0.1 mm off)
PROBE_M = 0.01  # the gradient's step, well inside what the clearance resolves
# Driving presses what lies within this of the heading: a body sliding along a wall it
# touches (the contact 90 deg off) does not press its side zone.
PRESS_WITHIN = math.radians(85.0)


def contact_bearing(world: SimWorld, pose: Pose2D, radius: float, height: float) -> float | None:
    """The bearing (rad, counter-clockwise from the heading) of what the body's cylinder
    (``radius``, ``height``: the body with its mast) at ``pose`` touches, or None when it
    touches nothing."""
    def clear(dx: float, dy: float) -> float:
        return world.clearance(pose.x + dx, pose.y + dy, radius, height)

    if clear(0.0, 0.0) > TOUCH_M:
        return None
    gx = clear(PROBE_M, 0.0) - clear(-PROBE_M, 0.0)
    gy = clear(0.0, PROBE_M) - clear(0.0, -PROBE_M)
    if gx == 0.0 and gy == 0.0:  # inside something, or touching all round: straight ahead
        return 0.0
    return wrap_angle(math.atan2(-gy, -gx) - pose.yaw)


def pressed_zone(
    world: SimWorld, pose: Pose2D, radius: float, height: float, linear: float
) -> str | None:
    """The bumper zone (its frame, "bump_front_left") pressed by driving at ``linear`` m/s
    at ``pose`` (the body's ``radius`` and ``height``), or None."""
    if linear <= 0.0:
        return None
    bearing = contact_bearing(world, pose, radius, height)
    if bearing is None or abs(bearing) > PRESS_WITHIN:
        return None
    return bump_zone(bearing)
