"""Fire doors: a pair of leaves across the corridor at a ``fire_door`` landmark, shut or
held open.

A hospital or school corridor is cut into fire compartments by double doors that stand
open on hold-open magnets all day and shut when the alarm sounds, or are kept shut where
the magnets are missing or broken. The building file says where a fire door is (a
landmark of a kind in ``landmark_kinds.FIRE_DOOR``); whether it is shut is the world's,
not the map's: each is shut with probability ``world.fire_doors_closed``, drawn per
building and seed from ``world.rng("fire_doors")`` (0 in both presets, so a building with
fire doors has them open and no stream of any other part changes).

The door line crosses the corridor at the point of the nearest corridor centre line to the
landmark's ``pos``, square to that corridor, from wall to wall of the open floor. Shut,
two leaves fill it (solid, so the robot's drive stops at them and the way-ahead check
reports the door: pmnav_bt/map/wording.py). Open, each leaf lies flat against its wall,
swung the way the corridor runs from its ``from`` waypoint to its ``to``. The leaves are
labelled ``obstacle``, as a barrier is, not ``landmark:<id>``: a fire door carries no sign,
and a grounder that reads labels (``sim_gt``) must not read it as one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from shapely.geometry import LineString

from pmnav_bt.errors import PmNavError
from pmnav_bt.map.building import Landmark
from pmnav_bt.map.landmark_kinds import (
    FIRE_DOOR_HEIGHT_M,
    FIRE_DOOR_THICKNESS_M,
    is_fire_door,
)
from pmnav_bt.seams import OBSTACLE_LABEL
from pmnav_bt.sim.scene.blocking import chord_through
from pmnav_bt.sim.scene.doors import GLASS_RGBA
from pmnav_bt.sim.scene.host import BoxWorld

WALL_MARGIN_M = 0.3  # how far past the corridor's nominal width the door line may reach
MEETING_GAP_M = 0.01  # between the two shut leaves: their faces never coincide
PANE_Z = (1.1, 1.8)  # each leaf's vision panel, the mark of a corridor fire door
PANE_WIDTH_M = 0.25


class FireDoorError(PmNavError):
    """A fire door with no open floor across its corridor at its point."""


@dataclass(frozen=True)
class FireDoor:
    """A built fire door: ``closed`` or held open; ``line`` its two ends, wall to wall;
    ``bodies`` its leaves."""

    id: str
    closed: bool
    line: tuple[tuple[float, float], tuple[float, float]]
    bodies: tuple[int, ...]


def fire_doors_closed(
    ids: list[str], probability: float, rng: np.random.Generator
) -> dict[str, bool]:
    """Which of the fire doors ``ids`` are shut: each with ``probability``, drawn by ``rng``."""
    draws = rng.random(len(ids))
    return {i: bool(d < probability) for i, d in zip(ids, draws, strict=True)}


def build_fire_doors(world: BoxWorld) -> dict[str, FireDoor]:
    """Every fire door of ``world``'s building, shut or open as the world's knob draws."""
    doors = [lm for lm in world.building.landmarks if is_fire_door(lm.kind)]
    if not doors:
        return {}
    shut = fire_doors_closed(
        [lm.id for lm in doors], world.scene.fire_doors_closed, world.rng("fire_doors")
    )
    return {lm.id: _build(world, lm, shut[lm.id]) for lm in doors}


def _door_line(world: BoxWorld, lm: Landmark) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The door line's two ends (wall to wall) and the unit direction its corridor runs."""
    b = world.building
    pos = np.asarray(lm.pos, float)
    best = None
    for e in b.edges:
        a, c = (np.asarray(b.waypoint(w).pos, float) for w in (e.a, e.b))
        d = c - a
        t = float(np.clip(np.dot(pos - a, d) / max(float(np.dot(d, d)), 1e-12), 0.0, 1.0))
        foot = a + t * d
        dist = float(np.hypot(*(pos - foot)))
        if best is None or dist < best[0]:
            best = (dist, foot, d / float(np.hypot(*d)), b.edge_width(e))
    _, foot, along, width = best
    across = np.array([-along[1], along[0]])
    reach = width / 2.0 + WALL_MARGIN_M
    line = LineString([foot - across * reach, foot + across * reach])
    chord = chord_through(world.floor_space().intersection(line), foot)
    if chord is None:
        raise FireDoorError(f"fire door {lm.id!r}: no open floor across its corridor")
    p0, p1 = (np.asarray(c, float) for c in chord.coords[:2])
    return p0, p1, along


def _build(world: BoxWorld, lm: Landmark, closed: bool) -> FireDoor:
    p0, p1, along = _door_line(world, lm)
    label = OBSTACLE_LABEL
    rgba = world.appearance.door
    h, t = FIRE_DOOR_HEIGHT_M, FIRE_DOOR_THICKNESS_M
    leaf = float(np.hypot(*(p1 - p0))) / 2.0
    bodies = []
    if closed:  # both leaves in the door line, meeting in the middle
        yaw = math.atan2(*(p1 - p0)[::-1])
        half = (leaf - MEETING_GAP_M) / 2.0
        for end, inward in ((p0, p1 - p0), (p1, p0 - p1)):
            c = end + inward / float(np.hypot(*inward)) * half
            bodies.append(
                world.add_box((*map(float, c), h / 2), (half, t / 2, h / 2), yaw, rgba, label)
            )
            _pane(world, c, yaw, label)
    else:  # each leaf swung through 90 degrees, flat against its wall
        yaw = math.atan2(along[1], along[0])
        for end, inward in ((p0, p1 - p0), (p1, p0 - p1)):
            c = end + inward / float(np.hypot(*inward)) * (t / 2) + along * (leaf / 2)
            bodies.append(
                world.add_box((*map(float, c), h / 2), (leaf / 2, t / 2, h / 2), yaw, rgba, label)
            )
            _pane(world, c, yaw, label)
    ends = (tuple(map(float, p0)), tuple(map(float, p1)))
    return FireDoor(lm.id, closed, ends, tuple(bodies))


def _pane(world: BoxWorld, centre: np.ndarray, yaw: float, label: str) -> None:
    """A leaf's vision panel, standing a few mm proud of both its faces (seen, not felt)."""
    z0, z1 = PANE_Z
    world.add_box(
        (float(centre[0]), float(centre[1]), (z0 + z1) / 2),
        (PANE_WIDTH_M / 2, FIRE_DOOR_THICKNESS_M / 2 + 0.004, (z1 - z0) / 2),
        yaw,
        GLASS_RGBA,
        label,
        solid=False,
    )
