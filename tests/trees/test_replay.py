"""``pmnav tree replay``: a tree log read back shows each tick's statuses and feedback;
user errors (missing or bad log, a tick not in it) are one-line PmNavErrors."""

from __future__ import annotations

import io

import py_trees
import pytest
from countdown import Countdown
from py_trees.common import Status
from rich.console import Console
from typer.testing import CliRunner

from pmnav_bt.errors import PmNavError
from pmnav_bt.trees.cli import app, load_replay, print_ticks
from pmnav_bt.trees.snapshots import Replay, SnapshotLogger


def small_tree() -> py_trees.trees.BehaviourTree:
    """Ticks 0-1: First runs; 2: First done, Same fails, Second runs; 3: all succeed."""
    choose = py_trees.composites.Selector(
        "Choose",
        memory=False,
        children=[py_trees.behaviours.Failure(name="Same"), Countdown("Second", 1)],
    )
    job = py_trees.composites.Sequence(
        "Job",
        memory=True,
        children=[
            Countdown("First", 2),
            py_trees.decorators.Retry("Again", choose, num_failures=2),
            py_trees.behaviours.Success(name="Same"),
        ],
    )
    root = py_trees.composites.Parallel(
        "Root",
        policy=py_trees.common.ParallelPolicy.SuccessOnOne(),
        children=[py_trees.behaviours.Running(name="Watch"), job],
    )
    return py_trees.trees.BehaviourTree(root)


def write_log(path) -> None:
    tree = small_tree()
    with open(path, "w", encoding="utf-8") as out:
        tree.add_post_tick_handler(SnapshotLogger(tree, out, clock_now=lambda: tree.count * 0.1))
        while tree.root.status != Status.SUCCESS and tree.count < 10:
            tree.tick()


@pytest.fixture()
def log(tmp_path):
    path = tmp_path / "tree.jsonl"
    write_log(path)
    return path


def invoke(*args):
    return CliRunner().invoke(app, [str(a) for a in args])


def test_replay_one_tick_shows_statuses_and_feedback(log):
    res = invoke("replay", log, "--tick", 2)
    assert res.exit_code == 0, res.output
    lines = res.stdout.splitlines()
    assert lines[0] == "tick 2  t=0.2 s"
    assert "    * Job [Sequence]" in lines
    assert "        ✔ First [Countdown] -- done" in lines
    assert "            * Choose [Selector]" in lines
    assert "                ✘ Same [Failure] -- failure" in lines
    assert "                * Second [Countdown] -- 1 to go" in lines
    assert "        · Same [Success]" in lines  # not ticked yet


def test_replay_range_prints_each_tick_in_order(log):
    res = invoke("replay", log, "--from", 1, "--to", 3, "--visited-only")
    assert res.exit_code == 0, res.output
    headers = [ln for ln in res.stdout.splitlines() if ln.startswith("tick ")]
    assert headers == ["tick 1  t=0.1 s", "tick 2  t=0.2 s", "tick 3  t=0.3 s"]
    assert "· " not in res.stdout  # visited only: no untouched nodes
    last = res.stdout.split("tick 3")[1]
    assert "✔ Root [Parallel]" in last and "✔ Same [Success]" in last


def test_replay_changes_skips_ticks_where_nothing_changed(log):
    res = invoke("replay", log, "--changes")
    headers = [ln for ln in res.stdout.splitlines() if ln.startswith("tick ")]
    assert headers == ["tick 0  t=0.0 s", "tick 2  t=0.2 s", "tick 3  t=0.3 s"]  # tick 1 = tick 0


def test_step_waits_between_ticks_and_stops_on_q(log):
    rp = load_replay(log)
    out = io.StringIO()
    answers = iter([True, False])
    calls = []

    def wait() -> bool:
        calls.append(1)
        return next(answers)

    shown = print_ticks(rp, rp.ticks, True, wait=wait, console=Console(file=out))
    assert shown == 2 and len(calls) == 2  # tick 0, Enter, tick 1, q
    assert out.getvalue().count("tick ") == 2


