"""A rolling local costmap in the odometry frame: what stands on the floor near the robot.

What it models: Nav2's local costmap with an obstacle layer and an inflation layer, for a
depth camera. A fixed window (``SIZE_M`` square, 10 m, ``RESOLUTION_M`` cells) centred on the
robot moves with it; each cell is free or occupied, with the time it was last marked.

- **Marking**: a depth pixel whose point stands above the floor (``FLOOR_BAND_M``, the
  same floor/obstacle split as ``perception/geometry.free_distance``) and below the top
  of the robot with its camera mast (``ROBOT_HEIGHT_M``) marks its cell, up to
  ``MARK_RANGE_M`` away (depth farther off is too coarse to steer by).
- **Clearing**: a cell is cleared where the camera sees the floor in it, nearer than the
  first obstacle along that bearing (Nav2 ray-traces each ray's 2-D shadow; a camera 1.6 m
  up looks over a low box, so only floor actually seen is free here). Cells out of view
  (the 3.7 m under and before the camera, everything beside and behind) keep what they
  were: a box seen 4 m ahead is remembered as the robot passes it. Cells never seen free
  are unknown (``CostGrid.seen``): a planner leaves its straight line only onto floor seen.
- **Seen gone**: each mark keeps the height of the highest point that made it. A
  frame whose rays pass through a cell's column, nearer than the first thing they hit,
  from the cell's floor up to where its lowest ray crosses it, shows that nothing as high
  as that ray stands there: a mark that reached higher (a person who walked on) is
  cleared; a low one below the view (a box passed up close) is kept. Nav2's voxel layer
  clears in 3-D for the same reason.
- **Decay**: a mark not seen again for ``DECAY_S`` is forgotten (someone who walked
  off where the camera no longer looks).
- **Other sources**: ``mark(points)``: odometry points of a bumper or IR hit (of no
  known height: kept until they decay).
- **Inflation**: ``snapshot()`` gives each cell's distance to the nearest occupied cell
  (a Euclidean distance transform), from which a planner reads lethal cells (closer than
  the body's radius and ``LETHAL_PAD_M``) and a cost falling off to ``INFLATION_M`` beyond
  the body.

Unknown cells count as free (Nav2's local costmap with ``track_unknown_space: false``).
The map is thread-safe: the worker marks it from a frame while the tick reads the last
snapshot (an immutable ``CostGrid``, swapped in whole).
"""

from __future__ import annotations

import math
import threading
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import distance_transform_edt

from pmnav_bt.seams import CREATE3_RADIUS_M, Observation

# The window: 5 m round the robot. The camera (1.6 m up, 47 deg vertical field) sees the
# floor only from 3.7 m ahead, so what it clears lies 3.7-5 m off: a smaller window would
# keep too little of it.
SIZE_M = 10.0
RESOLUTION_M = 0.05  # Nav2's local costmap default
FLOOR_BAND_M = 0.08  # a point this far above the floor is on something (depth noise, sills)
ROBOT_HEIGHT_M = 1.7  # the body with its camera mast: anything higher is passed under
MARK_RANGE_M = 4.5  # depth beyond this marks nothing (too coarse to steer by)
CLEAR_RANGE_M = 5.0  # floor seen farther than this clears nothing (the window's edge)
DECAY_S = 30.0  # a mark unseen this long is forgotten (a person who walked on)
LETHAL_PAD_M = 0.05  # lethal: within the body's radius and this (a cell's diagonal and more)
INFLATION_M = 0.25  # cost falls off over this much beyond the lethal distance
PIXEL_STRIDE = 2  # every second row and column of the depth image (4x fewer points)
# A mark is seen gone where the frame's lowest ray through its cell passes this much
# below the mark's top (depth noise, and a cell 5 cm across seen slantwise).
SEEN_GONE_MARGIN_M = 0.1


