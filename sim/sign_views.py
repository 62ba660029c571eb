"""Rendered views of sign plates from chosen distances and angles (perception benchmarks).

A view stands ``distance`` metres from a sign plate's centre, ``angle`` off the plate's
normal (towards either end of the wall), inside the corridor with room for the robot,
and looks at the plate with a seeded yaw jitter that keeps it in the frame.
"""

from __future__ import annotations

import math
import random
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np
from shapely.geometry import Point

from pmnav_bt.seams import CameraIntrinsics, Entity, Observation, Pose2D, sign_label
from pmnav_bt.sim.render import render_camera
from pmnav_bt.sim.robot import CAMERA_HEIGHT, HFOV, RADIUS
from pmnav_bt.sim.world import SimWorld, WallItem


@dataclass(frozen=True)
class SignView:
    """One rendered view of a sign: the entity it names, where the camera stood, the frame."""

    entity: Entity
    text: str
    distance: float
    angle: float  # rad off the plate's normal
    observation: Observation


def plates(world: SimWorld) -> list[tuple[Entity, WallItem]]:
    """Every sign plate of the world with the entity it names (rooms, then landmarks)."""
    out = [(Entity.room(rid), item) for rid, item in world.signs.items()]
    out += [(Entity.landmark(lid), item) for lid, item in world.landmark_signs.items()]
    for lid, item in world.landmarks.items():  # plain plates: the landmark is its own sign
        if lid not in world.landmark_signs and item.text and item.z[0] > 1.0:
            out.append((Entity.landmark(lid), item))
    return out


def built_mounting(sign: WallItem, door: WallItem) -> str:
    """How the world hung room sign ``sign`` relative to its ``door`` (``PlateStyle.mounting``
    as built: an ``on_door`` plate of an open door hangs beside it), told from their places:
    ``flag``, ``on_door``, ``above_door``, or ``beside_left`` / ``beside_right`` (the plate on
    the viewer's left / right of the door, facing the wall)."""
    n = np.asarray(door.normal, float)
    if abs(float(np.asarray(sign.normal, float) @ n)) < 0.5:
        return "flag"
    left = np.array([n[1], -n[0]])
    along = float((np.asarray(sign.centre, float) - np.asarray(door.centre, float)) @ left)
    if abs(along) < 0.1:
        return "on_door" if sign.z[1] <= door.z[1] else "above_door"
    return "beside_left" if along > 0 else "beside_right"


def view_pose(
    item: WallItem, distance: float, angle: float, side: int, jitter: float
) -> tuple[Pose2D, float]:
    """The camera pose ``distance`` from the plate at ``angle`` (rad) towards ``side`` (+-1)."""
    n = np.asarray(item.normal, float)
    t = np.array([-n[1], n[0]]) * side
    pos = np.asarray(item.centre, float) + distance * (math.cos(angle) * n + math.sin(angle) * t)
    yaw = math.atan2(item.centre[1] - pos[1], item.centre[0] - pos[0]) + jitter
    return Pose2D(float(pos[0]), float(pos[1]), yaw), yaw


def sample_views(
    world: SimWorld,
    n: int,
    *,
    width: int = 320,
    height: int = 240,
    distances: tuple[float, float] = (1.5, 6.0),
    angles: tuple[float, float] = (0.0, math.radians(70.0)),
    seed: int = 0,
    segmentation: bool = True,
    select: Callable[[str], bool] | None = None,
) -> Iterator[SignView]:
    """``n`` views of random plates of ``world`` (seeded), each from a free spot in the
    corridor; ``select``: only plates whose text it accepts."""
    rng = random.Random(seed)
    k = CameraIntrinsics.from_hfov(width, height, HFOV)
    items = [(e, it) for e, it in plates(world) if select is None or select(it.text)]
    if not items:
        return
    free = world.free_space
    made = tries = 0
    while made < n and tries < 200 * max(n, 1):
        tries += 1
        entity, item = items[rng.randrange(len(items))]
        d = rng.uniform(*distances)
        a = rng.uniform(*angles)
        # Keep the plate (0.8 m wide) inside the frame: jitter at most what the FOV leaves.
        half_plate = math.atan2(0.45, d)
        room = max(0.0, HFOV / 2 - half_plate - math.radians(2))
        pose, _ = view_pose(item, d, a, rng.choice((-1, 1)), rng.uniform(-room, room))
        if not free.contains(Point(pose.x, pose.y).buffer(RADIUS + 0.05)):
            continue
        if world.clearance(pose.x, pose.y, RADIUS) < 0.02:
            continue
        made += 1
        yield SignView(entity, item.text, d, a, observe(world, pose, k, segmentation))


def observe(
    world: SimWorld, pose: Pose2D, k: CameraIntrinsics, segmentation: bool = True
) -> Observation:
    """The robot camera's frame from ``pose`` (RGB, depth, and labels if ``segmentation``)."""
    f = render_camera(
        world, pose.x, pose.y, pose.yaw, k, height=CAMERA_HEIGHT, segmentation=segmentation
    )
    with world.lock:
        labels = dict(world.labels)
    return Observation(
        rgb=f.rgb,
        pose=pose,
        stamp=0.0,
        intrinsics=k,
        depth=f.depth,
        segmentation=f.segmentation,
        labels=labels,
        camera_height=CAMERA_HEIGHT,
    )


MIN_PLATE_PX = 15  # labelled pixels of a plate for its box to count as in view


def labelled_plate_box(obs: Observation, rid: str) -> tuple[float, float, float, float] | None:
    """Room ``rid``'s sign's box (x0, y0, x1, y1) from the simulator's labels; None with
    too little of it in view. Measures the door placement alone, not the reading."""
    ids = [i for i, name in obs.labels.items() if name == sign_label(rid)]
    m = np.isin(obs.segmentation, ids)
    if m.sum() < MIN_PLATE_PX:
        return None
    ys, xs = np.nonzero(m)
    return (float(xs.min()), float(ys.min()), float(xs.max()), float(ys.max()))
