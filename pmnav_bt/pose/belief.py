"""A belief over where on the corridors the robot is, kept across localization attempts.

Each hypothesis is a map pose for the robot at a reference odometry pose (the first
glimpse's, moved onto the centre line the walls showed there): a lattice point of a
corridor centre line, facing along the corridor either way or across it (the walls seen
in depth give the robot's angle to an axis, but near a junction the strongest wall may
run across the corridor).
Every glimpse (a panorama: the signs read there and where each was seen, in odometry)
reweights all hypotheses: a sign read where the map puts it under the hypothesis
supports it, one read elsewhere or one the map says cannot be read there counts
against it, and a sign the map says is readable but was not read is a likely miss.

``fix`` gives ``map_T_odom`` once one hypothesis cluster dominates; ``lead`` says which
way to drive along the corridor, in odometry, towards the nearest stretch where the map
says at least two signs are readable, or, when the belief is split between a few
clusters (a symmetric corridor's mirror images), to the nearest place where they predict
different signs.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import networkx as nx
import numpy as np
import shapely

from pmnav_bt.geometry import fit_se2, se2_apply, se2_compose, se2_inverse, wrap_angle
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.pose.lookahead import expected_trip, telling
from pmnav_bt.pose.visibility import Visibility, entity_xy
from pmnav_bt.seams import Entity, EntityKind, Pose2D

P_MISS = 0.25  # a sign the map says is readable is not read
P_SPURIOUS = 0.005  # a sign is read that the map says cannot be read from there
P_OCCLUDED = 0.1  # ... from there, but it is within reading range (round a corner)
SIGHT_SIGMA_M = 0.8  # spread of a sign's seen position around the map's
DRIFT_PER_M = 0.05  # the sight spread grows with odometry distance from the reference
FIX_MASS = 0.85  # a cluster holding this much weight is a fix
MAX_LEVEL = math.radians(15.0)  # a two-sign fit is turned onto the walls' axis up to this
SIGN_AGREE_M = 1.0  # signs fixing the position together must agree on it this well
# How far (m, one sigma) a sign's seen place may be from the map's point: a door is found
# where the map puts it (the grounders return the door, not its plate); an elevator's or
# a stair's plate hangs beside it, 0.8-2.2 m along the wall in the simulator.
PLACE_SIGMA_M = {EntityKind.ROOM: 0.2, EntityKind.LANDMARK: 1.0}
FIX_SIGMA_M = 0.5  # a fix from the belief and its signs must know the place this well
HYPOTHESIS_SIGMA_M = 0.5  # a hypothesis is a lattice point: no surer of the place than a step
MISREAD = math.log(P_MISS * P_SPURIOUS)  # readable here, but read far from its place
P_THROUGH_WALL = 0.02  # the robot is where the hypothesis puts it inside a wall
OFF_CORRIDOR_M = 1.0  # beyond a corridor's half-width by this much: inside a wall
BLOCK_PROBE_M = 1.5  # a blocked drive: the hypothesis's corridor must end within this
BLOCKED_NEAR_M = 1.0  # ... and from this close to where it was blocked, that way is shut
WALL_COST_M = 100.0  # a way with no signs ever ahead counts as this far
KEEP_WAY_MASS = 0.3  # keep exploring the same way while this much belief says it goes on
CROSS_WAY_MASS = 0.7  # turn into a side corridor only when this much belief says it is there
MAX_DRIFT_STEP = math.radians(20.0)  # a larger change of the wall axis is another corridor
MIN_BLIND_GLIMPSES = 4  # glimpses before a fix from the corridors' shape alone
BLIND_SPREAD_M = 0.75  # ... and how tight the belief must be for it
LOOK_SPACING_M = 6.0  # look round at least this far beyond an earlier look in the same way
NEAR_WALL_M = 2.0  # depth: a wall closer than this ahead of a view ...
MAX_RAY_M = 8.0  # free floor seen in depth is checked along the view up to this far
RAY_SLACK_M = 0.4  # ... short of where it ends, this far outside the corridors (and a
# probe beyond a near wall must be this far inside one to count against a hypothesis)
P_DEPTH = 0.1  # a hypothesis that disagrees with one such depth reading
# ... one reading ahead while driving: weak alone (after a long drive the odometry's drift
# puts even the true hypothesis a metre off), telling when many agree
P_DRIVE_RAY = 0.5
JUNCTION_REACH_M = 1.0  # side corridors of a junction this close are the robot's
CLUSTER_M = 4.0  # hypotheses this close (and facing alike) form one cluster
DIFFUSE_MASS = 0.3  # below this (best cluster), the belief is diffuse: look close by first
NEAR_JUNCTION_M = 6.0  # ... at a junction or corridor end this close (its shape tells much)
FIRST_JUNCTION_QUANTILE = 0.2  # diffuse, first drive: stop where this share puts a junction
LEAD_QUANTILE = 0.25  # drive to where this share of the belief has signs in reach
SWITCH_COST_RATIO = 2.0  # turn back when the other way is expected this much shorter
TELLING_MIN_WEIGHT = 0.05  # hypotheses this likely (of the best) must be told apart ...
TELLING_MAX_MODES = 4  # ... when they form at most this many clusters ...
TELLING_COVER = 0.8  # ... holding this much of the belief between them
TELLING_REACH_M = 60.0  # look for a telling place this far along the corridors
LEG_OFF_LINE_M = 0.25  # ... and this much more: the robot is beside a path's run
TELLING_LOOKED_M = 1.5  # a place this close to an earlier glimpse was looked from
# A look round shows the free floor along every bearing (to MAX_RAY_M): two places whose
# map floor differs by less than this along each of these bearings look alike.
LOOK_ALIKE_M = 1.0
LOOK_BEARINGS = np.radians(np.arange(0.0, 360.0, 15.0))
RESCALE_MIN = 0.002  # a change of the odometry's distance gain smaller than this waits
# Doors seen along the walls (``perception.door_sightings``): found 95 % of the time 4-13 m
# off in the simulator's views, never where none is (``benchmarks/bench_door_sightings.py``).
DOOR_SEEN_M = (2.0, 12.0)  # a map door this far off, on the robot's corridor (the robot
DOOR_WALL_NEAR_M = 2.5  # this near its wall line: not round a corner), is in view ...
DOOR_FOV_MARGIN = math.radians(4.0)  # ... well inside a view that looked for doors
HALF_FOV = math.radians(30.0)  # the camera's 60 deg (a wider one only sees more)
DOOR_MATCH_M = 1.0  # a door seen this close to a map door (or landmark) is that one
P_DOOR_MISS = 0.2  # a map door in view is not seen (a look round)
P_DOOR_SPURIOUS = 0.1  # a door is seen where the map has none
# ... while driving, one view ahead every metre: the same door again and again
P_DRIVE_DOOR_MISS, P_DRIVE_DOOR_SPURIOUS = 0.6, 0.4


@dataclass(frozen=True)
class Glimpse:
    """What one panorama saw: its odometry pose and each sign read, with where (odom)."""

    odom: Pose2D
    seen: dict[Entity, tuple[float, float]]
    blocked: float | None = None  # odometry heading of a drive that was just blocked here
    # Free floor (m) seen in depth straight ahead of each view: (odometry yaw, distance).
    free: tuple[tuple[float, float], ...] = ()
    # Signs read whose place is not known (cut by the image border): in sight, not missed.
    named: frozenset[Entity] = frozenset()
    # The way (odometry, m) from the robot to the corridor's centre line, seen in depth.
    to_centre: tuple[float, float] | None = None
    # Doors seen along the walls (odometry xy of each), and the odometry yaws of the views
    # that looked for them (none: no door evidence).
    doors: tuple[tuple[float, float], ...] = ()
    door_views: tuple[float, ...] = ()


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
    # A prior from an earlier estimate: map_T_odom and its position uncertainty (m).
    prior: tuple[tuple[float, float, float], float] | None = None
    pending_blocked: float | None = None  # a drive was blocked heading this way (odometry)
    # The free floor seen straight ahead while driving between glimpses (straightened
    # odometry): depth only, no look round, so no sign is missed in them.
    rays: list[Glimpse] = field(default_factory=list)
    _last_way: int | None = None  # the way (0-3 from the axis) the last lead chose
    _drift: float = 0.0  # odometry heading drift since the reference, from the walls
    read_range: float | None = None  # m, signs are read to (None: visibility.READ_RANGE_M)
    # recall(entity, distance m, angle rad off the plate's normal): how likely that sign is
    # read from there (None: 1 - P_MISS within read_range); a sign the map says is in sight
    # but not read costs 1 - recall.
    recall: Callable[[Entity, float, float], float] | None = None
    # m, signs are read reliably to: where to go to read them (None: read_range). A sign
    # 5 m off that OCR reads one time in seven is no place to drive to.
    lead_range: float | None = None
    # Where the robot is going (map; None: nowhere yet): of two ways towards signs, the
    # one whose whole trip, finding the place and then going on, is shorter.
    target: tuple[float, float] | None = None
    # The odometry's distance gain (``CalibratedBase``) the positions held were driven
    # under: when it changes, they are scaled about the reference (``rescale``).
    gain: float = 1.0

    def __post_init__(self) -> None:
        self.vis = Visibility.of(self.pm, self.read_range)
        # The same lattice, with the signs read reliably from each point (where to go).
        self.goal = Visibility.of(
            self.pm, self.read_range if self.lead_range is None else self.lead_range
        )
        self._plate = {  # each sign's plate: where the map puts it and its wall's normal
            e: (xy, n)
            for e, xy, n in zip(
                self.vis.entities, self.vis.sign_xy, self.vis.sign_normal, strict=True
            )
        }
        self._floor = shapely.buffer(self.vis.corridors, RAY_SLACK_M)  # a little tolerance
        self._half_width = np.array(  # per lattice point: its corridor's half-width
            [self.pm.segments[p.segment - 1].width / 2.0 for p in self.vis.lattice_points]
        )
        shapely.prepare(self._floor)
        self._doors = _MapDoors.of(self.vis)
        self._build()

    def __repr__(self) -> str:  # short, for tree logs
        if self.ref is None:
            return "CorridorBelief(no glimpse)"
        _, mass = self.best_cluster()
        return f"CorridorBelief({len(self.glimpses)} glimpses, best {mass:.0%})"

    def fork(self) -> CorridorBelief:
        """A copy to add to away from the tree (in the worker): it shares the map and the
        lattice, and holds its own glimpses, drive rays and weights."""
        other = copy.copy(self)
        other.glimpses, other.rays, other.logw = (
            list(self.glimpses),
            list(self.rays),
            self.logw.copy(),
        )
        return other

    def _build(self) -> None:
        pts = self.vis.lattice_points
        segs = self.pm.segments
        lat, yaw = [], []
        for p in pts:
            h = segs[p.segment - 1].heading
            for k in (0.0, math.pi / 2, math.pi, -math.pi / 2):
                lat.append(p.index)
                yaw.append(wrap_angle(h + k + self.axis_offset))
        self.lattice = np.array(lat, dtype=int)
        self.yaw = np.array(yaw, dtype=float)
        self.xy = self.vis.lattice_xy[self.lattice]
        self.logw = np.zeros(len(self.lattice))
        if self.ref is None:
            return
        if self.prior is not None:
            self._weigh_prior(*self.prior)
        for g in self.glimpses:
            self._weigh(g)
        tfs = self._map_T_odom()
        for r in self.rays:
            self._weigh_ray(r, tfs)

    def _miss_log(self, entity: Entity, xy: np.ndarray) -> float:
        """The log-probability that ``entity``'s sign, in sight, is not read from ``xy``
        (map): by the reader's recall from that distance and angle off the plate's normal.
        From where the hypothesis puts the robot, not its lattice point on the centre
        line: a plate on the wall the robot drives beside is seen along the wall (no
        evidence when not read), the same plate from the centre line at 50 degrees."""
        plate, normal = self._plate[entity]
        v = xy - plate
        d = float(math.hypot(v[0], v[1]))
        off = math.acos(min(1.0, max(-1.0, float(v @ normal) / max(d, 1e-9))))
        return math.log(max(P_MISS, 1.0 - self.recall(entity, d, off)))

    def _weigh_prior(self, map_T_odom: tuple[float, float, float], sigma: float) -> None:
        """Hypotheses near where the earlier estimate puts the reference are likelier."""
        ref = self.ref
        est = se2_apply(map_T_odom, (ref.x, ref.y))
        yaw = wrap_angle(map_T_odom[2] + ref.yaw)
        d = np.linalg.norm(self.xy - est, axis=1)
        turn = np.abs(np.angle(np.exp(1j * (self.yaw - yaw))))
        s = max(sigma, 0.5)
        self.logw += np.maximum(-0.5 * (d / s) ** 2, math.log(P_SPURIOUS))
        self.logw += np.where(turn > math.radians(60.0), math.log(P_MISS), 0.0)

    # -- updates --------------------------------------------------------------------------

    def observe(self, glimpse: Glimpse, axis_odom: float | None = None) -> None:
        """Add a panorama and reweight every hypothesis with it.

        ``axis_odom``: the corridor axis measured in odometry (mod pi) there. At the first
        glimpse (the reference) it sets the hypotheses' headings; later, how far it has
        turned (mod pi/2) is the odometry's heading drift, taken out of the glimpse (the
        belief works in odometry straightened by the walls)."""
        if self.pending_blocked is not None and glimpse.blocked is None:
            glimpse = replace(glimpse, blocked=self.pending_blocked)
        self.pending_blocked = None
        if self.ref is None:
            # The hypotheses put the reference on a centre line: where the walls say the
            # centre line is, not where the robot stands (beside a wall, maybe).
            dx, dy = glimpse.to_centre or (0.0, 0.0)
            self.ref = replace(glimpse.odom, x=glimpse.odom.x + dx, y=glimpse.odom.y + dy)
            self._ref_axis = axis_odom if axis_odom is not None else glimpse.odom.yaw
            if axis_odom is not None:
                self.axis_offset = wrap_angle(2.0 * (self.ref.yaw - axis_odom)) / 2.0
            self._drift, self._raw, self._corr = 0.0, glimpse.odom, (glimpse.odom.x, glimpse.odom.y)
            self._last_axis = axis_odom  # the walls' axis at the last glimpse (straightened)
            self.glimpses.append(glimpse)
            self._build()
            return
        took = self._advance(glimpse.odom, axis_odom)
        drift, corr, raw = self._drift, self._corr, glimpse.odom
        self._last_axis = wrap_angle(axis_odom - drift) if took else None
        g = Glimpse(
            Pose2D(corr[0], corr[1], wrap_angle(raw.yaw - drift)),
            {e: tuple(self._straighten(xy)) for e, xy in glimpse.seen.items()},
            None if glimpse.blocked is None else wrap_angle(glimpse.blocked - drift),
            tuple((wrap_angle(y - drift), f) for y, f in glimpse.free),
            glimpse.named,
            doors=tuple(tuple(self._straighten(xy)) for xy in glimpse.doors),
            door_views=tuple(wrap_angle(y - drift) for y in glimpse.door_views),
        )
        self.glimpses.append(g)
        self._weigh(g)

    def _advance(self, odom: Pose2D, axis_odom: float | None) -> bool:
        """Carry the straightened odometry on to ``odom``: the walls' axis measured there
        (odometry, mod pi/2) against the reference's is the heading drift now, unless it
        jumped more than ``MAX_DRIFT_STEP`` since the last (another corridor's walls), and
        the leg since the last update turned by the mean drift. Whether the axis was taken.
        """
        drift, took = self._drift, False
        if axis_odom is not None:  # mod pi/2, the value nearest the drift so far
            step = wrap_angle(4.0 * (axis_odom - self._ref_axis - drift)) / 4.0
            if abs(step) < MAX_DRIFT_STEP:
                drift, took = drift + step, True
        mean = (self._drift + drift) / 2.0
        c, s = math.cos(-mean), math.sin(-mean)
        dx, dy = odom.x - self._raw.x, odom.y - self._raw.y
        self._corr = (self._corr[0] + c * dx - s * dy, self._corr[1] + s * dx + c * dy)
        self._drift, self._raw = drift, odom
        return took

    def observe_ray(
        self,
        odom: Pose2D,
        free: float,
        axis_odom: float | None = None,
        doors: tuple[tuple[float, float], ...] | None = None,
    ) -> None:
        """Add the free floor (m) seen in depth straight ahead from ``odom`` while driving:
        a hypothesis under which the map has a wall within that reach is a little less
        likely (``P_DRIVE_RAY``), so readings along a drive tell apart places where the
        corridor ahead ends sooner. No sign is read or missed (the view is along the
        corridor, not round it), and it is no look round.

        ``axis_odom``: the walls' axis in view there (odometry). Taken in along the drive,
        it keeps the heading drift current: on a long drive the odometry's heading can
        drift further between two looks round than a jump the belief would believe
        (``MAX_DRIFT_STEP``), and the straightened leg bends with the drift as it grows.

        ``doors``: the doors seen in that view (odometry xy; None: not looked for)."""
        if self.ref is None:
            return
        self._advance(odom, axis_odom)
        p = self._straighten((odom.x, odom.y))
        yaw = wrap_angle(odom.yaw - self._drift)
        ray = Glimpse(Pose2D(float(p[0]), float(p[1]), yaw), {}, free=((yaw, free),))
        if doors is not None:
            seen = tuple(tuple(self._straighten(xy)) for xy in doors)
            ray = replace(ray, doors=seen, door_views=(yaw,))
        self._weigh_ray(ray, self._map_T_odom())
        self.rays.append(ray)

    def rescale(self, gain: float) -> None:
        """The odometry's distance calibration is now ``gain``: every position the belief
        holds (glimpses, signs seen, drive rays, the straightened odometry) was driven under
        the old one, so it is moved from the reference by new / old and every hypothesis is
        weighed again. Each hypothesis is one rigid transform from the reference: without
        this, a long first leg on odometry 5 % long puts the true place a metre and a half
        short of the wall it then meets, and the walls rule it out.

        A change within ``RESCALE_MIN`` of the gain the positions are in waits (``gain``
        stays): several small ones in a row move them once they add up to more."""
        if self.ref is None:  # nothing held yet
            self.gain = gain
        if not self.rescale_due(gain):
            return
        k, self.gain = gain / self.gain, gain
        rx, ry = self.ref.x, self.ref.y

        def moved(xy) -> tuple[float, float]:
            return (rx + k * (xy[0] - rx), ry + k * (xy[1] - ry))

        def glimpse(g: Glimpse) -> Glimpse:
            x, y = moved((g.odom.x, g.odom.y))
            seen = {e: moved(xy) for e, xy in g.seen.items()}
            doors = tuple(moved(xy) for xy in g.doors)
            return replace(g, odom=replace(g.odom, x=x, y=y), seen=seen, doors=doors)

        self.glimpses = [glimpse(g) for g in self.glimpses]
        self.rays = [glimpse(r) for r in self.rays]
        self._corr = moved(self._corr)
        self._build()

    def rescale_due(self, gain: float) -> bool:
        """Whether ``rescale(gain)`` would move what the belief holds and weigh every
        hypothesis again (too slow for a tick: behaviours do it in the worker)."""
        return self.ref is not None and abs(gain / self.gain - 1.0) >= RESCALE_MIN

    def _straighten_tf(self) -> tuple[float, float, float]:
        """straightened_T_odom at the last glimpse."""
        if self.ref is None:
            return (0.0, 0.0, 0.0)
        c, s = math.cos(-self._drift), math.sin(-self._drift)
        rx, ry = self._raw.x, self._raw.y
        return (self._corr[0] - (c * rx - s * ry), self._corr[1] - (s * rx + c * ry), -self._drift)

    def _straighten(self, xy) -> np.ndarray:
        return se2_apply(self._straighten_tf(), xy)

    def to_odom(self, map_T_straight: tuple[float, float, float]) -> tuple[float, float, float]:
        """A fix in the belief's straightened frame as ``map_T_odom`` for the odometry now."""
        return se2_compose(map_T_straight, self._straighten_tf())

    def level_with_walls(
        self, map_T_straight: tuple[float, float, float], pivot: tuple[float, float]
    ) -> tuple[float, float, float] | None:
        """A fix (in the belief's straightened frame) turned about ``pivot`` (map) so that
        the corridor axis the walls gave at the last glimpse lies along the map's corridor
        there (mod 90 deg): two signs a couple of metres apart, each plate a little off
        where the map puts its door, give a heading several degrees off; the walls give it
        to a degree or two. Unchanged without a wall axis; when they differ by more than
        ``MAX_LEVEL``: then None, the signs cannot be where the map puts them (a misread,
        or a plate far from its map point) and the fix is not to be taken."""
        axis = getattr(self, "_last_axis", None)
        if self.ref is None or axis is None:
            return map_T_straight
        here = se2_apply(map_T_straight, (self._corr[0], self._corr[1]))
        seg = self.pm.locate(float(here[0]), float(here[1])).segment
        err = wrap_angle(4.0 * (seg.heading - (axis + map_T_straight[2]))) / 4.0
        if abs(err) > MAX_LEVEL:
            return None
        c, s = math.cos(err), math.sin(err)
        px, py = pivot
        x, y = map_T_straight[0] - px, map_T_straight[1] - py
        return (px + c * x - s * y, py + s * x + c * y, wrap_angle(map_T_straight[2] + err))

    def sightings(self) -> list[tuple[Entity, tuple[float, float]]]:
        """Every sign read so far and where (odometry), oldest first."""
        return [(e, xy) for g in self.glimpses for e, xy in g.seen.items()]

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

    def _weigh_free(
        self, tfs: np.ndarray, here: np.ndarray, odom: Pose2D, yaw: float, free: float, p: float
    ) -> None:
        """The free floor seen along ``yaw`` from ``odom`` (``here`` under each hypothesis)
        must be floor on the map: a hypothesis with a wall within that reach gets ``p``."""
        reach = min(free, MAX_RAY_M) - RAY_SLACK_M
        if reach > 1.0:
            end = _apply_many(tfs, (odom.x + reach * math.cos(yaw), odom.y + reach * math.sin(yaw)))
            floor = shapely.covers(self._floor, shapely.linestrings(np.stack([here, end], 1)))
            self.logw += np.where(floor, 0.0, math.log(p))

    def _weigh_ray(self, r: Glimpse, tfs: np.ndarray) -> None:
        """Reweigh by the free floor seen ahead while driving (``observe_ray``)."""
        here = _apply_many(tfs, (r.odom.x, r.odom.y))
        for yaw, free in r.free:
            self._weigh_free(tfs, here, r.odom, yaw, free, P_DRIVE_RAY)
        self._weigh_doors(r, tfs, here, P_DRIVE_DOOR_MISS, P_DRIVE_DOOR_SPURIOUS)

    def _blocked_log(self, tfs: np.ndarray, xy, blocked: float) -> np.ndarray:
        """Log-weights for a drive blocked from ``xy`` heading ``blocked`` (straightened
        odometry): a hypothesis under which the corridor goes on ``BLOCK_PROBE_M`` ahead
        is unlikely."""
        d = BLOCK_PROBE_M
        probe = _apply_many(tfs, (xy[0] + d * math.cos(blocked), xy[1] + d * math.sin(blocked)))
        pn, poff = self.vis.nearest_many(probe)
        return np.where(poff <= self._half_width[pn], math.log(P_THROUGH_WALL), 0.0)

    def _weigh_depth(self, g: Glimpse, tfs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Reweigh by what a glimpse saw in depth (and where it was): the robot inside a
        wall, a blocked drive, walls close ahead, free floor along each ray. Returns where
        each hypothesis puts the robot (map) and the lattice point nearest it."""
        here = _apply_many(tfs, (g.odom.x, g.odom.y))
        near, off = self.vis.nearest_many(here)
        half = self._half_width[near]
        # A hypothesis that puts the robot inside a wall is unlikely.
        self.logw += np.where(off > half + OFF_CORRIDOR_M, math.log(P_THROUGH_WALL), 0.0)
        if g.blocked is not None:  # the corridor must end (or turn) just ahead
            self.logw += self._blocked_log(tfs, (g.odom.x, g.odom.y), g.blocked)
        # Depth: a wall close ahead of a view must be a wall on the map; the free floor seen
        # along each view (the whole ray, e.g. into a side corridor) must be floor on it.
        for yaw, free in g.free:
            c, s_ = math.cos(yaw), math.sin(yaw)
            if free < NEAR_WALL_M:
                d = free + 0.5
                probe = _apply_many(tfs, (g.odom.x + d * c, g.odom.y + d * s_))
                pn, poff = self.vis.nearest_many(probe)
                # Clearly inside a corridor: an oblique view puts the probe only a little
                # beyond the wall, and the hypothesis is a lattice point on the centre line.
                inside = poff <= self._half_width[pn] - RAY_SLACK_M
                self.logw += np.where(inside, math.log(P_DEPTH), 0.0)
            self._weigh_free(tfs, here, g.odom, yaw, free, P_DEPTH)
        return here, near

    def _weigh_doors(
        self,
        g: Glimpse,
        tfs: np.ndarray,
        here: np.ndarray,
        p_miss: float,
        p_spurious: float,
        sigma: float = SIGHT_SIGMA_M,
    ) -> None:
        """Reweigh by the doors seen along the walls: a map door on the robot's corridor,
        in a view that looked for doors and within ``DOOR_SEEN_M``, not seen costs
        ``p_miss``; a door seen where the map has no door or landmark costs
        ``p_spurious``. Which door it is is not known, only that one is there."""
        if not g.door_views or self._doors.xy.shape[0] == 0:
            return
        md = self._doors
        tol = max(DOOR_MATCH_M, 1.5 * sigma)
        seen = np.array(g.doors, dtype=float).reshape(-1, 2)
        seen_map = np.stack([_apply_many(tfs, xy) for xy in seen], 1) if len(seen) else None
        if seen_map is not None:  # (N, K, 2): each door seen, where each hypothesis puts it
            to_any = np.linalg.norm(seen_map[:, :, None] - md.any_xy[None, None], axis=3)
            self.logw += (to_any.min(axis=2) > tol).sum(axis=1) * math.log(p_spurious)
        # Hypothesis-door pairs in range first (a few in a hundred): the rest on those only,
        # so that the view ahead, weighed in the tick every metre, stays cheap.
        v = md.xy[None] - here[:, None]  # (N, M, 2)
        d2 = np.einsum("nmk,nmk->nm", v, v)
        lo, hi_m = DOOR_SEEN_M
        hi, di = np.nonzero((d2 >= lo * lo) & (d2 <= hi_m * hi_m))
        v = v[hi, di]
        bearing = np.arctan2(v[:, 1], v[:, 0])
        half = HALF_FOV - DOOR_FOV_MARGIN
        in_view = np.zeros(len(hi), bool)
        for yaw in g.door_views:
            off = np.remainder(bearing - (yaw + tfs[hi, 2]) + math.pi, 2.0 * math.pi) - math.pi
            in_view |= np.abs(off) <= half
        # On the robot's corridor: the robot is within a corridor's width of its wall line
        # (a door round a corner, on a crossing corridor's wall, is seen edge-on or not).
        across = md.along[di, 0] * v[:, 1] - md.along[di, 1] * v[:, 0]
        in_view &= np.abs(across) <= DOOR_WALL_NEAR_M
        if seen_map is not None:
            to_seen = np.linalg.norm(md.xy[di][:, None] - seen_map[hi], axis=2)
            in_view &= to_seen.min(axis=1) > tol
        if not in_view.any():
            return
        hi, di = hi[in_view], di[in_view]
        lines = shapely.linestrings(np.stack([here[hi], md.front[di]], 1))
        clear = shapely.covers(self._floor, lines)
        np.add.at(self.logw, hi[clear], math.log(p_miss))

    def _weigh(self, g: Glimpse) -> None:
        tfs = self._map_T_odom()
        ref = self.ref
        travelled = math.hypot(g.odom.x - ref.x, g.odom.y - ref.y)
        sigma = math.hypot(SIGHT_SIGMA_M, DRIFT_PER_M * travelled)
        here_xy, near = self._weigh_depth(g, tfs)
        self._weigh_doors(g, tfs, here_xy, P_DOOR_MISS, P_DOOR_SPURIOUS, sigma)
        # What the map says is readable at each hypothesis's position for this glimpse.
        readable = [self.vis.lattice_points[j].readable for j in near]
        seen = g.seen.keys()
        named = g.named - seen
        map_xy = {e: np.array(entity_xy(self.pm, e)) for e in seen}
        seen_map = {e: _apply_many(tfs, xy) for e, xy in g.seen.items()}  # (N, 2) per sign
        d_seen = {e: np.linalg.norm(seen_map[e] - map_xy[e], axis=1) for e in seen}
        # An elevator's plate hangs beside it: its sighting tells the place less exactly.
        sig = {e: math.hypot(sigma, PLACE_SIGMA_M[e.kind]) for e in seen}
        # Read, but the map says out of sight here: unlikely. A plate read but cut by the
        # image border, whose place is not known, much less so within reading range: the
        # plate hangs a metre beside the door the map's sight line ends at, and round a
        # corner one of the two is in sight when the other is not.
        spurious = {
            e: np.where(
                np.linalg.norm(here_xy - np.array(entity_xy(self.pm, e)), axis=1)
                <= self.vis.read_range,
                math.log(P_OCCLUDED),
                math.log(P_SPURIOUS),
            )
            for e in named
        }
        for i, r in enumerate(readable):
            if self.recall is None:
                lw = len(r - seen - named) * math.log(P_MISS)
            else:
                lw = sum(self._miss_log(e, here_xy[i]) for e in r - seen - named)
            lw += sum(spurious[e][i] for e in named - r)
            for e in seen:
                if e in r:
                    lw += max(-0.5 * (d_seen[e][i] / sig[e]) ** 2, MISREAD)
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
        """(map_T_odom, spread in metres) once one cluster holds FIX_MASS of the belief, a
        sign was read, the belief began from an earlier estimate (``prior``: re-localizing
        after a blocked corner, the estimate and the walls seen can be enough) or
        ``MIN_BLIND_GLIMPSES`` glimpses were taken (the corridors' shape alone, the ends
        met and the turns taken, can tell where the robot is); refined on the signs read
        under that hypothesis."""
        if not self.glimpses:
            return None
        blind = not any(g.seen for g in self.glimpses)
        if blind and self.prior is None and len(self.glimpses) < MIN_BLIND_GLIMPSES:
            return None
        idx, mass = self.best_cluster()
        if mass < FIX_MASS:
            return None
        w = self.weights()[idx]
        i = idx[int(np.argmax(w))]
        tf = tuple(self._map_T_odom()[i])
        src, dst, placed = [], [], []
        for g in self.glimpses:
            for e, oxy in g.seen.items():
                m = np.array(entity_xy(self.pm, e))
                if np.linalg.norm(se2_apply(tf, oxy) - m) <= 3.0 * SIGHT_SIGMA_M:
                    src.append(oxy)
                    dst.append(m)
                    placed.append(PLACE_SIGMA_M[e.kind])
        if not src:  # nothing read: the hypothesis as it is, if the belief is tight enough
            spread = float(np.sqrt((w * ((self.xy[idx] - self.xy[i]) ** 2).sum(1)).sum() / w.sum()))
            if spread > BLIND_SPREAD_M:
                return None
            return self.to_odom(tf), spread + 0.5
        fitted = None
        if len({tuple(d) for d in dst}) >= 2 and np.ptp(np.array(dst), axis=0).max() >= 2.0:
            fit, res = fit_se2(np.array(src), np.array(dst))
            fitted = self.level_with_walls(fit, tuple(np.mean(dst, axis=0)))
        if fitted is not None:
            tf = fitted
        spread = float(np.sqrt((w * ((self.xy[idx] - self.xy[i]) ** 2).sum(1)).sum() / w.sum()))
        if fitted is None:  # signs close together, or a fit the walls refute: the
            # hypothesis's heading, its position moved towards what the signs say as far
            # as they are surer of it than the belief is (an elevator's plate hangs a
            # metre or two from the map's point; a door is found where the map puts it)
            shift, res, sure = _sign_shift(tf, src, dst, placed)
            s2 = max(spread, HYPOTHESIS_SIGMA_M) ** 2
            if 1.0 / math.sqrt(1.0 / s2 + 1.0 / sure**2) > FIX_SIGMA_M:
                return None  # one cluster, not sure where in it (a lone elevator plate)
            shift = shift * (s2 / (s2 + sure**2))
            tf = (tf[0] + float(shift[0]), tf[1] + float(shift[1]), tf[2])
        tf = self.to_odom((float(tf[0]), float(tf[1]), float(tf[2])))
        return tf, math.hypot(spread, res)

    def sign_in_reach(self, odom: Pose2D) -> float:
        """The share of the belief under which the map puts a sign within reliable reading
        range of ``odom`` (1 with no glimpse yet): near 0 in a bare stretch, where looking
        harder round the same spot reads nothing. A drive just blocked here counts (a
        dead end is no junction with signs round it)."""
        if self.ref is None:
            return 1.0
        w = self.weights()
        p = self._straighten((odom.x, odom.y))
        tfs = self._map_T_odom()
        if self.pending_blocked is not None:  # the drive here just met a wall: count it
            w = w * np.exp(self._blocked_log(tfs, p, self.pending_blocked - self._drift))
            w = w / w.sum()
        near, _ = self.goal.nearest_many(_apply_many(tfs, (p[0], p[1])))
        pts = self.goal.lattice_points
        return float(w[np.array([bool(pts[j].readable) for j in near])].sum())

    def look_tells(self, odom: Pose2D) -> bool:
        """Whether a look round from ``odom`` can tell the belief's likely places apart.

        False when no place holds ``FIX_MASS`` of the belief, no sign is within sight
        under any likely hypothesis (those a telling place tells apart), and every
        cluster of them has one whose map shows the same free floor round about as the
        likeliest (``LOOK_ALIKE_M`` along every bearing, to ``MAX_RAY_M``): the mirror
        images of a symmetric junction, or places along a bare corridor. There a look
        costs a full turn and cannot move the belief from one cluster to another. True
        before the first glimpse, and after a blocked drive (its wall is told at the
        look)."""
        if self.ref is None or self.pending_blocked is not None:
            return True
        _, mass = self.best_cluster()
        if mass >= FIX_MASS:  # one place: a look may read the sign that fixes it
            return True
        _, idx, modes = self._likely_modes()
        tfs = self._map_T_odom()
        p = self._straighten((odom.x, odom.y))
        here = _apply_many(tfs[idx], (p[0], p[1]))
        near, _ = self.vis.nearest_many(here)
        if any(self.vis.lattice_points[j].readable for j in near):
            return True
        if len(modes) < 2:
            return False
        yaw = odom.yaw - self._drift
        at = {int(i): k for k, i in enumerate(idx)}

        def floor(i: int) -> np.ndarray:
            return self._floor_round(here[at[i]], tfs[i][2] + yaw)

        # Told apart when some cluster has no member (a step along its corridor, maybe)
        # that would see what the likeliest place sees.
        ref = floor(modes[0][0])
        alike = (any((np.abs(floor(i) - ref) <= LOOK_ALIKE_M).all() for i in m) for m in modes[1:])
        return not all(alike)

    def _floor_round(self, xy: np.ndarray, heading: float) -> np.ndarray:
        """The free floor (m, to ``MAX_RAY_M``) the map has round ``xy`` (map) along
        ``LOOK_BEARINGS`` from ``heading``: what a look round from there shows in depth."""
        a = heading + LOOK_BEARINGS
        ends = np.asarray(xy) + MAX_RAY_M * np.stack([np.cos(a), np.sin(a)], 1)
        rays = shapely.linestrings(np.stack([np.broadcast_to(xy, ends.shape), ends], 1))
        hits = shapely.intersection(rays, self.vis.walls)
        d = shapely.distance(shapely.Point(xy), hits)
        return np.where(np.isnan(d), MAX_RAY_M, np.minimum(d, MAX_RAY_M))

    def lead(self, odom: Pose2D, max_distance: float = 8.0) -> Lead | None:
        """Where to drive from ``odom``: one of the ways out along the corridor axis (or
        across it at a junction). It keeps the way it chose last while enough of the belief
        says that way goes on (so it explores one way to the end, then the other), else the
        open way with the least expected corridor distance to where the map says two
        signs are readable (with a ``target``: to the target by way of such signs, so the
        search for signs heads where the robot is going), as far as where a quarter of the
        belief has signs in reach. The drive stops at the next junction, where half the
        belief puts it (on the first drive from a diffuse belief, where a fifth does: from
        a bare corridor the median junction is far, and a nearer one passed unlooked-at is
        the place that would have told the position)."""
        dist, _ = self.goal.towards_signs
        if not dist:
            return None
        blocked = self._blocked_ways(odom)
        kept = self._last_way
        telling = self._telling_lead(odom, max_distance)
        if telling is not None:
            if self._last_way not in blocked:
                return telling
            self._last_way = kept  # its way is shut from here: choose as if it had none
        w = self.weights()
        tfs = self._map_T_odom()
        live = np.nonzero(w > 1e-4 * w.max())[0]
        p = self._straighten((odom.x, odom.y))
        here = _apply_many(tfs[live], (p[0], p[1]))
        near, _ = self.vis.nearest_many(here)
        axis = self._axis()
        open_mass = np.zeros(4)  # belief that each way (along/across the axis) is open
        cost = np.zeros(4)  # expected distance to signs each way
        trip = np.zeros(4)  # ... and to the target by way of signs (the whole trip)
        onward = None if self.target is None else self.goal.exits_to(self.target)
        run = [[] for _ in range(4)]  # (weight, distance to the next junction) per way
        reads = [[] for _ in range(4)]  # (weight, distance to signs) per way
        side_mass = 0.0  # belief that the robot is at a junction with a side corridor
        # Side corridors of a junction within reach count (it is easy to stop a little off
        # its centre); along the axis only the nearest point's ways (a dead end stays one).
        pairs = self.vis._lattice_tree.query(
            shapely.points(here), predicate="dwithin", distance=JUNCTION_REACH_M
        )
        reach: dict[int, list[int]] = {}
        for a, b in pairs.T:
            reach.setdefault(int(a), []).append(int(b))
        for n, (i, j) in enumerate(zip(live, near, strict=True)):
            ways: dict[int, tuple[float, float, float]] = {}
            for m in {j, *reach.get(n, ())}:
                for h_map, d in self.goal.exits[m]:
                    k = int(round(wrap_angle(h_map - tfs[i][2] - axis) / (math.pi / 2))) % 4
                    if m != j and k % 2 == 0:
                        continue
                    r = self.goal.run_lengths[m].get(h_map, 0.0)
                    t = d if onward is None else onward[m].get(h_map, math.inf)
                    if k not in ways or d < ways[k][0]:
                        ways[k] = (d, r, t)
            if 1 in ways or 3 in ways:
                side_mass += w[i]
            for k, (d, r, t) in ways.items():
                open_mass[k] += w[i]
                cost[k] += w[i] * min(d, WALL_COST_M)
                trip[k] += w[i] * min(t, 2.0 * WALL_COST_M)
                run[k].append((w[i], r))
                reads[k].append((w[i], min(d, WALL_COST_M)))
        total = float(w[live].sum())
        open_mass /= total
        side_mass /= total
        cost = np.where(open_mass > 0, cost / np.maximum(open_mass * total, 1e-12), np.inf)
        trip = np.where(open_mass > 0, trip / np.maximum(open_mass * total, 1e-12), np.inf)
        # Across the axis only where the belief is sure of a junction (it is easy to be a
        # metre or two short of one); along it while a third of the belief says it goes on,
        # except at a junction, where the way is chosen afresh.
        cross = CROSS_WAY_MASS if side_mass < CROSS_WAY_MASS else KEEP_WAY_MASS
        need = np.array([KEEP_WAY_MASS, cross, KEEP_WAY_MASS, cross])
        ends = np.full(4, np.inf)  # weighted median distance to the next junction or end
        for j, r in enumerate(run):
            if r:
                ends[j] = _weighted_median(*np.array(r).T)
        open_mass[list(blocked)] = 0.0  # not into the wall this spot's drive just met
        ok = np.nonzero(open_mass >= need)[0]
        k = self._last_way
        if k is not None and open_mass[k] >= need[k] and side_mass < CROSS_WAY_MASS:
            # Keep the way, unless the other way is expected much shorter (after what was
            # seen on this one): a search that doubles back instead of going on forever.
            back = (k + 2) % 4
            if back in ok and SWITCH_COST_RATIO * cost[back] < cost[k]:
                k = back
        elif len(ok):
            k = int(ok[np.argmin(trip[ok])])
            _, mass = self.best_cluster()
            near = [j for j in ok if ends[j] <= NEAR_JUNCTION_M]
            if mass < DIFFUSE_MASS and near and len(self.glimpses) <= 1:
                # Nothing tells the ways apart yet: first the junction or end close by.
                k = int(min(near, key=lambda j: ends[j]))
        else:
            k = int(np.argmax(open_mass[::2]) * 2)
        self._last_way = k
        # As far as where a share of the belief has signs in reach: the mean distance of a
        # split belief (signs 3 m on under some hypotheses, 30 m under others) is where
        # none has any.
        go = 1.0
        if reads[k]:
            near_signs = _weighted_quantile(*np.array(reads[k]).T, LEAD_QUANTILE)
            go = float(np.clip(near_signs + 1.0, 1.0, max_distance))
        # Drive past the places already looked round from in that direction.
        h = axis + k * math.pi / 2
        u = np.array([math.cos(h), math.sin(h)])
        ahead = [float((np.array([g.odom.x, g.odom.y]) - p) @ u) for g in self.glimpses]
        seen_to = max([a for a in ahead if a > 0.0], default=0.0)
        if seen_to > 0.0:
            go = float(min(max(go, seen_to + LOOK_SPACING_M), 2.0 * max_distance))
        # Stop at the next junction (most of the belief agrees where): look round there.
        if run[k]:
            # Where most of the belief puts it; on the first drive from a diffuse belief
            # (a bare corridor), where a share of it already does: a drive past a
            # junction not looked round at skips the place that tells most.
            _, mass = self.best_cluster()
            first = mass < DIFFUSE_MASS and len(self.glimpses) <= 1
            q = FIRST_JUNCTION_QUANTILE if first else 0.5
            to_junction = _weighted_quantile(*np.array(run[k]).T, q)
            at = p + u * to_junction
            looked = any(
                math.hypot(g.odom.x - at[0], g.odom.y - at[1]) < 3.0 for g in self.glimpses
            )
            if 1.0 < to_junction < go and not looked:
                go = to_junction
        heading = wrap_angle(h + self._drift)  # back to odometry
        return Lead(heading, go, float(open_mass[k]))

    def turned_lead(self, odom: Pose2D, heading: float, max_distance: float = 8.0) -> Lead | None:
        """The lead from ``odom`` when it is not along ``heading`` (odometry; more than 45
        deg off: the belief now says another way), else None and the belief's memory of
        the way it keeps is left as it was (a drive under way goes on its way)."""
        kept = self._last_way
        new = self.lead(odom, max_distance)
        if new is not None and abs(wrap_angle(new.heading - heading)) > math.pi / 4:
            return new
        self._last_way = kept
        return None

    def _blocked_ways(self, odom: Pose2D) -> set[int]:
        """The ways (0-3 from the axis) that a drive from within ``BLOCKED_NEAR_M`` of
        ``odom`` met a wall on: whatever the hypotheses say, that way is shut from here (a
        belief that puts the robot at the wrong junction would drive into it again)."""
        p = self._straighten((odom.x, odom.y))
        axis = self._axis()
        return {
            int(round(wrap_angle(g.blocked - axis) / (math.pi / 2))) % 4
            for g in self.glimpses
            if g.blocked is not None
            and math.hypot(g.odom.x - p[0], g.odom.y - p[1]) < BLOCKED_NEAR_M
        }

    def _likely_modes(self) -> tuple[np.ndarray, np.ndarray, list[list[int]]]:
        """The weights, the hypotheses at least ``TELLING_MIN_WEIGHT`` as likely as the best
        (best first), and their clusters: the places a look must tell apart."""
        w = self.weights()
        idx = np.argsort(-w)
        idx = idx[w[idx] >= TELLING_MIN_WEIGHT * w[idx[0]]]
        return w, idx, self._modes(idx)

    def _modes(self, idx: np.ndarray) -> list[list[int]]:
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

    def _telling_lead(self, odom: Pose2D, max_distance: float) -> Lead | None:
        """Towards the nearest place where the few likely hypotheses predict different
        signs (the most information per metre driven; with a ``target``, the place with
        the shortest expected trip there and on to it), when the belief is split between
        a few clusters, e.g. the mirror images of a symmetric corridor: a glimpse there
        tells them apart, where driving towards signs that every hypothesis puts alike
        (both ends of the corridor) cannot. The first leg of the way there, along or
        across the axis; None when no such place is in reach or the belief is not split."""
        if self.ref is None:
            return None
        w, idx, modes = self._likely_modes()
        mass = np.array([w[m].sum() for m in modes])
        if (
            len(modes) < 2
            or len(modes) > TELLING_MAX_MODES
            or mass.sum() < TELLING_COVER
            or mass.max() >= FIX_MASS * mass.sum()
        ):
            return None
        tfs = self._map_T_odom()
        best = int(idx[0])
        p = self._straighten((odom.x, odom.y))
        here = _apply_many(tfs[[best]], (p[0], p[1]))[0]
        start, _ = self.vis.nearest_many(here[None])
        g = self.vis.lattice_graph
        reach, paths = nx.single_source_dijkstra(
            g, int(start[0]), cutoff=TELLING_REACH_M, weight="length"
        )
        cand = np.array(sorted(reach, key=reach.get), dtype=int)
        inv = se2_inverse(tuple(tfs[best]))
        q = np.array([se2_apply(inv, xy) for xy in self.vis.lattice_xy[cand]])  # odom places
        looked = np.array([[g_.odom.x, g_.odom.y] for g_ in self.glimpses])
        fresh = np.linalg.norm(q[:, None, :] - looked[None], axis=2).min(1) > TELLING_LOOKED_M
        half = np.array([s.width / 2.0 for s in self.pm.segments])
        pts = self.goal.lattice_points  # what each would read there for sure
        hyp = np.array([m[int(np.argmax(w[m]))] for m in modes])  # one per cluster
        preds = []  # per cluster: the signs readable at each candidate (None: a wall)
        to_target = None if self.target is None else self.goal.distance_to(self.target)
        onward = np.zeros((len(hyp), len(cand)))  # way on from each candidate, per cluster
        for k, i in enumerate(hyp):
            c, s_ = math.cos(tfs[i][2]), math.sin(tfs[i][2])
            there = np.stack(
                [tfs[i][0] + c * q[:, 0] - s_ * q[:, 1], tfs[i][1] + s_ * q[:, 0] + c * q[:, 1]], 1
            )
            near, off = self.vis.nearest_many(there)
            if to_target is not None:
                onward[k] = [to_target.get(int(n), WALL_COST_M) for n in near]
            preds.append(
                [
                    pts[n].readable if o <= half[pts[n].segment - 1] else None
                    for n, o in zip(near, off, strict=True)
                ]
            )
        dist = np.array([reach[int(m)] for m in cand])
        usable = fresh & (dist >= 1.0)
        ids: dict[frozenset, int] = {}  # what each cluster reads there, as an id (-1: a wall)
        sees = np.array(
            [[-1 if r is None else ids.setdefault(r, len(ids)) for r in pr] for pr in preds]
        )
        if to_target is None:  # the nearest place that tells the clusters apart
            ok = np.nonzero(telling(sees, mass, usable, FIX_MASS))[0]
            best_c = int(cand[ok[0]]) if len(ok) else None
        else:  # with a target: the least expected whole trip, looking again if need be
            between = self.vis.distances_between(cand)
            trip = expected_trip(dist, between, sees, onward, mass, usable, FIX_MASS)
            best_c = int(cand[int(np.argmin(trip))]) if np.isfinite(trip).any() else None
        if best_c is None:
            return None
        return self._leg_towards(here, paths[best_c], tfs[best], float(mass.sum()), max_distance)

    def _leg_towards(self, here, path, tf, support: float, max_distance: float) -> Lead | None:
        """The first straight leg from ``here`` (map) along a lattice path: the first
        straight run of the path that does not end within a metre of ``here``, driven
        along from beside it (a junction this close is the robot's, as in ``lead``), or
        towards its start when the robot is off its line; as a way along or across the
        axis in odometry, and its length."""
        pts = self.vis.lattice_xy[list(path)]
        runs: list[tuple[np.ndarray, np.ndarray, float]] = []  # start, direction, length
        for p0, p1 in zip(pts, pts[1:], strict=False):
            v = p1 - p0
            n = float(np.linalg.norm(v))
            if n < 1e-3:
                continue
            u = v / n
            if runs and float(runs[-1][1] @ u) > 0.95:
                runs[-1] = (runs[-1][0], runs[-1][1], runs[-1][2] + n)
            else:
                runs.append((p0, u, n))
        here = np.asarray(here)
        for a, u, n in runs:
            end = a + u * n
            if np.linalg.norm(end - here) < 1.0:
                continue
            rel = here - a
            if abs(rel[0] * u[1] - rel[1] * u[0]) <= JUNCTION_REACH_M + LEG_OFF_LINE_M:
                go = float((end - here) @ u)
            else:
                u = -rel / float(np.linalg.norm(rel))
                go = float(np.linalg.norm(rel))
            axis = self._axis()
            h0 = math.atan2(u[1], u[0])
            k = int(round(wrap_angle(h0 - tf[2] - axis) / (math.pi / 2))) % 4
            self._last_way = k
            heading = wrap_angle(axis + k * math.pi / 2 + self._drift)
            return Lead(heading, float(np.clip(go, 1.0, 2.0 * max_distance)), support)
        return None

    def _axis(self) -> float:
        """The corridor axis in odometry, as seen at the reference."""
        return 0.0 if self.ref is None else self.ref.yaw - self.axis_offset


def _sign_shift(tf, src, dst, placed) -> tuple[np.ndarray, float, float]:
    """The shift that puts the signs read (``src``, odometry) on their map places (``dst``)
    under ``tf``, its residual (m, RMS over the signs kept) and its uncertainty (m) from
    how far each kept sign may be from its map place (``placed``, m per sighting).

    Each sign's shift is the mean of its sightings'; the signs kept are weighed by how
    exactly they are placed. Signs that disagree by more than
    ``SIGN_AGREE_M`` cannot all be right (a sign plate sits beside the door or elevator the
    map places, up to 1.7 m off): those that agree with the sign asking for the smallest
    shift, the one the belief's hypothesis (every sighting, depth, the corridors) already
    agrees with, are kept."""
    per: dict[tuple, list] = {}
    sigma: dict[tuple, float] = {}
    for s, d, p in zip(src, dst, placed, strict=True):
        per.setdefault(tuple(d), []).append(d - se2_apply(tf, s))
        sigma[tuple(d)] = p
    shifts = np.array([np.mean(v, axis=0) for v in per.values()])
    sig = np.array([sigma[k] for k in per])
    least = shifts[int(np.argmin(np.linalg.norm(shifts, axis=1)))]
    keep = np.linalg.norm(shifts - least, axis=1) <= SIGN_AGREE_M
    kept, wk = shifts[keep], 1.0 / sig[keep] ** 2
    shift = (kept * wk[:, None]).sum(axis=0) / wk.sum()
    res = float(np.sqrt(np.mean(np.sum((kept - shift) ** 2, axis=1))))
    return shift, res, float(1.0 / math.sqrt(wk.sum()))


@dataclass(frozen=True)
class _MapDoors:
    """The map's room doors as the door sightings see them: on the wall (``xy``), a point
    in front of each in the corridor (``front``, for the line of sight), the wall's
    direction (``along``), and every door and landmark a sighting may be (``any_xy``)."""

    xy: np.ndarray
    front: np.ndarray
    along: np.ndarray
    any_xy: np.ndarray

    @classmethod
    def of(cls, vis: Visibility) -> _MapDoors:
        """From the map's signs (``Visibility``): the map places a room's at its door."""
        rooms = [i for i, e in enumerate(vis.entities) if e.kind is EntityKind.ROOM]
        xy, front, n = vis.sign_xy[rooms], vis.sign_front[rooms], vis.sign_normal[rooms]
        along = np.stack([-n[:, 1], n[:, 0]], 1).reshape(-1, 2)
        any_xy = vis.sign_xy
        return cls(xy, front, along, any_xy)


def _weighted_median(w: np.ndarray, x: np.ndarray) -> float:
    return _weighted_quantile(w, x, 0.5)


def _weighted_quantile(w: np.ndarray, x: np.ndarray, q: float) -> float:
    order = np.argsort(x)
    c = np.cumsum(w[order])
    return float(x[order][min(len(x) - 1, int(np.searchsorted(c, q * c[-1])))])


def _apply_many(tfs: np.ndarray, p) -> np.ndarray:
    c, s = np.cos(tfs[:, 2]), np.sin(tfs[:, 2])
    return np.stack([tfs[:, 0] + c * p[0] - s * p[1], tfs[:, 1] + s * p[0] + c * p[1]], 1)
