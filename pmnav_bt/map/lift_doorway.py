"""Where a lift's doorway and cabin are, read from the map: what the lift subtree drives
through and what the simulator builds behind a lift's doors.

A lift is a landmark of kind ``elevator`` (``landmark_kinds.ELEVATOR``) on a corridor
wall: its doors (``ELEVATOR_WIDTH_M`` across both leaves) with the call-button panel on
the viewer's right, so the doorway's centre is half a panel's width to the viewer's left
of the landmark's point. Behind the doors, through the wall, is the cabin.

The cabin is 2.0 m wide and 1.6 m deep inside: EN 81-70's type 3 car (2.0 x 1.4 m, a
wheelchair with a companion, or a small bed) with 0.2 m more depth, so that the
robot (0.34 m across) can turn round inside and leave facing the corridor. The robot
stands in its middle, ``CABIN_DEPTH_M / 2`` beyond the doorway.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmnav_bt.map.landmark_kinds import ELEVATOR, ELEVATOR_PANEL_M, ELEVATOR_WIDTH_M, landmark_shape
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.seams import Pose2D

CABIN_WIDTH_M = 2.0
CABIN_DEPTH_M = 1.6
# The corridor wall the doorway goes through (the simulator's walls: sim/scene/appearance.py).
DOORWAY_WALL_M = 0.10


@dataclass(frozen=True)
class Doorway:
    """A lift's doorway on one level, in that level's map frame: ``centre`` on the corridor
    wall's face, ``into`` the unit direction from the corridor into the cabin, ``width``
    of the opening, ``lobby`` the point on the corridor's centre line in front of it."""

    centre: tuple[float, float]
    into: tuple[float, float]
    width: float
    lobby: tuple[float, float]

    @property
    def yaw_in(self) -> float:
        """The heading from the corridor into the cabin."""
        return math.atan2(self.into[1], self.into[0])

    def cabin_centre(self, wall: float = DOORWAY_WALL_M) -> tuple[float, float]:
        """The middle of the cabin's floor, behind a wall ``wall`` m thick."""
        d = wall + CABIN_DEPTH_M / 2.0
        return self.centre[0] + d * self.into[0], self.centre[1] + d * self.into[1]

    def cabin_corners(self, wall: float = DOORWAY_WALL_M) -> list[tuple[float, float]]:
        """The cabin's floor, four corners (for drawing it)."""
        u = np.asarray(self.into)
        v = np.array([-u[1], u[0]]) * CABIN_WIDTH_M / 2.0
        near = np.asarray(self.centre) + u * wall
        far = near + u * CABIN_DEPTH_M
        return [(float(q[0]), float(q[1])) for q in (near - v, far - v, far + v, near + v)]

    def cabin_pose(self, wall: float = DOORWAY_WALL_M) -> Pose2D:
        """The robot in the middle of the cabin, turned round to face the doors."""
        x, y = self.cabin_centre(wall)
        return Pose2D(x, y, math.atan2(-self.into[1], -self.into[0]))


class NotALiftError(ValueError):
    """The landmark named as a lift's lobby is not a lift (its kind is not elevator/lift)."""


def doorway(pm: PrioriMap, landmark_id: str) -> Doorway:
    """The doorway of the lift landmark ``landmark_id`` of ``pm``'s building: on the wall
    of the corridor the landmark is beside, the doors half a panel to the viewer's left of
    its point (as the simulator builds them, ``sim/world.py``)."""
    lm = pm.building.landmark(landmark_id)
    if landmark_shape(lm.kind) is not ELEVATOR:
        raise NotALiftError(
            f"landmark {landmark_id!r} is a {lm.kind!r}, not a lift (kind elevator or lift)"
        )
    pos = np.asarray(lm.pos, float)
    loc = pm.locate(float(pos[0]), float(pos[1]))
    on_line = loc.point(pm)
    out = pos - on_line
    n = float(np.linalg.norm(out))
    if n < 1e-6:  # on the centre line itself: take the wall on the segment's left
        h = loc.segment.heading
        out = np.array([-math.sin(h), math.cos(h)])
    else:
        out = out / n
    wall = on_line + out * loc.segment.width / 2.0
    left = np.array([-out[1], out[0]])  # the viewer faces +out; their left
    centre = wall + left * ELEVATOR_PANEL_M / 2.0
    lobby = on_line + left * ELEVATOR_PANEL_M / 2.0
    return Doorway(
        (float(centre[0]), float(centre[1])),
        (float(out[0]), float(out[1])),
        ELEVATOR_WIDTH_M,
        (float(lobby[0]), float(lobby[1])),
    )
