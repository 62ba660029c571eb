"""Drafts from floor-plan drawings: walls from the drawing's lines, then the same drafting."""

from __future__ import annotations

import math
import os
from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml

from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.draft import draft_drawing, draft_source, drawing_grid_path
from pmnav_bt.map.drawing import DrawingError, drawing_plan, scale_from_points
from pmnav_bt.map.floorplan import load_ros_map

RES = 0.02  # metres per pixel of the synthetic drawing
W, H = 22.0, 12.0  # paper size (m); the building is 20 m x 10 m, 1 m from the edges


def _px(x: float, y: float) -> tuple[int, int]:
    return round(x / RES), round((H - y) / RES)


def _line(img, a, b, thick=0.12):
    cv2.line(img, _px(*a), _px(*b), 0, max(1, round(thick / RES)))


def _drawing(path):
    """A 20 m corridor between two rows of rooms, doors 0.9 m wide, labels in the rooms,
    and a 1.2 m entrance at the west end of the corridor."""
    img = np.full((round(H / RES), round(W / RES)), 255, np.uint8)
    x0, x1, y0, y1 = 1.0, 21.0, 1.0, 11.0
    _line(img, (x0, y0), (x1, y0))
    _line(img, (x0, y1), (x1, y1))
    _line(img, (x1, y0), (x1, y1))
    _line(img, (x0, y0), (x0, 5.4))  # the entrance: x0, y 5.4..6.6
    _line(img, (x0, 6.6), (x0, y1))
    for yw in (5.0, 7.0):  # corridor walls, a door gap into every 4 m room
        xs = np.arange(x0, x1 + 1e-9, 4.0)
        for a, b in zip(xs, xs[1:], strict=False):
            _line(img, (a, yw), (a + 1.5, yw))
            _line(img, (a + 2.4, yw), (b, yw))
            _line(img, (a, y0 if yw == 5.0 else y1), (a, yw))
            cv2.putText(img, "RM", _px(a + 1.0, yw + (2.0 if yw == 7.0 else -2.0)),
                        cv2.FONT_HERSHEY_SIMPLEX, 0.6, 0, 2)
    cv2.imwrite(str(path), img)
    return path


def test_drawing_is_read_as_walls_free_inside_and_unknown_outside(tmp_path):
    plan = drawing_plan(_drawing(tmp_path / "plan.png"), RES)
    occ = plan.occupancy()
    assert plan.resolution == pytest.approx(0.05, rel=0.02)  # shrunk to 5 cm cells

    def at(x, y):
        c = plan.world_to_cell([[x, y]])[0]
        return occ[c[1], c[0]]

    assert at(10.0, 6.0) == 0  # the corridor is free
    assert at(0.3, 6.0) == -1  # the street beyond the entrance is not
    assert at(11.0, 9.0) == 0  # a room's label is no wall
    assert at(10.0, 7.0) == 100  # the corridor wall is


def test_draft_from_a_drawing_finds_its_corridor_and_writes_the_grid(tmp_path):
    out = tmp_path / "b" / "building.yaml"
    out.parent.mkdir()
    b, d, text = draft_drawing(_drawing(tmp_path / "plan.png"), out, RES)
    assert drawing_grid_path(out).is_file()
    assert b.floor_plan.ros_map == "building_grid.yaml"
    length = sum(math.dist(b.waypoint(e.a).pos, b.waypoint(e.b).pos) for e in b.edges)
    assert length >= 16.0
    assert all(abs(w.pos[1] - 6.0) <= 0.3 for w in b.waypoints), b.waypoints
    assert all(abs(b.edge_width(e) - 2.0) <= 0.3 for e in b.edges)


def test_drawing_scale_from_two_points():
    assert scale_from_points("0,0,300,400,10") == pytest.approx(0.02)
    for bad in ("0,0,300,400", "0,0,0,0,5", "a,b,c,d,e", "0,0,1,1,-2"):
        with pytest.raises(DrawingError, match="--scale-from"):
            scale_from_points(bad)


def test_a_drawing_needs_exactly_one_scale_and_a_grid_none(tmp_path):
    png = _drawing(tmp_path / "plan.png")
    with pytest.raises(DrawingError, match="needs its scale"):
        draft_source(png, tmp_path / "b.yaml")
    with pytest.raises(DrawingError, match="needs its scale"):
        draft_source(png, tmp_path / "b.yaml", scale=RES, scale_from="0,0,1,0,0.02")
    grid = tmp_path / "g.yaml"
    grid.write_text("image: x.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n", encoding="utf-8")
    with pytest.raises(DrawingError, match="for drawings"):
        draft_source(grid, tmp_path / "b.yaml", scale=0.05)


def test_pmnav_map_draft_of_a_drawing(tmp_path, capsys):
    from pmnav_bt.cli import main

    out = tmp_path / "new" / "b.yaml"
    args = ["map", "draft", str(_drawing(tmp_path / "plan.png")), "-o", str(out)]
    with pytest.raises(SystemExit) as ex:
        main([*args, "--scale-from", "0,0,500,0,10"])
    assert ex.value.code == 0
    assert load_building(out).floor_plan.ros_map == "b_grid.yaml"
    assert load_ros_map(out.parent / "b_grid.yaml").width > 0
    assert "wrote" in capsys.readouterr().out


def _known_scale(building_yaml) -> float:
    """The drawing's metres per pixel from the RMF file's measurements (pixel pairs with
    their real distance): for the clinic 0.7 m over 26.0 px, 0.0269 m a pixel."""
    lv = next(iter(yaml.safe_load(building_yaml.read_text())["levels"].values()))
    v = lv["vertices"]
    a, b, p = lv["measurements"][0]
    return p["distance"][1] / math.dist(v[a][:2], v[b][:2])


def _shared_clinic() -> Path | None:
    """The RMF clinic in $PMNAV_SHARED_MAPS, or in a shared/maps beside an ancestor."""
    env = os.environ.get("PMNAV_SHARED_MAPS")
    roots = [Path(env)] if env else [p / "shared" / "maps" for p in Path(__file__).parents]
    found = [r / "rmf" / "clinic" for r in roots if (r / "rmf/clinic/clinic.png").is_file()]
    return found[0] if found else None


def test_draft_of_the_rmf_clinic_drawing_finds_both_wings(tmp_path):
    clinic = _shared_clinic()
    if clinic is None:
        pytest.skip("the RMF clinic is absent: set PMNAV_SHARED_MAPS to a maps/ folder")
    scale = _known_scale(clinic / "clinic.building.yaml")
    assert scale == pytest.approx(0.0269, abs=1e-4)
    b, _, _ = draft_drawing(clinic / "clinic.png", tmp_path / "clinic.yaml", scale)
    length = sum(math.dist(b.waypoint(e.a).pos, b.waypoint(e.b).pos) for e in b.edges)
    xs = [w.pos[0] for w in b.waypoints]
    # The corridors round both blocks of consulting rooms, the west wing included (an
    # earlier draft dropped it as small parts apart), and the corridors inside the two
    # blocks, joined to the rest through the doorways at their ends.
    assert length >= 150.0
    assert min(xs) < 10.0 and max(xs) > 50.0
    pts = np.array([w.pos for w in b.waypoints])
    for inner in ((21.5, 26.6), (40.6, 27.7)):
        assert np.linalg.norm(pts - inner, axis=1).min() < 2.5, inner
