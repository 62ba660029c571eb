"""Where to stand to read a plate seen but not read: nearer, square to it, on free floor.

A plate's text reads from as far as its size allows (``read_range.plate_read_range``:
the sign benchmark's recall by distance for text lines that high, at the camera's width)
and at any angle up to 70 deg off its normal (``read_range.ANGLE_RECALL``); seen from
farther or more aslant than that, it is a patch of text the recogniser cannot name. The
reading pose stands on the plate's normal (the wall's, from depth) or near it
(``ANGLES_DEG``, square first), ``RANGE_MARGIN_M`` inside the read range (the pose
estimate and depth are good to a few decimetres), and never farther than where the
plate was already seen and not read, less ``CLOSER_M``: a second look from the same
spot reads no better. It stands no nearer than ``MIN_STANDOFF_M`` (the body's radius and
room to turn) and than where the plate's text leaves the top of the camera's view
(``view_standoff``, from the height of the text's top as depth measured it: a flag sign
hangs at 2.2-2.45 m, 0.6-0.85 m above the camera, and its small text is read only from
between where it leaves the view and where it grows too small, a few decimetres). Of
the candidate spots the first on free floor (``free``: the caller's corridors and what
depth showed standing there) wins, the one nearest the robot at each angle.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

ANGLES_DEG = (0.0, 15.0, -15.0, 30.0, -30.0, 45.0, -45.0)  # off the normal, square first
RANGE_MARGIN_M = 0.3
CLOSER_M = 0.5
MIN_STANDOFF_M = 0.6
STEP_M = 0.2  # between candidate distances along each direction
VIEW_MARGIN = math.radians(2.0)  # the text's top this far inside the top of the view (10
# rows of a 240-row frame, 20 of the 480-row reading view: room round the text for OCR)


@dataclass(frozen=True)
class ReadingPose:
    """Where to stand (``x``, ``y``, the plate's frame) facing the plate (``yaw``, rad),
    ``distance`` m from it, ``angle`` rad off its normal."""

    x: float
    y: float
    yaw: float
    distance: float
    angle: float


def view_standoff(top: float, camera_height: float, vfov: float) -> float:
    """How near (m) a plate whose text's top is ``top`` m above the floor can be stood to
    and its text still be whole in a view ``vfov`` rad high from ``camera_height`` m
    (level camera)."""
    above = top - camera_height
    if above <= 0.0:
        return 0.0
    return above / math.tan(vfov / 2.0 - VIEW_MARGIN)


def reading_pose(
    plate: tuple[float, float],
    normal: tuple[float, float],
    read_range: float,
    free: Callable[[tuple[float, float]], bool],
    *,
    seen_from: tuple[float, float],
    robot: tuple[float, float],
    nearest: float = MIN_STANDOFF_M,
) -> ReadingPose | None:
    """The spot to read ``plate`` (its centre; ``normal``: the wall's, unit, out into the
    corridor) from, for a plate read to ``read_range`` m and seen unread from
    ``seen_from``: see the module docstring. ``robot``: where the robot is (the nearest
    free spot at each angle wins); ``nearest``: the least standoff (at least
    ``MIN_STANDOFF_M``). None when no candidate spot is free."""
    p, n = np.asarray(plate, float), np.asarray(normal, float)
    n = n / np.linalg.norm(n)
    nearest = max(MIN_STANDOFF_M, nearest)
    seen = float(np.linalg.norm(np.asarray(seen_from, float) - p))
    far = max(nearest, min(read_range - RANGE_MARGIN_M, seen - CLOSER_M))
    count = int(math.floor((far - nearest) / STEP_M + 1e-9)) + 1
    distances = [far - i * STEP_M for i in range(count)]
    for deg in ANGLES_DEG:
        a = math.radians(deg)
        c, s = math.cos(a), math.sin(a)
        way = np.array([c * n[0] - s * n[1], s * n[0] + c * n[1]])
        spots = [(d, p + d * way) for d in distances]
        spots = [(d, q) for d, q in spots if free((float(q[0]), float(q[1])))]
        if spots:
            d, q = min(spots, key=lambda dq: float(np.linalg.norm(dq[1] - robot)))
            yaw = math.atan2(-way[1], -way[0])
            return ReadingPose(float(q[0]), float(q[1]), yaw, d, a)
    return None
