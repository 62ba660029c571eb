"""The seams (docs/architecture.md): small Protocols the tree talks to, and the data they pass.

Nothing above ``sim/`` and ``hardware/`` knows which body it drives: both implement
``Base`` and ``Clock``. Perception back ends implement ``Grounder``,
``CoarseDirection`` and ``Refiner``; planners implement ``Planner``.

Units are SI, angles radians, REP-103 axes (x forward, y left, z up), headings
counter-clockwise from +x in the map frame.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING, Protocol, Union, runtime_checkable

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.map.priori_map import PrioriMap
    from pmnav_bt.planning.plan import Plan

# Discrete motion, the Habitat/PixelNav convention.
FORWARD_STEP_M = 0.25
TURN_STEP_RAD = math.radians(30.0)

# The iRobot Create 3's speed limits (safety_override none), used by every body and the tree.
CREATE3_MAX_LINEAR = 0.306  # m/s
CREATE3_MAX_ANGULAR = 1.9  # rad/s
CREATE3_BACKUP_LIMIT_M = 0.15  # reverse allowed after driving forward (safety_override none)
CREATE3_RADIUS_M = 0.17  # body radius (342 mm across), for collisions and shortest paths
CAMERA_HEIGHT_M = 1.6  # camera above the floor (paper), for every body and the simulator


@dataclass(frozen=True)
class Pose2D:
    """A planar pose in the map (sim) or odom (robot) frame."""

    x: float
    y: float
    yaw: float

    def xy(self) -> np.ndarray:
        return np.array([self.x, self.y], dtype=float)


@dataclass(frozen=True)
class CameraIntrinsics:
    """Pinhole intrinsics of the RGB camera (pixels)."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    @classmethod
    def from_hfov(cls, width: int, height: int, hfov: float) -> CameraIntrinsics:
        """Square pixels, principal point at the centre, horizontal field of view in radians."""
        f = (width / 2.0) / math.tan(hfov / 2.0)
        return cls(width, height, f, f, (width - 1) / 2.0, (height - 1) / 2.0)

    @property
    def hfov(self) -> float:
        return 2.0 * math.atan((self.width / 2.0) / self.fx)

    def pixel_bearing(self, u: float) -> float:
        """Bearing (rad, left positive) of image column u from the optical axis."""
        return math.atan2(self.cx - u, self.fx)


# Segmentation labels of a simulated Observation (the only place they are spelled).
FLOOR_LABEL = "floor"
WALL_LABEL = "wall"
CEILING_LABEL = "ceiling"
OBSTACLE_LABEL = "obstacle"


def door_label(room_id: str) -> str:
    return f"door:{room_id}"


def sign_label(room_id: str) -> str:
    return f"sign:{room_id}"


def landmark_label(landmark_id: str) -> str:
    return f"landmark:{landmark_id}"


def directional_sign_label(index: int) -> str:
    """A wayfinding sign ("Radiology ->"), numbered in the building file's order."""
    return f"direction:{index}"


def parse_label(label: str) -> tuple[str, str]:
    """``"door:room17"`` -> ``("door", "room17")``; ``"floor"`` -> ``("floor", "")``."""
    kind, _, ident = label.partition(":")
    return kind, ident


@runtime_checkable
class ReadingView(Protocol):
    """The view of an observation's RGB frame at the camera's higher resolution, for
    reading signs: a body whose camera has more pixels than the tree's frame offers it
    (the simulator renders it, a robot keeps the camera's full image), made only when
    asked. ``width`` x ``height``: its size (pixels, the frame's aspect ratio)."""

    width: int
    height: int

    def rgb(self) -> np.ndarray:
        """(height, width, 3) uint8: the same view as the observation's ``rgb``."""
        ...

    def crop(self, box: tuple[int, int, int, int]) -> np.ndarray:
        """``rgb()[y0:y1, x0:x1]`` for ``box`` (x0, y0, x1, y1) inside the view: a body
        may make that part alone (the simulator renders just those pixels)."""
        ...


