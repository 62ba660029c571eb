"""Grid walls carry what hangs on them: doors, signs and landmarks move onto the real wall.

One corridor annotated 1.6 m wide in a grid 2.6 m wide, so its annotated walls float
0.5 m in front of the grid's. Behind the top wall a room (closed: the grid shows wall
where its door is); below the bottom wall an alcove deeper than the search reaches.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest
import yaml
from shapely.geometry import Polygon
from typer.testing import CliRunner

from pmnav_bt.experiments.sim_cli import app
from pmnav_bt.map.building import building_from_data
from pmnav_bt.map.checks import mount_warnings
from pmnav_bt.map.floorplan import (
    FREE,
    OCCUPIED,
    UNKNOWN,
    FloorPlanImage,
    fill_world_polygons,
    load_ros_map,
    save_ros_map,
)
from pmnav_bt.map.wall_surface import RealWalls
from pmnav_bt.sim.render import GRID_WALL_RGB
from pmnav_bt.sim.wall_mounting import summary
from pmnav_bt.sim.world import PANEL_DEPTH, SIGN_CENTRE_Z, SIGN_DEPTH, WALL, SimWorld

REAL_HALF = 1.3  # the grid's corridor: |y| <= 1.3
ANNOTATED_HALF = 0.8  # the file's: 0.5 m less on each side
WALL_M = 0.2  # between the corridor and the room


def _box(x0, y0, x1, y1):
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], float)


def _plan() -> FloorPlanImage:
    plan = FloorPlanImage(np.full((200, 360), UNKNOWN, np.uint8), 0.05, (-3.0, -6.0, 0.0))
    h, t = REAL_HALF, WALL_M
    fill_world_polygons(plan, [_box(-1.5, -h - t, 13.5, h + t)], OCCUPIED)
    fill_world_polygons(plan, [_box(-1.3, -h, 13.3, h)], FREE)
    fill_world_polygons(plan, [_box(3.0, h + t, 7.0, 4.0)], FREE)  # room1, behind a closed door
    fill_world_polygons(plan, [_box(1.0, -4.5, 7.0, -h)], FREE)  # an alcove 3.2 m deep
    return plan


@pytest.fixture(scope="module")
def narrow(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("mount")
    save_ros_map(_plan(), tmp / "map.yaml")
    a = ANNOTATED_HALF
    data = {
        "schema_version": 1,
        "name": "narrow",
        "corridor_width": 2 * a,
        "floor_plan": {"ros_map": "map.yaml"},
        "waypoints": [
            {"id": "start", "kind": "start", "pos": [0.0, 0.0]},
            {"id": "end1", "kind": "end", "pos": [12.0, 0.0]},
        ],
        "edges": [["start", "end1"]],
        "rooms": [
            {"id": "room1", "door": [5.0, a], "sign": "101"},
            {"id": "room2", "door": [9.5, a], "sign": "102"},
            {"id": "room3", "door": [4.0, -a], "sign": "103"},
        ],
        "landmarks": [{"id": "exit", "kind": "sign", "pos": [9.5, -a], "sign": "Exit"}],
    }
    path = tmp / "building.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


@pytest.fixture(scope="module")
def worlds(narrow):
    with SimWorld(narrow, ceiling=False) as annotated, SimWorld(
        narrow, walls="grid", ceiling=False
    ) as grid:
        yield annotated, grid


def _hit(w: SimWorld, x: float, y_to: float, z: float):
    return w.ray((x, 0.0, z), (x, y_to, z))


def test_items_floating_in_front_end_on_the_grid_wall(worlds):
    annotated, grid = worlds
    # Door, its sign and a landmark sign: 0.5 m further from the centre line than annotated.
    door = _hit(grid, 5.0, 3.0, 1.0)
    assert door.label == "door:room1"
    assert door.distance == pytest.approx(REAL_HALF - PANEL_DEPTH, abs=0.06)
    assert _hit(annotated, 5.0, 3.0, 1.0).distance == pytest.approx(
        ANNOTATED_HALF - PANEL_DEPTH, abs=0.01
    )
    sign = grid.signs["room1"]
    hit = _hit(grid, sign.centre[0], 3.0, SIGN_CENTRE_Z)
    assert hit.label == "sign:room1"
    assert hit.distance == pytest.approx(REAL_HALF - SIGN_DEPTH, abs=0.06)
    hit = _hit(grid, 9.5, -3.0, SIGN_CENTRE_Z)
    assert hit.label == "landmark:exit"
    assert hit.distance == pytest.approx(REAL_HALF - SIGN_DEPTH, abs=0.06)
    # The items record where they are; the report says how far they moved.
    assert grid.doors["room1"].centre[1] == pytest.approx(REAL_HALF, abs=0.05)
    assert grid.doors["room1"].normal == pytest.approx((0.0, -1.0), abs=0.02)
    moved = {(m.kind, m.id): m for m in grid.moved_items}
    for key in [("door", "room1"), ("sign", "room1"), ("door", "room2"), ("sign", "exit")]:
        assert moved[key].found and moved[key].distance == pytest.approx(0.5, abs=0.06), key
        assert moved[key].annotated[0] == pytest.approx(moved[key].placed[0], abs=0.02), key


def _wall_footprints(w: SimWorld) -> list[Polygon]:
    return [w._boxes[b][0] for b in w.bodies_with_label(WALL) if b in w._boxes]


def test_a_door_cuts_an_opening_in_the_grid_wall(worlds):
    _, grid = worlds
    walls = _wall_footprints(grid)
    h = REAL_HALF
    # Room1's door: through the wall into the room; room2's: a doorway 0.3 m deep.
    for x in (5.0, 9.5):
        opening = Polygon(_box(x - 0.45, h + 0.02, x + 0.45, h + 0.18))
        assert not any(f.intersects(opening) for f in walls), x
    beside = Polygon(_box(1.0, h + 0.02, 1.8, h + 0.18))  # plain wall: still there
    assert any(f.intersects(beside) for f in walls)
    # From inside the room, through the opening, the first thing is the door leaf.
    hit = grid.ray((5.0, 3.0, 1.0), (5.0, 0.0, 1.0))
    assert hit.label == "door:room1"


def test_items_beyond_reach_stay_and_are_reported(worlds):
    annotated, grid = worlds
    (missed,) = [m for m in grid.moved_items if not m.found and m.kind == "door"]
    assert missed.id == "room3" and missed.distance == 0.0
    assert grid.doors["room3"].centre == pytest.approx(annotated.doors["room3"].centre)
    assert summary(grid.moved_items).endswith("no wall within reach of 2: door room3, sign room3")


def test_validate_says_how_far_and_where_no_wall_is(narrow):
    from pmnav_bt.map.catalogue import load_building

    b = load_building(narrow)
    w = {p.field: p.message for p in mount_warnings(b, load_ros_map(narrow.parent / "map.yaml"))}
    assert set(w) == {"rooms[0].door", "rooms[1].door", "rooms[2].door", "landmarks[0].pos"}
    for field in ("rooms[0].door", "rooms[1].door", "landmarks[0].pos"):
        metres = float(w[field].split(" m in front of")[0].rsplit(" ", 1)[1])
        assert metres == pytest.approx(0.5, abs=0.06), w[field]
    assert "no stretch of the grid's wall within 1.5 m" in w["rooms[2].door"]
    # Within the tolerance: no warning.
    data = yaml.safe_load(narrow.read_text())
    data["corridor_width"] = 2 * REAL_HALF - 0.3
    data["rooms"] = [dict(r, door=[r["door"][0], 1.15]) for r in data["rooms"][:2]]
    data["landmarks"] = []
    near = building_from_data(data)
    assert mount_warnings(near, load_ros_map(narrow.parent / "map.yaml")) == []


def test_corridor_walls_hang_items_on_the_annotated_walls(worlds):
    annotated, _ = worlds
    assert annotated.moved_items == []
    assert annotated.annotated_walls == len(annotated.walls)
    for d in annotated.doors.values():
        assert abs(d.centre[1]) == pytest.approx(ANNOTATED_HALF, abs=1e-6)


def test_a_tilted_wall_gives_its_own_direction():
    plan = FloorPlanImage(np.full((160, 160), UNKNOWN, np.uint8), 0.05, (-4.0, -4.0, 0.0))
    tilt = math.radians(8.0)
    d = np.array([math.cos(tilt), math.sin(tilt)])
    n = np.array([-d[1], d[0]])
    base = np.array([0.0, -0.6])  # the real wall runs through here, 0.6 m below the annotation
    free = [base - 3 * d, base + 3 * d, base + 3 * d + 3 * n, base - 3 * d + 3 * n]
    fill_world_polygons(plan, [_box(-3.5, -3.5, 3.5, 3.5)], OCCUPIED)
    fill_world_polygons(plan, [np.array(free)], FREE)
    m = RealWalls(plan).mount((0.0, 0.0), (0.0, 1.0), 0.5)
    assert m is not None and m.fitted
    assert math.degrees(math.atan2(m.normal[1], m.normal[0])) == pytest.approx(98.0, abs=1.5)
    assert m.offset == pytest.approx(0.6, abs=0.05)
    assert m.point[0] == pytest.approx(0.0, abs=1e-9)


def test_success_is_measured_at_the_door_the_world_has(worlds):
    from pmnav_bt.map.priori_map import parse_building
    from pmnav_bt.sim.episodes import Episode, goal_door_in_world, score_episode

    annotated, grid = worlds
    pm = parse_building(grid.building)
    assert goal_door_in_world(annotated, pm, "room1") == pytest.approx((5.0, ANNOTATED_HALF))
    door = goal_door_in_world(grid, pm, "room1")
    assert door == pytest.approx((5.0, REAL_HALF), abs=0.06)
    ep = Episode(
        id="e", building="narrow", tier="easy", start_x=0.0, start_y=0.0, start_yaw=0.0,
        goal="room1", route_length=5.0, seed=0, goal_visible=True, turns=0, forks=0,
    )

    class Flat:  # a geodesic 5 m from everywhere: only success matters here
        def distance(self, xy) -> float:
            return 5.0

    def scored(stop_y: float, door) -> bool:
        r = score_episode(
            pm, ep, (5.0, stop_y), geodesic=Flat(), path_length=5.0, steps=20, collisions=0,
            people_contacts=0,
            wall_time=0.0, door=door,
        )
        return r.success

    # 0.1 m from the centre line: within 1 m of the annotated door, not of the real one.
    assert scored(0.1, None) and not scored(0.1, door)
    assert scored(0.6, door)


def test_a_door_point_already_in_the_real_wall_is_where_success_is_measured(narrow):
    """An imported RMF door's point is the door's centre in the real wall, while the
    corridor is annotated narrower: the door hangs there (not where its annotated wall,
    cut short at the corridor's end, would keep it), and success is measured there, not
    as far again behind the wall (the annotated wall's gap to the real one)."""
    from pmnav_bt.map.priori_map import parse_building
    from pmnav_bt.sim.episodes import goal_door_in_world

    data = yaml.safe_load(narrow.read_text())
    data["rooms"][0]["door"] = [5.0, REAL_HALF]
    # Near the corridor's end: its annotated wall ends at 12.8 m, and a door kept within
    # it would hang at 12.22 m, 0.4 m along the real wall from where the door is.
    data["rooms"][1]["door"] = [12.6, REAL_HALF]
    real = narrow.with_name("door_in_the_real_wall.yaml")
    real.write_text(yaml.safe_dump(data))
    with SimWorld(real, walls="grid", ceiling=False) as w:
        pm = parse_building(w.building)
        for room, x in (("room1", 5.0), ("room2", 12.6)):
            assert tuple(w.doors[room].centre) == pytest.approx((x, REAL_HALF), abs=0.06)
            assert goal_door_in_world(w, pm, room) == pytest.approx((x, REAL_HALF), abs=0.06)


def test_a_real_walls_run_is_followed_to_its_end_and_capped():
    walls = RealWalls(_plan())
    # The top wall's face (y = 1.3) runs from x = -1.3 to 13.3; its direction with the
    # corridor below is -x, so "back" is towards +x.
    back, forth = walls.extent((12.0, REAL_HALF), (0.0, -1.0), most=3.0)
    assert back == pytest.approx(13.3 - 12.0, abs=0.06)
    assert forth == pytest.approx(3.0, abs=1e-9)
    # The bottom wall stops at the alcove's mouth (x = 1 to 7): a gap ends its run.
    back, forth = walls.extent((9.0, -REAL_HALF), (0.0, 1.0), most=3.0)
    assert forth == pytest.approx(3.0, abs=1e-9) and back == pytest.approx(2.0, abs=0.06)


def test_a_door_beyond_its_annotated_walls_end_gets_its_plate_on_the_real_wall(narrow):
    """An imported door where the corridors' outline gives its wall no room (here past
    the annotated corridor's end, its other side taken by the next door): the real wall
    runs on, so the plate hangs beside the door at its height, not above the door."""
    data = yaml.safe_load(narrow.read_text())
    data["waypoints"][1]["pos"] = [6.0, 0.0]  # the annotated corridor ends at x = 6.8
    data["rooms"][1]["door"] = [6.3, REAL_HALF]  # in the real wall, 1.3 m from room1's
    data["landmarks"] = []
    short = narrow.with_name("short_annotated_wall.yaml")
    short.write_text(yaml.safe_dump(data))
    with SimWorld(short, walls="grid", ceiling=False) as w:
        door, sign = w.doors["room2"], w.signs["room2"]
        assert door.centre == pytest.approx((6.3, REAL_HALF), abs=0.06)
        assert sum(sign.z) / 2.0 == pytest.approx(SIGN_CENTRE_Z)
        assert sign.centre[1] == pytest.approx(REAL_HALF, abs=0.06)
        assert sign.centre[0] - door.centre[0] > door.width / 2.0  # beside it, past the end
        hit = _hit(w, sign.centre[0], 3.0, SIGN_CENTRE_Z)
        assert hit.label == "sign:room2"


def test_sim_show_says_what_moved_and_draws_the_grid_walls(narrow, tmp_path):
    args = ["show", str(narrow), "--out", str(tmp_path), "--width", "64", "--height", "48"]
    res = CliRunner().invoke(app, [*args, "--set", "sim.walls=grid"])
    assert res.exit_code == 0, res.output
    assert "5 of 7 doors, signs and landmarks moved onto the grid's walls (mean 0.5" in res.output
    img = cv2.cvtColor(cv2.imread(str(tmp_path / "narrow_top_down.png")), cv2.COLOR_BGR2RGB)
    assert (img == GRID_WALL_RGB).all(axis=2).any()


@pytest.mark.parametrize("mounting", ["flag", "on_door", "beside_left"])
def test_styled_plates_hang_with_their_door_on_the_grid_wall(narrow, mounting):
    from pmnav_bt.config import WorldConfig

    scene = WorldConfig(preset="realistic", people_per_100m=0.0)
    styled = narrow.with_name(f"styled_{mounting}.yaml")
    styled.write_text(narrow.read_text() + f"signage: {{style: {{mounting: {mounting}}}}}\n")
    with SimWorld(styled, walls="grid", ceiling=False, scene=scene, seed=1) as w:
        assert set(w.signs) == {"room1", "room2", "room3"}
        doors = {m.id for m in w.moved_items if m.kind == "door"}
        assert doors == {"room1", "room2", "room3"}
        for room, sign in w.signs.items():  # by its door, not on the annotated wall
            assert math.dist(sign.centre, w.doors[room].centre) < 1.5
