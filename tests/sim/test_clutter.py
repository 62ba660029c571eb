"""Clutter along the corridor walls: each kind stands where it is placed, solid and labelled;
the seeded placement keeps every door, junction and landmark clear, leaves room to pass,
keeps every goal reachable, and is reproducible."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Point

from pmnav_bt.config import WorldConfig
from pmnav_bt.eval.geodesic import GeodesicField
from pmnav_bt.eval.task import STOP_OFFSET_M, SUCCESS_RADIUS_M
from pmnav_bt.seams import OBSTACLE_LABEL, CameraIntrinsics
from pmnav_bt.sim.render import draw_top_down, render_camera
from pmnav_bt.sim.robot import COLLISION_HEIGHT, RADIUS
from pmnav_bt.sim.scene.clutter import (
    CENTRE_BAND_M,
    JUNCTION_CLEAR_M,
    PASSAGE_M,
    WALL_GAP_M,
    add_item,
)
from pmnav_bt.sim.scene.corridors import corridors, junction_points
from pmnav_bt.sim.scene.furniture import BUILDERS, ON_WALL
from pmnav_bt.sim.world import SimWorld

# straight_office: one corridor along x (y = 0), 2.2 m wide; its wall at y = -1.1 is bare
# from the last door (x = 50.1) to the dead end (x = 55.1): room for an item of every kind.
WALL = np.array([52.6, -1.1])
INTO = np.array([0.0, 1.0])  # out of that wall, into the corridor
# Plates beside the doors (signage: file), so that every sign can have clutter before it
# (a projecting flag sign hangs over the corridor, out of any item's reach).
CLUTTERED = WorldConfig(preset="realistic", clutter_per_10m=3.0, signage="file")
K = CameraIntrinsics.from_hfov(160, 120, math.radians(60.0))


def _ray_hits(world: SimWorld, along: float, z: float):
    """What a ray across the corridor towards the bare wall hits, ``along`` m beside WALL."""
    x = WALL[0] + along
    return world.ray((x, WALL[1] + 2.1, z), (x, WALL[1] + 0.01, z))


@pytest.mark.parametrize("kind", sorted(BUILDERS))
def test_each_kind_stands_where_it_is_placed_solid_and_labelled(kind):
    with SimWorld("straight_office") as world:
        on_wall = [*world.doors.values(), *world.signs.values(), *world.landmarks.values()]
        assert all(
            abs(it.centre[0] - WALL[0]) > 2.4 for it in on_wall if it.centre[1] < 0
        ), "the bare wall is no longer bare"
        shape = BUILDERS[kind](np.random.default_rng(1))
        gap = 0.0 if kind in ON_WALL else WALL_GAP_M
        centre = WALL + INTO * (gap + shape.depth / 2.0)
        prints = len(world.obstacle_footprints(COLLISION_HEIGHT))
        body = add_item(world, kind, shape, centre, INTO)
        assert world.label_of(body) == OBSTACLE_LABEL
        # A ray across the corridor at mid-height of the item hits its front face ...
        z = (shape.bottom + shape.top) / 2.0
        hit = _ray_hits(world, 0.0, z)
        assert hit is not None and hit.body == body
        front = WALL[1] + gap + shape.depth
        assert hit.point[1] == pytest.approx(front, abs=0.01)
        # ... and along the wall it spans its length, and no more.
        half = shape.length / 2.0
        for along, inside in ((half - 0.03, True), (half + 0.03, False)):
            for sign in (-1, 1):
                h = _ray_hits(world, sign * along, z)
                assert (h is not None and h.body == body) is inside, (kind, along, sign)
        # Part of the building as built; solid for the robot where it stands on the floor.
        fps = world.obstacle_footprints(COLLISION_HEIGHT)
        assert len(fps) == prints + 1
        assert shapely.union_all(fps).contains(Point(centre))
        if kind not in ON_WALL:
            assert world.clearance(WALL[0], front + RADIUS - 0.05, RADIUS) < 0.0
            assert world.clearance(WALL[0], front + RADIUS + 0.05, RADIUS) > 0.0
        # The camera facing it from across the corridor sees its label in the middle,
        # nearer than the wall behind it.
        eye = WALL + INTO * 2.0
        f = render_camera(world, eye[0], eye[1], -math.pi / 2, K, height=z)
        mid = f.segmentation[50:70, 70:90] == world.label_id(OBSTACLE_LABEL)
        assert mid.mean() > 0.2, kind
        assert f.depth[50:70, 70:90][mid].max() < 2.0 - gap, kind


def _cross_width(c, s: float, blocks) -> float:
    """The widest clear stretch across corridor ``c`` at ``s`` among ``blocks``."""
    seg = LineString([c.point(s, -c.half_width), c.point(s, c.half_width)])
    free = seg.difference(blocks)
    return max((g.length for g in getattr(free, "geoms", [free])), default=0.0)


@pytest.fixture(scope="module", params=[("fig2_hospital", 0), ("u_office", 1), ("loop_school", 2)])
def cluttered(request):
    name, seed = request.param
    w = SimWorld(name, scene=CLUTTERED, seed=seed)
    yield w
    w.close()


def test_the_density_asked_for_is_placed(cluttered):
    wall = sum(w.length for w in cluttered.walls)
    expected = wall * CLUTTERED.clutter_per_10m / 10.0
    n = len(cluttered.clutter)
    assert 0.6 * expected <= n <= expected + 1
    assert len({c.kind for c in cluttered.clutter}) >= 4


def test_door_approaches_junctions_and_landmark_fronts_stay_clear(cluttered):
    w = cluttered
    prints = shapely.union_all([c.footprint for c in w.clutter])
    for rid, door in w.doors.items():
        assert not Point(door.centre).buffer(SUCCESS_RADIUS_M).intersects(prints), rid
    for xy, hw in junction_points(w.building):
        assert Point(xy).distance(prints) >= hw * math.sqrt(2.0) + JUNCTION_CLEAR_M - 1e-6
    for lid, lm in w.landmarks.items():
        if lm.z[0] < 0.5:  # stands on the floor
            front = Point(np.asarray(lm.centre) + np.asarray(lm.normal) * 0.6)
            assert front.distance(prints) > 0.5, lid


def test_the_centre_lines_stay_drivable_and_the_passage_wide(cluttered):
    w = cluttered
    floor_items = [c.footprint for c in w.clutter if c.kind not in ON_WALL]
    blocks = shapely.union_all(floor_items)
    lines = shapely.union_all([LineString([c.a, c.b]) for c in corridors(w.building)])
    assert lines.distance(blocks) >= CENTRE_BAND_M - 1e-6
    narrowed = 0
    for c in corridors(w.building):
        for s in np.arange(0.0, c.length, 0.1):
            width = _cross_width(c, s, blocks)
            assert width >= PASSAGE_M - 1e-6, (c.index, s)
            narrowed += width < 2.0 * c.half_width - 0.3
    assert narrowed  # the check saw clutter


def test_every_door_is_reachable_from_the_start_round_the_clutter(cluttered):
    w = cluttered
    start = w.start_pose()
    field = GeodesicField(
        w.floor_space(), (start.x, start.y), 0.3, obstacles=w.obstacle_footprints(COLLISION_HEIGHT)
    )
    for rid, door in w.doors.items():
        stop = np.asarray(door.centre) + STOP_OFFSET_M * np.asarray(door.normal)
        assert math.isfinite(field.distance(stop)), rid


def test_items_before_signs_partly_hide_them(cluttered):
    w = cluttered
    before = [c for c in w.clutter if c.before_sign]
    asked = sum(x.length for x in w.walls) * CLUTTERED.clutter_per_10m / 10.0
    asked *= CLUTTERED.clutter_before_signs
    assert 0.6 * asked <= len(before) <= asked + 1
    plates = [*w.signs.values(), *w.landmark_signs.values(), *w.landmarks.values()]
    for item in before:
        plate = next(p for p in plates if p.label == item.before_sign and p.z[0] >= 0.5)
        t = np.array([-item.normal[1], item.normal[0]])
        offset = abs(float((np.asarray(item.centre) - plate.centre) @ t))
        assert offset < (item.length + plate.width) / 2.0  # overlaps the plate along the wall
        assert item.top > plate.z[0]  # and reaches above its lower edge
    others = [c for c in w.clutter if not c.before_sign]
    fronts = [Point(p.centre).buffer(0.3) for p in plates if p.z[0] >= 0.5]
    assert not any(c.footprint.intersects(f) for c in others for f in fronts)


def test_placement_is_reproducible_from_the_seed():
    def layout(seed: int):
        with SimWorld("straight_office", scene=CLUTTERED, seed=seed) as w:
            return [(c.kind, round(c.centre[0], 6), round(c.centre[1], 6)) for c in w.clutter]

    assert layout(4) == layout(4)
    assert layout(4) != layout(5)


def test_the_top_down_view_draws_each_item_in_its_kind_colour(cluttered):
    from pmnav_bt.sim.render import CLUTTER_COLOURS

    img = draw_top_down(cluttered, px_per_m=20.0, margin_m=3.0)
    x0, _, _, y1 = cluttered.bounds(margin=3.0)
    for item in cluttered.clutter:
        c = item.footprint.centroid
        u, v = int(round((c.x - x0) * 20)), int(round((y1 - c.y) * 20))
        if item.kind in ON_WALL:
            continue  # 3 cm deep: under its outline
        assert tuple(img[v, u]) == CLUTTER_COLOURS[item.kind], item.kind


def test_the_clean_preset_places_nothing():
    with SimWorld("fig2_hospital", scene=WorldConfig(preset="clean"), seed=9) as w:
        assert w.clutter == []
        assert w.bodies_with_label(OBSTACLE_LABEL) == []
