"""Lift leaves: ride a lift from one level to another, as a robot that cannot press a
button does it: through the building's lift system (``seams.Lift``, Open-RMF's lift
request and state), with its eyes for what the lift system cannot say.

A ride (``Ride``) is one lift between two levels: the lift's doorway on each
(``pmnav_bt.map.lift_doorway``), and the session the robot asks for the lift by. The
leaves, in the order ``trees/lift.py`` strings them:

- ``ToLobby``: to the lobby point in front of the doors, facing them;
- ``CallLift``: ask for the lift at a level (again with another level to ride);
- ``WaitForLift``: until the lift says it is at that level with its door open for us
  (LIFT_NOT_COMING after a clock timeout);
- ``FindDoors``: depth finds the open doorway, ahead or turned aside, and the estimate
  is moved along the wall to put it where the map has it;
- ``CabinHasRoom``: depth says whether the cabin's floor is free (LIFT_FULL, counted);
- ``ReleaseLift``: end the session (a full cabin goes on without us; off at the far end);
- ``BoardingBegins``, ``BoardAgainAllowed``: a boarding let go because the lift came full
  is the building's delay, not the robot's search: its actions are added to the budget;
- ``SeeItLeave``: after letting a full lift go, wait until it has shut its doors, so that
  the next call is answered by the lift's next arrival, not by the same full cabin;
- ``DriveThrough``: straight through the doorway, into the cabin's middle or out to the
  lobby, on odometry (the doorway is 1.6 m wide, the robot 0.34 m);
- ``StartLevel``: the mission's first leaf: the level it starts on;
- ``OnNewLevel``: in the cabin on the far level: the old level's estimate, plan and what
  was found blocked are dropped; the estimate restarts at the cabin on the new level's
  map, heading as the robot stood in the cabin (``arrival_pose``), with the lift's word
  as its only evidence (a prior, ``ARRIVAL_SIGMA_M``), for the re-localization to
  confirm;
- ``LiftWordStands``: the arrival look agrees with the lift's word but cannot sharpen it
  (the lift's own plate alone): the estimate stands;
- ``CheckLevel``: the signs read on arrival name places of the level asked, not of
  another (WRONG_LEVEL).

Failure texts name the lift and the levels as the building does (``Ride.name``, the
level names of the site file).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from enum import Enum

import numpy as np
from py_trees.common import Status

from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context, map_pose
from pmnav_bt.behaviours.localize import forget_stale_sightings
from pmnav_bt.control import goto_command
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import heading, se2_apply, se2_compose, se2_inverse, wrap_angle
from pmnav_bt.map.building import Building
from pmnav_bt.map.lift_doorway import CABIN_DEPTH_M, DOORWAY_WALL_M, Doorway
from pmnav_bt.perception.geometry import free_distance
from pmnav_bt.pose.correction import PoseTracker
from pmnav_bt.pose.hypotheses import CLUSTER_M, FIX_MASS
from pmnav_bt.seams import (
    CREATE3_RADIUS_M,
    Lift,
    LiftDoor,
    LiftMotion,
    MotionStatus,
    Pose2D,
)

# Through the doorway at a walking pace for a tight place: a third of the Create 3's limit.
DOORWAY_SPEED = 0.1  # m/s
# A drive through the doorway that has not covered its distance after this long gives up
# (blocked): 2.5 m at 0.1 m/s takes 25 s.
DOORWAY_TIMEOUT_S = 40.0
# The cabin has room when depth shows its floor free this far past the robot's footprint
# at the cabin's middle, the width of the robot and this margin each side.
CABIN_MARGIN_M = 0.1
# The way into the cabin is looked for over these bearings of the 60-degree camera.
SCAN_HALF = math.radians(27.5)
SCAN_STEP = math.radians(2.5)
# An open lift whose doorway is not in view is looked at again this many times, this
# many seconds apart, before the robot says it is not at the doors: someone walking past
# (1 m/s) clears the 1.6 m doorway in two seconds, someone waiting steps in or aside,
# and the lift holds its doors open for the robot's session meanwhile. Waiting costs no
# action; walking off to look elsewhere would.
CABIN_LOOKS = 4
CABIN_LOOK_AGAIN_S = 4.0
# The open doors are looked for turned this far either way from facing them, when the look
# straight at them does not show the whole opening: an estimate off along the wall (a
# lift's plate, the sign the leg found it by, hangs 1-2 m beside its doors) puts the
# doors aside. A 60-degree camera turned 40 degrees sees 10-70 degrees off the doors'
# normal: from the corridor's centre line 1.2 m off the wall, 0.2-3.3 m along it.
DOORS_ASIDE = math.radians(40.0)
# A ray through the doorway shows floor this far past the wall's far face at least (the
# cabin is 1.6 m deep; the wall beside the doors shows none).
PAST_WALL_M = 0.2
# A ray that stops this near the wall's face meets the wall (a jamb), not someone before it.
JAMB_M = 0.3
# Rays more oblique than this to the wall see too little through a doorway to tell.
DOORS_OBLIQUE = math.radians(75.0)
# The opening found is the lift's when its middle is at most this far along the wall from
# where the estimate puts the doors: a lift's plate is 0.8-2.2 m beside them, so an
# estimate the plate placed is off by as much (an open room door farther off is not it).
DOORS_SHIFT_M = 2.5
# A stretch of rays through an opening narrower than this along the wall is not taken
# for a doorway (someone standing in it, a gap between people), nor one wider than the
# doorway by this (a side corridor, a lobby open to the corridor).
DOORS_MIN_RUN_M = 0.4
DOORS_WIDER_M = 0.3
# The estimate on arrival: the cabin on the new level's map, as sure as the ride put the
# robot there (it drove in on the old level's estimate, a few tenths of a metre off).
ARRIVAL_SIGMA_M = 0.5
# Signs of another level read on arrival: this many, and more than of the level asked,
# say the lift stopped at the wrong floor (one could be a misread).
WRONG_LEVEL_SIGNS = 2
# What belongs to the level left behind: the estimate, the plan and what was found there.
OLD_LEVEL_KEYS = (
    "plan",
    "step_index",
    "target",
    "views",
    "choice",
    "bearing",
    "sighting",
    "last_action",
    "avoid_landmarks",
    "blocked_segments",
    "blocked_suspects",
    "blocked_ways",
    "way_shut",
    "belief",
    "fix_attempts",
    "drive_end",
    "corridor_drive",
)


@dataclass(frozen=True)
class Ride:
    """One lift ride: ``lift`` as the lift system knows it, ``name`` as people call it
    ("Lift A"), from ``from_level`` to ``to_level`` (the site's level names), through
    ``board`` (its doorway on the first level's map) and ``alight`` (on the second's),
    asked for by ``session``."""

    lift: str
    name: str
    from_level: str
    to_level: str
    board: Doorway
    alight: Doorway
    session: str = "pmnav"


class ToLobby(PmNavBehaviour):
    """Drive to the lobby point in front of the lift's doors (on the corridor's centre
    line) and turn to face them, on the map estimate. Reads ``map_T_odom``."""

    READS = ("map_T_odom",)
    STOPS_BASE = True

    def __init__(self, name: str, ctx: Context, ride: Ride):
        super().__init__(name, ctx)
        self.ride = ride

    def initialise(self) -> None:
        self._at = False

    def update(self) -> Status:
        est = map_pose(self.get("map_T_odom"), self.ctx.base.pose())
        d = self.ride.board
        if not self._at:
            v, w, self._at = goto_command(est, *d.lobby, self.ctx.limits)
            self.ctx.base.set_velocity(v, w)
            if not self._at:
                return Status.RUNNING
        if not self.face(heading((est.x, est.y), d.centre), est):
            return Status.RUNNING
        self.feedback_message = f"at the doors of {self.ride.name}"
        return Status.SUCCESS


class CallLift(PmNavBehaviour):
    """Ask the lift system for the ride's lift at ``level`` (to come there, or with the
    robot inside to go there), door open, for the ride's session. SUCCESS at once."""

    def __init__(self, name: str, ctx: Context, lift: Lift, ride: Ride, level: str):
        super().__init__(name, ctx)
        self.lift, self.ride, self.level = lift, ride, level

    def update(self) -> Status:
        self.lift.request(self.ride.lift, self.level, self.ride.session)
        self.ctx.log("lift_call", self.ride.lift, level=self.level)
        self.feedback_message = f"asked for {self.ride.name} at level {self.level}"
        return Status.SUCCESS


