"""The lifts of an imported Open-RMF building stand in the simulator where the drawing
has their doors: each level's world builds a cabin behind every lift lobby."""

from __future__ import annotations

from pmnav_bt.map.rmf_site import import_rmf_site
from pmnav_bt.map.site import read_site_file
from pmnav_bt.sim.world import SimWorld


def test_the_rmf_clinic_builds_a_cabin_behind_every_lift_door(rmf_maps, tmp_path):
    out = tmp_path / "clinic.yaml"
    import_rmf_site(rmf_maps / "clinic" / "clinic.building.yaml", out)
    site = read_site_file(out)
    for level in site.level_names:
        lobbies = {lift.lobbies[level] for lift in site.lifts if level in lift.lobbies}
        assert len(lobbies) >= 2, level
        b = site.level(level).building
        with SimWorld(b, lifts=lobbies) as world:
            assert set(world.cabins) == lobbies, level
