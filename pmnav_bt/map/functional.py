"""Seeded hospital, school and office floors that look like the real thing (issue 36).

A generated floor is built in four steps, each from the seed:

1. a corridor layout of the type (:mod:`pmnav_bt.map.layouts`: a main corridor with
   wings, an L or a U, or a ring round a core), with the type's corridor widths and a
   wide entrance lobby whose far end opens into a lift lobby;
2. landmarks where buildings have them: the reception desk in the lobby, the main stairs
   beside it, a lift in the lift lobby facing the entrance, escape stairs at the far end,
   and a sign at the mouth of every department's wing (``Ward 3B``, ``Imaging``);
3. rooms along every corridor wall, drawn from the type's programme
   (:mod:`pmnav_bt.map.programmes`): each department's rooms with their widths along the
   wall (the door pitch), the building's named rooms near the lobby, services anywhere,
   the core's rooms on the inside of a ring (a school's courtyard side has none);
4. one numbering scheme for the building (:mod:`pmnav_bt.map.numbering`), from the core
   outward; the sign of a numbered room reads its code (``117``), that of a named room
   the code and a short name (``2.04 Library``), as the built-in building files do.

Nothing here draws signage styles, clutter or light: the world preset does that per
episode seed (``world.preset=realistic``). A floor takes a few milliseconds to make.
"""

from __future__ import annotations

import math
import random
from collections import Counter
from dataclasses import dataclass

import networkx as nx

from pmnav_bt.map.building import (
    DOOR_REACH_SLACK,
    SCHEMA_VERSION,
    Building,
    building_from_data,
)
from pmnav_bt.map.layouts import Layout, ring_layout, spine_layout
from pmnav_bt.map.numbering import PER_WING, SCHEMES, room_code, wing_letter
from pmnav_bt.map.programmes import CITIES, PROGRAMMES, Department, Function, Programme

BUILDING_KINDS = tuple(PROGRAMMES)  # hospital, school, office

# Wall clearances (m), from the world's door (1.16 m with its frame) and sign plate (0.82 m
# beside it, 0.15 m off the frame): a door centre this far past the mouth of a meeting
# corridor or a dead end leaves its sign room on the wall.
MOUTH_CLEARANCE_M = 1.6
END_CLEARANCE_M = 1.4
MIN_ROOM_M = 2.4  # no room narrower along the wall: a door and its sign plate
PLATE_ROOM_M = 1.0  # a sign plate and its gap, kept free beside a landmark
DESK_SLOT_M = 2.4  # the reception desk (1.9 m) and its margins
STAIRS_SLOT_M = 2.4  # the stairs (1.8 m) and their margins
SIGN_SLOT_M = 1.2  # a department sign plate
LIFT_SLOT_M = 3.2  # a lift's doors, frame and call panel (2.14 m) and its name plate



@dataclass(frozen=True)
class _Shape:
    """A type's layouts: the chance of a ring (else a main corridor with wings), a ring's
    length and core depth (m) and its fewest and most wings, a main corridor's length (m)."""

    p_ring: float
    ring_m: tuple[float, float]
    core_m: tuple[float, float]
    ring_wings: tuple[int, int]
    main_m: tuple[float, float]


_SHAPES = {
    # a racetrack round its support rooms, or a hospital street with ward wings
    "hospital": _Shape(0.4, (30.0, 60.0), (10.0, 16.0), (0, 3), (40.0, 80.0)),
    # a courtyard with teaching wings off it, or a long finger plan
    "school": _Shape(0.4, (36.0, 64.0), (14.0, 24.0), (1, 3), (50.0, 90.0)),
    # the floor round its lift-and-stair core, or a double-loaded corridor (L, U, T)
    "office": _Shape(0.55, (28.0, 48.0), (8.0, 12.0), (0, 1), (36.0, 64.0)),
}
COURTYARD_P = 0.6  # a school ring's inner walls face a courtyard: no doors there
SPLIT_P = 0.12  # a small repeated room divided in two (117A, 117B), as rooms get divided
SPLIT_MAX_M = 4.2  # ... if it is no wider than this (offices, consulting rooms, stores)
LAYOUT_TRIES = 12  # layouts drawn until one has a corridor bend (medium episodes need one)


