"""Poses as a person types them on a command line: ``x,y,yaw_deg``."""

from __future__ import annotations

import math

from pmnav_bt.errors import PmNavError
from pmnav_bt.seams import Pose2D


class PoseError(PmNavError):
    """A --pose value that is not x,y,yaw_deg."""


def parse_pose(text: str) -> Pose2D:
    """'x,y,yaw_deg' (metres, degrees) -> Pose2D (radians)."""
    parts = text.replace(" ", "").split(",")
    try:
        x, y, yaw_deg = (float(v) for v in parts)
    except ValueError:
        raise PoseError(
            f"--pose {text!r}: expected three numbers 'x,y,yaw_deg', e.g. --pose 0,30,-90"
        ) from None
    return Pose2D(x, y, math.radians(yaw_deg))
