"""Corridor-shaped free space on a building's grid that none of its corridors reaches.

A draft that leaves a part of the building out says so in its file; ``pmnav validate``
says it again from the grid itself, for any building file with a floor-plan grid: the
grid's corridor-shaped pieces (``corridor_space``, as the draft finds them) are checked
against the file's corridors, and a piece mostly farther than its corridor's half width
plus ``REACH_SLACK_M`` from every centre line is named, with its length and where it is.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pmnav_bt.errors import PmNavError, Problem
from pmnav_bt.geometry import project_points_to_segments
from pmnav_bt.map.building import Building
from pmnav_bt.map.corridor_space import SpaceParams, corridor_space, pieces
from pmnav_bt.map.floorplan import FloorPlanImage, load_floor_plan
from pmnav_bt.map.grid import free_mask

REACH_SLACK_M = 1.0  # a cell this far past a corridor's annotated wall still counts as reached
REACHED_MIN = 0.2  # a piece with less than this fraction of its cells reached is unreached
SAMPLE_PX = 3  # every third cell each way: enough for a fraction, nine times faster


def unreached_warnings(
    b: Building, plan: FloorPlanImage, p: SpaceParams | None = None
) -> list[Problem]:
    """One warning per corridor-shaped piece of the grid that no corridor reaches."""
    if not b.edges:
        return []
    p = p or SpaceParams()
    res = plan.resolution
    _, lab = corridor_space(free_mask(plan), res, p)
    pos = {w.id: np.asarray(w.pos, float) for w in b.waypoints}
    seg_a = np.array([pos[e.a] for e in b.edges])
    seg_b = np.array([pos[e.b] for e in b.edges])
    half = np.array([b.edge_width(e) / 2.0 for e in b.edges])
    out = []
    for pc in pieces(lab, res, p):
        if not pc.corridor:
            continue
        rows, cols = np.nonzero(lab[::SAMPLE_PX, ::SAMPLE_PX] == pc.label)
        xy = plan.pixel_to_world(np.stack([cols, rows], axis=1) * SAMPLE_PX)
        if len(xy) == 0:
            continue
        j, _, dist = project_points_to_segments(xy, seg_a, seg_b)
        reached = float(np.mean(dist <= half[j] + REACH_SLACK_M))
        if reached < REACHED_MIN:
            x, y = xy.mean(axis=0)
            out.append(
                Problem(
                    "edges",
                    f"the grid has a corridor-shaped space of about {pc.length_m:.0f} m near "
                    f"({x:.1f}, {y:.1f}) that no corridor reaches ({100 * reached:.0f} % of it "
                    "within reach): add its corridors, or leave it out on purpose",
                )
            )
    return out


def unreached_warnings_of(b: Building, base_dir: str | Path) -> list[Problem]:
    """``unreached_warnings`` for a building whose floor plan is a grid; none without one."""
    if b.floor_plan is None or b.floor_plan.ros_map is None:
        return []
    try:
        plan = load_floor_plan(b, base_dir)
    except PmNavError:  # a floor plan that does not load is reported by the other checks
        return []
    return unreached_warnings(b, plan)