@dataclass
class _Wall:
    """One side of a corridor: the stretches (distances along it) free for rooms."""

    free: list[tuple[float, float]]


@dataclass
class _Room:
    corridor: int
    side: int
    s: float
    door: tuple[float, float]
    function: Function
    state: _DeptState
    n: int = 0  # sequence number of the numbering scheme
    half: str = ""  # "A" or "B": one half of a divided room (117A, 117B)
    twin: _Room | None = None  # a B half's A half, whose number it shares


class _DeptState:
    """A department while its walls are filled: its title and the once-rooms left."""

    def __init__(self, dept: Department, title: str, rng: random.Random):
        self.dept = dept
        self.title = title
        self.once = list(dept.once)
        rng.shuffle(self.once)

    def draw(self, rng: random.Random, prog: Programme) -> Function:
        if self.once and rng.random() < self.dept.p_once:
            return self.once.pop()
        if rng.random() < prog.p_service:
            return rng.choice(prog.service)
        return rng.choice(self.dept.generic)


def generate_functional(kind: str, seed: int) -> Building:
    """A valid ``kind`` floor (hospital, school or office); the same seed, the same file."""
    rng = random.Random(f"{kind}:{seed}")  # a str seed is hashed stably (sha512)
    shell = draw_shell(rng, kind)
    walls = shell.walls()
    floor = rng.randint(1, 5)
    states = departments(rng, shell, floor)
    core = draw_core(rng, shell, walls)
    landmarks = core_landmarks(shell, walls, core, reception=True)
    landmarks += department_signs(rng, shell, walls, states)
    scheme = rng.choice(list(SCHEMES))
    odd_even = rng.random() < 0.5
    room_data = fill_rooms(rng, shell, walls, states, scheme, odd_even, floor)
    label = f"{kind}_{seed}"  # the family member's name
    description = (
        f"Generated {kind} floor {floor} (seed {seed}): {shell.layout.describe()}; corridors "
        f"{shell.main_w:g} m wide, an entrance lobby {shell.lobby_w:g} m wide with reception, "
        f"the main stairs and a lift lobby at its far end; {len(room_data)} rooms numbered "
        f"like {room_data[0]['sign'].split()[0] if room_data else scheme} "
        f"({'odd and even sides' if odd_even else 'in passing order'})."
    )
    return building_from_data(
        floor_data(shell, label, description, room_data, landmarks), source=label
    )


@dataclass(frozen=True)
class Shell:
    """What every floor of one building shares: the type's programme, the corridor widths
    and layout, and the layout's corridors oriented away from the core (``ends``: from its
    nearer node to its farther one; the lobby from the entrance in), visited from the core
    outward (``order``). A multi-level site (``functional_site``) stacks floors on one
    shell, so their corridors lie over each other and its lifts and stairs line up."""

    kind: str
    prog: Programme
    main_w: float
    wing_w: float
    lobby_w: float
    layout: Layout
    graph: nx.Graph
    order: tuple[int, ...]
    ends: dict[int, tuple[int, int]]

    @property
    def lobby(self) -> int:
        """The entrance lobby's corridor."""
        return next(i for i, c in enumerate(self.layout.corridors) if c.role == "lobby")

    def walls(self) -> dict[tuple[int, int], _Wall]:
        """Every corridor side's wall, free for a floor's landmarks and rooms."""
        return {
            (i, side): _wall(self.layout, self.graph, i, self.ends[i])
            for i in self.order
            for side in (1, -1)
        }


