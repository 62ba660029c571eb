"""The Table 3 study's parts that need no simulator: classed start poses and the table."""

from __future__ import annotations

from pmnav_bt.experiments.localization_study import (
    PAPER,
    LocResult,
    LocStart,
    classified_starts,
    table,
)
from pmnav_bt.map.building import load_building
from pmnav_bt.map.priori_map import parse_building
from pmnav_bt.pose.visibility import LandmarkDensity, Visibility


def test_starts_are_classed_by_the_signs_readable_there(tmp_path, monkeypatch):
    monkeypatch.setenv("PMNAV_CACHE", str(tmp_path))
    starts = classified_starts("sign_sparse_0", n=3, seed=1)
    assert {s.density for s in starts} == {c.value for c in LandmarkDensity}
    vis = Visibility.of(parse_building(load_building("sign_sparse_0")))
    for s in starts:
        assert vis.density((s.x, s.y)).value == s.density
        assert vis.n_readable((s.x, s.y)) == s.readable
    assert starts == classified_starts("sign_sparse_0", n=3, seed=1)  # seeded


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
