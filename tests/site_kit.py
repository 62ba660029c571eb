"""Small sites for tests: levels written inline, each a short corridor with rooms and lifts."""

from __future__ import annotations

import copy
from typing import Any


def level_data(
    name: str, rooms: dict[str, float], lifts: dict[str, float], length: float = 40.0
) -> dict[str, Any]:
    """A one-corridor level: ``start`` at x=0 to ``end1`` at x=``length``; each room's door
    on the north wall at its x; each lift (kind elevator) on the south wall at its x."""
    return {
        "schema_version": 1,
        "name": name,
        "waypoints": [
            {"id": "start", "kind": "start", "pos": [0.0, 0.0]},
            {"id": "end1", "kind": "end", "pos": [length, 0.0]},
        ],
        "edges": [["start", "end1"]],
        "rooms": [
            {"id": rid, "name": f"Room {rid[4:]}", "door": [x, 1.2], "sign": rid[4:]}
            for rid, x in rooms.items()
        ],
        "landmarks": [
            {"id": lid, "kind": "elevator", "name": lid, "pos": [x, -1.2], "sign": lid}
            for lid, x in lifts.items()
        ],
    }


def two_level_site() -> dict[str, Any]:
    """L1 and L2, joined by liftA (at x=5 on both) and liftB (at x=35 on both)."""
    l1 = level_data("ground", {"room101": 10.0, "room102": 30.0}, {"lA": 5.0, "lB": 35.0})
    l2 = level_data("first", {"room201": 10.0, "room202": 30.0}, {"lA": 5.0, "lB": 35.0})
    return {
        "site_version": 1,
        "name": "twin",
        "levels": [
            {"name": "L1", "elevation": 0.0, "building": l1},
            {"name": "L2", "elevation": 4.0, "building": l2},
        ],
        "lifts": [
            {"id": "liftA", "name": "Lift A", "lobbies": {"L1": "lA", "L2": "lA"}},
            {"id": "liftB", "name": "Lift B", "lobbies": {"L1": "lB", "L2": "lB"}},
        ],
    }


def changed(data: dict[str, Any], **top: Any) -> dict[str, Any]:
    """A deep copy of ``data`` with top-level keys replaced."""
    out = copy.deepcopy(data)
    out.update(top)
    return out
