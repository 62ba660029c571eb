"""Shared fixtures: built-in buildings and their priori-maps."""

from __future__ import annotations

import pytest

from pmnav_bt.map.building import load_building
from pmnav_bt.map.priori_map import parse_building


@pytest.fixture(scope="session")
def fig2():
    return load_building("fig2_hospital")


@pytest.fixture(scope="session")
def fig2_map(fig2):
    return parse_building(fig2)


@pytest.fixture(scope="session")
def loop_map():
    return parse_building(load_building("loop_school"))
