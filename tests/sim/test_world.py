"""The pybullet world built from a building file: walls, junctions, doors, signs, labels."""

from __future__ import annotations

import math

import numpy as np
import pytest
from typer.testing import CliRunner

from pmnav_bt.experiments.sim_cli import PoseError, app
from pmnav_bt.map.building import WaypointKind
from pmnav_bt.map.catalogue import builtin_buildings, load_building
from pmnav_bt.map.landmark_kinds import landmark_shape
from pmnav_bt.seams import CameraIntrinsics
from pmnav_bt.sim.render import draw_top_down, linearise_depth, render_camera
from pmnav_bt.sim.textures import make_sign, sign_lines
from pmnav_bt.sim.world import (
    FIXED_LABELS,
    SimError,
    SimWorld,
    door_label,
    landmark_label,
    sign_label,
)

RAY_Z = 1.0  # below the sign plates, above the skirting
SMALL = CameraIntrinsics.from_hfov(160, 120, math.radians(60.0))


@pytest.fixture(scope="module", params=builtin_buildings())
def world(request):
    w = SimWorld(request.param)
    yield w
    w.close()


@pytest.fixture(scope="module")
def fig2_world():
    w = SimWorld("fig2_hospital")
    yield w
    w.close()


def _items(w: SimWorld):
    return [*w.doors.values(), *w.signs.values(), *w.landmarks.values(), *w.landmark_signs.values()]


def _edges(w: SimWorld):
    b = w.building
    for e in b.edges:
        a, z = np.array(b.waypoint(e.a).pos, float), np.array(b.waypoint(e.b).pos, float)
        yield e, a, z, b.edge_width(e) / 2.0


def _hits_at(w: SimWorld, origin: np.ndarray, direction: np.ndarray, length: float):
    start = (origin[0], origin[1], RAY_Z)
    end = (origin[0] + length * direction[0], origin[1] + length * direction[1], RAY_Z)
    return w.ray(start, end)


def test_walls_stand_at_the_corridor_half_width(world):
    items = _items(world)
    checked = 0
    for _e, a, z, half in _edges(world):
        length = float(np.linalg.norm(z - a))
        d = (z - a) / length
        n = np.array([-d[1], d[0]])
        for s in np.arange(half + 0.5, length - half - 0.5, 0.5):
            q = a + s * d
            # Skip where something mounted on a wall of this corridor is in the way.
            if any(
                abs(np.dot(np.array(it.centre) - q, d)) < it.width / 2.0 + 0.1
                and abs(np.dot(np.array(it.centre) - q, n)) < half + 0.1
                for it in items
            ):
                continue
            for side in (n, -n):
                hit = _hits_at(world, q, side, half + 2.0)
                assert hit is not None and hit.label == "wall", (world.building.name, q, side)
                assert hit.distance == pytest.approx(half, abs=0.02)
                checked += 1
    assert checked >= 10


def test_junctions_are_open(world):
    b = world.building
    g = b.corridor_graph()
    for wp in b.waypoints:
        if wp.kind not in (WaypointKind.TURN, WaypointKind.BRANCH):
            continue
        here = np.array(wp.pos, float)
        for other in g.neighbors(wp.id):
            there = np.array(b.waypoint(other).pos, float)
            length = float(np.linalg.norm(there - here))
            hit = _hits_at(world, here, (there - here) / length, length)
            assert hit is None or hit.distance >= length - 0.01, (b.name, wp.id, other, hit)


def test_dead_ends_are_closed_by_an_end_wall(world):
    b = world.building
    for e, a, z, half in _edges(world):
        for end, other in ((a, z), (z, a)):
            wid = e.a if end is a else e.b
            if b.waypoint(wid).kind not in (WaypointKind.START, WaypointKind.END):
                continue
            out = (end - other) / np.linalg.norm(end - other)
            hit = _hits_at(world, end, out, 5.0)
            assert hit is not None, (b.name, wid)
            if hit.label == "wall":
                assert hit.distance == pytest.approx(half, abs=0.02)
            else:  # something mounted on the end wall
                assert hit.label.split(":")[0] in ("door", "sign", "landmark"), hit
                assert half - 0.8 < hit.distance < half


def test_free_space_is_watertight(world):
    for wp in world.building.waypoints:
        for k in range(24):
            ang = 2 * math.pi * k / 24 + 0.01
            hit = _hits_at(
                world, np.array(wp.pos, float), np.array([math.cos(ang), math.sin(ang)]), 150.0
            )
            assert hit is not None, (world.building.name, wp.id, k)
            assert hit.label not in ("floor", "ceiling", "background")