@dataclass(frozen=True)
class ImageReading:
    """A ``ReadingView`` of an image already at hand (a robot camera's full frame)."""

    image: np.ndarray  # (H, W, 3) uint8

    @property
    def width(self) -> int:
        return int(self.image.shape[1])

    @property
    def height(self) -> int:
        return int(self.image.shape[0])

    def rgb(self) -> np.ndarray:
        return self.image

    def crop(self, box: tuple[int, int, int, int]) -> np.ndarray:
        x0, y0, x1, y1 = box
        return self.image[y0:y1, x0:x1]


@dataclass
class Observation:
    """What the body sees at one instant.

    ``segmentation`` holds integer ids whose meaning is in ``labels``:
    "floor", "wall", "door:<room>", "sign:<room>", "landmark:<id>", "obstacle".
    ``reading``: the same view at a higher resolution for reading signs, when the body
    offers one (None: read ``rgb``).
    """

    rgb: np.ndarray  # (H, W, 3) uint8
    pose: Pose2D  # odometry pose of the base
    stamp: float  # Clock time, seconds
    intrinsics: CameraIntrinsics
    depth: np.ndarray | None = None  # (H, W) float32 metres along the optical axis
    segmentation: np.ndarray | None = None  # (H, W) int32
    labels: dict[int, str] = field(default_factory=dict)
    camera_height: float = CAMERA_HEIGHT_M
    reading: ReadingView | None = None


class DiscreteAction(str, Enum):
    """A discrete motion step."""

    FORWARD = "forward"  # FORWARD_STEP_M ahead
    TURN_LEFT = "turn_left"  # TURN_STEP_RAD counter-clockwise
    TURN_RIGHT = "turn_right"  # TURN_STEP_RAD clockwise
    STOP = "stop"


class MotionStatus(str, Enum):
    """State of the last motion command."""

    IDLE = "idle"  # nothing commanded, or the last step completed
    MOVING = "moving"
    BLOCKED = "blocked"  # the last motion ended early against an obstacle
    FAULT = "fault"  # the body cannot move (stale odometry, lost connection)


@runtime_checkable
class Clock(Protocol):
    """Time for tree timeouts: sim time in simulation, ROS time on the robot."""

    def now(self) -> float:
        """Seconds on this clock."""
        ...

    def wait(self, dt: float) -> None:
        """Let ``dt`` seconds pass (the sim advances physics; the robot sleeps). Runner only."""
        ...


@runtime_checkable
class Base(Protocol):
    """The robot body: observations, motion commands, motion status, stop."""

    clock: Clock

    def observe(self) -> Observation:
        """The latest observation (may render or wait for a frame: call from a worker)."""
        ...

    def pose(self) -> Pose2D:
        """The current odometry pose (cheap)."""
        ...

    def step(self, action: DiscreteAction) -> None:
        """Start a discrete step; progress is reported by ``motion_status``."""
        ...

    def set_velocity(self, linear: float, angular: float) -> None:
        """Command a body velocity (m/s, rad/s), clipped to the body's limits."""
        ...

    def motion_status(self) -> MotionStatus: ...

    def stop(self) -> None:
        """Stop at once and drop any step in progress."""
        ...


class EntityKind(str, Enum):
    """What a plan step, a sign or a detection refers to."""

    ROOM = "room"  # seen as its door, marked by its door sign
    LANDMARK = "landmark"  # elevator, stairs, reception, ...: seen as itself or its sign


@dataclass(frozen=True, order=True)
class Entity:
    """A typed reference to a room or landmark of the building (never a prefixed string)."""

    kind: EntityKind
    id: str

    @classmethod
    def room(cls, ident: str) -> Entity:
        return cls(EntityKind.ROOM, ident)

    @classmethod
    def landmark(cls, ident: str) -> Entity:
        return cls(EntityKind.LANDMARK, ident)

    def __str__(self) -> str:  # for logs and people: "room 17", "landmark elevator1"
        return f"{self.kind.value} {self.id}"


