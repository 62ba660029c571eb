"""--ray gives the same results as the process pool and the serial loop for the same seeds
(two short episodes); the executors cancel cleanly. Skipped only where Ray is not installed
(it is an optional extra; make setup installs it)."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time

import pytest

from pmnav_bt.config import load_config
from pmnav_bt.experiments.evaluation import evaluate
from pmnav_bt.experiments.executors import run_tasks
from pmnav_bt.sim.episodes import generate_episodes

pytestmark = pytest.mark.timeout(300)


def _rows(results):
    return {
        (name, r.episode_id): {k: v for k, v in r.to_dict().items() if k != "wall_time"}
        for name, rs in results.items()
        for r in rs
    }


def test_ray_and_the_pool_give_the_same_results_as_one_process():
    pytest.importorskip("ray")
    eps = generate_episodes("straight_office", "easy", 2, seed=3)
    configs = {"pmnav": load_config(None, ["grounder.backend=sim_gt"])}
    serial = _rows(evaluate(eps, configs, jobs=1))
    pool = _rows(evaluate(eps, configs, jobs=2))
    ray = _rows(evaluate(eps, configs, jobs=2, ray="local"))
    assert len(serial) == 2
    assert serial == pool == ray


def test_ray_tasks_come_back_indexed_and_the_runtime_is_shut_down():
    ray = pytest.importorskip("ray")
    got = dict(run_tasks(math.factorial, [1, 2, 3, 4], jobs=2, ray="local"))
    assert got == {0: 1, 1: 2, 2: 6, 3: 24}
    assert not ray.is_initialized()


def test_stopping_early_terminates_the_pool():
    it = run_tasks(math.factorial, list(range(50)), jobs=2)
    first = next(it)
    it.close()  # what an Interrupted on the way up does
    assert first[1] == math.factorial(first[0])


@pytest.mark.skipif(sys.platform != "linux", reason="process groups")
def test_ctrl_c_during_a_ray_run_keeps_the_finished_episodes(tmp_path):
    pytest.importorskip("ray")
    out = tmp_path / "eval"
    cmd = [
        sys.executable, "-m", "pmnav_bt.experiments.cli", "sim", "eval", "--building",
        "straight_office", "--tier", "easy", "-n", "8", "--variants", "pmnav", "--worlds", "clean",
        "--jobs", "2",
        "--ray", "--out", str(out), "--set", "grounder.backend=sim_gt",  # the oracle: fast
    ]  # fmt: skip
    proc = subprocess.Popen(
        cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True
    )
    results = out / "results.jsonl"
    try:
        deadline = time.monotonic() + 150
        while time.monotonic() < deadline and (
            not results.exists() or not results.read_text().count("\n")
        ):
            assert proc.poll() is None, proc.communicate()
            time.sleep(0.2)
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=90)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130 and "Traceback" not in err, err[-2000:]
    done = results.read_text().count("\n")
    assert 1 <= done < 8 and f"after {done} of 8 episodes" in err
