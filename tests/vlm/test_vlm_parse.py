"""Tolerant parsing of plan answers."""

from __future__ import annotations

import pytest

from pmnav_bt.vlm.parse import ParseFailure, RawStep, parse_plan

STEPS = [
    RawStep("room8", "go straight"),
    RawStep("turn2", "turn left"),
    RawStep("room17", "arrive"),
]
JSON = (
    '{"plan": [{"landmark": "room8", "action": "go straight"}, '
    '{"landmark": "turn2", "action": "turn left"}, {"landmark": "room17", "action": "arrive"}]}'
)


@pytest.mark.parametrize(
    "text",
    [
        JSON,
        f"Step 1: ...\nStep 2: ...\n```json\n{JSON}\n```\nThat is all.",
        f"```\n{JSON}\n```",
        '[{"room8": "go straight"}, {"turn2": "turn left"}, {"room17": "arrive"}]',
        '[["room8", "go straight"], ["turn2", "turn left"], ["room17", "arrive"]]',
        '{"steps": [{"name": "room8", "action": "go straight"}, {"name": "turn2", '
        '"action": "turn left"}, {"name": "room17", "action": "arrive"}]}',
        "{room8: go straight} -> {turn2: turn left} -> {room17: arrive}",
        "1. {room8: go straight} -> {turn2: turn left}\n2. {turn2: turn left} -> {room17: arrive}",
    ],
)
def test_every_accepted_form_gives_the_same_steps(text):
    assert parse_plan(text) == STEPS


def test_the_last_fenced_block_wins():
    first = JSON.replace("room17", "room18")
    assert parse_plan(f"```json\n{first}\n```\nSorry, corrected:\n```json\n{JSON}\n```") == STEPS


def test_truncated_json_is_malformed_not_salvaged():
    with pytest.raises(ParseFailure) as err:
        parse_plan("```json\n" + JSON[: len(JSON) // 2])
    assert err.value.kind == "malformed_json"


def test_prose_is_no_plan():
    with pytest.raises(ParseFailure) as err:
        parse_plan("Walk east along the corridor; the room is on your left.")
    assert err.value.kind == "no_plan"