def draw_shell(rng: random.Random, kind: str) -> Shell:
    """A ``kind`` building's corridor widths and layout, drawn from ``rng``."""
    if kind not in PROGRAMMES:
        raise ValueError(f"unknown building kind {kind!r}; choose {', '.join(PROGRAMMES)}")
    prog = PROGRAMMES[kind]
    main_w = round(rng.uniform(*prog.corridor), 1)
    wing_w = round(rng.uniform(max(prog.corridor[0], main_w - 0.4), main_w), 1)
    lobby_w = round(rng.uniform(*prog.lobby), 1)
    layout = _layout(rng, kind, prog, main_w, wing_w, lobby_w)
    g = nx.Graph()
    for i, c in enumerate(layout.corridors):
        g.add_edge(c.a, c.b, index=i)
    depth = nx.single_source_shortest_path_length(g, layout.core)
    # Orient every corridor away from the core; visit them from the core outward.
    order = sorted(
        range(len(layout.corridors)),
        key=lambda i: min(depth[layout.corridors[i].a], depth[layout.corridors[i].b]),
    )
    ends = {}
    for i in order:
        c = layout.corridors[i]
        ends[i] = (c.a, c.b) if depth[c.a] <= depth[c.b] else (c.b, c.a)
        if c.role == "lobby":  # the lobby runs from the entrance in
            ends[i] = (layout.entrance, layout.core)
    return Shell(kind, prog, main_w, wing_w, lobby_w, layout, g, tuple(order), ends)


def fill_rooms(
    rng: random.Random,
    shell: Shell,
    walls,
    states,
    scheme: str,
    odd_even: bool,
    floor: int,
    courtyard: bool | None = None,
) -> list[dict]:
    """One floor's rooms on what its landmarks left of ``walls``, numbered in ``scheme``
    for ``floor``, as file data. ``courtyard``: whether a school ring's inner walls face a
    courtyard (no doors there), which a building of several floors decides once for all
    of them; None: drawn here, for this floor alone."""
    split_p = 0.0 if scheme in PER_WING else SPLIT_P  # "3BA" is no code anyone uses
    rooms = _fill(
        rng, shell.prog, shell.layout, shell.ends, walls, shell.order, states, split_p, courtyard
    )
    _number(rooms, shell.order, shell.layout, scheme, odd_even)
    return _room_data(rooms, shell.layout, scheme, floor)


def floor_data(shell: Shell, label: str, description: str, rooms, landmarks) -> dict:
    """A floor's building file data: the shell's waypoints and corridors, its rooms and
    landmarks."""
    waypoints, wp_ids = _waypoints(shell.layout, shell.graph)
    edges = []
    for c in shell.layout.corridors:
        pair = [wp_ids[c.a], wp_ids[c.b]]
        wide = {"from": pair[0], "to": pair[1], "width": c.width}
        edges.append(pair if c.width == shell.main_w else wide)
    return {
        "schema_version": SCHEMA_VERSION,
        "name": label,
        "kind": shell.kind,
        "description": description,
        "corridor_width": shell.main_w,
        "waypoints": waypoints,
        "edges": edges,
        "rooms": rooms,
        "landmarks": landmarks,
    }


def _layout(rng, kind: str, prog: Programme, main_w, wing_w, lobby_w) -> Layout:
    """The type's layout; redrawn (a few times) until some corridor bends."""
    shape = _SHAPES[kind]
    for _ in range(LAYOUT_TRIES):
        if rng.random() < shape.p_ring:
            layout = ring_layout(
                rng,
                main_w,
                wing_w,
                lobby_w,
                prog.room_depth,
                (shape.ring_m, shape.core_m),
                shape.ring_wings,
            )
        else:
            layout = spine_layout(rng, main_w, wing_w, lobby_w, prog.room_depth, shape.main_m)
        if _has_bend(layout):
            break
    return layout


def _has_bend(layout: Layout) -> bool:
    """Whether two corridors meet at an angle where no third one joins (a turn waypoint)."""
    g = nx.Graph([(c.a, c.b) for c in layout.corridors])
    for n in g:
        if g.degree(n) == 2:
            a, b = (layout.pos[m] for m in g.neighbors(n))
            p = layout.pos[n]
            if abs((a[0] - p[0]) * (b[1] - p[1]) - (a[1] - p[1]) * (b[0] - p[0])) > 1e-6:
                return True
    return False


