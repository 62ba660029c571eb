"""Goal requests from any front end (goal topic, ``goal_pose``, the action) and their progress.

A ``GoalRequest`` is what the mission loop runs: a room, where it came from, a way to
report progress (``feedback``), to ask whether the client cancelled, and to hand back
the result. ``progress`` reads the tree's blackboard into the feedback fields
(phase, plan step, distance to go, recoveries, elapsed). ``room_near_pose`` turns an
RViz "2D Goal Pose" into the room whose door is nearest.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from pmnav_bt.errors import PmNavError
from pmnav_bt.seams import Pose2D


class GoalPoseError(PmNavError):
    """A goal pose that cannot be turned into a room (wrong frame, empty building)."""


@dataclass
class GoalRequest:
    """One goal for the mission loop.

    ``feedback(dict)``: called from the mission thread with ``progress`` fields;
    ``cancel_requested()``: polled every tick; ``finish(result)``: called once with the
    result dict.
    """

    goal: str
    source: str  # "topic" | "goal_pose" | "action"
    feedback: Callable[[dict], None] | None = None
    cancel_requested: Callable[[], bool] | None = None
    on_done: Callable[[dict], None] | None = None
    done: threading.Event = field(default_factory=threading.Event)
    result: dict | None = None

    def finish(self, result: dict) -> None:
        self.result = result
        self.done.set()
        if self.on_done is not None:
            self.on_done(result)


def room_near_pose(building, x: float, y: float) -> tuple[Any, float]:
    """The room whose door is nearest to (x, y) in the map frame, and that distance (m)."""
    if not building.rooms:
        raise GoalPoseError(f"building {building.name!r} has no rooms")
    room = min(building.rooms, key=lambda r: math.hypot(r.door[0] - x, r.door[1] - y))
    return room, math.hypot(room.door[0] - x, room.door[1] - y)


def goal_from_pose(building, frame_id: str, x: float, y: float, map_frame: str = "map"):
    """The room id for a goal pose; GoalPoseError if the pose is not in the map frame."""
    frame = frame_id.lstrip("/")
    if frame and frame != map_frame.lstrip("/"):
        raise GoalPoseError(
            f"goal pose in frame {frame_id!r}: PM-Nav takes goal poses in the "
            f"{map_frame!r} frame (set RViz's fixed frame to {map_frame!r})"
        )
    return room_near_pose(building, x, y)


def _plan_distance(plan, index: int, pose: Pose2D | None) -> float:
    """Metres along the plan from ``pose`` through steps ``index``.. to the goal's door."""
    steps = plan.steps
    if not steps:
        return 0.0
    i = min(max(index, 0), len(steps) - 1)
    first = steps[i].position
    here = 0.0 if pose is None else math.hypot(first[0] - pose.x, first[1] - pose.y)
    rest = sum(float(s.distance) for s in steps[i + 1 :])
    last = steps[-1]
    door = last.target or last.position
    tail = math.hypot(door[0] - last.position[0], door[1] - last.position[1])
    return here + rest + tail


def progress(bb: Callable[[str], Any], map_pose: Pose2D | None, elapsed: float) -> dict:
    """Feedback fields from the blackboard reader ``bb(key)`` and the estimated map pose.

    phase: localizing (no map_T_odom yet), planning (no plan), navigating. level: the
    blackboard's ``level`` (the site's level the robot is on; "" in a one-level building).
    """
    plan = bb("plan")
    m = bb("map_T_odom")
    index = int(bb("step_index") or 0)
    replans = int(bb("replans") or 0)
    fixes = int(bb("fix_attempts") or 0)
    out: dict[str, Any] = {
        "phase": "localizing" if m is None else ("planning" if plan is None else "navigating"),
        "current_step": 0,
        "step_count": 0,
        "step_text": "",
        "distance_remaining": math.nan,
        "recoveries": replans + max(0, fixes - 1),
        "elapsed": elapsed,
        "level": str(bb("level") or ""),
    }
    if plan is not None:
        n = len(plan.steps)
        k = min(index, n - 1) if n else 0
        out.update(
            current_step=min(index + 1, n),
            step_count=n,
            step_text=plan.steps[k].text() if n else "",
            distance_remaining=_plan_distance(plan, index, map_pose if m is not None else None),
        )
    return out


def progress_line(p: dict) -> str:
    """One line for people: ``navigating step 3/7 {room8: go straight}, 21.4 m to go, ...``."""
    parts = [p.get("phase", "")]
    if p.get("level"):
        parts.append(f"level {p['level']}")
    if p.get("step_text") and not p.get("step_count"):
        parts.append(p["step_text"])
    if p.get("step_count"):
        parts.append(f"step {p['current_step']}/{p['step_count']} {p.get('step_text', '')}")
    d = p.get("distance_remaining")
    if d is not None and not math.isnan(d):
        parts.append(f"{d:.1f} m to go")
    parts.append(f"{p.get('recoveries', 0)} recoveries")
    parts.append(f"{p.get('elapsed', 0.0):.0f} s")
    return ", ".join(x for x in parts if x)
