"""Wires a run's map-updates sink into its tree: the sign and landmark checks on what
perception reads (``perception.map_check.MapCheck``, watching the grounder's reader) and
the sink the leaves write other disagreements to (``Context.map_updates``: a corridor
that stays blocked). The simulator run and the ROS node call :func:`watch_map` with the
sink they write beside their output (``map.updates.UpdatesFile``). Also the run's watch of
plates that named nothing (``perception.misreads``), for the words of a TARGET_NOT_FOUND,
with or without a sink (:func:`watch_misreads`).
"""

from __future__ import annotations

import py_trees

from pmnav_bt.behaviours.common import NAMESPACE
from pmnav_bt.behaviours.context import Context
from pmnav_bt.map.updates import MapUpdateSink
from pmnav_bt.perception.map_check import MapCheck, ReadsObserver, WatchesReads
from pmnav_bt.perception.misreads import Misreads
from pmnav_bt.tree_variants import TREE_VARIANTS


def watch_map(ctx: Context, sink: MapUpdateSink) -> None:
    """Send what ``ctx``'s tree sees that disagrees with its map to ``sink`` (call before
    anything wraps ``ctx.grounder``: the ROS node's back ends, kept from run to run, get
    this run's watcher). A variant that does not read the priori-map (the map-less
    baseline) has nothing to disagree with."""
    if not TREE_VARIANTS.spec(ctx.config.tree.variant).knows.plans:
        return
    ctx.map_updates = sink
    if isinstance(ctx.grounder, WatchesReads):  # a reader of plates (not the oracle)
        check = MapCheck(ctx.pm, sink, _map_T_odom).frame
        ctx.grounder.watch_reads(check if ctx.misreads is None else _both(ctx.misreads, check))


def watch_misreads(ctx: Context) -> None:
    """Keep the plates ``ctx``'s reader reads that name nothing (``ctx.misreads``), for the
    words of a TARGET_NOT_FOUND (``make_context`` calls it, before ``watch_map``). Not for a
    variant that does not read the priori-map, nor for a grounder that reads no plates."""
    if not TREE_VARIANTS.spec(ctx.config.tree.variant).knows.plans:
        return
    if isinstance(ctx.grounder, WatchesReads):
        ctx.misreads = Misreads(ctx.pm, _map_T_odom)
        ctx.grounder.watch_reads(ctx.misreads.frame)


def _both(misreads: Misreads, check: ReadsObserver) -> ReadsObserver:
    def frame(obs, matched, unmatched) -> None:
        misreads.frame(obs, matched, unmatched)
        check(obs, matched, unmatched)

    return frame


def _map_T_odom():
    """The tree's current map-from-odometry transform (None before localization); read
    from the worker thread, a value the tree replaces whole, never changes in place."""
    return py_trees.blackboard.Blackboard.storage.get(f"{NAMESPACE}/map_T_odom")
