"""What the corridor belief weighs its hypotheses by, one kind of evidence a module.

Each kind says what it models and owns its probabilities; each adds log-likelihoods to
the belief's per-hypothesis log-weights (``logw``, in place, in the order the belief
calls them: the sums are kept bit for bit as they were).

- ``signs``: the signs read at a look round, where each was seen; signs the map says are
  readable but were not read (missed); signs read where the map says none can be
  (misread or spurious).
- ``floor``: where the walls are (a ``floor_model.FloorModel``, by name: the corridor
  rectangles, ``floor.py``, or the building's grid as a likelihood field,
  ``likelihood_field.py``): the robot inside a wall, a drive blocked where the floor goes
  on, and the free floor along each view in depth (at a look round and along a drive).
- ``doors``: doors seen along the walls, or map doors in view not seen; a look's doors
  are one scene's (``look_doors``: capped, and shared with the looks that see the same
  wall, ``doors.scene_weights``, which the belief applies over all its looks).
- ``prior``: an earlier estimate of the pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.pose.evidence.doors import (
    P_DOOR_MISS,
    P_DOOR_SPURIOUS,
    P_DRIVE_DOOR_MISS,
    P_DRIVE_DOOR_SPURIOUS,
    MapDoors,
    scene_capped,
)
from pmnav_bt.pose.evidence.floor_model import CORRIDORS, FloorModel, WallSource
from pmnav_bt.pose.evidence.signs import SIGHT_SIGMA_M, Recall, Signs, sight_sigma
from pmnav_bt.pose.glimpse import Glimpse
from pmnav_bt.pose.hypotheses import apply_many
from pmnav_bt.pose.visibility import Visibility
from pmnav_bt.seams import Pose2D


@dataclass(frozen=True)
class Evidence:
    """Every kind of evidence, built once per map: ``signs``, ``floor`` and ``doors``."""

    signs: Signs
    floor: FloorModel
    doors: MapDoors

    @classmethod
    def of(
        cls, pm: PrioriMap, vis: Visibility, recall: Recall | None, walls: WallSource = CORRIDORS
    ) -> Evidence:
        """``walls``: the wall model depth is weighed against (``floor_model``)."""
        return cls(Signs.of(pm, vis, recall), walls.floor(pm, vis), MapDoors.of(vis))

    def look(self, logw: np.ndarray, g: Glimpse, tfs: np.ndarray, ref: Pose2D) -> None:
        """Add a look round ``g`` (straightened odometry) to ``logw`` under each hypothesis
        of ``tfs``: where it was (inside a wall?), a blocked drive, depth along each view
        and the signs read (``ref``: the reference, from which the odometry's drift
        grows). Its doors are ``look_doors``: the belief weighs them over all its looks."""
        travelled = math.hypot(g.odom.x - ref.x, g.odom.y - ref.y)
        here = apply_many(tfs, (g.odom.x, g.odom.y))
        self.floor.stand(logw, here)
        if g.blocked is not None:  # the corridor must end (or turn) just ahead
            logw += self.floor.blocked_log(tfs, (g.odom.x, g.odom.y), g.blocked)
        for yaw, free in g.free:
            self.floor.depth_ray(logw, tfs, here, g.odom, yaw, free, travelled, True)
        near, _ = self.signs.vis.nearest_many(here)
        self.signs.weigh(logw, g.seen, g.named, tfs, here, near, sight_sigma(travelled))

    def look_doors(self, g: Glimpse, tfs: np.ndarray, ref: Pose2D) -> np.ndarray:
        """The log-likelihood under each hypothesis of ``tfs`` of the doors a look round
        ``g`` saw along the walls (and of the map doors in view it did not see), as one
        scene's (``doors.scene_capped``)."""
        travelled = math.hypot(g.odom.x - ref.x, g.odom.y - ref.y)
        here = apply_many(tfs, (g.odom.x, g.odom.y))
        lw = np.zeros(len(tfs))
        self.doors.weigh(
            lw, self.floor, g.doors, g.door_views, tfs, here,
            P_DOOR_MISS, P_DOOR_SPURIOUS, sight_sigma(travelled),
        )  # fmt: skip
        return scene_capped(lw)

    def drive_view(self, logw: np.ndarray, r: Glimpse, tfs: np.ndarray, ref: Pose2D) -> None:
        """Add the view ahead while driving ``r`` (``CorridorBelief.observe_ray``): its free
        floor and the doors seen in it, each weaker than at a look round."""
        travelled = math.hypot(r.odom.x - ref.x, r.odom.y - ref.y)
        here = apply_many(tfs, (r.odom.x, r.odom.y))
        for yaw, free in r.free:
            self.floor.depth_ray(logw, tfs, here, r.odom, yaw, free, travelled, False)
        self.doors.weigh(
            logw, self.floor, r.doors, r.door_views, tfs, here,
            P_DRIVE_DOOR_MISS, P_DRIVE_DOOR_SPURIOUS, SIGHT_SIGMA_M,
        )  # fmt: skip
