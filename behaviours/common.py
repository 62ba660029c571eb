"""The base class of PM-Nav leaves: context, blackboard client, failure reporting, and
the one way to collect slow work from the worker (``poll``)."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import py_trees
from py_trees.common import Access, Status

from pmnav_bt.behaviours.context import Context
from pmnav_bt.control import rotate_command
from pmnav_bt.failures import Failure, FailureCode, failure_from
from pmnav_bt.hazards import body_blocked_by
from pmnav_bt.seams import Pose2D
from pmnav_bt.worker import Job

NAMESPACE = "/pmnav"
# Failures of the body's motion: their message names the hazard that stopped it, if any.
HAZARD_CODES = (FailureCode.BLOCKED, FailureCode.BASE_FAULT)

# Every blackboard key of the tree, under /pmnav.
KEYS = (
    "goal",  # str: the goal room as the user gave it
    "map_T_odom",  # (x, y, yaw) | None: localization, odometry frame -> map frame
    "fix_attempts",  # int: localization attempts so far (SDF's d)
    "plan",  # Plan
    "step_index",  # int: index of the current plan step
    "target",  # PlanStep: the current target
    "views",  # list[View]: the last panorama
    "choice",  # CoarseChoice (view + detection): where the target was seen
    "bearing",  # float: refined bearing to the target, relative to the chosen view
    "sighting",  # Sighting: the target's position seen, in the odometry frame
    "recent_sightings",  # list[Sighting]: the last verified sightings (pose re-fits)
    "reading_pose",  # ReadingPlan: an unread plate and where to read it (active_read.py)
    "last_action",  # Action: the last plan action carried out
    "avoid_landmarks",  # frozenset[str]: landmark IDs that failed and are not used again
    "blocked_segments",  # frozenset[int]: segments found blocked (twice)
    "blocked_suspects",  # frozenset[int]: segments found blocked once
    "blocked_ways",  # dict[int, BlockedWay]: segments seen shut: where, and the failure
    "way_shut",  # WayShut | None: the shut way the last drive gave up on (way_ahead.py)
    "replans",  # int
    "failure",  # Failure: why the last thing failed (its ``cause``: the failure recovered from)
    "recovering_from",  # Failure | None: what the recovery under way started from
    "belief",  # CorridorBelief | None: where on the corridors, while localizing
    "pose_tracker",  # PoseTracker: map_T_odom's uncertainty, for verification and snapping
    "drive_end",  # DriveEnd | None: how the last localization drive ended (follow_lead)
    "corridor_drive",  # CorridorDrive: the localization drive under way (follow_lead)
    # lifts (behaviours/lift.py, trees/lift.py)
    "level",  # str: the level the robot is on, after a lift ride (the site's level name)
    "lift_full_seen",  # int: lifts that came full on this ride so far
    "cabin_way",  # (bearing rad, metres): the way into the lift's cabin depth showed
    "boarding_actions",  # int: the odometer's actions when the lift's boarding began
    "actions_granted",  # int: actions added to the budget (boardings let go: lift full)
    # the map-less baseline (trees/mapless.py)
    "goal_entity",  # Entity: the goal room, from the sign vocabulary
    "grid",  # ExplorationGrid: what it has seen and where it has been (odometry frame)
    "explore_over",  # bool: no frontier left, or exploring failed for good
    "door_odom",  # (x, y): the goal door seen, odometry frame
    "seen_from",  # (x, y): where the robot stood when it placed the door, odometry frame
)


class PmNavBehaviour(py_trees.behaviour.Behaviour):
    """A leaf with the shared Context and a blackboard client.

    Subclasses list the keys they read and write in READS and WRITES (and in their
    docstrings); reading an unset key returns None. ``terminate`` is declarative: JOBS
    names the attributes holding worker jobs, STOPS_BASE says the leaf drives the body.
    """

    READS: tuple[str, ...] = ()
    WRITES: tuple[str, ...] = ()
    # Attributes holding this leaf's Worker jobs: cancelled (and cleared) whenever it ends,
    # so no result is computed for a behaviour that will not read it.
    JOBS: tuple[str, ...] = ()
    # The leaf commands the body: stop it when interrupted (INVALID); a leaf that ends
    # with SUCCESS or FAILURE has already stopped the body where it had to.
    STOPS_BASE: bool = False

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
        if "recovering_from" not in self.WRITES:
            self.bb.register_key(key="recovering_from", access=Access.READ)
        self._names: dict[str, str] = {}  # key -> its blackboard name, once checked

    def terminate(self, new_status: Status) -> None:
        """Cancel the leaf's jobs (``JOBS``); stop the body if interrupted (``STOPS_BASE``)."""
        for attr in self.JOBS:
            job = getattr(self, attr, None)
            if job is not None:
                job.cancel()
                setattr(self, attr, None)
        if self.STOPS_BASE and new_status == Status.INVALID:
            self.ctx.base.stop()

    def get(self, key: str, default=None):
        """A blackboard value, or ``default`` when unset. The key must be registered (as
        py_trees' client checks: AttributeError otherwise); checked once, then read
        straight from the blackboard's storage: the client's ``exists`` and ``get`` cost
        6 us a read (a drive's tick reads five or six keys; issue 37: tick p99 under
        1 ms), and the reads they record in the activity stream are not in the tree log."""
        name = self._names.get(key)
        if name is None:
            if not self.bb.is_registered(key):
                raise AttributeError(f"{self.name} has no access to the blackboard key {key!r}")
            name = self._names[key] = self.bb.absolute_name(key)
        return py_trees.blackboard.Blackboard.storage.get(name, default)

    def face(self, yaw: float, pose: Pose2D | None = None) -> bool:
        """Turn towards ``yaw`` (rad) at the body's limits; True, with the body stopped, once
        facing it. ``pose``: the pose to turn from (default: odometry)."""
        base = self.ctx.base
        v, w, done = rotate_command(base.pose() if pose is None else pose, yaw, self.ctx.limits)
        base.set_velocity(*((0.0, 0.0) if done else (v, w)))
        return done

    def fail(self, code: FailureCode, message: str) -> Status:
        """Record why, and return FAILURE."""
        return self.fail_with(Failure(code, message))

    def fail_with(self, failure: Failure) -> Status:
        """Record ``failure`` (during a recovery, with what the recovery started from as its
        ``cause``, so that the root cause survives), and return FAILURE. A BLOCKED or
        BASE_FAULT failure names the hazard the body felt, where it has hazard sensors
        ("3 collisions on the way: bumped front left at (1.20, 0.40)")."""
        hazard = body_blocked_by(self.ctx.base) if failure.code in HAZARD_CODES else None
        words = hazard.describe() if hazard is not None else None
        if words is not None and not failure.message.endswith(words):
            failure = dataclasses.replace(failure, message=f"{failure.message}: {words}")
        root = self.get("recovering_from")
        if root is not None and failure.cause is None and failure != root:
            failure = dataclasses.replace(failure, cause=root)
        self.bb.set("failure", failure)
        self.feedback_message = str(failure)
        return Status.FAILURE

    def poll(
        self,
        job: Job,
        doing: str,
        classify: Callable[[BaseException], Failure | None] | None = None,
    ) -> tuple[Status | None, Any]:
        """Collect a worker job without blocking: ``(RUNNING, None)`` while it runs,
        ``(FAILURE, None)`` when it raised (the failure recorded, never an escape from the
        tick), ``(None, result)`` when it is done.

        An exception becomes a Failure by its type (``failures.failure_from``: a sensor
        error is SENSOR_TIMEOUT, a VLM error VLM_ERROR, a bug INTERNAL_ERROR with its
        message); ``classify`` may give a more specific one first. ``doing`` (e.g. "taking a
        frame") prefixes the message.
        """
        if not job.done():
            return Status.RUNNING, None
        try:
            return None, job.result()
        except Exception as err:  # noqa: BLE001 - every exception becomes a failure code
            failure = (classify(err) if classify is not None else None) or failure_from(err, doing)
            return self.fail_with(failure), None