def _frame(layout: Layout, ends: tuple[int, int]):
    """Start point, unit direction, left normal and length of a corridor from ends[0]."""
    (x0, y0), (x1, y1) = layout.pos[ends[0]], layout.pos[ends[1]]
    length = math.hypot(x1 - x0, y1 - y0)
    ux, uy = (x1 - x0) / length, (y1 - y0) / length
    return (x0, y0), (ux, uy), (-uy, ux), length


def _on_wall(layout: Layout, c: int, ends, side: int, s: float) -> tuple[float, float]:
    """The point ``s`` along corridor ``c`` on its ``side`` wall (rounded to mm)."""
    (x0, y0), (ux, uy), (nx_, ny_), _ = _frame(layout, ends)
    off = side * layout.corridors[c].width / 2.0
    return round(x0 + ux * s + nx_ * off, 3), round(y0 + uy * s + ny_ * off, 3)


def _wall(layout: Layout, g: nx.Graph, c: int, ends) -> _Wall:
    """A corridor side's wall less the mouths of the corridors meeting it at either end."""
    _, _, _, length = _frame(layout, ends)
    clear = []
    for node in ends:
        widths = [
            layout.corridors[g.edges[node, m]["index"]].width
            for m in g.neighbors(node)
            if g.edges[node, m]["index"] != c
        ]
        clear.append(max(widths) / 2.0 + MOUTH_CLEARANCE_M if widths else END_CLEARANCE_M)
    lo, hi = clear[0], length - clear[1]
    return _Wall([(lo, hi)] if hi - lo >= MIN_ROOM_M else [])


def _reserve(wall: _Wall, s: float, width: float) -> bool:
    """Take ``width`` centred at ``s`` out of the wall's free intervals, if it fits there,
    with a sign plate's room either side (a neighbouring door's sign may hang there)."""
    a, b = s - width / 2.0, s + width / 2.0
    for k, (lo, hi) in enumerate(wall.free):
        if lo - 0.01 <= a and b <= hi + 0.01:
            left, right = (lo, a - PLATE_ROOM_M), (b + PLATE_ROOM_M, hi)
            wall.free[k : k + 1] = [iv for iv in (left, right) if iv[1] - iv[0] >= MIN_ROOM_M]
            return True
    return False


@dataclass(frozen=True)
class Core:
    """Where a building's core landmarks go, the same on every floor: the side of the
    lobby the reception desk stands on (the main stairs face it), how far along its free
    wall the desk stands (0-1; None where that wall has no room), and the escape stairs'
    wall sides in the order tried."""

    desk_side: int
    desk_at: float | None
    escape_sides: tuple[int, int]


def draw_core(rng: random.Random, shell: Shell, walls) -> Core:
    """The core's places, drawn from ``rng``."""
    desk_side = rng.choice((1, -1))
    desk_at = rng.uniform(0.0, 1.0) if walls[(shell.lobby, desk_side)].free else None
    return Core(desk_side, desk_at, tuple(rng.sample((1, -1), 2)))


