"""The iRobot Create 3 as a ``pmnav_bt.seams.Base``, over rclpy with standard messages only.

Topics (names configurable in ``Create3Options``):

- ``cmd_vel`` (geometry_msgs/Twist, out, reliable): the Create 3 stops about 0.5 s
  after the last command, so while the body moves a heartbeat thread republishes
  the current command at ``cmd_rate_hz`` (20 Hz). On a stop it sends a few zero
  commands, then stays silent (so a teleop node can still drive the idle robot).
- ``odom`` (nav_msgs/Odometry, in, sensor-data QoS): the pose in the odometry frame
  (REP-105 odom -> base_link). Kept as a short history, so that each camera frame
  gets the pose *at its time stamp*.
- a camera (sensor_msgs/Image rgb8/bgr8, and CameraInfo, sensor-data QoS); optional
  depth (32FC1 m or 16UC1 mm) and, from the simulator, a label-id segmentation image
  with its id -> label map (std_msgs/String JSON, latched).
- ``hazard_detection`` (irobot_create_msgs/HazardDetectionVector, sensor-data QoS) where
  ``interfaces/build.sh`` built that package (``hardware/hazards.py``): a bump stops a
  forward motion at once (BLOCKED) and refuses forward motion while the bumper is pressed,
  a stall stops the motion (BLOCKED), a cliff or a dropped wheel stops every motion (FAULT,
  which ends the mission). Each hazard is kept as a point in the odometry frame
  (``hazards()``, for the local costmap), and the one that stopped the latest motion
  (``blocked_by()``) is named in the tree's failure message ("bumped front left at
  (1.20, 0.40)").

Safety: velocities are clipped to the Create 3's limits. Reversing is allowed only
within the robot's backup limit (``backup_limit.BackupBuffer``: with ``safety_override:
none`` it reverses at most 0.15 m, over floor it has just driven forward over); a
reverse command beyond it ends the motion as BLOCKED instead of being sent. The command
is replaced by a stop while odometry is stale (``odom_timeout``, 0.3 s) or the camera
is silent (``camera_timeout``, 2 s), on ``stop()``, ``close()`` and interpreter exit.
A short odometry gap only pauses the robot: ``motion_status()`` turns FAULT, and
``fault()`` reports SENSOR_TIMEOUT (the tree's Monitor ends the mission with it), once
odometry has been missing for ``odom_fault_s`` (1 s) or the camera for
``camera_timeout``.

Discrete steps (forward 0.25 m, turn 30 deg) are closed on odometry in the
heartbeat thread. A motion that makes no progress for ``stall_s`` ends as BLOCKED.

Threading: subscriptions run in the node's executor thread(s) and only store
messages; ``observe()`` waits for a frame that arrives after the call and decodes
it in the caller's thread (the tree's worker). Every method is thread-safe.
Staleness uses the monotonic wall clock, so it holds with simulated time too.
"""

from __future__ import annotations

import atexit
import contextlib
import json
import math
import threading
import time
import weakref
from collections import deque
from dataclasses import dataclass

from pmnav_bt.backup_limit import BackupBuffer
from pmnav_bt.errors import PmNavError, SensorError
from pmnav_bt.failures import Failure, FailureCode
from pmnav_bt.geometry import wrap_angle
from pmnav_bt.hardware import qos
from pmnav_bt.hardware.clock import RosClock
from pmnav_bt.hardware.hazards import (
    FAULT_KINDS,
    HazardWatch,
    hazards_from_message,
    message_types,
)
from pmnav_bt.hardware.messages import (
    depth_from_image,
    intrinsics_from_camera_info,
    labels_from_image,
    pose_from_odometry,
    rgb_from_image,
    shrink_frame,
    stamp_to_sec,
)
from pmnav_bt.hazards import Hazard
from pmnav_bt.seams import (
    CAMERA_HEIGHT_M,
    CREATE3_MAX_ANGULAR,
    CREATE3_MAX_LINEAR,
    FORWARD_STEP_M,
    TURN_STEP_RAD,
    CameraIntrinsics,
    DiscreteAction,
    ImageReading,
    MotionStatus,
    Observation,
    Pose2D,
)

