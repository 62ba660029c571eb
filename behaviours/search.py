"""Search for the current target: coarse direction, grounding, fine direction, verification."""

from __future__ import annotations

import math

import numpy as np
from py_trees.common import Status

from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import map_pose
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import se2_apply, wrap_angle
from pmnav_bt.planning.resolve import entity_position, step_entity
from pmnav_bt.pose.landmark_fix import Sighting, fix_pose
from pmnav_bt.seams import CoarseChoice, Entity, EntityKind, View

# How far (m) a sighting may be from where the map puts the target and still be it, when
# no pose tracker says how uncertain the estimate is (it does after a fix).
VERIFY_TOLERANCE = 3.0
# How much of a verified sighting's disagreement with the map goes into map_T_odom.
CORRECTION_GAIN = 0.9
# Verified sightings kept for re-fitting map_T_odom, and what a re-fit needs.
RECENT_SIGHTINGS = 3
REFIT_RESIDUAL = 0.6
MIN_REFIT_SPREAD = 3.0


def target_entity(b: PmNavBehaviour) -> Entity | None:
    """The room or landmark the current target step looks for (None: nothing to see)."""
    t = b.get("target")
    if t is None or t.look_for is None:
        return None
    return step_entity(b.ctx.pm.building, t.look_for)


def target_bearing(b: PmNavBehaviour) -> float:
    """The current target's bearing by the map from the estimated pose, relative to the
    heading (rad; 0 without a target or a pose estimate): towards its door or landmark
    (where the sign is), else its node on the centre line (from level with the node, the
    node's own bearing says nothing)."""
    t, tf = b.get("target"), b.get("map_T_odom")
    if t is None or tf is None:
        return 0.0
    est = map_pose(tf, b.ctx.base.pose())
    x, y = (float(v) for v in (t.target if t.target is not None else t.position))
    return wrap_angle(math.atan2(y - est.y, x - est.x) - est.yaw)


class CoarseDirection(PmNavBehaviour):
    """Pick the view that shows the target with the context's coarse-direction back end
    (``detector``: the best grounding score across the views; a VLM takes seconds), in
    the worker.

    Reads ``views``, ``target``; writes ``choice`` (CoarseChoice: view + detection).
    FAILURE: TARGET_NOT_FOUND when no view shows it; the back end's code when it fails.
    """

    READS = ("views", "target")
    WRITES = ("choice",)
    JOBS = ("_job",)

    def initialise(self) -> None:
        views, target, coarse = tuple(self.get("views") or ()), target_entity(self), self.ctx.coarse
        self._n_views = len(views)
        self._job = (
            None
            if target is None
            else self.ctx.worker.submit(lambda c: coarse.choose(views, target))
        )

    def update(self) -> Status:
        choice: CoarseChoice | None = None
        if self._job is not None:
            status, choice = self.poll(self._job, "choosing the coarse direction")
            if status is not None:
                return status
        if choice is None:
            t = self.get("target")
            return self.fail(
                FailureCode.TARGET_NOT_FOUND,
                f"{t.look_for if t else 'target'} not seen in {self._n_views} views",
            )
        self.bb.set("choice", choice)
        self.feedback_message = (
            f"seen at {math.degrees(choice.view.relative_yaw):+.0f} deg "
            f"(score {choice.detection.score:.2f})"
        )
        return Status.SUCCESS


