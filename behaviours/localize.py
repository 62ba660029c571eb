"""Localization (paper, "Localization"): two recognised landmarks fix the pose on the map."""

from __future__ import annotations

import math

from py_trees.common import Status

from pmnav_bt.behaviours.capture import LOCALIZATION_YAWS_DEG, READ_SIGNS
from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context, thumbnail
from pmnav_bt.control import goto_command, rotate_command
from pmnav_bt.failures import FailureCode
from pmnav_bt.localization import fix_pose, sighting
from pmnav_bt.perception.geometry import free_distance
from pmnav_bt.seams import Entity, EntityKind, MotionStatus, View


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


class FixPosition(PmNavBehaviour):
    """Fix the map pose from the landmarks in the localization views.

    Reads ``views``, ``fix_attempts``; writes ``map_T_odom``, ``fix_attempts``,
    ``recent_sightings`` (cleared on a fix: see ``forget_stale_sightings``).
    FAILURE (LOCALIZATION_FAILED) with fewer than two consistent landmarks.
    """

    READS = ("views", "fix_attempts")
    WRITES = ("map_T_odom", "fix_attempts", "recent_sightings")
    JOBS = ("_job",)

    def initialise(self) -> None:
        pm, views = self.ctx.pm, self.get("views") or []

        def locate(cancelled):
            sightings = [
                s
                for v in views
                for d in v.detections or ()
                if (s := sighting(pm, v.observation, d)) is not None
            ]
            return sightings, fix_pose(sightings)

        self._job = self.ctx.worker.submit(locate)

    def update(self) -> Status:
        status, located = self.poll(self._job, "fixing the position")
        if status is not None:
            return status
        sightings, fix = located
        attempts = (self.get("fix_attempts") or 0) + 1
        self.bb.set("fix_attempts", attempts)
        if fix is None:
            seen = sorted({s.entity for s in sightings})
            return self.fail(
                FailureCode.LOCALIZATION_FAILED,
                f"attempt {attempts}: {len(seen)} landmark(s) recognised "
                f"({', '.join(map(str, seen)) or 'none'})"
                "; two are needed",
            )
        self.bb.set("map_T_odom", fix.map_T_odom)
        forget_stale_sightings(self)
        est = fix.map_pose(self.ctx.base.pose())
        views = self.get("views") or []
        self.ctx.log(
            "fix",
            "+".join(e.id for e in fix.entities),
            thumbnail(views[-1].observation.rgb) if views else None,
            map_pose=[est.x, est.y, est.yaw],
            residual=fix.residual,
            attempts=attempts,
        )
        where = f"({est.x:.1f}, {est.y:.1f})"
        self.feedback_message = (
            f"at {where} from {', '.join(map(str, fix.entities))} (rms {fix.residual:.2f} m)"
        )
        return Status.SUCCESS


class Explore(PmNavBehaviour):
    """Explore along the corridor: turn to the most open direction of the last panorama
    (the view with the most free floor ahead, from depth), then drive ``distance``.

    Reads ``views``; writes nothing. SUCCESS when the distance is covered or the way
    is blocked (exploring is best effort).
    """

    READS = ("views",)
    STOPS_BASE = True

    def __init__(self, name: str, ctx: Context, distance: float):
        super().__init__(name, ctx)
        self.distance = distance

    def initialise(self) -> None:
        pose = self.ctx.base.pose()
        self._heading = pose.yaw
        best = -1.0
        for v in self.get("views") or []:
            free = free_distance(v.observation, 0.0)
            if free > best:
                best, self._heading = free, v.observation.pose.yaw
        self._goal = None

    def update(self) -> Status:
        base = self.ctx.base
        pose = base.pose()
        if self._goal is None:
            v, w, done = rotate_command(pose, self._heading, self.ctx.limits)
            if not done:
                base.set_velocity(v, w)
                return Status.RUNNING
            self._goal = (
                pose.x + self.distance * math.cos(pose.yaw),
                pose.y + self.distance * math.sin(pose.yaw),
            )
        if base.motion_status() == MotionStatus.BLOCKED:
            base.stop()
            self.feedback_message = "blocked: explored as far as possible"
            return Status.SUCCESS
        v, w, done = goto_command(pose, *self._goal, self.ctx.limits)
        if done:
            base.set_velocity(0.0, 0.0)
            return Status.SUCCESS
        base.set_velocity(v, w)
        return Status.RUNNING
