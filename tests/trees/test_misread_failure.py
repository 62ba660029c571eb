"""A whole mission on the test doubles whose goal's plate is read, but as text that names
nothing of the map: its TARGET_NOT_FOUND says what was read there, in the building's words
(the issue's "sign 'Room 17' read as 'Room 71' twice")."""

from __future__ import annotations

import dataclasses

import pytest

from pmnav_bt.failures import FailureCode, root_cause
from pmnav_bt.map.catalogue import load_building
from pmnav_bt.planning.resolve import sign_text
from pmnav_bt.seams import Detection, Entity, Pose2D
from pmnav_bt.testing.doubles import ScriptedGrounder

START = Pose2D(4.0, 0.0, 0.0)  # straight_office, facing east down the corridor
GOAL = Entity.room("room2")  # its door (10, 1.1) is in view from the start
MISREAD = "Rom 2O"


@pytest.fixture(scope="module")
def building():
    return load_building("straight_office")


@dataclasses.dataclass
class Misreading(ScriptedGrounder):
    """Reads the goal's plate in every frame that shows it, as ``MISREAD`` (which names
    nothing), and tells a watcher so, as the OCR grounder does (``watch_reads``)."""

    observer: object = None

    def watch_reads(self, observer) -> None:
        self.observer = observer

    def read_signs(self, obs):
        seen = super().read_signs(obs)
        plate = dataclasses.replace(self, hidden=frozenset())._see(obs, GOAL)
        if self.observer is not None and plate is not None:
            self.observer(obs, seen, [Detection(MISREAD, plate.box, 0.9, point=plate.point)])
        return seen


def test_the_goal_not_found_says_what_its_plate_was_read_as(make_rig, pm):
    rig = make_rig(START, grounder=Misreading(pm, hidden=frozenset({GOAL.id})))
    outcome = rig.mission(GOAL.id, max_ticks=20_000)
    assert not outcome.success
    lost = root_cause(outcome.failure)
    assert lost.code is FailureCode.TARGET_NOT_FOUND, outcome.failure
    mapped = sign_text(pm.building, GOAL)
    assert f"; sign '{mapped}' read as '{MISREAD}' " in lost.message, lost.message


def test_without_reads_at_the_goal_the_failure_says_nothing_more(make_rig, pm):
    rig = make_rig(START, grounder=ScriptedGrounder(pm, hidden=frozenset({GOAL.id})))
    outcome = rig.mission(GOAL.id, max_ticks=20_000)
    assert "read as" not in str(outcome.failure) and rig.ctx.misreads is None
