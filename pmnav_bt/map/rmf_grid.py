"""An RMF level's walls as a ROS map_server occupancy grid (what ``sim.walls=grid`` reads).

Free cells are the level's floor polygons (or, for a level without floors, what the
lanes reach without crossing a wall); walls and **closed doors** are occupied lines
``WALL_M`` thick, and so is a ring round the free space (a floor ends at a wall, drawn in
the file or not); everything else is unknown. Closing the doors keeps rooms out of the
corridors' free space: the corridor network is the largest free part, and the
simulator cuts each room's door opening through the grid's wall where it hangs the door.
"""

from __future__ import annotations

import math

import cv2
import networkx as nx
import numpy as np

from pmnav_bt.loading import MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE
from pmnav_bt.map.floorplan import FREE, OCCUPIED, UNKNOWN, WALL_M, FloorPlanImage
from pmnav_bt.map.rmf_read import RmfLevel

RESOLUTION_M = 0.05  # metres per grid cell, coarser only where the level is too large
MARGIN_M = 2.0  # unknown border round the level
SIDE_M = 0.35  # a door's two sides are looked at this far from it
PASSAGE_DOORS = 3  # a part behind a door with this many doors is a corridor, not a room
PASSAGE_LANE_M = 5.0  # ... and one where the lanes run on this far


def level_grid(level: RmfLevel, open_doors: frozenset[int] = frozenset()) -> FloorPlanImage:
    """The level's walls, doors and floors rasterised (grey levels of map_saver).

    The doors whose indices are in ``open_doors`` (passages) are left open.
    """
    pts = [level.xy] + [np.array([d.pos for d in level.lift_doors]).reshape(-1, 2)]
    allp = np.vstack(pts)
    lo, hi = allp.min(axis=0) - MARGIN_M, allp.max(axis=0) + MARGIN_M
    span = hi - lo
    res = max(
        RESOLUTION_M,
        float(span.max()) / (MAX_IMAGE_SIDE - 1),
        math.sqrt(float(span[0] * span[1]) / (MAX_IMAGE_PIXELS * 0.9)),
    )
    w, h = (int(math.ceil(v / res)) for v in span)
    plan = FloorPlanImage(
        np.full((h, w), UNKNOWN, np.uint8), res, (float(lo[0]), float(lo[1]), 0.0),
        source=f"<walls of {level.source} level {level.name}>",
    )
    px = plan.world_to_pixel(level.xy)
    walls = np.zeros((h, w), np.uint8)
    thick = max(2, round(WALL_M / res))
    doors = [d for i, d in enumerate(level.doors) if i not in open_doors]
    for link in level.walls + doors:
        a, b = (tuple(int(round(v)) for v in px[k]) for k in (link.a, link.b))
        cv2.line(walls, a, b, 1, thick)
    shafts = [np.array(d.cabin) for d in level.lift_doors if d.cabin]
    if shafts:
        cv2.polylines(walls, [np.rint(plan.world_to_pixel(c)).astype(np.int32) for c in shafts],
                      True, 1, thick)
    inside = np.zeros((h, w), np.uint8)
    if level.floors:
        polys = [np.rint(px[f]).astype(np.int32) for f in level.floors if len(f) >= 3]
        cv2.fillPoly(inside, polys, 1)
    else:  # no floors drawn: what the lanes reach without crossing a wall
        seeds = {k for link in level.lanes for k in (link.a, link.b)}
        mask = np.zeros((h + 2, w + 2), np.uint8)
        mask[1:-1, 1:-1] = walls
        for k in sorted(seeds):
            c, r = (int(round(v)) for v in px[k])
            if 0 <= r < h and 0 <= c < w and not walls[r, c] and not inside[r, c]:
                cv2.floodFill(inside, mask, (c, r), 1, flags=4 | (1 << 8))
    plan.image[inside.astype(bool)] = FREE
    # A floor ends at a wall, drawn in the file or not: a wall's thickness off its edge is
    # occupied, not unknown (a grid's unknown beside free space is where a scanner
    # stopped seeing, which a draft reads as a laser fan).
    ring = np.ones((2 * thick + 1, 2 * thick + 1), np.uint8)
    edge = cv2.dilate(inside, ring).astype(bool) & ~inside.astype(bool)
    plan.image[edge | walls.astype(bool)] = OCCUPIED
    return plan


def passage_doors(level: RmfLevel, plan: FloorPlanImage) -> frozenset[int]:
    """Doors a lane runs through from the largest free part into a corridor: into the
    largest part again (a door across a corridor), or into a part where the lanes run on
    for ``PASSAGE_LANE_M`` or more, or that has ``PASSAGE_DOORS`` or more doors (a corridor
    behind a fire door, a clinic's back-of-house corridor). A lane into a room stops a few
    metres in, at a parking spot. These doors are left open, so the corridor behind joins
    the network; the other doors stay closed.
    """
    occ = (plan.occupancy() == 0).astype(np.uint8)
    _, lab = cv2.connectedComponents(occ, connectivity=4)
    sizes = np.bincount(lab.ravel())
    sizes[0] = 0
    main = int(np.argmax(sizes))
    sides = []
    for d in level.doors:
        a, b = level.xy[d.a], level.xy[d.b]
        mid, along = (a + b) / 2.0, b - a
        n = np.array([-along[1], along[0]]) / max(float(np.linalg.norm(along)), 1e-9)
        sides.append(tuple(_labels(plan, lab, np.array([mid + n * SIDE_M, mid - n * SIDE_M]))))
    doors_of = nx.Graph()  # part -> doors on its boundary
    for i, (p, q) in enumerate(sides):
        for part in {p, q} - {0}:
            doors_of.add_edge(("part", part), i)
    lane_m = _lane_length_per_part(level, plan, lab)
    out = set()
    for i, d in enumerate(level.doors):
        p, q = sides[i]
        if main not in (p, q) or 0 in (p, q) or not _lane_crosses(level, d):
            continue
        other = q if p == main else p
        if (
            other == main
            or lane_m.get(other, 0.0) >= PASSAGE_LANE_M
            or doors_of.degree(("part", other)) >= PASSAGE_DOORS
        ):
            out.add(i)
    return frozenset(out)


def _labels(plan: FloorPlanImage, lab: np.ndarray, pts: np.ndarray) -> list[int]:
    cells = plan.world_to_cell(pts)
    ok = (cells >= 0).all(axis=1) & (cells[:, 0] < plan.width) & (cells[:, 1] < plan.height)
    return [int(lab[c[1], c[0]]) if k else 0 for c, k in zip(cells, ok, strict=True)]


def _lane_length_per_part(level: RmfLevel, plan: FloorPlanImage, lab: np.ndarray) -> dict:
    """Metres of lane inside each free part."""
    step = plan.resolution
    out: dict[int, float] = {}
    for ln in level.lanes:
        a, b = level.xy[ln.a], level.xy[ln.b]
        n = max(2, int(np.linalg.norm(b - a) / step))
        for part in _labels(plan, lab, a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)):
            out[part] = out.get(part, 0.0) + float(np.linalg.norm(b - a)) / n
    return out


def _lane_crosses(level: RmfLevel, door) -> bool:
    r, s = level.xy[door.a], level.xy[door.b]
    return any(_segments_cross(level.xy[ln.a], level.xy[ln.b], r, s) for ln in level.lanes)


def _segments_cross(p, q, r, s) -> bool:
    def side(a, b, c) -> float:
        return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    return side(p, q, r) * side(p, q, s) < 0 and side(r, s, p) * side(r, s, q) < 0
