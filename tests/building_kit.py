"""Buildings changed for a test: a built-in with something more in it."""

from __future__ import annotations

from pmnav_bt.map.building import Building, Landmark


def with_landmark(building: Building, landmark: Landmark) -> Building:
    """``building`` with one landmark more (validated afresh: ``model_copy`` would keep
    the lookups the original has cached, without the new landmark)."""
    data = building.model_dump()
    data["landmarks"] = [*data["landmarks"], landmark.model_dump()]
    return Building.model_validate(data)


def as_floor(building: Building, n: int) -> Building:
    """``building`` as floor ``n`` of a tower: the same corridors, its rooms numbered
    n01... ("301" on the third floor, "401" on the fourth), as real floors are."""
    data = building.model_dump()
    data["name"] = f"{building.name}_{n}"
    for room in data["rooms"]:
        room["sign"] = f"{n}{room['sign'][1:]}"
        room["name"] = room["name"].replace(room["name"].split()[-1], room["sign"])
    return Building.model_validate(data)
