"""Keep the pose estimate honest between fixes: snap it onto the corridor it must be in,
and line its heading up with the corridor walls seen in depth."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from py_trees.common import Status

from pmnav_bt.behaviours.belief import wall_mask
from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import map_pose
from pmnav_bt.failures import FailureCode
from pmnav_bt.pose.correction import PoseTracker, rotated
from pmnav_bt.pose.snap import OffMapError, snap_to_corridor
from pmnav_bt.pose.walls import (
    WallLine,
    axis_in_odom,
    fit_wall_angle,
    fit_wall_line,
    heading_correction,
    wall_points,
)
from pmnav_bt.seams import Pose2D

if TYPE_CHECKING:
    from pmnav_bt.pose.evidence.likelihood_field import LikelihoodField

MAX_WALL_CORRECTION = math.radians(15.0)  # larger: a side corridor's wall, not drift


def tracker_of(b: PmNavBehaviour) -> PoseTracker:
    """The blackboard's pose tracker, made from ``map_T_odom`` when there is none yet."""
    tf = b.get("map_T_odom") or (0.0, 0.0, 0.0)
    t = b.get("pose_tracker")
    if t is None or t.map_T_odom != tf:
        base = t if t is not None else PoseTracker(tf, odometer0=b.ctx.odometer.distance)
        base.map_T_odom = tf
        t = base
    return t


class SnapToCorridor(PmNavBehaviour):
    """Move an estimate that drifted off the corridors onto the most plausible corridor.

    Reads ``map_T_odom``, ``pose_tracker``; writes ``map_T_odom``, ``pose_tracker``.
    SUCCESS (moved or not); FAILURE (LOCALIZATION_FAILED) when no corridor is plausibly
    near, so the pose must be found again.
    """

    READS = ("map_T_odom", "pose_tracker")
    WRITES = ("map_T_odom", "pose_tracker")

    def update(self) -> Status:
        if self.get("map_T_odom") is None:
            return Status.SUCCESS
        tracker = tracker_of(self)
        odom = self.ctx.base.pose()
        est = map_pose(tracker.map_T_odom, odom)
        sigma = tracker.sigma(self.ctx.odometer.distance)
        try:
            s = snap_to_corridor(self.ctx.pm, est, sigma)
        except OffMapError as err:
            return self.fail(FailureCode.LOCALIZATION_FAILED, str(err))
        if s.moved > 0.0:
            x, y, yaw = tracker.map_T_odom
            tracker.map_T_odom = (x + s.pose.x - est.x, y + s.pose.y - est.y, yaw)
            self.ctx.log("snap", s.segment.name, moved=s.moved, sigma=sigma)
        self.bb.set("map_T_odom", tracker.map_T_odom)
        self.bb.set("pose_tracker", tracker)
        self.feedback_message = (
            f"snapped {s.moved:.1f} m onto {s.segment.name}" if s.moved else "on a corridor"
        )
        return Status.SUCCESS


class CorrectHeading(PmNavBehaviour):
    """Turn ``map_T_odom`` so that the corridor walls seen in the last panorama run along
    the corridor the estimate is in (small corrections only).

    Reads ``views``, ``map_T_odom``, ``pose_tracker``; writes ``map_T_odom``,
    ``pose_tracker``. Always SUCCESS (no walls seen: nothing to correct).
    """

    READS = ("views", "map_T_odom", "pose_tracker")
    WRITES = ("map_T_odom", "pose_tracker")
    JOBS = ("_job",)

    def initialise(self) -> None:
        views, grounder = self.get("views") or [], self.ctx.grounder

        def measure(cancelled):
            angles = []
            for v in views:
                mask = wall_mask(grounder, v.observation)
                fit = None if mask is None else fit_wall_angle(wall_points(v.observation, mask))
                if fit is not None:
                    angles.append((v.observation.pose.yaw, fit[0], fit[1]))
            return axis_in_odom(angles)

        self._job = self.ctx.worker.submit(measure)

    def update(self) -> Status:
        status, axis = self.poll(self._job, "measuring the walls")
        if status is not None:
            return status
        if axis is None or self.get("map_T_odom") is None:
            self.feedback_message = "no wall line"
            return Status.SUCCESS
        tracker = tracker_of(self)
        odom = self.ctx.base.pose()
        est = map_pose(tracker.map_T_odom, odom)
        seg = self.ctx.pm.locate(est.x, est.y).segment
        turn = heading_correction(axis, tracker.map_T_odom[2], seg.heading)
        if abs(turn) > MAX_WALL_CORRECTION:
            self.feedback_message = f"wall at {math.degrees(turn):+.0f} deg: not this corridor's"
            return Status.SUCCESS
        tracker.rotate(turn, (odom.x, odom.y))
        self.bb.set("map_T_odom", tracker.map_T_odom)
        self.bb.set("pose_tracker", tracker)
        self.feedback_message = f"heading {math.degrees(turn):+.1f} deg from the walls"
        return Status.SUCCESS


# -- keeping to the corridor while driving -------------------------------------------------

AXIS_MAX_TURN = math.radians(10.0)  # a wall more oblique than this is not the corridor's
AXIS_GAIN = 0.5  # share of the measured heading and lateral error removed per frame
MIN_WALL_LENGTH_M = 1.5  # a wall line this long, not a door frame or a pillar
MAX_SHIFT_M = 0.5  # the most one frame moves the estimate across the corridor
# With a grid: a wall seen up to this far away is weighed (a wall farther is seen at a
# slant too flat to place it across), and it is the grid's when the grid has a wall within
# this of where it was seen, from the estimate (the estimate's error across a corridor is
# under a metre between fixes; more is another wall).
GRID_REACH_M = 4.0
GRID_MATCH_M = 1.0


