"""What the belief is told: a glimpse is one look round (a panorama) or one view ahead
while driving, in odometry: the signs read and where, the free floor in depth, the doors
seen along the walls, the way to the corridor's centre line."""

from __future__ import annotations

from dataclasses import dataclass

from pmnav_bt.seams import Entity, Pose2D


@dataclass(frozen=True)
class Glimpse:
    """What one panorama saw: its odometry pose and each sign read, with where (odom)."""

    odom: Pose2D
    seen: dict[Entity, tuple[float, float]]
    blocked: float | None = None  # odometry heading of a drive that was just blocked here
    # Free floor (m) seen in depth straight ahead of each view: (odometry yaw, distance).
    free: tuple[tuple[float, float], ...] = ()
    # Signs read whose place is not known (cut by the image border): in sight, not missed.
    named: frozenset[Entity] = frozenset()
    # The way (odometry, m) from the robot to the corridor's centre line, seen in depth.
    to_centre: tuple[float, float] | None = None
    # Doors seen along the walls (odometry xy of each), and the odometry yaws of the views
    # that looked for them (none: no door evidence).
    doors: tuple[tuple[float, float], ...] = ()
    door_views: tuple[float, ...] = ()
