"""``pmnav-sim-create3``: the pybullet simulator behind the Create 3's ROS 2 topics.

A SimWorld and a SimBase (with drifting wheel odometry, ``odometry_noise``) driven in
real time: a timer advances the SimClock by the wall time elapsed since its last
call. It speaks the robot's topics, so ``pmnav-ros`` runs against it exactly as
against a Create 3:

- in ``cmd_vel`` (geometry_msgs/Twist); like the robot it stops ``cmd_timeout``
  (0.5 s) after the last command, and with ``safety_override: none`` reverses at most
  its backup limit (0.15 m, refilled by driving forward; ``pmnav_bt/backup_limit.py``);
- out ``odom`` (nav_msgs/Odometry, ``odom_rate_hz``): odom -> base_link; with
  ``odom_at_origin`` (default) the odometry frame starts at the start pose, as a
  Create 3's does where it boots;
- out ``camera/image_raw`` (rgb8), ``camera/camera_info``, ``camera/depth/image_raw``
  (32FC1 m), ``camera/segmentation`` (16UC1 label ids) at ``camera_rate_hz``, all
  with one stamp (the render time) and sensor-data QoS; ``camera/segmentation_labels``
  (std_msgs/String JSON id -> label, latched). With ``publish_segmentation`` false no
  segmentation is rendered or published: the real stack (``grounder.backend`` ``ocr``
  or ``gdino_sam``) needs none;
- out ``hazard_detection`` (irobot_create_msgs/HazardDetectionVector, ``hazard_rate_hz``,
  QoS as the robot's: reliable sensor data) where ``interfaces/build.sh`` built that
  package: BUMP in the bumper zone pressed, driving into something (``sim/bumper.py``), STALL of
  both wheels when commanded to drive for ``STALL_AFTER_S`` without moving, BACKUP_LIMIT
  while a reverse command is refused. Its worlds have no floor edges, so no CLIFF;
- out ``sim/true_pose`` (geometry_msgs/PoseStamped, frame ``map``: ground truth) and
  ``sim/stats`` (std_msgs/String JSON: collisions, path length, rotation).

Fault injection: the parameters ``publish_odom`` and ``publish_camera`` can be set to
false at run time (``ros2 param set /sim_create3 publish_camera false``).
"""

from __future__ import annotations

import json
import math
import sys
import threading
import time

from pmnav_bt.backup_limit import BackupBuffer
from pmnav_bt.errors import PmNavError
from pmnav_bt.geometry import se2_compose, se2_inverse, wrap_angle
from pmnav_bt.seams import CAMERA_HEIGHT_M, Pose2D

# A wheel stall: commanded to drive at least STALL_SPEED for STALL_AFTER_S without
# getting STALL_MOVE_M further (the robot feels it in its motor currents).
STALL_SPEED = 0.05  # m/s
STALL_AFTER_S = 0.5
STALL_MOVE_M = 0.01

PARAMETERS = {
    "building": ("fig2_hospital", "building file (YAML) or built-in name"),
    "start_pose": ("", "x,y,yaw_deg in the map frame; empty: the building's start"),
    "width": (320, "camera image width, pixels"),
    "height": (240, "camera image height, pixels"),
    "hfov_deg": (60.0, "horizontal field of view"),
    "camera_height": (CAMERA_HEIGHT_M, "m"),
    "camera_rate_hz": (5.0, "frames per second (rendering costs ~25 ms at 320x240)"),
    "odom_rate_hz": (20.0, ""),
    "physics_rate_hz": (50.0, "how often sim time catches up with the wall clock"),
    "hazard_rate_hz": (20.0, "hazard_detection messages a second (the robot: about 60)"),
    "cmd_timeout": (0.5, "stop this long after the last cmd_vel (s)"),
    "odometry_noise": (0.02, "relative error of each odometry increment"),
    "seed": (0, "odometry noise seed"),
    "odom_at_origin": (True, "odometry frame starts at the start pose"),
    "publish_odom": (True, "false: stop publishing odometry (fault injection)"),
    "publish_camera": (True, "false: stop publishing camera frames (fault injection)"),
    "publish_segmentation": (
        True,
        "false: render and publish no segmentation (the real stack needs none; sim_gt does)",
    ),
    "odom_frame": ("odom", ""),
    "base_frame": ("base_link", ""),
    "camera_frame": ("camera_optical_frame", ""),
    "map_frame": ("map", ""),
}


