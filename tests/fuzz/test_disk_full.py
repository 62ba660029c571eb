"""Results written while the disk fills (issue 42): ``results.jsonl`` keeps every finished
episode whole, and the command says what happened in one line, exiting non-zero.

A child process runs under RLIMIT_FSIZE, the file-size limit: a write past it fails with
EFBIG as a write to a full disk fails with ENOSPC (SIGXFSZ, which would kill the child
first, is ignored), while the rest of the machine keeps its space.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import pytest
from evalproc import eval_argv, rows
from fuzzkit import TRIED, one_line

pytestmark = [
    pytest.mark.timeout(180),
    pytest.mark.skipif(sys.platform != "linux", reason="RLIMIT_FSIZE and SIGXFSZ"),
]

LIMITED = """
import resource, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
resource.setrlimit(resource.RLIMIT_FSIZE, ({limit}, {limit}))
"""


def limited(limit: int, body: str, *argv: str, timeout: float = 120):
    """Run ``body`` (Python) in a child whose files may not grow past ``limit`` bytes."""
    code = LIMITED.format(limit=limit) + textwrap.dedent(body)
    return subprocess.run(
        [sys.executable, "-c", code, *argv], capture_output=True, text=True, timeout=timeout
    )


def test_the_store_keeps_every_row_written_before_the_disk_filled(tmp_path):
    """The result store alone, quick: rows of 200 bytes into a file limited to 1,000."""
    TRIED["results.jsonl: disk full"] += 1
    body = """
    from pathlib import Path
    from pmnav_bt.experiments.runstore import Expected, ResultStore, ResultsWriteError
    keys = [f"v/e{i}" for i in range(10)]
    store = ResultStore(Path(sys.argv[1]), [Expected(k, "v", "i", "c") for k in keys], False)
    try:
        for k in keys:
            store.write(k, {"pad": "x" * 130})
    except ResultsWriteError as err:
        print(store.count, err, sep="\\n")
    """
    path = tmp_path / "results.jsonl"
    res = limited(1000, body, str(path))
    assert res.returncode == 0, res.stderr
    count, message = res.stdout.strip().splitlines()
    lines = path.read_bytes().splitlines(keepends=True)
    written = [json.loads(line) for line in lines]
    assert len(written) == int(count) == 1000 // len(lines[0])  # every row that fitted
    assert path.read_bytes().endswith(b"\n")  # and no half row after them
    assert [r["key"] for r in written] == [f"v/e{i}" for i in range(len(written))]
    assert f"it keeps the {count} runs finished before" in message and "File too large" in message


def test_sim_eval_on_a_full_disk_says_so_in_one_line(tmp_path):
    TRIED["sim eval: disk full"] += 1
    out = tmp_path / "eval"
    row = 700  # bytes: one results.jsonl row is about 550-650
    body = """
    from pmnav_bt.experiments.cli import main
    main(sys.argv[1:])
    """
    argv = eval_argv(out, 3, 1)[3:]  # the pmnav arguments, without python -m ...
    res = limited(row + 100, body, *argv, timeout=150)
    assert res.returncode == 1, res.stderr[-2000:]
    assert "Traceback" not in res.stderr
    last = one_line(res.stderr.strip().splitlines()[-1], "results.jsonl", "File too large")
    done = rows(out / "results.jsonl")
    assert len(done) == 1 and (out / "results.jsonl").read_bytes().endswith(b"\n")
    assert "it keeps the 1 run finished before" in last and "--resume" in last
