"""The corridors' floor as evidence: where the robot can be and what depth sees from there.

The ``corridors`` wall model (``floor_model``): the map's corridors
(``Visibility.corridors``) say where there is floor. A hypothesis is less likely when,
under it,

- the robot stands inside a wall (``off_corridor``): beyond its corridor's half-width by
  more than ``OFF_CORRIDOR_M`` (the hypothesis is a lattice point on the centre line, the
  robot beside a wall maybe);
- a drive was blocked where the corridor goes on (``blocked_log``);
- a view saw a wall close ahead where the map has corridor (``wall_ahead``);
- the free floor a view saw in depth crosses a wall on the map (``free_floor``): at a look
  round each reading counts ``P_DEPTH``; along a drive (``P_DRIVE_RAY``) one reading is
  weak, since after a long drive the odometry's drift puts even the true hypothesis a
  metre off, and many agreeing readings tell.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import shapely

from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.pose.hypotheses import apply_many
from pmnav_bt.pose.visibility import Visibility
from pmnav_bt.seams import Pose2D

P_THROUGH_WALL = 0.02  # the robot is where the hypothesis puts it inside a wall
OFF_CORRIDOR_M = 1.0  # beyond a corridor's half-width by this much: inside a wall
BLOCK_PROBE_M = 1.5  # a blocked drive: the hypothesis's corridor must end within this
NEAR_WALL_M = 2.0  # depth: a wall closer than this ahead of a view ...
MAX_RAY_M = 8.0  # free floor seen in depth is checked along the view up to this far
RAY_SLACK_M = 0.4  # ... short of where it ends, this far outside the corridors (and a
# probe beyond a near wall must be this far inside one to count against a hypothesis)
P_DEPTH = 0.1  # a hypothesis that disagrees with one such depth reading
# ... one reading ahead while driving: weak alone (after a long drive the odometry's drift
# puts even the true hypothesis a metre off), telling when many agree
P_DRIVE_RAY = 0.5


def corridor_floor(pm: PrioriMap, vis: Visibility, _field=None) -> CorridorFloor:
    """The ``corridors`` wall model's factory (``floor_model``; it needs no grid)."""
    return CorridorFloor.of(pm, vis)


@dataclass(frozen=True)
class CorridorFloor:
    """The corridors as depth evidence sees them (a ``floor_model.FloorModel``): ``vis``
    (the lattice), ``area`` (the corridor floor with ``RAY_SLACK_M`` of tolerance) and
    ``half_width`` (per lattice point, its corridor's half-width)."""

    vis: Visibility
    area: shapely.Geometry
    half_width: np.ndarray

    @classmethod
    def of(cls, pm: PrioriMap, vis: Visibility) -> CorridorFloor:
        area = shapely.buffer(vis.corridors, RAY_SLACK_M)  # a little tolerance
        half_width = np.array(
            [pm.segments[p.segment - 1].width / 2.0 for p in vis.lattice_points]
        )
        shapely.prepare(area)
        return cls(vis, area, half_width)

    def stand(self, logw: np.ndarray, here: np.ndarray) -> None:
        """A hypothesis that puts the robot inside a wall (more than ``OFF_CORRIDOR_M``
        beyond its corridor's half-width from its nearest lattice point) is unlikely."""
        near, off = self.vis.nearest_many(here)
        half = self.half_width[near]
        logw += np.where(off > half + OFF_CORRIDOR_M, math.log(P_THROUGH_WALL), 0.0)

    def blocked_log(self, tfs: np.ndarray, xy, blocked: float) -> np.ndarray:
        """Log-weights for a drive blocked from ``xy`` heading ``blocked`` (straightened
        odometry): a hypothesis under which the corridor goes on ``BLOCK_PROBE_M`` ahead
        is unlikely."""
        d = BLOCK_PROBE_M
        probe = apply_many(tfs, (xy[0] + d * math.cos(blocked), xy[1] + d * math.sin(blocked)))
        pn, poff = self.vis.nearest_many(probe)
        return np.where(poff <= self.half_width[pn], math.log(P_THROUGH_WALL), 0.0)

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
        """At a look round, a wall close ahead (``wall_ahead``) and the free floor
        (``free_floor``, ``P_DEPTH``); while driving, the free floor only
        (``P_DRIVE_RAY``). ``travelled`` is not used: the corridors' slack is fixed."""
        if at_look:
            self.wall_ahead(logw, tfs, odom, yaw, free)
        self.free_floor(logw, tfs, here, odom, yaw, free, P_DEPTH if at_look else P_DRIVE_RAY)

    def clear(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Whether each line from ``a`` to ``b`` stays on the corridor floor (with slack)."""
        return shapely.covers(self.area, shapely.linestrings(np.stack([a, b], 1)))

    def reach(self, xy: np.ndarray, angles: np.ndarray, most: float) -> np.ndarray:
        """How far the corridor floor runs from ``xy`` along each of ``angles``, to
        ``most``: where each ray first meets the corridors' outline."""
        ends = np.asarray(xy) + most * np.stack([np.cos(angles), np.sin(angles)], 1)
        rays = shapely.linestrings(np.stack([np.broadcast_to(xy, ends.shape), ends], 1))
        hits = shapely.intersection(rays, self.vis.walls)
        d = shapely.distance(shapely.Point(xy), hits)
        return np.where(np.isnan(d), most, np.minimum(d, most))

    def wall_ahead(
        self, logw: np.ndarray, tfs: np.ndarray, odom: Pose2D, yaw: float, free: float
    ) -> None:
        """A wall seen closer than ``NEAR_WALL_M`` along ``yaw`` from ``odom`` must be a
        wall on the map: a probe just beyond it clearly inside a corridor (an oblique
        view puts it only a little beyond the wall, and the hypothesis is a lattice point
        on the centre line) costs ``P_DEPTH``."""
        if free < NEAR_WALL_M:
            d = free + 0.5
            probe = apply_many(tfs, (odom.x + d * math.cos(yaw), odom.y + d * math.sin(yaw)))
            pn, poff = self.vis.nearest_many(probe)
            inside = poff <= self.half_width[pn] - RAY_SLACK_M
            logw += np.where(inside, math.log(P_DEPTH), 0.0)

    def free_floor(
        self,
        logw: np.ndarray,
        tfs: np.ndarray,
        here: np.ndarray,
        odom: Pose2D,
        yaw: float,
        free: float,
        p: float,
    ) -> None:
        """The free floor seen along ``yaw`` from ``odom`` (``here`` under each hypothesis)
        must be floor on the map: a hypothesis with a wall within that reach (to
        ``MAX_RAY_M``, less ``RAY_SLACK_M``) gets ``p``."""
        reach = min(free, MAX_RAY_M) - RAY_SLACK_M
        if reach > 1.0:
            end = apply_many(tfs, (odom.x + reach * math.cos(yaw), odom.y + reach * math.sin(yaw)))
            floor = shapely.covers(self.area, shapely.linestrings(np.stack([here, end], 1)))
            logw += np.where(floor, 0.0, math.log(p))
