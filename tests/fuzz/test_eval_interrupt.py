"""``pmnav sim eval`` stopped mid-run by SIGINT (Ctrl-C, to the whole process group, as a
terminal sends it) and by SIGTERM (to the parent only, as a service manager sends it):
the finished episodes are on disk, one line says so, and no process is left behind."""

from __future__ import annotations

import json
import os
import signal
import sys
import time

import pytest
from evalproc import eval_argv, rows, running, wait_for_rows
from fuzzkit import TRIED, one_line

pytestmark = pytest.mark.timeout(180)  # bounded time, whatever regresses


def _session(sid: int) -> list[int]:
    """Live (non-zombie) processes of session ``sid``."""
    out = []
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open(f"/proc/{d}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[3]) == sid and fields[0] != "Z":
            out.append(int(d))
    return out


@pytest.mark.skipif(sys.platform != "linux", reason="reads /proc")
@pytest.mark.parametrize("signame, jobs", [("SIGINT", 2), ("SIGTERM", 2)])
def test_eval_interrupted_keeps_finished_episodes(tmp_path, signame, jobs):
    TRIED["sim eval: interrupted mid-run"] += 1
    out = tmp_path / "eval"
    with running(eval_argv(out, 40, jobs)) as proc:
        wait_for_rows(proc, out / "results.jsonl", 2)
        if jobs > 1:
            assert len(_session(proc.pid)) > 1  # the pool's workers are running
        sig = getattr(signal, signame)
        if signame == "SIGINT":
            os.killpg(proc.pid, sig)
        else:
            proc.send_signal(sig)
        _, err = proc.communicate(timeout=60)
    assert proc.returncode == (130 if signame == "SIGINT" else 143)
    assert "Traceback" not in err
    last = one_line(err.strip().splitlines()[-1], f"stopped by {signame}", "results.jsonl")
    done = rows(out / "results.jsonl")
    assert len(done) == len((out / "results.jsonl").read_text().splitlines())  # none torn
    assert 2 <= len(done) < 40 and f"after {len(done)} of 40" in last
    assert len({r["episode_id"] for r in done}) == len(done)
    saved = json.loads((out / "results.json").read_text())  # whole, written atomically
    assert len(saved["pmnav@clean"]) == len(done)
    time.sleep(0.5)
    assert _session(proc.pid) == [], "processes left behind"


@pytest.mark.skipif(sys.platform != "linux", reason="process groups")
def test_table3_interrupted_keeps_a_partial_table(tmp_path):
    TRIED["sim table3: interrupted mid-run"] += 1
    out = tmp_path / "t3"
    argv = [
        sys.executable, "-m", "pmnav_bt.experiments.cli", "sim", "table3",
        "--building", "straight_office", "-n", "3", "--set", "grounder.backend=sim_gt",
        "--out", str(out),
    ]  # fmt: skip
    with running(argv) as proc:
        wait_for_rows(proc, out / "results.jsonl", 1)
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "Traceback" not in err
    done = rows(out / "results.jsonl")
    last = err.strip().splitlines()[-1]
    assert f"stopped by SIGINT after {len(done)} of " in last and "--resume" in last
    total = int(last.split(" of ")[1].split()[0])
    assert 1 <= len(done) < total
    assert "PARTIAL: stopped by SIGINT" in (out / "results.md").read_text()
