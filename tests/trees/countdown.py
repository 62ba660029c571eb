"""A leaf with scripted statuses and feedback, for the tree log/replay/live-view tests."""

from __future__ import annotations

import py_trees
from py_trees.common import Status


class Countdown(py_trees.behaviour.Behaviour):
    """RUNNING ``n`` ticks ("k to go"), then SUCCESS ("done")."""

    def __init__(self, name: str, n: int):
        super().__init__(name)
        self.n = n

    def initialise(self) -> None:
        self.left = self.n

    def update(self) -> Status:
        if self.left == 0:
            self.feedback_message = "done"
            return Status.SUCCESS
        self.feedback_message = f"{self.left} to go"
        self.left -= 1
        return Status.RUNNING
