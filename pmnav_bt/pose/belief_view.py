"""What the lead reads of the corridor belief (``pose.belief.CorridorBelief``), as a
Protocol: the lead's modules (``pose.lead``, ``pose.telling``) sit below the belief, which
asks them where to go, so they name its parts here instead of importing it."""

from __future__ import annotations

from typing import Protocol

import numpy as np

from pmnav_bt.map.priori_map import PrioriMap
from pmnav_bt.pose.evidence import Evidence
from pmnav_bt.pose.glimpse import Glimpse
from pmnav_bt.pose.hypotheses import Hypotheses
from pmnav_bt.pose.visibility import Visibility
from pmnav_bt.seams import Pose2D


class BeliefView(Protocol):
    """The belief as the lead sees it."""

    pm: PrioriMap
    vis: Visibility  # the lattice with the signs readable from each point
    goal: Visibility  # ... read reliably: where to go to read them
    hyps: Hypotheses
    evidence: Evidence  # (the blocked ways: ``evidence.floor``)
    glimpses: list[Glimpse]
    ref: Pose2D | None
    pending_blocked: float | None
    target: tuple[float, float] | None

    @property
    def drift(self) -> float: ...

    def axis(self) -> float: ...

    def weights(self) -> np.ndarray: ...

    def best_cluster(self) -> tuple[np.ndarray, float]: ...

    def map_T_odoms(self) -> np.ndarray: ...

    def straighten(self, xy) -> np.ndarray: ...
