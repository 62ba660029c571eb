"""Property tests on random buildings: every plan is a valid corridor walk to the target,
and no shorter walk exists (checked against an independent shortest-path computation)."""

from __future__ import annotations

import math
from itertools import pairwise

import networkx as nx
import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pmnav_bt.map.building import Building, building_from_data
from pmnav_bt.map.generate import generate_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.planning.graph_planner import GraphPlanner

EPS = 1e-6


@st.composite
def buildings(draw) -> Building:
    """A generated corridor network with rooms drawn anywhere along its corridors."""
    topo = generate_building(
        draw(st.integers(1, 60)),
        seed=draw(st.integers(0, 10_000)),
        spacing=draw(st.floats(8.0, 30.0)),
        loop_fraction=draw(st.floats(0.0, 0.7)),
    )
    data = topo.to_dict()
    wps = {w.id: w.pos for w in topo.waypoints}
    rooms = []
    for k in range(draw(st.integers(1, 25))):
        e = topo.edges[draw(st.integers(0, len(topo.edges) - 1))]
        t = draw(st.floats(0.0, 1.0))
        side = draw(st.sampled_from([-1.0, 1.0]))
        (x0, y0), (x1, y1) = wps[e.a], wps[e.b]
        L = math.hypot(x1 - x0, y1 - y0)
        nx_, ny_ = -(y1 - y0) / L, (x1 - x0) / L
        off = side * topo.corridor_width / 2
        rooms.append(
            {
                "id": f"room{k + 1}",
                "door": [x0 + t * (x1 - x0) + off * nx_, y0 + t * (y1 - y0) + off * ny_],
            }
        )
    data["rooms"] = rooms
    data["landmarks"] = []
    return building_from_data(data)


def on_corridor(b: Building, p, q) -> bool:
    """True when the straight move p->q lies along one corridor of the building file."""
    for e in b.edges:
        a, c = np.array(b.waypoint(e.a).pos), np.array(b.waypoint(e.b).pos)
        d = c - a
        for r in (np.asarray(p), np.asarray(q)):
            t = np.clip(np.dot(r - a, d) / np.dot(d, d), 0, 1)
            if np.linalg.norm(a + t * d - r) > 1e-6:
                break
        else:
            return True
    return False


def independent_distance(b: Building, start_xy, goal_xy) -> float:
    """Shortest corridor distance between two points on corridors, from the building file alone."""
    g = nx.Graph()
    extra = {"S": np.asarray(start_xy), "G": np.asarray(goal_xy)}
    pos = {w.id: np.asarray(w.pos, dtype=float) for w in b.waypoints}
    for e in b.edges:
        a, c = pos[e.a], pos[e.b]
        d = c - a
        on = [(0.0, e.a), (1.0, e.b)]
        for name, r in extra.items():
            t = float(np.dot(r - a, d) / np.dot(d, d))
            if -EPS <= t <= 1 + EPS and np.linalg.norm(a + t * d - r) < 1e-6:
                on.append((t, name))
        on.sort()
        for (t0, u), (t1, v) in pairwise(on):
            w = (t1 - t0) * float(np.linalg.norm(d))
            if u != v and (not g.has_edge(u, v) or g.edges[u, v]["w"] > w):
                g.add_edge(u, v, w=w)
    if np.linalg.norm(extra["S"] - extra["G"]) < 1e-9:
        return 0.0
    return nx.shortest_path_length(g, "S", "G", weight="w")


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(b=buildings(), data=st.data())
def test_plans_are_shortest_valid_walks_to_the_target(b, data):
    pm = parse_building(b)
    goal = data.draw(st.sampled_from([r.id for r in b.rooms]))
    kind = data.draw(st.sampled_from(["segment", "pose", "waypoint"]))
    if kind == "segment":
        start = f"seg{data.draw(st.integers(1, len(pm.segments)))}"
    elif kind == "waypoint":
        start = data.draw(st.sampled_from([w.id for w in b.waypoints]))
    else:
        seg = pm.segments[data.draw(st.integers(0, len(pm.segments) - 1))]
        t = data.draw(st.floats(0, 1))
        a, c = pm.node_xy(seg.a), pm.node_xy(seg.b)
        x, y = a + t * (c - a)
        start = f"{x:.6f},{y:.6f},{data.draw(st.integers(-180, 180))}"
    plan = GraphPlanner().plan(pm, start, goal)

    # A valid walk: each move runs along one corridor of the building file.
    for p, q in pairwise(plan.path):
        assert on_corridor(b, p, q), (p, q)
    # It ends at the target's room waypoint (the door's projection on its corridor).
    assert plan.nodes[-1] == pm.places[goal].node
    assert plan.steps[-1].landmark == goal and plan.steps[-1].action.value == "arrive"
    # Its length is the length of the polyline, and no shorter walk exists.
    poly = sum(math.dist(p, q) for p, q in pairwise(plan.path))
    assert math.isclose(plan.length, poly, abs_tol=1e-6)
    best = independent_distance(b, plan.start.position, pm.nodes[plan.nodes[-1]].pos)
    assert math.isclose(plan.length, best, rel_tol=1e-9, abs_tol=1e-6), (plan.length, best)
    # Steps are in path order and their distances add up to the route.
    assert math.isclose(sum(s.distance for s in plan.steps), plan.length, abs_tol=1e-6)


@settings(max_examples=40, deadline=None)
@given(n=st.integers(1, 300), seed=st.integers(0, 2**31 - 1))
def test_generator_is_valid_sized_and_seeded(n, seed):
    b = generate_building(n, seed=seed)
    assert len(b.rooms) == n
    assert generate_building(n, seed=seed) == b
    assert nx.is_connected(b.corridor_graph())
