"""The tree log's view entry (version 2) written by a whole mission on the test doubles: the
run it names, the estimated and true poses, the plan, a landmark's failure with the replan
after it, and the frames perception grounded with what they showed."""

from __future__ import annotations

import math
from types import SimpleNamespace

import pytest

from pmnav_bt.map.catalogue import load_building
from pmnav_bt.seams import Pose2D
from pmnav_bt.testing.doubles import FakePlanner, ScriptedGrounder
from pmnav_bt.treelog import SCHEMA_VERSION, read_tree_log
from pmnav_bt.trees.view_record import ViewRecorder

START = Pose2D(4.0, 0.0, 0.0)  # straight_office, facing east down the corridor


@pytest.fixture(scope="module")
def building():
    return load_building("straight_office")


def test_a_mission_logs_what_the_view_draws(make_rig, pm, tmp_path):
    plan = FakePlanner().plan(pm, "4,0,0", "room13")
    hidden = next(s.look_for for s in plan.steps[1:-1] if s.look_for.startswith("room"))
    rig = make_rig(START, grounder=ScriptedGrounder(pm, hidden=frozenset({hidden})))
    view = ViewRecorder(rig.ctx, building="straight_office", truth=rig.true_pose)
    path = tmp_path / "run.tree.jsonl"
    with open(path, "w", encoding="utf-8") as out:
        outcome = rig.mission("Kitchen", max_ticks=20_000, log=out, view=view)
    assert outcome.success and outcome.replans == 1
    log = read_tree_log(path)  # every view entry passes the reader's checks
    assert log.header == {
        "version": SCHEMA_VERSION,
        "run": {"building": "straight_office", "goal": "Kitchen"},
    }
    views = [t["view"] for t in log.ticks]
    first_fix = next(k for k, v in enumerate(views) if v.get("pose"))
    assert all("pose" not in v or v["pose"] is None for v in views[:first_fix])
    last = lambda key: next(v[key] for v in reversed(views) if key in v)  # noqa: E731
    est, true = rig.estimate(), rig.true_pose()
    assert last("pose") == pytest.approx([est.x, est.y, est.yaw], abs=2e-3)
    assert last("truth") == pytest.approx([true.x, true.y, true.yaw], abs=2e-3)
    assert last("sigma") > 0
    plans = [v["plan"] for v in views if v.get("plan")]
    assert len(plans) == 2 and plans[-1]["steps"][-1]["landmark"] == "room13"
    assert math.dist(plans[0]["path"][0], (START.x, START.y)) < 1.0
    failures = [v["failure"] for v in views if v.get("failure")]
    assert any(f["code"] == "TARGET_NOT_FOUND" and hidden in f["message"] for f in failures)
    frames = [v["frame"] for v in views if "frame" in v]
    found = [d for f in frames for d in f["found"]]
    assert found and all(f["jpeg"] and f["size"][0] <= 320 for f in frames)
    seen = {e for v in views for e in v.get("seen", [])}
    assert {d["entity"] for d in found if d["entity"]} <= seen
    assert f"room {hidden}" not in seen


class _PlateReader(ScriptedGrounder):
    """A grounder with the optional capabilities of the real stack (remembered unread
    plates, watched reads), as the OCR grounder has them."""

    def unread_plates(self, since: float) -> list:
        return [f"unread since {since}"]

    def plate_named(self, entity) -> None:
        return None

    def watch_reads(self, observer) -> None:
        self.observer = observer


def test_the_view_s_tap_keeps_what_the_grounder_can_do(make_rig, pm):
    """Turning the view on wraps the grounder in a FrameTap: the tree must find the same
    capabilities behind it (active reading asks for SeesUnreadPlates), or a run with the
    view would do other things than the same run without it."""
    from pmnav_bt.perception.frame_tap import FrameTap
    from pmnav_bt.perception.map_check import WatchesReads
    from pmnav_bt.perception.unread_plates import SeesUnreadPlates

    rig = make_rig(START, grounder=_PlateReader(pm))
    ViewRecorder(rig.ctx, building="straight_office", truth=rig.true_pose)
    tap = rig.ctx.grounder
    assert isinstance(tap, FrameTap)
    assert isinstance(tap, SeesUnreadPlates) and isinstance(tap, WatchesReads)
    assert tap.unread_plates(2.0) == ["unread since 2.0"]
    tap.watch_reads(print)
    assert tap.inner.observer is print
    plain = FrameTap(SimpleNamespace(needs_sim_labels=False))  # one without them
    assert not isinstance(plain, SeesUnreadPlates) and not isinstance(plain, WatchesReads)
