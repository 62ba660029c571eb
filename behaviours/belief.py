"""The corridor belief in the localization stage (issue 15): what a panorama tells it
(``read_panorama``), the leaves that add a look to it (``UpdateBelief``), fix the pose from
it (``FixFromBelief``) and decide whether a look is worth taking (``NoSignInReach``,
``LookTellsNothing``). The drive towards where signs are readable is ``follow_lead``."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import StrEnum

import numpy as np
from py_trees.common import Status

from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context
from pmnav_bt.behaviours.localize import forget_stale_sightings
from pmnav_bt.errors import UnknownNameError
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import se2_apply, wrap_angle
from pmnav_bt.perception.depth import surfaces
from pmnav_bt.perception.door_sightings import find_doors
from pmnav_bt.perception.geometry import free_distance
from pmnav_bt.perception.read_range import sign_lead_range, sign_recall, sign_visible_range
from pmnav_bt.planning.resolve import resolve_room
from pmnav_bt.pose.belief import CorridorBelief
from pmnav_bt.pose.correction import PoseTracker
from pmnav_bt.pose.evidence.prior import P_FAR
from pmnav_bt.pose.glimpse import Glimpse
from pmnav_bt.pose.landmark_fix import Sighting, fix_pose, sighting
from pmnav_bt.pose.odometry import CalibratedBase, rotation_scale_error
from pmnav_bt.pose.visibility import Visibility, entity_xy
from pmnav_bt.pose.walls import axis_in_odom, wall_lines, wall_points, way_to_centre
from pmnav_bt.seams import Entity, Grounder, Observation, Pose2D

# Take the views between a panorama's only where at least this share of the belief puts a
# sign in reach: a plate across a seam (about one bearing in four) is worth another turn
# (11 of the action budget's turn-equivalents) only where a sign is likely at all.
NO_SIGN_SHARE = 0.5

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

    ``anchored``: the estimate a new belief starts from cannot be grossly wrong (the lift's
    word on arrival, ``behaviours/lift.py``): a place far from it is ruled out as the
    Gaussian rules it out, not kept possible (``evidence.prior``).

    Reads ``views``, ``belief``, ``map_T_odom``, ``pose_tracker``, ``goal``; writes ``belief``.
    """

    READS = ("views", "belief", "map_T_odom", "pose_tracker", "goal")
    WRITES = ("belief",)
    JOBS = ("_job",)

    def __init__(self, name: str, ctx: Context, anchored: bool = False):
        super().__init__(name, ctx)
        self.anchored = anchored

    def initialise(self) -> None:
        ctx, views, belief = self.ctx, self.get("views") or [], self.get("belief")
        odom = views[0].observation.pose if views else ctx.base.pose()
        goal, prior = self.get("goal"), None
        if belief is None and (tf := self.get("map_T_odom")) is not None:
            tracker = self.get("pose_tracker")
            prior = (tf, tracker.sigma(ctx.odometer.distance) if tracker else 3.0)

        def job(cancelled):
            read = read_panorama(ctx, views)
            floor = None if self.anchored else P_FAR
            b = _new_belief(ctx, goal, prior, floor) if belief is None else belief.fork()
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
            b.settle()  # the fix FixFromBelief asks for next, worked out here
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


def _new_belief(ctx, goal, prior, floor: float | None = P_FAR) -> CorridorBelief:
    """A belief with no glimpse yet, for ``goal`` (its door is where to look first), with
    ``prior`` ((map_T_odom, sigma m) of the estimate so far; None: none) and ``floor``
    (how likely that estimate is grossly wrong; None: it cannot be)."""
    cfg, pm = ctx.config, ctx.pm
    belief = CorridorBelief(
        pm,
        read_range=sign_visible_range(cfg),
        recall=sign_recall(cfg, pm.building),
        lead_range=sign_lead_range(cfg),
        target=_goal_xy(pm, goal),
        walls=ctx.walls,
    )
    belief.prior = prior
    belief.prior_floor = floor
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
    of a fifth of its corridors). FAILURE otherwise. The share (``sign_share``: tens of ms
    on a large belief, the map's readable lattice the first time) is weighed in the worker.

    Reads ``belief``, ``map_T_odom``."""

    READS = ("belief", "map_T_odom")
    JOBS = ("_job",)

    def initialise(self) -> None:
        ctx, belief, tf = self.ctx, self.get("belief"), self.get("map_T_odom")
        pose, reach = ctx.base.pose(), sign_lead_range(ctx.config)
        self._job = ctx.worker.submit(lambda c: sign_share(ctx.pm, reach, belief, tf, pose))
        self.feedback_message = "weighing where signs are in reach"

    def update(self) -> Status:
        status, got = self.poll(self._job, "weighing where signs are in reach")
        if status is not None:
            return status
        share, of = got
        self.feedback_message = f"{share:.0%} of {of} puts a sign in reach"
        return Status.SUCCESS if share < NO_SIGN_SHARE else Status.FAILURE


def sign_share(pm, reach: float | None, belief, map_T_odom, pose: Pose2D) -> tuple[float, str]:
    """The share of the belief (with a glimpse), else of the last estimate (``map_T_odom``:
    0 or 1), else of the map's corridors, that puts a sign within ``reach`` of ``pose``
    (odometry), and which of the three it is."""
    if belief is not None and belief.ref is not None:
        return belief.sign_in_reach(pose), "the belief"
    vis = Visibility.of(pm, reach)
    if map_T_odom is not None:
        return float(bool(vis.readable_from(se2_apply(map_T_odom, (pose.x, pose.y))))), (
            "the last estimate"
        )
    return float(np.mean([bool(p.readable) for p in vis.lattice_points])), "the corridors"


class DriveEnd(StrEnum):
    """How a localization drive ended (``drive_end``: written by the drive's leaves in
    ``follow_lead``, read by ``LookTellsNothing``)."""

    COVERED = "covered"
    RETHOUGHT = "rethought"  # the belief chose another way on the drive
    SIGN = "sign ahead"
    WALL = "wall ahead"
    BLOCKED = "blocked"  # (then the tree backs off the wall)
    CORNER = "corner"  # a corner met early in the drive: slid past, and the drive goes on


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

            def job(cancelled) -> bool:
                tells = belief.look_tells(pose)
                if not tells:
                    belief.settle()  # no look: FixFromBelief asks this belief next
                return tells

            self._job = self.ctx.worker.submit(job)
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
            views[-1].observation.rgb if views else None,
            map_pose=[est_x, est_y],
            attempts=attempts,
        )
        self.feedback_message = f"at ({est_x:.1f}, {est_y:.1f}) from {how}"
        return Status.SUCCESS


def _map_xy(tf, pose) -> tuple[float, float]:
    c, s = math.cos(tf[2]), math.sin(tf[2])
    return tf[0] + c * pose.x - s * pose.y, tf[1] + s * pose.x + c * pose.y
