"""Small planar geometry: headings, compass words, relative actions, point-to-segment
projection, SE(2) poses, axis-aligned rectangles.

Map frame is REP-103: x east, y north, headings counter-clockwise from +x, radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
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


def point_towards(a, b, distance: float) -> tuple[float, float]:
    """The point ``distance`` metres from ``a`` towards ``b``, never beyond ``b``."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    d = float(np.linalg.norm(b - a))
    if d < 1e-6:
        return float(b[0]), float(b[1])
    p = a + (b - a) * min(distance, d) / d
    return float(p[0]), float(p[1])


def project_points_to_segments(
    points: np.ndarray, seg_a: np.ndarray, seg_b: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nearest segment for each point.

    points (N,2), seg_a/seg_b (M,2). Returns (index of nearest segment (N,),
    parameter t in [0,1] along it (N,), distance (N,)). Uses an STR-tree, so large
    maps cost O(N log M); to ask about the same segments again and again, keep a
    ``SegmentIndex``.
    """
    return SegmentIndex(seg_a, seg_b).project(points)


class SegmentIndex:
    """Segments (seg_a/seg_b (M,2)) with their STR-tree built once: ``project`` answers
    as ``project_points_to_segments`` does. Building the tree is most of the cost of
    asking about one point (80 of 90 us on a 27-segment map), which a tick that asks
    where the robot is along its corridor cannot spend (issue 37: tick p99 under 1 ms)."""

    def __init__(self, seg_a: np.ndarray, seg_b: np.ndarray):
        self.seg_a = np.asarray(seg_a, dtype=float).reshape(-1, 2)
        self.seg_b = np.asarray(seg_b, dtype=float).reshape(-1, 2)
        self._tree = None
        if len(self.seg_a):
            self._tree = shapely.STRtree(
                shapely.linestrings(np.stack([self.seg_a, self.seg_b], axis=1))
            )

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(index of the nearest segment, t in [0,1] along it, distance) for each point."""
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        n = len(points)
        if n == 0 or self._tree is None:
            return np.zeros(n, dtype=int), np.zeros(n), np.full(n, np.inf)
        pairs = self._tree.query_nearest(shapely.points(points), all_matches=False)
        idx = np.empty(n, dtype=int)
        idx[pairs[0]] = pairs[1]
        a, d = self.seg_a[idx], self.seg_b[idx] - self.seg_a[idx]
        len2 = np.maximum((d * d).sum(axis=1), 1e-12)
        t = np.clip(((points - a) * d).sum(axis=1) / len2, 0.0, 1.0)
        dist = np.linalg.norm(points - (a + t[:, None] * d), axis=1)
        return idx, t, dist


# -- planar rigid transforms, as (x, y, yaw) triples ------------------------------------


def se2_compose(a: tuple[float, float, float], b: tuple[float, float, float]) -> tuple:
    """a * b: the pose b expressed in a's parent frame."""
    ax, ay, ath = a
    bx, by, bth = b
    c, s = math.cos(ath), math.sin(ath)
    return (ax + c * bx - s * by, ay + s * bx + c * by, wrap_angle(ath + bth))


def se2_inverse(a: tuple[float, float, float]) -> tuple:
    """The inverse transform of a."""
    x, y, th = a
    c, s = math.cos(th), math.sin(th)
    return (-c * x - s * y, s * x - c * y, wrap_angle(-th))


def se2_apply(a: tuple[float, float, float], p) -> np.ndarray:
    """Transform point p (x, y) by a."""
    x, y, th = a
    c, s = math.cos(th), math.sin(th)
    return np.array([x + c * float(p[0]) - s * float(p[1]), y + s * float(p[0]) + c * float(p[1])])


def fit_se2(src: np.ndarray, dst: np.ndarray) -> tuple[tuple[float, float, float], float]:
    """Least-squares rigid transform T with T(src_i) ~ dst_i (2D Kabsch), and the RMS residual.

    src, dst: (N, 2) with N >= 2 distinct points.
    """
    src = np.asarray(src, dtype=float)
    dst = np.asarray(dst, dtype=float)
    cs, cd = src.mean(axis=0), dst.mean(axis=0)
    a, b = src - cs, dst - cd
    sxx = float((a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]).sum())
    sxy = float((a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]).sum())
    th = math.atan2(sxy, sxx)
    c, s = math.cos(th), math.sin(th)
    t = cd - np.array([c * cs[0] - s * cs[1], s * cs[0] + c * cs[1]])
    tf = (float(t[0]), float(t[1]), th)
    res = np.array([se2_apply(tf, p) for p in src]) - dst
    return tf, float(np.sqrt((res**2).sum(axis=1).mean()))


@dataclass(frozen=True)
class Rect:
    """An axis-aligned rectangle in the map frame (metres): an open area a floor plan's
    draft flags (``map.draft``), a wall box the simulator builds from a grid
    (``sim.grid_walls``)."""

    xmin: float
    ymin: float
    xmax: float
    ymax: float

    @property
    def centre(self) -> tuple[float, float]:
        return (self.xmin + self.xmax) / 2.0, (self.ymin + self.ymax) / 2.0

    @property
    def half(self) -> tuple[float, float]:
        """Half its width and half its height."""
        return (self.xmax - self.xmin) / 2.0, (self.ymax - self.ymin) / 2.0
