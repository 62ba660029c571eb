"""Doors seen along the walls as evidence (``perception.door_sightings``).

The door finder sees doors 95 % of the time 4-13 m off in the simulator's views, and
never where there is none (``benchmarks/bench_door_sightings.py``); which door it is, it
does not know, only that one is there. Under a hypothesis,

- a door seen where the map has no door (or landmark) within ``DOOR_MATCH_M`` is
  spurious: ``P_DOOR_SPURIOUS``;
- a map door on the robot's corridor, well inside a view that looked for doors, within
  ``DOOR_SEEN_M`` and in the line of sight, not seen is a miss: ``P_DOOR_MISS``.

While driving, one view ahead every metre sees the same door again and again, so each
reading counts less (``P_DRIVE_DOOR_MISS``, ``P_DRIVE_DOOR_SPURIOUS``).

The door finder was measured in the clean world's bare corridors. In a furnished one
(the realistic preset: benches, carts, plants and screens along the walls, a third of the
doors open, two-tone walls) it finds about half the doors in view and about one
door-like thing a view where the map has no door (``bench_door_sightings.py --world
realistic``: 60 in 120 views, recall 55 %). Such errors are not independent: the same
cart is seen in two overlapping views of a look, and again from the next look two metres
on. So a look's doors are weighed as one scene (``scene_capped``): its sightings follow
the map's doors, or the scene holds door-like things the map does not know, and then
they say little of where the robot is; a look's doors cost a hypothesis at most
``P_DOOR_SCENE`` against the one they fit best. And looks taken where they see the same
stretch of wall share their evidence (``scene_weights``): two looks two metres apart are
not two independent scenes. Without this, two looks with nothing read from a corridor
lined with clutter held 94 % on a corridor of the same shape whose doors happened to
stand where the clutter was (fig2_hospital easy, realistic), and a correct sign read
could not overturn it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmnav_bt.pose.evidence.floor_model import FloorModel
from pmnav_bt.pose.hypotheses import apply_many
from pmnav_bt.pose.visibility import Visibility
from pmnav_bt.seams import EntityKind

DOOR_SEEN_M = (2.0, 12.0)  # a map door this far off, on the robot's corridor (the robot
DOOR_WALL_NEAR_M = 2.5  # this near its wall line: not round a corner), is in view ...
DOOR_FOV_MARGIN = math.radians(4.0)  # ... well inside a view that looked for doors
HALF_FOV = math.radians(30.0)  # the camera's 60 deg (a wider one only sees more)
DOOR_MATCH_M = 1.0  # a door seen this close to a map door (or landmark) is that one
P_DOOR_MISS = 0.2  # a map door in view is not seen (a look round)
P_DOOR_SPURIOUS = 0.1  # a door is seen where the map has none
# ... while driving, one view ahead every metre: the same door again and again
P_DRIVE_DOOR_MISS, P_DRIVE_DOOR_SPURIOUS = 0.6, 0.4
# The most one look's doors can tell against a hypothesis: as much as two independent
# sightings (two doors seen where one corridor has them and another has none), however
# many door-like things the scene holds.
P_DOOR_SCENE = P_DOOR_SPURIOUS**2
# Looks this far apart (odometry) see no stretch of wall in common: doors are seen up
# to DOOR_SEEN_M[1] either way.
SCENE_SPAN_M = 2.0 * DOOR_SEEN_M[1]


def scene_capped(lw: np.ndarray) -> np.ndarray:
    """One look's door log-likelihoods (per hypothesis) as one scene's: none lower than
    ``P_DOOR_SCENE`` under the hypothesis they fit best."""
    if lw.size == 0:
        return lw
    return np.maximum(lw, lw.max() + math.log(P_DOOR_SCENE))


def scene_weights(xy: np.ndarray) -> np.ndarray:
    """How much each look's doors count, from where the looks were taken (``xy``: (K, 2),
    odometry): 1 over how many looks see its stretch of wall, each counted by the share
    it sees too (1 - distance / ``SCENE_SPAN_M``, at least 0). Looks far apart count
    fully; k looks from one spot count as one."""
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    d = np.linalg.norm(xy[:, None] - xy[None], axis=2)
    shared = np.clip(1.0 - d / SCENE_SPAN_M, 0.0, 1.0)
    return 1.0 / shared.sum(axis=1)


@dataclass(frozen=True)
class MapDoors:
    """The map's room doors as the door sightings see them: on the wall (``xy``), a point
    in front of each in the corridor (``front``, for the line of sight), the wall's
    direction (``along``), and every door and landmark a sighting may be (``any_xy``)."""

    xy: np.ndarray
    front: np.ndarray
    along: np.ndarray
    any_xy: np.ndarray

    @classmethod
    def of(cls, vis: Visibility) -> MapDoors:
        """From the map's signs (``Visibility``): the map places a room's at its door."""
        rooms = [i for i, e in enumerate(vis.entities) if e.kind is EntityKind.ROOM]
        xy, front, n = vis.sign_xy[rooms], vis.sign_front[rooms], vis.sign_normal[rooms]
        along = np.stack([-n[:, 1], n[:, 0]], 1).reshape(-1, 2)
        any_xy = vis.sign_xy
        return cls(xy, front, along, any_xy)

    def weigh(
        self,
        logw: np.ndarray,
        floor: FloorModel,
        doors: tuple[tuple[float, float], ...],
        door_views: tuple[float, ...],
        tfs: np.ndarray,
        here: np.ndarray,
        p_miss: float,
        p_spurious: float,
        sigma: float,
    ) -> None:
        """Add to ``logw`` the doors seen (``doors``, odometry) in the views that looked
        for them (``door_views``, odometry yaws) from ``here`` (where each hypothesis of
        ``tfs`` puts the robot); ``floor``: the wall model, for the line of sight;
        ``sigma``: how far (m) a door's seen place may be off (at least
        ``DOOR_MATCH_M`` / 1.5)."""
        if not door_views or self.xy.shape[0] == 0:
            return
        tol = max(DOOR_MATCH_M, 1.5 * sigma)
        seen = np.array(doors, dtype=float).reshape(-1, 2)
        seen_map = np.stack([apply_many(tfs, xy) for xy in seen], 1) if len(seen) else None
        if seen_map is not None:  # (N, K, 2): each door seen, where each hypothesis puts it
            to_any = np.linalg.norm(seen_map[:, :, None] - self.any_xy[None, None], axis=3)
            logw += (to_any.min(axis=2) > tol).sum(axis=1) * math.log(p_spurious)
        # Hypothesis-door pairs in range first (a few in a hundred): the rest on those only,
        # so that the view ahead, weighed in the tick every metre, stays cheap.
        v = self.xy[None] - here[:, None]  # (N, M, 2)
        d2 = np.einsum("nmk,nmk->nm", v, v)
        lo, hi_m = DOOR_SEEN_M
        hi, di = np.nonzero((d2 >= lo * lo) & (d2 <= hi_m * hi_m))
        v = v[hi, di]
        bearing = np.arctan2(v[:, 1], v[:, 0])
        half = HALF_FOV - DOOR_FOV_MARGIN
        in_view = np.zeros(len(hi), bool)
        for yaw in door_views:
            off = np.remainder(bearing - (yaw + tfs[hi, 2]) + math.pi, 2.0 * math.pi) - math.pi
            in_view |= np.abs(off) <= half
        # On the robot's corridor: the robot is within a corridor's width of its wall line
        # (a door round a corner, on a crossing corridor's wall, is seen edge-on or not).
        across = self.along[di, 0] * v[:, 1] - self.along[di, 1] * v[:, 0]
        in_view &= np.abs(across) <= DOOR_WALL_NEAR_M
        if seen_map is not None:
            to_seen = np.linalg.norm(self.xy[di][:, None] - seen_map[hi], axis=2)
            in_view &= to_seen.min(axis=1) > tol
        if not in_view.any():
            return
        hi, di = hi[in_view], di[in_view]
        clear = floor.clear(here[hi], self.front[di])
        np.add.at(logw, hi[clear], math.log(p_miss))
