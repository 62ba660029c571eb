"""Draft coverage: the measure itself, and the drafts of real maps against hand annotations."""

from __future__ import annotations

import functools
import tempfile
from pathlib import Path

import numpy as np
import pytest

from pmnav_bt.loading import InputFileError
from pmnav_bt.map.building import building_from_data
from pmnav_bt.map.draft import draft_building
from pmnav_bt.map.draft_coverage import line_fit, load_annotation, measure
from pmnav_bt.map.floorplan import FloorPlanImage, load_ros_map

ROOT = Path(__file__).resolve().parents[2]
DATA = Path(__file__).resolve().parent / "data"
# The targets: a draft covers 90 % of the annotated corridor length, and at most
# 10 % of what it drafts is spurious.
TARGET_COVERAGE, TARGET_SPURIOUS = 0.90, 0.10


def _building(points: dict, edges: list[tuple[str, str]]):
    wps = [{"id": k, "kind": "start" if i == 0 else "turn", "pos": list(p)}
           for i, (k, p) in enumerate(points.items())]
    deg = {k: sum(k in e for e in edges) for k in points}
    for w in wps[1:]:
        w["kind"] = {1: "end", 2: "turn"}.get(deg[w["id"]], "branch")
    data = {
        "schema_version": 1,
        "name": "t",
        "corridor_width": 2.0,
        "waypoints": wps,
        "edges": [{"from": a, "to": b} for a, b in edges],
        "rooms": [],
    }
    return building_from_data(data, "<test>")


def _annotation(tmp_path, text: str):
    f = tmp_path / "ann.yaml"
    f.write_text(text, encoding="utf-8")
    return load_annotation(f)


def test_coverage_and_spurious_are_fractions_of_length(tmp_path):
    ann = _annotation(
        tmp_path, "corridors:\n  - [[0, 0], [20, 0]]\n  - [[20, 0], [20, 10]]\n"
    )
    # The draft follows the first corridor 0.5 m off its line (within the 0.75 m
    # tolerance), misses the second but for its first 1.25 m (within 0.75 m of the draft's
    # corner at (20, 0.5)), and adds 11 m going south of which the first 1.25 m lie
    # within 0.75 m of the annotation.
    b = _building({"a": (0, 0.5), "b": (20, 0.5), "c": (20, -10.5)}, [("a", "b"), ("b", "c")])
    m = measure(b, ann)
    assert m.annotated_m == pytest.approx(30.0)
    assert m.coverage == pytest.approx(21.25 / 30.0, abs=0.01)
    assert m.spurious == pytest.approx(9.75 / 31.0, abs=0.01)


def test_what_lies_in_an_open_area_is_not_spurious(tmp_path):
    text = (
        "corridors:\n  - [[0, 0], [20, 0]]\n"
        "open_areas:\n  - [[18, -1], [30, -1], [30, 12], [18, 12]]\n"
    )
    ann = _annotation(tmp_path, text)
    b = _building({"a": (0, 0), "b": (20, 0), "c": (26, 10)}, [("a", "b"), ("b", "c")])
    m = measure(b, ann)
    assert m.coverage == pytest.approx(1.0)
    assert m.spurious == pytest.approx(0.0)


def test_a_malformed_annotation_is_one_clear_error(tmp_path):
    with pytest.raises(InputFileError, match="corridors"):
        _annotation(tmp_path, "corridors:\n  - [[0, 0], [1]]\n")


def test_line_fit_tells_a_line_along_a_wall_or_through_one():
    from shapely.geometry import LineString

    # A 2 m corridor from y = 1 to 3 (0.1 m cells) across a 20 m grid, walls round it.
    img = np.zeros((40, 200), np.uint8)
    img[40 - 30 : 40 - 10, 5:195] = 254
    plan = FloorPlanImage(img, 0.1, (0.0, 0.0, 0.0))
    middle = line_fit(plan, LineString([(1, 2), (19, 2)]))
    assert middle.outside == 0.0 and middle.off_centre_m <= 0.05
    along = line_fit(plan, LineString([(1, 1.2), (19, 1.2)]))  # 0.2 m from the south wall
    assert along.outside == 0.0 and along.off_centre_m == pytest.approx(0.8, abs=0.1)
    # Bent out through the north wall for its last 6 m (of about 16 m).
    through = line_fit(plan, LineString([(1, 2), (10, 2), (16, 5)]))
    assert 0.25 <= through.outside <= 0.45


REAL = {
    "hospital": (ROOT / "examples/hospital/hospital.yaml", DATA / "hospital_corridors.yaml"),
    "willow": (ROOT / "examples/maps/willow/willow.yaml", DATA / "willow_corridors.yaml"),
    # Measured only, never tuned on: annotated before any draft of them was run.
    "stata": (ROOT / "examples/maps/stata/stata.yaml", DATA / "stata_corridors.yaml"),
    "ipa_office": (
        ROOT / "examples/maps/ipa_office/ipa_office.yaml", DATA / "ipa_office_corridors.yaml"
    ),
}


@functools.cache
def _measured(name: str):
    grid, ann = REAL[name]
    with tempfile.TemporaryDirectory() as tmp:
        b, _, _ = draft_building(grid, Path(tmp) / "building.yaml")
    return measure(b, load_annotation(ann))


@pytest.mark.parametrize("name", sorted(REAL))
def test_the_hand_annotations_run_down_the_middle_of_free_space(name):
    # The annotation is half the measure. Willow's used to run through walls and unknown
    # space (12 to 20 % of four of its lines), along a wall (0.6 m off the middle of the
    # corridor to the west office) and through doors 0.65 to 0.75 m wide into rooms seen
    # only through laser rays, which the draft's centred lines were counted against. A
    # corridor is no narrower than the narrowest the draft looks for (1.0 m, a cell less
    # for the grid's rounding); the hospital's cross corridor under the lobby, open to
    # it behind a dotted glass front, is 0.48 m off by this measure.
    grid, ann = REAL[name]
    plan = load_ros_map(grid)
    for line in load_annotation(ann).corridors:
        fit = line_fit(plan, line)
        assert fit.outside <= 0.05, (name, list(line.coords), fit)
        assert fit.off_centre_m <= 0.55 and fit.narrowest_m >= 0.9, (name, list(line.coords), fit)


@pytest.mark.parametrize("name", sorted(REAL))
def test_draft_finds_most_of_a_real_building(name):
    # Before the draft cut its corridor space only at doorways, it found 79 % of the
    # hospital's annotated corridors and none of the Willow Garage office's.
    m = _measured(name)
    assert m.coverage >= 0.75, (name, m)
    assert m.spurious <= 0.5, (name, m)


@pytest.mark.parametrize(
    "name",
    [
        "hospital",
        pytest.param(
            "willow",
            marks=pytest.mark.xfail(
                strict=True,
                reason="not met yet: measured 96.3 % covered / 19.1 % spurious: corridor-shaped "
                "aisles between the cluttered offices' desk rows, ways into the rooms "
                "east of the lounge, a loop east of the east office (docs/real-maps.md)",
            ),
        ),
        "stata",
        pytest.param(
            "ipa_office",
            marks=pytest.mark.xfail(
                strict=True,
                reason="not met yet: measured 100 % covered / 31.7 % spurious: corridors up "
                "spaces seen only through laser rays north-west of the hall and at the "
                "corridor's south-west end, stubs into rooms (docs/real-maps.md)",
            ),
        ),
    ],
)
def test_draft_meets_the_coverage_target(name):
    m = _measured(name)
    assert m.coverage >= TARGET_COVERAGE and m.spurious <= TARGET_SPURIOUS, (name, m)
