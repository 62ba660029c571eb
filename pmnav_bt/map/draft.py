"""Draft a building file from a ROS map_server occupancy grid.

The steps (each a function, so a person can look at every stage; run
``python -m pmnav_bt.map.draft GRID.yaml -o building.yaml --image steps.png``):

1. **Free space**: map_server's free cells, the largest connected part; specks closed
   and small islands (bins, desks) filled.
2. **Corridor space** (``corridor_space``): slivers narrower than a corridor (laser
   fans, scan noise) opened away, the space cut at doorways (short narrow places), and
   every piece that is long for its width kept, whatever its size: the main network
   and the parts apart from it. Holes up to ``pillar_m`` (pillars) are filled.
3. **Skeleton** of the corridor space (scikit-image), traced into a graph of pixel
   paths between junctions and ends; spurs shorter than the local half width plus
   ``spur_m`` are pruned and straight-through nodes merged. Dead ends that widen
   behind their mouth, or that branch off a corridor and are less than
   ``corridor_ratio`` times longer than wide (a room seen through a wide opening), go;
   so do dead ends walled on both sides (by cells the scanner saw, not space never
   seen) along less than ``wall_min`` of their length (laser fans through open doors,
   rooms seen through their doorways).
4. **Open areas**: skeleton stretches wider than ``open_width_m`` (a lobby, a hall)
   are cut out; each area becomes one waypoint at its most open point with a
   straight corridor to each of its exits, not a lattice round its pillars.
5. **Straight lines**: each path is split by Douglas-Peucker into straight pieces;
   every piece is fitted by total least squares, and every key waypoint moved to the
   least-squares crossing of its corridors' lines (so it sits on the centre lines).
6. **Parts joined**: a part apart from the rest (cut off at a doorway, a pinch or a
   hall) is joined to it by a straight corridor through free space from its nearest
   waypoint, up to ``link_max_m`` long; a part that cannot be joined is left out
   with a warning in the file and on the command line.
7. **Widths** from the distance transform along the middle of each corridor.
8. **Door candidates**: runs along each annotated corridor wall where the wall is
   open and free space lies behind it, as wide as a door; each is placed exactly on
   the annotated wall (half the corridor width from the centre line).

What a grid cannot tell (room names, sign texts, closed doors, which end is the
entrance) is left for the person and marked ``todo`` in the file's comments.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import cv2
import networkx as nx
import numpy as np

from pmnav_bt.errors import PmNavError
from pmnav_bt.geometry import Rect, project_points_to_segments
from pmnav_bt.map.building import (
    DOOR_REACH_SLACK,
    SCHEMA_VERSION,
    Building,
    building_from_data,
)
from pmnav_bt.map.corridor_space import SpaceParams, corridor_space
from pmnav_bt.map.corridor_walls import cut_unlined_loops, edge_share, edge_walled
from pmnav_bt.map.draft_links import free_along, hall_hubs, link_parts
from pmnav_bt.map.floorplan import FloorPlanImage, load_ros_map, save_ros_map
from pmnav_bt.map.grid import (
    centre_line_width,
    distance_map,
    free_mask,
    seen_mask,
    unseen_mask,
)

ROOM_SPUR_M = 8.0  # a dead end longer than this is a corridor, whatever lies at its end


class DraftError(PmNavError):
    """The grid holds no corridor network the draft can use."""


@dataclass(frozen=True)
class DraftParams:
    """Knobs of the extraction, in metres.

    The defaults were measured on four real maps (the hospital SLAM map, the Willow
    Garage office SLAM map, the CCIA university floor SLAM map and the RMF clinic
    drawing; ``benchmarks/bench_draft_coverage.py``): see docs/real-maps.md.
    """

    door_max_m: float = 1.6  # a wall opening wider than this is not a door
    door_min_m: float = 0.6  # narrower than this is noise, not a door
    behind_m: float = 0.4  # free space needed this far behind the wall for a door
    spur_m: float = 0.6  # prune spurs shorter than the local half width + this
    line_tol_m: float = 0.35  # Douglas-Peucker tolerance for straight pieces
    open_width_m: float = 6.0  # a stretch wider than this is an open area, not a corridor
    min_edge_m: float = 0.8  # merge key waypoints closer than this
    clean_m: float = 0.1  # close free-space holes smaller than this (laser speckle)
    clutter_m: float = 1.25  # fill obstacles no longer than this in free space (bins, desks)
    corridor_min_m: float = 1.0  # free space narrower than this is no corridor (laser fans)
    doorway_max_m: float = 1.6  # a short place this narrow is a doorway: the space is cut
    doorway_m: float = 1.2  # ... if it is no longer than this (longer: a narrow corridor)
    # A piece, or a dead end branching off a corridor, is a corridor when this many times
    # longer than wide (else a room); 3.0 is the best on both annotated maps (2.5 and 3.5
    # drafted more spurious corridors, or lost coverage: docs/real-maps.md).
    corridor_ratio: float = 3.0
    part_min_m: float = 4.0  # a corridor-shaped piece shorter than this is left out
    link_max_m: float = 6.0  # join a part apart by a straight corridor up to this long
    pillar_m: float = 2.0  # a hole in the corridor space this small is run past, not round
    room_widening: float = 1.5  # a dead end this many times wider behind its mouth is a room
    # A dead end walled on both sides (by what the scanner saw) along less than this share
    # of its length is a laser fan or a room seen through its doorway: a corridor has
    # walls along most of it (corridor_walls.walled_share).
    wall_min: float = 0.5
    # A corridor on a loop, or a dead end, with less of its sides lined by walls parallel
    # to it is a way through a room or a fan, not a corridor (corridor_walls.py).
    lined_min: float = 0.5

    def space(self) -> SpaceParams:
        return SpaceParams(
            corridor_min_m=self.corridor_min_m,
            doorway_max_m=self.doorway_max_m,
            doorway_m=self.doorway_m,
            corridor_ratio=self.corridor_ratio,
            part_min_m=self.part_min_m,
        )


@dataclass
class Draft:
    """The result: plain building data plus what the person must look at."""

    waypoints: list[dict]
    edges: list[dict]
    rooms: list[dict]
    open_areas: list[Rect] = field(default_factory=list)  # free areas too wide for a corridor
    warnings: list[str] = field(default_factory=list)  # what was left out, and why
    # Stages, for pictures (pixel masks and the skeleton graph).
    free: np.ndarray | None = None
    corridor: np.ndarray | None = None
    skeleton: np.ndarray | None = None

    def building_data(self, name: str, ros_map: str, kind: str = "building") -> dict:
        widths = [e["width"] for e in self.edges]
        return {
            "schema_version": SCHEMA_VERSION,
            "name": name,
            "kind": kind,
            "description": "Drafted from an occupancy grid by 'pmnav map draft'.",
            "corridor_width": round(float(np.median(widths)), 2) if widths else 2.4,
            "floor_plan": {"ros_map": ros_map},
            "waypoints": self.waypoints,
            "edges": self.edges,
            "rooms": self.rooms,
        }


# -- skeleton graph ---------------------------------------------------------------------


def skeleton_graph(skel: np.ndarray) -> nx.MultiGraph:
    """Junctions and ends of a one-pixel skeleton as nodes; edges carry their pixel ``path``.

    Node positions (``rc``) are (row, col) floats; a node of several touching junction
    pixels is their mean.
    """
    rows, cols = np.nonzero(skel)
    pix = set(zip(rows.tolist(), cols.tolist(), strict=True))
    nbrs: dict[tuple[int, int], list[tuple[int, int]]] = {}
    for r, c in pix:
        ortho = [(r + dr, c + dc) for dr, dc in ((-1, 0), (1, 0), (0, -1), (0, 1))]
        ortho = [q for q in ortho if q in pix]
        out = list(ortho)
        for dr, dc in ((-1, -1), (-1, 1), (1, -1), (1, 1)):
            q = (r + dr, c + dc)
            # A diagonal step is redundant when an orthogonal pixel already links the two.
            if q in pix and (r + dr, c) not in pix and (r, c + dc) not in pix:
                out.append(q)
        nbrs[(r, c)] = out
    is_node = {p for p, n in nbrs.items() if len(n) != 2}
    # Cluster touching node pixels into one node.
    node_of: dict[tuple[int, int], int] = {}
    g = nx.MultiGraph()
    for p in is_node:
        if p in node_of:
            continue
        k = g.number_of_nodes()
        stack, members = [p], []
        node_of[p] = k
        while stack:
            q = stack.pop()
            members.append(q)
            for s in nbrs[q]:
                if s in is_node and s not in node_of:
                    node_of[s] = k
                    stack.append(s)
        g.add_node(k, rc=np.mean(members, axis=0))
    seen: set[frozenset] = set()
    for p in is_node:
        for q in nbrs[p]:
            if q in is_node or frozenset((p, q)) in seen:
                continue
            path, prev, cur = [p, q], p, q
            seen.add(frozenset((p, q)))
            while cur not in is_node:
                nxt = [s for s in nbrs[cur] if s != prev]
                if not nxt:
                    break
                prev, cur = cur, nxt[0]
                seen.add(frozenset((prev, cur)))
                path.append(cur)
            if cur in is_node:
                g.add_edge(node_of[p], node_of[cur], path=np.array(path, float))
    # Direct node-to-node steps (adjacent clusters were merged, so none are left) and
    # closed loops with no node at all: cut each loop at its first pixel.
    left = {p for p in pix if p not in is_node} - {q for e in seen for q in e}
    while left:
        p = min(left)
        k = g.number_of_nodes()
        g.add_node(k, rc=np.array(p, float))
        path, prev, cur = [p], None, p
        while True:
            nxt = [s for s in nbrs[cur] if s != prev and s in left | {p}]
            if not nxt or (nxt[0] == p and len(path) > 2):
                path.append(p)
                break
            prev, cur = cur, nxt[0]
            path.append(cur)
            if cur == p:
                break
        left -= set(path)
        if len(path) > 3:
            g.add_edge(k, k, path=np.array(path, float))
    return g


def _path_len(path: np.ndarray) -> float:
    return float(np.linalg.norm(np.diff(path, axis=0), axis=1).sum())


def prune_and_merge(g: nx.MultiGraph, dist: np.ndarray, spur_px: float) -> nx.MultiGraph:
    """Remove short spurs (end to junction) and merge nodes that became pass-throughs."""
    changed = True
    while changed:
        changed = False
        for u, v, k, d in list(g.edges(keys=True, data=True)):
            if u == v or not g.has_edge(u, v, k):
                continue
            du, dv = g.degree(u), g.degree(v)
            if (du == 1) == (dv == 1):
                continue
            end, junction = (u, v) if du == 1 else (v, u)
            rc = g.nodes[junction]["rc"].round().astype(int)
            limit = dist[rc[0], rc[1]] + spur_px
            if _path_len(d["path"]) < limit:
                g.remove_edge(u, v, k)
                g.remove_node(end)
                changed = True
        for n in list(g.nodes):
            if g.degree(n) == 2 and g.number_of_edges(n, n) == 0:
                (a, b, ka, da), (c, e, kc, dc) = list(g.edges(n, keys=True, data=True))
                other1, other2 = (b if a == n else a), (e if c == n else c)
                p1 = _oriented(da["path"], g.nodes[n]["rc"], to_node=True)
                p2 = _oriented(dc["path"], g.nodes[n]["rc"], to_node=False)
                g.remove_node(n)
                g.add_edge(other1, other2, path=np.vstack([p1, p2[1:]]))
                changed = True
    g.remove_nodes_from([n for n in list(g.nodes) if g.degree(n) == 0])
    return g


def _oriented(path: np.ndarray, rc: np.ndarray, to_node: bool) -> np.ndarray:
    """The path running towards (or away from) the node at ``rc``."""
    ends_here = np.linalg.norm(path[-1] - rc) <= np.linalg.norm(path[0] - rc)
    if ends_here != to_node:
        path = path[::-1]
    return path


# -- open areas -------------------------------------------------------------------------


def fill_pillars(corridor: np.ndarray, pillar_px: float) -> np.ndarray:
    """The corridor space with its small holes (pillars, counters, bins) filled.

    A skeleton goes round a hole both ways: a lattice of short corridors round every
    pillar in a hall. Filled, the corridor runs past it; ``pmnav validate`` then names
    the obstacle on the centre line, and the robot goes round it where depth shows the
    floor beside it open.
    """
    n, lab, stats, _ = cv2.connectedComponentsWithStats((~corridor).astype(np.uint8), 4)
    h, w = corridor.shape
    x, y, bw, bh = (stats[:, i] for i in range(4))
    inside = (x > 0) & (y > 0) & (x + bw < w) & (y + bh < h)
    small = inside & (np.maximum(bw, bh) <= pillar_px)
    small[0] = False
    return corridor | small[lab]


def open_area_mask(corridor: np.ndarray, dist_px: np.ndarray, res: float, params: DraftParams):
    """Corridor-space pixels belonging to areas wider than ``open_width_m``.

    The centres of the wide places grown by half the width limit (a distance transform,
    not a dilation: a disc of a hundred pixels is slow) and kept inside the corridors.
    """
    core = (dist_px * 2.0 - 1.0) * res > params.open_width_m
    if not core.any():
        return np.zeros(corridor.shape, bool)
    r = params.open_width_m / 2.0 / res
    near = cv2.distanceTransform((~core).astype(np.uint8), cv2.DIST_L2, 5) <= r
    return near & corridor


def _boxes(mask: np.ndarray, plan: FloorPlanImage) -> list[Rect]:
    n, lab, stats, _ = cv2.connectedComponentsWithStats(mask.astype(np.uint8), connectivity=8)
    out = []
    for i in range(1, n):
        x, y, w, h = (int(v) for v in stats[i, :4])
        corners = plan.pixel_to_world([[x - 0.5, y - 0.5], [x + w - 0.5, y + h - 0.5]])
        lo, hi = corners.min(axis=0), corners.max(axis=0)
        out.append(Rect(*(round(float(v), 2) for v in (lo[0], lo[1], hi[0], hi[1]))))
    out.sort(key=lambda a: -(a.xmax - a.xmin) * (a.ymax - a.ymin))
    return out


# -- straight corridors -----------------------------------------------------------------


def _split_straight(g: nx.MultiGraph, tol_px: float) -> nx.Graph:
    """Each skeleton path cut into straight pieces (Douglas-Peucker); a simple graph."""
    from skimage.measure import approximate_polygon

    h = nx.Graph()
    for n, d in g.nodes(data=True):
        h.add_node(n, rc=d["rc"])
    nxt = max(g.nodes, default=-1) + 1
    for u, v, d in g.edges(data=True):
        path = _oriented(d["path"], g.nodes[u]["rc"], to_node=False)
        verts = approximate_polygon(path, tol_px)
        # Indices of the kept vertices along the path.
        idx = [int(np.argmin(np.linalg.norm(path - q, axis=1))) for q in verts]
        idx = sorted(set([0, *idx, len(path) - 1]))
        if u == v and len(idx) < 4:  # a loop needs at least three sides
            idx = sorted(set([0, len(path) // 3, 2 * len(path) // 3, len(path) - 1]))
        chain = [u]
        for i in idx[1:-1]:
            h.add_node(nxt, rc=path[i])
            chain.append(nxt)
            nxt += 1
        chain.append(v)
        for k, (a, b) in enumerate(zip(chain, chain[1:], strict=False)):
            piece = path[idx[k] : idx[k + 1] + 1]
            if a == b or h.has_edge(a, b):
                continue
            h.add_edge(a, b, path=piece)
    return h


def _merge_close(h: nx.Graph, dist: np.ndarray, min_px: float) -> nx.Graph:
    """Contract corridor pieces shorter than ``min_px`` or than the corridor is wide.

    A piece shorter than the corridors are wide (a chamfer at a corner, a kink at a junction) is
    no corridor a robot could follow; its two ends become one waypoint.
    """

    def width_px(n) -> float:
        r, c = np.clip(h.nodes[n]["rc"].round().astype(int), 0, np.array(dist.shape) - 1)
        return 2.0 * float(dist[r, c])

    changed = True
    while changed:
        changed = False
        for u, v in list(h.edges):
            limit = max(min_px, 0.8 * min(width_px(u), width_px(v)))
            if np.linalg.norm(h.nodes[u]["rc"] - h.nodes[v]["rc"]) >= limit:
                continue
            keep, drop = (u, v) if h.degree(u) >= h.degree(v) else (v, u)
            for w in list(h.neighbors(drop)):
                if w != keep and not h.has_edge(keep, w):
                    h.add_edge(keep, w, path=h.edges[drop, w]["path"])
            h.remove_node(drop)
            changed = True
            break
    return h


def prune_room_spurs(h: nx.Graph, dist: np.ndarray, res: float, widening: float) -> int:
    """Remove dead ends that widen behind a narrower mouth: rooms and laser fans, not corridors.

    A corridor's dead end keeps its width to the end; a room seen through a wide opening,
    or the fan of laser rays through a door, is wider behind its mouth. Along each dead
    end's centre line (up to ``ROOM_SPUR_M`` long), the mouth is the narrowest place in
    the half next to the junction (past the junction's own width) and the room the
    widest place in the far half; the dead end goes when the room is ``widening`` times
    the mouth and 1 m wider. Repeated
    until none goes; returns how many went.
    """
    gone = 0
    changed = True
    while changed:
        changed = False
        for end in [n for n in h.nodes if h.degree(n) == 1]:
            chain = _dead_end_chain(h, end)
            if chain is None:
                continue
            nodes, path = chain
            if _path_len(path) * res > ROOM_SPUR_M:
                continue  # a long corridor that ends in a room keeps its corridor
            rc = np.clip(path.round().astype(int), 0, np.array(dist.shape) - 1)
            w = 2.0 * dist[rc[:, 0], rc[:, 1]] * res
            j = rc[0]
            skip = int(np.searchsorted(np.linalg.norm(path - j, axis=1), dist[j[0], j[1]]))
            half = max(len(path) // 2, skip + 1)
            if half >= len(path):
                continue
            mouth, room = float(w[skip:half].min()), float(w[half:].max())
            if room >= widening * mouth and room - mouth >= 1.0:
                h.remove_nodes_from(nodes)
                gone += 1
                changed = True
    return gone


def prune_alcoves(h: nx.Graph, dist: np.ndarray, ratio: float) -> int:
    """Remove dead ends short for their width that branch off a corridor: rooms, not corridors.

    A corridor is long for its width; a dead end no longer than ``ratio`` times its
    median width, meeting its junction across the corridor there (not carrying one of
    the junction's corridors straight on), is a room or an alcove seen through a wide
    opening or a glass front (the hospital's middle blocks), or a bay between shelves.
    A dead end that carries a corridor straight on through its junction is that
    corridor's last stretch and stays, however short; so does one that points at
    another dead end within twice its width (one corridor the graph broke in two).
    Repeated until none goes; returns how many went.
    """

    def goes(nodes: list, path: np.ndarray) -> bool:
        rc = np.clip(path.round().astype(int), 0, np.array(dist.shape) - 1)
        width = 2.0 * float(np.median(dist[rc[:, 0], rc[:, 1]]))
        if _path_len(path) >= ratio * width:
            return False
        return not (_carries_on(h, nodes[-1], path) or _faces_an_end(h, nodes, path, 2.0 * width))

    return _prune_dead_ends(h, goes)


def _prune_dead_ends(h: nx.Graph, goes: Callable[[list, np.ndarray], bool]) -> int:
    """Remove every dead end (its chain of nodes and centre-line path) that ``goes``,
    repeated until none goes (a stem is a dead end once its arms went); how many went."""
    gone = 0
    changed = True
    while changed:
        changed = False
        for end in [n for n in h.nodes if h.degree(n) == 1]:
            if end not in h or h.degree(end) != 1:
                continue
            chain = _dead_end_chain(h, end)
            if chain is not None and goes(*chain):
                h.remove_nodes_from(chain[0])
                gone += 1
                changed = True
    return gone


def prune_fans(
    h: nx.Graph, free: np.ndarray, unseen: np.ndarray, dist: np.ndarray, res: float, wall_min: float
) -> int:
    """Remove dead ends whose sides fade into space never seen: laser fans, and rooms seen
    only through their doorways, not corridors.

    A corridor runs between walls the laser saw; the rays a scanner threw through an open
    door fan out into space it never mapped, and a room seen only through its doorway is
    free space fading into unknown on at least one side. From each dead end's tip, the
    longest stretch of its corridors that is walled (neither side fading into space never
    seen, ``corridor_walls.walled_share``) along less than ``wall_min`` of its length
    goes. Judged by its sides, not by what lies at its far end: a long walled corridor
    that ends in fans is a corridor, and keeps its length.
    Repeated until none goes (the stem of a fan is a dead end once its arms went);
    returns how many went. (A map with no wall at all, free space drawn on unknown,
    cannot tell a fan from a corridor: ``draft_from_plan`` does not ask it.)
    """

    gone = 0
    changed = True
    while changed:
        changed = False
        for end in [n for n in h.nodes if h.degree(n) == 1]:
            chain = _dead_end_chain(h, end) if end in h and h.degree(end) == 1 else None
            if chain is None:
                continue
            nodes = chain[0]
            junction = next(m for m in h.neighbors(nodes[-1]) if m not in nodes)
            edges = list(zip(nodes, [*nodes[1:], junction], strict=True))
            lengths = np.array([len(h.edges[e]["path"]) for e in edges], float)
            shares = np.array([edge_walled(h, a, b, free, unseen, dist, res) for a, b in edges])
            # The longest stretch from the tip that is walled along less than wall_min of
            # it goes: a walled corridor keeps its length when rays fan out at its end.
            walled = np.cumsum(shares * lengths) / np.cumsum(lengths)
            fading = np.flatnonzero(walled < wall_min)
            if len(fading):
                h.remove_nodes_from(nodes[: fading[-1] + 1])
                gone += 1
                changed = True
    return gone


def prune_unlined(
    h: nx.Graph, space: np.ndarray, dist: np.ndarray, res: float, lined_min: float
) -> int:
    """Remove what no two parallel walls line: ways through rooms, round furniture, up fans.

    A corridor runs between two walls parallel to it (``corridor_walls.lined_share``).
    First the corridors on loops whose share is under ``lined_min`` go
    (``cut_unlined_loops``); then every dead end whose length-weighted share is under
    it, repeated until none goes. Returns how many went (loop corridors and dead ends).
    """
    gone = cut_unlined_loops(h, space, dist, res, lined_min)

    def goes(nodes: list, _path: np.ndarray) -> bool:
        junction = next(m for m in h.neighbors(nodes[-1]) if m not in nodes)
        edges = list(zip(nodes, [*nodes[1:], junction], strict=True))
        lengths = [len(h.edges[e]["path"]) for e in edges]
        shares = [edge_share(h, a, b, space, dist, res) for a, b in edges]
        return float(np.average(shares, weights=lengths)) < lined_min

    return gone + _prune_dead_ends(h, goes)


def _faces_an_end(h: nx.Graph, nodes: list, path: np.ndarray, reach_px: float) -> bool:
    """Whether the dead end running along ``path`` (junction to end) points at another
    dead end's end within ``reach_px`` of its own (within 30 degrees of straight on)."""
    p = path[-1]
    ahead = path[-1] - path[max(0, len(path) - 1 - int(reach_px))]
    ahead = ahead / max(float(np.linalg.norm(ahead)), 1e-9)
    for m in h.nodes:
        if m in nodes or h.degree(m) != 1:
            continue
        gap = h.nodes[m]["rc"] - p
        d = float(np.linalg.norm(gap))
        if d <= reach_px and float(np.dot(gap, ahead)) >= math.cos(math.radians(30)) * d:
            return True
    return False


def _carries_on(h: nx.Graph, last, path: np.ndarray) -> bool:
    """Whether the dead end leaving its junction along ``path`` runs straight on from one of
    the junction's other corridors (within 30 degrees)."""
    junction = next(m for m in h.neighbors(last) if h.degree(m) >= 3)
    j = h.nodes[junction]["rc"]
    out = h.nodes[last]["rc"] - j
    out = out / max(float(np.linalg.norm(out)), 1e-9)
    for m in h.neighbors(junction):
        if m == last:
            continue
        back = j - h.nodes[m]["rc"]
        back = back / max(float(np.linalg.norm(back)), 1e-9)
        if float(np.dot(out, back)) >= math.cos(math.radians(30)):
            return True
    return False


def _dead_end_chain(h: nx.Graph, end) -> tuple[list, np.ndarray] | None:
    """The waypoints from a dead end back to its junction (not included), and the pixel
    path from the junction out to the end; None for a corridor on its own."""
    nodes, paths, prev, cur = [end], [], None, end
    while True:
        nxt = [m for m in h.neighbors(cur) if m != prev]
        if len(nxt) != 1:
            return None
        paths.append(_oriented(h.edges[cur, nxt[0]]["path"], h.nodes[cur]["rc"], to_node=False))
        prev, cur = cur, nxt[0]
        if h.degree(cur) >= 3:
            break
        if h.degree(cur) == 1:
            return None
        nodes.append(cur)
    out = [p[::-1] for p in reversed(paths)]
    return nodes, np.vstack([out[0], *(p[1:] for p in out[1:])])


def _fit_lines(h: nx.Graph, world: dict, dist_m: dict) -> dict:
    """Per edge, (centroid, unit direction) of a total-least-squares line through its middle."""
    lines = {}
    for u, v, d in h.edges(data=True):
        pts = d["world"]
        pu, pv = world[u], world[v]
        trim_u = dist_m.get(u, 0.0) + 0.2
        trim_v = dist_m.get(v, 0.0) + 0.2
        far_u = np.linalg.norm(pts - pu, axis=1) > trim_u
        keep = far_u & (np.linalg.norm(pts - pv, axis=1) > trim_v)
        sel = pts[keep] if keep.sum() >= 5 else np.array([pu, pv])
        c = sel.mean(axis=0)
        if len(sel) >= 3:
            _, _, vt = np.linalg.svd(sel - c)
            direc = vt[0]
        else:
            direc = (pv - pu) / max(np.linalg.norm(pv - pu), 1e-9)
        if np.dot(direc, pv - pu) < 0:
            direc = -direc
        lines[(u, v)] = lines[(v, u)] = (c, direc)
    return lines


def _place_nodes(
    h: nx.Graph, world: dict, lines: dict, free_way: Callable[[np.ndarray, np.ndarray], bool]
) -> dict:
    """Each key waypoint at the least-squares crossing of its corridors' centre lines.

    ``free_way(a, b)`` says whether the straight way between two map points is free: a
    waypoint moves to its crossing only along one.
    """
    out = {}
    for n in h.nodes:
        ls = [lines[(n, m)] for m in h.neighbors(n)]
        dirs = [d for _, d in ls]
        crossing = any(
            abs(float(a[0] * b[1] - a[1] * b[0])) > math.sin(math.radians(20))
            for i, a in enumerate(dirs)
            for b in dirs[i + 1 :]
        )
        p0 = world[n]
        if crossing:
            a = np.zeros((2, 2))
            b = np.zeros(2)
            for (c, d), m_ in zip(ls, h.neighbors(n), strict=True):
                # Long corridors weigh more than short stubs (a spur into a room).
                wgt = float(np.linalg.norm(world[m_] - p0)) ** 2
                m = (np.eye(2) - np.outer(d, d)) * wgt
                a += m
                b += m @ c
            p = np.linalg.solve(a, b)
            # Not farther than 3 m, and never through a wall (a room's skeleton bends
            # whose lines cross beyond the room's wall).
            out[n] = p if np.linalg.norm(p - p0) < 3.0 and free_way(p0, p) else p0
        else:  # an end, or nearly straight: project onto the lines
            out[n] = np.mean([c + d * np.dot(p0 - c, d) for c, d in ls], axis=0)
    return out


# -- doors ----------------------------------------------------------------------------


def door_candidates(
    plan: FloorPlanImage,
    free: np.ndarray,
    a: np.ndarray,
    b: np.ndarray,
    width: float,
    margins: tuple[float, float],
    params: DraftParams,
) -> list[tuple[float, int]]:
    """Door-wide openings in both walls of the corridor a-b, with free space behind them.

    Returns (distance along from ``a``, side) pairs; side +1 is left of a->b.
    """
    length = float(np.linalg.norm(b - a))
    u = (b - a) / length
    n = np.array([-u[1], u[0]])
    step = plan.resolution / 2.0
    s = np.arange(margins[0], length - margins[1], step)
    if len(s) == 0:
        return []
    res = plan.resolution
    offs = np.arange(width / 2.0 + res, width / 2.0 + params.behind_m + 1e-9, res)
    found = []
    for side in (1, -1):
        pts = a + s[:, None, None] * u + side * offs[None, :, None] * n
        open_ = plan.mask_at(free, pts.reshape(-1, 2)).reshape(len(s), len(offs)).all(axis=1)
        for lo, hi in _runs(open_):
            run = (hi - lo) * step
            if params.door_min_m <= run <= params.door_max_m:
                found.append((float((s[lo] + s[hi - 1]) / 2.0), side))
    return found


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """[lo, hi) index ranges of the True runs."""
    d = np.diff(np.concatenate([[0], flags.astype(int), [0]]))
    return list(zip(np.nonzero(d == 1)[0], np.nonzero(d == -1)[0], strict=True))


# -- the whole draft --------------------------------------------------------------------


def draft_from_plan(plan: FloorPlanImage, params: DraftParams = DraftParams()) -> Draft:
    """Corridors, widths, key waypoints, open areas and door candidates from a grid."""
    from skimage.morphology import skeletonize

    res = plan.resolution
    if abs(plan.origin[2]) > 1e-9:
        raise DraftError(f"{plan.source}: origin yaw must be 0 for a draft (got {plan.origin[2]})")
    free = free_mask(plan, params.clean_m, params.clutter_m, seen_only=True)
    if not free.any():
        raise DraftError(f"{plan.source}: the grid has no free cells")
    corridor, _ = corridor_space(free, res, params.space())
    if not corridor.any():
        raise DraftError(
            f"{plan.source}: no corridor-shaped free space (at least {params.corridor_min_m} m "
            f"wide and {params.corridor_ratio} times longer than wide); check resolution and "
            "the free/occupied thresholds"
        )
    corridor = fill_pillars(corridor, params.pillar_m / res)
    dist = distance_map(free)
    open_mask = open_area_mask(corridor, dist, res, params)
    skel = skeletonize(corridor) & ~open_mask
    g = skeleton_graph(skel)
    g = prune_and_merge(g, dist, params.spur_m / res)
    if g.number_of_edges() == 0:
        raise DraftError(f"{plan.source}: no corridor found in the free space")
    h = _split_straight(g, params.line_tol_m / res)
    h = _merge_close(h, dist, params.min_edge_m / res)
    h.remove_edges_from(nx.selfloop_edges(h))
    prune_room_spurs(h, dist, res, params.room_widening)
    prune_alcoves(h, dist, params.corridor_ratio)
    unseen = unseen_mask(plan)
    walls_seen = bool(seen_mask(plan).any())

    def fans() -> int:
        return prune_fans(h, free, unseen, dist, res, params.wall_min) if walls_seen else 0

    # A loop the lined rule cuts leaves dead ends; the fan rule judges those too.
    while fans() + prune_unlined(h, corridor, dist, res, params.lined_min):
        pass
    hall_hubs(h, open_mask, free, dist)
    warnings = []
    for rc, n_px in link_parts(h, free, params.link_max_m / res):
        x, y = plan.pixel_to_world([rc[::-1]])[0]
        warnings.append(
            f"a corridor part of {n_px * res:.0f} m near ({x:.1f}, {y:.1f}) has no free straight "
            f"way to the rest within {params.link_max_m} m (--link-max): left out; "
            "join it by hand if the robot should reach it"
        )

    def to_world(rc: np.ndarray) -> np.ndarray:
        return plan.pixel_to_world(np.asarray(rc).reshape(-1, 2)[:, ::-1])

    world = {n: to_world(d["rc"])[0] for n, d in h.nodes(data=True)}
    half = {}
    for n, d in h.nodes(data=True):
        r, c = np.clip(d["rc"].round().astype(int), 0, np.array(free.shape) - 1)
        half[n] = (float(dist[r, c]) - 0.5) * res
    for _, _, d in h.edges(data=True):
        d["world"] = to_world(d["path"])
        rc = d["path"].round().astype(int)
        d["half"] = (dist[rc[:, 0], rc[:, 1]] - 0.5) * res
    lines = _fit_lines(h, world, half)
    def free_way(a: np.ndarray, b: np.ndarray) -> bool:
        rc = plan.world_to_pixel(np.array([a, b]))[:, ::-1]
        return free_along(free, rc[0], rc[1])

    pos = _place_nodes(h, world, lines, free_way)

    # Widths from the distance transform along the fitted centre line, as the robot drives it.
    widths = {}
    for u, v, d in h.edges(data=True):
        w = centre_line_width(plan, dist, pos[u], pos[v], half[u] + 0.2, half[v] + 0.2)
        if w is None:
            w = 2.0 * float(np.median(d["half"]))
        # A short link through a doorway can measure next to nothing: no corridor is
        # narrower than the narrowest the draft looks for.
        widths[frozenset((u, v))] = round(max(w, params.corridor_min_m), 2)

    open_areas = _boxes(open_mask, plan)
    names = _name_nodes(h, pos, open_areas)
    waypoints = [
        {"id": names[n], "kind": _kind(h, n, names), "pos": [round(float(v), 2) for v in pos[n]]}
        for n in sorted(h.nodes, key=lambda n: _order(names[n]))
    ]
    edges, rooms = [], []
    for u, v in sorted(h.edges, key=lambda e: sorted((_order(names[e[0]]), _order(names[e[1]])))):
        if _order(names[u]) > _order(names[v]):
            u, v = v, u
        w = widths[frozenset((u, v))]
        edges.append({"from": names[u], "to": names[v], "width": w})
        a, b = pos[u], pos[v]
        uu = (b - a) / np.linalg.norm(b - a)
        nn = np.array([-uu[1], uu[0]])
        others = [(x, m) for x, y in ((u, v), (v, u)) for m in h.neighbors(x) if m != y]
        for s, side in door_candidates(plan, free, a, b, w, (0.0, 0.0), params):
            door = a + uu * s + side * nn * (w / 2.0)
            if any(_beside(door, pos[x], pos[m], widths[frozenset((x, m))]) for x, m in others):
                continue  # the mouth of a corridor meeting this one, not a door
            xy = [round(float(x), 2) for x in door]
            rooms.append({"id": f"room{len(rooms) + 1}", "door": xy})
    # Judged from the waypoints as written (rounded to 1 cm), as the building file checks.
    rooms = _reachable_doors(rooms, edges, {w["id"]: np.array(w["pos"]) for w in waypoints})
    return Draft(waypoints, edges, rooms, open_areas, warnings, free, corridor, skel)


def _reachable_doors(rooms: list[dict], edges: list[dict], pos: dict) -> list[dict]:
    """The door candidates whose nearest corridor reaches them (as the building file checks).

    A candidate on the wall of a wide corridor (a hall's) can lie nearer the centre line
    of a narrow one that does not reach it; such a candidate is dropped, renumbered.
    """
    if not rooms:
        return rooms
    a = np.array([pos[e["from"]] for e in edges])
    b = np.array([pos[e["to"]] for e in edges])
    half = np.array([e["width"] / 2.0 for e in edges])
    j, _, dist = project_points_to_segments(np.array([r["door"] for r in rooms]), a, b)
    kept = [r for r, jj, d in zip(rooms, j, dist, strict=True) if d <= half[jj] + DOOR_REACH_SLACK]
    return [{"id": f"room{i + 1}", "door": r["door"]} for i, r in enumerate(kept)]


def _beside(p: np.ndarray, a: np.ndarray, b: np.ndarray, width: float) -> bool:
    """Whether ``p`` lies within the corridor a-b (past ``a``, within its half width)."""
    d = b - a
    t = float(np.dot(p - a, d) / np.dot(d, d))
    perp = float(np.linalg.norm(p - (a + t * d)))
    return t > -0.05 and perp < width / 2.0 + 0.2


def _name_nodes(h: nx.Graph, pos: dict, open_areas: list[Rect]) -> dict:
    """start, endN, turnN, branchN; numbered top to bottom, left to right."""
    order = sorted(h.nodes, key=lambda n: (-round(pos[n][1], 1), round(pos[n][0], 1)))
    ends = [n for n in order if h.degree(n) == 1]
    start = None
    if ends:
        if open_areas:  # the entrance is most likely where a corridor meets the lobby
            c = np.array(open_areas[0].centre)
            start = min(ends, key=lambda n: np.linalg.norm(pos[n] - c))
        else:
            start = ends[0]
    names, counts = {}, {"end": 0, "turn": 0, "branch": 0}
    for n in order:
        if n == start:
            names[n] = "start"
            continue
        kind = "end" if h.degree(n) == 1 else "turn" if h.degree(n) == 2 else "branch"
        counts[kind] += 1
        names[n] = f"{kind}{counts[kind]}"
    return names


def _kind(h: nx.Graph, n, names: dict) -> str:
    if names[n] == "start":
        return "start"
    return {1: "end", 2: "turn"}.get(h.degree(n), "branch")


def _order(name: str) -> tuple[int, int]:
    rank = {"start": 0, "branch": 1, "turn": 2, "end": 3}
    kind = name.rstrip("0123456789")
    num = name[len(kind) :]
    return rank.get(kind, 9), int(num) if num else 0


# -- writing --------------------------------------------------------------------------


def draft_building(
    grid_yaml: str | Path,
    out_path: str | Path,
    name: str | None = None,
    params: DraftParams = DraftParams(),
) -> tuple[Building, Draft, str]:
    """Draft a building file for ``out_path`` from a map_server YAML; (building, draft, text).

    The floor plan is referenced relative to ``out_path``'s folder. The building is
    validated before it is returned; nothing is written here.
    """
    grid_yaml, out_path = Path(grid_yaml), Path(out_path)
    plan = load_ros_map(grid_yaml)
    d = draft_from_plan(plan, params)
    rel = os.path.relpath(grid_yaml.resolve(), out_path.resolve().parent)
    data = d.building_data(name or grid_yaml.stem, Path(rel).as_posix())
    base = out_path.parent if out_path.parent.is_dir() else None
    b = building_from_data(data, str(out_path), base)
    return b, d, draft_text(data, d, grid_yaml)


def drawing_grid_path(out_path: str | Path) -> Path:
    """Where a drawing's grid is written for the building at ``out_path``: ``NAME_grid.yaml``."""
    out_path = Path(out_path)
    return out_path.with_name(f"{out_path.stem}_grid.yaml")


def draft_drawing(
    drawing: str | Path,
    out_path: str | Path,
    scale_m_per_px: float,
    name: str | None = None,
    params: DraftParams = DraftParams(),
) -> tuple[Building, Draft, str]:
    """Draft a building from a floor-plan drawing; its grid is written beside ``out_path``.

    The drawing is read as a grid (``pmnav_bt.map.drawing``), saved as a map_server
    map (``drawing_grid_path``) so the building's floor plan and ``sim.walls=grid``
    work at once, and drafted like any grid.
    """
    from pmnav_bt.map.drawing import drawing_plan

    plan = drawing_plan(drawing, scale_m_per_px)
    grid = save_ros_map(plan, drawing_grid_path(out_path), ".png")  # PNG: a tenth of a PGM
    return draft_building(grid, out_path, name or Path(drawing).stem, params)


def draft_source(
    source: str | Path,
    out_path: str | Path,
    name: str | None = None,
    scale: float | None = None,
    scale_from: str | None = None,
    knobs: dict | None = None,
) -> tuple[Building, Draft, str, FloorPlanImage]:
    """Draft from a grid YAML or a drawing (by its suffix); (building, draft, text, grid).

    A drawing needs its scale: ``scale`` metres per pixel, or ``scale_from`` two pixels
    and their distance (``X1,Y1,X2,Y2,METRES``). ``knobs`` override DraftParams fields.
    """
    from pmnav_bt.map.drawing import DrawingError, scale_from_points

    source = Path(source)
    for k, v in (knobs or {}).items():
        if not (isinstance(v, int | float) and math.isfinite(v) and v > 0):
            option = "--" + k.removesuffix("_m").replace("_", "-")
            unit = " of metres" if k.endswith("_m") else ""
            raise DraftError(f"{option} must be a positive number{unit}, not {v!r}")
    if (knobs or {}).get("wall_min", 0.0) > 1.0:
        raise DraftError(
            f"--wall-min is a share of a dead end's length, 0 to 1, not {knobs['wall_min']!r}"
        )
    if (knobs or {}).get("lined_min", 0.0) > 1.0:
        raise DraftError(
            f"--lined-min is a share of a corridor's sides, 0 to 1, not {knobs['lined_min']!r}"
        )
    params = DraftParams(**(knobs or {}))
    if source.suffix.lower() in (".yaml", ".yml"):
        if scale is not None or scale_from is not None:
            raise DrawingError(f"{source}: --scale and --scale-from are for drawings, not grids")
        b, d, text = draft_building(source, out_path, name, params)
        return b, d, text, load_ros_map(source)
    if (scale is None) == (scale_from is None):
        raise DrawingError(
            f"{source}: a drawing needs its scale: --scale M_PER_PX or "
            "--scale-from X1,Y1,X2,Y2,METRES (one of them)"
        )
    m_per_px = scale if scale is not None else scale_from_points(scale_from)
    b, d, text = draft_drawing(source, out_path, m_per_px, name, params)
    return b, d, text, load_ros_map(drawing_grid_path(out_path))


def _flow(item: dict) -> str:
    import yaml

    return yaml.safe_dump(item, default_flow_style=True, sort_keys=False, width=10**6).strip()


def draft_text(data: dict, d: Draft, source: Path) -> str:
    """The building file, with ``todo`` comments for what the grid cannot tell."""
    import yaml

    head = {k: data[k] for k in ("schema_version", "name", "kind", "description", "corridor_width")}
    lines = [
        f"# Drafted by 'pmnav map draft' from {source.name}: a start, not a finished file.",
        "# todo: give every room its name, aliases and the text on its sign; delete door",
        "#       candidates that are not doors and add closed doors the grid cannot show;",
        "#       add landmarks (elevators, stairs, desks, signs); check which end is 'start'.",
        "# Then: pmnav validate THIS_FILE, and look at pmnav map THIS_FILE --image map.png.",
    ]
    for warning in d.warnings:
        lines.append(f"# warning: {warning}")
    for i, a in enumerate(d.open_areas):
        lines.append(
            f"# todo: open area {i + 1} (wider than a corridor) at x {a.xmin}..{a.xmax}, "
            f"y {a.ymin}..{a.ymax}: a hall; with two exits or more they meet at one "
            "waypoint in its most open place: check the ways across it"
        )
    lines.append(yaml.safe_dump(head, sort_keys=False, width=100).strip())
    lines.append(f"floor_plan: {_flow(data['floor_plan'])}")
    lines.append("waypoints:")
    lines += [f"  - {_flow(w)}" for w in data["waypoints"]]
    lines.append("edges:")
    lines += [f"  - {_flow(e)}" for e in data["edges"]]
    if data["rooms"]:
        lines.append("rooms:  # door candidates: an opening in the corridor wall with space behind")
        lines += [f"  - {_flow(r)}  # todo: name, sign" for r in data["rooms"]]
    else:
        lines.append("rooms: []  # todo: no door openings found; add the rooms by hand")
    return "\n".join(lines) + "\n"


# -- a picture of the steps -------------------------------------------------------------


def draw_steps(plan: FloorPlanImage, d: Draft, path: str | Path) -> Path:
    """The grid with the corridor space, skeleton, open areas, corridors and doors drawn."""
    img = plan.bgr().copy()
    tint = img.copy()
    tint[d.corridor] = (200, 230, 200)
    img = cv2.addWeighted(img, 0.5, tint, 0.5, 0)
    img[d.skeleton] = (0, 140, 255)
    for a in d.open_areas:
        p = plan.world_to_pixel([[a.xmin, a.ymin], [a.xmax, a.ymax]]).round().astype(int)
        cv2.rectangle(img, tuple(p[0]), tuple(p[1]), (200, 0, 200), 2)
    pos = {w["id"]: np.array(w["pos"]) for w in d.waypoints}
    for e in d.edges:
        p = plan.world_to_pixel([pos[e["from"]], pos[e["to"]]]).round().astype(int)
        cv2.line(img, tuple(p[0]), tuple(p[1]), (200, 60, 0), 2)
    for w in d.waypoints:
        p = plan.world_to_pixel([w["pos"]]).round().astype(int)[0]
        cv2.circle(img, tuple(p), 5, (0, 0, 220), -1)
    for r in d.rooms:
        p = plan.world_to_pixel([r["door"]]).round().astype(int)[0]
        cv2.drawMarker(img, tuple(p), (0, 160, 0), cv2.MARKER_TILTED_CROSS, 9, 2)
    path = Path(path)
    cv2.imwrite(str(path), img)
    return path


def main(argv: list[str] | None = None) -> None:
    """``python -m pmnav_bt.map.draft SOURCE -o building.yaml [--scale M] [--image steps.png]``."""
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("source", help="a map_server YAML, or a drawing (PNG/JPEG) with --scale")
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--scale", type=float, help="a drawing's metres per pixel")
    ap.add_argument("--image")
    args = ap.parse_args(argv)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    b, d, text, plan = draft_source(args.source, args.out, scale=args.scale)
    Path(args.out).write_text(text, encoding="utf-8")
    if args.image:
        draw_steps(plan, d, args.image)
    n = f"{len(b.waypoints)} waypoints, {len(b.edges)} corridors, {len(b.rooms)} door candidates"
    print(f"wrote {args.out}: {n}")


if __name__ == "__main__":  # pragma: no cover
    main()
