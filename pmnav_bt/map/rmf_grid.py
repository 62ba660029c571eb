"""An RMF level's walls as a ROS map_server occupancy grid (what ``sim.walls=grid`` reads).

Free cells are the level's floor polygons (or, for a level without floors, what the
lanes reach without crossing a wall); walls and **closed doors** are occupied lines
``WALL_M`` thick; everything else is unknown. Closing the doors keeps rooms out of the
corridors' free space: the corridor network is the largest free part, and the
simulator cuts each room's door opening through the grid's wall where it hangs the door.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from pmnav_bt.loading import MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE
from pmnav_bt.map.floorplan import FREE, OCCUPIED, UNKNOWN, WALL_M, FloorPlanImage
from pmnav_bt.map.rmf_read import RmfLevel

RESOLUTION_M = 0.05  # metres per grid cell, coarser only where the level is too large
MARGIN_M = 2.0  # unknown border round the level


def level_grid(level: RmfLevel) -> FloorPlanImage:
    """The level's walls, doors and floors rasterised (grey levels of map_saver)."""
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
    for link in level.walls + level.doors:
        a, b = (tuple(int(round(v)) for v in px[k]) for k in (link.a, link.b))
        cv2.line(walls, a, b, 1, thick)
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
    plan.image[walls.astype(bool)] = OCCUPIED
    return plan
