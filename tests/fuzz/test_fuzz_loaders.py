"""Generated bad inputs against every loader: only the project's own error, never another.

Each class feeds hypothesis-generated inputs (bytes, YAML-ish text, mutated valid data,
override strings, episode and tree-log records, map YAMLs, image headers) to a loader in
this process and asserts that it either loads or raises the loader's own PmNavError
whose message is one line naming the file. Counts go to fuzzkit.TRIED.
"""

from __future__ import annotations

import copy
import json
import math
import struct
import zlib

import pytest
from fuzzkit import TRIED
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from site_kit import two_level_site

from pmnav_bt.config import load_config
from pmnav_bt.errors import BuildingFileError, ConfigError, PmNavError
from pmnav_bt.map.building import building_from_data
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.floorplan import FloorPlanError, load_ros_map, read_image
from pmnav_bt.map.site import load_site, site_from_data
from pmnav_bt.sim.episodes import EPISODES_SCHEMA_VERSION, EpisodeFileError, load_episodes
from pmnav_bt.treelog import read_tree_log

pytestmark = pytest.mark.timeout(120)  # bounded time, whatever regresses

FUZZ = settings(
    max_examples=150,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)

GOOD = {
    "schema_version": 1,
    "name": "tiny",
    "corridor_width": 2.0,
    "waypoints": [
        {"id": "start", "kind": "start", "pos": [0, 0]},
        {"id": "turn1", "kind": "turn", "pos": [10, 0]},
        {"id": "end1", "kind": "end", "pos": [10, 10]},
    ],
    "edges": [["start", "turn1"], {"from": "turn1", "to": "end1", "width": 2.5}],
    "rooms": [{"id": "room1", "name": "Office", "aliases": ["Boss"], "door": [5, 1.0]}],
    "landmarks": [{"id": "lift", "kind": "elevator", "pos": [5, -1.0]}],
}

ODD_VALUES = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**40), max_value=10**40),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=30),
    st.sampled_from(["1", "true", "1e400", "nan", "-0", "", " ", "../../..", "a/b"]),
    st.lists(st.integers(), max_size=4),
    st.dictionaries(st.text(max_size=5), st.integers(), max_size=3),
)

YAMLISH = st.text(alphabet=st.sampled_from(list("[]{}:-,&*!?|>'\"# \n\tab01.eE+") + ["\\"]))


def _one_line_naming(err: PmNavError, name: str) -> None:
    msg = err.summary() if isinstance(err, BuildingFileError) else str(err)
    assert "\n" not in msg and name in msg, msg


# -- building files ----------------------------------------------------------------------


@FUZZ
@given(data=st.binary(max_size=400))
def test_building_from_random_bytes(tmp_path, data):
    TRIED["building file: random bytes"] += 1
    f = tmp_path / "b.yaml"
    f.write_bytes(data)
    try:
        load_building(f)
    except BuildingFileError as err:
        _one_line_naming(err, "b.yaml")


@FUZZ
@given(text=YAMLISH)
def test_building_from_yamlish_text(tmp_path, text):
    TRIED["building file: YAML-like text"] += 1
    f = tmp_path / "b.yaml"
    f.write_text(text, encoding="utf-8")
    try:
        load_building(f)
    except BuildingFileError as err:
        _one_line_naming(err, "b.yaml")


def _leaf_paths(d, prefix=()):
    if isinstance(d, dict):
        for k, v in d.items():
            yield from _leaf_paths(v, (*prefix, k))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            yield from _leaf_paths(v, (*prefix, i))
    yield prefix


LEAVES = [p for p in _leaf_paths(GOOD) if p]


@FUZZ
@given(where=st.sampled_from(LEAVES), value=ODD_VALUES)
def test_building_with_one_odd_value(where, value):
    TRIED["building data: one value replaced"] += 1
    data = copy.deepcopy(GOOD)
    d = data
    for k in where[:-1]:
        d = d[k]
    d[where[-1]] = value
    try:
        b = building_from_data(data, "t.yaml")
    except BuildingFileError as err:
        _one_line_naming(err, "t.yaml")
        return
    # What loads is sane: finite, in the stated limits, numbers not made from text.
    for w in b.waypoints:
        assert all(math.isfinite(v) and abs(v) <= 1000 for v in w.pos)
    assert 0 < b.corridor_width <= 50 and 0 < b.wall_height <= 20


# -- site files (levels and lifts) ---------------------------------------------------------

SITE = two_level_site()
SITE_LEAVES = [p for p in _leaf_paths(SITE) if p]


