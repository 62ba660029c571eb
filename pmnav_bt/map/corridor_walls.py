"""Whether a drafted corridor runs between two walls parallel to it.

A corridor is long, and bounded by two roughly parallel walls: stand anywhere on its
centre line and look square to it, and the wall on each side is about as far as it is
everywhere else along it (a door, a junction or a notice board breaks that for a
metre). A skeleton's branch through a room does not: it runs diagonally across the
room, or round its furniture, and the walls either side come nearer or go farther as
one walks along it (the hospital's I-shaped rooms and its south-east room, Willow's
cluttered offices); a laser fan's rays diverge from the door they came through.

``lined_share`` measures it for one piece of centre line: along the straight line fitted
to the piece, rays square to it on both sides find the first cell that is not corridor
space; a side is *lined* at a sample when its distance is within ``WALL_TOL_M`` of that
side's median distance. The share is the mean, over both sides, of the samples that
are lined. The draft (``draft.prune_unlined``) removes the corridors of its loops, and
its dead ends, whose (length-weighted) share stays under ``--lined-min``.

``walled_share`` asks what those walls are: a corridor's walls are obstacles the scanner
saw, on both sides; the free space a laser fan throws through an open door, or a room
seen only through its doorway, fades into space never seen on at least one side. Rays
square to the piece stop at the first cell that is not free; a side *fades* there when
that cell was never seen (``grid.unseen_mask``), and the piece's share is the share of
its samples where neither side fades. The draft (``draft.prune_fans``) removes the dead ends
whose (length-weighted) share is under ``--wall-min``.
"""

from __future__ import annotations

import networkx as nx
import numpy as np

# A wall counts as the same wall when this close to its median distance: SLAM walls are
# drawn a cell or two thick and wander by about as much, and the fitted line is within
# the draft's Douglas-Peucker tolerance of the skeleton.
WALL_TOL_M = 0.25
# Rays look this many times the piece's median half width (and at least 1 m) for a wall:
# a wall farther than that is across a room, not the corridor's.
REACH = 3.0
SAMPLE_M = 0.2  # one look square to the line every this far along it


def lined_share(path: np.ndarray, space: np.ndarray, dist: np.ndarray, res: float) -> float:
    """The share (0..1) of a centre-line piece's sides lined by a wall parallel to it.

    ``path`` is the piece's pixel (row, col) points; ``space`` the corridor space rays
    stop at; ``dist`` the free space's distance map (pixels), which gives the half width.
    The first and last half width of the piece (junctions and ends, where walls turn)
    are left out; a piece too short for that is judged on its middle pixel.
    """
    pts, normal, steps = _samples(path, dist, res)
    tol = WALL_TOL_M / res
    shares = []
    for side in (1.0, -1.0):
        p = (pts[:, None, :] + side * steps[None, :, None] * normal).round().astype(int)
        inside = (p >= 0).all(axis=2) & (p[..., 0] < space.shape[0]) & (p[..., 1] < space.shape[1])
        pc = np.clip(p, 0, np.array(space.shape) - 1)
        open_ = inside & space[pc[..., 0], pc[..., 1]]
        blocked = ~open_
        hit = blocked.any(axis=1)
        d = np.where(hit, np.argmax(blocked, axis=1) + 1.0, np.inf)
        if not hit.any():
            shares.append(0.0)
            continue
        med = float(np.median(d[hit]))
        shares.append(float(np.mean(np.abs(d - med) <= tol)))
    return float(np.mean(shares))


def _samples(path: np.ndarray, dist: np.ndarray, res: float):
    """The fitted line of a centre-line piece: sample points every ``SAMPLE_M`` (the first
    and last half width left out, or the middle alone for a short piece), its normal, and
    the ray steps (pixels) out to ``REACH`` half widths (at least 1 m)."""
    path = np.asarray(path, float)
    rc = np.clip(path.round().astype(int), 0, np.array(dist.shape) - 1)
    half = max(float(np.median(dist[rc[:, 0], rc[:, 1]])), 1.0)
    c = path.mean(axis=0)
    _, _, vt = np.linalg.svd(path - c) if len(path) >= 2 else (None, None, np.eye(2))
    u = vt[0]
    t = (path - c) @ u
    lo, hi = float(t.min()) + half, float(t.max()) - half
    step = max(1.0, SAMPLE_M / res)
    ts = np.arange(lo, hi + 1e-9, step) if hi > lo else np.array([(t.min() + t.max()) / 2.0])
    reach = max(REACH * half, 1.0 / res)
    return c + ts[:, None] * u, np.array([-u[1], u[0]]), np.arange(1.0, reach + 1.0)


def walled_share(
    path: np.ndarray, free: np.ndarray, unseen: np.ndarray, dist: np.ndarray, res: float
) -> float:
    """The share (0..1) of a centre-line piece where neither side fades into space never seen.

    Rays square to the piece's fitted line (``_samples``) stop at the first cell that is
    not ``free``; a side fades at a sample when that cell is ``unseen`` (or off the grid):
    the free space there ends where the scanner stopped seeing, not at a wall. A side
    open beyond reach (a doorway into a room, a hall) is no evidence either way and does
    not fade: a hospital corridor lined with open rooms is still walled.
    """
    pts, normal, steps = _samples(path, dist, res)
    fades = np.zeros(len(pts), bool)
    shape = np.array(free.shape)
    k = np.arange(len(pts))
    for side in (1.0, -1.0):
        p = (pts[:, None, :] + side * steps[None, :, None] * normal).round().astype(int)
        inside = (p >= 0).all(axis=2) & (p < shape).all(axis=2)
        pc = np.clip(p, 0, shape - 1)
        blocked = ~(inside & free[pc[..., 0], pc[..., 1]])
        hit = blocked.any(axis=1)
        first = np.argmax(blocked, axis=1)
        at = pc[k, first]
        fades |= hit & (~inside[k, first] | unseen[at[:, 0], at[:, 1]])
    return float(1.0 - fades.mean())


def edge_walled(
    h: nx.Graph, u, v, free: np.ndarray, unseen: np.ndarray, dist: np.ndarray, res: float
) -> float:
    """``walled_share`` of the corridor u-v's pixel path, kept on the edge once measured."""
    d = h.edges[u, v]
    if "walled" not in d:
        d["walled"] = walled_share(d["path"], free, unseen, dist, res)
    return d["walled"]


def edge_share(h: nx.Graph, u, v, space: np.ndarray, dist: np.ndarray, res: float) -> float:
    """``lined_share`` of the corridor u-v's pixel path, kept on the edge once measured."""
    d = h.edges[u, v]
    if "lined" not in d:
        d["lined"] = lined_share(d["path"], space, dist, res)
    return d["lined"]


def cut_unlined_loops(
    h: nx.Graph, space: np.ndarray, dist: np.ndarray, res: float, lined_min: float
) -> int:
    """Remove the corridors on loops that no parallel walls line, weakest first.

    A corridor on a loop (removing it leaves the network joined) goes when its share is
    under ``lined_min``: a way through a room with two openings onto corridors (one of
    the hospital's I-shaped rooms), a ring round an office's furniture. What is left
    of the way is a dead end, for the dead-end rule to judge. Returns how many went.
    """
    gone = 0
    while True:
        bridges = {frozenset(e) for e in nx.bridges(h)}
        weak = [
            (s, u, v)
            for u, v in h.edges
            if u != v
            and frozenset((u, v)) not in bridges
            and (s := edge_share(h, u, v, space, dist, res)) < lined_min
        ]
        if not weak:
            return gone
        _, u, v = min(weak, key=lambda x: x[0])
        h.remove_edge(u, v)
        gone += 1
