"""Active localization (issue 15): a belief over corridor positions, kept across attempts,
a fix from it (one sign and the corridor axis can be enough), and a drive along the
corridor axis towards where the map says signs are readable."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import StrEnum

import numpy as np
from py_trees.common import Status

from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context, thumbnail
from pmnav_bt.behaviours.localize import forget_stale_sightings
from pmnav_bt.behaviours.recovery import BACKUP_LIMIT_M
from pmnav_bt.errors import UnknownNameError
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import se2_apply, wrap_angle
from pmnav_bt.localization import Sighting, fix_pose, sighting
from pmnav_bt.perception.depth import surfaces
from pmnav_bt.perception.door_sightings import find_doors
from pmnav_bt.perception.geometry import free_distance, target_point
from pmnav_bt.perception.read_range import sign_lead_range, sign_recall, sign_visible_range
from pmnav_bt.planning.resolve import resolve_room
from pmnav_bt.pose.belief import CorridorBelief, Glimpse
from pmnav_bt.pose.correction import PoseTracker
from pmnav_bt.pose.odometry import TRACK_FREE_M, CalibratedBase, rotation_scale_error
from pmnav_bt.pose.visibility import Visibility, entity_xy
from pmnav_bt.pose.walls import (
    axis_in_odom,
    centre_between,
    wall_lines,
    wall_points,
    way_to_centre,
)
from pmnav_bt.seams import Entity, Grounder, MotionStatus, Observation, Pose2D

# Take the views between a panorama's only where at least this share of the belief puts a
# sign in reach: a plate across a seam (about one bearing in four) is worth another turn
# (11 of the action budget's turn-equivalents) only where a sign is likely at all.
NO_SIGN_SHARE = 0.5
NO_PROGRESS_S = 6.0  # clock seconds without moving 0.1 m: the drive is blocked
MIN_BLOCKED_DRIVE_M = 0.2  # blocked sooner: a brush with a wall, not the corridor's end
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
# Bearings in each view along which the free floor is measured: twelve thin rays a view,
# so a six-view panorama looks every 5 deg. From a bare corridor a side opening a few
# metres off is seen only through a narrow window of bearings (4 m off: 11-19 deg from
# the axis), and only a thin ray that passes it ends beyond the corridor's side walls.
FREE_BEARINGS = tuple(math.radians(b) for b in np.arange(-27.5, 28.0, 5.0))
RAY_HALF_WIDTH_M = 0.05  # a thin ray: the floor along a line, not the body's swept strip


def wall_mask(grounder: Grounder, obs: Observation):
    """The wall mask of a frame (the grounder's surfaces)."""
    return grounder.surfaces(obs).wall


def doors_in_odom(obs: Observation) -> tuple[tuple[float, float], ...] | None:
    """The doors seen along the walls of a frame (``door_sightings``), odometry xy; None
    without depth (not looked for). The walls are depth's (``depth.surfaces``), whatever
    the grounder's masks: a segmentation's wall mask leaves the doors out."""
    if obs.depth is None:
        return None
    p = obs.pose
    return tuple(
        tuple(se2_apply((p.x, p.y, p.yaw), d.centre))  # type: ignore[misc]
        for d in find_doors(obs, surfaces(obs).wall)
    )


def read_panorama(ctx: Context, views: list) -> Panorama:
    """What a panorama tells the belief (``Panorama``). Worker only.

    A rotation-scale error turns each view's odometry yaw by a share of the turning since:
    the views are put back into the odometry frame of the last one (where the robot is
    now) before signs, free floor and the axis are read from them."""
    fits, walls = [], []
    for i, v in enumerate(views):
        mask = wall_mask(ctx.grounder, v.observation)
        points = None if mask is None else wall_points(v.observation, mask)
        lines = [] if points is None else wall_lines(points, 2)
        if lines:
            fits.append((i, (lines[0].angle, lines[0].inliers)))
            walls += [(i, line) for line in lines]
    error = rotation_scale_error([(views[i].observation.pose.yaw, *f) for i, f in fits])
    if error is not None:
        turned = [0.0]
        for a, b in zip(views, views[1:], strict=False):
            turned.append(turned[-1] + wrap_angle(b.observation.pose.yaw - a.observation.pose.yaw))
        views = [
            replace(v, observation=_turned(v.observation, -error * (r - turned[-1])))
            for v, r in zip(views, turned, strict=True)
        ]
    sightings, named = [], set()
    for v in views:
        for d in v.detections or ():
            s = sighting(ctx.pm, v.observation, d)
            if s is not None:
                sightings.append(s)
            elif d.entity is not None:
                named.add(d.entity)  # read, but cut by the border: in sight, place unknown
    angles = [(views[i].observation.pose.yaw, f[0], f[1]) for i, f in fits]
    axis = axis_in_odom(angles)
    seen = [(views[i].observation.pose.yaw + w.angle, w.offset) for i, w in walls]
    free = tuple(
        (
            wrap_angle(v.observation.pose.yaw + b),
            min(free_distance(v.observation, b, half_width=RAY_HALF_WIDTH_M), 50.0),
        )
        for v in views
        for b in FREE_BEARINGS
    )
    doors, door_views = [], []
    if ctx.config.tree.localization_doors:
        for v in views:
            if (found := doors_in_odom(v.observation)) is not None:
                doors += found
                door_views.append(v.observation.pose.yaw)
    return Panorama(
        sightings,
        axis,
        free,
        error,
        frozenset(named),
        way_to_centre(seen, axis),
        tuple(doors),
        tuple(door_views),
    )


@dataclass(frozen=True)
class Panorama:
    """What a panorama tells: the signs read with a place, the corridor axis (odometry,
    mod pi; None: no walls seen), the free floor along each view's ``FREE_BEARINGS``
    ((odometry yaw, m) each), the odometry's rotation-scale error (None: not measured),
    the signs read without a place, the way across to the corridor's centre line
    (``walls.way_to_centre``), and the doors seen along the walls (odometry xy) with the
    odometry yaws of the views that looked for them.
    """

    sightings: list[Sighting]
    axis: float | None
    free: tuple[tuple[float, float], ...]
    rotation_error: float | None
    named: frozenset[Entity]
    to_centre: tuple[float, float] | None
    doors: tuple[tuple[float, float], ...] = ()
    door_views: tuple[float, ...] = ()


def _turned(obs: Observation, dyaw: float) -> Observation:
    q = obs.pose
    return replace(obs, pose=Pose2D(q.x, q.y, wrap_angle(q.yaw + dyaw)))


class UpdateBelief(PmNavBehaviour):
    """Add the last panorama to the corridor belief (the signs read and where, and the
    corridor axis from the walls); start a belief when there is none, with the current
    estimate as its prior when there is one. How the walls' direction moved while the
    panorama turned calibrates the odometry's rotation (``CalibratedBase``).

    The goal room's door is the belief's ``target``: where to look for signs first.

    Reading the panorama and weighing every hypothesis with it (0.1-2 s) run in the
    worker, on a fork of the belief (``CorridorBelief.fork``) that replaces it when done:
    a look halted half-way leaves the belief as it was.

    Reads ``views``, ``belief``, ``map_T_odom``, ``pose_tracker``, ``goal``; writes ``belief``.
    """

    READS = ("views", "belief", "map_T_odom", "pose_tracker", "goal")
    WRITES = ("belief",)
    JOBS = ("_job",)

    def initialise(self) -> None:
        ctx, views, belief = self.ctx, self.get("views") or [], self.get("belief")
        odom = views[0].observation.pose if views else ctx.base.pose()
        goal, prior = self.get("goal"), None
        if belief is None and (tf := self.get("map_T_odom")) is not None:
            tracker = self.get("pose_tracker")
            prior = (tf, tracker.sigma(ctx.odometer.distance) if tracker else 3.0)

        def job(cancelled):
            read = read_panorama(ctx, views)
            b = _new_belief(ctx, goal, prior) if belief is None else belief.fork()
            _rescale(b, ctx.base)  # a new gain weighs every hypothesis again
            seen: dict[Entity, tuple[float, float]] = {}
            for s in read.sightings:
                seen.setdefault(s.entity, s.odom_xy)
            glimpse = Glimpse(
                odom,
                seen,
                free=read.free,
                named=read.named,
                to_centre=read.to_centre,
                doors=read.doors,
                door_views=read.door_views,
            )
            b.observe(glimpse, axis_odom=read.axis)
            return read, b, len(seen), b.best_cluster()[1]

        self._job = ctx.worker.submit(job)

    def update(self) -> Status:
        status, done = self.poll(self._job, "reading the panorama")
        if status is not None:
            return status
        read, belief, n_seen, mass = done
        error = read.rotation_error
        if error is not None and isinstance(self.ctx.base, CalibratedBase):
            gain = self.ctx.base.calibrate(error)
            self.ctx.log("calibrate", "", rotation_error=error, gain=gain)
        self.bb.set("belief", belief)
        self.feedback_message = (
            f"{n_seen} sign(s) read, {len(belief.glimpses)} glimpse(s); best {mass:.0%}"
        )
        return Status.SUCCESS


def _new_belief(ctx, goal, prior) -> CorridorBelief:
    """A belief with no glimpse yet, for ``goal`` (its door is where to look first), with
    ``prior`` ((map_T_odom, sigma m) of the estimate so far; None: none)."""
    cfg, pm = ctx.config, ctx.pm
    belief = CorridorBelief(
        pm,
        read_range=sign_visible_range(cfg),
        recall=sign_recall(cfg, pm.building),
        lead_range=sign_lead_range(cfg),
        target=_goal_xy(pm, goal),
    )
    belief.prior = prior
    return belief


def _rescale(belief: CorridorBelief, base) -> None:
    """Keep the belief's positions in the odometry's calibrated distance (it changes when a
    straight drive at a wall ends: ``CalibratedBase``). Slow when the belief moves
    (``CorridorBelief.rescale_due``)."""
    if isinstance(base, CalibratedBase):
        belief.rescale(base.distance_gain)


def _goal_xy(pm, goal) -> tuple[float, float] | None:
    """The goal room's door (map), or None when there is no goal or it names no room."""
    if not goal:
        return None
    try:
        return entity_xy(pm, Entity.room(resolve_room(pm, str(goal))))
    except UnknownNameError:
        return None


class NoSignInReach(PmNavBehaviour):
    """SUCCESS when the corridor belief so far does not put a sign within reliable reading
    range here (less than ``NO_SIGN_SHARE`` of it does): in a bare stretch, or where only
    one of several mirror-image places has a sign, the six views between the panorama's
    are not worth their turn. Before the first glimpse the share is that of the last
    estimate (0 or 1), else of the whole map (a sign-sparse building has signs in reach
    of a fifth of its corridors). FAILURE otherwise.

    Reads ``belief``, ``map_T_odom``."""

    READS = ("belief", "map_T_odom")

    def update(self) -> Status:
        belief: CorridorBelief | None = self.get("belief")
        pose = self.ctx.base.pose()
        if belief is not None and belief.ref is not None:
            share, of = belief.sign_in_reach(pose), "the belief"
        else:  # before the first glimpse: the last estimate, else anywhere on the map
            vis = Visibility.of(self.ctx.pm, sign_lead_range(self.ctx.config))
            tf = self.get("map_T_odom")
            if tf is not None:
                share = float(bool(vis.readable_from(se2_apply(tf, (pose.x, pose.y)))))
                of = "the last estimate"
            else:
                share = float(np.mean([bool(p.readable) for p in vis.lattice_points]))
                of = "the corridors"
        self.feedback_message = f"{share:.0%} of {of} puts a sign in reach"
        return Status.SUCCESS if share < NO_SIGN_SHARE else Status.FAILURE


class DriveEnd(StrEnum):
    """How a FollowLead drive ended (``drive_end``)."""

    COVERED = "covered"
    RETHOUGHT = "rethought"  # the belief chose another way on the drive
    SIGN = "sign ahead"
    WALL = "wall ahead"
    BLOCKED = "blocked"


# After these a look round that cannot tell the belief's places apart is skipped; after a
# wall met or a sign seen ahead, never.
SKIPPABLE_ENDS = (DriveEnd.COVERED, DriveEnd.RETHOUGHT)


class LookTellsNothing(PmNavBehaviour):
    """SUCCESS when a look round here cannot tell the belief's places apart
    (``CorridorBelief.look_tells``: its clusters are the mirror images of a symmetric
    junction, or stretches of bare corridor, with no sign in sight under any), after a
    drive that covered its lead or stopped because the belief chose another way: then the
    panorama (a full turn, eleven actions) is skipped and the lead worked out again.
    FAILURE (take the look) with no belief, or after a drive that met a wall or saw a
    sign ahead. The check, a few rays per cluster on the map, runs in the worker.

    Reads ``belief``, ``drive_end``; writes ``drive_end`` (cleared: one skip per drive).
    """

    READS = ("belief", "drive_end")
    WRITES = ("drive_end",)
    JOBS = ("_job",)

    def initialise(self) -> None:
        belief: CorridorBelief | None = self.get("belief")
        end = self.get("drive_end")
        self.bb.set("drive_end", None)
        self._job = None
        if belief is not None and end in SKIPPABLE_ENDS:
            pose = self.ctx.base.pose()
            self._job = self.ctx.worker.submit(lambda c: belief.look_tells(pose))
            self.feedback_message = "weighing a look round"  # not the last decision's reason
        self._end = end

    def update(self) -> Status:
        if self._job is None:
            self.feedback_message = f"look round (drive: {self._end or 'none'})"
            return Status.FAILURE
        status, tells = self.poll(self._job, "weighing a look round")
        if status is not None:
            return status
        if tells:
            self.feedback_message = "a look round here can tell the places apart"
            return Status.FAILURE
        self.feedback_message = "every likely place looks alike from here: no look round"
        self.ctx.log("no look", self.feedback_message)
        return Status.SUCCESS


class FixFromBelief(PmNavBehaviour):
    """Fix the map pose: from two or more landmarks of the last panorama, else from the
    belief once one corridor position dominates it.

    Reads ``belief``, ``views``, ``fix_attempts``; writes ``map_T_odom``, ``pose_tracker``,
    ``fix_attempts``, ``belief`` and ``recent_sightings`` (both cleared on a fix).
    FAILURE (LOCALIZATION_FAILED) otherwise.
    """

    READS = ("belief", "views", "fix_attempts")
    WRITES = ("map_T_odom", "pose_tracker", "fix_attempts", "belief", "recent_sightings")

    def update(self) -> Status:
        belief: CorridorBelief | None = self.get("belief")
        attempts = (self.get("fix_attempts") or 0) + 1
        self.bb.set("fix_attempts", attempts)
        if belief is None:
            return self.fail(FailureCode.LOCALIZATION_FAILED, "no panorama to localize from")
        last = belief.glimpses[-1]
        now = [Sighting(e, entity_xy(self.ctx.pm, e), xy) for e, xy in last.seen.items()]
        fix = fix_pose(now)
        level = None
        if fix is not None:  # the heading follows the walls; a fit they refute is not taken
            used = [x.map_xy for x in now if x.entity in fix.entities]
            level = belief.level_with_walls(fix.map_T_odom, tuple(np.mean(used, axis=0)))
        if level is not None:
            tf = belief.to_odom(level)  # the sightings are in the belief's frame
            sigma, how = 0.3 + fix.residual, f"{len(fix.entities)} signs"
        else:
            got = belief.fix()
            if got is None:
                _, mass = belief.best_cluster()
                seen = sorted({str(e) for e, _ in belief.sightings()})
                return self.fail(
                    FailureCode.LOCALIZATION_FAILED,
                    f"attempt {attempts}: {len(seen)} sign(s) read so far "
                    f"({', '.join(seen) or 'none'}); the likeliest corridor position holds "
                    f"{mass:.0%} of the belief",
                )
            tf, spread = got
            sigma, how = 0.3 + spread, f"the corridor belief ({len(belief.glimpses)} glimpses)"
        self.bb.set("map_T_odom", tf)
        self.bb.set(
            "pose_tracker",
            PoseTracker(map_T_odom=tf, sigma0=sigma, odometer0=self.ctx.odometer.distance),
        )
        self.bb.set("belief", None)
        forget_stale_sightings(self)
        est_x, est_y = _map_xy(tf, self.ctx.base.pose())
        views = self.get("views") or []
        self.ctx.log(
            "fix",
            how,
            thumbnail(views[-1].observation.rgb) if views else None,
            map_pose=[est_x, est_y],
            attempts=attempts,
        )
        self.feedback_message = f"at ({est_x:.1f}, {est_y:.1f}) from {how}"
        return Status.SUCCESS


def _ahead(obs: Observation, det) -> float:
    """How far ahead (m, along the view) a sign read in ``obs`` is; SIGN_STOP_M plus
    SIGN_APPROACH_M without depth."""
    p = det.point[:2] if det.point is not None else target_point(obs, det)
    return SIGN_STOP_M + SIGN_APPROACH_M if p is None else float(p[0])


def _open_beside(obs: Observation) -> float | None:
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


def _map_xy(tf, pose) -> tuple[float, float]:
    c, s = math.cos(tf[2]), math.sin(tf[2])
    return tf[0] + c * pose.x - s * pose.y, tf[1] + s * pose.x + c * pose.y


class FollowLead(PmNavBehaviour):
    """Drive along the corridor axis towards where the map says signs are readable (the
    belief's lead), or, without a belief, towards the most open view. The heading is kept
    parallel to the walls seen in depth (odometry's rotation error does not steer it into a
    wall), and the walls' axis and the free floor ahead go to the belief every metre. A
    blocked drive is remembered by the belief (the corridor ends or turns there); a wall
    met in the drive's first metres with open floor on one side of it is a corner, slid
    past. The lead, a search over the map's corridors, is worked out in the worker and
    again every few metres of the drive (the belief may now say another way: stop).

    Reads ``belief``, ``views``; writes ``drive_end`` (how the drive ended: covered,
    rethought, sign ahead, wall ahead, blocked; the belief notes a blocked drive).
    SUCCESS when the distance is covered (shortened when a sign comes into view ahead:
    look round near it), or the way is blocked (then it backs off the wall first;
    exploring is best effort).
    """

    READS = ("belief", "views")
    WRITES = ("drive_end",)
    JOBS = ("_job", "_lead_job", "_rethink_job")
    STOPS_BASE = True

    def __init__(self, name: str, ctx: Context, max_distance: float):
        super().__init__(name, ctx)
        self.max_distance = max_distance

    def initialise(self) -> None:
        pose = self.ctx.base.pose()
        belief: CorridorBelief | None = self.get("belief")
        self._lead_job = None
        if belief is not None:  # which way: a search over the map, in the worker
            self._lead_job = self.ctx.worker.submit(lambda c: belief.lead(pose, self.max_distance))
            self._heading, self._distance = pose.yaw, 0.0
            self.feedback_message = "choosing the way"
        else:
            self._aim(None, pose)
        self._start = (pose.x, pose.y)
        self._job = None
        self._driving = False
        self._next_check = -math.inf
        self._best, self._best_t = 0.0, self.ctx.now()
        self._signs_ahead: list[float] = []  # how far ahead (m) each sign read ahead is
        self._free_ahead = math.inf
        self._backing = None
        self._open_beside: float | None = None  # bearing (body) of open floor beside a wall
        self._slide: tuple[float, float, float, float] | None = None  # (heading, x, y, t)
        self._slid = False
        self._last_ray = self._start
        self._rethink_job = None
        self._thought_at = self._start
        self._sign_stop = False  # the distance was cut short for a sign seen ahead
        self._measure_extended = False  # driven on to measure the distance at a wall
        self.bb.set("drive_end", None)

    def _aim(self, lead, pose: Pose2D) -> None:
        """Drive along the belief's ``lead``, or, without one, 2 m towards the most open view."""
        if lead is not None:
            self._heading, self._distance = lead.heading, lead.distance
            self.feedback_message = (
                f"{lead.distance:.1f} m along the corridor ({lead.support:.0%} of the belief)"
            )
            return
        self._heading, best = pose.yaw, -1.0
        for v in self.get("views") or []:
            free = free_distance(v.observation, 0.0)
            if free > best:
                best, self._heading = free, v.observation.pose.yaw
        self._distance = min(2.0, self.max_distance)
        self.feedback_message = "towards the most open view"

    def _check_walls(self) -> None:
        """Measure the wall direction in view (worker); re-aim along it when it comes."""
        base, grounder = self.ctx.base, self.ctx.grounder
        look_for_doors = self.ctx.config.tree.localization_doors

        def measure(cancelled):
            obs = base.observe()
            mask = wall_mask(grounder, obs)
            doors = doors_in_odom(obs) if look_for_doors else None
            points = None if mask is None else wall_points(obs, mask)
            lines = [] if points is None else wall_lines(points, 2)  # fitted once, for both
            ahead = [_ahead(obs, d) for d in grounder.read_signs(obs)]
            free = free_distance(obs, 0.0) if obs.depth is not None else None
            return (
                obs.pose,
                lines[0].angle if lines else None,
                ahead,
                free,
                centre_between(lines),
                _open_beside(obs) if free is not None and free < STOP_BEFORE_M else None,
                doors,
            )

        self._job = self.ctx.worker.submit(measure)

    def _poll_walls(self) -> None:
        if self._job is None or not self._job.done():
            return
        job, self._job = self._job, None
        try:
            seen_from, angle, ahead, free, centre, self._open_beside, doors = job.result()
        except Exception:  # noqa: BLE001 - a lost wall check: drive on, check again
            return
        if self._slide is not None:  # seen while turning to slide: not along the way
            return
        yaw, axis = seen_from.yaw, None
        if centre is not None and abs(centre[0]) < ALONG_WALL_MAX:
            # Along both walls, turning a little towards the centre line: there a plate
            # on either wall is seen at the angle the map's reading ranges assume.
            axis = yaw + centre[0]
            steer = math.atan2(centre[1], CENTRE_LOOKAHEAD_M)
            self._heading = axis + max(-MAX_CENTRE_TURN, min(MAX_CENTRE_TURN, steer))
        elif angle is not None and abs(angle) < ALONG_WALL_MAX:
            axis = self._heading = yaw + angle  # parallel to the wall in view
        self._note_ray(seen_from, free, axis, doors)
        self._signs_ahead = ahead
        self._free_ahead = math.inf if free is None else free

    def _note_ray(
        self,
        seen_from: Pose2D,
        free: float | None,
        axis: float | None,
        doors: tuple[tuple[float, float], ...] | None = None,
    ) -> None:
        """Add the free floor ahead, the walls' axis (odometry; None: not seen) and the
        doors seen along the walls (None: not looked for) to the belief every
        ``RAY_SPACING_M`` of the drive. Not after the odometry's distance gain
        has changed until the next look moves the belief to it (in the worker: too slow for
        a tick): a ray would mix two gains."""
        belief: CorridorBelief | None = self.get("belief")
        if belief is None or free is None or not self._driving or self._rethink_job is not None:
            return  # (not while the lead is worked out again on the belief, in the worker)
        base = self.ctx.base
        if isinstance(base, CalibratedBase) and belief.rescale_due(base.distance_gain):
            return
        x, y = self._last_ray
        if math.hypot(seen_from.x - x, seen_from.y - y) < RAY_SPACING_M:
            return
        self._last_ray = (seen_from.x, seen_from.y)
        belief.observe_ray(seen_from, min(free, 50.0), axis, doors)

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
        moved = math.hypot(pose.x - self._thought_at[0], pose.y - self._thought_at[1])
        if belief is not None and moved >= RETHINK_EVERY_M:
            self._thought_at = (pose.x, pose.y)
            heading, most = self._heading, self.max_distance
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
        if (
            self._measure_extended
            or self._sign_stop
            or not isinstance(base, CalibratedBase)
            or base.distance_measured
            or not MEASURE_NEAR_M < self._free_ahead <= TRACK_FREE_M[1] + MEASURE_STALE_M
        ):
            return False
        self._measure_extended = True
        self._distance = done_m + (self._free_ahead - MEASURE_NEAR_M)
        self.feedback_message = (
            f"a wall {self._free_ahead:.1f} m ahead: on to {MEASURE_NEAR_M:.1f} m from it, "
            "where its approach measures the odometry's distance"
        )
        return True

    def _sliding(self, pose: Pose2D) -> bool:
        """Slide past a corner (along the open bearing beside it, ``SLIDE_ACROSS_M`` across
        the drive's heading); True once done (then the drive faces its heading and looks at
        the walls again)."""
        heading, x, y, t = self._slide
        if not self.face(heading, pose):
            return False
        across = abs(math.sin(heading - self._heading)) * math.hypot(pose.x - x, pose.y - y)
        blocked = self.ctx.base.motion_status() == MotionStatus.BLOCKED
        if across >= SLIDE_ACROSS_M or blocked or self.ctx.now() - t > NO_PROGRESS_S + 5.0:
            self.ctx.base.set_velocity(0.0, 0.0)
            self._slide, self._next_check = None, -math.inf
            return True
        self.ctx.base.set_velocity(self.ctx.limits.linear, 0.0)
        return False

    def update(self) -> Status:
        base, now = self.ctx.base, self.ctx.now()
        pose = base.pose()
        if self._lead_job is not None:
            status, lead = self.poll(self._lead_job, "choosing the way")
            if status is not None:
                return status
            self._lead_job = None
            self._aim(lead, pose)
        if self._backing is not None:  # off the wall it ran into, then done
            x, y, t, sent = self._backing
            refused = sent and base.motion_status() == MotionStatus.BLOCKED  # backup limit
            backed = math.hypot(pose.x - x, pose.y - y) >= BACKUP_LIMIT_M - 0.01
            if refused or backed or now - t > 5.0:
                base.set_velocity(0.0, 0.0)
                self.bb.set("drive_end", DriveEnd.BLOCKED)
                return Status.SUCCESS
            base.set_velocity(-0.1, 0.0)
            self._backing = (x, y, t, True)
            return Status.RUNNING
        self._poll_walls()
        if self._slide is not None and not self._sliding(pose):
            return Status.RUNNING
        if not self._driving:
            if not self.face(self._heading, pose):
                return Status.RUNNING
            if self._next_check == -math.inf:  # aligned once: look at the walls, then go
                self._check_walls()
                self._next_check = now
                return Status.RUNNING
            if self._job is not None:
                return Status.RUNNING
            self._driving = True
            self._best_t = now
        done_m = math.hypot(pose.x - self._start[0], pose.y - self._start[1])
        # At the lead's end: stop, unless driving on to a wall ahead measures the distance.
        if done_m >= self._distance and not self._approach_to_measure(base, done_m):
            base.set_velocity(0.0, 0.0)
            self.bb.set("drive_end", DriveEnd.SIGN if self._sign_stop else DriveEnd.COVERED)
            return Status.SUCCESS
        if self._rethink(pose):
            # The belief now says another way: look again from here.
            base.set_velocity(0.0, 0.0)
            self.bb.set("drive_end", DriveEnd.RETHOUGHT)
            self.feedback_message = f"after {done_m:.1f} m the belief says another way: look again"
            return Status.SUCCESS
        ahead = [a for a in self._signs_ahead if a > SIGN_STOP_M]  # nearer: read already
        if ahead:
            # A sign read ahead: stop short of it (a plate is read best 2-3 m off, and
            # seen along its wall from beside it), then look round.
            stop = done_m + min(SIGN_APPROACH_M, min(ahead) - SIGN_STOP_M)
            if stop < self._distance:
                self._distance, self._sign_stop = stop, True
                self.feedback_message = f"a sign in view after {done_m:.1f} m: look round soon"
            self._signs_ahead = []
        if done_m > self._best + 0.1:
            self._best, self._best_t = done_m, now
        stuck = now - self._best_t > NO_PROGRESS_S
        if self._driving and self._free_ahead < STOP_BEFORE_M:  # a wall ahead, seen in depth
            base.set_velocity(0.0, 0.0)
            beside = self._open_beside
            if beside is not None and done_m < SLIDE_WITHIN_M and not self._slid:
                self._slide, self._slid = (pose.yaw + beside, pose.x, pose.y, now), True
                self._driving, self._free_ahead = False, math.inf
                self.feedback_message = "a corner ahead: sliding past it"
                return Status.RUNNING
            belief = self.get("belief")
            if belief is not None:
                belief.pending_blocked = self._heading
            self.feedback_message = f"a wall ahead after {done_m:.1f} m: the corridor ends"
            self.bb.set("drive_end", DriveEnd.WALL)
            return Status.SUCCESS
        if base.motion_status() == MotionStatus.BLOCKED or stuck:
            base.stop()
            belief = self.get("belief")
            if belief is not None and done_m >= MIN_BLOCKED_DRIVE_M:
                belief.pending_blocked = self._heading  # not just a brush with a side wall
            self.feedback_message = f"blocked after {done_m:.1f} m: the corridor ends or turns"
            self._backing = (pose.x, pose.y, now, False)
            return Status.RUNNING
        if self._job is None and now - self._next_check > WALL_CHECK_S:
            self._check_walls()
            self._next_check = now
        err = math.atan2(math.sin(self._heading - pose.yaw), math.cos(self._heading - pose.yaw))
        lim = self.ctx.limits
        base.set_velocity(lim.linear, max(-lim.angular, min(lim.angular, 2.0 * err)))
        return Status.RUNNING
