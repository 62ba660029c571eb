"""Import one level of an Open-RMF building as a building file (``pmnav map import-rmf``).

What comes across, and from where (``docs/import-rmf.md`` has the details and limits):

- the scale and the map frame from the level's measurements (``rmf_read``: RMF's world
  frame, y up, so y = -pixel row x scale);
- the walls as a map_server grid beside the output, named in ``floor_plan.ros_map``, so
  ``--set sim.walls=grid`` works at once (``rmf_grid``);
- corridors from the lanes, centred and measured in the grid (``rmf_corridors``);
- a room per named door on a corridor (its name the door's, its door the door's centre,
  which lies in the wall the door is in);
- a landmark per named vertex on a corridor (kind ``sign``: a name plate on the real wall
  nearest it, ``rmf_places``; none on an open floor) and per lift door on this level
  (kind ``elevator``);
- the start at a dead end next to a charger or a robot's spawn point, else the dead end
  nearest an outside door.

Everything left out is listed with its reason in ``Imported.skipped``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pmnav_bt.errors import BuildingFileError, PmNavError
from pmnav_bt.geometry import project_points_to_segments
from pmnav_bt.loading import atomic_write_text, image_size
from pmnav_bt.map.building import (
    DOOR_REACH_SLACK,
    MAX_TEXT_CHARS,
    SCHEMA_VERSION,
    Building,
    building_from_data,
    dump_building,
)
from pmnav_bt.map.floorplan import FloorPlanImage, load_image_plan, save_ros_map
from pmnav_bt.map.grid import largest_component
from pmnav_bt.map.rmf_corridors import Corridors, lane_corridors, measure_widths
from pmnav_bt.map.rmf_grid import level_grid, passage_doors
from pmnav_bt.map.rmf_places import PLACE_WALL_M, plate_on_wall
from pmnav_bt.map.rmf_read import RmfLevel, param, read_level
from pmnav_bt.map.rmf_spurs import LIFT_PAST_M, PAST_M, add_spur, turn_at_door
from pmnav_bt.map.wall_surface import RealWalls

START_REACH_M = 3.0  # a dead end this near a charger or spawn point is the start
MIN_DOOR_M = 0.3  # a door narrower than this is a drawing slip
MAX_ID = 64  # the building format's id length
# A lift door this far beyond its corridor's wall (half its width off the centre line) is
# on the wall still (the corridors' widths are medians, the drawing's walls wander).
LIFT_OFF_WALL_M = 0.1


class RmfImportError(PmNavError):
    """The RMF level holds nothing this project can use as corridors."""


@dataclass
class Imported:
    """The imported level: building data, the validated building, its grid, what was skipped."""

    data: dict
    building: Building
    grid: FloorPlanImage
    level: RmfLevel
    skipped: list[str]
    named_doors: int
    cut_lanes: int
    spurs: int  # short corridors added to reach doors off the lanes
    lift_landmarks: dict[str, list[str]] = field(default_factory=dict)  # RMF lift -> ids


def import_rmf(path: str | Path, out: str | Path, level: str | None = None) -> Imported:
    """Import ``level`` of the RMF building at ``path`` for a building file at ``out``.

    Nothing is written (see ``write_import``); the building is validated against the
    grid that ``write_import`` puts beside ``out``.
    """
    lvl = read_level(path, level)
    plan = level_grid(lvl)
    passages = passage_doors(lvl, plan)
    if passages:
        plan = level_grid(lvl, passages)
    free = largest_component(plan.occupancy() == 0)
    cor = lane_corridors(lvl, plan, free)
    if len(cor.edges) == 0:
        raise RmfImportError(
            f"{path}: level {lvl.name}: no lane runs inside the walls' free space; "
            "the import needs the level's lanes to find its corridors"
        )
    skipped = list(cor.skipped)
    doors = _doors(lvl, passages, skipped)
    lift_doors = [(ld, np.asarray(ld.pos), ld.along) for ld in lvl.lift_doors if ld.cabin]
    spurs = _add_spurs(cor, plan, free, doors, lift_doors)
    measure_widths(cor, plan)  # the corridors a spur's foot split, measured part by part
    ids: set[str] = set()
    names = _waypoint_names(cor, lvl, _entrances(lvl, plan), skipped, ids)
    seg_a = np.array([cor.pos[u] for u, _, _ in cor.edges])
    seg_b = np.array([cor.pos[v] for _, v, _ in cor.edges])
    half = np.array([w / 2.0 for _, _, w in cor.edges])

    def reach(pt, what: str, tail: str = "") -> bool:
        j, _, d = project_points_to_segments(np.asarray(pt, float)[None], seg_a, seg_b)
        limit = half[j[0]] + DOOR_REACH_SLACK
        if d[0] > limit:
            skipped.append(
                f"{what}: not on a corridor ({d[0]:.2f} m from the nearest centre line; "
                f"at most {limit:.2f} m{tail})"
            )
            return False
        return True

    rooms = []
    for d, centre, _ in doors:
        if reach(centre, f"door {d.name!r}", "; no spur along the free space reaches it"):
            rid = _unique_id(d.name, ids)
            plate = room_plate(d.name)
            rooms.append({"id": rid, "name": plate, "door": _r(centre), "sign": plate})
    door_names = {d.name for d in lvl.doors if d.name}
    walls = RealWalls(plan)
    landmarks = []
    for i, name in enumerate(lvl.names):
        if not name:
            continue
        if name in door_names:
            skipped.append(f"vertex {name!r}: named like a door (the room is the door's)")
        elif _is_start_point(lvl.vparams[i]):
            continue
        elif (plate := _place_plate(walls, lvl.xy[i], name, skipped)) is not None and reach(
            plate, f"vertex {name!r}"
        ):
            lid = _unique_id(name, ids)
            landmarks.append(
                {"id": lid, "kind": "sign", "name": _words(name), "pos": _r(plate),
                 "sign": _words(name)}
            )
    lift_landmarks: dict[str, list[str]] = {}
    for ld in lvl.lift_doors:
        if reach(ld.pos, f"lift {ld.lift!r} door {ld.door!r}"):
            lid = _unique_id(ld.lift, ids)
            lift_landmarks.setdefault(ld.lift, []).append(lid)
            landmarks.append(
                {"id": lid, "kind": "elevator", "name": _words(ld.lift), "pos": _r(ld.pos),
                 "sign": _words(ld.lift)}
            )
    ros_map = Path(out).stem + "_walls.yaml"
    widths = [w for *_, w in cor.edges]
    data = {
        "schema_version": SCHEMA_VERSION,
        "name": _ident(f"{Path(path).name.split('.')[0]}_{lvl.name}"),
        "kind": "building",
        "description": (
            f"Imported from the Open-RMF building {Path(path).name}, level {lvl.name}, "
            "by 'pmnav map import-rmf'."
        ),
        "corridor_width": round(float(np.median(widths)), 2),
        "floor_plan": {"ros_map": ros_map},
        "waypoints": [
            {"id": names[n], "kind": _kind(cor, n, names), "pos": _r(cor.pos[n])}
            for n in sorted(cor.pos, key=lambda n: names[n])
        ],
        "edges": [{"from": names[u], "to": names[v], "width": w} for u, v, w in cor.edges],
        "rooms": rooms,
        "landmarks": landmarks,
    }
    try:
        b = building_from_data(data, str(out), None)
    except BuildingFileError as err:
        raise RmfImportError(
            f"{path}: level {lvl.name}: the imported building does not validate: "
            f"{err.problems[0]}"
        ) from None
    return Imported(
        data, b, plan, lvl, skipped, len(door_names), cor.cuts, spurs, lift_landmarks
    )


def write_import(imp: Imported, out: str | Path) -> Path:
    """Write the building file and its grid (``<stem>_walls.yaml`` + ``.pgm``) beside it."""
    out = Path(out)
    save_ros_map(imp.grid, out.parent / imp.data["floor_plan"]["ros_map"])
    head = [
        f"# Imported by 'pmnav map import-rmf' from {imp.level.source} level {imp.level.name}.",
        "# Ids are the RMF names; names and plates their words (a room's without 'door').",
        "# Check the signs and the start.",
    ]
    return atomic_write_text(out, "\n".join(head) + "\n" + dump_building(imp.building))


def drawing_plan(imp: Imported) -> FloorPlanImage | None:
    """The level's drawing placed in the map frame (None when the file is not there)."""
    if imp.level.drawing is None:
        return None
    path = Path(imp.level.source).parent / imp.level.drawing
    if not path.is_file():
        return None
    _, h = image_size(path)
    s = imp.level.scale
    # RMF's pixel coordinates run from the drawing's top-left corner (0, 0), y down: its
    # bottom-left corner (0, h) lies at map (0, -h * scale).
    return load_image_plan(path, s, (0.0, -h * s))


