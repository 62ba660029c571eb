"""Walls from the grid: the simulator builds its walls from a ros_map's occupied cells."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from pmnav_bt.config import load_config
from pmnav_bt.map.catalogue import load_building, resolve_building_path
from pmnav_bt.map.floorplan import FREE, rasterize_building, save_ros_map
from pmnav_bt.sim.grid_walls import grid_wall_boxes, merge_cells
from pmnav_bt.sim.world import WALL, SimError, SimWorld

RAY_Z = 2.6  # above the doors and sign plates, below the ceiling


def test_merge_cells_covers_every_wall_cell_and_no_free_cell():
    rng = np.random.default_rng(3)
    for _ in range(20):
        must = rng.random((30, 40)) < 0.3
        may = rng.random((30, 40)) < 0.3
        covered = np.zeros_like(must)
        for r0, c0, r1, c1 in merge_cells(must, may):
            assert (must | may)[r0:r1, c0:c1].all()
            covered[r0:r1, c0:c1] = True
        assert covered[must].all()


@pytest.fixture(scope="module")
def alcove_building(tmp_path_factory):
    """straight_office with its map, and a 2 m deep alcove carved into the grid only."""
    tmp = tmp_path_factory.mktemp("grid")
    b = load_building("straight_office")
    plan = rasterize_building(b)
    xy = plan.world_to_pixel([[9.0, -1.0], [11.0, -3.0]]).round().astype(int)
    (c0, r0), (c1, r1) = xy.min(axis=0), xy.max(axis=0)
    plan.image[r0:r1, c0:c1] = FREE
    save_ros_map(plan, tmp / "map.yaml")
    data = yaml.safe_load(resolve_building_path("straight_office").read_text())
    data["floor_plan"] = {"ros_map": "map.yaml"}
    path = tmp / "building.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _down(w: SimWorld, x: float) -> float:
    hit = w.ray((x, 0.0, RAY_Z), (x, -10.0, RAY_Z))
    assert hit is not None and hit.label == WALL
    return hit.distance


def test_grid_walls_follow_the_grid_not_the_annotation(alcove_building):
    with SimWorld(alcove_building) as annotated, SimWorld(alcove_building, walls="grid") as grid:
        assert _down(annotated, 10.0) == pytest.approx(1.1, abs=0.05)
        assert _down(grid, 10.0) == pytest.approx(3.0, abs=0.1)  # into the alcove
        assert _down(grid, 3.0) == pytest.approx(1.1, abs=0.1)  # a plain wall stays put
        assert set(grid.doors) == set(annotated.doors)  # doors and signs from the file
        assert set(grid.signs) == set(annotated.signs)
        assert len(grid.bodies_with_label(WALL)) < 150  # merged into few boxes
        x0, y0, x1, y1 = grid.bounds()
        assert y0 < -3.0  # the floor reaches the alcove


def test_grid_walls_need_a_ros_map():
    with pytest.raises(SimError, match="need a floor_plan with ros_map"):
        SimWorld("straight_office", walls="grid")
    with pytest.raises(SimError, match="walls 'bricks'"):
        SimWorld("straight_office", walls="bricks")


def test_walls_is_a_config_option():
    assert load_config(overrides=["sim.walls=grid"]).sim.walls == "grid"
    assert load_config().sim.walls == "corridors"


def test_hospital_grid_boxes_stay_few(hospital_grid):
    from pmnav_bt.map.floorplan import load_ros_map

    boxes = grid_wall_boxes(load_ros_map(hospital_grid))
    assert 0 < len(boxes) < 1500


def test_example_hospital_builds_with_grid_walls():
    from pathlib import Path

    f = Path(__file__).resolve().parents[2] / "examples" / "hospital" / "building.yaml"
    with SimWorld(f, walls="grid", ceiling=False) as w:
        start = w.start_pose()
        assert w.clearance(start.x, start.y, 0.17) > 0.0  # Create 3 radius
        assert len(w.doors) == len(w.building.rooms)
