"""The annotated priori-map: frame, label layout without overlap, backgrounds, plan path."""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

from pmnav_bt.errors import PmNavError
from pmnav_bt.map.building import building_from_data
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.floorplan import FloorPlanImage, rasterize_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.render.annotate import (
    MAP_PAD,
    PATH_COLOUR,
    layout_labels,
    make_canvas,
    nice_length,
    render_annotated_map,
)


@pytest.fixture(scope="module", params=["fig2_hospital", "loop_school"])
def pm(request):
    return parse_building(load_building(request.param))


def _overlaps(a, b) -> bool:
    return a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]


def _assert_no_overlap(layout):
    boxes = [lb.box for lb in layout.labels]
    for i, a in enumerate(boxes):
        for j in range(i + 1, len(boxes)):
            assert not _overlaps(a, boxes[j]), (layout.labels[i].text, layout.labels[j].text)


def test_canvas_maps_world_to_pixels(pm):
    canvas = make_canvas(pm, scale_px_per_m=25.0)
    a, b = canvas.to_px([[0.0, 0.0], [4.0, 2.0]])
    assert b - a == pytest.approx([100.0, -50.0])  # y up in the map, down in the image
    u, v = canvas.to_px([[canvas.xmin, canvas.ymax]])[0]
    assert (u, v) == pytest.approx((canvas.map_left + MAP_PAD, canvas.map_top + MAP_PAD))


def test_image_has_the_canvas_size(pm, tmp_path):
    canvas = make_canvas(pm, scale_px_per_m=25.0)
    out = tmp_path / "map.png"
    img = render_annotated_map(pm, out, scale_px_per_m=25.0)
    assert img.shape == (canvas.height, canvas.width, 3) and img.dtype == np.uint8
    assert (cv2.imread(str(out)) == img).all()


def test_every_room_waypoint_and_landmark_is_tagged_without_overlap(pm):
    layout = layout_labels(pm)
    assert layout.texts("room") == {r.id for r in pm.building.rooms}
    assert layout.texts("waypoint") == {n.id for n in pm.key_waypoints}
    assert layout.texts("landmark") == {lm.id for lm in pm.building.landmarks}
    segs = {s.short for s in pm.segments}
    assert layout.texts("segment") | set(layout.dropped) == segs
    assert layout.dropped == ()  # the built-in buildings have room for every label
    _assert_no_overlap(layout)
    x0, y0, x1, y1 = layout.canvas.map_box
    for lb in layout.labels:
        assert x0 <= lb.box[0] < lb.box[2] <= x1 and y0 <= lb.box[1] < lb.box[3] <= y1


def test_room_tags_sit_beside_their_doors(pm):
    layout = layout_labels(pm)
    for lb in layout.labels:
        if lb.kind == "room":
            assert _gap(lb.box, lb.anchor) < 40, lb.text
            u, v = layout.canvas.to_px([pm.building.room(lb.text).door])[0]
            assert lb.anchor == pytest.approx((u, v))


def _gap(box, p) -> float:
    dx = max(box[0] - p[0], 0, p[0] - box[2])
    dy = max(box[1] - p[1], 0, p[1] - box[3])
    return math.hypot(dx, dy)


def _crowded_pm():
    """One 12 m corridor with a door every 0.7 m on alternating sides."""
    rooms = [
        {"id": f"room{i + 1}", "door": [1.0 + 0.7 * i, 1.2 if i % 2 else -1.2]} for i in range(15)
    ]
    data = {
        "schema_version": 1,
        "name": "crowded",
        "waypoints": [
            {"id": "start", "kind": "start", "pos": [0, 0]},
            {"id": "end1", "kind": "end", "pos": [12, 0]},
        ],
        "edges": [["start", "end1"]],
        "rooms": rooms,
    }
    return parse_building(building_from_data(data))


def test_crowded_map_drops_only_segment_labels():
    pm = _crowded_pm()
    layout = layout_labels(pm, make_canvas(pm, scale_px_per_m=20.0))
    assert layout.dropped, "expected some segment labels to find no room"
    assert set(layout.dropped) <= {s.short for s in pm.segments}
    assert layout.texts("room") == {f"room{i + 1}" for i in range(15)}
    assert layout.texts("waypoint") == {"start", "end1"}
    _assert_no_overlap(layout)
    assert any(lb.leader for lb in layout.labels if lb.kind == "room")