# -- doors -------------------------------------------------------------------------------


def _doors(lvl: RmfLevel, passages: frozenset[int], skipped: list[str]) -> list:
    """(door, centre, direction along its wall) of each named door that may be a room."""
    out = []
    for i, d in enumerate(lvl.doors):
        if not d.name:
            skipped.append(f"doors[{i}]: no name")
        elif i in passages:
            skipped.append(f"door {d.name!r}: a passage between corridors (left open)")
        elif np.linalg.norm(lvl.xy[d.b] - lvl.xy[d.a]) < MIN_DOOR_M:
            skipped.append(f"door {d.name!r}: shorter than {MIN_DOOR_M} m, not a door")
        else:
            a, b = lvl.xy[d.a], lvl.xy[d.b]
            out.append((d, (a + b) / 2.0, b - a))
    return out


def _place_plate(walls: RealWalls, place, name: str, skipped: list[str]):
    """Where the plate of the named place at ``place`` hangs (``rmf_places``), or None,
    listed as skipped, on an open floor."""
    plate, _ = plate_on_wall(walls, place)
    if plate is None:
        skipped.append(
            f"vertex {name!r}: on an open floor, no wall within {PLACE_WALL_M:g} m to hang "
            "its plate on"
        )
    return plate


def _entrances(lvl: RmfLevel, plan: FloorPlanImage) -> list[np.ndarray]:
    """The centres of the doors with free floor on one side and the outside (unknown
    cells, beyond every floor) on the other."""
    occ = plan.occupancy()
    out = []
    for d in lvl.doors:
        a, b = lvl.xy[d.a], lvl.xy[d.b]
        length = float(np.linalg.norm(b - a))
        if length < MIN_DOOR_M:
            continue
        mid = (a + b) / 2.0
        n = np.array([a[1] - b[1], b[0] - a[0]]) / length
        cells = plan.world_to_cell(np.array([mid + n * 0.35, mid - n * 0.35]))
        cells = np.clip(cells, 0, [plan.width - 1, plan.height - 1])
        if sorted(int(occ[r, c]) for c, r in cells) == [-1, 0]:
            out.append(mid)
    return out


