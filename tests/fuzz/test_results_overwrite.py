"""Issue 42: an interrupted ``pmnav sim eval --out DIR`` replaced the results of an earlier,
different run in DIR with its partial ones. Now a folder of results is refused unless
the run resumes them or is told to ``--overwrite`` them, and an ``--overwrite`` run
writes beside them until it has finished: stopped by a real SIGINT, it leaves them whole.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import pytest
from evalproc import eval_argv, rows, running, wait_for_rows
from fuzzkit import TRIED, one_line

pytestmark = [
    pytest.mark.timeout(240),
    pytest.mark.skipif(sys.platform != "linux", reason="process groups"),
]

EARLIER = {  # what an earlier, different run left (the guard reads names, not contents)
    "results.jsonl": b'{"variant": "mapless", "key": "mapless/e0", "config_sha": "0"}\n',
    "results.json": b'{"mapless": [{"episode_id": "e0", "success": true}]}',
    "results.md": b"# PM-Nav evaluation\n\nthe earlier run's table\n",
}


def _earlier(tmp_path):
    out = tmp_path / "eval"
    out.mkdir()
    for name, data in EARLIER.items():
        (out / name).write_bytes(data)
    return out


def _files(out) -> dict:
    return {p.name: p.read_bytes() for p in out.iterdir() if p.is_file()}


def test_interrupted_overwrite_leaves_the_earlier_results_whole(tmp_path):
    TRIED["sim eval: --overwrite interrupted"] += 1
    out = _earlier(tmp_path)
    refused = subprocess.run(eval_argv(out, 5, 1), capture_output=True, text=True, timeout=120)
    assert refused.returncode == 2
    one_line(refused.stderr, "earlier run", "--resume", "--overwrite")
    assert _files(out) == EARLIER

    staged = out / "overwriting"
    with running(eval_argv(out, 5, 1, "--overwrite")) as proc:
        wait_for_rows(proc, staged / "results.jsonl", 1)
        os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C: the whole process group
        _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "Traceback" not in err
    last = err.strip().splitlines()[-1]
    assert "stopped by SIGINT" in last and f"the earlier results in {out} are untouched" in last
    assert _files(out) == EARLIER  # not one byte of the earlier run replaced
    done = rows(staged / "results.jsonl")
    assert 1 <= len(done) < 5 and all(r["variant"] == "pmnav@clean" for r in done)
    assert "partial: stopped by SIGINT" in (staged / "results.md").read_text()


@pytest.mark.slow  # runs the five episodes to the end (about half a minute)
def test_resumed_overwrite_replaces_the_earlier_results_when_finished(tmp_path):
    out = _earlier(tmp_path)
    with running(eval_argv(out, 5, 1, "--overwrite")) as proc:
        wait_for_rows(proc, out / "overwriting" / "results.jsonl", 1)
        os.killpg(proc.pid, signal.SIGINT)
        proc.communicate(timeout=60)
    first = [r["key"] for r in rows(out / "overwriting" / "results.jsonl")]
    done = subprocess.run(
        eval_argv(out, 5, 1, "--resume"), capture_output=True, text=True, timeout=200
    )
    assert done.returncode == 0, done.stderr
    assert f"{len(first)} of 5 runs done" in done.stderr
    keys = [r["key"] for r in rows(out / "results.jsonl")]
    assert len(keys) == 5 and keys[: len(first)] == first  # the new run's, whole
    assert b"earlier" not in (out / "results.md").read_bytes()
    assert not (out / "overwriting").exists()
