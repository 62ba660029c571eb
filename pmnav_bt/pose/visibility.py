"""Which landmarks the priori-map says are readable from a point of the corridors.

A sign is readable from a point when the straight line to it stays inside the corridors
(walls block the view) and it is no farther than ``READ_RANGE_M``. Every sign is on a
corridor wall, so the check uses a point just in front of the wall. The counts along the
corridor centre lines, on a ``LATTICE_M`` lattice, tell active localization where signs
are and class start poses by landmark density (paper, Table 3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from enum import Enum
from functools import cached_property

import networkx as nx
import numpy as np
import scipy.sparse.csgraph
import shapely

from pmnav_bt.map.landmark_kinds import landmark_shape
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.planning.resolve import entity_position
from pmnav_bt.seams import Entity

READ_RANGE_M = 9.5  # a sign is read up to about this far (checked against the sim grounder)
WALL_INSET_M = 0.3  # the sight line ends this far in front of the wall
LATTICE_M = 0.5  # spacing of the lattice points along the corridor centre lines


def entity_xy(pm: PrioriMap, entity: Entity) -> tuple[float, float]:
    """Where the map puts a room's door or a landmark's face on the wall."""
    return entity_position(pm, entity)


def map_entities(pm: PrioriMap) -> list[Entity]:
    """Every room and landmark of the building with a sign (all but fire doors)."""
    b = pm.building
    lms = [Entity.landmark(lm.id) for lm in b.landmarks if landmark_shape(lm.kind).readable]
    return [Entity.room(r.id) for r in b.rooms] + lms


class LandmarkDensity(str, Enum):
    """Start poses by the landmarks readable from them (paper, Table 3)."""

    REDUNDANT = "redundant"  # more than 2
    MINIMAL = "minimal"  # exactly 2
    SCARCE = "scarce"  # 0 or 1


def density_class(n_readable: int) -> LandmarkDensity:
    if n_readable > 2:
        return LandmarkDensity.REDUNDANT
    return LandmarkDensity.MINIMAL if n_readable == 2 else LandmarkDensity.SCARCE


@dataclass(frozen=True)
class LatticePoint:
    """A point on a corridor centre line: its segment, position and the signs readable there."""

    index: int
    segment: int  # 1-based, as in the priori-map
    xy: tuple[float, float]
    readable: frozenset[Entity]


class Visibility:
    """The map's prediction of what is readable where (built once per priori-map)."""

    def __init__(self, pm: PrioriMap, read_range: float = READ_RANGE_M, lattice: float = LATTICE_M):
        self.pm = pm
        self.read_range = read_range
        self.lattice = lattice
        self.entities = map_entities(pm)
        self._xy = np.array([entity_xy(pm, e) for e in self.entities], dtype=float).reshape(-1, 2)
        self._eye = np.array([self._inset(p) for p in self._xy]).reshape(-1, 2)

    @property
    def sign_xy(self) -> np.ndarray:
        """(N, 2) where the map puts each of ``entities``' signs."""
        return self._xy

    @property
    def sign_front(self) -> np.ndarray:
        """(N, 2) where a sight line to each of ``entities``' signs ends: ``WALL_INSET_M``
        in front of its wall, towards the corridor's centre line."""
        return self._eye

    @cached_property
    def sign_normal(self) -> np.ndarray:
        """(N, 2) unit normals of ``entities``' plates: from the wall into the corridor."""
        d = self._eye - self._xy
        n = np.linalg.norm(d, axis=1, keepdims=True)
        return np.where(n > 1e-9, d / np.maximum(n, 1e-9), 0.0)

    @classmethod
    def of(cls, pm: PrioriMap, read_range: float | None = None) -> Visibility:
        """The cached Visibility of ``pm`` for signs read to ``read_range`` (None:
        ``READ_RANGE_M``; the OCR reader's comes from perception/read_range.py)."""
        r = READ_RANGE_M if read_range is None else float(read_range)
        cache = pm.__dict__.setdefault("_visibility", {})
        v = cache.get(r)
        if v is None:
            v = cache[r] = cls(pm, read_range=r)
        return v

    @cached_property
    def corridors(self):
        """The corridor floor as one polygon (each segment buffered by half its width)."""
        pm = self.pm
        parts = [
            shapely.buffer(
                shapely.LineString([pm.nodes[s.a].pos, pm.nodes[s.b].pos]),
                s.width / 2.0,
                cap_style="square",
            )
            for s in pm.segments
        ]
        poly = shapely.union_all(parts)
        shapely.prepare(poly)
        return poly

    @cached_property
    def walls(self):
        """The corridor floor's outline: where a ray along the floor ends."""
        return self.corridors.boundary

    def _inset(self, p: np.ndarray) -> np.ndarray:
        loc = self.pm.locate(float(p[0]), float(p[1]))
        c = loc.point(self.pm)
        d = c - p
        n = float(np.linalg.norm(d))
        return c if n < 1e-6 else p + d * min(1.0, WALL_INSET_M / n)

    def readable_from(self, xy) -> frozenset[Entity]:
        """The entities whose signs can be read from ``xy`` (a full turn on the spot)."""
        p = np.asarray(xy, dtype=float)
        if not len(self.entities):
            return frozenset()
        near = np.nonzero(np.linalg.norm(self._xy - p, axis=1) <= self.read_range)[0]
        if not len(near):
            return frozenset()
        lines = shapely.linestrings(
            np.stack([np.broadcast_to(p, (len(near), 2)), self._eye[near]], 1)
        )
        ok = shapely.covers(self.corridors, lines)
        return frozenset(self.entities[i] for i, k in zip(near, ok, strict=True) if k)

    def n_readable(self, xy) -> int:
        return len(self.readable_from(xy))

    def density(self, xy) -> LandmarkDensity:
        return density_class(self.n_readable(xy))

    @cached_property
    def lattice_points(self) -> list[LatticePoint]:
        """Points every ``lattice`` metres along each segment, ends included."""
        pts: list[LatticePoint] = []
        for s in self.pm.segments:
            a, b = self.pm.node_xy(s.a), self.pm.node_xy(s.b)
            n = max(1, int(np.ceil(s.length / self.lattice)))
            for k in range(n + 1):
                xy = a + (b - a) * (k / n)
                pts.append(
                    LatticePoint(
                        len(pts), s.index, (float(xy[0]), float(xy[1])), self.readable_from(xy)
                    )
                )
        return pts

    @cached_property
    def lattice_xy(self) -> np.ndarray:
        return np.array([p.xy for p in self.lattice_points], dtype=float)

    @cached_property
    def lattice_graph(self) -> nx.Graph:
        """Lattice points joined along each segment, and wherever two lie on one spot (nodes)."""
        g = nx.Graph()
        pts = self.lattice_points
        for p in pts:
            g.add_node(p.index)
        for p, q in zip(pts, pts[1:], strict=False):
            if p.segment == q.segment:
                g.add_edge(p.index, q.index, length=float(np.hypot(*np.subtract(p.xy, q.xy))))
        xy = self.lattice_xy
        tree = shapely.STRtree(shapely.points(xy))
        for i, j in tree.query(shapely.points(xy), predicate="dwithin", distance=1e-3).T:
            if i < j:
                g.add_edge(int(i), int(j), length=0.0)
        return g

    @cached_property
    def _lattice_csgraph(self):
        """The lattice graph as a sparse matrix for scipy's shortest paths (its explicit
        zeros, two points on one spot, are edges there)."""
        n = len(self.lattice_points)
        return nx.to_scipy_sparse_array(
            self.lattice_graph, nodelist=range(n), weight="length", format="csr"
        )

    def distances_between(self, points) -> np.ndarray:
        """Corridor distance (m) between every pair of the lattice points ``points``
        (inf where not connected), shape (len(points), len(points))."""
        idx = np.asarray(points, dtype=int)
        d = scipy.sparse.csgraph.dijkstra(self._lattice_csgraph, directed=False, indices=idx)
        return d[:, idx]

    @cached_property
    def exits(self) -> list[list[tuple[float, float]]]:
        """For each lattice point: (map heading, corridor distance to signs) of every way
        out of it (two mid-corridor, more at a junction, one at a dead end); infinite for
        a way whose nearest signs lie back through the point."""
        dist, nxt = self.towards_signs
        out: list[list[tuple[float, float]]] = []
        for j in range(len(self.lattice_xy)):
            group = self._group(j)
            ways = {}
            for k, length, h in self._ways_out(group):
                key = round(h, 2)
                # The nearest signs that way, unless the way there comes back (a dead end).
                d = length + dist.get(k, math.inf) if nxt.get(k) not in group else math.inf
                ways[key] = min(ways.get(key, math.inf), d)
            out.append(sorted(ways.items()))
        return out

    def _group(self, m: int) -> set[int]:
        """Lattice point ``m`` and the points on the same spot (a node's segment ends)."""
        g = self.lattice_graph
        return {m} | {k for k in g[m] if g[m][k]["length"] == 0.0}

    def _ways_out(self, group: set[int]):
        """Each step out of a ``_group``: the next lattice point, the distance to it and
        its map heading."""
        g, xy = self.lattice_graph, self.lattice_xy
        for a in group:
            for k in g[a]:
                length = g[a][k]["length"]
                if length == 0.0 or k in group:
                    continue
                yield k, length, math.atan2(xy[k][1] - xy[a][1], xy[k][0] - xy[a][0])

    @cached_property
    def run_lengths(self) -> list[dict[float, float]]:
        """For each lattice point and way out (keyed like ``exits``): how far straight on
        to the next junction or corridor end."""
        out: list[dict[float, float]] = []
        for j in range(len(self.lattice_xy)):
            runs = {}
            for key, _ in self.exits[j]:
                runs[key] = max((d for _, d in self._run(j, key)), default=0.0)
            out.append(runs)
        return out

    def _step(self, m: int, key: float) -> tuple[int, float] | None:
        """The next lattice point from ``m`` along the way out keyed ``key`` (map heading,
        as in ``exits``) and the distance to it; None at a corridor end."""
        for k, length, h in self._ways_out(self._group(m)):
            if abs(math.remainder(h - key, 2 * math.pi)) < 0.05:
                return k, length
        return None

    def _run(self, j: int, key: float):
        """The lattice points (and distances) from ``j`` straight on along way ``key`` up
        to the next junction or corridor end, which is the last."""
        d, m = 0.0, j
        while (nxt := self._step(m, key)) is not None:
            m, d = nxt[0], d + nxt[1]
            yield m, d
            if len(self.exits[m]) != 2:
                break

    def nearest_lattice(self, xy) -> int:
        return int(self.nearest_many(np.asarray(xy, dtype=float).reshape(1, 2))[0][0])

    @cached_property
    def _lattice_tree(self):
        return shapely.STRtree(shapely.points(self.lattice_xy))

    def lattice_within(self, xy: np.ndarray, distance: float) -> np.ndarray:
        """(2, K) pairs (index into ``xy``, lattice point) of every lattice point within
        ``distance`` of each of the (N, 2) points ``xy``."""
        return self._lattice_tree.query(
            shapely.points(xy), predicate="dwithin", distance=distance
        )

    def nearest_many(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """For (N, 2) points: the nearest lattice point of each and the distance to it."""
        pairs, dist = self._lattice_tree.query_nearest(
            shapely.points(xy), all_matches=False, return_distance=True
        )
        idx = np.empty(len(xy), dtype=int)
        out = np.empty(len(xy))
        idx[pairs[0]] = pairs[1]
        out[pairs[0]] = dist
        return idx, out

    @cached_property
    def towards_signs(self) -> tuple[dict[int, float], dict[int, int]]:
        """For each lattice point: the corridor distance to the nearest point where at least
        two signs are readable, and the next lattice point on the way there."""
        g = self.lattice_graph
        good = [p.index for p in self.lattice_points if len(p.readable) >= 2]
        if not good:
            return {}, {}
        dist, paths = nx.multi_source_dijkstra(g, good, weight="length")
        nxt = {i: (path[-2] if len(path) > 1 else i) for i, path in paths.items()}
        return dist, nxt

    def distance_to(self, target: tuple[float, float]) -> dict[int, float]:
        """Corridor distance from each lattice point to the one nearest ``target`` (map)."""
        key = (round(float(target[0]), 2), round(float(target[1]), 2))
        cache = self.__dict__.setdefault("_distance_to", {})
        if key not in cache:
            cache[key] = nx.single_source_dijkstra_path_length(
                self.lattice_graph, self.nearest_lattice(key), weight="length"
            )
        return cache[key]

    def via_signs_to(self, target: tuple[float, float]) -> dict[int, float]:
        """For each lattice point: the corridor distance to ``target`` (map) by way of a
        point where at least two signs are readable (the robot finds where it is, then goes
        on): the least, over such points, of the way there plus the way on to the target."""
        to_target = self.distance_to(target)
        good = [
            p.index for p in self.lattice_points if len(p.readable) >= 2 and p.index in to_target
        ]
        if not good:
            return {}
        g = self.lattice_graph.copy()
        src = -1  # joined to each sign point by the way on from it to the target
        for i in good:
            g.add_edge(src, i, length=float(to_target[i]))
        dist = nx.single_source_dijkstra_path_length(g, src, weight="length")
        dist.pop(src)
        return dist

    def exits_to(self, target: tuple[float, float]) -> list[dict[float, float]]:
        """For each lattice point and way out (keyed like ``exits``): the corridor distance
        to ``target`` (map) for a robot that goes that way and first finds where it is:
        the least of reading signs on the way straight on and going on to the target from
        there, or going on to the next junction or corridor end and from there by way of
        the best signs (``via_signs_to``, which may lead back)."""
        key = (round(float(target[0]), 2), round(float(target[1]), 2))
        cache = self.__dict__.setdefault("_exits_to", {})
        if key in cache:
            return cache[key]
        to_target, via = self.distance_to(key), self.via_signs_to(key)
        pts = self.lattice_points
        out: list[dict[float, float]] = []
        for j in range(len(pts)):
            ways = {}
            for way, _ in self.exits[j]:
                best = math.inf
                m, d = j, 0.0
                for m, d in self._run(j, way):
                    if len(pts[m].readable) >= 2:
                        best = min(best, d + to_target.get(m, math.inf))
                if m != j:
                    best = min(best, d + via.get(m, math.inf))
                ways[way] = best
            out.append(ways)
        cache[key] = out
        return out