def test_every_room_has_one_door_and_one_sign(world):
    b = world.building
    assert set(world.doors) == set(world.signs) == {r.id for r in b.rooms}
    for r in b.rooms:
        door, sign = world.doors[r.id], world.signs[r.id]
        assert math.dist(door.centre, r.door) < 1.0
        assert world.bodies_with_label(door_label(r.id))
        assert world.bodies_with_label(sign_label(r.id))
        assert sign.text == r.sign_text
        assert math.dist(sign.centre, door.centre) < 2.5
        assert sign.z[0] < 1.6 < sign.z[1] or sign.z[0] > door.z[1]  # camera height, or above
    # All doors alike.
    assert len({(d.width, d.z) for d in world.doors.values()}) <= 1


def test_every_landmark_is_built_and_labelled(world):
    for lm in world.building.landmarks:
        assert lm.id in world.landmarks
        assert world.bodies_with_label(landmark_label(lm.id))


def test_views_facing_doors_signs_and_landmarks_show_their_labels(fig2_world):
    w = fig2_world
    for what, item in [
        *(("sign", s) for s in w.signs.values()),
        *(("door", d) for d in w.doors.values()),
        *(("landmark", lm) for lm in w.landmarks.values()),
    ]:
        view = item.viewpoint(1.5)
        frame = render_camera(w, view.x, view.y, view.yaw, SMALL, height=sum(item.z) / 2)
        centre = frame.segmentation[50:70, 70:90]
        assert w.label_id(item.label) in centre, (what, item.id)


def test_fixed_labels_and_lookup(fig2_world):
    w = fig2_world
    assert [w.labels[i] for i in range(len(FIXED_LABELS))] == list(FIXED_LABELS)
    assert w.label_of(-1) == "background"
    walls = w.bodies_with_label("wall")
    assert walls and all(w.label_of(b) == "wall" for b in walls)
    seg = np.array([[-1, walls[0]]])
    assert w.segmentation_to_labels(seg).tolist() == [[0, w.label_id("wall")]]


def test_depth_is_metric_along_the_optical_axis(fig2_world):
    # fig2 corridor start-turn1 runs along x = 0, walls at x = +-1.2; y = 8 is clear.
    f = render_camera(fig2_world, 0.0, 8.0, 0.0, SMALL)
    assert f.depth[60, 80] == pytest.approx(1.2, abs=0.02)
    assert fig2_world.labels[int(f.segmentation[60, 80])] == "wall"
    ahead = render_camera(fig2_world, 0.0, 8.0, -math.pi / 2, SMALL)  # along the corridor
    assert ahead.segmentation[115, 80] == fig2_world.label_id("floor")
    assert ahead.segmentation[2, 80] == fig2_world.label_id("ceiling")
    floor_depth = 1.6 * SMALL.fy / (115 - SMALL.cy)  # a floor point 1.6 m below the camera
    assert ahead.depth[115, 80] == pytest.approx(floor_depth, rel=0.03)
    assert linearise_depth(np.array([0.0]))[0] == pytest.approx(0.05)


def test_floor_and_walls_differ_in_colour(fig2_world):
    f = render_camera(fig2_world, 0.0, 8.0, math.pi / 2, SMALL)
    floor = f.rgb[f.segmentation == fig2_world.label_id("floor")].mean(axis=0)
    wall = f.rgb[f.segmentation == fig2_world.label_id("wall")].mean(axis=0)
    assert np.abs(floor - wall).sum() > 60


def test_obstacles_block_rays_and_can_be_removed(fig2_world):
    w = fig2_world
    start, end = (0.0, 9.0, 0.5), (0.0, 5.0, 0.5)
    assert w.ray(start, end) is None
    body = w.add_obstacle(0.0, 7.0, 0.5)
    try:
        hit = w.ray(start, end)
        assert hit is not None and hit.label == "obstacle"
        assert hit.distance == pytest.approx(1.75, abs=0.01)
    finally:
        w.remove_obstacle(body)
    assert w.ray(start, end) is None
    with pytest.raises(SimError):
        w.add_obstacle(0.0, 7.0, -1.0)


def test_camera_on_a_face_plane_does_not_hang(fig2_world):
    # The wall's back face lies in the plane x = -1.3: the tiny renderer used to spin forever.
    f = render_camera(fig2_world, -1.3, 16.0, 0.0, SMALL)
    assert f.rgb.shape == (120, 160, 3)


def test_sign_layout_and_texture():
    assert sign_lines("117 One-Stop Service Centre") == ["117", "One-Stop", "Service Centre"]
    assert sign_lines("Stairs") == ["Stairs"]
    tex = make_sign("104 Laboratory")
    assert tex.lines == ("104", "Laboratory")
    h, w, _ = tex.image.shape
    assert w / h == pytest.approx(tex.width_m / tex.height_m, rel=0.02)
    dark = (tex.image.mean(axis=2) < 80).mean()
    assert 0.05 < dark < 0.5


