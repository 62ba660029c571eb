"""Evaluation throughput: episodes per hour with --jobs 1, --jobs 2 and --ray (local), and
the same seeds giving the same results across the three.

Runs ``pmnav sim eval`` on a few short episodes (generated gen_small buildings, easy tier,
ground-truth perception sim_gt, the default 320x240 camera) once per mode, timing the whole
command (start-up included: what a user waits for), its CPU seconds (which the other
users of a shared machine do not change much) and the episodes alone (the rows' wall
times), then compares the results.jsonl rows minus their wall times. The load average
is printed: on a busy machine the wall-clock rates say more about the others.

Run: python benchmarks/bench_eval_throughput.py [--buildings 2] [-n 4] [--out out/bench]
Target: none; on a 2-core machine --jobs 2 should beat --jobs 1 and Ray should be within
its start-up (~10 s) of --jobs 2.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

PMNAV = str(Path(sys.executable).with_name("pmnav"))
MODES = {
    "--jobs 1": ["--jobs", "1"],
    "--jobs 2": ["--jobs", "2"],
    "--ray": ["--jobs", "2", "--ray"],
}


def _cpu() -> float:
    """CPU seconds of every finished descendant (load-independent, unlike the wall)."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def rows(path: Path) -> dict[str, dict]:
    out = {}
    for line in path.read_text().splitlines():
        r = json.loads(line)
        out[r["key"]] = {k: v for k, v in r.items() if k != "wall_time"}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--buildings", type=int, default=2)
    ap.add_argument("-n", type=int, default=4, help="easy episodes per building")
    ap.add_argument("--out", type=Path, default=Path("out/bench_eval"))
    a = ap.parse_args()
    base = [
        PMNAV, "sim", "eval", "--building", f"gen_small:{a.buildings}", "--tier", "easy",
        "-n", str(a.n), "--variants", "pmnav", "--set", "grounder.backend=sim_gt",
        "--overwrite",  # each run of the benchmark replaces the last one's results
    ]  # fmt: skip
    total = a.buildings * a.n
    print(f"{total} episodes (gen_small:{a.buildings}, easy, sim_gt, 320x240) per mode; "
          f"{os.cpu_count()} CPUs; load average {os.getloadavg()[0]:.1f} at start")  # fmt: skip
    got = {}
    for mode, flags in MODES.items():
        out = a.out / mode.strip("-").replace(" ", "")
        t0, c0 = time.perf_counter(), _cpu()
        p = subprocess.run([*base, *flags, "--out", str(out)], capture_output=True, text=True)
        dt, cpu = time.perf_counter() - t0, _cpu() - c0
        if p.returncode != 0:
            sys.exit(f"{mode}: exit {p.returncode}: {p.stderr.strip().splitlines()[-1]}")
        got[mode] = rows(out / "results.jsonl")
        busy = sum(
            json.loads(x)["wall_time"] for x in (out / "results.jsonl").read_text().splitlines()
        )
        # Ray's workers are the raylet's children, reaped there: not in our rusage.
        cpu_text = "CPU n/a (Ray's workers)" if "--ray" in flags else f"{cpu / total:.1f} CPU-s"
        print(
            f"{mode:>9}: {total} episodes in {dt:6.1f} s = {total / dt * 3600:6.0f} episodes/h "
            f"(whole command); {cpu_text} per episode (start-up included); "
            f"mean episode {busy / total:.1f} s wall in its worker"
        )
    ref = got["--jobs 1"]
    same = all(g == ref for g in got.values())
    print(
        f"same seeds, same results across the three (rows minus wall_time): "
        f"{'yes' if same else 'NO'} ({len(ref)} rows each)"
    )
    if not same:
        for mode, g in got.items():
            diff = [k for k in ref if g.get(k) != ref[k]]
            if diff:
                print(f"  {mode} differs on {diff[:5]}")
        sys.exit(1)


if __name__ == "__main__":
    main()
