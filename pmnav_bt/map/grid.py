"""The free space of an occupancy grid, and corridor widths measured in it."""

from __future__ import annotations

import cv2
import numpy as np

from pmnav_bt.map.floorplan import FloorPlanImage

CLEAN_M = 0.1  # close free-space holes smaller than this (laser speckle)
CLUTTER_M = 1.25  # fill obstacles no longer than this in free space (bins, desks)
# map_saver writes every cell it never saw in this grey (occupancy 0.196, its default
# free_thresh, so that map_server reads it unknown).
NEVER_SEEN_SHADE = 205


def free_mask(
    plan: FloorPlanImage,
    clean_m: float = CLEAN_M,
    clutter_m: float = CLUTTER_M,
    seen_only: bool = False,
) -> np.ndarray:
    """map_server's free cells (bool, rows as in the image), specks closed, largest part only.

    ``seen_only`` leaves out the cells map_saver marks never seen that a loose
    ``free_thresh`` reads free (``never_seen_free``).
    """
    occupancy = plan.occupancy()
    free = occupancy == 0
    if seen_only:
        free &= ~never_seen_free(plan, occupancy)
    free = free.astype(np.uint8)
    k = max(1, round(clean_m / plan.resolution))
    if k > 1:
        free = cv2.morphologyEx(free, cv2.MORPH_CLOSE, np.ones((k, k), np.uint8))
    free = largest_component(free)
    # Small islands of non-free cells enclosed by free space are clutter, not walls.
    n, lab, stats, _ = cv2.connectedComponentsWithStats((~free).astype(np.uint8), connectivity=8)
    h, w = free.shape
    small = clutter_m / plan.resolution
    for i in range(1, n):
        x, y, bw, bh, _ = stats[i]
        inside = x > 0 and y > 0 and x + bw < w and y + bh < h
        if inside and max(bw, bh) <= small:
            free[lab == i] = True
    return free


def never_seen_free(plan: FloorPlanImage, occupancy: np.ndarray | None = None) -> np.ndarray:
    """Cells in map_saver's never-seen grey that the map's thresholds read as free.

    map_saver saves unknown cells as ``NEVER_SEEN_SHADE``, which its default
    ``free_thresh`` (0.196) reads unknown; a map published with a looser one (the
    hospital's 0.25) reads the rooms the scanner never entered as free floor, and a
    corridor beside them as part of a hall. Only where the map also has lighter free
    cells (what was seen free): a map drawn all in that grey is left as it reads.
    ``occupancy``: the plan's, when already computed.
    """
    grey = plan.grey().round()
    free = (plan.occupancy() if occupancy is None else occupancy) == 0
    shade = free & (grey == NEVER_SEEN_SHADE)
    if not shade.any() or not (free & (grey > NEVER_SEEN_SHADE)).any():
        return np.zeros(free.shape, bool)
    return shade


def seen_mask(plan: FloorPlanImage) -> np.ndarray:
    """The non-free cells a sensor saw (walls, furniture), not those it never saw.

    A map saver writes every never-seen cell in one grey (map_saver: 205), the commonest
    shade of the non-free cells; a wall is any other non-free shade. A trinary reading
    cannot tell them apart where walls are saved as grey likelihoods (the Willow Garage
    map: only 544 cells are over its occupied threshold). A map whose commonest non-free
    shade is itself occupied (all walls, nothing unknown) has every non-free cell seen.
    """
    grey = plan.grey().round()
    other = plan.occupancy() != 0
    shades, counts = np.unique(grey[other], return_counts=True)
    if not len(shades):
        return other
    never = shades[np.argmax(counts)]
    occupancy = never / 255.0 if plan.negate else 1.0 - never / 255.0
    if occupancy > plan.occupied_thresh:
        return other
    return other & (grey != never)


def unseen_mask(plan: FloorPlanImage) -> np.ndarray:
    """The cells a sensor never saw: non-free cells not ``seen_mask`` (map_saver's grey),
    and that grey where a loose ``free_thresh`` reads it free (``never_seen_free``)."""
    return ((plan.occupancy() != 0) & ~seen_mask(plan)) | never_seen_free(plan)


def largest_component(mask: np.ndarray) -> np.ndarray:
    n, lab, stats, _ = cv2.connectedComponentsWithStats(mask.astype(np.uint8), connectivity=4)
    if n <= 1:
        return np.zeros(mask.shape, bool)
    best = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    return lab == best


def distance_map(free: np.ndarray) -> np.ndarray:
    """Per free cell, the distance (cells) to the nearest non-free cell centre."""
    return cv2.distanceTransform(free.astype(np.uint8), cv2.DIST_L2, 5)


def centre_line_width(
    plan: FloorPlanImage,
    dist: np.ndarray,
    a,
    b,
    trim_a: float = 0.0,
    trim_b: float = 0.0,
) -> float | None:
    """The corridor width along the line a-b: twice the median distance to a wall (metres).

    ``trim_a``/``trim_b`` metres at the ends are left out (junctions widen the space);
    None when fewer than 5 free cells remain.
    """
    a, b = np.asarray(a, float), np.asarray(b, float)
    length = float(np.linalg.norm(b - a))
    s = np.linspace(0.0, length, max(2, round(length / plan.resolution) + 1))
    xy = a + np.outer(s / max(length, 1e-9), b - a)
    cell = plan.world_to_cell(xy)
    keep = (s > trim_a) & (s < length - trim_b)
    keep &= (cell >= 0).all(axis=1) & (cell[:, 0] < plan.width) & (cell[:, 1] < plan.height)
    c = cell[keep]
    d = dist[c[:, 1], c[:, 0]] if len(c) else np.zeros(0)
    d = d[d > 0]
    if len(d) < 5:
        return None
    return 2.0 * (float(np.median(d)) - 0.5) * plan.resolution
