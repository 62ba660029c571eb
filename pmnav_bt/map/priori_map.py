"""Map parsing (paper, "Map Parsing"): a Building becomes a segment-based semantic priori-map.

Each room's door is linked to the nearest corridor centre line (its *room
waypoint*); each landmark likewise. The corridors are cut into segments at the key
waypoints (start, turn, branch, end) and the room waypoints, numbered in a stable
order and named after their two ends, ``seg13(room14-room7)``. Directions between
key waypoints are given as compass words ("from start to turn1, the direction is
south"). The result renders as structured text (what a VLM prompt contains) and as
JSON.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from functools import cached_property
from itertools import pairwise

import networkx as nx
import numpy as np

from pmnav_bt.errors import UnknownNameError
from pmnav_bt.geometry import (
    SegmentIndex,
    compass,
    heading,
    project_points_to_segments,
    side_of,
)
from pmnav_bt.map.building import Building

# Room waypoints closer than this (metres, along one corridor) share one map node,
# as doors facing each other across a corridor do.
MERGE_TOLERANCE = 0.6

_NATURAL = re.compile(r"(\d+)")


def clipped(text: str, n: int = 40) -> str:
    """``text`` cut to ``n`` characters for a message (a typed name can be any length)."""
    return text if len(text) <= n else text[: n - 3] + "..."


def natural_key(s: str) -> tuple:
    """Sort key that orders room2 before room10."""
    return tuple(int(t) if t.isdigit() else t for t in _NATURAL.split(s))


@dataclass(frozen=True)
class MapNode:
    """A node of the priori-map: a key waypoint or a room/landmark waypoint on a corridor."""

    id: str
    kind: str  # start | turn | branch | end | room | landmark
    pos: tuple[float, float]
    rooms: tuple[str, ...] = ()
    landmarks: tuple[str, ...] = ()

    @property
    def is_key(self) -> bool:
        return self.kind in ("start", "turn", "branch", "end")

    @property
    def visible(self) -> bool:
        """True where something can be seen and recognised (a door sign or landmark)."""
        return bool(self.rooms or self.landmarks)


@dataclass(frozen=True)
class Segment:
    """A straight piece of corridor between two consecutive map nodes."""

    index: int
    a: str
    b: str
    length: float
    heading: float  # from a to b, rad
    corridor: tuple[str, str]  # the key-waypoint edge it lies on
    width: float

    @property
    def name(self) -> str:
        return f"seg{self.index}({self.a}-{self.b})"

    @property
    def short(self) -> str:
        return f"seg{self.index}"


@dataclass(frozen=True)
class Direction:
    """Direction of travel along one corridor, between two key waypoints."""

    a: str
    b: str
    heading: float
    length: float

    @property
    def compass(self) -> str:
        return compass(self.heading)

    def sentence(self) -> str:
        return f"from {self.a} to {self.b}, the direction is {self.compass} ({self.length:.1f} m)"


@dataclass(frozen=True)
class Place:
    """Where a room or landmark is: its node, segment and side (seen travelling a->b)."""

    node: str
    segment: int
    side: str


@dataclass(frozen=True)
class SegmentPosition:
    """A point projected onto the priori-map: segment, fraction t from a to b, offset."""

    segment: Segment
    t: float
    offset: float

    def point(self, pm: PrioriMap) -> np.ndarray:
        a, b = pm.node_xy(self.segment.a), pm.node_xy(self.segment.b)
        return a + self.t * (b - a)


@dataclass
class PrioriMap:
    """The semantic priori-map of a building."""

    building: Building
    nodes: dict[str, MapNode]
    segments: list[Segment]
    directions: list[Direction]
    places: dict[str, Place]  # room or landmark id -> place
    graph: nx.Graph = field(repr=False)

    # -- lookups --------------------------------------------------------------------------

    def node_xy(self, node_id: str) -> np.ndarray:
        return np.asarray(self.nodes[node_id].pos, dtype=float)

    @cached_property
    def adjacency(self) -> dict[str, dict[str, tuple[float, int]]]:
        """Each node's neighbours (in the graph's order), each with (metres, segment index),
        as plain dicts: a search over these (``corridor_search``), or a plan's walk along
        them, is several times quicker than over the graph's views. Built once: a
        priori-map does not change once parsed."""
        return {
            n: {m: (e["length"], e["segment"]) for m, e in nbrs.items()}
            for n, nbrs in self.graph.adj.items()
        }

    @cached_property
    def _segment_arrays(self) -> tuple[np.ndarray, np.ndarray]:
        a = np.array([self.nodes[s.a].pos for s in self.segments], dtype=float)
        b = np.array([self.nodes[s.b].pos for s in self.segments], dtype=float)
        return a, b

    def segment(self, ref: str | int) -> Segment:
        """A segment by index (13), short name ("seg13") or full name ("seg13(room14-room7)")."""
        text = str(ref).strip().lower().replace(" ", "")
        m = re.fullmatch(r"(?:seg)?(\d+)(?:\((.*)\))?", text)
        if m and len(m.group(1)) <= 9:  # longer: no such segment (and past int()'s limit)
            i = int(m.group(1))
            if 1 <= i <= len(self.segments):
                seg = self.segments[i - 1]
                if m.group(2) is None or m.group(2) == f"{seg.a}-{seg.b}".lower():
                    return seg
                raise UnknownNameError(
                    f"segment {ref!r} does not match this map: seg{i} is {seg.name}", [seg.name]
                )
        names = [s.name for s in self.segments]
        raise UnknownNameError(
            f"unknown segment {clipped(str(ref))!r}: this map has seg1 to seg{len(names)}",
            names[:5],
        )

    @cached_property
    def _segment_index(self) -> SegmentIndex:
        return SegmentIndex(*self._segment_arrays)

    def locate(self, x: float, y: float) -> SegmentPosition:
        """Project a map position onto the nearest segment (the segments' index is built
        once: a tick may ask)."""
        j, t, d = self._segment_index.project(np.array([[x, y]]))
        return SegmentPosition(self.segments[int(j[0])], float(t[0]), float(d[0]))

    def segments_at(self, node_id: str) -> list[Segment]:
        return [self.segments[d["segment"] - 1] for _, _, d in self.graph.edges(node_id, data=True)]

    @property
    def key_waypoints(self) -> list[MapNode]:
        return [n for n in self.nodes.values() if n.is_key]

    # -- output ---------------------------------------------------------------------------

    def to_text(self) -> str:
        """Structured text of the priori-map, as a VLM prompt contains it."""
        b = self.building
        lines = [f"# Semantic priori-map of {b.name} ({b.kind})"]
        if b.description:
            lines.append(b.description)
        lines += ["", "## Key waypoints"]
        for n in self.key_waypoints:
            lines.append(f"- {n.id}: {n.kind} at ({n.pos[0]:.1f}, {n.pos[1]:.1f})")
        lines += ["", "## Directions between key waypoints"]
        lines += [f"- {d.sentence()}" for d in self.directions]
        lines += ["", "## Segments (a-b: length, direction of travel from a to b)"]
        for s in self.segments:
            lines.append(f"- {s.name}: {s.length:.1f} m, {compass(s.heading)}")
        lines += ["", "## Rooms (id: name; aliases; sign; where)"]
        for r in sorted(b.rooms, key=lambda r: natural_key(r.id)):
            p = self.places[r.id]
            seg = self.segments[p.segment - 1]
            extra = f"; aliases: {', '.join(r.aliases)}" if r.aliases else ""
            lines.append(
                f'- {r.id}: {r.display_name}{extra}; sign "{r.sign_text}"; at {p.node}, '
                f"on the {p.side} of {seg.short} going {seg.a}->{seg.b}"
            )
        if b.landmarks:
            lines += ["", "## Landmarks"]
            for lm in b.landmarks:
                p = self.places[lm.id]
                seg = self.segments[p.segment - 1]
                lines.append(
                    f'- {lm.id}: {lm.kind} "{lm.display_name}" at {p.node}, '
                    f"on the {p.side} of {seg.short} going {seg.a}->{seg.b}"
                )
        return "\n".join(lines) + "\n"

    def to_dict(self) -> dict:
        """The priori-map as JSON-ready data."""
        return {
            "building": self.building.name,
            "kind": self.building.kind,
            "nodes": [
                {
                    "id": n.id,
                    "kind": n.kind,
                    "pos": list(n.pos),
                    "rooms": list(n.rooms),
                    "landmarks": list(n.landmarks),
                }
                for n in self.nodes.values()
            ],
            "segments": [
                {
                    "index": s.index,
                    "name": s.name,
                    "a": s.a,
                    "b": s.b,
                    "length_m": round(s.length, 3),
                    "heading_deg": round(math.degrees(s.heading), 1),
                    "compass": compass(s.heading),
                    "corridor": list(s.corridor),
                    "width_m": s.width,
                }
                for s in self.segments
            ],
            "directions": [
                {
                    "from": d.a,
                    "to": d.b,
                    "compass": d.compass,
                    "length_m": round(d.length, 3),
                    "text": d.sentence(),
                }
                for d in self.directions
            ],
            "rooms": [
                {
                    "id": r.id,
                    "name": r.display_name,
                    "aliases": list(r.aliases),
                    "sign": r.sign_text,
                    "door": list(r.door),
                    **_place_dict(self.places[r.id]),
                }
                for r in self.building.rooms
            ],
            "landmarks": [
                {
                    "id": lm.id,
                    "kind": lm.kind,
                    "name": lm.display_name,
                    "pos": list(lm.pos),
                    **_place_dict(self.places[lm.id]),
                }
                for lm in self.building.landmarks
            ],
        }


def _place_dict(p: Place) -> dict:
    return {"node": p.node, "segment": p.segment, "side": p.side}


def parse_building(b: Building) -> PrioriMap:
    """Build the semantic priori-map of a (validated) building."""
    wps = {w.id: w for w in b.waypoints}
    edges = list(b.edges)
    seg_a = np.array([wps[e.a].pos for e in edges], dtype=float)
    seg_b = np.array([wps[e.b].pos for e in edges], dtype=float)
    edge_len = np.linalg.norm(seg_b - seg_a, axis=1)

    # Link every door and landmark to its nearest corridor: (edge, distance along it).
    items: list[tuple[str, str, tuple[float, float]]] = [
        ("room", r.id, r.door) for r in b.rooms
    ] + [("landmark", lm.id, lm.pos) for lm in b.landmarks]
    if items:
        pts = np.array([p for _, _, p in items], dtype=float)
        ei, tt, _ = project_points_to_segments(pts, seg_a, seg_b)
    else:
        ei, tt = np.zeros(0, dtype=int), np.zeros(0)

    nodes: dict[str, MapNode] = {
        w.id: MapNode(w.id, w.kind.value, (float(w.pos[0]), float(w.pos[1]))) for w in b.waypoints
    }
    at_key: dict[str, list[tuple[str, str]]] = {}  # waypoint id -> items attached there
    per_edge: dict[int, list[tuple[float, str, str, int]]] = {}
    for (kind, ident, p), e, t in zip(items, ei, tt, strict=True):
        s = float(t) * float(edge_len[e])
        if s < MERGE_TOLERANCE:
            at_key.setdefault(edges[e].a, []).append((kind, ident))
        elif edge_len[e] - s < MERGE_TOLERANCE:
            at_key.setdefault(edges[e].b, []).append((kind, ident))
        else:
            per_edge.setdefault(int(e), []).append((s, kind, ident, _side(seg_a[e], seg_b[e], p)))
    for wid, attached in at_key.items():
        n = nodes[wid]
        nodes[wid] = MapNode(
            n.id,
            n.kind,
            n.pos,
            tuple(sorted((i for k, i in attached if k == "room"), key=natural_key)),
            tuple(sorted((i for k, i in attached if k == "landmark"), key=natural_key)),
        )

    segments: list[Segment] = []
    graph = nx.Graph()
    for n in nodes.values():
        graph.add_node(n.id)
    for e_idx, e in enumerate(edges):
        a_xy, b_xy = seg_a[e_idx], seg_b[e_idx]
        length = float(edge_len[e_idx])
        chain = [e.a]
        for cluster in _clusters(sorted(per_edge.get(e_idx, []))):
            s_mid = sum(a[0] for a in cluster) / len(cluster)
            rooms = tuple(sorted((a[2] for a in cluster if a[1] == "room"), key=natural_key))
            lms = tuple(sorted((a[2] for a in cluster if a[1] == "landmark"), key=natural_key))
            node_id = rooms[0] if rooms else lms[0]
            xy = a_xy + (s_mid / length) * (b_xy - a_xy)
            nodes[node_id] = MapNode(
                node_id, "room" if rooms else "landmark", (float(xy[0]), float(xy[1])), rooms, lms
            )
            graph.add_node(node_id)
            chain.append(node_id)
        chain.append(e.b)
        width = b.edge_width(e)
        along = heading(a_xy, b_xy)  # every segment's: a 0 m one (two items at one spot) too
        for u, v in pairwise(chain):
            pu, pv = nodes[u].pos, nodes[v].pos
            seg = Segment(len(segments) + 1, u, v, math.dist(pu, pv), along, (e.a, e.b), width)
            segments.append(seg)
            graph.add_edge(u, v, length=seg.length, segment=seg.index)

    places: dict[str, Place] = {}
    item_pos = {ident: p for _, ident, p in items}
    for n in nodes.values():
        for ident in n.rooms + n.landmarks:
            places[ident] = _place_of(ident, item_pos[ident], n, graph, segments, nodes)

    directions = [
        Direction(e.a, e.b, heading(wps[e.a].pos, wps[e.b].pos), float(edge_len[i]))
        for i, e in enumerate(edges)
    ]
    return PrioriMap(b, nodes, segments, directions, places, graph)


def _side(a, b, p) -> int:
    """+1 left of the centre line a->b, -1 right, 0 on it (within 5 cm)."""
    u = (b - a) / float(np.linalg.norm(b - a))
    off = u[0] * (p[1] - a[1]) - u[1] * (p[0] - a[0])
    return 0 if abs(off) < 0.05 else (1 if off > 0 else -1)


def _clusters(
    anchors: list[tuple[float, str, str, int]],
) -> list[list[tuple[float, str, str, int]]]:
    """Group anchors sorted by distance along an edge: facing doors share a node.

    An anchor joins the open group when it lies within MERGE_TOLERANCE of the group's
    first anchor and on a side of the corridor the group does not have yet, so doors
    along one wall never chain into one node however close they are.
    """
    out: list[list[tuple[float, str, str, int]]] = []
    for a in anchors:
        group = out[-1] if out else None
        if (
            group is not None
            and a[0] - group[0][0] < MERGE_TOLERANCE
            and all(g[3] != a[3] for g in group)
        ):
            group.append(a)
        else:
            out.append([a])
    return out


def _place_of(ident, pos, node: MapNode, graph, segments, nodes) -> Place:
    """The segment a room/landmark belongs to and its side, seen travelling that segment a->b."""
    segs = [segments[d["segment"] - 1] for _, _, d in graph.edges(node.id, data=True)]
    if not segs:
        return Place(node.id, 0, "left")
    # Prefer the segment that ends at the node (it is seen while approaching it).
    seg = next((s for s in segs if s.b == node.id), segs[0])
    a = nodes[seg.a].pos
    return Place(node.id, seg.index, side_of(seg.heading, a, pos))
