"""results.jsonl as a store that survives kills: one row per finished run, keyed, resumable.

Every row carries ``key`` (the variant and episode id), ``episode_sha`` (a hash of the
episode: start, goal, seed, building hash) and ``config_sha`` (a hash of the variant's
whole config). ``--resume`` reads the rows back, skips the keys already there, and refuses,
in one line, when a row was made under another config or for another episode of the same
id: results of two configurations never mix silently. A torn last line (the process was
killed mid-write) is dropped and the file truncated to its last whole line before
appending; a broken line anywhere else is an error. A row that cannot be written (a
full disk) is cut off again, so the file never holds half a row of this session.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pmnav_bt.errors import PmNavError
from pmnav_bt.interrupts import signals_deferred


class ResumeError(PmNavError):
    """The results on disk cannot be resumed with this run (another config or episode)."""


class ResultsWriteError(OSError):
    """A row could not be written (the disk is full); the file holds every earlier row.

    An OSError, as the failure is the machine's, not the user's: the command line prints
    ``<file>: <what happened>; it keeps the N runs finished before ...`` and exits 1."""


def record_key(variant: str, run_id: str) -> str:
    return f"{variant}/{run_id}"


def stable_hash(data: Any) -> str:
    """A short hash of JSON-able ``data`` (keys sorted)."""
    text = json.dumps(data, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class Expected:
    """What this run would write for one key."""

    key: str
    variant: str
    item_sha: str
    config_sha: str


def read_rows(path: Path) -> tuple[list[dict], int]:
    """The rows of a results.jsonl and the byte length of its whole lines. A last line
    without its newline is the torn write of a kill: dropped unless it parses whole.
    ResumeError for a broken line that ends in a newline (damage, not a kill)."""
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        return [], 0
    *lines, tail = data.split(b"\n")
    rows, end = [], 0
    for i, raw in enumerate(lines, 1):
        end += len(raw) + 1
        if not raw.strip():
            continue
        row = _row(raw)
        if row is None:
            raise ResumeError(
                f"{path}: line {i} is not a JSON object; the file is damaged (move it aside, "
                "or run without --resume to start afresh)"
            )
        rows.append(row)
    row = _row(tail) if tail.strip() else None
    if row is not None:
        rows.append(row)
        end = len(data)
    return rows, end


def _row(raw: bytes) -> dict | None:
    try:
        row = json.loads(raw)
    except ValueError:
        return None
    return row if isinstance(row, dict) else None


class ResultStore:
    """Append rows to ``path``; with ``resume``, keep (and report) the rows already there.

    ``done`` maps each kept key to its row. Rows for keys this run does not expect (an
    earlier, larger run) stay in the file and out of ``done``.
    """

    def __init__(self, path: Path, expected: Iterable[Expected], resume: bool):
        self.path = Path(path)
        self.expected = {e.key: e for e in expected}
        self.done: dict[str, dict] = {}
        self.duplicates = 0
        self.count = 0
        if resume:
            rows, end = read_rows(self.path)
            self._check(rows)
            for row in rows:
                k = row.get("key")
                if k in self.expected:
                    if k in self.done:
                        self.duplicates += 1
                    else:
                        self.done[k] = row
            if self.path.exists() and end < self.path.stat().st_size:
                with open(self.path, "r+b") as f:
                    f.truncate(end)
            if end and not self.path.read_bytes().endswith(b"\n"):
                with open(self.path, "ab") as f:
                    f.write(b"\n")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        mode = os.O_WRONLY | os.O_CREAT | os.O_APPEND | (0 if resume else os.O_TRUNC)
        self._fd = os.open(self.path, mode, 0o644)

    def _check(self, rows: list[dict]) -> None:
        configs = {e.variant: e.config_sha for e in self.expected.values()}
        for i, row in enumerate(rows, 1):
            variant, key = row.get("variant"), row.get("key")
            if key is None or "config_sha" not in row:
                raise ResumeError(
                    f"--resume: {self.path} line {i} has no key/config_sha (written by an "
                    "older pmnav); use another --out or run without --resume"
                )
            if variant in configs and row["config_sha"] != configs[variant]:
                raise ResumeError(
                    f"--resume: {self.path} holds {variant} results made under another config "
                    f"(config hash {row['config_sha']}, this run {configs[variant]}); "
                    "use another --out, or run without --resume to start afresh"
                )
            e = self.expected.get(key)
            if e is not None and row.get("item_sha") != e.item_sha:
                raise ResumeError(
                    f"--resume: {self.path}: {key} was run for a different episode (another "
                    "seed, building file or tier rule); use another --out or drop --resume"
                )

    def todo(self, keys: Iterable[str]) -> list[str]:
        """The keys not done yet, in the order given."""
        return [k for k in keys if k not in self.done]

    def write(self, key: str, row: dict) -> dict:
        e = self.expected[key]
        full = {
            "variant": e.variant,
            "key": key,
            "item_sha": e.item_sha,
            "config_sha": e.config_sha,
            **row,
        }
        with signals_deferred():  # Ctrl-C between the line and its count would miscount
            self._append((json.dumps(full) + "\n").encode())
            self.done[key] = full
            self.count += 1
        return full

    def _append(self, data: bytes) -> None:
        """Add ``data`` (one row) at the end of the file, synced, whole or not at all: a
        write that fails midway (a full disk, a file-size limit) is cut off again, so the
        file keeps exactly the rows finished before it. ResultsWriteError says so."""
        start = os.fstat(self._fd).st_size
        try:
            view = memoryview(data)
            while view:  # a write may take only part (the last bytes before a limit)
                view = view[os.write(self._fd, view) :]
            os.fsync(self._fd)
        except OSError as err:
            with contextlib.suppress(OSError):
                os.ftruncate(self._fd, start)
            kept = len(self.done)
            raise ResultsWriteError(
                err.errno,
                f"{err.strerror}; it keeps the {kept} run{'' if kept == 1 else 's'} finished "
                "before (go on with --resume when there is room)",
                str(self.path),
            ) from None

    def close(self) -> None:
        os.close(self._fd)

    def __enter__(self) -> ResultStore:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