@dataclass
class Detection:
    """A grounded object: pixel box (x0, y0, x1, y1), score in [0, 1], optional mask.

    ``entity``: what the grounder recognised it as (None for class masks and unmatched
    text); ``label``: the text a person would read there (the sign), for logs.
    ``point``: the object's 3D position in the camera body frame (x forward, y left,
    z up, metres) when the grounder had depth, else None.
    """

    label: str
    box: tuple[float, float, float, float]
    score: float
    mask: np.ndarray | None = None  # (H, W) bool
    entity: Entity | None = None
    point: tuple[float, float, float] | None = None

    @property
    def centre(self) -> tuple[float, float]:
        if self.mask is not None and self.mask.any():
            ys, xs = np.nonzero(self.mask)
            return float(xs.mean()), float(ys.mean())
        x0, y0, x1, y1 = self.box
        return (x0 + x1) / 2.0, (y0 + y1) / 2.0


@dataclass(frozen=True)
class SurfaceMasks:
    """Where the floor and the walls are in one frame: (H, W) bool masks."""

    floor: np.ndarray
    wall: np.ndarray


@runtime_checkable
class Grounder(Protocol):
    """Finds things in one frame: a room's door or a landmark, every readable sign, and
    the floor/wall surfaces (corner, opening and obstacle checks).

    ``needs_sim_labels``: True for back ends that read the simulator's segmentation;
    the factory refuses them on a robot. How far and how often it names signs (its
    reading model) and whether it is an oracle are declared, by name, in its registry
    spec (``registry.GrounderSpec``): read before any grounder is built.
    """

    needs_sim_labels: bool

    def detect(self, obs: Observation, target: Entity) -> list[Detection]:
        """Detections of ``target`` (a room is grounded as its door), best first."""
        ...

    def read_signs(self, obs: Observation) -> list[Detection]:
        """Every sign readable in the frame, each with the ``entity`` it names."""
        ...

    def surfaces(self, obs: Observation) -> SurfaceMasks:
        """Floor and wall masks of the frame."""
        ...


@dataclass(frozen=True)
class View:
    """One view of a panorama: its yaw relative to the heading when the sweep began, the
    frame, and the target's detections when it was grounded during the capture (None: not
    grounded yet; an empty tuple: grounded, nothing found)."""

    relative_yaw: float
    observation: Observation
    detections: tuple[Detection, ...] | None = None


@dataclass(frozen=True)
class CoarseChoice:
    """The view that shows the target, and the detection that says so."""

    view: View
    detection: Detection

    def __str__(self) -> str:  # logs and tree snapshots (no image arrays)
        d = self.detection
        yaw = math.degrees(self.view.relative_yaw)
        return f"{d.entity or d.label} at {yaw:+.0f} deg (score {d.score:.2f})"


@runtime_checkable
class CoarseDirection(Protocol):
    """Panorama views -> the view that shows the target (and its detection), or None."""

    def choose(self, views: Sequence[View], target: Entity) -> CoarseChoice | None: ...


@dataclass(frozen=True)
class Refinement:
    """A refined direction to a grounded goal: bearing (rad, left positive, relative to the
    observation's heading) and range (m) when the back end measures it."""

    bearing: float
    range: float | None = None


@runtime_checkable
class Refiner(Protocol):
    """Observation + grounded goal (pixel/mask) -> a precise bearing, and range if known.

    ``gives_range``: whether ``refine`` measures the range (else callers take it from the map).
    ``drives_approach``: whether it is also a ``PixelGoalPolicy`` that drives the approach
    to the goal door in closed loop (the tree then approaches with ``PolicyApproach``).
    """

    gives_range: bool
    drives_approach: bool

    def refine(self, obs: Observation, goal: Detection) -> Refinement: ...


