"""The Table 3 study's parts that need no simulator: classed start poses and the table."""

from __future__ import annotations

import json
import math
from dataclasses import asdict

from pmnav_bt.config import load_config
from pmnav_bt.experiments.localization_study import (
    PAPER,
    LocResult,
    LocStart,
    classified_starts,
    table,
)
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.perception.read_range import entity_plate_kind, landmark_ranges
from pmnav_bt.pose.visibility import (
    READ_RANGE_M,
    LandmarkDensity,
    Visibility,
    density_class,
    entity_xy,
)


def test_starts_are_classed_by_the_signs_readable_there(tmp_path, monkeypatch):
    monkeypatch.setenv("PMNAV_CACHE", str(tmp_path))
    starts = classified_starts("sign_sparse_0", n=3, seed=1)
    assert {s.density for s in starts} == {c.value for c in LandmarkDensity}
    vis = Visibility.of(parse_building(load_building("sign_sparse_0")))
    for s in starts:
        assert vis.density((s.x, s.y)).value == s.density
        assert vis.n_readable((s.x, s.y)) == s.readable
    assert starts == classified_starts("sign_sparse_0", n=3, seed=1)  # seeded


def test_with_the_readers_ranges_a_sign_beyond_its_plate_kinds_range_is_no_landmark(
    tmp_path, monkeypatch
):
    monkeypatch.setenv("PMNAV_CACHE", str(tmp_path))
    b = load_building("sign_sparse_0")
    pm = parse_building(b)
    ranges = {"number": 3.5, "name": 2.5, "long name": 2.5}
    starts = classified_starts("sign_sparse_0", n=4, seed=2, ranges=ranges)
    assert {s.density for s in starts} == {c.value for c in LandmarkDensity}
    vis = Visibility.of(pm)
    fewer = 0
    for s in starts:
        near = [
            e
            for e in vis.readable_from((s.x, s.y))
            if math.dist(entity_xy(pm, e), (s.x, s.y)) <= ranges[entity_plate_kind(b, e)]
        ]
        assert len(near) == s.readable
        assert density_class(len(near)).value == s.density
        fewer += len(near) < vis.n_readable((s.x, s.y))
    assert fewer  # the map's 9.5 m would have counted more signs at some starts
    json.dumps([asdict(s) for s in starts])  # stored with the results
    assert classified_starts("sign_sparse_0", n=4, seed=2, ranges=ranges) == starts


def test_the_oracle_counts_landmarks_to_the_maps_range_and_ocr_to_its_own():
    assert landmark_ranges(load_config(None, ["grounder.backend=sim_gt"])) is None
    ocr = landmark_ranges(load_config(None, ["grounder.backend=ocr"]))
    assert set(ocr) == {"number", "name", "long name"}
    assert ocr["name"] < ocr["number"] < READ_RANGE_M


def test_the_table_gives_sr_and_sdf_per_class_beside_the_paper():
    def run(density: str, ok: bool, attempts: int) -> LocResult:
        start = LocStart("b", 0.0, 0.0, 0.0, density, 0, 0)
        return LocResult(start, ok, attempts, 0.1, 1.0, 0.0, None, 0.0)

    rows = [run("scarce", True, 4), run("scarce", False, 10), run("redundant", True, 1)]
    text = table(rows)
    assert "| redundant | 1 | 100.0 | 100.0 |" in text
    assert "| scarce | 2 | 50.0 | 25.0 |" in text  # SDF: (2/4 + 0) / 2
    assert "| minimal | 0 |" in text
    assert str(PAPER[LandmarkDensity.SCARCE][0]) in text
