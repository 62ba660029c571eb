"""Decorators py_trees lacks: a timeout on the tree's Clock (py_trees' Timeout is wall time)."""

from __future__ import annotations

from collections.abc import Callable

import py_trees
from py_trees.common import Access, Status

from pmnav_bt.failures import Failure, FailureCode


class ClockTimeout(py_trees.decorators.Decorator):
    """FAILURE (TIMEOUT) if the child runs longer than ``duration`` seconds of ``now()``
    (the tree's Clock).

    Writes ``/pmnav/failure`` on timeout (reads ``recovering_from``, its cause).
    """

    def __init__(
        self,
        name: str,
        child: py_trees.behaviour.Behaviour,
        now: Callable[[], float],
        duration: float,
    ):
        super().__init__(name=name, child=child)
        self.now = now
        self.duration = duration
        self.bb = self.attach_blackboard_client(name=name, namespace="/pmnav")
        self.bb.register_key(key="failure", access=Access.WRITE)
        self.bb.register_key(key="recovering_from", access=Access.READ)

    def initialise(self) -> None:
        self._start = self.now()

    def update(self) -> Status:
        elapsed = self.now() - self._start
        if self.decorated.status == Status.RUNNING and elapsed > self.duration:
            cause = self.bb.get("recovering_from") if self.bb.exists("recovering_from") else None
            self.bb.set(
                "failure",
                Failure(
                    FailureCode.TIMEOUT,
                    f"{self.decorated.name} took over {self.duration:.0f} s",
                    cause,
                ),
            )
            self.feedback_message = "timed out"
            return Status.FAILURE
        return self.decorated.status


class RetryWhile(py_trees.decorators.Decorator):
    """Run the child again after each FAILURE while ``again()`` is true (an exploration
    loop that ends by a condition, not a count); SUCCESS when the child succeeds, FAILURE
    once ``again()`` is false. The child writes the failure."""

    def __init__(self, name: str, child: py_trees.behaviour.Behaviour, again: Callable[[], bool]):
        super().__init__(name=name, child=child)
        self.again = again

    def update(self) -> Status:
        if self.decorated.status == Status.FAILURE:
            if self.again():
                self.decorated.stop(Status.INVALID)
                self.feedback_message = "again"
                return Status.RUNNING
            return Status.FAILURE
        return self.decorated.status