def measure_walls(grounder, obs) -> WallLine | None:
    """The strongest wall line in a frame (worker only)."""
    mask = wall_mask(grounder, obs)
    line = None if mask is None else fit_wall_line(wall_points(obs, mask))
    return line if line is not None and line.length >= MIN_WALL_LENGTH_M else None


@dataclass(frozen=True)
class AxisCorrection:
    """What a corridor wall seen while driving does to ``map_T_odom``: the estimate it was
    worked out on (``before``), the corrected one (None: the wall is not the corridor's,
    nothing changes) and what it did, in words."""

    before: tuple[float, float, float]
    after: tuple[float, float, float] | None
    words: str | None


def axis_correction(
    pm, map_T_odom, odom: Pose2D, line: WallLine, grid: LikelihoodField | None = None
) -> AxisCorrection:
    """The correction a corridor wall ``line`` seen from odometry pose ``odom`` makes to
    ``map_T_odom``: its direction gives the heading relative to the corridor axis, its
    distance the position across the corridor (``AXIS_GAIN`` of each). Worked out in the
    worker beside the wall's measurement (``measure_walls``): finding the corridor on the
    map is most of a drive's slowest ticks (issue 37).

    Where the wall is across the corridor comes from ``grid`` where the building has one
    (the wall model the belief weighs depth against, ``Context.walls.field``): the grid's
    wall on the side the wall was seen, looked for straight across the corridor from the
    estimate (``grid_lateral``). Without a grid, the corridor's rectangle: its side at half
    its width. A real corridor is not its rectangle: an imported corridor's line runs off
    the middle of a corridor whose walls are not abreast (the office's lane past the
    pantry), and a rectangle about it put the far wall where there is none, so every wall
    seen there pulled the estimate towards that wall by the difference."""
    est = map_pose(map_T_odom, odom)
    seg = pm.locate(est.x, est.y).segment
    turn = heading_correction(odom.yaw + line.angle, map_T_odom[2], seg.heading)
    reach = GRID_REACH_M if grid is not None else seg.width
    if abs(turn) > AXIS_MAX_TURN or not 0.1 < abs(line.offset) < reach:
        return AxisCorrection(map_T_odom, None, None)
    turned = rotated(map_T_odom, AXIS_GAIN * turn, (odom.x, odom.y))
    est = map_pose(turned, odom)
    u = (math.cos(seg.heading), math.sin(seg.heading))
    n = (-u[1], u[0])  # the corridor's left
    # The line's left normal (body) is the corridor's left, or its right.
    side = 1.0 if math.cos(est.yaw + line.angle - seg.heading) >= 0.0 else -1.0
    wall = side * line.offset  # the wall relative to the robot, across the corridor
    if grid is not None:
        error = grid_lateral(grid, (est.x, est.y), n, wall)
        if error is None:
            return AxisCorrection(map_T_odom, None, None)
    else:
        a = pm.node_xy(seg.a)
        lateral = n[0] * (est.x - a[0]) + n[1] * (est.y - a[1])
        error = (seg.width / 2.0 if wall > 0.0 else -seg.width / 2.0) - wall - lateral
    shift = max(-MAX_SHIFT_M, min(MAX_SHIFT_M, AXIS_GAIN * error))
    x, y, yaw = turned
    return AxisCorrection(
        map_T_odom,
        (x + shift * n[0], y + shift * n[1], yaw),
        f"walls: heading {math.degrees(AXIS_GAIN * turn):+.1f} deg, across {shift:+.2f} m",
    )


def grid_lateral(grid: LikelihoodField, xy, n, wall: float) -> float | None:
    """How far (m, along the corridor's left ``n``) the estimate at map point ``xy`` must
    move for the grid's wall on that side to be where depth saw it (``wall``: signed, m
    across the corridor from the robot); None when the grid has no wall within
    ``GRID_MATCH_M`` of that distance there (a doorway, a junction, another wall seen)."""
    way = np.array([[n[0], n[1]]]) * math.copysign(1.0, wall)
    found, _ = grid.march(np.array([xy], float), way, abs(wall) + GRID_MATCH_M)
    if not math.isfinite(float(found[0])) or abs(float(found[0]) - abs(wall)) > GRID_MATCH_M:
        return None
    return math.copysign(float(found[0]) - abs(wall), wall)


def keep_on_axis(
    b: PmNavBehaviour, odom: Pose2D, line: WallLine, worked: AxisCorrection | None = None
) -> str | None:
    """Correct ``map_T_odom`` with a corridor wall seen while driving (from odometry pose
    ``odom``; ``axis_correction``), taking the correction ``worked`` out in the worker when
    it was worked out on the estimate as it is now. Writes ``map_T_odom`` and
    ``pose_tracker``; returns what it did (None: the wall is not the corridor's, nothing
    changed)."""
    if b.get("map_T_odom") is None:
        return None
    tracker = tracker_of(b)
    fix = worked
    if fix is None or fix.before != tracker.map_T_odom:
        fix = axis_correction(b.ctx.pm, tracker.map_T_odom, odom, line, b.ctx.walls.field)
    if fix.after is None:
        return None
    tracker.map_T_odom = fix.after
    b.bb.set("map_T_odom", tracker.map_T_odom)
    b.bb.set("pose_tracker", tracker)
    return fix.words
