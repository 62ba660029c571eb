"""The map check: signs that read differently from the map, and landmarks seen away from
their place, are written once seen twice; the OCR reads real plates (synthetic wall)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from pmnav_bt.perception.map_check import CONFIRM_READS, MOVED_M, MapCheck
from pmnav_bt.seams import Detection, Entity, Pose2D


class _Sink:
    def __init__(self):
        self.updates = []

    def record(self, update, crop=None):
        self.updates.append((update, crop))


class _Grounder:
    """Returns what it is given; ``unmatched`` only when ``reports_unmatched``."""

    needs_sim_labels = False

    def __init__(self, signs, unmatched=None):
        self.signs, self._unmatched, self.calls = signs, unmatched, []
        if unmatched is not None:
            self.unmatched_signs = lambda obs: list(self._unmatched)

    def detect(self, obs, target):
        self.calls.append("detect")
        return []

    def read_signs(self, obs):
        self.calls.append("read_signs")
        return list(self.signs)

    def surfaces(self, obs):
        return None


def _frames(wall, n, text):
    return [dataclasses.replace(wall.frame([(text, 0.0)]), stamp=float(k)) for k in range(n)]


@pytest.fixture(scope="module")
def ocr(fig2):
    pytest.importorskip("rapidocr_onnxruntime")
    from pmnav_bt.perception.grounders.ocr import OcrGrounder

    return OcrGrounder(fig2)


def test_a_renamed_room_read_on_its_plate_is_written_once_confirmed(ocr, fig2_map, wall):
    sink = _Sink()
    check = MapCheck(ocr, fig2_map, sink, lambda: None)
    frames = _frames(wall, CONFIRM_READS + 2, "108 Quiet Room")
    assert check.read_signs(frames[0]) == []  # nothing of the map is named
    assert sink.updates == []  # one read is not a stale map
    for obs in frames[1:]:
        check.read_signs(obs)
    assert len(sink.updates) == 1  # once per run
    update, crop = sink.updates[0]
    assert (update.kind, update.subject_kind, update.subject) == ("sign_text", "room", "room8")
    assert update.mapped == "108" and update.seen == "108 Quiet Room"
    assert update.evidence.reads == ("108 Quiet Room",) * CONFIRM_READS
    assert update.evidence.pose is None and crop.shape[2] == 3 and 0 < crop.shape[1] <= 160


def test_a_plate_that_reads_as_the_map_says_is_no_update(ocr, fig2_map, wall):
    sink = _Sink()
    check = MapCheck(ocr, fig2_map, sink, lambda: None)
    for obs in _frames(wall, 3, "102 Pharmacy"):
        assert [d.entity for d in check.read_signs(obs)] == [Entity.room("room2")]
    assert sink.updates == []


def test_a_landmark_seen_far_from_its_place_is_moved(fig2_map):
    """elevator1 is at (37.4, 6.0) on the map; seen 4.5 m further along its corridor."""
    from pmnav_bt.planning.resolve import entity_position

    mx, my = entity_position(fig2_map, Entity.landmark("elevator1"))
    seen = Detection("Elevator A", (10, 10, 60, 40), 0.9, entity=Entity.landmark("elevator1"),
                     point=(2.0, 0.0, 0.0))  # fmt: skip
    sink = _Sink()
    # The map pose puts the camera 2 m short of where the landmark is seen, facing it.
    tf = (mx - 2.0, my + 4.5, 0.0)
    check = MapCheck(_Grounder([seen]), fig2_map, sink, lambda: tf)
    obs = _observation()
    for _ in range(CONFIRM_READS):
        check.read_signs(obs)
    (update, _), = sink.updates
    assert (update.kind, update.subject) == ("moved", "elevator1")
    assert update.at == pytest.approx((mx, my + 4.5), abs=0.01)
    assert MOVED_M < 4.5  # seen 4.5 m away: beyond the check's threshold
    assert update.evidence.pose == pytest.approx((mx - 2.0, my + 4.5, 0.0))


def test_a_landmark_where_the_map_puts_it_is_no_update(fig2_map):
    from pmnav_bt.planning.resolve import entity_position

    mx, my = entity_position(fig2_map, Entity.landmark("elevator1"))
    seen = Detection("Elevator A", (10, 10, 60, 40), 0.9, entity=Entity.landmark("elevator1"),
                     point=(2.0, 0.0, 0.0))  # fmt: skip
    sink = _Sink()
    check = MapCheck(_Grounder([seen]), fig2_map, sink, lambda: (mx - 2.0, my + 0.5, 0.0))
    for _ in range(3):
        check.read_signs(_observation())
    assert sink.updates == []


def test_detect_reads_signs_only_of_a_grounder_that_reports_unmatched_plates(fig2_map):
    """The oracle draws its misses from a seeded stream: a check must not read its signs
    behind its back, or a run's episode would change."""
    plain, reporting = _Grounder([]), _Grounder([], unmatched=[])
    for g in (plain, reporting):
        MapCheck(g, fig2_map, _Sink(), lambda: None).detect(_observation(), Entity.room("room2"))
    assert plain.calls == ["detect"]
    assert reporting.calls == ["detect", "read_signs"]


def _observation():
    from pmnav_bt.seams import CameraIntrinsics, Observation

    k = CameraIntrinsics.from_hfov(64, 48, 1.0)
    return Observation(np.zeros((48, 64, 3), np.uint8), Pose2D(0.0, 0.0, 0.0), 1.0, k)
