"""The lifts of an imported Open-RMF building stand in the simulator where the drawing
has their doors: each level's world builds a cabin behind every lift lobby, with its walls
from the file's corridors or from the grid."""

from __future__ import annotations

from pmnav_bt.behaviours.lift import look_into_cabin
from pmnav_bt.map.lift_doorway import doorway
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.map.rmf_site import import_rmf_site
from pmnav_bt.map.site import read_site_file
from pmnav_bt.seams import Pose2D
from pmnav_bt.sim.robot import SimBase
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


def test_on_the_clinic_s_grid_walls_the_lobby_looks_into_an_open_cabin(rmf_maps, tmp_path):
    """With the world's walls from the grid (``sim.walls=grid``), which walls each lift's
    shaft round, the doorway and the cabin are cut out of the grid's walls: from the
    map's lobby, facing the doors, depth sees shut doors, then the open cabin's floor."""
    out = tmp_path / "clinic.yaml"
    import_rmf_site(rmf_maps / "clinic" / "clinic.building.yaml", out)
    site = read_site_file(out)
    level = site.level("L1")
    pm = parse_building(level.building)
    lobbies = {lift.lobbies["L1"] for lift in site.lifts if "L1" in lift.lobbies}
    with SimWorld(level.building, walls="grid", base_dir=out.parent, lifts=lobbies) as world:
        assert set(world.cabins) == lobbies
        for lid in sorted(lobbies):
            d = doorway(pm, lid)
            at = Pose2D(*d.lobby, d.yaw_in)
            base = SimBase(world, pose=at, width=160, height=120)
            assert not look_into_cabin(base.observe(), at, d).beyond, lid
            world.cabins[lid].set_door(True)
            look = look_into_cabin(base.observe(), at, d)
            world.cabins[lid].set_door(False)
            assert look.way is not None, lid
