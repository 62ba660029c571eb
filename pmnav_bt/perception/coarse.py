"""Coarse direction: which panorama view shows the target.

The ``detector`` back end grounds the target in every view and takes the view with
the best score; a VLM back end answers the same question from a stitched panorama.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TypeVar

from pmnav_bt.seams import Detection, Grounder, View

V = TypeVar("V")


def best_detection(
    views: Iterable[tuple[V, list[Detection]]], min_score: float
) -> tuple[V, Detection] | None:
    """The (view, detection) with the highest score at or above ``min_score``, or None."""
    best = None
    for v, dets in views:
        for d in dets:
            if d.score >= min_score and (best is None or d.score > best[1].score):
                best = (v, d)
    return best


@dataclass
class DetectorCoarseDirection:
    """The ``CoarseDirection`` seam by grounding: best score across the views.

    Views that carry ``detections`` (grounded while they were captured, even if that
    found nothing) are not grounded again; plain seam ``View``s are.
    """

    grounder: Grounder
    min_score: float = 0.3

    def choose_view(self, views: list, target: str, min_score: float | None = None):
        """The (view, detection) that shows ``target`` best, or None."""
        floor = self.min_score if min_score is None else min_score
        pairs = (
            (v, v.detections)
            if getattr(v, "detections", None) is not None
            else (v, self.grounder.detect(v.observation, target))
            for v in views
        )
        return best_detection(pairs, floor)

    def choose(self, views: list[View], target: str) -> float | None:
        best = self.choose_view(views, target)
        return None if best is None else best[0].relative_yaw
