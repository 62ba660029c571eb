"""Helpers of the bad-input suite (issue 16): run the CLI, check the one-line contract, count.

``pmnav_cli`` runs ``pmnav`` in-process (fast); ``pmnav_subprocess`` runs it in a child
with a timeout and an address-space limit, for the classes that used to crash, hang or
blow up memory, so a regression fails the test instead of taking pytest down with it.
Each test adds the inputs it tried to ``TRIED``; the totals per class are printed at the
end of the run.
"""

from __future__ import annotations

import resource
import subprocess
import sys
from collections import Counter
from pathlib import Path

import pytest

from pmnav_bt.experiments.cli import main

TRIED: Counter[str] = Counter()
MEMORY_LIMIT = 3 << 30  # bytes of address space for a CLI child
TIMEOUT_S = 60


def one_line(err: str, *words: str) -> str:
    """The single stderr line; asserts there is exactly one, no traceback, and ``words``.

    ``pmnav validate`` lists every problem and then counts them: its "1 problem(s)" line
    is that count, not a second message."""
    lines = err.strip("\n").splitlines()
    if len(lines) == 2 and lines[1] == "1 problem(s)":
        lines = lines[:1]
    assert "Traceback" not in err, err
    assert len(lines) == 1, f"expected one line on stderr, got {len(lines)}:\n{err[:2000]}"
    for w in words:
        assert w in lines[0], f"{w!r} not in {lines[0]!r}"
    return lines[0]


def pmnav_cli(capsys, *argv: str | Path) -> tuple[int, str, str]:
    """``pmnav ARGV`` in this process: (exit status, stdout, stderr)."""
    with pytest.raises(SystemExit) as info:
        main([str(a) for a in argv])
    out, err = capsys.readouterr()
    code = info.value.code
    return (code if isinstance(code, int) else 1), out, err


def _limit_memory() -> None:  # pragma: no cover - runs in the child
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, MEMORY_LIMIT))


def pmnav_subprocess(*argv: str | Path, timeout: float = TIMEOUT_S, **kw):
    """``pmnav ARGV`` in a child process with a timeout and RLIMIT_AS."""
    return subprocess.run(
        [sys.executable, "-m", "pmnav_bt.experiments.cli", *map(str, argv)],
        capture_output=True,
        text=True,
        timeout=timeout,
        preexec_fn=_limit_memory,
        check=False,
        **kw,
    )


def assert_clean_failure(res, *words: str) -> str:
    """A child that failed cleanly: non-zero, not killed by a signal, one line naming words."""
    assert res.returncode > 0, f"status {res.returncode}; stderr: {res.stderr[-2000:]}"
    return one_line(res.stderr, *words)
