"""Recoveries like Nav2's: back up, spin to look (or to the corridor axis), wait.

Each is a small leaf; the tree picks them by the failure that triggered the recovery
(``trees.recovery.recovery_subtree``), and the localization drive backs off a wall it
ran into with ``BackUp`` too. Backing up stays within ``BACKUP_LIMIT_M``, the Create 3's
backup limit (0.15 m): it has no cliff sensors at the back, and with its default
``safety_override: none`` it reverses only that far over floor it has just driven
forward over (hazard BACKUP_LIMIT), so a recovery never asks for more.
"""

from __future__ import annotations

import math

from py_trees.common import Status

from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context, map_pose
from pmnav_bt.contact import BackOff
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import wrap_angle
from pmnav_bt.hazards import body_blocked_by
from pmnav_bt.seams import CREATE3_BACKUP_LIMIT_M, MotionStatus

BACKUP_LIMIT_M = CREATE3_BACKUP_LIMIT_M  # the most a recovery reverses
BACKUP_TIME_S = 8.0  # clock seconds before a backup that does not move gives up (default)


class FailureIs(PmNavBehaviour):
    """SUCCESS when the last failure has one of ``codes`` (a recovery's guard).

    Reads ``failure``."""

    READS = ("failure",)

    def __init__(self, name: str, ctx: Context, *codes: FailureCode):
        super().__init__(name, ctx)
        self.codes = frozenset(codes)

    def update(self) -> Status:
        f = self.get("failure")
        ok = f is not None and f.code in self.codes
        self.feedback_message = f.code.value if f is not None else "no failure"
        return Status.SUCCESS if ok else Status.FAILURE


class BackUp(PmNavBehaviour):
    """Reverse ``distance`` metres (at most BACKUP_LIMIT_M) off a wall or an obstacle:
    away from the bump the body felt when one stopped it (turned to face it first,
    ``contact.BackOff``), else straight back; never into what the steering's costmap
    holds behind. SUCCESS when covered, or when the body cannot reverse further: it
    refuses (BLOCKED) or has not covered it after ``timeout_s`` clock seconds (best
    effort).
    """

    STOPS_BASE = True

    def __init__(
        self,
        name: str,
        ctx: Context,
        distance: float = BACKUP_LIMIT_M,
        timeout_s: float = BACKUP_TIME_S,
    ):
        super().__init__(name, ctx)
        self.distance = min(distance, BACKUP_LIMIT_M)
        self.timeout_s = timeout_s

    def initialise(self) -> None:
        base, now = self.ctx.base, self.ctx.now()
        p = base.pose()
        bump = body_blocked_by(base)
        ahead = (p.x + math.cos(p.yaw), p.y + math.sin(p.yaw))  # none felt: straight back
        self._backing = BackOff(
            ahead if bump is None else bump.point, p, now, self.distance,
            self.ctx.steering.clearance, self.timeout_s,
        )  # fmt: skip
        self._sent = False  # BLOCKED before the first command is the failure that led here

    def update(self) -> Status:
        base = self.ctx.base
        blocked = self._sent and base.motion_status() == MotionStatus.BLOCKED
        v, w, done = self._backing.command(base.pose(), blocked, self.ctx.now())
        if done:
            base.stop()
            moved, why = self._backing.moved, self._backing.why
            self.feedback_message = f"backed up {moved:.2f} m" + (f" ({why})" if why else "")
            return Status.SUCCESS
        base.set_velocity(v, w)
        self._sent = True
        return Status.RUNNING


class Spin(PmNavBehaviour):
    """Turn on the spot by ``angle`` (rad, counter-clockwise positive): look round."""

    STOPS_BASE = True

    def __init__(self, name: str, ctx: Context, angle: float):
        super().__init__(name, ctx)
        self.angle = angle

    def target(self) -> float:
        return self.ctx.base.pose().yaw + self.angle

    def initialise(self) -> None:
        self._goal = self.target()

    def update(self) -> Status:
        return Status.SUCCESS if self.face(self._goal) else Status.RUNNING


class FaceCorridor(Spin):
    """Turn to the nearer direction along the corridor the estimate is in (after a drive
    that went diagonally into a wall). Reads ``map_T_odom``."""

    READS = ("map_T_odom",)

    def __init__(self, name: str, ctx: Context):
        super().__init__(name, ctx, 0.0)

    def target(self) -> float:
        odom = self.ctx.base.pose()
        est = map_pose(self.get("map_T_odom"), odom)
        axis = self.ctx.pm.locate(est.x, est.y).segment.heading
        turn = wrap_angle(2.0 * (axis - est.yaw)) / 2.0  # to the nearer of the two ways
        self.feedback_message = f"turn {math.degrees(turn):+.0f} deg onto the corridor axis"
        return odom.yaw + turn


class Wait(PmNavBehaviour):
    """Wait ``seconds`` of the tree's clock (a person or a door in the way may move)."""

    def __init__(self, name: str, ctx: Context, seconds: float):
        super().__init__(name, ctx)
        self.seconds = seconds

    def initialise(self) -> None:
        self.ctx.base.stop()
        self._t0 = self.ctx.now()

    def update(self) -> Status:
        left = self.seconds - (self.ctx.now() - self._t0)
        self.feedback_message = f"{max(0.0, left):.1f} s left"
        return Status.SUCCESS if left <= 0.0 else Status.RUNNING
