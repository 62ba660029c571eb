"""Check a VLM plan against the priori-map; every problem is a typed, quotable issue.

A plan is valid when:

- every step names a room, landmark or key waypoint of the map (not a segment);
- every action is one of go straight, turn left, turn right, turn around, arrive;
- the start reaches the first step, and each step the next, along one stretch of
  corridor: no key waypoint (turn, branch, end) is passed without being a step, and no
  segment found blocked is used;
- each action agrees with the headings: the turn from the way the robot arrives at a
  step to the way it leaves towards the next (the graph planner's ``relative_action``);
- no step is a landmark the plan must avoid (it failed to be found before);
- the last step is the goal room, with the action ``arrive``.

The valid plan's node route then becomes a project Plan through the graph planner's
``build_plan``: the geometry is derived once, in one place.
"""

from __future__ import annotations

import difflib
import heapq
import math
from dataclasses import dataclass
from enum import Enum

import numpy as np

from pmnav_bt.errors import UnknownNameError
from pmnav_bt.geometry import Action, compass, heading, relative_action
from pmnav_bt.map.priori_map import PrioriMap, natural_key
from pmnav_bt.planning.resolve import StartPoint, entity_index, normalise, resolve_room
from pmnav_bt.seams import PlanConstraints
from pmnav_bt.vlm.parse import RawStep

NO_CONSTRAINTS = PlanConstraints()


class IssueKind(str, Enum):
    """What is wrong with an answer (the evaluation counts them by kind)."""

    NO_PLAN = "no_plan"  # no plan in the answer
    MALFORMED_JSON = "malformed_json"  # JSON cut off or broken
    UNKNOWN_LANDMARK = "unknown_landmark"  # a name that is not on the map
    UNKNOWN_ACTION = "unknown_action"  # an action outside the five
    NOT_CONNECTED = "not_connected"  # consecutive steps not joined by one corridor stretch
    WRONG_ACTION = "wrong_action"  # the action disagrees with the headings
    WRONG_GOAL = "wrong_goal"  # the plan does not end at the goal (with arrive)
    WRONG_LIFT = "wrong_lift"  # across levels: a ride on no lift, or one not joining the levels
    AVOIDED_LANDMARK = "avoided_landmark"  # a landmark the replan must avoid
    BLOCKED_SEGMENT = "blocked_segment"  # the way uses a segment found blocked
    DETOUR = "detour"  # valid, but much longer than the shortest route
    SERVER_ERROR = "server_error"  # no answer at all (timeout, HTTP errors)


@dataclass(frozen=True)
class PlanIssue:
    """One problem, with the step it concerns (1-based; None: the plan as a whole)."""

    kind: IssueKind
    message: str
    step: int | None = None

    def __str__(self) -> str:
        return f"step {self.step}: {self.message}" if self.step else self.message


@dataclass(frozen=True)
class CheckedRoute:
    """A valid plan as a route on the map: every node passed, its length, the start point."""

    nodes: tuple[str, ...]
    length: float
    start_xy: tuple[float, float]
    steps: tuple[tuple[str, Action], ...]  # the plan's own steps, resolved to map nodes


_ACTIONS = {
    Action.GO_STRAIGHT: (
        "gostraight",
        "straight",
        "continue",
        "goforward",
        "forward",
        "goahead",
        "straightahead",
        "keepstraight",
        "passby",
        "pass",
    ),
    Action.TURN_LEFT: ("turnleft", "left", "goleft", "leftturn"),
    Action.TURN_RIGHT: ("turnright", "right", "goright", "rightturn"),
    Action.TURN_AROUND: ("turnaround", "uturn", "turnback", "goback", "reverse"),
    Action.ARRIVE: (
        "arrive",
        "stop",
        "arrived",
        "arriveat",
        "destination",
        "enter",
        "reached",
        "goal",
        "reach",
    ),
}
_ACTION_INDEX = {k: a for a, keys in _ACTIONS.items() for k in keys}


def parse_action(text: str) -> Action | None:
    """A plan action from what a VLM wrote ('Go straight', 'turn_left', 'U-turn'), or None."""
    return _ACTION_INDEX.get(normalise(text))


