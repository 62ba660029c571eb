"""The ``ocr`` grounder on synthetic wall frames with real sign textures and real OCR."""

from __future__ import annotations

import math

import pytest

from pmnav_bt.seams import Entity

pytest.importorskip("rapidocr_onnxruntime")


@pytest.fixture(scope="module")
def grounder(fig2):
    from pmnav_bt.perception.grounders.ocr import OcrGrounder

    return OcrGrounder(fig2)


def test_reads_a_sign_and_places_it_with_depth(grounder, wall):
    obs = wall.frame([("102 Pharmacy", 0.0)])
    signs = grounder.read_signs(obs)
    assert [d.entity for d in signs] == [Entity.room("room2")]
    # The point is the room's: its door, 1.14 m beside the sign (no door in the picture:
    # the building's convention puts it on the sign's left), at mid-door height.
    x, y, z = signs[0].point
    assert x == pytest.approx(wall.RANGE, abs=0.05)
    assert y == pytest.approx(1.14, abs=0.1) and z == pytest.approx(1.09 - 1.6, abs=0.05)


def test_two_similar_signs_the_query_gets_its_own(grounder, wall):
    """Signs 111 and 112 side by side: the query for room 12 is grounded at the 112 sign's
    door, not at 111's."""
    obs = wall.frame([("111", 0.55), ("112", -0.55)])
    named = {d.entity for d in grounder.read_signs(obs)}
    assert named == {Entity.room("room11"), Entity.room("room12")}
    dets = grounder.detect(obs, Entity.room("room12"))
    assert len(dets) == 1
    door = dets[0]
    # The door is sign_to_door (1.14 m) beside the 112 sign (at y = -0.55), on the wall.
    assert door.point[0] == pytest.approx(wall.RANGE, abs=0.05)
    assert abs(door.point[1] - (-0.55)) == pytest.approx(1.14, abs=0.1)


def test_a_sign_cut_by_the_image_border_is_still_named(grounder, wall):
    # Centred at the left edge of the view: the plate's left part is out of the frame.
    half_view = wall.RANGE * math.tan(wall.K.hfov / 2)
    obs = wall.frame([("104 Laboratory", half_view - 0.1)])
    signs = grounder.read_signs(obs)
    assert signs and signs[0].entity == Entity.room("room4")
    assert signs[0].box[0] <= 2  # it touches the border


def test_a_number_seen_close_up_and_cut_by_the_border_is_read_whole(grounder, wall):
    """At 1 m a bare "113" has characters farther apart than the candidate finder's
    closing: they are joined into one word, not read as "13" (room 13 has no such sign)."""
    half_view = 1.0 * math.tan(wall.K.hfov / 2)
    obs = wall.frame([("113", half_view - 0.25)], range_m=1.0)
    signs = grounder.read_signs(obs)
    assert [d.entity for d in signs] == [Entity.room("room13")]


def test_without_depth_signs_are_named_but_not_placed(grounder, wall):
    obs = wall.frame([("102 Pharmacy", 0.0)], depth=False)
    signs = grounder.read_signs(obs)
    assert [d.entity for d in signs] == [Entity.room("room2")] and signs[0].point is None
    dets = grounder.detect(obs, Entity.room("room2"))
    assert len(dets) == 1 and dets[0].point is None  # the sign stands in for its door
    assert grounder.surfaces(obs).floor.sum() == 0


def test_a_plain_wall_names_nothing(grounder, wall):
    assert grounder.read_signs(wall.frame([])) == []
    assert grounder.detect(wall.frame([]), Entity.room("room2")) == []


def test_the_door_side_follows_the_image(grounder, wall):
    """A brown door on the sign's right (viewer's) is found there, against the default."""
    obs = wall.frame([("105", 0.0)])
    px_per_m = wall.K.fx / wall.RANGE
    u0 = int(round(wall.K.cx + (1.14 - 0.5) * px_per_m))
    obs.rgb[int(wall.K.cy - 0.2 * px_per_m) :, u0 : u0 + int(px_per_m)] = (148, 97, 51)
    (door,) = grounder.detect(obs, Entity.room("room5"))
    assert door.point[1] == pytest.approx(-1.14, abs=0.1)  # right of the sign


def test_a_misread_code_is_a_plate_to_read_again_a_code_read_sure_is_not(fig2, wall):
    # fig2's codes are three digits ("101"): "79" is spelled as none of them, a plate
    # misread (the tree reads it again from nearer); "188", read sure and spelled as the
    # building's codes, is a plate the building does not hold: read, naming nothing.
    from pmnav_bt.perception.grounders.ocr import OcrGrounder

    for text, again in (("79", True), ("188", False)):
        g = OcrGrounder(fig2)
        assert g.read_signs(wall.frame([(text, 0.0)], range_m=1.5)) == []
        plates = g.unread_plates(0.0)
        assert bool(plates) == again, text
        if again:
            assert plates[0].read == text
