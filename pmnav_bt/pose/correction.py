"""Pose correction from verified landmarks: position, heading, odometry scale, uncertainty.

``PoseTracker`` holds ``map_T_odom`` and what it rests on. Each verified landmark
(where it was seen in odometry, where the map puts it) corrects the position; two or
more far enough apart re-fit the heading too, so a heading error from the odometry's
rotation bias is removed after the second landmark. The odometry's scale bias is the
ratio of map to odometry distances between landmarks verified on one straight leg.

The position uncertainty grows with the distance driven since the last correction
(``drift`` per metre, plus the heading error's lever arm) and sets how far from the map's
position a sighting may be and still be the landmark (``verify_tolerance``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pmnav_bt.geometry import fit_se2, se2_apply, wrap_angle

DRIFT_PER_M = 0.05  # odometry position error per metre driven (a 5 % drift budget)
HEADING_SIGMA0 = math.radians(3.0)  # heading uncertainty right after a fix
TOLERANCE_MIN_M = 2.0  # never verify tighter than this (rooms are 3 m apart)
TOLERANCE_MAX_M = 8.0  # never looser
TOLERANCE_SIGMAS = 3.0
REFIT_SPREAD_M = 3.0  # landmarks this far apart fix the heading
REFIT_RESIDUAL_M = 0.6
MAX_HEADING_STEP = math.radians(20.0)  # a re-fit that turns more than this is a mismatch
KEEP = 4  # verified sightings kept for re-fitting


@dataclass(frozen=True)
class Verified:
    """A verified landmark: where it was seen (odometry) and where the map puts it."""

    odom_xy: tuple[float, float]
    map_xy: tuple[float, float]
    odometer: float  # odometry distance driven when it was seen (m)


def rotated(
    map_T_odom: tuple[float, float, float], dyaw: float, about_odom: tuple[float, float]
) -> tuple[float, float, float]:
    """``map_T_odom`` turned by ``dyaw`` about the map point of ``about_odom`` (the robot),
    that point keeping its map position."""
    before = se2_apply(map_T_odom, about_odom)
    yaw = wrap_angle(map_T_odom[2] + dyaw)
    c, s = math.cos(yaw), math.sin(yaw)
    x = before[0] - (c * about_odom[0] - s * about_odom[1])
    y = before[1] - (s * about_odom[0] + c * about_odom[1])
    return (float(x), float(y), yaw)


@dataclass
class PoseTracker:
    """``map_T_odom`` and its uncertainty, corrected by verified landmarks."""

    map_T_odom: tuple[float, float, float]
    sigma0: float = 0.5  # position uncertainty at the last correction (m)
    odometer0: float = 0.0  # odometry distance at the last correction (m)
    drift: float = DRIFT_PER_M
    recent: list[Verified] = field(default_factory=list)
    scale: float = 1.0  # map metres per odometry metre, once estimated

    def __repr__(self) -> str:  # short, for tree logs
        x, y, yaw = self.map_T_odom
        return (
            f"PoseTracker(({x:.2f}, {y:.2f}, {math.degrees(yaw):.1f} deg), sigma0 "
            f"{self.sigma0:.2f} m at {self.odometer0:.1f} m, scale {self.scale:.3f})"
        )

    def sigma(self, odometer: float) -> float:
        """Position uncertainty (m) after driving to ``odometer``."""
        d = max(0.0, odometer - self.odometer0)
        return math.sqrt(self.sigma0**2 + (self.drift * d) ** 2 + (HEADING_SIGMA0 * d) ** 2)

    def verify_tolerance(self, odometer: float) -> float:
        """How far (m) a sighting may be from the map's position and still be the landmark."""
        t = TOLERANCE_SIGMAS * self.sigma(odometer)
        return float(min(TOLERANCE_MAX_M, max(TOLERANCE_MIN_M, t)))

    def error(self, odom_xy, map_xy) -> float:
        """How far the landmark seen at ``odom_xy`` is from the map's ``map_xy`` (m)."""
        return float(np.linalg.norm(np.asarray(map_xy) - se2_apply(self.map_T_odom, odom_xy)))

    def correct(self, v: Verified, gain: float = 0.9) -> str:
        """Correct with a verified landmark; returns how (for logs)."""
        recent = [r for r in self.recent if r.map_xy != v.map_xy] + [v]
        self.recent = recent[-KEEP:]
        tf = self.map_T_odom
        how = "shifted"
        refit = self._refit()
        if refit is not None:
            tf, how = refit, f"re-fit on {len(self.recent)} landmarks (heading), shifted"
        err = np.asarray(v.map_xy) - se2_apply(tf, v.odom_xy)
        x, y, yaw = tf
        self.map_T_odom = (x + gain * float(err[0]), y + gain * float(err[1]), yaw)
        self.sigma0 = max(0.3, (1.0 - gain) * float(np.hypot(*err)) + 0.3)
        self.odometer0 = v.odometer
        self._estimate_scale()
        return how

    def reset(self, map_T_odom: tuple[float, float, float], residual: float, odometer: float):
        """A correction made elsewhere: the new transform, what it left unexplained (m)."""
        self.map_T_odom = map_T_odom
        self.sigma0 = max(0.3, residual + 0.3)
        self.odometer0 = odometer

    def rotate(self, dyaw: float, about_odom: tuple[float, float]) -> None:
        """Turn ``map_T_odom`` by ``dyaw`` about the map point of ``about_odom`` (the robot),
        keeping that point's map position (a heading correction from the walls)."""
        self.map_T_odom = rotated(self.map_T_odom, dyaw, about_odom)

    def _refit(self) -> tuple[float, float, float] | None:
        if len(self.recent) < 2:
            return None
        dst = np.array([r.map_xy for r in self.recent])
        if float(np.linalg.norm(dst.max(0) - dst.min(0))) < REFIT_SPREAD_M:
            return None
        src = np.array([r.odom_xy for r in self.recent])
        tf, res = fit_se2(src, dst)
        if res > REFIT_RESIDUAL_M or abs(wrap_angle(tf[2] - self.map_T_odom[2])) > MAX_HEADING_STEP:
            return None
        return tf

    def _estimate_scale(self) -> None:
        """Map over odometry distance between the farthest pair of recent landmarks."""
        if len(self.recent) < 2:
            return
        best = None
        for i, p in enumerate(self.recent):
            for q in self.recent[i + 1 :]:
                dm = math.dist(p.map_xy, q.map_xy)
                do = math.dist(p.odom_xy, q.odom_xy)
                if dm >= 2.0 * REFIT_SPREAD_M and do > 0 and (best is None or dm > best[0]):
                    best = (dm, do)
        if best is not None:
            self.scale = best[0] / best[1]
