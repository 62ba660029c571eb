"""``pmnav map import-rmf``: an Open-RMF level as a building file that validates.

The small example (pmnav_bt/testing/rmf_example.py) checks each step by what it must
give; the real RMF demo buildings (clinic, two levels; office) check that the result
validates, that the named doors become rooms and that corridors and doors lie where the
drawing has them. Those skip when the shared maps folder is absent.
"""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from pmnav_bt.geometry import project_points_to_segments
from pmnav_bt.map.building import read_building_file
from pmnav_bt.map.floorplan import WALL_M, load_floor_plan
from pmnav_bt.map.grid import largest_component
from pmnav_bt.map.rmf_import import import_rmf, write_import
from pmnav_bt.map.rmf_read import read_level
from pmnav_bt.testing.rmf_example import (
    CORRIDOR,
    DOOR,
    SCALE_M_PER_PX,
    example_rmf,
    write_example_rmf,
)


def run_pmnav(capsys, *argv) -> tuple[int, str, str]:
    """``pmnav ARGV`` in this process: (exit status, stdout, stderr)."""
    from pmnav_bt.cli import main

    with pytest.raises(SystemExit) as info:
        main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return info.value.code, out, err


@pytest.fixture
def example(tmp_path):
    return write_example_rmf(tmp_path)


def test_pixels_become_metres_with_y_flipped(example):
    lvl = read_level(example)
    assert lvl.scale == pytest.approx(SCALE_M_PER_PX)
    # Vertex 0 is pixel (0, 100): rows run down the drawing, the map's y up.
    assert lvl.xy[0] == pytest.approx([0.0, -100 * SCALE_M_PER_PX])
    assert lvl.xy[7][1] > lvl.xy[0][1]  # the room (rows 40-100) lies north of the corridor


def test_the_corridor_is_centred_between_the_walls_not_on_the_lane(example, tmp_path):
    imp = import_rmf(example, tmp_path / "out.yaml")
    b = imp.building
    mid = (CORRIDOR["north"] + CORRIDOR["south"]) / 2.0  # the lane runs 0.5 m north of it
    assert [w.pos[1] for w in b.waypoints] == pytest.approx([mid] * len(b.waypoints), abs=0.1)
    (edge,) = b.edges
    free_width = CORRIDOR["north"] - CORRIDOR["south"] - WALL_M
    assert b.edge_width(edge) == pytest.approx(free_width, abs=0.15)


def test_a_corridors_width_is_what_it_leaves_free_all_along_not_a_median(tmp_path):
    data = example_rmf()
    lvl = data["levels"]["L1"]
    v = lvl["vertices"]
    # A block 0.75 m deep on the south wall from x 16 to 20 m: a narrowing over a seventh
    # of the corridor, 2.1 m free (north wall face -5.075, the block's face -7.175).
    k = len(v)
    v += [[320, 160, 0, ""], [320, 145, 0, ""], [400, 145, 0, ""], [400, 160, 0, ""]]
    lvl["walls"] += [[k, k + 1, {}], [k + 1, k + 2, {}], [k + 2, k + 3, {}]]
    imp = import_rmf(write_example_rmf(tmp_path, data), tmp_path / "out.yaml")
    b = imp.building
    (edge,) = b.edges
    assert b.edge_width(edge) <= 2.1  # the median wall-to-wall width was 2.85 m
    # The corridor's rectangle (less 0.15 m a side: rays stop in the first wall cell)
    # lies on the free space all along.
    a, c = (np.array(b.waypoint(w).pos) for w in (edge.a, edge.b))
    u = (c - a) / np.linalg.norm(c - a)
    n = np.array([-u[1], u[0]])
    s, t = np.meshgrid(np.linspace(0, 1, 120), np.linspace(-0.5, 0.5, 15))
    pts = a + s.reshape(-1, 1) * (c - a) + t.reshape(-1, 1) * n * (b.edge_width(edge) - 0.3)
    assert imp.grid.mask_at(imp.grid.occupancy() == 0, pts).all()


