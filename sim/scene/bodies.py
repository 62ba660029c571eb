"""Compound bodies: one pybullet body made of several coloured boxes, cylinders and spheres.

A bench, a bed or a person is many pieces but one thing: it is built as one multibody
whose base carries a single collision shape (the envelope the robot bumps into) and
whose fixed links carry the visible pieces, each with its own colour. One body moves
with one call (people walk), and the robot's collision check sees one simple shape.

Coordinates of the pieces are in the body's frame: origin on the floor at the centre of
the footprint, x along the body (along the wall for clutter, forward for a person), y to
its left (out of the wall into the corridor for clutter), z up.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from shapely.geometry import Polygon

from pmnav_bt.sim._pybullet import p

RGBA = tuple[float, float, float, float]


@dataclass(frozen=True)
class Part:
    """One visible piece: ``shape`` "box" (``size`` = half extents x, y, z), "cylinder"
    (``size`` = radius, length; upright) or "sphere" (``size`` = radius,), centred ``at``."""

    shape: str
    size: tuple[float, ...]
    at: tuple[float, float, float]
    rgba: RGBA


def box(x0: float, x1: float, y0: float, y1: float, z0: float, z1: float, rgba: RGBA) -> Part:
    """A box spanning [x0, x1] x [y0, y1] x [z0, z1] in the body frame (either order)."""
    return Part(
        "box",
        (abs(x1 - x0) / 2.0, abs(y1 - y0) / 2.0, abs(z1 - z0) / 2.0),
        ((x0 + x1) / 2.0, (y0 + y1) / 2.0, (z0 + z1) / 2.0),
        rgba,
    )


def cylinder(x: float, y: float, radius: float, z0: float, z1: float, rgba: RGBA) -> Part:
    """An upright cylinder of ``radius`` at (x, y) from ``z0`` to ``z1``."""
    return Part("cylinder", (radius, z1 - z0), (x, y, (z0 + z1) / 2.0), rgba)


def sphere(x: float, y: float, z: float, radius: float, rgba: RGBA) -> Part:
    return Part("sphere", (radius,), (x, y, z), rgba)


def _visual(part: Part, client: int, at: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> int:
    """The visual shape of ``part``, its centre ``at`` in the frame it is attached to."""
    if part.shape == "box":
        return p.createVisualShape(
            p.GEOM_BOX,
            halfExtents=part.size,
            rgbaColor=part.rgba,
            visualFramePosition=at,
            physicsClientId=client,
        )
    if part.shape == "cylinder":
        return p.createVisualShape(
            p.GEOM_CYLINDER,
            radius=part.size[0],
            length=part.size[1],
            rgbaColor=part.rgba,
            visualFramePosition=at,
            physicsClientId=client,
        )
    if part.shape == "sphere":
        return p.createVisualShape(
            p.GEOM_SPHERE,
            radius=part.size[0],
            rgbaColor=part.rgba,
            visualFramePosition=at,
            physicsClientId=client,
        )
    raise ValueError(f"part shape {part.shape!r}: choose box, cylinder or sphere")


@dataclass(frozen=True)
class Envelope:
    """The collision shape of a compound body: a box of half extents ``half`` (x, y, z)
    from ``bottom`` up, or an upright cylinder (``radius``, ``height``) when ``radius``."""

    half: tuple[float, float, float] = (0.0, 0.0, 0.0)
    radius: float = 0.0
    height: float = 0.0
    bottom: float = 0.0  # a box's lowest point above the floor (a board on the wall)

    def shape(self, client: int) -> int:
        """The pybullet collision shape in the body frame."""
        if self.radius > 0.0:
            return p.createCollisionShape(
                p.GEOM_CYLINDER,
                radius=self.radius,
                height=self.height,
                collisionFramePosition=(0.0, 0.0, self.height / 2.0),
                physicsClientId=client,
            )
        return p.createCollisionShape(
            p.GEOM_BOX,
            halfExtents=self.half,
            collisionFramePosition=(0.0, 0.0, self.bottom + self.half[2]),
            physicsClientId=client,
        )


def footprint(x: float, y: float, yaw: float, half_x: float, half_y: float) -> Polygon:
    """The floor rectangle ``2 half_x`` x ``2 half_y`` centred at (x, y), turned by ``yaw``."""
    c, s = math.cos(yaw), math.sin(yaw)
    corners = [(-half_x, -half_y), (half_x, -half_y), (half_x, half_y), (-half_x, half_y)]
    return Polygon([(x + c * u - s * v, y + s * u + c * v) for u, v in corners])


def compound_body(
    client: int,
    parts: list[Part],
    xy: tuple[float, float],
    yaw: float,
    envelope: Envelope | None,
) -> int:
    """One static body at ``xy`` turned by ``yaw``: the ``parts`` (at least one) as its
    look, and the ``envelope`` (or nothing: visible only) as its collision shape. Call it
    under the world's lock."""
    col = envelope.shape(client) if envelope is not None else -1
    # The first part is the base's visual (a body without one would show its collision
    # shape in the camera); the others hang on it as fixed links.
    base, links = parts[0], parts[1:]
    n = len(links)
    return p.createMultiBody(
        0.0,
        col,
        _visual(base, client, base.at),
        (xy[0], xy[1], 0.0),
        p.getQuaternionFromEuler((0.0, 0.0, yaw)),
        baseInertialFramePosition=(0.0, 0.0, 0.0),
        linkMasses=[0.0] * n,
        linkCollisionShapeIndices=[-1] * n,
        linkVisualShapeIndices=[_visual(part, client) for part in links],
        linkPositions=[part.at for part in links],
        linkOrientations=[(0.0, 0.0, 0.0, 1.0)] * n,
        linkInertialFramePositions=[(0.0, 0.0, 0.0)] * n,
        linkInertialFrameOrientations=[(0.0, 0.0, 0.0, 1.0)] * n,
        linkParentIndices=[0] * n,
        linkJointTypes=[p.JOINT_FIXED] * n,
        linkJointAxis=[(0.0, 0.0, 1.0)] * n,
        physicsClientId=client,
    )
