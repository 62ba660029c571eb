"""The building file: rooms, doors, signs, corridor key waypoints and edges, landmarks.

One YAML file describes a functional building for both the priori-map (planning)
and the simulator (the world). Loading validates the structure (pydantic: unknown
keys, bad numbers) and then the meaning (duplicate IDs, edges to unknown
waypoints, rooms no corridor reaches, disconnected corridors), and reports every
problem with its file and field.

Coordinates are metres in the map frame (x east, y north).
"""

from __future__ import annotations

import math
from enum import Enum
from functools import cached_property
from pathlib import Path
from typing import Annotated, Any

import networkx as nx
import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from pmnav_bt.errors import BuildingFileError, Problem
from pmnav_bt.geometry import project_points_to_segments
from pmnav_bt.loading import (
    InputFileError,
    atomic_write_text,
    image_size,
    is_regular_file,
    load_yaml,
)
from pmnav_bt.map.amenities import Amenity
from pmnav_bt.map.signage import Signage, signage_problems

SCHEMA_VERSION = 1
SITE_VERSION = 1  # a site file's (map/site.py): here, below the site's readers and writers

# What a building can plausibly be (docs/building-format.md, "Limits"): beyond these a
# file is a mistake or an attack, and rendering or simulating it would exhaust memory.
MAX_COORD_M = 1000.0  # |x|, |y| of any point
MAX_WIDTH_M = 50.0  # corridor width
MAX_WALL_HEIGHT_M = 20.0
MAX_WAYPOINTS = 2000
MAX_EDGES = 4000
# Rooms: the planner's scale target (benchmarks/bench_plan.py plans on 10,000 rooms). A real
# building has that many: the largest hospital, Zhengzhou University's First Affiliated
# Hospital, reports over 10,000 beds (2022), with its wards, offices and labs besides.
MAX_ROOMS = 10_000
MAX_LANDMARKS = 5000
MAX_ALIASES = 32
MAX_ID_CHARS = 64
MAX_TEXT_CHARS = 200  # names, signs, aliases, kinds, file names
MAX_DESCRIPTION_CHARS = 2000

# Numbers are strict: "1" or true is not a number.
Finite = Annotated[float, Field(allow_inf_nan=False, strict=True)]
Coord = Annotated[float, Field(allow_inf_nan=False, strict=True, ge=-MAX_COORD_M, le=MAX_COORD_M)]
Point = tuple[Coord, Coord]
Ident = Annotated[str, Field(min_length=1, max_length=MAX_ID_CHARS, strict=True)]
Text = Annotated[str, Field(max_length=MAX_TEXT_CHARS, strict=True)]
Width = Annotated[float, Field(allow_inf_nan=False, strict=True, gt=0, le=MAX_WIDTH_M)]

# A door may be this far beyond the corridor wall and still count as reached.
DOOR_REACH_SLACK = 1.0


class WaypointKind(str, Enum):
    """Key waypoint kinds of the paper: start, turn, branch (fork), end."""

    START = "start"
    TURN = "turn"
    BRANCH = "branch"
    END = "end"


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Waypoint(_Strict):
    """A key waypoint on the corridor centre line."""

    id: Ident
    kind: WaypointKind
    pos: Point


class Edge(_Strict):
    """A straight corridor between two key waypoints; ``width`` overrides the building default."""

    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True)

    a: Ident = Field(alias="from")
    b: Ident = Field(alias="to")
    width: Width | None = None

    @model_validator(mode="before")
    @classmethod
    def _from_pair(cls, data: Any) -> Any:
        # Shorthand in YAML: "- [start, turn1]".
        if isinstance(data, (list, tuple)):
            if len(data) != 2:
                raise ValueError("an edge is [from, to] or {from: ..., to: ..., width: ...}")
            return {"from": data[0], "to": data[1]}
        return data


class _Named:
    """What people call a room or landmark (``name`` or ``id``), and what its sign reads."""

    @property
    def display_name(self) -> str:
        return self.name or self.id

    @property
    def sign_text(self) -> str:
        """The text on its sign plate (defaults to the display name)."""
        return self.sign or self.display_name


