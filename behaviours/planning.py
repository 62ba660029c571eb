"""Plan, target determination, target update and the bookkeeping of recovery."""

from __future__ import annotations

import math

from py_trees.common import Status

from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context, map_pose
from pmnav_bt.errors import PlanningError, UnknownNameError
from pmnav_bt.failures import Failure, FailureCode, root_cause
from pmnav_bt.map.updates import corridor_blocked
from pmnav_bt.map.wording import corridor_words
from pmnav_bt.planning.resolve import resolve_room
from pmnav_bt.seams import PlanConstraints
from pmnav_bt.way_ahead import BlockedWay


class MakePlan(PmNavBehaviour):
    """Plan from the estimated map pose to the goal (in the worker).

    Reads ``goal``, ``map_T_odom``, ``avoid_landmarks``, ``blocked_segments``,
    ``blocked_ways``; writes ``plan``, ``step_index`` (0), ``last_action`` (None),
    ``target`` (None), ``recovering_from`` (None: a new plan ends the recovery under way).
    FAILURE: INVALID_GOAL for an unknown room, PLANNING_FAILED when no route exists,
    BLOCKED when only corridors found blocked would serve (DOOR_CLOSED when one of them
    is shut by a closed fire door), saying which in the building's words; a planner back
    end's own failure code otherwise (VLM_ERROR, INTERNAL_ERROR, ...).
    """

    READS = ("goal", "map_T_odom", "avoid_landmarks", "blocked_segments", "blocked_ways")
    WRITES = ("plan", "step_index", "last_action", "target", "recovering_from")
    JOBS = ("_job",)

    def initialise(self) -> None:
        self.bb.set("target", None)  # a planning failure belongs to no step
        start = map_pose(self.get("map_T_odom"), self.ctx.base.pose())
        goal = self.get("goal")
        constraints = PlanConstraints(
            avoid_landmarks=frozenset(self.get("avoid_landmarks") or ()),
            blocked_segments=frozenset(self.get("blocked_segments") or ()),
            blocked_at=frozenset(w.point for w in (self.get("blocked_ways") or {}).values()),
        )
        planner, pm = self.ctx.planner, self.ctx.pm
        self._job = self.ctx.worker.submit(lambda c: planner.plan(pm, start, goal, constraints))

    def update(self) -> Status:
        status, plan = self.poll(self._job, "planning", self._classify)
        if status is not None:
            return status
        self.bb.set("plan", plan)
        self.bb.set("step_index", 0)
        self.bb.set("last_action", None)
        self.bb.set("recovering_from", None)
        self.ctx.log(
            "plan",
            plan.goal,
            steps=[s.text() for s in plan.steps],
            path=[list(p) for p in plan.path],
        )
        self.feedback_message = f"{len(plan.steps)} steps, {plan.length:.1f} m"
        return Status.SUCCESS

    def _classify(self, err: BaseException) -> Failure | None:
        """The planning errors that mean more than their type: a blocked way, a bad goal."""
        if isinstance(err, PlanningError) and self.get("blocked_segments"):
            ways = self.get("blocked_ways") or {}
            pm = self.ctx.pm
            why = [
                ways[i].failure.message if i in ways else f"{corridor_words(pm.segment(i))} blocked"
                for i in sorted(self.get("blocked_segments"))
            ]
            door = any(w.failure.code == FailureCode.DOOR_CLOSED for w in ways.values())
            code = FailureCode.DOOR_CLOSED if door else FailureCode.BLOCKED
            return Failure(code, f"no way round: {'; '.join(why)}")
        if isinstance(err, UnknownNameError) and not _names_a_room(self.ctx, self.get("goal")):
            return Failure(FailureCode.INVALID_GOAL, str(err))  # the goal, not the start
        if isinstance(err, (PlanningError, UnknownNameError)):
            return Failure(FailureCode.PLANNING_FAILED, str(err))
        return None


class CheckGoal(PmNavBehaviour):
    """The goal names a room of the map. Reads ``goal``; FAILURE (INVALID_GOAL) if not."""

    READS = ("goal",)

    def update(self) -> Status:
        goal = self.get("goal")
        try:
            room = resolve_room(self.ctx.pm, str(goal))
        except UnknownNameError as err:
            return self.fail(FailureCode.INVALID_GOAL, str(err))
        self.feedback_message = f"goal {room}"
        return Status.SUCCESS


class PlanComplete(PmNavBehaviour):
    """SUCCESS when every step of the plan is done. Reads ``plan``, ``step_index``."""

    READS = ("plan", "step_index")

    def update(self) -> Status:
        plan = self.get("plan")
        done = plan is not None and (self.get("step_index") or 0) >= len(plan.steps)
        return Status.SUCCESS if done else Status.FAILURE


class DetermineTarget(PmNavBehaviour):
    """Target determination: the current step becomes the target.

    Reads ``plan``, ``step_index``; writes ``target``.
    """

    READS = ("plan", "step_index")
    WRITES = ("target",)

    def update(self) -> Status:
        plan, i = self.get("plan"), self.get("step_index") or 0
        if plan is None or i >= len(plan.steps):
            return self.fail(FailureCode.PLANNING_FAILED, "no step left to target")
        step = plan.steps[i]
        self.bb.set("target", step)
        self.feedback_message = f"step {i + 1}/{len(plan.steps)}: {step.text()}"
        return Status.SUCCESS


