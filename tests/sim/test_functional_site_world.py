"""A generated site's levels build as pybullet worlds with their lift's cabin: the doorway
the simulator cuts is the one the map says the robot drives through (``lift_doorway``),
on the wall the lift's point is on, and nothing on the walls is squeezed out."""

from __future__ import annotations

import logging
import math

import pytest

from pmnav_bt.config import WorldConfig
from pmnav_bt.map.lift_doorway import doorway
from pmnav_bt.map.site import load_site
from pmnav_bt.map.site_map import parse_site
from pmnav_bt.sim.world import SimWorld


@pytest.mark.parametrize("name", ["hospital_site_0", "school_site_1"])
def test_each_level_builds_with_its_cabin_behind_the_mapped_doorway(
    name, tmp_path, monkeypatch, caplog
):
    monkeypatch.setenv("PMNAV_CACHE", str(tmp_path))
    caplog.set_level(logging.INFO, logger="pmnav_bt.sim.world")
    site = load_site(name)
    sm = parse_site(site)
    realistic = WorldConfig(preset="realistic")
    for lv in (site.levels[0], site.levels[-1]):
        with SimWorld(lv.building, scene=realistic, lifts={"lift1"}) as world:
            mapped = doorway(sm.maps[lv.name], "lift1")
            cabin = world.cabins["lift1"]
            assert math.dist(cabin.centre, mapped.centre) < 0.05, lv.name
            assert math.dist(cabin.into, mapped.into) < 1e-6, lv.name
    squeezed = [m for m in caplog.messages if "overlap" in m or "no room" in m or "short" in m]
    assert squeezed == []