def core_landmarks(
    shell: Shell, walls, core: Core, reception: bool, shaft: bool = False
) -> list[dict]:
    """Reception (where ``reception``: the entrance floor), the main stairs and the lift at
    the core, escape stairs far away; their places taken out of ``walls``. Nothing here
    draws: every floor of a shell with the same ``core`` gets its stairs and lift at the
    same points.

    ``shaft``: the lift is one the robot rides (a site's), whose doorway and cabin the
    map (``lift_doorway``) and the simulator put behind the corridor wall its point is
    on: it stands on a main corridor's wall beside the lift lobby (``_shaft_spot``). A
    floor of its own (``shaft`` False) keeps its lift on the lift lobby's back wall facing
    the entrance, its point in front of it (the world mounts it on the nearest wall)."""
    prog, layout, ends, lobby = shell.prog, shell.layout, shell.ends, shell.lobby
    out: list[dict] = []
    _, (ux, uy), _, _ = _frame(layout, ends[lobby])
    wall = walls[(lobby, core.desk_side)]
    if reception and core.desk_at is not None:
        lo, hi = wall.free[0]
        s = round(lo + DESK_SLOT_M / 2.0 + core.desk_at * (hi - lo - DESK_SLOT_M), 2)
        if _reserve(wall, s, DESK_SLOT_M):
            out.append(_lm("reception", "reception_desk", prog.reception, "Reception",
                           _on_wall(layout, lobby, ends[lobby], core.desk_side, s)))
    wall = walls[(lobby, -core.desk_side)]
    if wall.free:
        s = round(wall.free[-1][1] - STAIRS_SLOT_M / 2.0, 2)
        if _reserve(wall, s, STAIRS_SLOT_M):
            out.append(_lm("stairs1", "stairs", f"Stairs {wing_letter(0)}", "Stairs",
                           _on_wall(layout, lobby, ends[lobby], -core.desk_side, s)))
    lift = f"{prog.lift} {wing_letter(0)}"
    pos = _shaft_spot(shell, walls) if shaft else _lobby_back_spot(layout, (ux, uy))
    out.append(_lm("lift1", "elevator", lift, lift, pos))
    # Escape stairs near the far end of the corridor farthest from the core.
    g = nx.Graph()
    for c in layout.corridors:
        g.add_edge(c.a, c.b, w=math.dist(layout.pos[c.a], layout.pos[c.b]))
    dist = nx.single_source_dijkstra_path_length(g, layout.core, weight="w")
    inner = [i for i in ends if layout.corridors[i].role != "lobby"]
    far = max(inner, key=lambda i: dist[ends[i][1]])
    for side in core.escape_sides:
        wall = walls[(far, side)]
        if wall.free and wall.free[-1][1] - wall.free[-1][0] >= STAIRS_SLOT_M:
            s = round(wall.free[-1][1] - STAIRS_SLOT_M / 2.0, 2)
            _reserve(wall, s, STAIRS_SLOT_M)
            out.append(_lm("stairs2", "stairs", f"Stairs {wing_letter(1)}", "Stairs",
                           _on_wall(layout, far, ends[far], side, s)))
            break
    return out


def _lobby_back_spot(layout: Layout, lobby_way: tuple[float, float]) -> tuple[float, float]:
    """A floor's own lift point: the lift faces the entrance, on the back wall of the lift
    lobby past the main corridor (``lobby_way``: the entrance lobby's direction in; the
    world mounts it on the nearest wall). The point stands in front of it, within reach of
    the main corridor: the file's rule measures reach from the nearest centre line, which
    there is the main corridor's."""
    cx, cy = layout.pos[layout.core]
    main_w = max(
        c.width for c in layout.corridors if c.role != "lobby" and layout.core in (c.a, c.b)
    )
    half = min(layout.lobby_width, main_w + 2.0 * DOOR_REACH_SLACK) / 2.0 - 0.05
    return (round(cx + lobby_way[0] * half, 3), round(cy + lobby_way[1] * half, 3))


def _shaft_spot(shell: Shell, walls) -> tuple[float, float]:
    """A ridden lift's point: on the wall of a corridor leaving the core, on the side the
    entrance lobby faces (past the main corridor, where the lift lobby is), at the first
    free stretch from the core; its place taken out of that wall. The lift lobby's back
    wall will not do for it: the point must be on the wall of the corridor whose centre
    line is nearest it, and there the main corridor's and the lobby's are equally near.
    ValueError where no such wall has room (no layout of ``layouts`` leaves none)."""
    layout, ends = shell.layout, shell.ends
    _, (ux, uy), _, _ = _frame(layout, ends[shell.lobby])
    for i in shell.order:
        if ends[i][0] != layout.core or layout.corridors[i].role == "lobby":
            continue
        _, _, (nx_, ny_), _ = _frame(layout, ends[i])
        side = 1 if nx_ * ux + ny_ * uy > 0 else -1
        wall = walls[(i, side)]
        if wall.free and wall.free[0][1] - wall.free[0][0] >= LIFT_SLOT_M:
            s = round(wall.free[0][0] + LIFT_SLOT_M / 2.0, 2)
            _reserve(wall, s, LIFT_SLOT_M)
            return _on_wall(layout, i, ends[i], side, s)
    raise ValueError("no corridor wall at the core has room for a lift")


