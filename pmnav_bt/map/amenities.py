"""What a room is for, where signs show it by a symbol: the toilets.

Buildings mark some rooms with a pictogram and no words (the toilets' man, woman and
wheelchair). To match such a plate the map must say which rooms those are: a room's
``amenity`` in the building file (``toilet``; ``none`` says a room is none, whatever its
name), and where the file leaves it unset, the room's name (``TOILET_NAME``: toilets,
WC, restroom, lavatory, washroom, in English as plans write them). The simulator hangs
pictogram plates on the rooms this names (``sim/scene/signage.py``), and the pictogram
reader's sightings are matched against the same rooms (``perception/sign_match.py``).
"""

from __future__ import annotations

import re
from typing import Literal, Protocol

Amenity = Literal["toilet", "none"]  # the building file's values ("none": not an amenity)
AMENITIES: tuple[str, ...] = ("toilet",)  # the kinds a room can be; each has a pictogram
TOILET_NAME = re.compile(r"\b(toilets?|wc|restrooms?|lavator(y|ies)|washrooms?)\b", re.I)


class _Room(Protocol):
    amenity: str | None

    @property
    def display_name(self) -> str: ...


def room_amenity(room: _Room) -> str | None:
    """The amenity ``room`` is (``"toilet"``), or None: the file's ``amenity`` where set,
    else what its name says."""
    if room.amenity is not None:
        return None if room.amenity == "none" else room.amenity
    return "toilet" if TOILET_NAME.search(room.display_name) else None