def resolve_node(pm: PrioriMap, name: str) -> tuple[str, str | None] | None:
    """(map node, room/landmark id or None for a key waypoint) a plan step names, or None."""
    key = normalise(name)
    for nid in pm.nodes:
        if normalise(nid) == key:
            ident = nid if nid in pm.places else None
            return nid, ident
    for ident, place in pm.places.items():
        if normalise(ident) == key:
            return place.node, ident
    hit = entity_index(pm.building).get(key)
    if hit is not None:
        ident = hit.split(":", 1)[1]
        return pm.places[ident].node, ident
    try:
        rid = resolve_room(pm, name)
    except UnknownNameError:
        return None
    return pm.places[rid].node, rid


def check_plan(
    pm: PrioriMap,
    sp: StartPoint,
    goal_id: str,
    raw: list[RawStep],
    constraints: PlanConstraints = NO_CONSTRAINTS,
) -> tuple[CheckedRoute | None, list[PlanIssue]]:
    """The route of a valid plan, or None and every issue found."""
    issues: list[PlanIssue] = []
    steps: list[tuple[int, str, str | None, Action | None, str]] = []
    for k, s in enumerate(raw, 1):
        node = resolve_node(pm, s.name)
        action = parse_action(s.action)
        if node is None:
            issues.append(PlanIssue(IssueKind.UNKNOWN_LANDMARK, _unknown(pm, s.name), k))
        if action is None:
            issues.append(
                PlanIssue(
                    IssueKind.UNKNOWN_ACTION,
                    f"{s.action!r} at {s.name} is not an action; use go straight, turn left, "
                    "turn right, turn around or arrive",
                    k,
                )
            )
        if node is not None:
            steps.append((k, node[0], node[1], action, s.name))
    if not raw:
        issues.append(PlanIssue(IssueKind.NO_PLAN, "the plan has no steps"))
    if issues:
        return None, issues

    goal_node = pm.places[goal_id].node
    for k, _node, ident, _a, name in steps:
        if ident and ident in constraints.avoid_landmarks and ident != goal_id:
            issues.append(
                PlanIssue(
                    IssueKind.AVOIDED_LANDMARK,
                    f"{name} was not found on the way before; plan a route without it",
                    k,
                )
            )
    # Consecutive steps on one node (two doors facing each other) are one step.
    merged: list[tuple[int, str, Action, str]] = []
    for k, node, _ident, action, name in steps:
        if merged and merged[-1][1] == node:
            merged[-1] = (k, node, action, name)
        else:
            merged.append((k, node, action, name))

    seg = sp.segment
    a_xy, b_xy = pm.node_xy(seg.a), pm.node_xy(seg.b)
    start_xy = a_xy + sp.t * (b_xy - a_xy)
    first_k, first_node, _, first_name = merged[0]
    best = None
    for end in (seg.a, seg.b):
        lead = float(np.linalg.norm(pm.node_xy(end) - start_xy))
        at_end = lead < 1e-6
        if end != first_node and pm.nodes[end].is_key and not at_end:
            continue  # would pass an unnamed turn, branch or end
        walk = _walk(pm, end, first_node, constraints.blocked_segments)
        if walk is not None and (best is None or lead + walk[1] < best[1]):
            best = (walk[0], lead + walk[1])
    if best is None:
        issues.append(
            PlanIssue(
                IssueKind.NOT_CONNECTED,
                f"the robot starts on {seg.name}; {first_name} cannot be reached from there "
                f"without passing another turn or branch first (the segment leads to "
                f"{seg.a} and {seg.b})",
                first_k,
            )
        )
        return None, issues
    nodes, length = list(best[0]), best[1]
    step_at = {0: len(nodes) - 1}  # merged index -> index in nodes
    for i in range(1, len(merged)):
        (_, u, _, u_name), (k, v, _, v_name) = merged[i - 1], merged[i]
        walk = _walk(pm, u, v, constraints.blocked_segments)
        if walk is None:
            issues.append(_not_connected(pm, u, v, u_name, v_name, k, constraints))
            return None, issues
        nodes += walk[0][1:]
        length += walk[1]
        step_at[i] = len(nodes) - 1

    pts = [start_xy] + [pm.node_xy(n) for n in nodes]
    for i, (k, _node, action, name) in enumerate(merged):
        j = step_at[i] + 1  # index in pts
        last = i == len(merged) - 1
        if last:
            continue
        if action is Action.ARRIVE:
            issues.append(
                PlanIssue(IssueKind.WRONG_ACTION, f"arrive at {name}, but {goal_id} is the goal", k)
            )
            continue
        h_in = _arrival_heading(pts, j, sp.heading)
        if h_in is None:
            continue
        h_out = heading(pts[j], pts[j + 1])
        want = relative_action(h_in, h_out)
        if want is not action:
            issues.append(
                PlanIssue(
                    IssueKind.WRONG_ACTION,
                    f"at {name} the robot arrives heading {compass(h_in)} and leaves heading "
                    f"{compass(h_out)} towards {nodes[step_at[i] + 1]}: that is "
                    f"'{want.value}', not '{action.value}'",
                    k,
                )
            )
    k, node, action, name = merged[-1]
    if node != goal_node:
        issues.append(
            PlanIssue(
                IssueKind.WRONG_GOAL,
                f"the plan ends at {name}, not at the goal {goal_id}; its last step must be "
                f"{{{goal_id}: arrive}}",
                k,
            )
        )
    elif action is not Action.ARRIVE:
        issues.append(
            PlanIssue(
                IssueKind.WRONG_GOAL,
                f"the last step reaches the goal {goal_id} with '{action.value}'; it must be "
                "'arrive'",
                k,
            )
        )
    if issues:
        return None, issues
    route = CheckedRoute(
        tuple(nodes),
        float(length),
        (float(start_xy[0]), float(start_xy[1])),
        tuple((n, a) for _, n, a, _ in merged),
    )
    return route, []


