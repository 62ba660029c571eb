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

Pure numpy on arrays the belief builds (``pose.telling.telling_lead``); costs are in
mass-weighted metres.
"""

from __future__ import annotations

import numpy as np


def _group_mass(sees: np.ndarray, mass: np.ndarray) -> np.ndarray:
    """(K, N): at each place, the mass of the clusters that read what cluster k reads."""
    same = sees[:, None, :] == sees[None, :, :]  # (j, k, N)
    return (same * mass[:, None, None]).sum(axis=0)


def telling(sees: np.ndarray, mass: np.ndarray, usable: np.ndarray, fix_share: float):
    """(N,) bool: places a first look may be taken from: usable (not looked from yet),
    floor under every cluster, and leaving no group of clusters that read alike with
    ``fix_share`` of the mass (the look tells something)."""
    floor = (sees >= 0).all(axis=0)
    return usable & floor & (_group_mass(sees, mass).max(axis=0) < fix_share * mass.sum())


def commit(mass: np.ndarray, onward: np.ndarray, sees: np.ndarray) -> np.ndarray:
    """Expected trip on from every place for clusters told apart only as far as what they
    read there (``sees``, (K, N)): each group of clusters that read alike commits to the
    way on of the member whose wrong guess is cheapest (ties: the first); a wrong guess
    costs that way there and back. Shape (N,)."""
    wrong = (_group_mass(sees, mass) - mass[:, None]) * onward  # others' mass, k's way
    same = sees[:, None, :] == sees[None, :, :]  # (j, k, N)
    order = np.arange(len(mass))
    cheaper = (wrong[:, None, :] < wrong[None, :, :]) | (
        (wrong[:, None, :] == wrong[None, :, :]) & (order[:, None] < order[None, :])[:, :, None]
    )
    guessed = ~(same & cheaper).any(axis=0)  # no groupmate's wrong guess is cheaper
    return (mass[:, None] * onward).sum(axis=0) + 2.0 * np.where(guessed, wrong, 0.0).sum(axis=0)


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
    total = float(mass.sum())
    second: dict[tuple[int, ...], np.ndarray] = {}  # per group: cost of its best next look
    stay: dict[tuple[int, ...], np.ndarray] = {}  # per group: committing with no more look

    def look_again(ks: tuple[int, ...]) -> np.ndarray:
        """For the group ``ks``: a second look's cost from each place, before the drive."""
        if ks not in second:
            sub = sees[list(ks)]
            splits = (sub != sub[0]).any(axis=0) & (sub >= 0).all(axis=0) & usable
            cost = commit(mass[list(ks)], onward[list(ks)], sub)
            second[ks] = np.where(splits, cost, np.inf)
        return second[ks]

    cost = np.full(len(reach), np.inf)
    for c in np.nonzero(telling(sees, mass, usable, fix_share))[0]:
        groups: dict[int, list[int]] = {}
        for k in range(len(mass)):
            groups.setdefault(int(sees[k, c]), []).append(k)
        trip = total * float(reach[c])
        for ks in groups.values():
            key = tuple(ks)
            if len(ks) == 1:
                trip += float(mass[ks[0]] * onward[ks[0], c])
                continue
            if key not in stay:  # one group: nothing told apart
                stay[key] = commit(mass[ks], onward[ks], np.zeros_like(sees[ks]))
            m = float(mass[ks].sum())
            again = float(np.min(m * between[c] + look_again(key)))
            trip += min(float(stay[key][c]), again)
        cost[c] = trip
    return cost
