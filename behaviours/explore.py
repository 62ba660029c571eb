"""Leaves of the map-less baseline (trees/mapless.py): no priori-map, no plan.

It looks around, records what depth shows in its own occupancy grid (odometry frame),
drives to the best frontier while reading signs, and once the goal's door is seen,
places it by the refiner's range and approaches it. Every pose here is odometry.
"""

from __future__ import annotations

import math

import numpy as np
from py_trees.common import Status

from pmnav_bt.behaviours.capture import CaptureViews
from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context
from pmnav_bt.behaviours.motion import DriveTo
from pmnav_bt.behaviours.search import FaceAndGround
from pmnav_bt.errors import UnknownNameError
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import heading, se2_apply
from pmnav_bt.perception.geometry import target_point
from pmnav_bt.perception.scan import depth_scan
from pmnav_bt.planning.frontier import ExplorationGrid
from pmnav_bt.planning.resolve import resolve_room
from pmnav_bt.seams import CoarseChoice, Entity, View

# Panorama views (relative yaw, deg) in one turn: ahead first, where a sign seen while
# driving was; the first view with the goal (score >= SEEN_SCORE) ends the panorama.
LOOK_YAWS_DEG = (0, 60, 120, 180, 240, 300)
SEEN_SCORE = 0.5
MAX_BLOCKED = 6  # frontier drives blocked in a row before exploring gives up (BLOCKED)
FRESH_STARTS = 1  # times the grid is forgotten when no frontier is left (odometry drift)


def look_yaws(_b: PmNavBehaviour) -> list[float]:
    return [math.radians(y) for y in LOOK_YAWS_DEG]


def goal_entity(b: PmNavBehaviour) -> Entity | None:
    return b.get("goal_entity")


def goal_seen(views: list[View]) -> bool:
    return any(d.score >= SEEN_SCORE for d in views[-1].detections or ())


class StartExploring(PmNavBehaviour):
    """Resolve the goal by the sign vocabulary and start an empty exploration grid at the
    robot. Reads ``goal``; writes ``goal_entity``, ``grid``, ``explore_over`` (False).
    FAILURE (INVALID_GOAL) when no room is called so."""

    READS = ("goal",)
    WRITES = ("goal_entity", "grid", "explore_over")

    def update(self) -> Status:
        goal = str(self.get("goal"))
        try:
            room = resolve_room(self.ctx.pm, goal)
        except UnknownNameError as err:
            return self.fail(FailureCode.INVALID_GOAL, str(err))
        p = self.ctx.base.pose()
        self.bb.set("goal_entity", Entity.room(room))
        self.bb.set("grid", ExplorationGrid(origin=(p.x, p.y)))
        self.bb.set("explore_over", False)
        self.feedback_message = f"looking for room {room}"
        return Status.SUCCESS


class Panorama(CaptureViews):
    """Look around (LOOK_YAWS_DEG, ahead first) grounding the goal in every view; stop at
    the first view that shows it. Reads ``goal_entity``; writes ``views``."""

    READS = CaptureViews.READS + ("goal_entity",)

    def __init__(self, name: str, ctx: Context):
        super().__init__(name, ctx, look_yaws, goal_entity, enough=goal_seen, sweep=False)


class RecordViews(PmNavBehaviour):
    """Add the depth of the last panorama's views to the grid (in the worker).
    Reads ``views``, ``grid``."""

    READS = ("views", "grid")
    JOBS = ("_job",)

    def initialise(self) -> None:
        views, grid = list(self.get("views") or ()), self.get("grid")
        x, y = self.ctx.base.pose().x, self.ctx.base.pose().y

        def record(cancelled):
            grid.mark_visited(x, y)
            for v in views:
                scan = depth_scan(v.observation)
                if scan is not None:
                    grid.integrate(scan)
            return grid.known_fraction()

        self._job = self.ctx.worker.submit(record)

    def update(self) -> Status:
        status, _ = self.poll(self._job, "recording the views")
        if status is not None:
            return status
        return Status.SUCCESS


class ChooseView(PmNavBehaviour):
    """The coarse-direction back end picks the view that shows the goal (in the worker).
    Reads ``views``, ``goal_entity``; writes ``choice``. FAILURE (TARGET_NOT_FOUND) when
    no view shows it: explore on."""

    READS = ("views", "goal_entity")
    WRITES = ("choice",)
    JOBS = ("_job",)

    def initialise(self) -> None:
        views, target, coarse = tuple(self.get("views") or ()), goal_entity(self), self.ctx.coarse
        self._job = self.ctx.worker.submit(lambda c: coarse.choose(views, target))

    def update(self) -> Status:
        status, choice = self.poll(self._job, "choosing the coarse direction")
        if status is not None:
            return status
        if choice is None:
            return self.fail(FailureCode.TARGET_NOT_FOUND, f"{goal_entity(self)} not in view")
        self.bb.set("choice", choice)
        self.feedback_message = str(choice)
        return Status.SUCCESS


