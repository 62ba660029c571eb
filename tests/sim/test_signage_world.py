"""Signs in the world where the signage section says: every mounting puts the plate where
its WallItem says (rays and a render), directional signs hang by their spot, random
signage is one system per building and seed, and without a section the world is today's."""

from __future__ import annotations

import math
from collections import Counter

import numpy as np
import pytest
import yaml

from pmnav_bt.config import WorldConfig
from pmnav_bt.map.building import building_from_data
from pmnav_bt.map.catalogue import resolve_building_path
from pmnav_bt.map.signage import LAYOUTS, MOUNTINGS, SIGN_FONTS
from pmnav_bt.seams import CameraIntrinsics, directional_sign_label, sign_label
from pmnav_bt.sim._pybullet import p
from pmnav_bt.sim.render import render_camera
from pmnav_bt.sim.scene import scene_rng
from pmnav_bt.sim.scene.plates import make_line_plate
from pmnav_bt.sim.scene.sign_mounting import FLAG_MIN_BOTTOM_M
from pmnav_bt.sim.scene.signage import (
    CLEAN_STYLE,
    COLOUR_SCHEMES,
    draw_style,
    resolve_signage,
)
from pmnav_bt.sim.scene.wayfinding import junction_signs
from pmnav_bt.sim.textures import make_sign
from pmnav_bt.sim.world import SIGN_CENTRE_Z, SimWorld

ROOM = "room3"  # fig2_hospital: door at (-1.2, 10) on the west wall of the first corridor
STYLE = {"plate_width": 0.3, "cap_height": 0.04, "font": "dejavu_sans_bold", "height": 1.5}


def fig2_data() -> dict:
    return yaml.safe_load(resolve_building_path("fig2_hospital").read_text())


def fig2_with(signage: dict | None):
    data = fig2_data()
    if signage is not None:
        data["signage"] = signage
    return building_from_data(data)


@pytest.fixture(scope="module")
def mounted():
    """One world per mounting: room3 in that mounting, the rest beside their doors."""
    worlds = {}
    for m in MOUNTINGS:
        b = fig2_with({"style": STYLE, "rooms": {ROOM: {"mounting": m}}})
        worlds[m] = SimWorld(b)
    yield worlds
    for w in worlds.values():
        w.close()


def _ray_to(world: SimWorld, item, distance: float):
    """A ray from ``distance`` out along the item's normal, at its mid height, to it."""
    zc = (item.z[0] + item.z[1]) / 2.0
    c, n = np.asarray(item.centre), np.asarray(item.normal)
    start = (*(c + distance * n), zc)
    end = (*(c - 0.2 * n), zc)
    return world.ray(start, end)


def _along(world: SimWorld, rid: str, item) -> float:
    """The item's position along the door's wall relative to the door, + to the viewer's
    left (the wall's tangent)."""
    door = world.doors[rid]
    n = np.asarray(door.normal)
    t = np.array([n[1], -n[0]])  # the viewer's left when facing the wall (along -n)
    return float(np.dot(np.asarray(item.centre) - np.asarray(door.centre), t))


