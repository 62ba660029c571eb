"""Telling a split belief apart: where to look next, and whether a look here can tell.

When the corridor belief is split between a few clusters of hypotheses (the mirror
images of a symmetric corridor, the arms of a cross junction), driving towards signs
that every cluster puts alike (both ends of the corridor) cannot tell them apart. A
place where the clusters predict different signs can: ``telling_lead`` drives to the
nearest one (with a ``target``, the one with the least expected whole trip,
``pose.lookahead``). And where no cluster can read a sign and all of them see the same
free floor round about, a look round costs a full turn and tells nothing
(``look_tells``).
"""

from __future__ import annotations

import math

import networkx as nx
import numpy as np

from pmnav_bt.geometry import se2_apply, se2_inverse, wrap_angle
from pmnav_bt.pose.belief_view import BeliefView
from pmnav_bt.pose.evidence.floor import MAX_RAY_M
from pmnav_bt.pose.hypotheses import FIX_MASS, apply_many
from pmnav_bt.pose.lookahead import expected_trip, telling
from pmnav_bt.seams import Pose2D

WALL_COST_M = 100.0  # a way with no signs (or no way on) ever ahead counts as this far
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


def likely_modes(b: BeliefView) -> tuple[np.ndarray, np.ndarray, list[list[int]]]:
    """The weights, the hypotheses at least ``TELLING_MIN_WEIGHT`` as likely as the best
    (best first), and their clusters: the places a look must tell apart."""
    w = b.weights()
    idx = np.argsort(-w)
    idx = idx[w[idx] >= TELLING_MIN_WEIGHT * w[idx[0]]]
    return w, idx, b.hyps.modes(idx)


def telling_lead(
    b: BeliefView, odom: Pose2D, max_distance: float, junction_reach: float
) -> tuple[float, float, float, int] | None:
    """Towards the nearest place where the few likely hypotheses predict different
    signs (the most information per metre driven; with a ``target``, the place with
    the shortest expected trip there and on to it), when the belief is split between
    a few clusters: the first leg of the way there, along or across the axis, as
    (heading in odometry, distance, the share of the belief told apart, way 0-3); None
    when no such place is in reach or the belief is not split."""
    if b.ref is None:
        return None
    w, idx, modes = likely_modes(b)
    mass = np.array([w[m].sum() for m in modes])
    if (
        len(modes) < 2
        or len(modes) > TELLING_MAX_MODES
        or mass.sum() < TELLING_COVER
        or mass.max() >= FIX_MASS * mass.sum()
    ):
        return None
    tfs = b.map_T_odoms()
    best = int(idx[0])
    p = b.straighten((odom.x, odom.y))
    here = apply_many(tfs[[best]], (p[0], p[1]))[0]
    start, _ = b.vis.nearest_many(here[None])
    g = b.vis.lattice_graph
    reach, paths = nx.single_source_dijkstra(
        g, int(start[0]), cutoff=TELLING_REACH_M, weight="length"
    )
    cand = np.array(sorted(reach, key=reach.get), dtype=int)
    inv = se2_inverse(tuple(tfs[best]))
    q = np.array([se2_apply(inv, xy) for xy in b.vis.lattice_xy[cand]])  # odom places
    looked = np.array([[g_.odom.x, g_.odom.y] for g_ in b.glimpses])
    fresh = np.linalg.norm(q[:, None, :] - looked[None], axis=2).min(1) > TELLING_LOOKED_M
    half = np.array([s.width / 2.0 for s in b.pm.segments])
    pts = b.goal.lattice_points  # what each would read there for sure
    hyp = np.array([m[int(np.argmax(w[m]))] for m in modes])  # one per cluster
    preds = []  # per cluster: the signs readable at each candidate (None: a wall)
    to_target = None if b.target is None else b.goal.distance_to(b.target)
    onward = np.zeros((len(hyp), len(cand)))  # way on from each candidate, per cluster
    for k, i in enumerate(hyp):
        c, s_ = math.cos(tfs[i][2]), math.sin(tfs[i][2])
        there = np.stack(
            [tfs[i][0] + c * q[:, 0] - s_ * q[:, 1], tfs[i][1] + s_ * q[:, 0] + c * q[:, 1]], 1
        )
        near, off = b.vis.nearest_many(there)
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
        between = b.vis.distances_between(cand)
        trip = expected_trip(dist, between, sees, onward, mass, usable, FIX_MASS)
        best_c = int(cand[int(np.argmin(trip))]) if np.isfinite(trip).any() else None
    if best_c is None:
        return None
    return leg_towards(
        b, here, paths[best_c], tfs[best], float(mass.sum()), max_distance, junction_reach
    )


