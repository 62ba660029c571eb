"""Frontier exploration without a map (Yamauchi 1997), in the odometry frame.

:class:`ExplorationGrid` is the map-less baseline's own record of the building: an
occupancy grid (unknown / free / occupied) filled from depth scans
(:func:`pmnav_bt.perception.scan.depth_scan`), the cells the robot has driven through,
and the frontiers already driven to (or found blocked). A *frontier* is known free space
next to unknown space: the mouth of a corridor branch not yet looked down, the far end of a corridor
seen only part of the way. :meth:`ExplorationGrid.choose` picks the frontier with the
least cost (path length on the free cells, plus a turn and a visited-area penalty) and
the path there, so the robot prefers unexplored branches and comes back along
corridors it knows when the branch at hand is a dead end.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import ndimage
from skimage.graph import MCP_Geometric

from pmnav_bt.geometry import wrap_angle
from pmnav_bt.perception.scan import Scan

UNKNOWN, FREE, OCCUPIED = 0, 1, 2
CELL_M = 0.25  # grid resolution
HALF_EXTENT_M = 100.0  # the grid spans this far from the start in every direction
CLEARANCE_M = 0.25  # cells nearer an occupied cell than this are not driven through
REACH_M = 0.75  # a frontier cell this near a passable cell is reached from it
CENTRE_M = 1.0  # paths keep this far from walls where they can (a corridor's middle)
MIN_FRONTIER_CELLS = 3  # a frontier narrower than ~1 m is a gap between rays, not a branch
TURN_WEIGHT_M = 1.0  # cost (m) of a frontier behind the robot (pi rad) over one ahead
VISITED_WEIGHT_M = 6.0  # cost (m) of a frontier in an area already driven through
VISITED_RADIUS_M = 0.6  # the robot marks cells this close to its path as visited
SPENT_RADIUS_M = 1.5  # frontiers this close to one driven to are not chosen again
WAYPOINT_SPACING = 4  # cells between the waypoints of a path (1 m)
HIT, SCORE_MAX = 2, 6  # occupancy evidence of a ray's end (a pass through a cell: -1)


@dataclass(frozen=True)
class FrontierChoice:
    """Where to explore next: the frontier cell (odometry xy), the path there (odometry
    waypoints, the last the frontier itself), its cost, and the frontier's size (cells)."""

    target: tuple[float, float]
    path: list[tuple[float, float]]
    cost: float
    size: int


@dataclass(frozen=True)
class _Reach:
    """Path costs from the robot over the crop [r0:r1, c0:c1] of the grid."""

    r0: int
    c0: int
    r1: int
    c1: int
    mcp: MCP_Geometric
    dist: np.ndarray


