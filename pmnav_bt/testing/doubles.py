"""Test doubles for every seam, so behaviour and tree logic runs without pybullet or ROS.

- ``FakeClock`` + ``FakeBase``: a kinematic unicycle that integrates its velocity command
  when the clock advances; frames are blank (no depth unless ``obstacles`` stand about:
  ``FakeObstacle``, upright cylinders, still or walking, drawn in depth), scripted faults
  and errors.
- ``ScriptedGrounder``: sees what is in the camera's field of view within range on the
  priori-map (doors and landmarks where the map puts them), with a 3D ``point`` per
  detection; entities can be hidden, signs made unreadable (or readable only from near:
  seen farther, an unread plate), errors injected.
- ``FakeCoarseDirection``: the best detection across the views, recording which thread
  it ran in; ``FakeRefiner``: the pixel bearing and the grounder's range;
  ``FakePlanner``: the real ``GraphPlanner`` with injectable errors.

Core module: numpy only (no pybullet, py_trees or rclpy). Use them in tests and in
examples of new back ends; never in a real run.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from pmnav_bt.geometry import wrap_angle
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.perception.unread_plates import UnreadPlate, UnreadPlates
from pmnav_bt.planning.graph_planner import GraphPlanner
from pmnav_bt.planning.plan import Plan
from pmnav_bt.planning.resolve import entity_position, sign_text
from pmnav_bt.pose.visibility import map_entities
from pmnav_bt.seams import (
    CAMERA_HEIGHT_M,
    CREATE3_MAX_ANGULAR,
    CREATE3_MAX_LINEAR,
    CREATE3_RADIUS_M,
    FORWARD_STEP_M,
    TURN_STEP_RAD,
    CameraIntrinsics,
    CoarseChoice,
    Detection,
    DiscreteAction,
    Entity,
    MotionStatus,
    Observation,
    PlanConstraints,
    PlanStart,
    Pose2D,
    Refinement,
    SurfaceMasks,
    View,
)


class FakeClock:
    """A clock that moves only when told to; bodies integrate their motion on ``wait``."""

    def __init__(self, start: float = 0.0):
        self.t = start
        self._on_wait: list[Callable[[float], None]] = []

    def now(self) -> float:
        return self.t

    def wait(self, dt: float) -> None:
        for advance in self._on_wait:
            advance(dt)
        self.t += dt

    def on_wait(self, advance: Callable[[float], None]) -> None:
        self._on_wait.append(advance)


@dataclass(frozen=True)
class FakeObstacle:
    """An upright cylinder of ``radius`` m standing on the floor, taller than the camera:
    a person, a post, a piece of a barrier. ``path``: (clock s, x, y) points it walks
    between at constant speed, standing at the first before it and at the last after."""

    path: tuple[tuple[float, float, float], ...]
    radius: float = 0.25

    def at(self, t: float) -> tuple[float, float]:
        """Where it stands at clock time ``t``."""
        ts = [p[0] for p in self.path]
        return (
            float(np.interp(t, ts, [p[1] for p in self.path])),
            float(np.interp(t, ts, [p[2] for p in self.path])),
        )

    @classmethod
    def standing(cls, x: float, y: float, radius: float = 0.25) -> FakeObstacle:
        return cls(((0.0, x, y),), radius)


FAR_M = 30.0  # the depth above the horizon where nothing stands (walls are not drawn)


def obstacle_depth(
    pose: Pose2D, k: CameraIntrinsics, centres: Sequence[tuple[float, float, float]]
) -> np.ndarray:
    """A depth frame (metres along the optical axis) from ``pose`` of a bare floor, open
    to ``FAR_M``, with upright cylinders (x, y, radius) that hide the floor behind them."""
    rows = np.arange(k.height, dtype=float)[:, None]
    with np.errstate(divide="ignore"):
        floor = np.where(rows > k.cy, CAMERA_HEIGHT_M * k.fy / (rows - k.cy), FAR_M)
    depth = np.broadcast_to(floor, (k.height, k.width))
    bearings = np.arctan2(k.cx - np.arange(k.width, dtype=float), k.fx)
    hit = np.full(k.width, np.inf)
    for x, y, r in centres:
        a = pose.yaw + bearings
        dx, dy = x - pose.x, y - pose.y
        along = dx * np.cos(a) + dy * np.sin(a)
        miss2 = dx * dx + dy * dy - along * along
        reach = along - np.sqrt(np.maximum(0.0, r * r - miss2))
        hit = np.where((miss2 <= r * r) & (reach > 0.0), np.minimum(hit, reach), hit)
    z = (hit * np.cos(bearings)).astype(np.float32)[None, :]
    return np.where(z < depth, z, depth).astype(np.float32)


@dataclass
class FakeBase:
    """A kinematic body: velocity commands integrate exactly, discrete steps are instant.

    ``blocked``: motion is refused (MotionStatus.BLOCKED); ``faulted``: FAULT;
    ``observe_error``: ``observe`` raises it (e.g. a SensorError for a silent camera);
    ``obstacles``: ``FakeObstacle``s drawn in each frame's depth (none: no depth). They
    are not solid: a test checks its gaps to them (``gap``). Odometry is exact, so the
    map and odometry frames coincide.
    """

    start: Pose2D = Pose2D(0.0, 0.0, 0.0)
    clock: FakeClock = field(default_factory=FakeClock)
    intrinsics: CameraIntrinsics = CameraIntrinsics.from_hfov(160, 120, math.radians(60))
    max_linear: float = CREATE3_MAX_LINEAR
    max_angular: float = CREATE3_MAX_ANGULAR
    blocked: bool = False
    faulted: bool = False
    observe_error: Exception | None = None
    observations: int = 0
    obstacles: list[FakeObstacle] = field(default_factory=list)

    def __post_init__(self) -> None:
        self._pose = self.start
        self._cmd = (0.0, 0.0)
        self._lock = threading.Lock()
        self.clock.on_wait(self._advance)

    def observe(self) -> Observation:
        if self.observe_error is not None:
            raise self.observe_error
        self.observations += 1
        k, pose, now = self.intrinsics, self.pose(), self.clock.now()
        depth = None
        if self.obstacles:
            centres = [(*o.at(now), o.radius) for o in self.obstacles]
            depth = obstacle_depth(pose, k, centres)
        return Observation(
            rgb=np.zeros((k.height, k.width, 3), np.uint8),
            pose=pose,
            stamp=now,
            intrinsics=k,
            depth=depth,
        )

    def gap(self, radius: float = CREATE3_RADIUS_M) -> float:
        """The least distance (m) from a body of ``radius`` here to any obstacle, now."""
        p, now = self.pose(), self.clock.now()
        return min(
            (math.dist((p.x, p.y), o.at(now)) - o.radius - radius for o in self.obstacles),
            default=math.inf,
        )

    def pose(self) -> Pose2D:
        with self._lock:
            return self._pose

    def set_pose(self, pose: Pose2D) -> None:
        with self._lock:
            self._pose = pose

    def step(self, action: DiscreteAction) -> None:
        p = self.pose()
        if action == DiscreteAction.FORWARD and not self.blocked:
            p = Pose2D(
                p.x + FORWARD_STEP_M * math.cos(p.yaw),
                p.y + FORWARD_STEP_M * math.sin(p.yaw),
                p.yaw,
            )
        elif action in (DiscreteAction.TURN_LEFT, DiscreteAction.TURN_RIGHT):
            sign = 1.0 if action == DiscreteAction.TURN_LEFT else -1.0
            p = Pose2D(p.x, p.y, wrap_angle(p.yaw + sign * TURN_STEP_RAD))
        self.set_pose(p)

    def set_velocity(self, linear: float, angular: float) -> None:
        self._cmd = (
            float(np.clip(linear, -self.max_linear, self.max_linear)),
            float(np.clip(angular, -self.max_angular, self.max_angular)),
        )

    @property
    def velocity_command(self) -> tuple[float, float]:
        return self._cmd

    def motion_status(self) -> MotionStatus:
        if self.faulted:
            return MotionStatus.FAULT
        if self.blocked and self._cmd[0] != 0.0:
            return MotionStatus.BLOCKED
        return MotionStatus.IDLE if self._cmd == (0.0, 0.0) else MotionStatus.MOVING

    def stop(self) -> None:
        self._cmd = (0.0, 0.0)

    def _advance(self, dt: float) -> None:
        v, w = self._cmd
        if self.blocked or self.faulted:
            v = 0.0
        with self._lock:
            p = self._pose
        if abs(w) < 1e-9:
            x, y = p.x + v * dt * math.cos(p.yaw), p.y + v * dt * math.sin(p.yaw)
        else:  # an exact arc
            r = v / w
            x = p.x + r * (math.sin(p.yaw + w * dt) - math.sin(p.yaw))
            y = p.y - r * (math.cos(p.yaw + w * dt) - math.cos(p.yaw))
        self.set_pose(Pose2D(x, y, wrap_angle(p.yaw + w * dt)))


@dataclass
class ScriptedGrounder:
    """Sees every room door and landmark of the map that lies in the camera's field of view
    within ``max_range`` (walls do not hide anything: the map is the script).

    ``hidden``: room/landmark IDs never seen; ``signs_readable``: False makes ``read_signs``
    see nothing (localization fails); ``error``: every call raises it (a buggy back end);
    ``open_ahead``: what ``surfaces`` shows in the lower band (floor, or a wall);
    ``masks``: each detection carries its box as a mask (as a segmenting grounder's do);
    ``readable_within``: room/landmark ID -> metres: its sign is read only that near, and
    seen farther it is an unread plate (``unread_plates``: at the entity's map point,
    facing its node on the centre line, text lines ``PLATE_LINE_M`` high).
    """

    pm: PrioriMap
    max_range: float = 9.0
    hidden: frozenset[str] = frozenset()
    signs_readable: bool = True
    error: Exception | None = None
    open_ahead: bool = True
    score: float = 0.9
    masks: bool = False
    readable_within: dict[str, float] = field(default_factory=dict)
    needs_sim_labels = False
    calls: list[str] = field(default_factory=list)
    unread: UnreadPlates = field(default_factory=UnreadPlates)

    PLATE_LINE_M = 0.05
    PLATE_Z_M = 1.5

    def unread_plates(self, since: float) -> list[UnreadPlate]:
        return self.unread.since(since)

    def plate_named(self, entity: Entity) -> UnreadPlate | None:
        return self.unread.plate_named(entity)

    def detect(self, obs: Observation, target: Entity) -> list[Detection]:
        self._called("detect")
        d = self._see(obs, target)
        return [] if d is None else [d]

    def read_signs(self, obs: Observation) -> list[Detection]:
        self._called("read_signs")
        if not self.signs_readable:
            return []
        every = map_entities(self.pm)  # every room and landmark with a sign to read
        return [d for e in every if (d := self._see(obs, e)) is not None]

    def surfaces(self, obs: Observation) -> SurfaceMasks:
        self._called("surfaces")
        h, w = obs.rgb.shape[:2]
        lower = np.zeros((h, w), bool)
        lower[h // 2 :] = True
        nothing = np.zeros((h, w), bool)
        return SurfaceMasks(
            floor=lower if self.open_ahead else nothing, wall=~lower if self.open_ahead else lower
        )

    def _called(self, what: str) -> None:
        self.calls.append(what)
        if self.error is not None:
            raise self.error

    def _see(self, obs: Observation, entity: Entity) -> Detection | None:
        if entity.id in self.hidden:
            return None
        mx, my = entity_position(self.pm, entity)
        p = obs.pose
        dx, dy = mx - p.x, my - p.y
        x = math.cos(p.yaw) * dx + math.sin(p.yaw) * dy  # body frame: x forward, y left
        y = -math.sin(p.yaw) * dx + math.cos(p.yaw) * dy
        k = obs.intrinsics
        if x <= 0.3 or math.hypot(x, y) > self.max_range:
            return None
        u = k.cx - k.fx * y / x
        if not 12 <= u <= k.width - 13:  # off the image, or cut by its border
            return None
        if math.hypot(x, y) > self.readable_within.get(entity.id, math.inf):
            self._unread(obs, entity, (mx, my))
            return None
        v = k.cy
        box = (u - 10.0, v - 10.0, u + 10.0, v + 10.0)
        text = sign_text(self.pm.building, entity)
        mask = None
        if self.masks:
            mask = np.zeros((k.height, k.width), bool)
            mask[int(v) - 10 : int(v) + 10, int(round(u)) - 10 : int(round(u)) + 10] = True
        return Detection(text, box, self.score, mask=mask, entity=entity, point=(x, y, 0.0))


    def _unread(self, obs: Observation, entity: Entity, at: tuple[float, float]) -> None:
        node = self.pm.node_xy(self.pm.places[entity.id].node)
        out = node - np.asarray(at, float)
        n = float(np.linalg.norm(out))
        if n > 1e-6:
            self.unread.seen(
                UnreadPlate(
                    xy=(float(at[0]), float(at[1])),
                    normal=(float(out[0] / n), float(out[1] / n)),
                    z=self.PLATE_Z_M,
                    top=self.PLATE_Z_M + self.PLATE_LINE_M / 2.0,
                    line_height=self.PLATE_LINE_M,
                    width=0.3,
                    stamp=obs.stamp,
                    seen_from=(obs.pose.x, obs.pose.y),
                )
            )


@dataclass
class FakeCoarseDirection:
    """The best-scoring detection across the views (grounding none), recording the thread
    each call ran in; ``error`` is raised instead (e.g. a VlmError)."""

    min_score: float = 0.3
    error: Exception | None = None
    threads: list[str] = field(default_factory=list)

    def choose(self, views: Sequence[View], target: Entity) -> CoarseChoice | None:
        self.threads.append(threading.current_thread().name)
        if self.error is not None:
            raise self.error
        best: CoarseChoice | None = None
        for view in views:
            for d in view.detections or ():
                ok = d.score >= self.min_score and d.entity in (None, target)
                if ok and (best is None or d.score > best.detection.score):
                    best = CoarseChoice(view, d)
        return best


@dataclass
class FakeRefiner:
    """The pixel bearing through the intrinsics, and the grounder's range (``point``)."""

    gives_range: bool = True
    error: Exception | None = None
    drives_approach = False

    def refine(self, obs: Observation, goal: Detection) -> Refinement:
        if self.error is not None:
            raise self.error
        bearing = obs.intrinsics.pixel_bearing(goal.centre[0])
        rng = None
        if self.gives_range and goal.point is not None:
            rng = math.hypot(goal.point[0], goal.point[1])
        return Refinement(bearing, rng)


@dataclass
class FakePlanner:
    """The real graph planner; its first ``fail_times`` calls raise ``error`` instead."""

    error: Exception | None = None
    fail_times: int = 1_000_000
    inner: GraphPlanner = field(default_factory=GraphPlanner)
    starts: list[PlanStart] = field(default_factory=list)
    constraints: list[PlanConstraints] = field(default_factory=list)

    def plan(
        self,
        pm: PrioriMap,
        start: PlanStart,
        goal: str,
        constraints: PlanConstraints = PlanConstraints(),
    ) -> Plan:
        self.starts.append(start)
        self.constraints.append(constraints)
        if self.error is not None and len(self.starts) <= self.fail_times:
            raise self.error
        return self.inner.plan(pm, start, goal, constraints)
