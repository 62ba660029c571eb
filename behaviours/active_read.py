"""Read actively: a plate seen but not read is read from where it can be.

The search views are taken from where the tree expects the target's sign to be read
(``read_range.SearchRanges``), sized for the plates the map's building was measured with;
a building with small plates, or a plate seen far aslant, shows the robot a patch of text
it cannot name. Such a plate, near where the map puts the target's sign, is not absent:
a person walks up to it. So does the tree:

1. ``PlanReadingPose``: of the plates the grounder saw and could not read in the last
   search (``perception.unread_plates.SeesUnreadPlates``), the one nearest where the map
   puts the target (within the pose's uncertainty and ``SIGN_REACH_M``, a sign beside,
   above or on its door); with none, the plate the grounder read as the target before
   the search (``plate_named``, as near the map's target), which the search did not see
   again: a flag above the view from where the search stood, a person before it. It gets
   a reading pose (``perception.reading_pose``): square to it,
   within the range a plate with text that size is read from at the camera's width
   (``read_range.plate_read_range``, the sign benchmark's table), inside the map's
   corridors and on floor depth showed free: the search views' depth, as a local costmap
   (``local_planner.costmap``), shows nothing within the body's radius and
   ``SPOT_PAD_M`` of the spot, nor within its radius and ``WAY_PAD_M`` of the straight
   way there (clutter by the wall, beside a plate, is where reading poses fall). A
   pose inside or touching something is not taken; the nearest free one is. Something
   standing before the plate is no reason to drive: the tree looks again later
   (``hidden_sign.SignHidden``, next in the tree), so the leaf fails.
2. ``DriveToReadingPose``: drive there (a ``DriveTo``: it stops for what is in the way,
   goes round it, waits for people).
3. ``ReadAgain``: face the plate and ground the target in a fresh frame; FAILURE when the
   target is still not read there.

At most ``tree.active_reads`` tries a target (each nearer than the last: a plate is never
read again from where it was seen and not read; the plate the last try faced and did not
read is a candidate of the next, seen from that reading pose, beside the plates of the
search between); then the search moves on as before. A
grounder that reads every sign it sees (the oracle) has no unread plates: the leaf fails
at once.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from py_trees.common import Status

from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.hidden_sign import BAND_M, HIDDEN_MARGIN_M, MIN_SLANT
from pmnav_bt.behaviours.motion import DriveTo
from pmnav_bt.behaviours.search import VERIFY_TOLERANCE, FaceAndGround, target_entity
from pmnav_bt.contact import way_clear
from pmnav_bt.geometry import heading, se2_apply, wrap_angle
from pmnav_bt.local_planner.costmap import LocalCostmap
from pmnav_bt.perception.geometry import free_distance
from pmnav_bt.perception.read_range import plate_read_range
from pmnav_bt.perception.reading_pose import ReadingPose, reading_pose, view_standoff
from pmnav_bt.perception.unread_plates import KEEP_S, SeesUnreadPlates, UnreadPlate
from pmnav_bt.planning.resolve import entity_position
from pmnav_bt.seams import CAMERA_HEIGHT_M, CREATE3_RADIUS_M, Entity, Observation

# A target's sign hangs at most this far from where the map puts the target (its door):
# beside it (1.14 m in the simulator's convention), above it or on it.
SIGN_REACH_M = 1.5
# A reading pose lies this far inside the map's corridors: the body and a margin.
WALL_MARGIN_M = CREATE3_RADIUS_M + 0.15
# A reading pose keeps the body's radius and this from what depth showed standing: the
# robot turns there to face the plate, on a pose estimate good to a few centimetres.
SPOT_PAD_M = 0.1
VIEW_MARGIN = math.radians(5.0)  # a spot this near the view's border is not judged by it


@dataclass(frozen=True)
class ReadingPlan:
    """An unread plate and where to read it, both in the odometry frame; ``read_range``:
    how far a plate of its text size is read (m); ``named``: the plate is the one read as
    the target before the search, which did not see it again."""

    plate: UnreadPlate
    pose: ReadingPose
    read_range: float
    named: bool = False  # the plate was read as the target before, not seen since


def stands_before(obs: Observation, plate: UnreadPlate) -> bool:
    """Whether ``obs``'s depth shows something standing on the floor before ``plate``
    (by ``hidden_sign``'s rule: nearer than the plate by ``HIDDEN_MARGIN_M`` and than
    where its wall, seen at a slant, enters the line of sight)."""
    p = obs.pose
    far = math.dist((p.x, p.y), plate.xy)
    bearing = wrap_angle(heading((p.x, p.y), plate.xy) - p.yaw)
    if obs.depth is None or abs(bearing) > abs(obs.intrinsics.pixel_bearing(0.0)) - VIEW_MARGIN:
        return False
    off = abs(wrap_angle(heading(plate.xy, (p.x, p.y)) - math.atan2(*plate.normal[::-1])))
    slant = math.pi / 2 - min(off, math.pi / 2)
    if slant < MIN_SLANT:
        return False
    before = free_distance(obs, bearing, half_width=BAND_M)
    return before < far - HIDDEN_MARGIN_M - BAND_M / math.tan(slant)


def floor_free(obs: Observation, spot: tuple[float, float]) -> bool:
    """Whether ``obs``'s depth shows the floor free on the way to ``spot`` (odometry frame)
    and round it, where the view shows it (elsewhere: not judged, True)."""
    p = obs.pose
    bearing = wrap_angle(heading((p.x, p.y), spot) - p.yaw)
    if obs.depth is None or abs(bearing) > abs(obs.intrinsics.pixel_bearing(0.0)) - VIEW_MARGIN:
        return True
    free = free_distance(obs, bearing, half_width=CREATE3_RADIUS_M)
    return free >= math.dist((p.x, p.y), spot) + CREATE3_RADIUS_M


class PlanReadingPose(PmNavBehaviour):
    """SUCCESS with ``reading_pose`` (a ReadingPlan) when the last search saw an unread
    plate near the target and a spot to read it from is free; FAILURE otherwise, or after
    ``tree.active_reads`` tries for this target. In the worker. Reads ``target``,
    ``views``, ``map_T_odom``, ``pose_tracker``; writes ``reading_pose``."""

    READS = ("target", "views", "map_T_odom", "pose_tracker")
    WRITES = ("reading_pose",)
    JOBS = ("_job",)

    def __init__(self, name, ctx):
        super().__init__(name, ctx)
        self._tries: dict[str, int] = {}  # target landmark -> reading poses planned
        # target landmark -> when its last reading pose was planned: a plate seen (and not
        # read) from that pose since is a candidate again, now seen from nearer
        self._planned: dict[str, float] = {}

    def initialise(self) -> None:
        self._job = None
        t, entity, g = self.get("target"), target_entity(self), self.ctx.grounder
        views = list(self.get("views") or ())
        if not isinstance(g, SeesUnreadPlates) or t is None or entity is None or not views:
            self.feedback_message = "no unread plate to go to"
            return
        if self._tries.get(t.landmark, 0) >= self.ctx.config.tree.active_reads:
            self.feedback_message = f"{t.look_for}: tried {self._tries[t.landmark]} times"
            return
        tf = self.get("map_T_odom") or (0.0, 0.0, 0.0)
        tracker = self.get("pose_tracker")
        tol = (
            tracker.verify_tolerance(self.ctx.odometer.distance)
            if tracker is not None
            else VERIFY_TOLERANCE
        )
        since = min(v.observation.stamp for v in views)
        here = self.ctx.base.pose()
        plan = _Planner(self.ctx, entity, tf, tol + SIGN_REACH_M, views, (here.x, here.y))
        read = g.plate_named(entity)
        if read is not None and not (since - KEEP_S <= read.stamp < since):
            read = None  # read in this search (not found for another reason), or long ago
        seen_since = min(since, self._planned.get(t.landmark, since))
        self._job = self.ctx.worker.submit(lambda c: plan(g.unread_plates(seen_since), read))

    def update(self) -> Status:
        if self._job is None:
            return Status.FAILURE
        status, found = self.poll(self._job, "planning where to read a plate")
        if status is not None:
            return status
        plan, why = found
        t = self.get("target")
        if plan is None:
            self.feedback_message = why
            return Status.FAILURE
        self._tries[t.landmark] = self._tries.get(t.landmark, 0) + 1
        self._planned[t.landmark] = self.ctx.now()
        self.bb.set("reading_pose", plan)
        p, pose = plan.plate, plan.pose
        self.ctx.log(
            "active_read",
            t.landmark,
            plate=list(p.xy),
            line_height_m=p.line_height,
            read_range_m=plan.read_range,
            seen_m=math.dist(p.xy, p.seen_from),
            distance_m=pose.distance,
            angle_deg=math.degrees(pose.angle),
            read=p.read,
        )
        seen = math.dist(p.xy, p.seen_from)
        how = (
            f"its plate, read {seen:.1f} m off before, not seen in the search"
            if plan.named
            else f"a plate seen {seen:.1f} m off, not read"
        )
        self.feedback_message = (
            f"{t.look_for}: {how}: reading it from {pose.distance:.1f} m, "
            f"{math.degrees(pose.angle):+.0f} deg"
        )
        return Status.SUCCESS


class _Planner:
    """The reading pose of the unread plate nearest the target (in the worker)."""

    def __init__(self, ctx, entity: Entity, tf, reach: float, views, robot):
        self.ctx, self.tf, self.reach, self.robot = ctx, tf, reach, robot
        self.sign = np.asarray(entity_position(ctx.pm, entity), float)
        self.views = views
        self.frames = {v.observation.stamp: v.observation for v in views}

    def __call__(
        self, plates: list[UnreadPlate], read: UnreadPlate | None = None
    ) -> tuple[ReadingPlan | None, str]:
        self.seen = LocalCostmap()  # what the views' depth showed standing round here
        for v in self.views:  # projected here, in the worker, not on the tick
            self.seen.add_depth(v.observation, v.observation.stamp)
        near = sorted((self.off(p), i, p) for i, p in enumerate(plates))
        near = [p for d, _, p in near if d <= self.reach]
        if not near:
            if read is not None and self.off(read) <= self.reach:
                plan = self.plan(read_from_where_read(read), None)
                if plan is not None:
                    return replace(plan, named=True), ""
                return None, "no free spot to read its plate, read before, from"
            return None, f"no unread plate within {self.reach:.1f} m of the target"
        for plate in near:
            obs = self.frames.get(plate.stamp)
            if obs is not None and stands_before(obs, plate):
                return None, "something stands before the plate: look again later"
            plan = self.plan(plate, obs)
            if plan is not None:
                return plan, ""
        return None, "no free spot to read the plate from"

    def off(self, plate: UnreadPlate) -> float:
        """How far (m) ``plate`` hangs from where the map puts the target."""
        return float(np.linalg.norm(se2_apply(self.tf, plate.xy) - self.sign))

    def plan(self, plate: UnreadPlate, obs: Observation | None) -> ReadingPlan | None:
        cfg = self.ctx.config
        rng = plate_read_range(cfg, plate.line_height)
        if rng is None:
            return None
        clear = self.ctx.detour_check
        k = obs.intrinsics if obs is not None else None
        vfov = 2.0 * math.atan(k.height / 2.0 / k.fy) if k is not None else math.radians(45.0)
        height = obs.camera_height if obs is not None else CAMERA_HEIGHT_M

        grid = self.seen.snapshot()

        def clearance(x: float, y: float) -> float:
            return float(grid.clearance(np.array([x]), np.array([y]))[0])

        def free(spot: tuple[float, float]) -> bool:
            m = se2_apply(self.tf, spot)
            if clear is not None and not clear((float(m[0]), float(m[1])), WALL_MARGIN_M):
                return False
            if clearance(*spot) < CREATE3_RADIUS_M + SPOT_PAD_M:
                return False  # inside or touching what depth showed standing there
            if not way_clear(self.robot, spot, clearance):
                return False
            return obs is None or floor_free(obs, spot)

        pose = reading_pose(
            plate.xy,
            plate.normal,
            rng,
            free,
            seen_from=plate.seen_from,
            robot=self.robot,
            nearest=view_standoff(plate.top, height, vfov),
        )
        return None if pose is None else ReadingPlan(plate, pose, rng)


def read_from_where_read(plate: UnreadPlate) -> UnreadPlate:
    """``plate``, read before from ``seen_from``, facing that way: a plate is read from
    where it was read. Depth's normal is its wall's, which for a flag sign (read end-on,
    its faces across the corridor) points where its text is seen edge-on."""
    out = np.asarray(plate.seen_from, float) - np.asarray(plate.xy, float)
    n = float(np.linalg.norm(out))
    if n < 1e-6:
        return plate
    return replace(plate, normal=(float(out[0] / n), float(out[1] / n)))


class DriveToReadingPose(DriveTo):
    """Drive to the reading pose (``reading_pose``); see ``DriveTo`` for what it reads and
    writes and how it meets what is in the way."""

    READS = DriveTo.READS + ("reading_pose",)

    def goal(self) -> tuple[float, float]:
        pose = self.get("reading_pose").pose
        m = se2_apply(self.get("map_T_odom") or (0.0, 0.0, 0.0), (pose.x, pose.y))
        return float(m[0]), float(m[1])


class ReadAgain(FaceAndGround):
    """Face the unread plate (``reading_pose``) and ground the target in a fresh frame:
    SUCCESS with ``choice`` when it is read there, FAILURE (TARGET_NOT_FOUND) when not.
    Reads ``reading_pose``, ``target``; writes ``choice``."""

    READS = ("reading_pose", "target")
    MUST_SEE = True

    def aim(self) -> tuple[float, Entity | None]:
        plate = self.get("reading_pose").plate
        here = self.ctx.base.pose()
        return heading((here.x, here.y), plate.xy), target_entity(self)

    def accept(self, detection) -> bool:
        return True

    def update(self) -> Status:
        status = super().update()
        if status != Status.RUNNING:
            t = self.get("target")
            self.ctx.log("active_read_done", t.landmark, read=status == Status.SUCCESS)
        return status
