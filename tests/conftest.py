"""Shared fixtures: built-in buildings and their priori-maps, and the tick rig's
(``make_rig``: a Context on the test doubles, or on pybullet for tests marked ``world``)."""

from __future__ import annotations

import pytest
from blackboard_kit import cleared
from rig import BODIES, Rig, build_rig

from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.seams import Pose2D


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


@pytest.fixture(scope="session")
def rmf_maps():
    """The folder of the Open-RMF demo buildings (rmf/clinic, rmf/office), or skip."""
    d = _shared_maps()
    if d is None or not (d / "rmf" / "clinic" / "clinic.building.yaml").is_file():
        pytest.skip("the Open-RMF demo buildings are absent: set PMNAV_SHARED_MAPS to a maps/ "
                    "folder holding rmf/clinic and rmf/office")
    return d / "rmf"


# -- the tick rig (tests/rig.py) ---------------------------------------------------------------


def pytest_configure(config):
    config.addinivalue_line(
        "markers",
        "world: the test needs a pybullet world (geometry: depth, walls, distances); "
        "its make_rig builds SimBase bodies instead of the test doubles",
    )


@pytest.fixture
def clean_blackboard():
    yield from cleared()


@pytest.fixture(scope="module")
def building(fig2):
    """The building of a module's rigs (override it in a module for another one)."""
    return fig2


@pytest.fixture(scope="module")
def pm(building):
    return parse_building(building)


@pytest.fixture(scope="module")
def world(building):
    """The module's pybullet world (built only for tests whose rigs need it)."""
    from pmnav_bt.sim.world import SimWorld

    w = SimWorld(building)
    yield w
    w.close()


@pytest.fixture
def body(request) -> str:
    """The body a test's rigs are built on: its parameter when a test is parametrized
    over it (``indirect=True``), else ``"pybullet"`` for a test marked ``world``, else
    ``"doubles"``."""
    kind = getattr(request, "param", None)
    if kind is None:
        kind = "pybullet" if request.node.get_closest_marker("world") else "doubles"
    assert kind in BODIES, f"no body {kind!r}; choose from {BODIES}"
    return kind


@pytest.fixture
def make_rig(request, body, pm, clean_blackboard):
    """``make_rig(pose, **options)`` -> Rig on the ``body`` fixture's body, in the module's
    building; options: ``width``, ``height``, ``seed``, ``budget``, ``overrides`` (config)
    for both bodies; ``grounder``, ``coarse``, ``refiner``, ``planner`` (doubles) on the
    doubles; ``noise``, ``segmentation``, ``reading_width`` on pybullet. Everything is torn
    down afterwards."""
    made: list[Rig] = []

    def make(pose: Pose2D, **options) -> Rig:
        world = request.getfixturevalue("world") if body == "pybullet" else None
        rig = build_rig(body, pm, pose, world=world, **options)
        made.append(rig)
        return rig

    yield make
    for rig in made:
        rig.close()


@pytest.fixture
def thumbnails_off_the_tick(monkeypatch):
    """A trace thumbnail made on the ticking (main) thread fails the test
    (docs/architecture.md: a tick never blocks; ``context.TraceEvent``); yields the names of
    the threads that made them."""
    import threading

    from pmnav_bt.behaviours import context

    made, shrink = [], context.thumbnail

    def off_the_tick(rgb, *args, **kw):
        if threading.current_thread() is threading.main_thread():
            raise AssertionError("a trace thumbnail made in the tick")
        made.append(threading.current_thread().name)
        return shrink(rgb, *args, **kw)

    monkeypatch.setattr(context, "thumbnail", off_the_tick)
    return made
