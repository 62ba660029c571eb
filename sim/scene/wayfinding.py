"""Directional signs at junctions, drawn for random signage when the file lists none.

Hospitals and schools hang wayfinding signs where corridors meet, on the wall that faces
a person arriving, pointing down a side corridor: "Radiology ->" or "<- 101-120". For
each junction (a turn or branch waypoint) and each corridor arriving at it, this draws
one such sign pointing to one of the corridors that leave to the left or right. What it
says is true: a room whose door is on that corridor or one corridor beyond, or the range
of their room numbers. A junction with no wall facing the arrival (a crossing) gets none.
"""

from __future__ import annotations

import math
import re

import numpy as np

from pmnav_bt.geometry import project_points_to_segments
from pmnav_bt.map.building import Building, Room
from pmnav_bt.map.signage import DirectionalSignSpec, split_number

WAYFINDING_P = 0.8  # buildings with wayfinding signs at their junctions
NUMBER_RANGE_P = 0.5  # signs listing a range of room numbers rather than a room's name
SIDEWAYS = 0.5  # |sin| of the angle between arrival and departure: a left or right turn
FACING = 0.9  # the wall's normal points back at the arrival within about 25 deg
ON_WALL_M = 0.3  # the far wall is at most this far from where the arrival meets it
MAX_NAME_CHARS = 40


def junction_signs(b: Building, walls, rng: np.random.Generator) -> list[DirectionalSignSpec]:
    """The directional signs of ``b`` with walls ``walls`` (``SimWorld.walls``)."""
    if not b.rooms or rng.random() >= WAYFINDING_P:
        return []
    wps = {w.id: np.asarray(w.pos, float) for w in b.waypoints}
    edges = [e for e in b.edges if e.a in wps and e.b in wps and e.a != e.b]
    j, _, _ = project_points_to_segments(
        np.array([r.door for r in b.rooms]),
        np.array([wps[e.a] for e in edges]),
        np.array([wps[e.b] for e in edges]),
    )
    on_edge: dict[frozenset, list[Room]] = {}
    for room, k in zip(b.rooms, j, strict=True):
        on_edge.setdefault(frozenset((edges[k].a, edges[k].b)), []).append(room)
    g = b.corridor_graph()
    out = []
    for junction in sorted(g.nodes):
        if g.degree(junction) < 2:
            continue
        here = wps[junction]
        half = max(b.edge_width(e) for e in edges if junction in (e.a, e.b)) / 2.0
        for came_from in sorted(g.neighbors(junction)):
            d = _unit(here - wps[came_from])
            turns = []
            for to in sorted(g.neighbors(junction)):
                side = _cross(d, _unit(wps[to] - here))
                if to != came_from and abs(side) > SIDEWAYS:
                    turns.append((to, side))
            at = _facing_wall(walls, here + d * half, d)
            if not turns or at is None:
                continue
            to, side = turns[int(rng.integers(len(turns)))]
            rooms = list(on_edge.get(frozenset((junction, to)), []))
            for beyond in sorted(g.neighbors(to)):
                if beyond != junction:
                    rooms += on_edge.get(frozenset((to, beyond)), [])
            text = _destination(rooms, rng)
            if text:
                arrowed = f"<- {text}" if side > 0 else f"{text} ->"
                out.append(DirectionalSignSpec(at=(float(at[0]), float(at[1])), text=arrowed))
    return out


def _destination(rooms: list[Room], rng: np.random.Generator) -> str:
    """What a sign to ``rooms`` says: their number range, or one room's name."""
    numbers = [n for n in (split_number(r.sign_text)[0] for r in rooms) if n]
    if len(numbers) >= 2 and rng.random() < NUMBER_RANGE_P:
        numbers.sort(key=_natural)
        return f"{numbers[0]}-{numbers[-1]}"
    names = [r.display_name for r in rooms if len(r.display_name) <= MAX_NAME_CHARS]
    return names[int(rng.integers(len(names)))] if names else ""


def _natural(text: str) -> list:
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", text)]


def _facing_wall(walls, p: np.ndarray, d: np.ndarray) -> np.ndarray | None:
    """The point of the wall near ``p`` that faces a person walking along ``d``."""
    best, best_dist = None, ON_WALL_M
    for w in walls:
        if float(np.dot(w.normal, d)) > -FACING:
            continue
        a = np.asarray(w.a)
        s = float(np.clip(np.dot(p - a, w.tangent), 0.0, w.length))
        q = w.point(s)
        dist = float(np.linalg.norm(p - q))
        if dist < best_dist:
            best, best_dist = q, dist
    return best


def _unit(v: np.ndarray) -> np.ndarray:
    return v / math.hypot(v[0], v[1])


def _cross(u: np.ndarray, v: np.ndarray) -> float:
    return float(u[0] * v[1] - u[1] * v[0])
