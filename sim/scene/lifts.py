"""Lift cabins: behind the doors of each lift landmark a level's world is told to open
(``SimWorld(lifts=...)``, the lobbies of a site's lifts), a recess the robot can drive
into: a doorway through the corridor wall as wide as the doors, and a cabin of
``CABIN_WIDTH_M`` x ``CABIN_DEPTH_M`` behind it (``pmnav_bt.map.lift_doorway``), walled
on three sides. Its two door leaves are the lift landmark's own (the world builds them
on the wall); ``Cabin.set_door`` slides them away and back. Where the cabin comes with
no room in it, a cart stands in its middle (``Cabin.fill``), taller than the camera's
lowest ray there, so the robot's depth sees it.

The world builds the cabins (it calls ``doorway_cut`` while it builds its walls and
``build_cabin`` once the lift's doors hang), so this module knows it only by the
Protocols of ``host.py``. Which level the cabin is at, when its doors move and who rides
in it is the lift's business (``pmnav_bt.sim.lift``).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from pmnav_bt.map.landmark_kinds import ELEVATOR_PANEL_M, ELEVATOR_WIDTH_M
from pmnav_bt.map.lift_doorway import CABIN_DEPTH_M, CABIN_WIDTH_M, DOORWAY_WALL_M
from pmnav_bt.seams import WALL_LABEL, Pose2D
from pmnav_bt.sim._pybullet import p
from pmnav_bt.sim.scene.host import BoxWorld, Doorway

CABIN_RGBA = (0.78, 0.80, 0.82, 1.0)  # brushed steel
# The cart of a cabin that comes full: a hospital linen or meal trolley, 0.8 m square and
# 1.4 m high, in the cabin's middle (the camera's lowest ray passes about 0.7 m up there).
CART_SIZE_M = 0.8
CART_HEIGHT_M = 1.4
HIDDEN_Z = -5.0  # an open door's leaves are slid away: under the floor, out of every view


def doorway_s(wall_s: float) -> float:
    """Where along its wall the doorway's centre is, for a lift landmark hung at
    ``wall_s``: the doors are half a panel beyond the landmark's centre (the world hangs
    the call panel on the viewer's right, at lower ``s``)."""
    return wall_s + ELEVATOR_PANEL_M / 2.0


def doorway_cut(
    length: float, openings: Sequence[float], ext_a: float = 0.0, ext_b: float = 0.0
) -> list[tuple[float, float]]:
    """The pieces of a wall from ``-ext_a`` to ``length + ext_b`` left standing round
    doorways centred at ``openings`` (distances along it)."""
    pieces, start = [], -ext_a
    for s in sorted(openings):
        lo, hi = s - ELEVATOR_WIDTH_M / 2.0, s + ELEVATOR_WIDTH_M / 2.0
        if lo > start:
            pieces.append((start, lo))
        start = max(start, hi)
    if length + ext_b > start:
        pieces.append((start, length + ext_b))
    return pieces


class CabinWorld(BoxWorld, Protocol):
    """A world that also stands obstacles on its floor and takes them away (the cart)."""

    def add_obstacle(self, x: float, y: float, size: float, height: float = 1.0) -> int: ...

    def remove_obstacle(self, body: int) -> None: ...


