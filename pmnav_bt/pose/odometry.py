"""Odometry whose rotation is calibrated against the corridor walls.

Wheel odometry turns by a constant factor too much or too little (wheel base
miscalibrated, wheel slip when turning in place): a 5 % rotation-scale error puts the
heading 9 deg off after turning round and 18 deg off after one panorama, which takes the
pose estimate off the corridor axis faster than the walls can pull it back. The walls
measure that error: their direction in odometry must stay the same (modulo 90 deg)
while the robot turns, so how fast it moves with the odometry's rotation during a
panorama is the rotation-scale error (``rotation_scale_error``).

``CalibratedBase`` wraps a ``Base`` and reports odometry re-integrated with every yaw
increment multiplied by ``gain`` (1.0 until ``calibrate`` learns it; until then it passes
the poses through unchanged).
"""

from __future__ import annotations

import math
import threading
from dataclasses import replace

import numpy as np

from pmnav_bt.geometry import se2_compose, se2_inverse, wrap_angle
from pmnav_bt.seams import Base, Observation, Pose2D
from pmnav_bt.wrapped_base import WrappedBase

MIN_VIEWS = 4  # wall directions needed in one panorama to measure the rotation error
MIN_SPAN = math.radians(180.0)  # ... spread over at least this much turning
MAX_RESIDUAL = math.radians(2.5)  # rms misfit of the wall directions: not one straight axis
MAX_GAIN_ERROR = 0.2  # a learnt gain stays within 1 +- this


def rotation_scale_error(angles: list[tuple[float, float, int]]) -> float | None:
    """How fast the corridor axis measured in odometry turns per radian the odometry
    turned, from one panorama's views in the order taken: (view odometry yaw, wall
    direction in that view, inliers), the same input as ``walls.axis_in_odom``. Walls run
    along or across the axis, so directions are compared modulo 90 deg. None when too few
    views see a wall, they span too little turning, or they do not fit one axis."""
    if len(angles) < MIN_VIEWS:
        return None
    turned, axis = [0.0], []
    for i, (yaw, a, _) in enumerate(angles):
        if i:
            turned.append(turned[-1] + wrap_angle(yaw - angles[i - 1][0]))
        d = yaw + a
        if axis:  # unwrap modulo pi/2, step by step
            d = axis[-1] + wrap_angle(4.0 * (d - axis[-1])) / 4.0
        axis.append(d)
    r, d = np.array(turned), np.array(axis)
    if np.ptp(r) < MIN_SPAN:
        return None
    slope, icpt = np.polyfit(r, d, 1)
    rms = float(np.sqrt(np.mean((d - (slope * r + icpt)) ** 2)))
    return None if rms > MAX_RESIDUAL else float(slope)


class CalibratedBase(WrappedBase):
    """A ``Base`` whose odometry yaw increments are multiplied by ``gain``.

    Poses are re-integrated from the wrapped base's increments each time they are read
    (the tree reads them every tick); an observation's pose is mapped with the current
    correction (it is read right after the frame). Everything else passes through.
    """

    def __init__(self, inner: Base) -> None:
        super().__init__(inner)
        self.gain = 1.0
        self._asked: list[float] = []  # the gain each measurement asked for
        self._lock = threading.Lock()
        self._raw: Pose2D | None = None
        self._corr: Pose2D | None = None

    def __getattr__(self, name):  # helpers of the wrapped base (tests, runners)
        return getattr(self.inner, name)

    def calibrate(self, error: float) -> float:
        """Take in a measured ``rotation_scale_error`` (of the calibrated odometry); the
        new gain: the mean of the gains every measurement so far asked for."""
        with self._lock:
            self._update(self.inner.pose())
            g = float(
                np.clip(self.gain * (1.0 - error), 1.0 - MAX_GAIN_ERROR, 1.0 + MAX_GAIN_ERROR)
            )
            self._asked.append(g)
            self.gain = float(np.mean(self._asked))
            return self.gain

    def corr_T_raw(self) -> tuple[float, float, float]:
        """The calibrated odometry frame from the wrapped base's, now (it changes as the
        robot turns once calibrated): ``map_T_odom`` of the tree composed with it is the
        map pose of the base's own odometry frame (for a map -> odom transform)."""
        with self._lock:
            self._update(self.inner.pose())
            return self._corr_T_raw()

    def _corr_T_raw(self) -> tuple[float, float, float]:
        c, r = self._corr, self._raw
        return se2_compose((c.x, c.y, c.yaw), se2_inverse((r.x, r.y, r.yaw)))

    def _update(self, raw: Pose2D) -> Pose2D:
        last, corr = self._raw, self._corr
        self._raw = raw
        if last is None or self.gain == 1.0 and corr == last:
            self._corr = raw  # not calibrated yet: the odometry as it is
            return raw
        dth = wrap_angle(raw.yaw - last.yaw)
        mid = last.yaw + dth / 2.0
        dx, dy = raw.x - last.x, raw.y - last.y
        fwd = math.cos(mid) * dx + math.sin(mid) * dy
        side = -math.sin(mid) * dx + math.cos(mid) * dy
        cth = dth * self.gain
        cm = corr.yaw + cth / 2.0
        self._corr = Pose2D(
            corr.x + math.cos(cm) * fwd - math.sin(cm) * side,
            corr.y + math.sin(cm) * fwd + math.cos(cm) * side,
            wrap_angle(corr.yaw + cth),
        )
        return self._corr

    def pose(self) -> Pose2D:
        with self._lock:
            return self._update(self.inner.pose())

    def observe(self) -> Observation:
        obs = self.inner.observe()
        with self._lock:
            self._update(self.inner.pose())
            if self._corr == self._raw:
                return obs
            corr_T_raw = self._corr_T_raw()
        q = obs.pose
        x, y, yaw = se2_compose(corr_T_raw, (q.x, q.y, q.yaw))
        return replace(obs, pose=Pose2D(x, y, wrap_angle(yaw)))
