"""The skill eval's failure reasons: each failed trial says how it failed, counted per method."""

from __future__ import annotations

from pmnav_bt.experiments.pixelnav_eval import FAILURES, Trial, failures, format_failures
from pmnav_bt.pixelnav.dataset import MAX_STEPS


def trial(success, reached, steps, method="pixelnav", dist=4.0):
    return Trial(method, 1, "floor", dist, success, reached, steps, 0.5 if success else 1.4)


def test_each_failure_says_how_it_failed():
    assert trial(True, True, 12).failure == ""
    assert trial(False, False, 16).failure == "stopped short"
    assert trial(False, True, 30).failure == "stopped after passing"
    assert trial(False, True, MAX_STEPS).failure == "no stop, passed"
    assert trial(False, False, MAX_STEPS).failure == "no stop, never near"


def test_failures_are_counted_per_method_and_reason():
    ts = [
        trial(False, False, 16, dist=4.5),
        trial(False, False, 17, dist=3.5),
        trial(True, True, 20),
        trial(False, True, MAX_STEPS, method="geometric"),
        trial(True, True, 20, method="geometric"),
    ]
    rows = {(r["method"], r["failure"]): r for r in failures(ts)}
    assert len(rows) == 2 * len(FAILURES)
    short = rows[("pixelnav", "stopped short")]
    assert (short["n"], short["of"], short["median_goal_m"]) == (2, 3, 4.0)
    assert rows[("geometric", "no stop, passed")]["n"] == 1
    assert rows[("pixelnav", "no stop, passed")]["median_steps"] is None
    text = format_failures(failures(ts))
    line = text.splitlines()[1]
    assert line.startswith("stopped short") and line.split()[-2:] == ["2", "0"]
