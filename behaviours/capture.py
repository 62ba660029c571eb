"""Panoramic capture: turn through a set of relative yaws and take a frame at each.

Used for localization (30, 90, ..., 330 deg) and for search (0, +-30, +-60, +-90 deg
minus the view the last action rules out). Frames are taken and grounded in the
worker; the tick only steers and polls.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

from py_trees.common import Status

from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context
from pmnav_bt.control import rotate_command
from pmnav_bt.failures import FailureCode
from pmnav_bt.geometry import Action, wrap_angle
from pmnav_bt.seams import Detection, Observation

LOCALIZATION_YAWS_DEG = (30, 90, 150, 210, 270, 330)
SEARCH_YAWS_DEG = (0, 30, -30, 60, -60, 90, -90)


@dataclass
class CapturedView:
    """One frame of a panorama: its yaw relative to the heading at the start, and detections."""

    relative_yaw: float
    observation: Observation
    detections: list[Detection] = field(default_factory=list)


def search_yaws(last_action: Action | None) -> list[float]:
    """The paper's search views; after a left turn -90 is left out, after a right turn +90."""
    excluded = {Action.TURN_LEFT: -90, Action.TURN_RIGHT: 90}.get(last_action)
    return [math.radians(y) for y in SEARCH_YAWS_DEG if y != excluded]


def sweep_order(yaws: list[float]) -> list[float]:
    """Visit the yaws in one sweep, starting from the nearer extreme (fewest turns)."""
    ys = sorted(yaws)
    if not ys:
        return ys
    return ys if abs(ys[0]) <= abs(ys[-1]) else ys[::-1]


class CaptureViews(PmNavBehaviour):
    """Turn through ``yaws(bb)`` capturing a frame at each, grounding ``query(bb)`` in it.

    Blackboard: reads what ``yaws``/``query`` read (``target``, ``last_action``);
    writes ``views`` (list[CapturedView]). Stops early when ``enough(views)`` is true.
    Ends facing the last view. FAILURE only if the body faults or a frame cannot be taken.
    """

    READS = ("target", "last_action")
    WRITES = ("views",)

    def __init__(
        self,
        name: str,
        ctx: Context,
        yaws: Callable[[PmNavBehaviour], list[float]],
        query: Callable[[PmNavBehaviour], str | None],
        enough: Callable[[list[CapturedView]], bool] | None = None,
        sweep: bool = True,
    ):
        super().__init__(name, ctx)
        self._yaws = yaws
        self._query = query
        self._enough = enough
        self._sweep = sweep
        self._job = None

    def initialise(self) -> None:
        yaws = self._yaws(self)
        self._todo = sweep_order(yaws) if self._sweep else list(yaws)
        self._query_text = self._query(self)
        self._start_yaw = self.ctx.base.pose().yaw
        self._views: list[CapturedView] = []
        self._job = None
        self.feedback_message = f"{len(self._todo)} views"

    def update(self) -> Status:
        if self._job is not None:
            if not self._job.done():
                return Status.RUNNING
            try:
                obs, dets = self._job.result()
            except Exception as err:  # noqa: BLE001 - reported as a sensor failure
                return self.fail(FailureCode.SENSOR_TIMEOUT, f"no frame: {err}")
            self._job = None
            rel = wrap_angle(obs.pose.yaw - self._start_yaw)
            self._views.append(CapturedView(rel, obs, dets))
            self._todo.pop(0)
            if not self._todo or (self._enough is not None and self._enough(self._views)):
                self.bb.set("views", list(self._views))
                return Status.SUCCESS
        goal = self._start_yaw + self._todo[0]
        v, w, done = rotate_command(self.ctx.base.pose(), goal, self.ctx.limits)
        if not done:
            self.ctx.base.set_velocity(v, w)
            return Status.RUNNING
        self.ctx.base.set_velocity(0.0, 0.0)
        query, base, grounder = self._query_text, self.ctx.base, self.ctx.grounder

        def take(cancelled):
            obs = base.observe()
            if cancelled.is_set() or query is None:
                return obs, []
            return obs, grounder.detect(obs, query)

        self._job = self.ctx.worker.submit(take)
        self.feedback_message = (
            f"view {len(self._views) + 1}: {math.degrees(self._todo[0]):+.0f} deg"
        )
        return Status.RUNNING

    def terminate(self, new_status: Status) -> None:
        if self._job is not None:
            self._job.cancel()
            self._job = None
        if new_status == Status.INVALID:
            self.ctx.base.stop()
