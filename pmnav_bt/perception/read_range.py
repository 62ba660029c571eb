"""How far a grounder names signs: the one source of the tree's search distances.

The ``ocr`` reader's recall per distance band is measured by ``benchmarks/bench_signs.py``
(docs/perception.md) at two camera sizes. A sign counts as readable up to the far end of
the last band where the reader names at least ``RELIABLE_RECALL`` of the signs. Other
widths are interpolated between the measured ones (below the smallest, in proportion to
the width: a sign's text is that many pixels smaller; above the largest, no farther, as
the reader's crops are upscaled anyway). The oracle (``sim_gt``) reads to its
``grounder.max_range``.

From the read range follow (``search_settings``): where the tree searches for a target
(``tree.search_range``), how far it moves on before searching again
(``tree.research_distance``), and the range the localization belief expects signs to be
read from (``pose.visibility``). Values set in the config win.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # pragma: no cover
    from pmnav_bt.config import Config

# benchmarks/bench_signs.py --views 200 (2026-11, 8 built-in buildings, 0-70 deg off the
# plate): (band start m, band end m, recall) per camera width.
OCR_RECALL: dict[int, tuple[tuple[float, float, float], ...]] = {
    320: ((1.5, 2.5, 0.939), (2.5, 3.5, 0.490), (3.5, 4.5, 0.033), (4.5, 6.0, 0.045)),
    640: ((1.5, 2.5, 0.949), (2.5, 3.5, 0.837), (3.5, 4.5, 0.300), (4.5, 6.0, 0.136)),
}
RELIABLE_RECALL = 0.75  # the tree searches where signs are read this often
POSSIBLE_RECALL = 0.25  # beyond where signs are read this often, a reading is unexpected
# The oracle's search settings (a sign read to 9 m): the tree's settings before the reader.
MAX_SEARCH_RANGE_M = 4.5
MAX_RESEARCH_DISTANCE_M = 2.0
# A door's sign hangs beside it and the robot drives the corridor's centre: search from
# this much nearer than the read range.
SEARCH_MARGIN_M = 0.5


def measured_range(width: int, recall: float = RELIABLE_RECALL) -> float:
    """The far end of the last band with at least ``recall``, at a measured width."""
    bands = OCR_RECALL[width]
    far = bands[0][0]
    for _, end, r in bands:
        if r < recall:
            break
        far = end
    return far


def ocr_read_range(width: int, recall: float = RELIABLE_RECALL) -> float:
    """How far (m) the OCR reader names at least ``recall`` of the signs with a camera
    ``width`` pixels wide."""
    widths = sorted(OCR_RECALL)
    if width <= widths[0]:
        return measured_range(widths[0], recall) * width / widths[0]
    for lo, hi in zip(widths, widths[1:], strict=False):
        if width <= hi:
            a, b = measured_range(lo, recall), measured_range(hi, recall)
            return a + (b - a) * (width - lo) / (hi - lo)
    return measured_range(widths[-1], recall)


def _oracle(config: Config) -> bool:
    from pmnav_bt.registry import GROUNDERS

    return GROUNDERS.spec(config.grounder.backend).needs_sim_labels


def sign_read_range(config: Config, width: int | None = None) -> float:
    """How far the configured grounder reliably names signs (m); ``width``: the camera's,
    if not ``sim.width``."""
    if _oracle(config):
        return config.grounder.max_range
    return ocr_read_range(width or config.sim.width)


def sign_visible_range(config: Config, width: int | None = None) -> float | None:
    """How far the localization belief expects signs to be read at all (m): a sign
    nearer and in sight but not read is a miss, one read from farther is unexpected.
    None for the oracle: the belief's own ``READ_RANGE_M``, checked against it."""
    if _oracle(config):
        return None
    return ocr_read_range(width or config.sim.width, POSSIBLE_RECALL)


@dataclass(frozen=True)
class SearchSettings:
    """The tree's search distances (m): search within ``search_range`` of the target (by
    the map), move ``research_distance`` on before searching again."""

    search_range: float
    research_distance: float
    read_range: float


def search_settings(config: Config, width: int | None = None) -> SearchSettings:
    """``tree.search_range`` and ``tree.research_distance`` as set, else from the read range:
    ``read_range - SEARCH_MARGIN_M`` (at most the oracle's 4.5 m) and half of that (at most
    2 m)."""
    read = sign_read_range(config, width)
    t = config.tree
    search = t.search_range
    if search is None:
        search = min(MAX_SEARCH_RANGE_M, max(1.0, read - SEARCH_MARGIN_M))
    research = t.research_distance
    if research is None:
        research = min(MAX_RESEARCH_DISTANCE_M, search / 2.0)
    return SearchSettings(search, research, read)
