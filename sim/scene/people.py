"""Walking people: kinematic bodies of human size that walk the corridors, some pausing.

The config's ``world.people_per_100m`` is the number of people per 100 m of corridor
(centre line), ``world.people_speed`` the range their walking speeds are drawn from
(0.8-1.4 m/s covers people strolling to hurrying; 1.2-1.4 m/s is the usual adult
pace), ``world.people_pausing`` the fraction who stop now and then (to talk, to read a
notice: they walk ``WALK_S`` seconds, stand ``PAUSE_S``). Everything is drawn from
``world.rng("people")``: each person gets a stream of their own for their route and
their pauses, so the same seed and the same robot motion replay the same crowd.

A person walks a corridor's centre line keeping right (``LANE_M`` off the centre, less
where a bench, a bed or a landmark stands on that side, and none at junctions, where
people cut the corner), and at a waypoint takes a corridor chosen at random, turning
back only at a dead end. Movement is a function of sim time: ``Crowd.advance(h)`` is a
clock listener that ``SimBase`` registers before its own (``Crowd.attach``), so people
move first in every tick and the robot then collides with them where they now stand.

People never walk into the robot: a person whose way ahead holds the robot within
``YIELD_AHEAD_M`` stops (and after ``TURN_BACK_S`` turns back), and no step ever brings
a person closer than ``KEEP_OFF_M`` to it, nor from outside into the floor a moving
robot will cover in the next ``ROBOT_REACH_S`` (its way: people see it move and do not
step in front of it; crossing at a junction, one waits beside its way; one already in
it walks on). They are solid for the robot (the world's
``clearance`` asks ``Crowd.clearance``: a person is an upright cylinder of
``PERSON_RADIUS_M``) but not part of the building: they are not in
``obstacle_footprints``, and SPL's shortest path ignores them. Where the robot drives
into a person the crowd counts a contact (``Crowd.contacts``, besides the robot's own
collision count). People walk through each other (they keep right, so those walking
towards each other pass side by side).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from pmnav_bt.seams import Pose2D
from pmnav_bt.sim._pybullet import p
from pmnav_bt.sim.clock import SimClock
from pmnav_bt.sim.scene.bodies import RGBA, Part, box, compound_body, cylinder, sphere
from pmnav_bt.sim.scene.corridors import Corridor, corridors
from pmnav_bt.sim.scene.host import SceneWorld

PERSON = "person"  # their segmentation label
PERSON_RADIUS_M = 0.25  # shoulders about 0.45-0.5 m across, arms swinging
HEIGHT_M = (1.6, 1.85)  # adult stature, women's and men's medians and above
LANE_M = 0.35  # keep-right offset of a walking person's centre from the centre line
TAPER_M = 1.5  # the offset shrinks to 0 over this far before a junction or turn
SIDESTEP_SPEED = 0.5  # m/s a person moves sideways to their lane
OBSTACLE_CLEAR_M = 0.05  # a person keeps this off clutter and landmarks beside the lane
YIELD_AHEAD_M = 0.8  # a person stops when the robot is this close ahead (gap)
YIELD_SIDE_M = 0.1  # ... and within this of their path's edge, sideways
KEEP_OFF_M = 0.05  # no step ever brings a person closer than this to the robot (gap)
# ... nor to where a moving robot will be within this: pedestrians judge a mover by its time
# to reach them, and keep out of the way of one due within 2-3 s (time-to-collision
# models of walking); 2 s also spans the robot's look at its way (a depth frame a second).
ROBOT_REACH_S = 2.0
TURN_BACK_S = 2.0  # a person held up this long by the robot turns back
START_CLEAR_M = 2.0  # people start at least this far from a robot put in the world
WALK_S = (8.0, 25.0)  # a pausing person walks this long between pauses (s)
PAUSE_S = (3.0, 10.0)  # ... and stands this long
CONTACT_M = 0.002  # a robot this close to a person touches them
_GRID_M = 0.1  # resolution of the lane offsets along a corridor


class Walker(Protocol):
    """What the crowd needs of a robot: where it is, how big, and its clock."""

    radius: float
    clock: SimClock

    def pose(self) -> Pose2D: ...


SKIN = (
    (0.96, 0.80, 0.69, 1.0),
    (0.88, 0.67, 0.52, 1.0),
    (0.72, 0.52, 0.38, 1.0),
    (0.55, 0.38, 0.26, 1.0),
    (0.40, 0.27, 0.18, 1.0),
)
HAIR = (
    (0.08, 0.07, 0.06, 1.0),
    (0.25, 0.16, 0.10, 1.0),
    (0.45, 0.32, 0.18, 1.0),
    (0.80, 0.68, 0.42, 1.0),
    (0.62, 0.62, 0.62, 1.0),
)
TOPS = (
    (0.85, 0.20, 0.20, 1.0),
    (0.20, 0.35, 0.70, 1.0),
    (0.92, 0.92, 0.90, 1.0),
    (0.25, 0.55, 0.30, 1.0),
    (0.95, 0.75, 0.20, 1.0),
    (0.45, 0.30, 0.55, 1.0),
    (0.30, 0.30, 0.32, 1.0),
)
TROUSERS = (
    (0.15, 0.20, 0.35, 1.0),
    (0.12, 0.12, 0.13, 1.0),
    (0.45, 0.40, 0.32, 1.0),
    (0.30, 0.32, 0.36, 1.0),
)
SCRUBS = ((0.30, 0.50, 0.75, 1.0), (0.35, 0.62, 0.55, 1.0), (0.18, 0.25, 0.45, 1.0))
COAT = (0.95, 0.95, 0.95, 1.0)
SHOES = (0.10, 0.09, 0.09, 1.0)


def _pick(rng: np.random.Generator, options: tuple[RGBA, ...]) -> RGBA:
    return options[int(rng.integers(len(options)))]


def person_parts(rng: np.random.Generator, hospital: bool) -> tuple[list[Part], float]:
    """A standing person's pieces (x forward, y left) and height: shoes, legs, torso, arms,
    neck, head and hair; in a hospital a third wear scrubs and a sixth a white coat."""
    h = float(rng.uniform(*HEIGHT_M))
    skin, hair = _pick(rng, SKIN), _pick(rng, HAIR)
    top, legs = _pick(rng, TOPS), _pick(rng, TROUSERS)
    u = rng.random()
    coat = False
    if hospital and u < 1 / 3:
        top = legs = _pick(rng, SCRUBS)
    elif hospital and u < 1 / 2:
        coat = True
    hip, shoulder = 0.47 * h, 0.82 * h
    parts: list[Part] = []
    for y in (-0.09, 0.09):
        parts.append(box(-0.06, 0.13, y - 0.05, y + 0.05, 0.0, 0.06, SHOES))
        parts.append(box(-0.07, 0.07, y - 0.065, y + 0.065, 0.06, hip, legs))
    parts.append(box(-0.11, 0.11, -0.19, 0.19, hip - 0.05, shoulder, top))
    if coat:  # a white coat over the torso, down to the knees
        parts.append(box(-0.12, 0.12, -0.2, 0.2, 0.3 * h, shoulder - 0.02, COAT))
    sleeve = COAT if coat else top
    for y in (-0.235, 0.235):
        parts.append(box(-0.045, 0.045, y - 0.045, y + 0.045, 0.46 * h, shoulder - 0.01, sleeve))
        parts.append(box(-0.04, 0.04, y - 0.035, y + 0.035, 0.40 * h, 0.46 * h, skin))
    parts.append(cylinder(0.0, 0.0, 0.05, shoulder, shoulder + 0.05, skin))
    parts.append(sphere(0.01, 0.0, h - 0.115, 0.1, skin))
    parts.append(sphere(-0.015, 0.0, h - 0.105, 0.102, hair))
    return parts, h


@dataclass
class Person:
    """One walker and where they are: on ``corridor`` (its index), walking a -> b when
    ``forward``, ``s`` m from a, ``lateral`` m right of their direction; with their own
    random stream. ``x``, ``y``, ``yaw``: where that is in the map."""

    body: int
    height: float
    speed: float
    pauses: bool
    rng: np.random.Generator
    corridor: int
    forward: bool
    s: float
    lateral: float = 0.0
    walk_left: float = math.inf  # metres to the next pause
    pause_left: float = 0.0  # seconds still standing
    blocked: float = 0.0  # seconds held up by a robot
    walked: float = 0.0  # metres walked in all
    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0


class Crowd:
    """The people of a world; ``advance(h)`` moves them (a clock listener, see ``attach``).

    Their bodies are drawn only: the robot's collision check asks ``clearance`` (the
    people are upright cylinders, so the distance is exact and costs microseconds), and
    the bodies are moved to where the people are when a camera renders (``show``)."""

    def __init__(self, world: SceneWorld, people: list[Person], ways: list[Corridor]) -> None:
        self.world = world
        self.people = people
        self.corridors = {c.index: c for c in ways}
        self.contacts = 0  # times a robot came into contact with a person
        self._robots: list[Walker] = []
        self._moves: dict[int, float] = {}  # robot -> metres ahead it will go (back: < 0)
        self._last: dict[int, Pose2D] = {}  # robot -> its pose a tick ago
        self._clock: SimClock | None = None
        self._touching: set[tuple[int, int]] = set()
        self._shown = False  # bodies where the people are
        self._ends: dict[str, list[tuple[int, bool]]] = {}  # waypoint -> (corridor, forward)
        for c in ways:
            self._ends.setdefault(c.a_id, []).append((c.index, True))
            self._ends.setdefault(c.b_id, []).append((c.index, False))
        # Per corridor: a's x, y, the unit vector to b, the length (floats: the tick is hot).
        self._geo = {
            c.index: (c.a[0], c.a[1], float(c.along[0]), float(c.along[1]), c.length)
            for c in ways
        }
        beside = [np.asarray(fp.exterior.coords) for fp in world.obstacle_footprints(HEIGHT_M[1])]
        self._lanes = {c.index: _lanes(c, beside) for c in ways}
        for q in people:
            self._locate(q)

    # -- where people are -------------------------------------------------------------------

    def _locate(self, q: Person) -> None:
        """Set ``q``'s map position and heading from their corridor coordinates."""
        ax, ay, ux, uy, _ = self._geo[q.corridor]
        dx, dy = (ux, uy) if q.forward else (-ux, -uy)
        q.x = ax + ux * q.s + dy * q.lateral  # the right of (dx, dy) is (dy, -dx)
        q.y = ay + uy * q.s - dx * q.lateral
        q.yaw = math.atan2(dy, dx)

    def poses(self) -> list[Pose2D]:
        """Where every person stands and faces, now."""
        return [Pose2D(q.x, q.y, q.yaw) for q in self.people]

    def lane(self, q: Person) -> float:
        """The offset right of the centre line ``q`` wants to walk at, where they are."""
        length = self._geo[q.corridor][4]
        lanes = self._lanes[q.corridor][0 if q.forward else 1]
        s = q.s if q.forward else length - q.s
        return float(lanes[min(len(lanes) - 1, max(0, int(round(s / _GRID_M))))])

    def clearance(self, x: float, y: float, radius: float) -> float:
        """Distance from an upright cylinder of ``radius`` at (x, y) to the nearest person
        (negative: overlapping); inf with nobody about."""
        best = math.inf
        for q in self.people:
            best = min(best, math.hypot(q.x - x, q.y - y) - PERSON_RADIUS_M - radius)
        return best

    def show(self) -> None:
        """Move the bodies to where the people are (before a camera renders them)."""
        if self._shown:
            return
        with self.world.lock:
            for q in self.people:
                p.resetBasePositionAndOrientation(
                    q.body,
                    (q.x, q.y, 0.0),
                    p.getQuaternionFromEuler((0.0, 0.0, q.yaw)),
                    physicsClientId=self.world.client,
                )
        self._shown = True

    # -- the clock ------------------------------------------------------------------------------

    def attach(self, robot: Walker) -> None:
        """Watch ``robot`` (people yield to it), move anyone within ``START_CLEAR_M`` of it
        on along their way, and follow its clock if the crowd follows none yet."""
        if not self.people:
            return
        self._robots.append(robot)
        for q in self.people:
            for _ in range(2000):  # 0.25 m at a time: at most 500 m
                if self._gap(q.x, q.y, robot) >= START_CLEAR_M:
                    break
                self._walk(q, 0.25)
                q.lateral = self.lane(q)
                self._locate(q)
        self._shown = False
        if self._clock is None:
            self._clock = robot.clock
            robot.clock.add_listener(self.advance)

    def detach(self, robot: Walker) -> None:
        """Stop watching ``robot``; leave its clock when no robot is left."""
        if robot in self._robots:
            self._robots.remove(robot)
            self._moves.pop(id(robot), None)
            self._last.pop(id(robot), None)
        if not self._robots and self._clock is not None:
            self._clock.remove_listener(self.advance)
            self._clock = None

    def advance(self, h: float) -> None:
        """Clock listener: ``h`` seconds of walking, pausing and yielding."""
        with self.world.lock:  # a camera may be rendering them from a worker thread
            self._watch_robots(h)
            for q in self.people:
                self._advance_one(q, h)
            self._count_contacts()

    def _watch_robots(self, h: float) -> None:
        """How far along its heading each robot will go in ``ROBOT_REACH_S`` at the speed
        it moved in the last tick (people see it move; backwards: negative)."""
        for robot in self._robots:
            r, k = robot.pose(), id(robot)
            last = self._last.get(k)
            self._last[k] = r
            if last is None or h <= 0.0:
                self._moves[k] = 0.0
                continue
            along = (r.x - last.x) * math.cos(r.yaw) + (r.y - last.y) * math.sin(r.yaw)
            self._moves[k] = along / h * ROBOT_REACH_S

    # -- walking --------------------------------------------------------------------------------

    @staticmethod
    def _gap(x: float, y: float, robot: Walker) -> float:
        r = robot.pose()
        return math.hypot(x - r.x, y - r.y) - PERSON_RADIUS_M - robot.radius

    def _way_gap(self, x: float, y: float, robot: Walker) -> float:
        """The gap from a person at (x, y) to the floor ``robot`` covers from where it is
        to where it will be in ``ROBOT_REACH_S`` (its body swept along its heading)."""
        r = robot.pose()
        lo, hi = sorted((0.0, self._moves.get(id(robot), 0.0)))
        c, s = math.cos(r.yaw), math.sin(r.yaw)
        t = max(lo, min(hi, (x - r.x) * c + (y - r.y) * s))
        return math.hypot(x - r.x - t * c, y - r.y - t * s) - PERSON_RADIUS_M - robot.radius

    def _advance_one(self, q: Person, h: float) -> None:
        if q.pause_left > 0.0:
            q.pause_left -= h
            return
        step = q.speed * h
        before = (q.corridor, q.forward, q.s, q.lateral, q.x, q.y, q.yaw)
        self._walk(q, step)
        want = self.lane(q)
        q.lateral += max(-SIDESTEP_SPEED * h, min(SIDESTEP_SPEED * h, want - q.lateral))
        self._locate(q)
        if self._robots and self._held_up(q, before[4], before[5]):
            q.corridor, q.forward, q.s, q.lateral, q.x, q.y, q.yaw = before
            q.blocked += h
            if q.blocked >= TURN_BACK_S:
                self._turn_back(q)
                self._locate(q)
                self._shown = False
                q.blocked = 0.0
            return
        q.blocked = 0.0
        q.walked += step
        self._shown = False
        if q.pauses:
            q.walk_left -= step
            if q.walk_left <= 0.0:
                q.pause_left = float(q.rng.uniform(*PAUSE_S))
                q.walk_left = q.speed * float(q.rng.uniform(*WALK_S))

    def _held_up(self, q: Person, x0: float, y0: float) -> bool:
        """Whether a robot stands in ``q``'s way ahead of (x0, y0), or their step to where
        they now are would close on one."""
        ux, uy = math.cos(q.yaw), math.sin(q.yaw)
        for robot in self._robots:
            r = robot.pose()
            rx, ry = r.x - x0, r.y - y0
            ahead, side = rx * ux + ry * uy, abs(rx * uy - ry * ux)
            reach = PERSON_RADIUS_M + robot.radius
            if 0.0 < ahead < YIELD_AHEAD_M + reach and side < reach + YIELD_SIDE_M:
                return True
            gap = self._gap(q.x, q.y, robot)
            if gap < KEEP_OFF_M and gap < self._gap(x0, y0, robot):
                return True
            # Into its way from outside (one already in it walks on: freezing there, in
            # front of it, is what must not happen).
            if self._way_gap(q.x, q.y, robot) < KEEP_OFF_M <= self._way_gap(x0, y0, robot):
                return True
        return False

    def _walk(self, q: Person, step: float) -> None:
        """Move ``q`` ``step`` m along their way, taking a random corridor at a waypoint."""
        while step > 0.0:
            c = self.corridors[q.corridor]
            left = c.length - q.s if q.forward else q.s
            if step < left:
                q.s += step if q.forward else -step
                return
            step -= left
            end = c.b_id if q.forward else c.a_id
            q.s = c.length if q.forward else 0.0
            nxt = [(i, fwd) for i, fwd in self._ends.get(end, []) if i != q.corridor]
            if not nxt:  # a dead end: turn back
                self._turn_back(q)
                continue
            i, fwd = nxt[int(q.rng.integers(len(nxt)))]
            q.corridor, q.forward = i, fwd
            q.s = 0.0 if fwd else self.corridors[i].length

    @staticmethod
    def _turn_back(q: Person) -> None:
        """Face the other way where ``q`` stands (their right is now the other side)."""
        q.forward = not q.forward
        q.lateral = -q.lateral

    def _count_contacts(self) -> None:
        for k, robot in enumerate(self._robots):
            for i, q in enumerate(self.people):
                gap = self._gap(q.x, q.y, robot)
                if gap < CONTACT_M:
                    if (i, k) not in self._touching:
                        self._touching.add((i, k))
                        self.contacts += 1
                elif gap > 2 * CONTACT_M:
                    self._touching.discard((i, k))