class Room(_Named, _Strict):
    """A room behind a door on a corridor. ``door`` is the door centre, in the corridor wall."""

    id: Ident
    name: Text = ""
    aliases: tuple[Text, ...] = Field(default=(), max_length=MAX_ALIASES)
    door: Point
    sign: Text = ""
    amenity: Amenity | None = None  # toilet (a pictogram plate); unset: by the name (amenities)


class Landmark(_Named, _Strict):
    """A non-room landmark (elevator, stairs, reception desk, a named sign ...)."""

    id: Ident
    kind: Annotated[Text, Field(min_length=1)]
    name: Text = ""
    aliases: tuple[Text, ...] = Field(default=(), max_length=MAX_ALIASES)
    pos: Point
    sign: Text = ""


class FloorPlan(_Strict):
    """An optional floor plan: an image with its scale, or a ROS map_server YAML.

    ``origin`` is the map-frame position of the image's bottom-left corner (the ROS
    map_server convention). Paths are relative to the building file.
    """

    image: Annotated[Text, Field(min_length=1)] | None = None
    metres_per_pixel: Annotated[Finite, Field(ge=0.001, le=10.0)] | None = None
    origin: Point = (0.0, 0.0)
    ros_map: Annotated[Text, Field(min_length=1)] | None = None

    @model_validator(mode="after")
    def _one_source(self) -> FloorPlan:
        if (self.image is None) == (self.ros_map is None):
            raise ValueError("give either 'image' (with 'metres_per_pixel') or 'ros_map'")
        if self.image is not None and self.metres_per_pixel is None:
            raise ValueError("'image' needs 'metres_per_pixel'")
        return self


class Building(_Strict):
    """A functional building: the content of one building file."""

    schema_version: Annotated[int, Field(strict=True)]
    name: Annotated[Text, Field(min_length=1)]
    kind: Text = "building"
    description: Annotated[str, Field(max_length=MAX_DESCRIPTION_CHARS, strict=True)] = ""
    corridor_width: Width = 2.4
    wall_height: Annotated[Finite, Field(gt=0, le=MAX_WALL_HEIGHT_M)] = 3.0
    floor_plan: FloorPlan | None = None
    waypoints: tuple[Waypoint, ...] = Field(max_length=MAX_WAYPOINTS)
    edges: tuple[Edge, ...] = Field(max_length=MAX_EDGES)
    rooms: tuple[Room, ...] = Field(default=(), max_length=MAX_ROOMS)
    landmarks: tuple[Landmark, ...] = Field(default=(), max_length=MAX_LANDMARKS)
    signage: Signage | None = None  # how the signs look (pmnav_bt.map.signage)

    @field_validator("schema_version")
    @classmethod
    def _known_version(cls, v: int) -> int:
        if v != SCHEMA_VERSION:
            raise ValueError(
                f"this version of pmnav reads schema_version {SCHEMA_VERSION}, not {v}"
            )
        return v

    # -- lookups ------------------------------------------------------------------------

    def waypoint(self, wid: str) -> Waypoint:
        return self._waypoint_index[wid]

    def room(self, rid: str) -> Room:
        return self._room_index[rid]

    def landmark(self, lid: str) -> Landmark:
        return self._landmark_index[lid]

    def edge_width(self, edge: Edge) -> float:
        return edge.width if edge.width is not None else self.corridor_width

    @cached_property
    def _waypoint_index(self) -> dict[str, Waypoint]:
        return {w.id: w for w in self.waypoints}

    @cached_property
    def _room_index(self) -> dict[str, Room]:
        return {r.id: r for r in self.rooms}

    @cached_property
    def _landmark_index(self) -> dict[str, Landmark]:
        return {lm.id: lm for lm in self.landmarks}

    def corridor_graph(self) -> nx.Graph:
        """Key waypoints as nodes, corridors as edges weighted by length (metres)."""
        g = nx.Graph()
        pos = {w.id: w.pos for w in self.waypoints}
        for w in self.waypoints:
            g.add_node(w.id, kind=w.kind)
        for e in self.edges:
            if e.a in pos and e.b in pos:
                g.add_edge(e.a, e.b, length=math.dist(pos[e.a], pos[e.b]))
        return g

    # -- serialisation ------------------------------------------------------------------

    def to_dict(self) -> dict[str, Any]:
        """Plain data in the file's layout (edges as {from, to[, width]})."""
        d = self.model_dump(mode="json", by_alias=True, exclude_defaults=True)
        d["schema_version"] = self.schema_version
        d["edges"] = [
            [e.a, e.b] if e.width is None else {"from": e.a, "to": e.b, "width": e.width}
            for e in self.edges
        ]
        return d


