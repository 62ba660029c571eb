"""The ``geometric`` refiner: the target's bearing and range from one point, the
grounder's 3D point where it gives one, else the goal pixel through the camera
intrinsics and depth over the goal's mask (or box).

The coarse-only ablation (paper Table 4) is a tree variant, not a refiner:
``tree.variant: coarse_only`` leaves grounding and refinement out of the tree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from pmnav_bt.perception.geometry import target_point
from pmnav_bt.seams import Detection, Observation, Refinement

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.backends import BackendDeps


@dataclass(frozen=True)
class GeometricRefiner:
    """Bearing and range of the grounder's 3D point where it gives one: a door placed
    from its sign may lie beside the box that was read, even out of view, and a bearing
    from the box with the door's range puts the target on the sign's line of sight at
    the door's distance, behind the wall. Without a point: the mask centre's column and
    the median depth over the mask (range None without depth)."""

    gives_range = True
    drives_approach = False

    def refine(self, obs: Observation, goal: Detection) -> Refinement:
        if goal.point is not None:
            x, y = float(goal.point[0]), float(goal.point[1])
            return Refinement(math.atan2(y, x), math.hypot(x, y))
        u, _ = goal.centre
        p = target_point(obs, goal)
        bearing = obs.intrinsics.pixel_bearing(u)
        return Refinement(bearing, None if p is None else float(math.hypot(p[0], p[1])))


def build(deps: BackendDeps) -> GeometricRefiner:
    """The ``geometric`` back end (registry factory)."""
    return GeometricRefiner()
