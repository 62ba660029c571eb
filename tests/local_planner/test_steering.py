"""The steering is chosen by name (``tree.local_planner``), one per episode's context."""

from __future__ import annotations

import pytest

from pmnav_bt.config import load_config
from pmnav_bt.errors import ConfigError
from pmnav_bt.local_planner.steering import DirectSteering, LocalPlannerSteering, make_steering


def test_a_steering_by_name_and_a_fresh_costmap_for_each():
    assert isinstance(make_steering("direct"), DirectSteering)
    a, b = make_steering("dwa"), make_steering("dwa")
    assert isinstance(a, LocalPlannerSteering) and a.costmap is not b.costmap


def test_an_unknown_local_planner_is_one_error_naming_the_known_ones():
    with pytest.raises(ConfigError, match="did you mean 'dwa'.*direct, dwa"):
        load_config(overrides=["tree.local_planner=dwb"])