def test_a_placed_line_off_its_band_is_as_wide_as_it_keeps_free():
    # A 20 m corridor 2.4 m wide (2.3 m free) whose line, as the waypoints were placed,
    # runs 0.7 m north of its middle: the rectangle about it that is free all along is
    # twice its 0.45 m to the north wall, not the corridor's 2.3 m.
    from pmnav_bt.map.building import building_from_data
    from pmnav_bt.map.floorplan import rasterize_building
    from pmnav_bt.map.rmf_corridors import Corridors, measure_widths

    b = building_from_data(
        {
            "schema_version": 1,
            "name": "one",
            "waypoints": [
                {"id": "start", "kind": "start", "pos": [0.0, 0.0]},
                {"id": "end1", "kind": "end", "pos": [20.0, 0.0]},
            ],
            "edges": [["start", "end1"]],
        }
    )
    plan = rasterize_building(b)
    cor = Corridors({0: np.array([0.0, 0.7]), 1: np.array([20.0, 0.7])}, [(0, 1, 2.3)])
    measure_widths(cor, plan)
    assert cor.edges[0][2] == pytest.approx(0.9, abs=0.1)
    cor.drawn.add(frozenset((0, 1)))  # a spur's width is drawn, not measured
    cor.edges[0] = (0, 1, 1.8)
    measure_widths(cor, plan)
    assert cor.edges[0][2] == 1.8


def test_named_door_becomes_a_room_on_its_wall_and_the_charger_the_start(example, tmp_path):
    imp = import_rmf(example, tmp_path / "out.yaml")
    (room,) = imp.building.rooms
    assert room.id == DOOR["name"] and room.door == pytest.approx(DOOR["centre"])
    start = imp.building.waypoint("start")
    assert start.pos[0] == pytest.approx(2.0, abs=0.1)  # the charger's end, not the other
    assert [lm.id for lm in imp.building.landmarks] == ["notice_board"]
    assert [lm.name for lm in imp.building.landmarks] == ["notice board"]
    # The vertex inside the room is no landmark, and the list says why.
    assert any("'desk': not on a corridor" in s for s in imp.skipped)


@pytest.mark.parametrize(
    "door,plate",
    [("coe_door", "coe"), ("L1_left_consult_rm_3_outer", "left consult rm 3 outer"),
     ("door_2", "2"), ("Main_Door", "Main"), ("door", "door")],
)
def test_an_imported_rooms_name_is_its_plate_the_door_name_without_door(tmp_path, door, plate):
    data = example_rmf()
    data["levels"]["L1"]["doors"][0][2]["name"] = [1, door]
    imp = import_rmf(write_example_rmf(tmp_path, data), tmp_path / "out.yaml")
    (room,) = imp.building.rooms
    assert room.id == door  # the identifier RMF's door requests use
    assert room.name == room.sign == plate


def test_a_named_places_plate_hangs_on_the_wall_nearest_it(tmp_path):
    imp = import_rmf(write_example_rmf(tmp_path), tmp_path / "out.yaml")
    (board,) = imp.building.landmarks
    # The place is drawn 0.5 m off the south wall (its centre line at y -8, its face
    # 0.075 m nearer): the plate is on that face, a grid cell into the wall.
    assert board.pos[0] == pytest.approx(20.0, abs=0.05)
    assert -8.0 < board.pos[1] < -7.9


def test_a_named_place_on_an_open_floor_is_no_plate(tmp_path):
    data = example_rmf()
    v = data["levels"]["L1"]["vertices"]
    v[4][1] = v[5][1] = 260  # the south wall 5 m further south: a hall 8 m deep
    imp = import_rmf(write_example_rmf(tmp_path, data), tmp_path / "out.yaml")
    assert imp.building.landmarks == ()
    assert any("'notice_board': on an open floor" in s for s in imp.skipped)


