"""``pmnav sim eval`` stopped mid-run by SIGINT (Ctrl-C, to the whole process group, as a
terminal sends it) and by SIGTERM (to the parent only, as a service manager sends it):
the finished episodes are on disk, one line says so, and no process is left behind."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import pytest
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


def _lines(path) -> list[dict]:
    try:
        text = path.read_text()
    except OSError:
        return []
    return [json.loads(x) for x in text.splitlines() if x.strip()]


@pytest.mark.skipif(sys.platform != "linux", reason="reads /proc")
@pytest.mark.parametrize("signame, jobs", [("SIGINT", 2), ("SIGTERM", 2)])
def test_eval_interrupted_keeps_finished_episodes(tmp_path, signame, jobs):
    TRIED["sim eval: interrupted mid-run"] += 1
    out = tmp_path / "eval"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "pmnav_bt.experiments.cli",
            "sim",
            "eval",
            "--building",
            "straight_office",
            "--tier",
            "easy",
            "-n",
            "40",
            "--variants",
            "pmnav",
            "--set",
            "grounder.backend=sim_gt",  # the oracle: fast episodes
            "--jobs",
            str(jobs),
            "--out",
            str(out),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # its own process group and session, to find every child
    )
    try:
        deadline = time.monotonic() + 120
        while len(_lines(out / "results.jsonl")) < 2 and time.monotonic() < deadline:
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.1)
        assert len(_lines(out / "results.jsonl")) >= 2, "no episode finished in 120 s"
        if jobs > 1:
            assert len(_session(proc.pid)) > 1  # the pool's workers are running
        sig = getattr(signal, signame)
        if signame == "SIGINT":
            os.killpg(proc.pid, sig)
        else:
            proc.send_signal(sig)
        _, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == (130 if signame == "SIGINT" else 143)
    assert "Traceback" not in err
    last = one_line(err.strip().splitlines()[-1], f"stopped by {signame}", "results.jsonl")
    done = _lines(out / "results.jsonl")
    assert 2 <= len(done) < 40 and f"after {len(done)} of 40" in last
    assert len({r["episode_id"] for r in done}) == len(done)
    saved = json.loads((out / "results.json").read_text())  # whole, written atomically
    assert len(saved["pmnav"]) == len(done)
    time.sleep(0.5)
    assert _session(proc.pid) == [], "processes left behind"
