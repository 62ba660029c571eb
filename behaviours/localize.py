"""The localization panorama (paper, "Localization"): which yaws it looks at, what it
reads, when it has read enough; and forgetting sightings from before a new fix. The
leaves that weigh it and fix the pose are ``belief``."""

from __future__ import annotations

import math

from py_trees.common import Status

from pmnav_bt.behaviours.capture import LOCALIZATION_YAWS_DEG, READ_SIGNS
from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context
from pmnav_bt.seams import Entity, EntityKind, View


def localization_yaws(_b) -> list[float]:
    return [math.radians(y) for y in LOCALIZATION_YAWS_DEG]


def read_signs(_b) -> str:
    """What the localization panorama grounds: every readable sign."""
    return READ_SIGNS


def enough_doors(views: list[View], n: int = 3) -> bool:
    """Stop the localization panorama early once ``n`` distinct doors have been read."""
    return sum(e.kind is EntityKind.ROOM for e in distinct_landmarks(views)) >= n


class SignsRead(PmNavBehaviour):
    """SUCCESS when the panorama in ``views`` read at least ``n`` distinct signs, else
    FAILURE (a condition: the six views' seams can hide a plate, so too few signs calls
    for the views in between).

    Reads ``views``."""

    READS = ("views",)

    def __init__(self, name: str, ctx: Context, n: int = 2):
        super().__init__(name, ctx)
        self.n = n

    def update(self) -> Status:
        got = len(distinct_landmarks(self.get("views") or []))
        self.feedback_message = f"{got} sign(s) read (want {self.n})"
        return Status.SUCCESS if got >= self.n else Status.FAILURE


def distinct_landmarks(views: list[View]) -> set[Entity]:
    """The rooms and landmarks whose signs were read in ``views``."""
    return {d.entity for v in views for d in v.detections or () if d.entity is not None}


def forget_stale_sightings(b: PmNavBehaviour) -> None:
    """Drop the verified sightings kept for heading re-fits, on a new fix.

    A re-fit assumes one rigid ``map_T_odom`` over its sightings; the panorama spins of a
    (re)localization turn the body a full circle or more, and odometry's rotation bias
    turns the odometry frame with them, so sightings from before a fix no longer share its
    frame. Mixed with new ones they re-fit the heading wrong by as much as the drift since
    (about 18 deg in fig2_hospital with the ``ocr`` grounder), and the robot then drives
    into a side wall that its depth watch rightly calls an obstacle.
    """
    b.bb.set("recent_sightings", None)