def _arrival_heading(pts: list[np.ndarray], j: int, start_heading: float | None) -> float | None:
    """The heading on arrival at pts[j]: from the point before it, or the start heading."""
    for i in range(j - 1, -1, -1):
        if np.linalg.norm(pts[j] - pts[i]) > 1e-6:
            return heading(pts[i], pts[j])
    return start_heading


def _walk(pm: PrioriMap, u: str, v: str, blocked: frozenset[int]) -> tuple[list[str], float] | None:
    """The shortest way from u to v passing only room and landmark nodes (no key waypoint
    other than u and v), avoiding ``blocked`` segments; None if there is none."""
    if u == v:
        return [u], 0.0
    dist = {u: 0.0}
    prev: dict[str, str] = {}
    heap = [(0.0, u)]
    while heap:
        d, n = heapq.heappop(heap)
        if n == v:
            path = [v]
            while path[-1] != u:
                path.append(prev[path[-1]])
            return path[::-1], d
        if d > dist[n] or (n != u and pm.nodes[n].is_key):
            continue
        for m, data in pm.graph[n].items():
            if data["segment"] in blocked:
                continue
            nd = d + data["length"]
            if nd < dist.get(m, math.inf):
                dist[m], prev[m] = nd, n
                heapq.heappush(heap, (nd, m))
    return None


def _not_connected(pm, u, v, u_name, v_name, k, constraints) -> PlanIssue:
    if constraints.blocked_segments and _walk(pm, u, v, frozenset()) is not None:
        segs = ", ".join(f"seg{i}" for i in sorted(constraints.blocked_segments))
        return PlanIssue(
            IssueKind.BLOCKED_SEGMENT,
            f"the way from {u_name} to {v_name} uses a segment found blocked ({segs})",
            k,
        )
    near = sorted(pm.graph.neighbors(u), key=natural_key)
    return PlanIssue(
        IssueKind.NOT_CONNECTED,
        f"{u_name} -> {v_name}: no single stretch of corridor joins them (a turn or branch "
        f"between them must be a step); from {u_name} the corridor leads to "
        f"{', '.join(near)}",
        k,
    )


def _unknown(pm: PrioriMap, name: str) -> str:
    key = normalise(name)
    if key.startswith("seg") and key[3:].isdigit():
        return f"{name!r} is a segment; name rooms, landmarks and key waypoints instead"
    names = sorted(set(pm.nodes) | set(pm.places), key=natural_key)
    close = difflib.get_close_matches(key, [normalise(n) for n in names], n=3, cutoff=0.6)
    by_key = {normalise(n): n for n in names}
    hint = f" (closest: {', '.join(by_key[c] for c in close)})" if close else ""
    return f"{name!r} is not on the map{hint}"
