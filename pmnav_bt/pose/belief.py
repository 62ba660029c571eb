"""A belief over where on the corridors the robot is, kept across localization attempts.

The façade of the localization stage's belief; its parts each live in a module of their
own:

- ``pose.hypotheses``: the hypotheses (a map pose at the reference odometry pose, on a
  corridor centre line, facing along or across it) and their motion update (odometry
  straightened by the walls);
- ``pose.evidence``: what reweights them, one kind of evidence a module (signs read,
  missed and misread; the floor in depth, against the corridor rectangles or the
  building's grid; doors along the walls; a prior);
- ``pose.lead`` and ``pose.telling``: where to drive or look next.

Every glimpse (a panorama: the signs read there and where each was seen, in odometry)
reweights all hypotheses; so, more weakly, does the free floor seen ahead while driving
(``observe_ray``). ``fix`` gives ``map_T_odom`` once one hypothesis cluster dominates;
``lead`` says which way to drive along the corridor, in odometry, towards the nearest
stretch where the map says at least two signs are readable, or, when the belief is split
between a few clusters (a symmetric corridor's mirror images), to the nearest place
where they predict different signs.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from pmnav_bt.geometry import fit_se2, se2_apply, se2_compose, wrap_angle
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.pose import lead as leads
from pmnav_bt.pose import telling
from pmnav_bt.pose.evidence import Evidence
from pmnav_bt.pose.evidence.doors import scene_weights
from pmnav_bt.pose.evidence.floor_model import CORRIDORS, WallSource
from pmnav_bt.pose.evidence.prior import P_FAR, weigh_prior
from pmnav_bt.pose.evidence.signs import PLACE_SIGMA_M, SIGHT_SIGMA_M
from pmnav_bt.pose.glimpse import Glimpse
from pmnav_bt.pose.hypotheses import FIX_MASS, Hypotheses, Straightened, apply_many
from pmnav_bt.pose.landmark_fix import sign_shift
from pmnav_bt.pose.lead import Lead
from pmnav_bt.pose.visibility import Visibility, entity_xy
from pmnav_bt.seams import Entity, Pose2D

MAX_LEVEL = math.radians(15.0)  # a two-sign fit is turned onto the walls' axis up to this
FIX_SIGMA_M = 0.5  # a fix from the belief and its signs must know the place this well
HYPOTHESIS_SIGMA_M = 0.5  # a hypothesis is a lattice point: no surer of the place than a step
MIN_BLIND_GLIMPSES = 4  # glimpses before a fix from the corridors' shape alone
BLIND_SPREAD_M = 0.75  # ... and how tight the belief must be for it
RESCALE_MIN = 0.002  # a change of the odometry's distance gain smaller than this waits
# A fix the signs refined is not taken over the hypothesis when the depth held fits it
# worse by more than this (log): two clear contradictions (a ray through a wall, 0.1 each).
WALLS_REFUTE = -2.0 * math.log(0.1)


@dataclass
class CorridorBelief:
    """Hypotheses over the corridor positions, reweighted by every glimpse."""

    pm: PrioriMap
    glimpses: list[Glimpse] = field(default_factory=list)
    ref: Pose2D | None = None
    axis_offset: float = 0.0  # robot yaw minus corridor axis at the reference (rad)
    # A prior from an earlier estimate: map_T_odom and its position uncertainty (m).
    prior: tuple[tuple[float, float, float], float] | None = None
    # How likely that estimate is grossly wrong (``evidence.prior``); None: it cannot be
    # (the lift's word on arrival).
    prior_floor: float | None = P_FAR
    pending_blocked: float | None = None  # a drive was blocked heading this way (odometry)
    # The free floor seen straight ahead while driving between glimpses (straightened
    # odometry): depth only, no look round, so no sign is missed in them.
    rays: list[Glimpse] = field(default_factory=list)
    _last_way: int | None = None  # the way (0-3 from the axis) the last lead chose
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
    # The walls depth is weighed against (``evidence.floor_model``): the corridor
    # rectangles, or the building's grid as a likelihood field.
    walls: WallSource = CORRIDORS
    # The odometry straightened by the walls (None before the first glimpse), and the
    # walls' axis in it at the last glimpse (None: not measured, or not taken).
    _odo: Straightened | None = field(default=None, init=False, repr=False)
    _last_axis: float | None = field(default=None, init=False, repr=False)
    # What ``fix`` and ``best_cluster`` answer for the belief as it is (None: not worked
    # out since it last changed). ``settle`` works them out in the worker, so that the
    # tick that asks (``FixFromBelief``) reads them: on a sign-sparse building's belief a
    # fix weighs every depth ray held against the walls (tens of ms).
    _answers: dict | None = field(default=None, init=False, repr=False)
    # Each look's doors (``Evidence.look_doors``, one per glimpse) and what they add to
    # ``logw`` together: each weighed by ``doors.scene_weights``, which a new look changes
    # for the looks that see the same stretch of wall.
    _door_looks: list[np.ndarray] = field(default_factory=list, init=False, repr=False)
    _door_sum: np.ndarray | float = field(default=0.0, init=False, repr=False)

    def __post_init__(self) -> None:
        self.vis = Visibility.of(self.pm, self.read_range)
        # The same lattice, with the signs read reliably from each point (where to go).
        self.goal = Visibility.of(
            self.pm, self.read_range if self.lead_range is None else self.lead_range
        )
        self.evidence = Evidence.of(self.pm, self.vis, self.recall, self.walls)
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
        other._door_looks = list(self._door_looks)
        return other

    # -- the hypotheses -------------------------------------------------------------------

    @property
    def lattice(self) -> np.ndarray:
        """The lattice point of each hypothesis."""
        return self.hyps.lattice

    @property
    def xy(self) -> np.ndarray:
        """(N, 2) each hypothesis's map position at the reference."""
        return self.hyps.xy

    @property
    def yaw(self) -> np.ndarray:
        """(N,) each hypothesis's map heading at the reference."""
        return self.hyps.yaw

    @property
    def drift(self) -> float:
        """The odometry's heading drift since the reference, from the walls (rad)."""
        return 0.0 if self._odo is None else self._odo.drift

    def axis(self) -> float:
        """The corridor axis in odometry, as seen at the reference."""
        return 0.0 if self.ref is None else self.ref.yaw - self.axis_offset

    def map_T_odoms(self) -> np.ndarray:
        """(N, 3) map_T_odom of each hypothesis, for the straightened odometry."""
        return self.hyps.map_T_odom(self.ref)

    def straighten(self, xy) -> np.ndarray:
        """An odometry point in the belief's straightened odometry."""
        return se2_apply(self._straighten_tf(), xy)

    def _straighten_tf(self) -> tuple[float, float, float]:
        """straightened_T_odom at the last glimpse."""
        if self.ref is None:
            return (0.0, 0.0, 0.0)
        return self._odo.tf()

    def to_odom(self, map_T_straight: tuple[float, float, float]) -> tuple[float, float, float]:
        """A fix in the belief's straightened frame as ``map_T_odom`` for the odometry now."""
        return se2_compose(map_T_straight, self._straighten_tf())

    def _build(self) -> None:
        """The hypotheses afresh, weighed by everything held."""
        self._answers = None
        self.hyps = Hypotheses.on_lattice(self.vis, self.pm.segments, self.axis_offset)
        self.logw = np.zeros(len(self.hyps))
        self._door_looks, self._door_sum = [], 0.0
        if self.ref is None:
            return
        if self.prior is not None:
            weigh_prior(self.logw, self.hyps, self.ref, *self.prior, floor=self.prior_floor)
        tfs = self.map_T_odoms()  # the hypotheses and the reference are fixed from here
        for g in self.glimpses:
            self.evidence.look(self.logw, g, tfs, self.ref)
            self._door_looks.append(self.evidence.look_doors(g, tfs, self.ref))
        self._weigh_doors()
        for r in self.rays:
            self.evidence.drive_view(self.logw, r, tfs, self.ref)

    def _weigh_doors(self) -> None:
        """Put the looks' doors into ``logw`` afresh, each look's weighed by how many
        looks see the same wall (``doors.scene_weights``)."""
        xy = np.array([(g.odom.x, g.odom.y) for g in self.glimpses])
        k = scene_weights(xy)
        total = np.zeros(len(self.hyps))
        for w, lw in zip(k, self._door_looks, strict=True):
            total = total + w * lw
        self.logw = self.logw - self._door_sum + total
        self._door_sum = total

    # -- updates --------------------------------------------------------------------------

    def observe(self, glimpse: Glimpse, axis_odom: float | None = None) -> None:
        """Add a panorama and reweight every hypothesis with it.

        ``axis_odom``: the corridor axis measured in odometry (mod pi) there. At the first
        glimpse (the reference) it sets the hypotheses' headings; later, how far it has
        turned (mod pi/2) is the odometry's heading drift, taken out of the glimpse (the
        belief works in odometry straightened by the walls)."""
        self._answers = None
        if self.pending_blocked is not None and glimpse.blocked is None:
            glimpse = replace(glimpse, blocked=self.pending_blocked)
        self.pending_blocked = None
        if self.ref is None:
            # The hypotheses put the reference on a centre line: where the walls say the
            # centre line is, not where the robot stands (beside a wall, maybe).
            dx, dy = glimpse.to_centre or (0.0, 0.0)
            self.ref = replace(glimpse.odom, x=glimpse.odom.x + dx, y=glimpse.odom.y + dy)
            if axis_odom is not None:
                self.axis_offset = wrap_angle(2.0 * (self.ref.yaw - axis_odom)) / 2.0
            self._odo = Straightened.start(glimpse.odom, axis_odom)
            self._last_axis = axis_odom  # the walls' axis at the last glimpse (straightened)
            self.glimpses.append(glimpse)
            self._build()
            return
        self._odo, took = self._odo.advanced(glimpse.odom, axis_odom)
        drift, corr, raw = self._odo.drift, self._odo.corr, glimpse.odom
        self._last_axis = wrap_angle(axis_odom - drift) if took else None
        g = Glimpse(
            Pose2D(corr[0], corr[1], wrap_angle(raw.yaw - drift)),
            {e: tuple(self.straighten(xy)) for e, xy in glimpse.seen.items()},
            None if glimpse.blocked is None else wrap_angle(glimpse.blocked - drift),
            tuple((wrap_angle(y - drift), f) for y, f in glimpse.free),
            glimpse.named,
            doors=tuple(tuple(self.straighten(xy)) for xy in glimpse.doors),
            door_views=tuple(wrap_angle(y - drift) for y in glimpse.door_views),
        )
        self.glimpses.append(g)
        tfs = self.map_T_odoms()
        self.evidence.look(self.logw, g, tfs, self.ref)
        self._door_looks.append(self.evidence.look_doors(g, tfs, self.ref))
        self._weigh_doors()

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
        self._answers = None
        self._odo, _ = self._odo.advanced(odom, axis_odom)
        p = self.straighten((odom.x, odom.y))
        yaw = wrap_angle(odom.yaw - self.drift)
        ray = Glimpse(Pose2D(float(p[0]), float(p[1]), yaw), {}, free=((yaw, free),))
        if doors is not None:
            seen = tuple(tuple(self.straighten(xy)) for xy in doors)
            ray = replace(ray, doors=seen, door_views=(yaw,))
        self.evidence.drive_view(self.logw, ray, self.map_T_odoms(), self.ref)
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
        self._odo = self._odo.scaled(moved)
        self._build()

    def rescale_due(self, gain: float) -> bool:
        """Whether ``rescale(gain)`` would move what the belief holds and weigh every
        hypothesis again (too slow for a tick: behaviours do it in the worker)."""
        return self.ref is not None and abs(gain / self.gain - 1.0) >= RESCALE_MIN

    # -- questions ------------------------------------------------------------------------

    def weights(self) -> np.ndarray:
        """Each hypothesis's probability (they sum to 1)."""
        w = np.exp(self.logw - self.logw.max())
        return w / w.sum()

    def best_cluster(self) -> tuple[np.ndarray, float]:
        """Indices of the hypotheses around the best one and the weight they hold."""
        return self._answer("best_cluster", self._best_cluster)

    def _best_cluster(self) -> tuple[np.ndarray, float]:
        w = self.weights()
        return self.hyps.cluster_around(w, int(np.argmax(w)))

    def settle(self) -> None:
        """Work out now what ``fix`` and ``best_cluster`` answer for the belief as it is,
        to be read (not worked out) when asked: the worker calls it on a belief it hands
        to the tree, whose ``FixFromBelief`` then asks in a tick. Each is worked out once
        per change (``observe``, ``observe_ray``, ``rescale``), the same answer either way."""
        self.fix()

    def _answer(self, question: str, work_out: Callable[[], object]):
        """``work_out()``'s answer, kept until the belief changes."""
        answers = self._answers or {}
        if question not in answers:
            # a new dict: a fork shares the one it was copied with until either changes
            answers = self._answers = {**answers, question: work_out()}
        return answers[question]

    def sightings(self) -> list[tuple[Entity, tuple[float, float]]]:
        """Every sign read so far and where (odometry), oldest first."""
        return [(e, xy) for g in self.glimpses for e, xy in g.seen.items()]

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
        axis = self._last_axis
        if self.ref is None or axis is None:
            return map_T_straight
        corr = self._odo.corr
        here = se2_apply(map_T_straight, (corr[0], corr[1]))
        seg = self.pm.locate(float(here[0]), float(here[1])).segment
        err = wrap_angle(4.0 * (seg.heading - (axis + map_T_straight[2]))) / 4.0
        if abs(err) > MAX_LEVEL:
            return None
        c, s = math.cos(err), math.sin(err)
        px, py = pivot
        x, y = map_T_straight[0] - px, map_T_straight[1] - py
        return (px + c * x - s * y, py + s * x + c * y, wrap_angle(map_T_straight[2] + err))

    def fix(self) -> tuple[tuple[float, float, float], float] | None:
        """(map_T_odom, spread in metres) once one cluster holds FIX_MASS of the belief, a
        sign was read, the belief began from an earlier estimate (``prior``: re-localizing
        after a blocked corner, the estimate and the walls seen can be enough) or
        ``MIN_BLIND_GLIMPSES`` glimpses were taken (the corridors' shape alone, the ends
        met and the turns taken, can tell where the robot is); refined on the signs read
        under that hypothesis. Kept until the belief changes (``settle``)."""
        return self._answer("fix", self._fix)

    def _fix(self) -> tuple[tuple[float, float, float], float] | None:
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
        tf = hyp = tuple(self.map_T_odoms()[i])
        spread = float(np.sqrt((w * ((self.xy[idx] - self.xy[i]) ** 2).sum(1)).sum() / w.sum()))
        src, dst, placed = [], [], []
        for g in self.glimpses:
            for e, oxy in g.seen.items():
                m = np.array(entity_xy(self.pm, e))
                if np.linalg.norm(se2_apply(tf, oxy) - m) <= 3.0 * SIGHT_SIGMA_M:
                    src.append(oxy)
                    dst.append(m)
                    placed.append(PLACE_SIGMA_M[e.kind])
        if not src:  # nothing read: the hypothesis as it is, if the belief is tight enough
            if spread > BLIND_SPREAD_M:
                return None
            return self.to_odom(tf), spread + 0.5
        fitted = None
        if len({tuple(d) for d in dst}) >= 2 and np.ptp(np.array(dst), axis=0).max() >= 2.0:
            fit, res = fit_se2(np.array(src), np.array(dst))
            fitted = self.level_with_walls(fit, tuple(np.mean(dst, axis=0)))
        if fitted is not None:
            tf = fitted
        if fitted is None:  # signs close together, or a fit the walls refute: the
            # hypothesis's heading, its position moved towards what the signs say as far
            # as they are surer of it than the belief is (an elevator's plate hangs a
            # metre or two from the map's point; a door is found where the map puts it)
            shift, res, sure = sign_shift(tf, src, dst, placed)
            s2 = max(spread, HYPOTHESIS_SIGMA_M) ** 2
            if 1.0 / math.sqrt(1.0 / s2 + 1.0 / sure**2) > FIX_SIGMA_M:
                return None  # one cluster, not sure where in it (a lone elevator plate)
            shift = shift * (s2 / (s2 + sure**2))
            tf = (tf[0] + float(shift[0]), tf[1] + float(shift[1]), tf[2])
        if self._walls_refute(tf, hyp):  # the signs moved it where depth says it is not
            tf, res = hyp, 0.0
        tf = self.to_odom((float(tf[0]), float(tf[1]), float(tf[2])))
        return tf, math.hypot(spread, res)

    def _walls_refute(self, tf, hyp) -> bool:
        """Whether the depth everything held saw (the free floor and returns of every look
        and drive view) fits the fix ``tf`` worse than the hypothesis ``hyp`` it was
        refined from, by more than ``WALLS_REFUTE`` (straightened frame, both): a plate
        read a metre or two from where the map puts its door (beside it, or its depth
        off) moves a fix along the corridor that the walls in view had placed."""
        tfs = np.array([tf, hyp], dtype=float)
        logw = np.zeros(2)
        floor = self.evidence.floor
        for views, at_look in ((self.glimpses, True), (self.rays, False)):
            for g in views:
                here = apply_many(tfs, (g.odom.x, g.odom.y))
                travelled = math.hypot(g.odom.x - self.ref.x, g.odom.y - self.ref.y)
                for yaw, free in g.free:
                    floor.depth_ray(logw, tfs, here, g.odom, yaw, free, travelled, at_look)
        return bool(logw[1] - logw[0] > WALLS_REFUTE)

    # -- where next (pose.lead, pose.telling) ---------------------------------------------

    def sign_in_reach(self, odom: Pose2D) -> float:
        """The share of the belief under which the map puts a sign within reliable reading
        range of ``odom`` (``pose.lead.sign_in_reach``)."""
        return leads.sign_in_reach(self, odom)

    def look_tells(self, odom: Pose2D) -> bool:
        """Whether a look round from ``odom`` can tell the belief's likely places apart
        (``pose.telling.look_tells``)."""
        return telling.look_tells(self, odom)

    def lead(self, odom: Pose2D, max_distance: float = 8.0) -> Lead | None:
        """Where to drive from ``odom`` (``pose.lead.choose_lead``); the way it takes is
        remembered, to be kept while enough of the belief says it goes on."""
        lead, self._last_way = leads.choose_lead(self, odom, max_distance, self._last_way)
        return lead

    def turned_lead(self, odom: Pose2D, heading: float, max_distance: float = 8.0) -> Lead | None:
        """The lead from ``odom`` when it is not along ``heading`` (odometry; more than 45
        deg off: the belief now says another way), else None and the belief's memory of
        the way it keeps is left as it was (a drive under way goes on its way)."""
        new, way = leads.choose_lead(self, odom, max_distance, self._last_way)
        if new is not None and abs(wrap_angle(new.heading - heading)) > math.pi / 4:
            self._last_way = way
            return new
        return None
