"""Soak: many realistic episodes through ``pmnav sim eval --ray``, none errored, memory flat.

Runs one ``pmnav sim eval`` over about ``--episodes`` realistic-world episodes of the
generated functional family (development seeds; hospitals, schools and offices in turn,
every tier) as Ray tasks on a local runtime, and samples every ``--every`` seconds the
resident memory of the driver (the ``pmnav`` process: it keeps every result it gathers)
and of all its descendants (Ray's GCS, raylet and the workers that build the worlds and
run the trees), from ``/proc`` (Linux). At the end it prints the errored episodes (rows
with an ``error``: a crash, not a failure to find the room), the driver's memory at the
start (after the first ``WARM_FRACTION`` of the episodes, when imports and the first
worlds are in) and at the end, and its growth per 100 episodes from a least-squares line
through the samples after the warm-up.

Target (issue 38): 1,000 episodes, 0 errored, the driver's memory flat (here: growth
under ``FLAT_MB_PER_100`` MB per 100 episodes; the results themselves are a few kB each).

Run: python benchmarks/soak.py [--episodes 1000] [--variant pmnav] [--jobs 2]
     [--out out/soak] (``--variant pmnav_oracle`` soaks with simulator labels: faster, and
     labelled so). ``--resume`` goes on from a run that was stopped.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

PMNAV = str(Path(sys.executable).with_name("pmnav"))
TIERS = 3  # easy, medium, hard: a functional building poses all three
WARM_FRACTION = 0.05
FLAT_MB_PER_100 = 5.0


def rss_mb(pid: int) -> float:
    """Resident memory of one process (MB), 0 when it is gone."""
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    except (FileNotFoundError, ProcessLookupError, PermissionError):
        pass
    return 0.0


def descendants(pid: int) -> list[int]:
    """Every process below ``pid`` (children of children...), read from /proc."""
    parent: dict[int, int] = {}
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
                parent[int(d.name)] = int(fields[1])
            except (FileNotFoundError, ProcessLookupError, IndexError, ValueError):
                continue
    out, frontier = [], [pid]
    while frontier:
        p = frontier.pop()
        kids = [c for c, pp in parent.items() if pp == p]
        out += kids
        frontier += kids
    return out


def results_done(path: Path) -> tuple[int, int]:
    """(rows, errored rows) in a results.jsonl so far."""
    if not path.exists():
        return 0, 0
    rows = [json.loads(x) for x in path.read_text().splitlines() if x.strip()]
    return len(rows), sum(1 for r in rows if r.get("error"))


def slope_per_100(samples: list[tuple[int, float]]) -> float:
    """Least-squares growth (MB per 100 episodes) of (episodes done, MB) samples."""
    if len(samples) < 2:
        return math.nan
    xs = [s[0] for s in samples]
    ys = [s[1] for s in samples]
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    if sxx == 0:
        return math.nan
    return 100 * sum((x - mx) * (y - my) for x, y in zip(xs, ys, strict=True)) / sxx


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", type=int, default=1000, help="about this many episodes")
    ap.add_argument("--variant", default="pmnav", help="pmnav (real stack) or pmnav_oracle")
    ap.add_argument("--jobs", type=int, default=2, help="Ray CPUs")
    ap.add_argument("--every", type=float, default=5.0, help="seconds between samples")
    ap.add_argument("--out", type=Path, default=Path("out/soak"))
    ap.add_argument("--resume", action="store_true")
    a = ap.parse_args()
    if a.episodes < 1 or a.jobs < 1 or a.every <= 0:
        ap.error("--episodes and --jobs must be at least 1, --every above 0")
    per_tier = max(1, math.ceil(a.episodes / (TIERS * 48)))
    buildings = max(1, math.ceil(a.episodes / (TIERS * per_tier)))
    cmd = [
        PMNAV, "sim", "eval", "--building", f"functional:{buildings}", "--tier", "all",
        "-n", str(per_tier), "--variants", a.variant, "--worlds", "realistic",
        "--jobs", str(a.jobs), "--ray", "--out", str(a.out),
        "--resume" if a.resume else "--overwrite",
    ]  # fmt: skip
    print("$ pmnav", " ".join(cmd[1:]), flush=True)
    results = a.out / "results.jsonl"
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST")
    t0 = time.monotonic()
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    driver: list[tuple[int, float]] = []
    tree: list[tuple[int, float]] = []
    try:
        while proc.poll() is None:
            done, _ = results_done(results)
            d = rss_mb(proc.pid)
            driver.append((done, d))
            kids = descendants(proc.pid)
            if kids:  # Ray is up (not yet started, or shut down at the end: no sample)
                tree.append((done, d + sum(rss_mb(p) for p in kids)))
            time.sleep(a.every)
    except KeyboardInterrupt:
        proc.terminate()
        proc.wait(30)
    stderr = proc.stderr.read().decode(errors="replace") if proc.stderr else ""
    done, errored = results_done(results)
    wall = time.monotonic() - t0
    warm = max(1, int(WARM_FRACTION * done))
    d_after = [s for s in driver if s[0] >= warm and s[1] > 0]
    t_after = [s for s in tree if s[0] >= warm and s[1] > 0]
    print(f"episodes: {done} ({a.variant}@realistic), errored {errored}, "
          f"{wall / 60:.1f} min wall, exit {proc.returncode}")  # fmt: skip
    if d_after and t_after:
        print(f"driver RSS: {d_after[0][1]:.0f} MB after {d_after[0][0]} episodes, "
              f"{d_after[-1][1]:.0f} MB after {d_after[-1][0]}; "
              f"{slope_per_100(d_after):+.2f} MB per 100 episodes")  # fmt: skip
        print(f"driver + Ray processes RSS: {t_after[0][1]:.0f} MB, then {t_after[-1][1]:.0f} MB; "
              f"{slope_per_100(t_after):+.2f} MB per 100 episodes")  # fmt: skip
        flat = abs(slope_per_100(d_after)) < FLAT_MB_PER_100
        ok = errored == 0 and flat and done >= a.episodes
        print(f"target (>= {a.episodes} episodes, 0 errored, driver flat within "
              f"{FLAT_MB_PER_100:g} MB/100): {'met' if ok else 'NOT met'}")  # fmt: skip
    if proc.returncode:
        print(stderr.strip().splitlines()[-1] if stderr.strip() else "(no message)")


if __name__ == "__main__":
    main()