class RouteDrive(DriveTo):
    """A DriveTo along a route of waypoints (odometry frame), one leg at a time: a
    subclass hands the route to ``follow`` and calls ``next_leg`` when a leg succeeds."""

    def goal(self) -> tuple[float, float]:
        if getattr(self, "_route", None):
            return self._route[0]
        p = self.ctx.base.pose()
        return p.x, p.y

    def initialise(self) -> None:
        self._route: list[tuple[float, float]] = []
        super().initialise()

    def follow(self, route) -> None:
        """Drive along ``route`` (at least one waypoint) from its first waypoint."""
        self._route = list(route)
        self.aim_at(self._route[0])

    def next_leg(self) -> bool:
        """Drop the waypoint reached and aim at the next; False when the route is done."""
        self._route.pop(0)
        if not self._route:
            return False
        self.aim_at(self._route[0])
        return True


class ExploreFrontier(RouteDrive):
    """Drive to the best frontier of the grid (``ExplorationGrid.choose``) along its path,
    marking where the robot goes as visited and adding what each watch frame's depth shows;
    stop early when the goal is seen on the way (SUCCESS: look around again).

    With no reachable frontier left the grid is forgotten once (FRESH_STARTS: drift may
    have closed them) and the robot looks again.

    Reads ``grid``, ``goal_entity``; writes ``explore_over``. A blocked drive marks its
    frontier failed and ends in SUCCESS (another frontier next), up to MAX_BLOCKED in a row.
    FAILURE (TARGET_NOT_FOUND, ``explore_over``) when no reachable frontier is left: the
    goal was never seen in all the robot could reach; the drive's code (BLOCKED,
    BASE_FAULT, SENSOR_TIMEOUT, ...) when it cannot go on.
    """

    READS = DriveTo.READS + ("grid", "goal_entity")
    WRITES = ("explore_over", "way_shut")  # (a drive notes a shut way; no map pose here)
    JOBS = RouteDrive.JOBS + ("_choice_job",)

    def initialise(self) -> None:
        super().initialise()
        grid: ExplorationGrid = self.get("grid")
        p = self.ctx.base.pose()
        self._grid, self._entity, self._seen = grid, goal_entity(self), False
        self._choice_job = self.ctx.worker.submit(lambda c: grid.choose((p.x, p.y, p.yaw)))
        self._choice = None

    def inspect(self, obs, est, target) -> dict:
        dets = self.ctx.grounder.detect(obs, self._entity) if self._entity is not None else []
        return {"seen": any(d.score >= SEEN_SCORE for d in dets), "scan": depth_scan(obs)}

    def on_watch(self, found: dict, obs) -> None:
        if found.get("scan") is not None:
            self._grid.integrate(found["scan"])
        if found.get("seen"):
            self._seen = True
            self.ctx.log("sign", str(self._entity), obs.rgb)

    def update(self) -> Status:
        if self._choice is None:
            status, choice = self.poll(self._choice_job, "choosing a frontier")
            if status == Status.RUNNING:
                return status
            if status is not None:  # the choice raised: a bug, reported
                self.bb.set("explore_over", True)
                return status
            if choice is None and self._grid.fresh_starts < FRESH_STARTS:
                self._grid.forget()
                self.ctx.log("fresh_start", "")
                self.feedback_message = "no frontier left: forgetting the grid, looking again"
                return Status.SUCCESS
            if choice is None:
                self.bb.set("explore_over", True)
                seen = self._grid.known_fraction() * (2 * self._grid.half_extent) ** 2
                return self.fail(
                    FailureCode.TARGET_NOT_FOUND,
                    f"{self._entity} never seen: no frontier left to explore ({seen:.0f} m2 seen)",
                )
            self._choice = choice
            self.follow(choice.path)
            self.ctx.log("frontier", "", target=list(choice.target), cost=choice.cost)
            self.feedback_message = f"frontier {choice.cost:.1f} m away"
        p = self.ctx.base.pose()
        self._grid.mark_visited(p.x, p.y)
        if self._seen:
            self.ctx.base.stop()
            return Status.SUCCESS
        status = super().update()
        if status == Status.SUCCESS:
            if self.next_leg():
                return Status.RUNNING
            self._grid.mark_spent(self._choice.target)
            self._grid.blocked_in_a_row = 0
            return Status.SUCCESS
        if status == Status.FAILURE:
            failure = self.get("failure")
            if failure is not None and failure.code == FailureCode.BLOCKED:
                self._grid.mark_spent(self._choice.target)
                self._grid.blocked_in_a_row += 1
                if self._grid.blocked_in_a_row < MAX_BLOCKED:
                    return Status.SUCCESS
            self.bb.set("explore_over", True)
        return status


