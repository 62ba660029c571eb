"""Joining the draft's corridor graph: open halls as hubs, and parts apart joined to the rest.

The graph here is the draft's straight-piece graph: nodes carry ``rc`` (row, col pixel
floats), edges a pixel ``path``. A new corridor is a straight line of pixels, and is
only drawn where every pixel along it is free space (a robot can drive it).
"""

from __future__ import annotations

import cv2
import networkx as nx
import numpy as np

LINK_STEP_PX = 5  # a link may end at every fifth pixel along a corridor
FREE_ALONG = 0.97  # a straight link needs this fraction of its pixels free (scan speckle)


def straight_path(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Pixel (row, col) points from ``a`` to ``b``, about one a pixel."""
    n = max(2, int(np.ceil(np.linalg.norm(b - a))) + 1)
    return np.linspace(a, b, n)


def free_along(free: np.ndarray, a: np.ndarray, b: np.ndarray) -> bool:
    """Whether the straight line a-b runs through free space."""
    p = straight_path(a, b).round().astype(int)
    p = np.clip(p, 0, np.array(free.shape) - 1)
    return float(free[p[:, 0], p[:, 1]].mean()) >= FREE_ALONG


def hall_hubs(h: nx.Graph, open_mask: np.ndarray, free: np.ndarray, dist: np.ndarray) -> int:
    """Each open area becomes one waypoint with a straight corridor to each of its exits.

    The hub sits at the area's most open point (farthest from any wall); an exit is a
    corridor end (or a corridor waypoint) within two pixels of the area, joined when
    the line to the hub is free. Returns the number of hubs added.
    """
    n, lab = cv2.connectedComponents(open_mask.astype(np.uint8), connectivity=8)
    grown = cv2.dilate(lab.astype(np.float32), np.ones((5, 5), np.uint8)).astype(int)
    added = 0
    nxt = max(h.nodes, default=-1) + 1
    for i in range(1, n):
        inside = lab == i
        masked = np.where(inside, dist, 0.0)
        hub = np.array(np.unravel_index(int(np.argmax(masked)), masked.shape), float)
        exits = []
        for m, d in h.nodes(data=True):
            r, c = np.clip(d["rc"].round().astype(int), 0, np.array(lab.shape) - 1)
            if grown[r, c] == i and h.degree(m) <= 1 and free_along(free, d["rc"], hub):
                exits.append(m)
        if len(exits) < 2:
            continue
        h.add_node(nxt, rc=hub)
        for m in exits:
            h.add_edge(nxt, m, path=straight_path(hub, h.nodes[m]["rc"]))
        nxt += 1
        added += 1
    return added


def _length(h: nx.Graph, nodes) -> float:
    return sum(len(d["path"]) for _, _, d in h.subgraph(nodes).edges(data=True))


def _places(h: nx.Graph, nodes: set, step: int) -> tuple[np.ndarray, list]:
    """Points of a part where a link may start or end: its waypoints, and every ``step``-th
    pixel along its corridors; (points (N, 2), what each is: a node, or (edge, index))."""
    pts, what = [], []
    for m in nodes:
        pts.append(h.nodes[m]["rc"])
        what.append(m)
    for u, v, d in h.subgraph(nodes).edges(data=True):
        for k in range(step, len(d["path"]) - step, step):
            pts.append(d["path"][k])
            what.append(((u, v), k))
    return np.array(pts, float), what


def _split_edge(h: nx.Graph, u, v, k: int, new) -> None:
    """Put node ``new`` on edge u-v at its path's pixel ``k``."""
    path = h.edges[u, v]["path"]
    if np.linalg.norm(path[0] - h.nodes[u]["rc"]) > np.linalg.norm(path[-1] - h.nodes[u]["rc"]):
        path = path[::-1]
        k = len(path) - 1 - k
    h.remove_edge(u, v)
    h.add_node(new, rc=path[k].astype(float))
    h.add_edge(u, new, path=path[: k + 1])
    h.add_edge(new, v, path=path[k:])


def _best_link(h: nx.Graph, part: set, main: set, free: np.ndarray, link_max_px: float):
    """The shortest free straight link between ``part`` and ``main``: the two places it
    joins (a node, or (edge, path index) to split), or None."""
    from scipy.spatial import cKDTree

    step = LINK_STEP_PX
    a_pts, a_what = _places(h, part, step)
    b_pts, b_what = _places(h, main, step)
    near = cKDTree(a_pts).sparse_distance_matrix(cKDTree(b_pts), link_max_px, output_type="ndarray")
    for i, j, _ in sorted(near.tolist(), key=lambda r: r[2]):
        if free_along(free, a_pts[int(i)], b_pts[int(j)]):
            return a_what[int(i)], b_what[int(j)]
    return None


def link_parts(
    h: nx.Graph, free: np.ndarray, link_max_px: float
) -> list[tuple[np.ndarray, float]]:
    """Join every part apart to the largest by its shortest free straight link.

    A link runs between waypoints or points along corridors of the two (a new waypoint
    splits a corridor where a link meets it). Parts are joined largest first, each to
    whatever is joined already; a part with no free straight link up to ``link_max_px`` long is
    removed. Returns per removed part its mean pixel (row, col) and length in pixels.
    """
    parts = sorted(nx.connected_components(h), key=lambda c: -_length(h, c))
    if len(parts) <= 1:
        return []
    main = set(parts[0])
    waiting = [set(p) for p in parts[1:]]
    nxt = max(h.nodes) + 1
    changed = True
    while changed and waiting:
        changed = False
        for part in list(waiting):
            best = _best_link(h, part, main, free, link_max_px)
            if best is None:
                continue
            ends = []
            for place in best:
                if isinstance(place, tuple):  # the middle of a corridor: split it there
                    (u, v), k = place
                    _split_edge(h, u, v, k, nxt)
                    place, nxt = nxt, nxt + 1
                ends.append(place)
            m, target = ends
            h.add_edge(m, target, path=straight_path(h.nodes[m]["rc"], h.nodes[target]["rc"]))
            main |= part | set(ends)
            waiting.remove(part)
            changed = True
    left = []
    for part in waiting:
        left.append((np.mean([h.nodes[m]["rc"] for m in part], axis=0), _length(h, part)))
        h.remove_nodes_from(part)
    return left
