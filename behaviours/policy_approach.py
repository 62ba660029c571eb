"""The approach driven by a pixel-goal policy (PixelNav) in closed loop."""

from __future__ import annotations

from py_trees.common import Status

from pmnav_bt.behaviours.motion import MAX_BUMPS, Approach, DriveTo
from pmnav_bt.behaviours.search import target_entity
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import Action
from pmnav_bt.seams import DiscreteAction, MotionStatus, PixelGoalPolicy


class PolicyApproach(Approach):
    """Approach the goal room's door with the context's pixel-goal policy, one discrete
    step per frame, until the policy stops (the paper's fine-grained actions). It first
    turns to face the door where it was grounded (the search may have turned away since).

    Reads ``target``, ``choice`` (the grounded detection), ``map_T_odom``. The goal pixel
    is the grounder's mask centre: re-grounded in the current frame at the start and every
    ``refiner.regrounding`` steps (a miss keeps the policy's own goal tracking); each frame,
    grounding and the policy's step run in the worker. Any other target (a landmark passed
    on the way, reached on the corridor centre line), a target grounded without a mask,
    and a policy that has not stopped within its ``max_steps`` fall back to the map
    approach (``Approach``). FAILURE: BLOCKED after repeated collisions, BASE_FAULT, or
    the worker's failure.
    """

    READS = (*Approach.READS, "choice")

    def initialise(self) -> None:
        super().initialise()
        t, choice = self.get("target"), self.get("choice")
        policy = self.ctx.refiner
        self._closed_loop = (
            isinstance(policy, PixelGoalPolicy)
            and t is not None
            and t.action == Action.ARRIVE
            and choice is not None
            and choice.detection.mask is not None
        )
        self._job = None
        self._steps = 0
        self._policy_bumps = 0
        self._facing = False
        if self._closed_loop:  # face the goal first: the policy starts from its frame
            obs, det = choice.view.observation, choice.detection
            self._goal_yaw = obs.pose.yaw + obs.intrinsics.pixel_bearing(det.centre[0])

    def update(self) -> Status:
        if not self._closed_loop:
            return super().update()
        base = self.ctx.base
        st = base.motion_status()
        if st == MotionStatus.FAULT:
            return self.fail(FailureCode.BASE_FAULT, "the base reports a fault")
        if st == MotionStatus.MOVING:
            return Status.RUNNING
        if not self._facing:
            if not self.face(self._goal_yaw):
                return Status.RUNNING
            self._facing = True
        if self._job is None:
            if st == MotionStatus.BLOCKED:
                base.stop()  # acknowledged: IDLE again
                self._policy_bumps += 1
                if self._policy_bumps >= MAX_BUMPS:
                    return self.fail(FailureCode.BLOCKED, f"{self._policy_bumps} collisions")
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
            self.feedback_message = f"the policy stopped after {self._steps} steps"
            return Status.SUCCESS
        base.step(step.action)
        self._steps += 1
        self.feedback_message = (
            f"step {self._steps}: {step.action.value}, ~{step.steps_to_goal:.0f} steps to go"
        )
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

    def terminate(self, new_status: Status) -> None:
        if getattr(self, "_job", None) is not None:
            self._job.cancel()
            self._job = None
        super().terminate(new_status)
