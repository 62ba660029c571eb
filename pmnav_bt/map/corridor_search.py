"""Shortest ways along a level's corridors: Dijkstra over a priori-map's segments, and the
tree of shortest ways to a lift's lobby that a site map keeps for each lobby.

A plan across levels asks every level the same questions again and again: how far is each
lift's lobby from here, how far is it from that lobby to the goal room, or to another
lift's lobby? The corridors do not change between plans, so one search from each lobby
over its whole level answers all of them for good (``LobbyTree``): the metres from every
node to the lobby and, for each node, the next node on its way there. A plan then costs
a lookup per lobby, not a search per plan. Only a start level whose corridors the robot
has found blocked needs a search of its own (``CorridorSearch`` with ``blocked``).
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

from pmnav_bt.map.priori_map import PrioriMap

INF = float("inf")


class CorridorSearch:
    """Dijkstra on a level's map from several sources, each with a starting (cost, metres),
    over corridor lengths, never over a segment of ``blocked``. ``dist``: the cost of each
    node settled; ``length``: its metres; ``pred``: the node it was reached from (None at
    a source). The cost may carry a tie-break on top of the metres (a source the robot
    faces costs a hair less), so the two are kept apart."""

    def __init__(
        self,
        pm: PrioriMap,
        sources: dict[str, tuple[float, float]],
        blocked: frozenset[int] = frozenset(),
    ):
        self.heap = [(c, n) for n, (c, _) in sources.items()]
        heapq.heapify(self.heap)
        self.best = {n: c for n, (c, _) in sources.items()}
        self.length = {n: m for n, (_, m) in sources.items()}
        self.pred: dict[str, str | None] = dict.fromkeys(sources)
        self.dist: dict[str, float] = {}
        self.adj = pm.adjacency
        self.blocked = blocked

    def run(self, targets: set[str] | None = None) -> CorridorSearch:
        """Settle nodes, nearest first, until every node of ``targets`` is settled or none
        can be reached (every node it can reach, with None)."""
        heap, dist, best, length, pred = self.heap, self.dist, self.best, self.length, self.pred
        adj, blocked = self.adj, self.blocked
        left = None if targets is None else set(targets) - set(dist)
        while heap and (left is None or left):
            c, n = heapq.heappop(heap)
            if n in dist:
                continue
            dist[n] = c
            for m, (metres, segment) in adj[n].items():
                nc = c + metres
                if nc < best.get(m, INF) and m not in dist and segment not in blocked:
                    best[m] = nc
                    length[m] = length[n] + metres
                    pred[m] = n
                    heapq.heappush(heap, (nc, m))
            if left is not None:
                left.discard(n)
        return self

    def path(self, node: str) -> list[str]:
        """The nodes from ``node`` back to the source it was reached from."""
        out = [node]
        while self.pred[out[-1]] is not None:
            out.append(self.pred[out[-1]])
        return out


@dataclass(frozen=True)
class LobbyTree:
    """The shortest ways from every node of a level to one lobby's node: ``dist`` the
    metres to it (a node the lobby cannot be reached from is absent), ``toward`` the next
    node on the way (None at the lobby). The corridors are undirected, so the way from the
    lobby to a node is the way back, reversed."""

    node: str
    dist: dict[str, float]
    toward: dict[str, str | None]

    @classmethod
    def grow(cls, pm: PrioriMap, node: str) -> LobbyTree:
        """One search from ``node`` over its whole level."""
        search = CorridorSearch(pm, {node: (0.0, 0.0)}).run()
        return cls(node, search.dist, search.pred)

    def way(self, node: str) -> list[str]:
        """The nodes from ``node`` to the lobby, both included."""
        out, toward = [node], self.toward
        while toward[out[-1]] is not None:
            out.append(toward[out[-1]])
        return out
