"""Short corridors to the doors the lanes pass by at a distance (``import-rmf``).

A lane runs straight where a wall curves away from it (a clinic's consult rooms round a
curved pod), or passes a side bay; the doors there open onto the corridors' free space
but lie farther from every centre line than a door may (half the width + 1 m). For each
such door a **spur** is added: a short corridor that runs along the door's wall, half a
spur width in front of it, from where that line meets the network to just past the door.
The door is then on the spur's wall, as a door on any corridor is, and the simulator
hangs it on the same wall the RMF file draws. Where no straight spur fits, a bent one
goes from the nearest point of the network to just before the door, then along its
wall. Doors are taken nearest first and a spur may start on an earlier one, so the
spurs along a curved wall chain into a polyline.
"""

from __future__ import annotations

import numpy as np

from pmnav_bt.geometry import project_points_to_segments
from pmnav_bt.map.floorplan import FloorPlanImage
from pmnav_bt.map.landmark_kinds import ELEVATOR
from pmnav_bt.map.rmf_corridors import MIN_EDGE_M, Corridors

SPUR_HALF_M = 0.9  # the spur's centre line runs this far in front of the door's wall
SPUR_MAX_M = 12.0  # a door farther than this along its wall from the network gets no spur
PAST_M = 0.6  # the spur ends this far past the door's centre
# ... a lift's: its doors, frame and call panel (ELEVATOR.span_m) and the spur's square
# end (half its width) stand on a straight wall, clear of the spur's bend
LIFT_PAST_M = ELEVATOR.span_m / 2.0 + SPUR_HALF_M
COLLINEAR_M = 0.1  # a ray this near an earlier spur's line continues that spur
END_ON_COS = 0.7  # a dead end within 45 deg of a door's normal runs into the door


def add_spur(
    cor: Corridors,
    plan: FloorPlanImage,
    free: np.ndarray,
    door: np.ndarray,
    along: np.ndarray,
    past: float = PAST_M,
) -> bool:
    """Add a spur to the door centred at ``door`` in a wall running along ``along``.

    Returns False (and changes nothing) when no straight spur along the wall, in the free
    space, reaches the network within ``SPUR_MAX_M``.
    """
    along = along / np.linalg.norm(along)
    normal = np.array([-along[1], along[0]])
    best = None
    for side in (1.0, -1.0):
        front = door + side * normal * SPUR_HALF_M
        if not plan.mask_at(free, front[None])[0]:
            continue
        for way in (1.0, -1.0):
            hit = _first_hit(cor, front, way * along)
            if hit is None:
                continue
            dist, k, foot = hit
            end = front - way * along * past
            if not _clear(plan, free, foot, end):
                continue
            if best is None or dist < best[0]:
                best = (dist, k, foot, end)
    if best is None:
        return _add_bent_spur(cor, plan, free, door, along, normal, past)
    _, k, foot, end = best
    if np.linalg.norm(end - foot) < MIN_EDGE_M:
        return False
    node = _node_at(cor, k, foot)
    new = max(cor.pos) + 1
    cor.pos[new] = end
    _add_drawn(cor, node, new)
    return True


def turn_at_door(
    cor: Corridors,
    plan: FloorPlanImage,
    free: np.ndarray,
    door: np.ndarray,
    along: np.ndarray,
    past: float = PAST_M,
) -> bool:
    """A dead end that runs into the door (a lane cut where it went through it) stops
    half a spur width in front of the door's wall and turns along it to just past the
    door, so the door is on a corridor's side wall, not at its end.
    """
    seg_a = np.array([cor.pos[u] for u, _, _ in cor.edges])
    seg_b = np.array([cor.pos[v] for _, v, _ in cor.edges])
    j, t, dist = project_points_to_segments(door[None], seg_a, seg_b)
    k, t = int(j[0]), float(t[0])
    u, v, w = cor.edges[k]
    end, other = (v, u) if t > 0.5 else (u, v)
    degree = sum(n == end for e in cor.edges for n in e[:2])
    along = along / np.linalg.norm(along)
    normal = np.array([-along[1], along[0]])
    axis = cor.pos[end] - cor.pos[other]
    axis = axis / float(np.linalg.norm(axis))
    if degree != 1 or min(t, 1.0 - t) > 1e-6 or abs(float(np.dot(axis, normal))) < END_ON_COS:
        return False
    if np.dot(normal, cor.pos[other] - door) < 0:
        normal = -normal  # towards the corridor
    front = door + normal * SPUR_HALF_M
    stop = float(np.dot(cor.pos[other] - front, normal) / np.dot(axis, -normal))
    knee = cor.pos[other] + axis * stop
    way = along if np.dot(front - knee, along) >= 0 else -along
    tip = front + way * past
    if stop < MIN_EDGE_M or not _clear(plan, free, knee, tip):
        return False
    cor.pos[end] = knee
    new = max(cor.pos) + 1
    cor.pos[new] = tip
    _add_drawn(cor, end, new)
    return True


