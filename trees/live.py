"""The tree's statuses in the terminal while it runs (``--show-tree``).

:class:`LiveTree` is a post-tick handler (``run_tree(..., on_tick=LiveTree(...))``). On a
terminal it redraws the tree in place with ``rich.live.Live``, at most ``max_fps`` times a
second of wall time, so that a fast simulated run is not slowed by drawing; elsewhere (a pipe,
a CI log) it prints the tree only when a status changed or every ``every`` ticks, so logs stay
short. Both use the format of ``pmnav tree replay`` (:meth:`Replay.render`): one line per
node, ``✔`` success, ``✘`` failure, ``*`` running, ``-`` invalid, ``·`` not ticked, then the
feedback message.

Between frames a call costs about a microsecond (a clock read). A frame of the visited
part of the PM-Nav tree costs about 0.1 ms to format and 1 ms with rich's redraw; the whole
57-node tree about 2 ms, so ``visited_only`` is the default.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import TextIO

import py_trees
from py_trees.common import Status
from rich.console import Console
from rich.live import Live
from rich.text import Text

from pmnav_bt.trees.snapshots import Replay, structure

STATUS_STYLE = {"✔": "bold green", "✘": "bold red", "*": "bold cyan", "-": "dim", "·": "dim"}


def tick_record(
    tree: py_trees.trees.BehaviourTree,
    visited: dict | None,
    now: Callable[[], float] | None = None,
    status_when_visited: bool = False,
) -> dict:
    """The tree's state after a tick, as a snapshot-log tick record (without blackboard).

    ``visited`` is a SnapshotVisitor's ``visited`` map; None takes every node whose status
    is not INVALID as visited (the first tick, before a visitor was attached). Statuses are
    the nodes' statuses now, as the snapshot log records them (a node a parallel stopped
    shows INVALID), or with ``status_when_visited`` those the visitor saw (for drawing a
    tick after the tree was interrupted)."""
    status, feedback = {}, {}
    for node in tree.root.iterate():
        if visited is None:
            st = node.status
            if st == Status.INVALID:
                continue
        else:
            seen = visited.get(node.id)
            if seen is None:
                continue
            st = seen if status_when_visited else node.status
        key = str(node.id)
        status[key] = st.name
        if node.feedback_message:
            feedback[key] = node.feedback_message
    return {
        "tick": tree.count,
        "time": round(now(), 3) if now is not None else None,
        "status": status,
        "feedback": feedback,
        "blackboard": {},
    }


def styled(text: str) -> Text:
    """Colour a rendered tree (``Replay.render``'s format): the status mark and name by
    status, the feedback message dim."""
    out = Text()
    for i, line in enumerate(text.split("\n")):
        if i:
            out.append("\n")
        body = line.lstrip(" ")
        mark = body[:1]
        style = STATUS_STYLE.get(mark)
        if style is None or body[1:2] != " ":
            out.append(line, style="bold" if i == 0 else "")
            continue
        out.append(line[: len(line) - len(body)])
        head, sep, fb = body.partition(" -- ")
        out.append(head, style=style)
        if sep:
            out.append(sep + fb, style="dim")
    return out


class LiveTree:
    """A post-tick handler that shows the tree with statuses and feedback messages.

    Use it as a context manager so the live display is closed even if the run fails::

        with LiveTree(now=ctx.now) as show:
            run_tree(ctx, goal, on_tick=show)

    Args:
        console: where to draw; default a rich Console on stdout.
        live: redraw in place (rich Live); default: when the console is a terminal.
        visited_only: show only the nodes ticked in the last tick (shorter; default).
        max_fps: most redraws a second in live mode (wall time).
        every: in print mode, print at least every this many ticks (0: only on changes).
        on_change: in print mode, print when a status changed since the last tick.
        now: the tree's clock, for the time shown in the header.
    """

    def __init__(
        self,
        console: Console | None = None,
        *,
        live: bool | None = None,
        visited_only: bool = True,
        max_fps: float = 8.0,
        every: int = 500,
        on_change: bool = True,
        now: Callable[[], float] | None = None,
        file: TextIO | None = None,
    ):
        self.console = console or Console(file=file or sys.stdout)
        self.live_mode = self.console.is_terminal if live is None else live
        self.visited_only = visited_only
        self.min_interval = 1.0 / max_fps if max_fps > 0 else 0.0
        self.every = every
        self.on_change = on_change
        self.now = now
        self.frames = 0
        self._replay: Replay | None = None
        self._replay_root = None
        self._root = None
        self._visitor: py_trees.visitors.SnapshotVisitor | None = None
        self._live: Live | None = None
        self._last_draw = -float("inf")
        self._last_printed_tick: int | None = None
        self._pending: tuple[py_trees.trees.BehaviourTree, int] | None = None

    # -- handler -----------------------------------------------------------------------
    def __call__(self, tree: py_trees.trees.BehaviourTree) -> None:
        visited = self._attach(tree)
        done = tree.root.status != Status.RUNNING
        if self.live_mode:
            t = time.perf_counter()
            if t - self._last_draw < self.min_interval and not done:
                self._pending = (tree, tree.count)
                return
            self._last_draw = t
            self._pending = None
            self._draw_live(tree, visited)
            if done:
                self.close()
            return
        if self._should_print(tree, done):
            self._print(tree, visited)

    def _attach(self, tree: py_trees.trees.BehaviourTree) -> dict | None:
        """On the first call (or a new tree): find or add a SnapshotVisitor, and read the
        tree's structure. Returns the visited map of the last tick (None on the first)."""
        if self._root is not tree.root:
            self._root = tree.root
            self._visitor = next(
                (v for v in tree.visitors if isinstance(v, py_trees.visitors.SnapshotVisitor)),
                None,
            )
            if self._visitor is None:
                self._visitor = py_trees.visitors.SnapshotVisitor()
                tree.visitors.append(self._visitor)
                return None  # it has not seen a tick yet
        return self._visitor.visited

    def _should_print(self, tree: py_trees.trees.BehaviourTree, done: bool) -> bool:
        if self._last_printed_tick is None or done:
            return True
        if self.on_change and self._visitor is not None and self._visitor.changed:
            return True
        return self.every > 0 and tree.count - self._last_printed_tick >= self.every

    # -- output ------------------------------------------------------------------------
    def text(
        self,
        tree: py_trees.trees.BehaviourTree,
        visited: dict | None = None,
        count: int | None = None,
    ) -> str:
        """The tree after its last tick, as ``pmnav tree replay`` prints a tick."""
        if self._replay is None or self._replay_root is not tree.root:
            self._replay_root = tree.root
            self._replay = Replay(structure(tree.root), [])
        record = tick_record(tree, visited, self.now, status_when_visited=count is not None)
        if count is not None:
            record["tick"] = count
        return self._replay.render(record, self.visited_only)

    def _draw_live(
        self,
        tree: py_trees.trees.BehaviourTree,
        visited: dict | None,
        count: int | None = None,
    ) -> None:
        text = self.text(tree, visited, count)
        lines = text.split("\n")
        room = self.console.size.height - 1
        if len(lines) > room >= 3:  # keep the header and the deepest (running) lines
            hidden = len(lines) - room + 1
            text = "\n".join([lines[0], f"  ... {hidden} lines above ..."] + lines[-(room - 2) :])
        frame = styled(text)
        if self._live is None:
            self._live = Live(
                frame, console=self.console, auto_refresh=False, vertical_overflow="crop"
            )
            self._live.start(refresh=True)
        else:
            self._live.update(frame, refresh=True)
        self.frames += 1

    def _print(self, tree: py_trees.trees.BehaviourTree, visited: dict | None) -> None:
        self._last_printed_tick = tree.count
        self.console.print(self.text(tree, visited), markup=False, highlight=False, soft_wrap=True)
        self.console.print()
        self.frames += 1

    # -- lifecycle ---------------------------------------------------------------------
    def close(self) -> None:
        """Draw the last tick if it was skipped, and stop the live display (the last frame
        stays on screen)."""
        if self._pending is not None and self._visitor is not None:
            (tree, count), self._pending = self._pending, None
            self._draw_live(tree, self._visitor.visited, count)
        if self._live is not None:
            self._live.stop()
            self._live = None

    def __enter__(self) -> LiveTree:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