def test_floor_plan_background_is_used():
    pm = parse_building(load_building("loop_school"))
    plan = FloorPlanImage(np.full((100, 100, 3), 255, np.uint8), 0.5, (-10.0, -20.0, 0.0))
    plan.image[:, :] = (255, 0, 255)  # magenta everywhere
    img = render_annotated_map(pm, scale_px_per_m=20.0, floor_plan=plan)
    canvas = make_canvas(pm, scale_px_per_m=20.0)
    # Middle of the courtyard inside the corridor loop: only the plan is drawn there.
    u, v = canvas.ipx((8.0, 11.0))
    assert img[v, u].tolist() == [255, 0, 255]
    clean = render_annotated_map(pm, scale_px_per_m=20.0)
    magenta = (clean[:, :, 0] > 200) & (clean[:, :, 1] < 50) & (clean[:, :, 2] > 200)
    assert not magenta.any()


def test_rasterized_plan_lines_up_with_the_drawing():
    pm = parse_building(load_building("fig2_hospital"))
    grid = rasterize_building(pm.building, resolution=0.05)
    img = render_annotated_map(pm, scale_px_per_m=20.0, floor_plan=grid)
    canvas = make_canvas(pm, scale_px_per_m=20.0)
    grey = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY)
    u, v = canvas.ipx((18.0, 10.0))  # enclosed block: the map's unknown grey
    assert abs(int(grey[v, u]) - 205) <= 2
    u, v = canvas.ipx((1.2 + 0.07, 3.0))  # east wall of the west corridor: black
    assert grey[v, u] < 60


def test_plan_path_is_drawn_in_blue():
    pm = parse_building(load_building("fig2_hospital"))
    path = [(0.0, 30.0), (0.0, 0.0), (36.0, 0.0)]
    with_path = render_annotated_map(pm, scale_px_per_m=20.0, path_xy=path)
    without = render_annotated_map(pm, scale_px_per_m=20.0)
    blue = np.all(np.abs(with_path.astype(int) - PATH_COLOUR) < 30, axis=2)
    assert blue.sum() > 500
    assert not np.all(np.abs(without.astype(int) - PATH_COLOUR) < 30, axis=2).any()


def test_annotated_map_differs_per_building():
    a = render_annotated_map(parse_building(load_building("fig2_hospital")))
    b = render_annotated_map(parse_building(load_building("loop_school")))
    assert a.shape != b.shape


@pytest.mark.parametrize(("target", "nice"), [(4.5, 5.0), (3.9, 5.0), (1.3, 1.0), (0.3, 0.2)])
def test_scale_bar_lengths_are_round(target, nice):
    assert nice_length(target) == pytest.approx(nice)


def test_bare_corridor_renders(tmp_path):
    data = {
        "schema_version": 1,
        "name": "bare",
        "waypoints": [
            {"id": "start", "kind": "start", "pos": [0, 0]},
            {"id": "end1", "kind": "end", "pos": [0, 8]},
        ],
        "edges": [["start", "end1"]],
    }
    pm = parse_building(building_from_data(data))
    layout = layout_labels(pm)
    assert layout.texts("waypoint") == {"start", "end1"} and layout.texts("segment") == {"seg1"}
    with pytest.raises(PmNavError, match="no_such_dir"):
        render_annotated_map(pm, tmp_path / "no_such_dir" / "map.png")


def test_corridor_widths_and_doors_show_over_a_floor_plan():
    pm = parse_building(load_building("fig2_hospital"))
    white = FloorPlanImage(np.full((100, 100), 254, np.uint8), 1.0, (-20.0, -20.0, 0.0))
    img = render_annotated_map(pm, scale_px_per_m=20.0, floor_plan=white)
    canvas = make_canvas(pm, scale_px_per_m=20.0)
    inside = img[canvas.ipx((0.9, 15.0))[::-1]]  # in the west corridor, 0.3 m from its wall
    outside = img[canvas.ipx((1.5, 15.0))[::-1]]  # 0.3 m beyond the wall
    assert outside.tolist() == [254, 254, 254]
    assert inside[0] > inside[2] + 20  # tinted blue: the corridor's annotated width
    u, v = canvas.ipx((-1.2, 26.0))  # room1's door on the west wall
    assert np.abs(img[v, u].astype(int) - (30, 80, 170)).max() < 40


def test_metre_grid_is_optional():
    pm = parse_building(load_building("straight_office"))
    plain = render_annotated_map(pm, scale_px_per_m=20.0)
    grid = render_annotated_map(pm, scale_px_per_m=20.0, grid_m=1.0)
    canvas = make_canvas(pm, scale_px_per_m=20.0)
    v = canvas.map_top + canvas.map_height - 10  # in the padding below the building
    u, _ = canvas.ipx((25.0, 0.0))  # on a 5 m line
    u2, _ = canvas.ipx((25.5, 0.0))  # between lines
    assert plain[v, u].tolist() == [255, 255, 255]
    assert grid[v, u].tolist() != [255, 255, 255]
    assert grid[v, u2].tolist() == [255, 255, 255]
    with pytest.raises(PmNavError, match="grid spacing"):
        render_annotated_map(pm, grid_m=-1.0)