@dataclass(frozen=True)
class CostGrid:
    """A snapshot of the costmap: ``dist[i, j]`` metres from the centre of cell (row i,
    column j) to the nearest occupied cell (inf: none in the window); ``seen``: cells whose
    floor the camera has shown free (the rest are occupied or unknown); cell (0, 0)'s
    corner at odometry ``origin``; rows along +y, columns along +x."""

    origin: tuple[float, float]
    resolution: float
    dist: np.ndarray
    seen: np.ndarray
    lethal_m: float
    inflation_m: float

    def cells(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Row, column and inside-the-window mask of odometry points."""
        j = np.floor((np.asarray(x) - self.origin[0]) / self.resolution).astype(int)
        i = np.floor((np.asarray(y) - self.origin[1]) / self.resolution).astype(int)
        n = self.dist.shape[0]
        inside = (i >= 0) & (i < n) & (j >= 0) & (j < n)
        return np.clip(i, 0, n - 1), np.clip(j, 0, n - 1), inside

    def clearance(self, x, y) -> np.ndarray:
        """Metres from odometry points to the nearest occupied cell (inf outside the window)."""
        i, j, inside = self.cells(x, y)
        return np.where(inside, self.dist[i, j], math.inf)

    def cost(self, clearance: np.ndarray) -> np.ndarray:
        """0 (far from everything) .. 1 (at the lethal distance) for clearances."""
        over = np.maximum(np.asarray(clearance) - self.lethal_m, 0.0)
        return np.where(over < self.inflation_m, np.exp(-3.0 * over / self.inflation_m), 0.0)


class LocalCostmap:
    """The rolling window (see the module's docstring). ``radius``: the body's (m)."""

    def __init__(
        self,
        size: float = SIZE_M,
        resolution: float = RESOLUTION_M,
        radius: float = CREATE3_RADIUS_M,
        decay_s: float = DECAY_S,
    ) -> None:
        if size <= 0.0 or resolution <= 0.0 or size / resolution > 2000:
            raise ValueError(f"a costmap of {size} m in {resolution} m cells is not sensible")
        self.n = int(round(size / resolution))
        self.resolution = resolution
        self.lethal_m = radius + LETHAL_PAD_M
        self.decay_s = decay_s
        self._origin = (-size / 2.0, -size / 2.0)
        self._marked = np.full((self.n, self.n), -math.inf)  # time last marked; -inf: free
        self._seen = np.zeros((self.n, self.n), bool)  # floor seen free (else unknown)
        self._top = np.zeros((self.n, self.n))  # how high the points that marked a cell stood
        self._lock = threading.Lock()
        self._grid = self._inflate()

    # -- reading ---------------------------------------------------------------------------

    def snapshot(self) -> CostGrid:
        """The latest inflated grid (cheap: made when the map last changed)."""
        return self._grid

    def occupied(self) -> np.ndarray:
        """Boolean (row, column) grid of occupied cells (tests, pictures)."""
        with self._lock:
            return np.isfinite(self._marked)

    @property
    def origin(self) -> tuple[float, float]:
        return self._origin

    # -- writing ---------------------------------------------------------------------------

    def add_depth(self, obs: Observation, now: float) -> None:
        """Clear the floor ``obs`` shows and mark what stands on it (the frame's body pose,
        its odometry pose, is where the camera stood), then forget stale marks."""
        if obs.depth is None:
            return
        pose = obs.pose
        scan = _depth_scan(obs)
        with self._lock:
            self._recentre(pose.x, pose.y)
            self._clear_seen_floor(pose, obs, scan)
            self._mark_xy(scan.obstacles(pose), now, scan.heights)
            self._marked[self._marked < now - self.decay_s] = -math.inf
            self._grid = self._inflate()

    def mark(self, points, now: float) -> None:
        """Mark odometry points (N x 2) occupied: a bumper or IR hit, any other source."""
        pts = np.asarray(points, float).reshape(-1, 2)
        with self._lock:
            self._mark_xy(pts, now)
            self._grid = self._inflate()

    def recentre(self, x: float, y: float) -> None:
        """Move the window to centre on odometry (x, y) (what leaves it is forgotten)."""
        with self._lock:
            self._recentre(x, y)
            self._grid = self._inflate()

    # -- inside ----------------------------------------------------------------------------

    def _recentre(self, x: float, y: float) -> None:
        r, half = self.resolution, self.n * self.resolution / 2.0
        ox, oy = math.floor((x - half) / r) * r, math.floor((y - half) / r) * r
        dj = int(round((ox - self._origin[0]) / r))
        di = int(round((oy - self._origin[1]) / r))
        if di == 0 and dj == 0:
            return
        moved = np.full_like(self._marked, -math.inf)
        top = np.zeros_like(self._top)
        n = self.n
        src_i, dst_i = slice(max(di, 0), n + min(di, 0)), slice(max(-di, 0), n + min(-di, 0))
        src_j, dst_j = slice(max(dj, 0), n + min(dj, 0)), slice(max(-dj, 0), n + min(-dj, 0))
        seen = np.zeros_like(self._seen)
        if abs(di) < n and abs(dj) < n:
            moved[dst_i, dst_j] = self._marked[src_i, src_j]
            seen[dst_i, dst_j] = self._seen[src_i, src_j]
            top[dst_i, dst_j] = self._top[src_i, src_j]
        self._marked, self._seen, self._top = moved, seen, top
        self._origin = (ox, oy)

    def _mark_xy(self, pts: np.ndarray, now: float, heights: np.ndarray | None = None) -> None:
        """Mark odometry points; ``heights``: how high each stood (None: unknown, kept
        until it decays)."""
        if len(pts) == 0:
            return
        j = np.floor((pts[:, 0] - self._origin[0]) / self.resolution).astype(int)
        i = np.floor((pts[:, 1] - self._origin[1]) / self.resolution).astype(int)
        keep = (i >= 0) & (i < self.n) & (j >= 0) & (j < self.n)
        i, j = i[keep], j[keep]
        fresh = ~np.isfinite(self._marked[i, j])
        self._top[i[fresh], j[fresh]] = 0.0
        h = np.zeros(len(i)) if heights is None else np.asarray(heights)[keep]
        np.maximum.at(self._top, (i, j), h)
        self._marked[i, j] = now
        self._seen[i, j] = False

    def _clear_seen_floor(self, pose, obs: Observation, scan: _Scan) -> None:
        """Free every cell whose floor the frame shows (``_Scan``: per image column, the
        floor's near and far edge and the first obstacle)."""
        r = self.resolution
        centres = self._origin[0] + (np.arange(self.n) + 0.5) * r
        rows = self._origin[1] + (np.arange(self.n) + 0.5) * r
        dx = centres[None, :] - pose.x
        dy = rows[:, None] - pose.y
        rng = np.hypot(dx, dy)
        bearing = np.arctan2(dy, dx) - pose.yaw
        bearing = (bearing + math.pi) % (2.0 * math.pi) - math.pi
        k = obs.intrinsics
        in_view = np.abs(bearing) < k.hfov / 2.0
        u = np.clip(np.round(k.cx - k.fx * np.tan(np.where(in_view, bearing, 0.0))), 0, k.width - 1)
        col = (u // PIXEL_STRIDE).astype(int).clip(0, len(scan.near) - 1)
        far = np.minimum(scan.far[col], scan.first_obstacle[col] - r)
        seen = in_view & (rng >= scan.near[col]) & (rng <= np.minimum(far, CLEAR_RANGE_M))
        self._marked[seen] = -math.inf
        self._seen |= seen
        # Marks that stood higher than the lowest ray through their column, with nothing
        # hit before them along it: seen gone.
        lowest = obs.camera_height - rng * (k.height - 1 - k.cy) / k.fy
        through = in_view & (rng < scan.first_obstacle[col] - r) & (rng <= CLEAR_RANGE_M)
        gone = through & (self._top > np.maximum(lowest, 0.0) + SEEN_GONE_MARGIN_M)
        self._marked[gone & np.isfinite(self._marked)] = -math.inf

    def _inflate(self) -> CostGrid:
        occ = np.isfinite(self._marked)
        if occ.any():
            dist = distance_transform_edt(~occ) * self.resolution
        else:
            dist = np.full(occ.shape, math.inf)
        return CostGrid(
            self._origin, self.resolution, dist, self._seen.copy(), self.lethal_m, INFLATION_M
        )


@dataclass(frozen=True)
class _Scan:
    """One depth frame reduced per image column (every ``PIXEL_STRIDE``-th): the floor seen
    nearest and farthest (horizontal range, m; +inf and -inf where none) and the first obstacle
    (inf: none); and the obstacle points in the body frame (forward, left)."""

    near: np.ndarray
    far: np.ndarray
    first_obstacle: np.ndarray
    points: np.ndarray
    heights: np.ndarray  # how high above the floor each obstacle point stands

    def obstacles(self, pose) -> np.ndarray:
        """The obstacle points in the odometry frame."""
        c, s = math.cos(pose.yaw), math.sin(pose.yaw)
        f, left = self.points[:, 0], self.points[:, 1]
        return np.column_stack((pose.x + c * f - s * left, pose.y + s * f + c * left))


def _depth_scan(obs: Observation) -> _Scan:
    k, h = obs.intrinsics, obs.camera_height
    depth = obs.depth[::PIXEL_STRIDE, ::PIXEL_STRIDE].astype(float)
    v = np.arange(0, k.height, PIXEL_STRIDE)[:, None]
    u = np.arange(0, k.width, PIXEL_STRIDE)[None, :]
    left = (k.cx - u) * depth / k.fx
    height = h - (v - k.cy) * depth / k.fy
    rng = np.hypot(depth, left)  # horizontal range
    valid = np.isfinite(depth) & (depth > 0.0)
    floor = valid & (np.abs(height) <= FLOOR_BAND_M)
    standing = valid & (height > FLOOR_BAND_M) & (height < ROBOT_HEIGHT_M)
    near = np.where(floor, rng, math.inf).min(axis=0)
    far = np.where(floor, rng, -math.inf).max(axis=0)
    first = np.where(standing, rng, math.inf).min(axis=0)
    marks = standing & (rng <= MARK_RANGE_M)
    points = np.column_stack((depth[marks], left[marks]))
    return _Scan(near, far, first, points, height[marks])