def department_signs(rng: random.Random, shell: Shell, walls, states) -> list[dict]:
    """A department's name where its wing leaves the main corridor."""
    layout, ends = shell.layout, shell.ends
    out: list[dict] = []
    for k, state in sorted(states.items()):
        first = next((i for i in ends if layout.corridors[i].wing == k), None)
        if not state.title or first is None:
            continue
        side = rng.choice((1, -1))
        wall = walls[(first, side)]
        if wall.free:
            s = round(wall.free[0][0] + SIGN_SLOT_M / 2.0, 2)
            if _reserve(wall, s, SIGN_SLOT_M):
                out.append(_lm(f"sign{k}", "sign", state.title, state.title,
                               _on_wall(layout, first, ends[first], side, s)))
    return out


def _lm(ident: str, kind: str, name: str, sign: str, pos) -> dict:
    return {"id": ident, "kind": kind, "name": name, "pos": list(pos), "sign": sign}


def departments(rng: random.Random, shell: Shell, floor: int) -> dict[int, _DeptState]:
    """The department of every wing (0: the main corridor and lobby) on ``floor``."""
    prog, layout = shell.prog, shell.layout
    pool = list(prog.wings)
    rng.shuffle(pool)
    states = {0: _DeptState(prog.main, "", rng)}
    for k in range(1, layout.wings + 1):
        dept = pool[(k - 1) % len(pool)]
        title = dept.title.format(ward=f"{floor}{wing_letter(k)}")
        states[k] = _DeptState(dept, title, rng)
    return states


def _fill(
    rng,
    prog: Programme,
    layout: Layout,
    ends,
    walls,
    order,
    states,
    split_p: float,
    courtyard: bool | None,
) -> list[_Room]:
    """Rooms along every free stretch of wall, from the core outward; a small repeated
    room is divided in two with chance ``split_p``."""
    core = _DeptState(prog.core, "", rng)
    if courtyard is None:
        courtyard = has_courtyard(rng, prog)
    rooms: list[_Room] = []
    for i in order:
        c = layout.corridors[i]
        for side in (1, -1):
            state = states[c.wing]
            if c.role == "ring" and _faces_centre(layout, i, ends[i], side):
                if courtyard:
                    continue
                state = core
            for lo, hi in walls[(i, side)].free:
                s = lo
                while hi - s >= MIN_ROOM_M:
                    f = state.draw(rng, prog)
                    halves = ("",)
                    if (
                        f in state.dept.generic
                        and f.widths[1] <= SPLIT_MAX_M
                        and hi - s >= 2 * MIN_ROOM_M
                        and rng.random() < split_p
                    ):
                        halves = ("A", "B")
                    for half in halves:
                        lo_w, hi_w = (MIN_ROOM_M, MIN_ROOM_M + 0.4) if half else f.widths
                        room_w = round(rng.uniform(lo_w, hi_w), 1)
                        # an A half leaves its B half a whole room's width
                        width = min(room_w, hi - s - (MIN_ROOM_M if half == "A" else 0.0))
                        door = _on_wall(layout, i, ends[i], side, s + width / 2.0)
                        room = _Room(i, side, s + width / 2.0, door, f, state, half=half)
                        if half == "B":
                            room.twin = rooms[-1]
                        rooms.append(room)
                        s += width
    return rooms


