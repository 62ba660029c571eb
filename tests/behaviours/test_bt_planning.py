"""Goal check, planning, target determination and update, and the bookkeeping of recovery,
on the test doubles in fig2_hospital's priori-map (the planner is the real graph planner)."""

from __future__ import annotations

import math

import pytest
from py_trees.common import Status

from pmnav_bt.behaviours.planning import (
    CheckGoal,
    DetermineTarget,
    MakePlan,
    NoteFailure,
    PlanComplete,
    TargetIs,
    UpdateTarget,
)
from pmnav_bt.failures import Failure, FailureCode
from pmnav_bt.geometry import Action
from pmnav_bt.seams import Pose2D

SOUTH_AT_20 = Pose2D(0.0, 20.0, math.radians(-90))
# With this map_T_odom the odometry pose (0, 20, -90 deg) is the map pose (12, 0, 0 deg):
# on the turn1-turn2 corridor, facing east.
EAST_AT_12 = (32.0, 0.0, math.radians(90))


@pytest.mark.parametrize(
    "goal", ["room17", "One-Stop Service Centre", "OSSC", "117 One-Stop Service Centre"]
)
def test_check_goal_accepts_a_room_of_the_map(make_rig, goal):
    rig = make_rig(SOUTH_AT_20)
    rig.set(goal=goal)
    check = CheckGoal("CheckGoal", rig.ctx)
    assert rig.tick(check) == Status.SUCCESS
    assert check.feedback_message == "goal room17"
    assert rig.failure is None


@pytest.mark.parametrize("goal", ["room99", "Cafeteria", "Elevator A", None])
def test_check_goal_fails_invalid_goal(make_rig, goal):
    rig = make_rig(SOUTH_AT_20)
    if goal is not None:
        rig.set(goal=goal)
    check = CheckGoal("CheckGoal", rig.ctx)
    assert rig.tick(check) == Status.FAILURE
    assert rig.failure.code == FailureCode.INVALID_GOAL
    assert str(goal) in rig.failure.message


def test_make_plan_plans_from_the_estimated_pose_in_the_worker(make_rig):
    rig = make_rig(SOUTH_AT_20)
    rig.set(goal="room17", map_T_odom=EAST_AT_12, step_index=4, last_action=Action.TURN_LEFT)
    release = rig.hold_worker()
    make = MakePlan("Plan", rig.ctx)
    assert rig.tick(make) == Status.RUNNING  # planning is queued in the worker
    assert rig.tick(make) == Status.RUNNING  # a tick never waits for it
    assert rig.get("plan") is None
    release.set()
    rig.wait()
    assert rig.tick(make) == Status.SUCCESS

    plan = rig.get("plan")
    assert plan.goal == "room17"
    # From the map pose (12, 0) facing east, not from the odometry pose (0, 20).
    assert plan.path[0] == pytest.approx((12.0, 0.0), abs=1e-6)
    assert plan.start.heading == pytest.approx(0.0, abs=1e-6)
    assert plan.initial_action == Action.GO_STRAIGHT
    assert plan.steps[0].landmark == "room14"  # the next landmark east, 8 m on
    assert plan.steps[-1].landmark == "room17" and plan.steps[-1].action == Action.ARRIVE
    assert rig.get("step_index") == 0  # the new plan starts afresh
    assert rig.get("last_action") is None
    assert rig.ctx.trace[-1].kind == "plan" and rig.ctx.trace[-1].label == "room17"
    assert rig.failure is None


def test_make_plan_without_a_fix_plans_from_odometry(make_rig):
    rig = make_rig(SOUTH_AT_20)
    rig.set(goal="room3")
    rig.expect(rig.run(MakePlan("Plan", rig.ctx), max_ticks=5), Status.SUCCESS)
    plan = rig.get("plan")
    assert plan.path[0] == pytest.approx((0.0, 20.0))
    assert [s.landmark for s in plan.steps][-1] == "room3"


def test_make_plan_from_a_pose_outside_the_corridors_fails_planning_failed(make_rig):
    rig = make_rig(SOUTH_AT_20)
    # The body is in the corridor, but the estimate puts it at (20, 10): inside the rooms.
    rig.set(goal="room17", map_T_odom=(40.0, 10.0, math.radians(90)))
    seen = rig.run(MakePlan("Plan", rig.ctx), max_ticks=5)
    rig.expect(seen, Status.FAILURE)
    assert rig.failure.code == FailureCode.PLANNING_FAILED
    assert "(20.00, 10.00)" in rig.failure.message and "corridor" in rig.failure.message
    assert rig.get("plan") is None