@pytest.mark.parametrize("mounting", [m for m in MOUNTINGS if m != "flag"])
def test_a_flat_plate_is_where_its_wall_item_says(mounted, mounting):
    world = mounted[mounting]
    item, door = world.signs[ROOM], world.doors[ROOM]
    hit = _ray_to(world, item, 1.5)
    assert hit is not None and hit.label == sign_label(ROOM)
    out = 0.02 if mounting == "on_door" else 0.0  # a door plate stands on the leaf
    assert hit.distance == pytest.approx(1.5 - out - 0.015, abs=0.01)  # the plate's face
    assert item.normal == door.normal
    assert item.width == pytest.approx(0.32, abs=0.01)  # 0.3 m plate with its backing
    along = _along(world, ROOM, item)
    off = door.width / 2 + 0.15 + item.width / 2
    mid = (item.z[0] + item.z[1]) / 2.0
    if mounting in ("beside", "beside_right"):
        assert along == pytest.approx(-off, abs=1e-6)  # the viewer's right
        assert mid == pytest.approx(1.5)
    elif mounting == "beside_left":
        assert along == pytest.approx(off, abs=1e-6)
    elif mounting == "on_door":
        assert along == pytest.approx(0.0, abs=1e-6) and item.z[1] < door.z[1]
        assert world.ray((*np.add(door.centre, 1.5 * np.asarray(door.normal)), 0.5),
                         (*door.centre, 0.5)).label == door.label  # the leaf below the plate
    else:  # above_door
        assert along == pytest.approx(0.0, abs=1e-6) and item.z[0] > door.z[1]
    # Just beside the plate along the wall there is no sign.
    side = np.array([item.normal[1], -item.normal[0]]) * (item.width / 2 + 0.05)
    out = np.asarray(item.centre) + side
    beside = world.ray((*(out + 1.5 * np.asarray(item.normal)), mid), (*out, mid))
    assert beside is None or beside.label != sign_label(ROOM)


def test_a_flag_sign_projects_from_the_wall_and_is_read_along_the_corridor(mounted):
    world = mounted["flag"]
    item, door = world.signs[ROOM], world.doors[ROOM]
    n_wall = np.asarray(door.normal)
    assert abs(np.dot(item.normal, n_wall)) < 1e-9  # faces along the corridor
    assert item.z[0] >= FLAG_MIN_BOTTOM_M - 1e-9  # above head height
    # Its centre stands out in the corridor by the bracket and half the plate.
    out = np.dot(np.asarray(item.centre) - np.asarray(door.centre), n_wall)
    assert out == pytest.approx(0.05 + item.width / 2, abs=1e-6)
    for side in (1, -1):  # double-sided: read from both ends of the corridor
        zc = (item.z[0] + item.z[1]) / 2.0
        start = np.asarray(item.centre) + side * 4.0 * np.asarray(item.normal)
        hit = world.ray((*start, zc), (*item.centre, zc))
        assert hit is not None and hit.label == sign_label(ROOM)
        assert hit.distance == pytest.approx(4.0 - 0.0095, abs=0.01)
    # Seen end-on from 4 m down the corridor: the plate is in the view, centred where its
    # centre projects (above the image's centre row: it hangs above the camera).
    k = CameraIntrinsics.from_hfov(160, 120, math.radians(60.0))
    pose = item.viewpoint(4.0)
    f = render_camera(world, pose.x, pose.y, pose.yaw, k, height=1.6, segmentation=True)
    mask = f.segmentation == world.label_id(sign_label(ROOM))
    assert mask.sum() > 20
    ys, xs = np.nonzero(mask)
    assert abs(xs.mean() - k.cx) < 3
    zc = (item.z[0] + item.z[1]) / 2.0
    assert ys.mean() == pytest.approx(k.cy - k.fy * (zc - 1.6) / 4.0, abs=3)
    # From across the corridor, in the plate's plane, the flag is only its thin edge.
    c = np.asarray(item.centre) + (2.0 - out) * n_wall
    yaw = math.atan2(-n_wall[1], -n_wall[0])
    f = render_camera(world, c[0], c[1], yaw, k, height=1.6, segmentation=True)
    edge = f.segmentation == world.label_id(sign_label(ROOM))
    assert 0 < edge.sum() < mask.sum() / 3


def test_sign_views_see_flag_signs(mounted):
    from pmnav_bt.sim.sign_views import sample_views

    world = mounted["flag"]
    views = list(
        sample_views(
            world, 3, width=96, height=72, seed=1, distances=(3.0, 5.0),
            angles=(0.0, 0.3), select=lambda text: text == world.signs[ROOM].text,
        )
    )
    assert len(views) == 3
    sid = world.label_id(sign_label(ROOM))
    for v in views:
        assert (v.observation.segmentation == sid).any()


