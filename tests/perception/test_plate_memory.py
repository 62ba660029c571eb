"""Reads of one plate add up; the rooms named along the corridor settle what one read
leaves open."""

from __future__ import annotations

import math

import pytest
from sign_kit import corridor, read

from pmnav_bt.perception.grounders.plate_memory import NEIGHBOUR_M, SPACING_FLOOR, PlateMemory
from pmnav_bt.perception.sign_match import MARGIN, SignMatcher, decide
from pmnav_bt.seams import Entity

PITCH = 3.0
CONFIDENCES = (0.3, 0.6, 0.7, 0.85, 0.92, 0.96, 0.99)


def setup():
    """B115 .. B118 along one corridor (doors PITCH apart), 8117 twenty doors down: B and
    8 are what OCR confuses."""
    codes = ("B115", "B116", "B117", "B118", *(f"C{i:03d}" for i in range(15)), "8117")
    b = corridor(*codes)
    m = SignMatcher(b)

    def door_of(e: Entity):
        return tuple(b.room(e.id).door)

    return m, PlateMemory(door_of), {r.sign_text: Entity.room(r.id) for r in b.rooms}


def open_read(m, room, text: str, settled=lambda gap: 2 * abs(gap) >= MARGIN):
    """``text`` read with its first character at a confidence that leaves B117 and 8117
    open on one read, where ``settled(log-likelihood of B117 less that of 8117)`` (by
    default: two alike reads settle it; the confusion table decides which confidence)."""
    for c in CONFIDENCES:
        ev = m.evidence(read(text, {0}, score=c))
        gap = ev.entities[room["B117"]] - ev.entities[room["8117"]]
        if decide(ev) is None and settled(gap):
            return ev
    pytest.fail(f"no confidence leaves {text!r} open and lets it be settled")


def test_two_consistent_reads_settle_what_one_leaves_open():
    m, mem, room = setup()
    ev = open_read(m, room, "b117")
    assert mem.read((0.0, 0.0), (0.0, -2.0, 0.0), 0.0, ev) is None
    # the same plate, from another place: the two reads agree
    got = mem.read((0.1, 0.0), (1.0, -2.0, 0.3), 1.0, ev)
    assert got is not None and got.entity == room["B117"]


def test_a_read_from_the_same_viewpoint_is_not_a_second_look():
    m, mem, room = setup()
    ev = open_read(m, room, "b117")
    for t in range(4):
        assert mem.read((0.0, 0.0), (0.0, -2.0, 0.0), float(t), ev) is None


def test_a_contradicting_read_takes_a_sighting_back():
    m, mem, room = setup()
    got = mem.read((0.0, 0.0), (0.0, -2.0, 0.0), 0.0, m.evidence(read("B117")))
    assert got.entity == room["B117"]
    assert mem.read((0.0, 0.0), (1.5, -2.0, 0.5), 1.0, m.evidence(read("8117"))) is None


def test_the_order_along_the_corridor_settles_it():
    """B116 named here; a plate one door pitch on reads B117-or-8117: it is B117 (8117's
    door is twenty doors away). Without the neighbour it stays open."""
    m, mem, room = setup()
    # open, and the spacing (8117's door does not fit it: SPACING_FLOOR) tips it to B117
    ev = open_read(m, room, "8117", lambda gap: gap - math.log(SPACING_FLOOR) >= MARGIN)
    assert decide(ev) is None
    named = mem.read((0.0, 0.0), (0.0, -2.0, 0.0), 0.0, m.evidence(read("B116")))
    assert named.entity == room["B116"]
    got = mem.read((PITCH, 0.0), (PITCH, -2.0, math.pi / 2), 1.0, ev)
    assert got is not None and got.entity == room["B117"]


def test_a_named_plate_far_away_does_not_vouch():
    """Odometry over a long run drifts: a plate named farther than NEIGHBOUR_M away says
    nothing about this one, even where the spacing would fit 8117 exactly."""
    m, mem, room = setup()
    mem.read((0.0, 0.0), (0.0, -2.0, 0.0), 0.0, m.evidence(read("B116")))
    far = (mem.door_of(room["8117"])[0] - mem.door_of(room["B116"])[0], 0.0)
    assert far[0] > NEIGHBOUR_M
    ev = open_read(m, room, "8117")
    assert mem.read(far, (far[0], -2.0, 0.0), 1.0, ev) is None
