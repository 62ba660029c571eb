"""What was read at a target's place that named nothing: the words a TARGET_NOT_FOUND
failure gives a person ("sign '117 Pharmacy' read as '171 Pharmacy' twice").

The OCR grounder names a room or landmark only when the matcher is sure of it
(``sign_match.decide``); a plate that named nothing of the building, or was ambiguous
between rooms, is dropped, and a search that fails says only "room117 not seen". Yet a
person on site can act on what was read there: a worn or renamed sign, a plate that
reads differently from the map. :class:`Misreads` watches the reader (a
``ReadsObserver``, like ``map_check.MapCheck``) and keeps each plate that named nothing
with where it hangs on the map; :meth:`Misreads.explain` adds the ones read within
``NEAR_M`` of the target's place to a TARGET_NOT_FOUND failure, in the building's words:
the sign the map has there, and what was read instead, with how many frames read it.

A plate that near the target's place is taken for its sign. Only plates read with
trusted digits reach a watcher (``OcrGrounder.watch_reads``), and only once the tree is
localized can a plate be placed on the map: reads before that are not kept.
"""

from __future__ import annotations

import dataclasses
import math
import threading
from collections.abc import Callable

from pmnav_bt.failures import Failure, FailureCode
from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.perception.map_check import plate_in_map
from pmnav_bt.perception.sign_match import normalise
from pmnav_bt.planning.resolve import entity_position, sign_text
from pmnav_bt.seams import Detection, Entity, Observation

# A sign hangs beside its door (at most about 0.6 m from the door point) and a plate's
# place by the pose estimate is good to about 1 m; the next door is usually farther.
NEAR_M = 2.0
MAX_SHOWN = 2  # distinct reads named in a failure, those read most often first


class Misreads:
    """The plates read that named nothing, by their text, with where each frame placed
    them (see the module docstring); give ``frame`` to a grounder's ``watch_reads``.
    ``map_T_odom()``: the tree's current map-from-odometry transform (None before
    localization). ``frame`` runs on the worker, ``explain`` in a tick: a lock between."""

    def __init__(self, pm: PrioriMap, map_T_odom: Callable[[], tuple | None]) -> None:
        self.pm = pm
        self.map_T_odom = map_T_odom
        self._reads: dict[str, tuple[str, dict[float, tuple[float, float]]]] = {}
        self._lock = threading.Lock()

    def frame(self, obs: Observation, matched: list[Detection], unmatched: list[Detection]):
        """Keep the plates of one frame that named nothing (``matched`` are not misreads)."""
        tf = self.map_T_odom()
        for d in unmatched:
            key, xy = normalise(d.label), plate_in_map(obs, d, tf)
            if not key or xy is None:
                continue
            with self._lock:
                _, places = self._reads.setdefault(key, (d.label, {}))
                places.setdefault(float(obs.stamp), xy)  # a frame counts once

    def words(self, entity: Entity) -> str | None:
        """"sign 'Room 17' read as 'Room 71' twice" for the plates read within ``NEAR_M``
        of ``entity``'s place (the most read first, ``MAX_SHOWN`` of them); None if none."""
        place = entity_position(self.pm, entity)
        with self._lock:
            counts = [
                (sum(math.dist(xy, place) <= NEAR_M for xy in places.values()), text)
                for text, places in self._reads.values()
            ]
        near = sorted(((n, t) for n, t in counts if n), key=lambda c: -c[0])[:MAX_SHOWN]
        if not near:
            return None
        read = " and as ".join(f"'{t}' {_times(n)}" for n, t in near)
        return f"sign '{sign_text(self.pm.building, entity)}' read as {read}"

    def explain(self, failure: Failure, entity: Entity | None) -> Failure:
        """``failure`` with the misreads at ``entity``'s place added to each TARGET_NOT_FOUND
        of its chain (its own message and its cause's); unchanged without any."""
        cause = None if failure.cause is None else self.explain(failure.cause, entity)
        message = failure.message
        if failure.code is FailureCode.TARGET_NOT_FOUND and entity is not None:
            words = self.words(entity)
            message = f"{message}; {words}" if words else message
        return dataclasses.replace(failure, message=message, cause=cause)


def _times(n: int) -> str:
    return {1: "once", 2: "twice"}.get(n, f"{n} times")
