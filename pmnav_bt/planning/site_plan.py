"""Planning across levels: legs on each level, joined by lift rides.

A goal on another level is reached as a person reaches it: walk to a lift's lobby, ride
to the goal's level, walk from that lift's lobby to the room. The planner chooses the
lifts by total cost, in metres of corridor: the metres to the lobby on the start level,
a ride's cost (a call, once per ride, and a cost per level travelled), and the metres
from the lobby on the goal level (with, where no lift serves both levels, the metres
between two lifts' lobbies on a level in between). It searches over the lobbies
(Dijkstra on a small graph: the start, each lift's lobby on each level, the goal), so
it costs two corridor searches per candidate lobby, not one per level.

Each leg is a ``Plan`` of the ordinary planner (``GraphPlanner``), to a landmark goal
(the lift's lobby) or to the goal room; each ride is a ``LiftRide`` between them, whose
step reads ``{lift1: take the lift to level L2}``. Leg i ends at the lobby of ride i on
its level; leg i+1 starts at that lift's lobby on the next level, facing out of the
lift. A goal on the start level is one leg and no ride: exactly the building's plan.
"""

from __future__ import annotations

import heapq
import json
from dataclasses import dataclass, replace
from itertools import count

import networkx as nx

from pmnav_bt.errors import PlanningError
from pmnav_bt.geometry import heading
from pmnav_bt.map.site_map import SiteMap
from pmnav_bt.planning.graph_planner import GraphPlanner, graph_segment, shortest_route
from pmnav_bt.planning.plan import MAX_GAP_M, Plan
from pmnav_bt.planning.resolve import StartPoint, resolve_site_room, resolve_start
from pmnav_bt.seams import CREATE3_MAX_LINEAR, PlanConstraints
from pmnav_bt.seams import PlanStart as SeamStart

# The ride's cost in corridor metres: what the robot's time in the lift is worth at its
# driving speed. A call (wait for the cabin, the door, drive in, the door closes; at the
# other end drive out) takes about 45 s; travel about 5 s a level (4 m floor to floor at
# 1 m/s, with starting and stopping). At the Create 3's 0.306 m/s that is 13.8 m a call
# and 1.5 m a level: a lift 14 m nearer is worth a change of lifts.
DRIVE_M_PER_S = CREATE3_MAX_LINEAR
LIFT_CALL_S = 45.0
LIFT_LEVEL_S = 5.0
LIFT_CALL_M = LIFT_CALL_S * DRIVE_M_PER_S
LIFT_LEVEL_M = LIFT_LEVEL_S * DRIVE_M_PER_S


@dataclass(frozen=True)
class LiftRide:
    """A ride in ``lift`` from ``from_level`` to ``to_level`` (between two legs)."""

    lift: str
    from_level: str
    to_level: str

    def text(self) -> str:
        """The step, in the paper's notation: ``{lift1: take the lift to level L2}``."""
        return f"{{{self.lift}: take the lift to level {self.to_level}}}"


@dataclass(frozen=True)
class Leg:
    """The part of a plan on one level: an ordinary ``Plan`` on that level's map."""

    level: str
    plan: Plan


