"""The landmark kinds: one list, which the simulator builds from and the docs name
(tests/sim/test_world.py checks that the solid ones are what the robot meets)."""

from __future__ import annotations

from pathlib import Path

from pmnav_bt.map.landmark_kinds import (
    DESK,
    ELEVATOR,
    FIRE_DOOR,
    PLATE,
    STAIRS,
    is_fire_door,
    kinds_table,
    known_kinds,
    landmark_shape,
)

DOC = Path(__file__).resolve().parents[2] / "docs" / "building-format.md"


def test_the_building_format_doc_names_every_kind_with_its_sizes():
    doc = DOC.read_text()
    assert kinds_table() in doc, "paste kinds_table() under 'Landmark kinds' in the doc"
    section = doc.split("## Landmark kinds", 1)[1].split("\n## ", 1)[0]
    for kind in known_kinds():
        assert f"`{kind}`" in section, kind


def test_kinds_are_matched_without_case_and_unknown_kinds_are_name_plates():
    assert landmark_shape("Lift") is ELEVATOR and landmark_shape("STAIRWAY") is STAIRS
    assert landmark_shape("information_desk") is DESK
    assert landmark_shape("fire_extinguisher") is PLATE and landmark_shape("sign") is PLATE
    assert len(known_kinds()) == len(set(known_kinds()))  # a kind names one shape



def test_a_fire_door_is_a_kind_across_its_corridor_with_nothing_to_read():
    assert landmark_shape(" Fire Door ") is FIRE_DOOR and is_fire_door("FIREDOOR")
    assert not is_fire_door("door") and not is_fire_door("fire_extinguisher")
    # Shut or open is the world's to say: the shape alone is not solid, and not a sign.
    assert not FIRE_DOOR.solid and not FIRE_DOOR.readable
    assert all(s.readable for s in (ELEVATOR, STAIRS, DESK, PLATE))
