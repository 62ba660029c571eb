"""The corridor belief's hypotheses, and how the robot's motion is carried to them.

A hypothesis is a map pose for the robot at the reference odometry pose (the first
look round's, moved onto the centre line the walls showed there): a lattice point of a
corridor centre line (``Visibility.lattice_points``), facing along the corridor either
way or across it. The walls seen in depth give the robot's angle to an axis, but near a
junction the strongest wall may run across the corridor, so all four are kept.

The hypotheses never move. Each is one rigid transform ``map_T_odom`` (its pose composed
with the reference's inverse), and the robot's motion reaches them through the odometry.
The odometry's heading drifts, though; the walls measured at each look round (and along a
drive) say by how much, so the belief works in odometry *straightened* by the walls
(``Straightened``): the motion update is carrying that frame on from one odometry pose
to the next.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pmnav_bt.geometry import se2_inverse, wrap_angle
from pmnav_bt.map.priori_map import Segment
from pmnav_bt.pose.visibility import Visibility
from pmnav_bt.seams import Pose2D

CLUSTER_M = 4.0  # hypotheses this close (and facing alike) form one cluster
FIX_MASS = 0.85  # a cluster holding this much weight is a fix
MAX_DRIFT_STEP = math.radians(20.0)  # a larger change of the wall axis is another corridor


@dataclass(frozen=True)
class Hypotheses:
    """Poses at the reference, one per lattice point and way along or across its corridor:
    ``lattice`` (the lattice point of each), ``xy`` (map) and ``yaw`` (map)."""

    lattice: np.ndarray
    xy: np.ndarray
    yaw: np.ndarray

    @classmethod
    def on_lattice(
        cls, vis: Visibility, segments: list[Segment], axis_offset: float
    ) -> Hypotheses:
        """Four headings at each lattice point: its corridor's heading, turned by 0, 90,
        180 and 270 degrees, plus ``axis_offset`` (the robot's yaw off the walls' axis at
        the reference)."""
        lat, yaw = [], []
        for p in vis.lattice_points:
            h = segments[p.segment - 1].heading
            for k in (0.0, math.pi / 2, math.pi, -math.pi / 2):
                lat.append(p.index)
                yaw.append(wrap_angle(h + k + axis_offset))
        lattice = np.array(lat, dtype=int)
        return cls(lattice, vis.lattice_xy[lattice], np.array(yaw, dtype=float))

    def __len__(self) -> int:
        return len(self.lattice)

    def map_T_odom(self, ref: Pose2D) -> np.ndarray:
        """(N, 3) map_T_odom of each hypothesis: its pose composed with the inverse of the
        reference ``ref`` (straightened odometry)."""
        rx, ry, rth = se2_inverse((ref.x, ref.y, ref.yaw))
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        return np.stack(
            [
                self.xy[:, 0] + c * rx - s * ry,
                self.xy[:, 1] + s * rx + c * ry,
                np.angle(np.exp(1j * (self.yaw + rth))),
            ],
            1,
        )

    def cluster_around(self, w: np.ndarray, i: int) -> tuple[np.ndarray, float]:
        """Indices of the hypotheses within ``CLUSTER_M`` of hypothesis ``i`` and facing
        alike, and the weight (of ``w``) they hold."""
        close = (np.linalg.norm(self.xy - self.xy[i], axis=1) <= CLUSTER_M) & (
            np.abs(np.angle(np.exp(1j * (self.yaw - self.yaw[i])))) < 0.5
        )
        return np.nonzero(close)[0], float(w[close].sum())

    def modes(self, idx: np.ndarray) -> list[list[int]]:
        """Hypotheses ``idx`` (best first) grouped greedily into clusters."""
        modes: list[list[int]] = []
        for i in idx:
            for m in modes:
                j = m[0]
                if (
                    np.linalg.norm(self.xy[i] - self.xy[j]) <= CLUSTER_M
                    and abs(wrap_angle(self.yaw[i] - self.yaw[j])) < 0.5
                ):
                    m.append(int(i))
                    break
            else:
                modes.append([int(i)])
        return modes


def apply_many(tfs: np.ndarray, p) -> np.ndarray:
    """(N, 2): the odometry point ``p`` in the map under each of the (N, 3) ``tfs``."""
    c, s = np.cos(tfs[:, 2]), np.sin(tfs[:, 2])
    return np.stack([tfs[:, 0] + c * p[0] - s * p[1], tfs[:, 1] + s * p[0] + c * p[1]], 1)


@dataclass(frozen=True)
class Straightened:
    """The odometry straightened by the walls: the motion update of the hypotheses.

    ``ref_axis`` is the walls' axis (odometry) at the reference; ``drift`` the odometry's
    heading drift since then, from the walls' axis measured since; ``raw`` the last
    odometry pose carried to and ``corr`` where it is in the straightened frame. Each leg
    between two updates is turned by the mean drift over it."""

    ref_axis: float
    drift: float
    raw: Pose2D
    corr: tuple[float, float]

    @classmethod
    def start(cls, odom: Pose2D, axis_odom: float | None) -> Straightened:
        """At the reference: no drift yet, the straightened frame is the odometry's."""
        ref_axis = axis_odom if axis_odom is not None else odom.yaw
        return cls(ref_axis, 0.0, odom, (odom.x, odom.y))

    def advanced(self, odom: Pose2D, axis_odom: float | None) -> tuple[Straightened, bool]:
        """Carried on to ``odom``: the walls' axis measured there (odometry, mod pi/2)
        against the reference's is the heading drift now, unless it jumped more than
        ``MAX_DRIFT_STEP`` since the last (another corridor's walls), and the leg since the
        last update turned by the mean drift. And whether the axis was taken."""
        drift, took = self.drift, False
        if axis_odom is not None:  # mod pi/2, the value nearest the drift so far
            step = wrap_angle(4.0 * (axis_odom - self.ref_axis - drift)) / 4.0
            if abs(step) < MAX_DRIFT_STEP:
                drift, took = drift + step, True
        mean = (self.drift + drift) / 2.0
        c, s = math.cos(-mean), math.sin(-mean)
        dx, dy = odom.x - self.raw.x, odom.y - self.raw.y
        corr = (self.corr[0] + c * dx - s * dy, self.corr[1] + s * dx + c * dy)
        return Straightened(self.ref_axis, drift, odom, corr), took

    def tf(self) -> tuple[float, float, float]:
        """straightened_T_odom at the last pose carried to."""
        c, s = math.cos(-self.drift), math.sin(-self.drift)
        rx, ry = self.raw.x, self.raw.y
        return (self.corr[0] - (c * rx - s * ry), self.corr[1] - (s * rx + c * ry), -self.drift)

    def scaled(self, moved) -> Straightened:
        """With the straightened position moved by ``moved`` (a rescale of distances)."""
        return Straightened(self.ref_axis, self.drift, self.raw, moved(self.corr))
