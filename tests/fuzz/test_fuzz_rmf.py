"""Bad Open-RMF building files against ``pmnav map import-rmf``: one line, exit 2.

The examples are the bad files a user meets (not YAML, no levels, no measurements, a
level that is not there, a wall naming a vertex that does not exist, huge numbers); the
generated classes feed random bytes and the small example building with one value
replaced to the importer, which either imports a building that validates or raises the
project's own error in one line naming the file. Counts go to fuzzkit.TRIED.
"""

from __future__ import annotations

import copy

import pytest
from fuzzkit import TRIED, one_line, pmnav_cli
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from pmnav_bt.errors import PmNavError
from pmnav_bt.map.rmf_import import import_rmf
from pmnav_bt.testing.rmf_example import example_rmf, write_example_rmf

pytestmark = pytest.mark.timeout(300)  # bounded time, whatever regresses

FUZZ = settings(
    max_examples=60,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)


def _with(change) -> dict:
    data = example_rmf()
    change(data, data["levels"]["L1"])
    return data


def _set(d: dict, key: str, value) -> None:
    d[key] = value


BAD_FILES = {
    "no-levels": (_with(lambda d, lv: _set(d, "levels", {})), ["no levels"]),
    "no-measurements": (
        _with(lambda d, lv: _set(lv, "measurements", [])), ["L1.measurements", "none"]
    ),
    "missing-vertex": (
        _with(lambda d, lv: lv["walls"].append([0, 999, {}])),
        ["levels.L1.walls[10]", "vertex 999 does not exist"],
    ),
    "huge-distance": (
        _with(lambda d, lv: _set(lv["measurements"][0][2], "distance", [3, 1e30])),
        ["out of range"],
    ),
    "huge-vertex": (
        _with(lambda d, lv: _set(lv["vertices"][3], 0, 1e8)), ["lies", "within 1000 m"]
    ),
    "nan-vertex": (
        _with(lambda d, lv: _set(lv["vertices"][3], 1, float("nan"))), ["finite number"]
    ),
    "no-lanes": (_with(lambda d, lv: _set(lv, "lanes", [])), ["no lane runs inside"]),
    "cartesian": (
        _with(lambda d, lv: _set(d, "coordinate_system", "cartesian_meters")),
        ["coordinate_system", "only 'reference_image'"],
    ),
}


@pytest.mark.parametrize("name", list(BAD_FILES))
def test_bad_rmf_files_get_one_line(capsys, tmp_path, name):
    TRIED["RMF building: bad files"] += 1
    data, words = BAD_FILES[name]
    rmf = write_example_rmf(tmp_path, data)
    code, _, err = pmnav_cli(capsys, "map", "import-rmf", rmf, "-o", tmp_path / "o.yaml")
    assert code == 2
    one_line(err, "example.building.yaml", *words)


def test_not_yaml_and_an_unknown_level(capsys, tmp_path):
    TRIED["RMF building: bad files"] += 2
    bad = tmp_path / "bad.building.yaml"
    bad.write_text("levels: [unclosed\n", encoding="utf-8")
    code, _, err = pmnav_cli(capsys, "map", "import-rmf", bad, "-o", tmp_path / "o.yaml")
    assert code == 2
    one_line(err, "bad.building.yaml", "not valid YAML")
    rmf = write_example_rmf(tmp_path)
    code, _, err = pmnav_cli(
        capsys, "map", "import-rmf", rmf, "--level", "L3", "-o", tmp_path / "o.yaml"
    )
    assert code == 2
    one_line(err, "no level 'L3'; the file has L1")


def _one_line_naming(err: PmNavError, name: str) -> None:
    assert "\n" not in str(err) and name in str(err), str(err)


@FUZZ
@given(data=st.binary(max_size=400))
def test_rmf_from_random_bytes(tmp_path, data):
    TRIED["RMF building: random bytes"] += 1
    f = tmp_path / "r.building.yaml"
    f.write_bytes(data)
    try:
        import_rmf(f, tmp_path / "o.yaml")
    except PmNavError as err:
        _one_line_naming(err, "r.building.yaml")


def _leaves(d, prefix=()):
    if isinstance(d, dict):
        for k, v in d.items():
            yield from _leaves(v, (*prefix, k))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            yield from _leaves(v, (*prefix, i))
    yield prefix


LEAVES = [p for p in _leaves(example_rmf()) if p]
ODD = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**12), max_value=10**12),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
    st.sampled_from([[], {}, [0, 0], [3, 0.0], [3, -1.0], [1, ""], "L1"]),
)


@FUZZ
@given(where=st.sampled_from(LEAVES), value=ODD)
def test_rmf_with_one_odd_value(tmp_path, where, value):
    TRIED["RMF building: one value replaced"] += 1
    data = copy.deepcopy(example_rmf())
    d = data
    for k in where[:-1]:
        d = d[k]
    d[where[-1]] = value
    try:
        rmf = write_example_rmf(tmp_path, data)
    except ValueError:  # YAML cannot write it (a float NaN key, ...): not an input
        return
    try:
        imp = import_rmf(rmf, tmp_path / "o.yaml")
    except PmNavError as err:
        _one_line_naming(err, "example.building.yaml")
        return
    assert imp.building.edges  # what imports is a building that validated


PAIRS = st.lists(st.tuples(st.integers(0, 16), st.integers(0, 16)), max_size=14)


@FUZZ
@given(walls=PAIRS, lanes=PAIRS, doors=PAIRS)
def test_rmf_with_random_walls_lanes_and_doors(tmp_path, walls, lanes, doors):
    TRIED["RMF building: random walls, lanes, doors"] += 1
    data = example_rmf()
    lvl = data["levels"]["L1"]
    lvl["walls"] = [[a, b, {}] for a, b in walls]
    lvl["lanes"] = [[a, b, {}] for a, b in lanes]
    lvl["doors"] = [[a, b, {"name": [1, f"d{i}"]}] for i, (a, b) in enumerate(doors)]
    rmf = write_example_rmf(tmp_path, data)
    try:
        imp = import_rmf(rmf, tmp_path / "o.yaml")
    except PmNavError as err:
        _one_line_naming(err, "example.building.yaml")
        return
    assert imp.building.edges