@dataclass(frozen=True)
class PolicyStep:
    """One decision of a pixel-goal policy: the action, where it tracks the goal pixel in
    this frame (pixels of the observation; None when it reckons the goal behind), and how
    many steps it expects to need."""

    action: DiscreteAction
    goal_pixel: tuple[float, float] | None
    steps_to_goal: float


@runtime_checkable
class PixelGoalPolicy(Protocol):
    """Closed-loop navigation to a goal pixel (PixelNav): ``reset`` with a frame and the
    grounded goal in it, then one ``act`` per new frame until it answers STOP.

    Stateful (it keeps the frame history) and slow (a network): call from the worker.
    ``max_steps``: the actions the policy was trained to reach its goal within.
    """

    max_steps: int

    def reset(self, obs: Observation, goal: Detection) -> None: ...

    def act(self, obs: Observation) -> PolicyStep: ...


@dataclass(frozen=True)
class PlanConstraints:
    """What a replan must avoid: landmarks that failed, corridor segments found blocked;
    ``blocked_at``: map points where a way was seen shut (a start on the segment of one
    leaves it only by the end on its own side)."""

    avoid_landmarks: frozenset[str] = frozenset()
    blocked_segments: frozenset[int] = frozenset()
    blocked_at: frozenset[tuple[float, float]] = frozenset()


# A plan start: an estimated map pose (inside the loop), or a map node / segment / room
# name as a person types it (the CLI).
PlanStart = Union[Pose2D, str]  # noqa: UP007 - a runtime alias on Python 3.10


@runtime_checkable
class Planner(Protocol):
    """Priori-map + start + goal room (+ constraints) -> Plan."""

    def plan(
        self,
        pm: PrioriMap,
        start: PlanStart,
        goal: str,
        constraints: PlanConstraints = PlanConstraints(),
    ) -> Plan: ...


# -- lifts -------------------------------------------------------------------------------
# A Create 3 cannot press a lift's buttons: the building's lift system (or a person) moves
# the lift for it. The seam follows Open-RMF's lift protocol (rmf_lift_msgs): a robot asks
# for a lift by a *session* (LiftRequest: lift_name, session_id, request_type AGV mode or
# end session, destination_floor, door_state open) and watches the lift's LiftState
# (current_floor, destination_floor, door_state, motion_state, session_id,
# available_floors). Levels are named as the building file names them.


class LiftDoor(str, Enum):
    """The lift's door, as rmf_lift_msgs/LiftState.door_state (0 closed, 1 moving, 2 open)."""

    CLOSED = "closed"
    MOVING = "moving"
    OPEN = "open"


class LiftMotion(str, Enum):
    """The cabin's motion, as rmf_lift_msgs/LiftState.motion_state (0..3)."""

    STOPPED = "stopped"
    UP = "up"
    DOWN = "down"
    UNKNOWN = "unknown"


@dataclass(frozen=True)
class LiftState:
    """What the lift system says about one lift. ``session``: the session the lift serves
    now ("" when none); ``stamp``: the lift system's time of this state, in seconds."""

    lift: str
    current_level: str
    destination_level: str
    door: LiftDoor
    motion: LiftMotion
    session: str = ""
    available_levels: tuple[str, ...] = ()
    stamp: float = 0.0


@runtime_checkable
class Lift(Protocol):
    """The building's lift system as the robot sees it: requests out, states in.

    ``request(lift, level, session)`` asks the lift to come to (or, with the robot inside,
    go to) ``level`` and open its door there, for ``session`` (RMF's REQUEST_AGV_MODE with
    DOOR_OPEN); asking again with another level moves the cabin. ``release`` ends the
    session (REQUEST_END_SESSION), so others may use the lift. ``state`` is the latest state
    heard of the lift, ``None`` before any. Implementations: the simulator's lift
    (``sim/``), the ROS 2 lift client over rmf_lift_msgs (``hardware/``), and the doubles.
    """

    def request(self, lift: str, level: str, session: str) -> None: ...

    def release(self, lift: str, session: str) -> None: ...

    def state(self, lift: str) -> LiftState | None: ...