def test_directional_signs_hang_on_the_nearest_wall():
    b = fig2_with(
        {"directional": [{"at": [-0.5, 5.0], "text": "Radiology ->"}, {"at": [35.0, 10.0],
                                                                       "text": "<- 101-120"}]}
    )
    with SimWorld(b) as world:
        assert set(world.directional_signs) == {"0", "1"}
        for i, item in world.directional_signs.items():
            assert item.label == directional_sign_label(int(i))
            assert item.kind == "directional"
            hit = _ray_to(world, item, 1.0)
            assert hit is not None and hit.label == item.label
        assert world.directional_signs["0"].text == "Radiology ->"
        # (-0.5, 5) is nearest the west wall of the first corridor (x = -1.2); (35, 10) the
        # west wall of the corridor from turn2 to branch1 (x = 34.8).
        assert world.directional_signs["0"].centre[0] == pytest.approx(-1.2)
        assert world.directional_signs["1"].centre[0] == pytest.approx(34.8)


def test_no_section_and_file_signage_builds_todays_plates():
    data = fig2_data()
    b = building_from_data(data)
    assert resolve_signage(b, "file", scene_rng(3, b.name, "signage")) is None
    with SimWorld(b, scene=WorldConfig(preset="clean"), seed=3) as world:
        for room in b.rooms:
            item = world.signs[room.id]
            tex = make_sign(room.sign_text)
            assert item.text == room.sign_text
            assert item.width == pytest.approx(tex.width_m + 0.02)
            assert (item.z[0] + item.z[1]) / 2 == pytest.approx(SIGN_CENTRE_Z)
            assert item.z[1] - item.z[0] == pytest.approx(tex.height_m)
        shapes = _visuals(world)
    with SimWorld(b, seed=11) as other:  # the clean world does not depend on the seed
        assert _visuals(other) == shapes


def _visuals(world: SimWorld) -> list:
    """Every body's label, pose and visual shapes (sizes, colours, textures' files aside)."""
    out = []
    with world.lock:
        for body in sorted(world._body_label):
            pos, orn = p.getBasePositionAndOrientation(body, physicsClientId=world.client)
            vis = p.getVisualShapeData(body, physicsClientId=world.client)
            out.append((world.label_of(body), np.round(pos, 6).tolist(), np.round(orn, 6).tolist(),
                        [(v[2], np.round(v[3], 6).tolist(), np.round(v[7], 4).tolist())
                         for v in vis]))
    return out


def test_todays_style_written_out_mounts_todays_places():
    clean = {
        "plate_width": CLEAN_STYLE.plate_width,
        "cap_height": CLEAN_STYLE.cap_height,
        "font": "hershey",
        "text_rgb": [0, 0, 0],
        "plate_rgb": [255, 255, 255],
        "mounting": "beside",
        "layout": "number_and_name",
        "height": SIGN_CENTRE_Z,
    }
    with SimWorld(fig2_with(None)) as today, SimWorld(fig2_with({"style": clean})) as styled:
        for rid, item in today.signs.items():
            again = styled.signs[rid]
            assert again.centre == pytest.approx(item.centre, abs=0.005)
            assert again.normal == item.normal
            assert again.width == pytest.approx(item.width, abs=0.01)
            assert np.mean(again.z) == pytest.approx(np.mean(item.z))


def test_random_signage_is_one_system_per_building_and_seed():
    data = fig2_data()
    data["rooms"].append({"id": "wc1", "name": "Toilets", "door": [-1.2, 3.0]})
    b = building_from_data(data)
    styles = [resolve_signage(b, "random", scene_rng(s, b.name, "signage")) for s in range(40)]
    again = resolve_signage(b, "random", scene_rng(7, b.name, "signage"))
    assert again == styles[7]  # seeded
    for sg in styles:
        plain = {st for rid, st in sg.rooms.items() if rid != "wc1"}
        assert plain == {sg.style}  # one style for every room
    pictograms = [sg.rooms["wc1"].pictogram for sg in styles]
    assert 0 < pictograms.count("toilet") < len(styles)  # most buildings, not all
    assert len({sg.style for sg in styles}) == len(styles)  # each seed its own system


