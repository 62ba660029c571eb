"""A floor-plan drawing (PNG/JPEG of an architect's plan) read as an occupancy grid.

A drawing shows walls as dark lines on light paper, and much else in the same ink: room
names, furniture, door swings, dimension lines, hatching. Reading it as a grid:

1. **Ink**: pixels darker than the paper (Otsu's threshold on the grey image, so a
   scan's grey paper and a clean export both work), plus transparent pixels as paper.
2. **Small marks dropped**: ink drawings no larger than ``mark_m`` across that touch
   no wall (letters, chairs, symbols) are paper again; walls are long connected lines.
3. **Walls closed**: small gaps in the lines (a scan's breaks, a dashed outline) are
   closed by ``gap_m``, so the free space does not leak through them.
4. **Cells**: a drawing finer than ``GRID_M`` a pixel is shrunk to it, a cell being
   wall where any of its pixels is.
5. **Outside**: the paper round the building, reached from the image's border through
   gaps wider than a door, is unknown, not free (the building's inside is what the
   draft reads; an entrance as wide as a door keeps the street out).

Door swings drawn as arcs close their doorways, as closed doors do; furniture touching
a wall stays an obstacle. The grid is then drafted like a SLAM map.
"""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np

from pmnav_bt.errors import PmNavError
from pmnav_bt.map.floorplan import FREE, OCCUPIED, UNKNOWN, FloorPlanImage, read_image

MARK_M = 1.0  # ink drawings no larger than this across, touching no wall, are not walls
GAP_M = 0.1  # gaps in wall lines up to this are closed
DOOR_M = 1.6  # the street enters through gaps wider than this only
# The grid's cell: a SLAM map's usual 5 cm. A finer drawing is read at full detail for its
# walls, then shrunk (a cell is wall where any of its pixels is): the draft's time grows
# with the cells, and finer cells find nothing more.
GRID_M = 0.05


class DrawingError(PmNavError):
    """A drawing or its scale cannot be used."""


def scale_from_points(spec: str) -> float:
    """Metres per pixel from ``"X1,Y1,X2,Y2,METRES"``: two pixels and their real distance."""
    try:
        x1, y1, x2, y2, d = (float(v) for v in spec.split(","))
    except ValueError as err:
        raise DrawingError(
            f"--scale-from {spec!r}: expected X1,Y1,X2,Y2,METRES (two pixels and their distance)"
        ) from err
    px = math.hypot(x2 - x1, y2 - y1)
    if px <= 0 or not d > 0 or not math.isfinite(d):
        raise DrawingError(f"--scale-from {spec!r}: the points must differ and METRES be > 0")
    return d / px


def _disc(r: int) -> np.ndarray:
    return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1,) * 2)


def ink_mask(img: np.ndarray) -> np.ndarray:
    """The drawing's dark pixels (bool); transparent pixels are paper."""
    if img.ndim == 3 and img.shape[2] == 4:
        alpha = img[:, :, 3:4].astype(float) / 255.0
        rgb = img[:, :, :3].astype(float) * alpha + 255.0 * (1.0 - alpha)
        grey = rgb.mean(axis=2).astype(np.uint8)
    elif img.ndim == 3:
        grey = img[:, :, :3].mean(axis=2).astype(np.uint8)
    else:
        grey = img
    _, ink = cv2.threshold(grey, 0, 1, cv2.THRESH_BINARY_INV + cv2.THRESH_OTSU)
    return ink.astype(bool)


def wall_mask(ink: np.ndarray, res: float, mark_m: float = MARK_M, gap_m: float = GAP_M):
    """The walls: ink without the small marks, its small gaps closed."""
    n, lab, stats, _ = cv2.connectedComponentsWithStats(ink.astype(np.uint8), connectivity=8)
    big = np.maximum(stats[:, cv2.CC_STAT_WIDTH], stats[:, cv2.CC_STAT_HEIGHT]) * res > mark_m
    big[0] = False
    walls = big[lab].astype(np.uint8)
    k = max(1, round(gap_m / res))
    return cv2.morphologyEx(walls, cv2.MORPH_CLOSE, _disc(k)).astype(bool)


def outside_mask(walls: np.ndarray, res: float, door_m: float = DOOR_M) -> np.ndarray:
    """The paper round the building: reached from the border through gaps wider than a door."""
    r = round(door_m / 2.0 / res) + 1
    free = (~walls).astype(np.uint8)
    core = cv2.erode(free, _disc(r))
    n, lab = cv2.connectedComponents(core, connectivity=4)
    border = np.unique(np.concatenate([lab[0], lab[-1], lab[:, 0], lab[:, -1]]))
    out = np.isin(lab, border[border > 0]).astype(np.uint8)
    return cv2.dilate(out, _disc(r)).astype(bool) & ~walls


def drawing_plan(path: str | Path, scale_m_per_px: float) -> FloorPlanImage:
    """The drawing at ``path`` as a map_server grid (free, walls, unknown outside)."""
    if not (scale_m_per_px > 0 and math.isfinite(scale_m_per_px)):
        raise DrawingError(
            f"--scale must be a positive number of metres per pixel, not {scale_m_per_px!r}"
        )
    img = read_image(path)
    walls = wall_mask(ink_mask(img), scale_m_per_px)
    if not walls.any():
        raise DrawingError(f"{path}: no wall lines found (is it a floor plan drawing?)")
    res = scale_m_per_px
    if res < GRID_M:
        f = GRID_M / res
        size = (max(1, round(walls.shape[1] / f)), max(1, round(walls.shape[0] / f)))
        walls = cv2.resize(walls.astype(np.float32), size, interpolation=cv2.INTER_AREA) > 0
        res = scale_m_per_px * walls_scale(img.shape, walls.shape)
    grid = np.full(walls.shape, FREE, np.uint8)
    grid[walls] = OCCUPIED
    grid[outside_mask(walls, res)] = UNKNOWN
    return FloorPlanImage(grid, res, (0.0, 0.0, 0.0), source=str(path))


def walls_scale(before: tuple[int, ...], after: tuple[int, ...]) -> float:
    """How many pixels of the drawing one cell spans (the mean of both axes)."""
    return (before[0] / after[0] + before[1] / after[1]) / 2.0
