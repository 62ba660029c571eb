"""The scale test: >= 1,000 episodes on generated buildings through Ray, hard-killed once
mid-run and resumed; then every key counted: none lost, none run twice.

Ground-truth perception (grounder sim_gt: the simulator's labels; an ORACLE, labelled so)
on the small generated family (gen_small_K: 2x2 junction grid, 10 rooms), easy tier,
a 160x120 camera: the cheapest honest episode, since the point here is the machinery.

Run: nice -n 19 python benchmarks/scale_test.py [--buildings 50] [-n 20] [--kill-after 300]
     [--out out/scale] [--jobs 2] [--ray ADDRESS]
Phase "kill" starts the run in its own session and SIGKILLs the whole group once
--kill-after rows are on disk; phase "resume" runs the same command with --resume (run
the script again to go on after any stop: it resumes when results exist); phase "check"
counts the keys. It prints the exact command of each phase, so the lead can resume by hand.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import shlex
import signal
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

PMNAV = str(Path(sys.executable).with_name("pmnav"))


def command(a) -> list[str]:
    cmd = [
        PMNAV,
        "sim",
        "eval",
        "--building",
        f"gen_small:{a.buildings}",
        "--tier",
        "easy",
        "-n",
        str(a.n),
        "--variants",
        "pmnav",
        "--jobs",
        str(a.jobs),
        "--ray",
        a.ray,
        "--out",
        str(a.out),
        "--set",
        "grounder.backend=sim_gt",
        "--set",
        "sim.width=160",
        "--set",
        "sim.height=120",
    ]
    return cmd


def rows(path: Path) -> list[dict]:
    if not path.exists():
        return []
    out = []
    for line in path.read_bytes().split(b"\n"):
        with contextlib.suppress(ValueError):  # an empty line or the torn tail of the kill
            out.append(json.loads(line))
    return out


def stamp(msg: str) -> None:
    print(f"[{time.strftime('%H:%M:%S', time.gmtime())} UTC] {msg}", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--buildings", type=int, default=50)
    ap.add_argument("-n", type=int, default=20, help="easy episodes per building")
    ap.add_argument("--kill-after", type=int, default=300, help="rows on disk before the kill")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--ray", default="local")
    ap.add_argument("--out", type=Path, default=Path("out/scale"))
    a = ap.parse_args()
    results = a.out / "results.jsonl"
    total = a.buildings * a.n
    cmd = command(a)
    a.out.parent.mkdir(parents=True, exist_ok=True)
    log = open(a.out.with_suffix(".log"), "a", encoding="utf-8")  # noqa: SIM115
    if not results.exists():
        stamp(f"phase kill: {shlex.join(cmd)}")
        proc = subprocess.Popen(cmd, stdout=log, stderr=log, start_new_session=True)
        while len(rows(results)) < a.kill_after and proc.poll() is None:
            time.sleep(2)
        os.killpg(proc.pid, signal.SIGKILL)  # the driver, Ray's runtime and its workers
        proc.wait()
        before = rows(results)
        torn = results.exists() and not results.read_bytes().endswith(b"\n")
        stamp(
            f"killed (SIGKILL to the process group) with {len(before)} rows on disk"
            + ("; the last line torn" if torn else "")
        )
    resume = [*cmd, "--resume"]
    stamp(f"phase resume: {shlex.join(resume)}")
    t0 = time.monotonic()
    before = len({r["key"] for r in rows(results)})
    rc = subprocess.call(resume, stdout=log, stderr=log)
    dt = time.monotonic() - t0
    got = rows(results)
    keys = Counter(r["key"] for r in got)
    dup = sum(c - 1 for c in keys.values() if c > 1)
    new = len(keys) - before
    stamp(
        f"resume exit {rc}: {len(keys)} unique keys of {total} expected, {dup} duplicate "
        f"rows, {len(got)} rows; {new} runs in {dt / 60:.1f} min "
        f"({new / max(dt, 1e-9) * 3600:.0f} episodes/hour)"
    )
    errors = sum(r.get("error") is not None for r in got)
    ok = sum(bool(r.get("success")) for r in got)
    stamp(f"SR {100 * ok / max(1, len(got)):.1f} % (oracle perception), {errors} errored")
    if len(keys) == total and dup == 0:
        stamp("PASS: every episode ran exactly once across the kill")
    else:
        stamp(f"INCOMPLETE: resume with: {shlex.join(resume)}")


if __name__ == "__main__":
    main()
