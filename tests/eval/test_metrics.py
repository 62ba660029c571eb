"""Metrics on hand-computed cases: success, SPL, SDF, per-tier aggregation."""

from __future__ import annotations

import dataclasses
import json
import math

import pytest

from pmnav_bt.eval.metrics import (
    SUCCESS_RADIUS_M,
    EpisodeResult,
    aggregate_by_tier,
    contact_totals,
    results_to_json,
    sdf,
    sdf_term,
    soft_spl,
    spl,
    success,
)
from pmnav_bt.eval.task import action_budget
from pmnav_bt.eval.tiers import TIER_NAMES, parse_tiers


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


def test_soft_spl_hand_cases():
    # habitat-lab: max(0, 1 - d_T / l) * l / max(l, p)
    assert soft_spl(10.0, 0.0, 10.0) == 1.0
    assert soft_spl(10.0, 0.0, 12.5) == pytest.approx(0.8)
    assert soft_spl(10.0, 4.0, 12.5) == pytest.approx(0.6 * 0.8)
    assert soft_spl(10.0, 15.0, 5.0) == 0.0  # ended farther than it started
    assert soft_spl(0.0, 0.0, 3.0) == 1.0 and soft_spl(0.0, 1.0, 3.0) == 0.0
    with pytest.raises(ValueError):
        soft_spl(-1.0, 0.0, 1.0)


def test_errored_episodes_are_counted_apart_from_failures():
    crashed = dataclasses.replace(_r("easy", False, 0.0), error="RuntimeError: boom")
    table = aggregate_by_tier([_r("easy", True, 1.0), _r("easy", False, 0.0), crashed])
    easy = table.row("easy")
    assert easy.episodes == 2 and easy.errors == 1
    assert easy.sr == 50.0 and easy.spl == 50.0
    only = aggregate_by_tier([crashed]).row("easy")
    assert only.episodes == 0 and only.errors == 1 and math.isnan(only.sr)


def test_result_dict_round_trip_keeps_nan():
    r = _r("easy", True, 1.0)
    back = EpisodeResult.from_dict(json.loads(json.dumps(r.to_dict())))
    assert math.isnan(back.soft_spl) and back.error is None and back.tier == "easy"


def test_one_budget_rule():
    assert action_budget(None) == 500
    assert action_budget(10.0) == 500  # 3 * 10 / 0.25 = 120 < 500
    assert action_budget(50.0) == 600  # 3 * 50 / 0.25
    assert action_budget(50.0, actions=100, path_factor=2.0) == 400


def test_tiers_parse():
    assert list(TIER_NAMES) == ["easy", "medium", "hard"]
    assert parse_tiers("all") == ["easy", "medium", "hard", "cross_level"]
    assert parse_tiers("hard, easy") == ["hard", "easy"]
    with pytest.raises(ValueError, match="choose easy, medium, hard, cross_level or all"):
        parse_tiers("extreme")


def test_contacts_are_totalled_over_the_episodes_that_ran_and_old_rows_load():
    old_row = {k: v for k, v in _r("easy", True, 1.0).to_dict().items() if k != "people_contacts"}
    old = EpisodeResult.from_dict(old_row)  # written before people contacts were recorded
    assert old.people_contacts is None
    rs = [
        dataclasses.replace(_r("easy", False, 0.0), collisions=2, people_contacts=1),
        dataclasses.replace(_r("easy", True, 1.0), collisions=1, people_contacts=0),
        dataclasses.replace(_r("easy", False, 0.0), collisions=5, error="RuntimeError: boom"),
        dataclasses.replace(old, collisions=1),
    ]
    c = contact_totals(rs)
    assert (c.episodes, c.collisions, c.people_contacts, c.unrecorded) == (3, 4, 1, 1)
    assert c.per_100_text() == "133.3" and c.people_text() == "1 (1 of 3 not recorded)"
    assert contact_totals([old]).people_text() == "not recorded"
    assert contact_totals([]).per_100_text() == "-"
    back = EpisodeResult.from_dict(json.loads(json.dumps(rs[0].to_dict())))
    assert (back.collisions, back.people_contacts) == (2, 1)
