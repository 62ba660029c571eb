"""Plan, target determination, target update and the bookkeeping of recovery."""

from __future__ import annotations

import math

from py_trees.common import Status

from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context, map_pose
from pmnav_bt.errors import PlanningError, UnknownNameError
from pmnav_bt.failures import Failure, FailureCode, root_cause
from pmnav_bt.map.updates import corridor_blocked
from pmnav_bt.planning.resolve import resolve_room
from pmnav_bt.seams import PlanConstraints


class MakePlan(PmNavBehaviour):
    """Plan from the estimated map pose to the goal (in the worker).

    Reads ``goal``, ``map_T_odom``, ``avoid_landmarks``, ``blocked_segments``;
    writes ``plan``, ``step_index`` (0), ``last_action`` (None), ``target`` (None),
    ``recovering_from`` (None: a new plan ends the recovery under way).
    FAILURE: INVALID_GOAL for an unknown room, PLANNING_FAILED when no route exists,
    BLOCKED when only corridors found blocked would serve; a planner back end's own
    failure code otherwise (VLM_ERROR, INTERNAL_ERROR, ...).
    """

    READS = ("goal", "map_T_odom", "avoid_landmarks", "blocked_segments")
    WRITES = ("plan", "step_index", "last_action", "target", "recovering_from")
    JOBS = ("_job",)

    def initialise(self) -> None:
        self.bb.set("target", None)  # a planning failure belongs to no step
        start = map_pose(self.get("map_T_odom"), self.ctx.base.pose())
        goal = self.get("goal")
        constraints = PlanConstraints(
            avoid_landmarks=frozenset(self.get("avoid_landmarks") or ()),
            blocked_segments=frozenset(self.get("blocked_segments") or ()),
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
            segs = ", ".join(f"seg{i}" for i in sorted(self.get("blocked_segments")))
            return Failure(FailureCode.BLOCKED, f"no route around the blocked {segs}")
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
    ``blocked_segments``, ``blocked_suspects``; writes ``replans``, ``avoid_landmarks``,
    ``blocked_segments``, ``blocked_suspects``, ``recovering_from`` (the root cause: a
    failure during the recovery reports it as its ``cause``). A target not found is avoided (unless
    it is the goal). A corridor found blocked once is suspected (a poor pose estimate
    can make a wall look like an obstacle; the replan re-localizes first); found
    blocked again, it is not routed through any more.
    """

    READS = (
        "failure",
        "target",
        "map_T_odom",
        "replans",
        "avoid_landmarks",
        "blocked_segments",
        "blocked_suspects",
    )
    WRITES = (
        "replans",
        "avoid_landmarks",
        "blocked_segments",
        "blocked_suspects",
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
        if failure is not None and failure.code == FailureCode.BLOCKED and t is not None:
            est = map_pose(self.get("map_T_odom"), self.ctx.base.pose())
            ahead = (est.x + 0.6 * math.cos(est.yaw), est.y + 0.6 * math.sin(est.yaw))
            seg = self.ctx.pm.locate(*ahead).segment.index
            suspects = frozenset(self.get("blocked_suspects") or ())
            if seg in suspects:
                blocked = frozenset(self.get("blocked_segments") or ()) | {seg}
                self.bb.set("blocked_segments", blocked)
                self.ctx.map_updates.record(
                    corridor_blocked(self.ctx.pm, seg, self.ctx.now(), self.ctx.base.pose(),
                                     est if self.get("map_T_odom") else None, str(failure))
                )  # fmt: skip
            else:
                self.bb.set("blocked_suspects", suspects | {seg})
        self.ctx.log("replan", str(failure) if failure else "")
        self.feedback_message = f"replan after {failure}"
        return Status.SUCCESS


def _names_a_room(ctx: Context, goal) -> bool:
    try:
        resolve_room(ctx.pm, str(goal))
    except UnknownNameError:
        return False
    return True