@dataclass
class ExplorationGrid:
    """An occupancy grid in the odometry frame, centred on ``origin`` (see module doc)."""

    origin: tuple[float, float] = (0.0, 0.0)
    cell: float = CELL_M
    half_extent: float = HALF_EXTENT_M
    state: np.ndarray = field(init=False, repr=False)
    score: np.ndarray = field(init=False, repr=False)  # occupancy evidence (integrate)
    visited: np.ndarray = field(init=False, repr=False)
    spent: list[tuple[float, float]] = field(default_factory=list)
    blocked_in_a_row: int = 0  # frontier drives blocked since the last one that arrived
    fresh_starts: int = 0  # times what was seen was forgotten (``forget``)

    def __post_init__(self) -> None:
        n = int(round(2 * self.half_extent / self.cell))
        self.state = np.zeros((n, n), np.int8)
        self.score = np.zeros((n, n), np.int8)
        self.visited = np.zeros((n, n), bool)

    # -- frames ---------------------------------------------------------------------------

    def to_cell(self, x, y) -> tuple[np.ndarray, np.ndarray]:
        """Row (y) and column (x) indices of odometry points (may be out of the grid)."""
        c = np.floor((np.asarray(x) - self.origin[0] + self.half_extent) / self.cell)
        r = np.floor((np.asarray(y) - self.origin[1] + self.half_extent) / self.cell)
        return r.astype(int), c.astype(int)

    def to_xy(self, r, c) -> tuple[float, float]:
        """The odometry centre of cell (r, c)."""
        x = (c + 0.5) * self.cell - self.half_extent + self.origin[0]
        y = (r + 0.5) * self.cell - self.half_extent + self.origin[1]
        return float(x), float(y)

    def _inside(self, r: np.ndarray, c: np.ndarray) -> np.ndarray:
        n = self.state.shape[0]
        return (r >= 0) & (r < n) & (c >= 0) & (c < n)

    # -- recording ------------------------------------------------------------------------

    def integrate(self, scan: Scan) -> None:
        """Evidence from one scan: free along every ray up to its range, occupied where it
        ends. Each cell keeps a score (a hit +HIT, a pass -1, clamped to +-SCORE_MAX), so
        a wall drawn in the wrong place by odometry drift is cleared by later looks
        through it, and a real wall is not by one grazing ray."""
        x0, y0, yaw = scan.pose
        ang = yaw + scan.bearings
        reach = np.where(np.isfinite(scan.ranges), scan.ranges, scan.max_range)
        step = self.cell / 2.0
        ts = np.arange(0.0, scan.max_range, step)
        # free: every sample short of the ray's end (by one step, so walls stay walls)
        t = ts[None, :]
        ok = t < (reach[:, None] - step)
        fx = x0 + t * np.cos(ang)[:, None]
        fy = y0 + t * np.sin(ang)[:, None]
        free = self._cells(fx[ok], fy[ok])
        hit = np.isfinite(scan.ranges)
        hx = x0 + scan.ranges[hit] * np.cos(ang[hit])
        hy = y0 + scan.ranges[hit] * np.sin(ang[hit])
        hits = self._cells(hx, hy)
        free = np.setdiff1d(free, hits, assume_unique=True)
        score = self.score.reshape(-1)
        score[free] = np.maximum(score[free] - 1, -SCORE_MAX)
        score[hits] = np.minimum(score[hits] + HIT, SCORE_MAX)
        touched = np.concatenate([free, hits])
        self.state.reshape(-1)[touched] = np.where(score[touched] > 0, OCCUPIED, FREE)

    def _cells(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """The distinct flat indices of the grid cells holding odometry points (x, y)."""
        r, c = self.to_cell(x, y)
        inside = self._inside(r, c)
        return np.unique(r[inside] * self.state.shape[1] + c[inside])

    def mark_visited(self, x: float, y: float) -> None:
        """The robot is at (x, y): cells within VISITED_RADIUS_M are visited (and free)."""
        k = int(math.ceil(VISITED_RADIUS_M / self.cell))
        r0, c0 = self.to_cell(x, y)
        rr, cc = np.mgrid[r0 - k : r0 + k + 1, c0 - k : c0 + k + 1]
        near = np.hypot(rr - r0, cc - c0) * self.cell <= VISITED_RADIUS_M
        inside = self._inside(rr, cc) & near
        self.visited[rr[inside], cc[inside]] = True
        free = self.state[rr[inside], cc[inside]] == UNKNOWN
        self.state[rr[inside][free], cc[inside][free]] = FREE

    def mark_spent(self, xy: tuple[float, float]) -> None:
        """A frontier driven to (or found blocked): it and its neighbourhood are not chosen
        again (what was to be seen from there has been)."""
        self.spent.append((float(xy[0]), float(xy[1])))

    def forget(self) -> None:
        """Forget what was seen and the frontiers spent, keep where the robot has been: a
        fresh start when odometry drift has drawn walls across corridors and closed
        every frontier (the visited penalty still steers away from known ground)."""
        self.state[:] = UNKNOWN
        self.score[:] = 0
        self.spent.clear()
        self.blocked_in_a_row = 0
        self.fresh_starts += 1

    def known_fraction(self) -> float:
        return float((self.state != UNKNOWN).mean())

    # -- choosing -------------------------------------------------------------------------

    def frontier_mask(self) -> np.ndarray:
        """Free cells with an unknown 4-neighbour."""
        unknown = self.state == UNKNOWN
        near_unknown = ndimage.binary_dilation(
            unknown, structure=ndimage.generate_binary_structure(2, 1)
        )
        return (self.state == FREE) & near_unknown

    def _reach(self, pose: tuple[float, float, float]) -> _Reach | None:
        """Path costs from ``pose`` over the known part of the grid (None: nothing known,
        or the robot outside the grid)."""
        known = np.argwhere(self.state != UNKNOWN)
        if len(known) == 0:
            return None
        pad = 3
        r0, c0 = np.maximum(known.min(axis=0) - pad, 0)
        r1, c1 = np.minimum(known.max(axis=0) + pad + 1, self.state.shape[0])
        state = self.state[r0:r1, c0:c1]
        clearance = ndimage.distance_transform_edt(state != OCCUPIED) * self.cell
        passable = (state == FREE) & (clearance >= CLEARANCE_M)
        costs = np.where(passable, 1.0 + 2.0 * np.clip(CENTRE_M - clearance, 0.0, None), np.inf)
        sr, sc = self.to_cell(pose[0], pose[1])
        sr, sc = int(sr - r0), int(sc - c0)
        if not (0 <= sr < state.shape[0] and 0 <= sc < state.shape[1]):
            return None
        costs[sr, sc] = 1.0  # the robot's own cell, however near a wall it stands
        mcp = MCP_Geometric(costs)
        dist, _ = mcp.find_costs([(sr, sc)])
        return _Reach(int(r0), int(c0), int(r1), int(c1), mcp, dist)

    def _waypoints(self, reach: _Reach, r: int, c: int) -> list[tuple[float, float]]:
        """Waypoints (odometry) along the path to the passable cell nearest crop cell
        (r, c) within REACH_M, about 1 m apart, the last that cell."""
        k = int(math.ceil(REACH_M / self.cell))
        wr0, wc0 = max(r - k, 0), max(c - k, 0)
        window = reach.dist[wr0 : r + k + 1, wc0 : c + k + 1]
        er, ec = np.unravel_index(int(np.argmin(window)), window.shape)
        cells_path = reach.mcp.traceback((int(er + wr0), int(ec + wc0)))
        keep = cells_path[WAYPOINT_SPACING::WAYPOINT_SPACING]
        if not keep or keep[-1] != cells_path[-1]:
            keep.append(cells_path[-1])
        return [self.to_xy(pr + reach.r0, pc + reach.c0) for pr, pc in keep]

    def path_to(
        self, pose: tuple[float, float, float], goal: tuple[float, float]
    ) -> list[tuple[float, float]] | None:
        """Waypoints from ``pose`` to ``goal`` over known free cells, ending at ``goal``;
        None when the grid knows no way there."""
        reach = self._reach(pose)
        if reach is None:
            return None
        gr, gc = self.to_cell(goal[0], goal[1])
        gr, gc = int(gr - reach.r0), int(gc - reach.c0)
        k = int(math.ceil(REACH_M / self.cell))
        h, w = reach.dist.shape
        if not (-k <= gr < h + k and -k <= gc < w + k):
            return None
        gr, gc = min(max(gr, 0), h - 1), min(max(gc, 0), w - 1)
        window = reach.dist[max(gr - k, 0) : gr + k + 1, max(gc - k, 0) : gc + k + 1]
        if not np.isfinite(window).any():
            return None
        return self._waypoints(reach, gr, gc)[:-1] + [(float(goal[0]), float(goal[1]))]

    def choose(self, pose: tuple[float, float, float]) -> FrontierChoice | None:
        """The frontier to explore from ``pose`` (odometry x, y, yaw), with its path; None
        when no reachable frontier is left (everything reachable has been seen)."""
        got = self._reach(pose)
        if got is None:
            return None
        r0, c0, r1, c1, dist = got.r0, got.c0, got.r1, got.c1, got.dist
        visited = self.visited[r0:r1, c0:c1]
        # A frontier seen past a corner may lie nearer the wall than the robot may drive:
        # it is reached from the nearest passable cell within REACH_M.
        k = int(math.ceil(REACH_M / self.cell))
        reach = ndimage.minimum_filter(dist, size=2 * k + 1, mode="constant", cval=np.inf)
        frontier = self.frontier_mask()[r0:r1, c0:c1] & np.isfinite(reach)
        rows, cols = np.mgrid[r0:r1, c0:c1]
        for fx, fy in self.spent:  # what was to be seen from there has been
            fr, fc = self.to_cell(fx, fy)
            frontier &= np.hypot(rows - fr, cols - fc) * self.cell >= SPENT_RADIUS_M
        labels, n = ndimage.label(frontier, structure=np.ones((3, 3)))
        if n == 0:
            return None
        near_visited = ndimage.binary_dilation(
            visited, iterations=int(VISITED_RADIUS_M / self.cell) + 2
        )
        best: tuple[float, int, int, int] | None = None
        for i, cells in enumerate(ndimage.find_objects(labels), start=1):
            members = np.argwhere(labels[cells] == i) + (cells[0].start, cells[1].start)
            if len(members) < MIN_FRONTIER_CELLS:
                continue
            d = reach[members[:, 0], members[:, 1]]
            j = int(np.argmin(d))
            r, c = int(members[j, 0]), int(members[j, 1])
            xy = self.to_xy(r + r0, c + c0)
            turn = abs(wrap_angle(math.atan2(xy[1] - pose[1], xy[0] - pose[0]) - pose[2]))
            cost = float(d[j]) * self.cell + TURN_WEIGHT_M * turn / math.pi
            if near_visited[members[:, 0], members[:, 1]].mean() > 0.5:
                cost += VISITED_WEIGHT_M
            if best is None or cost < best[0]:
                best = (cost, r, c, len(members))
        if best is None:
            return None
        cost, r, c, size = best
        path = self._waypoints(got, r, c)
        return FrontierChoice(self.to_xy(r + r0, c + c0), path, cost, size)

    def wall_normal(
        self, xy: tuple[float, float], towards: tuple[float, float], radius: float = 1.2
    ) -> tuple[float, float]:
        """The unit normal of the wall at ``xy`` (a door in it), on the side of ``towards``:
        the principal direction of the occupied cells within ``radius`` is the wall's.
        Without enough of the wall seen, the direction from ``xy`` towards ``towards``."""
        fallback = np.subtract(towards, xy)
        n = float(np.hypot(*fallback))
        fallback = fallback / n if n > 1e-6 else np.array([1.0, 0.0])
        r0, c0 = self.to_cell(xy[0], xy[1])
        k = int(math.ceil(radius / self.cell))
        rr, cc = np.mgrid[r0 - k : r0 + k + 1, c0 - k : c0 + k + 1]
        inside = self._inside(rr, cc)
        rr, cc = rr[inside], cc[inside]
        occ = self.state[rr, cc] == OCCUPIED
        if occ.sum() < 5:
            return float(fallback[0]), float(fallback[1])
        pts = np.array([self.to_xy(r, c) for r, c in zip(rr[occ], cc[occ], strict=True)])
        pts -= pts.mean(axis=0)
        _, s, vt = np.linalg.svd(pts, full_matrices=False)
        if s[0] < 2.0 * s[1]:  # no line (a corner, clutter): no wall direction to trust
            return float(fallback[0]), float(fallback[1])
        normal = np.array([-vt[0][1], vt[0][0]])
        if normal @ fallback < 0:
            normal = -normal
        return float(normal[0]), float(normal[1])