def _lanes(c: Corridor, obstacles: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """The keep-right offsets along ``c`` walking a -> b and b -> a (index: metres walked
    / ``_GRID_M``): ``LANE_M``, less beside an obstacle (its outline's points) on that side,
    growing back at 1 m per m beyond it; tapering to 0 before a junction end."""
    n = int(math.ceil(c.length / _GRID_M)) + 1
    s = np.arange(n) * _GRID_M
    fwd, back = np.full(n, LANE_M), np.full(n, LANE_M)
    for pts in obstacles:
        d = pts - np.asarray(c.a)
        along, lateral = d @ c.along, d @ c.left
        s0, s1 = along.min(), along.max()
        l0, l1 = lateral.min(), lateral.max()
        if s1 < -c.half_width or s0 > c.length + c.half_width or l0 * l1 <= 0:
            continue  # elsewhere, or astride the centre line (not clutter beside a lane)
        if min(abs(l0), abs(l1)) > c.half_width + 0.05:
            continue
        room = min(abs(l0), abs(l1)) - PERSON_RADIUS_M - OBSTACLE_CLEAR_M
        beyond = np.maximum(0.0, np.maximum(s0 - PERSON_RADIUS_M - s, s - s1 - PERSON_RADIUS_M))
        limit = room + beyond
        if l1 < 0:  # right of a -> b
            fwd = np.minimum(fwd, limit)
        else:  # left of a -> b: right of b -> a (its index runs from b)
            back = np.minimum(back, limit[::-1])
    for lanes, ends in ((fwd, c.junction_at), (back, c.junction_at[::-1])):
        if ends[0]:
            lanes[:] = np.minimum(lanes, LANE_M * np.clip(s / TAPER_M, 0.0, 1.0))
        if ends[1]:
            lanes[:] = np.minimum(lanes, LANE_M * np.clip((c.length - s) / TAPER_M, 0.0, 1.0))
    return fwd, back


def populate(world: SceneWorld) -> Crowd:
    """The config's people in ``world``, walking from random places of its corridors; an
    empty crowd (nothing drawn, nothing built) when ``people_per_100m`` is 0."""
    ways = [c for c in corridors(world.building) if c.length > 0.1]
    scene = world.scene
    if scene.people_per_100m <= 0.0 or not ways:
        return Crowd(world, [], ways)
    rng = world.rng("people")
    total = sum(c.length for c in ways)
    expected = total * scene.people_per_100m / 100.0
    n = int(expected) + int(rng.random() < expected - int(expected))
    hospital = world.building.kind.lower() == "hospital"
    lengths = np.array([c.length for c in ways])
    people = []
    for _ in range(n):
        parts, height = person_parts(rng, hospital)
        way = ways[int(rng.choice(len(ways), p=lengths / total))]
        q = Person(
            body=-1,
            height=height,
            speed=float(rng.uniform(*scene.people_speed)),
            pauses=bool(rng.random() < scene.people_pausing),
            rng=np.random.default_rng(int(rng.integers(2**63))),
            corridor=way.index,
            forward=bool(rng.random() < 0.5),
            s=float(rng.uniform(0.0, way.length)),
            lateral=0.0,
        )
        if q.pauses:
            q.walk_left = q.speed * float(q.rng.uniform(*WALK_S))
        with world.lock:
            q.body = compound_body(world.client, parts, (0.0, 0.0), 0.0, None)
        world.register(q.body, PERSON)
        people.append(q)
    crowd = Crowd(world, people, ways)
    for q in people:
        q.lateral = crowd.lane(q)
        crowd._locate(q)
    crowd.show()
    return crowd
