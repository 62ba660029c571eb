"""Search for the current target: coarse direction, grounding, fine direction, verification."""

from __future__ import annotations

import math

import numpy as np
from py_trees.common import Status

from pmnav_bt.behaviours.capture import CapturedView
from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context, map_pose, thumbnail
from pmnav_bt.control import rotate_command
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import se2_apply
from pmnav_bt.localization import Sighting, fix_pose
from pmnav_bt.perception.geometry import target_point
from pmnav_bt.planning.resolve import entity_position

# How far (m) a sighting may be from where the map puts the target and still be it.
VERIFY_TOLERANCE = 3.0
# How much of a verified sighting's disagreement with the map goes into map_T_odom.
CORRECTION_GAIN = 0.9
# Verified sightings kept for re-fitting map_T_odom, and what a re-fit needs.
RECENT_SIGHTINGS = 3
REFIT_RESIDUAL = 0.6
MIN_REFIT_SPREAD = 3.0


def target_query(b: PmNavBehaviour) -> str | None:
    """The text to ground for the current target: its sign as a person would read it."""
    t = b.get("target")
    if t is None or t.look_for is None:
        return None
    entity = target_entity(b.ctx, t.look_for)
    kind, ident = entity.split(":", 1)
    bld = b.ctx.pm.building
    if kind == "room":
        return bld.room(ident).sign_text
    lm = bld.landmark(ident)
    return lm.sign or lm.display_name


def target_entity(ctx: Context, look_for: str) -> str:
    """'room:<id>' or 'landmark:<id>' for a plan step's look_for."""
    ids = {r.id for r in ctx.pm.building.rooms}
    return f"room:{look_for}" if look_for in ids else f"landmark:{look_for}"


class CoarseDirection(PmNavBehaviour):
    """Pick the view that shows the target, with the context's coarse-direction back end
    (``detector``: best grounding score across the views).

    Reads ``views``, ``target``; writes ``choice`` (view, detection). FAILURE
    (TARGET_NOT_FOUND) when no view shows it. ``min_score`` overrides the back end's.
    """

    READS = ("views", "target")
    WRITES = ("choice",)

    def __init__(self, name: str, ctx: Context, min_score: float | None = None):
        super().__init__(name, ctx)
        self.min_score = min_score

    def update(self) -> Status:
        views = self.get("views") or []
        best = self.ctx.coarse.choose_view(views, target_query(self) or "", self.min_score)
        if best is None:
            t = self.get("target")
            return self.fail(
                FailureCode.TARGET_NOT_FOUND,
                f"{t.look_for if t else 'target'} not seen in {len(views)} views",
            )
        self.bb.set("choice", best)
        self.feedback_message = (
            f"seen at {math.degrees(best[0].relative_yaw):+.0f} deg (score {best[1].score:.2f})"
        )
        return Status.SUCCESS


class Ground(PmNavBehaviour):
    """Grounding: face the coarse direction and ground the target in a fresh frame.

    Reads ``choice``; writes ``choice`` (the new frame and its best detection, with a
    mask). Facing the target keeps its mask off the image border, where a cut-off
    mask would bias the bearing and range. If the fresh frame misses the target, the
    coarse view's detection stands.
    """

    READS = ("choice",)
    WRITES = ("choice",)

    def initialise(self) -> None:
        view, det = self.get("choice")
        obs = view.observation
        self._yaw = obs.pose.yaw + obs.intrinsics.pixel_bearing(det.centre[0])
        self._query = det.label
        self._job = None

    def update(self) -> Status:
        base = self.ctx.base
        if self._job is None:
            v, w, done = rotate_command(base.pose(), self._yaw, self.ctx.limits)
            if not done:
                base.set_velocity(v, w)
                return Status.RUNNING
            base.set_velocity(0.0, 0.0)
            query, grounder = self._query, self.ctx.grounder

            def take(cancelled):
                obs = base.observe()
                return obs, ([] if cancelled.is_set() else grounder.detect(obs, query))

            self._job = self.ctx.worker.submit(take)
            return Status.RUNNING
        if not self._job.done():
            return Status.RUNNING
        obs, dets = self._job.result()
        dets = [d for d in dets if d.mask is not None]
        if dets:
            best = max(dets, key=lambda d: d.score)
            self.bb.set("choice", (CapturedView(0.0, obs, dets), best))
            self.feedback_message = f"grounded, score {best.score:.2f}"
        else:
            self.feedback_message = "not in the fresh frame: keeping the coarse view's detection"
        return Status.SUCCESS

    def terminate(self, new_status: Status) -> None:
        if getattr(self, "_job", None) is not None:
            self._job.cancel()
        if new_status == Status.INVALID:
            self.ctx.base.stop()


