"""The decorators py_trees lacks (behaviours/decorators.py) over scripted children, with the
status asserted per tick: RetryWhile's loop that ends by a condition, and ClockTimeout's
TIMEOUT that keeps the root cause of a recovery under way."""

from __future__ import annotations

import py_trees
from py_trees.behaviours import StatusQueue
from py_trees.common import Status

from pmnav_bt.behaviours.decorators import ClockTimeout, RetryWhile
from pmnav_bt.failures import Failure, FailureCode
from pmnav_bt.seams import Pose2D

RUNNING, SUCCESS, FAILURE = Status.RUNNING, Status.SUCCESS, Status.FAILURE


def statuses(b: py_trees.behaviour.Behaviour, n: int) -> list[Status]:
    out = []
    for _ in range(n):
        b.tick_once()
        out.append(b.status)
    return out


def test_retry_while_runs_a_failed_child_again_until_it_succeeds():
    child = StatusQueue("Explore", queue=[FAILURE, RUNNING, FAILURE], eventually=SUCCESS)
    loop = RetryWhile("ExploreLoop", child, again=lambda: True)
    assert statuses(loop, 4) == [RUNNING, RUNNING, RUNNING, SUCCESS]
    assert child.status == SUCCESS


def test_retry_while_fails_once_the_condition_no_longer_holds():
    asked = []

    def again() -> bool:
        asked.append(1)
        return len(asked) < 3

    child = StatusQueue("Explore", queue=[], eventually=FAILURE)
    loop = RetryWhile("ExploreLoop", child, again=again)
    got = []
    for _ in range(3):
        loop.tick_once()
        got.append(loop.status)
        if loop.status == RUNNING:
            assert child.status == Status.INVALID  # stopped, to start afresh
            assert loop.feedback_message == "again"
    assert got == [RUNNING, RUNNING, FAILURE]
    assert len(asked) == 3  # asked after each failure, never while the child runs


def test_retry_while_never_asks_while_the_child_runs_or_succeeds():
    def never() -> bool:
        raise AssertionError("again() asked although the child had not failed")

    child = StatusQueue("Explore", queue=[RUNNING, RUNNING], eventually=SUCCESS)
    assert statuses(RetryWhile("ExploreLoop", child, again=never), 3) == [
        RUNNING,
        RUNNING,
        SUCCESS,
    ]


def test_a_timeout_during_a_recovery_names_what_the_recovery_started_from(make_rig):
    rig = make_rig(Pose2D(0.0, 20.0, 0.0))
    root = Failure(FailureCode.BLOCKED, "obstacle 0.4 m ahead")
    rig.set(recovering_from=root)
    slow = ClockTimeout("StepTimeout", py_trees.behaviours.Running("Slow"), rig.ctx.now, 1.05)
    rig.ticks(slow, [RUNNING] * 11 + [FAILURE])  # over 1.05 s at the twelfth tick (1.1 s)
    assert rig.failure == Failure(FailureCode.TIMEOUT, "Slow took over 1 s", cause=root)
    assert str(rig.failure).endswith(f"(after {root})")
