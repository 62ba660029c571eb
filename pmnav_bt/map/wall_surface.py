"""Where a building's real wall stands, seen from an annotated wall point.

A building file draws each corridor as a rectangle, and its doors, signs and landmarks
on the rectangle's sides (the annotated walls). A real occupancy grid (a ros_map) shows
where the walls really are, and the two can disagree by most of a metre (a corridor
annotated narrower than it is, a ragged SLAM wall, a recessed door). This module finds
the grid's wall surface behind (or in front of) an annotated wall point, so that the
simulator hangs the item on the real wall and ``pmnav validate`` can say how far apart
the two are.

The search: from sample points along the annotated wall around the item, look along
the wall's normal, up to ``SEARCH_M`` either way, for the place where the free space
ends (a free cell followed by a non-free one, walking away from the corridor). Of the
places found on one ray, the one nearest the annotation counts: the first wall behind
it, or the wall standing in front of it inside the corridor. A door is often a gap in
the grid (an open door the scan saw through) and a bench or a pillar can stand in front
of a wall, so one ray is not trusted: the depths of all rays are grouped, the largest
group nearest the annotation is the wall, and a straight line through it gives the
wall's depth at the item and, where it is well fitted, the wall's direction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from pmnav_bt.map.floorplan import FloorPlanImage
from pmnav_bt.map.grid import free_mask

SMOOTH_M = 0.15  # free-space specks and slivers thinner than this are dropped
BORDER_CELLS = 2  # nothing is known beyond the image: this many border cells are wall
SEARCH_M = 1.5  # look this far along the normal, either way (a corridor is 2-3 m wide)
SAMPLE_STEP_M = 0.1  # spacing of the rays along the annotated wall
SPAN_M = 1.0  # rays reach this far beyond each side of the item (the wall beside a door)
GROUP_M = 0.1  # depths this close to the wall's line are the same wall (two grid cells)
MIN_RAYS = 8  # a wall needs this many rays (0.7 m of it) agreeing
MAX_TILT_DEG = 25.0  # a fitted direction further off the annotation is not trusted
MIN_FIT_SPAN_M = 0.6  # ... nor one fitted over less wall than this
MAX_FIT_RMS_M = 0.05  # ... nor one the rays scatter about more than this
FACE_M = 0.1  # a wall face: free floor this far in front of its line, wall this far behind
EXTENT_M = 3.0  # how far a wall's run is followed from an item (a door and its plates)


def grid_free_space(plan: FloorPlanImage) -> np.ndarray:
    """The free space the simulator builds grid walls around (bool, rows as in the image).

    map_server's free cells, largest part, specks and slivers thinner than ``SMOOTH_M``
    smoothed away, the image border wall.
    """
    free = free_mask(plan, clean_m=SMOOTH_M, clutter_m=0.0)
    k = max(1, round(SMOOTH_M / plan.resolution))
    free = cv2.morphologyEx(free.astype(np.uint8), cv2.MORPH_OPEN, np.ones((k, k), np.uint8)) > 0
    b = BORDER_CELLS
    free[:b], free[-b:], free[:, :b], free[:, -b:] = False, False, False, False
    return free


@dataclass(frozen=True)
class WallMount:
    """The real wall at an annotated wall point.

    ``point``: the real wall surface at the item's place along the wall; ``normal``: unit,
    from that wall into the corridor; ``offset``: metres from the annotated point to the
    real wall along the annotated normal, positive when the real wall stands behind the
    annotation (the annotation floats in the corridor), negative when it stands in front.
    """

    point: tuple[float, float]
    normal: tuple[float, float]
    offset: float
    fitted: bool  # the normal is the real wall's fitted direction (else the annotated one)

    @property
    def distance(self) -> float:
        return abs(self.offset)


class RealWalls:
    """The grid's wall surfaces, found from annotated wall points (see the module)."""

    def __init__(self, plan: FloorPlanImage, free: np.ndarray | None = None) -> None:
        self.plan = plan
        self.free = grid_free_space(plan) if free is None else free

    def free_at(self, xy: np.ndarray) -> np.ndarray:
        """Free (bool) at map points ``xy`` (..., 2); outside the image is not free."""
        flat = xy.reshape(-1, 2)
        cell = self.plan.world_to_cell(flat)
        h, w = self.free.shape
        inside = (cell[:, 0] >= 0) & (cell[:, 1] >= 0) & (cell[:, 0] < w) & (cell[:, 1] < h)
        out = np.zeros(len(flat), bool)
        out[inside] = self.free[cell[inside, 1], cell[inside, 0]]
        return out.reshape(xy.shape[:-1])

    def depths(self, points, normal, search: float = SEARCH_M) -> np.ndarray:
        """Per point, the distance along ``-normal`` to the nearest wall surface (NaN: none).

        ``normal`` points from the annotated wall into the corridor; a positive depth is a
        wall behind the point, a negative one a wall in front of it, within ``search``.
        """
        pts = np.atleast_2d(np.asarray(points, float))
        n = np.asarray(normal, float)
        step = self.plan.resolution / 2.0
        t = np.arange(-search - step, search + step + 1e-9, step)
        free = self.free_at(pts[:, None, :] - t[None, :, None] * n)
        ends = free[:, :-1] & ~free[:, 1:]  # free, then not free: a surface (away from corridor)
        where = (t[:-1] + t[1:]) / 2.0
        # Nearest the annotation; a wall behind wins a tie with one in front.
        key = np.where(ends, np.abs(where) - 1e-6 * np.sign(where), np.inf)
        best = np.argmin(key, axis=1)
        d = where[best]
        d[~np.isfinite(key[np.arange(len(pts)), best])] = np.nan
        d[np.abs(d) > search] = np.nan
        return d

    def mount(
        self, point, normal, half_width: float, search: float = SEARCH_M
    ) -> WallMount | None:
        """The real wall for an item ``2 * half_width`` wide at annotated wall ``point``.

        None when no stretch of wall of ``MIN_RAYS`` rays is found within ``search``.
        """
        p0 = np.asarray(point, float)
        n = np.asarray(normal, float) / np.linalg.norm(normal)
        t = np.array([n[1], -n[0]])  # along the wall
        reach = half_width + SPAN_M
        u = np.arange(-reach, reach + 1e-9, SAMPLE_STEP_M)
        d = self.depths(p0 + u[:, None] * t, n, search)
        ok = np.isfinite(d)
        u, d = u[ok], d[ok]
        if len(d) < MIN_RAYS:
            return None
        # The largest group of alike depths; nearest the annotation among equals.
        count = (np.abs(d[:, None] - d[None, :]) <= GROUP_M).sum(axis=1)
        seed = int(np.lexsort((np.abs(d), -count))[0])
        inl = np.abs(d - d[seed]) <= GROUP_M
        a, b = float(np.median(d[inl])), 0.0
        for _ in range(2):  # a line through the group, then the rays near that line
            if inl.sum() < 2 or np.ptp(u[inl]) < MIN_FIT_SPAN_M:
                break
            b, a = (float(v) for v in np.polyfit(u[inl], d[inl], 1))
            inl = np.abs(d - (a + b * u)) <= GROUP_M
        rms = float(np.sqrt(np.mean((d[inl] - (a + b * u[inl])) ** 2))) if inl.any() else 0.0
        fitted = (
            b != 0.0
            and math.degrees(math.atan(abs(b))) <= MAX_TILT_DEG
            and np.ptp(u[inl]) >= MIN_FIT_SPAN_M
            and rms <= MAX_FIT_RMS_M
        )
        if not fitted:  # a wall parallel to the annotation, at the group's depth
            a, b = float(np.median(d[np.abs(d - d[seed]) <= GROUP_M])), 0.0
            inl = np.abs(d - a) <= GROUP_M
        if inl.sum() < MIN_RAYS:
            return None
        # The wall is p0 + u t - n (a + b u): its normal into the corridor is n + b t.
        nn = (n + b * t) / math.hypot(1.0, b)
        at = p0 - n * a
        return WallMount((float(at[0]), float(at[1])), (float(nn[0]), float(nn[1])), a, fitted)

    def extent(self, point, normal, most: float = EXTENT_M) -> tuple[float, float]:
        """How far the wall face at ``point`` (``normal`` into the free space) runs on
        straight each way, back (against the wall's direction, ``normal`` turned right)
        and forth, at most ``most`` metres: as long as the floor is free ``FACE_M`` in
        front of the line and the wall stands ``FACE_M`` behind it. A corner, a gap, the
        end of a wall or a slant away from the line ends it."""
        p0 = np.asarray(point, float)
        n = np.asarray(normal, float) / np.linalg.norm(normal)
        t = np.array([n[1], -n[0]])
        step = self.plan.resolution
        u = np.arange(step, most + 1e-9, step)
        out = []
        for sign in (-1.0, 1.0):
            line = p0 + sign * u[:, None] * t
            face = self.free_at(line + FACE_M * n) & ~self.free_at(line - FACE_M * n)
            run = int(np.argmin(face)) if not face.all() else len(u)  # samples on the face
            out.append(float(u[run - 1]) if run else 0.0)
        return out[0], out[1]

    def thickness(self, point, normal, most: float) -> float | None:
        """How far behind the wall surface at ``point`` map_server's free space begins again
        (a room, reached or not), looking at most ``most`` metres; None when it does not."""
        p0, n = np.asarray(point, float), np.asarray(normal, float)
        step = self.plan.resolution / 2.0
        t = np.arange(step, most + 1e-9, step)
        cell = self.plan.world_to_cell(p0[None, :] - t[:, None] * n)
        h, w = self.free.shape
        inside = (cell[:, 0] >= 0) & (cell[:, 1] >= 0) & (cell[:, 0] < w) & (cell[:, 1] < h)
        free = np.zeros(len(t), bool)
        free[inside] = self.plan.occupancy()[cell[inside, 1], cell[inside, 0]] == 0
        first = np.nonzero(free)[0]
        return float(t[first[0]]) if len(first) else None


def nearest_boundary_point(rings, pt) -> tuple[np.ndarray, np.ndarray]:
    """The point of the rings nearest ``pt`` and the unit normal there, pointing left of
    the ring's direction (into the free space of a counter-clockwise exterior)."""
    q = np.asarray(pt, float)
    best, best_d = (q, np.array([1.0, 0.0])), math.inf
    for ring in rings:
        r = np.asarray(ring, float)
        a, b = r, np.roll(r, -1, axis=0)
        d = b - a
        length2 = (d**2).sum(axis=1)
        keep = length2 > 1e-12
        a, d, length2 = a[keep], d[keep], length2[keep]
        s = np.clip(((q - a) * d).sum(axis=1) / length2, 0.0, 1.0)
        foot = a + s[:, None] * d
        dist = np.linalg.norm(foot - q, axis=1)
        i = int(np.argmin(dist))
        if dist[i] < best_d:
            tan = d[i] / math.sqrt(length2[i])
            best, best_d = (foot[i], np.array([-tan[1], tan[0]])), float(dist[i])
    return best