def _add_spurs(
    cor: Corridors, plan: FloorPlanImage, free: np.ndarray, doors: list, lift_doors: list
) -> int:
    """Turns in front of the doors a dead end runs into, then spurs to the doors beyond
    reach of every centre line, nearest first; how many of both.

    A lift's door gets its spur (its lobby) unless it is on a corridor's wall already:
    the simulator hangs the lift's doors and frame (``ELEVATOR.span_m``) centred on the
    wall at the door, with its cabin behind, so a lift door a little off the wall (a
    corridor narrower in the drawing's centre-line model than at the lift, or a lane run
    on into the cabin) would hang elsewhere, where its shaft is not."""

    def gap(centre, slack: float) -> float:
        """How far ``centre`` is beyond reach of the nearest centre line (``slack`` past
        its corridor's wall): above 0, it needs a spur."""
        seg_a = np.array([cor.pos[u] for u, _, _ in cor.edges])
        seg_b = np.array([cor.pos[v] for _, v, _ in cor.edges])
        j, _, d = project_points_to_segments(np.asarray(centre)[None], seg_a, seg_b)
        return float(d[0] - cor.edges[j[0]][2] / 2.0 - slack)

    slack = [DOOR_REACH_SLACK] * len(doors) + [LIFT_OFF_WALL_M] * len(lift_doors)
    past = [PAST_M] * len(doors) + [LIFT_PAST_M] * len(lift_doors)
    doors = doors + lift_doors
    added = sum(
        turn_at_door(cor, plan, free, c, along, past[k]) for k, (_, c, along) in enumerate(doors)
    )
    far = sorted((gap(c, slack[k]), k) for k, (_, c, _) in enumerate(doors))
    for g, k in far:
        if g > 0 and gap(doors[k][1], slack[k]) > 0:
            added += add_spur(cor, plan, free, doors[k][1], doors[k][2], past[k])
    return added


