"""What every PM-Nav behaviour shares: the body, the map, the back ends, the worker, the trace.

Data that flows between behaviours goes on the blackboard (namespace ``/pmnav``);
the Context holds the things a behaviour *uses* (injected once, not looked up).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from pmnav_bt.config import Config
from pmnav_bt.control import Limits, Odometer
from pmnav_bt.geometry import se2_compose, wrap_angle
from pmnav_bt.local_planner.steering import DirectSteering, Steering, make_steering
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.map.updates import NO_MAP_UPDATES, MapUpdateSink
from pmnav_bt.pose.evidence.floor_model import CORRIDORS, WallSource
from pmnav_bt.pose.odometry import CalibratedBase
from pmnav_bt.seams import Base, CoarseDirection, Grounder, Planner, Pose2D, Refiner
from pmnav_bt.tree_variants import DetourCheck
from pmnav_bt.worker import Worker

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.perception.misreads import Misreads


@dataclass
class TraceEvent:
    """Something worth drawing later: a detection, a fix, a turn, a plan; with the camera
    frame it was seen in, if any, shown by a thumbnail.

    Shrinking a frame to its thumbnail takes a third of a millisecond, too long for a
    tick (docs/architecture.md: a tick never blocks): ``Context.log`` keeps the frame and
    has the worker shrink it (``shrink``); an event whose shrinking never ran (the run
    ended first) shrinks its frame when its thumbnail is first asked for, after the run."""

    kind: str
    time: float
    odom: tuple[float, float, float]
    label: str = ""
    data: dict[str, Any] = field(default_factory=dict)
    frame: np.ndarray | None = None  # the frame, until it is shrunk to ``thumbnail``
    _thumbnail: np.ndarray | None = field(default=None, repr=False)

    def shrink(self) -> None:
        """Replace the frame by its thumbnail (in the worker; nothing to do once done)."""
        frame = self.frame
        if frame is not None:
            self._thumbnail, self.frame = thumbnail(frame), None

    @property
    def thumbnail(self) -> np.ndarray | None:
        """A small copy of the frame (None: the event has none)."""
        self.shrink()
        return self._thumbnail


@dataclass
class Context:
    """Injected into every behaviour of one tree. ``base`` is wrapped in a
    ``CalibratedBase``: its odometry's rotation and distance scales are learnt from the
    walls (each distance track is a ``calibrate`` trace event)."""

    base: Base
    pm: PrioriMap  # the map-less baseline: a SignsOnly (sign vocabulary, no geometry)
    config: Config
    grounder: Grounder
    coarse: CoarseDirection
    refiner: Refiner
    planner: Planner | None  # None: the map-less baseline
    worker: Worker
    detour_check: DetourCheck | None  # None: no walls known beyond what depth shows
    # The walls the localization belief weighs depth against (``pose.evidence.floor_model``).
    walls: WallSource = CORRIDORS
    odometer: Odometer = field(default_factory=Odometer)
    trace: list[TraceEvent] = field(default_factory=list)
    budget_actions: int = 500
    map_updates: MapUpdateSink = NO_MAP_UPDATES  # where disagreements with the map go
    misreads: Misreads | None = None  # plates read that named nothing (trees.map_watch)
    steering: Steering = field(default_factory=DirectSteering)  # the drives' local planner

    def __post_init__(self) -> None:
        if not isinstance(self.base, CalibratedBase):
            self.base = CalibratedBase(self.base)
        self.base.on_distance = lambda scale, gain: self.log(
            "calibrate", "", distance_scale=scale, distance_gain=gain
        )
        # Every frame the body takes (a drive's watch, a panorama, a look) goes into the
        # drives' local costmap: what it showed is remembered when it is out of view.
        self.base.on_frame = lambda obs: self.steering.sense(obs, self.now())

    @classmethod
    def wired(
        cls, base: Base, pm: Any, config: Config, backends: Any, budget: int | None,
        deferred_work: bool, *, detour_check: DetourCheck | None, walls: WallSource = CORRIDORS,
    ) -> Context:  # fmt: skip
        """The back ends ``backends`` (a ``backends.Backends``) wired to ``base`` and ``pm``,
        with a fresh Worker and the config's action budget unless ``budget`` is given;
        ``detour_check``: see ``DetourCheck`` (the tree variant decides it); ``walls``: the
        localization's wall model."""
        return cls(
            base=base,
            pm=pm,
            config=config,
            grounder=backends.grounder,
            coarse=backends.coarse,
            refiner=backends.refiner,
            planner=backends.planner,
            worker=Worker(deferred=deferred_work),
            detour_check=detour_check,
            walls=walls,
            budget_actions=budget if budget is not None else config.tree.budget_actions,
            steering=make_steering(config.tree.local_planner),
        )

    @property
    def limits(self) -> Limits:
        return Limits(self.config.tree.max_linear, self.config.tree.max_angular)

    def now(self) -> float:
        return self.base.clock.now()

    def log(self, kind: str, label: str = "", frame: np.ndarray | None = None, **data) -> None:
        """Add an event to the trace, with the camera ``frame`` (RGB) it was seen in, if any:
        its thumbnail is made in the worker (``TraceEvent``), not in the tick."""
        p = self.base.pose()
        event = TraceEvent(kind, self.now(), (p.x, p.y, p.yaw), label, data, frame)
        self.trace.append(event)
        if frame is not None:
            self.worker.submit(lambda cancelled: event.shrink())


def map_pose(map_T_odom: tuple[float, float, float] | None, odom: Pose2D) -> Pose2D:
    """The estimated map pose from the odometry pose (identity before localization)."""
    if map_T_odom is None:
        return odom
    x, y, yaw = se2_compose(map_T_odom, (odom.x, odom.y, odom.yaw))
    return Pose2D(x, y, yaw)


def thumbnail(rgb: np.ndarray, width: int = 96) -> np.ndarray:
    """A small copy of a frame for the trace."""
    import cv2

    h, w = rgb.shape[:2]
    return cv2.resize(rgb, (width, max(1, int(round(h * width / w)))), interpolation=cv2.INTER_AREA)


def heading_error(a: float, b: float) -> float:
    return abs(wrap_angle(a - b))
