"""Metrics on hand-computed cases: success, SPL, SDF, per-tier aggregation."""

from __future__ import annotations

import json

import pytest

from pmnav_bt.eval.metrics import (
    SUCCESS_RADIUS_M,
    EpisodeResult,
    aggregate_by_tier,
    results_to_json,
    sdf,
    sdf_term,
    spl,
    success,
)


def test_success_radius():
    assert SUCCESS_RADIUS_M == 1.0
    assert success((0.6, 0.8), (0.0, 0.0))  # exactly 1.0 m
    assert not success((0.61, 0.8), (0.0, 0.0))
    assert success((3.0, 4.0), (0.0, 0.0), radius=5.0)


def test_spl_hand_cases():
    assert spl(True, 10.0, 10.0) == 1.0
    assert spl(True, 10.0, 12.5) == pytest.approx(0.8)
    assert spl(True, 10.0, 8.0) == 1.0  # a shorter path is clipped: l / max(l, p)
    assert spl(False, 10.0, 10.0) == 0.0
    assert spl(True, 0.0, 0.0) == 1.0
    with pytest.raises(ValueError):
        spl(True, -1.0, 2.0)


def test_sdf_is_two_over_max_two_d():
    # 2 / max(2, d): two attempts (the minimum to localise) score 1, more score less.
    assert sdf_term(True, 2) == 1.0
    assert sdf_term(True, 1) == 1.0
    assert sdf_term(True, 4) == 0.5
    assert sdf_term(True, 5) == pytest.approx(0.4)
    assert sdf_term(False, 2) == 0.0
    # mean over trials: (1 + 0.5 + 0 + 0.4) / 4
    assert sdf([True, True, False, True], [2, 4, 3, 5]) == pytest.approx(0.475)
    assert sdf([], []) == 0.0
    with pytest.raises(ValueError):
        sdf([True], [2, 3])


def _r(tier, ok, spl_, steps=10, path=5.0, coll=0):
    return EpisodeResult(
        f"e-{tier}", tier, ok, spl_, path, steps, coll, 1.0, None if ok else "stopped too far"
    )


def test_aggregate_by_tier_hand_case():
    results = [
        _r("hard", False, 0.0, steps=500, coll=2),
        _r("easy", True, 1.0),
        _r("easy", True, 0.8),
        _r("easy", False, 0.0),
        _r("medium", True, 0.9, steps=30),
    ]
    table = aggregate_by_tier(results)
    assert [r.tier for r in table.rows] == ["easy", "medium", "hard", "all"]
    easy = table.row("easy")
    assert easy.episodes == 3
    assert easy.sr == pytest.approx(200 / 3)
    assert easy.spl == pytest.approx(60.0)
    assert table.row("medium").sr == 100.0 and table.row("medium").spl == pytest.approx(90.0)
    assert table.row("hard").sr == 0.0 and table.row("hard").collisions == 2
    assert table.row("all").sr == pytest.approx(60.0)
    assert table.row("all").spl == pytest.approx(54.0)
    md = table.to_markdown()
    assert "| easy | 3 | 66.7 | 60.0 |" in md
    data = json.loads(table.to_json())
    assert data["tiers"][0]["tier"] == "easy"


def test_episode_result_json():
    r = _r("easy", False, 0.0)
    r.trace = [[0.0, 0.0, 0.0]]
    (d,) = json.loads(results_to_json([r]))
    assert d["failure_reason"] == "stopped too far" and "trace" not in d
    assert d["shortest_path_length"] is None  # NaN is written as null
    assert json.loads(results_to_json([r], with_trace=True))[0]["trace"] == [[0.0, 0.0, 0.0]]
