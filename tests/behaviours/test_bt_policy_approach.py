"""PolicyApproach with a scripted pixel-goal policy, on the test doubles (a grounder whose
detections carry masks): the policy's actions drive the body step by step, grounding and
acting run in the worker, the map approach takes over for other targets and for a policy
that never stops, and the tree picks it only for a pixel-goal refiner. Stepping into the
wall by the door needs the wall: pybullet."""

from __future__ import annotations

import math
import threading

import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.policy_approach import PolicyApproach
from pmnav_bt.geometry import Action
from pmnav_bt.seams import (
    CoarseChoice,
    DiscreteAction,
    Entity,
    PixelGoalPolicy,
    PolicyStep,
    Pose2D,
    Refinement,
    View,
)
from pmnav_bt.testing.doubles import ScriptedGrounder

SOUTH = math.radians(-90)
# 2.8 m from room4's door (1.2, 22), facing it: its sign is readable from here
START = Pose2D(0.0, 24.5, math.atan2(22.0 - 24.5, 1.2))
# 1.6 m from the same door on the same line: four steps bring the body to 0.6 m of it
NEAR = Pose2D(1.2 - 1.6 * math.cos(START.yaw), 22.0 - 1.6 * math.sin(START.yaw), START.yaw)


class ScriptedPolicy:
    """Plays ``script`` (then STOP, or forever its last action); records its calls."""

    gives_range = False
    drives_approach = True

    def __init__(self, script, max_steps=64, forever=False):
        self.script, self.max_steps, self.forever = list(script), max_steps, forever
        self.resets, self.acts, self.threads = [], 0, set()

    def refine(self, obs, goal):
        return Refinement(0.0)

    def reset(self, obs, goal):
        self.resets.append((obs.pose, goal))
        self.threads.add(threading.current_thread().name)

    def act(self, obs):
        self.threads.add(threading.current_thread().name)
        i = self.acts
        self.acts += 1
        if i < len(self.script):
            a = self.script[i]
        else:
            a = self.script[-1] if self.forever else DiscreteAction.STOP
        return PolicyStep(a, None, 0.0)


def grounded(rig, goal="room4"):
    """The goal step and a choice grounded in the frame from the body's pose."""
    step = rig.plan(f"0,24.5,{math.degrees(START.yaw)}", goal).steps[-1]
    assert step.action == Action.ARRIVE
    obs = rig.base.observe()
    dets = rig.ctx.grounder.detect(obs, Entity.room(goal))
    assert dets and dets[0].mask is not None
    return step, CoarseChoice(View(0.0, obs, tuple(dets)), dets[0])


def test_the_policy_drives_the_approach_step_by_step_until_it_stops(make_rig, pm):
    rig = make_rig(NEAR, grounder=ScriptedGrounder(pm, masks=True))
    policy = ScriptedPolicy([DiscreteAction.FORWARD] * 4 + [DiscreteAction.TURN_LEFT])
    assert isinstance(policy, PixelGoalPolicy)
    rig.ctx.refiner = policy
    step, choice = grounded(rig)
    rig.set(target=step, choice=choice)
    seen = rig.run(PolicyApproach("Approach", rig.ctx), max_ticks=200)
    rig.expect(seen, Status.SUCCESS)
    p = rig.true_pose()
    ahead = (NEAR.x + 1.0 * math.cos(NEAR.yaw), NEAR.y + 1.0 * math.sin(NEAR.yaw))
    # four 0.25 m steps towards the door (after facing the grounded mask's centre), one turn
    assert math.dist((p.x, p.y), ahead) < 0.05
    assert math.isclose(p.yaw, NEAR.yaw + math.radians(30), abs_tol=math.radians(3))
    assert policy.acts == 6  # five moves, then STOP: 0.6 m from the door, accepted
    assert rig.stopped()
    # re-grounded in the current frame at the start (regrounding: every 8 steps)
    assert len(policy.resets) == 1 and policy.resets[0][1].mask is not None
    assert all(name.startswith("pmnav-worker") for name in policy.threads)


def test_a_stop_short_of_the_door_is_finished_by_the_map_approach(make_rig, pm):
    # 2.8 m from the door; the policy stops after three steps
    rig = make_rig(START, grounder=ScriptedGrounder(pm, masks=True))
    policy = ScriptedPolicy([DiscreteAction.FORWARD] * 3)
    rig.ctx.refiner = policy
    step, choice = grounded(rig)
    rig.set(target=step, choice=choice)
    rig.expect(rig.run(PolicyApproach("Approach", rig.ctx), max_ticks=600), Status.SUCCESS)
    assert policy.acts == 4
    p = rig.true_pose()
    assert math.dist((p.x, p.y), (1.2 - 0.6, 22.0)) < 0.2  # the map's stop point