class FaceAndGround(PmNavBehaviour):
    """Face a heading, then ground a target in a fresh frame (in the worker, which skips
    the detection once cancelled). The best detection ``accept`` takes becomes ``choice``
    with the new frame; if none, the old ``choice`` stands. SUCCESS either way, unless
    ``MUST_SEE``: then FAILURE (TARGET_NOT_FOUND) when the fresh frame shows none.

    Subclasses say where to look and for what (``aim``) and which detections count
    (``accept``). Writes ``choice``.
    """

    WRITES = ("choice",)
    JOBS = ("_job",)
    STOPS_BASE = True
    ACTIVITY = "grounding the target"  # what a failed job was doing
    KEPT = "not in the fresh frame: keeping the earlier detection"
    MUST_SEE = False

    def aim(self) -> tuple[float, Entity | None]:
        """The heading to face (rad, odometry frame) and what to ground there."""
        raise NotImplementedError

    def accept(self, detection) -> bool:
        raise NotImplementedError

    def initialise(self) -> None:
        self._yaw, self._target = self.aim()
        self._job = None

    def update(self) -> Status:
        if self._job is None:
            if not self.face(self._yaw):
                return Status.RUNNING
            base, grounder, target = self.ctx.base, self.ctx.grounder, self._target

            def take(cancelled):
                obs = base.observe()
                if cancelled.is_set() or target is None:
                    return obs, ()
                return obs, tuple(grounder.detect(obs, target))

            self._job = self.ctx.worker.submit(take)
            return Status.RUNNING
        status, taken = self.poll(self._job, self.ACTIVITY)
        if status is not None:
            return status
        obs, dets = taken
        accepted = [d for d in dets if self.accept(d)]
        if accepted:
            best = max(accepted, key=lambda d: d.score)
            self.bb.set("choice", CoarseChoice(View(0.0, obs, dets), best))
            self.feedback_message = f"seen in the fresh frame, score {best.score:.2f}"
        elif self.MUST_SEE:
            return self.fail(FailureCode.TARGET_NOT_FOUND, f"{self._target} not in the fresh frame")
        else:
            self.feedback_message = self.KEPT
        return Status.SUCCESS


class Ground(FaceAndGround):
    """Grounding: face the coarse direction and ground the target in a fresh frame.

    Reads ``choice``, ``target``; writes ``choice`` (the new frame and its best detection,
    with a mask). Facing the target keeps its mask off the image border, where a cut-off
    mask would bias the bearing and range. If the fresh frame misses the target, the
    coarse view's detection stands.
    """

    READS = ("choice", "target")
    KEPT = "not in the fresh frame: keeping the coarse view's detection"

    def aim(self) -> tuple[float, Entity | None]:
        choice: CoarseChoice = self.get("choice")
        obs, det = choice.view.observation, choice.detection
        yaw = obs.pose.yaw + obs.intrinsics.pixel_bearing(det.centre[0])
        return yaw, target_entity(self) or det.entity

    def accept(self, detection) -> bool:
        return detection.mask is not None


class FineDirection(PmNavBehaviour):
    """Refine the bearing to the target and place it in the odometry frame.

    Reads ``choice``, ``target``, ``map_T_odom``; writes ``bearing`` (relative to the
    chosen view) and ``sighting`` (the target seen, odometry frame). The refiner gives
    the bearing, and the range when it measures one (``Refinement.range``); without a
    range the target is taken along the bearing, as far as the map predicts. The refiner
    runs in the worker (FAILURE with its code if it fails). With
    ``refine=False`` (the coarse-only variant, paper Table 4) the target is taken
    straight ahead of the view it was seen in.
    """

    READS = ("choice", "target", "map_T_odom")
    WRITES = ("bearing", "sighting")
    JOBS = ("_job",)

    def __init__(self, name: str, ctx, refine: bool = True):
        super().__init__(name, ctx)
        self.refine = refine

    def initialise(self) -> None:
        choice: CoarseChoice = self.get("choice")
        obs, det = choice.view.observation, choice.detection
        refiner = self.ctx.refiner
        # A refiner may be a network (PixelNav): it runs in the worker.
        self._job = (
            self.ctx.worker.submit(lambda c: refiner.refine(obs, det)) if self.refine else None
        )

    def update(self) -> Status:
        choice: CoarseChoice = self.get("choice")
        obs, det = choice.view.observation, choice.detection
        bearing, rng = 0.0, None
        if self._job is not None:
            status, refined = self.poll(self._job, "refining the direction")
            if status is not None:
                return status
            bearing, rng = float(refined.bearing), refined.range
        t = self.get("target")
        entity = target_entity(self)
        m = entity_position(self.ctx.pm, entity)
        if rng is None:
            est = map_pose(self.get("map_T_odom"), obs.pose)
            rng = float(np.hypot(m[0] - est.x, m[1] - est.y))
        body = np.array([rng * math.cos(bearing), rng * math.sin(bearing)])
        odom = se2_apply((obs.pose.x, obs.pose.y, obs.pose.yaw), body)
        s = Sighting(entity, (float(m[0]), float(m[1])), (float(odom[0]), float(odom[1])))
        self.bb.set("bearing", bearing)
        self.bb.set("sighting", s)
        self.ctx.log("detection", t.look_for, obs.rgb, score=det.score, seen_odom=list(s.odom_xy))
        self.feedback_message = f"{t.look_for} at {math.degrees(bearing):+.1f} deg"
        return Status.SUCCESS


