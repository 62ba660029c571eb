"""The records the web view shows, from wherever they come.

A :class:`Feed` holds one run's tree (its nodes), its tick records in the page's compact
form, the camera frames apart (served one by one, not in the page's first download),
and one line of error or warning. Three sources fill it:

- a log read whole (``Feed.load``: replay); a bad log is a PmNavError, one line;
- a log followed as it grows (:class:`LogFollower`, a thread polling the file);
- the lines a running tree writes (:class:`FeedWriter`, the tree log's second sink:
  its ``write`` only queues the text; a thread of its own parses and checks it, so a
  tick is not slowed by the view).

Every record is checked by ``pmnav_bt.treelog`` as ``pmnav tree replay`` checks it. In
a followed log, a bad line stops the feed with its one-line error (the page and the
command line show it), and a second tree record starts a new run (a node appends each
goal's tree to one log). The page waits on :meth:`Feed.wait` (Server-Sent Events).
"""

from __future__ import annotations

import base64
import binascii
import os
import queue
import stat
import threading
import time
from pathlib import Path
from typing import Any

from pmnav_bt.errors import PmNavError
from pmnav_bt.loading import MAX_BYTES
from pmnav_bt.treelog import TreeLogLines, read_tree_log

STATUS_LETTER = {"SUCCESS": "S", "FAILURE": "F", "RUNNING": "R", "INVALID": "I"}
MAX_LOG_BYTES = MAX_BYTES["tree log"]  # as pmnav tree replay reads
MAX_LINE_BYTES = 64 << 20  # one record; a longer line is no tree log's
POLL_S = 0.2  # how often a followed log is looked at


