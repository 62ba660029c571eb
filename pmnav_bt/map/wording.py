"""Places of the map in the building's words, for failure reasons a person can act on.

A failure that says "BLOCKED: obstacle 0.9 m ahead" tells a person on site nothing
they can go and look at; "the corridor between room8 and turn2 blocked for 10 s" or
"fire door at branch1 closed" does. The words are the map's own: a corridor is named
by the two places (rooms, landmarks, waypoints) at the ends of its priori-map segment,
a fire door by the waypoint (node) it stands at.

A fire door is a landmark of the building file whose ``kind`` names one
(``pmnav_bt.map.landmark_kinds.FIRE_DOOR``), standing across its corridor; something
that shuts the way within ``FIRE_DOOR_NEAR_M`` of one is taken for that door, closed.
"""

from __future__ import annotations

import math

from pmnav_bt.map.landmark_kinds import is_fire_door
from pmnav_bt.map.priori_map import PrioriMap, Segment
from pmnav_bt.map.signs_only import MapAccessError

# The leaves cross the corridor where the map links the door to its centre line (its
# node: sim/scene/fire_doors.py builds them there, whichever wall ``pos`` is at); the
# depth a drive measures to what shut its way is good to a few tenths of a metre.
FIRE_DOOR_NEAR_M = 1.5


def corridor_words(seg: Segment) -> str:
    """``seg`` as a person would name it: "the corridor between room8 and turn2"."""
    return f"the corridor between {seg.a} and {seg.b}"


def fire_door_at(pm: PrioriMap, point: tuple[float, float]) -> str | None:
    """The words for a fire door of the map within ``FIRE_DOOR_NEAR_M`` of ``point``
    ("fire door at branch1", or its name where it has one); None when there is none."""
    best, words = FIRE_DOOR_NEAR_M, None
    for lm in pm.building.landmarks:
        if not is_fire_door(lm.kind):
            continue
        place = pm.places.get(lm.id)
        # its leaves cross the corridor where the map puts the door on the centre line
        where = pm.node_xy(place.node) if place is not None else lm.pos
        d = math.dist(point, where)
        if d <= best:
            at = place.node if place is not None else lm.id
            best, words = d, f"fire door {lm.name} at {at}" if lm.name else f"fire door at {at}"
    return words


def shut_way_words(pm: PrioriMap, point: tuple[float, float]) -> tuple[str, str | None]:
    """Where a way shut at map ``point`` is, in words: the corridor, and the fire door
    there (None: none). The map-less baseline knows neither: "the way ahead"."""
    try:
        seg = pm.locate(*point).segment
    except MapAccessError:
        return "the way ahead", None
    return corridor_words(seg), fire_door_at(pm, point)