def test_make_plan_honours_avoided_landmarks_and_blocked_segments(make_rig):
    rig = make_rig(SOUTH_AT_20)
    rig.set(goal="room17", map_T_odom=EAST_AT_12, avoid_landmarks=frozenset({"room13"}))
    rig.expect(rig.run(MakePlan("Plan", rig.ctx), max_ticks=5), Status.SUCCESS)
    looked_for = [s.look_for for s in rig.get("plan").steps]
    assert "room13" not in looked_for and "room17" in looked_for

    # Seg 14 (room7-room15) is the only way east: blocked, there is no route around it.
    rig.set(blocked_segments=frozenset({14}))
    rig.expect(rig.run(MakePlan("Replan", rig.ctx), max_ticks=5), Status.FAILURE)
    assert rig.failure.code == FailureCode.BLOCKED
    assert rig.failure.message == "no way round: the corridor between room7 and room15 blocked"
    assert rig.get("plan").steps[-1].look_for == "room17"  # the old plan is left alone


def test_make_plan_for_an_unknown_room_fails_invalid_goal(make_rig):
    rig = make_rig(SOUTH_AT_20)
    rig.set(goal="room99")
    rig.expect(rig.run(MakePlan("Plan", rig.ctx), max_ticks=5), Status.FAILURE)
    assert rig.failure.code == FailureCode.INVALID_GOAL  # as the docstring says
    assert "room99" in rig.failure.message
    assert rig.get("plan") is None


def test_make_plan_terminate_cancels_the_planning_job(make_rig):
    rig = make_rig(SOUTH_AT_20)
    rig.set(goal="room17")
    release = rig.hold_worker()
    make = MakePlan("Plan", rig.ctx)
    assert rig.tick(make) == Status.RUNNING
    job = make._job
    make.stop(Status.INVALID)
    assert job.cancelled.is_set()
    release.set()
    rig.ctx.worker.drain()
    assert not job.started()  # dropped before it ran
    assert rig.get("plan") is None


def test_determine_update_and_complete_walk_through_the_plan(make_rig):
    rig = make_rig(SOUTH_AT_20)
    plan = rig.plan("0,3,-90", "room11")  # {turn1: turn left}, {room11: arrive}
    assert [(s.landmark, s.action) for s in plan.steps] == [
        ("turn1", Action.TURN_LEFT),
        ("room11", Action.ARRIVE),
    ]
    determine = DetermineTarget("TargetDetermination", rig.ctx)
    update = UpdateTarget("TargetUpdate", rig.ctx)
    complete = PlanComplete("PlanComplete", rig.ctx)
    visible = TargetIs("IsVisible", rig.ctx, visible=True)
    unseen = TargetIs("IsUnseen", rig.ctx, visible=False)

    assert rig.tick(complete) == Status.FAILURE  # no plan yet
    assert rig.tick(determine) == Status.FAILURE
    assert rig.failure.code == FailureCode.PLANNING_FAILED
    assert rig.tick(visible) == Status.FAILURE and rig.tick(unseen) == Status.FAILURE  # no target

    rig.set(plan=plan, failure=None)  # step_index unset reads as 0
    assert rig.tick(complete) == Status.FAILURE
    assert rig.tick(determine) == Status.SUCCESS
    assert rig.get("target") == plan.steps[0]
    assert "step 1/2" in determine.feedback_message
    assert rig.tick(visible) == Status.FAILURE and rig.tick(unseen) == Status.SUCCESS
    assert rig.tick(update) == Status.SUCCESS
    assert rig.get("step_index") == 1
    assert rig.get("last_action") == Action.TURN_LEFT
    assert rig.ctx.trace[-1].kind == "step" and rig.ctx.trace[-1].label == "turn1"

    assert rig.tick(complete) == Status.FAILURE
    assert rig.tick(determine) == Status.SUCCESS
    assert rig.get("target") == plan.steps[1]
    assert rig.tick(visible) == Status.SUCCESS and rig.tick(unseen) == Status.FAILURE
    assert rig.tick(update) == Status.SUCCESS
    assert rig.get("step_index") == 2
    assert rig.get("last_action") == Action.ARRIVE

    assert rig.tick(complete) == Status.SUCCESS
    assert rig.tick(determine) == Status.FAILURE  # nothing left to target
    assert rig.failure.code == FailureCode.PLANNING_FAILED
    assert rig.get("target") == plan.steps[1]  # unchanged


