"""What the scene's parts use of the world they fill: ``pmnav_bt.sim.world.SimWorld``
satisfies ``SceneWorld``, its ``WallItem`` satisfies ``Mounted``. The world builds the
scene, so the scene knows the world only by these Protocols (no import back)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from contextlib import AbstractContextManager
from typing import Protocol

import numpy as np
from shapely.geometry import MultiPolygon, Polygon

from pmnav_bt.config import WorldConfig
from pmnav_bt.map.building import Building


class Mounted(Protocol):
    """Something on a corridor wall (a door, a sign plate, a landmark)."""

    label: str
    kind: str
    centre: tuple[float, float]  # on the wall surface
    normal: tuple[float, float]  # unit, from the wall into the corridor
    width: float  # along the wall
    z: tuple[float, float]  # bottom and top heights


class Crossing(Protocol):
    """Something across a corridor (a fire door): its ``line`` from wall to wall."""

    line: tuple[tuple[float, float], tuple[float, float]]


class Doorway(Protocol):
    """A way through a corridor wall (a lift's cabin, ``lifts.Cabin``): its centre on the
    wall's face and the direction through it, away from the corridor."""

    centre: tuple[float, float]
    into: tuple[float, float]


class Segment(Protocol):
    @property
    def length(self) -> float: ...


class SceneWorld(Protocol):
    """A built world: its building, config, walls and what hangs on them; a pybullet
    client with its lock; bodies registered by label; the floor and its obstacles."""

    building: Building
    scene: WorldConfig
    client: int
    lock: AbstractContextManager
    walls: Sequence[Segment]
    annotated_walls: int  # walls[:annotated_walls] bound the corridors; the rest hang items
    doors: Mapping[str, Mounted]
    signs: Mapping[str, Mounted]
    landmarks: Mapping[str, Mounted]
    landmark_signs: Mapping[str, Mounted]
    fire_doors: Mapping[str, Crossing]
    cabins: Mapping[str, Doorway]  # lift landmark id -> the doorway to its cabin

    def rng(self, part: str) -> np.random.Generator: ...

    def floor_space(self) -> Polygon | MultiPolygon: ...

    def obstacle_footprints(self, below: float) -> list[Polygon]: ...

    def register(
        self,
        body: int,
        label: str,
        solid: bool = False,
        footprint: Polygon | None = None,
        bottom: float = 0.0,
    ) -> int: ...


class Painted(Protocol):
    """The part of the world's look (``appearance.Appearance``) that boxes take."""

    door: tuple[float, ...]  # RGBA of door leaves


class BoxWorld(SceneWorld, Protocol):
    """A world that also adds plain static boxes (barriers, fire-door leaves)."""

    appearance: Painted

    def add_box(
        self,
        centre: tuple[float, float, float],
        half_extents: tuple[float, float, float],
        yaw: float,
        rgba: tuple[float, ...],
        label: str,
        *,
        solid: bool = True,
        collision: bool | None = None,
    ) -> int: ...
