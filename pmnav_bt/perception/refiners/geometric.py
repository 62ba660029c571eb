"""The ``geometric`` refiner: goal pixel -> bearing through the camera intrinsics, range
from depth over the goal's mask (or box).

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
    """Bearing from the mask centre's column; range from the grounder's 3D point, else the
    median depth over the mask (None without depth)."""

    gives_range = True
    drives_approach = False

    def refine(self, obs: Observation, goal: Detection) -> Refinement:
        u, _ = goal.centre
        bearing = obs.intrinsics.pixel_bearing(u)
        p = goal.point if goal.point is not None else target_point(obs, goal)
        return Refinement(bearing, None if p is None else float(math.hypot(p[0], p[1])))


def build(deps: BackendDeps) -> GeometricRefiner:
    """The ``geometric`` back end (registry factory)."""
    return GeometricRefiner()
