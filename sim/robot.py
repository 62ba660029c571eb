"""The simulated robot: a Create 3 sized differential-drive body with a 1.6 m camera.

``SimBase`` implements the ``pmnav_bt.seams.Base`` seam. Motion is kinematic: each
clock tick moves the body at the speed limits (discrete steps) or at the commanded
velocity, and a translation that would make the body's cylinder touch a wall,
door, landmark or obstacle is cut at the contact point (bisection to 0.1 mm), which
ends the motion as BLOCKED. A collision event is counted once, when the body first
touches something; it ends when the body is 1 cm clear again. Turning in place never
collides (the body is a round cylinder). Like the Create 3 (``safety_override: none``)
it reverses only within its backup buffer (``pmnav_bt.backup_limit``): at most 0.15 m
over floor it has just driven forward over; a reverse beyond it stops as BLOCKED.

It has the Create 3's bumper (``pmnav_bt.hazards.FeelsHazards``): a motion cut at a
contact in front of the wheels is felt as a bump in the zone that touched
(``sim/bumper.py``), a point in its odometry frame; it is what stopped that motion
(``blocked_by``) until the next motion is accepted. A contact behind the wheels (backing
into something) presses no bumper, as on the robot.
"""

from __future__ import annotations

import math
import threading
from collections import deque
from dataclasses import dataclass

import numpy as np

from pmnav_bt.backup_limit import BACKUP_LIMIT_M, BackupBuffer
from pmnav_bt.geometry import wrap_angle
from pmnav_bt.hazards import Hazard, HazardKind, bump_zone, place
from pmnav_bt.seams import (
    CAMERA_HEIGHT_M,
    CREATE3_MAX_ANGULAR,
    CREATE3_MAX_LINEAR,
    CREATE3_RADIUS_M,
    FORWARD_STEP_M,
    TURN_STEP_RAD,
    CameraIntrinsics,
    DiscreteAction,
    MotionStatus,
    Observation,
    Pose2D,
)
from pmnav_bt.sim._pybullet import p
from pmnav_bt.sim.bumper import contact_bearing
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.render import render_camera
from pmnav_bt.sim.scene.camera_effects import CameraEffects
from pmnav_bt.sim.world import ROBOT, SimWorld

MAX_LINEAR = CREATE3_MAX_LINEAR  # m/s
MAX_ANGULAR = CREATE3_MAX_ANGULAR  # rad/s
RADIUS = CREATE3_RADIUS_M  # m
COLLISION_HEIGHT = 1.7  # the body with its camera mast, for collisions
CAMERA_HEIGHT = CAMERA_HEIGHT_M  # m (paper)
HFOV = math.radians(60.0)  # horizontal field of view (paper)
CONTACT_CLEAR = 0.01  # a collision event ends once the body is this far from everything
FELT_KEPT = 64  # bumps kept for ``hazards`` (the costmap takes them within a second)
_BISECT_TOL = 1e-4


@dataclass
class MotionStats:
    """What the body has done: metres driven, radians turned, collision events, actions."""

    path_length: float = 0.0
    rotation: float = 0.0
    collisions: int = 0
    actions: int = 0


