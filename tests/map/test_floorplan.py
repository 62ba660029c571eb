"""Floor plans: map_server transforms and reading, rasterised buildings, PGM+YAML round trip."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
import yaml

from pmnav_bt.errors import PmNavError
from pmnav_bt.map.building import building_from_data
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.floorplan import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    WALL_M,
    FloorPlanError,
    FloorPlanImage,
    door_frames,
    load_floor_plan,
    load_image_plan,
    load_ros_map,
    rasterize_building,
    save_ros_map,
)


def _plan(h=3, w=4, res=0.5, origin=(1.0, 2.0, 0.0), **kw) -> FloorPlanImage:
    return FloorPlanImage(np.zeros((h, w), np.uint8), res, origin, **kw)


# -- transforms ------------------------------------------------------------------------


def test_pixel_centres_follow_map_server_convention():
    p = _plan()  # 3 rows x 4 columns, 0.5 m, bottom-left corner at (1, 2)
    # The bottom-left pixel is the last image row; its centre is half a cell from the origin.
    assert p.pixel_to_world([[0, 2]]) == pytest.approx(np.array([[1.25, 2.25]]))
    assert p.pixel_to_world([[3, 0]]) == pytest.approx(np.array([[2.75, 3.25]]))
    assert p.world_to_pixel([[1.25, 2.25]]) == pytest.approx(np.array([[0.0, 2.0]]))
    assert p.corners_world().min(axis=0) == pytest.approx([1.0, 2.0])
    assert p.corners_world().max(axis=0) == pytest.approx([3.0, 3.5])


def test_world_to_cell_matches_costmap_indexing():
    p = _plan()
    pts = np.array([[1.01, 2.01], [2.99, 3.49], [1.6, 2.9], [2.0, 2.5]])
    # costmap_2d worldToMap: mx = (wx - ox) / res, my = (wy - oy) / res; image row = h - 1 - my
    mx = np.floor((pts[:, 0] - 1.0) / 0.5)
    my = np.floor((pts[:, 1] - 2.0) / 0.5)
    expected = np.stack([mx, 3 - 1 - my], axis=1)
    assert (p.world_to_cell(pts) == expected).all()
    assert p.world_to_cell(pts)[:2].tolist() == [[0, 2], [3, 0]]


def test_a_mask_is_read_at_map_points_and_is_false_off_the_image():
    p = _plan()  # 3 rows x 4 columns, 0.5 m, bottom-left corner at (1, 2)
    mask = np.zeros((3, 4), bool)
    mask[2, 0] = True  # the bottom-left cell
    pts = [[1.25, 2.25], [2.75, 3.25], [0.9, 2.25], [1.25, 1.9], [3.1, 2.25], [1.25, 3.6]]
    assert p.mask_at(mask, pts).tolist() == [True, False, False, False, False, False]


def test_yaw_rotates_about_the_origin():
    p = _plan(origin=(1.0, 2.0, math.pi / 2))
    # Cell (0, 0) centre is (0.25, 0.25) in the map's own axes, rotated a quarter turn.
    assert p.pixel_to_world([[0, 2]]) == pytest.approx(np.array([[0.75, 2.25]]))
    assert p.world_to_cell([[0.75, 2.25]]).tolist() == [[0, 2]]


@pytest.mark.parametrize("yaw", [0.0, 0.3, -2.0])
def test_world_pixel_round_trip(yaw):
    p = _plan(h=50, w=70, res=0.05, origin=(-3.0, 4.0, yaw))
    pts = np.random.default_rng(0).uniform(-10, 10, size=(20, 2))
    assert p.pixel_to_world(p.world_to_pixel(pts)) == pytest.approx(pts)
    assert p.world_to_pixel(p.pixel_to_world(pts)) == pytest.approx(pts)
    # The affine matrix is what world_to_pixel applies.
    m = p.affine()
    assert p.world_to_pixel(pts) == pytest.approx(pts @ m[:, :2].T + m[:, 2])


# -- map_server reading of pixels ------------------------------------------------------


def test_trinary_occupancy_uses_map_saver_levels():
    img = np.array([[OCCUPIED, FREE, UNKNOWN, 128]], np.uint8)
    p = FloorPlanImage(img, 0.05, (0.0, 0.0, 0.0))
    assert p.occupancy().tolist() == [[100, 0, -1, -1]]
    neg = FloorPlanImage(img, 0.05, (0.0, 0.0, 0.0), negate=True)
    assert neg.occupancy().tolist()[0][:2] == [0, 100]


def test_scale_and_raw_modes():
    img = np.array([[0, 255, 150, 50]], np.uint8)
    scale = FloorPlanImage(
        img, 0.05, (0.0, 0.0, 0.0), occupied_thresh=0.65, free_thresh=0.196, mode="scale"
    )
    occ = (255 - 150) / 255
    expected = round((occ - 0.196) / (0.65 - 0.196) * 100)
    assert scale.occupancy().tolist() == [[100, 0, expected, 100]]
    raw = FloorPlanImage(img, 0.05, (0.0, 0.0, 0.0), mode="raw")
    assert raw.occupancy().tolist() == [[0, -1, -1, 50]]


def test_colour_image_is_averaged():
    img = np.zeros((1, 2, 3), np.uint8)
    img[0, 1] = (254, 254, 254)
    p = FloorPlanImage(img, 0.1, (0.0, 0.0, 0.0))
    assert p.occupancy().tolist() == [[100, 0]]
    assert p.bgr().shape == (1, 2, 3)


# -- rasterised buildings --------------------------------------------------------------


@pytest.mark.parametrize("name", ["fig2_hospital", "loop_school"])
def test_rasterized_corridors_free_walls_occupied(name):
    b = load_building(name)
    grid = rasterize_building(b, resolution=0.05)
    occ = grid.occupancy()
    wps = {w.id: np.asarray(w.pos) for w in b.waypoints}
    doors = np.array([r.door for r in b.rooms])
    for e in b.edges:
        a, c = wps[e.a], wps[e.b]
        line = a + np.linspace(0, 1, 40)[:, None] * (c - a)
        cols, rows = grid.world_to_cell(line).T
        assert (occ[rows, cols] == 0).all(), f"centre line {e.a}-{e.b} not free"
        # Points in the wall band, away from any door, are occupied.
        u = (c - a) / np.linalg.norm(c - a)
        n = np.array([-u[1], u[0]])
        wall = b.edge_width(e) / 2 + WALL_M / 2
        for side in (1, -1):
            pts = line[5:-5] + side * wall * n
            far = np.linalg.norm(pts[:, None] - doors[None], axis=2).min(axis=1) > 1.0
            cols, rows = grid.world_to_cell(pts[far]).T
            assert (occ[rows, cols] == 100).all(), f"wall of {e.a}-{e.b} not occupied"


def test_rasterized_door_gaps_and_unknown_rooms():
    b = load_building("fig2_hospital")
    grid = rasterize_building(b, resolution=0.05)
    occ = grid.occupancy()
    for f in door_frames(b):
        inside_room = np.asarray(f.foot) + np.asarray(f.out) * (f.wall + WALL_M + 0.25)
        col, row = grid.world_to_cell(inside_room)[0]
        assert occ[row, col] == 0, f"door of {f.room} is not open"
    # The middle of the block enclosed by the corridors is neither corridor nor door.
    col, row = grid.world_to_cell([[18.0, 10.0]])[0]
    assert occ[row, col] == -1
    assert grid.image.dtype == np.uint8 and grid.resolution == 0.05


def test_rasterize_rejects_bad_resolution():
    with pytest.raises(FloorPlanError, match="resolution"):
        rasterize_building(load_building("loop_school"), resolution=0.0)


# -- saving and loading ----------------------------------------------------------------


def test_save_and_load_ros_map_round_trip(tmp_path):
    grid = rasterize_building(load_building("loop_school"), resolution=0.1)
    yaml_path = save_ros_map(grid, tmp_path / "school.yaml")
    meta = yaml.safe_load(yaml_path.read_text())
    assert meta["image"] == "school.pgm"
    assert meta["origin"] == pytest.approx(list(grid.origin))
    assert (tmp_path / "school.pgm").read_bytes().startswith(b"P5")
    back = load_ros_map(yaml_path)
    assert (back.image == grid.image).all()
    assert back.resolution == pytest.approx(grid.resolution)
    assert back.origin == pytest.approx(grid.origin)
    assert (back.occupancy() == grid.occupancy()).all()
    pts = np.array([[15.0, 0.0], [0.0, 22.0]])
    assert (back.world_to_cell(pts) == grid.world_to_cell(pts)).all()


def test_load_ros_map_defaults_and_relative_image(tmp_path):
    (tmp_path / "maps").mkdir()
    cv2.imwrite(str(tmp_path / "maps" / "m.png"), np.full((4, 5), 254, np.uint8))
    (tmp_path / "maps" / "m.yaml").write_text(
        "image: m.png\nresolution: 0.1\norigin: [1, 2, 0.5]\n"
    )
    p = load_ros_map(tmp_path / "maps" / "m.yaml")
    assert p.origin == (1.0, 2.0, 0.5)
    assert (p.negate, p.mode, p.occupied_thresh, p.free_thresh) == (False, "trinary", 0.65, 0.196)
    assert (p.occupancy() == 0).all()


def test_load_floor_plan_from_building(tmp_path):
    cv2.imwrite(str(tmp_path / "plan.png"), np.full((20, 30, 3), 200, np.uint8))
    data = load_building("loop_school").to_dict()
    data["floor_plan"] = {"image": "plan.png", "metres_per_pixel": 0.5, "origin": [-2, -14]}
    b = building_from_data(data, "school.yaml", tmp_path)
    p = load_floor_plan(b, tmp_path)
    assert p.image.shape == (20, 30, 3)
    assert p.corners_world().min(axis=0) == pytest.approx([-2.0, -14.0])
    save_ros_map(rasterize_building(b), tmp_path / "ros.yaml")
    data["floor_plan"] = {"ros_map": "ros.yaml"}
    b2 = building_from_data(data, "school.yaml", tmp_path)
    assert load_floor_plan(b2, tmp_path).source.endswith("ros.yaml")
    assert load_floor_plan(load_building("loop_school")) is None


# -- errors a user can cause -----------------------------------------------------------


def _write(tmp_path, text, name="map.yaml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_missing_yaml_names_the_file(tmp_path):
    with pytest.raises(FloorPlanError, match="nope.yaml") as err:
        load_ros_map(tmp_path / "nope.yaml")
    assert isinstance(err.value, PmNavError)


@pytest.mark.parametrize(
    ("text", "field"),
    [
        ("image: [unclosed\n", "not valid YAML"),
        ("- just a list\n", "mapping"),
        ("resolution: 0.05\norigin: [0, 0, 0]\n", "image"),
        ("image: m.pgm\nresolution: 0\norigin: [0, 0, 0]\n", "resolution"),
        ("image: m.pgm\nresolution: -0.1\norigin: [0, 0, 0]\n", "resolution"),
        ("image: m.pgm\nresolution: 0.05\norigin: [0, 0]\n", "origin"),
        ("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 2\n", "negate"),
        ("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nmode: fancy\n", "mode"),
        ("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nfree_thresh: 0.9\n", "free_thresh"),
        ("image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n", "image file not found"),
    ],
)
def test_bad_yaml_names_file_and_field(tmp_path, text, field):
    path = _write(tmp_path, text)
    with pytest.raises(FloorPlanError) as err:
        load_ros_map(path)
    assert str(path) in str(err.value)
    assert field in str(err.value)


def test_unreadable_image_names_the_image(tmp_path):
    (tmp_path / "m.pgm").write_bytes(b"not an image at all")
    path = _write(tmp_path, "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n")
    with pytest.raises(FloorPlanError, match=r"m\.pgm.*not a PNG, PGM or JPEG"):
        load_ros_map(path)


def test_plain_image_errors(tmp_path):
    with pytest.raises(FloorPlanError, match=r"missing\.png.*not found"):
        load_image_plan(tmp_path / "missing.png", 0.05)
    cv2.imwrite(str(tmp_path / "ok.png"), np.zeros((2, 2), np.uint8))
    with pytest.raises(FloorPlanError, match="metres_per_pixel"):
        load_image_plan(tmp_path / "ok.png", -1.0)