class SimCreate3:
    """The node's logic on an rclpy ``node``."""

    def __init__(self, node) -> None:
        from geometry_msgs.msg import PoseStamped, Twist
        from nav_msgs.msg import Odometry
        from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
        from sensor_msgs.msg import CameraInfo, Image
        from std_msgs.msg import String

        from pmnav_bt.hardware import qos
        from pmnav_bt.hardware.hazards import message_types
        from pmnav_bt.hardware.node import declare_parameters
        from pmnav_bt.sim.clock import SimClock
        from pmnav_bt.sim.odometry import NoisyOdometry
        from pmnav_bt.sim.poses import parse_pose
        from pmnav_bt.sim.robot import SimBase
        from pmnav_bt.sim.world import SimWorld

        self.node = node
        self.log = node.get_logger()
        self.p = p = declare_parameters(node, PARAMETERS)
        self._String, self._Odometry = String, Odometry
        self.world = SimWorld(p["building"])
        try:
            start = parse_pose(p["start_pose"]) if p["start_pose"] else self.world.start_pose()
        except PmNavError:
            self.world.close()
            raise PmNavError(
                f"parameter 'start_pose' {p['start_pose']!r}: expected 'x,y,yaw_deg', "
                "e.g. -p start_pose:=0,30,-90"
            ) from None
        self.start = start
        self.clock = SimClock(start=time.time())
        self.inner = SimBase(
            self.world,
            self.clock,
            pose=start,
            width=int(p["width"]),
            height=int(p["height"]),
            hfov=math.radians(float(p["hfov_deg"])),
            camera_height=float(p["camera_height"]),
            segmentation=bool(p["publish_segmentation"]),
            backup_limit=None,  # kept below from odometry, as the robot keeps it
        )
        self.base = NoisyOdometry(self.inner, float(p["odometry_noise"]), seed=int(p["seed"]))
        self.backup = BackupBuffer()
        self._odom_T_map = (
            se2_inverse((start.x, start.y, start.yaw)) if p["odom_at_origin"] else (0.0, 0.0, 0.0)
        )
        self._lock = threading.Lock()
        self._last_wall = time.monotonic()
        self._last_cmd: float | None = None
        self._wanted = (0.0, 0.0)  # the last cmd_vel, before the backup limit refused it
        self._stall_ref: tuple[Pose2D, float] | None = None  # progress of a drive
        self._last_odom: tuple[float, Pose2D] | None = None
        self._labels_sent = -1
        self.frames = 0

        sensor, latched, ev = qos.sensor(), qos.latched(), qos.events()
        self.pub_odom = node.create_publisher(Odometry, "odom", ev)
        self.pub_rgb = node.create_publisher(Image, "camera/image_raw", sensor)
        self.pub_info = node.create_publisher(CameraInfo, "camera/camera_info", sensor)
        self.pub_depth = node.create_publisher(Image, "camera/depth/image_raw", sensor)
        self.pub_seg = node.create_publisher(Image, "camera/segmentation", sensor)
        self.pub_labels = node.create_publisher(String, "camera/segmentation_labels", latched)
        self.pub_true = node.create_publisher(PoseStamped, "sim/true_pose", ev)
        self.pub_stats = node.create_publisher(String, "sim/stats", ev)
        motion = MutuallyExclusiveCallbackGroup()
        camera = MutuallyExclusiveCallbackGroup()
        node.create_subscription(
            Twist, "cmd_vel", self._on_cmd, qos.events(), callback_group=motion
        )
        node.create_timer(1.0 / float(p["physics_rate_hz"]), self._physics, callback_group=motion)
        node.create_timer(1.0 / float(p["odom_rate_hz"]), self._odom, callback_group=motion)
        node.create_timer(1.0 / float(p["camera_rate_hz"]), self._camera, callback_group=camera)
        node.create_timer(1.0, self._stats, callback_group=motion)
        self._hazard_types = message_types()
        if self._hazard_types is None:
            self.log.warn(
                "irobot_create_msgs is not built (interfaces/build.sh): no hazard_detection"
            )
        else:
            self.pub_hazards = node.create_publisher(
                self._hazard_types[0], "hazard_detection", qos.hazards()
            )
            rate = float(p["hazard_rate_hz"])
            node.create_timer(1.0 / rate, self._hazards, callback_group=motion)
        self._publish_labels()
        self.log.info(
            f"simulated Create 3 in {self.world.building.name} at "
            f"({start.x:.2f}, {start.y:.2f}, {math.degrees(start.yaw):.0f} deg), camera "
            f"{p['width']}x{p['height']} at {p['camera_rate_hz']} Hz"
        )

    # -- motion ---------------------------------------------------------------------------

    def _on_cmd(self, msg) -> None:
        with self._lock:
            self._physics_locked()
            self._last_cmd = time.monotonic()
            v, w = float(msg.linear.x), float(msg.angular.z)
            self._wanted = (v, w)
            if not self.backup.allows(v):
                v = w = 0.0  # the robot refuses to reverse beyond its backup limit
            self.inner.set_velocity(v, w)

    def _physics(self) -> None:
        with self._lock:
            self._physics_locked()

    def _physics_locked(self) -> None:
        now = time.monotonic()
        dt, self._last_wall = now - self._last_wall, now
        if dt > 0.25:
            self.log.warn(f"the simulator did not run for {dt:.2f} s (CPU starved?)")
        if dt > 0.0:
            self.clock.wait(min(dt, 0.5))  # a stalled process does not teleport the body
        stale = self._last_cmd is None or now - self._last_cmd > float(self.p["cmd_timeout"])
        if stale and self.inner.velocity_command != (0.0, 0.0):
            self.inner.stop()
            self.log.info("cmd_vel timeout: stopping")
        self.backup.update(self.base.pose())
        if not self.backup.allows(self.inner.velocity_command[0]):
            self.inner.stop()
            self.log.warn("reached the backup limit: stopping")

    def odom_pose(self) -> Pose2D:
        q = self.base.pose()
        x, y, yaw = se2_compose(self._odom_T_map, (q.x, q.y, q.yaw))
        return Pose2D(x, y, yaw)

    # -- publishing -------------------------------------------------------------------------

    def _stamp(self):
        """Now on the node's ROS clock (the controller's clock domain)."""
        return self.node.get_clock().now().to_msg()

    def _odom(self) -> None:
        from pmnav_bt.hardware.messages import pose_stamped, quaternion_from_yaw

        with self._lock:
            self._physics_locked()
            t = self.clock.now()
            pose = self.odom_pose()
            true = self.inner.pose()
        stamp = self._stamp()
        self.pub_true.publish(pose_stamped(true, stamp, self.p["map_frame"]))
        if not self.node.get_parameter("publish_odom").value:
            return
        v = w = 0.0
        if self._last_odom is not None:
            t0, q0 = self._last_odom
            if t > t0:
                dx, dy = pose.x - q0.x, pose.y - q0.y
                v = (math.cos(q0.yaw) * dx + math.sin(q0.yaw) * dy) / (t - t0)
                w = wrap_angle(pose.yaw - q0.yaw) / (t - t0)
        self._last_odom = (t, pose)
        msg = self._Odometry()
        msg.header.stamp = stamp
        msg.header.frame_id = self.p["odom_frame"]
        msg.child_frame_id = self.p["base_frame"]
        msg.pose.pose.position.x, msg.pose.pose.position.y = pose.x, pose.y
        msg.pose.pose.orientation = quaternion_from_yaw(pose.yaw)
        msg.twist.twist.linear.x, msg.twist.twist.angular.z = v, w
        self.pub_odom.publish(msg)

    def _camera(self) -> None:
        from pmnav_bt.hardware.messages import camera_info_message, image_message

        if not self.node.get_parameter("publish_camera").value:
            return
        with self._lock:
            self._physics_locked()
        stamp = self._stamp()
        obs = self.inner.observe()  # renders under the world's lock (~25 ms at 320x240)
        frame = self.p["camera_frame"]
        self.pub_rgb.publish(image_message(obs.rgb, "rgb8", stamp, frame))
        self.pub_info.publish(camera_info_message(obs.intrinsics, stamp, frame))
        if obs.depth is not None:
            self.pub_depth.publish(image_message(obs.depth, "32FC1", stamp, frame))
        if obs.segmentation is not None:
            seg = obs.segmentation
            if int(seg.max(initial=0)) < 65536:
                self.pub_seg.publish(image_message(seg.astype("<u2"), "16UC1", stamp, frame))
            else:
                self.pub_seg.publish(image_message(seg.astype("<i4"), "32SC1", stamp, frame))
        self.frames += 1
        self._publish_labels()

    def _hazards(self) -> None:
        """What the robot's sensors feel now, as one HazardDetectionVector (empty: none)."""
        from pmnav_bt.hardware.hazards import BACKUP_LIMIT_CODE, TYPE_CODES, vector_message
        from pmnav_bt.hazards import HazardKind
        from pmnav_bt.sim.bumper import pressed_zone
        from pmnav_bt.sim.robot import COLLISION_HEIGHT

        with self._lock:
            self._physics_locked()
            now = self.clock.now()
            true = self.inner.pose()
            driving = self._wanted[0] if self._commanded() else 0.0
            zone = pressed_zone(self.world, true, self.inner.radius, COLLISION_HEIGHT, driving)
            stalled = self._stalled(true, now)
            refused = not self.backup.allows(self._wanted[0])
        found = []
        if zone is not None:
            found.append((TYPE_CODES[HazardKind.BUMP], zone))
        if stalled:
            code = TYPE_CODES[HazardKind.STALL]
            found += [(code, "left_wheel"), (code, "right_wheel")]
        if refused and self._commanded():
            found.append((BACKUP_LIMIT_CODE, self.p["base_frame"]))
        msg = vector_message(self._hazard_types, found, self._stamp(), self.p["base_frame"])
        self.pub_hazards.publish(msg)

    def _commanded(self) -> bool:
        """Whether a cmd_vel is in force (the robot's own timeout has not stopped it)."""
        t = self._last_cmd
        return t is not None and time.monotonic() - t <= float(self.p["cmd_timeout"])

    def _stalled(self, true: Pose2D, now: float) -> bool:
        """Whether the wheels have been driven STALL_AFTER_S without moving the body."""
        v = self._wanted[0]
        if not self._commanded() or abs(v) < STALL_SPEED or not self.backup.allows(v):
            self._stall_ref = None
            return False
        ref = self._stall_ref
        if ref is None or math.dist((true.x, true.y), (ref[0].x, ref[0].y)) > STALL_MOVE_M:
            self._stall_ref = (true, now)
            return False
        return now - ref[1] >= STALL_AFTER_S

    def _publish_labels(self) -> None:
        labels = dict(self.world.labels)
        if len(labels) != self._labels_sent:
            self._labels_sent = len(labels)
            data = json.dumps({str(k): v for k, v in labels.items()})
            self.pub_labels.publish(self._String(data=data))

    def _stats(self) -> None:
        s = self.inner.stats
        q = self.inner.pose()
        stats = {
            "collisions": s.collisions,
            "path_length": round(s.path_length, 3),
            "rotation": round(s.rotation, 3),
            "true_pose": [round(q.x, 3), round(q.y, 3), round(q.yaw, 4)],
            "frames": self.frames,
            "command": list(self.inner.velocity_command),
        }
        self.pub_stats.publish(self._String(data=json.dumps(stats)))

    def close(self) -> None:
        self.inner.close()
        self.world.close()


def main(argv: list[str] | None = None) -> None:
    """Console script ``pmnav-sim-create3``: ``pmnav-sim-create3 --ros-args -p
    building:=fig2_hospital -p start_pose:=22,0,0``."""
    from pmnav_bt.hardware.params import usage, wants_help
    from pmnav_bt.hardware.runtime import run_node

    args = list(sys.argv if argv is None else argv)
    if wants_help(args):
        print(usage("pmnav-sim-create3", (__doc__ or "").split("\n\n")[0], PARAMETERS,
                    "pmnav-sim-create3 --ros-args -p building:=fig2_hospital "
                    "-p start_pose:=47,20,0"))  # fmt: skip
        sys.exit(0)
    run_node(
        "pmnav-sim-create3",
        "sim_create3",
        args,
        lambda node, _runtime: SimCreate3(node),
        after_shutdown=SimCreate3.close,
    )


if __name__ == "__main__":  # pragma: no cover
    main()
