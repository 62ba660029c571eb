"""How a drive turns its goal into wheel commands: the seam, and its two variants by name.

A drive (``behaviours/motion.py`` ``DriveTo``) asks its ``Steering`` three things:

- ``sense(obs, now)``, in the worker, with every frame the body takes (``Context``):
  take in what the frame shows;
- ``movers(before, after)``: whether what moved between two watch frames is to be asked
  (``perception/movers.py`` tells a mover by where things stand on the floor; a thing the
  robot drives up to leaves the bottom of its view and would read as gone);
- ``way_shut(...)``, in the worker, after that: is the way shut, so that the drive must
  stop and hold (``way_ahead``: wait for a person, give up on a shut way)? The free
  distance ahead when it is, else None;
- ``command(...)``, in the tick: the velocity command (v, w, done) for this period;
- ``clearance(x, y)``: how far an odometry point is from what the steering knows stands
  on the floor (its local costmap: depth, and what the body felt, ``feel``): where a
  drive that touched something may back off to and go round it (``pmnav_bt/contact.py``);
- ``way_round(pose, goal)``, in the worker: a point round what the costmap holds on the
  straight way (``clear_way``), for a drive that steers itself (the localization drive,
  ``behaviours/follow_lead.py``) as for the direct steering.

Both keep a local costmap (``costmap.LocalCostmap``) of what every frame the body took
showed (``Context`` hands each to ``sense``: the drive's watch frames, panoramas, looks)
and what the bumper felt.

``direct`` (``DirectSteering``): steer straight at the goal (``control.goto_command``);
the drive takes a point round what the costmap remembers on that line first
(``way_round``: what the camera saw from afar and no longer sees up close, what the
bumper felt); anything depth shows closer than the goal on that line holds the drive
(and the hold goes round clutter by a detour point, ``motion.detour``).

``dwa`` (``LocalPlannerSteering``): a rolling local costmap from depth
(``costmap.LocalCostmap``) and the dynamic window approach (``dwa.choose``) within the
Create 3's limits: clutter is driven round as it comes; the drive holds only for what
moves (a person, whom ``way_ahead`` waits for and passes with room) or where the costmap
leaves no way to the goal in its window.

Chosen by ``tree.local_planner`` (``STEERINGS``); one instance per episode (its costmap
lives as long as the episode's odometry frame).
"""

from __future__ import annotations

import math
import threading
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from pmnav_bt.contact import felt_item
from pmnav_bt.control import Limits, goto_command
from pmnav_bt.geometry import se2_apply, se2_inverse, wrap_angle
from pmnav_bt.hazards import Hazard, HazardKind
from pmnav_bt.local_planner.clear_way import Inside, blocked_at, point_round
from pmnav_bt.local_planner.costmap import LocalCostmap
from pmnav_bt.local_planner.dwa import Dynamics, Navigation, choose, navigation, passable
from pmnav_bt.registry import Named
from pmnav_bt.seams import Observation, Pose2D

GOAL_TOLERANCE_M = 0.15  # as goto_command's: a drive's goal is reached this near
AIM_SAME_M = 0.05  # a navigation function made for a goal this near serves this one
RECENT_COMMAND_S = 0.5  # a command older than this: the body has stopped since
FINAL_APPROACH_M = 0.5  # this near the goal, with a clear straight way, drive straight in
STILL_M = 0.02  # frames this near each other were taken standing still
SAME_HEADING = math.radians(15.0)  # frames this near in heading were taken on one straight way
SHUT_PROBE_M = 3.0  # how far along the way a shut way's distance is looked for
# A drive judges this much of its straight way against the costmap each watch frame: a
# second's drive and the 2.5 m more in which the camera loses a low box.
JUDGE_M = 3.0

Transform = tuple[float, float, float] | None  # map_T_odom (None: identity)


class Steering(Protocol):
    """The seam between a drive's goal and its wheels (see the module's docstring).
    ``plans_round``: whether it goes round what its costmap holds by itself (the DWA);
    else a drive takes a point round it first (``way_round``)."""

    plans_round: bool

    def sense(self, obs: Observation, now: float) -> None: ...

    def feel(self, hazards: Sequence[Hazard], pose: Pose2D, now: float) -> None: ...

    def movers(self, before: Observation, after: Observation) -> bool: ...

    def way_shut(
        self, obs: Observation, tf: Transform, goal: tuple[float, float],
        ahead: float | None, moving: bool,
    ) -> float | None: ...  # fmt: skip

    def command(
        self, est: Pose2D, odom: Pose2D, aim: tuple[float, float], tf: Transform,
        limits: Limits, now: float,
    ) -> tuple[float, float, bool]: ...  # fmt: skip

    def clearance(self, x: float, y: float) -> float: ...

    def way_round(
        self, pose: Pose2D, goal: tuple[float, float], inside: Inside | None = None
    ) -> tuple[float, float] | None: ...  # fmt: skip


