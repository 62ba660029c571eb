"""The ``navigate_to_room`` action (pmnav_interfaces/action/NavigateToRoom), like Nav2's
NavigateToPose: a goal (a room, or a pose taken to the nearest door), feedback at least
once a second (phase, plan step, distance remaining, recoveries, elapsed, pose, level),
cancel, and a result with a numeric ``error_code`` and an ``error_msg``.

The execute callback is a coroutine: it hands a GoalRequest to the mission loop (which
runs the tree in the main thread) and awaits its result, so the executor thread is
never blocked and odometry keeps flowing. Accepted goals preempt the running one.

``pmnav_interfaces`` is built from ``interfaces/`` by ``interfaces/build.sh`` (part
of ``make setup``); without it ``available()`` is False and the node runs with its
topics only.
"""

from __future__ import annotations

from collections.abc import Callable

from pmnav_bt.failures import FailureCode
from pmnav_bt.hardware.requests import GoalPoseError, GoalRequest, goal_from_pose

ACTION_NAME = "navigate_to_room"


def action_type():
    """The NavigateToRoom action class, or None when pmnav_interfaces is not built."""
    try:
        from pmnav_interfaces.action import NavigateToRoom
    except ImportError:
        return None
    return NavigateToRoom


def available() -> bool:
    return action_type() is not None


def error_code(code: str | None) -> int:
    """The Result constant for a FailureCode name (None: NONE; unknown names: UNKNOWN)."""
    result = action_type().Result
    if code is None:
        return result.NONE
    return int(getattr(result, str(code), result.UNKNOWN))


def _duration(seconds: float):
    from builtin_interfaces.msg import Duration

    ns = int(round(max(0.0, seconds) * 1e9))
    return Duration(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def feedback_message(p: dict, pose_msg=None):
    fb = action_type().Feedback()
    fb.phase = str(p.get("phase", ""))
    fb.current_step = int(p.get("current_step", 0))
    fb.step_count = int(p.get("step_count", 0))
    fb.step_text = str(p.get("step_text", ""))
    d = p.get("distance_remaining")
    fb.distance_remaining = float("nan") if d is None else float(d)
    fb.number_of_recoveries = int(p.get("recoveries", 0))
    fb.navigation_time = _duration(float(p.get("elapsed", 0.0)))
    fb.level = str(p.get("level", ""))
    if pose_msg is not None:
        fb.current_pose = pose_msg
    return fb


def result_message(r: dict, pose_msg=None):
    res = action_type().Result()
    res.error_code = error_code(None if r.get("success") else (r.get("code") or "UNKNOWN"))
    res.error_msg = str(r.get("message", ""))
    res.failure_code = "" if r.get("success") else str(r.get("code") or "UNKNOWN")
    res.room_id = str(r.get("room_id", ""))
    res.room_name = str(r.get("room_name", ""))
    res.navigation_time = _duration(float(r.get("duration_s") or 0.0))
    for k in ("ticks", "actions", "replans", "fix_attempts"):
        setattr(res, k, int(r.get(k) or 0))
    if pose_msg is not None:
        res.pose = pose_msg
    return res


class NavigateActionServer:
    """Serves ``navigate_to_room`` on ``node``; ``submit(GoalRequest)`` queues a goal for
    the mission loop; ``pose_msg(xy_yaw)`` builds a map-frame PoseStamped."""

    def __init__(
        self,
        node,
        building,
        submit: Callable[[GoalRequest], None],
        wake: Callable[[], None],
        pose_msg: Callable[[tuple[float, float, float]], object],
        map_frame: str = "map",
    ) -> None:
        from rclpy.action import ActionServer, CancelResponse, GoalResponse
        from rclpy.callback_groups import ReentrantCallbackGroup

        self.node, self.building, self.submit, self.wake = node, building, submit, wake
        self.pose_msg, self.map_frame = pose_msg, map_frame
        self.log = node.get_logger()
        self._server = ActionServer(
            node,
            action_type(),
            ACTION_NAME,
            execute_callback=self._execute,
            goal_callback=lambda _goal: GoalResponse.ACCEPT,
            cancel_callback=lambda _gh: CancelResponse.ACCEPT,
            callback_group=ReentrantCallbackGroup(),
        )

    def _room(self, goal) -> str:
        if goal.room.strip():
            return goal.room.strip()
        p = goal.pose.pose.position
        room, dist = goal_from_pose(
            self.building, goal.pose.header.frame_id, float(p.x), float(p.y), self.map_frame
        )
        self.log.info(f"goal pose ({p.x:.1f}, {p.y:.1f}): nearest door {room.id} at {dist:.1f} m")
        return room.id

    async def _execute(self, gh):
        from rclpy.task import Future

        try:
            room = self._room(gh.request)
        except GoalPoseError as err:
            gh.abort()
            return result_message(
                {"success": False, "code": FailureCode.INVALID_GOAL.value, "message": str(err)}
            )
        done = Future()

        def on_done(result: dict) -> None:
            done.set_result(result)
            self.wake()

        def feedback(p: dict) -> None:
            pose = p.get("pose_map")
            gh.publish_feedback(feedback_message(p, self.pose_msg(pose) if pose else None))

        self.submit(
            GoalRequest(
                room,
                "action",
                feedback=feedback,
                cancel_requested=lambda: gh.is_cancel_requested,
                on_done=on_done,
            )
        )
        r = await done
        pose = r.get("pose_map")
        msg = result_message(r, self.pose_msg(tuple(pose)) if pose else None)
        if r.get("success"):
            gh.succeed()
        elif r.get("code") == FailureCode.CANCELLED.value and gh.is_cancel_requested:
            gh.canceled()
        else:
            gh.abort()
        return msg