@FUZZ
@given(where=st.sampled_from(SITE_LEAVES), value=ODD_VALUES)
def test_site_with_one_odd_value(where, value):
    TRIED["site data: one value replaced"] += 1
    data = copy.deepcopy(SITE)
    d = data
    for k in where[:-1]:
        d = d[k]
    d[where[-1]] = value
    try:
        site = site_from_data(data, "s.yaml")
    except BuildingFileError as err:
        _one_line_naming(err, "s.yaml")
        return
    # What loads holds together: every lobby is a lift landmark of its level.
    for lift in site.lifts:
        assert len(lift.lobbies) >= 2
        for level, lobby in lift.lobbies.items():
            assert site.level(level).building.landmark(lobby).kind == "elevator"


@FUZZ
@given(text=YAMLISH)
def test_site_from_yamlish_text(tmp_path, text):
    TRIED["site file: YAML-like text"] += 1
    f = tmp_path / "s.yaml"
    f.write_text("site_version: 1\n" + text, encoding="utf-8")
    try:
        load_site(f)
    except BuildingFileError as err:
        _one_line_naming(err, "s.yaml")


# -- config ------------------------------------------------------------------------------

CONFIG_KEYS = [
    "tree.tick_hz",
    "tree.budget_actions",
    "tree.variant",
    "sim.width",
    "sim.height",
    "sim.odometry_noise",
    "grounder.miss_rate",
    "grounder.hidden",
    "planner.max_gap",
    "tree",
    "nosuch.key",
    "tree.tick_hz.deeper",
]


@FUZZ
@given(key=st.sampled_from(CONFIG_KEYS), raw=st.one_of(YAMLISH, ODD_VALUES.map(str)))
def test_config_override(key, raw):
    TRIED["config: --set key=value"] += 1
    try:
        cfg = load_config(None, [f"{key}={raw}"])
    except ConfigError as err:
        assert "\n" not in str(err)
        return
    assert 0.5 <= cfg.tree.tick_hz <= 1000 and cfg.sim.width <= 1920


@FUZZ
@given(data=st.binary(max_size=300))
def test_config_file_random_bytes(tmp_path, data):
    TRIED["config file: random bytes"] += 1
    f = tmp_path / "c.yaml"
    f.write_bytes(data)
    try:
        load_config(f)
    except ConfigError as err:
        _one_line_naming(err, "c.yaml")


# -- episodes ----------------------------------------------------------------------------

EPISODE = {
    "id": "e0",
    "building": "fig2_hospital",
    "tier": "easy",
    "start_x": 0.0,
    "start_y": 30.0,
    "start_yaw": -1.57,
    "goal": "room17",
    "route_length": 12.0,
    "seed": 0,
    "goal_visible": True,
    "turns": 0,
    "forks": 0,
}


@FUZZ
@given(key=st.sampled_from([*EPISODE, "extra"]), value=ODD_VALUES)
def test_episode_with_one_odd_value(tmp_path, key, value):
    TRIED["episode file: one value replaced"] += 1
    ep = dict(EPISODE, **{key: value})
    f = tmp_path / "e.json"
    try:
        text = json.dumps({"schema_version": EPISODES_SCHEMA_VERSION, "episodes": [ep]})
    except ValueError:
        return
    f.write_text(text)
    try:
        eps = load_episodes(f)
    except EpisodeFileError as err:
        _one_line_naming(err, "e.json")
        return
    e = eps[0]
    assert math.isfinite(e.start_x) and e.seed >= 0


@FUZZ
@given(
    text=st.text(alphabet=st.sampled_from(list('[]{}":,0123456789.eE-+ \ntrufalsn')), max_size=200)
)
def test_episode_file_jsonish(tmp_path, text):
    TRIED["episode file: JSON-like text"] += 1
    f = tmp_path / "e.json"
    f.write_text(text)
    try:
        load_episodes(f)
    except EpisodeFileError as err:
        _one_line_naming(err, "e.json")


# -- tree logs ---------------------------------------------------------------------------

TREE = {
    "type": "tree",
    "nodes": [
        {"id": "1", "name": "root", "class": "Sequence", "parent": None},
        {"id": "2", "name": "child", "class": "Action", "parent": "1"},
    ],
}
TICK = {
    "type": "tick",
    "tick": 1,
    "time": 0.1,
    "status": {"1": "RUNNING"},
    "feedback": {},
    "blackboard": {},
}


