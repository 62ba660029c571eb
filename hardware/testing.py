"""Run the nodes as subprocesses in a private DDS domain and watch them (tests, benchmarks).

``Proc`` starts ``python -m <module> --ros-args ...`` with ROS_AUTOMATIC_DISCOVERY_RANGE=
LOCALHOST and the run's own ROS_DOMAIN_ID (``pmnav_bt.hardware.env.ros_env``), so DDS
never leaves the loopback. ``Probe`` is an in-process node that records cmd_vel,
odometry, results, status and the simulator's ground truth with arrival times, sends
goals and sets the simulator's fault parameters. Every wait takes a timeout.
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from pathlib import Path

from pmnav_bt.hardware.env import ros_env


class Proc:
    """A node started as ``python -m module --ros-args ...``, output to a log file."""

    def __init__(
        self,
        module: str,
        params: dict,
        domain_id: int,
        log: Path,
        name: str = "",
        options: tuple[str, ...] = (),
    ):
        """``options`` go before ``--ros-args`` (the node's own, as ``--record FILE``)."""
        args = [sys.executable, "-m", module, *options, "--ros-args"]
        for k, v in params.items():
            if isinstance(v, bool):
                v = "true" if v else "false"
            args += ["-p", f"{k}:={v}"]
        if name:
            args += ["-r", f"__node:={name}"]
        self.log = log
        self._out = open(log, "w", encoding="utf-8")  # noqa: SIM115
        self.proc = subprocess.Popen(
            args,
            env=ros_env(domain_id=domain_id, discovery_range="LOCALHOST"),
            stdout=self._out,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            start_new_session=True,
        )

    def alive(self) -> bool:
        return self.proc.poll() is None

    def kill(self, sig: int = signal.SIGKILL) -> None:
        if self.proc.poll() is None:
            with contextlib.suppress(ProcessLookupError):
                os.kill(self.proc.pid, sig)

    def stop(self, timeout: float = 5.0) -> int | None:
        """SIGINT, then SIGKILL after ``timeout``; the exit code."""
        if self.proc.poll() is None:
            self.kill(signal.SIGINT)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                self.kill(signal.SIGKILL)
                self.proc.wait(5.0)
        self._out.close()
        return self.proc.returncode

    def tail(self, n: int = 30) -> str:
        try:
            return "\n".join(self.log.read_text(errors="replace").splitlines()[-n:])
        except OSError:
            return ""


class Probe:
    """An in-process node that records what the test needs, with arrival times."""

    def __init__(self, runtime):
        from geometry_msgs.msg import PoseStamped, Twist
        from nav_msgs.msg import Odometry
        from nav_msgs.msg import Path as PathMsg
        from rclpy.node import Node
        from std_msgs.msg import String
        from visualization_msgs.msg import MarkerArray

        from pmnav_bt.hardware import qos

        self.node = Node("pmnav_test_probe", context=runtime.context)
        self.lock = threading.Condition()
        self.cmd: deque = deque(maxlen=20000)  # (t, v, w)
        self.cmd_dds: deque = deque(maxlen=20000)  # (source, received) s, one per cmd
        self.odom: deque = deque(maxlen=20000)  # (t, v, w)
        self.results: list[dict] = []
        self.status: dict | None = None
        self.stats: dict | None = None
        self.true_pose = None
        self.plans = 0
        self.trees = 0
        self.structure = 0
        self.markers = 0
        n, ev, lat = self.node, qos.events(), qos.latched()
        n.create_subscription(Twist, "cmd_vel", self._on_cmd, qos.events())
        n.create_subscription(Odometry, "odom", self._on_odom, qos.sensor())
        n.create_subscription(String, "result", self._on_result, ev)
        n.create_subscription(String, "status", self._on_status, ev)
        n.create_subscription(String, "sim/stats", self._on_stats, ev)
        n.create_subscription(PoseStamped, "sim/true_pose", self._on_true, ev)
        n.create_subscription(PathMsg, "plan", lambda m: self._count("plans"), lat)
        n.create_subscription(String, "tree", lambda m: self._count("trees"), ev)
        n.create_subscription(String, "tree/structure", lambda m: self._count("structure"), lat)
        n.create_subscription(MarkerArray, "markers", lambda m: self._count("markers"), lat)
        self.pub_goal = n.create_publisher(String, "goal", ev)
        self._String = String
        runtime.add(self.node)

    def _count(self, name):
        with self.lock:
            setattr(self, name, getattr(self, name) + 1)
            self.lock.notify_all()

    def _on_cmd(self, m, info):  # two arguments: rclpy passes the message info
        with self.lock:
            self.cmd.append((time.monotonic(), m.linear.x, m.angular.z))
            if isinstance(info, dict):  # DDS times (ns): when written, and when received
                self.cmd_dds.append(
                    (
                        info.get("source_timestamp", 0) * 1e-9,
                        info.get("received_timestamp", 0) * 1e-9,
                    )
                )
            self.lock.notify_all()

    def _on_odom(self, m):
        with self.lock:
            self.odom.append((time.monotonic(), m.twist.twist.linear.x, m.twist.twist.angular.z))

    def _on_result(self, m):
        with self.lock:
            self.results.append(json.loads(m.data))
            self.lock.notify_all()

    def _on_status(self, m):
        with self.lock:
            self.status = json.loads(m.data)
            self.lock.notify_all()

    def _on_stats(self, m):
        with self.lock:
            self.stats = json.loads(m.data)

    def _on_true(self, m):
        from pmnav_bt.hardware.messages import yaw_from_quaternion

        with self.lock:
            p = m.pose
            self.true_pose = (p.position.x, p.position.y, yaw_from_quaternion(p.orientation))

    def wait_for(self, pred: Callable[[], object], timeout: float, what: str, procs=()):
        """Wait until ``pred()`` is truthy (checked under the lock); AssertionError on timeout,
        with the logs of ``procs``."""
        deadline = time.monotonic() + timeout
        with self.lock:
            while True:
                v = pred()
                if v:
                    return v
                remaining = deadline - time.monotonic()
                dead = [p for p in procs if not p.alive()]
                if remaining <= 0 or dead:
                    logs = "\n".join(f"--- {p.log.name}\n{p.tail()}" for p in procs)
                    why = "a process died" if dead else f"timed out after {timeout:.0f} s"
                    raise AssertionError(f"waiting for {what}: {why}\n{logs}")
                self.lock.wait(min(remaining, 0.2))

    def send_goal(self, goal: str) -> None:
        self.pub_goal.publish(self._String(data=goal))

    def set_param(self, node: str, name: str, value: bool, timeout: float = 5.0) -> None:
        from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
        from rcl_interfaces.srv import SetParameters

        cli = self.node.create_client(SetParameters, f"/{node}/set_parameters")
        try:
            if not cli.wait_for_service(timeout_sec=timeout):
                raise AssertionError(f"no parameter service on /{node}")
            req = SetParameters.Request()
            req.parameters = [
                Parameter(
                    name=name,
                    value=ParameterValue(type=ParameterType.PARAMETER_BOOL, bool_value=value),
                )
            ]
            fut = cli.call_async(req)
            deadline = time.monotonic() + timeout
            while not fut.done():
                if time.monotonic() > deadline:
                    raise AssertionError(f"setting {name} on /{node} timed out")
                time.sleep(0.01)
            res = fut.result().results[0]
            assert res.successful, res.reason
        finally:
            self.node.destroy_client(cli)