class _Remembers:
    """A local costmap of what depth showed and the body felt (both steerings keep one)."""

    def __init__(self, costmap: LocalCostmap | None = None) -> None:
        self.costmap = costmap if costmap is not None else LocalCostmap()

    def sense(self, obs: Observation, now: float) -> None:
        self.costmap.add_depth(obs, now)

    def feel(self, hazards: Sequence[Hazard], pose: Pose2D, now: float) -> None:
        """Mark the item the bumper touched (``contact.felt_item``: a disc of clutter
        behind the contact) and where a cliff sensor found the floor's end (a wheel stall
        is felt at the wheels, not where the obstacle is), the window round the robot's
        odometry ``pose`` (a body may feel with no depth frame)."""
        points = [h.point for h in hazards if h.kind == HazardKind.CLIFF]
        for h in hazards:
            if h.kind == HazardKind.BUMP:
                points += felt_item(pose, h.point)
        if points:
            self.costmap.recentre(pose.x, pose.y)
            self.costmap.mark(points, now)

    def clearance(self, x: float, y: float) -> float:
        """Metres from odometry (x, y) to the nearest marked cell (inf: none known)."""
        return float(self.costmap.snapshot().clearance(np.array([x]), np.array([y]))[0])

    def way_round(
        self, pose: Pose2D, goal: tuple[float, float], inside: Inside | None = None
    ) -> tuple[float, float] | None:
        """A point (odometry) to drive to first on the straight way from ``pose`` to
        ``goal`` (odometry), round what the costmap holds on its first ``JUDGE_M``; None
        when that way is clear, or when marks leave no way round in the window that
        stays ``inside`` (the caller's walls; the drive then goes on as depth and the
        bumper say). Worker only (``clear_way``)."""
        grid = self.costmap.snapshot()
        here = (pose.x, pose.y)
        d = math.dist(here, goal)
        if d == 0.0:
            return None
        k = min(1.0, JUDGE_M / d)
        end = (here[0] + k * (goal[0] - here[0]), here[1] + k * (goal[1] - here[1]))
        if blocked_at(grid, here, end) is None:
            return None
        return point_round(grid, here, goal, inside)


class DirectSteering(_Remembers):
    """Straight at the goal; whatever depth shows closer than the goal holds the drive. The
    drive itself goes round what the costmap remembers on the way (``way_round``)."""

    plans_round = False

    def movers(self, before: Observation, after: Observation) -> bool:
        """Between frames facing the same way (a straight drive stops at the first frame
        that shows something in the way; from frames a turn apart, onto a point round
        clutter, what stands still would read as moved)."""
        turned = abs(wrap_angle(after.pose.yaw - before.pose.yaw))
        return turned < SAME_HEADING

    def way_shut(self, obs, tf, goal, ahead, moving) -> float | None:
        return ahead

    def command(self, est, odom, aim, tf, limits, now) -> tuple[float, float, bool]:
        return goto_command(est, *aim, limits)


