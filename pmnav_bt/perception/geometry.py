"""Image geometry: where a grounded target is, and how far the floor is free.

The camera looks along the body's +x at height ``camera_height`` with zero pitch;
depth is metres along the optical axis.
"""

from __future__ import annotations

import math

import numpy as np

from pmnav_bt.seams import Detection, Observation


def pixel_bearing(obs: Observation, u: float) -> float:
    """Bearing (rad, left positive) of image column u."""
    return obs.intrinsics.pixel_bearing(u)


def target_point(obs: Observation, det: Detection) -> np.ndarray | None:
    """The target's position (x forward, y left, metres) in the body frame, from depth.

    Uses the median depth over the mask (or box). None without depth.
    """
    if obs.depth is None:
        return None
    if det.mask is not None and det.mask.any():
        z = float(np.median(obs.depth[det.mask]))
    else:
        x0, y0, x1, y1 = (int(round(v)) for v in det.box)
        z = float(np.median(obs.depth[y0 : y1 + 1, x0 : x1 + 1]))
    u, _ = det.centre
    k = obs.intrinsics
    return np.array([z, (k.cx - u) * z / k.fx])


def free_distance(
    obs: Observation, bearing: float, half_width: float = 0.25, margin: float = 0.15
) -> float:
    """How far (m) the body can drive along ``bearing`` before something stands on the floor.

    For each image row below the horizon, the floor would be at a known depth; a
    pixel closer than that (by ``margin``) is an obstacle or a wall. Only columns
    within ``half_width`` of the straight line along ``bearing`` count.
    """
    if obs.depth is None:
        return math.inf
    k = obs.intrinsics
    h = obs.camera_height
    rows = np.arange(int(math.ceil(k.cy)) + 1, k.height)
    if len(rows) == 0:
        return math.inf
    z_floor = h * k.fy / (rows - k.cy)  # depth of the floor seen in each row
    depth = obs.depth[rows]  # (R, W)
    cols = np.arange(k.width)
    # Lateral offset of each pixel from the line along `bearing`, at its measured depth.
    y = (k.cx - cols)[None, :] * depth / k.fx
    lateral = np.abs(y * math.cos(bearing) - depth * math.sin(bearing))
    blocked = (depth < z_floor[:, None] - margin) & (lateral <= half_width)
    if not blocked.any():
        return math.inf
    ahead = depth * math.cos(bearing) + y * math.sin(bearing)
    return float(ahead[blocked].min())