def test_a_landmark_on_the_way_is_approached_on_the_map_not_by_the_policy(make_rig, pm):
    rig = make_rig(Pose2D(0.0, 26.5, SOUTH), grounder=ScriptedGrounder(pm, masks=True))
    policy = ScriptedPolicy([DiscreteAction.TURN_LEFT])
    rig.ctx.refiner = policy
    step = rig.plan("0,29,-90", "room3").steps[0]  # {room4: go straight}
    rig.set(target=step)
    rig.expect(rig.run(PolicyApproach("Approach", rig.ctx), max_ticks=400), Status.SUCCESS)
    p = rig.true_pose()
    assert math.dist((p.x, p.y), (0.0, 22.0)) < 0.2  # its node on the centre line
    assert policy.acts == 0


def test_a_policy_that_never_stops_hands_over_to_the_map_approach(make_rig, pm):
    rig = make_rig(START, grounder=ScriptedGrounder(pm, masks=True))
    policy = ScriptedPolicy([DiscreteAction.TURN_RIGHT], max_steps=4, forever=True)
    rig.ctx.refiner = policy
    step, choice = grounded(rig)
    rig.set(target=step, choice=choice)
    rig.expect(rig.run(PolicyApproach("Approach", rig.ctx), max_ticks=600), Status.SUCCESS)
    assert policy.acts == 4
    p = rig.true_pose()
    assert math.dist((p.x, p.y), (1.2 - 0.6, 22.0)) < 0.2  # the map's stop point


def test_the_tree_approaches_with_the_policy_only_when_the_refiner_is_one(make_rig):
    from pmnav_bt.behaviours.motion import Approach
    from pmnav_bt.trees.runner import build_tree

    def approaches(ctx):
        tree = build_tree(ctx, "room4")
        return {type(n) for n in tree.root.iterate() if isinstance(n, Approach)}

    rig = make_rig(START)
    assert approaches(rig.ctx) == {Approach}  # geometric
    rig.ctx.refiner = ScriptedPolicy([DiscreteAction.STOP])
    assert approaches(rig.ctx) == {PolicyApproach}
    coarse = rig.ctx.config.model_copy(
        update={"tree": rig.ctx.config.tree.model_copy(update={"variant": "coarse_only"})}
    )
    rig.ctx.config = coarse
    assert approaches(rig.ctx) == {Approach}  # coarse-only: no refiner, no policy


def test_it_turns_to_face_the_door_before_the_policy_drives(make_rig, pm):
    # The search left the body turned away from where the door was grounded: the turn
    # is a velocity command (MOVING until face() stops it), so it must not wait on it.
    rig = make_rig(START, grounder=ScriptedGrounder(pm, masks=True))
    policy = ScriptedPolicy([DiscreteAction.FORWARD])
    rig.ctx.refiner = policy
    step, choice = grounded(rig)
    rig.body.set_pose(Pose2D(START.x, START.y, START.yaw + math.radians(70)))
    rig.set(target=step, choice=choice)
    seen = rig.run(PolicyApproach("Approach", rig.ctx), max_ticks=300, until=lambda: policy.acts)
    assert seen[-1] == Status.RUNNING and policy.acts == 1
    assert abs(rig.true_pose().yaw - START.yaw) < math.radians(5)  # faced the door first


def test_a_door_beyond_the_policy_range_is_approached_on_the_map(make_rig, pm):
    rig = make_rig(START, grounder=ScriptedGrounder(pm, masks=True))  # 2.8 m from the door
    policy = ScriptedPolicy([DiscreteAction.TURN_LEFT])
    rig.ctx.refiner = policy
    cfg = rig.ctx.config
    refiner = cfg.refiner.model_copy(update={"policy_range": 2.0})
    rig.ctx.config = cfg.model_copy(update={"refiner": refiner})
    step, choice = grounded(rig)
    rig.set(target=step, choice=choice)
    rig.expect(rig.run(PolicyApproach("Approach", rig.ctx), max_ticks=600), Status.SUCCESS)
    assert policy.acts == 0
    p = rig.true_pose()
    assert math.dist((p.x, p.y), (1.2 - 0.6, 22.0)) < 0.2  # the map's stop point


@pytest.mark.world
def test_a_policy_blocked_at_the_door_has_arrived(make_rig):
    # Stepping on into the wall by the door: as near as the body gets, not a failure.
    rig = make_rig(NEAR)
    policy = ScriptedPolicy([DiscreteAction.FORWARD], forever=True)
    rig.ctx.refiner = policy
    step, choice = grounded(rig)
    rig.set(target=step, choice=choice)
    rig.expect(rig.run(PolicyApproach("Approach", rig.ctx), max_ticks=600), Status.SUCCESS)
    p = rig.true_pose()
    assert math.dist((p.x, p.y), (1.2, 22.0)) < 0.8
    assert rig.body.stats.collisions >= 1
