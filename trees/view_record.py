"""What the web view (``pmnav view``) shows of a tick beside the statuses: the ``view``
entry of a tree log's tick record (schema version 2, ``pmnav_bt/treelog.py``).

The statuses, feedback and blackboard changes say what the tree *did*; the view entry
says what it *knew* and where the robot was, in numbers the page can draw:

- ``pose``: the estimated map pose ``[x, y, yaw]`` (null before the first fix),
  ``sigma`` its position uncertainty (m, the PoseTracker's), ``odom`` the tree's
  odometry pose, ``truth`` the true pose where the body knows it (the simulator);
- ``plan``: the plan's path and steps, when a plan is written (null: none);
- ``belief``: where the likeliest corridor hypotheses put the robot when the belief was
  last updated (at most ``MAX_BELIEF_POINTS``, with their weights; null: no belief);
- ``failure`` and ``recovering``: the last failure (code, message, root cause) and the
  failure the recovery under way started from, when written;
- ``frame`` and ``seen``: the newest frame perception grounded, with its detections and
  the signs read (``pmnav_bt/perception/frame_tap.py``), and every room or landmark
  named since the tick before.

Like the blackboard part, a key is there only when it changed: the view carries the
last value forward. Reading the blackboard and the pose costs a few microseconds a
tick; the belief's points are worked out only on the tick the belief is replaced (it
is, after each look round), and the frame was encoded in the worker.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import py_trees

from pmnav_bt.behaviours.common import NAMESPACE
from pmnav_bt.behaviours.context import Context, map_pose
from pmnav_bt.failures import Failure, root_cause
from pmnav_bt.perception.frame_tap import FrameTap
from pmnav_bt.seams import Pose2D

MAX_BELIEF_POINTS = 300  # the likeliest hypotheses drawn; more only blur the picture
SHOWN_WEIGHT = 1e-3  # of the likeliest: as pmnav sim belief draws them (render/belief.py)


def _key(name: str) -> str:
    return f"{NAMESPACE}/{name}"


def _pose(p: Pose2D | tuple) -> list[float]:
    x, y, yaw = (p.x, p.y, p.yaw) if isinstance(p, Pose2D) else p
    return [round(float(x), 3), round(float(y), 3), round(float(yaw), 3)]


def failure_record(f: Failure | None) -> dict | None:
    """A Failure as JSON: code, message and the root cause when a recovery came after it."""
    if f is None:
        return None
    out: dict[str, Any] = {"code": f.code.value, "message": f.message}
    root = root_cause(f)
    if root is not f:
        out["root"] = {"code": root.code.value, "message": root.message}
    return out


def plan_record(plan) -> dict | None:
    """A Plan as JSON: its headline, path and steps (None: no plan)."""
    if plan is None:
        return None
    return {
        "text": plan.text().splitlines()[0],
        "path": [[round(float(x), 3), round(float(y), 3)] for x, y in plan.path],
        "steps": [
            {
                "landmark": s.landmark,
                "action": s.action.value,
                "xy": [round(float(s.position[0]), 3), round(float(s.position[1]), 3)],
                "text": s.text(),
            }
            for s in plan.steps
        ],
    }


def belief_record(belief, odom: Pose2D) -> dict | None:
    """Where the likeliest hypotheses of a CorridorBelief put the robot at ``odom``."""
    if belief is None:
        return None
    if belief.ref is None:
        return {"xy": [], "w": [], "best": 0.0, "glimpses": 0}
    from pmnav_bt.render.belief import hypotheses_now

    w = belief.weights()
    here, _ = hypotheses_now(belief, odom)
    order = np.argsort(w)[::-1][:MAX_BELIEF_POINTS]
    order = order[w[order] >= SHOWN_WEIGHT * w[order[0]]]
    _, best = belief.best_cluster()
    return {
        "xy": np.round(here[order], 2).tolist(),
        "w": np.round(w[order], 4).tolist(),
        "best": round(float(best), 3),
        "glimpses": len(belief.glimpses),
    }


class ViewRecorder:
    """Makes the ``view`` entry of each tick record (see the module docstring).

    ``building``: how the view finds the map again (a built-in name or the building
    file's path; default the map's own name). ``truth``: the body's true pose, where it is
    known (the simulator), for the driven path. Wraps ``ctx.grounder`` in a FrameTap.
    """

    def __init__(
        self,
        ctx: Context,
        building: str | None = None,
        truth: Callable[[], Pose2D] | None = None,
    ) -> None:
        self.ctx = ctx
        self.building = building or ctx.pm.building.name
        self.truth = truth
        if not isinstance(ctx.grounder, FrameTap):
            ctx.grounder = FrameTap(ctx.grounder)
        self.tap: FrameTap = ctx.grounder
        self._last: dict[str, Any] = {}

    def run_fields(self, goal: str | None) -> dict:
        """The tree record's ``run`` entry: the building and the goal."""
        return {"building": self.building, "goal": goal}

    def __call__(self, changes: dict[str, Any]) -> dict:
        """The view entry of this tick; ``changes``: the blackboard's raw writes (key ->
        value) in it."""
        out: dict[str, Any] = {}
        store = py_trees.blackboard.Blackboard.storage
        odom = self.ctx.base.pose()
        tf = store.get(_key("map_T_odom"))
        tracker = store.get(_key("pose_tracker"))
        now = {
            "odom": _pose(odom),
            "pose": _pose(map_pose(tf, odom)) if tf is not None else None,
            "sigma": _sigma(tracker, self.ctx.odometer.distance),
        }
        if self.truth is not None:
            now["truth"] = _pose(self.truth())
        for k, v in now.items():
            if self._last.get(k, ...) != v:
                out[k] = self._last[k] = v
        if _key("plan") in changes:
            out["plan"] = plan_record(changes[_key("plan")])
        if _key("belief") in changes:
            out["belief"] = belief_record(changes[_key("belief")], odom)
        if _key("failure") in changes:
            out["failure"] = failure_record(changes[_key("failure")])
        if _key("recovering_from") in changes:
            out["recovering"] = failure_record(changes[_key("recovering_from")])
        frame, seen = self.tap.take()
        if frame is not None:
            out["frame"] = frame.record()
        if seen:
            out["seen"] = seen
        return out


def _sigma(tracker, distance: float) -> float | None:
    if tracker is None:
        return None
    s = float(tracker.sigma(distance))
    return round(s, 3) if math.isfinite(s) else None
