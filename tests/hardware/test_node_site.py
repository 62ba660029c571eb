"""``pmnav-ros`` in a site of several levels (hardware/node_site.py), without ROS: which
buildings are sites, the start level, the goal on any level, and the mission's tree: it
starts on the start level and rides the lift by the node's session."""

from __future__ import annotations

import pytest

from pmnav_bt.config import load_config
from pmnav_bt.errors import PmNavError
from pmnav_bt.hardware.node_site import NodeSite, UnknownGoalError, site_of_levels
from pmnav_bt.map.site import load_site

CONFIG = load_config(None, ["grounder.backend=sim_gt"])


@pytest.fixture(scope="module")
def site():
    return NodeSite(load_site("hospital_2l"), "", CONFIG, on_robot=False, seed=0)


def test_a_site_of_several_levels_is_a_site_and_one_floor_is_not():
    assert site_of_levels("hospital_2l").name == load_site("hospital_2l").name
    assert site_of_levels("fig2_hospital") is None
    assert site_of_levels("no_such_building") is None  # the node's building error says so


def test_the_start_level_is_the_first_unless_given(site):
    assert site.start_level == "L1" and site.start.pm is site.sm.maps["L1"]
    assert site.start_file == str(load_site("hospital_2l").level("L1").path)
    on_l2 = NodeSite(load_site("hospital_2l"), "l2", CONFIG, on_robot=False, seed=0)
    assert on_l2.start_level == "L2"
    with pytest.raises(PmNavError, match="parameter 'start_level': no level 'L9'"):
        NodeSite(load_site("hospital_2l"), "L9", CONFIG, on_robot=False, seed=0)


def test_a_goal_names_a_room_on_any_level(site):
    level, room = site.room("Laboratory")
    assert (level, room.id) == ("L2", "room208")
    with pytest.raises(UnknownGoalError, match="no room called 'Nowhere'"):
        site.room("Nowhere")
