"""The seams of DESIGN.md: small Protocols the tree talks to, and the data they pass.

Nothing above ``sim/`` and ``hardware/`` knows which body it drives: both implement
``Base`` and ``Clock``. Perception back ends implement ``Grounder``,
``CoarseDirection`` and ``Refiner``; planners implement ``Planner``.

Units are SI, angles radians, REP-103 axes (x forward, y left, z up), headings
counter-clockwise from +x in the map frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING, Protocol, runtime_checkable

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


@dataclass
class Observation:
    """What the body sees at one instant.

    ``segmentation`` holds integer ids whose meaning is in ``labels``:
    "floor", "wall", "door:<room>", "sign:<room>", "landmark:<id>", "obstacle".
    """

    rgb: np.ndarray  # (H, W, 3) uint8
    pose: Pose2D  # odometry pose of the base
    stamp: float  # Clock time, seconds
    intrinsics: CameraIntrinsics
    depth: np.ndarray | None = None  # (H, W) float32 metres along the optical axis
    segmentation: np.ndarray | None = None  # (H, W) int32
    labels: dict[int, str] = field(default_factory=dict)
    camera_height: float = 1.6


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


@dataclass
class Detection:
    """A grounded object: label, pixel box (x0, y0, x1, y1), optional mask, score in [0, 1]."""

    label: str
    box: tuple[float, float, float, float]
    score: float
    mask: np.ndarray | None = None  # (H, W) bool

    @property
    def centre(self) -> tuple[float, float]:
        if self.mask is not None and self.mask.any():
            ys, xs = np.nonzero(self.mask)
            return float(xs.mean()), float(ys.mean())
        x0, y0, x1, y1 = self.box
        return (x0 + x1) / 2.0, (y0 + y1) / 2.0


class Grounder(Protocol):
    """Text query -> detections in one image."""

    def detect(self, obs: Observation, query: str) -> list[Detection]: ...


@dataclass(frozen=True)
class View:
    """One view of a panorama: its yaw relative to the body heading when taken, and the frame."""

    relative_yaw: float
    observation: Observation


class CoarseDirection(Protocol):
    """Panorama views -> the relative yaw of the view that shows the target, or None."""

    def choose(self, views: list[View], target: str) -> float | None: ...


class Refiner(Protocol):
    """Observation + goal pixel/mask -> precise relative heading (rad) to the goal."""

    def refine(self, obs: Observation, goal: Detection) -> float: ...


class Planner(Protocol):
    """Priori-map + start + goal -> Plan."""

    def plan(self, pm: PrioriMap, start: str, goal: str) -> Plan: ...
