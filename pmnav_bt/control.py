"""Velocity control toward a point or a heading, for a differential-drive base.

Pure functions: the behaviours call them once per tick with the estimated pose and
send the result to ``Base.set_velocity``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmnav_bt.geometry import wrap_angle
from pmnav_bt.seams import (
    CREATE3_MAX_ANGULAR,
    CREATE3_MAX_LINEAR,
    FORWARD_STEP_M,
    TURN_STEP_RAD,
    Pose2D,
)

ROTATE_FIRST = math.radians(25.0)  # turn in place when the heading error is larger


@dataclass(frozen=True)
class Limits:
    linear: float = CREATE3_MAX_LINEAR
    angular: float = CREATE3_MAX_ANGULAR


def clip(v: float, limit: float) -> float:
    return max(-limit, min(limit, v))


def rotate_command(pose: Pose2D, heading: float, lim: Limits, tol: float = 0.03):
    """(v, w, done) to turn in place onto ``heading``."""
    e = wrap_angle(heading - pose.yaw)
    if abs(e) <= tol:
        return 0.0, 0.0, True
    return 0.0, clip(3.0 * e, lim.angular), False


def goto_command(pose: Pose2D, gx: float, gy: float, lim: Limits, tol: float = 0.15):
    """(v, w, done) to drive to (gx, gy): turn first when far off, then steer while driving."""
    dx, dy = gx - pose.x, gy - pose.y
    dist = math.hypot(dx, dy)
    if dist <= tol:
        return 0.0, 0.0, True
    e = wrap_angle(math.atan2(dy, dx) - pose.yaw)
    if abs(e) > ROTATE_FIRST:
        return 0.0, clip(3.0 * e, lim.angular), False
    v = min(lim.linear, 0.8 * dist + 0.05)
    return v, clip(2.5 * e, lim.angular), False


class Odometer:
    """Counts motion as discrete-action equivalents: 0.25 m forward or 30 deg turned each."""

    def __init__(self) -> None:
        self.distance = 0.0
        self.rotation = 0.0
        self._last: Pose2D | None = None

    def update(self, pose: Pose2D) -> None:
        if self._last is not None:
            self.distance += math.hypot(pose.x - self._last.x, pose.y - self._last.y)
            self.rotation += abs(wrap_angle(pose.yaw - self._last.yaw))
        self._last = pose

    @property
    def actions(self) -> int:
        return int(self.distance / FORWARD_STEP_M + self.rotation / TURN_STEP_RAD + 0.5)