def test_step_without_a_terminal_prints_everything(log):
    res = CliRunner().invoke(app, ["replay", str(log), "--step"], input="")
    assert res.exit_code == 0
    assert res.stdout.count("\ntick ") + res.stdout.startswith("tick ") == 4


@pytest.mark.parametrize(
    "content, expected",
    [
        (None, "cannot read tree log"),
        ('{"type": "tree", "nodes": [\n', "line 1: not valid JSON"),
        (
            '{"type": "tick", "tick": 0, "time": 0, "status": {}, "feedback": {}, '
            '"blackboard": {}}\n',
            "not a tree log",
        ),
        ("[1, 2]\n", "not a tree log"),
        (b"\x89PNG\r\n\x1a\n\xff\xfe", "not a tree log"),
    ],
    ids=["missing", "bad-json", "no-tree-record", "not-objects", "binary"],
)
def test_bad_logs_are_one_line_errors(tmp_path, content, expected):
    path = tmp_path / "x.jsonl"
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif content is not None:
        path.write_text(content)
    res = invoke("replay", path)
    assert isinstance(res.exception, PmNavError)
    msg = str(res.exception)
    assert expected in msg and str(path) in msg and "\n" not in msg


def test_tick_not_in_log(log):
    res = invoke("replay", log, "--tick", 99)
    assert isinstance(res.exception, PmNavError)
    assert str(res.exception) == f"{log}: no tick 99 in this log (it holds ticks 0..3)"
    res = invoke("replay", log, "--from", 7)
    assert "no tick at or after tick 7" in str(res.exception)
    res = invoke("replay", log, "--from", 3, "--to", 1)
    assert "--from 3 is after --to 1" in str(res.exception)


def test_tick_record_missing_a_field(tmp_path, log):
    lines = log.read_text().splitlines()
    bad = tmp_path / "bad.jsonl"
    bad.write_text("\n".join([lines[0], '{"type": "tick", "tick": 5, "status": {}}']))
    res = invoke("replay", bad)
    assert "line 2: a tick record lacks blackboard, feedback, time" in str(res.exception)


@pytest.fixture(scope="module")
def episode_log(tmp_path_factory):
    """A real log: 60 ticks of PM-Nav on the test doubles in fig2_hospital's map."""
    from rig import build_rig

    from pmnav_bt.map.catalogue import load_building
    from pmnav_bt.map.priori_map import parse_building
    from pmnav_bt.seams import Pose2D

    pm = parse_building(load_building("fig2_hospital"))
    rig = build_rig("doubles", pm, Pose2D(22.0, 0.0, 0.0))
    path = tmp_path_factory.mktemp("episode") / "tree.jsonl"
    with open(path, "w", encoding="utf-8") as out:
        outcome = rig.mission("room17", max_ticks=60, log=out)
    assert outcome.ticks == 60
    return path


def test_replay_of_a_real_episode(episode_log):
    rp = Replay.load(episode_log)
    assert len(rp.ticks) == 60
    first = invoke("replay", episode_log, "--tick", 0, "--visited-only").stdout
    assert "✔ CheckGoal [CheckGoal] -- goal room17" in first
    assert "* LocalizeViews [CaptureViews]" in first
    assert "Monitor [Monitor] -- 0/500 actions" in first
    fixed = next(t for t in rp.ticks if t["status"].get(_id(rp, "LocalizeFix")) == "SUCCESS")
    text = invoke("replay", episode_log, "--tick", fixed["tick"], "--visited-only").stdout
    assert "✔ Localize [Retry] -- succeeded" in text
    assert "✔ LocalizeFix [FixFromBelief] -- at (" in text


def _id(rp: Replay, name: str) -> str:
    return next(n["id"] for n in rp.nodes if n["name"] == name)
