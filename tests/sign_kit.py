"""Buildings of chosen room codes and sign readings of chosen confidence, for the
matching tests (the recogniser's own reads are tested on rendered plates)."""

from __future__ import annotations

from pmnav_bt.map.building import building_from_data

SURE = 0.9995  # a character the recogniser is sure of
UNSURE = 0.6  # a character it hesitates over (as its misreads of small text come)


def corridor(*signs: str, pitch: float = 3.0):
    """A building with one corridor and a room per sign, doors ``pitch`` apart in order."""
    data = {
        "schema_version": 1,
        "name": "codes",
        "waypoints": [
            {"id": "start", "kind": "start", "pos": [0, 0]},
            {"id": "end1", "kind": "end", "pos": [pitch * (len(signs) + 1), 0]},
        ],
        "edges": [["start", "end1"]],
        "rooms": [
            {"id": f"r{i}", "door": [pitch * (i + 1), 1.2], "sign": s}
            for i, s in enumerate(signs)
        ],
    }
    return building_from_data(data, "codes.yaml")


def read(text: str, unsure: set[int] = frozenset(), score: float = UNSURE):
    """One line read: the characters at the indices ``unsure`` read with ``score``, the
    others sure."""
    chars = tuple(score if i in unsure else SURE for i in range(len(text)))
    return [(text, sum(chars) / len(chars), chars)]
