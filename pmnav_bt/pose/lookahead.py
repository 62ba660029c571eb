"""Where to look next when the belief is split between a few places: the expected trip.

The robot's belief holds a few clusters of hypotheses (mirror images of a symmetric
corridor, the four ways out of a cross junction). From each candidate place it could
drive to, every cluster predicts which signs it would read there; places where the
predictions differ split the clusters into groups. Each candidate is scored by the
expected length of the whole trip: the drive there, then for each group it leaves

- one cluster: the way on to the target from where that cluster puts the robot;
- several clusters: the better of going on without knowing (commit to one cluster's way;
  if it is the wrong one, that way is driven there and back: ``commit``) and one more look
  from a second place that splits the group (``between`` the two, then each subgroup
  commits).

Going to the nearest place that tells some clusters apart and then on to the target as if
the rest were told apart too (the way on averaged over the clusters) prefers a place
that leaves the likeliest clusters mirror images of each other, such as a dead end when
both dead ends look alike: from a cross junction it drove to one dead end, learnt
nothing it needed, and drove 60 m back.

Pure numpy on arrays the belief builds (``CorridorBelief._telling_lead``); costs are in
mass-weighted metres.
"""

from __future__ import annotations

import numpy as np


def commit(mass: np.ndarray, onward: np.ndarray, sees: np.ndarray, ks: list[int]) -> np.ndarray:
    """Expected trip on from every place for the clusters ``ks`` told apart only as far as
    what they read there (``sees``): each group of clusters that read alike commits to the
    way on of the member that makes the wrong guess cheapest; a wrong guess costs that way
    there and back. Shape (N,)."""
    total = np.zeros(onward.shape[1])
    for k in ks:
        total += mass[k] * onward[k]
    share = {k: np.zeros(onward.shape[1]) for k in ks}  # mass of k's group at each place
    for k in ks:
        for j in ks:
            share[k] += np.where(sees[j] == sees[k], mass[j], 0.0)
    wrong = {k: (share[k] - mass[k]) * onward[k] for k in ks}  # others' mass, k's way
    for k in ks:
        # k is the guess of its group where no groupmate's wrong guess is cheaper.
        chosen = np.ones(onward.shape[1], dtype=bool)
        for j in ks:
            if j == k:
                continue
            same = sees[j] == sees[k]
            cheaper = (wrong[j] < wrong[k]) | ((wrong[j] == wrong[k]) & (j < k))
            chosen &= ~(same & cheaper)
        total += np.where(chosen, 2.0 * wrong[k], 0.0)
    return total


def expected_trip(
    reach: np.ndarray,
    between: np.ndarray,
    sees: np.ndarray,
    onward: np.ndarray,
    mass: np.ndarray,
    usable: np.ndarray,
    fix_share: float,
) -> np.ndarray:
    """The expected whole trip (mass-weighted m) of looking first from each candidate.

    ``reach`` (N,): corridor distance from the robot to each candidate place;
    ``between`` (N, N): corridor distance between candidates; ``sees`` (K, N): an id of
    what cluster k reads at each candidate (equal ids, equal signs; -1: under k the place
    is inside a wall); ``onward`` (K, N): distance on to the target from there under
    cluster k; ``mass`` (K,); ``usable`` (N,): not looked from yet. A first look must be
    floor under every cluster and leave no group holding ``fix_share`` of the mass (it
    tells something); others are inf."""
    k_all = list(range(len(mass)))
    total = float(mass.sum())
    floor = (sees >= 0).all(axis=0)
    second: dict[tuple[int, ...], np.ndarray] = {}  # per group: cost of its best next look

    def look_again(ks: tuple[int, ...]) -> np.ndarray:
        """For the group ``ks``: a second look's cost from each place, before the drive."""
        if ks not in second:
            sub = sees[list(ks)]
            splits = (sub != sub[0]).any(axis=0) & (sub >= 0).all(axis=0) & usable
            second[ks] = np.where(splits, commit(mass, onward, sees, list(ks)), np.inf)
        return second[ks]

    stay = {}  # per group: committing from each place without a second look
    cost = np.full(len(reach), np.inf)
    for c in np.nonzero(usable & floor)[0]:
        groups: dict[int, list[int]] = {}
        for k in k_all:
            groups.setdefault(int(sees[k, c]), []).append(k)
        if max(float(mass[g].sum()) for g in groups.values()) >= fix_share * total:
            continue  # tells (next to) nothing
        trip = total * float(reach[c])
        for ks in groups.values():
            key = tuple(ks)
            if len(ks) == 1:
                trip += float(mass[ks[0]] * onward[ks[0], c])
                continue
            if key not in stay:
                same = np.zeros_like(sees[list(ks)])  # one group: nothing told apart
                idx = list(ks)
                stay[key] = commit(mass[idx], onward[idx], same, list(range(len(ks))))
            again = look_again(key)
            m = float(mass[ks].sum())
            trip += min(float(stay[key][c]), float(np.min(m * between[c] + again)))
        cost[c] = trip
    return cost
