"""Where the plate of an imported RMF named place hangs: on the real wall nearest it.

An RMF named place (a vertex with a name: ``pantry``, ``patrol_D1``) is a spot on the
floor the fleet sends robots to; the import makes it a name plate, and a plate hangs on
a wall. The building file's landmark point is where the plate is, both for the robot's
map (a sign read there fixes the pose) and for the simulator (which hangs an item whose
point lies in a real wall there). So the point goes onto the grid's wall nearest the
place, just inside its face; a place with no wall within ``PLACE_WALL_M`` stands on an
open floor, where no plate would hang, and is left out. (Kept at the place, its plate
hung on the corridors' outline up to 2.7 m from it, on the imported office: read there,
it put the robot metres from where it was.)
"""

from __future__ import annotations

import numpy as np

from pmnav_bt.map.wall_surface import RealWalls

PLACE_WALL_M = 1.5  # a wall farther from a place than this is not the one its plate is on
RAYS = 72  # directions looked along for the nearest wall (5 deg apart)


def plate_on_wall(walls: RealWalls, place) -> tuple[np.ndarray | None, float]:
    """The point, one grid cell inside the face of the real wall nearest ``place``, where
    its plate hangs, and that wall's distance; (None, distance) when it is farther than
    ``PLACE_WALL_M`` (inf: none in reach)."""
    p = np.asarray(place, float)
    step = walls.plan.resolution / 2.0
    r = np.arange(0.0, PLACE_WALL_M + 1e-9, step)
    angles = np.linspace(0.0, 2.0 * np.pi, RAYS, endpoint=False)
    ways = np.stack([np.cos(angles), np.sin(angles)], 1)
    free = walls.free_at(p[None, None, :] + r[None, :, None] * ways[:, None, :])
    hit = ~free
    first = np.where(hit.any(axis=1), hit.argmax(axis=1), len(r))
    k = int(np.argmin(first))
    if first[k] == len(r):
        return None, float("inf")
    d = float(r[first[k]])
    if d == 0.0:
        return p, 0.0  # the place is drawn in the wall itself
    return p + ways[k] * (d + walls.plan.resolution), d
