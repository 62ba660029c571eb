"""A generated hospital, school or office floor builds as a pybullet world: every door,
sign plate and landmark of the file stands where the file says, none squeezed out."""

from __future__ import annotations

import logging
import math

import pytest

from pmnav_bt.sim.world import SimWorld


@pytest.mark.parametrize("name", ["hospital_1", "office_3"])
def test_a_generated_floor_builds_with_every_door_sign_and_landmark(
    name, tmp_path, monkeypatch, caplog
):
    monkeypatch.setenv("PMNAV_CACHE", str(tmp_path))
    caplog.set_level(logging.INFO, logger="pmnav_bt.sim.world")
    with SimWorld(name) as world:
        b = world.building
        assert set(world.doors) == set(world.signs) == {r.id for r in b.rooms}
        assert set(world.landmarks) == {lm.id for lm in b.landmarks}
        for r in b.rooms:  # on the wall the file puts it on
            assert math.dist(world.doors[r.id].centre, r.door) < 0.05, r.id
        # the lift faces the entrance, straight ahead at the far end of the lobby
        lift, start = world.landmarks["lift1"], b.waypoint("start").pos
        to_start = (start[0] - lift.centre[0], start[1] - lift.centre[1])
        facing = (lift.normal[0] * to_start[0] + lift.normal[1] * to_start[1]) / math.hypot(
            *to_start
        )
        assert facing > 0.999
    squeezed = [m for m in caplog.messages if "overlap" in m or "no room" in m or "short" in m]
    assert squeezed == []