class RenderedReading:
    """A view rendered at a higher resolution when asked for (``seams.ReadingView``): RGB
    only, from the pose and heading of the observation it belongs to; ``crop`` renders
    just the pixels asked for (a plate's crop: a few ms, the whole 640x480 view ~150 ms).
    The same ``camera`` takes it as the observation (blur, exposure, noise), turning at
    the observation's ``yaw_rate`` at time ``stamp``."""

    def __init__(
        self,
        world: SimWorld,
        body: Pose2D,
        yaw_offset: float,
        intrinsics: CameraIntrinsics,
        camera_height: float,
        camera: CameraEffects,
        yaw_rate: float,
        stamp: float,
    ) -> None:
        self.width, self.height = intrinsics.width, intrinsics.height
        self._args = (world, body.x, body.y, body.yaw + yaw_offset, intrinsics)
        self._height_m = camera_height
        self._camera, self._yaw_rate, self._stamp = camera, yaw_rate, stamp
        self._rgb: np.ndarray | None = None
        self._lock = threading.Lock()

    def _take(self, rgb: np.ndarray, window: tuple[int, int, int, int]) -> np.ndarray:
        _, x, y, yaw, k = self._args
        key = (self._stamp, x, y, yaw, *window)
        return self._camera.apply(rgb, yaw_rate=self._yaw_rate, fx=k.fx, key=key)

    def rgb(self) -> np.ndarray:
        with self._lock:
            if self._rgb is None:
                frame = render_camera(
                    *self._args, height=self._height_m, depth=False, segmentation=False
                )
                self._rgb = self._take(frame.rgb, (0, 0, self.width, self.height))
            return self._rgb

    def crop(self, box: tuple[int, int, int, int]) -> np.ndarray:
        x0, y0, x1, y1 = box
        with self._lock:
            if self._rgb is not None:
                return self._rgb[y0:y1, x0:x1]
        window = (max(0, x0), max(0, y0), min(self.width, x1), min(self.height, y1))
        if window[2] <= window[0] or window[3] <= window[1]:
            return np.zeros((0, 0, 3), np.uint8)
        if self._camera.identity:
            frame = render_camera(
                *self._args, height=self._height_m, depth=False, segmentation=False, window=window
            )
            return frame.rgb
        # Rendered wider by the blur's reach, so the crop's edges blur as in the whole view.
        m = self._camera.margin_px(self._yaw_rate, self._args[4].fx)
        wide = (max(0, window[0] - m), window[1], min(self.width, window[2] + m), window[3])
        frame = render_camera(
            *self._args, height=self._height_m, depth=False, segmentation=False, window=wide
        )
        rgb = self._take(frame.rgb, wide)
        return rgb[:, window[0] - wide[0] : window[2] - wide[0]]


