"""``pmnav-ros-goal ROOM``: send a goal to pmnav-ros, wait for its result, print it.

    pmnav-ros-goal room17 [--timeout 600] [--namespace /robot1] [--cancel]

Prints the result JSON on one line; exits 0 on success, 1 on a failed run or a
timeout, 2 when ROS cannot start. (Equivalent with the ROS CLI, where installed:
``ros2 topic pub --once /goal std_msgs/msg/String "{data: room17}"`` and
``ros2 topic echo /result``.)
"""

from __future__ import annotations

import argparse
import json
import sys
import threading
import time

from pmnav_bt.errors import PmNavError


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    """The command line; the goal stripped as the node strips it (its result names it so)."""
    ap = argparse.ArgumentParser(prog="pmnav-ros-goal", description=__doc__.splitlines()[0])
    ap.add_argument("goal", nargs="?", help="a room name, id or alias")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds to wait for the result")
    ap.add_argument("--namespace", default="/", help="the controller's namespace")
    ap.add_argument("--cancel", action="store_true", help="cancel the running goal instead")
    args = ap.parse_args(argv)
    # The node strips the name it receives and reports the stripped name in its result.
    args.goal = (args.goal or "").strip()
    if not args.goal and not args.cancel:
        ap.error("give a goal, or --cancel")
    if not (args.timeout > 0 and args.timeout < 1e7):
        ap.error(f"--timeout {args.timeout}: expected seconds above 0")
    return args


def result_for(data: str, goal: str) -> dict | None:
    """The result record in a ``result`` message if it is for ``goal``, else None."""
    try:
        r = json.loads(data)
    except ValueError:
        return None  # not a pmnav-ros result
    return r if isinstance(r, dict) and r.get("goal") == goal else None


def main(argv: list[str] | None = None) -> None:
    args = parse_args(argv)

    from pmnav_bt.hardware.runtime import RosRuntime

    try:
        rt = RosRuntime(args=[])
    except PmNavError as err:
        print(f"pmnav-ros-goal: {err}", file=sys.stderr)
        sys.exit(2)
    from rclpy.node import Node
    from std_msgs.msg import Empty, String

    from pmnav_bt.hardware import qos

    node = Node("pmnav_goal", namespace=args.namespace, context=rt.context)
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
    code = 1
    try:
        deadline = time.monotonic() + 10.0
        pub = pub_cancel if args.cancel else pub_goal
        while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
            time.sleep(0.05)
        if pub.get_subscription_count() == 0:
            print(
                "pmnav-ros-goal: no pmnav-ros node is listening (same ROS_DOMAIN_ID?)",
                file=sys.stderr,
            )
        elif args.cancel:
            pub_cancel.publish(Empty())
            time.sleep(0.3)
            code = 0
        else:
            pub_goal.publish(String(data=args.goal))
            if done.wait(args.timeout):
                print(json.dumps(result))
                code = 0 if result.get("success") else 1
            else:
                print(f"pmnav-ros-goal: no result within {args.timeout:.0f} s", file=sys.stderr)
    except KeyboardInterrupt:
        pass
    finally:
        rt.shutdown()
    sys.exit(code)


if __name__ == "__main__":  # pragma: no cover
    main()