class Feed:
    """One run's records for the page (see the module docstring).

    ``source``: what the records come from, for the page's title and errors; ``live``:
    more may come; ``building``: the map to draw (default: the one the log names)."""

    def __init__(self, source: str, live: bool, building: str | None = None) -> None:
        self.source = source
        self.live = live
        self.building = building
        self._cond = threading.Condition()
        self._lines = TreeLogLines(source, new_runs=live)
        self._line_no = 0
        self._bytes = 0
        self.run = 0  # counts tree records: a new run makes the page start again
        self.header: dict = {}
        self.nodes: list[dict] = []
        self._index: dict[str, int] = {}
        self.ticks: list[dict] = []
        self.frames: dict[int, bytes] = {}
        self.error = ""
        self.warning = ""
        self.ended = False  # no more records will come (the run's writer closed)

    # -- filling ---------------------------------------------------------------------------

    def load(self, path: str | Path) -> Feed:
        """Read a whole log (replay); PmNavError names the file, line and fault."""
        log = read_tree_log(path)
        with self._cond:
            self._start(log.header, log.nodes)
            self.ticks = [self._compact(t) for t in log.ticks]
            self.warning = log.warning
            self.ended = True
        return self

    def add_line(self, line: str) -> None:
        """One line of a log being written (its newline stripped)."""
        with self._cond:
            if self.error:
                return
            self._line_no += 1
            self._bytes += len(line) + 1
            if not line.strip():
                return
            try:
                if self._bytes > MAX_LOG_BYTES:
                    raise PmNavError(
                        f"{self.source}: the log passed {MAX_LOG_BYTES >> 20} MiB, the most "
                        "the view reads; it stopped following"
                    )
                rec = self._lines.add(self._line_no, line)
            except PmNavError as err:
                self._fail(str(err))
                return
            if rec.get("type") == "tree":
                self._start(self._lines.header, self._lines.nodes or [])
            elif rec.get("type") == "tick":
                self._lines.ticks.clear()  # kept here, compacted
                self.ticks.append(self._compact(rec))
            self._cond.notify_all()

    def fail(self, message: str) -> None:
        """Stop with one line of error (the page and the command line show it)."""
        with self._cond:
            self._fail(message)

    def _fail(self, message: str) -> None:
        if not self.error:
            self.error = message
        self._cond.notify_all()

    def note(self, message: str) -> None:
        """A warning line for the page (empty: none)."""
        with self._cond:
            self.warning = message
            self._cond.notify_all()

    def end(self) -> None:
        """No more records will come."""
        with self._cond:
            self.ended = True
            self._cond.notify_all()

    def restart(self) -> None:
        """The followed file was replaced: read it again from its start."""
        with self._cond:
            self._lines = TreeLogLines(self.source, new_runs=self.live)
            self._line_no = self._bytes = 0
            self.error = ""
            self._start({}, [])

    def _start(self, header: dict, nodes: list[dict]) -> None:
        self.run += 1
        self.header, self.nodes = dict(header), list(nodes)
        self._index = {n["id"]: k for k, n in enumerate(self.nodes)}
        self.ticks, self.frames = [], {}
        self._cond.notify_all()

    def _compact(self, rec: dict) -> dict:
        """A tick record as the page takes it: node ids as indices into ``nodes``, one
        letter a status, the camera frame's JPEG kept apart (``frame.id``)."""
        idx = self._index
        out: dict[str, Any] = {
            "i": rec["tick"],
            "t": rec["time"],
            "s": {idx[k]: STATUS_LETTER[v] for k, v in rec["status"].items() if k in idx},
            "f": {idx[k]: v for k, v in rec["feedback"].items() if k in idx},
            "b": rec["blackboard"],
        }
        view = rec.get("view")
        if view:
            view = dict(view)
            frame = view.get("frame")
            if frame:
                frame = dict(frame)
                fid = len(self.ticks)
                try:
                    self.frames[fid] = base64.b64decode(frame.pop("jpeg"), validate=True)
                    frame["id"] = fid
                except (binascii.Error, ValueError):
                    frame["id"] = None
                view["frame"] = frame
            out["v"] = view
        return out

    # -- reading -------------------------------------------------------------------------

    def snapshot(self) -> dict:
        """Everything so far, for the page's first download."""
        with self._cond:
            return {
                "source": self.source,
                "live": self.live,
                "run": self.run,
                "header": self.header,
                "nodes": self.nodes,
                "ticks": list(self.ticks),
                "error": self.error,
                "warning": self.warning,
                "ended": self.ended,
            }

    def wait(self, run: int, have: int, timeout: float, most: int = 500) -> dict | None:
        """What came after the page's first ``have`` ticks of run ``run``: at most
        ``most`` new ticks, a new run, an error or the end; None after ``timeout``
        seconds of nothing."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                if run != self.run:
                    return {"reset": True}
                if len(self.ticks) > have or self.error or self.ended:
                    return {
                        "from": have,
                        "ticks": self.ticks[have : have + most],
                        "error": self.error,
                        "warning": self.warning,
                        "ended": self.ended and have + most >= len(self.ticks),
                    }
                left = deadline - time.monotonic()
                if left <= 0:
                    return None
                self._cond.wait(left)

    def frame(self, fid: int) -> bytes | None:
        with self._cond:
            return self.frames.get(fid)


class _Lines:
    """Splits text into lines for a Feed, holding a part line until its newline."""

    def __init__(self, feed: Feed) -> None:
        self.feed = feed
        self.part = b""

    def add(self, data: bytes) -> None:
        *lines, self.part = (self.part + data).split(b"\n")
        for raw in lines:
            self._line(raw)
        if len(self.part) > MAX_LINE_BYTES:
            self.feed.fail(f"{self.feed.source}: a line longer than {MAX_LINE_BYTES >> 20} MiB")
            self.part = b""

    def _line(self, raw: bytes) -> None:
        try:
            text = raw.decode("utf-8")
        except UnicodeDecodeError:
            self.feed.fail(f"{self.feed.source}: not a tree log (not UTF-8 text)")
            return
        self.feed.add_line(text.rstrip("\r"))


class FeedWriter:
    """The tree log's second sink for a live view: ``write`` queues the text and returns
    (a few microseconds in the tick); a daemon thread splits and checks it."""

    def __init__(self, feed: Feed) -> None:
        self.feed = feed
        self._queue: queue.SimpleQueue[str | None] = queue.SimpleQueue()
        self._thread = threading.Thread(target=self._drain, name="pmnav-view-feed", daemon=True)
        self._thread.start()

    def write(self, text: str) -> int:
        self._queue.put(text)
        return len(text)

    def flush(self) -> None:
        """Nothing to flush: the lines are queued already."""

    def close(self) -> None:
        """Feed what is queued, then say the run ended (again: nothing more)."""
        if self._thread.is_alive():
            self._queue.put(None)
            self._thread.join()

    def _drain(self) -> None:
        lines = _Lines(self.feed)
        while (text := self._queue.get()) is not None:
            lines.add(text.encode("utf-8"))
        self.feed.end()


class LogFollower:
    """Follows a log file as a run writes it (``pmnav view --follow``): waits for the file
    to appear, reads what was added every ``POLL_S`` seconds, and starts again when the
    file shrinks (a new run wrote it afresh)."""

    def __init__(self, path: Path, feed: Feed) -> None:
        self.path = path
        self.feed = feed
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="pmnav-view-follow", daemon=True)

    def start(self) -> LogFollower:
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self._thread.join()

    def _run(self) -> None:
        offset, lines, waiting = 0, _Lines(self.feed), False
        while not self._stop.is_set():
            try:
                st = os.stat(self.path)
            except FileNotFoundError:
                if not waiting:
                    self.feed.note(f"{self.path}: waiting for the run to write it")
                    waiting = True
                self._stop.wait(POLL_S)
                continue
            except OSError as err:
                self.feed.fail(f"{self.path}: cannot read tree log file: {err.strerror}")
                return
            if not stat.S_ISREG(st.st_mode):
                self.feed.fail(f"{self.path}: not a regular file; give a tree log file")
                return
            if waiting:
                self.feed.note("")
                waiting = False
            size = st.st_size
            if size < offset:
                self.feed.restart()
                offset, lines = 0, _Lines(self.feed)
            if size > offset:
                offset += self._read(offset, lines)
            self._stop.wait(POLL_S)

    def _read(self, offset: int, lines: _Lines) -> int:
        fd = os.open(self.path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as f:
            f.seek(offset)
            data = f.read(8 << 20)
        lines.add(data)
        return len(data)
