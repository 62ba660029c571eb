"""The base class of PM-Nav leaves: context, blackboard client, failure reporting."""

from __future__ import annotations

import py_trees
from py_trees.common import Access, Status

from pmnav_bt.behaviours.context import Context
from pmnav_bt.failures import Failure, FailureCode

NAMESPACE = "/pmnav"

# Every blackboard key of the tree, under /pmnav.
KEYS = (
    "goal",  # str: the goal room as the user gave it
    "map_T_odom",  # (x, y, yaw) | None: localization, odometry frame -> map frame
    "fix_attempts",  # int: localization attempts so far (SDF's d)
    "plan",  # Plan
    "step_index",  # int: index of the current plan step
    "target",  # PlanStep: the current target
    "views",  # list[CapturedView]: the last panorama
    "choice",  # CapturedView + Detection: where the target was seen
    "bearing",  # float: refined bearing to the target, relative to the chosen view
    "sighting",  # Sighting: the target's position seen, in the odometry frame
    "recent_sightings",  # list[Sighting]: the last verified sightings (pose re-fits)
    "last_action",  # Action: the last plan action carried out
    "avoid_landmarks",  # frozenset[str]: landmarks that failed and are not used again
    "blocked_segments",  # frozenset[int]: segments found blocked (twice)
    "blocked_suspects",  # frozenset[int]: segments found blocked once
    "replans",  # int
    "failure",  # Failure: why the last thing failed
)


class PmNavBehaviour(py_trees.behaviour.Behaviour):
    """A leaf with the shared Context and a blackboard client.

    Subclasses list the keys they read and write in READS and WRITES (and in their
    docstrings); reading an unset key returns None.
    """

    READS: tuple[str, ...] = ()
    WRITES: tuple[str, ...] = ()

    def __init__(self, name: str, ctx: Context):
        super().__init__(name)
        self.ctx = ctx
        self.bb = self.attach_blackboard_client(name=name, namespace=NAMESPACE)
        for key in set(self.READS) - set(self.WRITES):
            self.bb.register_key(key=key, access=Access.READ)
        for key in self.WRITES:
            self.bb.register_key(key=key, access=Access.WRITE)
        if "failure" not in self.WRITES:
            self.bb.register_key(key="failure", access=Access.WRITE)

    def get(self, key: str, default=None):
        """A blackboard value, or ``default`` when unset."""
        return self.bb.get(key) if self.bb.exists(key) else default

    def fail(self, code: FailureCode, message: str) -> Status:
        """Record why, and return FAILURE."""
        self.bb.set("failure", Failure(code, message))
        self.feedback_message = f"{code.value}: {message}"
        return Status.FAILURE