class LocalPlannerSteering(_Remembers):
    """A local costmap and the DWA (see the module's docstring). ``costmap``: the one to
    mark (None: a fresh 10 m window); the hazards of a robot may ``mark`` it too."""

    plans_round = True

    def __init__(self, costmap: LocalCostmap | None = None) -> None:
        super().__init__(costmap)
        # The navigation function for an aim (odometry) and the cells passable, made in the
        # worker with each frame, read in the tick.
        self._nav: tuple = ((math.nan, math.nan), None, None)
        self._last = (0.0, 0.0, -math.inf)  # the command in force and when it was sent
        self._line: tuple[tuple[float, float], tuple[float, float]] | None = None
        self._lock = threading.Lock()

    def movers(self, before: Observation, after: Observation) -> bool:
        """Only between frames from where the robot stood still (held, or stopped with no
        way on): while it drives round clutter, what it passes leaves the view."""
        a, b = before.pose, after.pose
        return math.hypot(a.x - b.x, a.y - b.y) < STILL_M

    def way_shut(self, obs, tf, goal, ahead, moving) -> float | None:
        """Shut for what moves in the way (a person: ``way_ahead`` waits for them), or
        where what the costmap marks leaves no way through the window to the goal (the
        free distance along the way then: depth's ``ahead``, else the first lethal cell)."""
        if ahead is not None and moving:
            return ahead
        pose = obs.pose
        g = _to_odom(tf, goal)
        grid = self.costmap.snapshot()
        line = self._line if self._line is not None and self._line[1] == g else None
        line = line or ((pose.x, pose.y), g)
        ok = passable(grid, line)
        nav = navigation(grid, pose.x, pose.y, g, ok)
        with self._lock:
            self._nav = (g, nav, ok)
        here = (np.array([pose.x]), np.array([pose.y]))
        if math.isfinite(float(nav.at(*here)[0])):
            return None
        # No way over floor seen free: shut only where what is marked cuts the way (floor
        # not seen yet may open as the robot drives on).
        anyway = navigation(grid, pose.x, pose.y, g)
        if math.isfinite(float(anyway.at(*here)[0])):
            return None
        return ahead if ahead is not None else _first_lethal(nav, pose, g)

    def command(self, est, odom, aim, tf, limits, now) -> tuple[float, float, bool]:
        g = _to_odom(tf, aim)
        if math.hypot(g[0] - odom.x, g[1] - odom.y) <= GOAL_TOLERANCE_M:
            self._last = (0.0, 0.0, now)
            return 0.0, 0.0, True
        if self._line is None or math.dist(self._line[1], g) > AIM_SAME_M:
            self._line = ((odom.x, odom.y), g)  # a new aim: its straight line from here
        v0, w0, then = self._last
        if now - then > RECENT_COMMAND_S:
            v0 = w0 = 0.0
        grid = self.costmap.snapshot()
        dyn = Dynamics(limits.linear, limits.angular)
        if _final_approach(grid, odom, g):  # the last half metre, clear: straight in
            v, w, _ = goto_command(odom, *g, limits)
            v = min(v, v0 + dyn.accel_linear * dyn.period)
            self._last = (v, w, now)
            return v, w, False
        with self._lock:
            made_for, nav, ok = self._nav
        if nav is None or math.dist(made_for, g) > AIM_SAME_M or nav.grid.origin != grid.origin:
            nav = ok = None  # for another aim, or the window moved: straight on, till the next
        choice = choose(grid, nav, (odom.x, odom.y, odom.yaw), (v0, w0), g, self._line, dyn, ok)
        v, w = (0.0, 0.0) if choice is None else (choice.v, choice.w)
        self._last = (v, w, now)
        return v, w, False


def _final_approach(grid, odom: Pose2D, goal: tuple[float, float]) -> bool:
    """Whether the goal is within ``FINAL_APPROACH_M`` with nothing lethal on the straight
    way to it: the DWA's 1.8 s rollouts overshoot so short a way, and weave."""
    d = math.hypot(goal[0] - odom.x, goal[1] - odom.y)
    if d > FINAL_APPROACH_M:
        return False
    s = np.linspace(0.0, 1.0, max(2, int(d / grid.resolution) + 2))
    clear = grid.clearance(odom.x + s * (goal[0] - odom.x), odom.y + s * (goal[1] - odom.y))
    return bool((clear >= min(grid.lethal_m, float(clear[0]))).all())


def _to_odom(tf: Transform, p: tuple[float, float]) -> tuple[float, float]:
    if tf is None:
        return float(p[0]), float(p[1])
    q = se2_apply(se2_inverse(tf), p)
    return float(q[0]), float(q[1])


def _first_lethal(nav: Navigation, pose: Pose2D, goal: tuple[float, float]) -> float:
    """Metres along the straight way to ``goal`` to the first lethal cell (SHUT_PROBE_M
    when none within it)."""
    a = math.atan2(goal[1] - pose.y, goal[0] - pose.x)
    s = np.arange(0.0, SHUT_PROBE_M, nav.grid.resolution)
    clear = nav.grid.clearance(pose.x + s * math.cos(a), pose.y + s * math.sin(a))
    hit = np.flatnonzero(clear < nav.grid.lethal_m)
    return float(s[hit[0]]) if len(hit) else SHUT_PROBE_M


@dataclass(frozen=True)
class SteeringSpec:
    """A steering by name: ``make()`` builds one episode's."""

    name: str
    make: type
    description: str


STEERINGS = Named(
    "tree.local_planner",
    "local planner",
    [
        SteeringSpec("direct", DirectSteering, "straight at the goal; clutter by detour points"),
        SteeringSpec("dwa", LocalPlannerSteering, "local costmap from depth and DWA"),
    ],
    SteeringSpec,
)


def make_steering(name: str) -> Steering:
    """One episode's steering, by name (``STEERINGS``)."""
    return STEERINGS.spec(name).make()