@FUZZ
@given(
    which=st.sampled_from(["tree", "node", "tick"]),
    key=st.sampled_from(
        [
            "id",
            "name",
            "class",
            "parent",
            "nodes",
            "tick",
            "time",
            "status",
            "feedback",
            "blackboard",
            "type",
        ]
    ),
    value=ODD_VALUES,
    cut=st.integers(min_value=0, max_value=40),
)
def test_tree_log_records(tmp_path, which, key, value, cut):
    TRIED["tree log: one value replaced, last line cut"] += 1
    tree, tick = copy.deepcopy(TREE), dict(TICK)
    target = {"tree": tree, "node": tree["nodes"][1], "tick": tick}[which]
    target[key] = value
    try:
        lines = [json.dumps(tree), json.dumps(TICK), json.dumps(tick)]
    except ValueError:
        return
    text = "\n".join(lines) + "\n"
    text = text[: len(text) - cut] if cut else text
    f = tmp_path / "t.jsonl"
    f.write_text(text)
    try:
        log = read_tree_log(f)
    except PmNavError as err:
        _one_line_naming(err, "t.jsonl")
        return
    from pmnav_bt.trees.snapshots import Replay

    rp = Replay(log.nodes, log.ticks)
    for t in rp.ticks:
        rp.render(t)  # whatever loads also renders


# -- ROS map YAML and images -------------------------------------------------------------


@FUZZ
@given(
    key=st.sampled_from(["image", "resolution", "origin", "negate", "occupied_thresh", "mode"]),
    value=ODD_VALUES,
)
def test_ros_map_yaml(tmp_path, key, value):
    TRIED["ros_map YAML: one value replaced"] += 1
    import yaml

    data = {"image": "m.pgm", "resolution": 0.05, "origin": [0, 0, 0], key: value}
    (tmp_path / "m.pgm").write_bytes(b"P5\n4 4\n255\n" + bytes(16))
    f = tmp_path / "m.yaml"
    try:
        f.write_text(yaml.safe_dump(data))
    except yaml.YAMLError:
        return
    try:
        load_ros_map(f)
    except FloorPlanError as err:
        _one_line_naming(err, "m.")


def _png(width: int, height: int, body: bytes = b"") -> bytes:
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    chunk = b"IHDR" + ihdr
    return (
        b"\x89PNG\r\n\x1a\n"
        + struct.pack(">I", len(ihdr))
        + chunk
        + struct.pack(">I", zlib.crc32(chunk))
        + body
    )


@FUZZ
@given(
    w=st.integers(min_value=0, max_value=2**32 - 1),
    h=st.integers(min_value=0, max_value=2**32 - 1),
    kind=st.sampled_from(["png", "pgm"]),
)
def test_image_headers(tmp_path, w, h, kind):
    TRIED["image: header sizes"] += 1
    f = tmp_path / f"i.{kind}"
    f.write_bytes(_png(w, h) if kind == "png" else f"P5\n{w} {h}\n255\n".encode())
    with pytest.raises(FloorPlanError) as err:  # truncated bodies never decode
        read_image(f)
    _one_line_naming(err.value, f"i.{kind}")


# -- issue 42: grids smaller than (or beside) their building -------------------------------


@FUZZ
@given(
    w=st.integers(min_value=1, max_value=120),
    h=st.integers(min_value=1, max_value=120),
    origin=st.tuples(st.floats(-80, 80), st.floats(-80, 80)),
    resolution=st.sampled_from([0.05, 0.1, 0.25, 1.0]),
    seed=st.integers(0, 3),
)
def test_grid_smaller_than_its_building(tmp_path, w, h, origin, resolution, seed):
    """``pmnav validate``'s grid checks on a grid that covers the building only in part,
    or not at all: warnings, one line each, never an IndexError."""
    import numpy as np
    import yaml

    from pmnav_bt.map.checks import building_warnings

    TRIED["ros_map: grid smaller than its building"] += 1
    cells = np.random.default_rng(seed).choice(np.array([0, 205, 254], np.uint8), size=w * h)
    (tmp_path / "m.pgm").write_bytes(f"P5\n{w} {h}\n255\n".encode() + cells.tobytes())
    (tmp_path / "m.yaml").write_text(
        yaml.safe_dump({"image": "m.pgm", "resolution": resolution, "origin": [*origin, 0]})
    )
    warnings = building_warnings(_OFFICE, plan=load_ros_map(tmp_path / "m.yaml"))
    assert all("\n" not in str(p) for p in warnings)
    (x0, y0), x1, y1 = origin, origin[0] + w * resolution, origin[1] + h * resolution
    if x0 > 54.1 or x1 < -0.1 or y0 > 0.1 or y1 < -0.1:  # the corridor (0,0)-(54,0) misses it
        assert any("runs off the floor-plan grid" in str(p) for p in warnings), warnings


_OFFICE = load_building("straight_office")
