"""What a drive does after it touched something: back off from it, then go round it.

A contact is an event, not a state: the body touched something once, however many
ticks it then reports BLOCKED. A robot that touched something stops pushing, backs off
*away from* what it felt, and goes round it; what it touched is an obstacle from then on
(the local costmap marks it: ``Steering.feel``), so the next try does not touch it
again. Nav2's answer is the same (its collision monitor stops the robot, its ``BackUp``
recovery reverses, the costmap keeps the bumper's hit).

Where the body touched (``Contact``): the bump the body felt, where it has a bumper (the
Create 3, the simulated body: ``pmnav_bt.hazards``, the zone's point on its rim); for a
body without one, the rim straight ahead (it was driving forward into it).

Backing off (``BackOff``): a round body turns in place without touching anything, so it
first turns to face the contact (within ``FACE_WITHIN``), and then reverses straight away
from it, ``BACK_OFF_M``: that much clear of it, as far as the contact goes. It reverses
only as far as nothing is known behind: the Create 3 itself reverses only over floor it
has just driven forward over (its backup buffer, ``pmnav_bt.backup_limit``), refusing
more (the body reports BLOCKED: the back-off ends there), and the local costmap (what
depth showed before the robot turned, and earlier bumps) must show nothing within the
body's reach behind (``behind_free``).

What a bump tells (``felt_item``): something stands at the contact point, and beyond it,
away from the body: the bumper feels an item's near face, not its size. It is taken to
be an item of clutter, a disc ``ITEM_RADIUS_M`` across behind the contact (a chair, a
plant, a bin: 0.4-0.6 m), and marked so in the local costmap.

Going round (``round_contact``): a step aside, as a person takes one: a point beside
the robot, square to the way to the goal, on the side away from the contact (the other
side second), the least step (``ROUND_SIDES_M``) whose way there is clear of what the
costmap holds and from which the way on towards the goal is clear for ``WAY_ON_M``
(``way_clear``); and only where the caller's check passes (inside the map's corridors).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from pmnav_bt.control import Limits, rotate_command
from pmnav_bt.geometry import heading, wrap_angle
from pmnav_bt.hazards import Hazard, HazardKind, body_blocked_by
from pmnav_bt.seams import CREATE3_BACKUP_LIMIT_M, CREATE3_RADIUS_M, Pose2D

# Reverse this far off a contact: most of the Create 3's 0.15 m backup buffer, which a
# drive that has just driven into something has full; a few cm are left for a recovery.
BACK_OFF_M = 0.12
BACK_OFF_SPEED = 0.1  # m/s, as the recovery's BackUp
BACK_OFF_TIME_S = 6.0  # clock seconds: a back-off the body does not carry out ends
FACE_WITHIN = math.radians(10.0)  # facing the contact this nearly, reversing moves off it
ITEM_RADIUS_M = 0.25  # what a bump felt: an item of clutter this big behind the contact
# Steps aside tried, least first: from a contact at the body's side to one straight
# ahead of a wide item.
ROUND_SIDES_M = (0.35, 0.5, 0.65, 0.8)
WAY_ON_M = 1.5  # from a step aside, the way on to the goal is this far clear
BEHIND_PROBE_M = 0.05  # a way is sampled this finely
WAY_PAD_M = 0.05  # a way keeps the body's radius and this (a costmap cell) from what is known


@dataclass(frozen=True)
class Contact:
    """Where the body touched something (a point in the odometry frame), when, and in
    words (the bump's, or "touched something ahead")."""

    point: tuple[float, float]
    stamp: float
    words: str


def felt_contact(base, now: float) -> Contact:
    """The contact that stopped ``base``'s motion: the bump its bumper felt, else the rim
    straight ahead of its odometry pose (a body without a bumper drives into what it
    touches)."""
    bump = body_blocked_by(base)
    if bump is not None:
        return Contact(bump.point, now, bump.describe())
    p = base.pose()
    rim = (p.x + CREATE3_RADIUS_M * math.cos(p.yaw), p.y + CREATE3_RADIUS_M * math.sin(p.yaw))
    return Contact(rim, now, f"touched something ahead at ({rim[0]:.2f}, {rim[1]:.2f})")


def as_bump(contact: Contact) -> Hazard:
    """``contact`` as the bump hazard a steering's ``feel`` marks (``felt_item``)."""
    return Hazard(HazardKind.BUMP, "", contact.point, contact.stamp)


Clearance = Callable[[float, float], float]  # metres from an odometry point to what is known


def behind_free(pose: Pose2D, distance: float, clearance: Clearance | None) -> float:
    """How far (m, at most ``distance``) the body at ``pose`` (odometry) may reverse: the
    way behind keeps its radius and ``WAY_PAD_M`` from what ``clearance`` (the local
    costmap) knows, except where it is already nearer than that and reversing takes it
    further away: touching what it felt ahead (which the costmap now holds), each step back
    gains clearance, and only a step that brings it nearer to something is refused."""
    if clearance is None:
        return distance
    was = clearance(pose.x, pose.y)
    steps = max(1, int(math.ceil(distance / BEHIND_PROBE_M)))
    for i in range(1, steps + 1):
        s = distance * i / steps
        x, y = pose.x - s * math.cos(pose.yaw), pose.y - s * math.sin(pose.yaw)
        here = clearance(x, y)
        if here < CREATE3_RADIUS_M + WAY_PAD_M and here < was:
            return distance * (i - 1) / steps
        was = here
    return distance


class BackOff:
    """Turn to face ``contact`` (odometry), then reverse straight off it ``distance`` m;
    ``command(pose, blocked, now)`` gives (v, w, done) each tick. Done when covered (as
    far as ``clearance``, the local costmap, shows the way behind free), when the body
    refuses to reverse further (``blocked``: its backup buffer is empty, or it touched
    something behind), or after ``BACK_OFF_TIME_S``."""

    def __init__(
        self,
        contact: tuple[float, float],
        start: Pose2D,
        now: float,
        distance: float = BACK_OFF_M,
        clearance: Clearance | None = None,
        timeout_s: float = BACK_OFF_TIME_S,
    ) -> None:
        self.contact = contact
        self.distance = min(distance, CREATE3_BACKUP_LIMIT_M)
        self.clearance = clearance
        self.timeout_s = timeout_s
        self._t0 = now
        self._from: tuple[float, float] | None = None  # where reversing began
        self._face = heading((start.x, start.y), contact)
        self.moved = 0.0
        self.why = ""

    def command(self, pose: Pose2D, blocked: bool, now: float) -> tuple[float, float, bool]:
        if now - self._t0 > self.timeout_s:
            return self._done("out of time")
        if self._from is None:
            v, w, facing = rotate_command(pose, self._face, Limits(), tol=FACE_WITHIN)
            if not facing:
                return v, w, False
            self._from = (pose.x, pose.y)
            self.distance = behind_free(pose, self.distance, self.clearance)
            if self.distance < 0.01:
                return self._done("something behind")
            return -BACK_OFF_SPEED, 0.0, False
        self.moved = math.dist(self._from, (pose.x, pose.y))
        if self.moved >= self.distance - 0.005:
            return self._done("")
        if blocked:
            return self._done("the body would reverse no further")
        return -BACK_OFF_SPEED, 0.0, False

    def _done(self, why: str) -> tuple[float, float, bool]:
        self.why = why
        return 0.0, 0.0, True


def way_clear(
    a: tuple[float, float],
    b: tuple[float, float],
    clearance: Clearance,
    skip: float = CREATE3_RADIUS_M,
) -> bool:
    """Whether the body can drive straight from ``a`` to ``b`` (odometry) keeping its
    radius and ``WAY_PAD_M`` from what ``clearance`` (the local costmap) knows. The first
    ``skip`` m are not judged: the body stands there now (beside what it touched)."""
    d = math.dist(a, b)
    if d == 0.0:
        return clearance(*a) >= CREATE3_RADIUS_M + WAY_PAD_M or skip > 0.0
    steps = max(1, int(math.ceil(d / BEHIND_PROBE_M)))
    for i in range(steps + 1):
        s = d * i / steps
        if s < skip:
            continue
        x, y = a[0] + (b[0] - a[0]) * s / d, a[1] + (b[1] - a[1]) * s / d
        if clearance(x, y) < CREATE3_RADIUS_M + WAY_PAD_M:
            return False
    return True


WayCheck = Callable[[tuple[float, float]], bool]  # whether a point round it may be taken


def round_contact(
    here: Pose2D,
    contact: tuple[float, float],
    goal: tuple[float, float],
    clearance: Clearance,
    inside: WayCheck,
) -> tuple[float, float] | None:
    """A step aside from what was touched at ``contact`` (all in the odometry frame) on
    the way from ``here`` to ``goal`` (see the module's docstring): the first point that
    is ``inside`` (the caller's walls) with its way and the way on clear in
    ``clearance``; None when there is none, or when the goal is nearer than the contact
    (nothing to go round)."""
    if math.dist((here.x, here.y), goal) <= math.dist((here.x, here.y), contact):
        return None
    way = heading((here.x, here.y), goal)
    off = wrap_angle(heading((here.x, here.y), contact) - way)  # the contact left (+) of it
    sides = (-1.0, 1.0) if off > 0.0 else (1.0, -1.0)
    for s in sides:
        for side_m in ROUND_SIDES_M:
            p = (here.x - s * side_m * math.sin(way), here.y + s * side_m * math.cos(way))
            if not inside(p) or not way_clear((here.x, here.y), p, clearance):
                continue
            on = min(WAY_ON_M, math.dist(p, goal))
            a = heading(p, goal)
            ahead = (p[0] + on * math.cos(a), p[1] + on * math.sin(a))
            if way_clear(p, ahead, clearance, skip=0.0):
                return float(p[0]), float(p[1])
    return None


def felt_item(pose: Pose2D, point: tuple[float, float]) -> list[tuple[float, float]]:
    """The points of the item a bump at ``point`` felt, the body at ``pose`` (odometry):
    a disc ``ITEM_RADIUS_M`` across beyond the contact, away from the body, every 5 cm
    (the costmap's cells), the contact point first."""
    a = heading((pose.x, pose.y), point)
    cx, cy = point[0] + ITEM_RADIUS_M * math.cos(a), point[1] + ITEM_RADIUS_M * math.sin(a)
    step = 0.05
    n = int(ITEM_RADIUS_M / step)
    pts = [point]
    for i in range(-n, n + 1):
        for j in range(-n, n + 1):
            if math.hypot(i * step, j * step) <= ITEM_RADIUS_M:
                pts.append((cx + i * step, cy + j * step))
    return pts