# -- loading ---------------------------------------------------------------------------


def _loc(loc: tuple) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part in ("function-before[_from_pair()]", "function-after[_one_source()]"):
            continue
        else:
            out += ("." if out else "") + str(part)
    return out


def pydantic_problems(err: ValidationError) -> list[Problem]:
    problems = []
    for e in err.errors():
        msg = e["msg"]
        if e["type"] == "extra_forbidden":
            msg = "unknown key (check the spelling; see docs/building-format.md)"
        elif e["type"] == "missing":
            msg = "required key is missing"
        elif msg.startswith("Value error, "):
            msg = msg[len("Value error, ") :]
        got = e.get("input")
        if e["type"] not in ("missing", "extra_forbidden") and not isinstance(got, (dict, list)):
            shown = repr(got)
            msg += f" (got {shown if len(shown) <= 60 else shown[:57] + '...'})"
        problems.append(Problem(_loc(e["loc"]), msg))
    return problems


def semantic_problems(b: Building, base_dir: Path | None = None) -> list[Problem]:
    """Problems of meaning in a structurally valid building."""
    problems: list[Problem] = []
    if len(b.waypoints) < 2:
        problems.append(Problem("waypoints", "a building needs at least 2 key waypoints"))
    if not b.edges:
        problems.append(Problem("edges", "a building needs at least 1 corridor edge"))
    # IDs share one namespace: plan steps name waypoints, rooms and landmarks alike.
    where: dict[str, list[str]] = {}
    for group, items in (
        ("waypoints", b.waypoints),
        ("rooms", b.rooms),
        ("landmarks", b.landmarks),
    ):
        for i, item in enumerate(items):
            where.setdefault(item.id, []).append(f"{group}[{i}]")
    for ident, places in where.items():
        if len(places) > 1:
            problems.append(
                Problem(f"{places[1]}.id", f"duplicate id {ident!r} (also at {places[0]})")
            )

    wps = b._waypoint_index
    seen_edges: dict[frozenset, int] = {}
    for i, e in enumerate(b.edges):
        for end, field in ((e.a, "from"), (e.b, "to")):
            if end not in wps:
                problems.append(Problem(f"edges[{i}].{field}", f"unknown waypoint {end!r}"))
        if e.a == e.b:
            problems.append(Problem(f"edges[{i}]", f"edge joins {e.a!r} to itself"))
            continue
        key = frozenset((e.a, e.b))
        if key in seen_edges:
            problems.append(
                Problem(
                    f"edges[{i}]", f"duplicate edge {e.a}-{e.b} (also edges[{seen_edges[key]}])"
                )
            )
        seen_edges.setdefault(key, i)
        if e.a in wps and e.b in wps and math.dist(wps[e.a].pos, wps[e.b].pos) < 0.05:
            problems.append(Problem(f"edges[{i}]", f"{e.a!r} and {e.b!r} are at the same position"))

    g = b.corridor_graph()
    for i, w in enumerate(b.waypoints):
        deg = g.degree(w.id)
        want = {
            WaypointKind.START: "exactly 1",
            WaypointKind.END: "exactly 1",
            WaypointKind.TURN: "exactly 2",
            WaypointKind.BRANCH: "3 or more",
        }[w.kind]
        ok = {
            WaypointKind.START: deg == 1,
            WaypointKind.END: deg == 1,
            WaypointKind.TURN: deg == 2,
            WaypointKind.BRANCH: deg >= 3,
        }[w.kind]
        if not ok:
            hint = "branch" if deg >= 3 else ("turn" if deg == 2 else "start or end")
            problems.append(
                Problem(
                    f"waypoints[{i}].kind",
                    f"{w.id!r} is a {w.kind.value} waypoint, which needs {want} corridor edges, "
                    f"but has {deg}" + (f"; use kind '{hint}'" if deg else ""),
                )
            )
    comps = [c for c in nx.connected_components(g) if c]
    if len(comps) > 1:
        comps.sort(key=len, reverse=True)
        parts = "; ".join(
            "{" + ", ".join(sorted(c)[:6]) + ("..." if len(c) > 6 else "") + "}" for c in comps
        )
        problems.append(
            Problem("edges", f"the corridors fall into {len(comps)} disconnected parts: {parts}")
        )

    # Every door and landmark must be reachable from a corridor.
    valid_edges = [e for e in b.edges if e.a in wps and e.b in wps and e.a != e.b]
    if valid_edges:
        seg_a = np.array([wps[e.a].pos for e in valid_edges])
        seg_b = np.array([wps[e.b].pos for e in valid_edges])
        half = np.array([b.edge_width(e) / 2.0 for e in valid_edges])
        directional = b.signage.directional if b.signage is not None else ()
        for group, items, attr in (
            ("rooms", b.rooms, "door"),
            ("landmarks", b.landmarks, "pos"),
            ("signage.directional", directional, "at"),
        ):
            if not items:
                continue
            pts = np.array([getattr(it, attr) for it in items])
            j, _, dist = project_points_to_segments(pts, seg_a, seg_b)
            for i, it in enumerate(items):
                limit = half[j[i]] + DOOR_REACH_SLACK
                if dist[i] > limit:
                    what = repr(it.id) if hasattr(it, "id") else f"sign {it.text!r}"
                    problems.append(
                        Problem(
                            f"{group}[{i}].{attr}",
                            f"{what} is {dist[i]:.2f} m from the nearest corridor centre line "
                            f"({valid_edges[j[i]].a}-{valid_edges[j[i]].b}); at most {limit:.2f} m "
                            "is reachable: move it next to a corridor or add a corridor edge",
                        )
                    )

    if b.signage is not None:
        problems.extend(signage_problems(b.signage, set(b._room_index)))

    if b.floor_plan is not None and base_dir is not None:
        for field in ("image", "ros_map"):
            rel = getattr(b.floor_plan, field)
            if rel is None:
                continue
            f = base_dir / rel
            if not is_regular_file(f):
                problems.append(Problem(f"floor_plan.{field}", f"file not found: {f}"))
            elif field == "image":
                try:
                    image_size(f, f"floor_plan.{field}")
                except InputFileError as err:
                    problems.append(Problem(f"floor_plan.{field}", f"{f}: {err.message}"))
    return problems


