"""The Create 3's backup limit (``safety_override: none``), as its motion control keeps it.

The Create 3's cliff sensors are only at the front, so by default the robot reverses
only over floor it has just driven forward over: forward travel fills a buffer capped
at ``BACKUP_LIMIT_M`` (0.15 m), reversing empties it, and a reverse command with the
buffer empty is refused (the robot stops and raises a BACKUP_LIMIT hazard). Being put
down somewhere new (a kidnap) empties it. Values from iRobot's create3_sim
``motion_control_node`` (BACKUP_BUFFER_STOP_THRESHOLD) and the Create 3 safety docs
(https://iroboteducation.github.io/create3_docs/api/safety/).

``BackupBuffer`` mirrors that from odometry: both simulators enforce it (``SimBase``,
used by ``pmnav sim``, and the ROS 2 simulated Create 3), and ``Create3Base`` uses it
so that it never asks for a reverse the robot would refuse.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from pmnav_bt.seams import CREATE3_BACKUP_LIMIT_M, Pose2D

BACKUP_LIMIT_M = CREATE3_BACKUP_LIMIT_M


@dataclass
class BackupBuffer:
    """How far the robot may still reverse: forward travel along its heading fills it (up
    to ``limit``), reversing empties it."""

    limit: float = BACKUP_LIMIT_M
    left: float = 0.0  # metres of reverse still allowed
    _last: Pose2D | None = None

    def update(self, pose: Pose2D) -> None:
        """Account for the motion from the last odometry pose to ``pose``."""
        last, self._last = self._last, pose
        if last is None:
            return
        forward = math.cos(last.yaw) * (pose.x - last.x) + math.sin(last.yaw) * (pose.y - last.y)
        self.left = min(self.limit, self.left + forward)

    def allows(self, linear: float) -> bool:
        """Whether a command with this linear speed (m/s) may be sent now."""
        return linear >= 0.0 or self.left > 0.0

    def reset(self) -> None:
        """Put down somewhere new: no reverse until it has driven forward again."""
        self.left, self._last = 0.0, None