MAX_LINEAR = CREATE3_MAX_LINEAR  # m/s, Create 3 with safety_override none
MAX_ANGULAR = CREATE3_MAX_ANGULAR  # rad/s
ZERO_BURST = 3  # zero commands sent on a stop
STEP_TOL_M = 0.005
STEP_TOL_RAD = math.radians(0.5)
HISTORY = 200  # odometry messages kept (10 s at 20 Hz)


class SensorTimeoutError(SensorError):
    """No fresh camera frame (or depth/segmentation to go with it) within the timeout."""


class BaseClosedError(PmNavError):
    """The base was closed (shutdown) while waiting."""


@dataclass
class Create3Options:
    """Topics, rates, timeouts and limits of a Create3Base (all SI units)."""

    cmd_vel_topic: str = "cmd_vel"
    odom_topic: str = "odom"
    image_topic: str = "camera/image_raw"
    camera_info_topic: str = "camera/camera_info"
    depth_topic: str = ""  # "" = no depth
    segmentation_topic: str = ""  # "" = none (the simulator publishes one)
    labels_topic: str = ""  # the segmentation's id -> label JSON (latched)
    hazard_topic: str = "hazard_detection"  # "" = none; used where irobot_create_msgs is built
    cmd_rate_hz: float = 20.0
    odom_timeout: float = 0.3  # hold the robot stopped when odometry is older than this
    odom_fault_s: float = 1.0  # ... and report FAULT (the mission fails) after this long
    camera_timeout: float = 2.0  # hold stopped, and fail, when the camera is this silent
    sync_slop: float = 0.05  # depth/segmentation match the colour frame within this (s)
    max_linear: float = MAX_LINEAR
    max_angular: float = MAX_ANGULAR
    camera_height: float = CAMERA_HEIGHT_M
    hfov_deg: float = 60.0  # intrinsics until a CameraInfo arrives
    stall_s: float = 2.0
    # frames wider than this are shrunk to it for the tree, and the camera's full image is
    # kept as the observation's view for reading signs (0: the tree gets the camera's image)
    frame_width: int = 0

    def __post_init__(self) -> None:
        for name in ("cmd_rate_hz", "odom_timeout", "camera_timeout", "max_linear", "max_angular"):
            if not getattr(self, name) > 0.0:
                raise PmNavError(f"Create3Options.{name} must be > 0, not {getattr(self, name)}")
        self.odom_fault_s = max(self.odom_fault_s, self.odom_timeout)


@dataclass
class _Step:
    action: DiscreteAction
    start: Pose2D
    best: float  # remaining distance/angle at the last progress
    best_t: float


@dataclass
class _Stamped:
    stamp: float  # header stamp, s
    arrival: float  # monotonic, s
    msg: object


def _interpolate(a: tuple[float, Pose2D], b: tuple[float, Pose2D], t: float) -> Pose2D:
    (ta, pa), (tb, pb) = a, b
    f = 0.0 if tb <= ta else min(1.0, max(0.0, (t - ta) / (tb - ta)))
    yaw = pa.yaw + f * wrap_angle(pb.yaw - pa.yaw)
    return Pose2D(pa.x + f * (pb.x - pa.x), pa.y + f * (pb.y - pa.y), wrap_angle(yaw))


