"""Fixtures of the pose tests."""

from __future__ import annotations

import pytest

from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.priori_map import parse_building


@pytest.fixture(scope="module")
def fig2():
    return parse_building(load_building("fig2_hospital"))
