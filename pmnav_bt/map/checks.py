"""Warnings about a valid building file: what the robot and the simulator will trip on.

A building that loads is well formed; these checks look for what makes runs fail
(``pmnav validate`` prints them; ``--strict`` makes them errors):

- a door off its corridor's annotated wall (the robot stops short of it);
- very short corridor edges, and turns back to back (no corridor to take);
- a centre line through walls or obstacles of the floor-plan grid, or a width the grid
  disagrees with;
- a door or landmark whose annotated wall is more than ``MOUNT_TOL_M`` from the grid's
  wall, or with no grid wall within reach (with ``sim.walls=grid`` the simulator hangs it
  on the grid's wall, or leaves it standing free);
- corridor stretches with fewer than two readable signs within reading range
  (localization has nothing to match there);
- a door or landmark on a wall too short for it, or two on one stretch of wall
  (``pmnav_bt.map.wall_items``: the simulator hangs them by the same placer);
- no start waypoint.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from pmnav_bt.errors import Problem
from pmnav_bt.geometry import project_points_to_segments
from pmnav_bt.map.building import Building, WaypointKind
from pmnav_bt.map.corridor_band import free_band
from pmnav_bt.map.floorplan import DOOR_WIDTH_M, FloorPlanImage, door_frames, load_floor_plan
from pmnav_bt.map.free_space import free_space_polygon, free_space_rings
from pmnav_bt.map.grid import free_mask
from pmnav_bt.map.landmark_kinds import landmark_shape
from pmnav_bt.map.wall_items import wall_item_warnings
from pmnav_bt.map.wall_surface import SEARCH_M, RealWalls, nearest_boundary_point

DOOR_OFF_WALL_M = 0.3  # a door farther than this from its annotated wall
SHORT_EDGE_M = 1.0  # an edge shorter than this (or than its width) is very short
KINK_M = 3.0  # a turn this close to another turn or fork is a kink
OFF_FREE_M = 0.3  # a centre line through this much non-free grid is off the free space
WIDTH_TOL_M = 0.5  # the grid's width may differ this much from the annotated one
SIGN_RANGE_M = 9.0  # the grounder reads signs up to this far (GrounderConfig.max_range)
MIN_SIGNS = 2  # localization needs this many readable signs in range
MIN_STRETCH_M = 2.0  # shorter sparse stretches are not reported
SAMPLE_M = 0.5  # spacing of the sample points along corridors
MOUNT_TOL_M = 0.3  # an item's annotated wall may be this far from the grid's wall
LANDMARK_HALF_M = 0.3  # half the width of a landmark's wall stretch the check looks at


def building_warnings(
    b: Building, base_dir: str | Path | None = None, plan: FloorPlanImage | None = None
) -> list[Problem]:
    """Every warning for a valid building; grid checks need ``plan`` or a loadable floor plan."""
    out = door_warnings(b) + wall_item_warnings(b) + shape_warnings(b) + sign_warnings(b)
    out += start_warnings(b)
    if plan is None and b.floor_plan is not None and base_dir is not None:
        try:
            plan = load_floor_plan(b, base_dir)
        except Exception:  # noqa: BLE001 - a floor plan that does not load is reported on load
            plan = None
    if plan is not None:
        out += grid_warnings(b, plan) + mount_warnings(b, plan)
    return out


def door_warnings(b: Building) -> list[Problem]:
    """Doors not on the annotated wall of their corridor (half its width from the centre)."""
    out = []
    index = {r.id: i for i, r in enumerate(b.rooms)}
    for f in door_frames(b):
        off = float(np.dot(np.subtract(f.door, f.foot), f.out))
        if abs(off - f.wall) > DOOR_OFF_WALL_M:
            out.append(
                Problem(
                    f"rooms[{index[f.room]}].door",
                    f"{f.room!r} is {off:.2f} m from its corridor's centre line but the annotated "
                    f"wall is at {f.wall:.2f} m (half the width): the robot stops "
                    f"{abs(off - f.wall):.2f} m from the door; put the door on the wall "
                    "or fix the corridor width",
                )
            )
    return out


def shape_warnings(b: Building) -> list[Problem]:
    """Very short edges and turns back to back."""
    out = []
    pos = {w.id: w.pos for w in b.waypoints}
    kind = {w.id: w.kind for w in b.waypoints}
    for i, e in enumerate(b.edges):
        length = math.dist(pos[e.a], pos[e.b])
        width = b.edge_width(e)
        if length < max(SHORT_EDGE_M, width):
            out.append(
                Problem(
                    f"edges[{i}]",
                    f"{e.a}-{e.b} is {length:.2f} m long, shorter than its width {width:.2f} m: "
                    "merge the two waypoints into one",
                )
            )
        elif length < KINK_M and WaypointKind.TURN in (kind[e.a], kind[e.b]):
            other = kind[e.b] if kind[e.a] == WaypointKind.TURN else kind[e.a]
            out.append(
                Problem(
                    f"edges[{i}]",
                    f"{e.a}-{e.b}: a turn {length:.2f} m from a {other.value} "
                    f"(back-to-back turns; the robot may find no corridor to take): "
                    "straighten the corridor or merge the waypoints",
                )
            )
    return out


def start_warnings(b: Building) -> list[Problem]:
    if any(w.kind == WaypointKind.START for w in b.waypoints):
        return []
    return [
        Problem(
            "waypoints",
            "no 'start' waypoint: runs start at the first waypoint; give the entrance kind: start",
        )
    ]


def _segments(b: Building):
    pos = {w.id: np.asarray(w.pos, float) for w in b.waypoints}
    a = np.array([pos[e.a] for e in b.edges])
    c = np.array([pos[e.b] for e in b.edges])
    return a, c


def _samples(a: np.ndarray, b: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    length = float(np.linalg.norm(b - a))
    s = np.linspace(0.0, length, max(2, round(length / step) + 1))
    return s, a + np.outer(s / max(length, 1e-9), b - a)


def sign_warnings(b: Building, range_m: float = SIGN_RANGE_M) -> list[Problem]:
    """Corridor stretches with fewer than MIN_SIGNS readable signs within ``range_m``.

    A sign counts for a point on a corridor when it hangs on that corridor or one
    meeting it at a waypoint, and lies within ``range_m``.
    """
    seg_a, seg_b = _segments(b)
    signs = [r.door for r in b.rooms if r.sign_text] + [
        lm.pos for lm in b.landmarks if lm.sign_text and landmark_shape(lm.kind).readable
    ]
    if signs:
        pts = np.array(signs, float)
        on, _, _ = project_points_to_segments(pts, seg_a, seg_b)
    else:
        pts, on = np.zeros((0, 2)), np.zeros(0, int)
    ends = [(e.a, e.b) for e in b.edges]
    out = []
    for i, e in enumerate(b.edges):
        near = [j for j, (x, y) in enumerate(ends) if {x, y} & {e.a, e.b}]
        mine = pts[np.isin(on, near)]
        s, xy = _samples(seg_a[i], seg_b[i], SAMPLE_M)
        if len(mine):
            count = (np.linalg.norm(xy[:, None] - mine[None], axis=2) <= range_m).sum(axis=1)
        else:
            count = np.zeros(len(s), int)
        for lo, hi in _runs(count < MIN_SIGNS):
            if s[hi - 1] - s[lo] < MIN_STRETCH_M and (lo > 0 or hi < len(s)):
                continue
            out.append(
                Problem(
                    f"edges[{i}]",
                    f"{e.a}-{e.b}, {s[lo]:.1f} to {s[hi - 1]:.1f} m from {e.a}: fewer than "
                    f"{MIN_SIGNS} readable signs within {range_m:g} m (localization may fail "
                    "there); add the signs, plates or landmarks the building has",
                )
            )
    return out


def grid_warnings(b: Building, plan: FloorPlanImage) -> list[Problem]:
    """Centre lines through non-free grid cells; widths the grid disagrees with."""
    free = free_mask(plan)  # map_server's free cells, small clutter (bins, desks) filled:
    # widths are wall to wall, the band the centre line keeps free all along (corridor_band)
    open_ = free_mask(plan, clutter_m=0.0)  # the path: clutter on the centre line blocks it
    seg_a, seg_b = _segments(b)
    out = []
    step = plan.resolution
    for i, e in enumerate(b.edges):
        s, xy = _samples(seg_a[i], seg_b[i], step)
        cell = plan.world_to_cell(xy)
        inside = (cell >= 0).all(axis=1) & (cell[:, 0] < plan.width) & (cell[:, 1] < plan.height)
        ok = np.zeros(len(s), bool)
        ok[inside] = open_[cell[inside, 1], cell[inside, 0]]
        for lo, hi in _runs(~ok):
            if (hi - lo) * step >= OFF_FREE_M:
                mid = xy[(lo + hi) // 2]
                c = cell[(lo + hi) // 2]
                if not inside[(lo + hi) // 2]:  # a grid smaller than the building
                    what, then = (
                        f"runs off the floor-plan grid ({plan.width}x{plan.height} cells, "
                        f"{plan.width * step:g} x {plan.height * step:g} m)",
                        "the grid does not cover the building; check the map's origin and "
                        "resolution",
                    )
                elif free[c[1], c[0]]:
                    what, then = (
                        "runs into an obstacle in the corridor",
                        "the robot must leave the centre line to go round it (it does when "
                        "depth shows open floor beside it); move the waypoints if they can "
                        "avoid it",
                    )
                else:
                    what, then = (
                        "leaves the grid's free space",
                        "the robot follows the centre line and stops there; move the "
                        "waypoints if they can avoid it",
                    )
                out.append(
                    Problem(
                        f"edges[{i}]",
                        f"{e.a}-{e.b} {what} for {(hi - lo) * step:.2f} m near "
                        f"({mid[0]:.2f}, {mid[1]:.2f}): {then}",
                    )
                )
        band = free_band(plan, free, seg_a[i], seg_b[i])
        if band is None or not math.isfinite(band.about_line):
            continue
        measured = band.about_line
        width = b.edge_width(e)
        if abs(measured - width) > WIDTH_TOL_M:
            out.append(
                Problem(
                    f"edges[{i}]",
                    f"{e.a}-{e.b} is annotated {width:.2f} m wide but the grid shows about "
                    f"{measured:.2f} m (the band free all along the centre line): set width: "
                    f"{measured:.2f} or move the centre line",
                )
            )
    return out


def mount_warnings(b: Building, plan: FloorPlanImage, tol: float = MOUNT_TOL_M) -> list[Problem]:
    """Doors and landmarks whose annotated wall (the corridor rectangles' side nearest
    them) is more than ``tol`` from the grid's wall, or has no grid wall within
    ``SEARCH_M`` (``pmnav_bt.map.wall_surface``, the search the simulator mounts them by)."""
    if not (b.rooms or b.landmarks):
        return []
    rings = free_space_rings(free_space_polygon(b))
    walls = RealWalls(plan)
    items = [
        (f"rooms[{i}].door", f"the door of {r.id!r} (and its sign)", r.door, DOOR_WIDTH_M / 2.0)
        for i, r in enumerate(b.rooms)
    ] + [
        (f"landmarks[{i}].pos", f"landmark {lm.id!r}", lm.pos, LANDMARK_HALF_M)
        for i, lm in enumerate(b.landmarks)
    ]
    out = []
    for field, what, pos, half in items:
        at, normal = nearest_boundary_point(rings, pos)
        m = walls.mount(at, normal, half)
        if m is None:
            out.append(
                Problem(
                    field,
                    f"{what} at ({at[0]:.2f}, {at[1]:.2f}) on its annotated wall: no stretch of "
                    f"the grid's wall within {SEARCH_M:g} m along the wall's normal; with walls "
                    "from the grid it stands free there; check the item and the corridor's width",
                )
            )
        elif m.distance > tol:
            where = "in front of" if m.offset > 0 else "behind"
            out.append(
                Problem(
                    field,
                    f"{what}: its annotated wall at ({at[0]:.2f}, {at[1]:.2f}) stands "
                    f"{m.distance:.2f} m {where} the grid's wall; with walls from the grid it "
                    "is hung on the grid's wall, with the annotated walls it floats; fix the "
                    "corridor's width or centre line",
                )
            )
    return out


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    d = np.diff(np.concatenate([[0], np.asarray(flags, int), [0]]))
    return list(zip(np.nonzero(d == 1)[0], np.nonzero(d == -1)[0], strict=True))
