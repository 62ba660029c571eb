"""Buildings changed for a test: a built-in with something more in it."""

from __future__ import annotations

from pmnav_bt.map.building import Building, Landmark


def with_landmark(building: Building, landmark: Landmark) -> Building:
    """``building`` with one landmark more (validated afresh: ``model_copy`` would keep
    the lookups the original has cached, without the new landmark)."""
    data = building.model_dump()
    data["landmarks"] = [*data["landmarks"], landmark.model_dump()]
    return Building.model_validate(data)
