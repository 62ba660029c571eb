"""A laser-scan-like range per image column from depth (like ``depthimage_to_laserscan``).

Every pixel with depth is back-projected; points between ``MIN_HEIGHT`` and
``MAX_HEIGHT`` above the floor are obstacles (walls, furniture), the floor is not. Each
column's range is the horizontal distance to its nearest obstacle point; a column that
sees none within ``max_range`` is free up to ``max_range`` (``inf``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pmnav_bt.perception.depth import back_project
from pmnav_bt.seams import Observation

MIN_HEIGHT = 0.12  # m above the floor: lower points are floor (and its depth noise)
MAX_HEIGHT = 2.0  # m above the floor: higher points cannot touch the body


@dataclass(frozen=True)
class Scan:
    """Ranges (m; inf: nothing within ``max_range``) along bearings (rad, left positive,
    relative to the camera's heading), taken at the observation's odometry pose."""

    bearings: np.ndarray
    ranges: np.ndarray
    max_range: float
    pose: tuple[float, float, float]


def depth_scan(obs: Observation, max_range: float = 6.0, column_step: int = 4) -> Scan | None:
    """The scan of every ``column_step``-th column of ``obs`` (None without depth)."""
    if obs.depth is None:
        return None
    pts = back_project(obs)[:, ::column_step]  # (H, W', 3): x forward, y left, z up
    height = pts[..., 2] + obs.camera_height
    with np.errstate(invalid="ignore"):
        obstacle = (height > MIN_HEIGHT) & (height < MAX_HEIGHT)
    dist = np.where(obstacle, np.hypot(pts[..., 0], pts[..., 1]), np.inf)
    ranges = np.nanmin(np.where(np.isfinite(dist), dist, np.inf), axis=0)
    ranges = np.where(ranges > max_range, np.inf, ranges)
    cols = np.arange(obs.depth.shape[1])[::column_step]
    bearings = np.array([obs.intrinsics.pixel_bearing(float(u)) for u in cols])
    p = obs.pose
    return Scan(bearings, ranges.astype(float), max_range, (p.x, p.y, p.yaw))
