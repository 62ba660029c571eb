"""The building's occupancy grid as a likelihood field: the ``grid`` wall model.

AMCL's likelihood field model (Thrun, Burgard and Fox, *Probabilistic Robotics*, 6.4)
weighs a range return by how far its end lies from the nearest occupied cell of the
map: a Gaussian on that distance, plus a constant for returns no wall explains (a
person, a cart, an open door the map shows shut). The distances come from one distance
transform of the grid, so a return costs one lookup, and the field is smooth where ray
casting is not: a hypothesis half a metre off still explains most returns a little, and
the weights lead towards the true place.

Here the returns are the free floor seen in depth along each bearing of a view
(``Glimpse.free``: how far the floor runs before something stands on it). Two things
are read from each under a hypothesis:

- the return (``free`` short of ``MAX_RAY_M``): its end should be on a wall
  (``FIELD_SIGMA_M`` Gaussian on the distance to the nearest wall surface, a floor of
  ``P_UNEXPLAINED`` for what no wall explains);
- the floor before it: depth saw floor where the map puts a wall across the way, more
  than ``RAY_SLACK_M`` beyond that wall (measured across the wall, so that a ray
  grazing a side wall a little off is no contradiction): as the corridor model's
  ``free_floor`` (``P_DEPTH`` at a look round, ``P_DRIVE_RAY`` while driving). The
  likelihood field alone cannot tell this: a real grid's walls are a few cells thick
  with rooms behind them, so a return seen through a wall can end near another one.

The grid's free space is the one the simulator builds its grid walls around
(``map.wall_surface.grid_free_space``): map_server's free cells, the largest part,
specks smoothed away. The robot inside a wall (``stand``), a drive blocked where the
floor runs on (``blocked_log``), a door's line of sight (``clear``) and the floor round a
place (``reach``, for ``pose.telling``) are read from the same grid.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from scipy.ndimage import distance_transform_edt

from pmnav_bt.map.floorplan import FloorPlanImage
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.pose.evidence.floor import (
    BLOCK_PROBE_M,
    MAX_RAY_M,
    OFF_CORRIDOR_M,
    P_DEPTH,
    P_DRIVE_RAY,
    P_THROUGH_WALL,
    RAY_SLACK_M,
)
from pmnav_bt.pose.evidence.signs import DRIFT_PER_M
from pmnav_bt.pose.visibility import Visibility
from pmnav_bt.seams import Pose2D

# The spread (m) of a depth return about the nearest wall under the true hypothesis, at
# the reference: hypotheses stand every 0.5 m along the centre lines (a quarter-metre
# off, at most), the centre line is found in depth to a decimetre or two, depth is good
# to a few centimetres. It grows with the odometry's drift (``signs.DRIFT_PER_M``).
FIELD_SIGMA_M = 0.3
# A return no wall explains: clutter, people, a door the grid shows shut. At a look
# round, 72 returns (six views, twelve bearings) that see the same walls in neighbouring
# bearings: each may cost at most this much ...
P_UNEXPLAINED = 0.3
# ... and one view ahead every metre of a drive sees the same walls again and again.
P_DRIVE_UNEXPLAINED = 0.6
STEP_M = 0.1  # rays are marched in steps this long over the walls grown by one cell


@dataclass(frozen=True, eq=False)
class LikelihoodField:
    """The grid's distances, built once per building (``of``): ``signed`` (m, per cell:
    distance to the nearest wall surface, positive on the floor, negative inside a
    wall), its unit gradient (``nx``, ``ny``: the way out of the nearest wall, map
    frame) and ``block`` (the walls grown by a cell, so that a ray marched in ``STEP_M``
    steps never passes between two cells of a thin wall). Each array has a one-cell
    border of wall round the grid: what lies outside it is wall."""

    plan: FloorPlanImage
    signed: np.ndarray
    nx: np.ndarray
    ny: np.ndarray
    block: np.ndarray

    @classmethod
    def of(cls, plan: FloorPlanImage) -> LikelihoodField:
        from pmnav_bt.map.wall_surface import grid_free_space

        free = np.pad(grid_free_space(plan), 1, constant_values=False)
        res = plan.resolution
        to_wall = distance_transform_edt(free) * res  # free cells: to the nearest wall cell
        to_free = distance_transform_edt(~free) * res  # wall cells: to the nearest free one
        # Cell centres are half a cell from the surface between them.
        signed = np.where(free, to_wall - res / 2.0, res / 2.0 - to_free).astype(np.float32)
        gy, gx = np.gradient(signed)  # rows run down the image: the grid's y is -row
        norm = np.hypot(gx, gy)
        norm[norm == 0.0] = 1.0
        c, s = math.cos(plan.origin[2]), math.sin(plan.origin[2])  # the grid's axes in the map
        ux, uy = gx / norm, -gy / norm
        block = cv2.dilate((~free).astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
        nx, ny = (c * ux - s * uy).astype(np.float32), (s * ux + c * uy).astype(np.float32)
        return cls(plan, signed, nx, ny, block)

    def cells(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(rows, cols) of the padded arrays holding map points ``xy`` (..., 2); points
        off the grid land on its border of wall."""
        p = self.plan
        ox, oy, yaw = p.origin
        c, s = math.cos(yaw), math.sin(yaw)
        dx, dy = xy[..., 0] - ox, xy[..., 1] - oy
        col = np.floor((c * dx + s * dy) / p.resolution).astype(np.int64) + 1
        row = p.height - np.floor((-s * dx + c * dy) / p.resolution).astype(np.int64)
        h, w = self.signed.shape
        return np.clip(row, 0, h - 1), np.clip(col, 0, w - 1)

    def surface(self, xy: np.ndarray) -> np.ndarray:
        """Signed distance (m) of map points ``xy`` (..., 2) to the nearest wall surface."""
        return self.signed[self.cells(xy)]

    def march(
        self, start: np.ndarray, way: np.ndarray, length
    ) -> tuple[np.ndarray, np.ndarray]:
        """Along each ray from ``start`` (K, 2) in the unit direction ``way`` (K, 2), up
        to ``length`` (m; a number or (K,)): how far (m) the floor runs before a wall
        (inf: none within ``length``), and |cos| of the angle between the ray and that
        wall's normal (1: straight at it; 0 where there is none)."""
        length = np.broadcast_to(np.asarray(length, float), (len(start),))
        most = float(length.max(initial=0.0))
        if most <= 0.0 or not len(start):
            return np.full(len(start), np.inf), np.zeros(len(start))
        s = STEP_M * np.arange(1, int(math.ceil(most / STEP_M)) + 1)
        pts = start[:, None, :] + s[None, :, None] * way[:, None, :]
        rows, cols = self.cells(pts)
        hit = self.block[rows, cols] & (s[None, :] <= length[:, None])
        first = np.argmax(hit, axis=1)
        any_hit = hit[np.arange(len(start)), first]
        k = np.arange(len(start))
        r, c = rows[k, first], cols[k, first]
        facing = np.abs(way[:, 0] * self.nx[r, c] + way[:, 1] * self.ny[r, c])
        # The wall's surface lies up to a step before the first sample in it.
        dist = np.where(any_hit, s[first] - STEP_M / 2.0, np.inf)
        return dist, np.where(any_hit, facing, 0.0)