def _add_bent_spur(cor, plan, free, door, along, normal, past) -> bool:
    """Where no straight spur fits: from the nearest point of the network straight to just
    before the door (in front of its wall), then along the wall to just past it."""
    seg_a = np.array([cor.pos[u] for u, _, _ in cor.edges])
    seg_b = np.array([cor.pos[v] for _, v, _ in cor.edges])
    for side in (1.0, -1.0):
        front = door + side * normal * SPUR_HALF_M
        j, t, d = project_points_to_segments(front[None], seg_a, seg_b)
        foot = seg_a[j[0]] + t[0] * (seg_b[j[0]] - seg_a[j[0]])
        way = 1.0 if np.dot(front - foot, along) < 0 else -1.0  # the knee nearer the network
        knee, end = front + way * along * past, front - way * along * past
        if not (d[0] <= SPUR_MAX_M and plan.mask_at(free, front[None])[0]
                and _clear(plan, free, foot, knee) and _clear(plan, free, knee, end)
                and np.linalg.norm(knee - foot) >= MIN_EDGE_M):
            continue
        node = _node_at(cor, int(j[0]), foot)
        k1 = max(cor.pos) + 1
        cor.pos[k1], cor.pos[k1 + 1] = knee, end
        cor.edges.append((node, k1, round(2.0 * SPUR_HALF_M, 2)))  # measured with the rest
        _add_drawn(cor, k1, k1 + 1)  # along the door's wall
        return True
    return False


def _first_hit(cor: Corridors, p: np.ndarray, d: np.ndarray):
    """(distance, edge index, point) where the ray p + t d first meets a centre line."""
    best = None
    for k, (u, v, _) in enumerate(cor.edges):
        a, b = cor.pos[u], cor.pos[v]
        e = b - a
        den = d[0] * (-e[1]) - d[1] * (-e[0])
        if abs(den) < 1e-9 * max(float(np.linalg.norm(e)), 1e-9):
            # Along the line of an earlier spur: the hit is the spur's nearer end.
            for q in (a, b):
                t = float(np.dot(q - p, d))
                off = float(np.linalg.norm(q - (p + t * d)))
                if off < COLLINEAR_M and 0.0 < t <= SPUR_MAX_M and (best is None or t < best[0]):
                    best = (t, k, q.copy())
            continue
        r = a - p
        t = (r[0] * (-e[1]) - r[1] * (-e[0])) / den
        s = (d[0] * r[1] - d[1] * r[0]) / den
        if 0.0 < t <= SPUR_MAX_M and -1e-9 <= s <= 1.0 + 1e-9 and (best is None or t < best[0]):
            best = (float(t), k, p + t * d)
    return best


def _clear(plan: FloorPlanImage, free: np.ndarray, a: np.ndarray, b: np.ndarray) -> bool:
    n = max(2, int(np.linalg.norm(b - a) / (plan.resolution / 2.0)))
    return bool(plan.mask_at(free, a + np.linspace(0.0, 1.0, n)[:, None] * (b - a)).all())


def _add_drawn(cor: Corridors, u: int, v: int) -> None:
    """A spur's piece u-v: ``2 * SPUR_HALF_M`` wide, drawn so (``Corridors.drawn``)."""
    cor.edges.append((u, v, round(2.0 * SPUR_HALF_M, 2)))
    cor.drawn.add(frozenset((u, v)))


def _node_at(cor: Corridors, k: int, foot: np.ndarray) -> int:
    """The node at ``foot`` on edge ``k``: an end of the edge when near, else a new one
    that splits the edge in two."""
    u, v, w = cor.edges[k]
    for n in (u, v):
        if np.linalg.norm(cor.pos[n] - foot) < MIN_EDGE_M:
            return n
    new = max(cor.pos) + 1
    cor.pos[new] = np.asarray(foot, float)
    cor.edges[k] = (u, new, w)
    cor.edges.append((new, v, w))
    if frozenset((u, v)) in cor.drawn:
        cor.drawn |= {frozenset((u, new)), frozenset((new, v))}
    return new
