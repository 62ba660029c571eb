"""Graph planner: the shortest corridor path from a start to a goal room, as a paper-style plan.

The path is found on the priori-map graph (Dijkstra on corridor lengths). It then
becomes ordered ``{landmark: action}`` steps: first-person actions from the change
of heading at each node; every turn and fork; the last recognisable landmark before
each unseen turn, carrying that turn as an action prediction; and enough landmarks
in between that no two consecutive steps are more than ``max_gap`` metres apart.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import pairwise
from typing import TYPE_CHECKING

import networkx as nx
import numpy as np

from pmnav_bt.errors import PlanningError, UnknownNameError
from pmnav_bt.geometry import Action, heading, relative_action, wrap_angle
from pmnav_bt.map.landmark_kinds import landmark_shape
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.planning.plan import MAX_GAP_M, ForkChoice, Plan, PlanStart, PlanStep
from pmnav_bt.planning.resolve import StartPoint, resolve_room, resolve_start
from pmnav_bt.seams import PlanConstraints
from pmnav_bt.seams import PlanStart as SeamStart

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.backends import BackendDeps

SAME_PLACE_M = 1e-6  # route points closer than this are one place (no leg to drive between)


@dataclass(frozen=True)
class GraphPlanner:
    """Shortest-path planner over the priori-map (the default planner)."""

    max_gap: float = MAX_GAP_M  # metres between consecutive steps, where landmarks allow

    name = "graph"

    def plan(
        self,
        pm: PrioriMap,
        start: SeamStart | StartPoint,
        goal: str,
        constraints: PlanConstraints = PlanConstraints(),
    ) -> Plan:
        """Plan from ``start`` (a map pose, a name a person types, or a resolved point) to
        the room ``goal``, using no landmark in ``constraints.avoid_landmarks`` as an
        intermediate step and no segment in ``constraints.blocked_segments``."""
        goal_id = resolve_room(pm, goal)
        sp = start if isinstance(start, StartPoint) else resolve_start(pm, start)
        return self._route_plan(pm, sp, goal_id, constraints)


    def plan_to_landmark(
        self,
        pm: PrioriMap,
        start: SeamStart | StartPoint,
        landmark_id: str,
        constraints: PlanConstraints = PlanConstraints(),
    ) -> Plan:
        """Plan from ``start`` to the landmark ``landmark_id`` (an id of the map, such as a
        lift's lobby), as ``plan`` plans to a room: the last step arrives at it."""
        place = pm.places.get(landmark_id)
        if place is None or landmark_id not in pm.nodes[place.node].landmarks:
            raise UnknownNameError(f"no landmark {landmark_id!r} in {pm.building.name}")
        sp = start if isinstance(start, StartPoint) else resolve_start(pm, start)
        return self._route_plan(pm, sp, landmark_id, constraints)

    def _route_plan(
        self, pm: PrioriMap, sp: StartPoint, goal_id: str, constraints: PlanConstraints
    ) -> Plan:
        blocked = constraints.blocked_segments
        graph = pm.graph
        if blocked:
            graph = nx.subgraph_view(
                pm.graph, filter_edge=lambda u, v: graph_segment(pm, u, v) not in blocked
            )
        nodes, length, start_xy = shortest_route(
            pm, sp, pm.places[goal_id].node, graph, constraints.blocked_at
        )
        return build_plan(
            pm,
            sp,
            goal_id,
            nodes,
            length,
            start_xy,
            self.max_gap,
            self.name,
            constraints.avoid_landmarks,
        )


def build(deps: BackendDeps) -> GraphPlanner:
    """The ``graph`` back end (registry factory)."""
    return GraphPlanner(max_gap=deps.config.planner.max_gap)


def graph_segment(pm: PrioriMap, u: str, v: str) -> int:
    """Index of the segment between two adjacent nodes."""
    return pm.graph.edges[u, v]["segment"]


def shortest_route(
    pm: PrioriMap,
    sp: StartPoint,
    goal_node: str,
    graph: nx.Graph | None = None,
    blocked_at: frozenset[tuple[float, float]] = frozenset(),
) -> tuple[list[str], float, np.ndarray]:
    """Nodes from the start point to the goal node, the route length, and the start point;
    never past a point of ``blocked_at`` on the start's own segment."""
    graph = pm.graph if graph is None else graph
    seg = sp.segment
    a_xy, b_xy = pm.node_xy(seg.a), pm.node_xy(seg.b)
    start_xy = a_xy + sp.t * (b_xy - a_xy)
    shut = shut_ends(pm, sp, blocked_at)
    best: tuple[float, list[str]] | None = None
    for end, lead in ((seg.a, sp.t * seg.length), (seg.b, (1.0 - sp.t) * seg.length)):
        if end in shut:
            continue
        try:
            d, path = nx.bidirectional_dijkstra(graph, end, goal_node, weight="length")
        except nx.NetworkXNoPath:
            continue
        total = lead + d
        # On a tie, prefer the way the robot already faces.
        tie_break = 0.0
        if sp.heading is not None:
            toward = heading(start_xy, pm.node_xy(end)) if lead > 1e-9 else sp.heading
            tie_break = abs(wrap_angle(toward - sp.heading)) * 1e-9
        if best is None or total + tie_break < best[0]:
            best = (total + tie_break, path)
    if best is None:
        raise PlanningError(f"{goal_node} cannot be reached from {sp.description}")
    nodes = best[1]
    length = _route_length(pm, start_xy, nodes)
    return nodes, length, start_xy


def shut_ends(
    pm: PrioriMap, sp: StartPoint, blocked_at: frozenset[tuple[float, float]]
) -> set[str]:
    """The ends of the start's segment that a point of ``blocked_at`` on it (within half
    its width of the centre line) lies between the start and."""
    seg, shut = sp.segment, set()
    for point in blocked_at:
        at = pm.locate(*point)
        if at.segment.index != seg.index or at.offset > seg.width / 2.0:
            continue
        shut.add(seg.b if at.t > sp.t else seg.a)
    return shut


def _route_length(pm: PrioriMap, start_xy: np.ndarray, nodes: list[str]) -> float:
    pts = [start_xy] + [pm.node_xy(n) for n in nodes]
    return float(sum(np.linalg.norm(q - p) for p, q in pairwise(pts)))


def _side(heading_in: float, at: np.ndarray, target) -> str:
    bearing = wrap_angle(heading(at, target) - heading_in)
    if abs(bearing) <= math.radians(30):
        return "ahead"
    if abs(bearing) >= math.radians(150):
        return "behind"
    return "left" if bearing > 0 else "right"


def _target_of(
    pm: PrioriMap, node_id: str, goal_id: str, avoid: frozenset[str] = frozenset()
) -> tuple[str | None, object]:
    """What to look for at a node (room or landmark id) and its position, or (None, None).
    A landmark with no sign to read (a fire door: ``LandmarkShape.readable``) is never it."""
    n = pm.nodes[node_id]
    b = pm.building
    if goal_id in n.rooms:
        return goal_id, b.room(goal_id).door
    if goal_id in n.landmarks:  # a landmark goal: a leg of a plan across levels ends at a lift
        return goal_id, b.landmark(goal_id).pos
    for rid in n.rooms:
        if rid not in avoid:
            return rid, b.room(rid).door
    for lid in n.landmarks:
        lm = b.landmark(lid)
        if lid not in avoid and landmark_shape(lm.kind).readable:
            return lid, lm.pos
    return None, None


def _places(
    pm: PrioriMap, sp: StartPoint, start_xy: np.ndarray, nodes: list[str]
) -> tuple[list[tuple[float, float]], list[str | None], list[str]]:
    """The route as the places the robot passes: their points, the node at each (None for a
    start point off every node) and the name of the segment that leads there.

    Consecutive route points at one place are one place: the start on its first node, or
    two landmarks at one spot of a wall, which the map links to one point of the centre
    line with a 0 m segment between them. A step over that segment would have no distance
    to drive and no heading (it would read as a turn around and back). The later node is
    kept, so the goal stays the last place, with the segment that led to the place.
    """
    adj, map_nodes, segments = pm.adjacency, pm.nodes, pm.segments
    pts = [(float(start_xy[0]), float(start_xy[1]))]
    route: list[str | None] = [None]
    via = [sp.segment.name]
    for n in nodes:
        x, y = map_nodes[n].pos
        px, py = pts[-1]
        if math.sqrt((x - px) ** 2 + (y - py) ** 2) < SAME_PLACE_M:
            pts[-1], route[-1] = (x, y), n
            continue
        edge = adj[route[-1]].get(n) if route[-1] is not None else None
        via.append(segments[edge[1] - 1].name if edge is not None else sp.segment.name)
        pts.append((x, y))
        route.append(n)
    return pts, route, via


def build_plan(
    pm: PrioriMap,
    sp: StartPoint,
    goal_id: str,
    nodes: list[str],
    length: float,
    start_xy: np.ndarray,
    max_gap: float,
    planner: str,
    avoid_landmarks: frozenset[str] = frozenset(),
) -> Plan:
    """Turn a node route into plan steps (actions, predictions, forks, sides)."""
    pts, route, via = _places(pm, sp, start_xy, nodes)  # index i of route matches pts[i]
    cum = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))])
    cum = cum.tolist()
    headings = [heading(p, q) for p, q in pairwise(pts)]  # headings[i - 1]: into place i
    notes: list[str] = []
    if len(pts) == 1:
        first_heading = sp.heading if sp.heading is not None else sp.segment.heading
    else:
        first_heading = headings[0]
    if sp.heading is None:
        initial = Action.GO_STRAIGHT
        notes.append("start heading unknown: the plan assumes the robot faces its first segment")
    else:
        initial = relative_action(sp.heading, first_heading)

    # Each place a candidate step (the start only where it is the goal's place already):
    # its action on arrival, the fork there, what to look for there and where that is.
    last = len(pts) - 1
    order = range(1, len(pts)) if last else range(1)
    h_ins = [first_heading, *headings]  # h_ins[i]: the heading on arriving at place i
    actions: list[Action] = [Action.ARRIVE] * len(pts)
    forks: list[ForkChoice | None] = [None] * len(pts)
    looks: list[str | None] = [goal_id] * len(pts)
    targets: list = [None] * len(pts)
    if not last:  # already at the goal's room waypoint
        targets[0] = _target_of(pm, route[0], goal_id)[1]
    first_at: dict[str, int] = {}  # each node's first index on the route, before merging
    for k, n in enumerate(nodes):
        first_at.setdefault(n, k)
    for i in range(1, len(pts)):
        node_id = route[i]
        h_in = h_ins[i]
        if i < last:
            actions[i] = relative_action(h_in, h_ins[i + 1])
            if pm.nodes[node_id].kind == "branch":
                k = first_at[node_id]  # its neighbours on the route, before places merged
                came, goes = nodes[k - 1] if k > 0 else route[i - 1], nodes[k + 1]
                others = [
                    relative_action(h_in, heading(pts[i], pm.nodes[nb].pos))
                    for nb in pm.adjacency[node_id]
                    if nb not in (came, goes)
                ]
                forks[i] = ForkChoice(actions[i], tuple(others))
        looks[i], targets[i] = _target_of(pm, node_id, goal_id, avoid_landmarks)

    required = {
        i
        for i in order
        if i == last or forks[i] is not None or actions[i] is not Action.GO_STRAIGHT
    }
    # The last visible node before each unseen required step predicts it.
    predictor: dict[int, int] = {}
    last_visible = None
    for i in order:
        visible = looks[i] is not None
        if i in required and not visible and last_visible is not None:
            predictor[last_visible] = i
            required.add(last_visible)
        if visible:
            last_visible = i
        if i in required:
            last_visible = None if not visible else i
    # Fill long gaps with visible landmarks (greedy: keep one before the gap gets too long).
    kept: list[int] = []
    last_cum = 0.0
    anchors = [i for i in order if looks[i] is not None or i in required]
    for k, i in enumerate(anchors):
        nxt = anchors[k + 1] if k + 1 < len(anchors) else None
        if i in required or (nxt is not None and cum[nxt] - last_cum > max_gap):
            kept.append(i)
            last_cum = cum[i]
    steps: list[PlanStep] = []
    prev_cum = 0.0
    for i in kept:
        visible = looks[i] is not None
        pred = predictor.get(i)
        steps.append(
            PlanStep(
                landmark=goal_id if i == last else route[i],
                action=actions[i],
                kind=pm.nodes[route[i]].kind,
                visible=visible,
                position=(float(pts[i][0]), float(pts[i][1])),
                heading=h_ins[i],
                distance=float(cum[i] - prev_cum),
                segment=via[i],
                side=_side(h_ins[i], pts[i], targets[i]) if visible else None,
                target=tuple(float(v) for v in targets[i]) if visible else None,
                look_for=looks[i],
                predicts=(route[pred] if pred != last else goal_id, actions[pred])
                if pred is not None
                else None,
                fork=forks[i],
            )
        )
        prev_cum = cum[i]
    goal_room = goal_id in pm.nodes[pm.places[goal_id].node].rooms
    goal = pm.building.room(goal_id) if goal_room else pm.building.landmark(goal_id)
    return Plan(
        building=pm.building.name,
        start=PlanStart(
            sp.description, sp.segment.name, (float(start_xy[0]), float(start_xy[1])), sp.heading
        ),
        goal=goal_id,
        goal_name=goal.display_name,
        steps=tuple(steps),
        nodes=tuple(nodes),
        path=((float(start_xy[0]), float(start_xy[1])),)
        + tuple((float(x), float(y)) for x, y in (pm.nodes[n].pos for n in nodes)),
        length=float(length),
        initial_action=initial,
        planner=planner,
        notes=tuple(notes),
        goal_kind="room" if goal_room else "landmark",
    )