def building_from_data(data: Any, source: str = "<data>", base_dir: Path | None = None) -> Building:
    """Validate plain data (as read from YAML) into a Building, or raise BuildingFileError."""
    if not isinstance(data, dict):
        raise BuildingFileError(
            source, [Problem("", f"expected a mapping at the top level, got {type(data).__name__}")]
        )
    try:
        b = Building.model_validate(data)
    except ValidationError as err:
        raise BuildingFileError(source, pydantic_problems(err)) from None
    problems = semantic_problems(b, base_dir)
    if problems:
        raise BuildingFileError(source, problems)
    return b


def read_building_file(path: str | Path) -> Building:
    """Read and validate a building file (a name is looked up by ``catalogue.load_building``)."""
    path = Path(path)
    try:
        data = load_yaml(path, "building")
    except InputFileError as err:
        raise BuildingFileError(str(path), [Problem(err.field, err.message)]) from None
    if isinstance(data, dict) and "site_version" in data:  # map/site.py reads those
        raise BuildingFileError(
            str(path),
            [
                Problem(
                    "site_version",
                    "this is a site file (a building of several levels); this command takes "
                    "one level: give that level's building file (or --level where the "
                    "command has one)",
                )
            ],
        )
    return building_from_data(data, str(path), path.parent)


def save_building(b: Building, path: str | Path) -> Path:
    """Write a building file that loads back to an equal Building."""
    return atomic_write_text(path, dump_building(b))


def dump_building(b: Building) -> str:
    """The building as YAML text."""
    dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
    return yaml.dump(b.to_dict(), Dumper=dumper, sort_keys=False, allow_unicode=True, width=100)
