"""Shared fixtures: built-in buildings and their priori-maps."""

from __future__ import annotations

import pytest

from pmnav_bt.map.catalogue import load_building
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


def _shared_maps():
    """The shared real-map folder: $PMNAV_SHARED_MAPS, or a shared/maps beside an ancestor."""
    import os
    from pathlib import Path

    env = os.environ.get("PMNAV_SHARED_MAPS")
    if env:
        return Path(env)
    for parent in Path(__file__).resolve().parents:
        cand = parent / "shared" / "maps"
        if cand.is_dir():
            return cand
    return None


@pytest.fixture(scope="session")
def hospital_grid():
    """The real SLAM map of a hospital floor (map_server YAML), or skip when it is absent."""
    d = _shared_maps()
    path = d / "hospital" / "hospital.yaml" if d else None
    if path is None or not path.is_file():
        pytest.skip("the real hospital map is absent: set PMNAV_SHARED_MAPS to a maps/ folder")
    return path
