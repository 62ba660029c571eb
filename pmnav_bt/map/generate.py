"""Seeded generator of functional buildings of any size (for benchmarks, tests and sims).

Corridors follow a square grid of junctions: a random spanning tree of the grid,
plus extra corridors that close loops. Straight runs through degree-2 junctions are
merged into one corridor, so every waypoint kind obeys the file's degree rules.
Rooms line both walls at a fixed spacing, numbered in order, all behind identical
doors; a few elevators and stairs are spread over the floor.
"""

from __future__ import annotations

import math
import random

import networkx as nx

from pmnav_bt.map.building import SCHEMA_VERSION, Building, building_from_data
from pmnav_bt.map.floorplan import DOOR_WIDTH_M
from pmnav_bt.map.landmark_kinds import landmark_shape

ROOM_PITCH = 3.0  # metres between door centres along a corridor (alternating walls)
JUNCTION_CLEARANCE = 2.5  # no door closer than this to a junction
# A lift or stairs is slid along its wall in these steps until no door hangs through it;
# a door takes its leaf and a frame each side (pmnav_bt/map/wall_items.DOOR_SPAN_M).
LANDMARK_SLIDE_M = 0.25
LANDMARK_CORNER_M = 0.5  # the wall left between the corner and a lift's (or stairs') end
DOOR_CLEARANCE_M = DOOR_WIDTH_M / 2.0 + 0.1


def _landmark_spot(
    g: nx.Graph, pos: dict, junction, corridor_width: float, span: float, rooms: list[dict]
) -> list[float]:
    """Where a lift or stairs ``span`` wide goes at ``junction``: on the right-hand wall of
    a corridor leaving it (the one going +y where there is one), its end just past the
    corner (it hangs where its point is: past the corner it would stick out), slid
    along that wall away from the junction until no door hangs through it."""
    x, y = pos[junction]
    ways = sorted(
        (pos[m][0] - x, pos[m][1] - y) for m in g.neighbors(junction)
    )
    dx, dy = next(((a, b) for a, b in ways if b > 0 and a == 0), ways[0])
    length = math.hypot(dx, dy)
    ux, uy = dx / length, dy / length
    wall = (x + uy * corridor_width / 2.0, y - ux * corridor_width / 2.0)
    reach = span / 2.0 + DOOR_CLEARANCE_M
    # doors on that wall, by their distance along it from the junction
    along = [
        (r["door"][0] - wall[0]) * ux + (r["door"][1] - wall[1]) * uy
        for r in rooms
        if abs((r["door"][0] - wall[0]) * uy - (r["door"][1] - wall[1]) * ux) < 1e-6
    ]
    s = corridor_width / 2.0 + span / 2.0 + LANDMARK_CORNER_M  # clear of the corner
    while any(abs(d - s) < reach for d in along):
        s += LANDMARK_SLIDE_M
    return [round(wall[0] + ux * s, 3), round(wall[1] + uy * s, 3)]


