"""The global plan: ordered ``{landmark: action}`` steps, as in the paper's Fig. 2.

A step names what to look for (a room, a landmark, or a key waypoint that cannot
be seen, such as ``turn2``) and the first-person action to take there. A visible
step followed by an unseen one carries that one's action as a prediction:
``{room8: go straight} -> {turn2: turn left}``.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict, dataclass, field

from pmnav_bt.geometry import Action, compass

# Most metres between consecutive plan steps, where landmarks allow: the planners' default
# and the config's (planner.max_gap).
MAX_GAP_M = 8.0


@dataclass(frozen=True)
class ForkChoice:
    """At a branch waypoint: the action taken and the actions the other corridors would need."""

    chosen: Action
    options: tuple[Action, ...]


@dataclass(frozen=True)
class PlanStep:
    """One step of a plan: reach ``landmark``, then do ``action``."""

    landmark: str
    action: Action
    kind: str  # room | landmark | start | turn | branch | end
    visible: bool  # a sign or landmark that can be recognised
    position: tuple[float, float]  # the map node on the corridor centre line
    heading: float  # direction of travel on arrival, rad
    distance: float  # metres from the previous step (or from the start)
    segment: str  # name of the segment that arrives at this step
    side: str | None = None  # where the landmark is seen on arrival: left | right | ahead
    target: tuple[float, float] | None = None  # door or landmark position, when visible
    look_for: str | None = None  # the room or landmark whose sign marks this step
    predicts: tuple[str, Action] | None = None  # the next, unseen step (action prediction)
    fork: ForkChoice | None = None

    def text(self) -> str:
        """The paper's notation, e.g. ``{room8: go straight} -> {turn2: turn left}``."""
        s = f"{{{self.landmark}: {self.action.value}}}"
        if self.predicts:
            s += f" -> {{{self.predicts[0]}: {self.predicts[1].value}}}"
        return s


@dataclass(frozen=True)
class PlanStart:
    """Where the plan starts: a point on a segment, and the heading if known."""

    description: str
    segment: str
    position: tuple[float, float]
    heading: float | None


@dataclass(frozen=True)
class Plan:
    """A global plan from a start to a goal room (or a landmark: a lift's lobby)."""

    building: str
    start: PlanStart
    goal: str  # room id (a landmark id where goal_kind is "landmark")
    goal_name: str
    steps: tuple[PlanStep, ...]
    nodes: tuple[str, ...]  # the map nodes passed, in order
    path: tuple[tuple[float, float], ...]  # the start point then each node position
    length: float  # metres along the corridors
    initial_action: Action  # to face the first segment from the start heading
    planner: str = "graph"
    notes: tuple[str, ...] = field(default=())
    goal_kind: str = "room"  # "landmark": a leg of a plan across levels, to a lift's lobby

    def text(self) -> str:
        """Human-readable plan, one step per line."""
        lines = [
            f"Plan in {self.building}: {self.start.description} -> {self.goal} "
            f'"{self.goal_name}" ({self.length:.1f} m, {len(self.steps)} steps, {self.planner})',
        ]
        first_heading = self.steps[0].heading if self.steps else 0.0
        lines.append(
            f"  0. at the start: {self.initial_action.value}, heading {compass(first_heading)}"
        )
        for i, s in enumerate(self.steps, 1):
            extra = []
            if s.side and s.visible:
                extra.append("ahead" if s.side == "ahead" else f"on the {s.side}")
            if s.fork:
                opts = ", ".join(o.value for o in s.fork.options)
                extra.append(f"fork: {s.fork.chosen.value} (other ways: {opts})")
            extra.append(f"{s.distance:.1f} m via {s.segment}")
            lines.append(f"  {i}. {s.text():<42} " + "; ".join(extra))
        lines += [f"  note: {n}" for n in self.notes]
        return "\n".join(lines)

    def to_dict(self) -> dict:
        """JSON-ready data; angles in degrees for people, positions in metres."""
        steps = []
        for s in self.steps:
            d = asdict(s)
            d["action"] = s.action.value
            d["heading_deg"] = round(math.degrees(d.pop("heading")), 1)
            d["predicts"] = {s.predicts[0]: s.predicts[1].value} if s.predicts else None
            d["fork"] = (
                {"chosen": s.fork.chosen.value, "options": [o.value for o in s.fork.options]}
                if s.fork
                else None
            )
            d["text"] = s.text()
            steps.append(d)
        start = asdict(self.start)
        h = start.pop("heading")
        start["heading_deg"] = None if h is None else round(math.degrees(h), 1)
        return {
            "building": self.building,
            "planner": self.planner,
            "start": start,
            "goal": {self.goal_kind: self.goal, "name": self.goal_name},
            "length_m": round(self.length, 3),
            "initial_action": self.initial_action.value,
            "steps": steps,
            "nodes": list(self.nodes),
            "path": [list(p) for p in self.path],
            "notes": list(self.notes),
        }

    def to_json(self, indent: int | None = 2) -> str:
        return json.dumps(self.to_dict(), indent=indent)
