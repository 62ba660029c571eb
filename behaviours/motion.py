"""Motion leaves: approach a seen target, drive to an unseen turn or fork, turn, arrive.

All drive on the estimated map pose (``map_T_odom`` composed with odometry) with
velocity commands, and watch for obstacles: the base reporting a collision, no
progress for a while, or depth showing something on the floor ahead. A drive that
sees something in its way stops and holds (``pmnav_bt/way_ahead.py``): it goes on when
the way clears, drives round what stood still with open floor beside it (a pillar, a
trolley on the centre line; ``detour``), waits for what moves (a person) up to a
patience and passes it where there is room, and gives up only on what keeps the way
shut, saying where in the building's words (``pmnav_bt/map/wording.py``). A drive that
touches something (what the camera, 1.6 m up, no longer sees near the body) stops
pushing, marks it, backs off away from it and goes round it (``pmnav_bt/contact.py``);
each touch counts once, however long the body reports BLOCKED.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from py_trees.common import Status

from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context, heading_error, map_pose
from pmnav_bt.behaviours.pose import axis_correction, keep_on_axis, measure_walls
from pmnav_bt.contact import BackOff, Contact, as_bump, felt_contact, round_contact, way_clear
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import (
    Action,
    heading,
    point_towards,
    se2_apply,
    se2_inverse,
    wrap_angle,
)
from pmnav_bt.hazards import body_hazards
from pmnav_bt.map.wording import shut_way_words
from pmnav_bt.perception.corner import band_reach, is_corner, is_open_way, mask_ratios
from pmnav_bt.perception.geometry import free_distance
from pmnav_bt.perception.movers import moved
from pmnav_bt.pose.visibility import Visibility
from pmnav_bt.seams import CREATE3_RADIUS_M, MotionStatus
from pmnav_bt.tree_variants import DetourCheck
from pmnav_bt.way_ahead import Hold, Verdict, WayShut, judge

NO_PROGRESS_S = 10.0  # clock seconds without getting 0.1 m closer -> blocked
WATCH_PERIOD_S = 1.0  # clock seconds between obstacle checks from depth
MAX_CONTACTS = 3  # touches (events, each backed off from) before a drive gives up
ROUND_WALL_MARGIN_M = CREATE3_RADIUS_M + 0.1  # a step aside keeps this off the map's walls
# A waypoint with a wall just past it is reached when depth shows that wall within half a
# corridor width and this margin, the estimate at most this far from the waypoint.
WALL_ARRIVAL_MARGIN_M = 0.4
WALL_ARRIVAL_NEAR_M = 3.0
# ... and that wall spans the way: depth this far either side of the way shows it too (a
# wall across a corridor fills the view; someone standing 1.1 m ahead, half a metre
# wide, covers 13 degrees either side of the way and leaves the wall beyond in view).
WALL_ACROSS = math.radians(20.0)
# Depth is checked this far ahead: a 1 m box leaves the 1.6 m camera's view 1.4 m away.
OBSTACLE_RANGE = 2.0
# Round an obstacle: the nearest bearing off the way to the goal (either side, in view)
# along which the floor is free DETOUR_PAST_M beyond the obstacle's near face (and a
# margin), to a point that far past it, clear of the walls the tree variant knows (PM-Nav:
# inside the map's corridors, Context.detour_check); at most MAX_DETOURS
# a drive (each watched like the drive: another obstacle, another detour).
DETOUR_BEARINGS = tuple(math.radians(a) for a in (10.0, 15.0, 20.0, 25.0, 30.0))
DETOUR_PAST_M = 0.6
DETOUR_MARGIN_M = 0.3
DETOUR_HALF_WIDTH_M = 0.25  # the floor kept free either side of a detour's line
DETOUR_VIEW_MARGIN = math.radians(5.0)  # a bearing this close to the image border is not seen
MAX_DETOURS = 2
# A goal where the body would stand this near what the costmap holds (its radius and a
# costmap cell) is reached this far short of it: stop there rather than push on.
GOAL_TAKEN_M = CREATE3_RADIUS_M + 0.05
STOP_SHORT_M = 0.3
MOVER_REACH_M = 0.5  # what moved this far beyond the thing in the way counts (it stepped back)
# Something that moves (a person) is passed this much wider and farther than clutter: a
# person steps and turns (0.3 m of personal space), and is never brushed past.
PERSON_SPACE_M = 0.3
# The opening check looks this far along the map's floor (beyond what the band can show).
FLOOR_RUN_MOST_M = 10.0
# A way the opening check finds shut is looked at again, this many looks in all this many
# clock seconds apart, before the turn or fork is given up: people walk the corridors'
# centre lines and cut across junctions and lobbies, and someone crossing (1 m/s) clears
# the view in two seconds, or stands still (the drive that follows waits for them). A
# wall where the map has the way shows the same in every look. Waiting costs no action.
OPENING_LOOKS = 3
OPENING_LOOK_AGAIN_S = 3.0


class DriveTo(PmNavBehaviour):
    """Drive to a map point; subclasses choose the point and may refine it on the way.

    Every watch frame's corridor wall keeps the estimate's heading and position across
    the corridor true (``keep_on_axis``). Something in the way closer than the goal
    stops the drive and holds it (``way_ahead.judge``: go on, go round, wait, give up).
    Reads ``map_T_odom``, ``target``; writes ``map_T_odom``, ``pose_tracker``,
    ``way_shut`` (a ``WayShut`` when it gave up on a shut way, else None). The way is
    kept clear of what the steering's costmap holds (a point round it,
    ``Steering.way_round``); a goal that stands against it is reached ``STOP_SHORT_M``
    short. A touch
    (the base reports BLOCKED) is one contact: the drive stops, marks it, backs off from
    it and goes round it. FAILURE: BLOCKED on the ``MAX_CONTACTS``-th contact, no
    progress, or a way that stayed shut for the patience; DOOR_CLOSED when what shut it
    stands where the map has a fire door.
    """

    READS = ("map_T_odom", "target", "plan", "pose_tracker")
    WRITES = ("map_T_odom", "pose_tracker", "way_shut")
    JOBS = ("_watch_job",)
    STOPS_BASE = True

    def goal(self) -> tuple[float, float]:
        raise NotImplementedError

    def inspect(self, obs, est, target) -> dict:
        """Extra analysis of a watch frame, in the worker (no blackboard access here)."""
        return {}

    def on_watch(self, found: dict, obs) -> None:
        """Use what ``inspect`` found, in the tick (cheap)."""

    def arrived_at_wall(self, free: float) -> bool:
        """Whether a wall ``free`` m ahead, closer than the goal, means the goal is reached
        (the waypoint lies just before that wall) rather than that the way is blocked."""
        return False

    def initialise(self) -> None:
        self._goal = self.goal()
        self._progress_afresh()
        self._contacts = 0
        self._backing: tuple[BackOff, Contact] | None = None  # backing off a contact
        self._watch_job = None
        self._watch_t = -math.inf
        self._felt_t = -math.inf  # hazards the body felt since then go to the steering
        self._detour: tuple[float, float] | None = None  # a point round an obstacle
        self._detours = 0
        self._round: tuple[float, float] | None = None  # odometry: round what the costmap holds
        self._hold: Hold | None = None  # stopped for something in the way
        self._last_frame = None  # the last watch frame (what moved since)
        self.bb.set("way_shut", None)

    def aim_at(self, goal: tuple[float, float]) -> None:
        """Drive to ``goal`` from here on, progress watched afresh (a route's next leg)."""
        self._goal = goal
        self._progress_afresh()
        self._contacts = 0

    def _progress_afresh(self) -> None:
        """Watch the progress towards a new aim from now on (``NO_PROGRESS_S``)."""
        self._best, self._best_t = math.inf, self.ctx.now()

    def _aim(self) -> tuple[float, float]:
        """Where the drive heads now: round an obstacle first, then the goal."""
        return self._goal if self._detour is None else self._detour

    def estimate(self):
        return map_pose(self.get("map_T_odom"), self.ctx.base.pose())

    def update(self) -> Status:
        base, now = self.ctx.base, self.ctx.now()
        st = base.motion_status()
        if st == MotionStatus.FAULT:
            return self.fail(FailureCode.BASE_FAULT, "the base reports a fault")
        if self._backing is not None:
            return self._back_off(now, st == MotionStatus.BLOCKED)
        if st == MotionStatus.BLOCKED:
            return self._touched(now)
        watched = self._poll_watch(now)
        if watched is not None:
            base.stop()
            return watched
        if self._hold is not None:  # stopped until the way ahead is judged again
            base.set_velocity(0.0, 0.0)
            return Status.RUNNING
        est = self.estimate()
        aim = self._aim()
        dist = math.hypot(aim[0] - est.x, aim[1] - est.y)
        if self._detour is None and dist <= STOP_SHORT_M and self._goal_taken(aim):
            base.set_velocity(0.0, 0.0)
            self.ctx.log("stopped_short", "", to_go=dist)
            self.feedback_message = f"stopped {dist:.2f} m short: something stands at the goal"
            return Status.SUCCESS
        if dist < self._best - 0.1:
            self._best, self._best_t = dist, now
        elif now - self._best_t > NO_PROGRESS_S:
            base.stop()
            return self.fail(FailureCode.BLOCKED, f"no progress for {NO_PROGRESS_S:.0f} s")
        tf, limits = self.get("map_T_odom"), self.ctx.limits
        v, w, done = self.ctx.steering.command(est, base.pose(), aim, tf, limits, now)
        if done and self._detour is not None:  # past the obstacle: on to the goal
            self._detour = self._round = None
            self._progress_afresh()
            return Status.RUNNING
        if done:
            base.set_velocity(0.0, 0.0)
            return Status.SUCCESS
        base.set_velocity(v, w)
        self.feedback_message = f"{dist:.1f} m to go" + (
            " round an obstacle" if self._detour else ""
        )
        return Status.RUNNING

    def _goal_taken(self, aim: tuple[float, float]) -> bool:
        """Whether the body at ``aim`` (map) would stand within the lethal distance of what
        the steering's costmap holds (the goal drawn against a wall or an item the map
        does not know, or placed there by a pose estimate off by that much)."""
        tf = self.get("map_T_odom") or (0.0, 0.0, 0.0)
        p = se2_apply(se2_inverse(tf), aim)
        return self.ctx.steering.clearance(float(p[0]), float(p[1])) < GOAL_TAKEN_M

    def _touched(self, now: float) -> Status:
        """The body touched something: one contact. Stop, mark it for the steering, and
        back off from it (FAILURE, BLOCKED, on the ``MAX_CONTACTS``-th)."""
        base, steer = self.ctx.base, self.ctx.steering
        base.stop()
        contact = felt_contact(base, now)
        self._contacts += 1
        self.ctx.log("contact", "", x=contact.point[0], y=contact.point[1], n=self._contacts)
        if self._contacts >= MAX_CONTACTS:
            return self.fail(FailureCode.BLOCKED, f"{self._contacts} collisions on the way")
        pose = base.pose()
        steer.feel([as_bump(contact)], pose, now)  # the item
        self._backing = (BackOff(contact.point, pose, now, clearance=steer.clearance), contact)
        self._hold = None
        self.feedback_message = f"backing off: {contact.words}"
        return Status.RUNNING

    def _back_off(self, now: float, blocked: bool) -> Status:
        """Back off the contact; then go round it (``round_contact``: inside what the
        variant knows of the walls, its way clear of what the steering's costmap holds),
        or on as before where there is no way round (the next touch counts)."""
        base, steer = self.ctx.base, self.ctx.steering
        backing, contact = self._backing
        v, w, done = backing.command(base.pose(), blocked, now)
        if not done:
            base.set_velocity(v, w)
            return Status.RUNNING
        base.stop()
        self._backing = None
        odom = base.pose()
        tf = self.get("map_T_odom") or (0.0, 0.0, 0.0)
        goal = tuple(se2_apply(se2_inverse(tf), self._goal))
        inside = inside_walls(tf, self.ctx.detour_check)
        point = round_contact(odom, contact.point, goal, steer.clearance, inside)
        self.ctx.log(
            "backed_off", "", moved=backing.moved, why=backing.why,
            round=None if point is None else list(point),
        )  # fmt: skip
        if point is not None:
            m = se2_apply(tf, point)
            self._detour, self._round = (float(m[0]), float(m[1])), None
        self._progress_afresh()
        return Status.RUNNING

    def _poll_watch(self, now: float) -> Status | None:
        """Start or collect a depth check of the way ahead; FAILURE when blocked (BLOCKED)
        or when the frame or its analysis failed (its code, e.g. SENSOR_TIMEOUT).

        The frame is taken and analysed in the worker; the tick only reads the verdict.
        """
        if self._watch_job is None:
            if now - self._watch_t >= WATCH_PERIOD_S:
                self._watch_t = now
                base, goal, target = self.ctx.base, self._aim(), self.get("target")
                tf, clear, steer = self.get("map_T_odom"), self.ctx.detour_check, self.ctx.steering
                before, felt_since = self._last_frame, self._felt_t
                self._felt_t = now
                moving = self._hold is not None and self._hold.moving
                # A way round what the costmap holds is judged towards the goal (or a
                # depth detour in force), keeping the one in force while it serves.
                toward = self._goal if self._round is not None else goal
                round_from, inside = self._round, inside_walls(tf, clear)

                def watch(cancelled):
                    obs = base.observe()  # into the steering's costmap (Context)
                    steer.feel(body_hazards(base, since=felt_since), obs.pose, now)
                    est = map_pose(tf, obs.pose)
                    found = self.inspect(obs, est, target)
                    found["walls"] = line = measure_walls(self.ctx.grounder, obs)
                    if line is not None and tf is not None:
                        found["axis"] = axis_correction(
                            self.ctx.pm, tf, obs.pose, line, self.ctx.walls.field
                        )
                    found["ahead"] = ahead = _toward_goal(obs, est, goal)
                    found["wall_across"] = _wall_across(obs, est, goal, ahead)
                    blocked = _closer_than_goal(ahead, est, goal)
                    if blocked is not None and before is not None and steer.movers(before, obs):
                        way = wrap_angle(heading((est.x, est.y), goal) - est.yaw)
                        found["moved"] = moved(before, obs, way, blocked + MOVER_REACH_M)
                    mover = moving or bool(found.get("moved"))
                    blocked = steer.way_shut(obs, tf, goal, blocked, mover)
                    if blocked is not None:
                        space = PERSON_SPACE_M if mover else 0.0
                        found["detour"] = detour(obs, est, goal, blocked, clear, space)
                    elif not steer.plans_round:
                        g = se2_apply(se2_inverse(tf or (0.0, 0.0, 0.0)), toward)
                        g = (float(g[0]), float(g[1]))
                        found["round"] = keep_round(steer, obs.pose, g, inside, round_from)
                    return obs, blocked, found

                self._watch_job = self.ctx.worker.submit(watch)
            return None
        status, watched = self.poll(self._watch_job, "watching the way ahead")
        if status == Status.RUNNING:
            return None
        self._watch_job = None
        if status is not None:
            return status
        obs, free, found = watched
        self._last_frame = obs
        if found.get("walls") is not None:
            keep_on_axis(self, obs.pose, found["walls"], found.get("axis"))
        self.on_watch(found, obs)
        ahead = found.get("ahead")
        if ahead is not None and found["wall_across"] and self.arrived_at_wall(ahead):
            self.feedback_message = f"at the wall beyond the waypoint ({ahead:.1f} m ahead)"
            return Status.SUCCESS
        if free is None:
            self._take_round(found.get("round"))
            if self._hold is not None:
                held = self._hold.held_for(now)
                self.ctx.log("way_clear", "", waited=held)
                self._hold = None
                self._progress_afresh()
            return None
        return self._held_up(now, obs, free, found)

    def _take_round(self, point: tuple[float, float] | None) -> None:
        """Drive by ``point`` (odometry), round what the costmap holds on the way; None:
        the way is clear again (or has no way round): drop the round in force."""
        if point is None:
            if self._round is not None:
                self._round = self._detour = None
                self._progress_afresh()  # on to the goal: progress is measured to it
            return
        if point != self._round:
            tf = self.get("map_T_odom") or (0.0, 0.0, 0.0)
            m = se2_apply(tf, point)
            self._detour = (float(m[0]), float(m[1]))
            self._progress_afresh()
            self.ctx.log("round", "", x=self._detour[0], y=self._detour[1])
        self._round = point

    def _held_up(self, now: float, obs, free: float, found: dict) -> Status | None:
        """Something ``free`` m ahead in the way: hold, and judge what to do
        (``way_ahead.judge``); FAILURE when the way stayed shut."""
        self.ctx.base.stop()
        point = found.get("detour") if self._detours < MAX_DETOURS else None
        if self._hold is None:
            self._hold = Hold(now, free, obs, point, moving=bool(found.get("moved")))
            self.ctx.log("obstacle", "", obs.rgb, free=free, moving=self._hold.moving)
        else:
            self._hold.seen(obs, free, point, found.get("moved"))
        hold = self._hold
        point = hold.room
        verdict = judge(hold, now, clear=False, room_beside=point is not None)
        if verdict == Verdict.WAIT:
            what = "someone moving" if hold.moving else "something"
            self.feedback_message = (
                f"waiting: {what} {free:.1f} m ahead for {hold.held_for(now):.0f} s"
            )
            return None
        if verdict == Verdict.GO_ROUND:
            self._hold = None
            self._round = None
            self._detour, self._detours = point, self._detours + 1
            self._progress_afresh()
            self.ctx.log("detour", "", x=point[0], y=point[1], obstacle=free, moving=hold.moving)
            return None
        return self._give_up(hold, now)

    def _give_up(self, hold: Hold, now: float) -> Status:
        """The way stayed shut for the patience: say where, in the building's words."""
        est = self.estimate()
        aim = self._aim()
        a = heading((est.x, est.y), aim)
        point = (est.x + hold.free * math.cos(a), est.y + hold.free * math.sin(a))
        seconds = hold.held_for(now)
        self.bb.set("way_shut", WayShut(point, seconds, hold.moving))
        self._hold = None
        where, door = shut_way_words(self.ctx.pm, point)
        if hold.moving:
            return self.fail(
                FailureCode.BLOCKED,
                f"someone stayed in the way in {where} for {seconds:.0f} s, "
                f"{hold.free:.1f} m ahead, with no room to pass",
            )
        if door is not None:
            return self.fail(
                FailureCode.DOOR_CLOSED, f"{door} closed ({where}, shut for {seconds:.0f} s)"
            )
        return self.fail(
            FailureCode.BLOCKED,
            f"{where} blocked for {seconds:.0f} s ({hold.free:.1f} m ahead)",
        )


def inside_walls(tf, walls: DetourCheck | None) -> Callable[[tuple[float, float]], bool]:
    """Whether an odometry point lies inside what the tree variant knows of the walls
    (``walls``, PM-Nav: the map's corridors; None: anywhere), ``ROUND_WALL_MARGIN_M`` off
    them, ``tf`` (map_T_odom) placing it on the map."""
    tf = tf or (0.0, 0.0, 0.0)

    def inside(p: tuple[float, float]) -> bool:
        m = se2_apply(tf, p)
        return walls is None or walls((float(m[0]), float(m[1])), ROUND_WALL_MARGIN_M)

    return inside


def keep_round(steer, pose, goal, inside, current) -> tuple[float, float] | None:
    """The point (odometry) to drive by round what the steering's costmap holds on the
    straight way from ``pose`` to ``goal`` (``Steering.way_round``): ``current``, the one
    in force, while the straight way to it stays clear (a way round chosen anew each
    frame would swing from side to side as the robot turns), else a new one; None when
    the way is clear or has no way round inside the walls."""
    point = steer.way_round(pose, goal, inside)
    if point is None or current is None:
        return point
    return current if way_clear((pose.x, pose.y), current, steer.clearance) else point


def detour(
    obs, est, goal, free: float, clear: DetourCheck | None, space: float = 0.0
) -> tuple[float, float] | None:
    """A map point round an obstacle ``free`` m ahead on the way from ``est`` to ``goal``:
    along the nearest bearing off that way (``DETOUR_BEARINGS``, the more open side first)
    with the floor free ``DETOUR_PAST_M`` beyond the obstacle's near face, that far past it
    and, where the variant knows the walls (``clear``: PM-Nav's map corridors), at least
    ``DETOUR_MARGIN_M`` from them; None when there is none (the corridor is shut).
    ``space``: metres more on each side of the way and beyond (a person's space)."""
    way = wrap_angle(heading((est.x, est.y), goal) - est.yaw)
    in_view = abs(obs.intrinsics.pixel_bearing(0.0)) - DETOUR_VIEW_MARGIN
    past = free + DETOUR_PAST_M + space
    for off in DETOUR_BEARINGS:
        reach = past / math.cos(off)
        sides = []
        for b in (way + off, way - off):
            if abs(b) > in_view:
                continue
            open_m = free_distance(obs, b, half_width=DETOUR_HALF_WIDTH_M + space)
            if open_m >= reach + DETOUR_MARGIN_M:
                sides.append((open_m, b))
        for _, b in sorted(sides, reverse=True):
            a = est.yaw + b
            p = (est.x + reach * math.cos(a), est.y + reach * math.sin(a))
            if clear is None or clear(p, DETOUR_MARGIN_M):
                return float(p[0]), float(p[1])
    return None


def _toward_goal(obs, est, goal) -> float | None:
    """The free distance (depth) towards ``goal``; None while still turning towards it."""
    bearing = heading((est.x, est.y), goal) - est.yaw
    if abs(wrap_angle(bearing)) > math.radians(25):
        return None  # still turning towards the goal: nothing to judge yet
    return free_distance(obs, bearing)


def _wall_across(obs, est, goal, ahead: float | None) -> bool:
    """Whether what stands ``ahead`` m towards ``goal`` spans the way as a wall does:
    depth along thin rays ``WALL_ACROSS`` either side of the way stops no farther than
    the plane there."""
    if ahead is None:
        return False
    bearing = heading((est.x, est.y), goal) - est.yaw
    return all(
        free_distance(obs, bearing + side, half_width=0.05) * math.cos(side)
        <= ahead + WALL_ARRIVAL_MARGIN_M
        for side in (-WALL_ACROSS, WALL_ACROSS)
    )


def _closer_than_goal(free: float | None, est, goal) -> float | None:
    """``free`` (the free distance towards ``goal``) when something stands closer than the
    goal, else None."""
    to_goal = math.hypot(goal[0] - est.x, goal[1] - est.y)
    return free if free is not None and free < min(to_goal, OBSTACLE_RANGE) - 0.3 else None


class Approach(DriveTo):
    """Approach the seen target: the goal room to ``goal_offset`` metres from its door;
    any other landmark to its node on the corridor centre line, abeam of it (desks and
    lift lobbies stand out from the wall; the centre line is always clear).

    Reads ``target`` (PlanStep), ``map_T_odom``.
    """

    def goal(self) -> tuple[float, float]:
        t = self.get("target")
        if t.action == Action.ARRIVE:
            return point_towards(t.target, t.position, self.ctx.config.tree.goal_offset)
        return float(t.position[0]), float(t.position[1])


class MoveToward(DriveTo):
    """Move along the way to the target until ``keep`` metres short of it, at most
    ``distance`` metres: into search range before a search, or on towards a target not
    found ("continue to locate the old landmark"). Either may be a function of this
    behaviour (e.g. of the target's sign: how close it must be to be read). Reads
    ``target``, ``map_T_odom``."""

    def __init__(
        self,
        name: str,
        ctx: Context,
        keep: float | Callable[[PmNavBehaviour], float],
        distance: float | Callable[[PmNavBehaviour], float] = math.inf,
    ):
        super().__init__(name, ctx)
        self.keep = keep
        self.distance = distance

    def _metres(self, value: float | Callable[[PmNavBehaviour], float]) -> float:
        return float(value(self) if callable(value) else value)

    def goal(self) -> tuple[float, float]:
        t = self.get("target")
        est = self.estimate()
        d = np.asarray(t.position, float) - (est.x, est.y)
        n = float(np.linalg.norm(d))
        step = max(0.0, min(self._metres(self.distance), n - self._metres(self.keep)))
        if step == 0.0:
            return est.x, est.y
        return float(est.x + d[0] * step / n), float(est.y + d[1] * step / n)


class DriveToWaypoint(DriveTo):
    """Drive to an unseen key waypoint (turn or fork) on the centre line.

    Where the map has a wall straight beyond the waypoint (a turn, or a fork reached
    from the stem of a T), the corner check (wall/floor mask ratio ahead) refines where
    it is: once a wall fills the way ahead, the waypoint is half a corridor width before
    it (after a long leg on dead reckoning the estimate may be a metre or two behind;
    by the map alone the drive would end against that wall). Reads ``target``,
    ``map_T_odom``.
    """

    def goal(self) -> tuple[float, float]:
        t = self.get("target")
        self._corner_seen = False
        self._wall_beyond = t.kind == "turn" or wall_beyond(self.ctx.pm, t.position, t.heading)
        return float(t.position[0]), float(t.position[1])

    def inspect(self, obs, est, target) -> dict:
        if not self._wall_beyond or obs.depth is None:
            return {}
        if heading_error(est.yaw, target.heading) > math.radians(15):
            return {}  # not looking along the corridor (still turning): no corner to judge
        ratios = mask_ratios(obs, self.ctx.grounder)
        if not is_corner(ratios):
            return {}
        h, w = obs.depth.shape
        wall = float(np.median(obs.depth[h // 2 : h // 2 + max(2, h // 20), w // 3 : 2 * w // 3]))
        width = self.ctx.pm.segment(target.segment).width
        ahead = max(0.0, wall - width / 2.0)
        p = (est.x + ahead * math.cos(target.heading), est.y + ahead * math.sin(target.heading))
        return {"corner": p, "ratios": ratios}

    def arrived_at_wall(self, free: float) -> bool:
        """Where the map has a wall just past the waypoint, depth showing a wall within
        half a corridor width (and a margin) ahead, near where the waypoint should be,
        means the robot is there: a corner placed beyond the wall (the wall measured
        through a side opening, or an estimate ahead of the truth) must not drive it
        into the wall."""
        if not self._wall_beyond:
            return False
        t = self.get("target")
        est = self.estimate()
        width = self.ctx.pm.segment(t.segment).width
        near = math.dist((est.x, est.y), t.position) <= WALL_ARRIVAL_NEAR_M
        if near and free <= width / 2.0 + WALL_ARRIVAL_MARGIN_M:
            self.ctx.log("at_wall", t.landmark, wall_ahead=free)
            return True
        return False

    def on_watch(self, found: dict, obs) -> None:
        t = self.get("target")
        p = found.get("corner")
        if p is None or self._corner_seen:
            return
        if math.dist(p, t.position) <= 2.0:  # agrees with the map: trust the eyes
            self._goal = p
            self._corner_seen = True
            r = found["ratios"]
            self.ctx.log("corner", t.landmark, obs.rgb, wall=r.wall, floor=r.floor)


def wall_beyond(pm, position, heading: float) -> bool:
    """Whether the map has a wall straight on past ``position`` along ``heading``: no
    corridor there half a width and half a metre on (a turn, or a T from its stem)."""
    loc = pm.locate(float(position[0]), float(position[1]))
    d = loc.segment.width / 2.0 + 0.5
    probe = pm.locate(position[0] + d * math.cos(heading), position[1] + d * math.sin(heading))
    return probe.offset > probe.segment.width / 2.0


def out_heading(plan, step) -> float:
    """Heading of the route leaving a step's node (the arrival heading at the goal)."""
    pts = [np.asarray(p) for p in plan.path]
    here = np.asarray(step.position)
    for i, p in enumerate(pts[:-1]):
        if np.linalg.norm(p - here) < 1e-6 and np.linalg.norm(pts[i + 1] - p) > 1e-6:
            return heading(p, pts[i + 1])
    return step.heading


class TurnOnto(PmNavBehaviour):
    """Turn in place onto the heading the plan takes after the target (turn or fork).

    Reads ``target``, ``plan``, ``map_T_odom``.
    """

    READS = ("target", "plan", "map_T_odom")
    STOPS_BASE = True

    def initialise(self) -> None:
        self._heading = out_heading(self.get("plan"), self.get("target"))

    def update(self) -> Status:
        est = map_pose(self.get("map_T_odom"), self.ctx.base.pose())
        if not self.face(self._heading, est):
            return Status.RUNNING
        t = self.get("target")
        self.ctx.log("turn", t.landmark, action=t.action.value)
        return Status.SUCCESS


class CheckOpening(PmNavBehaviour):
    """Fork choice / turn check: the way now ahead is open as far as the map says.

    The paper's check: floor in the lower-central band (``is_opening``). That band sees
    the floor only from some metres out; where the map's floor along the plan's way out
    of the target ends sooner (``floor_run``), depth decides instead (``is_open_way``).
    A look that finds the way shut is taken again (``OPENING_LOOKS`` looks,
    ``OPENING_LOOK_AGAIN_S`` apart): someone crossing the junction hides a way that is
    there. Reads ``target``, ``plan``, ``map_T_odom``. FAILURE (TARGET_NOT_FOUND) when
    every look shows the way filled.
    """

    READS = ("target", "plan", "map_T_odom")
    JOBS = ("_job",)

    def initialise(self) -> None:
        self._looks = 0
        self._look()

    def _look(self) -> None:
        base, grounder = self.ctx.base, self.ctx.grounder
        t = self.get("target")
        est = map_pose(self.get("map_T_odom"), base.pose())
        ctx, heading = self.ctx, out_heading(self.get("plan"), t)

        def look(cancelled):
            obs = base.observe()
            free = None if obs.depth is None else free_distance(obs, 0.0)
            run = floor_run(ctx, t.position, heading, est)  # the map's floor: not in a tick
            return mask_ratios(obs, grounder), free, band_reach(obs), run

        self._looks += 1
        self._again_at = None
        self._job = self.ctx.worker.submit(look)

    def update(self) -> Status:
        if self._again_at is not None:
            if self.ctx.now() < self._again_at:
                return Status.RUNNING
            self._look()
        status, seen = self.poll(self._job, "checking the way ahead")
        if status is not None:
            return status
        ratios, free, reach, run = seen
        t = self.get("target")
        depth = "" if free is None else f"; depth {free:.1f} m free, the map {run:.1f} m"
        if not is_open_way(ratios, free, run, reach):
            if self._looks < OPENING_LOOKS:
                self._job, self._again_at = None, self.ctx.now() + OPENING_LOOK_AGAIN_S
                self.feedback_message = (
                    f"no way ahead at {t.landmark} in look {self._looks} of {OPENING_LOOKS} "
                    f"(floor {ratios.floor:.2f}{depth}): someone in the way? looking again"
                )
                return Status.RUNNING
            return self.fail(
                FailureCode.TARGET_NOT_FOUND,
                f"no corridor to take at {t.landmark} in {OPENING_LOOKS} looks (floor "
                f"{ratios.floor:.2f}, wall {ratios.wall:.2f}{depth})",
            )
        self.feedback_message = f"open (floor {ratios.floor:.2f}{depth})"
        return Status.SUCCESS


def floor_run(ctx: Context, position, heading: float, est) -> float:
    """How far (m) the map's floor runs along ``heading`` (the plan's way out of the
    waypoint at ``position``) from the estimated pose ``est``: what depth should show from
    where the robot believes it stands, in the wall model the localization weighs depth
    against (``ctx.walls``: the building's grid where it has one, else its corridors).

    From the estimate, not from the waypoint: on an open floor a lane's leg may pass a
    room's corner, and a robot half a metre beside the lane has that corner ahead while
    the waypoint has the whole floor (a corridor's side walls make the two alike). Where
    the estimate is outside every corridor, from the waypoint, counted from level with
    the estimate. At most ``FLOOR_RUN_MOST_M`` past the waypoint."""
    floor = ctx.walls.floor(ctx.pm, Visibility.of(ctx.pm))
    angle = np.array([heading])
    behind = (position[0] - est.x) * math.cos(heading) + (position[1] - est.y) * math.sin(heading)
    loc = ctx.pm.locate(est.x, est.y)
    if loc.offset <= loc.segment.width / 2.0:
        most = FLOOR_RUN_MOST_M + max(0.0, behind)
        return float(floor.reach(np.array([est.x, est.y], float), angle, most)[0])
    return float(floor.reach(np.asarray(position, float), angle, FLOOR_RUN_MOST_M)[0]) + behind


class Arrive(PmNavBehaviour):
    """Arrive and stop at the goal. Reads ``plan``."""

    READS = ("plan",)

    def __init__(self, name: str, ctx: Context):
        super().__init__(name, ctx)

    def update(self) -> Status:
        self.ctx.base.stop()
        plan = self.get("plan")
        self.ctx.log("arrive", plan.goal if plan else "")
        self.feedback_message = f"arrived at {plan.goal if plan else 'goal'}"
        return Status.SUCCESS
