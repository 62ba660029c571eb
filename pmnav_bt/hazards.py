"""What the robot's body feels: a bump, a cliff, a stalled or dropped wheel, as a point.

The iRobot Create 3 reports its hazards on ``hazard_detection``
(``irobot_create_msgs/HazardDetectionVector``, docs/ros2.md): each detection is a type
and the frame of the sensor that felt it. This module is their one home on PM-Nav's
side, without ROS: the kinds the body acts on, where on the body each sensor sits, which
bumper zone a contact falls in, and how a hazard reads in a failure message. The body
(``hardware/create3.py``) turns detections into ``Hazard`` s with points in its odometry
frame; the simulated Create 3 uses ``bump_zone`` to say which part of its bumper touched.

Where the sensors are (REP-103 ``base_link``: x forward, y left, metres), from iRobot's
Create 3 description (create3_sim, ``irobot_create_description`` and
``irobot_create_toolbox/sensors/bumpers.hpp``):

- the bumper covers the front half of the body in five zones of 36 deg, named by the
  frame the robot reports: ``bump_right`` [-90, -54) deg, ``bump_front_right`` [-54, -18),
  ``bump_front_center`` [-18, 18], ``bump_front_left`` (18, 54], ``bump_left`` (54, 90].
  A bump is placed on the body's rim (``CREATE3_RADIUS_M``) at its zone's centre bearing:
  where the body touched. Behind the wheels there is no bumper, so no bump;
- the four cliff sensors under the front: ``cliff_front_left`` (0.16, 0.045),
  ``cliff_side_left`` (0.06, 0.145) and their mirror images on the right;
- the wheels, 0.233 m apart: a stall is reported by wheel (``left_wheel``,
  ``right_wheel``), a dropped wheel by ``wheel_drop_left`` / ``wheel_drop_right``.

A frame the table does not know (or a namespaced one, ``robot1/bump_left``, is read by its
last part) is placed at the body's centre and described without a side.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import Enum
from typing import Protocol, runtime_checkable

from pmnav_bt.geometry import se2_apply, wrap_angle
from pmnav_bt.seams import CREATE3_RADIUS_M, Pose2D


class HazardKind(str, Enum):
    """The hazards the body acts on (irobot_create_msgs/HazardDetection's types)."""

    BUMP = "bump"  # the bumper touched something: the way ahead is blocked
    CLIFF = "cliff"  # the floor ends under a cliff sensor: never drive on
    STALL = "stall"  # the wheels turn no more (pushing against something)
    WHEEL_DROP = "wheel_drop"  # a wheel hangs free: lifted, or over a hole


@dataclass(frozen=True)
class Sensor:
    """A hazard sensor: where it sits in ``base_link`` and the side a person names."""

    offset: tuple[float, float]
    side: str


_ZONE_DEG = 36.0  # the bumper's front half in five equal zones
_BUMPER = {  # frame: the zone's centre bearing (deg, counter-clockwise from ahead)
    "bump_right": -72.0,
    "bump_front_right": -36.0,
    "bump_front_center": 0.0,
    "bump_front_left": 36.0,
    "bump_left": 72.0,
}
_WHEEL_Y = 0.233 / 2.0

SENSORS: dict[str, Sensor] = {
    **{
        frame: Sensor(
            (CREATE3_RADIUS_M * math.cos(math.radians(deg)),
             CREATE3_RADIUS_M * math.sin(math.radians(deg))),
            frame.removeprefix("bump_").replace("front_center", "front").replace("_", " "),
        )  # fmt: skip
        for frame, deg in _BUMPER.items()
    },
    "cliff_front_left": Sensor((0.16, 0.045), "front left"),
    "cliff_front_right": Sensor((0.16, -0.045), "front right"),
    "cliff_side_left": Sensor((0.06, 0.145), "left"),
    "cliff_side_right": Sensor((0.06, -0.145), "right"),
    "left_wheel": Sensor((0.0, _WHEEL_Y), "left"),
    "right_wheel": Sensor((0.0, -_WHEEL_Y), "right"),
    "wheel_drop_left": Sensor((0.0, _WHEEL_Y), "left"),
    "wheel_drop_right": Sensor((0.0, -_WHEEL_Y), "right"),
}
_CENTRE = Sensor((0.0, 0.0), "")


def sensor(frame: str) -> Sensor:
    """The sensor a detection's frame names (the body's centre for one not known)."""
    return SENSORS.get(frame.rsplit("/", 1)[-1], _CENTRE)


def bump_zone(bearing: float) -> str | None:
    """The bumper zone (its frame) that a contact at ``bearing`` (rad, counter-clockwise
    from straight ahead) presses; None behind the bumper (more than 90 deg off ahead)."""
    deg = math.degrees(wrap_angle(bearing))
    if abs(deg) > 90.0:
        return None
    return min(_BUMPER, key=lambda frame: abs(_BUMPER[frame] - deg))


@dataclass(frozen=True)
class Hazard:
    """One hazard felt: its kind, the sensor's frame, where (a point in the odometry
    frame: the sensor's place when it felt it) and when (s, the body's clock)."""

    kind: HazardKind
    frame: str
    point: tuple[float, float]
    stamp: float

    @property
    def side(self) -> str:
        """The side of the body that felt it ("front left"; "" when not known)."""
        return sensor(self.frame).side

    def describe(self) -> str:
        """In a person's words: "bumped front left at (1.20, 0.40)" (odometry frame)."""
        at = f"at ({self.point[0]:.2f}, {self.point[1]:.2f})"
        side = self.side
        if self.kind == HazardKind.BUMP:
            return f"bumped {side} {at}" if side else f"bumped {at}"
        if self.kind == HazardKind.CLIFF:
            return f"cliff {side} {at}" if side else f"cliff {at}"
        wheel = f"{side} wheel" if side else "wheels"
        verb = "stalled" if self.kind == HazardKind.STALL else "dropped"
        return f"{wheel} {verb} {at}"

    def moved(self, frame_T_odom: tuple[float, float, float]) -> Hazard:
        """The same hazard with its point in another frame (``frame_T_odom`` takes this
        odometry frame into it)."""
        x, y = se2_apply(frame_T_odom, self.point)
        return replace(self, point=(float(x), float(y)))


def place(kind: HazardKind, frame: str, pose: Pose2D, stamp: float) -> Hazard:
    """A hazard felt by the sensor ``frame`` while the body stood at ``pose`` (odometry)."""
    x, y = se2_apply((pose.x, pose.y, pose.yaw), sensor(frame).offset)
    return Hazard(kind, frame, (float(x), float(y)), stamp)


@runtime_checkable
class FeelsHazards(Protocol):
    """A body with hazard sensors (the Create 3): what it felt, and what stopped it."""

    def hazards(self, since: float = -math.inf) -> list[Hazard]:
        """The hazards felt since ``since`` (the body's clock), oldest first."""
        ...

    def blocked_by(self) -> Hazard | None:
        """The hazard that stopped or refused the latest motion command (None: none)."""
        ...


def body_hazards(base: object, since: float = -math.inf) -> list[Hazard]:
    """What ``base`` felt since ``since``; [] for a body without hazard sensors."""
    return base.hazards(since) if isinstance(base, FeelsHazards) else []


def body_blocked_by(base: object) -> Hazard | None:
    """The hazard that stopped ``base``'s latest motion; None for a body without sensors."""
    return base.blocked_by() if isinstance(base, FeelsHazards) else None