@dataclass(frozen=True)
class SitePlan:
    """A plan across levels: ``legs`` and, between each two, a ride (``rides[i]`` joins
    ``legs[i]`` to ``legs[i + 1]``). ``cost``: corridor metres plus the rides' costs."""

    site: str
    legs: tuple[Leg, ...]
    rides: tuple[LiftRide, ...]
    goal_level: str
    goal: str
    goal_name: str
    cost: float

    @property
    def start_level(self) -> str:
        return self.legs[0].level

    @property
    def length(self) -> float:
        """Metres along the corridors, every level together (the rides not counted)."""
        return sum(leg.plan.length for leg in self.legs)

    def step_texts(self) -> list[str]:
        """Every step in order, the rides between the legs' ``{landmark: action}`` steps."""
        out: list[str] = []
        for i, leg in enumerate(self.legs):
            out += [s.text() for s in leg.plan.steps]
            if i < len(self.rides):
                out.append(self.rides[i].text())
        return out

    def text(self) -> str:
        """Human-readable: one level's plan as the building's; else each leg under its
        level, with the rides between."""
        if not self.rides:
            return self.legs[0].plan.text()
        lines = [
            f"Plan in {self.site}: {self.legs[0].plan.start.description} on {self.start_level} "
            f'-> {self.goal} "{self.goal_name}" on {self.goal_level} ({self.length:.1f} m of '
            f"corridor, {len(self.rides)} lift ride(s), cost {self.cost:.1f} m)"
        ]
        for i, leg in enumerate(self.legs):
            lines.append(f"Level {leg.level}:")
            lines += ["  " + line for line in leg.plan.text().splitlines()]
            if i < len(self.rides):
                r = self.rides[i]
                lines.append(f"  ride: {r.text()} (from {r.from_level})")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        return {
            "site": self.site,
            "start_level": self.start_level,
            "goal": {"level": self.goal_level, "room": self.goal, "name": self.goal_name},
            "length_m": round(self.length, 3),
            "cost_m": round(self.cost, 3),
            "legs": [{"level": leg.level, "plan": leg.plan.to_dict()} for leg in self.legs],
            "rides": [
                {"lift": r.lift, "from": r.from_level, "to": r.to_level, "text": r.text()}
                for r in self.rides
            ],
            "steps": self.step_texts(),
        }

    def to_json(self, indent: int | None = 2) -> str:
        return json.dumps(self.to_dict(), indent=indent)


# A node of the lobby search: the start, the goal, or (level, lift id) at a lobby.
_START = ("", "start")
_GOAL = ("", "goal")


