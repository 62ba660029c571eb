"""The landmark kinds a building file may name, and what each is in a world.

A landmark's ``kind`` is free text (``kind: elevator``), matched without regard to case.
Three shapes have bodies of their own: the simulator builds a lift's doors, a flight of
steps, a reception counter, each with its name plate (``sign``) beside or above it.
A fire door is not on a wall but across its corridor: a pair of leaves, shut or held open
(sim/scene/fire_doors.py); it has no sign to read, so no plan looks for it, and a way shut
near one is reported as that door closed (pmnav_bt/map/wording.py). Every other kind
(``sign``, ``exit``, ``fire_extinguisher`` ...) is a name plate on the wall. ``SHAPES``
is the one list: the simulator builds from it, ``pmnav validate`` checks what fits on a
wall by it, and docs/building-format.md ("Landmark kinds") names every kind in it (a
test holds the two together).

A shape is *solid* when it stands out into the corridor (stairs 0.45 m, a desk 0.7 m):
the robot must drive round it, and its footprint is taken off the floor the evaluation
measures shortest paths (SPL) on. A flush one (a plate, the lift's doors at 6 cm) only
marks the wall. A fire door is solid when it is shut and flush when its leaves are held
open against the walls.
"""

from __future__ import annotations

from dataclasses import dataclass

from pmnav_bt.map.signage import HISTORICAL_PLATE_M

FLUSH_M = 0.1  # a body standing out of its wall less than this is flush with it
PLATE_BACKING_M = 0.02  # a plate's backing board is 1 cm wider than its face each side

ELEVATOR_WIDTH_M = 1.6  # the lift's doors, both leaves
ELEVATOR_FRAME_M = 0.12  # its frame each side
ELEVATOR_PANEL_M = 0.3  # the call-button panel beside it
ELEVATOR_DEPTH_M = 0.06  # the frame's depth out of the wall
STAIRS_LENGTH_M = 1.8  # six steps along the wall
STAIRS_DEPTH_M = 0.45  # out into the corridor
DESK_LENGTH_M = 1.8
DESK_DEPTH_M = 0.6  # the desk; its counter top overhangs 0.05 m each way
DESK_TOP_M = 0.1  # how much longer and deeper the counter top is than the desk
# A double fire door across a 2.4 m corridor: two 1.2 m leaves of a 54 mm door (FD30s are
# 44-54 mm), 2.1 m high; held open, each leaf lies flat against its wall.
FIRE_DOOR_LEAF_M = 1.2
FIRE_DOOR_THICKNESS_M = 0.054
FIRE_DOOR_HEIGHT_M = 2.1


@dataclass(frozen=True)
class LandmarkShape:
    """What a group of landmark kinds is in a world: how much wall it takes, how far it
    stands out of the wall, and what the simulator builds."""

    name: str
    kinds: tuple[str, ...]  # the names a file may give it (lower case); () for any other
    span_m: float  # along the wall, its name plate beside it not counted
    depth_m: float  # out of the wall into the corridor
    looks: str  # what the simulator builds, for the docs
    across: bool = False  # it stands across its corridor (a fire door), not on a wall

    @property
    def solid(self) -> bool:
        """True when it stands in the corridor: the robot must go round it. A shape across
        the corridor is solid only when shut, which the world decides, not the shape."""
        return not self.across and self.depth_m >= FLUSH_M

    @property
    def readable(self) -> bool:
        """True when it carries a name plate a robot can look for (not a fire door)."""
        return not self.across


ELEVATOR = LandmarkShape(
    "elevator",
    ("elevator", "lift"),
    ELEVATOR_WIDTH_M + 2 * ELEVATOR_FRAME_M + ELEVATOR_PANEL_M,
    ELEVATOR_DEPTH_M,
    "steel double doors in a frame, a call-button panel, the name plate beside them",
)
STAIRS = LandmarkShape(
    "stairs",
    ("stairs", "stair", "staircase", "stairway"),
    STAIRS_LENGTH_M,
    STAIRS_DEPTH_M,
    "six steps against the wall, the name plate on the wall above them",
)
DESK = LandmarkShape(
    "desk",
    ("reception_desk", "reception", "desk", "counter", "information_desk"),
    DESK_LENGTH_M + DESK_TOP_M,
    DESK_DEPTH_M + DESK_TOP_M,
    "a desk with a counter top against the wall, the name plate on the wall above it",
)
PLATE = LandmarkShape(
    "name plate",
    (),
    HISTORICAL_PLATE_M + PLATE_BACKING_M,
    0.0,
    "its name plate on the wall: 0.8 m wide with the file's signage, or a one-line plate "
    "as wide as its text in the building's style",
)
FIRE_DOOR = LandmarkShape(
    "fire door",
    ("fire_door", "fire door", "firedoor"),
    FIRE_DOOR_LEAF_M,  # beside its point, where a leaf lies held open
    FIRE_DOOR_THICKNESS_M,
    "two door leaves across the corridor, wall to wall: shut (solid) or held open flat "
    "against the walls (`world.fire_doors_closed`); no name plate",
    across=True,
)
SHAPES: tuple[LandmarkShape, ...] = (ELEVATOR, STAIRS, DESK, FIRE_DOOR, PLATE)


def landmark_shape(kind: str) -> LandmarkShape:
    """The shape of a landmark of ``kind`` (any case, outer spaces ignored); a name plate
    for a kind not listed."""
    k = kind.strip().lower()
    return next((s for s in SHAPES if k in s.kinds), PLATE)


def is_fire_door(kind: str) -> bool:
    """True for a landmark ``kind`` that names a fire door (``FIRE_DOOR.kinds``)."""
    return landmark_shape(kind) is FIRE_DOOR


def known_kinds() -> list[str]:
    """Every kind with a body of its own, in the order of ``SHAPES``."""
    return [k for s in SHAPES for k in s.kinds]


def kinds_table() -> str:
    """The Markdown table of ``SHAPES`` in docs/building-format.md ("Landmark kinds")."""
    rows = ["| kinds | in the simulator | along the wall | out of the wall | solid |"]
    rows.append("|---|---|---|---|---|")
    for s in SHAPES:
        kinds = ", ".join(f"`{k}`" for k in s.kinds) if s.kinds else "any other"
        solid = "when shut" if s.across else "yes" if s.solid else "no"
        rows.append(f"| {kinds} | {s.looks} | {s.span_m:.2f} m | {s.depth_m:.2f} m | {solid} |")
    return "\n".join(rows) + "\n"
