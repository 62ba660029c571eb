"""Door states: the fractions open and glazed are those asked for and replay from the seed;
an open door shows a dark doorway, a glazed one a pale pane, both still labelled as the
door; the recorded doors are the clean world's, and the clean preset closes every door."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.config import WorldConfig
from pmnav_bt.seams import CameraIntrinsics, door_label
from pmnav_bt.sim.render import render_camera
from pmnav_bt.sim.scene.doors import CLOSED, door_states
from pmnav_bt.sim.world import SimWorld

K = CameraIntrinsics.from_hfov(160, 120, math.radians(60.0))
# Today's door colours (appearance clean), so a closed leaf is known to be wood.
MIXED = WorldConfig(
    preset="realistic", doors_open=0.3, doors_glass=0.2, people_per_100m=0.0, appearance="clean"
)


@pytest.mark.parametrize("n", [1, 7, 40])
def test_door_states_take_the_fractions_asked_for_from_the_seed(n):
    rooms = [f"r{k}" for k in range(n)]

    def states(seed: int):
        return door_states(rooms, MIXED, np.random.default_rng(seed))

    a = states(1)
    assert sum(s.open for s in a.values()) == round(0.3 * n)
    assert sum(s.glass for s in a.values()) == round(0.2 * n)
    assert a == states(1)
    if n == 40:
        assert a != states(2)
    none = door_states(rooms, WorldConfig(), np.random.default_rng(1))
    assert set(none.values()) == {CLOSED}


@pytest.fixture(scope="module")
def worlds():
    with SimWorld("fig2_hospital") as clean, SimWorld("fig2_hospital", scene=MIXED, seed=3) as w:
        yield clean, w


def _look(world: SimWorld, room: str):
    """The middle of a view of ``room``'s door from 1.5 m, at 1.2 m height."""
    q = world.doors[room].viewpoint(1.5)
    f = render_camera(world, q.x, q.y, q.yaw, K, height=1.2)
    return f.rgb[50:70, 70:90].reshape(-1, 3).astype(float), f.segmentation[50:70, 70:90]


def test_each_state_has_its_look_and_keeps_the_door_label(worlds):
    clean, w = worlds
    states = w.door_states
    assert set(states) == set(clean.door_states) == {r.id for r in w.building.rooms}
    seen = set()
    for room, state in states.items():
        rgb, seg = _look(w, room)
        assert (seg == w.label_id(door_label(room))).mean() > 0.95, room
        r, g, b = rgb.mean(axis=0)
        if state.open:
            assert max(r, g, b) < 60, room  # a dark doorway
        elif state.glass:
            assert b > r + 15 and min(r, g, b) > 110, room  # a pale blue-grey pane
        else:
            assert r > b + 30, room  # the wooden leaf
        seen.add((state.open, state.glass and not state.open))
    assert {(True, False), (False, True), (False, False)} <= seen


def test_the_recorded_doors_are_the_clean_worlds(worlds):
    clean, w = worlds
    assert w.doors == clean.doors
    for room, state in w.door_states.items():
        bodies = w.bodies_with_label(door_label(room))
        if state == CLOSED:  # leaf, two jambs, head, handle: as the clean world builds it
            assert len(bodies) == len(clean.bodies_with_label(door_label(room))) == 5


def test_the_clean_preset_closes_every_door(worlds):
    clean, _ = worlds
    assert set(clean.door_states.values()) == {CLOSED}
