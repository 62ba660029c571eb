"""Walls from an occupancy grid: the cells that bound the free space, merged into boxes.

The simulator normally builds its walls from the annotated corridor rectangles, which
tests the annotation rather than the building. With a ros_map floor plan it can build
them from the grid instead: every non-free cell next to free space (occupied walls,
and unknown cells where the scan saw nothing) becomes wall, open areas and rooms
included. Cells are merged into few boxes: runs along each image row, then runs of the
same columns in consecutive rows, so a straight wall is one box.
"""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np

from pmnav_bt.geometry import Rect
from pmnav_bt.map.floorplan import FREE, FloorPlanError, FloorPlanImage, fill_world_polygons
from pmnav_bt.map.wall_surface import grid_free_space

BAND_CELLS = 2  # wall thickness: non-free cells within this many cells of free space


def wall_cells(free: np.ndarray, band: int = BAND_CELLS) -> np.ndarray:
    """Non-free cells within ``band`` cells of a free cell (bool, rows as in the image)."""
    k = cv2.getStructuringElement(cv2.MORPH_RECT, (2 * band + 1, 2 * band + 1))
    near = cv2.dilate(free.astype(np.uint8), k).astype(bool)
    return near & ~free


def merge_cells(must: np.ndarray, may: np.ndarray | None = None) -> list[tuple[int, int, int, int]]:
    """Rectangles (row0, col0, row1, col1), ends exclusive, covering every ``must`` cell.

    Rectangles may also cover ``may`` cells (default: only ``must``), and may overlap.
    Greedy: from each uncovered cell in row order, grow right as far as allowed, then
    down while the whole span is allowed. Letting walls grow into the unknown cells
    behind them turns a ragged laser border into a few big boxes.
    """
    ok = must if may is None else (must | may)
    h, w = ok.shape
    # bad[r, c] = number of disallowed cells in row r before column c.
    bad = np.zeros((h, w + 1), np.int32)
    bad[:, 1:] = np.cumsum(~ok, axis=1)
    covered = np.zeros_like(must, dtype=bool)
    rects = []
    for r in range(h):
        todo = np.nonzero(must[r] & ~covered[r])[0]
        for c0 in todo:
            if covered[r, c0]:
                continue
            # Right: up to the first disallowed cell.
            stops = np.nonzero(~ok[r, c0:])[0]
            c1 = c0 + (int(stops[0]) if len(stops) else w - c0)
            r1 = r + 1
            while r1 < h and bad[r1, c1] - bad[r1, c0] == 0:
                r1 += 1
            covered[r:r1, c0:c1] = True
            rects.append((r, int(c0), r1, int(c1)))
    return rects


def grid_wall_boxes(plan: FloorPlanImage, band: int = BAND_CELLS, clear=()) -> list[Rect]:
    """The grid's walls as map-frame boxes (the grid must not be rotated).

    ``clear``: convex map-frame polygons whose cells count as free (kept clear of walls).
    """
    if abs(plan.origin[2]) > 1e-9:
        raise FloorPlanError(
            plan.source,
            "origin",
            f"walls from a rotated grid are not supported (yaw {plan.origin[2]})",
        )
    if len(clear):
        plan = replace(plan, image=plan.image.copy())
        fill_world_polygons(plan, list(clear), FREE)
    res = plan.resolution
    ox, oy = plan.origin[0], plan.origin[1]
    h = plan.height
    out = []
    free = grid_free_space(plan)
    for r0, c0, r1, c1 in merge_cells(wall_cells(free, band), ~free):
        # Image row r covers map y from oy + (h - 1 - r) * res to oy + (h - r) * res.
        out.append(Rect(ox + c0 * res, oy + (h - r1) * res, ox + c1 * res, oy + (h - r0) * res))
    return out
