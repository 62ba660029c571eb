"""The mission monitor (action budget, the body's faults) and ClockTimeout (the tree's
clock, not wall time), on the test doubles: a kinematic body in fig2_hospital's map."""

from __future__ import annotations

import math
import time

import py_trees
import pytest
from py_trees.common import ParallelPolicy, Status

from pmnav_bt.behaviours.decorators import ClockTimeout
from pmnav_bt.behaviours.monitor import Monitor
from pmnav_bt.behaviours.motion import MoveToward
from pmnav_bt.failures import Failure, FailureCode
from pmnav_bt.seams import FORWARD_STEP_M, Pose2D

SOUTH_AT_28 = Pose2D(0.0, 28.0, math.radians(-90))


def far_target(rig):
    """{room5: go straight} at (0, 14): 14 m down the corridor from SOUTH_AT_28."""
    step = next(s for s in rig.plan("0,28,-90", "room3").steps if s.landmark == "room5")
    assert step.position == (0.0, 14.0)
    return step


def test_monitor_fails_budget_exceeded_once_the_odometer_passes_the_budget(make_rig):
    rig = make_rig(SOUTH_AT_28, budget=5)
    monitor = Monitor("Monitor", rig.ctx)
    rig.body.set_velocity(0.3, 0.0)  # driving south, open-loop
    seen, actions = [], []
    for _ in range(200):
        seen.append(rig.tick(monitor))
        actions.append(rig.ctx.odometer.actions)
        if seen[-1] != Status.RUNNING:
            break
        assert monitor.feedback_message == f"{actions[-1]}/5 actions"
        rig.wait()
    rig.expect(seen, Status.FAILURE)
    assert all(a <= 5 for a in actions[:-1]) and actions[-1] == 6  # fails on the first over
    assert rig.failure.code == FailureCode.BUDGET_EXCEEDED
    assert rig.failure.message == "6 actions used of 5"
    driven = 28.0 - rig.true_pose().y
    assert 5.5 * FORWARD_STEP_M <= driven < 5.5 * FORWARD_STEP_M + 0.04  # 0.3 m/s * 0.1 s
    assert rig.stopped()


def test_actions_granted_on_the_way_raise_the_budget(make_rig):
    """A boarding let go because the lift came full (``BoardAgainAllowed``) adds its
    actions to the budget: the Monitor fails only past the budget and the grant."""
    rig = make_rig(SOUTH_AT_28, budget=5)
    rig.set(actions_granted=3)
    monitor = Monitor("Monitor", rig.ctx)
    rig.body.set_velocity(0.3, 0.0)
    seen = rig.run(monitor, max_ticks=200)
    rig.expect(seen, Status.FAILURE)
    assert rig.failure.message == "9 actions used of 8"
    assert rig.ctx.odometer.actions == 9


def test_monitor_counts_turning_too(make_rig):
    rig = make_rig(SOUTH_AT_28, budget=5)
    monitor = Monitor("Monitor", rig.ctx)
    rig.body.set_velocity(0.0, 1.0)  # on the spot: 30 deg per action
    seen = rig.run(monitor, max_ticks=100)
    rig.expect(seen, Status.FAILURE)
    assert rig.failure.code == FailureCode.BUDGET_EXCEEDED
    assert rig.ctx.odometer.distance == 0.0
    turned = rig.true_pose().yaw - SOUTH_AT_28.yaw  # under half a turn: no wrap
    assert turned == pytest.approx(math.radians(30 * 5.5), abs=0.11)


def test_monitor_fails_base_fault_once_the_body_faults(make_rig):
    rig = make_rig(SOUTH_AT_28)
    monitor = Monitor("Monitor", rig.ctx)
    rig.body.set_velocity(0.2, 0.0)
    rig.ticks(monitor, [Status.RUNNING, Status.RUNNING])
    assert rig.failure is None
    rig.body.faulted = True
    assert rig.tick(monitor) == Status.FAILURE
    assert rig.failure == Failure(FailureCode.BASE_FAULT, "the base reports a fault")
    assert rig.body.velocity_command == (0.0, 0.0)  # stopped


