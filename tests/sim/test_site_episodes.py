"""Episodes across levels (sim/site_episodes.py): seeded, start and goal on different
levels, their route the site plan's, their budget with the rides; bad sites refused."""

from __future__ import annotations

import pytest

from pmnav_bt.eval.task import action_budget
from pmnav_bt.sim.site_episodes import (
    RIDE_ACTIONS,
    SiteEpisodeError,
    custom_site_episode,
    generate_site_episodes,
    site_map,
    site_plan,
)


def test_episodes_are_seeded_and_cross_levels():
    a = generate_site_episodes("hospital_2l", 8, seed=3)
    assert a == generate_site_episodes("hospital_2l", 8, seed=3)
    assert a != generate_site_episodes("hospital_2l", 8, seed=4)
    assert all(e.start_level != e.goal_level and e.rides >= 1 for e in a)
    assert {e.start_level for e in a} == {"L1", "L2"}  # both ways, over eight
    sm = site_map("hospital_2l")
    for e in a[:3]:
        plan = site_plan(sm, e)
        assert plan.goal == e.goal and e.route_length == pytest.approx(plan.length)
        assert e.goal in {r.id for r in sm.maps[e.goal_level].building.rooms}
        assert e.step_budget == action_budget(e.route_length) + RIDE_ACTIONS * e.rides


def test_a_custom_episode_starts_where_asked_and_finds_the_goal_on_any_level():
    e = custom_site_episode("hospital_2l", "Laboratory")
    assert (e.start_level, e.goal_level, e.goal) == ("L1", "L2", "room208")
    e = custom_site_episode("hospital_2l", "Registration", start="L2/10,0,180")
    assert (e.start_level, e.goal_level, e.goal) == ("L2", "L1", "room101")
    assert (e.start_x, e.start_y) == (10.0, 0.0)


def test_a_one_level_building_has_no_episodes_across_levels():
    with pytest.raises(SiteEpisodeError, match="one level"):
        generate_site_episodes("straight_office", 1)
