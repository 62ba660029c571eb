"""Run the README's ROS 2 sequence exactly as written, N times from a cold start.

    .venv/bin/python benchmarks/ros_readme_sequence.py [-n 10] [--domain 57]

Takes the lines of README.md's ROS 2 block (the ``export``, the two background
nodes, the ``pmnav-ros-goal`` line), runs them in a fresh bash each time with the
venv's ``bin`` first on PATH, then interrupts the background nodes and waits for
them. ``--domain`` replaces the README's ROS_DOMAIN_ID (so as not to meet other ROS
users of the machine); nothing else is changed. Prints one line per run (exit code,
wall time, the result) and the count of successes.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def readme_lines() -> list[str]:
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    block = text[text.index("# ROS 2 (Jazzy)") :].split("```", 1)[0]
    lines = [ln for ln in block.splitlines()[1:] if ln.strip()]
    assert lines[0].startswith("export ROS_DOMAIN_ID=") and "pmnav-ros-goal" in lines[-1], lines
    return lines


def script(lines: list[str], domain: int | None) -> str:
    if domain is not None:
        lines = [re.sub(r"ROS_DOMAIN_ID=\d+", f"ROS_DOMAIN_ID={domain}", lines[0]), *lines[1:]]
    body = "\n".join(lines)
    # After the goal: interrupt the background nodes (the README leaves them running).
    return f"{body}\nrc=$?\nkill -INT $(jobs -p) 2>/dev/null\nwait\nexit $rc\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-n", type=int, default=10)
    ap.add_argument("--domain", type=int, default=None, help="replace the README's domain id")
    ap.add_argument("--timeout", type=float, default=600.0)
    args = ap.parse_args()
    lines = readme_lines()
    print("README lines:\n  " + "\n  ".join(lines))
    env = dict(os.environ)
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}"
    ok = 0
    for i in range(1, args.n + 1):
        t0 = time.monotonic()
        p = subprocess.run(
            ["bash", "-c", script(lines, args.domain)],
            env=env,
            capture_output=True,
            text=True,
            timeout=args.timeout,
            cwd=ROOT,
        )
        wall = time.monotonic() - t0
        result = next((ln for ln in p.stdout.splitlines() if ln.startswith("{")), "")
        try:
            r = json.loads(result)
            summary = f"{r.get('status')} error_code={r.get('error_code')} {r.get('message')!r}"
            summary += f" in {r.get('duration_s')} s, {r.get('feedback_messages')} feedback"
        except ValueError:
            summary = "no result: " + (p.stderr.strip().splitlines() or [""])[-1]
        ok += p.returncode == 0
        print(f"run {i:2d}: exit {p.returncode}, {wall:5.1f} s wall, {summary}", flush=True)
    print(f"{ok}/{args.n} successes")
    sys.exit(0 if ok == args.n else 1)


if __name__ == "__main__":
    main()
