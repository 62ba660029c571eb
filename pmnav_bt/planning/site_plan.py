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
from pmnav_bt.geometry import heading, wrap_angle
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.map.site import Site
from pmnav_bt.map.site_map import SiteMap
from pmnav_bt.planning.graph_planner import GraphPlanner, build_plan, shut_ends
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

    def ride_cost(self, site: Site, a: str, b: str) -> float:
        """A ride's cost in corridor metres, from level ``a`` to level ``b``."""
        return self.ride_call_m + self.ride_level_m * abs(site.rank(b) - site.rank(a))

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
        search = _LobbySearch(self, sm, level, sp, goal_level, goal_id, constraints)
        route, cost = search.route()
        legs: list[Leg] = []
        rides: list[LiftRide] = []
        here, at, prev = level, sp, None
        for lv, lift in route:
            if prev is not None and prev[1] == lift and prev[0] != lv:  # a ride
                rides.append(LiftRide(lift, prev[0], lv))
                here, at = lv, out_of_lift(sm, lift, lv)
            elif prev is None:  # the first walk: its route is the search's
                legs.append(Leg(lv, search.first_leg(lift, self.max_gap)))
            else:  # a change of lifts on a level between
                lobby = site.lift(lift).lobbies[lv]
                legs.append(Leg(lv, legs_planner.plan_to_landmark(sm.maps[lv], at, lobby)))
            prev = (lv, lift)
        legs.append(Leg(here, search.last_leg(prev[1], at, self.max_gap)))
        return SitePlan(site.name, tuple(legs), tuple(rides), goal_level, goal_id, goal_name, cost)


class _LobbySearch:
    """The cheapest way from a start to a goal room on another level, over the lifts'
    lobbies: a small graph whose nodes are the start, each (level, lift) lobby and the
    goal. Its edges: the corridor metres from the start to each lobby of its level (one
    search from the start), a ride's cost between two lobbies of one lift, the metres
    between two lifts' lobbies on a level (cached on the site map), and the metres from
    each lobby of the goal's level to the goal (one search from the goal). The two
    searches grow together and stop once no lobby left can do better (``_search_both``);
    the first and last legs' routes are theirs, so each leg costs no search of its own."""

    def __init__(self, planner, sm, level, sp, goal_level, goal_id, constraints):
        self.planner, self.sm, self.level, self.sp = planner, sm, level, sp
        self.goal_level, self.goal_id, self.constraints = goal_level, goal_id, constraints
        pm = sm.maps[level]
        seg = sp.segment
        a_xy, b_xy = pm.node_xy(seg.a), pm.node_xy(seg.b)
        self.start_xy = a_xy + sp.t * (b_xy - a_xy)
        shut = shut_ends(pm, sp, constraints.blocked_at)
        sources = {}
        for end, lead in ((seg.a, sp.t * seg.length), (seg.b, (1.0 - sp.t) * seg.length)):
            if end in shut:
                continue
            # On a tie, the way the robot already faces, else the segment's first end (as
            # shortest_route): the legs' routes are the graph planner's.
            tie = 0.0 if end == seg.a else 1e-12
            if sp.heading is not None:
                toward = heading(self.start_xy, pm.node_xy(end)) if lead > 1e-9 else sp.heading
                tie += abs(wrap_angle(toward - sp.heading)) * 1e-9
            sources[end] = (lead + tie, lead)
        site = sm.site
        goal_pm = sm.maps[goal_level]
        self.goal_node = goal_pm.places[goal_id].node
        at_start = {lift.id: sm.lobby_nodes[(lift.id, level)] for lift in site.lifts_at(level)}
        at_goal = {
            lift.id: sm.lobby_nodes[(lift.id, goal_level)] for lift in site.lifts_at(goal_level)
        }
        self.from_start = _Search(pm, sources, set(at_start.values()), constraints.blocked_segments)
        self.to_goal = _Search(goal_pm, {self.goal_node: (0.0, 0.0)}, set(at_goal.values()))
        self._search_both(at_start, at_goal)

    def _search_both(self, at_start: dict[str, str], at_goal: dict[str, str]) -> None:
        """Grow the start's and the goal's searches together, the nearer frontier first,
        until no lobby either has not reached can lead to a cheaper way than one known.
        A way by a lift serving both levels costs its two walks and its ride; any other
        changes lifts, so rides twice at least. A lobby not reached is at least as far
        as its search's frontier."""
        s, g = self.from_start, self.to_goal
        direct = [k for k in at_start if k in at_goal]
        ride = self.planner.ride_cost(self.sm.site, self.level, self.goal_level)
        two_calls = 2.0 * self.planner.ride_call_m
        known, pops = INF, 0
        while s.frontier < INF or g.frontier < INF:
            search = s if s.frontier <= g.frontier else g
            if search.step() is not None:
                for k in direct:
                    a, b = s.dist.get(at_start[k]), g.dist.get(at_goal[k])
                    if a is not None and b is not None:
                        known = min(known, a + ride + b)
            pops += 1
            if known == INF or pops % 8:
                continue
            bound = two_calls + min(map(s.value, at_start.values())) + min(
                map(g.value, at_goal.values())
            )
            for k in direct:
                a, b = at_start[k], at_goal[k]
                if a not in s.dist or b not in g.dist:
                    bound = min(bound, s.value(a) + ride + g.value(b))
            if bound >= known:
                return

    def _neighbours(self, node: tuple[str, str]):
        sm, site, level = self.sm, self.sm.site, self.level
        if node == _START:
            for lift in site.lifts_at(level):
                d = self.from_start.dist.get(sm.lobby_nodes[(lift.id, level)])
                if d is not None:
                    yield (level, lift.id), d
            return
        lv, lift_id = node
        for other in site.lift(lift_id).lobbies:
            if other != lv:
                yield (other, lift_id), self.planner.ride_cost(site, lv, other)
        if lv == self.goal_level:
            d = self.to_goal.dist.get(sm.lobby_nodes[(lift_id, lv)])
            if d is not None:
                yield _GOAL, d
        for other in site.lifts_at(lv):
            if other.id != lift_id:
                d = _lobby_distance(sm, lv, lift_id, other.id)
                if d is not None:
                    yield (lv, other.id), d

    def route(self) -> tuple[list[tuple[str, str]], float]:
        """The (level, lift) lobbies passed, in order, and the total cost."""
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
            for nxt, step in self._neighbours(node):
                c = cost + step
                if c < best.get(nxt, float("inf")):
                    best[nxt] = c
                    came[nxt] = node
                    heapq.heappush(heap, (c, next(tie), nxt))
        site, level = self.sm.site, self.level
        served = ", ".join(lift.id for lift in site.lifts_at(level))
        why = (
            f"no lift leaves {level}"
            if not served
            else f"no lift ({served}) reached from there leads to {self.goal_level}"
        )
        raise PlanningError(
            f"{self.goal_id} on {self.goal_level} cannot be reached from "
            f"{self.sp.description} on {level}: {why}"
        )

    def first_leg(self, lift: str, max_gap: float) -> Plan:
        """The walk from the start to ``lift``'s lobby on the start level."""
        sm, level = self.sm, self.level
        node = sm.lobby_nodes[(lift, level)]
        nodes = self.from_start.path(node)[::-1]
        length = self.from_start.length[node]
        lobby = sm.site.lift(lift).lobbies[level]
        return build_plan(
            sm.maps[level], self.sp, lobby, nodes, length, self.start_xy, max_gap, "graph",
            self.constraints.avoid_landmarks,
        )

    def last_leg(self, lift: str, at: StartPoint, max_gap: float) -> Plan:
        """The walk out of ``lift`` on the goal level to the goal room."""
        sm, level = self.sm, self.goal_level
        pm = sm.maps[level]
        node = sm.lobby_nodes[(lift, level)]
        nodes = self.to_goal.path(node)
        seg = at.segment
        a_xy, b_xy = pm.node_xy(seg.a), pm.node_xy(seg.b)
        start_xy = a_xy + at.t * (b_xy - a_xy)
        length = self.to_goal.length[node]
        return build_plan(pm, at, self.goal_id, nodes, length, start_xy, max_gap, "graph")


