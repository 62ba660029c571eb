"""``pmnav-ros``: the PM-Nav controller node for a Create 3 (real, or ``pmnav-sim-create3``).

API (all standard messages; names relative to the node's namespace):

- action ``navigate_to_room`` (pmnav_interfaces/action/NavigateToRoom, when built:
  ``hardware/action_server.py``): goal, feedback, cancel, a numeric error code.
- in ``goal`` (std_msgs/String): a room name, id or alias; in ``goal_pose``
  (geometry_msgs/PoseStamped, RViz's "2D Goal Pose", frame ``map``): the room whose
  door is nearest. A new goal preempts the one running (its result says
  CANCELLED). In ``cancel`` (std_msgs/Empty).
- readiness (``hardware/readiness.py``): a goal that arrives before odometry and the
  camera are fresh waits for them, up to ``ready_timeout_s``.
- out ``result`` (std_msgs/String, JSON): ``{"id", "goal", "success", "code",
  "message", "cause", "duration_s", "ticks", "actions", "fix_attempts", "replans",
  "pose_odom", "pose_map"}``; ``code`` is a FailureCode (INVALID_GOAL,
  SENSOR_TIMEOUT, CANCELLED, INTERNAL_ERROR, ...) or null; ``cause`` is the root-cause
  failure ``{"code", "message"}`` when recoveries failed after it, else null.
- out ``/diagnostics`` (diagnostic_msgs/DiagnosticArray, ``status_hz``) and ``status``
  (std_msgs/String, JSON): ready or the missing inputs, idle/running, the goal,
  sensor ages, the current fault; with ``lifts``, what each lift last said.
- with ``lifts``: the building's lifts over Open-RMF's ``/lift_requests`` and
  ``/lift_states`` (``hardware/lift_client.py``, a ``seams.Lift``: ``self.lift``). In a
  site of several levels (``building:=hospital_2l``, with ``lifts``) a goal runs the
  mission across levels from ``start_level`` (``hardware/node_site.py``).
- out ``tree`` (std_msgs/String, JSON): one snapshot per tick (statuses, feedback,
  blackboard changes, the view entry; the format of ``pmnav tree replay``);
  ``tree/structure`` (latched) holds the tree's nodes.
- ``view_port``: the live web view of ``pmnav view`` on http://127.0.0.1:PORT/; the
  snapshots reach it through a queue its own thread reads (``webview/feed.py``), so
  the tree does not wait for it.
- out ``plan`` (nav_msgs/Path, latched, frame ``map``), ``trajectory`` (nav_msgs/Path,
  the driven odometry poses put in the map frame with the latest localization),
  ``pose`` (geometry_msgs/PoseStamped, the estimated map pose), ``markers``
  (visualization_msgs/MarkerArray, latched: doors, landmarks, plan steps),
  ``map_to_odom`` (geometry_msgs/TransformStamped), and ``/tf`` map -> odom when
  tf2_msgs can be imported.

The tree runs in the main thread (``run_tree`` with ``sync_workers=False`` and a
RosClock); rclpy spins in a background executor. Parameters: see ``PARAMETERS``
(``pmnav-ros --help``); an unknown ``-p`` name is an error. ``--record FILE.mcap``
records the run (``hardware/recorder.py``).
"""

from __future__ import annotations

import json
import math
import queue
import sys
import threading
import time
import traceback
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

from pmnav_bt.errors import PmNavError
from pmnav_bt.failures import Failure, FailureCode, failure_from
from pmnav_bt.geometry import se2_compose
from pmnav_bt.hardware import action_server
from pmnav_bt.hardware.create3 import Create3Options
from pmnav_bt.hardware.diagnostics import diagnostic_array
from pmnav_bt.hardware.messages import pose_stamped
from pmnav_bt.hardware.params import check_unknown, usage, wants_help
from pmnav_bt.hardware.readiness import Readiness
from pmnav_bt.hardware.recorder import McapRecorder
from pmnav_bt.hardware.requests import GoalPoseError, GoalRequest, goal_from_pose, progress
from pmnav_bt.seams import CAMERA_HEIGHT_M, CREATE3_MAX_ANGULAR, CREATE3_MAX_LINEAR, Pose2D