class SimBase:
    """A simulated Create 3 in a SimWorld, driven by a SimClock (``pmnav_bt.seams.Base``).

    ``width``/``height``/``hfov`` set the camera; ``depth``/``segmentation`` choose what
    ``observe`` renders besides RGB. ``reading_width`` (pixels, wider than ``width``):
    each observation offers the same view at that size for reading signs
    (``Observation.reading``, rendered only when asked; 0: none). The body starts at
    ``pose`` (default: the world's start pose). ``backup_limit``: metres it may reverse
    after driving forward (None: no limit, as with the Create 3's
    ``safety_override: backup_only``).
    """

    def __init__(
        self,
        world: SimWorld,
        clock: SimClock | None = None,
        *,
        pose: Pose2D | None = None,
        width: int = 320,
        height: int = 240,
        hfov: float = HFOV,
        camera_height: float = CAMERA_HEIGHT,
        depth: bool = True,
        segmentation: bool = True,
        reading_width: int = 0,
        radius: float = RADIUS,
        max_linear: float = MAX_LINEAR,
        max_angular: float = MAX_ANGULAR,
        backup_limit: float | None = BACKUP_LIMIT_M,
    ) -> None:
        self.world = world
        self.clock = clock if clock is not None else SimClock()
        self.intrinsics = CameraIntrinsics.from_hfov(width, height, hfov)
        self.camera_height = camera_height
        self.render_depth = depth
        self.render_segmentation = segmentation
        self.reading_intrinsics = (
            CameraIntrinsics.from_hfov(
                reading_width, max(1, round(reading_width * height / width)), hfov
            )
            if reading_width > width
            else None
        )
        self.radius = radius
        self.max_linear = max_linear
        self.max_angular = max_angular
        self.stats = MotionStats()
        self.backup = None if backup_limit is None else BackupBuffer(limit=backup_limit)
        self.camera_effects = CameraEffects.of_world(world)
        self._pose = pose if pose is not None else world.start_pose()
        self._status = MotionStatus.IDLE
        self._step: DiscreteAction | None = None
        self._remaining = 0.0
        self._cmd = (0.0, 0.0)
        self._in_contact = False
        self._felt: deque[Hazard] = deque(maxlen=FELT_KEPT)  # bumps, oldest first
        self._blocked_by: Hazard | None = None  # the bump that cut the latest motion
        with world.lock:
            vis = p.createVisualShape(
                p.GEOM_CYLINDER,
                radius=radius,
                length=0.09,
                rgbaColor=(0.85, 0.85, 0.85, 1.0),
                physicsClientId=world.client,
            )
            self.body = p.createMultiBody(0.0, -1, vis, (0, 0, 0.045), physicsClientId=world.client)
            world.register(self.body, ROBOT, solid=False)
        self._sync_body()
        world.people.attach(self)  # people move first in each tick, then the robot
        self.clock.add_listener(self._advance)

    # -- Base seam --------------------------------------------------------------------------

    def observe(self) -> Observation:
        """Render the camera now (RGB, and depth/segmentation if enabled)."""
        return self.render_view(0.0)

    def pose(self) -> Pose2D:
        """Odometry pose (sim ground truth)."""
        return self._pose

    def step(self, action: DiscreteAction) -> None:
        """Start a discrete step (replaces any motion in progress)."""
        action = DiscreteAction(action)
        with self.world.lock:
            self.stats.actions += 1
            self._cmd = (0.0, 0.0)
            if action == DiscreteAction.STOP:
                self._step = None
                self._status = MotionStatus.IDLE
                return
            self._step = action
            self._remaining = FORWARD_STEP_M if action == DiscreteAction.FORWARD else TURN_STEP_RAD
            self._status = MotionStatus.MOVING
            self._blocked_by = None

    def set_velocity(self, linear: float, angular: float) -> None:
        """Command a body velocity, clipped to the limits; it holds until changed or blocked."""
        v = max(-self.max_linear, min(self.max_linear, float(linear)))
        w = max(-self.max_angular, min(self.max_angular, float(angular)))
        with self.world.lock:
            self._step = None
            if v < 0.0 and self.backup is not None and self.backup.left <= 0.0:
                self._cmd = (0.0, 0.0)  # refused, as the robot refuses it (BACKUP_LIMIT)
                self._status = MotionStatus.BLOCKED
                self._blocked_by = None
                return
            self._cmd = (v, w)
            self._status = MotionStatus.MOVING if (v or w) else MotionStatus.IDLE
            if v or w:
                self._blocked_by = None

    def motion_status(self) -> MotionStatus:
        return self._status

    def stop(self) -> None:
        with self.world.lock:
            self._step = None
            self._cmd = (0.0, 0.0)
            self._status = MotionStatus.IDLE

    # -- the bumper (pmnav_bt.hazards.FeelsHazards) ----------------------------------------

    def hazards(self, since: float = -math.inf) -> list[Hazard]:
        """The bumps felt from ``since`` (the clock's seconds) on, oldest first."""
        with self.world.lock:
            return [h for h in self._felt if h.stamp >= since]

    def blocked_by(self) -> Hazard | None:
        """The bump that cut the latest motion (None: none, or a motion accepted since)."""
        return self._blocked_by

    # -- helpers for runners, tests and the oracle ------------------------------------------

    @property
    def velocity_command(self) -> tuple[float, float]:
        """The (clipped) velocity command in force."""
        return self._cmd

    def set_pose(self, pose: Pose2D) -> None:
        """Teleport the body (drops any motion; does not count as driving)."""
        with self.world.lock:
            self._pose = Pose2D(float(pose.x), float(pose.y), wrap_angle(float(pose.yaw)))
            self._step = None
            self._cmd = (0.0, 0.0)
            self._status = MotionStatus.IDLE
            self._in_contact = False
            if self.backup is not None:
                self.backup.reset()  # put down somewhere new
            self._sync_body()

    def execute(self, action: DiscreteAction, timeout: float = 30.0) -> MotionStatus:
        """Run one discrete step to its end, advancing the clock; the final status."""
        self.step(action)
        t_end = self.clock.now() + timeout
        while self._status == MotionStatus.MOVING and self.clock.now() < t_end:
            self.clock.wait(self.clock.tick)
        return self._status

    def step_duration(self, action: DiscreteAction) -> float:
        """Seconds an unobstructed discrete step takes at the speed limits."""
        action = DiscreteAction(action)
        if action == DiscreteAction.FORWARD:
            return FORWARD_STEP_M / self.max_linear
        if action in (DiscreteAction.TURN_LEFT, DiscreteAction.TURN_RIGHT):
            return TURN_STEP_RAD / self.max_angular
        return 0.0

    def render_view(
        self,
        yaw_offset: float = 0.0,
        pose: Pose2D | None = None,
        *,
        depth: bool | None = None,
        segmentation: bool | None = None,
    ) -> Observation:
        """Render the camera turned by ``yaw_offset`` (rad, left positive) from ``pose``
        (default: the current pose). The observation's pose is the body pose, not the
        camera's; safe to call from a worker thread (for panoramas). The RGB is taken by
        the episode's camera (``camera_effects``: blur while turning, exposure, noise)."""
        body = pose if pose is not None else self._pose
        stamp = self.clock.now()
        yaw_rate = self.yaw_rate()
        with self.world.lock:
            labels = dict(self.world.labels)
        frame = render_camera(
            self.world,
            body.x,
            body.y,
            body.yaw + yaw_offset,
            self.intrinsics,
            height=self.camera_height,
            depth=self.render_depth if depth is None else depth,
            segmentation=self.render_segmentation if segmentation is None else segmentation,
        )
        yaw = body.yaw + yaw_offset
        key = (stamp, body.x, body.y, yaw, 0, 0, self.intrinsics.width, self.intrinsics.height)
        rgb = self.camera_effects.apply(
            frame.rgb, yaw_rate=yaw_rate, fx=self.intrinsics.fx, key=key
        )
        k = self.reading_intrinsics
        reading = None
        if k is not None:
            reading = RenderedReading(
                self.world,
                body,
                yaw_offset,
                k,
                self.camera_height,
                self.camera_effects,
                yaw_rate,
                stamp,
            )
        return Observation(
            rgb=rgb,
            pose=body,
            stamp=stamp,
            intrinsics=self.intrinsics,
            depth=frame.depth,
            segmentation=frame.segmentation,
            labels=labels,
            camera_height=self.camera_height,
            reading=reading,
        )

    def yaw_rate(self) -> float:
        """The body's turn rate now (rad/s, left positive): a turning step's speed limit or
        the commanded velocity's, 0 when it stands or is blocked."""
        with self.world.lock:
            if self._status != MotionStatus.MOVING:
                return 0.0
            if self._step == DiscreteAction.TURN_LEFT:
                return self.max_angular
            if self._step == DiscreteAction.TURN_RIGHT:
                return -self.max_angular
            return self._cmd[1] if self._step is None else 0.0

    def close(self) -> None:
        """Detach from the clock (the world is closed by its owner)."""
        if self._advance in self.clock._listeners:
            self.clock.remove_listener(self._advance)
        self.world.people.detach(self)

    # -- motion integration -------------------------------------------------------------------

    def _advance(self, h: float) -> None:
        """Clock listener: integrate ``h`` seconds of motion."""
        with self.world.lock:
            if self._step is not None:
                self._advance_step(h)
            elif self._cmd != (0.0, 0.0):
                v, w = self._cmd
                self._rotate(w * h / 2.0)
                want = v * h
                if want < 0.0 and self.backup is not None:
                    want = max(want, -self.backup.left)  # the backup buffer's end
                moved = self._translate(want)
                self._rotate(w * h / 2.0)
                if self.backup is not None:
                    self.backup.left = min(self.backup.limit, self.backup.left + moved)
                if abs(moved) < abs(v * h) - 1e-12:
                    self._cmd = (0.0, 0.0)
                    self._status = MotionStatus.BLOCKED
            else:
                return
            self._sync_body()

    def _advance_step(self, h: float) -> None:
        if self._step == DiscreteAction.FORWARD:
            want = min(self.max_linear * h, self._remaining)
            moved = self._translate(want)
            self._remaining -= moved
            if self.backup is not None:
                self.backup.left = min(self.backup.limit, self.backup.left + moved)
            if moved < want - 1e-12:
                self._step = None
                self._status = MotionStatus.BLOCKED
                return
        else:
            da = min(self.max_angular * h, self._remaining)
            self._rotate(da if self._step == DiscreteAction.TURN_LEFT else -da)
            self._remaining -= da
        if self._remaining <= 1e-9:
            self._step = None
            self._status = MotionStatus.IDLE

    def _rotate(self, da: float) -> None:
        if da:
            q = self._pose
            self._pose = Pose2D(q.x, q.y, wrap_angle(q.yaw + da))
            self.stats.rotation += abs(da)

    def _clearance(self, x: float, y: float) -> float:
        return self.world.clearance(x, y, self.radius, COLLISION_HEIGHT)

    def _translate(self, ds: float) -> float:
        """Move ``ds`` metres along the heading, stopping at contact; the signed distance moved."""
        if ds == 0.0:
            return 0.0
        q = self._pose
        cx, cy = math.cos(q.yaw), math.sin(q.yaw)
        d_new = self._clearance(q.x + ds * cx, q.y + ds * cy)
        if d_new >= 0.0:
            frac = 1.0
        else:
            d_now = self._clearance(q.x, q.y)
            if d_now < 0.0 and d_new > d_now:  # already inside something: let it back out
                frac = 1.0
            else:
                lo, hi = 0.0, 1.0  # lo is free, hi touches
                while (hi - lo) * abs(ds) > _BISECT_TOL:
                    mid = (lo + hi) / 2.0
                    if self._clearance(q.x + mid * ds * cx, q.y + mid * ds * cy) >= 0.0:
                        lo = mid
                    else:
                        hi = mid
                frac = lo
                if not self._in_contact:
                    self.stats.collisions += 1
                    self._in_contact = True
        moved = frac * ds
        if moved:
            self._pose = Pose2D(q.x + moved * cx, q.y + moved * cy, q.yaw)
            self.stats.path_length += abs(moved)
            if frac == 1.0 and d_new > CONTACT_CLEAR:
                self._in_contact = False
        if frac < 1.0:
            self._bump()
        return moved

    def _bump(self) -> None:
        """Feel the contact that cut the motion with the bumper, where it has one."""
        pose = self._pose
        bearing = contact_bearing(self.world, pose, self.radius, COLLISION_HEIGHT)
        zone = None if bearing is None else bump_zone(bearing)
        if zone is None:  # behind the wheels: no bumper there
            self._blocked_by = None
            return
        hazard = place(HazardKind.BUMP, zone, pose, self.clock.now())
        last = self._felt[-1] if self._felt else None
        if last is None or (last.frame, last.point) != (hazard.frame, hazard.point):
            self._felt.append(hazard)
        self._blocked_by = hazard

    def _sync_body(self) -> None:
        q = self._pose
        with self.world.lock:
            p.resetBasePositionAndOrientation(
                self.body,
                (q.x, q.y, 0.045),
                p.getQuaternionFromEuler((0.0, 0.0, q.yaw)),
                physicsClientId=self.world.client,
            )
