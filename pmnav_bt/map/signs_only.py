"""What a map-less navigator may know of a building: the words on its signs, nowhere.

:class:`SignsOnly` stands where a :class:`~pmnav_bt.map.priori_map.PrioriMap` would (the
tree's ``Context.pm``, the back ends' ``BackendDeps.pm``) for the map-less baseline. It
holds the building's *sign vocabulary* only: which room or landmark each sign text,
name or alias names (what a person is told: "room 108 is the pharmacy"), so that a
grounder can tell that a plate reading "108 Pharmacy" is the goal. Every position is
gone (no waypoints, corridors, floor plan; doors and landmarks at NaN), and reading any
other attribute of the priori-map raises :class:`MapAccessError`.

Where a grounder needs a building convention to go from a sign to its door (the ``ocr``
grounder's ``sign_to_door``, ``door_side``), it comes from ``config.grounder``, not from
the map: the baseline uses the same documented default as PM-Nav (docs/baseline.md).
"""

from __future__ import annotations

import math

from pmnav_bt.map.building import Building

_NOWHERE = (math.nan, math.nan)


class MapAccessError(AttributeError):
    """Something of the map-less baseline tried to read the priori-map."""


def sign_vocabulary(building: Building) -> Building:
    """``building`` without geometry: rooms and landmarks keep their ids, names, aliases,
    kinds and sign texts; positions become NaN; corridors and the floor plan go."""
    return building.model_copy(
        update={
            "waypoints": (),
            "edges": (),
            "floor_plan": None,
            "rooms": tuple(r.model_copy(update={"door": _NOWHERE}) for r in building.rooms),
            "landmarks": tuple(
                lm.model_copy(update={"pos": _NOWHERE}) for lm in building.landmarks
            ),
        }
    )


class SignsOnly:
    """A stand-in for the priori-map with the sign vocabulary only (see the module doc)."""

    def __init__(self, building: Building):
        self.building = sign_vocabulary(building)

    def __getattr__(self, name: str):
        # Only called for attributes that do not exist: everything a PrioriMap has but this.
        raise MapAccessError(
            f"the map-less baseline may not read the priori-map ({name!r}); it knows the "
            "sign vocabulary only"
        )
