"""Shortest drivable distance to a goal region, as habitat measures it for SPL.

The drivable space is the building's free space (corridors, less any solid obstacles)
eroded by the robot's radius, rasterised on a grid; the distance to the goal region
(the success disc around the goal door, within the drivable space) is the fast-marching
solution of the eikonal equation on that grid (scikit-fmm, second order), so paths cut
corners the way a driven robot does instead of following corridor centre lines.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import numpy as np
import shapely
import skfmm
from shapely.geometry import MultiPolygon, Polygon

from pmnav_bt.errors import PmNavError
from pmnav_bt.seams import CREATE3_RADIUS_M

GRID_M = 0.05  # cell size of the distance field


class GeodesicError(PmNavError):
    """The goal region cannot be reached in the drivable space."""


class GeodesicField:
    """Geodesic distance (m) from any drivable point to the disc ``radius`` around ``goal``."""

    def __init__(
        self,
        free_space: Polygon | MultiPolygon,
        goal: Sequence[float],
        radius: float,
        *,
        robot_radius: float = CREATE3_RADIUS_M,
        obstacles: Iterable[Polygon] = (),
        resolution: float = GRID_M,
    ):
        obstacles = list(obstacles)
        space = free_space.difference(shapely.union_all(obstacles)) if obstacles else free_space
        drivable = space.buffer(-robot_radius)  # round: the body is a disc
        # Only the parts that reach the goal: the rest (outside the building) is no way.
        disc = shapely.Point(goal[0], goal[1]).buffer(radius)
        near = [g for g in getattr(drivable, "geoms", [drivable]) if g.intersects(disc)]
        self.drivable = shapely.union_all(near) if near else drivable
        self.resolution = res = float(resolution)
        x0, y0, x1, y1 = free_space.bounds
        self.origin = (x0 - 2 * res, y0 - 2 * res)
        nx_ = int(math.ceil((x1 - x0) / res)) + 4
        ny_ = int(math.ceil((y1 - y0) / res)) + 4
        xs = self.origin[0] + (np.arange(nx_) + 0.5) * res
        ys = self.origin[1] + (np.arange(ny_) + 0.5) * res
        gx, gy = np.meshgrid(xs, ys)  # rows: y, columns: x
        self.free = shapely.contains_xy(self.drivable, gx, gy)
        phi = np.hypot(gx - goal[0], gy - goal[1]) - radius
        if not (self.free & (phi <= 0)).any():
            raise GeodesicError(
                f"no drivable point within {radius:g} m of the goal {tuple(goal)} "
                f"(robot radius {robot_radius:g} m)"
            )
        d = skfmm.distance(np.ma.MaskedArray(phi, ~self.free), dx=res)
        field = np.where(np.ma.getmaskarray(d), np.inf, np.ma.getdata(d))
        self.field = np.maximum(field, 0.0)

    def distance(self, xy: Sequence[float]) -> float:
        """Geodesic distance from ``xy`` to the goal region; inf where it cannot be reached.

        Bilinear between the four surrounding cells when all are drivable; otherwise the
        nearest drivable cell within half a metre plus the straight line to it.
        """
        res = self.resolution
        u = (float(xy[0]) - self.origin[0]) / res - 0.5
        v = (float(xy[1]) - self.origin[1]) / res - 0.5
        i0, j0 = int(math.floor(v)), int(math.floor(u))
        h, w = self.field.shape
        if 0 <= i0 < h - 1 and 0 <= j0 < w - 1:
            cell = self.field[i0 : i0 + 2, j0 : j0 + 2]
            if np.isfinite(cell).all():
                fv, fu = v - i0, u - j0
                top = cell[0, 0] * (1 - fu) + cell[0, 1] * fu
                bottom = cell[1, 0] * (1 - fu) + cell[1, 1] * fu
                return float(top * (1 - fv) + bottom * fv)
        k = int(math.ceil(0.5 / res))
        ia, ib = max(0, i0 - k), min(h, i0 + k + 2)
        ja, jb = max(0, j0 - k), min(w, j0 + k + 2)
        win = self.field[ia:ib, ja:jb]
        if not np.isfinite(win).any():
            return math.inf
        ii, jj = np.mgrid[ia:ib, ja:jb]
        off = np.hypot(ii - v, jj - u) * res
        return float(np.min(np.where(np.isfinite(win), win + off, np.inf)))

    def drivable_at(self, xy: Sequence[float]) -> bool:
        """Whether the grid cell holding ``xy`` is drivable."""
        i = int(math.floor((float(xy[1]) - self.origin[1]) / self.resolution))
        j = int(math.floor((float(xy[0]) - self.origin[0]) / self.resolution))
        h, w = self.free.shape
        return 0 <= i < h and 0 <= j < w and bool(self.free[i, j])

    def path(self, start: Sequence[float]) -> list[tuple[float, float]]:
        """A shortest path from ``start`` into the goal region, as a polyline (map metres).

        Steepest descent over the drivable neighbours of each cell of the distance field
        (it decreases to the region), then pulled taut: each vertex is joined to the
        farthest later one in straight view inside the drivable space. Its length is
        within about 1 % of :meth:`distance`.
        """
        res = self.resolution
        h, w = self.field.shape
        i = int(math.floor((float(start[1]) - self.origin[1]) / res))
        j = int(math.floor((float(start[0]) - self.origin[0]) / res))
        if not (0 <= i < h and 0 <= j < w and math.isfinite(self.field[i, j])):
            raise GeodesicError(f"{tuple(start)} is not in the drivable space")
        cells = [(i, j)]
        while self.field[i, j] > 0.0:
            best = None
            for di in (-1, 0, 1):
                for dj in (-1, 0, 1):
                    a, b = i + di, j + dj
                    if (di or dj) and 0 <= a < h and 0 <= b < w:
                        # the steepest slope, not the lowest value: no drift to diagonals
                        drop = (self.field[i, j] - self.field[a, b]) / math.hypot(di, dj)
                        if drop > 0 and (best is None or drop > best[0]):
                            best = (drop, a, b)
            if best is None:  # pragma: no cover - the field decreases to the region
                break
            i, j = best[1], best[2]
            cells.append((i, j))
        pts = [(float(start[0]), float(start[1]))]
        pts += [
            (self.origin[0] + (b + 0.5) * res, self.origin[1] + (a + 0.5) * res)
            for a, b in cells[1:]
        ]
        return self._taut(pts)

    def _taut(self, pts: list[tuple[float, float]]) -> list[tuple[float, float]]:
        """Shortcut the polyline: join each vertex to the farthest later one in straight
        view inside the drivable space (less half a cell of slack for the grid)."""
        from shapely.geometry import LineString
        from shapely.prepared import prep

        room = prep(self.drivable.buffer(self.resolution / 2))
        out = [pts[0]]
        k = 0
        while k < len(pts) - 1:
            nxt = next(
                (
                    j
                    for j in range(len(pts) - 1, k + 1, -1)
                    if room.contains(LineString([pts[k], pts[j]]))
                ),
                k + 1,
            )
            out.append(pts[nxt])
            k = nxt
        return out