# name -> (default, description). Types follow the defaults.
PARAMETERS: dict[str, tuple[Any, str]] = {
    "building": ("fig2_hospital", "building file (YAML) or built-in name"),
    "config": ("", "PM-Nav config file (YAML); empty: defaults"),
    "overrides": ("", "config overrides 'section.key=value', separated by ';'"),
    "tick_hz": (0.0, "tree tick rate; 0: the config's tree.tick_hz"),
    "budget": (0, "action budget; 0: the config's tree.budget_actions"),
    "seed": (0, "seed of the perception back ends"),
    "max_duration_s": (900.0, "a mission ends with TIMEOUT after this long"),
    "ready_timeout_s": (60.0, "a goal waits this long for fresh odometry and camera (s)"),
    "cmd_vel_topic": ("cmd_vel", ""),
    "odom_topic": ("odom", ""),
    "image_topic": ("camera/image_raw", "sensor_msgs/Image rgb8 or bgr8"),
    "camera_info_topic": ("camera/camera_info", ""),
    "depth_topic": ("camera/depth/image_raw", "32FC1 m or 16UC1 mm; empty: none"),
    "segmentation_topic": ("camera/segmentation", "simulator labels; empty: none"),
    "labels_topic": ("camera/segmentation_labels", "the segmentation's id -> label JSON"),
    "hazard_topic": ("hazard_detection", "bumps, cliffs, stalls; needs irobot_create_msgs"),
    "cmd_rate_hz": (20.0, "cmd_vel republish rate while moving"),
    "odom_timeout": (0.3, "hold the robot stopped when odometry is older than this (s)"),
    "odom_fault_s": (1.0, "fail the mission (SENSOR_TIMEOUT) after this long without odometry"),
    "camera_timeout": (2.0, "stop and fail when the camera is silent this long (s)"),
    "sync_slop": (0.05, "depth/segmentation match the colour frame within this (s)"),
    "max_linear": (CREATE3_MAX_LINEAR, "m/s"),
    "max_angular": (CREATE3_MAX_ANGULAR, "rad/s"),
    "camera_height": (CAMERA_HEIGHT_M, "m above the floor"),
    "hfov_deg": (60.0, "horizontal field of view until a CameraInfo arrives"),
    "stall_s": (2.0, "a motion without progress for this long is BLOCKED"),
    "frame_width": (
        0,
        "shrink wider camera frames to this for the tree and read signs in "
        "the full image; 0: the tree gets the camera's image",
    ),
    "map_frame": ("map", ""),
    "odom_frame": ("odom", ""),
    "publish_tf": (True, "publish map -> odom on /tf (needs tf2_msgs)"),
    "tree_log": ("", "also write the tree snapshots (JSON lines) to this file"),
    "map_updates_dir": (
        "", "write what each run sees that disagrees with the map to DIR/<time>-run<N>"
        ".map_updates.jsonl"
    ),
    "view_port": (0, "serve the live web view (pmnav view) on this port; 0: none"),
    "view_host": ("127.0.0.1", "address of the web view; only loopback unless view_allow_remote"),
    "view_allow_remote": (False, "let view_host be an address other machines reach"),
    "lifts": (
        False, "use the building's lifts: requests on /lift_requests, states from "
        "/lift_states (Open-RMF's rmf_lift_msgs; hardware/lift_client.py)",
    ),
    "start_level": (
        "", "in a site of several levels: the level the robot starts on; empty: the first",
    ),
    "status_hz": (1.0, "status topic rate"),
    "viz_hz": (2.0, "pose, trajectory and map -> odom publish rate"),
}

_OPTION_NAMES = {f.name for f in fields(Create3Options)}


class Cancelled(Exception):  # noqa: N818 - raised out of run_tree to end a run
    """Raised from the tick handler to end a run early."""


class NotReadyError(PmNavError):
    """Odometry or the camera did not become fresh within ``ready_timeout_s``."""


def read_parameters(node) -> dict[str, Any]:
    """Declare every parameter of ``PARAMETERS`` on ``node`` and return their values,
    checked against their ranges (hardware/param_limits.py)."""
    from pmnav_bt.hardware.param_limits import check_parameters

    return check_parameters(declare_parameters(node, PARAMETERS))


def declare_parameters(node, spec: dict[str, tuple[Any, str]]) -> dict[str, Any]:
    """Declare ``spec``'s parameters; a value of the wrong type is a PmNavError."""
    from rcl_interfaces.msg import ParameterDescriptor
    from rclpy.exceptions import InvalidParameterTypeException

    out = {}
    for name, (default, desc) in spec.items():
        try:
            node.declare_parameter(name, default, ParameterDescriptor(description=desc))
        except InvalidParameterTypeException as err:
            kind = type(default).__name__
            raise PmNavError(
                f"parameter {name!r}: expected a {kind} like {default!r} ({err})"
            ) from None
        out[name] = node.get_parameter(name).value
    check_unknown(node, spec)
    return out


def camera_config(cfg, camera_width: int | None, opt: Create3Options):
    """``cfg`` with the robot camera's size where the simulator's stands: the tree's frame
    width (``sim.width``) and the width signs are read at (``sim.reading_width``), from
    which the reader's range and the search distances follow (perception/read_range.py).
    Unchanged before the first frame; search distances set in the config still win."""
    if not camera_width:
        return cfg
    frame = opt.frame_width if 0 < opt.frame_width < camera_width else camera_width
    sim = cfg.sim.model_copy(update={"width": frame, "reading_width": camera_width})
    return cfg.model_copy(update={"sim": sim})


def create3_options(params: dict[str, Any]) -> Create3Options:
    kw = {k: v for k, v in params.items() if k in _OPTION_NAMES}
    for k in ("depth_topic", "segmentation_topic", "labels_topic", "hazard_topic"):
        kw[k] = str(kw.get(k) or "")
    return Create3Options(**kw)


