"""Refiners: a grounded target -> a precise bearing to it.

``GeometricRefiner`` takes the mask centre's column through the intrinsics.
``CoarseOnly`` keeps the view's own direction (the coarse-only variant of the
paper's Table 4: no fine refinement).
"""

from __future__ import annotations

from dataclasses import dataclass

from pmnav_bt.seams import Detection, Observation


@dataclass(frozen=True)
class GeometricRefiner:
    """Goal pixel -> bearing from the camera intrinsics (the ``geometric`` back end)."""

    name = "geometric"

    def refine(self, obs: Observation, goal: Detection) -> float:
        u, _ = goal.centre
        return obs.intrinsics.pixel_bearing(u)


@dataclass(frozen=True)
class CoarseOnly:
    """No refinement: the target is taken to lie straight ahead of the view it was seen in."""

    name = "coarse"

    def refine(self, obs: Observation, goal: Detection) -> float:
        return 0.0
