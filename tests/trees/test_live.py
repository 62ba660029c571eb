"""``--show-tree``: the LiveTree post-tick handler draws the tree with statuses and feedback,
in place on a terminal (throttled) or printed on changes elsewhere, in replay's format."""

from __future__ import annotations

import io

import py_trees
from countdown import Countdown
from py_trees.common import Status
from rich.console import Console

from pmnav_bt.trees.live import LiveTree, styled, tick_record
from pmnav_bt.trees.snapshots import Replay, SnapshotLogger


def small_tree() -> py_trees.trees.BehaviourTree:
    """Ticks 0-1: First runs; 2: First done, Second runs; 3: Second done, root succeeds."""
    job = py_trees.composites.Sequence(
        "Job", memory=True, children=[Countdown("First", 2), Countdown("Second", 1)]
    )
    root = py_trees.composites.Parallel(
        "Root",
        policy=py_trees.common.ParallelPolicy.SuccessOnOne(),
        children=[py_trees.behaviours.Running(name="Watch"), job],
    )
    return py_trees.trees.BehaviourTree(root)


def run(tree: py_trees.trees.BehaviourTree, handler, max_ticks: int = 10) -> None:
    tree.add_post_tick_handler(handler)
    while tree.root.status != Status.SUCCESS and tree.count < max_ticks:
        tree.tick()


def blocks(text: str) -> list[str]:
    return [b for b in text.strip().split("\n\n") if b]


def test_printed_ticks_read_like_replay(tmp_path):
    tree = small_tree()
    log = io.StringIO()
    clock = lambda: tree.count * 0.5  # noqa: E731
    tree.add_post_tick_handler(SnapshotLogger(tree, log, clock_now=clock))
    out = io.StringIO()
    show = LiveTree(Console(file=out, width=200), now=clock)
    assert not show.live_mode  # a StringIO is not a terminal
    run(tree, show)
    path = tmp_path / "tree.jsonl"
    path.write_text(log.getvalue())
    rp = Replay.load(path)
    printed = blocks(out.getvalue())
    # tick 0 (first), 2 (First done, Second runs), 3 (the end); tick 1 changed no status
    assert [b.splitlines()[0] for b in printed] == [
        "tick 0  t=0.0 s",
        "tick 2  t=1.0 s",
        "tick 3  t=1.5 s",
    ]
    for block, t in zip(printed, [rp.ticks[0], rp.ticks[2], rp.ticks[3]], strict=True):
        assert block == rp.render(t, visited_only=True)
    assert (
        "        ✔ First [Countdown] -- done\n        * Second [Countdown] -- 1 to go" in printed[1]
    )
    assert printed[2].splitlines()[1] == "✔ Root [Parallel]"


def test_every_nth_tick_without_change_detection():
    tree = small_tree()
    out = io.StringIO()
    job = tree.root.children[1]
    job.children[0].n = 6  # First runs for ticks 0-5, Second for 6, done at 7
    run(tree, LiveTree(Console(file=out, width=200), on_change=False, every=3))
    heads = [b.splitlines()[0] for b in blocks(out.getvalue())]
    assert heads == ["tick 0", "tick 3", "tick 6", "tick 7"]


def test_first_tick_without_a_visitor_shows_what_ran():
    tree = small_tree()
    assert not tree.visitors
    rec = tick_record(tree, None)
    assert rec["status"] == {}  # nothing has run yet
    tree.tick()
    rec = tick_record(tree, None)
    names = {str(n.id): n.name for n in tree.root.iterate()}
    assert {names[k]: v for k, v in rec["status"].items()} == {
        "Root": "RUNNING",
        "Watch": "RUNNING",
        "Job": "RUNNING",
        "First": "RUNNING",
    }
    show = LiveTree(Console(file=io.StringIO(), width=200))
    show(tree)  # attaches its own visitor for the next ticks
    assert any(isinstance(v, py_trees.visitors.SnapshotVisitor) for v in tree.visitors)
    assert "* First [Countdown] -- 2 to go" in show.text(tree, None)


def terminal() -> tuple[Console, io.StringIO]:
    out = io.StringIO()
    return Console(file=out, force_terminal=True, width=100, height=40), out


def test_live_redraws_in_place_with_statuses():
    console, out = terminal()
    show = LiveTree(console, max_fps=0)  # no throttle: a frame per tick
    assert show.live_mode
    with show:
        run(small_tree(), show)
    assert show.frames == 4
    screen = out.getvalue()
    assert "\x1b[" in screen  # styled and redrawn with cursor movement
    assert "First [Countdown]" in screen and " -- done" in screen and "tick 3" in screen


def test_live_is_throttled_but_shows_the_last_tick():
    console, out = terminal()
    show = LiveTree(console, max_fps=1e-6)  # one frame, then only the end
    with show:
        run(small_tree(), show)
    assert show.frames == 2  # tick 0, and tick 3 where the root succeeded
    console, out = terminal()
    show = LiveTree(console, max_fps=1e-6)
    with show:
        run(small_tree(), show, max_ticks=2)  # stops while running
    assert show.frames == 2  # tick 0, then tick 1 drawn on close
    assert "tick 1" in out.getvalue() and "1 to go" in out.getvalue()


def test_styled_colours_marks_and_dims_feedback():
    text = styled("tick 3  t=None\n✔ Root [Parallel]\n    ✘ A [B] -- why\n    · C [D]")
    styles = {text.plain[s.start : s.end]: str(s.style) for s in text.spans}
    assert styles["✔ Root [Parallel]"] == "bold green"
    assert styles["✘ A [B]"] == "bold red"
    assert styles[" -- why"] == "dim"
    assert styles["tick 3  t=None"] == "bold"


def test_a_tree_taller_than_the_terminal_keeps_its_deepest_lines():
    out = io.StringIO()
    console = Console(file=out, force_terminal=True, width=100, height=5)
    tree = small_tree()
    show = LiveTree(console, visited_only=False, max_fps=0)
    assert "Second [Countdown]" in show.text(tree)  # usable before the first tick
    with show:
        run(tree, show, max_ticks=1)
    screen = out.getvalue()
    assert "tick 0" in screen and "lines above" in screen
    assert "Second [Countdown]" in screen  # the last line of the tree
    assert "Watch [Running]" not in screen  # cut from the top
