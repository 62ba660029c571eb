"""The localization drive (issue 15) as leaves: along the corridor axis towards where the
map says signs are readable (the corridor belief's lead), or, without a belief, towards
the most open view of the last panorama.

``trees.localize.follow_lead_subtree`` runs them in this order:

- ``ChooseLead``: which way and how far (a search over the map's corridors, in the worker).
- ``AlignWithCorridor``: face the lead's heading, look at the walls once (their direction
  steers the heading), and face it again.
- ``DriveAlongCorridor``: drive, keeping parallel to the walls seen in depth (odometry's
  rotation error does not steer it into a wall) and adding the walls' axis and the free
  floor ahead to the belief every metre (weighed in the worker). It ends when the distance
  is covered (cut short when a sign comes into view ahead: look round near it), when the
  lead worked out again every few metres goes another way, at a wall ahead (the corridor
  ends: the belief notes the way blocked), when the body is blocked (the tree then backs
  off the wall with the ``BackUp`` recovery), or at a corner early in the drive.
- ``SlidePastCorner``: a wall met in the drive's first metres with open floor on one
  side of it is a corner: slide past it, then align and drive on (once a drive).

The leaves share the drive under way, ``CorridorDrive`` (blackboard ``corridor_drive``);
how it ended is ``drive_end`` (``belief.DriveEnd``), which the next look reads.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from py_trees.common import Status

from pmnav_bt.behaviours.belief import DriveEnd, doors_in_odom, wall_mask
from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context
from pmnav_bt.contact import as_bump, felt_contact, way_clear
from pmnav_bt.perception.geometry import free_distance, target_point
from pmnav_bt.pose.belief import CorridorBelief
from pmnav_bt.pose.odometry import TRACK_FREE_M, CalibratedBase
from pmnav_bt.pose.walls import centre_between, wall_lines, wall_points
from pmnav_bt.seams import MotionStatus, Observation, Pose2D

NO_PROGRESS_S = 6.0  # clock seconds without moving 0.1 m: the drive is blocked
MIN_BLOCKED_DRIVE_M = 0.2  # blocked sooner: a brush with a wall, not the corridor's end
BACK_OFF_S = 5.0  # a blocked drive backs off the wall (``BackUp``) for at most this long
SIGN_APPROACH_M = 3.0  # with a sign in view ahead, drive at most this much further ...
SIGN_STOP_M = 2.5  # ... to stop this far short of it (nearer, a plate is seen along its wall)
CENTRE_LOOKAHEAD_M = 3.0  # steer back onto the corridor's centre line over this distance
MAX_CENTRE_TURN = math.radians(15.0)  # ... turning at most this far off the axis for it
WALL_CHECK_S = 1.0  # clock seconds between wall checks while driving along the corridor
STOP_BEFORE_M = 0.9  # stop when depth shows a wall this close ahead
MEASURE_NEAR_M = 3.5  # drive on to this far from a wall ahead while the distance is unmeasured
MEASURE_STALE_M = 1.0  # ... seen up to this much beyond the calibration's reach (the last
# depth reading is up to a wall check old)
RAY_SPACING_M = 1.0  # while driving, add the free floor ahead to the belief this often ...
RETHINK_EVERY_M = 3.0  # ... and work the lead out again every so far (a junction passed)
ALONG_WALL_MAX = math.radians(35.0)  # a wall more oblique than this is not the corridor's
# A wall ahead this early in a drive, with open floor on one side of it, is a corner: the
# robot stands off-centre at a junction (its hypotheses disagree on the junction's centre
# by a metre) and the side corridor it turns into opens beside the wall in front of it.
# Slide past: face the open bearing, drive until SLIDE_ACROSS_M across the heading, face
# the lead's heading again.
SLIDE_WITHIN_M = 1.5
SLIDE_BEARINGS = tuple(math.radians(b) for b in (25.0, 40.0, 55.0))  # either side
SLIDE_OPEN_M = 2.0  # floor this long along a bearing beside the wall: open
SLIDE_ACROSS_M = 0.5
SLIDE_GIVE_UP_S = NO_PROGRESS_S + 5.0  # clock seconds after the corner was met
# Clutter the local costmap holds on the way ahead (seen from afar, lost from view up
# close: ``local_planner/clear_way.py``) is driven round by a point beside it; the way is
# judged this far ahead at each wall look, the point is reached this near, and a turn
# larger than this onto it is made on the spot (a round body turns without touching).
ROUND_JUDGE_M = 3.0
ROUND_REACHED_M = 0.15
ROUND_TURN_FIRST = math.radians(45.0)
SLIDE_PROBE_M = 0.4  # a slide past a corner stops where the costmap holds something this near


@dataclass
class CorridorDrive:
    """The drive under way, shared by its leaves (blackboard ``corridor_drive``, changed in
    place). Positions are odometry; distances are measured from ``start``."""

    start: tuple[float, float]  # where the drive began
    max_distance: float  # the farthest a lead may go (worked out again on the drive)
    heading: float  # odometry yaw to drive along: the lead's, steered by the walls seen
    distance: float  # how far from ``start`` to go (cut short for a sign, extended to measure)
    checked_at: float = -math.inf  # clock time of the last wall look
    signs_ahead: list[float] = field(default_factory=list)  # how far ahead (m) signs read are
    free_ahead: float = math.inf  # the free floor straight ahead at the last wall look
    open_beside: float | None = None  # bearing (body) of open floor beside a wall ahead
    best: float = 0.0  # the farthest from ``start`` so far (progress)
    last_ray: tuple[float, float] = (0.0, 0.0)  # where the last ray went to the belief
    thought_at: tuple[float, float] = (0.0, 0.0)  # where the lead was last worked out
    sign_stop: bool = False  # the distance was cut short for a sign seen ahead
    measure_extended: bool = False  # driven on to measure the distance at a wall
    slid: bool = False  # slid past a corner already (once a drive)
    corner: tuple[float, float, float, float] | None = None  # (open yaw, x, y, clock) met
    round: tuple[float, float] | None = None  # odometry: driving round clutter by this point


@dataclass(frozen=True)
class WallLook:
    """What one frame tells the drive: the strongest wall's direction (rad, body; None:
    no wall seen), the way to the centre line between two walls (``centre_between``), how
    far ahead each sign read is, the free floor straight ahead (None: no depth), the open
    bearing beside a wall ahead (``open_beside``; only with a wall within
    ``STOP_BEFORE_M``), the doors along the walls (odometry; None: not looked for) and,
    for a drive, a point round what the local costmap holds on its way ahead (``round``:
    ``Steering.way_round``; None: the way is clear)."""

    seen_from: Pose2D
    angle: float | None
    centre: tuple[float, float] | None
    signs_ahead: list[float]
    free: float | None
    open_beside: float | None
    doors: tuple[tuple[float, float], ...] | None
    round: tuple[float, float] | None = None  # odometry: a point round clutter ahead


def look_at_walls(ctx: Context) -> WallLook:
    """Take a frame and read it (``WallLook``). Worker only."""
    base, grounder = ctx.base, ctx.grounder
    obs = base.observe()
    mask = wall_mask(grounder, obs)
    doors = doors_in_odom(obs) if ctx.config.tree.localization_doors else None
    points = None if mask is None else wall_points(obs, mask)
    lines = [] if points is None else wall_lines(points, 2)  # fitted once, for both
    ahead = [_ahead(obs, d) for d in grounder.read_signs(obs)]
    free = free_distance(obs, 0.0) if obs.depth is not None else None
    return WallLook(
        obs.pose,
        lines[0].angle if lines else None,
        centre_between(lines),
        ahead,
        free,
        open_beside(obs) if free is not None and free < STOP_BEFORE_M else None,
        doors,
    )


def steer(drive: CorridorDrive, look: WallLook) -> float | None:
    """Re-aim ``drive`` by a wall look: along both walls, turning a little towards the
    centre line (there a plate on either wall is seen at the angle the map's reading ranges
    assume), else parallel to the wall in view; a wall more oblique than
    ``ALONG_WALL_MAX`` is not the corridor's. Keeps what the look saw ahead. The walls'
    axis (odometry yaw), or None."""
    drive.open_beside = look.open_beside
    drive.round = look.round
    yaw, axis = look.seen_from.yaw, None
    if look.centre is not None and abs(look.centre[0]) < ALONG_WALL_MAX:
        axis = yaw + look.centre[0]
        turn = math.atan2(look.centre[1], CENTRE_LOOKAHEAD_M)
        drive.heading = axis + max(-MAX_CENTRE_TURN, min(MAX_CENTRE_TURN, turn))
    elif look.angle is not None and abs(look.angle) < ALONG_WALL_MAX:
        axis = drive.heading = yaw + look.angle
    drive.signs_ahead = look.signs_ahead
    drive.free_ahead = math.inf if look.free is None else look.free
    return axis


def _ahead(obs: Observation, det) -> float:
    """How far ahead (m, along the view) a sign read in ``obs`` is; SIGN_STOP_M plus
    SIGN_APPROACH_M without depth."""
    p = det.point[:2] if det.point is not None else target_point(obs, det)
    return SIGN_STOP_M + SIGN_APPROACH_M if p is None else float(p[0])


def open_beside(obs: Observation) -> float | None:
    """The bearing (rad, body) nearest ahead along which the floor is open for
    ``SLIDE_OPEN_M`` on one side only (``SLIDE_BEARINGS``), or None: open on both sides
    (the wall ahead is a corridor's end across a junction) or on neither."""
    for b in SLIDE_BEARINGS:
        left = free_distance(obs, b) >= SLIDE_OPEN_M
        right = free_distance(obs, -b) >= SLIDE_OPEN_M
        if left != right:
            return b if left else -b
        if left:
            return None
    return None


def mark_contact(ctx: Context, pose: Pose2D) -> None:
    """The body touched something: the steering's costmap marks it (``felt_item``), so the
    next drive goes round it (the tree backs off it, ``BackUp``)."""
    now = ctx.now()
    contact = felt_contact(ctx.base, now)
    ctx.log("contact", "", x=contact.point[0], y=contact.point[1], n=1)
    ctx.steering.feel([as_bump(contact)], pose, now)


class ChooseLead(PmNavBehaviour):
    """Work out which way to drive and how far: the belief's lead (a search over the map's
    corridors, in the worker), or, without a belief or a lead, 2 m towards the most open
    view of the last panorama. Starts the drive (``CorridorDrive``) from here.

    Reads ``belief``, ``views``; writes ``corridor_drive``, ``drive_end`` (cleared).
    SUCCESS once chosen (in the tick the lead comes: the drive turns onto it at once).
    """

    READS = ("belief", "views")
    WRITES = ("corridor_drive", "drive_end")
    JOBS = ("_job",)

    def __init__(self, name: str, ctx: Context, max_distance: float):
        super().__init__(name, ctx)
        self.max_distance = max_distance

    def initialise(self) -> None:
        pose = self.ctx.base.pose()
        belief: CorridorBelief | None = self.get("belief")
        most = self.max_distance
        self._start = (pose.x, pose.y)
        self._job = None
        if belief is not None:
            self._job = self.ctx.worker.submit(lambda c: belief.lead(pose, most))
            self.feedback_message = "choosing the way"
        self.bb.set("drive_end", None)

    def update(self) -> Status:
        lead = None
        if self._job is not None:
            status, lead = self.poll(self._job, "choosing the way")
            if status is not None:
                return status
            self._job = None
        heading, distance = self._aim(lead, self.ctx.base.pose())
        start = self._start
        self.bb.set(
            "corridor_drive",
            CorridorDrive(
                start, self.max_distance, heading, distance, last_ray=start, thought_at=start
            ),
        )
        return Status.SUCCESS

    def _aim(self, lead, pose: Pose2D) -> tuple[float, float]:
        """(heading, distance) along the belief's ``lead``, or, without one, 2 m towards
        the most open view."""
        if lead is not None:
            self.feedback_message = (
                f"{lead.distance:.1f} m along the corridor ({lead.support:.0%} of the belief)"
            )
            return lead.heading, lead.distance
        heading, best = pose.yaw, -1.0
        for v in self.get("views") or []:
            free = free_distance(v.observation, 0.0)
            if free > best:
                best, heading = free, v.observation.pose.yaw
        self.feedback_message = "towards the most open view"
        return heading, min(2.0, self.max_distance)


class _LooksAtWalls(PmNavBehaviour):
    """A leaf of the drive that looks at the walls in the worker (``look_at_walls``) and
    steers the drive by what comes back (``steer``)."""

    READS = ("corridor_drive",)
    WRITES = ("corridor_drive",)
    JOBS = ("_look",)
    STOPS_BASE = True

    @property
    def drive(self) -> CorridorDrive:
        return self.get("corridor_drive")

    def initialise(self) -> None:
        self._look = None

    def _look_again(self) -> None:
        ctx, heading = self.ctx, self.drive.heading

        def look(cancelled) -> WallLook:
            seen = look_at_walls(ctx)  # its frame is in the costmap now (Context)
            p = seen.seen_from
            reach = ROUND_JUDGE_M
            ahead = (p.x + reach * math.cos(heading), p.y + reach * math.sin(heading))
            return replace(seen, round=ctx.steering.way_round(p, ahead))

        self._look = ctx.worker.submit(look)
        self.drive.checked_at = ctx.now()

    def _take_look(self) -> tuple[WallLook, float | None] | None:
        """The wall look that came (and the walls' axis it steered by), or None."""
        if self._look is None or not self._look.done():
            return None
        job, self._look = self._look, None
        try:
            look = job.result()
        except Exception:  # noqa: BLE001 - a lost wall check: drive on, check again
            return None
        return look, steer(self.drive, look)


class AlignWithCorridor(_LooksAtWalls):
    """Face the drive's heading, look at the walls once and face the heading they steer
    it to. SUCCESS then (the drive starts in the same tick).

    Reads and writes ``corridor_drive``."""

    def initialise(self) -> None:
        super().initialise()
        self._looked = False

    def update(self) -> Status:
        pose = self.ctx.base.pose()
        self._take_look()
        if not self.face(self.drive.heading, pose):
            return Status.RUNNING
        if not self._looked:  # aligned once: look at the walls, then go
            self._look_again()
            self._looked = True
            return Status.RUNNING
        if self._look is not None:
            return Status.RUNNING
        return Status.SUCCESS


class DriveAlongCorridor(_LooksAtWalls):
    """Drive along the drive's heading, looking at the walls every ``WALL_CHECK_S``
    (``steer``), adding the free floor ahead to the belief every ``RAY_SPACING_M`` and
    working the lead out again every ``RETHINK_EVERY_M``.

    SUCCESS, with the body stopped and ``drive_end`` written, when: the distance is
    covered (``covered``; ``sign ahead`` when it was cut short for a sign read ahead; at a
    wall ahead within the distance calibration's reach, while the odometry's distance is
    unmeasured, the drive first goes on to ``MEASURE_NEAR_M`` from it), the lead worked
    out again goes another way (``rethought``), depth shows a wall within
    ``STOP_BEFORE_M`` (``wall ahead``; the belief notes the way blocked), or, a tick after
    it stopped the body: a corner within ``SLIDE_WITHIN_M`` of the start (``corner``, the
    open bearing beside it in ``corridor_drive``) or the body blocked or without progress
    for ``NO_PROGRESS_S`` (``blocked``; the belief notes the way blocked after
    ``MIN_BLOCKED_DRIVE_M``). That tick at rest comes before the body turns to slide or
    reverses.

    Reads ``belief``, ``corridor_drive``; writes ``belief`` (with a drive ray weighed in,
    in the worker), ``corridor_drive``, ``drive_end``.
    """

    READS = ("belief", "corridor_drive")
    WRITES = ("belief", "corridor_drive", "drive_end")
    JOBS = ("_look", "_rethink_job", "_ray_job")

    def initialise(self) -> None:
        super().initialise()
        self._rethink_job = None
        self._ray_job = None
        self._best_t = self.ctx.now()
        self._stopped = False

    def update(self) -> Status:
        self._take_ray()
        if self._stopped:  # at rest after stopping: for a corner or a block, or for a ray
            return Status.RUNNING if self._ray_job is not None else Status.SUCCESS
        base, now, drive = self.ctx.base, self.ctx.now(), self.drive
        pose = base.pose()
        if (took := self._take_look()) is not None:
            self._note_ray(took[0], took[1])
        done_m = math.hypot(pose.x - drive.start[0], pose.y - drive.start[1])
        # At the lead's end: stop, unless driving on to a wall ahead measures the distance.
        if done_m >= drive.distance and not self._approach_to_measure(base, done_m):
            base.set_velocity(0.0, 0.0)
            return self._end(DriveEnd.SIGN if drive.sign_stop else DriveEnd.COVERED)
        if self._rethink(pose):
            # The belief now says another way: look again from here.
            base.set_velocity(0.0, 0.0)
            self.feedback_message = f"after {done_m:.1f} m the belief says another way: look again"
            return self._end(DriveEnd.RETHOUGHT)
        self._cut_short_for_signs(done_m)
        if done_m > drive.best + 0.1:
            drive.best, self._best_t = done_m, now
        stuck = now - self._best_t > NO_PROGRESS_S
        if drive.free_ahead < STOP_BEFORE_M:  # a wall ahead, seen in depth
            base.set_velocity(0.0, 0.0)
            beside = drive.open_beside
            if beside is not None and done_m < SLIDE_WITHIN_M and not drive.slid:
                drive.corner, drive.slid = (pose.yaw + beside, pose.x, pose.y, now), True
                drive.free_ahead = math.inf
                self.feedback_message = "a corner ahead: sliding past it"
                return self._end_after_rest(DriveEnd.CORNER)
            self._note_blocked()
            self.feedback_message = f"a wall ahead after {done_m:.1f} m: the corridor ends"
            return self._end(DriveEnd.WALL)
        touched = base.motion_status() == MotionStatus.BLOCKED
        if touched or stuck:
            base.stop()
            if touched:
                mark_contact(self.ctx, pose)
            if done_m >= MIN_BLOCKED_DRIVE_M:
                self._note_blocked()  # not just a brush with a side wall
            self.feedback_message = f"blocked after {done_m:.1f} m: the corridor ends or turns"
            return self._end_after_rest(DriveEnd.BLOCKED)
        if self._look is None and now - drive.checked_at > WALL_CHECK_S:
            self._look_again()
        want = drive.heading
        if drive.round is not None:  # round clutter the costmap holds on the way
            if math.hypot(drive.round[0] - pose.x, drive.round[1] - pose.y) <= ROUND_REACHED_M:
                drive.round = None
            else:
                want = math.atan2(drive.round[1] - pose.y, drive.round[0] - pose.x)
        err = math.atan2(math.sin(want - pose.yaw), math.cos(want - pose.yaw))
        lim = self.ctx.limits
        if abs(err) > ROUND_TURN_FIRST:  # turn onto the way round before driving on
            base.set_velocity(0.0, max(-lim.angular, min(lim.angular, 3.0 * err)))
            return Status.RUNNING
        base.set_velocity(lim.linear, max(-lim.angular, min(lim.angular, 2.0 * err)))
        return Status.RUNNING


    def _end(self, end: DriveEnd) -> Status:
        """End the drive (the body stopped): SUCCESS, or while a drive ray is still being
        weighed, RUNNING at rest until it is in the belief the next look adds to."""
        self.bb.set("drive_end", end)
        if self._ray_job is None:
            return Status.SUCCESS
        self._stopped = True
        return Status.RUNNING

    def _end_after_rest(self, end: DriveEnd) -> Status:
        self.bb.set("drive_end", end)
        self._stopped = True
        return Status.RUNNING

    def _note_blocked(self) -> None:
        """The belief notes the drive's way blocked (the corridor ends or turns there)."""
        belief: CorridorBelief | None = self.get("belief")
        if belief is not None:
            belief.pending_blocked = self.drive.heading

    def _cut_short_for_signs(self, done_m: float) -> None:
        """A sign read ahead: stop short of it (a plate is read best 2-3 m off, and seen
        along its wall from beside it), then look round."""
        drive = self.drive
        ahead = [a for a in drive.signs_ahead if a > SIGN_STOP_M]  # nearer: read already
        if not ahead:
            return
        stop = done_m + min(SIGN_APPROACH_M, min(ahead) - SIGN_STOP_M)
        if stop < drive.distance:
            drive.distance, drive.sign_stop = stop, True
            self.feedback_message = f"a sign in view after {done_m:.1f} m: look round soon"
        drive.signs_ahead = []

    def _note_ray(self, look: WallLook, axis: float | None) -> None:
        """Add the free floor ahead, the walls' axis (odometry; None: not seen) and the
        doors seen along the walls (None: not looked for) to the belief every
        ``RAY_SPACING_M`` of the drive. Weighing every hypothesis with them (10-20 ms on
        a sign-sparse building's belief) runs in the worker, on a fork of the belief that
        replaces it when done (``_take_ray``); one ray at a time, and none while the lead
        is worked out again on the belief. Not after the odometry's distance gain has
        changed until the next look moves the belief to it: a ray would mix two gains."""
        belief: CorridorBelief | None = self.get("belief")
        busy = self._rethink_job is not None or self._ray_job is not None
        if belief is None or look.free is None or busy:
            return
        base, drive, seen_from = self.ctx.base, self.drive, look.seen_from
        if isinstance(base, CalibratedBase) and belief.rescale_due(base.distance_gain):
            return
        x, y = drive.last_ray
        if math.hypot(seen_from.x - x, seen_from.y - y) < RAY_SPACING_M:
            return
        drive.last_ray = (seen_from.x, seen_from.y)
        free, doors = min(look.free, 50.0), look.doors

        def weigh(cancelled) -> CorridorBelief:
            fork = belief.fork()
            fork.observe_ray(seen_from, free, axis, doors)
            return fork

        self._ray_job = self.ctx.worker.submit(weigh)

    def _take_ray(self) -> None:
        """The belief with the last drive ray weighed in, in place of the one it was forked
        from (with what the drive noted on that one since: ``pending_blocked``)."""
        job = self._ray_job
        if job is None or not job.done():
            return
        self._ray_job = None
        try:
            fork = job.result()
        except Exception:  # noqa: BLE001 - a lost ray: the belief stays as it was
            return
        was: CorridorBelief | None = self.get("belief")
        if was is not None:
            fork.pending_blocked = was.pending_blocked
        self.bb.set("belief", fork)

    def _rethink(self, pose: Pose2D) -> bool:
        """Whether the lead, worked out again (worker) every ``RETHINK_EVERY_M`` of the drive
        with what the depth ahead has told the belief since, now goes another way."""
        belief: CorridorBelief | None = self.get("belief")
        if self._rethink_job is not None:
            if not self._rethink_job.done():
                return False
            job, self._rethink_job = self._rethink_job, None
            try:
                return job.result() is not None
            except Exception:  # noqa: BLE001 - a lost rethink: keep to the lead
                return False
        drive = self.drive
        moved = math.hypot(pose.x - drive.thought_at[0], pose.y - drive.thought_at[1])
        if belief is not None and moved >= RETHINK_EVERY_M and self._ray_job is None:
            drive.thought_at = (pose.x, pose.y)
            heading, most = drive.heading, drive.max_distance
            self._rethink_job = self.ctx.worker.submit(
                lambda c: belief.turned_lead(pose, heading, most)
            )
        return False

    def _approach_to_measure(self, base, done_m: float) -> bool:
        """At the end of the drive with a wall ahead within (about) the distance
        calibration's reach and the odometry's distance not measured yet: drive on (once) to
        ``MEASURE_NEAR_M`` from it, so that the approach spans the ``MIN_TRACK_M`` a
        measurement needs. Until then each hypothesis is a rigid transform of distances
        counted up to 10 % long, and a look a few metres short of a T junction takes
        the dead end that many metres long for it."""
        drive = self.drive
        if (
            drive.measure_extended
            or drive.sign_stop
            or not isinstance(base, CalibratedBase)
            or base.distance_measured
            or not MEASURE_NEAR_M < drive.free_ahead <= TRACK_FREE_M[1] + MEASURE_STALE_M
        ):
            return False
        drive.measure_extended = True
        drive.distance = done_m + (drive.free_ahead - MEASURE_NEAR_M)
        self.feedback_message = (
            f"a wall {drive.free_ahead:.1f} m ahead: on to {MEASURE_NEAR_M:.1f} m from it, "
            "where its approach measures the odometry's distance"
        )
        return True


class SlidePastCorner(PmNavBehaviour):
    """Slide past the corner the drive met (``CorridorDrive.corner``): face the open
    bearing beside it and drive until ``SLIDE_ACROSS_M`` across the drive's heading
    (or blocked: touched, or what the local costmap holds within ``SLIDE_PROBE_M`` ahead;
    or ``SLIDE_GIVE_UP_S`` after the corner was met). SUCCESS then, with the
    body stopped (the drive faces its heading and looks at the walls again).

    Reads and writes ``corridor_drive`` (the corner cleared)."""

    READS = ("corridor_drive",)
    WRITES = ("corridor_drive",)
    STOPS_BASE = True

    def update(self) -> Status:
        base, drive = self.ctx.base, self.get("corridor_drive")
        heading, x, y, t = drive.corner
        pose = base.pose()
        if not self.face(heading, pose):
            return Status.RUNNING
        across = abs(math.sin(heading - drive.heading)) * math.hypot(pose.x - x, pose.y - y)
        blocked = base.motion_status() == MotionStatus.BLOCKED
        if blocked:
            mark_contact(self.ctx, pose)
        ahead = (
            pose.x + SLIDE_PROBE_M * math.cos(pose.yaw),
            pose.y + SLIDE_PROBE_M * math.sin(pose.yaw),
        )
        if not way_clear((pose.x, pose.y), ahead, self.ctx.steering.clearance):
            blocked = True  # what the costmap holds stands in the slide's way: slide no further
        if across >= SLIDE_ACROSS_M or blocked or self.ctx.now() - t > SLIDE_GIVE_UP_S:
            base.set_velocity(0.0, 0.0)
            drive.corner = None
            return Status.SUCCESS
        base.set_velocity(self.ctx.limits.linear, 0.0)
        return Status.RUNNING


class DriveEnded(PmNavBehaviour):
    """SUCCESS when the last drive ended ``end`` (``drive_end``), else FAILURE: the guard
    of what a drive's end calls for (a corner: slide past it; blocked: back off the wall).

    Reads ``drive_end``."""

    READS = ("drive_end",)

    def __init__(self, name: str, ctx: Context, end: DriveEnd):
        super().__init__(name, ctx)
        self.end = end

    def update(self) -> Status:
        got = self.get("drive_end")
        self.feedback_message = f"the drive ended: {got or 'not yet'}"
        return Status.SUCCESS if got == self.end else Status.FAILURE