class _WaitsOnLift(PmNavBehaviour):
    """A wait, stopped, on what the ride's lift says: ``watch()`` gives its state (None:
    not heard) and the seconds of the tree's clock waited so far."""

    def __init__(self, name: str, ctx: Context, lift: Lift, ride: Ride):
        super().__init__(name, ctx)
        self.lift, self.ride = lift, ride

    def initialise(self) -> None:
        self.ctx.base.stop()
        self._t0 = self.ctx.now()

    def watch(self):
        return self.lift.state(self.ride.lift), self.ctx.now() - self._t0


class WaitForLift(_WaitsOnLift):
    """Wait, stopped, until the lift says it stands at ``level`` with its door open for the
    ride's session; FAILURE (LIFT_NOT_COMING) after ``timeout_s`` seconds of the tree's
    clock."""

    def __init__(
        self, name: str, ctx: Context, lift: Lift, ride: Ride, level: str, timeout_s: float
    ):
        super().__init__(name, ctx, lift, ride)
        self.level, self.timeout_s = level, timeout_s

    def update(self) -> Status:
        st, waited = self.watch()
        if (
            st is not None
            and st.current_level == self.level
            and st.door == LiftDoor.OPEN
            and st.motion == LiftMotion.STOPPED
            and st.session == self.ride.session
        ):
            self.ctx.log("lift_open", self.ride.lift, level=self.level, waited=waited)
            self.feedback_message = f"{self.ride.name} open at level {self.level}"
            return Status.SUCCESS
        if waited > self.timeout_s:
            seen = "no word from it" if st is None else (
                f"it is at level {st.current_level}, door {st.door.value}"
            )
            return self.fail(
                FailureCode.LIFT_NOT_COMING,
                f"{self.ride.name} did not open its door at level {self.level} in "
                f"{self.timeout_s:.0f} s ({seen})",
            )
        self.feedback_message = f"waiting for {self.ride.name} at level {self.level}"
        return Status.RUNNING