def open_stretches(doorways: Iterable[Doorway], a, b) -> list[tuple[float, float]]:
    """The stretches (from, to metres from ``a``) of the wall face from ``a`` to ``b`` that
    no doorway of ``doorways`` goes through: where a surface may cover the wall."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    length = float(np.linalg.norm(b - a))
    t = (b - a) / length
    cuts = []
    for d in doorways:
        u = np.asarray(d.centre, float) - a
        s = float(u @ t)
        if abs(u[0] * t[1] - u[1] * t[0]) < 0.01 and 0.0 <= s <= length:
            cuts.append(s)
    return doorway_cut(length, cuts)


@dataclass
class Cabin:
    """One lift's cabin on one level: the doorway's ``centre`` on the corridor wall's face,
    ``into`` the cabin, its leaves (pybullet bodies) and where they hang closed."""

    world: CabinWorld
    landmark: str
    centre: tuple[float, float]
    into: tuple[float, float]
    leaves: tuple[int, ...]
    closed: tuple[tuple[tuple[float, float, float], tuple[float, ...]], ...]
    cart: int | None = None
    is_open: bool = False

    @property
    def middle(self) -> tuple[float, float]:
        d = DOORWAY_WALL_M + CABIN_DEPTH_M / 2.0
        return self.centre[0] + d * self.into[0], self.centre[1] + d * self.into[1]

    @property
    def frame(self) -> Pose2D:
        """The cabin's frame on this level: its middle, x into the cabin."""
        x, y = self.middle
        return Pose2D(x, y, math.atan2(self.into[1], self.into[0]))

    def holds(self, x: float, y: float) -> bool:
        """Whether the point (x, y) is on the cabin's floor (past the corridor wall)."""
        u = np.subtract((x, y), self.centre)
        along_in = float(u @ self.into)
        across = float(abs(u[0] * self.into[1] - u[1] * self.into[0]))
        return DOORWAY_WALL_M <= along_in <= DOORWAY_WALL_M + CABIN_DEPTH_M and (
            across <= CABIN_WIDTH_M / 2.0
        )

    def clearings(self, wall: float) -> list[np.ndarray]:
        """Where a wall built from a grid (``sim.walls=grid``) must leave room for the
        lift, as map-frame polygons: the doorway through the real wall (``wall`` m thick
        there) and the cabin behind it to its walls' outer faces. The grid walls the
        shaft round (an imported RMF lift: ``map/rmf_grid.py``), and the cabin, built with
        walls of its own, stands in it."""
        c, u = np.asarray(self.centre, float), np.asarray(self.into, float)
        v = np.array([-u[1], u[0]])
        t = DOORWAY_WALL_M

        def box(near: float, far: float, half: float) -> np.ndarray:
            return np.array([c + u * near - v * half, c + u * far - v * half,
                             c + u * far + v * half, c + u * near + v * half])  # fmt: skip

        inside = max(wall, t)
        return [
            box(-0.05, inside + 0.05, ELEVATOR_WIDTH_M / 2.0),
            box(inside, t + CABIN_DEPTH_M + t, CABIN_WIDTH_M / 2.0 + t),
        ]

    def set_door(self, is_open: bool) -> None:
        """Open the doors (the leaves slid away) or shut them."""
        if is_open == self.is_open:
            return
        with self.world.lock:
            for body, (pos, orn) in zip(self.leaves, self.closed, strict=True):
                at = (pos[0], pos[1], HIDDEN_Z) if is_open else pos
                p.resetBasePositionAndOrientation(
                    body, at, orn, physicsClientId=self.world.client
                )
        self.is_open = is_open

    def fill(self) -> None:
        """A cart in the cabin's middle (the cabin comes with no room for the robot)."""
        if self.cart is not None:
            return
        self.cart = self.world.add_obstacle(*self.middle, CART_SIZE_M, CART_HEIGHT_M)

    def empty(self) -> None:
        """The cart leaves with the cabin."""
        if self.cart is None:
            return
        self.world.remove_obstacle(self.cart)
        self.cart = None


def build_cabin(
    world: CabinWorld, landmark: str, centre, normal, leaves: Sequence[int]
) -> Cabin:
    """The cabin behind the doorway at ``centre`` on a corridor wall whose ``normal``
    points into the corridor, walled on three sides (the world has cut the doorway:
    ``doorway_cut``); ``leaves``: the lift's door leaves, hanging closed."""
    into = (-float(normal[0]), -float(normal[1]))
    c = np.asarray(centre, float)
    u, v = np.asarray(into), np.array([-into[1], into[0]])
    t, d, w, h = DOORWAY_WALL_M, CABIN_DEPTH_M, CABIN_WIDTH_M, world.building.wall_height
    yaw = math.atan2(u[1], u[0])
    back = c + u * (t + d + t / 2.0)
    world.add_box((*back, h / 2.0), (t / 2.0, w / 2.0 + t, h / 2.0), yaw, CABIN_RGBA, WALL_LABEL)
    for side in (-1.0, 1.0):
        mid = c + u * (t + d / 2.0) + v * side * (w / 2.0 + t / 2.0)
        world.add_box((*mid, h / 2.0), (d / 2.0 + t, t / 2.0, h / 2.0), yaw, CABIN_RGBA, WALL_LABEL)
    with world.lock:
        closed = tuple(
            tuple(p.getBasePositionAndOrientation(b, physicsClientId=world.client))
            for b in leaves
        )
    return Cabin(world, landmark, (float(c[0]), float(c[1])), into, tuple(leaves), closed)
