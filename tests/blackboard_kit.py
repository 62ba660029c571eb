"""The test side of the tree's blackboard: a client that may write every ``/pmnav`` key
(to put a behaviour in a known situation), read access that returns None for an unset
key, and a fixture-friendly clear."""

from __future__ import annotations

from collections.abc import Iterator

import py_trees
from py_trees.common import Access

from pmnav_bt.behaviours.common import KEYS, NAMESPACE


def writer(name: str = "test") -> py_trees.blackboard.Client:
    """A blackboard client that may read and write every key of the tree."""
    bb = py_trees.blackboard.Client(name=name, namespace=NAMESPACE)
    for key in KEYS:
        bb.register_key(key=key, access=Access.WRITE)
    return bb


class BlackboardAccess:
    """``set``/``get``/``failure`` for a test rig holding a ``writer()`` client as ``bb``."""

    bb: py_trees.blackboard.Client

    def set(self, **values) -> None:
        for k, v in values.items():
            self.bb.set(k, v)

    def get(self, key: str):
        return self.bb.get(key) if self.bb.exists(key) else None

    @property
    def failure(self):
        return self.get("failure")


def cleared() -> Iterator[None]:
    """An empty blackboard before and after (the body of a pytest fixture)."""
    py_trees.blackboard.Blackboard.clear()
    yield
    py_trees.blackboard.Blackboard.clear()
