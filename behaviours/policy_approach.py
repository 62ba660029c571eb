"""The approach driven by a pixel-goal policy (PixelNav) in closed loop."""

from __future__ import annotations

import math

from py_trees.common import Status

from pmnav_bt.behaviours.motion import MAX_CONTACTS, Approach, DriveTo
from pmnav_bt.behaviours.search import target_entity
from pmnav_bt.eval.task import SUCCESS_RADIUS_M
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import Action
from pmnav_bt.seams import DiscreteAction, MotionStatus

# A policy STOP farther than this from the door on the map is finished by the map approach:
# the success radius less a margin for the estimate's error (STOP is the policy's weak
# part: it stops early, docs/pixelnav.md).
STOP_CHECK_M = SUCCESS_RADIUS_M - 0.2


class PolicyApproach(Approach):
    """Approach the goal room's door with the context's pixel-goal policy (a refiner that
    ``drives_approach``: a ``seams.PixelGoalPolicy``), one discrete step per frame, until
    the policy stops (the paper's fine-grained actions). It first turns to face the door
    where it was grounded (the search may have turned away since); the turn is a velocity
    command, so the body reads MOVING until ``face`` stops it.

    Reads ``target``, ``choice`` (the grounded detection), ``map_T_odom``. The goal pixel
    is the grounder's mask centre: re-grounded in the current frame at the start and every
    ``refiner.regrounding`` steps (a miss keeps the policy's own goal tracking); each frame,
    grounding and the policy's step run in the worker. Any other target (a landmark passed
    on the way, reached on the corridor centre line), a target grounded without a mask,
    and a policy that has not stopped within its ``max_steps`` fall back to the map
    approach (``Approach``), and so does a door farther than ``refiner.policy_range`` on
    the map when grounded: beyond it the policy's skill is not reliable (docs/pixelnav.md),
    and a STOP more than ``STOP_CHECK_M`` from the door on the map (the map approach
    finishes it).
    Repeated collisions of the policy's steps end it: SUCCESS at the door (within
    ``STOP_CHECK_M`` on the map), else the map approach. FAILURE: BASE_FAULT, the map
    approach's failures, or the worker's failure.
    """

    READS = (*Approach.READS, "choice")
    JOBS = Approach.JOBS + ("_job",)

    def initialise(self) -> None:
        super().initialise()
        t, choice = self.get("target"), self.get("choice")
        policy = self.ctx.refiner
        self._closed_loop = (
            policy.drives_approach
            and t is not None
            and t.action == Action.ARRIVE
            and choice is not None
            and choice.detection.mask is not None
            and self._door_distance(t) <= self.ctx.config.refiner.policy_range
        )
        self._job = None
        self._steps = 0
        self._policy_bumps = 0
        self._facing = False
        if self._closed_loop:  # face the goal first: the policy starts from its frame
            obs, det = choice.view.observation, choice.detection
            self._goal_yaw = obs.pose.yaw + obs.intrinsics.pixel_bearing(det.centre[0])

    def _door_distance(self, t) -> float:
        """Metres from the map pose estimate to the goal room's door (``t.target``)."""
        est = self.estimate()
        return math.hypot(float(t.target[0]) - est.x, float(t.target[1]) - est.y)

    def update(self) -> Status:
        if not self._closed_loop:
            return super().update()
        base = self.ctx.base
        st = base.motion_status()
        if st == MotionStatus.FAULT:
            return self.fail(FailureCode.BASE_FAULT, "the base reports a fault")
        if not self._facing:  # a velocity turn: MOVING until face() stops it
            if not self.face(self._goal_yaw):
                return Status.RUNNING
            self._facing = True
            st = base.motion_status()
        if st == MotionStatus.MOVING:  # a discrete step under way
            return Status.RUNNING
        if self._job is None:
            if st == MotionStatus.BLOCKED:
                base.stop()  # acknowledged: IDLE again
                self._policy_bumps += 1
                if self._policy_bumps >= MAX_CONTACTS:
                    return self._blocked()
            if self._steps >= self.ctx.refiner.max_steps:
                self._closed_loop = False
                DriveTo.initialise(self)
                self.feedback_message = f"no stop in {self._steps} steps: map approach"
                return Status.RUNNING
            self._job = self.ctx.worker.submit(self._step_job())
            return Status.RUNNING
        status, step = self.poll(self._job, "running the pixel-goal policy")
        if status is not None:
            return status
        self._job = None
        if step.action == DiscreteAction.STOP:
            base.stop()
            away = self._door_distance(self.get("target"))
            if away > STOP_CHECK_M:
                self._closed_loop = False
                DriveTo.initialise(self)
                self.feedback_message = f"the policy stopped {away:.1f} m away: map approach"
                return Status.RUNNING
            self.feedback_message = f"the policy stopped after {self._steps} steps"
            return Status.SUCCESS
        base.step(step.action)
        self._steps += 1
        self.feedback_message = (
            f"step {self._steps}: {step.action.value}, ~{step.steps_to_goal:.0f} steps to go"
        )
        return Status.RUNNING

    def _blocked(self) -> Status:
        """Repeated collisions of the policy's steps: at the door on the map (within
        ``STOP_CHECK_M``) the body is as near as it gets, so SUCCESS; farther, the map
        approach takes over (it has its own collision and obstacle handling)."""
        away = self._door_distance(self.get("target"))
        if away <= STOP_CHECK_M:
            self.feedback_message = f"blocked {away:.1f} m from the door: arrived"
            return Status.SUCCESS
        self._closed_loop = False
        DriveTo.initialise(self)
        self.feedback_message = f"blocked {away:.1f} m from the door: map approach"
        return Status.RUNNING

    def _step_job(self):
        """The worker's part of one step: a frame, maybe a re-grounding, the policy's act."""
        base, grounder, policy = self.ctx.base, self.ctx.grounder, self.ctx.refiner
        target = target_entity(self)
        choice = self.get("choice")
        first = self._steps == 0
        reground = first or self._steps % self.ctx.config.refiner.regrounding == 0

        def job(cancelled):
            obs = base.observe()
            if reground and target is not None and not cancelled.is_set():
                masked = [d for d in grounder.detect(obs, target) if d.mask is not None]
                if masked:
                    policy.reset(obs, max(masked, key=lambda d: d.score))
                elif first:  # the frame it was grounded in
                    policy.reset(choice.view.observation, choice.detection)
            return policy.act(obs)

        return job
