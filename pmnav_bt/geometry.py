"""Small planar geometry: headings, compass words, relative actions, point-to-segment projection.

Map frame is REP-103: x east, y north, headings counter-clockwise from +x, radians.
"""

from __future__ import annotations

import math
from enum import Enum

import numpy as np
import shapely

COMPASS = ("east", "northeast", "north", "northwest", "west", "southwest", "south", "southeast")


class Action(str, Enum):
    """First-person actions of a plan step (the paper's words)."""

    GO_STRAIGHT = "go straight"
    TURN_LEFT = "turn left"
    TURN_RIGHT = "turn right"
    TURN_AROUND = "turn around"
    ARRIVE = "arrive"


# Bends smaller than this are "go straight"; larger than TURN_AROUND_MIN are "turn around".
STRAIGHT_MAX = math.radians(30.0)
TURN_AROUND_MIN = math.radians(150.0)


def wrap_angle(a: float) -> float:
    """Wrap an angle to (-pi, pi]."""
    a = math.fmod(a + math.pi, 2.0 * math.pi)
    if a <= 0.0:
        a += 2.0 * math.pi
    return a - math.pi


def heading(p: np.ndarray | tuple, q: np.ndarray | tuple) -> float:
    """Heading (rad, CCW from +x) of the direction from p to q."""
    return math.atan2(float(q[1]) - float(p[1]), float(q[0]) - float(p[0]))


def compass(h: float) -> str:
    """Eight-way compass word for a heading in the map frame (+x east, +y north)."""
    idx = int(round(wrap_angle(h) / (math.pi / 4.0))) % 8
    return COMPASS[idx]


def relative_action(heading_in: float, heading_out: float) -> Action:
    """The action that turns a traveller heading ``heading_in`` onto ``heading_out``."""
    d = wrap_angle(heading_out - heading_in)
    if abs(d) <= STRAIGHT_MAX:
        return Action.GO_STRAIGHT
    if abs(d) >= TURN_AROUND_MIN:
        return Action.TURN_AROUND
    return Action.TURN_LEFT if d > 0 else Action.TURN_RIGHT


def side_of(heading_travel: float, origin, point) -> str:
    """'left' or 'right': where ``point`` lies seen from ``origin`` facing ``heading_travel``."""
    dx, dy = float(point[0]) - float(origin[0]), float(point[1]) - float(origin[1])
    cross = math.cos(heading_travel) * dy - math.sin(heading_travel) * dx
    return "left" if cross >= 0.0 else "right"


def project_points_to_segments(
    points: np.ndarray, seg_a: np.ndarray, seg_b: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nearest segment for each point.

    points (N,2), seg_a/seg_b (M,2). Returns (index of nearest segment (N,),
    parameter t in [0,1] along it (N,), distance (N,)). Uses an STR-tree, so large
    maps cost O(N log M).
    """
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    seg_a = np.asarray(seg_a, dtype=float).reshape(-1, 2)
    seg_b = np.asarray(seg_b, dtype=float).reshape(-1, 2)
    n = len(points)
    if n == 0 or len(seg_a) == 0:
        return np.zeros(n, dtype=int), np.zeros(n), np.full(n, np.inf)
    lines = shapely.linestrings(np.stack([seg_a, seg_b], axis=1))
    tree = shapely.STRtree(lines)
    pairs = tree.query_nearest(shapely.points(points), all_matches=False)
    idx = np.empty(n, dtype=int)
    idx[pairs[0]] = pairs[1]
    a, d = seg_a[idx], seg_b[idx] - seg_a[idx]
    len2 = np.maximum((d * d).sum(axis=1), 1e-12)
    t = np.clip(((points - a) * d).sum(axis=1) / len2, 0.0, 1.0)
    dist = np.linalg.norm(points - (a + t[:, None] * d), axis=1)
    return idx, t, dist
