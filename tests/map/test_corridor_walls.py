"""Corridor walls: a centre line between two parallel walls, and one across a room."""

from __future__ import annotations

import networkx as nx
import numpy as np

from pmnav_bt.map.corridor_walls import cut_unlined_loops, lined_share
from pmnav_bt.map.draft_links import straight_path

RES = 0.05


def _space() -> np.ndarray:
    """A 2 m corridor (rows 20..60) along a 10 m x 8 m room (rows 60..220, cols 0..200)."""
    space = np.zeros((240, 400), bool)
    space[20:60, :] = True
    space[60:220, 0:200] = True
    return space


def _dist(space: np.ndarray) -> np.ndarray:
    import cv2

    return cv2.distanceTransform(space.astype(np.uint8), cv2.DIST_L2, 5)


def test_a_corridor_is_lined_and_a_way_across_a_room_is_not():
    space = _space()
    dist = _dist(space)
    along = straight_path(np.array([40.0, 220.0]), np.array([40.0, 390.0]))
    across = straight_path(np.array([200.0, 20.0]), np.array([80.0, 180.0]))
    assert lined_share(along, space, dist, RES) > 0.9
    assert lined_share(across, space, dist, RES) < 0.5


def test_a_loop_through_a_room_is_cut_and_the_corridor_stays():
    space = _space()
    dist = _dist(space)
    # The corridor L-M-R, and a way M-X-R through the room (diagonal), joining it again.
    pts = {"L": (40, 210), "M": (40, 300), "R": (40, 390), "X": (200, 20)}
    h = nx.Graph()
    for n, rc in pts.items():
        h.add_node(n, rc=np.array(rc, float))
    for a, b in (("L", "M"), ("M", "R"), ("M", "X"), ("X", "L")):
        h.add_edge(a, b, path=straight_path(h.nodes[a]["rc"], h.nodes[b]["rc"]))
    assert cut_unlined_loops(h, space, dist, RES, 0.5) == 1
    assert h.has_edge("L", "M") and h.has_edge("M", "R")
    assert nx.is_connected(h)