def test_note_failure_avoids_a_landmark_not_found(make_rig):
    rig = make_rig(SOUTH_AT_20)
    plan = rig.plan("0,6,-90", "room17")
    room11, room13, goal = plan.steps[1], plan.steps[2], plan.steps[-1]
    assert (room11.look_for, room13.look_for, goal.action) == ("room11", "room13", Action.ARRIVE)
    note = NoteFailure("NoteFailure", rig.ctx)

    rig.set(target=room11, failure=Failure(FailureCode.TARGET_NOT_FOUND, "room11 not seen"))
    assert rig.tick(note) == Status.SUCCESS
    assert rig.get("avoid_landmarks") == frozenset({"room11"})
    assert rig.get("replans") == 1
    assert rig.ctx.trace[-1].kind == "replan" and "TARGET_NOT_FOUND" in rig.ctx.trace[-1].label

    rig.set(target=room13)
    assert rig.tick(note) == Status.SUCCESS
    assert rig.get("avoid_landmarks") == frozenset({"room11", "room13"})
    assert rig.get("replans") == 2

    rig.set(target=goal)  # the goal itself is never given up
    assert rig.tick(note) == Status.SUCCESS
    assert rig.get("avoid_landmarks") == frozenset({"room11", "room13"})
    rig.set(target=plan.steps[0], failure=Failure(FailureCode.TIMEOUT, "slow"))  # turn1
    assert rig.tick(note) == Status.SUCCESS
    assert rig.get("avoid_landmarks") == frozenset({"room11", "room13"})
    assert rig.get("blocked_segments") is None
    assert rig.get("replans") == 4


def test_note_failure_blocks_the_segment_ahead_once_found_blocked_twice(make_rig):
    rig = make_rig(SOUTH_AT_20)
    rig.set(
        map_T_odom=EAST_AT_12,  # at (12, 0) facing east: 0.6 m ahead is seg11(room12-room13)
        failure=Failure(FailureCode.BLOCKED, "obstacle 0.4 m ahead"),
        blocked_segments=frozenset({3}),
        target=rig.plan("12,0,0", "room17").steps[0],
    )
    note = NoteFailure("NoteFailure", rig.ctx)
    assert rig.tick(note) == Status.SUCCESS
    # Once: only suspected (a poor pose estimate can make a wall look like an obstacle).
    assert rig.get("blocked_segments") == frozenset({3})
    assert rig.get("blocked_suspects") == frozenset({11})
    assert rig.tick(note) == Status.SUCCESS
    assert rig.get("blocked_segments") == frozenset({3, 11})
    assert rig.pm.segment(11).name == "seg11(room12-room13)"
    assert rig.get("avoid_landmarks") is None
    assert rig.get("replans") == 2


def test_note_failure_after_a_planning_failure_blocks_nothing_new(make_rig):
    rig = make_rig(SOUTH_AT_20)
    rig.set(
        map_T_odom=EAST_AT_12,
        failure=Failure(FailureCode.BLOCKED, "no route around the blocked seg3"),
        blocked_segments=frozenset({3}),
        target=None,  # MakePlan clears the target: the failure belongs to no step
    )
    assert rig.tick(NoteFailure("NoteFailure", rig.ctx)) == Status.SUCCESS
    assert rig.get("blocked_segments") == frozenset({3})
    assert rig.get("blocked_suspects") is None


def test_a_corridor_found_blocked_for_good_is_written_as_a_map_update(make_rig):
    rig = make_rig(SOUTH_AT_20)
    written = []

    class Sink:
        def record(self, update, crop=None):
            written.append(update)

    rig.ctx.map_updates = Sink()
    rig.set(
        map_T_odom=EAST_AT_12,
        failure=Failure(FailureCode.BLOCKED, "obstacle 0.4 m ahead"),
        target=rig.plan("12,0,0", "room17").steps[0],
    )
    note = NoteFailure("NoteFailure", rig.ctx)
    rig.tick(note)
    assert written == []  # suspected only
    rig.tick(note)
    (update,) = written
    assert (update.kind, update.subject_kind, update.subject) == ("corridor_blocked", "segment",
                                                                  "seg11")  # fmt: skip
    assert update.evidence.reads == ("BLOCKED: obstacle 0.4 m ahead",)
    assert update.at == pytest.approx((12.0, 0.0), abs=0.01)
