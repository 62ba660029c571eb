"""A stale map: the world built a little differently from the building file the robot gets.

Floor plans age: rooms are renamed, a lift or a reception desk moves with a refit, a
corridor is closed for works. With probability ``world.stale_map`` an episode's world
differs from its map by one such change, drawn from ``world.stale_kinds`` and placed on
the episode's route (so the robot passes it and can see it):

- ``renamed``: a room passed on the way (never the goal) gets another name; its sign
  keeps the room number ("117 Pharmacy" becomes "117 Quiet Room"). A number-only plate
  layout hides the change, as it would in a real building.
- ``moved``: a landmark on the route stands ``MOVE_M`` further along its corridor.
- ``closed``: a corridor segment of the route is closed by a barrier
  (``scene.blocking``) at its middle, only where another way to the goal remains (the
  episode stays solvable) and the segment is ``MIN_CLOSED_M`` long (the barrier stands in
  a corridor, not at a junction).

The robot is given the building file unchanged; :func:`stale_world` returns the building
the world is built from, the segments to close and what changed (:class:`StaleChange`,
with the kind of map update a robot that notices it should write: what the stale-map
measurement compares with, ``benchmarks/stale_map_updates.py``). Drawn from the episode's
seed (part "stale_map"), so the same episode is stale the same way.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import networkx as nx
import numpy as np

from pmnav_bt.config import WorldConfig
from pmnav_bt.map.building import Building
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.map.signage import split_number
from pmnav_bt.sim.scene import scene_rng

# How far a landmark moves along its corridor: far enough for a robot to tell it from the
# sign's own offset (a lift's sign hangs up to 1.5 m beside it) and its pose error (about
# 1 m), that is beyond map_check.MOVED_M seen from most sides; near enough that a search
# for it where the map puts it may still read its sign (at 4.5 m and more it never did in
# fig2_hospital's hard episodes: the plate is behind the search or seen edge-on).
MOVE_M = (3.0, 4.0)
CLEAR_M = 2.5  # a moved landmark stays this far from every door and other landmark (a lift
# is about 2 m wide: nearer, the world would hang it over another item)
MIN_CLOSED_M = 6.0  # a closed segment is this long: its barrier (at the middle) stands in a
# corridor, not at a junction, where a turn's corner check would take it for a wall
# Names a room may be given: none is a name of a generated or built-in room type by
# itself, so a renamed room never takes another room's name.
NEW_NAMES = (
    "Quiet Room",
    "Family Lounge",
    "Equipment Store",
    "Staff Kitchen",
    "Meeting Room B",
    "Prayer Room",
    "Study Hub",
    "Print Room",
)
UPDATE_KIND = {"renamed": "sign_text", "moved": "moved", "closed": "corridor_blocked"}


@dataclass(frozen=True)
class StaleChange:
    """One way the world differs from the map: ``kind`` (renamed, moved, closed), its
    ``subject`` (room, landmark or segment id), ``before`` and ``after`` (sign texts or
    positions, "open"/"closed"), and ``update_kind``, the map update it should cause."""

    kind: str
    subject: str
    before: str
    after: str

    @property
    def update_kind(self) -> str:
        return UPDATE_KIND[self.kind]


@dataclass(frozen=True)
class StaleWorld:
    """The building the world is built from, the segments to close, and what changed."""

    building: Building
    closed: tuple[str, ...]
    changes: tuple[StaleChange, ...]


def stale_world(
    pm: PrioriMap, world: WorldConfig, seed: int, route: Sequence[str], goal: str
) -> StaleWorld:
    """The world of the episode of ``seed`` with route ``route`` (priori-map nodes) to
    ``goal``: the map's building unchanged, or with one change (see the module docstring)."""
    b = pm.building
    rng = scene_rng(seed, b.name, "stale_map")
    if world.stale_map <= 0.0 or rng.random() >= world.stale_map:
        return StaleWorld(b, (), ())
    kinds = list(world.stale_kinds)
    for k in rng.permutation(len(kinds)):
        made = _MAKERS[kinds[int(k)]](pm, rng, list(route), goal)
        if made is not None:
            return made
    return StaleWorld(b, (), ())


def _renamed(pm: PrioriMap, rng, route: list[str], goal: str) -> StaleWorld | None:
    b = pm.building
    rooms = [r for r in b.rooms if r.id in route and r.id != goal]
    taken = {r.display_name.casefold() for r in b.rooms}
    names = [n for n in NEW_NAMES if n.casefold() not in taken]
    if not rooms or not names:
        return None
    room = rooms[int(rng.integers(len(rooms)))]
    name = names[int(rng.integers(len(names)))]
    number = split_number(room.sign_text)[0]
    sign = f"{number} {name}" if number else name
    new = room.model_copy(update={"name": name, "sign": sign, "aliases": ()})
    rooms_after = tuple(new if r.id == room.id else r for r in b.rooms)
    change = StaleChange("renamed", room.id, room.sign_text, sign)
    return StaleWorld(b.model_copy(update={"rooms": rooms_after}), (), (change,))


def _moved(pm: PrioriMap, rng, route: list[str], goal: str) -> StaleWorld | None:
    b = pm.building
    options = []
    for lm in b.landmarks:
        others = [r.door for r in b.rooms] + [x.pos for x in b.landmarks if x.id != lm.id]
        items = np.array(others, float).reshape(-1, 2)
        place = pm.places.get(lm.id)
        if place is None or place.node not in route:
            continue
        seg = pm.segments[place.segment - 1]
        ends = [pm.node_xy(w) for w in seg.corridor]
        along = (ends[1] - ends[0]) / np.linalg.norm(ends[1] - ends[0])
        for sign in (-1.0, 1.0):
            new = np.asarray(lm.pos, float) + sign * float(rng.uniform(*MOVE_M)) * along
            t = float((new - ends[0]) @ along)
            inside = 0.5 <= t <= float(np.linalg.norm(ends[1] - ends[0])) - 0.5
            clear = not len(items) or float(np.hypot(*(items - new).T).min()) > CLEAR_M
            if inside and clear:
                options.append((lm, new))
    if not options:
        return None
    lm, new = options[int(rng.integers(len(options)))]
    pos = (round(float(new[0]), 2), round(float(new[1]), 2))
    moved = tuple(x.model_copy(update={"pos": pos}) if x.id == lm.id else x for x in b.landmarks)
    change = StaleChange("moved", lm.id, f"{tuple(lm.pos)}", f"{pos}")
    return StaleWorld(b.model_copy(update={"landmarks": moved}), (), (change,))


def _closed(pm: PrioriMap, rng, route: list[str], goal: str) -> StaleWorld | None:
    options = []
    for u, v in zip(route, route[1:], strict=False):
        if not pm.graph.has_edge(u, v) or pm.graph.edges[u, v]["length"] < MIN_CLOSED_M:
            continue
        g = pm.graph.copy()
        g.remove_edge(u, v)
        if nx.has_path(g, route[0], goal):  # another way round: the episode stays solvable
            options.append(pm.segments[pm.graph.edges[u, v]["segment"] - 1])
    if not options:
        return None
    seg = options[int(rng.integers(len(options)))]
    change = StaleChange("closed", seg.short, "open", "closed")
    return StaleWorld(pm.building, (seg.short,), (change,))


_MAKERS = {"renamed": _renamed, "moved": _moved, "closed": _closed}
