"""A real ``pmnav sim eval`` sent SIGINT mid-run leaves valid partial results and a partial
table; ``--resume`` then runs only the rest (every episode exactly once), and refuses in
one line when the config changed."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import pytest
from evalproc import eval_argv, rows, running, wait_for_rows

pytestmark = [
    pytest.mark.timeout(240),
    pytest.mark.skipif(sys.platform != "linux", reason="process groups"),
]

N = 5


def _keys(path) -> list[str]:
    return [r["key"] for r in rows(path)]


def test_sigint_keeps_a_partial_table_and_resume_runs_only_the_rest(tmp_path):
    out = tmp_path / "eval"
    with running(eval_argv(out, N, 1)) as proc:
        wait_for_rows(proc, out / "results.jsonl", 2)
        os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C: the whole process group
        _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "Traceback" not in err
    first = _keys(out / "results.jsonl")
    assert 2 <= len(first) < N and len(set(first)) == len(first)
    assert "--resume" in err.strip().splitlines()[-1]
    table = (out / "results.md").read_text()
    assert f"partial: stopped by SIGINT, {len(first)} of {N} runs" in table
    assert "| easy |" in table

    done = subprocess.run(
        eval_argv(out, N, 1, "--resume"), capture_output=True, text=True, timeout=180
    )
    assert done.returncode == 0, done.stderr
    assert f"{len(first)} of {N} runs done" in done.stderr
    keys = _keys(out / "results.jsonl")
    assert len(keys) == N and len(set(keys)) == N and keys[: len(first)] == first
    assert "partial" not in (out / "results.md").read_text()

    changed = subprocess.run(
        eval_argv(out, N, 1, "--resume", "--set", "sim.width=200"), capture_output=True, text=True
    )
    assert changed.returncode == 2
    assert len(changed.stderr.strip().splitlines()) == 1
    assert "another config" in changed.stderr
    assert _keys(out / "results.jsonl") == keys  # nothing written
