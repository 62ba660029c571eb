"""Something that moves: what stands on the floor in depth, and where it stood a frame ago.

A robot cannot tell a person from a bin by its outline in depth alone, but it can watch
where things stand. Each depth frame shows, per image column, the nearest thing on the
floor (a pixel nearer than the floor it hides, as ``free_distance`` finds it); put in
the odometry frame with the frame's own pose, those points stay where they are for
walls, benches and barriers however the robot moves, and shift for a person walking,
turning or stepping aside. ``moved`` compares two frames' points in the robot's way
(along ``bearing``, ``half_width`` either side, within ``reach``): points of either
frame with none of the other frame near them are where something came or went. It
needs no labels, so it runs alike in the simulator and on the robot; a person standing
quite still reads as still (and is waited for all the same where they shut the way:
see ``pmnav_bt/way_ahead.py``).

The thresholds: ``CHANGE_M`` (0.2 m) is above what odometry drifts in the 1 s between
watch frames and what the near face of a still thing shifts by as the robot's view of it
turns (a few cm), and below the 0.3-1.4 m a walker moves in that second;
``MIN_COLUMNS`` (1.5 % of the columns, at least 3) is a person's edge a few
centimetres wide at 2 m, well above single flickering columns at depth edges.
"""

from __future__ import annotations

import math

import numpy as np

from pmnav_bt.seams import Observation

CHANGE_M = 0.2  # a point with nothing of the other frame this near moved
MIN_COLUMNS_FRACTION = 0.015  # this share of a frame's columns moving is something moving
MIN_COLUMNS = 3
FLOOR_MARGIN_M = 0.15  # a pixel this much nearer than the floor it hides stands on it


def floor_points(obs: Observation) -> np.ndarray:
    """Per image column, the nearest point standing on the floor, in the odometry frame
    ((N, 2), columns where nothing stands left out; empty without depth)."""
    if obs.depth is None:
        return np.empty((0, 2))
    k = obs.intrinsics
    rows = np.arange(int(math.ceil(k.cy)) + 1, k.height)
    if len(rows) == 0:
        return np.empty((0, 2))
    z_floor = obs.camera_height * k.fy / (rows - k.cy)
    depth = obs.depth[rows]
    standing = depth < z_floor[:, None] - FLOOR_MARGIN_M
    z = np.where(standing, depth, np.inf).min(axis=0)
    cols = np.flatnonzero(np.isfinite(z))
    z = z[cols]
    y = (k.cx - cols) * z / k.fx  # left of the optical axis
    p = obs.pose
    c, s = math.cos(p.yaw), math.sin(p.yaw)
    return np.stack([p.x + c * z - s * y, p.y + s * z + c * y], axis=1)


def _in_way(points: np.ndarray, obs: Observation, bearing: float, reach: float, half: float):
    """The ``points`` (odometry frame) within ``reach`` along ``bearing`` from ``obs``'s
    pose and ``half`` either side of that line."""
    p = obs.pose
    a = p.yaw + bearing
    d = points - (p.x, p.y)
    ahead = d[:, 0] * math.cos(a) + d[:, 1] * math.sin(a)
    side = np.abs(-d[:, 0] * math.sin(a) + d[:, 1] * math.cos(a))
    return points[(ahead > 0.0) & (ahead <= reach) & (side <= half)]


def _in_view(points: np.ndarray, obs: Observation, margin: float = math.radians(2.0)):
    """The ``points`` (odometry frame) inside ``obs``'s horizontal field of view."""
    p = obs.pose
    edge = abs(obs.intrinsics.pixel_bearing(0.0)) - margin
    b = np.arctan2(points[:, 1] - p.y, points[:, 0] - p.x) - p.yaw
    return points[np.abs(np.remainder(b + math.pi, math.tau) - math.pi) <= edge]


def _unmatched(these: np.ndarray, others: np.ndarray) -> int:
    """How many of ``these`` points have none of ``others`` within CHANGE_M."""
    if len(these) == 0:
        return 0
    if len(others) == 0:
        return len(these)
    d2 = ((these[:, None, :] - others[None, :, :]) ** 2).sum(axis=2)
    return int(np.count_nonzero(d2.min(axis=1) > CHANGE_M**2))


def moved(
    before: Observation,
    after: Observation,
    bearing: float,
    reach: float,
    half_width: float = 0.6,
) -> bool | None:
    """Whether something in the way along ``bearing`` (rad, body frame of ``after``)
    within ``reach`` metres came, went or moved between ``before`` and ``after``; None
    when a frame has no depth."""
    if before.depth is None or after.depth is None:
        return None
    old, new = floor_points(before), floor_points(after)
    changed = _unmatched(_in_way(new, after, bearing, reach, half_width), old)
    gone = _in_view(_in_way(old, after, bearing, reach, half_width), after)
    changed += _unmatched(gone, new)
    need = max(MIN_COLUMNS, int(MIN_COLUMNS_FRACTION * after.depth.shape[1]))
    return changed >= need