class TargetIs(PmNavBehaviour):
    """Condition: the target is visible (a sign to find) or not (a turn or fork to reach).

    Reads ``target``.
    """

    READS = ("target",)

    def __init__(self, name: str, ctx: Context, visible: bool):
        super().__init__(name, ctx)
        self.visible = visible

    def update(self) -> Status:
        t = self.get("target")
        return Status.SUCCESS if t is not None and t.visible == self.visible else Status.FAILURE


class UpdateTarget(PmNavBehaviour):
    """Target update: on to the next step. Reads ``step_index``, ``target``;
    writes ``step_index``, ``last_action``."""

    READS = ("step_index", "target")
    WRITES = ("step_index", "last_action")

    def update(self) -> Status:
        t = self.get("target")
        self.bb.set("step_index", (self.get("step_index") or 0) + 1)
        self.bb.set("last_action", t.action)
        self.ctx.log("step", t.landmark, action=t.action.value)
        return Status.SUCCESS


class NoteFailure(PmNavBehaviour):
    """Before a replan: remember what failed so the next plan avoids it.

    Reads ``failure``, ``target``, ``map_T_odom``, ``replans``, ``avoid_landmarks``,
    ``blocked_segments``, ``blocked_suspects``, ``blocked_ways``, ``way_shut``; writes
    ``replans``, ``avoid_landmarks``, ``blocked_segments``, ``blocked_suspects``,
    ``blocked_ways``, ``way_shut`` (None: used up), ``recovering_from`` (the root cause:
    a failure during the recovery reports it as its ``cause``). A target not found is
    avoided (unless it is the goal). A corridor a drive saw shut by something standing
    still for the whole patience (``way_shut``: a barrier, a closed fire door) is marked
    blocked for the rest of the run at once, with the failure that says so
    (``blocked_ways``), so the plan goes round it after one replan and never comes back
    to it. A way shut by someone moving marks nothing (people walk on). A corridor found
    blocked otherwise (collisions, no progress) is suspected (a poor pose estimate can
    make a wall look like an obstacle; the replan re-localizes first); found blocked
    again, it is not routed through any more.
    """

    READS = (
        "failure",
        "target",
        "map_T_odom",
        "replans",
        "avoid_landmarks",
        "blocked_segments",
        "blocked_suspects",
        "blocked_ways",
        "way_shut",
    )
    WRITES = (
        "replans",
        "avoid_landmarks",
        "blocked_segments",
        "blocked_suspects",
        "blocked_ways",
        "way_shut",
        "recovering_from",
    )

    def update(self) -> Status:
        self.bb.set("replans", (self.get("replans") or 0) + 1)
        failure, t = self.get("failure"), self.get("target")
        if failure is not None:
            self.bb.set("recovering_from", self.get("recovering_from") or root_cause(failure))
        plan_goal = t is not None and t.action.value == "arrive"
        not_found = failure is not None and failure.code == FailureCode.TARGET_NOT_FOUND
        if not_found and t is not None and t.look_for and not plan_goal:
            self.bb.set(
                "avoid_landmarks", frozenset(self.get("avoid_landmarks") or ()) | {t.look_for}
            )
        shut = self.get("way_shut")
        self.bb.set("way_shut", None)
        if failure is not None and failure.code in WAY_SHUT and shut is not None:
            if not shut.moving:
                seg = self.ctx.pm.locate(*shut.point).segment.index
                self._mark_blocked(seg, BlockedWay(shut.point, failure), failure)
        elif failure is not None and failure.code == FailureCode.BLOCKED and t is not None:
            est = map_pose(self.get("map_T_odom"), self.ctx.base.pose())
            ahead = (est.x + 0.6 * math.cos(est.yaw), est.y + 0.6 * math.sin(est.yaw))
            seg = self.ctx.pm.locate(*ahead).segment.index
            suspects = frozenset(self.get("blocked_suspects") or ())
            if seg in suspects:
                self._mark_blocked(seg, None, failure)
            else:
                self.bb.set("blocked_suspects", suspects | {seg})
        self.ctx.log("replan", str(failure) if failure else "")
        self.feedback_message = f"replan after {failure}"
        return Status.SUCCESS

    def _mark_blocked(self, seg: int, why: BlockedWay | None, failure: Failure) -> None:
        """Route round segment ``seg`` from now on, and write it to the map updates;
        ``why``: where and how it was seen shut."""
        self.bb.set("blocked_segments", frozenset(self.get("blocked_segments") or ()) | {seg})
        odom, tf = self.ctx.base.pose(), self.get("map_T_odom")
        est = map_pose(tf, odom) if tf is not None else None
        self.ctx.map_updates.record(
            corridor_blocked(self.ctx.pm, seg, self.ctx.now(), odom, est, str(failure))
        )
        if why is not None:
            self.bb.set("blocked_ways", {**(self.get("blocked_ways") or {}), seg: why})
        self.ctx.log("blocked", corridor_words(self.ctx.pm.segment(seg)), segment=seg)


# The failures of a drive that gave up on a shut way (it leaves a ``WayShut``).
WAY_SHUT = frozenset({FailureCode.BLOCKED, FailureCode.DOOR_CLOSED})


def _names_a_room(ctx: Context, goal) -> bool:
    try:
        resolve_room(ctx.pm, str(goal))
    except UnknownNameError:
        return False
    return True
