"""Coarse direction: which panorama view shows the target.

The ``detector`` back end grounds the target in every view and takes the view with
the best score; a VLM back end answers the same question from a stitched panorama.
Runs in the worker (a back end may take seconds).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from pmnav_bt.seams import CoarseChoice, Entity, Grounder, View

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.backends import BackendDeps


@dataclass
class DetectorCoarseDirection:
    """The ``CoarseDirection`` seam by grounding: the best score across the views.

    Views grounded while they were captured (``detections`` not None, even if empty) are
    not grounded again; the others are, with ``grounder``.
    """

    grounder: Grounder
    min_score: float = 0.3

    def choose(self, views: Sequence[View], target: Entity) -> CoarseChoice | None:
        best: CoarseChoice | None = None
        for view in views:
            dets = view.detections
            if dets is None:
                dets = self.grounder.detect(view.observation, target)
            for d in dets:
                if d.score >= self.min_score and (best is None or d.score > best.detection.score):
                    best = CoarseChoice(view, d)
        return best


def build_detector(deps: BackendDeps) -> DetectorCoarseDirection:
    """The ``detector`` back end on the run's grounder (registry factory)."""
    if deps.grounder is None:
        raise ValueError("the detector coarse direction needs the grounder built first")
    return DetectorCoarseDirection(deps.grounder, deps.config.coarse.min_score)
