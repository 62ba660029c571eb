"""Odometry whose rotation and distance are calibrated against the corridor walls.

Wheel odometry turns by a constant factor too much or too little (wheel base
miscalibrated, wheel slip when turning in place): a 5 % rotation-scale error puts the
heading 9 deg off after turning round and 18 deg off after one panorama, which takes the
pose estimate off the corridor axis faster than the walls can pull it back. The walls
measure that error: their direction in odometry must stay the same (modulo 90 deg)
while the robot turns, so how fast it moves with the odometry's rotation during a
panorama is the rotation-scale error (``rotation_scale_error``).

Wheels also drive a constant factor too far or too short (tyre wear, wheel radius): at
5 % a 28 m leg ends 1.4 m off, beyond what the corridor belief and the door checks
allow. A wall ahead measures that too: driving straight at it, the free floor seen in
depth shrinks by the true distance driven (``distance_scale``), whatever the odometry
says.

``CalibratedBase`` wraps a ``Base`` and reports odometry re-integrated with every yaw
increment multiplied by ``gain`` and every distance by ``distance_gain`` (1.0 until
``calibrate`` and its own straight-drive tracks learn them; until then it passes the
poses through unchanged). What the body felt (``pmnav_bt.hazards``: bumps, cliffs) is put in
the calibrated frame too.
"""

from __future__ import annotations

import math
import threading
from dataclasses import replace

import numpy as np

from pmnav_bt.geometry import se2_compose, se2_inverse, wrap_angle
from pmnav_bt.hazards import Hazard, body_blocked_by, body_hazards
from pmnav_bt.perception.geometry import free_distance
from pmnav_bt.seams import Base, Observation, Pose2D
from pmnav_bt.wrapped_base import WrappedBase

MIN_VIEWS = 4  # wall directions needed in one panorama to measure the rotation error
MIN_SPAN = math.radians(180.0)  # ... spread over at least this much turning
MAX_RESIDUAL = math.radians(2.5)  # rms misfit of the wall directions: not one straight axis
MAX_GAIN_ERROR = 0.2  # a learnt gain stays within 1 +- this
# Distance: a straight drive at a wall seen in depth.
MIN_TRACK_M = 2.0  # the readings of one wall must span this much driving
MIN_TRACK_POINTS = 4
MAX_TRACK_TURN = math.radians(4.0)  # a drive is straight while the heading stays this close
TRACK_FREE_M = (0.6, 6.0)  # wall readings used: nearer, the wall leaves the view; farther,
# a pixel of the wall's foot spans centimetres
TRACK_STEP_SLACK_M = 0.1  # between two readings of one wall (beyond the gain's range)
MAX_TRACK_RMS = 0.05  # m, the readings' misfit of one straight-line approach


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


def distance_scale(track: list[tuple[float, float]]) -> float | None:
    """True metres per odometry metre, from one straight drive's frames in the order
    taken: (odometry distance driven along the drive's heading, free floor seen straight
    ahead in depth). Readings of one wall (consecutive frames whose free floor shrinks
    as the odometry says, within ``MAX_GAIN_ERROR``) spanning ``MIN_TRACK_M`` give the
    slope of free floor against odometry; a reading of something else (a door frame, the
    far wall once a side corridor opens) starts another run, and the longest run counts.
    None when no run is long enough or straight enough."""
    lo, hi = TRACK_FREE_M
    pts = [(s, f) for s, f in track if lo <= f <= hi]
    runs: list[list[tuple[float, float]]] = []
    for s, f in pts:
        if runs:
            s0, f0 = runs[-1][-1]
            ds = s - s0
            if ds >= 0.0 and abs((f0 - f) - ds) <= MAX_GAIN_ERROR * ds + TRACK_STEP_SLACK_M:
                runs[-1].append((s, f))
                continue
        runs.append([(s, f)])
    best = max(runs, key=lambda r: r[-1][0] - r[0][0], default=[])
    if len(best) < MIN_TRACK_POINTS or best[-1][0] - best[0][0] < MIN_TRACK_M:
        return None
    s, f = np.array(best).T
    slope, icpt = np.polyfit(s, f, 1)
    rms = float(np.sqrt(np.mean((f - (slope * s + icpt)) ** 2)))
    k = -float(slope)
    if rms > MAX_TRACK_RMS or abs(k - 1.0) > MAX_GAIN_ERROR:
        return None
    return k