def generate_building(
    n_rooms: int,
    seed: int = 0,
    spacing: float = 24.0,
    loop_fraction: float = 0.15,
    corridor_width: float = 2.4,
    name: str | None = None,
    doors_per_corridor: int | None = None,
    bare_fraction: float = 0.0,
    n_landmarks: int = 4,
    min_side: int = 2,
    wing_signs: bool = False,
) -> Building:
    """A valid building with exactly ``n_rooms`` rooms; the same seed gives the same building.

    ``doors_per_corridor`` caps the doors on one corridor (placed from its first end, so
    the rest of it stays bare); ``bare_fraction`` of the corridors get no door at all (the
    sign-sparse family); ``n_landmarks`` elevators and stairs are spread over junctions;
    ``min_side`` junctions per side of the grid at least; ``wing_signs``: signs numbered
    per corridor with a wing letter ("A101", "B101", ...), near-identical across wings.
    """
    if n_rooms < 1:
        raise ValueError("n_rooms must be at least 1")
    rng = random.Random(seed)
    per_edge = max(1, int((spacing - 2 * JUNCTION_CLEARANCE) / ROOM_PITCH) + 1)
    # Grid big enough that a spanning tree (n-1 edges) holds all rooms.
    side = max(2, min_side)
    while side * side - 1 < math.ceil(n_rooms / per_edge) + 1:
        side += 1
    grid = nx.grid_2d_graph(side, side)
    for u, v in grid.edges:
        grid.edges[u, v]["w"] = rng.random()
    tree = nx.minimum_spanning_tree(grid, weight="w")
    extra = [e for e in grid.edges if not tree.has_edge(*e)]
    rng.shuffle(extra)
    tree.add_edges_from(extra[: int(loop_fraction * len(extra))])
    g = _merge_straight_runs(tree)

    # A start spur off a corner when no dead end exists (every node in a loop).
    ends = sorted(n for n in g if g.degree(n) == 1)
    pos = {n: (n[0] * spacing, n[1] * spacing) for n in g}
    if not ends:
        corner = min(g)
        spur = ("spur",)
        g.add_edge(corner, spur)
        pos[spur] = (pos[corner][0] - spacing / 2, pos[corner][1])
        ends = [spur]

    ids: dict = {}
    counters = {"start": 0, "turn": 0, "branch": 0, "end": 0}
    start_node = ends[rng.randrange(len(ends))]
    waypoints = []
    for n in sorted(g, key=str):
        deg = g.degree(n)
        kind = (
            "start" if n == start_node else "end" if deg == 1 else "turn" if deg == 2 else "branch"
        )
        counters[kind] += 1
        ids[n] = kind if kind == "start" else f"{kind}{counters[kind]}"
        waypoints.append({"id": ids[n], "kind": kind, "pos": list(pos[n])})

    edges, rooms = [], []
    corridors = sorted(g.edges, key=lambda e: (str(e[0]), str(e[1])))
    n_bare = int(bare_fraction * len(corridors))
    bare = set(rng.sample(range(len(corridors)), n_bare)) if n_bare else set()
    for ci, (u, v) in enumerate(corridors):
        edges.append([ids[u], ids[v]])
        if len(rooms) >= n_rooms or ci in bare:
            continue
        placed = 0
        (x0, y0), (x1, y1) = pos[u], pos[v]
        length = math.hypot(x1 - x0, y1 - y0)
        ux, uy = (x1 - x0) / length, (y1 - y0) / length
        s = JUNCTION_CLEARANCE
        side_sign = 1.0
        while s <= length - JUNCTION_CLEARANCE and len(rooms) < n_rooms:
            if doors_per_corridor is not None and placed >= doors_per_corridor:
                break
            placed += 1
            k = len(rooms) + 1
            off = side_sign * corridor_width / 2.0
            door = [round(x0 + ux * s - uy * off, 3), round(y0 + uy * s + ux * off, 3)]
            sign = f"{chr(ord('A') + ci % 26)}{100 + placed}" if wing_signs else str(100 + k)
            rooms.append({"id": f"room{k}", "name": f"Room {k}", "door": door, "sign": sign})
            s += ROOM_PITCH
            side_sign = -side_sign
    if len(rooms) < n_rooms and doors_per_corridor is None and not bare:
        # cannot happen with the sizing above; keep it loud if it does
        raise RuntimeError(f"generator placed {len(rooms)} of {n_rooms} rooms")

    landmarks = []
    junctions = [n for n in sorted(g, key=str) if g.degree(n) >= 2]
    for i, n in enumerate(junctions[:: max(1, len(junctions) // 4)][:n_landmarks]):
        kind = ("elevator", "stairs")[i % 2]
        landmarks.append(
            {
                "id": f"{kind}{i + 1}",
                "kind": kind,
                "name": f"{kind.title()} {i + 1}",
                "pos": _landmark_spot(
                    g, pos, n, corridor_width, landmark_shape(kind).span_m, rooms
                ),
            }
        )
    data = {
        "schema_version": SCHEMA_VERSION,
        "name": name or f"generated_{n_rooms}_{seed}",
        "kind": "office",
        "description": f"Generated: {n_rooms} rooms, seed {seed}.",
        "corridor_width": corridor_width,
        "waypoints": waypoints,
        "edges": edges,
        "rooms": rooms,
        "landmarks": landmarks,
    }
    return building_from_data(data, source=data["name"])


SIGN_SPARSE_FAMILY = "sign_sparse"


def generate_sign_sparse(seed: int = 0) -> Building:
    """The sign-sparse family (issue 15, paper Table 3): 30 m grid corridors, about 40 %
    of them without a single door, at most three doors on the others (all near one end),
    one elevator, and wing-numbered near-identical signs (A101, B101, ...)."""
    return generate_building(
        n_rooms=14,
        seed=seed,
        spacing=30.0,
        loop_fraction=0.2,
        name=f"{SIGN_SPARSE_FAMILY}_{seed}",
        doors_per_corridor=3,
        bare_fraction=0.4,
        n_landmarks=1,
        min_side=3,
        wing_signs=True,
    )


SMALL_FAMILY = "gen_small"


def generate_small(seed: int = 0) -> Building:
    """The small generated family (the scale test's buildings): a 2x2 junction grid of
    16 m corridors (a tree, no loops), ten rooms and two landmarks: cheap to simulate,
    yet with turns and forks."""
    return generate_building(
        n_rooms=10,
        seed=seed,
        spacing=16.0,
        loop_fraction=0.0,
        name=f"{SMALL_FAMILY}_{seed}",
        n_landmarks=2,
    )


def _merge_straight_runs(g: nx.Graph) -> nx.Graph:
    """Collapse degree-2 grid nodes whose two corridors are collinear into one corridor."""
    g = nx.Graph(g)
    changed = True
    while changed:
        changed = False
        for n in list(g):
            if g.degree(n) != 2:
                continue
            a, b = list(g.neighbors(n))
            if (a[0] == n[0] == b[0]) or (a[1] == n[1] == b[1]):
                g.remove_node(n)
                g.add_edge(a, b)
                changed = True
    return g