def leg_towards(
    b: BeliefView, here, path, tf, support: float, max_distance: float, junction_reach: float
) -> tuple[float, float, float, int] | None:
    """The first straight leg from ``here`` (map) along a lattice path: the first
    straight run of the path that does not end within a metre of ``here``, driven
    along from beside it (a junction within ``junction_reach`` is the robot's, as in
    ``choose_lead``), or towards its start when the robot is off its line; as a way along
    or across the axis: (heading in odometry, length, ``support``, way 0-3)."""
    pts = b.vis.lattice_xy[list(path)]
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
        if abs(rel[0] * u[1] - rel[1] * u[0]) <= junction_reach + LEG_OFF_LINE_M:
            go = float((end - here) @ u)
        else:
            u = -rel / float(np.linalg.norm(rel))
            go = float(np.linalg.norm(rel))
        axis = b.axis()
        h0 = math.atan2(u[1], u[0])
        k = int(round(wrap_angle(h0 - tf[2] - axis) / (math.pi / 2))) % 4
        heading = wrap_angle(axis + k * math.pi / 2 + b.drift)
        return heading, float(np.clip(go, 1.0, 2.0 * max_distance)), support, k
    return None


def look_tells(b: BeliefView, odom: Pose2D) -> bool:
    """Whether a look round from ``odom`` can tell the belief's likely places apart.

    False when no place holds ``FIX_MASS`` of the belief, no sign is within sight
    under any likely hypothesis (those a telling place tells apart), and every
    cluster of them has one whose map shows the same free floor round about as the
    likeliest (``LOOK_ALIKE_M`` along every bearing, to ``MAX_RAY_M``): the mirror
    images of a symmetric junction, or places along a bare corridor. There a look
    costs a full turn and cannot move the belief from one cluster to another. True
    before the first glimpse, and after a blocked drive (its wall is told at the
    look)."""
    if b.ref is None or b.pending_blocked is not None:
        return True
    _, mass = b.best_cluster()
    if mass >= FIX_MASS:  # one place: a look may read the sign that fixes it
        return True
    _, idx, modes = likely_modes(b)
    tfs = b.map_T_odoms()
    p = b.straighten((odom.x, odom.y))
    here = apply_many(tfs[idx], (p[0], p[1]))
    near, _ = b.vis.nearest_many(here)
    if any(b.vis.lattice_points[j].readable for j in near):
        return True
    if len(modes) < 2:
        return False
    yaw = odom.yaw - b.drift
    at = {int(i): k for k, i in enumerate(idx)}

    def floor(i: int) -> np.ndarray:
        return floor_round(b, here[at[i]], tfs[i][2] + yaw)

    # Told apart when some cluster has no member (a step along its corridor, maybe)
    # that would see what the likeliest place sees.
    ref = floor(modes[0][0])
    alike = (any((np.abs(floor(i) - ref) <= LOOK_ALIKE_M).all() for i in m) for m in modes[1:])
    return not all(alike)


def floor_round(b: BeliefView, xy: np.ndarray, heading: float) -> np.ndarray:
    """The free floor (m, to ``MAX_RAY_M``) the wall model has round ``xy`` (map) along
    ``LOOK_BEARINGS`` from ``heading``: what a look round from there shows in depth."""
    return b.evidence.floor.reach(np.asarray(xy, float), heading + LOOK_BEARINGS, MAX_RAY_M)
