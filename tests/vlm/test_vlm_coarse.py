"""The VLM coarse direction: the stitched panorama and the answer -> view mapping."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pmnav_bt.errors import VlmError
from pmnav_bt.seams import CameraIntrinsics, Detection, Entity, Observation, Pose2D, View
from pmnav_bt.vlm.client import VlmClient
from pmnav_bt.vlm.coarse import VlmCoarseDirection, parse_angle, stitch_panorama
from pmnav_bt.vlm.scripted_server import ChatServer, Reply, Script

ANGLES = (0, 30, -30, 60, -60, 90)


def views(with_detections: bool = False) -> list[View]:
    out = []
    for k, a in enumerate(ANGLES):
        rgb = np.full((60, 80, 3), 20 * k, np.uint8)
        obs = Observation(rgb, Pose2D(0, 0, 0), 0.0, CameraIntrinsics.from_hfov(80, 60, 1.0))
        dets = None
        if with_detections:
            dets = (Detection(f"door {a}", (10, 10, 20, 20), 0.9),) if a == 60 else ()
        out.append(View(math.radians(a), obs, dets))
    return out


def test_the_panorama_runs_left_to_right_with_its_angles():
    pano, angles = stitch_panorama(views(), height=120)
    assert angles == [90, 60, 30, 0, -30, -60]
    assert pano.shape[0] == 120 + 34 and pano.shape[1] == 6 * 160 + 5 * 6
    # The +90 view (the 6th frame, grey 100) is the leftmost tile, under its label band.
    assert (pano[60, 5] == 100).all() and (pano[60, -5] == 80).all()
    assert (pano[:34] < 128).any()  # the labels are written


@pytest.mark.parametrize(
    "text,angle",
    [('{"angle": 60}', 60.0), ("```json\n{\"angle\": -30}\n```", -30.0),
     ('{"angle": null}', None), ("The target is at +90 deg.", 90.0), ("Not visible.", None)],
)  # fmt: skip
def test_parse_angle(text, angle):
    assert parse_angle(text) == angle


def coarse(server, **kw) -> VlmCoarseDirection:
    from pmnav_bt.map.catalogue import load_building

    client = VlmClient(server.base_url, "m", timeout_s=kw.pop("timeout_s", 5.0), retries=0)
    return VlmCoarseDirection(client, load_building("fig2_hospital"), **kw)


def test_the_vlm_picks_the_view_and_its_detection_comes_with_it():
    with ChatServer(Script([Reply('{"angle": 60}')])) as s:
        choice = coarse(s).choose(views(with_detections=True), Entity.room("room17"))
    assert math.degrees(choice.view.relative_yaw) == pytest.approx(60)
    assert choice.detection.label == "door 60"
    parts = s.requests[0]["messages"][0]["content"]
    assert 'the door of One-Stop Service Centre (its sign reads "117' in parts[0]["text"]
    assert "+90, +60, +30, +0, -30, -60" in parts[0]["text"]
    assert parts[1]["image_url"]["url"].startswith("data:image/png;base64,")


def test_a_view_the_grounder_misses_gives_a_coarse_detection():
    with ChatServer(Script([Reply('{"angle": -60}')])) as s:
        choice = coarse(s).choose(views(with_detections=True), Entity.landmark("elevator1"))
    assert math.degrees(choice.view.relative_yaw) == pytest.approx(-60)
    assert choice.detection.box == (0.0, 0.0, 80.0, 60.0)  # straight ahead of that view
    assert choice.detection.entity == Entity.landmark("elevator1")


def test_null_or_no_such_view_is_none():
    with ChatServer(Script([Reply('{"angle": null}'), Reply('{"angle": 180}')])) as s:
        c = coarse(s)
        assert c.choose(views(), Entity.room("room17")) is None
        assert c.choose(views(), Entity.room("room17")) is None
    assert c.stats.not_seen == 1 and c.stats.unreadable == 1


def test_a_hanging_server_is_a_vlm_error_after_the_timeout():
    with (
        ChatServer(Script([Reply('{"angle": 0}', delay_s=3.0)])) as s,
        pytest.raises(VlmError, match="no answer within 0.2 s"),
    ):
        coarse(s, timeout_s=0.2).choose(views(), Entity.room("room17"))


def test_both_vlm_back_ends_are_registered_and_built_from_the_config(fig2_map):
    from pmnav_bt.backends import BackendDeps
    from pmnav_bt.config import load_config
    from pmnav_bt.registry import COARSE, PLANNERS
    from pmnav_bt.vlm.planner import VlmPlanner

    cfg = load_config(
        None,
        [
            "planner.backend=vlm", "coarse.backend=vlm", "vlm.model=m", "vlm.prompt=h-em",
            "vlm.plan_tries=2", "vlm.fallback=false", "vlm.timeout_s=7",
        ],
    )  # fmt: skip
    deps = BackendDeps(config=cfg, pm=fig2_map)
    p = PLANNERS.build("vlm", deps)
    assert isinstance(p, VlmPlanner)
    assert (p.inputs, p.tries, p.fallback, p.client.timeout_s) == ("h-em", 2, False, 7.0)
    c = COARSE.build("vlm", deps)
    assert isinstance(c, VlmCoarseDirection) and c.client.model == "m"