def has_courtyard(rng: random.Random, prog: Programme) -> bool:
    """Whether a ring's inner walls face a courtyard (a school's, with ``COURTYARD_P``)."""
    return prog.kind == "school" and rng.random() < COURTYARD_P


def _faces_centre(layout: Layout, c: int, ends, side: int) -> bool:
    (x0, y0), _, (nx_, ny_), _ = _frame(layout, ends)
    cx, cy = layout.centre
    return side * ((cx - x0) * nx_ + (cy - y0) * ny_) > 0


def _number(rooms: list[_Room], order, layout: Layout, scheme: str, odd_even: bool) -> None:
    """Sequence numbers from the core outward, per wing in the per-wing schemes."""
    nxt: dict[int, int] = {}
    for i in order:
        wing = layout.corridors[i].wing if scheme in PER_WING else 0
        mine = sorted(
            (r for r in rooms if r.corridor == i and r.twin is None), key=lambda r: (r.s, -r.side)
        )
        base = nxt.get(wing, 0)
        if odd_even:
            for side, first in ((1, 1), (-1, 2)):
                for k, r in enumerate(x for x in mine if x.side == side):
                    r.n = base + first + 2 * k
            top = max((r.n for r in mine), default=base)
            nxt[wing] = top + (top % 2)
        else:
            for k, r in enumerate(mine):
                r.n = base + k + 1
            nxt[wing] = base + len(mine)
    for r in rooms:
        if r.twin is not None:
            r.n = r.twin.n


def _room_data(rooms: list[_Room], layout: Layout, scheme: str, floor: int) -> list[dict]:
    """Rooms as file data: ids in number order, unique names, aliases each given once."""
    out = []
    names: set[str] = set()
    aliases_used: set[str] = set()
    cities = iter(CITIES)
    counts: Counter[tuple[str, str]] = Counter()  # {n}: per department where named after it
    ordered = sorted(rooms, key=lambda r: (layout.corridors[r.corridor].wing, r.n))
    for k, r in enumerate(ordered, start=1):
        wing = wing_letter(layout.corridors[r.corridor].wing)
        code = room_code(scheme, floor, r.n, wing) + r.half
        f = r.function
        fields = {
            "code": code,
            "dept": r.state.title,
            "n": _count(counts, (f.name, r.state.title if "{dept}" in f.name else "")),
            "city": next(cities, code) if "{city}" in f.name else "",
        }
        name = f.name.format(**fields)
        words = (name if f.sign is None else f.sign.format(**fields)).strip()
        base, dup = name, 1
        while name.casefold() in names:  # a second "Toilets" is "Toilets 2"; its sign "Toilets"
            dup += 1
            name = f"{base} {dup}"
        names.add(name.casefold())
        aliases = []
        for a in (a.format(**fields) for a in f.aliases):
            if a.casefold() not in aliases_used and a.casefold() not in names:
                aliases_used.add(a.casefold())
                aliases.append(a)
        room = {"id": f"room{k}", "name": name}
        if aliases:
            room["aliases"] = aliases
        room["door"] = list(r.door)
        room["sign"] = f"{code} {words}" if words else code
        out.append(room)
    return out


def _count(counts: Counter, key: tuple[str, str]) -> int:
    counts[key] += 1
    return counts[key]


def _waypoints(layout: Layout, g: nx.Graph) -> tuple[list[dict], dict[int, str]]:
    """Key waypoints, named start, turnK, branchK, endK in the order met from the entrance."""
    counters = {"turn": 0, "branch": 0, "end": 0}
    ids: dict[int, str] = {}
    out = []
    for n in nx.bfs_tree(g, layout.entrance):
        deg = g.degree(n)
        if n == layout.entrance:
            kind = "start"
            ids[n] = "start"
        else:
            kind = "end" if deg == 1 else "turn" if deg == 2 else "branch"
            counters[kind] += 1
            ids[n] = f"{kind}{counters[kind]}"
        out.append({"id": ids[n], "kind": kind, "pos": list(layout.pos[n])})
    return out, ids
