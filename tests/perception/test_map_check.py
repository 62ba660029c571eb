"""The map check: signs that read differently from the map, and landmarks seen away from
their place, are written once seen twice; the OCR reads real plates (synthetic wall)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pmnav_bt.perception.map_check import CONFIRM_READS, MOVED_M, MapCheck, WatchesReads
from pmnav_bt.planning.resolve import entity_position
from pmnav_bt.seams import CameraIntrinsics, Detection, Entity, Observation, Pose2D


class _Sink:
    def __init__(self):
        self.updates = []

    def record(self, update, crop=None):
        self.updates.append((update, crop))


def _frames(wall, n, text):
    return [dataclasses.replace(wall.frame([(text, 0.0)]), stamp=float(k)) for k in range(n)]


@pytest.fixture(scope="module")
def reader(fig2):
    pytest.importorskip("rapidocr_onnxruntime")
    from pmnav_bt.perception.grounders.ocr import OcrGrounder

    return OcrGrounder(fig2)


@pytest.fixture
def ocr(reader):
    yield reader
    reader.watch_reads(None)


def test_a_renamed_room_read_on_its_plate_is_written_once_confirmed(ocr, fig2_map, wall):
    sink = _Sink()
    assert isinstance(ocr, WatchesReads)
    ocr.watch_reads(MapCheck(fig2_map, sink, lambda: None).frame)
    frames = _frames(wall, CONFIRM_READS + 2, "108 Quiet Room")
    named = [d.entity for d in ocr.read_signs(frames[0])]
    assert named == [Entity.room("room8")]  # by its number: the robot still finds it
    assert sink.updates == []  # one read is not a stale map
    for obs in frames[1:]:
        ocr.detect(obs, Entity.room("room15"))  # frames read for any reason are watched
    assert len(sink.updates) == 1  # once per run
    update, crop = sink.updates[0]
    assert (update.kind, update.subject_kind, update.subject) == ("sign_text", "room", "room8")
    assert update.mapped == "108" and update.seen == "108 Quiet Room"
    assert update.evidence.reads == ("108 Quiet Room",) * CONFIRM_READS
    assert update.evidence.pose is None and crop.shape[2] == 3 and 0 < crop.shape[1] <= 160


def test_a_frame_asked_about_twice_is_one_read(ocr, fig2_map, wall):
    sink = _Sink()
    ocr.watch_reads(MapCheck(fig2_map, sink, lambda: None).frame)
    (obs,) = _frames(wall, 1, "108 Quiet Room")
    ocr.read_signs(obs)
    ocr.detect(obs, Entity.room("room8"))  # the same frame, from the reader's cache
    assert sink.updates == []


def test_a_plate_that_reads_as_the_map_says_is_no_update(ocr, fig2_map, wall):
    sink = _Sink()
    ocr.watch_reads(MapCheck(fig2_map, sink, lambda: None).frame)
    for obs in _frames(wall, 3, "102 Pharmacy"):
        assert [d.entity for d in ocr.read_signs(obs)] == [Entity.room("room2")]
    assert sink.updates == []


def _elevator_seen(fig2_map, beyond: float):
    """elevator1's sign seen 2 m ahead of a camera whose map pose puts it ``beyond`` m
    from the map's place for it."""
    mx, my = entity_position(fig2_map, Entity.landmark("elevator1"))
    seen = Detection("Elevator A", (10, 10, 60, 40), 0.9, entity=Entity.landmark("elevator1"),
                     point=(2.0, 0.0, 0.0))  # fmt: skip
    return (mx, my), seen, (mx - 2.0, my + beyond, 0.0)


def test_a_landmark_seen_far_from_its_place_is_moved(fig2_map):
    (mx, my), seen, tf = _elevator_seen(fig2_map, beyond=4.5)
    assert MOVED_M < 4.5
    sink = _Sink()
    check = MapCheck(fig2_map, sink, lambda: tf)
    check.frame(_observation(0.0), [seen], [])
    check.frame(_observation(0.0), [seen], [])  # the same frame again: one read
    assert sink.updates == []
    for k in range(1, CONFIRM_READS):
        check.frame(_observation(float(k)), [seen], [])
    ((update, _),) = sink.updates
    assert (update.kind, update.subject) == ("moved", "elevator1")
    assert update.at == pytest.approx((mx, my + 4.5), abs=0.01)
    assert update.evidence.pose == pytest.approx(tf)


def test_a_landmark_where_the_map_puts_it_is_no_update(fig2_map):
    _, seen, tf = _elevator_seen(fig2_map, beyond=0.5)
    sink = _Sink()
    check = MapCheck(fig2_map, sink, lambda: tf)
    for k in range(3):
        check.frame(_observation(float(k)), [seen], [])
    assert sink.updates == []


def _observation(stamp: float = 1.0):
    k = CameraIntrinsics.from_hfov(64, 48, 1.0)
    return Observation(np.zeros((48, 64, 3), np.uint8), Pose2D(0.0, 0.0, 0.0), stamp, k)


def _plate(text):
    """A plate read 2 m straight ahead that names nothing of the map."""
    return Detection(text, (10, 10, 60, 40), 0.9, point=(2.0, 0.0, 0.0))


def test_a_plate_without_a_number_is_the_room_whose_door_it_hangs_by(fig2_map):
    """room8's door is at (31, 1.2); the next door, room15's, 4.5 m from the plate."""
    sink = _Sink()
    check = MapCheck(fig2_map, sink, lambda: (29.8, 1.2, 0.0))  # the plate at (31.8, 1.2)
    for k in range(CONFIRM_READS):
        check.frame(_observation(float(k)), [], [_plate("Quiet Room")])
    ((update, _),) = sink.updates
    assert (update.kind, update.subject, update.seen) == ("sign_text", "room8", "Quiet Room")
    assert update.at == pytest.approx((31.8, 1.2), abs=0.01)


def test_a_plate_without_a_number_far_from_doors_or_before_a_fix_names_no_room(fig2_map):
    sink = _Sink()
    # The plate at (26, 0): 2.3 m from room7's door (24, 1.2) and room15's (28, -1.2).
    between = MapCheck(fig2_map, sink, lambda: (24.0, 0.0, 0.0))
    unlocalized = MapCheck(fig2_map, sink, lambda: None)
    for k in range(3):
        between.frame(_observation(float(k)), [], [_plate("Quiet Room")])
        unlocalized.frame(_observation(float(k)), [], [_plate("Quiet Room")])
    assert sink.updates == []


def test_digits_and_specks_beside_a_door_are_a_misread_not_a_renamed_room(fig2_map):
    """Read in a realistic run: "18", then "1.8", by room14's door."""
    sink = _Sink()
    check = MapCheck(fig2_map, sink, lambda: (29.8, 1.2, 0.0))  # by room8's door
    for k, text in enumerate(["18", "1.8", "1.8 B", "108 x"]):
        check.frame(_observation(float(k)), [], [_plate(text)])
    assert sink.updates == []