class Verify(PmNavBehaviour):
    """Verify the sighting against the map, then correct the pose estimate with it.

    Reads ``sighting``, ``map_T_odom``, ``recent_sightings``, ``pose_tracker``; writes
    ``map_T_odom``, ``recent_sightings``, ``pose_tracker``. A sighting farther from where
    the map puts the target than the pose uncertainty allows (the tracker's tolerance, or
    VERIFY_TOLERANCE without one) is a wrong landmark (FAILURE, TARGET_NOT_FOUND), so the
    search runs again. A verified one re-fits ``map_T_odom`` on the last few verified
    sightings (position and heading), or shifts it towards this one alone.
    """

    READS = ("sighting", "map_T_odom", "recent_sightings", "pose_tracker")
    WRITES = ("map_T_odom", "recent_sightings", "pose_tracker")

    def update(self) -> Status:
        s = self.get("sighting")
        tf = self.get("map_T_odom") or (0.0, 0.0, 0.0)
        seen = se2_apply(tf, s.odom_xy)
        err = np.asarray(s.map_xy) - seen
        dist = float(np.hypot(*err))
        tracker, odometer = self.get("pose_tracker"), self.ctx.odometer.distance
        tol = tracker.verify_tolerance(odometer) if tracker is not None else VERIFY_TOLERANCE
        if dist > tol:
            return self.fail(
                FailureCode.TARGET_NOT_FOUND,
                f"{s.entity} seen {dist:.1f} m from where the map puts it (tolerance "
                f"{tol:.1f} m): not it",
            )
        recent = [r for r in (self.get("recent_sightings") or []) if r.entity != s.entity]
        landmark = s.entity.kind is EntityKind.LANDMARK
        if not landmark:
            recent = (recent + [s])[-RECENT_SIGHTINGS:]
            self.bb.set("recent_sightings", recent)
        refit = fix_pose(recent, max_residual=REFIT_RESIDUAL) if len(recent) >= 2 else None
        how = "shifted"
        if landmark:
            # A landmark is known by its sign, which may hang beside it (an elevator's,
            # ~1.5 m along the wall): it tells how far the wall is, not where along it.
            err = across_wall(self.ctx.pm, s.entity, err)
            how = "shifted across its wall"
        elif refit is not None and _spread(recent) >= MIN_REFIT_SPREAD:
            tf = refit.map_T_odom  # heading from the recent landmarks ...
            err = np.asarray(s.map_xy) - se2_apply(tf, s.odom_xy)
            how = f"re-fit on {len(refit.entities)} landmarks, shifted"
        # ... position from the newest one, the best reference for what comes next.
        x, y, yaw = tf
        gain = CORRECTION_GAIN
        corrected = (x + gain * float(err[0]), y + gain * float(err[1]), yaw)
        self.bb.set("map_T_odom", corrected)
        if tracker is not None:
            tracker.reset(corrected, (1.0 - gain) * float(np.hypot(*err)), odometer)
            self.bb.set("pose_tracker", tracker)
        self.feedback_message = f"{s.entity} verified ({dist:.2f} m off the map; {how})"
        return Status.SUCCESS


def across_wall(pm, entity: Entity, err: np.ndarray) -> np.ndarray:
    """The part of ``err`` (map metres) across the corridor wall that ``entity`` is on."""
    heading = pm.segments[pm.places[entity.id].segment - 1].heading
    normal = np.array([-math.sin(heading), math.cos(heading)])
    return normal * float(err @ normal)


def _spread(sightings: list[Sighting]) -> float:
    pts = np.array([r.map_xy for r in sightings])
    return float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
