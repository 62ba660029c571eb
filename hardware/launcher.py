"""``pmnav-launch``: what ``launch/pmnav.launch.py`` does, without the ROS 2 launch packages.

    pmnav-launch                                   # simulator + controller
    pmnav-launch sim:=false image_topic:=/camera/color/image_raw segmentation_topic:=
    pmnav-launch record:=run.mcap start_pose:=47,20,0

``launch``/``launch_ros`` are not on PyPI, so ``ros2 launch`` needs a full ROS 2
install. This starts the same two processes with the same arguments (``ARGS``, which
the launch file imports too), prefixes their output with the node name, and on
Ctrl-C/SIGTERM interrupts the controller first (it stops the robot), then the
simulator. When either process ends, the other is stopped; the exit code is the
controller's.
"""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import threading
import time

# name -> (default, description); shared with launch/pmnav.launch.py.
ARGS: dict[str, tuple[str, str]] = {
    "sim": ("true", "start pmnav-sim-create3 (false: a real Create 3 and camera)"),
    "building": ("fig2_hospital", "building file (YAML) or built-in name"),
    "start_pose": ("", "simulator start x,y,yaw_deg (empty: the building's start)"),
    "width": ("320", "simulated camera width"),
    "height": ("240", "simulated camera height"),
    "camera_rate_hz": ("5.0", "simulated camera rate"),
    "config": ("", "PM-Nav config file"),
    "overrides": ("", "config overrides 'section.key=value;...'"),
    "namespace": ("/", "robot namespace (a Create 3's, e.g. /robot1)"),
    "image_topic": ("camera/image_raw", ""),
    "camera_info_topic": ("camera/camera_info", ""),
    "depth_topic": ("camera/depth/image_raw", ""),
    "segmentation_topic": ("camera/segmentation", "empty on a real robot"),
    "tree_log": ("", "also write tree snapshots (JSON lines) here"),
    "record": ("", "record the run to this FILE.mcap (pmnav-ros --record)"),
    "view_port": ("0", "serve the live web view (pmnav view) on this port; 0: none"),
    "map_updates_dir": ("", "write what the robot saw that disagrees with the map here"),
}
SIM_STRINGS = ("building", "start_pose")
SIM_NUMBERS = ("width", "height", "camera_rate_hz")
CONTROLLER_STRINGS = (
    "building",
    "config",
    "overrides",
    "image_topic",
    "camera_info_topic",
    "depth_topic",
    "segmentation_topic",
    "tree_log",
    "map_updates_dir",
)
CONTROLLER_NUMBERS = ("view_port",)


class LaunchArgumentError(ValueError):
    """A ``name:=value`` argument that the launch file does not declare."""


def parse(argv: list[str]) -> dict[str, str]:
    """``name:=value`` arguments over the defaults of ``ARGS``."""
    values = {k: v for k, (v, _) in ARGS.items()}
    for a in argv:
        name, sep, value = a.partition(":=")
        if not sep or name not in ARGS:
            import difflib

            close = difflib.get_close_matches(name, list(ARGS), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise LaunchArgumentError(f"unknown launch argument {a!r}{hint}")
        values[name] = value
    return values


def ros_args(node: str, values: dict[str, str], strings, numbers=()) -> list[str]:
    """``--ros-args`` for ``node``; strings YAML-quoted (an empty value stays a string)."""
    cmd = ["--ros-args", "-r", f"__node:={node}", "-r", f"__ns:={values['namespace']}"]
    for p in strings:
        cmd += ["-p", f"{p}:='{values[p]}'"]
    for p in numbers:
        cmd += ["-p", f"{p}:={values[p]}"]
    return cmd


def commands(values: dict[str, str]) -> list[tuple[str, list[str]]]:
    """(name, argv) of each process to start, the simulator first."""
    py = [sys.executable, "-m"]
    out = []
    if values["sim"].lower() in ("true", "1", "yes"):
        sim = ros_args("sim_create3", values, SIM_STRINGS, SIM_NUMBERS)
        out.append(("sim_create3", [*py, "pmnav_bt.hardware.sim_create3", *sim]))
    record = ["--record", values["record"]] if values["record"] else []
    ctl = ros_args("pmnav", values, CONTROLLER_STRINGS, CONTROLLER_NUMBERS)
    out.append(("pmnav", [*py, "pmnav_bt.hardware.node", *record, *ctl]))
    return out


def _pipe(name: str, stream) -> None:
    for line in iter(stream.readline, ""):
        sys.stdout.write(f"[{name}] {line}")
        sys.stdout.flush()


def _stop(proc: subprocess.Popen, timeout: float) -> None:
    if proc.poll() is None:
        with contextlib.suppress(ProcessLookupError):
            proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait(5.0)


def run(values: dict[str, str]) -> int:
    """Start the processes, wait until one ends or a signal comes, stop them all."""
    from pmnav_bt.hardware.env import ros_env

    env = ros_env(discovery_range=None)
    env.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    procs: list[tuple[str, subprocess.Popen]] = []
    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    for name, argv in commands(values):
        proc = subprocess.Popen(
            argv,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            text=True,
            start_new_session=True,  # our signals reach them only through us
        )
        threading.Thread(target=_pipe, args=(name, proc.stdout), daemon=True).start()
        procs.append((name, proc))
        print(f"[launcher] started {name} (pid {proc.pid})", flush=True)
    while not stop.is_set() and all(p.poll() is None for _, p in procs):
        stop.wait(0.2)
    for name, proc in reversed(procs):  # the controller first: it stops the robot
        _stop(proc, 8.0)
        print(f"[launcher] {name} exited with {proc.returncode}", flush=True)
    return procs[-1][1].returncode or 0


def main(argv: list[str] | None = None) -> None:
    argv = list(sys.argv[1:] if argv is None else argv)
    if "-h" in argv or "--help" in argv:
        print((__doc__ or "").strip() + "\n\narguments (name:=value):")
        for k, (v, d) in ARGS.items():
            print(f"  {k:<18} {v!r:<20} {d}")
        sys.exit(0)
    try:
        values = parse(argv)
    except LaunchArgumentError as err:
        print(f"pmnav-launch: {err}", file=sys.stderr)
        sys.exit(2)
    os.environ.setdefault("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST")
    t0 = time.monotonic()
    code = run(values)
    print(f"[launcher] done after {time.monotonic() - t0:.0f} s", flush=True)
    sys.exit(code)


if __name__ == "__main__":  # pragma: no cover
    main()
