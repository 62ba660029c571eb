"""The corridor axis from the walls seen in depth.

Wall pixels are projected to the floor plane (walls are vertical, so every height of a
wall lands on one line); a RANSAC line fit on those points gives the wall's direction in
the body frame. Corridor walls run along the corridor axis, so the angle is the robot's
heading relative to the axis, modulo pi: a heading constraint available almost
everywhere in a functional building.

A real corridor has more than its two walls in view: an alcove's side walls, a pillar,
a cart or a bench standing at an angle. Counted in pixels, a pillar's face a metre off
fills the frame top to bottom and outweighs four metres of wall further on (a 0.6 m
box turned 30 deg, 1.6 m ahead: the fit took its face, 60 deg off the axis). So RANSAC
scores a line by the floor it covers (``_cover``: each ``COVER_CELL_M`` cell of the
floor plane once however many pixels land on it), and a line covering less than
``MIN_COVER_M`` is no wall (a pillar's face, a cart's side). The line is then fitted on
every pixel near it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmnav_bt.geometry import wrap_angle
from pmnav_bt.seams import Observation

MAX_RANGE_M = 6.0  # wall points farther than this are too noisy
MIN_INLIERS = 60
INLIER_M = 0.05
ITERATIONS = 60
MAX_PARALLEL = math.radians(10.0)  # a corridor's two walls: this parallel ...
MIN_WIDTH_M, MAX_WIDTH_M = 1.0, 6.0  # ... and this far apart
MIN_CENTRE_WAY_M = 0.15  # nearer the centre line than this: on it, as far as depth tells
COVER_CELL_M = 0.05  # the floor plane in cells this size: each counts once in a line's score
COVER_GAP_M = 0.3  # ... which is the floor it covers, gaps longer than this left out
MIN_COVER_M = 0.8  # a line over less floor than this is no wall: a pillar's face, a cart


def wall_points(obs: Observation, wall: np.ndarray, stride: int = 2) -> np.ndarray:
    """(N, 2) floor-plane points (x forward, y left, metres) of the wall pixels in view."""
    if obs.depth is None:
        return np.zeros((0, 2))
    k = obs.intrinsics
    vs, us = np.nonzero(wall[::stride, ::stride])
    vs, us = vs * stride, us * stride
    z = obs.depth[vs, us].astype(float)
    keep = np.isfinite(z) & (z > 0.2) & (z < MAX_RANGE_M)
    z, us = z[keep], us[keep]
    return np.stack([z, (k.cx - us) * z / k.fx], axis=1)


def fit_wall_angle(points: np.ndarray, seed: int = 0) -> tuple[float, int] | None:
    """The direction (rad, in (-pi/2, pi/2], body frame) of the best line through ``points``
    and its inlier count, or None when no line has ``MIN_INLIERS`` points."""
    line = fit_wall_line(points, seed)
    return None if line is None else (line.angle, line.inliers)


@dataclass(frozen=True)
class WallLine:
    """A wall line in the body frame: its direction (rad, mod pi), its signed distance
    from the robot (m, positive: on the left), its inlier count and length along it (m)."""

    angle: float
    offset: float
    inliers: int
    length: float


def fit_wall_line(points: np.ndarray, seed: int = 0) -> WallLine | None:
    """The best line through the floor-plane ``points`` (RANSAC over the floor cells they
    cover, then least squares on the points near the line), or None when no line has
    ``MIN_INLIERS`` points and ``MIN_COVER_M`` of floor (see the module)."""
    n = len(points)
    if n < MIN_INLIERS:
        return None
    cells = np.unique(np.floor(points / COVER_CELL_M), axis=0)
    cells = (cells + 0.5) * COVER_CELL_M  # each covered cell once, at its centre
    m = len(cells)
    if m < 2:
        return None
    rng = np.random.default_rng(seed)
    best: tuple[float, np.ndarray, np.ndarray] | None = None  # (cover, a point, normal)
    for _ in range(ITERATIONS):
        i, j = rng.choice(m, 2, replace=False)
        d = cells[j] - cells[i]
        norm = float(np.hypot(*d))
        if norm < 0.3:
            continue
        normal = np.array([-d[1], d[0]]) / norm
        score = _cover(cells[np.abs((cells - cells[i]) @ normal) < INLIER_M], normal)
        if best is None or score > best[0]:
            best = (score, cells[i], normal)
    if best is None:
        return None
    _, at, normal = best
    best_in = np.abs((points - at) @ normal) < INLIER_M
    if best_in.sum() < MIN_INLIERS or _cover(points[best_in], normal) < MIN_COVER_M:
        return None
    p = points[best_in]
    mean = p.mean(axis=0)
    _, _, vt = np.linalg.svd(p - mean, full_matrices=False)
    d = vt[0]
    a = math.atan2(d[1], d[0])
    along = (p - mean) @ d
    # Signed distance of the line from the origin: the left normal of d, flipped to face
    # the line's side of the robot when d points backwards.
    normal = np.array([-d[1], d[0]]) if d[0] >= 0 else np.array([d[1], -d[0]])
    offset = float(mean @ normal)
    return WallLine(wrap_angle(2.0 * a) / 2.0, offset, int(best_in.sum()), float(np.ptp(along)))


def _cover(points: np.ndarray, normal: np.ndarray) -> float:
    """How much of a line (m) ``points`` near it cover: their run along it, less the gaps
    over ``COVER_GAP_M`` (a far wall's points lie a column apart, 0.1-0.2 m; a gap wider
    than that is a doorway or another surface in front)."""
    if len(points) < 2:
        return 0.0
    along = np.sort(points @ np.array([normal[1], -normal[0]]))
    return float(np.minimum(np.diff(along), COVER_GAP_M).sum())


def wall_lines(points: np.ndarray, most: int) -> list[WallLine]:
    """Up to ``most`` wall lines through ``points``, strongest first: each fit on the points
    the lines before it left."""
    lines: list[WallLine] = []
    for seed in range(most):
        line = fit_wall_line(points, seed=seed)
        if line is None:
            break
        lines.append(line)
        normal = np.array([-math.sin(line.angle), math.cos(line.angle)])
        points = points[np.abs(points @ normal - line.offset) > 3.0 * INLIER_M]
    return lines


def corridor_centre(points: np.ndarray) -> tuple[float, float] | None:
    """(axis direction, centre-line offset) from both walls of the corridor in view: the
    strongest wall line and a second one parallel to it on the robot's other side, the
    offset (m, positive: the centre line is on the left) half-way between them. None
    without two such walls (a junction, a wall ahead, one wall out of view)."""
    return centre_between(wall_lines(points, 2))


def centre_between(lines: list[WallLine]) -> tuple[float, float] | None:
    """``corridor_centre`` from the two strongest wall lines already fitted."""
    if len(lines) < 2:
        return None
    first, second = lines[:2]
    if first.offset * second.offset >= 0.0:
        return None
    if abs(wrap_angle(2.0 * (first.angle - second.angle))) / 2.0 > MAX_PARALLEL:
        return None
    if not MIN_WIDTH_M <= abs(first.offset - second.offset) <= MAX_WIDTH_M:
        return None
    return first.angle, (first.offset + second.offset) / 2.0


def way_to_centre(
    lines: list[tuple[float, float]], axis: float | None
) -> tuple[float, float] | None:
    """The way (odometry, m) across the corridor from the robot to its centre line, from
    the wall lines a look round saw: (odometry direction of the line, its offset, positive
    on the line's left). Half-way between the nearest walls along the axis on either side
    is the centre line. None without an axis or such a wall on both sides, or within
    ``MIN_CENTRE_WAY_M`` of the line (on it: no move).

    A robot that stopped against a wall stands most of a corridor's half-width off the
    centre line the corridor belief's hypotheses put it on; its look round, taken from
    there, fits a place with wider corridors better than the true one (sign_sparse_2 hard
    #8 at 5 %: 0.8 m off centre at a T junction, the belief put it at the cross junction).
    Along the corridor the hypotheses stand every lattice step: no way along it is needed
    (and walls across the axis pair up wrongly: an end wall with a door's recess)."""
    if axis is None:
        return None
    normal = np.array([-math.sin(axis), math.cos(axis)])
    side = []  # each wall's signed distance along the normal
    for direction, offset in lines:
        if abs(wrap_angle(2.0 * (direction - axis)) / 2.0) < MAX_PARALLEL:
            side.append(offset * float(normal @ (-math.sin(direction), math.cos(direction))))
    left = [d for d in side if d > 0.0]
    right = [d for d in side if d < 0.0]
    if not left or not right or not MIN_WIDTH_M <= min(left) - max(right) <= MAX_WIDTH_M:
        return None
    across = (min(left) + max(right)) / 2.0
    if abs(across) < MIN_CENTRE_WAY_M:
        return None
    return float(normal[0] * across), float(normal[1] * across)


def wall_angle(obs: Observation, wall: np.ndarray) -> float | None:
    """The wall direction in the body frame (mod pi) from one frame, or None."""
    fit = fit_wall_angle(wall_points(obs, wall))
    return None if fit is None else fit[0]


def axis_in_odom(angles: list[tuple[float, float, int]]) -> float | None:
    """Combine (view odometry yaw, wall angle in that view, inliers) into one corridor axis
    in the odometry frame (mod pi): the inlier-weighted circular mean of the doubled angles,
    over the views that agree with the strongest one (walls of side corridors disagree)."""
    if not angles:
        return None
    dirs = [(wrap_angle(2.0 * (yaw + a)), n) for yaw, a, n in angles]
    ref = max(dirs, key=lambda d: d[1])[0]
    agree = [(d, n) for d, n in dirs if abs(wrap_angle(d - ref)) < math.radians(30.0)]
    s = sum(n * math.sin(d) for d, n in agree)
    c = sum(n * math.cos(d) for d, n in agree)
    return math.atan2(s, c) / 2.0


def heading_correction(axis_odom: float, rotation: float, corridor_heading: float) -> float:
    """The rotation to add to ``map_T_odom`` so that the wall axis measured in odometry
    (``axis_odom``, mod pi) lines up with the corridor's heading on the map, in (-pi/2, pi/2]."""
    return wrap_angle(2.0 * (corridor_heading - (axis_odom + rotation))) / 2.0