@dataclass
class _Run:
    id: int
    goal: str
    cancel: threading.Event = field(default_factory=threading.Event)
    reason: str = ""
    request: GoalRequest | None = None
    waiting: bool = False  # for fresh sensors, before the tree starts

    def cancelled(self) -> bool:
        """Set by a cancel/preempt, or the action client asked to cancel."""
        if not self.cancel.is_set() and self.request is not None:
            ask = self.request.cancel_requested
            if ask is not None and ask():
                self.reason = self.reason or "cancelled by the action client"
                self.cancel.set()
        return self.cancel.is_set()


class _SnapshotWriter:
    """A text sink for SnapshotLogger: the structure record goes to ``tree/structure``
    (latched), tick records to ``tree``; optionally tee'd to a file and to the web
    view's queue (``view``: a FeedWriter)."""

    def __init__(self, tick_pub, structure_pub, tee=None, view=None) -> None:
        from std_msgs.msg import String

        self._String = String
        self._tick, self._structure, self._tee = tick_pub, structure_pub, tee
        self._view = view

    def write(self, text: str) -> int:
        if self._tee is not None:
            self._tee.write(text)
        if self._view is not None:
            self._view.write(text)
        line = text.strip()
        if line:
            pub = self._structure if line.startswith('{"type": "tree"') else self._tick
            pub.publish(self._String(data=line))
        return len(text)

    def flush(self) -> None:
        if self._tee is not None:
            self._tee.flush()


