"""Panoramic capture: turn through a set of relative yaws and take a frame at each.

Used for localization (30, 90, ..., 330 deg) and for search (0, +-30, +-60, +-90 deg
minus the view the last action rules out, centred on the target when the map puts it
off to a side: ``search_centre``; taken nearest the target's bearing first:
``nearest_first``). Frames are taken and grounded in the worker; the tick only steers
and polls.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from py_trees.common import Status

from pmnav_bt.behaviours.common import PmNavBehaviour
from pmnav_bt.behaviours.context import Context
from pmnav_bt.geometry import Action, wrap_angle
from pmnav_bt.seams import Entity, View

LOCALIZATION_YAWS_DEG = (30, 90, 150, 210, 270, 330)
SEARCH_YAWS_DEG = (0, 30, -30, 60, -60, 90, -90)
AHEAD_DEG = 45.0  # a target this near the heading is searched with the paper's views


# What a panorama grounds in each frame: every readable sign (localization), or one entity.
READ_SIGNS = "signs"
Grounding = Entity | str | None  # an Entity, READ_SIGNS, or None (just take the frames)


def search_yaws(last_action: Action | None, centre: float = 0.0) -> list[float]:
    """The paper's search views around ``centre`` (rad from the heading); after a left turn
    -90 is left out, after a right turn +90."""
    excluded = {Action.TURN_LEFT: -90, Action.TURN_RIGHT: 90}.get(last_action)
    return [centre + math.radians(y) for y in SEARCH_YAWS_DEG if y != excluded]


def search_centre(bearing: float) -> float:
    """Where the search views centre (rad from the heading), given the target's bearing by
    the map: on the heading (the paper's views) while the target is within
    ``AHEAD_DEG`` of it, else on the target, to the nearest 30 deg. A door's sign hangs
    beside it: from level with a door, or past it, the sign is out of the forward fan."""
    if abs(bearing) <= math.radians(AHEAD_DEG):
        return 0.0
    step = math.radians(30.0)
    return round(bearing / step) * step


def sweep_order(yaws: list[float]) -> list[float]:
    """Visit the yaws in one sweep, starting from the nearer extreme (fewest turns)."""
    ys = sorted(yaws)
    if not ys:
        return ys
    return ys if abs(ys[0]) <= abs(ys[-1]) else ys[::-1]


def nearest_first(yaws: list[float], bearing: float) -> list[float]:
    """The search views in the order to take them: first the one nearest ``bearing`` (the
    target's, by the map; a search that stops once the target is seen mostly ends there),
    then on outwards to the side the bearing leans from it, then the other side (on a
    tie, the side with fewer views first: fewer turns back). Turning to the nearer
    extreme first and sweeping across passes the likeliest view only halfway through."""
    ys = sorted(yaws)
    if not ys:
        return ys
    i = min(range(len(ys)), key=lambda k: abs(wrap_angle(ys[k] - bearing)))
    up, down = ys[i + 1 :], ys[:i][::-1]
    lean = wrap_angle(bearing - ys[i])
    up_first = lean > 0 if lean != 0 else len(up) <= len(down)
    return [ys[i], *(up + down if up_first else down + up)]


class CaptureViews(PmNavBehaviour):
    """Turn through ``yaws(b)`` capturing a frame at each and grounding ``what(b)`` in it:
    READ_SIGNS (every readable sign, for localization), an Entity (the search target),
    or None (frames only).

    Blackboard: reads what ``yaws``/``what`` read (``target``, ``last_action``,
    ``map_T_odom``);
    writes ``views`` (list[View]; with ``extend``, added to the ``views`` already there: one
    panorama taken in two sweeps). Stops early when ``enough(views)`` is true. Ends
    facing the last view. FAILURE if the body faults or a frame cannot be taken or
    grounded (SENSOR_TIMEOUT for a silent camera, the back end's code otherwise).
    """

    READS = ("target", "last_action", "map_T_odom", "views")
    WRITES = ("views",)
    JOBS = ("_job",)
    STOPS_BASE = True

    def __init__(
        self,
        name: str,
        ctx: Context,
        yaws: Callable[[PmNavBehaviour], list[float]],
        what: Callable[[PmNavBehaviour], Grounding],
        enough: Callable[[list[View]], bool] | None = None,
        sweep: bool = True,
        extend: bool = False,
    ):
        super().__init__(name, ctx)
        self._yaws = yaws
        self._what = what
        self._enough = enough
        self._sweep = sweep
        self._extend = extend
        self._job = None

    def initialise(self) -> None:
        yaws = self._yaws(self)
        self._todo = sweep_order(yaws) if self._sweep else list(yaws)
        self._grounding = self._what(self)
        self._start_yaw = self.ctx.base.pose().yaw
        self._views: list[View] = []
        self._job = None
        self.feedback_message = f"{len(self._todo)} views"

    def update(self) -> Status:
        if self._job is not None:
            status, taken = self.poll(self._job, "taking a view")
            if status is not None:
                return status
            self._job = None
            obs, dets = taken
            rel = wrap_angle(obs.pose.yaw - self._start_yaw)
            self._views.append(View(rel, obs, dets))
            self._todo.pop(0)
            if not self._todo or (self._enough is not None and self._enough(self._views)):
                before = list(self.get("views") or []) if self._extend else []
                self.bb.set("views", before + self._views)
                return Status.SUCCESS
        goal = self._start_yaw + self._todo[0]
        if not self.face(goal):
            return Status.RUNNING
        what, base, grounder = self._grounding, self.ctx.base, self.ctx.grounder

        def take(cancelled):
            obs = base.observe()
            if cancelled.is_set() or what is None:
                return obs, None
            if what == READ_SIGNS:
                return obs, tuple(grounder.read_signs(obs))
            return obs, tuple(grounder.detect(obs, what))

        self._job = self.ctx.worker.submit(take)
        self.feedback_message = (
            f"view {len(self._views) + 1}: {math.degrees(self._todo[0]):+.0f} deg"
        )
        return Status.RUNNING