class CalibratedBase(WrappedBase):
    """A ``Base`` whose odometry yaw increments are multiplied by ``gain`` and distance
    increments by ``distance_gain``.

    Poses are re-integrated from the wrapped base's increments each time they are read
    (the tree reads them every tick); an observation's pose is mapped with the current
    correction (it is read right after the frame). Every observation with depth also
    extends the current straight-drive track (raw odometry, free floor ahead); a frame
    that turned from it ends the track, whose ``distance_scale`` joins the distance
    gain (the mean of all tracks' scales, weighted by how far each drove).
    ``on_distance(scale, gain)`` is told each one; ``on_frame(obs)`` each observation, as
    corrected (the local costmap remembers what every frame shows). Everything else passes
    through.
    """

    def __init__(self, inner: Base) -> None:
        super().__init__(inner)
        self.gain = 1.0
        self.distance_gain = 1.0
        self.on_distance = None  # called with (scale, new distance gain) per track
        self.on_frame = None  # called with each observation, its pose corrected
        self._asked: list[float] = []  # the gain each measurement asked for
        self._scales: list[tuple[float, float]] = []  # (scale, metres) per track
        self._track: list[tuple[float, float]] = []
        self._track_from: Pose2D | None = None  # raw odometry where the track began
        self._lock = threading.RLock()
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
        robot turns or drives once calibrated): ``map_T_odom`` of the tree composed with it is the
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
        if last is None or self.gain == 1.0 and self.distance_gain == 1.0 and corr == last:
            self._corr = raw  # not calibrated yet: the odometry as it is
            return raw
        dth = wrap_angle(raw.yaw - last.yaw)
        mid = last.yaw + dth / 2.0
        dx, dy = raw.x - last.x, raw.y - last.y
        k = self.distance_gain
        fwd = k * (math.cos(mid) * dx + math.sin(mid) * dy)
        side = k * (-math.sin(mid) * dx + math.cos(mid) * dy)
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

    def hazards(self, since: float = -math.inf) -> list[Hazard]:
        """The hazards the wrapped body felt since ``since``, in this odometry frame ([]
        for a body without hazard sensors). Mapped with the correction of now: the body
        stops at a hazard, so it is read where it was felt."""
        felt = body_hazards(self.inner, since)
        if not felt:
            return felt
        corr_T_raw = self.corr_T_raw()
        return [h.moved(corr_T_raw) for h in felt]

    def blocked_by(self) -> Hazard | None:
        """The hazard that stopped the wrapped body's latest motion, in this frame."""
        hazard = body_blocked_by(self.inner)
        return None if hazard is None else hazard.moved(self.corr_T_raw())

    @property
    def distance_measured(self) -> bool:
        """Whether a straight drive at a wall has measured the distance gain yet."""
        with self._lock:
            return bool(self._scales)

    def _extend_track(self, raw: Pose2D, free: float) -> None:
        """Add a frame (its raw odometry pose and the free floor ahead) to the
        straight-drive track, ending the track and taking in its scale when the frame
        turned away from it or went back."""
        start = self._track_from
        if start is not None:
            c, s = math.cos(start.yaw), math.sin(start.yaw)
            along = c * (raw.x - start.x) + s * (raw.y - start.y)
            last = self._track[-1][0] if self._track else 0.0
            turned = abs(wrap_angle(raw.yaw - start.yaw)) > MAX_TRACK_TURN
            if not turned and along >= last - 0.05:
                self._track.append((along, free))
                return
            self._end_track()
        self._track_from = raw
        self._track = [(0.0, free)]

    def _end_track(self) -> None:
        track, self._track, self._track_from = self._track, [], None
        scale = distance_scale(track)
        if scale is None:
            return
        span = track[-1][0] - track[0][0]
        self._scales.append((scale, span))
        k, w = np.array(self._scales).T
        self.distance_gain = float(
            np.clip(np.average(k, weights=w), 1.0 - MAX_GAIN_ERROR, 1.0 + MAX_GAIN_ERROR)
        )
        if self.on_distance is not None:
            self.on_distance(scale, self.distance_gain)

    def observe(self) -> Observation:
        obs = self.inner.observe()
        # The free floor ahead for the distance track: measured once, outside the lock
        # (the tree's tick reads the pose meanwhile).
        free = free_distance(obs, 0.0) if obs.depth is not None else None
        with self._lock:
            self._update(self.inner.pose())
            if free is not None:
                self._extend_track(obs.pose, free)
            corr_T_raw = None if self._corr == self._raw else self._corr_T_raw()
        if corr_T_raw is not None:
            q = obs.pose
            x, y, yaw = se2_compose(corr_T_raw, (q.x, q.y, q.yaw))
            obs = replace(obs, pose=Pose2D(x, y, wrap_angle(yaw)))
        if self.on_frame is not None:
            self.on_frame(obs)
        return obs