class PmNavController:
    """The pmnav-ros node's logic: parameters, topics, the goal queue and the mission loop."""

    def __init__(self, node, runtime, record: str = "") -> None:
        from diagnostic_msgs.msg import DiagnosticArray
        from geometry_msgs.msg import PoseStamped, TransformStamped
        from nav_msgs.msg import Path
        from std_msgs.msg import Empty, String
        from visualization_msgs.msg import MarkerArray

        from pmnav_bt.config import load_config
        from pmnav_bt.hardware import qos
        from pmnav_bt.hardware.create3 import Create3Base
        from pmnav_bt.map.catalogue import load_building, resolve_building_path
        from pmnav_bt.map.priori_map import parse_building
        from pmnav_bt.pose.evidence.floor_model import building_grid

        # the tree imported now, not at the first goal: a long import holds the GIL and
        # would starve the executor (odometry "stale")
        from pmnav_bt.trees import runner

        self.node = node
        self.runtime = runtime
        self.log = node.get_logger()
        self.params = p = read_parameters(node)
        overrides = [s.strip() for s in str(p["overrides"]).split(";") if s.strip()]
        if p["tick_hz"] > 0:
            overrides.append(f"tree.tick_hz={float(p['tick_hz'])}")
        self.config = load_config(p["config"] or None, overrides, label="parameter 'overrides'")
        # A site of several levels: the start level's map, back ends and grid below, and
        # a mission across levels per goal (None: one floor, as any building).
        self.site = self._node_site(p)
        self.map_file = p["building"]  # how the view and the records find the map again
        if self.site is not None:
            self.pm, self.grid = self.site.start.pm, self.site.start.grid
            self.building, self.backends = self.pm.building, self.site.start.backends
            self.map_file = self.site.start_file
        else:
            self.building = load_building(p["building"])
            self.pm = parse_building(self.building)
            # Its occupancy grid, where it has one: the walls the localization weighs depth on.
            self.grid = building_grid(self.building, resolve_building_path(p["building"]).parent)
            # The back ends, built once on what the tree variant may read (an unknown variant
            # is refused now, not at the first goal); a back end that reads the simulator's
            # labels is refused (one line, from the registry) unless the simulated Create 3
            # publishes them.
            self.backends = runner.variant_backends(
                self.config, self.pm, on_robot=not p["segmentation_topic"], seed=int(p["seed"])
            )
        self.base = Create3Base(node, create3_options(p))
        self.readiness = Readiness(self.base, p["odom_timeout"], p["camera_timeout"])
        self.map_frame, self.odom_frame = p["map_frame"], p["odom_frame"]

        self._String = String
        self._goals: queue.Queue[GoalRequest] = queue.Queue()
        self._run: _Run | None = None
        self._runs = 0
        self._lock = threading.Lock()

        ev, latched = qos.events(), qos.latched()
        self.pub_result = node.create_publisher(String, "result", ev)
        self.pub_status = node.create_publisher(String, "status", ev)
        self.pub_tree = node.create_publisher(String, "tree", ev)
        self.pub_structure = node.create_publisher(String, "tree/structure", latched)
        self.pub_plan = node.create_publisher(Path, "plan", latched)
        self.pub_traj = node.create_publisher(Path, "trajectory", ev)
        self.pub_pose = node.create_publisher(PoseStamped, "pose", ev)
        self.pub_markers = node.create_publisher(MarkerArray, "markers", latched)
        self.pub_map_odom = node.create_publisher(TransformStamped, "map_to_odom", ev)
        self.pub_diag = node.create_publisher(DiagnosticArray, "/diagnostics", ev)
        self.pub_tf = None
        if p["publish_tf"]:
            try:
                from tf2_msgs.msg import TFMessage
            except ImportError:
                self.log.info("tf2_msgs is not installed: map -> odom only on map_to_odom")
            else:
                self.pub_tf = node.create_publisher(TFMessage, "/tf", qos.events(100))
        node.create_subscription(String, "goal", self._on_goal, ev)
        node.create_subscription(PoseStamped, "goal_pose", self._on_goal_pose, ev)
        node.create_subscription(Empty, "cancel", self._on_cancel, ev)
        node.create_timer(1.0 / max(0.1, float(p["status_hz"])), self._publish_status)
        self.lift = self._lift_client(p)
        self.action = None
        if action_server.available():
            self.action = action_server.NavigateActionServer(
                node,
                self.building,
                self.submit,
                runtime.executor.wake,
                lambda q: pose_stamped(Pose2D(*q), self._stamp(), self.map_frame),
                self.map_frame,
            )
        else:
            self.log.warn(
                "pmnav_interfaces is not built (interfaces/build.sh): no navigate_to_room "
                "action, goals on the goal topics only"
            )
        self.recorder = None
        if record:
            self.recorder = McapRecorder(node, record, self._recorded_topics())
            self.log.info(f"recording to {record}")
        self._publish_map_markers()
        self.view_server, self.view_writer = self._start_view(p)
        action = node.resolve_topic_name(action_server.ACTION_NAME) if self.action else None
        where = f"building {self.building.name}, {len(self.building.rooms)} rooms"
        if self.site is not None:
            site = self.site.sm.site
            where = (
                f"site {site.name}, levels {', '.join(site.level_names)}, starting on "
                f"{self.site.start_level} ({where}); lift session {node.get_fully_qualified_name()}"
            )
        self.log.info(
            f"pmnav-ros started: {where}; goals: action {action}, "
            f"{node.resolve_topic_name('goal')} (a room name), "
            f"{node.resolve_topic_name('goal_pose')} (the nearest door); waiting for sensors"
        )

    def _stamp(self):
        return self.node.get_clock().now().to_msg()

    def _node_site(self, p: dict[str, Any]):
        """The site of several levels ``building`` names (``NodeSite``), else None."""
        from pmnav_bt.hardware.node_site import NodeSite, site_of_levels

        site = site_of_levels(p["building"])
        if site is None:
            if p["start_level"]:
                raise PmNavError(
                    f"parameter 'start_level': {p['building']} is a building of one level"
                )
            return None
        if not p["lifts"]:
            raise PmNavError(
                f"parameter 'building': {site.name} has several levels, reached by lift: "
                "give -p lifts:=true"
            )
        return NodeSite(
            site, p["start_level"], self.config, on_robot=not p["segmentation_topic"],
            seed=int(p["seed"]),
        )  # fmt: skip

    def _lift_client(self, p: dict[str, Any]):
        """The lift system over Open-RMF's topics (``seams.Lift``) with ``lifts``, else None."""
        if not p["lifts"]:
            return None
        from pmnav_bt.hardware.lift_client import RosLiftClient

        try:
            return RosLiftClient(self.node)
        except PmNavError as err:
            raise PmNavError(f"parameter 'lifts': {err}") from None

    def _start_view(self, p: dict[str, Any]):
        """The web view's server and the queue the snapshots reach it by (None, None
        when ``view_port`` is 0)."""
        if not p["view_port"]:
            return None, None
        from pmnav_bt.webview.feed import Feed, FeedWriter
        from pmnav_bt.webview.server import ViewServer, check_host

        feed = Feed(f"pmnav-ros {self.node.get_fully_qualified_name()}", live=True,
                    building=self.map_file)  # fmt: skip
        host = check_host(p["view_host"], p["view_allow_remote"])
        server = ViewServer(feed, host, int(p["view_port"]), p["view_allow_remote"]).start()
        self.log.info(f"web view: {server.url}")
        return server, FeedWriter(feed)

    def close_view(self) -> None:
        """Stop the web view's server (the node is shutting down)."""
        if self.view_server is not None:
            self.view_writer.close()
            self.view_server.close()

    def _recorded_topics(self) -> list[tuple[str, type, object]]:
        from diagnostic_msgs.msg import DiagnosticArray
        from geometry_msgs.msg import PoseStamped, TransformStamped, Twist
        from nav_msgs.msg import Odometry, Path
        from sensor_msgs.msg import CameraInfo, Image
        from std_msgs.msg import String
        from visualization_msgs.msg import MarkerArray

        from pmnav_bt.hardware import qos

        p, sensor, ev, latched = self.params, qos.sensor(), qos.events(), qos.latched()
        lifts = []
        if self.lift is not None:  # what was asked of the lifts and what they said
            from pmnav_bt.hardware import rmf_lift

            request, state = rmf_lift.messages()
            lifts = [
                (rmf_lift.REQUESTS_TOPIC, request, qos.lift_requests()),
                (rmf_lift.STATES_TOPIC, state, qos.lift_states()),
            ]
        return [
            (p["image_topic"], Image, sensor),
            (p["camera_info_topic"], CameraInfo, sensor),
            (p["odom_topic"], Odometry, sensor),
            (p["cmd_vel_topic"], Twist, ev),
            ("plan", Path, latched),
            ("trajectory", Path, ev),
            ("pose", PoseStamped, ev),
            ("markers", MarkerArray, latched),
            ("map_to_odom", TransformStamped, ev),
            ("tree", String, ev),
            ("tree/structure", String, latched),
            ("result", String, ev),
            ("/diagnostics", DiagnosticArray, ev),
            *lifts,
        ]

    # -- goals -------------------------------------------------------------------------------

    def submit(self, req: GoalRequest) -> None:
        """Queue a goal; it preempts the running one."""
        self.log.info(f"goal {req.goal!r} received ({req.source})")
        with self._lock:
            if self._run is not None:
                self._run.reason = f"preempted by goal {req.goal!r}"
                self._run.cancel.set()
                self.base.clock.interrupt()
            self._goals.put(req)

    def _on_goal(self, msg) -> None:
        self.submit(GoalRequest(msg.data.strip(), "topic"))

    def _on_goal_pose(self, msg) -> None:
        p = msg.pose.position
        try:
            room, dist = goal_from_pose(
                self.building, msg.header.frame_id, float(p.x), float(p.y), self.map_frame
            )
        except GoalPoseError as err:
            self.log.error(str(err))
            return
        self.log.info(f"goal pose ({p.x:.1f}, {p.y:.1f}): nearest door {room.id} at {dist:.1f} m")
        self.submit(GoalRequest(room.id, "goal_pose"))

    def _on_cancel(self, _msg) -> None:
        with self._lock:
            if self._run is not None:
                self._run.reason = "cancelled on request"
                self._run.cancel.set()
                self.base.clock.interrupt()
            dropped = []
            while not self._goals.empty():
                dropped.append(self._goals.get_nowait())
        for req in dropped:
            req.finish(
                {
                    "goal": req.goal,
                    "success": False,
                    "code": FailureCode.CANCELLED.value,
                    "message": "cancelled",
                }
            )

    def request_stop(self) -> None:
        """Signal handler side: end the current run (the main loop then exits)."""
        run = self._run
        if run is not None:
            run.reason = "the node is shutting down"
            run.cancel.set()
        self.base.clock.interrupt()

    def spin(self) -> None:
        """The mission loop: wait for goals, run the tree, publish results; until stopped."""
        stop = self.runtime.stop_requested
        while not stop.is_set():
            try:
                req = self._goals.get(timeout=0.1)
            except queue.Empty:
                continue
            if stop.is_set():
                req.finish({"goal": req.goal, "success": False,
                            "code": FailureCode.CANCELLED.value,
                            "message": "the node is shutting down"})  # fmt: skip
                break
            try:
                self.execute(req)
            except Exception as err:  # noqa: BLE001 - one bad run must not end the node
                self.log.error(f"goal {req.goal!r} failed:\n{traceback.format_exc()}")
                self.base.stop()
                if not req.done.is_set():
                    failure = failure_from(err)
                    req.finish({"goal": req.goal, "success": False,
                                "code": failure.code.value,
                                "message": failure.message})  # fmt: skip

    def _room_fields(self, goal: str) -> dict:
        from pmnav_bt.planning.resolve import resolve_room

        try:
            if self.site is not None:
                room = self.site.room(goal)[1]
            else:
                room = self.building.room(resolve_room(self.pm, goal))
        except Exception:  # noqa: BLE001 - an unknown room: the tree reports INVALID_GOAL
            return {"room_id": "", "room_name": ""}
        return {"room_id": room.id, "room_name": room.display_name}

    def _wait_ready(self, run: _Run, req: GoalRequest, w0: float) -> None:
        """Wait for fresh sensors (feedback meanwhile); NotReadyError after the timeout."""
        if self.readiness.ready():
            return

        def on_wait(missing: list[str], waited: float) -> None:
            if req.feedback is not None:
                req.feedback({"phase": "waiting_for_sensors", "missing": missing,
                              "step_text": "waiting for: " + "; ".join(missing),
                              "elapsed": time.monotonic() - w0})  # fmt: skip

        timeout = float(self.params["ready_timeout_s"])
        self.log.info(f"goal {req.goal!r} waits for: {'; '.join(self.readiness.missing())}")
        run.waiting = True
        try:
            missing = self.readiness.wait(timeout, run.cancelled, on_wait)
        finally:
            run.waiting = False
        if run.cancelled():
            raise Cancelled(run.reason or "cancelled")
        if missing:
            raise NotReadyError(f"not ready after {timeout:g} s: {'; '.join(missing)}")

    def _feedback_fn(self, req: GoalRequest, viz: _Viz, w0: float):
        """A tick handler part: feedback to ``req`` every 0.5 s and on each step change."""
        last = {"t": -math.inf, "step": None}

        def send() -> None:
            if req.feedback is None:
                return
            now = time.monotonic()
            step = viz._bb("step_index")
            if now - last["t"] < 0.5 and step == last["step"]:
                return
            last.update(t=now, step=step)
            est = viz.map_pose(self.base.pose())
            fb = progress(viz._bb, est, now - w0)
            fb["pose_map"] = (est.x, est.y, est.yaw)
            req.feedback(fb)

        return send

    def execute(self, req: GoalRequest) -> dict:
        """Run the tree for one goal and publish its result."""
        from pmnav_bt.hardware.node_site import UnknownGoalError
        from pmnav_bt.map.updates import SUFFIX as UPDATES_SUFFIX
        from pmnav_bt.map.updates import UpdatesFile
        from pmnav_bt.trees.map_watch import watch_map
        from pmnav_bt.trees.runner import make_context, run_tree
        from pmnav_bt.trees.view_record import ViewRecorder

        goal = req.goal
        w0 = time.monotonic()
        with self._lock:
            self._runs += 1
            run = self._run = _Run(self._runs, goal, request=req)
        p, cfg = self.params, self.config
        self.base.clock.clear()
        t0 = self.base.clock.now()
        budget = int(p["budget"]) or None
        ctx = make_context(
            self.base, self.pm, cfg, seed=int(p["seed"]), budget=budget, backends=self.backends,
            grid=self.grid,
        )  # fmt: skip
        if p["map_updates_dir"]:  # reviewed later with 'pmnav map updates FILE'
            name = f"{time.strftime('%Y%m%d-%H%M%S')}-run{run.id}{UPDATES_SUFFIX}"
            watch_map(ctx, UpdatesFile(Path(p["map_updates_dir"]) / name, self.map_file))
        viz = _Viz(self, ctx)
        tee = open(p["tree_log"], "a", encoding="utf-8") if p["tree_log"] else None  # noqa: SIM115
        writer = _SnapshotWriter(self.pub_tree, self.pub_structure, tee, self.view_writer)
        feedback = self._feedback_fn(req, viz, w0)

        def on_tick(tree) -> None:
            viz.update()
            feedback()
            if run.cancelled():
                raise Cancelled(run.reason or "cancelled")

        result: dict[str, Any] = {"id": run.id, "goal": goal, **self._room_fields(goal)}
        try:
            self._wait_ready(run, req, w0)
            ctx.config = camera_config(cfg, self.base.camera_width(), self.base.options)
            max_ticks = max(1, int(float(p["max_duration_s"]) * cfg.tree.tick_hz))
            view = ViewRecorder(ctx, building=self.map_file)
            build = ended_on = None
            if self.site is not None:  # the mission across levels, riding the lifts
                session = self.node.get_fully_qualified_name()
                build, ended_on = self.site.mission(ctx, goal, self.lift, session)
            out = run_tree(
                ctx, goal, max_ticks, log=writer, on_tick=on_tick, sync_workers=False, view=view,
                build=build, ended_on=ended_on,
            )  # fmt: skip
            result.update(
                success=out.success,
                code=out.failure.code.value if out.failure else None,
                message=out.failure.message if out.failure else "arrived",
                cause=_failure_dict(out.cause),
                ticks=out.ticks,
                actions=out.actions,
                fix_attempts=out.fix_attempts,
                replans=out.replans,
            )
        except Cancelled as c:
            result.update(success=False, code=FailureCode.CANCELLED.value, message=str(c))
        except NotReadyError as err:
            result.update(success=False, code=FailureCode.SENSOR_TIMEOUT.value, message=str(err))
        except UnknownGoalError as err:
            result.update(success=False, code=FailureCode.INVALID_GOAL.value, message=str(err))
        except Exception as err:  # noqa: BLE001 - reported with its code, the node goes on
            if not isinstance(err, PmNavError):
                self.log.error(traceback.format_exc())
            failure = failure_from(err)
            result.update(success=False, code=failure.code.value, message=failure.message)
        finally:
            self.base.stop()
            if tee is not None:
                tee.close()
            with self._lock:
                self._run = None
        viz.update(force=True)
        odom = self.base.pose()
        est = viz.map_pose(odom)
        result.update(
            duration_s=round(self.base.clock.now() - t0, 3),
            pose_odom=[round(odom.x, 3), round(odom.y, 3), round(odom.yaw, 4)],
            pose_map=[round(est.x, 3), round(est.y, 3), round(est.yaw, 4)],
        )
        self.pub_result.publish(self._String(data=json.dumps(result)))
        req.finish(result)
        # (rclpy ties a severity to each call site: one call per severity)
        if result["success"]:
            self.log.info(f"goal {goal!r}: SUCCESS: {result['message']}")
        else:
            self.log.warn(f"goal {goal!r}: {result['code']}: {result['message']}")
        return result

    # -- status and visualisation -------------------------------------------------------------

    def _publish_status(self) -> None:
        run = self._run
        fault = self.base.fault()
        s = self.base.sensors()
        missing = self.readiness.missing()
        status = {
            "ready": not missing,
            "missing": missing,
            "state": "running" if run is not None else "idle",
            "waiting_for_sensors": run is not None and run.waiting,
            "goal": run.goal if run is not None else None,
            "runs": self._runs,
            "odom_age": None if s["odom_age"] is None else round(s["odom_age"], 3),
            "camera_age": None if s["camera_age"] is None else round(s["camera_age"], 3),
            "max_odom_gap": round(s["max_odom_gap"], 3),
            "fault": str(fault) if fault is not None else None,
            "motion": self.base.motion_status().value,
        }
        if self.lift is not None:
            status["lifts"] = self.lift.summary()
        per = sorted(self.base.cmd_periods()[-1000:])
        if per:
            status["cmd_period_ms"] = {
                "n": len(per),
                "median": round(1000 * per[len(per) // 2], 1),
                "p99": round(1000 * per[min(len(per) - 1, int(0.99 * len(per)))], 1),
                "max": round(1000 * per[-1], 1),
            }
        self.pub_status.publish(self._String(data=json.dumps(status)))
        self.pub_diag.publish(diagnostic_array(status, self._stamp(), self.building.name))

    def _publish_map_markers(self) -> None:
        from visualization_msgs.msg import MarkerArray

        arr = MarkerArray()
        stamp = self.node.get_clock().now().to_msg()
        i = 0
        for room in self.building.rooms:
            arr.markers += _marker_pair(
                i, "doors", stamp, self.map_frame, room.door, room.sign_text, (0.2, 0.5, 1.0), 0.3
            )
            i += 2
        for lm in self.building.landmarks:
            arr.markers += _marker_pair(
                i, "landmarks", stamp, self.map_frame, lm.pos, lm.display_name, (1.0, 0.6, 0.1), 0.5
            )
            i += 2
        self.pub_markers.publish(arr)
        self._map_markers = list(arr.markers)


class _Viz:
    """Per-run publishing from the tick handler: pose, trajectory, plan, map -> odom."""

    def __init__(self, ctl: PmNavController, ctx) -> None:
        self.ctl, self.ctx = ctl, ctx
        self._plan = None
        self._traj: list[Pose2D] = []
        self._last_pub = -math.inf
        self._period = 1.0 / max(0.1, float(ctl.params["viz_hz"]))

    @staticmethod
    def _bb(key: str):
        import py_trees

        return py_trees.blackboard.Blackboard.storage.get(f"/pmnav/{key}")

    def map_pose(self, odom: Pose2D) -> Pose2D:
        from pmnav_bt.behaviours.context import map_pose

        return map_pose(self._bb("map_T_odom"), odom)

    def update(self, force: bool = False) -> None:
        from pmnav_bt.hardware.messages import path_message, pose_stamped, transform_stamped

        ctl = self.ctl
        odom = self.ctx.base.pose()  # the tree's odometry (rotation-calibrated)
        if not self._traj or _moved(self._traj[-1], odom):
            self._traj.append(odom)
        plan = self._bb("plan")
        stamp = ctl.node.get_clock().now().to_msg()
        if plan is not None and plan is not self._plan:
            self._plan = plan
            ctl.pub_plan.publish(path_message(_plan_poses(plan), stamp, ctl.map_frame))
            self._publish_plan_markers(plan, stamp)
        now = ctl.base.clock.now()
        if not force and now - self._last_pub < self._period:
            return
        self._last_pub = now
        m = self._bb("map_T_odom")
        frame = ctl.map_frame if m is not None else ctl.odom_frame
        ctl.pub_pose.publish(pose_stamped(self.map_pose(odom), stamp, frame))
        ctl.pub_traj.publish(path_message([self.map_pose(q) for q in self._traj], stamp, frame))
        if m is not None:
            # map -> the robot's own odom frame: through the calibrated odometry's frame.
            m = se2_compose(m, self.ctx.base.corr_T_raw())
            tf = transform_stamped(Pose2D(*m), stamp, ctl.map_frame, ctl.odom_frame)
            ctl.pub_map_odom.publish(tf)
            if ctl.pub_tf is not None:
                from tf2_msgs.msg import TFMessage

                ctl.pub_tf.publish(TFMessage(transforms=[tf]))

    def _publish_plan_markers(self, plan, stamp) -> None:
        from visualization_msgs.msg import Marker, MarkerArray

        ctl = self.ctl
        arr = MarkerArray()
        clear = Marker()
        clear.header.frame_id = ctl.map_frame
        clear.ns = "plan_steps"
        clear.action = Marker.DELETEALL
        arr.markers.append(clear)
        for k, step in enumerate(plan.steps):
            arr.markers += _marker_pair(
                1000 + 2 * k,
                "plan_steps",
                stamp,
                ctl.map_frame,
                step.position,
                f"{k + 1}. {step.landmark}: {step.action.value}",
                (0.1, 0.8, 0.2),
                0.25,
            )
        ctl.pub_markers.publish(MarkerArray(markers=ctl._map_markers + arr.markers))


def _failure_dict(failure: Failure | None) -> dict | None:
    return None if failure is None else {"code": failure.code.value, "message": failure.message}


def _moved(a: Pose2D, b: Pose2D) -> bool:
    return math.hypot(a.x - b.x, a.y - b.y) > 0.05 or abs(a.yaw - b.yaw) > 0.17


def _plan_poses(plan) -> list[Pose2D]:
    pts = [tuple(p) for p in plan.path]
    out = []
    for i, (x, y) in enumerate(pts):
        nx_, ny_ = pts[min(i + 1, len(pts) - 1)]
        px, py = pts[max(i - 1, 0)]
        dx, dy = (nx_ - x, ny_ - y) if i + 1 < len(pts) else (x - px, y - py)
        out.append(Pose2D(float(x), float(y), math.atan2(dy, dx) if (dx or dy) else 0.0))
    return out


def _marker_pair(mid, ns, stamp, frame, xy, text, rgb, size):
    """A sphere and a text label at ``xy``."""
    from visualization_msgs.msg import Marker

    out = []
    for k, kind in enumerate((Marker.SPHERE, Marker.TEXT_VIEW_FACING)):
        m = Marker()
        m.header.stamp = stamp
        m.header.frame_id = frame
        m.ns, m.id, m.type, m.action = ns, mid + k, kind, Marker.ADD
        m.pose.position.x, m.pose.position.y = float(xy[0]), float(xy[1])
        m.pose.position.z = 0.2 if kind == Marker.SPHERE else 0.8
        m.pose.orientation.w = 1.0
        m.scale.x = m.scale.y = size
        m.scale.z = size if kind == Marker.SPHERE else 0.3
        m.color.r, m.color.g, m.color.b, m.color.a = (*map(float, rgb), 1.0)
        if kind == Marker.TEXT_VIEW_FACING:
            m.text = text
        out.append(m)
    return out


HELP = """The PM-Nav controller for an iRobot Create 3 (or pmnav-sim-create3).
Goals: the navigate_to_room action (pmnav_interfaces/action/NavigateToRoom), a room
name on the goal topic, or a PoseStamped on goal_pose (the nearest room door).
Status on /diagnostics. --record FILE.mcap writes the run (camera, odometry,
cmd_vel, plan, trajectory, markers, tree snapshots) as ROS 2 MCAP. docs/ros2.md."""
EXAMPLE = "pmnav-ros --ros-args -p building:=fig2_hospital"


def split_record(args: list[str]) -> tuple[str, list[str]]:
    """(the ``--record`` path or "", the arguments left for rclpy)."""
    head, tail = args, []
    if "--ros-args" in args:
        i = args.index("--ros-args")
        head, tail = args[:i], args[i:]
    record, rest = "", head[:1]
    i = 1
    while i < len(head):
        a = head[i]
        if a == "--record" or a.startswith("--record="):
            value = a.split("=", 1)[1] if "=" in a else (head[i + 1] if i + 1 < len(head) else "")
            if not value.endswith(".mcap"):
                raise PmNavError(f"--record needs a FILE.mcap, not {value!r}")
            record = value
            i += 1 if "=" in a else 2
            continue
        rest.append(a)
        i += 1
    return record, rest + tail


def main(argv: list[str] | None = None) -> None:
    """Console script ``pmnav-ros``: ``pmnav-ros --ros-args -p building:=fig2_hospital``."""
    args = list(sys.argv if argv is None else argv)
    if wants_help(args):
        print(usage("pmnav-ros [--record FILE.mcap]", HELP, PARAMETERS, EXAMPLE))
        sys.exit(0)
    try:
        record, args = split_record(args)
    except PmNavError as err:
        print(f"pmnav-ros: {err}", file=sys.stderr)
        sys.exit(2)
    # The cmd_vel heartbeat thread must get the GIL quickly while the tree and the
    # perception worker run: hand it over every 1 ms instead of 5 ms.
    sys.setswitchinterval(0.001)
    from pmnav_bt.hardware.runtime import run_node

    run_node(
        "pmnav-ros",
        "pmnav",
        args,
        lambda node, runtime: PmNavController(node, runtime, record=record),
        serve=PmNavController.spin,
        on_signal=PmNavController.request_stop,
        before_shutdown=_before_shutdown,
        after_shutdown=_close_recorder,
    )


def _before_shutdown(controller: PmNavController) -> None:
    controller.base.close()
    controller.close_view()


def _close_recorder(controller: PmNavController) -> None:
    if controller.recorder is not None:
        controller.recorder.close()


if __name__ == "__main__":  # pragma: no cover
    main()
