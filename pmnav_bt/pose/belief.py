"""A belief over where on the corridors the robot is, kept across localization attempts.

Each hypothesis is a map pose for the robot at a reference odometry pose (the first
glimpse): a lattice point of a corridor centre line, facing along the corridor either
way (corrected by the angle of the corridor axis seen in depth, when it was measured).
Every glimpse (a panorama: the signs read there and where each was seen, in odometry)
reweights all hypotheses: a sign read where the map puts it under the hypothesis
supports it, one read elsewhere or one the map says cannot be read there counts
against it, and a sign the map says is readable but was not read is a likely miss.

``fix`` gives ``map_T_odom`` once one hypothesis cluster dominates; ``lead`` says which
way to drive along the corridor, in odometry, towards the nearest stretch where the map
says at least two signs are readable.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pmnav_bt.geometry import fit_se2, se2_apply, se2_inverse, wrap_angle
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.pose.visibility import Visibility, entity_xy
from pmnav_bt.seams import Entity, Pose2D

P_MISS = 0.25  # a sign the map says is readable is not read
P_SPURIOUS = 0.005  # a sign is read that the map says cannot be read from there
SIGHT_SIGMA_M = 0.8  # spread of a sign's seen position around the map's
DRIFT_PER_M = 0.05  # the sight spread grows with odometry distance from the reference
FIX_MASS = 0.85  # a cluster holding this much weight is a fix
MISREAD = math.log(P_MISS * P_SPURIOUS)  # readable here, but read far from its place
P_THROUGH_WALL = 0.02  # the robot is where the hypothesis puts it inside a wall
OFF_CORRIDOR_M = 1.0  # beyond a corridor's half-width by this much: inside a wall
BLOCK_PROBE_M = 1.0  # a blocked drive: the hypothesis's corridor must end within this
CLUSTER_M = 4.0  # hypotheses this close (and facing alike) form one cluster


@dataclass(frozen=True)
class Glimpse:
    """What one panorama saw: its odometry pose and each sign read, with where (odom)."""

    odom: Pose2D
    seen: dict[Entity, tuple[float, float]]
    blocked: float | None = None  # odometry heading of a drive that was just blocked here


@dataclass(frozen=True)
class Lead:
    """Which way to go: an odometry heading, how far, and the share of belief behind it."""

    heading: float
    distance: float
    support: float


@dataclass
class CorridorBelief:
    """Hypotheses over the corridor positions, reweighted by every glimpse."""

    pm: PrioriMap
    glimpses: list[Glimpse] = field(default_factory=list)
    ref: Pose2D | None = None
    axis_offset: float = 0.0  # robot yaw minus corridor axis at the reference (rad)

    def __post_init__(self) -> None:
        self.vis = Visibility.of(self.pm)
        self._build()

    def _build(self) -> None:
        pts = self.vis.lattice_points
        segs = self.pm.segments
        lat, yaw = [], []
        for p in pts:
            h = segs[p.segment - 1].heading
            for k in (0.0, math.pi):
                lat.append(p.index)
                yaw.append(wrap_angle(h + k + self.axis_offset))
        self.lattice = np.array(lat, dtype=int)
        self.yaw = np.array(yaw, dtype=float)
        self.xy = self.vis.lattice_xy[self.lattice]
        self.logw = np.zeros(len(self.lattice))
        for g in self.glimpses:
            self._weigh(g)

    # -- updates --------------------------------------------------------------------------

    def set_axis(self, axis_odom: float) -> None:
        """The corridor axis measured in odometry (mod pi) at the reference pose."""
        ref = self.ref
        if ref is None:
            return
        off = wrap_angle(2.0 * (ref.yaw - axis_odom)) / 2.0  # in (-pi/2, pi/2]
        if abs(off - self.axis_offset) > 1e-3:
            self.axis_offset = off
            self._build()

    def observe(self, glimpse: Glimpse) -> None:
        """Add a panorama and reweight every hypothesis with it."""
        if self.ref is None:
            self.ref = glimpse.odom
        self.glimpses.append(glimpse)
        self._weigh(glimpse)

    def _map_T_odom(self) -> np.ndarray:
        """(N, 3) map_T_odom of each hypothesis: its pose composed with the reference's inverse."""
        rx, ry, rth = se2_inverse((self.ref.x, self.ref.y, self.ref.yaw))
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        return np.stack(
            [
                self.xy[:, 0] + c * rx - s * ry,
                self.xy[:, 1] + s * rx + c * ry,
                np.angle(np.exp(1j * (self.yaw + rth))),
            ],
            1,
        )

    def _weigh(self, g: Glimpse) -> None:
        tfs = self._map_T_odom()
        ref = self.ref
        travelled = math.hypot(g.odom.x - ref.x, g.odom.y - ref.y)
        sigma = math.hypot(SIGHT_SIGMA_M, DRIFT_PER_M * travelled)
        here = _apply_many(tfs, (g.odom.x, g.odom.y))
        near, off = self.vis.nearest_many(here)
        half = np.array(
            [self.pm.segments[p.segment - 1].width / 2.0 for p in self.vis.lattice_points]
        )
        # A hypothesis that puts the robot inside a wall is unlikely.
        self.logw += np.where(off > half[near] + OFF_CORRIDOR_M, math.log(P_THROUGH_WALL), 0.0)
        if g.blocked is not None:  # the corridor must end (or turn) just ahead
            d = BLOCK_PROBE_M
            probe = _apply_many(
                tfs, (g.odom.x + d * math.cos(g.blocked), g.odom.y + d * math.sin(g.blocked))
            )
            pn, poff = self.vis.nearest_many(probe)
            self.logw += np.where(poff <= half[pn], math.log(P_THROUGH_WALL), 0.0)
        # What the map says is readable at each hypothesis's position for this glimpse.
        readable = [self.vis.lattice_points[j].readable for j in near]
        seen = g.seen.keys()
        map_xy = {e: np.array(entity_xy(self.pm, e)) for e in seen}
        seen_map = {e: _apply_many(tfs, xy) for e, xy in g.seen.items()}  # (N, 2) per sign
        d_seen = {e: np.linalg.norm(seen_map[e] - map_xy[e], axis=1) for e in seen}
        for i, r in enumerate(readable):
            lw = len(r - seen) * math.log(P_MISS)
            for e in seen:
                if e in r:
                    lw += max(-0.5 * (d_seen[e][i] / sigma) ** 2, MISREAD)
                else:
                    lw += math.log(P_SPURIOUS)
            self.logw[i] += lw

    # -- questions ------------------------------------------------------------------------

    def weights(self) -> np.ndarray:
        w = np.exp(self.logw - self.logw.max())
        return w / w.sum()

    def best_cluster(self) -> tuple[np.ndarray, float]:
        """Indices of the hypotheses around the best one and the weight they hold."""
        w = self.weights()
        i = int(np.argmax(w))
        close = (np.linalg.norm(self.xy - self.xy[i], axis=1) <= CLUSTER_M) & (
            np.abs(np.angle(np.exp(1j * (self.yaw - self.yaw[i])))) < 0.5
        )
        return np.nonzero(close)[0], float(w[close].sum())

    def fix(self) -> tuple[tuple[float, float, float], float] | None:
        """(map_T_odom, spread in metres) once one cluster holds FIX_MASS of the belief and
        a sign was read; refined on the signs read (all glimpses) under that hypothesis."""
        if not self.glimpses or not any(g.seen for g in self.glimpses):
            return None
        idx, mass = self.best_cluster()
        if mass < FIX_MASS:
            return None
        w = self.weights()[idx]
        i = idx[int(np.argmax(w))]
        tf = tuple(self._map_T_odom()[i])
        src, dst = [], []
        for g in self.glimpses:
            for e, oxy in g.seen.items():
                m = np.array(entity_xy(self.pm, e))
                if np.linalg.norm(se2_apply(tf, oxy) - m) <= 3.0 * SIGHT_SIGMA_M:
                    src.append(oxy)
                    dst.append(m)
        if not src:
            return None
        if len({tuple(d) for d in dst}) >= 2 and np.ptp(np.array(dst), axis=0).max() >= 2.0:
            tf, res = fit_se2(np.array(src), np.array(dst))
        else:  # one sign: the heading is the hypothesis's, the position from the sign
            shift = np.mean([d - se2_apply(tf, s) for s, d in zip(src, dst, strict=True)], axis=0)
            tf = (tf[0] + float(shift[0]), tf[1] + float(shift[1]), tf[2])
            res = 0.0
        spread = float(np.sqrt((w * ((self.xy[idx] - self.xy[i]) ** 2).sum(1)).sum() / w.sum()))
        return (float(tf[0]), float(tf[1]), float(tf[2])), math.hypot(spread, res)

    def lead(self, odom: Pose2D, max_distance: float = 8.0) -> Lead | None:
        """Where to drive from ``odom``: towards the nearest stretch of corridor where the
        map says two signs are readable, voted over the hypotheses by weight."""
        dist, nxt = self.vis.towards_signs
        if not dist:
            return None
        w = self.weights()
        tfs = self._map_T_odom()
        here = _apply_many(tfs, (odom.x, odom.y))
        votes: dict[int, list[tuple[float, float]]] = {}
        live = np.nonzero(w > 1e-4 * w.max())[0]
        near, _ = self.vis.nearest_many(here[live])
        for i, j in zip(live, near, strict=True):
            d, k = dist.get(j, math.inf), nxt.get(j, j)
            if not math.isfinite(d):
                continue
            if k == j:  # already where signs are readable: turn the way the robot faces
                h_odom = odom.yaw
            else:
                a, b = self.vis.lattice_xy[j], self.vis.lattice_xy[k]
                h_map = math.atan2(b[1] - a[1], b[0] - a[0])
                h_odom = wrap_angle(h_map - tfs[i][2])
            key = int(round(h_odom / (math.pi / 4))) % 8
            votes.setdefault(key, []).append((float(w[i]), d))
        if not votes:
            return None
        # The way where the most belief finds signs soonest.
        key, vs = max(votes.items(), key=lambda kv: sum(v / max(d, 1.0) for v, d in kv[1]))
        ws = np.array([v for v, _ in vs])
        ds = np.array([d for _, d in vs])
        go = float(np.clip(np.average(ds, weights=ws) + 1.0, 1.0, max_distance))
        return Lead(wrap_angle(self._snap_heading(key * math.pi / 4)), go, float(ws.sum()))

    def _snap_heading(self, h: float) -> float:
        """Round a voted heading onto the corridor axis (or its normal) seen at the reference."""
        if self.ref is None:
            return h
        axis = self.ref.yaw - self.axis_offset
        k = round(wrap_angle(h - axis) / (math.pi / 2))
        return axis + k * math.pi / 2


def _apply_many(tfs: np.ndarray, p) -> np.ndarray:
    c, s = np.cos(tfs[:, 2]), np.sin(tfs[:, 2])
    return np.stack([tfs[:, 0] + c * p[0] - s * p[1], tfs[:, 1] + s * p[0] + c * p[1]], 1)
