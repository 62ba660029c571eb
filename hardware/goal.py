"""``pmnav-ros-goal ROOM``: send a goal to pmnav-ros, print its progress and the result.

    pmnav-ros-goal "One-Stop Service Centre" [--timeout 900] [--wait 120] [--namespace /robot1]
    pmnav-ros-goal --pose 30,12            # the room whose door is nearest to (30, 12), map frame
    pmnav-ros-goal --cancel                # cancel the running goal

Waits (up to ``--wait`` s) for a pmnav-ros node to serve the ``navigate_to_room``
action; the node itself holds the goal until its odometry and camera are fresh.
Progress (phase, plan step, distance to go, recoveries, elapsed) goes to stderr, at
most every 2 s and on each change of step; the result is one JSON line on stdout with
``error_code`` (pmnav_interfaces/action/NavigateToRoom) and ``code`` (the FailureCode).
Ctrl-C cancels the goal. Exit: 0 success, 1 a failed goal or a timeout, 2 ROS or no node.
Without pmnav_interfaces it falls back to the ``goal``/``result`` topics (no progress).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import threading
import time

from pmnav_bt.errors import PmNavError
from pmnav_bt.hardware.requests import progress_line


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    """The command line; the goal stripped as the node strips it (its result names it so)."""
    ap = argparse.ArgumentParser(
        prog="pmnav-ros-goal",
        description=(__doc__ or "").splitlines()[0],
        epilog="Exit 0 on success, 1 on a failed goal or a timeout, 2 when no node answers.",
    )
    ap.add_argument("goal", nargs="?", help="a room name, id or alias")
    ap.add_argument("--pose", help="X,Y in the map frame: go to the nearest room door")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds to wait for the result")
    ap.add_argument("--wait", type=float, default=120.0, help="seconds to wait for pmnav-ros")
    ap.add_argument("--namespace", default="/", help="the controller's namespace")
    ap.add_argument("--cancel", action="store_true", help="cancel the running goal instead")
    ap.add_argument("--quiet", action="store_true", help="no progress lines")
    args = ap.parse_args(argv)
    # The node strips the name it receives and reports the stripped name in its result.
    args.goal = (args.goal or "").strip()
    if not (args.goal or args.pose or args.cancel):
        ap.error("give a goal (a room name), --pose X,Y, or --cancel")
    if args.pose:
        try:
            x, y = (float(v) for v in args.pose.split(","))
        except ValueError:
            ap.error(f"--pose {args.pose!r}: expected X,Y in metres, e.g. --pose 30,12")
        args.xy = (x, y)
    for name in ("timeout", "wait"):
        value = getattr(args, name)
        if not 0 < value < 1e7:
            ap.error(f"--{name} {value}: expected seconds above 0")
    return args


def result_for(data: str, goal: str) -> dict | None:
    """The result record in a ``result`` message if it is for ``goal``, else None."""
    try:
        r = json.loads(data)
    except ValueError:
        return None  # not a pmnav-ros result
    return r if isinstance(r, dict) and r.get("goal") == goal else None


def _err(text: str) -> None:
    print(f"pmnav-ros-goal: {text}", file=sys.stderr, flush=True)


def _wait_until(pred, timeout: float, poll: float = 0.05) -> bool:
    deadline = time.monotonic() + timeout
    while not pred():
        if time.monotonic() > deadline:
            return False
        time.sleep(poll)
    return True


def _feedback_dict(fb) -> dict:
    nav = fb.navigation_time
    return {
        "phase": fb.phase,
        "current_step": fb.current_step,
        "step_count": fb.step_count,
        "step_text": fb.step_text,
        "distance_remaining": float(fb.distance_remaining),
        "recoveries": int(fb.number_of_recoveries),
        "elapsed": nav.sec + nav.nanosec * 1e-9,
        "level": fb.level,
    }


def _result_dict(goal: str, res, status: int) -> dict:
    from action_msgs.msg import GoalStatus

    nav = res.navigation_time
    pose = res.pose.pose
    yaw = 2.0 * math.atan2(pose.orientation.z, pose.orientation.w)
    return {
        "goal": goal,
        "success": status == GoalStatus.STATUS_SUCCEEDED and res.error_code == res.NONE,
        "status": {4: "SUCCEEDED", 5: "CANCELED", 6: "ABORTED"}.get(status, str(status)),
        "error_code": int(res.error_code),
        "code": res.failure_code or None,
        "message": res.error_msg,
        "room_id": res.room_id,
        "room_name": res.room_name,
        "duration_s": round(nav.sec + nav.nanosec * 1e-9, 3),
        "ticks": res.ticks,
        "actions": res.actions,
        "replans": res.replans,
        "fix_attempts": res.fix_attempts,
        "pose_map": [round(pose.position.x, 3), round(pose.position.y, 3), round(yaw, 4)],
    }


class _Progress:
    """Prints feedback lines: on a new step, phase or level, else at most every ``every`` s."""

    def __init__(self, quiet: bool, every: float = 2.0) -> None:
        self.quiet, self.every = quiet, every
        self.count = 0
        self._last = (-math.inf, None)

    def __call__(self, msg) -> None:
        self.count += 1
        if self.quiet:
            return
        fb = _feedback_dict(msg.feedback)
        key = (fb["phase"], fb["current_step"], fb["level"])
        now = time.monotonic()
        if key != self._last[1] or now - self._last[0] >= self.every:
            self._last = (now, key)
            print(progress_line(fb), file=sys.stderr, flush=True)


def _run_action(node, rt, args, goal_type) -> int:
    from action_msgs.msg import GoalStatus

    from pmnav_bt.hardware.action_client import ThreadSafeActionClient
    from pmnav_bt.hardware.action_server import ACTION_NAME

    client = ThreadSafeActionClient(node, goal_type, ACTION_NAME)
    rt.add(node)
    rt.start()
    name = node.resolve_topic_name(ACTION_NAME)
    if not client.server_is_ready():
        _err(f"waiting up to {args.wait:.0f} s for pmnav-ros ({name})")
    if not client.wait_for_server(timeout_sec=args.wait):
        _err(f"no pmnav-ros node serves {name} (same ROS_DOMAIN_ID? is it running?)")
        return 2
    goal = goal_type.Goal()
    label = args.goal or f"pose {args.pose}"
    if args.goal:
        goal.room = args.goal
    else:
        goal.pose.header.frame_id = "map"
        goal.pose.pose.position.x, goal.pose.pose.position.y = args.xy
        goal.pose.pose.orientation.w = 1.0
    progress = _Progress(args.quiet)
    sent = client.send_goal_async(goal, feedback_callback=progress)
    if not _wait_until(sent.done, 10.0) or not sent.result().accepted:
        _err(f"goal {label!r} was not accepted")
        return 1
    handle = sent.result()
    result = handle.get_result_async()
    try:
        if not _wait_until(result.done, args.timeout):
            _err(f"no result within {args.timeout:.0f} s; cancelling the goal")
            handle.cancel_goal_async()
            _wait_until(result.done, 5.0)
            return 1
    except KeyboardInterrupt:
        _err("cancelling the goal")
        handle.cancel_goal_async()
        _wait_until(result.done, 5.0)
        if not result.done():
            return 1
    r = result.result()
    out = _result_dict(label, r.result, r.status)
    out["feedback_messages"] = progress.count
    print(json.dumps(out), flush=True)
    return 0 if r.status == GoalStatus.STATUS_SUCCEEDED else 1


def _run_topics(node, rt, args) -> int:
    """The fallback without pmnav_interfaces: the goal, cancel and result topics."""
    from std_msgs.msg import Empty, String

    from pmnav_bt.hardware import qos

    done = threading.Event()
    result: dict = {}

    def on_result(msg) -> None:
        r = result_for(msg.data, args.goal)
        if r is not None:
            result.update(r)
            done.set()

    node.create_subscription(String, "result", on_result, qos.events())
    pub_goal = node.create_publisher(String, "goal", qos.events())
    pub_cancel = node.create_publisher(Empty, "cancel", qos.events())
    rt.add(node)
    rt.start()
    pub = pub_cancel if args.cancel else pub_goal
    if not _wait_until(lambda: pub.get_subscription_count() > 0, args.wait):
        _err("no pmnav-ros node is listening (same ROS_DOMAIN_ID?)")
        return 2
    if args.cancel:
        pub_cancel.publish(Empty())
        time.sleep(0.3)
        return 0
    if not args.goal:
        _err("--pose needs the navigate_to_room action (pmnav_interfaces)")
        return 2
    pub_goal.publish(String(data=args.goal))
    if not done.wait(args.timeout):
        _err(f"no result within {args.timeout:.0f} s")
        return 1
    print(json.dumps(result), flush=True)
    return 0 if result.get("success") else 1


def main(argv: list[str] | None = None) -> None:
    args = parse_args(argv)
    from pmnav_bt.hardware.action_server import action_type
    from pmnav_bt.hardware.runtime import RosRuntime

    try:
        rt = RosRuntime(args=[])
    except PmNavError as err:
        _err(str(err))
        sys.exit(2)
    from rclpy.node import Node

    node = Node("pmnav_goal", namespace=args.namespace, context=rt.context)
    code = 1
    try:
        goal_type = action_type()
        if goal_type is not None and not args.cancel:
            code = _run_action(node, rt, args, goal_type)
        else:
            code = _run_topics(node, rt, args)
    except KeyboardInterrupt:
        pass
    finally:
        rt.shutdown()
    sys.exit(code)


if __name__ == "__main__":  # pragma: no cover
    main()