def grid_floor(_pm: PrioriMap, _vis: Visibility, field: LikelihoodField) -> GridFloor:
    """The ``grid`` wall model's factory (``floor_model``; the field is the building's)."""
    return GridFloor(field)


@dataclass(frozen=True)
class GridFloor:
    """The ``grid`` wall model (a ``floor_model.FloorModel``): depth against the
    building's occupancy grid, through its ``LikelihoodField``."""

    field: LikelihoodField

    def stand(self, logw: np.ndarray, here: np.ndarray) -> None:
        """The robot more than ``OFF_CORRIDOR_M`` inside a wall: ``P_THROUGH_WALL``."""
        inside = self.field.surface(here) < -OFF_CORRIDOR_M
        logw += np.where(inside, math.log(P_THROUGH_WALL), 0.0)

    def blocked_log(self, tfs: np.ndarray, xy, blocked: float) -> np.ndarray:
        """A drive blocked: under a hypothesis where the floor runs ``BLOCK_PROBE_M`` on
        ahead without a wall, ``P_THROUGH_WALL``."""
        from pmnav_bt.pose.hypotheses import apply_many

        here = apply_many(tfs, xy)
        a = blocked + tfs[:, 2]
        dist, _ = self.field.march(here, np.stack([np.cos(a), np.sin(a)], 1), BLOCK_PROBE_M)
        return np.where(np.isinf(dist), math.log(P_THROUGH_WALL), 0.0)

    def depth_ray(
        self,
        logw: np.ndarray,
        tfs: np.ndarray,
        here: np.ndarray,
        odom: Pose2D,
        yaw: float,
        free: float,
        travelled: float,
        at_look: bool,
    ) -> None:
        """The floor seen along ``yaw`` through a wall, and the return's distance to the
        nearest wall (see the module)."""
        a = yaw + tfs[:, 2]
        way = np.stack([np.cos(a), np.sin(a)], 1)
        reach = min(free, MAX_RAY_M)
        dist, facing = self.field.march(here, way, reach)
        beyond = _beyond(reach, dist, facing)
        p_floor = P_DEPTH if at_look else P_DRIVE_RAY
        logw += np.where(beyond > RAY_SLACK_M, math.log(p_floor), 0.0)
        if free < MAX_RAY_M:
            d = self.field.surface(here + free * way)
            z = P_UNEXPLAINED if at_look else P_DRIVE_UNEXPLAINED
            sigma = math.hypot(FIELD_SIGMA_M, DRIFT_PER_M * travelled)
            logw += np.log((1.0 - z) * np.exp(-0.5 * (d / sigma) ** 2) + z)

    def clear(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Whether each line ``a``-``b`` reaches ``b`` with no wall across it (``b``
        no more than ``RAY_SLACK_M`` beyond one, measured across it)."""
        d = b - a
        length = np.hypot(d[:, 0], d[:, 1])
        way = d / np.maximum(length, 1e-9)[:, None]
        dist, facing = self.field.march(a, way, length)
        return _beyond(length, dist, facing) <= RAY_SLACK_M

    def reach(self, xy: np.ndarray, angles: np.ndarray, most: float) -> np.ndarray:
        """How far the floor runs from ``xy`` along each of ``angles``, to ``most``."""
        way = np.stack([np.cos(angles), np.sin(angles)], 1)
        dist, _ = self.field.march(np.broadcast_to(xy, way.shape), way, most)
        return np.minimum(dist, most)


def _beyond(reach, dist: np.ndarray, facing: np.ndarray) -> np.ndarray:
    """How far (m) past the wall a ray met at ``dist`` its end at ``reach`` lies, measured
    across that wall (``facing``: |cos| of the ray against the wall's normal); 0 where the
    ray met none (``dist`` inf)."""
    met = np.isfinite(dist)
    return np.where(met, (reach - np.where(met, dist, reach)) * facing, 0.0)
