"""Wheel odometry with drift, around a simulated body.

Real odometry drifts; a tree that never corrects itself with landmarks would look
fine on perfect odometry and fail on a robot. ``NoisyOdometry`` wraps a SimBase and
reports an odometry pose integrated from the true motion with a seeded relative
error on every increment (scale on distance, and heading error growing with distance
and rotation). It is itself a ``Base``; ``true_pose()`` gives the ground truth. What the
body's bumper felt is reported in the drifting frame (``hazards``), as the robot's is.
"""

from __future__ import annotations

import math
import random
from dataclasses import replace
from typing import TYPE_CHECKING

from pmnav_bt.geometry import se2_compose, se2_inverse, wrap_angle
from pmnav_bt.hazards import Hazard, body_blocked_by, body_hazards
from pmnav_bt.seams import Base, Observation, Pose2D
from pmnav_bt.sim.robot import SimBase
from pmnav_bt.wrapped_base import WrappedBase

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.config import SimConfig
    from pmnav_bt.sim.world import SimWorld


def simulated_robot(
    world: SimWorld, sim: SimConfig, pose: Pose2D, seed: int
) -> tuple[SimBase, Base]:
    """The robot of a simulated run as the config's ``sim`` section describes it: the body
    (ground truth: its true pose and its stats) with the camera of ``sim.width`` x
    ``sim.height`` (and ``sim.reading_width``), and the base the tree drives: the body seen
    through drifting odometry (``NoisyOdometry``, seeded by ``seed``), or the body itself
    when ``sim.odometry_noise`` is 0."""
    body = SimBase(
        world, pose=pose, width=sim.width, height=sim.height, reading_width=sim.reading_width
    )
    if sim.odometry_noise > 0:
        return body, NoisyOdometry(body, sim.odometry_noise, seed=seed)
    return body, body


class NoisyOdometry(WrappedBase):
    """A Base whose pose is drifting odometry of the wrapped SimBase.

    ``noise`` is the standard deviation of the relative error of each increment; the
    odometry frame starts equal to the map frame (the tree does not know that).
    """

    def __init__(self, base: SimBase, noise: float, seed: int = 0):
        super().__init__(base)
        self.noise = float(noise)
        self._rng = random.Random(seed)
        self._last_true = base.pose()
        self._odom = base.pose()
        # Constant biases per run (miscalibrated wheel radius and wheel base), plus
        # per-increment noise: distance scale ~ N(1, noise), heading drift ~ N(0, noise/10)
        # rad per metre, rotation scale ~ N(1, noise).
        self._scale = 1.0 + self._rng.gauss(0.0, self.noise)
        self._yaw_per_m = self._rng.gauss(0.0, self.noise / 10.0)
        self._rot_scale = 1.0 + self._rng.gauss(0.0, self.noise)
        self.clock.add_listener(self._integrate)

    def _integrate(self, _h: float) -> None:
        # Runs before the inner body moves in this tick: integrate the previous tick's motion.
        self._update()

    def _update(self) -> None:
        true = self.inner.pose()
        last = self._last_true
        dx, dy = true.x - last.x, true.y - last.y
        # Increment in the body frame of the last true pose.
        c, s = math.cos(last.yaw), math.sin(last.yaw)
        fwd, side = c * dx + s * dy, -s * dx + c * dy
        dth = wrap_angle(true.yaw - last.yaw)
        if fwd or side or dth:
            n = self.noise
            dist = math.hypot(fwd, side)
            fwd *= self._scale * (1.0 + self._rng.gauss(0.0, n))
            side *= self._scale
            dth = dth * self._rot_scale * (1.0 + self._rng.gauss(0.0, n)) + self._yaw_per_m * dist
            o = self._odom
            co, so = math.cos(o.yaw), math.sin(o.yaw)
            self._odom = Pose2D(
                o.x + co * fwd - so * side, o.y + so * fwd + co * side, wrap_angle(o.yaw + dth)
            )
        self._last_true = true

    # -- Base seam ---------------------------------------------------------------------------

    def pose(self) -> Pose2D:
        self._update()
        return self._odom

    def true_pose(self) -> Pose2D:
        return self.inner.pose()

    def hazards(self, since: float = -math.inf) -> list[Hazard]:
        """What the body felt since ``since``, in this odometry frame (mapped with the
        drift of now: the body stops at what it bumps, so it is read where it was felt)."""
        return [h.moved(self._odom_T_true()) for h in body_hazards(self.inner, since)]

    def blocked_by(self) -> Hazard | None:
        """The bump that cut the body's latest motion, in this odometry frame."""
        hazard = body_blocked_by(self.inner)
        return None if hazard is None else hazard.moved(self._odom_T_true())

    def _odom_T_true(self) -> tuple[float, float, float]:
        o, t = self.pose(), self.inner.pose()
        return se2_compose((o.x, o.y, o.yaw), se2_inverse((t.x, t.y, t.yaw)))

    def observe(self) -> Observation:
        obs = self.inner.observe()
        return replace(obs, pose=self.pose())
