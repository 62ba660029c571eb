"""Colours, textures and light of a world (sim/scene/appearance.py): clean is today's world
to the bit, random palettes are drawn per building and seed, the light level sets the
brightness of everything, sign plates included."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.config import load_config
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.seams import Pose2D, sign_label
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.robot import SimBase
from pmnav_bt.sim.scene.appearance import CLEAN_LIGHT, LIGHT_DIRECTION, PALETTES, draw_light
from pmnav_bt.sim.world import SimWorld

BUILDING = "straight_office"


def scene(*sets: str):
    return load_config(None, list(sets)).world


def views(world: SimWorld, reading: bool = False) -> list:
    """Three frames of ``world`` (RGB, depth, segmentation; a reading crop if asked)."""
    base = SimBase(world, SimClock(), width=160, height=120, reading_width=320 if reading else 0)
    out = []
    for k in range(3):
        o = base.render_view(k * 2.1)
        out += [o.rgb, o.depth, o.segmentation]
        if reading:
            out.append(o.reading.crop((40, 30, 200, 120)))
    base.close()
    return out


def sign_view(world: SimWorld) -> tuple[np.ndarray, np.ndarray]:
    """A frame 1.5 m in front of the first sign plate and the plate's pixel mask."""
    rid = sorted(world.signs)[0]
    v = world.signs[rid].viewpoint(1.5)
    base = SimBase(world, SimClock(), width=160, height=120, pose=Pose2D(v.x, v.y, v.yaw))
    o = base.observe()
    base.close()
    return o.rgb, o.segmentation == world.label_id(sign_label(rid))


def test_clean_preset_is_the_default_world_to_the_bit():
    with SimWorld(BUILDING) as plain, SimWorld(BUILDING, scene=scene("world.preset=clean"),
                                               seed=7) as clean:
        assert clean.appearance.light == CLEAN_LIGHT
        for a, b in zip(views(plain, reading=True), views(clean, reading=True), strict=True):
            assert np.array_equal(a, b)


def test_random_appearance_is_reproducible_per_seed_and_differs_across_seeds():
    cfg = scene("world.appearance=random")
    with SimWorld(BUILDING, scene=cfg, seed=3) as a, SimWorld(BUILDING, scene=cfg, seed=3) as b:
        assert all(np.array_equal(x, y) for x, y in zip(views(a), views(b), strict=True))
        first = views(a)[0]
    looks = set()
    for seed in range(4, 8):
        with SimWorld(BUILDING, scene=cfg, seed=seed) as w:
            looks.add((w.appearance.wall, w.appearance.floor, w.appearance.door))
            assert not np.array_equal(views(w)[0], first)
    assert len(looks) > 1


@pytest.mark.parametrize("name", ["l_hospital", "t_school", "straight_office"])
def test_the_palette_follows_the_building_kind(name):
    kind = load_building(name).kind
    assert kind in PALETTES
    with SimWorld(name, scene=scene("world.appearance=random"), seed=1) as w:
        assert w.appearance.palette == kind
        assert w.appearance.floor_surface is not None


def test_random_appearance_keeps_the_labels_and_the_solid_walls():
    """The textures are visual quads: what the robot bumps into and the labels it is told
    stay those of the clean world (the textured floor and walls carry floor/wall labels)."""
    with SimWorld("t_school") as clean, SimWorld(
        "t_school", scene=scene("world.appearance=random"), seed=2
    ) as looks:
        assert looks.wall_source == "corridors" and looks.appearance.wall_surface is not None
        assert set(looks.labels.values()) == set(clean.labels.values())
        assert len(looks._solid) == len(clean._solid)
        for x, y in [(w.point(w.length / 2) + 0.4 * np.asarray(w.normal)) for w in clean.walls[:5]]:
            assert looks.clearance(x, y, 0.17) == pytest.approx(clean.clearance(x, y, 0.17))


def test_a_dimmer_light_darkens_the_frame_and_the_sign_plate():
    bright_cfg = scene("world.light_level=[1.0,1.0]")
    dim_cfg = scene("world.light_level=[0.5,0.5]")
    with SimWorld(BUILDING, scene=bright_cfg) as w:
        bright, plate = sign_view(w)
    with SimWorld(BUILDING, scene=dim_cfg) as w:
        assert w.appearance.light.level == 0.5
        dim, plate_dim = sign_view(w)
    assert np.array_equal(plate, plate_dim) and plate.sum() > 50
    assert 0.4 < dim.mean() / bright.mean() < 0.6
    assert dim[plate].mean() < 0.6 * bright[plate].mean()


def test_the_light_turns_in_azimuth_by_at_most_the_setting():
    cfg = scene("world.light_turn_deg=30")
    base = math.atan2(LIGHT_DIRECTION[1], LIGHT_DIRECTION[0])
    turns = []
    for seed in range(20):
        light = draw_light(cfg, np.random.default_rng(seed))
        d = light.direction
        assert d[2] == LIGHT_DIRECTION[2] and math.hypot(*d) == pytest.approx(1.0)
        turns.append(math.degrees(math.atan2(d[1], d[0]) - base))
    assert max(abs(t) for t in turns) <= 30.0 and np.std(turns) > 5.0
    assert draw_light(scene(), np.random.default_rng(0)) is CLEAN_LIGHT