class _Search:
    """Dijkstra on a level's map from several sources, each with a starting (cost, metres),
    over corridor lengths, never over a segment of ``blocked``, one node at a time
    (``step``), towards ``targets``. ``dist``: the cost of each node settled; ``length``:
    its metres; ``pred``: the node it was reached from (None at a source)."""

    def __init__(
        self,
        pm: PrioriMap,
        sources: dict[str, tuple[float, float]],
        targets: set[str],
        blocked: frozenset[int] = frozenset(),
    ):
        self.heap = [(c, n) for n, (c, _) in sources.items()]
        heapq.heapify(self.heap)
        self.best = {n: c for n, (c, _) in sources.items()}
        self.length = {n: m for n, (_, m) in sources.items()}
        self.pred: dict[str, str | None] = dict.fromkeys(sources)
        self.dist: dict[str, float] = {}
        self.left = set(targets)
        self.adj = _adjacency(pm)
        self.blocked = blocked

    @property
    def frontier(self) -> float:
        """The least cost not yet settled (infinite once every target is settled)."""
        return self.heap[0][0] if self.heap and self.left else INF

    def value(self, node: str) -> float:
        """A settled node's cost, else the frontier: as little as it can cost."""
        return self.dist.get(node, self.frontier)

    def step(self) -> str | None:
        """Settle the nearest node not settled; return it when it is a target."""
        heap, dist, best = self.heap, self.dist, self.best
        while heap:
            c, n = heapq.heappop(heap)
            if n in dist:
                continue
            dist[n] = c
            for m, length, segment in self.adj[n]:
                nc = c + length
                if nc < best.get(m, INF) and m not in dist and segment not in self.blocked:
                    best[m] = nc
                    self.length[m] = self.length[n] + length
                    self.pred[m] = n
                    heapq.heappush(heap, (nc, m))
            if n in self.left:
                self.left.discard(n)
                return n
            return None
        return None

    def path(self, node: str) -> list[str]:
        """The nodes from ``node`` back to the source it was reached from."""
        out = [node]
        while self.pred[out[-1]] is not None:
            out.append(self.pred[out[-1]])
        return out


INF = float("inf")


def _adjacency(pm: PrioriMap) -> dict[str, list[tuple[str, float, int]]]:
    """Each node's (neighbour, metres, segment index), as plain lists (cached on the map):
    a search over these is several times quicker than over the graph's views."""
    cached = pm.__dict__.get("_site_adjacency")
    if cached is None:
        cached = {
            n: [(m, e["length"], e["segment"]) for m, e in nbrs.items()]
            for n, nbrs in pm.graph.adj.items()
        }
        pm.__dict__["_site_adjacency"] = cached
    return cached


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


def out_of_lift(sm: SiteMap, lift: str, level: str) -> StartPoint:
    """Where a leg starts after a ride: the lift's lobby on ``level``, facing out of the
    lift (from the doors towards the corridor's centre line)."""
    pm = sm.maps[level]
    lobby = sm.site.lift(lift).lobbies[level]
    sp = resolve_start(pm, lobby)
    doors = pm.building.landmark(lobby).pos
    node = pm.node_xy(pm.places[lobby].node)
    facing = heading(doors, node) if abs(node - doors).sum() > 1e-6 else None
    return replace(sp, description=f"{lobby} (out of {lift})", heading=facing)