def test_the_written_files_validate_and_the_grid_has_the_walls(example, tmp_path, capsys):
    out = tmp_path / "out.yaml"
    code, text, err = run_pmnav(capsys, "map", "import-rmf", example, "-o", out)
    assert code == 0, err
    assert "1 rooms from 1 named doors" in text and "skipped: vertex 'desk'" in text
    b = read_building_file(out)
    assert b.floor_plan.ros_map == "out_walls.yaml"
    plan = load_floor_plan(b, tmp_path)
    occ = plan.occupancy()
    for x, y, want in [(12.5, -5.0, 100), (12.5, -6.5, 0), (12.5, -9.0, -1)]:
        c, r = plan.world_to_cell([[x, y]])[0]
        assert occ[r, c] == want, (x, y)  # the closed door, the corridor, outside
    code, _, err = run_pmnav(capsys, "validate", out)
    assert code == 0, err


def test_the_grid_has_a_wall_wherever_the_floor_ends(tmp_path):
    # The example with no wall drawn along its corridor's south side, where its floor
    # ends: the grid still has one there. Free space beside unknown is where a scanner
    # stopped seeing, which the draft reads as a laser fan, not as the building's edge.
    import cv2

    data = example_rmf()
    lvl = data["levels"]["L1"]
    lvl["walls"] = [w for w in lvl["walls"] if w[:2] != [4, 5]]
    out = tmp_path / "out.yaml"
    write_import(import_rmf(write_example_rmf(tmp_path, data), out), out)
    plan = load_floor_plan(read_building_file(out), tmp_path)
    occ = plan.occupancy()
    beside_free = cv2.dilate((occ == 0).astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
    assert not (beside_free & (occ == -1)).any()


def test_a_level_that_is_not_there_names_the_levels(example, tmp_path, capsys):
    code, _, err = run_pmnav(capsys, "map", "import-rmf", example, "--level", "L9", "-o",
                             tmp_path / "o.yaml")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "no level 'L9'; the file has L1" in err


def test_without_a_charger_the_start_is_the_dead_end_by_the_entrance(tmp_path):
    data = example_rmf()
    lvl = data["levels"]["L1"]
    lvl["vertices"][10][4] = {}  # no charger
    v = lvl["vertices"]
    v += [[600, 120, 0, ""], [600, 140, 0, ""]]  # a door in the east end wall, to outside
    lvl["walls"] = [w for w in lvl["walls"] if w[:2] != [3, 4]]
    lvl["walls"] += [[3, len(v) - 2, {}], [len(v) - 1, 4, {}]]
    lvl["doors"].append([len(v) - 2, len(v) - 1, {"name": [1, "entrance"]}])
    imp = import_rmf(write_example_rmf(tmp_path, data), tmp_path / "out.yaml")
    assert imp.building.waypoint("start").pos[0] > 25.0  # the east end, not the west
    assert any("nearest an entrance" in s for s in imp.skipped)
    # The corridor ran into the entrance; it now turns in front of it, so the door is on
    # the last piece's side wall (half a spur width out), not at its end.
    room = next(r for r in imp.building.rooms if r.id == "entrance")
    b = imp.building
    last = next(e for e in b.edges if "start" in (e.a, e.b))
    a, c = (np.array(b.waypoint(w).pos) for w in (last.a, last.b))
    _, t, dist = project_points_to_segments(np.array([room.door]), a[None], c[None])
    assert 0.0 < t[0] < 1.0 and dist[0] == pytest.approx(b.edge_width(last) / 2.0, abs=0.1)


def test_a_door_across_the_corridor_with_a_lane_through_it_is_a_passage(tmp_path):
    data = example_rmf()
    lvl = data["levels"]["L1"]
    v = lvl["vertices"]
    v += [[450, 100, 0, ""], [450, 160, 0, ""]]  # a door across the whole corridor at x 22.5
    lvl["doors"].append([len(v) - 2, len(v) - 1, {"name": [1, "fire_door"]}])
    imp = import_rmf(write_example_rmf(tmp_path, data), tmp_path / "out.yaml")
    assert "fire_door" not in {r.id for r in imp.building.rooms}
    assert any("'fire_door': a passage" in s for s in imp.skipped)
    xs = sorted(w.pos[0] for w in imp.building.waypoints)
    assert xs[-1] > 25.0  # the corridor goes on through the open door


def test_a_door_in_a_side_bay_beyond_reach_gets_a_spur_along_its_wall(tmp_path):
    data = example_rmf()
    lvl = data["levels"]["L1"]
    v = lvl["vertices"]
    # A bay 4 m deep off the south wall from x 20 to 25 m, with a door in its east wall.
    k = len(v)
    v += [[400, 160, 0, ""], [400, 240, 0, ""], [500, 240, 0, ""], [500, 200, 0, ""],
          [500, 180, 0, ""], [500, 160, 0, ""]]
    lvl["walls"] = [w for w in lvl["walls"] if w[:2] != [4, 5]]
    lvl["walls"] += [[4, k + 5, {}], [k + 5, k + 4, {}], [k + 3, k + 2, {}], [k + 2, k + 1, {}],
                     [k + 1, k, {}], [k, 5, {}]]
    lvl["doors"].append([k + 4, k + 3, {"name": [1, "bay_store"]}])
    lvl["floors"].append({"vertices": [k, k + 1, k + 2, k + 5], "parameters": {}})
    imp = import_rmf(write_example_rmf(tmp_path, data), tmp_path / "out.yaml")
    assert imp.spurs == 1
    room = next(r for r in imp.building.rooms if r.id == "bay_store")
    assert room.door == pytest.approx([25.0, -9.5])


# -- the real RMF demo buildings ---------------------------------------------------------------


@pytest.mark.parametrize(
    "name,level", [("clinic", "L1"), ("clinic", "L2"), ("office", None)], ids=str
)
def test_real_rmf_buildings_import_and_validate(rmf_maps, tmp_path, capsys, name, level):
    rmf = rmf_maps / name / f"{name}.building.yaml"
    out = tmp_path / f"{name}.yaml"
    imp = import_rmf(rmf, out, level)
    write_import(imp, out)
    code, out_text, err = run_pmnav(capsys, "validate", out)
    assert code == 0, err
    # The import sizes its corridors by the measure validate checks (corridor_band), on
    # the lines as placed: no width warning but on a spur's piece along its door's wall,
    # whose width is drawn (1.8 m).
    widths = [x for x in (out_text + err).splitlines() if "wide but the grid shows" in x]
    assert [x for x in widths if "annotated 1.80 m" not in x] == []
    raw = yaml.safe_load(rmf.read_text())["levels"][imp.level.name]["doors"]
    named = {d[2]["name"][1] for d in raw}
    passages = {s.split("'")[1] for s in imp.skipped if "a passage" in s}
    rooms = {r.id for r in imp.building.rooms}
    assert rooms <= named
    # Nearly every named door that is not a passage between corridors becomes a room.
    assert len(rooms) >= 0.9 * len(named - passages), sorted(named - passages - rooms)
    plan = imp.grid
    occ = plan.occupancy()
    doors = np.array([r.door for r in imp.building.rooms])
    cells = plan.world_to_cell(doors)
    # Every door on a wall: a wall cell within 0.15 m of its centre.
    near = [(occ[r - 3 : r + 4, c - 3 : c + 4] == 100).any() for c, r in cells]
    assert all(near)
    # Corridors in the corridors: nearly all of every centre line on the free space.
    free = largest_component(occ == 0)
    pos = {w.id: np.array(w.pos) for w in imp.building.waypoints}
    for e in imp.building.edges:
        pts = pos[e.a] + np.linspace(0, 1, 50)[:, None] * (pos[e.b] - pos[e.a])
        c = plan.world_to_cell(pts)
        assert free[c[:, 1], c[:, 0]].mean() >= 0.9, (e.a, e.b)
    # Every room's door is reached by a corridor (validate says so too) within its width.
    seg_a = np.array([pos[e.a] for e in imp.building.edges])
    seg_b = np.array([pos[e.b] for e in imp.building.edges])
    _, _, dist = project_points_to_segments(doors, seg_a, seg_b)
    assert dist.max() < 6.0