def test_random_signage_uses_every_kind_across_seeds():
    drawn = [draw_style(scene_rng(s, "any", "signage")) for s in range(300)]
    assert set(Counter(d.mounting for d in drawn)) == set(MOUNTINGS)
    assert set(Counter(d.layout for d in drawn)) == set(LAYOUTS)
    assert set(Counter(d.font for d in drawn)) == set(SIGN_FONTS)
    schemes = {(d.text_rgb, d.plate_rgb) for d in drawn}
    assert schemes == set(COLOUR_SCHEMES.values())
    for d in drawn:
        assert 0.15 <= d.plate_width <= 0.45 and 0.02 <= d.cap_height <= 0.08


def test_random_signage_keeps_what_the_file_sets():
    b = fig2_with({"style": {"mounting": "flag", "plate_rgb": [0, 0, 0]}})
    for s in range(5):
        sg = resolve_signage(b, "random", scene_rng(s, b.name, "signage"))
        assert sg.style.mounting == "flag" and sg.style.plate_rgb == (0, 0, 0)


def test_realistic_world_builds_styled_signs():
    with SimWorld("fig2_hospital", scene=WorldConfig(preset="realistic"), seed=2) as world:
        style = resolve_signage(world.building, "random", world.rng("signage")).style
        widths = {round(it.width, 3) for it in world.signs.values()}
        assert widths == {round(style.plate_width + 0.02, 3)}
        for rid, item in world.signs.items():
            assert item.label == sign_label(rid)
        # Landmark plates too are in the building's style: one line, as wide as the name.
        for lid, item in world.landmark_signs.items():
            text = world.building.landmark(lid).sign_text
            assert item.width == pytest.approx(make_line_plate(text, style).width_m + 0.02)
            hit = _ray_to(world, item, 1.0)
            assert hit is not None and hit.label == item.label


@pytest.mark.parametrize("name", ["fig2_hospital", "t_school"])
def test_junction_signs_point_the_right_way(name):
    """Each wayfinding sign hangs on a wall facing the arrival at a junction, and the rooms
    it names lie on the side its arrow points to (left: counter-clockwise of walking)."""
    with SimWorld(name, scene=WorldConfig(signage="random"), seed=0) as world:
        b = world.building
        signs = []
        for seed in range(6):
            signs += junction_signs(b, world.walls, scene_rng(seed, b.name, "wayfinding"))
        assert len(signs) >= 4
        junctions = np.array([w.pos for w in b.waypoints])
        for spec in signs:
            wi, _ = world._nearest_wall(spec.at)
            d = -np.asarray(world.walls[wi].normal)  # the reader walks towards the wall
            here = junctions[np.argmin(np.linalg.norm(junctions - spec.at, axis=1))]
            left = spec.text.startswith("<- ")
            assert left != spec.text.endswith(" ->")
            body = spec.text.removeprefix("<- ").removesuffix(" ->")
            named = [r for r in b.rooms if r.display_name == body]  # or the range's ends:
            named = named or [r for r in b.rooms if r.sign_text.split()[0] in body.split("-")]
            assert named, spec.text
            for r in named:
                v = np.subtract(r.door, here)
                side = d[0] * v[1] - d[1] * v[0]
                assert (side > 0) == left, (spec.text, r.id)


def test_realistic_worlds_hang_junction_signs():
    with SimWorld("t_school", scene=WorldConfig(preset="realistic"), seed=6) as world:
        assert world.directional_signs
        for i, item in world.directional_signs.items():
            assert item.label == directional_sign_label(int(i))
            hit = _ray_to(world, item, 1.0)
            assert hit is not None and hit.label == item.label
    with SimWorld("t_school") as clean:
        assert not clean.directional_signs