@dataclass(frozen=True)
class CabinLook:
    """What depth shows through a lift's open doors: ``way`` in (the bearing, rad from the
    frame's heading, and the metres along it to the cabin's middle), None when there is
    none; ``beyond``: whether anything is seen past the doors' plane (an open doorway in
    view: no way in then means a full cabin, not a wall)."""

    way: tuple[float, float] | None
    beyond: bool


def look_into_cabin(obs, est: Pose2D, d: Doorway) -> CabinLook:
    """Scan the frame's bearings (``SCAN_HALF``, every ``SCAN_STEP``) for a way into the
    cabin's middle: one along which depth shows the floor free (the robot's width and
    ``CABIN_MARGIN_M`` each side) to the middle's depth and a radius and margin past it.
    The way is the middle of those that pass, so that an estimate a little off along the
    corridor still finds the doorway (the doors are 1.6 m wide). ``est``: the map pose
    the frame was taken from."""
    u = np.asarray(d.into, float)
    to_wall = float(np.dot(np.subtract(d.centre, (est.x, est.y)), u))
    middle = to_wall + DOORWAY_WALL_M + CABIN_DEPTH_M / 2.0
    half = CREATE3_RADIUS_M + CABIN_MARGIN_M
    passing, deepest = [], 0.0
    for b in np.arange(-SCAN_HALF, SCAN_HALF + 1e-9, SCAN_STEP):
        off = wrap_angle(est.yaw + b - d.yaw_in)
        if abs(off) >= math.radians(60.0):
            continue
        reach = middle / math.cos(off)
        free = free_distance(obs, float(b), half_width=half)
        deepest = max(deepest, min(free, 10.0) * math.cos(off))
        if free >= reach + half:
            passing.append((float(b), reach))
    way = passing[len(passing) // 2] if passing else None
    return CabinLook(way, deepest > to_wall + DOORWAY_WALL_M + 0.2)


class Ray(Enum):
    """What one ray of ``opening_samples`` meets at the lift's wall: it sees floor past
    the wall (``THROUGH`` an opening), the wall's face (``WALL``, within ``JAMB_M``: a
    jamb beside an opening), or something nearer (``NEAR``: a person, a cart)."""

    THROUGH = "through"
    WALL = "wall"
    NEAR = "near"


def opening_samples(obs, est: Pose2D, d: Doorway) -> list[tuple[float, Ray]]:
    """Where the frame's rays cross the plane of the lift's wall and what each meets there
    (``Ray``): ``(s, ray)`` per ray, ``s`` metres along the wall from the doorway's centre
    on the estimate ``est`` (the map pose the frame was taken from). Rays more oblique
    than ``DOORS_OBLIQUE`` are left out; none without depth."""
    if obs.depth is None:
        return []
    k = obs.intrinsics
    u = np.asarray(d.into, float)
    along = np.array([-u[1], u[0]])
    to_wall = float(np.dot(np.subtract(d.centre, (est.x, est.y)), u))
    if to_wall <= 0.0:
        return []
    half_fov = math.atan2(k.cx, k.fx) - SCAN_STEP
    out = []
    for b in np.arange(-half_fov, half_fov + 1e-9, SCAN_STEP / 2.0):
        yaw = est.yaw + float(b)
        off = wrap_angle(yaw - d.yaw_in)
        if abs(off) >= DOORS_OBLIQUE:
            continue
        reach = to_wall / math.cos(off)  # along the ray to the wall's near face
        cross = np.array([est.x, est.y]) + reach * np.array([math.cos(yaw), math.sin(yaw)])
        s = float(np.dot(cross - np.asarray(d.centre), along))
        deep = free_distance(obs, float(b), half_width=0.02) * math.cos(off)
        if deep >= to_wall + DOORWAY_WALL_M + PAST_WALL_M:
            out.append((s, Ray.THROUGH))
        else:
            out.append((s, Ray.WALL if deep >= to_wall - JAMB_M else Ray.NEAR))
    return out


def doors_along(samples: list[tuple[float, Ray]], s_robot: float, width: float) -> float | None:
    """Where along the wall (m from where the estimate puts the doorway's centre) the open
    doorway is, from the rays of ``opening_samples`` (several frames together), or None
    when no doorway is seen within ``DOORS_SHIFT_M``. ``s_robot``: the robot's own place
    along the wall, ``width``: the doorway's.

    An opening is a run of rays, in order along the wall, that all see through. Its edge
    is a jamb where the ray beside it meets the wall; where it meets something nearer,
    someone stands before the opening and hides where it ends. Seen from aside, the near
    jamb is sharp but the far one is hidden by the cabin's side (a ray at 70 degrees
    enters only a metre deep): the doorway's middle is then half its ``width`` beyond the
    near jamb. Seen from in front of it, both jambs are: their middle. An opening whose
    jambs are hidden says nothing."""
    ordered = sorted(samples, key=lambda sr: sr[0])
    runs: list[tuple[int, int]] = []  # first and last index of each run of THROUGH rays
    for i, (_, ray) in enumerate(ordered):
        if ray is not Ray.THROUGH:
            continue
        if runs and runs[-1][1] == i - 1:
            runs[-1] = (runs[-1][0], i)
        else:
            runs.append((i, i))

    def jamb(j: int) -> bool:
        return 0 <= j < len(ordered) and ordered[j][1] is Ray.WALL

    best = None
    for i, j in runs:
        lo, hi = ordered[i][0], ordered[j][0]
        if not DOORS_MIN_RUN_M <= hi - lo <= width + DOORS_WIDER_M:
            continue
        if lo > s_robot and jamb(i - 1):  # the doorway is on ahead along the wall
            middle = lo + width / 2.0
        elif hi < s_robot and jamb(j + 1):
            middle = hi - width / 2.0
        elif lo <= s_robot <= hi and jamb(i - 1) and jamb(j + 1):
            middle = (lo + hi) / 2.0
        else:
            continue
        if abs(middle) <= DOORS_SHIFT_M and (best is None or abs(middle) < abs(best)):
            best = middle
    return best


class FindDoors(PmNavBehaviour):
    """The lift says its doors are open here: find the doorway with depth and put the
    estimate where the doorway says. It looks straight at the doors (the robot stands at
    the lobby point on its estimate); unless that frame shows the whole opening, turned
    ``DOORS_ASIDE`` to either side too. The rays through an opening (``opening_samples``,
    ``doors_along``) say where the doorway is along the wall; the map places it exactly,
    so the estimate is moved along the wall by the difference (the across-wall distance
    it already had from the walls). The leg found the lift by its plate, which hangs a
    metre or two beside the doors, so the estimate may be off by that much along the wall:
    the doors then stand aside of the lobby point, out of the straight look. The next leaf
    (``ToLobby`` again) drives to the lobby point on the corrected estimate.

    SUCCESS in any case (no opening seen: someone may stand before the doors, which
    ``CabinHasRoom`` waits for). Each frame is judged in the worker.

    Reads ``map_T_odom``, ``pose_tracker``; writes ``map_T_odom``, ``pose_tracker``."""

    READS = ("map_T_odom", "pose_tracker")
    WRITES = ("map_T_odom", "pose_tracker")
    JOBS = ("_job",)
    STOPS_BASE = True

    def __init__(self, name: str, ctx: Context, ride: Ride):
        super().__init__(name, ctx)
        self.ride = ride

    def initialise(self) -> None:
        self._turns = [0.0, DOORS_ASIDE, -DOORS_ASIDE]
        self._samples: list[tuple[float, Ray]] = []
        self._job = None

    def update(self) -> Status:
        d, tf = self.ride.board, self.get("map_T_odom")
        if tf is None:
            return Status.SUCCESS
        if self._job is None:
            est = map_pose(tf, self.ctx.base.pose())
            if not self.face(wrap_angle(d.yaw_in + self._turns[0]), est):
                return Status.RUNNING
            base = self.ctx.base

            def look(cancelled):
                obs = base.observe()
                return opening_samples(obs, map_pose(tf, obs.pose), d)

            self._job = self.ctx.worker.submit(look)
            return Status.RUNNING
        status, samples = self.poll(self._job, "looking for the lift's doors")
        if status is not None:
            return status
        self._job = None
        first = self._turns.pop(0) == 0.0
        self._samples += samples
        if first and not _whole_opening(samples, d.width):
            return Status.RUNNING  # and look aside
        if self._turns and not first:
            return Status.RUNNING
        return self._correct(tf)

    def _correct(self, tf) -> Status:
        d, r = self.ride.board, self.ride
        u = np.asarray(d.into, float)
        along = np.array([-u[1], u[0]])
        est = map_pose(tf, self.ctx.base.pose())
        s_robot = float(np.dot(np.subtract((est.x, est.y), d.centre), along))
        shift = doors_along(self._samples, s_robot, d.width)
        if shift is None:
            self.feedback_message = f"no open doorway of {r.name} seen"
            return Status.SUCCESS
        moved = (tf[0] - shift * along[0], tf[1] - shift * along[1], tf[2])
        self.bb.set("map_T_odom", moved)
        tracker = self.get("pose_tracker")
        if tracker is not None:
            tracker.reset(moved, 0.0, self.ctx.odometer.distance)
            self.bb.set("pose_tracker", tracker)
        self.ctx.log("lift_doors", r.lift, shift=shift)
        self.feedback_message = f"the doors of {r.name} {shift:+.2f} m along the wall"
        return Status.SUCCESS


def _whole_opening(samples: list[tuple[float, Ray]], width: float) -> bool:
    """Whether one frame's rays show an opening with the wall on both sides, as wide as
    half a doorway at least (the straight look at doors where the estimate has them)."""
    if len(samples) < 3 or samples[0][1] is not Ray.WALL or samples[-1][1] is not Ray.WALL:
        return False
    through = [s for s, ray in samples if ray is Ray.THROUGH]
    return bool(through) and max(through) - min(through) >= width / 2.0


class CabinHasRoom(PmNavBehaviour):
    """Look into the open cabin (``look_into_cabin``): SUCCESS with a way in, written to
    ``cabin_way``; FAILURE (LIFT_FULL) when depth sees into the cabin but no way to its
    middle, counting the full cabins of this ride in ``lift_full_seen`` and saying how many
    of ``tries`` are spent. When no open doorway is in view, someone may stand between the
    robot and the doors: it waits ``CABIN_LOOK_AGAIN_S`` and looks again, ``CABIN_LOOKS``
    looks in all, before FAILURE (TARGET_NOT_FOUND: the robot is not in front of the
    doors, its estimate is off). Each frame is taken and judged in the worker.

    Reads and writes ``lift_full_seen``; reads ``map_T_odom``; writes ``cabin_way``."""

    READS = ("lift_full_seen", "map_T_odom")
    WRITES = ("lift_full_seen", "cabin_way")
    JOBS = ("_job",)

    def __init__(self, name: str, ctx: Context, ride: Ride, tries: int):
        super().__init__(name, ctx)
        self.ride, self.tries = ride, tries

    def initialise(self) -> None:
        self._looks = 0
        self._look()

    def _look(self) -> None:
        base, tf, d = self.ctx.base, self.get("map_T_odom"), self.ride.board

        def look(cancelled):
            obs = base.observe()
            return look_into_cabin(obs, map_pose(tf, obs.pose), d)

        self._looks += 1
        self._again_at = None
        self._job = self.ctx.worker.submit(look)

    def update(self) -> Status:
        r = self.ride
        if self._again_at is not None:
            if self.ctx.now() < self._again_at:
                return Status.RUNNING
            self._look()
        status, look = self.poll(self._job, "looking into the lift")
        if status is not None:
            return status
        if look.way is not None:
            self.bb.set("cabin_way", look.way)
            b, m = look.way
            self.feedback_message = f"room in {r.name}: {m:.1f} m in at {math.degrees(b):+.0f} deg"
            return Status.SUCCESS
        if not look.beyond and self._looks < CABIN_LOOKS:
            self._job, self._again_at = None, self.ctx.now() + CABIN_LOOK_AGAIN_S
            self.ctx.log("lift_door_hidden", r.lift, looks=self._looks)
            self.feedback_message = (
                f"no open door of {r.name} in view ({self._looks} of {CABIN_LOOKS} looks): "
                "someone in the way? looking again"
            )
            return Status.RUNNING
        if not look.beyond:
            return self.fail(
                FailureCode.TARGET_NOT_FOUND,
                f"no open door of {r.name} in view at its lobby on level {r.from_level} in "
                f"{CABIN_LOOKS} looks, though the lift says it is open",
            )
        seen = (self.get("lift_full_seen") or 0) + 1
        self.bb.set("lift_full_seen", seen)
        self.ctx.log("lift_full", r.lift, times=seen)
        return self.fail(
            FailureCode.LIFT_FULL,
            f"{r.name} came full to level {r.from_level} ({seen} of {self.tries} times: "
            "no room in it for the robot)",
        )


class BoardingBegins(PmNavBehaviour):
    """A boarding of the lift begins (call, wait, find the doors, look in): note the actions
    spent so far (``boarding_actions``), for ``BoardAgainAllowed``. SUCCESS.

    Writes ``boarding_actions``."""

    WRITES = ("boarding_actions",)

    def update(self) -> Status:
        self.bb.set("boarding_actions", self.ctx.odometer.actions)
        return Status.SUCCESS


class BoardAgainAllowed(PmNavBehaviour):
    """The lift came full and was let go: the boarding just made must be made again. An
    episode's budget allows each ride one boarding (``RIDE_ACTIONS``); a lift full when
    it comes is the building's delay, as its call delay is, so the actions this boarding
    spent (since ``BoardingBegins``: turning to find the doors, stepping before them) are
    added to the budget (``actions_granted``, which the Monitor adds to the context's
    budget). Measured, not a constant: a boarding costs what the doors' place made it
    cost. SUCCESS.

    Reads ``boarding_actions``, ``actions_granted``; writes ``actions_granted``."""

    READS = ("boarding_actions", "actions_granted")
    WRITES = ("actions_granted",)

    def update(self) -> Status:
        began = self.get("boarding_actions")
        spent = max(0, self.ctx.odometer.actions - began) if began is not None else 0
        granted = (self.get("actions_granted") or 0) + spent
        self.bb.set("actions_granted", granted)
        self.ctx.log("budget_granted", "", actions=spent, granted=granted)
        self.feedback_message = f"{spent} actions of a boarding let go added to the budget"
        return Status.SUCCESS


class SeeItLeave(_WaitsOnLift):
    """After letting a full lift go: wait, stopped, until the lift says its door at the
    ride's first level is shut (it is leaving with its load, or gone). A call while that
    door still stands open, or is closing, is answered as a lift answers it: the doors
    open again on the same full cabin; only a call after they shut is answered by the
    lift's next arrival. SUCCESS once shut, or after ``limit_s`` (a lift held open by
    others: call it anyway)."""

    def __init__(self, name: str, ctx: Context, lift: Lift, ride: Ride, limit_s: float):
        super().__init__(name, ctx, lift, ride)
        self.limit_s = limit_s

    def update(self) -> Status:
        st, waited = self.watch()
        here = st is not None and st.current_level == self.ride.from_level
        if not here or st.door == LiftDoor.CLOSED or waited >= self.limit_s:
            self.ctx.log("lift_gone", self.ride.lift, waited=waited, shut=not here or (
                st.door == LiftDoor.CLOSED))
            self.feedback_message = f"{self.ride.name} let go after {waited:.0f} s"
            return Status.SUCCESS
        self.feedback_message = f"letting the full {self.ride.name} leave ({waited:.0f} s)"
        return Status.RUNNING


class ReleaseLift(PmNavBehaviour):
    """End the ride's session with the lift system (others may use the lift). SUCCESS."""

    def __init__(self, name: str, ctx: Context, lift: Lift, ride: Ride):
        super().__init__(name, ctx)
        self.lift, self.ride = lift, ride

    def update(self) -> Status:
        self.lift.release(self.ride.lift, self.ride.session)
        self.ctx.log("lift_release", self.ride.lift)
        return Status.SUCCESS


class DriveThrough(PmNavBehaviour):
    """Drive ``distance`` m on odometry at ``DOORWAY_SPEED``, through the lift's doorway:
    in, along the way ``CabinHasRoom`` found (``cabin_way``: its bearing and distance),
    else straight ahead; out, straight ahead back to the lobby. FAILURE (BLOCKED) when the
    body stops against something or the drive takes longer than ``DOORWAY_TIMEOUT_S``.

    Reads ``cabin_way`` (with ``way=True``)."""

    READS = ("cabin_way",)
    STOPS_BASE = True

    def __init__(
        self, name: str, ctx: Context, ride: Ride, distance: float, where: str, way: bool = False
    ):
        super().__init__(name, ctx)
        self.ride, self.distance, self.where, self.way = ride, distance, where, way

    def initialise(self) -> None:
        p = self.ctx.base.pose()
        bearing, distance = 0.0, self.distance
        if self.way and self.get("cabin_way") is not None:
            bearing, distance = self.get("cabin_way")
        self._goal = (
            p.x + distance * math.cos(p.yaw + bearing),
            p.y + distance * math.sin(p.yaw + bearing),
        )
        self._t0 = self.ctx.now()
        self._sent = False

    def update(self) -> Status:
        base = self.ctx.base
        if self._sent and base.motion_status() == MotionStatus.BLOCKED:
            return self._blocked("stopped against something")
        if self.ctx.now() - self._t0 > DOORWAY_TIMEOUT_S:
            base.stop()
            return self._blocked(f"not through after {DOORWAY_TIMEOUT_S:.0f} s")
        v, w, done = goto_command(base.pose(), *self._goal, self.ctx.limits, tol=0.05)
        if done:
            base.stop()
            self.feedback_message = f"{self.where} {self.ride.name}"
            return Status.SUCCESS
        base.set_velocity(min(v, DOORWAY_SPEED), w)
        self._sent = True
        return Status.RUNNING

    def _blocked(self, why: str) -> Status:
        return self.fail(FailureCode.BLOCKED, f"the doorway of {self.ride.name}: {why}")


def into_cabin(d: Doorway) -> float:
    """From the lobby point to the cabin's middle (m)."""
    return math.dist(d.lobby, d.cabin_centre())


class StartLevel(PmNavBehaviour):
    """The mission starts on ``level``: the blackboard's ``level`` says so from the first
    tick (the node's feedback reports it; ``OnNewLevel`` changes it after each ride)."""

    WRITES = ("level",)

    def __init__(self, name: str, ctx: Context, level: str):
        super().__init__(name, ctx)
        self.level = level

    def update(self) -> Status:
        self.bb.set("level", self.level)
        self.feedback_message = f"level {self.level}"
        return Status.SUCCESS


class OnNewLevel(PmNavBehaviour):
    """The robot stands in the cabin on the ride's far level, turned round. Everything
    of the level left (``OLD_LEVEL_KEYS``: the plan, what was found blocked, the belief) is
    dropped, and the estimate restarts on the new level's map in the cabin
    (``map_T_odom``, with ``ARRIVAL_SIGMA_M`` in ``pose_tracker``): the lift's word,
    which the re-localization then checks against the signs. ``ctx`` is the new level's.

    The lift carries the cabin and the robot in it together: the robot's heading in the
    cabin is the one it had there on the level left (``arrival_pose``), not the doors'
    (it drove in along the way depth found, up to 27 degrees aside, and turned round on
    odometry); its place is the cabin's middle, where it drove to.

    Reads ``map_T_odom`` (the old level's, before it is replaced). Writes ``level``,
    ``map_T_odom``, ``pose_tracker``, ``recent_sightings``, ``lift_full_seen`` and every
    key of ``OLD_LEVEL_KEYS`` (cleared)."""

    READS = ("map_T_odom",)
    WRITES = (
        "level", "map_T_odom", "pose_tracker", "recent_sightings", "lift_full_seen",
        *OLD_LEVEL_KEYS,
    )  # fmt: skip

    def __init__(self, name: str, ctx: Context, ride: Ride):
        super().__init__(name, ctx)
        self.ride = ride

    def update(self) -> Status:
        odom = self.ctx.base.pose()
        cabin = arrival_pose(self.ride, self.get("map_T_odom"), odom)
        for key in OLD_LEVEL_KEYS:
            self.bb.set(key, None)
        forget_stale_sightings(self)
        tf = se2_compose(
            (cabin.x, cabin.y, cabin.yaw), se2_inverse((odom.x, odom.y, odom.yaw))
        )
        self.bb.set("map_T_odom", tf)
        self.bb.set(
            "pose_tracker",
            PoseTracker(
                map_T_odom=tf, sigma0=ARRIVAL_SIGMA_M, odometer0=self.ctx.odometer.distance
            ),
        )
        self.bb.set("level", self.ride.to_level)
        self.bb.set("lift_full_seen", 0)
        self.ctx.log("level", self.ride.to_level, lift=self.ride.lift, map_pose=[cabin.x, cabin.y])
        self.feedback_message = f"level {self.ride.to_level}, in {self.ride.name}"
        return Status.SUCCESS


def arrival_pose(ride: Ride, old_map_T_odom, odom: Pose2D) -> Pose2D:
    """The robot's map pose on the ride's far level: the middle of the cabin there, heading
    as it was in the cabin on the level left (its estimate there, ``old_map_T_odom`` of
    the odometry pose ``odom``, turned from the first level's cabin to the second's);
    facing the doors when there was no estimate."""
    out = ride.alight.cabin_pose()
    if old_map_T_odom is None:
        return out
    was = wrap_angle(old_map_T_odom[2] + odom.yaw)
    return Pose2D(out.x, out.y, wrap_angle(was - ride.board.cabin_pose().yaw + out.yaw))


class LiftWordStands(PmNavBehaviour):
    """After the arrival look, when the belief cannot sharpen the estimate (one plate
    read, a lift's own plate a metre or two from its point, is too loose for a fix) but
    agrees with it: ``FIX_MASS`` of the belief lies in one place (a cluster,
    ``CLUSTER_M``) about where the lift's word puts the robot. What was read places the
    robot no better than that; the ride (the cabin's middle, a drive out on odometry)
    places it to a few tenths. So the estimate stands as the ride gave it (``OnNewLevel``)
    and the belief is dropped: looking round again and driving to read more, as a robot
    lost must, spends actions on what the lift already told. FAILURE when the belief does
    not agree (something is odd: the localization subtree then looks further).

    Reads ``belief``, ``map_T_odom``; writes ``belief``."""

    READS = ("belief", "map_T_odom")
    WRITES = ("belief",)

    def update(self) -> Status:
        belief, tf = self.get("belief"), self.get("map_T_odom")
        if belief is None or belief.ref is None or tf is None:
            return Status.FAILURE
        est = se2_apply(tf, belief.ref.xy())  # both at the belief's reference
        off = np.linalg.norm(belief.xy - est, axis=1)
        share = float(belief.weights()[off <= CLUSTER_M].sum())
        if share < FIX_MASS:
            self.feedback_message = (
                f"{share:.0%} of the belief within {CLUSTER_M:.0f} m of the lift's word"
            )
            return Status.FAILURE
        self.bb.set("belief", None)
        est_x, est_y = (float(v) for v in se2_apply(tf, self.ctx.base.pose().xy()))
        self.ctx.log("fix", "the lift's word", map_pose=[est_x, est_y], share=share)
        self.feedback_message = f"at ({est_x:.1f}, {est_y:.1f}): the lift's word stands"
        return Status.SUCCESS


def sign_key(text: str) -> str:
    """A sign's text as compared across levels: letters and digits, case folded."""
    return re.sub(r"[^0-9a-z]+", "", text.casefold())


def level_signs(levels: Mapping[str, Building]) -> dict[str, frozenset[str]]:
    """Each level's sign texts (``sign_key``) that no other level has: the ones that tell
    the levels apart (a "Toilets" plate on every floor tells nothing)."""
    texts = {
        name: frozenset(
            sign_key(t)
            for t in [r.sign_text for r in b.rooms] + [lm.sign_text for lm in b.landmarks]
            if sign_key(t)
        )
        for name, b in levels.items()
    }
    return {
        name: own - frozenset().union(*(t for n, t in texts.items() if n != name))
        for name, own in texts.items()
    }


class CheckLevel(PmNavBehaviour):
    """The signs read on arrival (the panorama in ``views``) belong to the level the lift
    was asked for: FAILURE (WRONG_LEVEL) when at least ``WRONG_LEVEL_SIGNS`` of them, and
    more than of the level asked, are signs only another level has (``level_signs``, by
    their text). SUCCESS otherwise, also when nothing telling was read. Reads ``views``."""

    READS = ("views",)

    def __init__(self, name: str, ctx: Context, ride: Ride, levels: Mapping[str, Building]):
        super().__init__(name, ctx)
        self.ride = ride
        self.own = level_signs(levels)

    def update(self) -> Status:
        read = {
            d.label
            for v in self.get("views") or []
            for d in v.detections or ()
            if sign_key(d.label)
        }
        count = {
            level: sorted(t for t in read if sign_key(t) in own) for level, own in self.own.items()
        }
        here = len(count.get(self.ride.to_level, ()))
        level, texts = max(
            ((n, t) for n, t in count.items() if n != self.ride.to_level),
            key=lambda nt: len(nt[1]),
            default=(None, []),
        )
        if level is not None and len(texts) >= WRONG_LEVEL_SIGNS and len(texts) > here:
            shown = ", ".join(f'"{t}"' for t in texts[:3])
            return self.fail(
                FailureCode.WRONG_LEVEL,
                f"{self.ride.name} stopped at the wrong floor: the signs read on leaving it "
                f"({shown}) are level {level}'s, not level {self.ride.to_level}'s",
            )
        self.feedback_message = f"{here} sign(s) of level {self.ride.to_level} read"
        return Status.SUCCESS
