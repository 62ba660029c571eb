"""Which part of a grid's free space is corridor: the draft's first question.

A corridor is free space that is *long for its width*, whatever that width is; a door
is a *short* narrow place (a wall's thickness deep) between two wider spaces. So
the free space is cut only at short narrow places, and every piece that is long for
its width stays, not only the largest:

1. **Walkable**: the free space opened by a disc ``corridor_min_m`` wide. Slivers
   narrower than the narrowest corridor go: laser fans through open doors and
   between furniture, scan noise along walls.
2. **Doorways cut**: the space eroded by a disc ``doorway_max_m`` wide falls into
   cores, one per wide place; each core takes back the space near it. What no core
   reaches is a narrow place: no longer than ``doorway_m``, it is a doorway (or a
   pinch by a cabinet) and the space is cut there; longer, it is a narrow corridor
   and joins the places it links into one piece.
3. **Corridor-shaped pieces**: each piece gets a width W, twice the distance to its
   edge that 90 % of its ridge (the distance map's local maxima) stays under (its
   open middle, not the gaps between furniture), and a length L = area / W. A piece
   is corridor-shaped when L is at least ``corridor_ratio`` times W and at least
   ``part_min_m``: a room, a fan of laser rays through its door, a cupboard are short
   for their width and fall away.

The pieces are joined again where the draft's graph needs them
(``draft_links.link_parts``); here they are only chosen.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np


@dataclass(frozen=True)
class SpaceParams:
    """The thresholds of the corridor space, in metres (see the module docstring)."""

    corridor_min_m: float = 1.0
    doorway_max_m: float = 1.6
    doorway_m: float = 1.2
    corridor_ratio: float = 3.0
    part_min_m: float = 4.0


def _disc(r: int) -> np.ndarray:
    return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * r + 1,) * 2)


def walkable(free: np.ndarray, res: float, p: SpaceParams) -> np.ndarray:
    """The free space without slivers narrower than ``corridor_min_m``."""
    r = max(1, round(p.corridor_min_m / 2.0 / res))
    return cv2.morphologyEx(free.astype(np.uint8), cv2.MORPH_OPEN, _disc(r)).astype(bool)


def split_at_doorways(space: np.ndarray, res: float, p: SpaceParams) -> np.ndarray:
    """Label the space's pieces between doorways (int32, 0 outside every piece).

    The space eroded by a disc ``doorway_max_m`` wide falls into cores, one per wide
    place, parted wherever the space is narrower (a doorway, a pinch, a narrow
    corridor). Each core takes back the space within the disc's radius of it, up to
    where it meets its neighbour. What no core reaches is a narrow place: one whose
    skeleton is longer than ``doorway_m`` is a narrow corridor and joins the cores it
    touches into one piece; a shorter one is a doorway and is cut away.
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from skimage.morphology import skeletonize
    from skimage.segmentation import expand_labels

    r = round(p.doorway_max_m / 2.0 / res) + 1
    n_core, cores = cv2.connectedComponents(
        cv2.erode(space.astype(np.uint8), _disc(r)), connectivity=8
    )
    grown = np.where(space, expand_labels(cores, distance=r), 0)
    narrow = space & (grown == 0)
    n_nar, nar = cv2.connectedComponents(narrow.astype(np.uint8), connectivity=8)
    length = np.bincount(nar[skeletonize(narrow)], minlength=n_nar) * res
    corridor = length > p.doorway_m
    corridor[0] = False
    # Narrow corridors are nodes n_core.. of a graph whose edges join what touches.
    lab = np.where(corridor[nar], nar + n_core - 1, grown).astype(np.int64)
    lab[narrow & ~corridor[nar]] = 0
    pairs = []
    for a, b in ((lab[:, :-1], lab[:, 1:]), (lab[:-1, :], lab[1:, :])):
        touch = (a > 0) & (b > 0) & (a != b) & ((a >= n_core) | (b >= n_core))
        pairs.append(np.stack([a[touch], b[touch]], axis=1))
    e = np.concatenate(pairs) if pairs else np.zeros((0, 2), int)
    n = n_core + n_nar
    adj = coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n))
    _, group = connected_components(adj, directed=False)
    out = group[lab] + 1
    out[lab == 0] = 0
    return out.astype(np.int32)


@dataclass(frozen=True)
class Piece:
    """One piece of the space between doorways: its label, length and width (m)."""

    label: int
    length_m: float
    width_m: float
    corridor: bool


def pieces(lab: np.ndarray, res: float, p: SpaceParams) -> list[Piece]:
    """Judge every labelled piece: its length, width and whether it is corridor-shaped."""
    n = int(lab.max()) + 1
    edge = np.zeros(lab.shape, bool)
    for a, b in ((np.s_[:, :-1], np.s_[:, 1:]), (np.s_[:-1, :], np.s_[1:, :])):
        differ = lab[a] != lab[b]
        edge[a] |= differ
        edge[b] |= differ
    inner = (lab > 0) & ~edge
    dist = cv2.distanceTransform(inner.astype(np.uint8), cv2.DIST_L2, 5)
    # The ridge of the distance map (its local maxima) stands in for the skeleton.
    ridge = inner & (dist >= cv2.dilate(dist, np.ones((3, 3), np.uint8)))
    area = np.bincount(lab.ravel(), minlength=n) * res * res
    # A piece's width: twice the distance to its edge that 90 % of its ridge stays
    # under (its open middle, not the gaps between furniture); its length: area / width.
    on = lab[ridge]
    d_on = dist[ridge]
    order = np.lexsort((d_on, on))
    on, d_on = on[order], d_on[order]
    starts = np.searchsorted(on, np.arange(n))
    ends = np.searchsorted(on, np.arange(n), side="right")
    out = []
    for i in range(1, n):
        if area[i] == 0:
            continue
        d = d_on[starts[i] : ends[i]]
        width = 2.0 * float(d[int(0.9 * (len(d) - 1))]) * res if len(d) else res
        length = float(area[i]) / max(width, res)
        corridor = length >= p.corridor_ratio * width and length >= p.part_min_m
        out.append(Piece(i, length, width, corridor))
    return out


def corridor_space(free: np.ndarray, res: float, p: SpaceParams) -> tuple[np.ndarray, np.ndarray]:
    """The corridor-shaped pieces of the free space, every one kept; (mask, piece labels).

    A floor with no corridor-shaped piece (an open-plan office) keeps its largest piece:
    the draft makes it one open area.
    """
    lab = split_at_doorways(walkable(free, res, p), res, p)
    keep = np.zeros(int(lab.max()) + 1, bool)
    ps = pieces(lab, res, p)
    for pc in ps:
        keep[pc.label] = pc.corridor
    if ps and not keep.any():
        keep[max(ps, key=lambda pc: pc.length_m * pc.width_m).label] = True
    return keep[lab], lab