def test_monitor_reports_the_failure_a_body_s_fault_hook_gives_first(make_rig):
    rig = make_rig(SOUTH_AT_28)
    silent = Failure(FailureCode.SENSOR_TIMEOUT, "no odometry on /odom for 1.0 s")
    reports = iter([None, silent])
    rig.body.fault = lambda: next(reports)  # a hardware body's optional hook
    rig.body.faulted = True  # also faulted: the hook's own failure is the one reported
    rig.body.set_velocity(0.2, 0.0)
    monitor = Monitor("Monitor", rig.ctx)
    assert rig.tick(monitor) == Status.FAILURE  # faulted, the hook said nothing
    assert rig.failure.code == FailureCode.BASE_FAULT
    assert rig.tick(monitor) == Status.FAILURE
    assert rig.failure == silent
    assert rig.body.velocity_command == (0.0, 0.0)


def test_monitor_beside_the_mission_stops_it_when_the_budget_is_spent(make_rig):
    rig = make_rig(SOUTH_AT_28, budget=8)
    rig.set(target=far_target(rig))
    move = MoveToward("MoveOn", rig.ctx, keep=1.0)
    root = py_trees.composites.Parallel(
        "PM-Nav", policy=ParallelPolicy.SuccessOnOne(), children=[Monitor("Monitor", rig.ctx), move]
    )
    tree = py_trees.trees.BehaviourTree(root)
    seen = []
    for _ in range(300):
        tree.tick()
        seen.append(root.status)
        if root.status != Status.RUNNING:
            break
        rig.wait()
    rig.expect(seen, Status.FAILURE)
    assert rig.failure.code == FailureCode.BUDGET_EXCEEDED
    assert move.status == Status.INVALID  # the parallel stopped the drive ...
    assert rig.stopped()  # ... which stopped the base
    assert 28.0 - rig.true_pose().y == pytest.approx(8.5 * FORWARD_STEP_M, abs=0.05)


def test_clock_timeout_fails_timeout_on_sim_time(make_rig):
    rig = make_rig(SOUTH_AT_28)
    child = py_trees.behaviours.Running(name="Slow")
    timeout = ClockTimeout("StepTimeout", child, rig.ctx.now, duration=1.05)
    t0 = rig.ctx.now()
    seen = rig.run(timeout, max_ticks=100)
    rig.expect(seen, Status.FAILURE)
    assert len(seen) == 12  # ticks at 0.0, 0.1, ..., 1.1 s: over 1.05 s at the twelfth
    assert rig.ctx.now() - t0 == pytest.approx(1.1)
    assert rig.failure.code == FailureCode.TIMEOUT
    assert rig.failure.message == "Slow took over 1 s"
    assert child.status == Status.INVALID  # the child was stopped

    # Ticked again, it times from the new start.
    assert rig.tick(timeout) == Status.RUNNING


def test_clock_timeout_ignores_wall_time(make_rig):
    rig = make_rig(SOUTH_AT_28)
    timeout = ClockTimeout(
        "StepTimeout", py_trees.behaviours.Running(name="Slow"), rig.ctx.now, duration=0.05
    )
    assert rig.tick(timeout) == Status.RUNNING
    time.sleep(0.2)  # four times the duration passes on the wall clock ...
    assert rig.tick(timeout) == Status.RUNNING  # ... but not on the sim clock
    assert rig.failure is None
    rig.base.clock.wait(0.1)
    assert rig.tick(timeout) == Status.FAILURE
    assert rig.failure.code == FailureCode.TIMEOUT


@pytest.mark.parametrize("child_status", [Status.SUCCESS, Status.FAILURE])
def test_clock_timeout_passes_the_child_result_through_in_time(make_rig, child_status):
    rig = make_rig(SOUTH_AT_28)
    child = py_trees.behaviours.StatusQueue(
        name="Quick", queue=[Status.RUNNING, Status.RUNNING], eventually=child_status
    )
    timeout = ClockTimeout("StepTimeout", child, rig.ctx.now, duration=1.0)
    seen = rig.run(timeout, max_ticks=10)
    rig.expect(seen, child_status)
    assert len(seen) == 3
    assert rig.failure is None  # no TIMEOUT written


def test_clock_timeout_over_a_drive_stops_the_base(make_rig):
    rig = make_rig(SOUTH_AT_28)
    rig.set(target=far_target(rig))
    move = MoveToward("MoveOn", rig.ctx, keep=1.0)
    timeout = ClockTimeout("StepTimeout", move, rig.ctx.now, duration=2.0)
    seen = rig.run(timeout, max_ticks=100)
    rig.expect(seen, Status.FAILURE)
    assert rig.failure.code == FailureCode.TIMEOUT
    assert move.status == Status.INVALID
    assert rig.stopped()
    p = rig.true_pose()
    assert 0.3 < 28.0 - p.y < 0.7  # 2 s of driving
    rig.wait(1.0)
    assert rig.true_pose() == p
