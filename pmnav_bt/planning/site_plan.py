"""Planning across levels: legs on each level, joined by lift rides.

A goal on another level is reached as a person reaches it: walk to a lift's lobby, ride
to the goal's level, walk from that lift's lobby to the room. The planner chooses the
lifts by total cost, in metres of corridor: the metres to the lobby on the start level,
a ride's cost (a call, once per ride, and a cost per level travelled), and the metres
from the lobby on the goal level (with, where no lift serves both levels, the metres
between two lifts' lobbies on a level in between). It searches over the lobbies (A* on
a small graph: the start, each lift's lobby on each level, the goal), whose edges are
read off the shortest-way trees the site map keeps for each lobby (``SiteMap.lobby_tree``,
one corridor search per lobby, once per site map): a plan makes no corridor search of its
own, unless blocked corridors on the start level call for one there. What a plan costs
is mostly turning its legs' routes into steps (``build_plan``), one leg per level walked.

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
from typing import NamedTuple

import numpy as np

from pmnav_bt.errors import PlanningError
from pmnav_bt.geometry import heading, wrap_angle
from pmnav_bt.lift_timing import BED_LIFT
from pmnav_bt.map.corridor_search import INF, CorridorSearch, LobbyTree
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.map.site import Site
from pmnav_bt.map.site_map import SiteMap
from pmnav_bt.planning.graph_planner import GraphPlanner, build_plan, shut_ends
from pmnav_bt.planning.plan import MAX_GAP_M, Plan
from pmnav_bt.planning.resolve import StartPoint, resolve_site_room, resolve_start
from pmnav_bt.seams import CREATE3_MAX_LINEAR, PlanConstraints
from pmnav_bt.seams import PlanStart as SeamStart

# The ride's cost in corridor metres: what the robot's time in the lift is worth at its
# driving speed, from the lift's timing model (pmnav_bt/lift_timing.py, a hospital bed
# lift). A call costs the mean wait for the cabin (half the longest), its door opening and
# shutting at both ends, and driving in, turning round and out (about 13 s): 45 s; travel
# 8 s a level. At the Create 3's 0.306 m/s that is 13.8 m a call and 2.4 m a level: a
# lift 14 m nearer is worth a change of lifts.
DRIVE_M_PER_S = CREATE3_MAX_LINEAR
CABIN_IN_OUT_S = 13.0
LIFT_CALL_S = BED_LIFT.call_delay_s / 2.0 + 4.0 * BED_LIFT.door_s + CABIN_IN_OUT_S
LIFT_LEVEL_S = BED_LIFT.ride_s_per_level
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
                legs.append(Leg(lv, search.between_leg(lv, at, lift, self.max_gap)))
            prev = (lv, lift)
        legs.append(Leg(here, search.last_leg(prev[1], at, self.max_gap)))
        return SitePlan(site.name, tuple(legs), tuple(rides), goal_level, goal_id, goal_name, cost)


class _Walk(NamedTuple):
    """A walk along one level's corridors: its cost (metres with a hair of tie-break),
    its metres and its nodes, from the first to the last."""

    cost: float
    metres: float
    nodes: list[str]


class _LobbySearch:
    """The cheapest way from a start to a goal room on another level, over the lifts'
    lobbies: a small graph whose nodes are the start, each (level, lift) lobby and the
    goal. Its edges are read off the site map's lobby trees (``SiteMap.lobby_tree``: one
    search of a level from each lobby, kept for every plan): the corridor metres from the
    start to each lobby of its level, a ride's cost between two lobbies of one lift, the
    metres between two lifts' lobbies on a level, and the metres from each lobby of the
    goal's level to the goal. So a plan searches no corridor, except where ``constraints``
    block segments of the start level, which the trees do not know of: then one search
    from the start to that level's lobbies. The legs' routes are read off the same trees
    (or that search), so no leg costs a search of its own either."""

    def __init__(self, planner, sm, level, sp, goal_level, goal_id, constraints):
        self.planner, self.sm, self.level, self.sp = planner, sm, level, sp
        self.goal_level, self.goal_id, self.constraints = goal_level, goal_id, constraints
        pm = sm.maps[level]
        self.start_xy = _point(pm, sp)
        sources = _sources(pm, sp, self.start_xy, shut_ends(pm, sp, constraints.blocked_at))
        self.goal_node = sm.maps[goal_level].places[goal_id].node
        lobbies = {lift.id: sm.lobby_nodes[(lift.id, level)] for lift in sm.site.lifts_at(level)}
        self.walks: dict[str, _Walk] = {}  # lift id -> the walk to its lobby on the start level
        if constraints.blocked_segments:
            search = CorridorSearch(pm, sources, constraints.blocked_segments)
            search.run(set(lobbies.values()))
            for lift, node in lobbies.items():
                if node in search.dist:
                    way = search.path(node)[::-1]
                    self.walks[lift] = _Walk(search.dist[node], search.length[node], way)
        else:
            for lift in lobbies:
                walk = _walk_to_lobby(sm.lobby_tree(lift, level), sources)
                if walk is not None:
                    self.walks[lift] = walk

    def _neighbours(self, node: tuple[str, str]):
        sm, site, level = self.sm, self.sm.site, self.level
        if node == _START:
            for lift, walk in self.walks.items():
                yield (level, lift), walk.cost
            return
        lv, lift_id = node
        for other in site.lift(lift_id).lobbies:
            if other != lv:
                yield (other, lift_id), self.planner.ride_cost(site, lv, other)
        if lv == self.goal_level:
            d = sm.lobby_tree(lift_id, lv).dist.get(self.goal_node)
            if d is not None:
                yield _GOAL, d
        if lv in (level, self.goal_level):
            return  # a change of lifts here never beats walking to the other lobby at once
        here = sm.lobby_nodes[(lift_id, lv)]
        for other in site.lifts_at(lv):
            if other.id != lift_id:
                d = sm.lobby_tree(other.id, lv).dist.get(here)
                if d is not None:
                    yield (lv, other.id), d

    def route(self) -> tuple[list[tuple[str, str]], float]:
        """The (level, lift) lobbies passed, in order, and the total cost: A* over the
        lobby graph, each lobby ranked by its cost so far and the least it can still cost
        (``_still``), so lobbies that cannot beat the way found are never expanded."""
        best = {_START: 0.0}
        came: dict[tuple[str, str], tuple[str, str]] = {}
        tie = count()
        heap = [(0.0, next(tie), 0.0, _START)]
        done = set()
        still = self._still()
        while heap:
            _, _, cost, node = heapq.heappop(heap)
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
                if c < best.get(nxt, INF):
                    best[nxt] = c
                    came[nxt] = node
                    heapq.heappush(heap, (c + still(nxt), next(tie), c, nxt))
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

    def _still(self):
        """The least a lobby can still cost to the goal: on a level other than the goal's,
        a ride there; and from a lobby of the goal's level, the walk from the nearest one
        to the goal. It never overstates, and falls by no more than an edge's cost along
        one, so A* expands each lobby once and finds the cheapest way."""
        sm, goal_level = self.sm, self.goal_level
        walks = [
            sm.lobby_tree(lift.id, goal_level).dist.get(self.goal_node, INF)
            for lift in sm.site.lifts_at(goal_level)
        ]
        last = min(walks, default=INF)
        ride = self.planner.ride_cost

        def still(node: tuple[str, str]) -> float:
            if node == _GOAL:
                return 0.0
            lv = node[0]
            return last if lv == goal_level else ride(sm.site, lv, goal_level) + last

        return still

    def first_leg(self, lift: str, max_gap: float) -> Plan:
        """The walk from the start to ``lift``'s lobby on the start level."""
        sm, level, walk = self.sm, self.level, self.walks[lift]
        lobby = sm.site.lift(lift).lobbies[level]
        return build_plan(
            sm.maps[level], self.sp, lobby, walk.nodes, walk.metres, self.start_xy, max_gap,
            "graph", self.constraints.avoid_landmarks,
        )

    def between_leg(self, level: str, at: StartPoint, lift: str, max_gap: float) -> Plan:
        """The walk on a level between two rides: from ``at`` (out of one lift) to
        ``lift``'s lobby, the change of lifts."""
        sm, pm = self.sm, self.sm.maps[level]
        xy = _point(pm, at)
        walk = _walk_to_lobby(sm.lobby_tree(lift, level), _sources(pm, at, xy, set()))
        lobby = sm.site.lift(lift).lobbies[level]
        return build_plan(pm, at, lobby, walk.nodes, walk.metres, xy, max_gap, "graph")

    def last_leg(self, lift: str, at: StartPoint, max_gap: float) -> Plan:
        """The walk out of ``lift`` on the goal level to the goal room."""
        level = self.goal_level
        pm, tree = self.sm.maps[level], self.sm.lobby_tree(lift, level)
        nodes = tree.way(self.goal_node)[::-1]
        metres = tree.dist[self.goal_node]
        return build_plan(pm, at, self.goal_id, nodes, metres, _point(pm, at), max_gap, "graph")