@dataclass(frozen=True)
class SitePlanner:
    """Plans across the levels of a site (``GraphPlanner`` legs, lifts by total cost)."""

    max_gap: float = MAX_GAP_M
    ride_call_m: float = LIFT_CALL_M
    ride_level_m: float = LIFT_LEVEL_M

    def plan(
        self,
        sm: SiteMap,
        start_level: str,
        start: SeamStart | StartPoint,
        goal: str,
        constraints: PlanConstraints = PlanConstraints(),
    ) -> SitePlan:
        """Plan from ``start`` on ``start_level`` to the room ``goal`` (a name a person
        types, on any level: see ``resolve_site_room``). ``constraints`` hold on the start
        level, where the robot is and has seen what failed."""
        site = sm.site
        level = site.level(start_level).name
        goal_level, goal_id = resolve_site_room(sm, goal)
        pm = sm.maps[level]
        sp = start if isinstance(start, StartPoint) else resolve_start(pm, start)
        legs_planner = GraphPlanner(max_gap=self.max_gap)
        goal_pm = sm.maps[goal_level]
        goal_name = goal_pm.building.room(goal_id).display_name
        if level == goal_level:
            plan = legs_planner.plan(pm, sp, goal_id, constraints)
            return SitePlan(
                site.name, (Leg(level, plan),), (), level, goal_id, goal_name, plan.length
            )
        route, cost = self._lobby_route(sm, level, sp, goal_level, goal_id, constraints)
        legs: list[Leg] = []
        rides: list[LiftRide] = []
        here, at, prev = level, sp, None
        for lv, lift in route:
            if prev is not None and prev[1] == lift and prev[0] != lv:  # a ride
                rides.append(LiftRide(lift, prev[0], lv))
                here, at = lv, _out_of_lift(sm, lift, lv)
            else:  # a walk on this level to the lift's lobby
                lobby = site.lift(lift).lobbies[lv]
                cons = constraints if lv == level else PlanConstraints()
                plan = legs_planner.plan_to_landmark(sm.maps[lv], at, lobby, cons)
                legs.append(Leg(lv, plan))
            prev = (lv, lift)
        legs.append(Leg(here, legs_planner.plan(goal_pm, at, goal_id)))
        return SitePlan(site.name, tuple(legs), tuple(rides), goal_level, goal_id, goal_name, cost)

    def _lobby_route(
        self,
        sm: SiteMap,
        level: str,
        sp: StartPoint,
        goal_level: str,
        goal_id: str,
        constraints: PlanConstraints,
    ) -> tuple[list[tuple[str, str]], float]:
        """The cheapest way from the start to the goal over the lifts' lobbies: the nodes
        (level, lift) it passes, the start and goal dropped, and its cost."""
        site = sm.site
        pm = sm.maps[level]
        graph = pm.graph
        if constraints.blocked_segments:
            graph = nx.subgraph_view(
                pm.graph,
                filter_edge=lambda u, v: graph_segment(pm, u, v)
                not in constraints.blocked_segments,
            )
        goal_node = sm.maps[goal_level].places[goal_id].node

        def neighbours(node: tuple[str, str]):
            if node == _START:
                for lift in site.lifts_at(level):
                    try:
                        _, d, _ = shortest_route(
                            pm, sp, sm.lobby_nodes[(lift.id, level)], graph, constraints.blocked_at
                        )
                    except PlanningError:
                        continue
                    yield (level, lift.id), d
                return
            lv, lift_id = node
            for other in site.lift(lift_id).lobbies:
                if other != lv:
                    levels = abs(site.rank(other) - site.rank(lv))
                    yield (other, lift_id), self.ride_call_m + self.ride_level_m * levels
            if lv == goal_level:
                d = _node_distance(sm, lv, sm.lobby_nodes[(lift_id, lv)], goal_node)
                if d is not None:
                    yield _GOAL, d
            for other in site.lifts_at(lv):
                if other.id != lift_id:
                    d = _lobby_distance(sm, lv, lift_id, other.id)
                    if d is not None:
                        yield (lv, other.id), d

        best = {_START: 0.0}
        came: dict[tuple[str, str], tuple[str, str]] = {}
        tie = count()
        heap = [(0.0, next(tie), _START)]
        done = set()
        while heap:
            cost, _, node = heapq.heappop(heap)
            if node in done:
                continue
            done.add(node)
            if node == _GOAL:
                route = [node]
                while route[-1] != _START:
                    route.append(came[route[-1]])
                return route[-2:0:-1], cost
            for nxt, step in neighbours(node):
                c = cost + step
                if c < best.get(nxt, float("inf")):
                    best[nxt] = c
                    came[nxt] = node
                    heapq.heappush(heap, (c, next(tie), nxt))
        served = ", ".join(lift.id for lift in site.lifts_at(level))
        why = (
            f"no lift leaves {level}"
            if not served
            else f"no lift ({served}) reached from there leads to {goal_level}"
        )
        raise PlanningError(
            f"{goal_id} on {goal_level} cannot be reached from {sp.description} on {level}: {why}"
        )


def _node_distance(sm: SiteMap, level: str, a: str, b: str) -> float | None:
    """Corridor metres between two nodes of a level (None: not joined)."""
    try:
        return float(nx.shortest_path_length(sm.maps[level].graph, a, b, weight="length"))
    except nx.NetworkXNoPath:
        return None


def _lobby_distance(sm: SiteMap, level: str, lift_a: str, lift_b: str) -> float | None:
    """Corridor metres between two lifts' lobbies on a level (cached on the site map: the
    change of lifts on a level between the start's and the goal's)."""
    cache = sm.__dict__.setdefault("_lobby_distances", {})
    key = (level, *sorted((lift_a, lift_b)))
    if key not in cache:
        a, b = sm.lobby_nodes[(lift_a, level)], sm.lobby_nodes[(lift_b, level)]
        cache[key] = _node_distance(sm, level, a, b)
    return cache[key]


def _out_of_lift(sm: SiteMap, lift: str, level: str) -> StartPoint:
    """Where a leg starts after a ride: the lift's lobby on ``level``, facing out of the
    lift (from the doors towards the corridor's centre line)."""
    pm = sm.maps[level]
    lobby = sm.site.lift(lift).lobbies[level]
    sp = resolve_start(pm, lobby)
    doors = pm.building.landmark(lobby).pos
    node = pm.node_xy(pm.places[lobby].node)
    facing = heading(doors, node) if abs(node - doors).sum() > 1e-6 else None
    return replace(sp, description=f"{lobby} (out of {lift})", heading=facing)
