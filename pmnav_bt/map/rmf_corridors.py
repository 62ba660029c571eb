"""Corridors from an RMF level's lanes, centred and measured in the walls' grid.

RMF lanes are the robots' navigation graph: they run along the corridors, but not on
their centre lines, and they also lead into rooms and to parking spots. The steps:

1. **Lanes inside the corridors' free space** (the largest free part of the grid, doors
   closed): a lane that leaves it (through a door into a room, or outside) is cut where
   it leaves, a little short of the wall; a lane wholly outside is skipped.
2. **A simple graph**: ends closer than ``MERGE_M`` are one node; spurs (dead ends
   shorter than ``SPUR_M``, the stubs to parking spots and through doors) are pruned;
   nodes that only continue a straight line are dropped; the largest connected part is
   kept, the others are listed as skipped.
3. **Centred and measured**: across each corridor, rays out to ``CAP_M`` on both sides
   find the walls, and each side's clearance is what it keeps all along
   (``corridor_band``, the measure ``pmnav validate`` checks widths by: a corridor is one
   rectangle about its centre line, so its width is what is free all along, not a median
   over a lane that passes a gap). Where both sides
   hit, the centre line moves to the middle of that band and the width is its breadth
   (unless the middle runs into more obstacles than the lane, a hall's pillars: then the
   lane and twice its nearer clearance); where one side is open (a hall), the line stays
   and the width is twice the clearance of the side with a wall; with no wall either
   side, ``OPEN_WIDTH_M``. A dead end
   is carried on along its corridor while walls stand on both sides ahead (a lane that
   stops at a parking spot half way down a corridor).
4. **Key waypoints** at the least-squares crossing of their corridors' centre lines, so
   every waypoint is on every centre line that meets there; each corridor's width is then
   measured again about its placed line (the measure ``pmnav validate`` checks).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import networkx as nx
import numpy as np

from pmnav_bt.map.corridor_band import REACH_M, WALLED, free_band
from pmnav_bt.map.floorplan import FloorPlanImage
from pmnav_bt.map.grid import free_mask
from pmnav_bt.map.rmf_read import RmfLevel

MERGE_M = 0.3  # lane ends closer than this are one node
SPUR_M = 1.5  # dead-end corridors shorter than this are stubs, not corridors
STRAIGHT_DEG = 12.0  # a node whose two corridors bend less than this is dropped
CAP_M = REACH_M  # rays look this far for a wall on each side
WALL_GAP_M = 0.15  # a cut lane stops this far short of the wall it meets
MIN_EDGE_M = 0.8  # waypoints closer than this after centring are merged
MIN_WIDTH_M = 0.6
OPEN_WIDTH_M = 3.0  # the width of a lane across a hall with no wall within CAP_M either side
EXTEND_M = 30.0  # a dead end is carried on at most this far
CROSSING_DEG = 20.0  # corridors meeting at more than this fix their waypoint by crossing


@dataclass
class Corridors:
    """Key waypoints (node -> map position), corridor edges with widths, what was skipped."""

    pos: dict[int, np.ndarray]
    edges: list[tuple[int, int, float]]
    skipped: list[str] = field(default_factory=list)
    cuts: int = 0  # lanes cut where they left the free space
    # edges whose width is drawn, not measured: a spur runs half its width in front of its
    # door's wall (rmf_spurs), whatever the space across from it
    drawn: set[frozenset] = field(default_factory=set)


def lane_corridors(level: RmfLevel, plan: FloorPlanImage, free: np.ndarray) -> Corridors:
    """The corridor network of ``level`` in ``free`` (the corridors' free cells of ``plan``)."""
    g, skipped, cuts = _lanes_inside(level, plan, free)
    g = _merge_close(g, MERGE_M)
    _prune_spurs(g, SPUR_M)
    _drop_straight(g)
    parts = sorted(nx.connected_components(g), key=len, reverse=True)
    for part in parts[1:]:
        length = sum(_len(g, u, v) for u, v in g.subgraph(part).edges)
        skipped.append(
            f"lanes: a part of {len(part)} lane end(s), {length:.1f} m, apart from the largest "
            "(not reachable without crossing a wall or a closed door)"
        )
    if not parts or g.subgraph(parts[0]).number_of_edges() == 0:
        return Corridors({}, [], skipped, cuts)
    g = g.subgraph(parts[0]).copy()
    walls = free_mask(plan)  # pillars and furniture filled in: widths are wall to wall
    lines, widths = {}, {}
    for u, v in g.edges:
        a, b = g.nodes[u]["xy"], g.nodes[v]["xy"]
        lines[(u, v)], widths[frozenset((u, v))] = _centre(plan, free, walls, a, b)
    pos = _place(g, lines)
    g, pos = _merge_after(g, pos, widths)
    _extend_dead_ends(g, pos, widths, plan, (free, walls))
    edges = [(u, v, widths[frozenset((u, v))]) for u, v in g.edges]
    cor = Corridors({n: pos[n] for n in g.nodes}, edges, skipped, cuts)
    measure_widths(cor, plan)
    return cor


# -- 1. lanes inside the free space -------------------------------------------------------


def _lanes_inside(level: RmfLevel, plan: FloorPlanImage, free: np.ndarray):
    g = nx.Graph()
    skipped, cuts = [], 0
    nxt = len(level.xy)
    step = plan.resolution / 2.0
    for i, lane in enumerate(level.lanes):
        a, b = level.xy[lane.a], level.xy[lane.b]
        length = float(np.linalg.norm(b - a))
        if length < 1e-6:
            continue
        s = np.arange(0.0, length + step, step).clip(max=length)
        ins = plan.mask_at(free, a + np.outer(s / length, b - a))
        if ins.all():
            _add(g, lane.a, a, lane.b, b)
            continue
        kept = False
        for end, xy, other, flags, ss in ((lane.a, a, b, ins, s), (lane.b, b, a, ins[::-1], s)):
            if not flags[0]:
                continue
            out_at = float(ss[int(np.argmin(flags))]) - WALL_GAP_M
            if out_at < MERGE_M:
                continue
            cut = xy + (other - xy) * (out_at / length)
            _add(g, end, xy, nxt, cut)
            nxt += 1
            kept = True
        if kept:
            cuts += 1
        else:
            skipped.append(f"lanes[{i}]: outside the corridors' free space (in a room or outside)")
    return g, skipped, cuts


def _add(g: nx.Graph, u: int, pu: np.ndarray, v: int, pv: np.ndarray) -> None:
    g.add_node(u, xy=np.asarray(pu, float))
    g.add_node(v, xy=np.asarray(pv, float))
    if u != v:
        g.add_edge(u, v)


# -- 2. a simple graph ----------------------------------------------------------------------


def _len(g: nx.Graph, u, v) -> float:
    return float(np.linalg.norm(g.nodes[u]["xy"] - g.nodes[v]["xy"]))


def _contract(g: nx.Graph, keep, drop) -> None:
    for w in list(g.neighbors(drop)):
        if w != keep:
            g.add_edge(keep, w)
    g.remove_node(drop)


def _merge_close(g: nx.Graph, limit: float) -> nx.Graph:
    """Contract nodes closer than ``limit`` (joined or not): one place, one waypoint."""
    changed = True
    while changed:
        changed = False
        nodes = list(g.nodes)
        xy = np.array([g.nodes[n]["xy"] for n in nodes]).reshape(-1, 2)
        d = np.linalg.norm(xy[:, None] - xy[None], axis=2) + np.eye(len(nodes)) * 1e9
        i, j = np.unravel_index(int(np.argmin(d)), d.shape) if len(nodes) > 1 else (0, 0)
        if len(nodes) > 1 and d[i, j] < limit:
            keep, drop = (nodes[i], nodes[j])
            if g.degree(drop) > g.degree(keep):
                keep, drop = drop, keep
            _contract(g, keep, drop)
            changed = True
    return g


def _prune_spurs(g: nx.Graph, limit: float) -> None:
    """Remove dead ends shorter than ``limit`` that hang off a junction, until none is left."""
    changed = True
    while changed:
        changed = False
        for n in list(g.nodes):
            if n in g and g.degree(n) == 1:
                (m,) = g.neighbors(n)
                if g.degree(m) >= 3 and _len(g, n, m) < limit:
                    g.remove_node(n)
                    changed = True
    g.remove_nodes_from([n for n in list(g.nodes) if g.degree(n) == 0])


def _bend_deg(g: nx.Graph, n) -> float:
    a, b = (g.nodes[m]["xy"] - g.nodes[n]["xy"] for m in g.neighbors(n))
    cos = float(np.dot(a, b) / max(np.linalg.norm(a) * np.linalg.norm(b), 1e-12))
    return 180.0 - math.degrees(math.acos(max(-1.0, min(1.0, cos))))


def _drop_straight(g: nx.Graph) -> None:
    """Drop nodes that only continue a straight corridor (two neighbours, a slight bend)."""
    changed = True
    while changed:
        changed = False
        for n in list(g.nodes):
            if g.degree(n) != 2:
                continue
            a, b = g.neighbors(n)
            if not g.has_edge(a, b) and _bend_deg(g, n) < STRAIGHT_DEG:
                g.remove_node(n)
                g.add_edge(a, b)
                changed = True


# -- 3. centred and measured ----------------------------------------------------------------


def _centre(plan: FloorPlanImage, free, walls, a: np.ndarray, b: np.ndarray):
    """((point, unit direction) of the centred line, width) of the corridor along a-b.

    The band is measured in ``walls`` (the free space with small obstacles filled in,
    ``corridor_band``); the centred line must not run into more of ``free``'s obstacles
    than the lane does.
    """
    length = float(np.linalg.norm(b - a))
    u = (b - a) / length
    n = np.array([-u[1], u[0]])
    band = free_band(plan, walls, a, b)
    mid = (a + b) / 2.0
    off, width = band.offset, band.width
    if off and _blocked(plan, free, a + off * n, b + off * n) > _blocked(plan, free, a, b):
        off, width = 0.0, 2.0 * min(band.left, band.right)  # the middle runs into a pillar
    width = width if np.isfinite(width) else OPEN_WIDTH_M
    return (mid + off * n, u), max(MIN_WIDTH_M, min(width, 2.0 * CAP_M))


def _blocked(plan: FloorPlanImage, free: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """The share of the line a-b off the free space."""
    n = max(2, int(np.linalg.norm(b - a) / (plan.resolution / 2.0)))
    return 1.0 - float(plan.mask_at(free, a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)).mean())


def _walled(plan: FloorPlanImage, free: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """The share of the line a-b with a wall within ``CAP_M`` on both sides."""
    length = float(np.linalg.norm(b - a))
    u = (b - a) / length
    n = np.array([-u[1], u[0]])
    s = np.linspace(0.0, length, max(3, int(length / 0.25)))
    t = np.arange(plan.resolution / 2.0, CAP_M, plan.resolution / 2.0)
    hit = []
    for side in (1.0, -1.0):
        pts = a + s[:, None, None] * u + side * t[None, :, None] * n
        hit.append(~plan.mask_at(free, pts.reshape(-1, 2)).reshape(len(s), len(t)).all(axis=1))
    return float((hit[0] & hit[1]).mean())


def _extend_dead_ends(g: nx.Graph, pos: dict, widths: dict, plan, masks) -> None:
    """Carry each dead end on along its corridor while the free space ahead stays
    corridor-shaped (walls on both sides): a lane that stops at a parking spot half way
    down a corridor leaves the rest of the corridor, and its doors, unreached."""
    free, walls = masks
    for n in [n for n in g.nodes if g.degree(n) == 1]:
        (m,) = g.neighbors(n)
        u = pos[n] - pos[m]
        u = u / max(float(np.linalg.norm(u)), 1e-9)
        t = np.arange(plan.resolution, EXTEND_M, plan.resolution / 2.0)
        ahead = plan.mask_at(free, pos[n] + t[:, None] * u)
        clear = float(t[int(np.argmin(ahead))]) if not ahead.all() else EXTEND_M
        half = widths[frozenset((n, m))] / 2.0
        reach = clear - max(half, 0.5)
        if reach < MIN_EDGE_M:
            continue
        end = pos[n] + u * reach
        if _walled(plan, walls, pos[n], end) < WALLED:
            continue
        la = float(np.linalg.norm(pos[n] - pos[m]))
        _, w = _centre(plan, free, walls, pos[n], end)
        widths[frozenset((n, m))] = (widths[frozenset((n, m))] * la + w * reach) / (la + reach)
        pos[n] = end


def measure_widths(cor: Corridors, plan: FloorPlanImage) -> None:
    """Each corridor's width as its placed centre line has it: the rectangle about that
    line free all along (``Band.about_line``, what ``pmnav validate`` checks), in the
    plan's free cells with small clutter filled in. Placing the waypoints at their lines'
    crossings moves a line off the band it was centred in (the office's corridor past the
    hardware room: 5.35 m wide from its lane, its placed line 1.35 m from one wall, so
    its rectangle ran 1.3 m into that wall, and the robot's wall corrections, which take
    the wall seen for the corridor's at half its width, pulled it off), and a spur's foot
    splits a corridor whose parts differ. A line with no wall in reach on either side,
    and a drawn edge (``Corridors.drawn``), keep their widths."""
    walls = free_mask(plan)
    for k, (u, v, w) in enumerate(cor.edges):
        band = None if frozenset((u, v)) in cor.drawn else free_band(
            plan, walls, cor.pos[u], cor.pos[v]
        )
        if band is not None and math.isfinite(band.about_line):
            w = max(MIN_WIDTH_M, band.about_line)
        cor.edges[k] = (u, v, round(w, 2))


def _place(g: nx.Graph, lines: dict) -> dict:
    """Each node at the least-squares crossing of its corridors' lines (or on its line)."""
    pos = {}
    for n in g.nodes:
        p0 = g.nodes[n]["xy"]
        ls = [lines[(n, m)] if (n, m) in lines else lines[(m, n)] for m in g.neighbors(n)]
        dirs = [d for _, d in ls]
        crossing = any(
            abs(float(x[0] * y[1] - x[1] * y[0])) > math.sin(math.radians(CROSSING_DEG))
            for i, x in enumerate(dirs)
            for y in dirs[i + 1 :]
        )
        on_lines = np.mean([c + d * np.dot(p0 - c, d) for c, d in ls], axis=0)
        pos[n] = on_lines
        if crossing:
            a, rhs = np.zeros((2, 2)), np.zeros(2)
            for c, d in ls:
                m = np.eye(2) - np.outer(d, d)
                a += m
                rhs += m @ c
            p = np.linalg.solve(a, rhs)
            if np.linalg.norm(p - p0) < 2.0:
                pos[n] = p
    return pos


def _merge_after(g: nx.Graph, pos: dict, widths: dict):
    """Merge waypoints that centring brought closer than ``MIN_EDGE_M``."""
    changed = True
    while changed:
        changed = False
        for u, v in list(g.edges):
            if np.linalg.norm(pos[u] - pos[v]) >= MIN_EDGE_M:
                continue
            keep, drop = (u, v) if g.degree(u) >= g.degree(v) else (v, u)
            for w in list(g.neighbors(drop)):
                if w != keep and not g.has_edge(keep, w):
                    widths[frozenset((keep, w))] = widths[frozenset((drop, w))]
            _contract(g, keep, drop)
            changed = True
            break
    return g, pos