def _point(pm: PrioriMap, sp: StartPoint) -> np.ndarray:
    """Where a start point is on the map."""
    a_xy, b_xy = pm.node_xy(sp.segment.a), pm.node_xy(sp.segment.b)
    return a_xy + sp.t * (b_xy - a_xy)


def _sources(
    pm: PrioriMap, sp: StartPoint, start_xy: np.ndarray, shut: set[str]
) -> dict[str, tuple[float, float]]:
    """The ends of the start's segment a walk can leave by (not those ``shut``), each with
    its (cost, metres) from the start. On a tie, the way the robot already faces, else the
    segment's first end (as ``shortest_route``): the legs' routes are the graph planner's."""
    seg, sources = sp.segment, {}
    for end, lead in ((seg.a, sp.t * seg.length), (seg.b, (1.0 - sp.t) * seg.length)):
        if end in shut:
            continue
        tie = 0.0 if end == seg.a else 1e-12
        if sp.heading is not None:
            toward = heading(start_xy, pm.node_xy(end)) if lead > 1e-9 else sp.heading
            tie += abs(wrap_angle(toward - sp.heading)) * 1e-9
        sources[end] = (lead + tie, lead)
    return sources


def _walk_to_lobby(tree: LobbyTree, sources: dict[str, tuple[float, float]]) -> _Walk | None:
    """The cheapest walk from one of ``sources`` to the tree's lobby (None: none reaches it)."""
    best = None
    for end, (cost, metres) in sources.items():
        d = tree.dist.get(end)
        if d is not None and (best is None or cost + d < best[0]):
            best = (cost + d, metres + d, end)
    if best is None:
        return None
    return _Walk(best[0], best[1], tree.way(best[2]))


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