class PlaceDoor(PmNavBehaviour):
    """Where the goal's door is, in the odometry frame: the refiner's bearing and range
    (or the detection's depth point) from the chosen view.

    Reads ``choice``; writes ``door_odom``, ``seen_from``. FAILURE (TARGET_NOT_FOUND)
    when nothing gives a range (no depth)."""

    READS = ("choice",)
    WRITES = ("door_odom", "seen_from")
    JOBS = ("_job",)

    def initialise(self) -> None:
        choice: CoarseChoice = self.get("choice")
        obs, det, refiner = choice.view.observation, choice.detection, self.ctx.refiner
        self._job = self.ctx.worker.submit(lambda c: refiner.refine(obs, det))

    def update(self) -> Status:
        status, refined = self.poll(self._job, "refining the direction")
        if status is not None:
            return status
        choice: CoarseChoice = self.get("choice")
        obs, det = choice.view.observation, choice.detection
        rng = refined.range
        if rng is None:
            p = det.point if det.point is not None else target_point(obs, det)
            rng = None if p is None else float(math.hypot(p[0], p[1]))
        if rng is None:
            return self.fail(FailureCode.TARGET_NOT_FOUND, "the goal's door seen, but no range")
        b = float(refined.bearing)
        odom = se2_apply(
            (obs.pose.x, obs.pose.y, obs.pose.yaw), np.array([rng * math.cos(b), rng * math.sin(b)])
        )
        door = (float(odom[0]), float(odom[1]))
        self.bb.set("door_odom", door)
        self.bb.set("seen_from", (obs.pose.x, obs.pose.y))
        self.ctx.log(
            "detection",
            det.entity.id if det.entity else det.label,
            obs.rgb,
            score=det.score,
            seen_odom=list(door),
        )
        self.feedback_message = f"door {rng:.1f} m away at {math.degrees(b):+.0f} deg"
        return Status.SUCCESS


class ApproachDoor(RouteDrive):
    """Drive to the stop point ``goal_offset`` in front of the door (along the wall's
    normal from the grid) on the grid's path there (round a desk or a corner), or until
    ``keep`` metres from it. Reads ``door_odom``, ``seen_from``, ``grid``."""

    READS = DriveTo.READS + ("door_odom", "seen_from", "grid")
    JOBS = RouteDrive.JOBS + ("_path_job",)

    def __init__(self, name: str, ctx: Context, keep: float = 0.0):
        super().__init__(name, ctx)
        self.keep = keep

    def stop_point(self) -> tuple[float, float]:
        door, seen_from, grid = self.get("door_odom"), self.get("seen_from"), self.get("grid")
        nx, ny = grid.wall_normal(door, seen_from)
        off = self.ctx.config.tree.goal_offset
        return door[0] + off * nx, door[1] + off * ny

    def initialise(self) -> None:
        super().initialise()
        self._stop = self.stop_point()
        grid, p, stop = self.get("grid"), self.ctx.base.pose(), self._stop
        self._path_job = self.ctx.worker.submit(lambda c: grid.path_to((p.x, p.y, p.yaw), stop))
        self._planned = False

    def update(self) -> Status:
        if not self._planned:
            status, path = self.poll(self._path_job, "planning the approach")
            if status is not None:
                return status
            self.follow(path or [self._stop])  # no known way: straight, watching depth
            self._planned = True
        p = self.ctx.base.pose()
        if self.keep > 0.0 and math.dist((p.x, p.y), self._stop) <= self.keep:
            self.ctx.base.set_velocity(0.0, 0.0)
            return Status.SUCCESS
        status = super().update()
        if status == Status.SUCCESS and self.next_leg():
            return Status.RUNNING
        return status


class LookAtDoor(FaceAndGround):
    """Face the placed door and ground the goal in a fresh frame; its best detection
    scoring at least ``SEEN_SCORE`` becomes the ``choice`` (else the old one stands).
    Reads ``door_odom``, ``goal_entity``; writes ``choice``."""

    READS = ("door_odom", "goal_entity")
    ACTIVITY = "looking at the door"
    KEPT = "not in the fresh frame: keeping the first placement"

    def aim(self) -> tuple[float, Entity | None]:
        p = self.ctx.base.pose()
        return heading((p.x, p.y), self.get("door_odom")), goal_entity(self)

    def accept(self, detection) -> bool:
        return detection.score >= SEEN_SCORE
