"""Door leaves in the states a corridor shows them: closed, standing open, glazed.

In a weekday hospital or school corridor many doors stand open (wards, classrooms,
offices in use) and some are glazed (clinics, staff rooms, offices with a vision
panel). The config's ``world.doors_open`` and ``world.doors_glass`` are the fractions
of doors in each state, drawn per building and seed from ``world.rng("doors")``: exactly
``round(fraction * doors)`` doors of each, chosen independently (a glazed door may
stand open). The clean preset has every door closed, built exactly as the clean
world always was.

The simulator's corridor wall is one box with nothing behind it, so an open door is
drawn, not cut: the opening shows a dark room (its floor a little lighter) with the
leaf swung into the room seen edge-on beside the hinge. pybullet's tiny renderer
has no transparency, so glass is drawn as a pale blue-grey pane in an aluminium
frame, with a light streak of reflection, a push bar and a kick plate. The door's
frame, its label ``door:<room>`` and its recorded ``WallItem`` stay as they are, so
the oracle and everything that finds a door by its label see every door alike.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from pmnav_bt.config import WorldConfig

RGBA = tuple[float, float, float, float]

ROOM_DARK_RGBA = (0.11, 0.11, 0.12, 1.0)  # an unlit room seen from a lit corridor
ROOM_FLOOR_RGBA = (0.30, 0.30, 0.32, 1.0)  # its floor, catching the corridor's light
ROOM_FLOOR_HEIGHT = 0.3  # m of the doorway showing the room's floor (camera at 1.6 m)
LEAF_EDGE_WIDTH = 0.12  # m of an open leaf seen beside the hinge
LEAF_EDGE_SHADE = 0.7  # the open leaf is in the room's shade
GLASS_RGBA = (0.72, 0.82, 0.86, 1.0)
GLASS_STREAK_RGBA = (0.88, 0.94, 0.96, 1.0)
ALUMINIUM_RGBA = (0.66, 0.68, 0.70, 1.0)
STEEL_RGBA = (0.78, 0.79, 0.80, 1.0)
STILE_WIDTH = 0.07  # the glazed leaf's aluminium frame
KICK_PLATE_HEIGHT = 0.25
PUSH_BAR_Z = (0.98, 1.04)


@dataclass(frozen=True)
class DoorState:
    """How a door stands: ``open`` (into its room) and/or ``glass`` (a glazed leaf)."""

    open: bool = False
    glass: bool = False


CLOSED = DoorState()


@dataclass(frozen=True)
class DoorLeaf:
    """The size and look of a closed leaf: ``width`` x ``height`` m, standing ``depth``
    out of the wall, in ``rgba``, with a lever handle in ``handle_rgba``."""

    width: float
    height: float
    depth: float
    rgba: RGBA
    handle_rgba: RGBA


# box(s, depth, width, z0, z1, rgba, label, out=...): a box on the door's wall centred
# ``s`` m along it (SimWorld._wall_box with the wall bound).
WallBox = Callable[..., int]


def door_states(rooms: Sequence[str], scene: WorldConfig, rng: np.random.Generator) -> dict:
    """The state of every room's door: ``round(fraction * len(rooms))`` open doors and as
    many glazed as the config's fractions say, chosen by ``rng``; all closed when both
    fractions are 0 (nothing is drawn then)."""
    n = len(rooms)
    chosen = {}
    for what, fraction in (("open", scene.doors_open), ("glass", scene.doors_glass)):
        k = int(round(fraction * n))
        chosen[what] = set(rng.choice(n, size=k, replace=False).tolist()) if k else set()
    return {
        room: DoorState(open=i in chosen["open"], glass=i in chosen["glass"])
        for i, room in enumerate(rooms)
    }


def build_leaf(box: WallBox, s: float, label: str, state: DoorState, leaf: DoorLeaf) -> None:
    """The door's leaf (what fills its frame) in ``state``, centred ``s`` m along the wall."""
    if state.open:
        _open_doorway(box, s, label, state, leaf)
    elif state.glass:
        _glass_leaf(box, s, label, leaf)
    else:
        box(s, leaf.depth, leaf.width, 0.0, leaf.height, leaf.rgba, label)
        # Lever handle near the opening edge (the viewer's right, i.e. towards -s).
        hs = s - leaf.width / 2.0 + 0.12
        box(hs, 0.04, 0.14, 0.98, 1.02, leaf.handle_rgba, label, out=leaf.depth)


def _open_doorway(box: WallBox, s: float, label: str, state: DoorState, leaf: DoorLeaf) -> None:
    """The opening onto a dark room, the leaf edge-on beside the hinge (the +s jamb)."""
    w, h, d = leaf.width, leaf.height, leaf.depth
    e = LEAF_EDGE_WIDTH
    rest = w - e
    s_rest = s - w / 2.0 + rest / 2.0
    box(s_rest, d, rest, ROOM_FLOOR_HEIGHT, h, ROOM_DARK_RGBA, label)
    box(s_rest, d, rest, 0.0, ROOM_FLOOR_HEIGHT, ROOM_FLOOR_RGBA, label)
    shade = GLASS_RGBA if state.glass else leaf.rgba
    edge = (*(LEAF_EDGE_SHADE * c for c in shade[:3]), 1.0)
    box(s + w / 2.0 - e / 2.0, d, e, 0.0, h, edge, label)


def _glass_leaf(box: WallBox, s: float, label: str, leaf: DoorLeaf) -> None:
    """A glazed leaf: aluminium stiles and rails round a pale pane, kick plate, push bar."""
    w, h, d = leaf.width, leaf.height, leaf.depth
    sw = STILE_WIDTH
    for side in (-1, 1):
        box(s + side * (w - sw) / 2.0, d, sw, 0.0, h, ALUMINIUM_RGBA, label)
    box(s, d, w - 2 * sw, h - sw, h, ALUMINIUM_RGBA, label)
    box(s, d, w - 2 * sw, 0.0, KICK_PLATE_HEIGHT, STEEL_RGBA, label)
    pane_z0 = KICK_PLATE_HEIGHT
    # The pane stands a little less far out than the frame, so their faces never coincide.
    box(s, d * 0.6, w - 2 * sw, pane_z0, h - sw, GLASS_RGBA, label)
    box(s + 0.18 * w, d * 0.7, 0.06, pane_z0 + 0.1, h - sw - 0.1, GLASS_STREAK_RGBA, label)
    box(s, 0.04, w - 2 * sw - 0.06, *PUSH_BAR_Z, STEEL_RGBA, label, out=d)