class FineDirection(PmNavBehaviour):
    """Refine the bearing to the target and place it in the odometry frame.

    Reads ``choice``, ``target``, ``map_T_odom``; writes ``bearing`` (relative to the
    chosen view) and ``sighting`` (the target seen, odometry frame). With the
    ``geometric`` refiner the range comes from depth over the mask; without
    refinement (coarse-only) the target is taken straight ahead of its view, at the
    distance the map predicts.
    """

    READS = ("choice", "target", "map_T_odom")
    WRITES = ("bearing", "sighting")

    def update(self) -> Status:
        view, det = self.get("choice")
        obs = view.observation
        t = self.get("target")
        entity = target_entity(self.ctx, t.look_for)
        bearing = float(self.ctx.refiner.refine(obs, det))
        m = entity_position(self.ctx.pm, entity)
        body = target_point(obs, det)
        if self.ctx.refiner.name != "geometric" or body is None:
            # No grounded range: assume the target lies along the bearing, as far as the map says.
            est = map_pose(self.get("map_T_odom"), obs.pose)
            rng = float(np.hypot(m[0] - est.x, m[1] - est.y))
            body = np.array([rng * math.cos(bearing), rng * math.sin(bearing)])
        odom = se2_apply((obs.pose.x, obs.pose.y, obs.pose.yaw), body)
        s = Sighting(entity, (float(m[0]), float(m[1])), (float(odom[0]), float(odom[1])))
        self.bb.set("bearing", bearing)
        self.bb.set("sighting", s)
        self.ctx.log(
            "detection", t.look_for, thumbnail(obs.rgb), score=det.score, seen_odom=list(s.odom_xy)
        )
        self.feedback_message = f"{t.look_for} at {math.degrees(bearing):+.1f} deg"
        return Status.SUCCESS


class Verify(PmNavBehaviour):
    """Verify the sighting against the map, then correct the pose estimate with it.

    Reads ``sighting``, ``map_T_odom``, ``recent_sightings``; writes ``map_T_odom``,
    ``recent_sightings``. A sighting farther than VERIFY_TOLERANCE from where the map
    puts the target is a wrong landmark (FAILURE, TARGET_NOT_FOUND), so the search
    runs again. A verified one re-fits ``map_T_odom`` on the last few verified
    sightings (position and heading), or shifts it towards this one alone.
    """

    READS = ("sighting", "map_T_odom", "recent_sightings")
    WRITES = ("map_T_odom", "recent_sightings")

    def update(self) -> Status:
        s = self.get("sighting")
        tf = self.get("map_T_odom") or (0.0, 0.0, 0.0)
        seen = se2_apply(tf, s.odom_xy)
        err = np.asarray(s.map_xy) - seen
        dist = float(np.hypot(*err))
        if dist > VERIFY_TOLERANCE:
            return self.fail(
                FailureCode.TARGET_NOT_FOUND,
                f"{s.entity} seen {dist:.1f} m from where the map puts it: not it",
            )
        recent = [r for r in (self.get("recent_sightings") or []) if r.entity != s.entity]
        recent = (recent + [s])[-RECENT_SIGHTINGS:]
        self.bb.set("recent_sightings", recent)
        refit = fix_pose(recent, max_residual=REFIT_RESIDUAL) if len(recent) >= 2 else None
        how = "shifted"
        if refit is not None and _spread(recent) >= MIN_REFIT_SPREAD:
            tf = refit.map_T_odom  # heading from the recent landmarks ...
            err = np.asarray(s.map_xy) - se2_apply(tf, s.odom_xy)
            how = f"re-fit on {len(refit.entities)} landmarks, shifted"
        # ... position from the newest one, the best reference for what comes next.
        x, y, yaw = tf
        gain = CORRECTION_GAIN
        self.bb.set("map_T_odom", (x + gain * float(err[0]), y + gain * float(err[1]), yaw))
        self.feedback_message = f"{s.entity} verified ({dist:.2f} m off the map; {how})"
        return Status.SUCCESS


def _spread(sightings: list[Sighting]) -> float:
    pts = np.array([r.map_xy for r in sightings])
    return float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