class Create3Base:
    """A ``Base`` for the Create 3 on an rclpy ``node`` that some executor spins.

    The caller owns the node and its executor (``RosRuntime`` in ``hardware/node.py``
    spins one in a background thread). ``close()`` stops the robot and the heartbeat.
    """

    def __init__(self, node, options: Create3Options | None = None) -> None:
        from geometry_msgs.msg import Twist
        from nav_msgs.msg import Odometry
        from rclpy.callback_groups import ReentrantCallbackGroup
        from sensor_msgs.msg import CameraInfo, Image
        from std_msgs.msg import String

        self.node = node
        self.options = opt = options or Create3Options()
        self.clock = RosClock(node)
        self._Twist = Twist
        self._lock = threading.RLock()
        self._frames = threading.Condition(self._lock)
        self._odom: deque[tuple[float, Pose2D]] = deque(maxlen=HISTORY)
        self._odom_arrival: float | None = None
        self._rgb: deque[_Stamped] = deque(maxlen=3)
        self._depth: deque[_Stamped] = deque(maxlen=6)
        self._seg: deque[_Stamped] = deque(maxlen=6)
        self._labels: dict[int, str] | None = None
        self._info = None
        self._camera_arrival: float | None = None
        self._cmd = (0.0, 0.0)
        self._step: _Step | None = None
        self._status = MotionStatus.IDLE
        self._zero_left = 0
        self._progress: tuple[Pose2D, float] | None = None
        self._hazards = HazardWatch()
        self._blocked_by: Hazard | None = None  # what stopped or refused the latest motion
        self._motion_since = 0.0  # monotonic: when the motion in force began
        self.backup = BackupBuffer()  # how far the robot may still reverse
        self._stale: str | None = "odometry"
        self._stale_since: float | None = None
        self._warned = False
        self._closing = threading.Event()
        self._wake = threading.Event()
        self.published = 0  # cmd_vel messages sent (for tests and benchmarks)
        self.max_odom_gap = 0.0  # longest time between two odometry messages (s)
        self._sent: deque[tuple[float, bool]] = deque(maxlen=4000)  # (monotonic, moving)

        group = ReentrantCallbackGroup()
        self._pub = node.create_publisher(Twist, opt.cmd_vel_topic, qos.command())
        sensor = qos.sensor()
        self._subs = [
            node.create_subscription(
                Odometry, opt.odom_topic, self._on_odom, sensor, callback_group=group
            ),
            node.create_subscription(
                Image, opt.image_topic, self._on_image, sensor, callback_group=group
            ),
            node.create_subscription(
                CameraInfo, opt.camera_info_topic, self._on_info, sensor, callback_group=group
            ),
        ]
        if opt.depth_topic:
            self._subs.append(
                node.create_subscription(
                    Image, opt.depth_topic, self._on_depth, sensor, callback_group=group
                )
            )
        if opt.segmentation_topic:
            self._subs.append(
                node.create_subscription(
                    Image, opt.segmentation_topic, self._on_seg, sensor, callback_group=group
                )
            )
        if opt.labels_topic:
            self._subs.append(
                node.create_subscription(
                    String, opt.labels_topic, self._on_labels, qos.latched(), callback_group=group
                )
            )
        types = message_types() if opt.hazard_topic else None
        self.hazards_enabled = types is not None
        if types is not None:
            self._subs.append(
                node.create_subscription(
                    types[0], opt.hazard_topic, self._on_hazards, sensor, callback_group=group
                )
            )
        elif opt.hazard_topic:
            node.get_logger().warn(
                "irobot_create_msgs is not built (interfaces/build.sh): no bumps, cliffs or "
                f"wheel stalls from {self._topic(opt.hazard_topic)}"
            )
        self._thread = threading.Thread(target=self._heartbeat, name="create3-cmd-vel", daemon=True)
        self._thread.start()
        ref = weakref.ref(self)
        self._atexit = lambda: (b := ref()) is not None and b.close()
        atexit.register(self._atexit)

    # -- Base seam ------------------------------------------------------------------------

    def pose(self) -> Pose2D:
        """The latest odometry pose (the origin before the first message)."""
        with self._lock:
            return self._odom[-1][1] if self._odom else Pose2D(0.0, 0.0, 0.0)

    def observe(self) -> Observation:
        """The first camera frame that arrives after the call, with the odometry pose at
        its stamp, and matching depth/segmentation when configured.

        Raises SensorTimeoutError when none comes within ``camera_timeout``.
        """
        opt = self.options
        t_req = time.monotonic()
        deadline = t_req + opt.camera_timeout
        with self._frames:
            rgb = self._wait(lambda: self._newest_after(self._rgb, t_req), deadline, "camera")
            if rgb is None:
                age = self._age(self._camera_arrival)
                last = "never received one" if age is None else f"the last came {age:.1f} s ago"
                raise SensorTimeoutError(
                    f"no camera frame on {self._topic(opt.image_topic)} within "
                    f"{opt.camera_timeout:.1f} s ({last})"
                )
            depth = seg = labels = None
            extra = min(deadline, time.monotonic() + 0.5)
            if opt.depth_topic:
                depth = self._wait(lambda: self._match(self._depth, rgb.stamp), extra, "depth")
                if depth is None:
                    raise SensorTimeoutError(
                        f"no depth frame on {self._topic(opt.depth_topic)} within "
                        f"{opt.sync_slop:.2f} s of the camera frame"
                    )
            if opt.segmentation_topic:
                seg = self._wait(lambda: self._match(self._seg, rgb.stamp), extra, "segmentation")
                if seg is None:
                    raise SensorTimeoutError(
                        f"no segmentation frame on {self._topic(opt.segmentation_topic)} "
                        f"within {opt.sync_slop:.2f} s of the camera frame"
                    )
                labels = self._labels
                if labels is None:
                    raise SensorTimeoutError(
                        f"no segmentation labels received on {self._topic(opt.labels_topic)}"
                    )
            pose = self._pose_at(rgb.stamp)
            info = self._info
        image = rgb_from_image(rgb.msg)
        d = depth_from_image(depth.msg) if depth is not None else None
        s = labels_from_image(seg.msg) if seg is not None else None
        reading = None
        if 0 < opt.frame_width < image.shape[1]:
            reading = ImageReading(image)
            image, d, s = shrink_frame(image, d, s, opt.frame_width)
        h, w = image.shape[:2]
        k = intrinsics_from_camera_info(info, w, h) if info is not None else None
        if k is None:
            k = CameraIntrinsics.from_hfov(w, h, math.radians(opt.hfov_deg))
        return Observation(
            rgb=image,
            pose=pose,
            stamp=rgb.stamp,
            intrinsics=k,
            depth=d,
            segmentation=s,
            labels=dict(labels) if labels is not None else {},
            camera_height=opt.camera_height,
            reading=reading,
        )

    def camera_width(self) -> int | None:
        """The width (pixels) of the camera's newest image (None before the first): the
        width signs are read at."""
        with self._frames:
            return int(self._rgb[-1].msg.width) if self._rgb else None

    def step(self, action: DiscreteAction) -> None:
        """Start a discrete step, closed on odometry; replaces any motion in progress."""
        action = DiscreteAction(action)
        if action == DiscreteAction.STOP:
            self.stop()
            return
        forward = action == DiscreteAction.FORWARD
        with self._lock:
            now = time.monotonic()
            was_moving = self._cmd != (0.0, 0.0) or self._step is not None
            if self._refuse(1.0 if forward else 0.0, 0.0 if forward else 1.0, now):
                self._stop_now(was_moving)
                return
            start = self.pose()
            goal = FORWARD_STEP_M if forward else TURN_STEP_RAD
            self._step = _Step(action, start, goal, now)
            self._cmd = (0.0, 0.0)
            self._progress = None
            self._status = MotionStatus.MOVING
            self._motion_since = now
        self._wake.set()

    def set_velocity(self, linear: float, angular: float) -> None:
        """Command a body velocity: linear clipped to +-max_linear (backwards only within
        the backup limit: beyond it the motion ends BLOCKED), angular to +-max_angular.
        Holds until changed; republished at ``cmd_rate_hz``."""
        v = min(self.options.max_linear, max(-self.options.max_linear, float(linear)))
        w = max(-self.options.max_angular, min(self.options.max_angular, float(angular)))
        if not (math.isfinite(v) and math.isfinite(w)):
            v = w = 0.0
        with self._lock:
            now = time.monotonic()
            was_moving = self._cmd != (0.0, 0.0) or self._step is not None
            if self._refuse(v, w, now):
                self._stop_now(was_moving)
                return
            self._step = None
            if (v, w) != self._cmd:
                self._progress = None
            self._cmd = (v, w)
            moving = (v, w) != (0.0, 0.0)
            self._status = MotionStatus.MOVING if moving else MotionStatus.IDLE
            if moving and not was_moving:
                self._motion_since = now
            if not moving and was_moving:
                self._zero_left = ZERO_BURST
        if moving != was_moving:
            self._wake.set()

    def motion_status(self) -> MotionStatus:
        """FAULT once odometry has been missing for ``odom_fault_s`` (the robot is held
        stopped from ``odom_timeout`` on) or while a cliff or a dropped wheel is felt;
        else the state of the last command."""
        with self._lock:
            if self._odom_stale(self.options.odom_fault_s):
                return MotionStatus.FAULT
            if self._hazards.fault(time.monotonic()) is not None:
                return MotionStatus.FAULT
            return self._status

    def stop(self) -> None:
        """Stop at once (a zero command now, and a few more), dropping any step."""
        with self._lock:
            self._step = None
            self._cmd = (0.0, 0.0)
            self._progress = None
            self._status = MotionStatus.IDLE
            self._zero_left = ZERO_BURST
        self._publish(0.0, 0.0)

    # -- beyond the seam ------------------------------------------------------------------

    def hazards(self, since: float = -math.inf) -> list[Hazard]:
        """The bumps, cliffs and wheel stalls felt with a stamp (ROS time, the tree's clock)
        from ``since`` on, oldest first, each a point in the odometry frame
        (``pmnav_bt.hazards``): for the local costmap to mark."""
        with self._lock:
            return self._hazards.felt(since)

    def blocked_by(self) -> Hazard | None:
        """The hazard that stopped or refused the latest motion command (a cliff felt
        now even without one); None once a motion was accepted after it."""
        with self._lock:
            return self._hazards.fault(time.monotonic()) or self._blocked_by

    def fault(self) -> Failure | None:
        """Why the body cannot go on (stale odometry, a silent camera), or None."""
        opt = self.options
        with self._lock:
            odom_age = self._age(self._odom_arrival)
            cam_age = self._age(self._camera_arrival)
        for age, what, topic, limit, name, digits in (
            (odom_age, "odometry", opt.odom_topic, opt.odom_fault_s, "odom_fault_s", 2),
            (cam_age, "camera frame", opt.image_topic, opt.camera_timeout, "camera_timeout", 1),
        ):
            if age is None:
                return Failure(
                    FailureCode.SENSOR_TIMEOUT, f"no {what} received on {self._topic(topic)}"
                )
            if age > limit:
                return Failure(
                    FailureCode.SENSOR_TIMEOUT,
                    f"no {what} on {self._topic(topic)} for {age:.{digits}f} s "
                    f"({name} {limit:.{digits}f} s)",
                )
        return None

    def sensors(self) -> dict[str, float | None]:
        """Seconds since the last odometry and camera message (None: never), and the
        longest odometry gap seen."""
        with self._lock:
            return {
                "odom_age": self._age(self._odom_arrival),
                "camera_age": self._age(self._camera_arrival),
                "max_odom_gap": self.max_odom_gap,
            }

    def cmd_periods(self) -> list[float]:
        """Seconds between consecutive motion (non-zero) cmd_vel messages, as published."""
        sent = list(self._sent)
        return [b[0] - a[0] for a, b in zip(sent, sent[1:], strict=False) if a[1] and b[1]]

    @property
    def velocity_command(self) -> tuple[float, float]:
        with self._lock:
            return self._cmd

    def close(self) -> None:
        """Stop the robot and the heartbeat; wake any waiting observe(). Idempotent."""
        if self._closing.is_set():
            return
        with self._lock:
            self._step = None
            self._cmd = (0.0, 0.0)
        for _ in range(ZERO_BURST):
            self._publish(0.0, 0.0)
        with contextlib.suppress(Exception):  # let the stop reach the robot before we go
            from rclpy.duration import Duration

            self._pub.wait_for_all_acked(Duration(seconds=0.5))
        self._closing.set()
        self._wake.set()
        with self._frames:
            self._frames.notify_all()
        if threading.current_thread() is not self._thread:
            self._thread.join(timeout=1.0)
        atexit.unregister(self._atexit)

    # -- subscriptions ----------------------------------------------------------------------

    def _on_odom(self, msg) -> None:
        pose = pose_from_odometry(msg)
        t = stamp_to_sec(msg.header.stamp)
        now = time.monotonic()
        with self._lock:
            if self._odom and t < self._odom[-1][0]:
                self._odom.clear()  # time went backwards (a restarted robot or bag)
            self._odom.append((t, pose))
            self.backup.update(pose)
            if self._odom_arrival is not None:
                self.max_odom_gap = max(self.max_odom_gap, now - self._odom_arrival)
            self._odom_arrival = now

    def _on_image(self, msg) -> None:
        self._store(self._rgb, msg)
        with self._lock:
            self._camera_arrival = time.monotonic()

    def _on_depth(self, msg) -> None:
        self._store(self._depth, msg)

    def _on_seg(self, msg) -> None:
        self._store(self._seg, msg)

    def _on_info(self, msg) -> None:
        with self._lock:
            self._info = msg

    def _on_labels(self, msg) -> None:
        try:
            labels = {int(k): str(v) for k, v in json.loads(msg.data).items()}
        except (ValueError, AttributeError, TypeError):
            self.node.get_logger().error(f"bad segmentation labels JSON: {msg.data[:80]!r}")
            return
        with self._frames:
            self._labels = labels
            self._frames.notify_all()

    def _on_hazards(self, msg) -> None:
        """Keep what the robot felt; stop at once a motion that a hazard forbids."""
        if not msg.detections:
            return
        now = time.monotonic()
        with self._lock:
            for hazard in hazards_from_message(msg, self._pose_at, stamp_to_sec):
                self._hazards.feel(hazard, now)
            stopped = self._stop_if_forbidden(now)
        if stopped is not None:
            self._stop_now(True)
            self.node.get_logger().warn(f"stopped: {stopped.describe()}")

    def _store(self, buf: deque, msg) -> None:
        item = _Stamped(stamp_to_sec(msg.header.stamp), time.monotonic(), msg)
        with self._frames:
            buf.append(item)
            self._frames.notify_all()

    # -- helpers (call with the lock held) --------------------------------------------------

    def _topic(self, name: str) -> str:
        try:
            return self.node.resolve_topic_name(name)
        except Exception:  # noqa: BLE001 - only for messages
            return name

    @staticmethod
    def _age(t: float | None) -> float | None:
        return None if t is None else time.monotonic() - t

    def _odom_stale(self, timeout: float | None = None) -> bool:
        age = self._age(self._odom_arrival)
        return age is None or age > (self.options.odom_timeout if timeout is None else timeout)

    def _camera_stale(self) -> bool:
        age = self._age(self._camera_arrival)
        return age is None or age > self.options.camera_timeout

    def _wait(self, find, deadline: float, what: str):
        while True:
            if self._closing.is_set():
                raise BaseClosedError(f"the base was closed while waiting for {what}")
            item = find()
            if item is not None:
                return item
            remaining = deadline - time.monotonic()
            if remaining <= 0.0:
                return None
            self._frames.wait(remaining)

    @staticmethod
    def _newest_after(buf: deque, t: float) -> _Stamped | None:
        for item in reversed(buf):
            if item.arrival > t:
                return item
        return None

    def _match(self, buf: deque, stamp: float) -> _Stamped | None:
        best = min(buf, key=lambda it: abs(it.stamp - stamp), default=None)
        if best is not None and abs(best.stamp - stamp) <= self.options.sync_slop:
            return best
        return None

    def _pose_at(self, t: float) -> Pose2D:
        """Odometry at stamp ``t`` (interpolated); the latest pose if the history does not
        cover it (clocks out of sync)."""
        hist = self._odom
        if not hist:
            return Pose2D(0.0, 0.0, 0.0)
        if t >= hist[-1][0]:
            return hist[-1][1]
        if t <= hist[0][0]:
            return hist[-1][1] if hist[0][0] - t > 1.0 else hist[0][1]
        for i in range(len(hist) - 1, 0, -1):
            if hist[i - 1][0] <= t:
                return _interpolate(hist[i - 1], hist[i], t)
        return hist[-1][1]

    def _motion(self) -> tuple[float, float]:
        """The motion in force as (v, w): a step's direction, else the command."""
        s = self._step
        if s is None:
            return self._cmd
        if s.action == DiscreteAction.FORWARD:
            return 1.0, 0.0
        return 0.0, 1.0 if s.action == DiscreteAction.TURN_LEFT else -1.0

    def _refuse(self, v: float, w: float, now: float) -> bool:
        """Whether a hazard forbids a new motion (v, w): then the body stops, BLOCKED or
        FAULT. An allowed motion clears what blocked the last one."""
        hazard = self._hazards.forbids(v, w, now, 0.0)
        if hazard is None:
            if (v, w) != (0.0, 0.0):
                self._blocked_by = None
            return False
        self._halt(hazard)
        return True

    def _stop_now(self, was_moving: bool) -> None:
        """A zero command at once (not at the heartbeat's next beat) if the body moved."""
        if was_moving:
            self._publish(0.0, 0.0)
            self._wake.set()

    def _stop_if_forbidden(self, now: float) -> Hazard | None:
        """Stop the motion in force if a hazard forbids it; that hazard, or None."""
        v, w = self._motion()
        hazard = self._hazards.forbids(v, w, now, now - self._motion_since)
        if hazard is not None:
            self._halt(hazard)
        return hazard

    def _halt(self, hazard: Hazard) -> None:
        """Stop for ``hazard``: FAULT for a cliff or a dropped wheel, else BLOCKED."""
        self._step = None
        self._cmd = (0.0, 0.0)
        self._progress = None
        fault = hazard.kind in FAULT_KINDS
        self._status = MotionStatus.FAULT if fault else MotionStatus.BLOCKED
        self._zero_left = ZERO_BURST
        self._blocked_by = hazard

    def _block(self, why: str) -> None:
        self._step = None
        self._cmd = (0.0, 0.0)
        self._progress = None
        self._status = MotionStatus.BLOCKED
        self._zero_left = ZERO_BURST
        self.node.get_logger().warn(f"motion blocked ({why})")

    # -- the heartbeat ----------------------------------------------------------------------

    def _publish(self, v: float, w: float) -> None:
        msg = self._Twist()
        msg.linear.x = float(v)
        msg.angular.z = float(w)
        try:
            self._pub.publish(msg)
        except Exception:  # noqa: BLE001 - the context may be shutting down
            return
        self.published += 1
        self._sent.append((time.monotonic(), bool(v or w)))

    def _heartbeat(self) -> None:
        """Publish the command every period while moving; between periods, wake at the
        moment odometry or camera would go stale, so a stop goes out without delay."""
        period = 1.0 / self.options.cmd_rate_hz
        next_t = time.monotonic()
        while not self._closing.is_set():
            now = time.monotonic()
            on_cadence = now >= next_t - 1e-4
            if on_cadence:
                next_t += period
                if next_t < now:  # fell behind: restart the cadence, no burst
                    next_t = now + period
            cmd = self._cycle(now, on_cadence)
            if cmd is not None:
                self._publish(*cmd)
            wake = next_t
            guard = self._stale_deadline()
            if guard is not None and now < guard < wake:
                wake = guard
            if self._wake.wait(max(0.0, wake - time.monotonic())):
                self._wake.clear()
                next_t = time.monotonic()

    def _stale_deadline(self) -> float | None:
        """While a motion is commanded: when the newest odometry or frame goes stale."""
        opt = self.options
        with self._lock:
            if self._cmd == (0.0, 0.0) and self._step is None:
                return None
            if self._odom_arrival is None or self._camera_arrival is None:
                return None
            return 1e-3 + min(
                self._odom_arrival + opt.odom_timeout, self._camera_arrival + opt.camera_timeout
            )

    def _cycle(self, now: float, on_cadence: bool = True) -> tuple[float, float] | None:
        """The command to publish now (None: stay silent). Off the cadence only a stop
        caused by a sensor going stale is returned."""
        with self._lock:
            stale = "odometry" if self._odom_stale() else "camera" if self._camera_stale() else None
            halted = False
            if stale is not None:
                if self._cmd != (0.0, 0.0) or self._step is not None:
                    self._step = None
                    self._cmd = (0.0, 0.0)
                    self._zero_left = ZERO_BURST
                    halted = True
                if halted and not self._warned:
                    self._warned = True
                    self.node.get_logger().warn(f"stale {stale}: holding the robot stopped")
            elif self._warned and self._stale_since is not None:
                self._warned = False
                gap = now - self._stale_since
                self.node.get_logger().info(f"{self._stale} back after {gap:.2f} s")
            if stale != self._stale:
                self._stale_since = now if stale is not None else None
            self._stale = stale
            if not on_cadence:
                return (0.0, 0.0) if halted else None
            if self._step is not None:
                cmd = self._step_command(now)
            else:
                cmd = self._cmd
                if not self.backup.allows(cmd[0]):
                    self._block(f"backup limit ({self.backup.limit:.2f} m) reached")
                    cmd = self._cmd
                if cmd != (0.0, 0.0):
                    self._check_stall(now)
                    cmd = self._cmd
            if cmd != (0.0, 0.0):
                self._zero_left = 0
                return cmd
            if self._zero_left > 0:
                self._zero_left -= 1
                return 0.0, 0.0
            return None

    def _check_stall(self, now: float) -> None:
        v, w = self._cmd
        pose = self.pose()
        if self._progress is None:
            self._progress = (pose, now)
            return
        ref, t0 = self._progress
        driving = abs(v) >= 0.05
        turning = not driving and abs(w) >= 0.2
        moved = math.hypot(pose.x - ref.x, pose.y - ref.y)
        turned = abs(wrap_angle(pose.yaw - ref.yaw))
        if not (driving or turning) or (driving and moved > 0.02) or (turning and turned > 0.05):
            self._progress = (pose, now)
        elif now - t0 > self.options.stall_s:
            self._block(f"no progress for {self.options.stall_s:.1f} s")

    def _step_command(self, now: float) -> tuple[float, float]:
        s = self._step
        opt = self.options
        pose = self.pose()
        if s.action == DiscreteAction.FORWARD:
            done = math.hypot(pose.x - s.start.x, pose.y - s.start.y)
            remaining = FORWARD_STEP_M - done
            tol = STEP_TOL_M
        else:
            sign = 1.0 if s.action == DiscreteAction.TURN_LEFT else -1.0
            remaining = TURN_STEP_RAD - sign * wrap_angle(pose.yaw - s.start.yaw)
            tol = STEP_TOL_RAD
        if remaining <= tol:
            self._step = None
            self._status = MotionStatus.IDLE
            self._zero_left = ZERO_BURST
            return 0.0, 0.0
        if remaining < s.best - tol:
            s.best, s.best_t = remaining, now
        elif now - s.best_t > opt.stall_s:
            self._block(f"step {s.action.value} made no progress for {opt.stall_s:.1f} s")
            return 0.0, 0.0
        if s.action == DiscreteAction.FORWARD:
            v = min(opt.max_linear, 1.2 * remaining + 0.05)
            w = max(
                -opt.max_angular, min(opt.max_angular, 2.0 * wrap_angle(s.start.yaw - pose.yaw))
            )
            return v, w
        return 0.0, sign * min(opt.max_angular, 2.5 * remaining + 0.15)
