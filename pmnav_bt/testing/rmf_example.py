"""A small Open-RMF traffic-editor building, for tests of ``pmnav map import-rmf``.

One level ``L1`` drawn at 0.05 m per pixel (one measurement: 200 px = 10 m): a corridor
30 m long and 3 m wide between walls at pixel rows 100 and 160 (map y -5 and -8), a room
above it behind the door ``office`` (1 m, centred at x 12.5 m), a lane 0.5 m off the
corridor's centre line (row 120) with a stub through the door to the vertex ``desk``, a
charger at the lane's west end and a named vertex ``notice_board`` by the south wall.
"""

from __future__ import annotations

from pathlib import Path

import yaml

SCALE_M_PER_PX = 0.05
CORRIDOR = {"west": 0.0, "east": 30.0, "north": -5.0, "south": -8.0}  # map frame, metres
DOOR = {"name": "office", "centre": (12.5, -5.0)}


def example_rmf() -> dict:
    """The building as plain data (``yaml.safe_dump`` it to get a ``.building.yaml``)."""
    v = [
        [0, 100, 0, ""], [240, 100, 0, ""], [260, 100, 0, ""], [600, 100, 0, ""],  # 0-3
        [600, 160, 0, ""], [0, 160, 0, ""],  # 4-5: corridor's south corners
        [200, 100, 0, ""], [200, 40, 0, ""], [300, 40, 0, ""], [300, 100, 0, ""],  # 6-9 room
        [40, 120, 0, "robot_charger", {"is_charger": [4, True]}],  # 10
        [560, 120, 0, ""],  # 11
        [250, 120, 0, ""], [250, 70, 0, "desk"],  # 12-13: the stub into the room
        [400, 150, 0, "notice_board"],  # 14
        [0, 300, 0, ""], [200, 300, 0, ""],  # 15-16: the measurement
    ]
    wall = {"alpha": [3, 1.0], "texture_name": [1, "default"]}
    walls = [[0, 6], [6, 1], [2, 9], [9, 3], [3, 4], [4, 5], [5, 0], [6, 7], [7, 8], [8, 9]]
    lane = {"bidirectional": [4, True], "graph_idx": [2, 0]}
    return {
        "coordinate_system": "reference_image",
        "name": "example",
        "levels": {
            "L1": {
                "drawing": {"filename": "example.png"},
                "elevation": 0,
                "vertices": v,
                "measurements": [[15, 16, {"distance": [3, 200 * SCALE_M_PER_PX]}]],
                "walls": [[a, b, wall] for a, b in walls],
                "doors": [[1, 2, {"name": [1, DOOR["name"]], "type": [1, "hinged"]}]],
                "lanes": [[10, 12, lane], [12, 11, lane], [12, 13, lane]],
                "floors": [
                    {"vertices": [0, 3, 4, 5], "parameters": {}},
                    {"vertices": [6, 7, 8, 9], "parameters": {}},
                ],
            }
        },
        "lifts": {},
    }


def write_example_rmf(folder: str | Path, data: dict | None = None) -> Path:
    """Write ``data`` (default: ``example_rmf()``) as ``example.building.yaml`` in ``folder``."""
    path = Path(folder) / "example.building.yaml"
    path.write_text(yaml.safe_dump(data or example_rmf(), sort_keys=False), encoding="utf-8")
    return path


LIFT_DOOR = (25.0, -8.0)  # map frame: the lift's door, in the corridor's south wall


def example_rmf_two_levels() -> dict:
    """The example building with a second level ``L2`` (the same floor 4 m up, its room
    ``office_2``) and the lift ``lift_a`` south of the corridor, its door at ``LIFT_DOOR``
    on both levels."""
    import copy

    data = example_rmf()
    l2 = copy.deepcopy(data["levels"]["L1"])
    l2["elevation"] = 4
    l2["doors"][0][2]["name"] = [1, "office_2"]
    data["levels"]["L2"] = l2
    x_px, y_px = LIFT_DOOR[0] / SCALE_M_PER_PX, (-LIFT_DOOR[1] + 1.5) / SCALE_M_PER_PX
    data["lifts"] = {
        "lift_a": {
            "x": x_px,
            "y": y_px,
            "yaw": 0.0,
            "reference_floor_name": "L1",
            "doors": {"door_a": {"x": 0.0, "y": 1.5, "width": 1.4, "door_type": 2}},
            "level_doors": {"L1": ["door_a"], "L2": ["door_a"]},
        }
    }
    return data


def example_rmf_lane_into_lift() -> dict:
    """The two-level example with its lift drawn as RMF drawings often have one: the
    cabin (2.5 x 3 m) floored and walled on three sides, the corridor's south wall open
    at its door, and a lane on through the door to the cabin's middle (where a robot
    rides)."""
    data = example_rmf_two_levels()
    data["lifts"]["lift_a"].update(width=2.5, depth=3.0)
    x = round(LIFT_DOOR[0] / SCALE_M_PER_PX)  # the door's column; the south wall is row 160
    for lvl in data["levels"].values():
        v, n = lvl["vertices"], len(lvl["vertices"])
        v += [[x - 30, 160, 0, ""], [x + 30, 160, 0, ""]]  # n, n+1: the opening
        v += [[x - 25, 160, 0, ""], [x - 25, 220, 0, ""], [x + 25, 220, 0, ""]]  # n+2..n+4
        v += [[x + 25, 160, 0, ""], [x, 120, 0, ""], [x, 190, 0, ""]]  # n+5..n+7
        wall = lvl["walls"][0][2]
        lvl["walls"] = [w for w in lvl["walls"] if w[:2] != [4, 5]] + [
            [4, n + 1, wall], [n, 5, wall], [n + 2, n + 3, wall], [n + 3, n + 4, wall],
            [n + 4, n + 5, wall],
        ]
        lvl["floors"].append({"vertices": [n + 2, n + 3, n + 4, n + 5], "parameters": {}})
        lane = lvl["lanes"][0][2]
        lvl["lanes"] = [ln for ln in lvl["lanes"] if ln[:2] != [12, 11]] + [
            [12, n + 6, lane], [n + 6, 11, lane], [n + 6, n + 7, lane],
        ]
    return data