def test_gui_without_display_is_a_clear_error(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    with pytest.raises(SimError, match="display"):
        SimWorld(load_building("straight_office"), gui=True)


def test_top_down_image(fig2_world):
    img = draw_top_down(fig2_world, fig2_world.start_pose(), px_per_m=10)
    x0, y0, x1, y1 = fig2_world.bounds(margin=3.0)
    assert img.shape[:2] == (math.ceil((y1 - y0) * 10), math.ceil((x1 - x0) * 10))


def test_cli_show_writes_images(tmp_path):
    runner = CliRunner()
    res = runner.invoke(
        app,
        [
            "show",
            "straight_office",
            "--out",
            str(tmp_path),
            "--width",
            "96",
            "--height",
            "72",
            "--pose",
            "10,0,90",
        ],
    )
    assert res.exit_code == 0, res.output
    names = {p.name for p in tmp_path.iterdir()}
    assert {
        "straight_office_top_down.png",
        "straight_office_view_rgb.png",
        "straight_office_view_depth.png",
        "straight_office_view_seg.png",
    } <= names
    assert "sees:" in res.output and "wall" in res.output
    bad = runner.invoke(app, ["show", "straight_office", "--out", str(tmp_path), "--pose", "1,2"])
    assert isinstance(bad.exception, PoseError)


def test_obstacle_footprints_are_landmarks_and_obstacles_not_walls(world):
    from shapely.geometry import Point

    from pmnav_bt.sim.robot import COLLISION_HEIGHT

    prints = world.obstacle_footprints(COLLISION_HEIGHT)
    # Every footprint touches the free space (things on walls stand out into it) ...
    assert all(fp.intersects(world.free_space) for fp in prints)
    # ... but none is a whole wall: walls are left to the free-space polygon.
    assert all(fp.area < 3.0 for fp in prints)
    for lm in world.building.landmarks:
        item = world.landmarks[lm.id]
        inside = np.add(item.centre, 0.3 * np.asarray(item.normal))  # 30 cm out of the wall
        # Solid kinds (desks, stairs) stand in the corridor, low: the body meets them.
        met = min(fp.distance(Point(*inside)) for fp in prints) < 1e-6
        assert met == landmark_shape(lm.kind).solid, lm.id
    body = world.add_obstacle(*world.start_pose().xy(), 0.5)
    try:
        assert len(world.obstacle_footprints(COLLISION_HEIGHT)) == len(prints) + 1
    finally:
        world.remove_obstacle(body)
    assert len(world.obstacle_footprints(COLLISION_HEIGHT)) == len(prints)
    assert len(world.obstacle_footprints(0.0)) == 0  # nothing starts below the floor


def test_the_simulator_warns_of_what_validate_warns_of(caplog):
    """One placer hangs the simulator's items and checks the file for validate: a door on
    a wall too short for it (the dead end of a corridor 1 m wide), two signs at one spot."""
    from pmnav_bt.map.building import building_from_data
    from pmnav_bt.map.wall_items import wall_item_warnings

    b = building_from_data(
        {
            "schema_version": 1,
            "name": "tight",
            "corridor_width": 1.0,
            "waypoints": [
                {"id": "start", "kind": "start", "pos": [0.0, 0.0]},
                {"id": "end1", "kind": "end", "pos": [20.0, 0.0]},
            ],
            "edges": [["start", "end1"]],
            "rooms": [{"id": "room1", "door": [20.5, 0.0], "sign": "101"}],
            "landmarks": [
                {"id": f"sign{k}", "kind": "sign", "pos": [10.0, 0.5], "sign": "Exit"}
                for k in "ab"
            ],
        }
    )
    warned = {w.message for w in wall_item_warnings(b)}
    assert len(warned) == 2
    with caplog.at_level("WARNING", logger="pmnav_bt.sim.world"), SimWorld(b, ceiling=False):
        pass
    logged = {r.getMessage() for r in caplog.records if r.name == "pmnav_bt.sim.world"}
    assert warned <= logged


def test_cli_show_takes_a_config_file(tmp_path):
    cfg = tmp_path / "run.yaml"
    cfg.write_text("world: {preset: realistic, people_per_100m: 0.0}\n")
    def show(out, *more):
        args = ["show", "straight_office", "--out", str(out), "--width", "32", "--height", "24"]
        res = CliRunner().invoke(app, [*args, *more])
        assert res.exit_code == 0, res.output
        return (out / "straight_office_view_rgb.png").read_bytes()

    # the realistic world looks different from the clean one
    assert show(tmp_path / "cfg", "--config", str(cfg)) != show(tmp_path / "clean")
