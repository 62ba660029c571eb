"""Poses as a person types them on a command line: ``x,y,yaw_deg`` (shared by ``pmnav sim``
and the simulated Create 3)."""

from __future__ import annotations

import math

from pmnav_bt.cli_values import CliValueError, parse_pose_text
from pmnav_bt.errors import PmNavError
from pmnav_bt.seams import Pose2D


class PoseError(PmNavError):
    """A --pose value that is not x,y,yaw_deg."""


def parse_pose(text: str) -> Pose2D:
    """'x,y,yaw_deg' (metres, degrees) -> Pose2D (radians); finite and in range."""
    try:
        x, y, yaw_deg = parse_pose_text(text, "--pose")
    except CliValueError as err:
        raise PoseError(str(err)) from None
    return Pose2D(x, y, math.radians(yaw_deg))