# -- names -------------------------------------------------------------------------------


def _is_start_point(params: dict) -> bool:
    return bool(param(params, "is_charger")) or bool(param(params, "spawn_robot_name"))


def _waypoint_names(
    cor: Corridors, lvl: RmfLevel, entrances: list, skipped: list[str], ids: set
) -> dict:
    """start, endN, turnN, branchN; the start at the dead end nearest a charger or spawn
    point, else nearest an entrance (else any named door)."""
    deg = {n: 0 for n in cor.pos}
    for u, v, _ in cor.edges:
        deg[u] += 1
        deg[v] += 1
    ends = [n for n in cor.pos if deg[n] == 1]
    start = None
    chargers = [i for i, p in enumerate(lvl.vparams) if _is_start_point(p)]
    for i in chargers:
        near = min(ends, key=lambda n: np.linalg.norm(cor.pos[n] - lvl.xy[i]), default=None)
        if near is not None and np.linalg.norm(cor.pos[near] - lvl.xy[i]) <= START_REACH_M:
            start = near
            skipped.append(f"vertex {lvl.names[i]!r}: a charger or spawn point: the start")
            break
        skipped.append(
            f"vertex {lvl.names[i]!r}: a charger or spawn point with no dead end within "
            f"{START_REACH_M:g} m (not the start)"
        )
    if start is None and ends:
        outside = entrances or [(lvl.xy[d.a] + lvl.xy[d.b]) / 2.0 for d in lvl.doors if d.name]
        what = "an entrance (a door to the outside)" if entrances else "a named door"

        def to_door(n) -> float:
            return min((float(np.linalg.norm(cor.pos[n] - p)) for p in outside), default=0.0)

        start = min(ends, key=to_door)
        skipped.append(f"start: no charger or spawn point at a dead end; the dead end nearest "
                       f"{what} is the start (check it)")
    order = sorted(cor.pos, key=lambda n: (-round(cor.pos[n][1], 1), round(cor.pos[n][0], 1)))
    names, counts = {}, {"end": 0, "turn": 0, "branch": 0}
    for n in order:
        if n == start:
            names[n] = "start"
        else:
            kind = "end" if deg[n] == 1 else "turn" if deg[n] == 2 else "branch"
            counts[kind] += 1
            names[n] = f"{kind}{counts[kind]}"
        ids.add(names[n])
    return names


def _kind(cor: Corridors, n, names: dict) -> str:
    if names[n] == "start":
        return "start"
    deg = sum((u == n) + (v == n) for u, v, _ in cor.edges)
    return {1: "end", 2: "turn"}.get(deg, "branch")


def _ident(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", text).strip("_")[:MAX_ID] or "item"


def _unique_id(name: str, ids: set) -> str:
    base = _ident(name)
    rid, k = base, 2
    while rid in ids:
        tail = f"_{k}"
        rid, k = base[: MAX_ID - len(tail)] + tail, k + 1
    ids.add(rid)
    return rid


def _text(name: str) -> str:
    return name[:MAX_TEXT_CHARS]


def _words(name: str) -> str:
    """An RMF name as a sign reads: 'L1_left_consult_rm_3' -> 'left consult rm 3'."""
    text = re.sub(r"^L\d+_", "", name).replace("_", " ").strip()
    return _text(text or name)


def room_plate(door_name: str) -> str:
    """What the plate by an imported door shows, and so the room's name: the RMF door's
    name in words, less the word "door" ('coe_door' -> 'coe', 'L1_left_consult_rm_3_outer'
    -> 'left consult rm 3 outer').

    An RMF door name is an identifier for the fleet (it names the door, and most end in
    "door"); a building prints what is behind the door. Kept, the word would be on every
    plate, and a plate read in part ('oor') would fit every room alike. A name that is only
    "door" keeps it. The room's id stays the RMF name (what RMF's door requests use)."""
    words = _words(door_name).split()
    kept = [w for w in words if w.casefold() not in ("door", "doors")]
    return _text(" ".join(kept or words))


def _r(p) -> list[float]:
    return [round(float(p[0]), 3), round(float(p[1]), 3)]
